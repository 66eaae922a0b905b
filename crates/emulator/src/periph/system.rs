//! IWDG (RM0440 §42), SYSCFG (§10), DBGMCU (§47) and the Cortex-M4 system control
//! space: NVIC, SCB, SysTick, MPU (plain storage: the image may program a stack guard),
//! FPU control (ARMv7-M Architecture Reference Manual B3).

use super::clock::unknown;
use crate::violation::Broken;

/// LSI \[Hz\] (DS12288 Table 56, typical 32 kHz).
pub const LSI_HZ: f64 = 32_000.0;

/// Independent watchdog.
#[derive(Debug)]
pub struct Iwdg {
    pr: u32,
    rlr: u32,
    unlocked: bool,
    /// Time the counter reaches zero \[s\], once started.
    pub expires_at: Option<f64>,
    /// Reloads.
    pub refreshes: u64,
}

impl Default for Iwdg {
    fn default() -> Self {
        Self {
            pr: 0,
            rlr: 0xFFF,
            unlocked: false,
            expires_at: None,
            refreshes: 0,
        }
    }
}

impl Iwdg {
    /// Timeout of the current PR/RLR \[s\]: (RLR + 1)·4·2^PR / f_LSI (RM0440 §42.3.2).
    pub fn timeout_s(&self) -> f64 {
        f64::from(self.rlr + 1) * f64::from(4u32 << self.pr.min(6)) / LSI_HZ
    }

    /// Register read.
    pub fn read(&mut self, off: u32) -> Result<u32, Broken> {
        match off {
            0x00 => Ok(0),
            0x04 => Ok(self.pr),
            0x08 => Ok(self.rlr),
            // SR: PVU/RVU/WVU update flags (the update is not timed: always 0).
            0x0C => Ok(0),
            0x10 => Ok(0xFFF),
            _ => Err(unknown("IWDG", off)),
        }
    }

    /// Register write at `now` \[s\]: keys 0xCCCC start, 0x5555 unlock, 0xAAAA reload
    /// (RM0440 §42.4.1); PR/RLR/WINR are write-protected without the unlock key (§42.3.6).
    pub fn write(&mut self, off: u32, value: u32, now: f64) -> Result<(), Broken> {
        match off {
            0x00 => match value & 0xFFFF {
                0xCCCC => {
                    if self.expires_at.is_none() {
                        self.expires_at = Some(now + self.timeout_s());
                    }
                    self.unlocked = false;
                }
                0x5555 => self.unlocked = true,
                0xAAAA => {
                    self.unlocked = false;
                    if self.expires_at.is_some() {
                        self.expires_at = Some(now + self.timeout_s());
                        self.refreshes += 1;
                    }
                }
                _ => self.unlocked = false,
            },
            0x04 | 0x08 | 0x10 => {
                if !self.unlocked {
                    return Err(Broken::new(
                        "IWDG",
                        "PR/RLR/WINR written without the 0x5555 key: write-protected (RM0440 §42.3.6)",
                    ));
                }
                match off {
                    0x04 => self.pr = value & 7,
                    0x08 => self.rlr = value & 0xFFF,
                    _ => {}
                }
            }
            _ => return Err(unknown("IWDG", off)),
        }
        Ok(())
    }
}

/// SYSCFG: CFGR2's lock bits are set-only until reset (RM0440 §10.2.8).
#[derive(Debug, Default)]
pub struct Syscfg {
    regs: [u32; 10],
}

impl Syscfg {
    /// SYSCFG_CFGR2.CLL: the Cortex-M4 LOCKUP output drives TIM1's break.
    pub fn lockup_to_break(&self) -> bool {
        self.regs[7] & 1 != 0
    }

    /// Register read.
    pub fn read(&mut self, off: u32) -> Result<u32, Broken> {
        match off {
            0x00..=0x24 if off.is_multiple_of(4) => Ok(self.regs[(off / 4) as usize]),
            _ => Err(unknown("SYSCFG", off)),
        }
    }

    /// Register write.
    pub fn write(&mut self, off: u32, value: u32) -> Result<(), Broken> {
        match off {
            // CFGR2 bits 0–3 (CLL, SPL, PVDL, ECCL) set-only; SPF (bit 8) rc_w1.
            0x1C => {
                let i = 7;
                self.regs[i] = (self.regs[i] & 0xF) | (value & 0xF);
            }
            0x00..=0x24 if off.is_multiple_of(4) => self.regs[(off / 4) as usize] = value,
            _ => return Err(unknown("SYSCFG", off)),
        }
        Ok(())
    }
}

/// NVIC interrupt number of ADC1_2 on the STM32G474 (RM0440 §16.3, Table 97).
pub const IRQ_ADC1_2: u32 = 18;

/// The system control space (0xE000_E000–0xE000_EFFF) and DBGMCU.
#[derive(Debug)]
pub struct Scs {
    /// NVIC_ISERn as enabled bits (ICER clears).
    pub enabled: [u32; 8],
    /// Pending bits.
    pub pending: [u32; 8],
    ipr: [u8; 240],
    /// SCB words from 0xED00 to 0xED8C, and the MPU from 0xED90 to 0xEDBC.
    scb: [u32; 0x90 / 4],
    mpu: [u32; 12],
    /// FPCCR, FPCAR, FPDSCR.
    fp: [u32; 3],
    /// SysTick CSR, RVR, CVR.
    pub systick: [u32; 3],
    /// DBGMCU IDCODE..APB2FZR.
    dbgmcu: [u32; 5],
}

