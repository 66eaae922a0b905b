//! Register values computed from the board's constants (pure, host-tested), so that the
//! board layer (`../app/src/board/`) only writes them: GPIO mode/alternate-function/speed
//! fields, the ADC injected sequence and sampling times, the one TIM1_BDTR write, the
//! ADC trigger at the board's sampling instant.
//!
//! An emulator (or a reviewer) can compare every value here with RM0440's register
//! descriptions without running the firmware.
#![forbid(unsafe_code)]

/// A read-modify-write of one 32-bit register: `new = (old & !mask) | value`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Field {
    /// Bits written.
    pub mask: u32,
    /// Their new value.
    pub value: u32,
}

impl Field {
    /// The register value after the write.
    pub const fn apply(self, old: u32) -> u32 {
        (old & !self.mask) | self.value
    }

    const fn or(self, other: Field) -> Field {
        Field {
            mask: self.mask | other.mask,
            value: self.value | other.value,
        }
    }
}

/// GPIO ports the firmware configures: A, B, C (the LQFP64's PD2, PF0/1, PG10 carry no
/// signal the board files may name for gates, break, excitation or CAN on this package;
/// a pin on another port is refused at compile time by [`port_config`]).
pub const PORTS: usize = 3;

/// The GPIO writes of one port (RM0440 GPIO registers: MODER 2 bits/pin, OSPEEDR 2 bits/pin,
/// AFRL pins 0–7 and AFRH pins 8–15, 4 bits each).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PortConfig {
    /// MODER: 0b10 (alternate function) for each pin.
    pub moder: Field,
    /// OSPEEDR: 0b11 (very high speed) for each pin.
    pub ospeedr: Field,
    /// AFRL.
    pub afrl: Field,
    /// AFRH.
    pub afrh: Field,
}

/// Port index (A = 0) and pin number of a `port·16 + pin` code.
pub const fn split(code: u8) -> (usize, u32) {
    ((code / 16) as usize, (code % 16) as u32)
}

/// The alternate-function configuration of `pins` (codes `port·16 + pin`) with `afs`,
/// per port A, B, C. `None` if a pin is on another port or an AF is above 15.
pub const fn port_config(pins: &[u8], afs: &[u8]) -> Option<[PortConfig; PORTS]> {
    let mut out = [PortConfig {
        moder: Field { mask: 0, value: 0 },
        ospeedr: Field { mask: 0, value: 0 },
        afrl: Field { mask: 0, value: 0 },
        afrh: Field { mask: 0, value: 0 },
    }; PORTS];
    if pins.len() != afs.len() {
        return None;
    }
    let mut k = 0;
    while k < pins.len() {
        let (port, n) = split(pins[k]);
        let af = afs[k] as u32;
        if port >= PORTS || af > 15 {
            return None;
        }
        let p = &mut out[port];
        p.moder = p.moder.or(Field {
            mask: 0b11 << (2 * n),
            value: 0b10 << (2 * n),
        });
        p.ospeedr = p.ospeedr.or(Field {
            mask: 0b11 << (2 * n),
            value: 0b11 << (2 * n),
        });
        let f = Field {
            mask: 0xF << (4 * (n % 8)),
            value: af << (4 * (n % 8)),
        };
        if n < 8 {
            p.afrl = p.afrl.or(f);
        } else {
            p.afrh = p.afrh.or(f);
        }
        k += 1;
    }
    Some(out)
}

/// MODER write that makes `pins` general-purpose outputs (0b01), per port (the fault
/// path drives the gate pins low independently of the timer).
pub const fn output_mode(pins: &[u8]) -> [Field; PORTS] {
    let mut out = [Field { mask: 0, value: 0 }; PORTS];
    let mut k = 0;
    while k < pins.len() {
        let (port, n) = split(pins[k]);
        if port < PORTS {
            out[port] = out[port].or(Field {
                mask: 0b11 << (2 * n),
                value: 0b01 << (2 * n),
            });
        }
        k += 1;
    }
    out
}

/// BSRR value that resets (drives low) `pins` of each port (BRy, bits 16–31).
pub const fn reset_bits(pins: &[u8]) -> [u32; PORTS] {
    let mut out = [0; PORTS];
    let mut k = 0;
    while k < pins.len() {
        let (port, n) = split(pins[k]);
        if port < PORTS {
            out[port] |= 1 << (16 + n);
        }
        k += 1;
    }
    out
}

