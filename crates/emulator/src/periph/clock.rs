//! RCC, PWR and FLASH: the clock tree as far as the image drives it (RM0440 §7 RCC,
//! §6 PWR, §3 FLASH). Ready flags follow their enables, SYSCLK/HCLK follow SW and HPRE,
//! and the rules of a switch above 150 MHz are checked at the write that makes HCLK
//! change.

use crate::violation::Broken;

/// HSI16 \[Hz\] (RM0440 §7.2.2).
pub const HSI_HZ: f64 = 16e6;

/// RCC_AHB1ENR, AHB2ENR, APB1ENR1, APB2ENR offsets (RM0440 §7.4.14–§7.4.19).
pub const AHB1ENR: u32 = 0x48;
/// RCC_AHB2ENR.
pub const AHB2ENR: u32 = 0x4C;
/// RCC_APB1ENR1.
pub const APB1ENR1: u32 = 0x58;
/// RCC_APB2ENR.
pub const APB2ENR: u32 = 0x60;

/// RCC, PWR and FLASH registers.
#[derive(Debug)]
pub struct Clocks {
    rcc: [u32; 0x100 / 4],
    pwr: [u32; 0x100 / 4],
    flash: [u32; 0x80 / 4],
    /// Time HPRE last changed and whether it was the /2 step \[s\].
    hpre_step_at: Option<f64>,
    /// The board's HSE crystal \[Hz\], if fitted ([`crate::hardware::Hardware`]).
    pub hse_crystal_hz: Option<f64>,
}

const fn word(off: u32) -> usize {
    (off / 4) as usize
}

/// Known RCC registers (RM0440 §7.4, register map Table 52).
const RCC_KNOWN: &[u32] = &[
    0x00, 0x04, 0x08, 0x0C, 0x18, 0x1C, 0x20, 0x28, 0x2C, 0x30, 0x38, 0x3C, 0x40, 0x48, 0x4C, 0x50, 0x58, 0x5C, 0x60,
    0x68, 0x6C, 0x70, 0x78, 0x7C, 0x80, 0x88, 0x90, 0x94, 0x98, 0x9C,
];
/// Known PWR registers (RM0440 §6.4: CR1–CR4, SR1, SR2, SCR, PUCRx/PDCRx, CR5).
const PWR_KNOWN: &[u32] = &[
    0x00, 0x04, 0x08, 0x0C, 0x10, 0x14, 0x18, 0x20, 0x24, 0x28, 0x2C, 0x30, 0x34, 0x38, 0x3C, 0x40, 0x44, 0x48, 0x4C,
    0x80,
];
/// Known FLASH registers (RM0440 §3.7).
const FLASH_KNOWN: &[u32] = &[
    0x00, 0x04, 0x08, 0x0C, 0x10, 0x14, 0x18, 0x20, 0x24, 0x28, 0x2C, 0x30, 0x44, 0x48, 0x4C, 0x50, 0x70, 0x74,
];

impl Clocks {
    /// Reset state; `optr` is FLASH_OPTR as loaded from the option bytes.
    pub fn new(optr: u32) -> Self {
        let mut c = Self {
            rcc: [0; 0x100 / 4],
            pwr: [0; 0x100 / 4],
            flash: [0; 0x80 / 4],
            hpre_step_at: None,
            hse_crystal_hz: None,
        };
        // RM0440 §7.4.1 RCC_CR reset 0x0000_0500: HSION, HSIRDY.
        c.rcc[0] = 0x0000_0500;
        // §7.4.3 RCC_CFGR reset 0x0000_0005: SW = SWS = HSI16.
        c.rcc[word(0x08)] = 0x0000_0005;
        // §7.4.4 RCC_PLLCFGR reset 0x0000_1000 (PLLN = 16).
        c.rcc[word(0x0C)] = 0x0000_1000;
        // §7.4.14 RCC_AHB1ENR reset 0x0000_0100 (FLASHEN).
        c.rcc[word(AHB1ENR)] = 0x0000_0100;
        // §6.4.1 PWR_CR1 reset 0x0000_0200 (VOS range 1); §6.4.22 PWR_CR5 0x0000_0100
        // (R1MODE = 1: range 1 normal, not boost).
        c.pwr[0] = 0x0000_0200;
        c.pwr[word(0x80)] = 0x0000_0100;
        // §3.7.1 FLASH_ACR reset 0x0000_0600 (ICEN, DCEN, 0 wait states); §3.7.6 FLASH_CR
        // reset 0xC000_0000 (LOCK, OPTLOCK).
        c.flash[0] = 0x0000_0600;
        c.flash[word(0x14)] = 0xC000_0000;
        c.flash[word(0x20)] = optr;
        c
    }