impl Default for Scs {
    fn default() -> Self {
        let mut scb = [0; 0x90 / 4];
        // CPUID of a Cortex-M4 r0p1 (ARM DDI 0439B, 0x410F_C241); CCR reset 0x0000_0200
        // (STKALIGN, ARMv7-M B3.2.8).
        scb[0] = 0x410F_C241;
        scb[0x14 / 4] = 0x0000_0200;
        Self {
            enabled: [0; 8],
            pending: [0; 8],
            ipr: [0; 240],
            scb,
            mpu: [0; 12],
            // FPCCR reset 0xC000_0000 (ASPEN, LSPEN, ARMv7-M B3.2.19).
            fp: [0xC000_0000, 0, 0],
            systick: [0; 3],
            // DBGMCU_IDCODE of the STM32G47x (RM0440 §47.6.1: DEV_ID 0x469).
            dbgmcu: [0x1000_6469, 0, 0, 0, 0],
        }
    }
}

impl Scs {
    /// IRQ `n` is enabled and pending.
    pub fn active_irq(&self) -> Option<u32> {
        (0..240u32).find(|&n| {
            let (w, b) = ((n / 32) as usize, n % 32);
            self.enabled[w] & self.pending[w] & (1 << b) != 0
        })
    }

    /// Sets or clears a pending bit.
    pub fn set_pending(&mut self, n: u32, on: bool) {
        let (w, b) = ((n / 32) as usize, n % 32);
        if on {
            self.pending[w] |= 1 << b;
        } else {
            self.pending[w] &= !(1 << b);
        }
    }

    /// Priority of IRQ `n` as the NVIC holds it: the upper four bits of its IPR byte
    /// (the STM32G4 implements 4 priority bits, PM0214 §4.3.7; the lower
    /// bits read as zero).
    pub fn priority(&self, n: u32) -> u8 {
        self.ipr.get(n as usize).copied().unwrap_or(0) & 0xF0
    }

    /// A byte or half-word read of NVIC_IPR at `off` (from 0xE000_0000).
    pub fn read_ipr(&self, off: u32, size: usize) -> u32 {
        let i = (off - 0xE400) as usize;
        (0..size).fold(0, |acc, k| acc | (u32::from(self.ipr[i + k] & 0xF0) << (8 * k)))
    }

    /// A byte or half-word write of NVIC_IPR (byte-accessible, ARMv7-M B3.4.9).
    pub fn write_ipr(&mut self, off: u32, size: usize, value: u32) {
        let i = (off - 0xE400) as usize;
        for k in 0..size {
            self.ipr[i + k] = (value >> (8 * k)) as u8 & 0xF0;
        }
    }

    /// VTOR.
    pub fn vtor(&self) -> u32 {
        self.scb[2]
    }

    /// Read at offset `off` from 0xE000_0000.
    pub fn read(&mut self, off: u32) -> Result<u32, Broken> {
        Ok(match off {
            0xE010..=0xE018 => self.systick[((off - 0xE010) / 4) as usize],
            0xE01C => 0,
            0xE100..=0xE11C => self.enabled[((off - 0xE100) / 4) as usize],
            0xE180..=0xE19C => self.enabled[((off - 0xE180) / 4) as usize],
            0xE200..=0xE21C => self.pending[((off - 0xE200) / 4) as usize],
            0xE280..=0xE29C => self.pending[((off - 0xE280) / 4) as usize],
            0xE400..=0xE4EC => self.read_ipr(off, 4),
            0xED00..=0xED8C => self.scb[((off - 0xED00) / 4) as usize],
            0xED90..=0xEDBC => self.mpu[((off - 0xED90) / 4) as usize],
            0xEF34..=0xEF3C => self.fp[((off - 0xEF34) / 4) as usize],
            0x4_2000..=0x4_2010 => self.dbgmcu[((off - 0x4_2000) / 4) as usize],
            _ => return Err(unknown("SCS", off + 0xE000_0000)),
        })
    }

    /// Write at offset `off` from 0xE000_0000.
    pub fn write(&mut self, off: u32, value: u32) -> Result<(), Broken> {
        match off {
            0xE010 => {
                if value & 1 != 0 {
                    return Err(Broken::new(
                        "SYST_CSR",
                        "SysTick enabled: its counter and exception are not modelled (the image does not use it)",
                    ));
                }
                self.systick[0] = value & 0x7;
            }
            0xE014 => self.systick[1] = value & 0x00FF_FFFF,
            0xE018 => self.systick[2] = 0,
            0xE100..=0xE11C => self.enabled[((off - 0xE100) / 4) as usize] |= value,
            0xE180..=0xE19C => self.enabled[((off - 0xE180) / 4) as usize] &= !value,
            0xE200..=0xE21C => self.pending[((off - 0xE200) / 4) as usize] |= value,
            0xE280..=0xE29C => self.pending[((off - 0xE280) / 4) as usize] &= !value,
            0xE400..=0xE4EC => self.write_ipr(off, 4, value),
            0xED00 => return Err(Broken::new("SCB_CPUID", "read-only (ARMv7-M B3.2.3)")),
            0xED04..=0xED8C => self.scb[((off - 0xED00) / 4) as usize] = value,
            0xED90 => return Err(Broken::new("MPU_TYPE", "read-only (ARMv7-M B3.5.5)")),
            0xED94..=0xEDBC => self.mpu[((off - 0xED90) / 4) as usize] = value,
            0xEF34..=0xEF3C => self.fp[((off - 0xEF34) / 4) as usize] = value,
            0x4_2004..=0x4_2010 => self.dbgmcu[((off - 0x4_2000) / 4) as usize] = value,
            _ => return Err(unknown("SCS", off + 0xE000_0000)),
        }
        Ok(())
    }
}