/// BSRR value that drives each of `pins` to its level in `levels` (1: set, BSy bits
/// 0–15; 0: reset, BRy bits 16–31; RM0440 GPIOx_BSRR), per port: the fault path's
/// write that turns every switch off whatever its driver's input logic.
pub const fn level_bits(pins: &[u8], levels: &[u8]) -> [u32; PORTS] {
    let mut out = [0; PORTS];
    let mut k = 0;
    while k < pins.len() && k < levels.len() {
        let (port, n) = split(pins[k]);
        if port < PORTS {
            out[port] |= if levels[k] != 0 { 1 << n } else { 1 << (16 + n) };
        }
        k += 1;
    }
    out
}

/// GPIOx_PUPDR write giving `pin` the pull `code` (RM0440 GPIOx_PUPDR, 2 bits per pin:
/// 00 none, 01 pull-up, 10 pull-down), per port.
pub const fn pull(pin: u8, code: u8) -> [Field; PORTS] {
    let mut out = [Field { mask: 0, value: 0 }; PORTS];
    let (port, n) = split(pin);
    if port < PORTS {
        out[port] = Field {
            mask: 0b11 << (2 * n),
            value: ((code & 0b11) as u32) << (2 * n),
        };
    }
    out
}

/// TIMx_CCER of the three PWM channels (RM0440 TIMx_CCER): CC1E, CC1NE, CC2E, CC2NE,
/// CC3E, CC3NE set (bits 0, 2, 4, 6, 8, 10 = 0x555), with the board's polarity bits
/// CCxP/CCxNP (`motor::board::TIM1_CCER_POLARITY`, only bits 1, 3, 5, 7, 9, 11 taken).
pub const fn ccer(polarity: u32) -> u32 {
    0x555 | (polarity & 0xAAA)
}

/// TIMx_CR2 (RM0440 TIMx_CR2): MMS (bits 6:4) and MMS2 (bits 23:20) = OC4REF, and the
/// board's idle levels OIS1..OIS3N (`motor::board::TIM1_CR2_IDLE`, only bits 8–13
/// taken). Written before BDTR: LOCK level 1 freezes OISx/OISxN (RM0440 TIMx_BDTR).
pub const fn cr2(idle: u32) -> u32 {
    ((MMS_OC4REF as u32 & 0b111) << 4) | ((MMS_OC4REF as u32 & 0xF) << 20) | (idle & 0x3F00)
}

/// ADC_JSQR.JEXTSEL of TIM1_TRGO2 for ADC1/ADC2 injected conversions (RM0440 ADC chapter, table
/// "ADC1/2 external triggers for injected channels"; ST's LL: `LL_ADC_INJ_TRIG_EXT_TIM1_TRGO2 = ADC_JSQR_JEXTSEL_3`).
pub const JEXTSEL_TIM1_TRGO2: u32 = 8;

/// ADC_JSQR for `channels` (1 to 4 ranks), triggered on the rising edge (JEXTEN = 01)
/// of TIM1_TRGO2 (RM0440, ADC_JSQR: JL bits 1:0 = ranks − 1, JEXTSEL 6:2, JEXTEN 8:7,
/// JSQ1 13:9, JSQ2 19:15, JSQ3 25:21, JSQ4 31:27). `None` for 0 or more than 4 ranks
/// or a channel above 18.
pub const fn jsqr(channels: &[u8]) -> Option<u32> {
    let n = channels.len();
    if n == 0 || n > 4 {
        return None;
    }
    let mut v = (n as u32 - 1) | (JEXTSEL_TIM1_TRGO2 << 2) | (0b01 << 7);
    let shifts = [9, 15, 21, 27];
    let mut k = 0;
    while k < n {
        if channels[k] > 18 {
            return None;
        }
        v |= (channels[k] as u32) << shifts[k];
        k += 1;
    }
    Some(v)
}

/// ADC_SMPR1 (channels 0–9) and ADC_SMPR2 (10–18) writes for the sampling codes of
/// `channels` (RM0440, ADC_SMPR1/2: 3 bits per channel).
pub const fn smpr(channels: &[u8], codes: &[u8]) -> [Field; 2] {
    let mut out = [Field { mask: 0, value: 0 }; 2];
    let mut k = 0;
    while k < channels.len() && k < codes.len() {
        let ch = channels[k] as u32;
        let (reg, pos) = if ch < 10 { (0, ch) } else { (1, ch - 10) };
        out[reg] = out[reg].or(Field {
            mask: 0b111 << (3 * pos),
            value: ((codes[k] & 0b111) as u32) << (3 * pos),
        });
        k += 1;
    }
    out
}

