//! TIM1, the advanced-control timer (RM0440 §28): centre-aligned counting, the update
//! event with the repetition counter, compare preload, OC4REF as TRGO/TRGO2, the
//! complementary outputs with dead time, and the break (BDTR write-once fields, LOCK,
//! MOE/BIF). Times are in timer ticks from the counter start.

use super::clock::unknown;
use crate::bridge::Wave;
use crate::violation::Broken;

/// The window a stopped counter's constant outputs are described over \[s\].
const STOPPED_WINDOW_S: f64 = 1e-6;

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
/// TIMx_CR2 OIS1..OIS4, OIS5, OIS6 (RM0440 TIMx_CR2).
const OIS_BITS: u32 = 0x7F00 | (1 << 16) | (1 << 18);
/// TIMx_CCER CC1P, CC1NP, …, CC4P, CC4NP, CC5P, CC6P (RM0440 TIMx_CCER).
const CCER_POLARITY_BITS: u32 = 0xAAAA | (1 << 17) | (1 << 21);
/// SR.BIF (RM0440 §28.6.5).
pub const BIF: u32 = 1 << 7;
/// SR.UIF.
const UIF: u32 = 1;
/// TIMx_CR1.UDIS (RM0440 §28.6.1).
const UDIS: u32 = 1 << 1;

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
    /// Update event: at the underflow or the overflow (RCR = 1, [`Tim1::update_at_overflow`]).
    Update,
}

