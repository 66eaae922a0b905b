//! Instruction counting on the emulated Cortex-M4F (`src/bin/icount.rs`, run by
//! `benches/icount.rs`): the representative control-step workload, the tick
//! statistics and the one-line report both sides agree on.
//!
//! Under `qemu-system-arm -machine netduinoplus2 -icount shift=5` every instruction
//! advances virtual time by 2^5 ns = 32 ns, and SysTick with CLKSOURCE = core counts
//! the STM32F405's 168 MHz SYSCLK, so one instruction is
//! 2^5 · 0.168 = 5.376 SysTick ticks ([`MILLITICKS_PER_INSTRUCTION`]). The emulated
//! binary checks this with a block of 1024 `nop`s (the `nop-1024` line).

use core::fmt;

use motor_control::angle::{ResolverToElectrical, ResolverTurns};
use motor_control::ato::ResolverSample;
use motor_control::step::{AdcSample, ControllerConfig};
use motor_control::transforms::{Dq, inverse_clarke, inverse_park};
use motor_control::trig::{SinCosQ31, Trig, sin_cos_q31};

/// SysTick ticks per instruction × 1000 under `-icount shift=5` on netduinoplus2:
/// 2^5 ns per instruction × 168 MHz SYSCLK = 5.376 ticks.
pub const MILLITICKS_PER_INSTRUCTION: u64 = 5_376;

/// SysTick reload value: the full 24-bit range (the counter counts down from it).
pub const SYSTICK_RELOAD: u32 = 0x00FF_FFFF;

/// Ticks elapsed between two reads of the 24-bit down-counting SysTick (at most one
/// wrap, i.e. < 2^24 ticks between the reads).
pub fn elapsed(start: u32, end: u32) -> u32 {
    start.wrapping_sub(end) & SYSTICK_RELOAD
}

/// `ticks` converted to instructions × 10 (one decimal), rounded to nearest.
pub fn deci_instructions(ticks: u64, count: u64) -> u64 {
    let den = MILLITICKS_PER_INSTRUCTION.saturating_mul(count.max(1));
    ticks.saturating_mul(10_000).saturating_add(den / 2) / den
}

/// Min/max/sum of per-call tick counts, after subtracting the measurement overhead.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stats {
    /// Number of measured calls.
    pub count: u32,
    /// Fewest ticks of one call.
    pub min: u32,
    /// Most ticks of one call.
    pub max: u32,
    /// Sum of all calls' ticks.
    pub sum: u64,
}

impl Default for Stats {
    fn default() -> Self {
        Self::new()
    }
}

impl Stats {
    /// No calls yet.
    pub const fn new() -> Self {
        Self {
            count: 0,
            min: u32::MAX,
            max: 0,
            sum: 0,
        }
    }

    /// Adds one call that took `ticks` (overhead already subtracted).
    pub fn add(&mut self, ticks: u32) {
        self.count = self.count.saturating_add(1);
        self.min = self.min.min(ticks);
        self.max = self.max.max(ticks);
        self.sum = self.sum.saturating_add(u64::from(ticks));
    }
}

/// One measured function: its name and tick statistics. Displays as the line the
/// emulated binary prints,
/// `<name> n=<count> ticks=<min>/<max>/<sum> instructions=<min>/<max>/<mean>`
/// (instructions to one decimal), and [`Measurement::parse`] reads it back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Measurement<'a> {
    /// What was measured (no whitespace).
    pub name: &'a str,
    /// Its tick statistics.
    pub stats: Stats,
}

/// Writes `deci` (a value × 10) as `<int>.<digit>`.
fn write_deci(f: &mut fmt::Formatter<'_>, deci: u64) -> fmt::Result {
    write!(f, "{}.{}", deci / 10, deci % 10)
}

impl fmt::Display for Measurement<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.stats;
        write!(
            f,
            "{} n={} ticks={}/{}/{} instructions=",
            self.name, s.count, s.min, s.max, s.sum
        )?;
        write_deci(f, deci_instructions(u64::from(s.min), 1))?;
        f.write_str("/")?;
        write_deci(f, deci_instructions(u64::from(s.max), 1))?;
        f.write_str("/")?;
        write_deci(f, deci_instructions(s.sum, u64::from(s.count)))
    }
}

