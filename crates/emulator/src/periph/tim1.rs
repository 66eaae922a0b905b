//! TIM1, the advanced-control timer (RM0440 §28): centre-aligned counting, the update
//! event with the repetition counter, compare preload, OC4REF as TRGO/TRGO2, the
//! complementary outputs with dead time, and the break (BDTR write-once fields, LOCK,
//! MOE/BIF). Times are in timer ticks from the counter start.

use super::clock::unknown;
use crate::violation::Broken;

/// BDTR bits (RM0440 §28.6.20).
const MOE: u32 = 1 << 15;
const BKE: u32 = 1 << 12;
const BKP: u32 = 1 << 13;
const LOCK_SHIFT: u32 = 8;
/// Fields LOCK level 1 freezes (RM0440 §28.6.20, LOCK\[1:0\] = 01: DTG, BKE, BKP, AOE,
/// BKF, BK2F, BK2E, BK2P, BKBID, BK2BID).
const LOCK1_FIELDS: u32 = 0xFF | (1 << 12) | (1 << 13) | (1 << 14) | (0xF << 16) | (0xF << 20) | (3 << 24) | (3 << 28);
/// Level 2 adds OSSR/OSSI (bits 11, 10).
const LOCK2_FIELDS: u32 = LOCK1_FIELDS | (3 << 10);
/// SR.BIF (RM0440 §28.6.5).
pub const BIF: u32 = 1 << 7;
/// SR.UIF.
const UIF: u32 = 1;

/// Known TIM1 registers (RM0440 §28.6, register map).
const KNOWN: &[u32] = &[
    0x00, 0x04, 0x08, 0x0C, 0x10, 0x14, 0x18, 0x1C, 0x20, 0x24, 0x28, 0x2C, 0x30, 0x34, 0x38, 0x3C, 0x40, 0x44, 0x48,
    0x4C, 0x50, 0x54, 0x58, 0x5C, 0x60, 0x64, 0x68, 0x3DC, 0x3E0,
];

/// One event of the counter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimerEvent {
    /// OC4REF rose: TRGO (MMS = OC4REF) and TRGO2 (MMS2 = OC4REF).
    Trigger,
    /// Update event at the underflow (RCR = 1).
    Update,
}

/// TIM1.
#[derive(Debug)]
pub struct Tim1 {
    regs: [u32; 0x70 / 4],
    /// Active compare values CCR1..CCR4 (the preload registers are `regs`).
    active_ccr: [u32; 4],
    /// Whether BDTR has been written since reset (LOCK is frozen after that).
    bdtr_written: bool,
    /// Counter start [timer ticks since reset... in bus sub-ticks], when running.
    pub started_at: Option<u64>,
    /// Bus sub-ticks per timer tick.
    pub tick: u64,
    /// Active ARR and RCR.
    arr: u32,
    /// Carrier periods completed (update events since start).
    pub updates: u64,
    /// Trigger instants delivered since start.
    pub triggers: u64,
    /// The break input is at its active level (set by the bus from the pin).
    pub break_active: bool,
    /// Phase of OC4REF's rising edge within the period, for the active CCR4/OC4M.
    trig_phase: Option<u64>,
}

impl Default for Tim1 {
    fn default() -> Self {
        Self::new()
    }
}

impl Tim1 {
    /// Reset state (all registers 0, RM0440 §28.6).
    pub fn new() -> Self {
        let mut regs = [0; 0x70 / 4];
        // AF1 reset 0x0000_0001: BKINE = 1 (RM0440 §28.6.25).
        regs[0x60 / 4] = 1;
        Self {
            regs,
            active_ccr: [0; 4],
            bdtr_written: false,
            started_at: None,
            tick: 8,
            arr: 0,
            updates: 0,
            triggers: 0,
            break_active: false,
            trig_phase: None,
        }
    }

    /// A register's value (no side effect), for reports.
    pub fn reg(&self, off: u32) -> u32 {
        self.regs[(off / 4) as usize]
    }

    /// BDTR.
    pub fn bdtr(&self) -> u32 {
        self.reg(0x44)
    }

