//! ADC1/ADC2 (RM0440 §21): deep power-down, the voltage regulator, calibration, enable,
//! and the injected sequence started by a hardware trigger, its conversion time from
//! the sampling codes, JEOC/JEOS and the injected data registers. Conversion codes come
//! from the test (the bus asks its analog source at each rank's sampling instant).

use super::clock::unknown;
use crate::violation::Broken;

/// ADC_CR bits (RM0440 §21.7.3).
const ADEN: u32 = 1;
const ADDIS: u32 = 1 << 1;
const ADSTART: u32 = 1 << 2;
const JADSTART: u32 = 1 << 3;
const ADVREGEN: u32 = 1 << 28;
const DEEPPWD: u32 = 1 << 29;
const ADCAL: u32 = 1 << 31;
/// The set-only bits of ADC_CR.
const RS_BITS: u32 = ADCAL | 0x3F;
/// ADC_ISR bits (RM0440 §21.7.1).
const ADRDY: u32 = 1;
const JEOC: u32 = 1 << 5;
const JEOS: u32 = 1 << 6;

/// t_ADCVREG_STUP, the regulator start-up time \[s\] (DS12288 Table 66: 20 µs max).
pub const VREG_STARTUP_S: f64 = 20e-6;
/// Calibration time t_CAL in ADC clock cycles (RM0440 §21.4.8: "the calibration lasts
/// 116 ADC clock cycles" for single-ended inputs; DS12288 Table 66 t_CAL).
pub const CALIBRATION_CYCLES: f64 = 116.0;
/// ADEN cannot be set for 4 ADC clock cycles after ADCAL clears (RM0440 §21.4.9).
pub const ADEN_BLACKOUT_CYCLES: f64 = 4.0;
/// ADRDY polls after a lost ADEN write without ADEN written again: the enable was never
/// retried (the image's defect 1 before the fix).
pub const ADRDY_POLLS_WITHOUT_RETRY: u32 = 3;
/// JEXTSEL of TIM1_TRGO2 for ADC1/2 injected conversions (RM0440 §21.4.19, Table 164:
/// adc_jext_trg8).
pub const JEXTSEL_TIM1_TRGO2: u32 = 8;
/// SAR conversion cycles at 12 bits (RM0440 §21.4.12: t_CONV = t_SMPL + 12.5 cycles).
/// The emulator keeps its own copy of this and [`TRIGGER_LATENCY_CYCLES`], read from
/// RM0440 and DS12288, rather than codegen's: the design's timing is checked against
/// them, not taken from itself.
pub const SAR_CYCLES: f64 = 12.5;
/// From an injected hardware trigger to the first rank's sampling \[ADC cycles\]: the
/// longest injected trigger latency t_LATRINJ with the synchronous clock HCLK/4
/// (CKMODE = 0b11, DS12288 Table 66 "ADC characteristics"), the value the design's
/// conversion time and duty limit take.
pub const TRIGGER_LATENCY_CYCLES: f64 = 3.125;

/// Sampling cycles of an SMPx code (RM0440 §21.7.6, ADC_SMPR1).
pub fn sampling_cycles(code: u32) -> f64 {
    [2.5, 6.5, 12.5, 24.5, 47.5, 92.5, 247.5, 640.5][(code & 7) as usize]
}

/// Known ADC registers (RM0440 §21.7 register map).
const KNOWN: &[u32] = &[
    0x00, 0x04, 0x08, 0x0C, 0x10, 0x14, 0x18, 0x20, 0x24, 0x28, 0x30, 0x34, 0x38, 0x3C, 0x40, 0x4C, 0x60, 0x64, 0x68,
    0x6C, 0x80, 0x84, 0x88, 0x8C, 0xA0, 0xA4, 0xB0, 0xB4, 0xC0,
];

/// An injected sequence in progress: ranks still to convert, with the time each ends.
#[derive(Clone, Debug)]
pub struct Sequence {
    /// (end time in seconds, rank index, channel).
    pub ranks: Vec<(f64, usize, u8)>,
}