    /// An RCC enable register.
    pub fn enr(&self, off: u32) -> u32 {
        self.rcc[word(off)]
    }

    /// PWR's clock (RCC_APB1ENR1.PWREN, RM0440 §7.4.17).
    pub fn pwr_clocked(&self) -> bool {
        self.rcc[word(APB1ENR1)] & (1 << 28) != 0
    }

    /// PLL output R \[Hz\] from RCC_PLLCFGR (RM0440 §7.4.4: f = f_in/M·N/R).
    fn pll_r_hz(&self) -> f64 {
        let cfg = self.rcc[word(0x0C)];
        let input = match cfg & 3 {
            2 => HSI_HZ,
            _ => 0.0,
        };
        let m = f64::from(((cfg >> 4) & 0xF) + 1);
        let n = f64::from((cfg >> 8) & 0x7F);
        let r = f64::from((((cfg >> 25) & 3) + 1) * 2);
        input / m * n / r
    }

    /// SYSCLK \[Hz\] from RCC_CFGR.SWS.
    pub fn sysclk_hz(&self) -> f64 {
        match (self.rcc[word(0x08)] >> 2) & 3 {
            3 => self.pll_r_hz(),
            _ => HSI_HZ,
        }
    }

    /// HCLK \[Hz\]: SYSCLK / HPRE (RM0440 §7.4.3).
    pub fn hclk_hz(&self) -> f64 {
        let hpre = (self.rcc[word(0x08)] >> 4) & 0xF;
        let div = if hpre < 8 { 1 } else { 2u32 << (hpre - 8).min(3) };
        let div = if hpre >= 12 { 64u32 << (hpre - 12) } else { div };
        self.sysclk_hz() / f64::from(div)
    }

    /// FDCAN's kernel clock \[Hz\] from RCC_CCIPR.FDCANSEL (RM0440 §7.4.26): 0b00 HSE
    /// (0 unless HSERDY), 0b10 PCLK1 (= HCLK: the image leaves APB1 undivided; PPRE1
    /// divides it otherwise, §7.4.3); 0b01 PLL "Q" is not modelled (0).
    pub fn fdcan_kernel_hz(&self) -> f64 {
        let ppre1 = (self.rcc[word(0x08)] >> 8) & 7;
        let pclk1 = if ppre1 < 4 {
            self.hclk_hz()
        } else {
            self.hclk_hz() / f64::from(1u32 << (ppre1 - 3))
        };
        match (self.rcc[word(0x88)] >> 24) & 3 {
            0 if self.rcc[0] & (1 << 17) != 0 => self.hse_crystal_hz.unwrap_or(0.0),
            2 => pclk1,
            _ => 0.0,
        }
    }

    /// PCLK2 \[Hz\] and TIM1's kernel clock (×2 when APB2 is divided, RM0440 §7.2.17).
    pub fn tim_apb2_hz(&self) -> f64 {
        let ppre2 = (self.rcc[word(0x08)] >> 11) & 7;
        if ppre2 < 4 {
            self.hclk_hz()
        } else {
            self.hclk_hz() / f64::from(1u32 << (ppre2 - 3)) * 2.0
        }
    }

    /// FLASH_ACR.LATENCY.
    fn latency(&self) -> u32 {
        self.flash[0] & 0xF
    }