/// TIM1_BDTR in one write (RM0440, TIMx_BDTR; as ST's `HAL_TIMEx_ConfigBreakDeadTime`
/// assembles it in a variable and writes it once): DTG, LOCK, OSSI, OSSR, BKE, BKP,
/// BKF, AOE = 0, MOE = 0. LOCK and the fields it protects are write-once after reset,
/// so a second write (the old firmware's `modify` for LOCK) never takes effect.
pub const fn bdtr(dtg: u8, break_active_high: bool, break_filter: u8, lock: u8) -> u32 {
    let dtg = dtg as u32; // bits 7:0
    let lock = ((lock & 0b11) as u32) << 8;
    let ossi = 1 << 10;
    let ossr = 1 << 11;
    let bke = 1 << 12;
    let bkp = (break_active_high as u32) << 13;
    let bkf = ((break_filter & 0xF) as u32) << 16;
    dtg | lock | ossi | ossr | bke | bkp | bkf
}

/// ADC_CR.ADEN (RM0440 §21.7.3).
pub const ADC_CR_ADEN: u32 = 1;
/// ADC_CR.JADSTART (RM0440 §21.7.3).
pub const ADC_CR_JADSTART: u32 = 1 << 3;
/// ADC_CR.ADCAL (RM0440 §21.7.3).
pub const ADC_CR_ADCAL: u32 = 1 << 31;
/// ADC_CR.DEEPPWD (RM0440 §21.7.3): deep power-down, 1 after reset.
pub const ADC_CR_DEEPPWD: u32 = 1 << 29;
/// ADC_CR.ADVREGEN (RM0440 §21.7.3): the ADC's voltage regulator.
pub const ADC_CR_ADVREGEN: u32 = 1 << 28;
/// ADC_CR.ADCALDIF (RM0440 §21.7.3): 0 calibrates the single-ended inputs.
pub const ADC_CR_ADCALDIF: u32 = 1 << 30;
/// ADC_CR's set-only ("rs") bits: ADCAL, JADSTP, ADSTP, JADSTART, ADSTART, ADDIS, ADEN
/// (RM0440 §21.7.3; ST's LL calls the set `ADC_CR_BITS_PROPERTY_RS`).
pub const ADC_CR_SET_ONLY: u32 = ADC_CR_ADCAL | 0x3F;

/// The ADC_CR value that commands `bit` (one of the set-only bits) and nothing else, from
/// the register's current value `cr`: the read/write bits (DEEPPWD, ADVREGEN, ADCALDIF)
/// kept, every other set-only bit written 0 (a 0 has no effect on them, RM0440 §21.7.3).
/// A read-modify-write instead writes back the ADEN that reads 1 next to the command —
/// re-enabling an enabled converter, which ST's HAL warns against; ST's LL does the
/// same masking (`MODIFY_REG(ADCx->CR, ADC_CR_BITS_PROPERTY_RS, bit)` in
/// `LL_ADC_INJ_StartConversion`, `LL_ADC_Enable`, `LL_ADC_StartCalibration`).
pub const fn adc_cr_command(cr: u32, bit: u32) -> u32 {
    (cr & !ADC_CR_SET_ONLY) | (bit & ADC_CR_SET_ONLY)
}

/// TIMx_BDTR.LOCK level 1: DTG, BKE, BKP, AOE, OSSI, OSSR and BKF cannot be written
/// again until reset (RM0440, TIMx_BDTR).
pub const LOCK_LEVEL_1: u8 = 0b01;