impl<'a> Measurement<'a> {
    /// Reads a line written by [`Measurement`]'s `Display` (the tick fields; the
    /// instruction figures are derived from them). `None` for any other line.
    pub fn parse(line: &'a str) -> Option<Self> {
        let mut words = line.split_whitespace();
        let name = words.next()?;
        let count = words.next()?.strip_prefix("n=")?.parse().ok()?;
        let mut ticks = words.next()?.strip_prefix("ticks=")?.split('/');
        let min = ticks.next()?.parse().ok()?;
        let max = ticks.next()?.parse().ok()?;
        let sum = ticks.next()?.parse().ok()?;
        words.next()?.strip_prefix("instructions=")?;
        Some(Self {
            name,
            stats: Stats { count, min, max, sum },
        })
    }
}

/// The operating point of the representative step: closed-loop currents with the
/// decoupling feed-forward, at speed, at the nominal DC-link voltage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OperatingPoint {
    /// Electrical speed ω_e \[rad/s\].
    pub omega_e: f32,
    /// Current reference and (up to [`Workload::sample`]'s ripple) measured current \[A\].
    pub current: Dq,
    /// DC-link voltage \[V\].
    pub u_dc: f32,
}

/// Synthesises the ADC samples a motor at an [`OperatingPoint`] produces, step after
/// step, through the inverse of the configured scalings (so the step sees realistic
/// codes), with a deterministic ±2 % current ripple so the PI controllers act.
#[derive(Clone, Copy, Debug)]
pub struct Workload {
    /// The operating point.
    pub point: OperatingPoint,
    /// Resolver angle θ_r (π-scaled Q1.31).
    pub theta_r: i32,
    /// Resolver angle increment per step ω_r^i (π-scaled Q1.31 per sample).
    pub omega_r: i32,
    turns: ResolverTurns,
    step: u32,
}

/// `x` rounded to the nearest `u16` code, saturating.
fn code(x: f32) -> u16 {
    let r = x + 0.5;
    if r.is_nan() || r <= 0.0 {
        0
    } else if r >= 65_535.0 {
        u16::MAX
    } else {
        r as u16
    }
}

impl Workload {
    /// Starts at θ_r = 0 for `config` at `point`.
    pub fn new(config: &ControllerConfig, point: OperatingPoint) -> Self {
        let angle: &ResolverToElectrical = &config.angle;
        // ω_r = ω_e·n_r/n_p [rad/s] → per-sample π-scaled increment ω_r·T_s/π·2^31 (4.20).
        let ratio = f32::from(angle.resolver_pole_pairs.max(1)) / f32::from(angle.motor_pole_pairs.max(1));
        let omega_r = point.omega_e * ratio * config.sample_period / core::f32::consts::PI * 2_147_483_648.0;
        Self {
            point,
            theta_r: 0,
            omega_r: omega_r as i32,
            turns: ResolverTurns::new(),
            step: 0,
        }
    }

    /// The sample of the current step, then advances one sample period. The phase
    /// currents are those at the true electrical angle θ_e = n_p/n_r·(θ_r − θ_off) (4.5).
    pub fn sample(&mut self, config: &ControllerConfig) -> AdcSample {
        let theta_e = config.angle.process(&mut self.turns, self.theta_r);
        let ripple = if self.step.is_multiple_of(2) { 1.02 } else { 0.98 };
        let i = Dq {
            d: self.point.current.d * ripple,
            q: self.point.current.q * ripple,
        };
        let phases = inverse_clarke(inverse_park(i, sin_cos_q31(theta_e).to_f32()));
        let cs = &config.current_sense;
        let codes = [
            code(cs.offset[0] as f32 + phases.u / cs.amps_per_lsb[0]),
            code(cs.offset[1] as f32 + phases.v / cs.amps_per_lsb[1]),
            code(cs.offset[2] as f32 + phases.w / cs.amps_per_lsb[2]),
        ];
        let dc = &config.dc_link_sense;
        let resolver = sin_cos_q31(self.theta_r);
        // Demodulated envelopes at 90 % of full scale (the observer error scales with
        // the amplitude, 4.10).
        let amp = |x: i32| ((i64::from(x) * 9) / 10) as i32;
        let sample = AdcSample {
            phase_currents: codes,
            resolver: ResolverSample {
                sin: amp(resolver.sin),
                cos: amp(resolver.cos),
            },
            dc_link: code(dc.offset as f32 + self.point.u_dc / dc.volts_per_lsb),
        };
        self.theta_r = self.theta_r.wrapping_add(self.omega_r);
        self.step = self.step.wrapping_add(1);
        sample
    }
}