    /// Wait states HCLK needs (RM0440 §3, Table 29 "Number of wait states according
    /// to CPU clock (HCLK) frequency"): range 1 boost 34/68/102/136/170 MHz, range 1
    /// normal 30/60/90/120/150 MHz per 0–4 WS.
    fn wait_states_needed(&self, hclk: f64) -> u32 {
        let boost = self.pwr[word(0x80)] & (1 << 8) == 0;
        let step = if boost { 34e6 } else { 30e6 };
        ((hclk / step).ceil() as u32).saturating_sub(1)
    }

    /// Checks the clock rules after a write that may have changed HCLK.
    fn check_hclk(&mut self, before: f64, now_s: f64, register: &str) -> Result<(), Broken> {
        let hclk = self.hclk_hz();
        if hclk > 150e6 && self.pwr[word(0x80)] & (1 << 8) != 0 {
            return Err(Broken::new(
                register,
                format!(
                    "HCLK {:.0} MHz above 150 MHz needs range-1 boost mode, PWR_CR5.R1MODE = 0 first (RM0440 §6.1.5)",
                    hclk / 1e6
                ),
            ));
        }
        if self.wait_states_needed(hclk) > self.latency() {
            return Err(Broken::new(
                register,
                format!(
                    "HCLK {:.0} MHz with FLASH_ACR.LATENCY = {}: {} wait states needed (RM0440 §3, Table 29)",
                    hclk / 1e6,
                    self.latency(),
                    self.wait_states_needed(hclk)
                ),
            ));
        }
        // RM0440 §7.2.7: to run HCLK above 80 MHz from a lower frequency, the AHB
        // prescaler must first divide by 2 for at least 1 µs (SYSCLK already switched).
        let hpre = (self.rcc[word(0x08)] >> 4) & 0xF;
        let sysclk = self.sysclk_hz();
        if hpre == 0b1000 && sysclk > 80e6 {
            self.hpre_step_at.get_or_insert(now_s);
        } else if hpre < 8 && hclk > 80e6 && hclk > before {
            let ok = before * 2.0 >= hclk && self.hpre_step_at.is_some_and(|t| now_s - t >= 1e-6 - 1e-12);
            self.hpre_step_at = None;
            if !ok {
                return Err(Broken::new(
                    register,
                    format!(
                        "HCLK from {:.0} to {:.0} MHz without 1 µs at AHB/2 first (RM0440 §7.2.7)",
                        before / 1e6,
                        hclk / 1e6
                    ),
                ));
            }
        } else {
            self.hpre_step_at = None;
        }
        Ok(())
    }

    /// RCC read.
    pub fn rcc_read(&mut self, off: u32) -> Result<u32, Broken> {
        if !RCC_KNOWN.contains(&off) {
            return Err(unknown("RCC", off));
        }
        Ok(self.rcc[word(off)])
    }