    /// MOE.
    pub fn moe(&self) -> bool {
        self.bdtr() & MOE != 0
    }

    /// SR.
    pub fn sr(&self) -> u32 {
        self.reg(0x10)
    }

    /// Active compare values CCR1..CCR3.
    pub fn compare(&self) -> [u32; 3] {
        [self.active_ccr[0], self.active_ccr[1], self.active_ccr[2]]
    }

    /// Carrier period in timer ticks (centre-aligned: 2·ARR, RM0440 §28.3.3).
    pub fn period_ticks(&self) -> u64 {
        2 * u64::from(self.arr)
    }

    /// Whether the break input, as TIM1 sees it through AF1 (BKINE, BKINP, RM0440
    /// §28.6.25) and BDTR.BKP, is active for the pin level `level`.
    pub fn break_input_active(&self, level: bool) -> bool {
        let af1 = self.reg(0x60);
        if af1 & 1 == 0 {
            return false;
        }
        let input = level ^ (af1 & (1 << 9) != 0);
        input == (self.bdtr() & BKP != 0)
    }

    /// Applies the break input (called by the bus whenever it may have changed): while
    /// active with BKE = 1, BIF is set and MOE cleared asynchronously (RM0440 §28.3.16).
    pub fn apply_break(&mut self) -> bool {
        if self.break_active && self.bdtr() & BKE != 0 {
            self.regs[0x10 / 4] |= BIF;
            if self.moe() {
                self.regs[0x44 / 4] &= !MOE;
                return true;
            }
        }
        false
    }

    /// Counter value at `t` sub-ticks (centre-aligned mode 1: up 0..ARR, down ARR..0).
    pub fn counter_at(&self, t: u64) -> u32 {
        let Some(start) = self.started_at else {
            return self.reg(0x24);
        };
        let p = self.period_ticks().max(1);
        let phase = (t.saturating_sub(start) / self.tick) % p;
        let arr = u64::from(self.arr);
        (if phase <= arr { phase } else { p - phase }) as u32
    }

    /// OCxM\[3:0\] of channel `ch` (0-based) from CCMR1/CCMR2 (RM0440 §28.6.7, §28.6.9).
    fn oc_mode(&self, ch: usize) -> u32 {
        let ccmr = self.reg(if ch < 2 { 0x18 } else { 0x1C });
        let shift = if ch.is_multiple_of(2) { 4 } else { 12 };
        ((ccmr >> shift) & 7) | (((ccmr >> (shift + 12)) & 1) << 3)
    }

    /// OCxREF of channel `ch` (0-based) at counter value `cnt`, counting up or down:
    /// PWM mode 1 active while CNT < CCR, mode 2 the inverse (RM0440 §28.6.7, OCxM).
    fn oc_ref(&self, ch: usize, cnt: u32) -> Option<bool> {
        let ccr = self.active_ccr[ch];
        match self.oc_mode(ch) {
            0b0110 => Some(cnt < ccr),
            0b0111 => Some(cnt >= ccr),
            0b0100 => Some(false),
            0b0101 => Some(true),
            _ => None,
        }
    }

    /// Phase within the period (ticks from the underflow) at which OC4REF rises, if it
    /// does.
    fn trigger_phase(&self) -> Result<Option<u64>, Broken> {
        let p = self.period_ticks();
        if p == 0 {
            return Ok(None);
        }
        let arr = u64::from(self.arr);
        let cnt = |ph: u64| (if ph <= arr { ph } else { p - ph }) as u32;
        let mut prev = self.oc_ref(3, cnt(p - 1)).ok_or_else(|| {
            Broken::new(
                "TIM1_CCMR2",
                "OC4M not in PWM mode 1/2 or forced: trigger source not modelled",
            )
        })?;
        for ph in 0..p {
            let now = self.oc_ref(3, cnt(ph)).unwrap_or(false);
            if now && !prev {
                return Ok(Some(ph));
            }
            prev = now;
        }
        Ok(None)
    }