/// TIMx_RCR before the counter starts, and after, for the update event one carrier
/// period after the board's sampling instant (RM0440 TIM1 "Repetition counter": in
/// centre-aligned mode the repetition counter REP_CNT counts overflows and underflows,
/// an update event comes when it has run down and reloads it from RCR; "for odd values
/// of RCR, the update event occurs either on the overflow or on the underflow depending
/// on when the RCR register was written and when the counter was launched: if the RCR
/// was written before launching the counter, the UEV occurs on the underflow. If the RCR
/// was written after launching the counter, the UEV occurs on the overflow").
///
/// * Sampling at the carrier minimum: RCR = 1 before the UG that loads REP_CNT and
///   before the start: the update at every underflow.
/// * Sampling at the carrier maximum (low-side shunts): RCR = 0 at the UG (REP_CNT = 0)
///   and RCR = 1 written right after the start, before the first overflow half a period
///   later: the update at every overflow.
///
/// Either way the compare values a control step computes from a trigger's conversions
/// take effect one period after the trigger and hold for one period: the loop delay of
/// thesis A §4.6, 1.5·T_s, less the time from the trigger to the end of the currents'
/// sampling phases (`codegen`'s `sections::board::control_timing`, which the current loop
/// is designed with). With the
/// update at the underflow and the sample at the maximum they would act after half a
/// period: a faster loop than designed. Returns (RCR at init, RCR after the start —
/// `None`: no write).
pub const fn repetition(at_carrier_maximum: bool) -> (u8, Option<u8>) {
    if at_carrier_maximum { (0, Some(1)) } else { (1, None) }
}

/// OCxM codes (RM0440, TIMx_CCMR1/2 OCxM): PWM mode 1 (active while CNT < CCR) and 2.
pub const PWM_MODE_1: u8 = 0b110;
/// PWM mode 2: active while CNT ≥ CCR (up-counting).
pub const PWM_MODE_2: u8 = 0b111;
/// TIMx_CR2.MMS / MMS2 code of OC4REF(C) as TRGO / TRGO2 (RM0440, TIMx_CR2:
/// MMS = 111; MMS2 = 0111; ST's LL: `LL_TIM_TRGO_OC4REF`, `LL_TIM_TRGO2_OC4`).
pub const MMS_OC4REF: u8 = 0b0111;

/// Where the ADC trigger (and the resolver excitation's reset) falls in the carrier.
///
/// Centre-aligned mode 1 counts 0 → ARR → 0. PWM mode 1 on CH1–3 makes a high side
/// conduct while CNT < CCRx, so around the carrier minimum (CNT = 0) the high sides
/// conduct and around the maximum (CNT = ARR) the low sides do. The update event does
/// *not* mark the sampling instant by itself: it comes once per period, at the underflow
/// or at the overflow as [`repetition`] sets it up (RM0440 §28.3.5, Figure "update rate
/// examples depending on mode and TIMx_RCR"). So the trigger comes from channel 4:
/// OC4REF as TRGO2 for the ADC and as TRGO for TIM3.
///
/// * Carrier maximum (low-side centre): PWM mode 2 with CCR4 = ARR − 1: OC4REF rises
///   when the up-count reaches ARR − 1, one timer tick (5.9 ns at 170 MHz) before the
///   peak.
/// * Carrier minimum (high-side centre): PWM mode 1 with CCR4 = 1: OC4REF rises when the
///   down-count passes below 1, at CNT = 0.
///
/// Returns (OC4M, CCR4).
pub const fn trigger_channel(at_carrier_maximum: bool, arr: u16) -> (u8, u16) {
    if at_carrier_maximum {
        (PWM_MODE_2, arr.saturating_sub(1))
    } else {
        (PWM_MODE_1, 1)
    }
}

/// FLASH_OPTR bits for the boot source (RM0440 §3.7.8, §3.4.1): nSWBOOT0 (bit 26) = 0
/// takes BOOT0 from the nBOOT0 option bit (bit 27) instead of the PB8-BOOT0 pin, and
/// nBOOT0 = 1 selects the main flash.
pub const OPTR_NSWBOOT0: u32 = 1 << 26;
/// nBOOT0.
pub const OPTR_NBOOT0: u32 = 1 << 27;