/// Number of sin/cos results a [`Replay`] can hold per step (observer, Park, inverse Park).
pub const REPLAY_SIN_COS: usize = 3;

/// A [`Trig`] that records what [`motor_control::SoftTrig`] returns and then replays
/// it: the step run once with `Replay::record` and again with the recorded results
/// computes exactly the same output, with every trig call reduced to reading a stored
/// result, i.e. the cost of the step without the software trigonometry (what the
/// CORDIC replaces by a register write and read).
#[derive(Clone, Copy, Debug, Default)]
pub struct Replay {
    sin_cos: [SinCosQ31; REPLAY_SIN_COS],
    atan2: i32,
    sin_cos_len: usize,
    next: usize,
    recording: bool,
}

impl Replay {
    /// An empty recorder.
    pub const fn record() -> Self {
        Self {
            sin_cos: [SinCosQ31 { sin: 0, cos: 0 }; REPLAY_SIN_COS],
            atan2: 0,
            sin_cos_len: 0,
            next: 0,
            recording: true,
        }
    }

    /// Switches to replay from the first recorded result.
    pub fn rewind(&mut self) {
        self.recording = false;
        self.next = 0;
    }

    /// sin/cos calls recorded.
    pub fn sin_cos_calls(&self) -> usize {
        self.sin_cos_len
    }
}

impl Trig for Replay {
    fn sin_cos(&mut self, theta: i32) -> SinCosQ31 {
        if self.recording {
            let r = sin_cos_q31(theta);
            if let Some(slot) = self.sin_cos.get_mut(self.sin_cos_len) {
                *slot = r;
                self.sin_cos_len = self.sin_cos_len.saturating_add(1);
            }
            r
        } else {
            let r = self.sin_cos.get(self.next).copied().unwrap_or_default();
            self.next = self.next.saturating_add(1);
            r
        }
    }

    fn atan2(&mut self, y: i32, x: i32) -> i32 {
        if self.recording {
            self.atan2 = motor_control::trig::atan2_q31(y, x);
        }
        self.atan2
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::string::ToString;

    use super::*;

    #[test]
    fn systick_elapsed_wraps_at_24_bits() {
        assert_eq!(elapsed(100, 40), 60);
        // Counter reloaded from 0 to 0xFF_FFFF between the reads: 100 + 1 + (0xFF_FFFF − 0xFF_FF00) ticks.
        assert_eq!(elapsed(100, 0x00FF_FF00), 100 + 1 + 0xFF);
    }

    #[test]
    fn ticks_convert_at_5_376_per_instruction() {
        // 1000 instructions × 5.376 = 5376 ticks (2^5 ns × 168 MHz).
        assert_eq!(deci_instructions(5_376, 1), 10_000);
        // 1024 nops = 5505.024 ticks → 5505 ticks reads as 1024.0.
        assert_eq!(deci_instructions(5_505, 1), 10_240);
        // mean of 3 calls totalling 3·5376 + 2 ticks: 1000.1 (1000.12 rounded).
        assert_eq!(deci_instructions(3 * 5_376 + 2, 3), 10_001);
    }

    #[test]
    fn measurement_line_round_trips() {
        let mut stats = Stats::new();
        for t in [5_376, 5_380, 5_372] {
            stats.add(t);
        }
        let m = Measurement { name: "step", stats };
        let line = m.to_string();
        assert_eq!(line, "step n=3 ticks=5372/5380/16128 instructions=999.3/1000.7/1000.0");
        assert_eq!(Measurement::parse(&line), Some(m));
        assert_eq!(Measurement::parse("panic: boom"), None);
    }
}