    /// The next `event` at or after `from` (bus units).
    pub fn next(&self, event: TimerEvent, from: u64) -> Option<u64> {
        let start = self.started_at?;
        let p = self.period_ticks() * self.tick;
        if p == 0 {
            return None;
        }
        let offset = match event {
            TimerEvent::Update => p,
            TimerEvent::Trigger => self.trig_phase? * self.tick,
        };
        let k = from.saturating_sub(start + offset).div_ceil(p);
        let t = start + offset + k * p;
        Some(if t < from { t + p } else { t })
    }

    /// The update event: preloaded compare values become active (OCxPE, RM0440
    /// §28.3.10), UIF is set.
    pub fn update(&mut self) {
        for ch in 0..4 {
            self.active_ccr[ch] = self.regs[(0x34 / 4) + ch];
        }
        self.arr = self.reg(0x2C);
        self.regs[0x10 / 4] |= UIF;
        self.updates += 1;
        self.trig_phase = self.trigger_phase().ok().flatten();
    }

    /// TRGO2 source: true if MMS2 = OC4REF (0111, RM0440 §28.6.2).
    pub fn trgo2_is_oc4ref(&self) -> bool {
        (self.reg(0x04) >> 20) & 0xF == 0b0111
    }

    /// Gate levels (high sides, then low sides) at `t`: with MOE = 0 and OSSI = 1 the
    /// idle levels OISx/OISxN (RM0440 §28.3.17, Table "Output control bits"); with MOE = 1
    /// OCxREF with the dead time delaying each rising edge (§28.3.14).
    pub fn gate_levels(&self, t: u64) -> [bool; 6] {
        let cr2 = self.reg(0x04);
        let ccer = self.reg(0x20);
        let mut out = [false; 6];
        for ch in 0..3 {
            let (e, ne) = (ccer & (1 << (4 * ch)) != 0, ccer & (1 << (4 * ch + 2)) != 0);
            if !self.moe() {
                out[ch] = e && cr2 & (1 << (8 + 2 * ch)) != 0;
                out[ch + 3] = ne && cr2 & (1 << (9 + 2 * ch)) != 0;
                continue;
            }
            let dead = u64::from(crate::periph::dead_time_ticks(self.bdtr() as u8)) * self.tick;
            let now = self.oc_ref(ch, self.counter_at(t)).unwrap_or(false);
            let before = self
                .oc_ref(ch, self.counter_at(t.saturating_sub(dead)))
                .unwrap_or(false);
            out[ch] = e && now && before;
            out[ch + 3] = ne && !now && !before;
        }
        out
    }

    /// Fraction of the carrier period each high side u, v, w is on with the active
    /// compare values, or `None` while the bridge does not switch (MOE = 0: the outputs
    /// at their idle levels, RM0440 §28.3.17; or a channel with CCxE or CCxNE clear, a
    /// half-bridge the model does not drive). Centre-aligned counting 0 → ARR → 0 with
    /// PWM mode 1 (OCxREF active while CNT < CCR, RM0440 §28.6.7 OCxM) gives CCR/ARR,
    /// mode 2 its complement, forced active/inactive 1/0. The dead time is not counted:
    /// the plant's inverter is ideal (volt-second average, thesis A (3.3)), as in
    /// `motorgen verify`.
    pub fn duties(&self) -> Option<[f64; 3]> {
        if !self.moe() || self.arr == 0 {
            return None;
        }
        let ccer = self.reg(0x20);
        let arr = f64::from(self.arr);
        let mut d = [0.0; 3];
        for (ch, duty) in d.iter_mut().enumerate() {
            if ccer & (1 << (4 * ch)) == 0 || ccer & (1 << (4 * ch + 2)) == 0 {
                return None;
            }
            let mode = self.oc_mode(ch);
            let high = f64::from(self.active_ccr[ch]).min(arr) / arr;
            *duty = match mode {
                0b0110 => high,
                0b0111 => 1.0 - high,
                0b0101 => 1.0,
                _ => 0.0,
            };
        }
        Some(d)
    }