    /// RCC write at `now_s`.
    pub fn rcc_write(&mut self, off: u32, value: u32, now_s: f64) -> Result<(), Broken> {
        if !RCC_KNOWN.contains(&off) {
            return Err(unknown("RCC", off));
        }
        let before = self.hclk_hz();
        match off {
            0x00 => {
                // PLLRDY follows PLLON (lock time not modelled), HSIRDY follows HSION.
                let mut v = value & !((1 << 25) | (1 << 10) | (1 << 17));
                if v & (1 << 24) != 0 {
                    let f = self.pll_r_hz();
                    let cfg = self.rcc[word(0x0C)];
                    let vco_in = HSI_HZ / f64::from(((cfg >> 4) & 0xF) + 1);
                    let vco = vco_in * f64::from((cfg >> 8) & 0x7F);
                    // DS12288 Table 43 (PLL characteristics): input 2.66–16 MHz, VCO
                    // 96–344 MHz, PLLR output ≤ 170 MHz.
                    if !(2.66e6..=16e6).contains(&vco_in) || !(96e6..=344e6).contains(&vco) || f > 170e6 {
                        return Err(Broken::new(
                            "RCC_CR",
                            format!(
                                "PLLON with VCO input {:.2} MHz, VCO {:.0} MHz, PLLR {:.0} MHz outside DS12288 Table 43",
                                vco_in / 1e6,
                                vco / 1e6,
                                f / 1e6
                            ),
                        ));
                    }
                    v |= 1 << 25;
                }
                if v & (1 << 8) != 0 {
                    v |= 1 << 10;
                }
                // HSERDY follows HSEON with a crystal fitted (start-up time not
                // modelled); without one it never comes.
                if v & (1 << 16) != 0 && self.hse_crystal_hz.is_some() {
                    v |= 1 << 17;
                }
                self.rcc[0] = v;
            }
            0x08 => {
                let sw = value & 3;
                if sw == 3 && self.rcc[0] & (1 << 25) == 0 {
                    return Err(Broken::new("RCC_CFGR", "SW = PLL while PLLRDY = 0 (RM0440 §7.4.3)"));
                }
                // SWS follows SW at once (RM0440 §7.4.3: set by hardware).
                self.rcc[word(0x08)] = (value & !0xC) | (sw << 2);
                self.check_hclk(before, now_s, "RCC_CFGR")?;
            }
            0x0C => {
                if self.rcc[0] & (1 << 24) != 0 {
                    return Err(Broken::new(
                        "RCC_PLLCFGR",
                        "written while PLLON = 1: only with the PLL off (RM0440 §7.4.4)",
                    ));
                }
                self.rcc[word(0x0C)] = value;
            }
            _ => self.rcc[word(off)] = value,
        }
        Ok(())
    }

    /// PWR read.
    pub fn pwr_read(&mut self, off: u32) -> Result<u32, Broken> {
        if !PWR_KNOWN.contains(&off) {
            return Err(unknown("PWR", off));
        }
        // SR2.VOSF (bit 10) = 0: the regulator is always ready (RM0440 §6.4.6).
        Ok(if off == 0x14 { 0 } else { self.pwr[word(off)] })
    }

    /// PWR write.
    pub fn pwr_write(&mut self, off: u32, value: u32) -> Result<(), Broken> {
        if !PWR_KNOWN.contains(&off) {
            return Err(unknown("PWR", off));
        }
        if off == 0x80 && value & (1 << 8) != 0 && self.hclk_hz() > 150e6 {
            return Err(Broken::new(
                "PWR_CR5",
                "R1MODE = 1 (leaving boost) with HCLK above 150 MHz (RM0440 §6.1.5)",
            ));
        }
        self.pwr[word(off)] = value;
        Ok(())
    }

    /// FLASH read.
    pub fn flash_read(&mut self, off: u32) -> Result<u32, Broken> {
        if !FLASH_KNOWN.contains(&off) {
            return Err(unknown("FLASH", off));
        }
        Ok(self.flash[word(off)])
    }

    /// FLASH write (ACR only: programming and option-byte changes are not modelled).
    pub fn flash_write(&mut self, off: u32, value: u32) -> Result<(), Broken> {
        match off {
            0x00 => {
                let latency = value & 0xF;
                if latency < self.wait_states_needed(self.hclk_hz()) {
                    return Err(Broken::new(
                        "FLASH_ACR",
                        "LATENCY lowered below what the running HCLK needs (RM0440 §3)",
                    ));
                }
                self.flash[0] = value;
                Ok(())
            }
            _ if FLASH_KNOWN.contains(&off) => Err(Broken::new(
                format!("FLASH+{off:#04x}"),
                "flash programming / option-byte writes are not modelled",
            )),
            _ => Err(unknown("FLASH", off)),
        }
    }
}

/// An offset no model knows.
pub fn unknown(periph: &str, off: u32) -> Broken {
    Broken::new(
        format!("{periph}+{off:#05x}"),
        "unknown register: not in the model's register map (RM0440 register map of the peripheral)",
    )
}
