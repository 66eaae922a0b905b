//! TIM3 as the image uses it (RM0440 §29): up-counting, reset by TIM1's TRGO in slave
//! reset mode (SMCR.SMS = 0100, TS = ITR0 = TIM1_TRGO, RM0440 §29.4.2 and Table 270),
//! OC1 in toggle mode (OC1M = 0011) driving the resolver excitation pin.

use super::clock::unknown;
use crate::violation::Broken;

/// Known TIM3 registers (RM0440 §29.5 register map).
const KNOWN: &[u32] = &[
    0x00, 0x04, 0x08, 0x0C, 0x10, 0x14, 0x18, 0x1C, 0x20, 0x24, 0x28, 0x2C, 0x34, 0x38, 0x3C, 0x40, 0x58, 0x5C, 0x60,
    0x64, 0x3DC, 0x3E0,
];

/// TIM3.
#[derive(Debug)]
pub struct Tim3 {
    regs: [u32; 0x68 / 4],
    /// Last counter reset (start, TIM1 TRGO) in bus sub-ticks, while running.
    reset_at: Option<u64>,
    /// OC1REF at that reset.
    level_at_reset: bool,
    /// The last two OC1REF toggles before that reset, latest first (bus sub-ticks).
    edges_at_reset: [Option<u64>; 2],
    /// Bus sub-ticks per timer tick.
    pub tick: u64,
    /// Resets by TIM1's TRGO.
    pub slave_resets: u64,
}

impl Default for Tim3 {
    fn default() -> Self {
        Self {
            regs: [0; 0x68 / 4],
            reset_at: None,
            level_at_reset: false,
            edges_at_reset: [None; 2],
            tick: 8,
            slave_resets: 0,
        }
    }
}

impl Tim3 {
    fn reg(&self, off: u32) -> u32 {
        self.regs[(off / 4) as usize]
    }

    /// OC1REF at `t`: toggles each time the counter matches CCR1 (RM0440 §29.3.10, toggle
    /// mode), the counter counting 0..=ARR from the last reset.
    pub fn oc1(&self, t: u64) -> bool {
        let Some(r) = self.reset_at else {
            return self.level_at_reset;
        };
        self.level_at_reset ^ (self.toggles(r, t) % 2 == 1)
    }

    /// OC1REF's toggles from the reset at `r` to `t` (toggle mode: one each time the
    /// counter, counting 0..=ARR from `r`, matches CCR1).
    fn toggles(&self, r: u64, t: u64) -> u64 {
        let ticks = t.saturating_sub(r) / self.tick;
        let (ccr, arr) = (u64::from(self.reg(0x34)), self.arr());
        if (self.reg(0x18) >> 4) & 7 == 0b011 && ticks >= ccr && ccr <= arr {
            1 + (ticks - ccr) / (arr + 1)
        } else {
            0
        }
    }

    /// The auto-reload value: TIM3 is a 16-bit timer (RM0440 §29.2, ARR[15:0] of
    /// TIMx_ARR without dithering; the PAC's `write` keeps the register's other reset bits).
    fn arr(&self) -> u64 {
        u64::from(self.reg(0x2C) & 0xFFFF)
    }

    /// The counter's period in ticks, ARR + 1.
    pub fn period_ticks(&self) -> u32 {
        self.arr() as u32 + 1
    }

    /// The last two OC1REF toggles at or before `t`, latest first (bus sub-ticks): the
    /// counter matches CCR1 at CCR1 ticks after the reset and every ARR + 1 after.
    fn last_edges(&self, t: u64) -> [Option<u64>; 2] {
        let Some(r) = self.reset_at else {
            return self.edges_at_reset;
        };
        let n = self.toggles(r, t);
        let (ccr, arr) = (u64::from(self.reg(0x34)), self.arr());
        let at = |k: u64| Some(r + (ccr + k * (arr + 1)) * self.tick);
        match n {
            0 => self.edges_at_reset,
            1 => [at(0), self.edges_at_reset[0]],
            _ => [at(n - 1), at(n - 2)],
        }
    }

    /// Restarts the counter at `t` (enable, UG, TIM1's TRGO), keeping OC1REF and its
    /// last edges.
    fn restart(&mut self, t: u64, running: bool) {
        self.level_at_reset = self.oc1(t);
        self.edges_at_reset = self.last_edges(t);
        self.reset_at = running.then_some(t);
    }

    /// The resolver excitation at `t` as the board's excitation filter passes it to the
    /// resolver: the fundamental of the pin's square wave, normalised to ±1 — the pin's
    /// level × sin(π·τ/H), τ the time since its last edge and H the time between its last
    /// two (a square wave's fundamental peaks midway between its edges; the filter is
    /// centred on the toggling frequency, so it adds no phase there, thesis A §4.3: the
    /// excitation is filtered to a sinusoid at f_s/2). 0 with the output disabled, before
    /// two edges, or once no edge has come for H: a transformer passes no DC.
    pub fn excitation(&self, t: u64) -> f64 {
        if self.reg(0x20) & 1 == 0 {
            return 0.0;
        }
        let [Some(last), Some(prev)] = self.last_edges(t) else {
            return 0.0;
        };
        let (h, tau) = ((last - prev) as f64, t.saturating_sub(last) as f64);
        if h <= 0.0 || tau >= h {
            return 0.0;
        }
        let level = if self.output(t) { 1.0 } else { -1.0 };
        level * (std::f64::consts::PI * tau / h).sin()
    }

    /// The pin output: OC1REF with CC1E (polarity CC1P).
    pub fn output(&self, t: u64) -> bool {
        let ccer = self.reg(0x20);
        ccer & 1 != 0 && (self.oc1(t) ^ (ccer & 2 != 0))
    }

    /// TIM1's TRGO at `t`: resets the counter in slave reset mode from ITR0.
    pub fn trgo(&mut self, t: u64) {
        let smcr = self.reg(0x08);
        let sms = (smcr & 7) | ((smcr >> 13) & 8);
        let ts = ((smcr >> 4) & 7) | ((smcr >> 17) & 0x18);
        if self.reset_at.is_some() && sms == 0b0100 && ts == 0 {
            self.restart(t, true);
            self.slave_resets += 1;
        }
    }

    /// Register read.
    pub fn read(&mut self, off: u32, t: u64) -> Result<u32, Broken> {
        if !KNOWN.contains(&off) {
            return Err(unknown("TIM3", off));
        }
        Ok(match (off, self.reset_at) {
            (0x24, Some(r)) => ((t.saturating_sub(r) / self.tick) % (self.arr() + 1)) as u32,
            _ => self.reg(off),
        })
    }

    /// Register write.
    pub fn write(&mut self, off: u32, value: u32, t: u64) -> Result<(), Broken> {
        if !KNOWN.contains(&off) {
            return Err(unknown("TIM3", off));
        }
        match off {
            0x00 => {
                let was = self.reg(0) & 1 != 0;
                if value & 1 != 0 && !was {
                    if value & (0x3 << 5 | 1 << 4) != 0 || self.reg(0x28) != 0 {
                        return Err(Broken::new(
                            "TIM3_CR1",
                            "only up-counting with PSC = 0 is modelled (RM0440 §29.5.1)",
                        ));
                    }
                    self.restart(t, true);
                } else if value & 1 == 0 && was {
                    self.restart(t, false);
                }
                self.regs[0] = value;
            }
            0x14 => {
                if value & 1 != 0 && self.reset_at.is_some() {
                    self.restart(t, true);
                }
            }
            0x10 => self.regs[4] &= value,
            _ => self.regs[(off / 4) as usize] = value,
        }
        Ok(())
    }
}