    /// Register read at `t`.
    pub fn read(&mut self, off: u32, t: u64) -> Result<u32, Broken> {
        if !KNOWN.contains(&off) {
            return Err(unknown("TIM1", off));
        }
        Ok(match off {
            0x24 => self.counter_at(t),
            0x14 => 0,
            _ => self.reg(off),
        })
    }

    /// Register write at `t`.
    pub fn write(&mut self, off: u32, value: u32, t: u64) -> Result<(), Broken> {
        if !KNOWN.contains(&off) {
            return Err(unknown("TIM1", off));
        }
        let i = (off / 4) as usize;
        match off {
            0x00 => {
                let was = self.regs[i] & 1 != 0;
                self.regs[i] = value;
                if value & 1 != 0 && !was {
                    if (value >> 5) & 3 != 0b01 {
                        return Err(Broken::new(
                            "TIM1_CR1",
                            "CMS other than centre-aligned mode 1 is not modelled (RM0440 §28.6.1)",
                        ));
                    }
                    if self.reg(0x28) != 0 || self.reg(0x30) != 1 {
                        return Err(Broken::new(
                            "TIM1_CR1",
                            "PSC ≠ 0 or RCR ≠ 1 at start: the model's update rate is one per period (RM0440 §28.3.3)",
                        ));
                    }
                    self.started_at = Some(t);
                    self.trig_phase = self.trigger_phase()?;
                } else if value & 1 == 0 && was {
                    self.regs[0x24 / 4] = self.counter_at(t);
                    self.started_at = None;
                }
            }
            // SR: rc_w0 flags (RM0440 §28.6.5); BIF stays while the break is active.
            0x10 => {
                self.regs[i] &= value;
                if self.break_active && self.bdtr() & BKE != 0 {
                    self.regs[i] |= BIF;
                }
            }
            // EGR.UG: re-initialise the counter and load the preloaded registers.
            0x14 => {
                if value & 1 != 0 {
                    self.update();
                    self.regs[0x10 / 4] &= !UIF;
                    self.updates -= 1;
                    if self.started_at.is_some() {
                        self.started_at = Some(t);
                    }
                }
            }
            0x44 => self.write_bdtr(value)?,
            _ => self.regs[i] = value,
        }
        Ok(())
    }

    /// BDTR: LOCK and the fields it protects are write-once (RM0440 §28.6.20: "LOCK
    /// bits can be written only once after the reset"; with LOCK ≥ 1 the protected
    /// fields "can no longer be written"). MOE cannot be set while the break input is
    /// active (§28.3.16); setting it while BIF is latched re-enables a bridge a break
    /// switched off (firmware README, review defect 6).
    fn write_bdtr(&mut self, value: u32) -> Result<(), Broken> {
        let old = self.bdtr();
        if self.bdtr_written {
            let lock = (old >> LOCK_SHIFT) & 3;
            if (value >> LOCK_SHIFT) & 3 != lock {
                return Err(Broken::new(
                    "TIM1_BDTR",
                    format!(
                        "LOCK written again ({} → {}): write-once after reset, frozen by the first BDTR write (RM0440 §28.6.20)",
                        lock,
                        (value >> LOCK_SHIFT) & 3
                    ),
                ));
            }
            let protected = match lock {
                0 => 0,
                1 => LOCK1_FIELDS,
                _ => LOCK2_FIELDS,
            };
            if (value ^ old) & protected != 0 {
                return Err(Broken::new(
                    "TIM1_BDTR",
                    format!(
                        "fields {:#010x} changed under LOCK level {lock}: write-protected (RM0440 §28.6.20)",
                        (value ^ old) & protected
                    ),
                ));
            }
        }
        if value & MOE != 0 && old & MOE == 0 && self.sr() & BIF != 0 {
            return Err(Broken::new(
                "TIM1_BDTR",
                "MOE set while SR.BIF is latched: a break must keep the outputs off (RM0440 §28.3.16; review defect 6)",
            ));
        }
        self.bdtr_written = true;
        let mut v = value;
        if self.break_active && v & BKE != 0 {
            v &= !MOE;
        }
        self.regs[0x44 / 4] = v;
        self.apply_break();
        Ok(())
    }
}