/// TIM1.
#[derive(Debug)]
pub struct Tim1 {
    regs: [u32; 0x70 / 4],
    /// Active compare values CCR1..CCR4 (the preload registers are `regs`).
    active_ccr: [u32; 4],
    /// CCR1..CCR3 active in the window before the current one: where its OCxREF rose,
    /// an edge the window's start cuts, whose dead time may reach into this window.
    previous_ccr: [u32; 3],
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
    /// The repetition counter REP_CNT, as the last UG or update event loaded it from RCR.
    rep_cnt: u32,
    /// The update events fall on the overflows (REP_CNT = 0 at the start), not the
    /// underflows (REP_CNT = 1) — RM0440 §28.3.3: "if the RCR was written before
    /// launching the counter, the UEV occurs on the underflow. If the RCR was written
    /// after launching the counter, the UEV occurs on the overflow".
    pub update_at_overflow: bool,
    /// Started with RCR = 0 (REP_CNT = 0): RCR = 1 must be written before this first
    /// overflow (bus units), or every overflow and underflow would be an update event.
    rcr_due: Option<u64>,
    /// The last trigger (OC4REF rising: TRGO/TRGO2) \[bus units\].
    pub last_trigger_at: Option<u64>,
    /// The trigger before the first CCR1–3 write since the last update: the conversions
    /// the written compare values were computed from.
    written_after_trigger: Option<u64>,
    /// Measured loop timing: bus units from a trigger to the update that made the
    /// compare values written after it active (min, max, count).
    pub trigger_to_update: Option<(u64, u64, u64)>,
    /// Update events TIMx_CR1.UDIS suppressed (RM0440 §28.6.1: no UEV, the shadow
    /// registers keep their values).
    pub updates_disabled: u64,
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
        // AF1 reset 0x0000_0001: BKINE = 1 (RM0440 §28.6.27).
        regs[0x60 / 4] = 1;
        Self {
            regs,
            active_ccr: [0; 4],
            previous_ccr: [0; 3],
            bdtr_written: false,
            started_at: None,
            tick: 8,
            arr: 0,
            updates: 0,
            triggers: 0,
            break_active: false,
            trig_phase: None,
            rep_cnt: 0,
            update_at_overflow: false,
            rcr_due: None,
            last_trigger_at: None,
            written_after_trigger: None,
            trigger_to_update: None,
            updates_disabled: 0,
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
    /// §28.6.27) and BDTR.BKP, is active for the pin level `level`.
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
            TimerEvent::Update if self.update_at_overflow => u64::from(self.arr) * self.tick,
            TimerEvent::Update => p,
            TimerEvent::Trigger => self.trig_phase? * self.tick,
        };
        let k = from.saturating_sub(start + offset).div_ceil(p);
        let t = start + offset + k * p;
        Some(if t < from { t + p } else { t })
    }

    /// The update event at `t` (bus units), unless TIMx_CR1.UDIS holds it off (then
    /// nothing is loaded: RM0440 §28.6.1); records the trigger → effective delay of
    /// compare values written since the last one.
    pub fn update_at(&mut self, t: u64) {
        if self.regs[0] & UDIS != 0 {
            self.updates_disabled += 1;
            // A new window with the same compare values.
            self.previous_ccr = [self.active_ccr[0], self.active_ccr[1], self.active_ccr[2]];
            return;
        }
        if let Some(tr) = self.written_after_trigger.take() {
            self.trigger_to_update = super::spread(self.trigger_to_update, t.saturating_sub(tr));
        }
        self.update();
    }

    /// The update event: preloaded compare values become active (OCxPE, RM0440
    /// §28.3.10), REP_CNT is reloaded from RCR, UIF is set.
    pub fn update(&mut self) {
        self.previous_ccr = [self.active_ccr[0], self.active_ccr[1], self.active_ccr[2]];
        for ch in 0..4 {
            self.active_ccr[ch] = self.regs[(0x34 / 4) + ch];
        }
        self.arr = self.reg(0x2C);
        self.rep_cnt = self.reg(0x30);
        self.regs[0x10 / 4] |= UIF;
        self.updates += 1;
        self.trig_phase = self.trigger_phase().ok().flatten();
    }

    /// At an update event: a counter started with REP_CNT = 0 whose RCR is still 0 updates
    /// at every overflow and underflow from now on, which the model does not follow.
    pub fn repetition_broken(&mut self) -> Option<Broken> {
        self.rcr_due.take().map(|_| {
            Broken::new(
                "TIM1_RCR",
                "still 0 at the first overflow of a counter started with REP_CNT = 0: an update at every overflow and underflow, twice per period, is not modelled (RM0440 §28.3.3) — write RCR = 1 right after the start",
            )
        })
    }

    /// TRGO2 source: true if MMS2 = OC4REF (0111, RM0440 §28.6.2).
    pub fn trgo2_is_oc4ref(&self) -> bool {
        (self.reg(0x04) >> 20) & 0xF == 0b0111
    }

    /// The dead time in timer ticks (BDTR.DTG, RM0440 TIMx_BDTR).
    pub fn dead_ticks(&self) -> u64 {
        u64::from(crate::periph::dead_time_ticks(self.bdtr() as u8))
    }

    /// OCxREF of channel `ch` over one carrier period from the update event (counter
    /// at 0 counting up, or at ARR counting down when the updates fall on the overflows),
    /// in seconds with `tick_s` per timer tick; a stopped counter holds its level. PWM
    /// mode 1 is active while CNT < CCR: `[0, c)` and `[2a − c, 2a)` ticks of the
    /// centre-aligned period 2a from the underflow, `[a − c, a + c)` from the overflow
    /// (RM0440 §28.3.3, OCxM); mode 2 its complement; forced modes constant.
    fn ref_wave(&self, ch: usize, tick_s: f64) -> Wave {
        let p = self.period_ticks();
        if self.started_at.is_none() || p == 0 {
            let level = self.oc_ref(ch, self.reg(0x24)).unwrap_or(false);
            return Wave::constant(level, STOPPED_WINDOW_S);
        }
        let len = p as f64 * tick_s;
        let a = self.arr as f64;
        let c = f64::from(self.active_ccr[ch]).min(a);
        // From the overflow the counter runs down from a and back up: CNT < c on
        // (a − c, a + c).
        let pwm1 = if self.update_at_overflow {
            Wave::from_intervals(len, vec![((a - c) * tick_s, (a + c) * tick_s)])
        } else {
            Wave::from_intervals(len, vec![(0.0, c * tick_s), ((2.0 * a - c) * tick_s, len)])
        };
        match self.oc_mode(ch) {
            0b0110 => pwm1,
            0b0111 => pwm1.not(),
            0b0101 => Wave::constant(true, len),
            _ => Wave::constant(false, len),
        }
    }

    /// The six outputs (CH1..CH3, CH1N..CH3N) over one carrier period from the last
    /// update event, `None` where the timer does not drive the pin (Hi-Z), as RM0440's
    /// Table "Output control bits for complementary tim_ocx and tim_ocxn channels with
    /// break feature" gives them from MOE, OSSI, OSSR, CCxE, CCxNE: with MOE = 1 and both
    /// outputs enabled OCxREF with the dead time on each rising edge, XOR CCxP, and its
    /// complement likewise XOR CCxNP; one output enabled: OCxREF XOR its polarity, the
    /// other Hi-Z (OSSR = 0) or at its inactive level CCxP/CCxNP (OSSR = 1); MOE = 0:
    /// Hi-Z with OSSI = 0, the idle levels OISx/OISxN with OSSI = 1 (either output
    /// enabled).
    pub fn outputs(&self, tick_s: f64) -> [Option<Wave>; 6] {
        let cr2 = self.reg(0x04);
        let ccer = self.reg(0x20);
        let bdtr = self.bdtr();
        let (ossi, ossr) = (bdtr & (1 << 10) != 0, bdtr & (1 << 11) != 0);
        let mut out: [Option<Wave>; 6] = Default::default();
        for ch in 0..3 {
            let bit = |b: usize| ccer & (1 << (4 * ch + b)) != 0;
            let (e, p, ne, np) = (bit(0), bit(1), bit(2), bit(3));
            let r = self.ref_wave(ch, tick_s);
            let len = r.len;
            let xor = |w: &Wave, pol: bool| if pol { w.not() } else { w.clone() };
            let level = |l: bool| Some(Wave::constant(l, len));
            let (hi, lo) = if !self.moe() {
                if ossi && (e || ne) {
                    (
                        level(cr2 & (1 << (8 + 2 * ch)) != 0),
                        level(cr2 & (1 << (9 + 2 * ch)) != 0),
                    )
                } else {
                    (None, None)
                }
            } else {
                let dead = self.dead_ticks() as f64 * tick_s;
                match (e, ne) {
                    (false, false) => (None, None),
                    (true, true) => {
                        let (hi, lo) = self.across_the_window_start(ch, &r, dead, tick_s);
                        (Some(xor(&hi, p)), Some(xor(&lo, np)))
                    }
                    (true, false) => (Some(xor(&r, p)), if ossr { level(np) } else { None }),
                    (false, true) => (if ossr { level(p) } else { None }, Some(xor(&r, np))),
                }
            };
            out[ch] = hi;
            out[ch + 3] = lo;
        }
        out
    }

    /// The dead-time generator's two outputs before their polarities (RM0440 §28.3.15:
    /// each output rises the dead time after its OCxREF edge, falls with it) over the
    /// window of [`Tim1::outputs`], `r` its OCxREF. Within the window each rising edge is
    /// delayed by `dead`. An interval that starts with the window did not rise there: with
    /// the update at the underflow OCxREF's high pulse spans the window's start (CNT < CCR
    /// on both sides of CNT = 0), having risen `CCR_prev` ticks before it, the previous
    /// window's compare value — so its output turns on only `dead − CCR_prev` ticks into
    /// this window when CCR_prev is below the dead time (which `codegen::design::duty_limit`
    /// keeps the image's compare values from since stop 44, p = t_d; a patched image or a
    /// board file's shorter dead time can still do it), and at `dead` when OCxREF was low
    /// at the previous window's end (CCR_prev = 0); likewise the complement, high from the
    /// start only with CCR = 0, rose there if OCxREF was high at the previous window's end.
    /// Until stop 43 the window's first interval was taken as on from the start: such a leg
    /// got up to `dead` of high time the timer never gives. With the update at the
    /// overflow (the pulse centred in the window, no straddling high pulse) the window's
    /// first interval is taken as is.
    fn across_the_window_start(&self, ch: usize, r: &Wave, dead: f64, tick_s: f64) -> (Wave, Wave) {
        let (mut hi, mut lo) = (r.delay_rise(dead), r.not().delay_rise(dead));
        if self.update_at_overflow {
            return (hi, lo);
        }
        let len = r.len;
        let prev = f64::from(self.previous_ccr.get(ch).copied().unwrap_or(0)).min(f64::from(self.arr));
        let from = |start: f64| Wave::from_intervals(len, vec![(start.max(0.0), len)]);
        if r.at(0.0) {
            hi = hi.and(&from(dead - prev * tick_s));
        } else if prev > 0.0 {
            lo = lo.and(&from(dead));
        }
        (hi, lo)
    }

    /// Seconds per timer tick.
    pub fn tick_s(&self) -> f64 {
        self.tick as f64 / crate::periph::UNITS_PER_S
    }

    /// The six outputs at `t` (bus units) — the pins' levels for GPIO IDR reads — `None`
    /// where Hi-Z.
    pub fn outputs_at(&self, t: u64) -> [Option<bool>; 6] {
        let phase = self.window_phase(t);
        self.outputs(self.tick_s()).map(|w| w.map(|w| w.at(phase)))
    }

    /// Where `t` (bus units) falls in the window of [`Tim1::outputs`] (one carrier period
    /// from the last update event) \[s\]; 0 with the counter stopped.
    pub fn window_phase(&self, t: u64) -> f64 {
        let tick_s = self.tick_s();
        match self.started_at {
            Some(start) if self.period_ticks() > 0 => {
                let p = self.period_ticks();
                let from_update = if self.update_at_overflow {
                    p - u64::from(self.arr)
                } else {
                    0
                };
                ((t.saturating_sub(start) / self.tick + from_update) % p) as f64 * tick_s
            }
            _ => 0.0,
        }
    }

    /// [`Tim1::window_phase`] of a time between bus units, `t_s` \[s\], without rounding
    /// to the tick: `None` with the counter stopped.
    pub fn window_phase_s(&self, t_s: f64) -> Option<f64> {
        let start = self.started_at?;
        let p = self.period_ticks();
        if p == 0 {
            return None;
        }
        let from_update = if self.update_at_overflow {
            (p - u64::from(self.arr)) as f64
        } else {
            0.0
        };
        let ticks = (t_s * crate::periph::UNITS_PER_S - start as f64) / self.tick as f64 + from_update;
        Some(ticks.rem_euclid(p as f64) * self.tick_s())
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
                    // One update per period: RCR = 1 with REP_CNT = 1 (updates at the
                    // underflows) or REP_CNT = 0 and RCR = 1 from before the first
                    // overflow (updates at the overflows).
                    let rcr = self.reg(0x30);
                    // (REP_CNT 0, RCR 1 written between the UG and the launch is left out:
                    // RM0440's rule names only before/after the launch.)
                    let one_per_period = matches!((self.rep_cnt, rcr), (1, 1) | (0, 0));
                    if self.reg(0x28) != 0 || !one_per_period {
                        return Err(Broken::new(
                            "TIM1_CR1",
                            "PSC ≠ 0, or RCR and the repetition counter loaded at the last UG other than 1/1 (update at the underflows) or 0 with RCR = 1 written before the first overflow (update at the overflows): the model's update rate is one per period (RM0440 §28.3.3)",
                        ));
                    }
                    self.update_at_overflow = self.rep_cnt == 0;
                    self.rcr_due = (rcr == 0).then(|| t + u64::from(self.reg(0x2C)) * self.tick);
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
            // RCR: with the counter started at REP_CNT = 0, the 1 must come before the
            // first overflow.
            0x30 => {
                if self.started_at.is_some() && value != self.regs[i] {
                    match self.rcr_due {
                        Some(due) if value == 1 && t < due => self.rcr_due = None,
                        _ => {
                            return Err(Broken::new(
                                "TIM1_RCR",
                                "RCR changed while the counter runs, other than 0 → 1 before the first overflow: the update rate is not modelled (RM0440 §28.3.3)",
                            ));
                        }
                    }
                }
                self.regs[i] = value;
            }
            // EGR.UG: re-initialise the counter and load the preloaded registers.
            0x14 => {
                if value & 1 != 0 {
                    self.update();
                    self.update_at_overflow = self.rep_cnt == 0;
                    self.regs[0x10 / 4] &= !UIF;
                    self.updates -= 1;
                    if self.started_at.is_some() {
                        self.started_at = Some(t);
                    }
                }
            }
            0x44 => self.write_bdtr(value)?,
            0x34 | 0x38 | 0x3C => {
                if self.started_at.is_some() && self.written_after_trigger.is_none() {
                    self.written_after_trigger = self.last_trigger_at;
                }
                self.regs[i] = value;
            }
            // CR2: OISx/OISxN (bits 8–14, 16, 18) are frozen from LOCK level 1 on, the CCER
            // polarity bits from level 2 (RM0440 TIMx_BDTR LOCK[1:0]): the timer ignores
            // such a write, so the image's idle levels must be written before BDTR.
            0x04 | 0x20 => {
                let lock = (self.bdtr() >> LOCK_SHIFT) & 3;
                let (frozen, what, level) = if off == 0x04 {
                    (OIS_BITS, "OISx/OISxN", 1)
                } else {
                    (CCER_POLARITY_BITS, "CCxP/CCxNP", 2)
                };
                if self.bdtr_written && lock >= level && (value ^ self.regs[i]) & frozen != 0 {
                    return Err(Broken::new(
                        if off == 0x04 { "TIM1_CR2" } else { "TIM1_CCER" },
                        format!(
                            "{what} changed ({:#x} → {:#x}) under LOCK level {lock}: write-protected, the timer keeps the old levels (RM0440 TIMx_BDTR LOCK) — write them before the BDTR write",
                            self.regs[i] & frozen,
                            value & frozen
                        ),
                    ));
                }
                self.regs[i] = value;
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// ARR = 100, CCR1 = 30 in PWM mode 1, tick = 8 bus units. RCR = 1 before the UG and
    /// the start: updates at the underflows, 200 ticks apart from the start, CH1's
    /// reference high on [0, 30) and [170, 200) ticks from there. RCR = 0 at the UG, 1
    /// written right after the start: updates at the overflows, 100 ticks after the
    /// start and every 200 after, the reference high on [70, 130) ticks from there (the
    /// counter runs 100 → 0 → 100, below 30 from tick 70 to 130). Never written: the
    /// first overflow is refused.
    #[test]
    fn update_at_the_underflow_or_the_overflow() {
        let setup = |rcr_at_ug: u32| {
            let mut t = Tim1::new();
            t.write(0x2C, 100, 0).unwrap();
            t.write(0x34, 30, 0).unwrap();
            t.write(0x18, 0b110 << 4, 0).unwrap();
            // OC4 in PWM mode 2 (the trigger channel).
            t.write(0x1C, 0b111 << 12, 0).unwrap();
            t.write(0x30, rcr_at_ug, 0).unwrap();
            t.write(0x14, 1, 0).unwrap();
            t.write(0x00, 0b01 << 5 | 1, 80).unwrap();
            t
        };
        let tick_s = 8.0 / crate::periph::UNITS_PER_S;
        let t = setup(1);
        assert!(!t.update_at_overflow);
        assert_eq!(t.next(TimerEvent::Update, 81), Some(80 + 200 * 8));
        let w = t.ref_wave(0, tick_s);
        assert_eq!(w.high.len(), 2);
        assert!((w.high[0].1 - 30.0 * tick_s).abs() < 1e-15 && (w.high[1].0 - 170.0 * tick_s).abs() < 1e-15);
        let mut t = setup(0);
        assert!(t.update_at_overflow);
        t.write(0x30, 1, 88).unwrap();
        assert_eq!(t.next(TimerEvent::Update, 81), Some(80 + 100 * 8));
        assert_eq!(t.next(TimerEvent::Update, 80 + 100 * 8 + 1), Some(80 + 300 * 8));
        assert!(t.repetition_broken().is_none());
        let w = t.ref_wave(0, tick_s);
        assert_eq!(w.high.len(), 1);
        assert!((w.high[0].0 - 70.0 * tick_s).abs() < 1e-15 && (w.high[0].1 - 130.0 * tick_s).abs() < 1e-15);
        assert!(setup(0).repetition_broken().is_some());
        // RCR written after the first overflow: refused.
        let mut t2 = setup(0);
        assert!(t2.write(0x30, 1, 80 + 100 * 8).is_err());
    }

    /// The dead time of an edge the window's start cuts (update at the underflow, ARR =
    /// 100, dead time 20 ticks, by hand): with the previous window's CCR = 30 the high
    /// pulse rose 30 ticks before the window, so its output is on from the start; with
    /// CCR = 8 it rose 8 ticks before, its output turns on 20 − 8 = 12 ticks in; with
    /// CCR = 0 OCxREF rose at the window's start, on from 20. Within the window the rise
    /// at 200 − 30 = 170 turns on at 190, and the complement (falling edge at 30) at 50.
    #[test]
    fn dead_time_across_the_window_start() {
        let tick_s = 1e-8;
        let mut t = Tim1::new();
        // PWM mode 1 on CH1 (OC1M = 0110).
        t.write(0x18, 0b110 << 4, 0).unwrap();
        t.arr = 100;
        t.started_at = Some(0);
        t.active_ccr[0] = 30;
        let r = t.ref_wave(0, tick_s);
        let dead = 20.0 * tick_s;
        let first_on = |t: &Tim1| t.across_the_window_start(0, &r, dead, tick_s).0.high[0].0 / tick_s;
        for (previous, on_at) in [(30, 0.0), (8, 12.0), (0, 20.0)] {
            t.previous_ccr[0] = previous;
            assert!(
                (first_on(&t) - on_at).abs() < 1e-9,
                "CCR_prev {previous}: {}",
                first_on(&t)
            );
        }
        let (hi, lo) = t.across_the_window_start(0, &r, dead, tick_s);
        assert!((hi.high[1].0 / tick_s - 190.0).abs() < 1e-9);
        assert!((lo.high[0].0 / tick_s - 50.0).abs() < 1e-9);
    }
}