/// One converter.
#[derive(Debug)]
pub struct Adc {
    /// Name (`ADC1`).
    pub name: &'static str,
    regs: [u32; 0xC4 / 4],
    /// When ADVREGEN was set \[s\].
    vreg_since: Option<f64>,
    /// When the running calibration ends \[s\].
    cal_until: Option<f64>,
    /// When ADCAL last cleared \[s\].
    cal_done_at: Option<f64>,
    /// ADRDY reads since an ADEN write was lost to the calibration logic.
    lost_aden_polls: Option<u32>,
    /// ADEN writes lost so far.
    pub lost_aden_writes: u32,
    /// The injected sequence in progress.
    pub sequence: Option<Sequence>,
    /// Triggers that arrived while a sequence was still converting.
    pub missed_triggers: u32,
    /// Completed injected sequences.
    pub sequences: u64,
}

impl Adc {
    /// Reset state: ADC_CR = 0x2000_0000 (DEEPPWD, RM0440 §21.7.3), ADC_CFGR =
    /// 0x8000_0000 (JQDIS, §21.7.4), TR1 0x0FFF_0000, TR2/TR3 0x00FF_0000.
    pub fn new(name: &'static str) -> Self {
        let mut regs = [0; 0xC4 / 4];
        regs[0x08 / 4] = DEEPPWD;
        regs[0x0C / 4] = 0x8000_0000;
        regs[0x20 / 4] = 0x0FFF_0000;
        regs[0x24 / 4] = 0x00FF_0000;
        regs[0x28 / 4] = 0x00FF_0000;
        Self {
            name,
            regs,
            vreg_since: None,
            cal_until: None,
            cal_done_at: None,
            lost_aden_polls: None,
            lost_aden_writes: 0,
            sequence: None,
            missed_triggers: 0,
            sequences: 0,
        }
    }

    /// A register's value (no side effect), for reports.
    pub fn reg(&self, off: u32) -> u32 {
        self.regs[(off / 4) as usize]
    }

    fn r(&self, off: u32) -> String {
        let name = match off {
            0x00 => "ISR",
            0x04 => "IER",
            0x08 => "CR",
            0x4C => "JSQR",
            _ => "",
        };
        if name.is_empty() {
            format!("{}+{off:#04x}", self.name)
        } else {
            format!("{}_{name}", self.name)
        }
    }

    /// Sampling cycles ADC_SMPR1/2 give channel `ch` (RM0440 §21.7.6).
    pub fn smp_cycles(&self, ch: u8) -> f64 {
        let smpr = if ch < 10 { self.reg(0x14) } else { self.reg(0x18) };
        sampling_cycles(smpr >> (3 * u32::from(ch % 10)))
    }

    /// ADEN (the converter is enabled).
    pub fn enabled(&self) -> bool {
        self.reg(0x08) & ADEN != 0
    }

    /// IER.JEOSIE and ISR.JEOS: the end-of-sequence interrupt is requested.
    pub fn irq(&self) -> bool {
        self.reg(0x04) & self.reg(0x00) & JEOS != 0
    }

    /// Finishes a calibration whose time has come.
    fn advance(&mut self, now: f64) {
        if let Some(t) = self.cal_until
            && now >= t
        {
            self.regs[0x08 / 4] &= !ADCAL;
            self.cal_until = None;
            self.cal_done_at = Some(t);
        }
    }