/// Whether FLASH_OPTR makes the MCU boot from flash whatever the PB8-BOOT0 pin does:
/// nSWBOOT0 = 0 and nBOOT0 = 1. With the factory value (nSWBOOT0 = 1) a CAN
/// transceiver's idle-high RXD on PB8 starts the system bootloader at the next reset.
pub const fn boots_from_flash_regardless_of_pb8(optr: u32) -> bool {
    optr & OPTR_NSWBOOT0 == 0 && optr & OPTR_NBOOT0 != 0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An enabled, calibrated converter (DEEPPWD 0, ADVREGEN 1 = bit 28, ADCALDIF 0, ADEN
    /// 1): JADSTART is written as 0x1000_0008 — the regulator kept, ADEN not written
    /// again (hand-assembled from RM0440 §21.7.3's bit positions). A converter in deep
    /// power-down with the differential-calibration bit (0x6000_0000) keeps both.
    #[test]
    fn adc_cr_commands_write_only_their_bit() {
        assert_eq!(adc_cr_command(0x1000_0001, ADC_CR_JADSTART), 0x1000_0008);
        assert_eq!(adc_cr_command(0x1000_0000, ADC_CR_ADEN), 0x1000_0001);
        assert_eq!(adc_cr_command(0x1000_0000, ADC_CR_ADCAL), 0x9000_0000);
        assert_eq!(adc_cr_command(0x6000_0000, 0), 0x6000_0000);
        // A running injected sequence (JADSTART reads 1) is not re-started by ADEN.
        assert_eq!(adc_cr_command(0x1000_0009, ADC_CR_ADEN), 0x1000_0001);
        // Only set-only bits are commands: a read/write bit passed as `bit` is dropped.
        assert_eq!(adc_cr_command(0x1000_0001, 1 << 29), 0x1000_0000);
    }

    /// The reference board's gates PA8, PA9, PA10 (AF6), PB13, PB14 (AF6), PB15 (AF4):
    /// hand-assembled register values (RM0440 GPIO registers): port A MODER bits 16–21 = 10 10 10
    /// (mask 0x003F_0000, value 0x002A_0000), AFRH of pins 8–10 = 6 (0x0000_0666);
    /// port B MODER bits 26–31 (0xFC00_0000 / 0xA800_0000), AFRH pins 13–15 = 6, 6, 4
    /// (0x4660_0000 in mask 0xFFF0_0000).
    #[test]
    fn gpio_fields_by_hand() {
        let pins = [0x08, 0x09, 0x0A, 0x1D, 0x1E, 0x1F];
        let afs = [6, 6, 6, 6, 6, 4];
        let c = port_config(&pins, &afs).unwrap();
        assert_eq!(
            c[0].moder,
            Field {
                mask: 0x003F_0000,
                value: 0x002A_0000
            }
        );
        assert_eq!(
            c[0].afrh,
            Field {
                mask: 0x0000_0FFF,
                value: 0x0000_0666
            }
        );
        assert_eq!(c[0].afrl, Field::default());
        assert_eq!(
            c[1].moder,
            Field {
                mask: 0xFC00_0000,
                value: 0xA800_0000
            }
        );
        assert_eq!(
            c[1].afrh,
            Field {
                mask: 0xFFF0_0000,
                value: 0x4660_0000
            }
        );
        assert_eq!(c[1].ospeedr.value, 0xFC00_0000);
        // A pin elsewhere in the register is kept: reset MODER of port A is 0xABFF_FFFF
        // (RM0440 GPIOA_MODER reset value: PA13/PA14/PA15 in their debug AF).
        assert_eq!(c[0].moder.apply(0xABFF_FFFF), 0xABEA_FFFF);
        // Output mode and BSRR reset bits of the same pins.
        assert_eq!(
            output_mode(&pins)[1],
            Field {
                mask: 0xFC00_0000,
                value: 0x5400_0000
            }
        );
        assert_eq!(reset_bits(&pins), [0x0700_0000, 0xE000_0000, 0]);
        assert_eq!(port_config(&[0x32], &[1]), None); // port D
        assert_eq!(port_config(&[0x08], &[16]), None);
    }

    /// The NUCLEO's gates PA8, PA9, PA10, PA7, PB0, PB1 with the L6398's off levels
    /// 0, 0, 0, 1, 1, 1: port A sets PA7 (bit 7) and resets PA8–PA10 (bits 24–26),
    /// port B sets PB0, PB1 (bits 0, 1) — 0x0700_0080 and 0x0000_0003. PA6 pulled up:
    /// PUPDR bits 12–13 = 01.
    #[test]
    fn gate_off_levels_and_break_pull_by_hand() {
        let pins = [0x08, 0x09, 0x0A, 0x07, 0x10, 0x11];
        assert_eq!(level_bits(&pins, &[0, 0, 0, 1, 1, 1]), [0x0700_0080, 0x0000_0003, 0]);
        assert_eq!(level_bits(&pins, &[0; 6]), [0x0780_0000, 0x0003_0000, 0]);
        assert_eq!(
            pull(0x06, 0b01)[0],
            Field {
                mask: 0b11 << 12,
                value: 0b01 << 12
            }
        );
        assert_eq!(pull(0x06, 0b01)[1], Field::default());
    }

    /// The update event's place, by hand from RM0440 §28.3.5's rule (RCR written before
    /// the launch: underflow; after it: overflow): sampling at the minimum keeps RCR = 1
    /// throughout; at the maximum RCR = 0 goes into REP_CNT at the UG and 1 is written
    /// after the launch.
    #[test]
    fn repetition_puts_the_update_at_the_sampling_instant() {
        assert_eq!(repetition(false), (1, None));
        assert_eq!(repetition(true), (0, Some(1)));
    }

    /// CCER with every output enabled (0x555) and the L6398's CC1NP..CC3NP (0x888):
    /// 0xDDD; CR2 with MMS = 111 (0x70), MMS2 = 0111 (0x70_0000) and OIS1N..OIS3N
    /// (0x2A00): 0x0070_2A70. Stray bits outside the fields are dropped.
    #[test]
    fn polarity_and_idle_registers_by_hand() {
        assert_eq!(ccer(0x888), 0xDDD);
        assert_eq!(ccer(0), 0x555);
        assert_eq!(ccer(0xFFFF_FFFF), 0xFFF);
        assert_eq!(cr2(0x2A00), 0x0070_2A70);
        assert_eq!(cr2(0), 0x0070_0070);
        assert_eq!(cr2(0xFFFF_FFFF), 0x0070_3F70);
    }

    /// JSQR of ADC2 on the reference board (IN3, IN4, IN17), TRGO2, rising edge:
    /// JL = 2, JEXTSEL 8 << 2 = 0x20, JEXTEN 1 << 7 = 0x80, 3 << 9, 4 << 15, 17 << 21 →
    /// 0x2 | 0x20 | 0x80 | 0x600 | 0x2_0000 | 0x220_0000 = 0x0222_06A2.
    #[test]
    fn injected_sequence_by_hand() {
        assert_eq!(jsqr(&[3, 4, 17]), Some(0x0222_06A2));
        assert_eq!(jsqr(&[1]), Some(0x0000_02A0));
        assert_eq!(jsqr(&[]), None);
        assert_eq!(jsqr(&[1, 2, 3, 4, 5]), None);
        assert_eq!(jsqr(&[19]), None);
    }

    /// IN17 at code 3 (24.5 cycles) → SMPR2 bits 21–23 = 011; IN3 code 1 → SMPR1 bits
    /// 9–11 = 001.
    #[test]
    fn sampling_registers_by_hand() {
        let [r1, r2] = smpr(&[3, 17], &[1, 3]);
        assert_eq!(
            r1,
            Field {
                mask: 0b111 << 9,
                value: 1 << 9
            }
        );
        assert_eq!(
            r2,
            Field {
                mask: 0b111 << 21,
                value: 3 << 21
            }
        );
    }

    /// 500 ns at 170 MHz → DTG 85 (0x55); LOCK 1 (0x100); OSSI, OSSR (0xC00); BKE
    /// (0x1000); BKP = 0 for active low; BKF 3 (0x3_0000): 0x0003_1D55 — one value with
    /// the lock in it, MOE and AOE clear.
    #[test]
    fn break_dead_time_register_in_one_write() {
        assert_eq!(bdtr(85, false, 0b0011, LOCK_LEVEL_1), 0x0003_1D55);
        assert_eq!(bdtr(85, true, 0b0011, LOCK_LEVEL_1), 0x0003_3D55);
        let moe = 1 << 15;
        let aoe = 1 << 14;
        assert_eq!(bdtr(0xFF, true, 0xF, 0b11) & (moe | aoe), 0);
    }

    /// The trigger is one tick before the peak for low-side shunts, at zero otherwise.
    #[test]
    fn trigger_at_the_board_instant() {
        assert_eq!(trigger_channel(true, 4250), (PWM_MODE_2, 4249));
        assert_eq!(trigger_channel(false, 4250), (PWM_MODE_1, 1));
    }

    /// As delivered nSWBOOT0 = nBOOT0 = 1 (RM0440 §3.4.1, boot configuration): the PB8
    /// level decides; with nSWBOOT0 cleared and nBOOT0 set the pin is ignored.
    #[test]
    fn option_bytes_boot_source() {
        let factory = OPTR_NSWBOOT0 | OPTR_NBOOT0 | 0x0000_00AA;
        assert!(!boots_from_flash_regardless_of_pb8(factory));
        assert!(boots_from_flash_regardless_of_pb8(factory & !OPTR_NSWBOOT0));
        assert!(!boots_from_flash_regardless_of_pb8(
            factory & !OPTR_NSWBOOT0 & !OPTR_NBOOT0
        ));
    }
}