    /// Next time this converter changes by itself.
    pub fn next_event(&self) -> Option<f64> {
        let seq = self.sequence.as_ref().and_then(|s| s.ranks.first().map(|r| r.0));
        match (self.cal_until, seq) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// A hardware trigger on JEXTSEL `source` at `now`: starts the injected sequence
    /// (JL + 1 ranks, RM0440 §21.4.19) if JADSTART is set and the trigger is selected
    /// with a rising edge. `adc_clock_s` is one ADC clock period.
    pub fn trigger(&mut self, source: u32, now: f64, adc_clock_s: f64) {
        let jsqr = self.reg(0x4C);
        let cr = self.reg(0x08);
        if cr & JADSTART == 0 || cr & ADEN == 0 || (jsqr >> 2) & 0x1F != source || (jsqr >> 7) & 3 != 1 {
            return;
        }
        if self.sequence.is_some() {
            self.missed_triggers += 1;
            return;
        }
        let ranks = (jsqr & 3) as usize + 1;
        let mut t = now + TRIGGER_LATENCY_CYCLES * adc_clock_s;
        let mut out = Vec::new();
        for rank in 0..ranks {
            let ch = ((jsqr >> (9 + 6 * rank)) & 0x1F) as u8;
            let smpr = if ch < 10 { self.reg(0x14) } else { self.reg(0x18) };
            let code = (smpr >> (3 * u32::from(ch % 10))) & 7;
            t += (sampling_cycles(code) + SAR_CYCLES) * adc_clock_s;
            out.push((t, rank, ch));
        }
        self.sequence = Some(Sequence { ranks: out });
    }

    /// Completes the ranks that have ended by `now`; `code` gives each rank's code
    /// (rank, channel, sampling end). Returns whether JEOS was set.
    pub fn complete(&mut self, now: f64, mut code: impl FnMut(u8, f64) -> u16) -> bool {
        self.advance(now);
        let Some(seq) = self.sequence.as_mut() else {
            return false;
        };
        let mut done = false;
        while let Some(&(t, rank, ch)) = seq.ranks.first() {
            if t > now {
                break;
            }
            seq.ranks.remove(0);
            self.regs[(0x80 / 4) + rank] = u32::from(code(ch, t));
            self.regs[0] |= JEOC;
            if seq.ranks.is_empty() {
                self.regs[0] |= JEOS;
                done = true;
            }
        }
        if done {
            self.sequence = None;
            self.sequences += 1;
        }
        done
    }

    /// Register read at `now` \[s\].
    pub fn read(&mut self, off: u32, now: f64) -> Result<u32, Broken> {
        if !KNOWN.contains(&off) {
            return Err(unknown(self.name, off));
        }
        self.advance(now);
        if off == 0x00
            && let Some(polls) = self.lost_aden_polls.map(|p| p + 1)
        {
            self.lost_aden_polls = Some(polls);
            {
                if polls >= ADRDY_POLLS_WITHOUT_RETRY {
                    return Err(Broken::new(
                        self.r(0),
                        format!(
                            "ADRDY polled {polls} times after an ADEN write was reset by the calibration logic \
                             (written within {ADEN_BLACKOUT_CYCLES} ADC clock cycles of ADCAL clearing, RM0440 §21.4.9) \
                             and ADEN was not written again: the converter never becomes ready"
                        ),
                    ));
                }
            }
        }
        Ok(self.reg(off))
    }

    /// Register write at `now` \[s\] with one ADC clock of `adc_clock_s` (None: no clock).
    pub fn write(&mut self, off: u32, value: u32, now: f64, adc_clock_s: Option<f64>) -> Result<(), Broken> {
        if !KNOWN.contains(&off) {
            return Err(unknown(self.name, off));
        }
        self.advance(now);
        let i = (off / 4) as usize;
        match off {
            // ISR: rc_w1 (RM0440 §21.7.1).
            0x00 => self.regs[i] &= !value,
            0x08 => return self.write_cr(value, now, adc_clock_s),
            0x80..=0x8C | 0x40 => {
                return Err(Broken::new(self.r(off), "data registers are read-only (RM0440 §21.7)"));
            }
            _ => {
                let cr = self.reg(0x08);
                // RM0440 §21.7.4–§21.7.11: configuration registers are writable only
                // while no conversion is ongoing (ADSTART = JADSTART = 0); JSQR also with
                // JADSTART = 1 (queue), which this model does not keep.
                if cr & (ADSTART | JADSTART) != 0 && off != 0x04 {
                    return Err(Broken::new(
                        self.r(off),
                        "written while a conversion is ongoing (ADSTART/JADSTART = 1, RM0440 §21.7.4–§21.7.11)",
                    ));
                }
                self.regs[i] = value;
            }
        }
        Ok(())
    }

    fn write_cr(&mut self, value: u32, now: f64, adc_clock_s: Option<f64>) -> Result<(), Broken> {
        let old = self.reg(0x08);
        let reg = self.r(0x08);
        if old & ADCAL != 0 && value & !RS_BITS != old & !RS_BITS {
            return Err(Broken::new(
                reg,
                "ADC_CR written during calibration (ADCAL = 1, RM0440 §21.4.8)",
            ));
        }
        // ADCAL, JADSTP, ADSTP, JADSTART, ADSTART, ADDIS, ADEN are set-only ("rs": writing
        // 0 has no effect, RM0440 §21.7.3); ADVREGEN, DEEPPWD, ADCALDIF read/write.
        // Writing 1 again to one that reads 1 is a read-modify-write carrying an old
        // command next to a new one (ADEN re-written with JADSTART, which ST's HAL warns
        // against; ST's LL masks the set-only bits: `ADC_CR_BITS_PROPERTY_RS`).
        let again = value & old & RS_BITS;
        if again != 0 {
            return Err(Broken::new(
                reg,
                format!(
                    "ADC_CR written with set-only bits that already read 1 (0x{again:08X}, e.g. ADEN re-written with JADSTART): write only the command meant (RM0440 §21.7.3; ST's LL masks ADC_CR_BITS_PROPERTY_RS)"
                ),
            ));
        }
        let mut v = (value & !RS_BITS) | (old & RS_BITS) | (value & RS_BITS);
        let set = v & !old;
        if set & ADVREGEN != 0 && value & DEEPPWD != 0 {
            return Err(Broken::new(
                reg,
                "ADVREGEN set while DEEPPWD = 1: leave deep power-down first (RM0440 §21.4.6)",
            ));
        }
        if set & ADVREGEN != 0 {
            self.vreg_since = Some(now);
        }
        if value & ADVREGEN == 0 {
            self.vreg_since = None;
        }
        if set & ADCAL != 0 {
            let Some(clk) = adc_clock_s else {
                return Err(Broken::new(
                    reg,
                    "ADCAL with no ADC clock (ADC12_CCR.CKMODE, RM0440 §21.4.3)",
                ));
            };
            let ready = self.vreg_since.is_some_and(|t| now - t >= VREG_STARTUP_S - 1e-12);
            if !ready {
                return Err(Broken::new(
                    reg,
                    format!(
                        "ADCAL {:.2} µs after ADVREGEN: the regulator needs t_ADCVREG_STUP = 20 µs (RM0440 §21.4.6, DS12288 Table 66)",
                        self.vreg_since.map_or(0.0, |t| (now - t) * 1e6)
                    ),
                ));
            }
            if old & ADEN != 0 {
                return Err(Broken::new(
                    reg,
                    "ADCAL with ADEN = 1: calibrate a disabled ADC (RM0440 §21.4.8)",
                ));
            }
            self.cal_until = Some(now + CALIBRATION_CYCLES * clk);
        }
        if set & ADEN != 0 {
            if v & ADCAL != 0 || old & ADCAL != 0 {
                return Err(Broken::new(reg, "ADEN set during calibration (RM0440 §21.4.9)"));
            }
            let blackout = adc_clock_s.map_or(0.0, |c| ADEN_BLACKOUT_CYCLES * c);
            if self.cal_done_at.is_some_and(|t| now - t < blackout) {
                // RM0440 §21.4.9: "ADEN bit cannot be set during ADCAL=1 and 4 ADC clock
                // cycles after the ADCAL bit is cleared by hardware": the write is lost.
                v &= !ADEN;
                self.lost_aden_writes += 1;
                self.lost_aden_polls = Some(0);
            } else {
                if self.vreg_since.is_none() {
                    return Err(Broken::new(
                        reg,
                        "ADEN with the regulator off (ADVREGEN = 0, RM0440 §21.4.9)",
                    ));
                }
                self.lost_aden_polls = None;
                // ADRDY once the ADC is ready (t_STAB not modelled: at once).
                self.regs[0] |= ADRDY;
            }
        }
        if set & JADSTART != 0 && (old & ADEN == 0 || self.reg(0) & ADRDY == 0 || value & ADDIS != 0) {
            return Err(Broken::new(
                reg,
                "JADSTART with the ADC not enabled and ready (ADEN = 1, ADRDY = 1, ADDIS = 0; RM0440 §21.4.19)",
            ));
        }
        if value & ADDIS != 0 && old & ADEN != 0 {
            v &= !(ADEN | ADDIS);
            self.regs[0] &= !ADRDY;
        }
        self.regs[0x08 / 4] = v;
        Ok(())
    }
}
