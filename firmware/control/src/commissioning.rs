//! Commissioning routines of thesis A chapter 6 as pure state machines.
//!
//! Each routine is stepped once per control period with the measurements it needs
//! and answers [`Progress::Running`] with the [`Demand`] to hand to the current-control
//! step ([`crate::step::ControllerConfig::process`]), or [`Progress::Finished`] with its
//! result (the board then switches the PWM off). No routine touches hardware.
//!
//! 1. [`VoltageStep`]: blocked-rotor voltage step on d or q (§6.2) with a current
//!    trip and a capture buffer; [`identify_rl`] evaluates it by (6.3)–(6.8).
//! 2. [`ResolverOffset`]: align the rotor with +α and read θ_off = θ_r (6.3), (6.9).
//! 3. [`PolePairRatio`]: rotate the stator field open loop by whole electrical turns and
//!    compare with the resolver angle travelled: n_p/n_r and direction (§6.4).
//! 4. [`FluxLinkage`]: at zero current and steady speed, ψ_M ≈ u_q/ω_e (6.10).
//! 5. [`FrequencyResponse`]: the current loop broken at the controller's output
//!    (v = u_PI + d, d a periodic multisine) at standstill; u_PI and v captured so that
//!    the host reads the open-loop response L(jω) = −U_PI(jω)/V(jω) at every line.

use crate::step::Demand;
use crate::transforms::{AlphaBeta, Dq};
use crate::trig::Trig;

/// What a routine wants this period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Progress<R> {
    /// Still running: apply this demand.
    Running(Demand),
    /// Done (or aborted): switch off; here is the outcome.
    Finished(R),
}

/// Why a routine failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CommissioningError {
    /// The current exceeded the trip level at this sample \[A\] (§6.2: PWM must be
    /// disabled at once).
    Tripped {
        /// Sample index (periods since start).
        sample: u32,
        /// Current magnitude |i_dq| that tripped \[A\].
        current: f32,
    },
    /// The rotor did not turn (resolver travel below a quarter resolver turn).
    NoRotation,
    /// The speed was below the configured minimum for the ψ_M estimate.
    TooSlow,
}

/// Which rotor axis a blocked-rotor step excites.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// Direct axis.
    D,
    /// Quadrature axis.
    Q,
}

// ---------------------------------------------------------------------------------
// 1. Blocked-rotor voltage step (§6.2)
// ---------------------------------------------------------------------------------

/// Blocked-rotor voltage step configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoltageStep {
    /// Excited axis.
    pub axis: Axis,
    /// Step height \[V\].
    pub voltage: f32,
    /// Trip level on |i_dq| \[A\] (10 A in thesis A §6.2).
    pub current_trip: f32,
    /// Periods at 0 V before the step (baseline).
    pub pre_samples: u32,
    /// Periods at the step voltage.
    pub step_samples: u32,
    /// Keep every `decimation`-th period in the capture buffer (0 treated as 1).
    pub decimation: u32,
}

/// One captured period of the step response.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Capture {
    /// Period index since the start of the routine.
    pub sample: u32,
    /// Voltage commanded in this period \[V\] (it takes effect with the PWM update).
    pub voltage: f32,
    /// Current measured at the start of this period in the excited axis \[A\].
    pub current: f32,
}

/// State of [`VoltageStep`] with room for `N` captures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoltageStepState<const N: usize> {
    n: u32,
    len: usize,
    buffer: [Capture; N],
}

impl<const N: usize> Default for VoltageStepState<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> VoltageStepState<N> {
    /// Empty buffer, at the start of the routine.
    pub const fn new() -> Self {
        Self {
            n: 0,
            len: 0,
            buffer: [Capture {
                sample: 0,
                voltage: 0.0,
                current: 0.0,
            }; N],
        }
    }

    /// The captures taken so far, oldest first.
    pub fn captures(&self) -> &[Capture] {
        self.buffer.get(..self.len).unwrap_or(&[])
    }
}

/// Outcome of a complete (not tripped) step: how many captures were stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepRecorded {
    /// Number of valid entries in [`VoltageStepState::captures`].
    pub captures: usize,
}

impl VoltageStep {
    /// One period with the measured dq currents `i_dq` \[A\].
    pub fn process<const N: usize>(
        &self,
        state: &mut VoltageStepState<N>,
        i_dq: Dq,
    ) -> Progress<Result<StepRecorded, CommissioningError>> {
        let n = state.n;
        let magnitude = libm::sqrtf(i_dq.d * i_dq.d + i_dq.q * i_dq.q);
        if magnitude.is_nan() || magnitude > self.current_trip {
            return Progress::Finished(Err(CommissioningError::Tripped {
                sample: n,
                current: magnitude,
            }));
        }
        let total = self.pre_samples.saturating_add(self.step_samples);
        if n >= total {
            return Progress::Finished(Ok(StepRecorded { captures: state.len }));
        }
        let voltage = if n < self.pre_samples { 0.0 } else { self.voltage };
        let current = match self.axis {
            Axis::D => i_dq.d,
            Axis::Q => i_dq.q,
        };
        if n.is_multiple_of(self.decimation.max(1))
            && let Some(slot) = state.buffer.get_mut(state.len)
        {
            *slot = Capture {
                sample: n,
                voltage,
                current,
            };
            state.len = state.len.saturating_add(1);
        }
        state.n = n.saturating_add(1);
        let demand = match self.axis {
            Axis::D => Dq { d: voltage, q: 0.0 },
            Axis::Q => Dq { d: 0.0, q: voltage },
        };
        Progress::Running(Demand::VoltageDq(demand))
    }
}

/// ln 9 = ln 0.9 − ln 0.1: the 10–90 % rise time of a first-order system is
/// `T_r = τ·ln 9 ≈ 2.197·τ` (6.7).
pub const LN_9: f32 = 2.197_224_6;

/// R and L of one axis from a recorded step (6.3)–(6.8).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RlEstimate {
    /// Resistance R = U/i(∞) \[Ω\] (6.3).
    pub resistance: f32,
    /// Inductance L = R·T_r/ln 9 \[H\] (6.8).
    pub inductance: f32,
    /// Time from the voltage step to the 5 % crossing \[s\] (§6.2, transport delay).
    pub delay: f32,
}

/// Evaluates a step recorded by [`VoltageStep`] (ideally after low-pass filtering the
/// currents, e.g. with [`crate::fir`]): final value from the mean of the last quarter
/// of the step, 10 %, 90 % and 5 % crossings by linear interpolation between captures.
/// `sample_period` is T_s \[s\]. `None` if the record has no step or never crosses.
pub fn identify_rl(captures: &[Capture], sample_period: f32) -> Option<RlEstimate> {
    let first_step = captures.iter().position(|c| c.voltage != 0.0)?;
    let step = captures.get(first_step..)?;
    let start = step.first()?;
    let voltage = start.voltage;
    let baseline = match first_step.checked_sub(1).and_then(|k| captures.get(k)) {
        Some(c) => c.current,
        None => 0.0,
    };
    let tail = step.get(step.len().saturating_mul(3) >> 2..)?;
    if tail.is_empty() {
        return None;
    }
    let mut sum = 0.0f32;
    for c in tail {
        sum += c.current;
    }
    let final_current = sum / tail.len() as f32 - baseline;
    let resistance = voltage / final_current;
    // Time (in samples, fractional) at which the response first reaches `level`.
    let crossing = |level: f32| -> Option<f32> {
        let target = baseline + level * final_current;
        let rising = final_current > 0.0;
        let mut previous: Option<&Capture> = None;
        for c in step {
            let reached = if rising {
                c.current >= target
            } else {
                c.current <= target
            };
            if reached {
                let p = previous?;
                let di = c.current - p.current;
                let frac = if di != 0.0 { (target - p.current) / di } else { 0.0 };
                return Some(p.sample as f32 + frac * (c.sample as f32 - p.sample as f32));
            }
            previous = Some(c);
        }
        None
    };
    let t10 = crossing(0.1)?;
    let t90 = crossing(0.9)?;
    let t05 = crossing(0.05)?;
    let rise = (t90 - t10) * sample_period;
    let estimate = RlEstimate {
        resistance,
        inductance: resistance * rise / LN_9,
        delay: (t05 - start.sample as f32) * sample_period,
    };
    if estimate.resistance.is_finite() && estimate.inductance.is_finite() {
        Some(estimate)
    } else {
        None
    }
}

// ---------------------------------------------------------------------------------
// 2. Resolver offset (§6.3)
// ---------------------------------------------------------------------------------

/// Resolver offset calibration: +α voltage, wait, θ_off = θ_r (6.9).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResolverOffset {
    /// α-axis voltage \[V\] (sets the aligning current U/R).
    pub voltage: f32,
    /// Periods of the linear voltage ramp (0: step).
    pub ramp_samples: u32,
    /// Periods to wait at full voltage for the rotor to settle.
    pub settle_samples: u32,
    /// Periods over which θ_r is averaged (0 treated as 1).
    pub average_samples: u32,
}

/// State of [`ResolverOffset`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ResolverOffsetState {
    n: u32,
    reference: i32,
    sum: i64,
}

impl ResolverOffset {
    /// One period with the observed resolver angle `theta_r` (π-scaled Q1.31).
    ///
    /// The result is θ_off (π-scaled Q1.31), the mean of θ_r over the averaging
    /// window (wrap-safe: differences to the first sample are averaged). Afterwards
    /// set [`crate::angle::ResolverToElectrical::offset`] to it and call
    /// [`crate::angle::ResolverTurns::align`] with the current θ_r.
    pub fn process(&self, state: &mut ResolverOffsetState, theta_r: i32) -> Progress<i32> {
        let n = state.n;
        let hold_end = self.ramp_samples.saturating_add(self.settle_samples);
        let average = self.average_samples.max(1);
        if n >= hold_end {
            let k = n.saturating_sub(hold_end);
            if k == 0 {
                state.reference = theta_r;
            }
            // An angle difference: wraps into [−π, π).
            state.sum = state
                .sum
                .saturating_add(i64::from(theta_r.wrapping_sub(state.reference)));
            if k.saturating_add(1) >= average {
                let mean = state.sum.checked_div(i64::from(average)).unwrap_or(0);
                // The mean difference is within [−π, π): truncation is exact.
                return Progress::Finished(state.reference.wrapping_add(mean as i32));
            }
        }
        let scale = if n < self.ramp_samples {
            n as f32 / self.ramp_samples as f32
        } else {
            1.0
        };
        state.n = n.saturating_add(1);
        Progress::Running(Demand::VoltageAlphaBeta(AlphaBeta {
            alpha: self.voltage * scale,
            beta: 0.0,
        }))
    }
}

// ---------------------------------------------------------------------------------
// 3. Pole-pair ratio and direction (§6.4)
// ---------------------------------------------------------------------------------

/// Open-loop rotation of the stator field to measure n_p/n_r (6.2) and the direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolePairRatio {
    /// Voltage amplitude of the rotating αβ vector \[V\].
    pub voltage: f32,
    /// Electrical angle advanced per period (π-scaled Q1.31, sign = direction);
    /// slow enough for the rotor to follow.
    pub step: i32,
    /// Whole electrical turns to rotate.
    pub turns: u32,
    /// Periods held at the start angle (alignment) and at the end (settling).
    pub settle_samples: u32,
}

/// State of [`PolePairRatio`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PolePairRatioState {
    n: u32,
    /// Generated electrical angle travelled, LSB.
    generated: i64,
    /// Resolver angle travelled since the rotation started, LSB.
    travelled: i64,
    previous: i32,
    end_hold: u32,
}

impl PolePairRatioState {
    /// The electrical angle the rotating field has reached (π-scaled Q1.31, wrapped).
    pub fn generated_angle(&self) -> i32 {
        // The generated angle modulo one turn (truncation is the wrap).
        self.generated as i32
    }
}

/// Measured pole-pair ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolePairRatioResult {
    /// |Δθ_e|/|Δθ_r| = n_p/n_r (6.2).
    pub ratio: f32,
    /// The resolver turned in the same direction as the stator field.
    pub directions_agree: bool,
}

/// One electrical turn in π-scaled LSB.
const TURN: i64 = 1 << 32;
/// A quarter turn in π-scaled LSB.
const QUARTER_TURN: i64 = 1 << 30;

impl PolePairRatio {
    /// One period with the observed resolver angle `theta_r`; `trig` gives the
    /// rotating voltage vector.
    pub fn process<T: Trig>(
        &self,
        state: &mut PolePairRatioState,
        trig: &mut T,
        theta_r: i32,
    ) -> Progress<Result<PolePairRatioResult, CommissioningError>> {
        let n = state.n;
        state.n = n.saturating_add(1);
        let target = TURN.saturating_mul(i64::from(self.turns));
        if n < self.settle_samples {
            // Align at electrical angle 0.
            state.previous = theta_r;
        } else {
            // An angle difference: wraps into [−π, π).
            let d = theta_r.wrapping_sub(state.previous);
            state.previous = theta_r;
            state.travelled = state.travelled.saturating_add(i64::from(d));
            if state.generated.saturating_abs() < target {
                let remaining = target.saturating_sub(state.generated.saturating_abs());
                let step = i64::from(self.step.unsigned_abs()).min(remaining);
                let step = if self.step < 0 { step.saturating_neg() } else { step };
                state.generated = state.generated.saturating_add(step);
            } else if state.end_hold < self.settle_samples {
                state.end_hold = state.end_hold.saturating_add(1);
            } else {
                return Progress::Finished(self.result(state));
            }
        }
        // The generated angle modulo one turn (truncation is the wrap).
        let angle = state.generated as i32;
        let sc = trig.sin_cos(angle).to_f32();
        Progress::Running(Demand::VoltageAlphaBeta(AlphaBeta {
            alpha: self.voltage * sc.cos,
            beta: self.voltage * sc.sin,
        }))
    }

    fn result(&self, state: &PolePairRatioState) -> Result<PolePairRatioResult, CommissioningError> {
        if state.travelled.saturating_abs() < QUARTER_TURN {
            return Err(CommissioningError::NoRotation);
        }
        let ratio = state.generated.saturating_abs() as f32 / state.travelled.saturating_abs() as f32;
        Ok(PolePairRatioResult {
            ratio,
            directions_agree: (state.generated > 0) == (state.travelled > 0),
        })
    }
}

// ---------------------------------------------------------------------------------
// 4. Permanent-magnet flux linkage (§6.5)
// ---------------------------------------------------------------------------------

/// ψ_M estimate at zero current and steady (externally driven) speed (6.10).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluxLinkage {
    /// Periods to let the current loop settle at i = 0.
    pub settle_samples: u32,
    /// Periods averaged (0 treated as 1).
    pub average_samples: u32,
    /// Smallest mean |ω_e| accepted \[rad/s\] (the back EMF must dominate R·i).
    pub min_speed: f32,
}

/// State of [`FluxLinkage`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FluxLinkageState {
    n: u32,
    sum_uq: f64,
    sum_omega: f64,
}

impl FluxLinkage {
    /// One period with the applied q voltage `u_q` \[V\] and electrical speed `omega_e`
    /// \[rad/s\] from the previous control step. Demands zero current with the
    /// feed-forward (5.3) disabled; the result is ψ_M = Σu_q/Σω_e \[Wb\].
    pub fn process(
        &self,
        state: &mut FluxLinkageState,
        u_q: f32,
        omega_e: f32,
    ) -> Progress<Result<f32, CommissioningError>> {
        let n = state.n;
        state.n = n.saturating_add(1);
        let average = self.average_samples.max(1);
        if n >= self.settle_samples {
            state.sum_uq += f64::from(u_q);
            state.sum_omega += f64::from(omega_e);
            if n.saturating_sub(self.settle_samples).saturating_add(1) >= average {
                let mean_speed = state.sum_omega / f64::from(average);
                if !(mean_speed.abs() >= f64::from(self.min_speed) && mean_speed.abs() > 0.0) {
                    return Progress::Finished(Err(CommissioningError::TooSlow));
                }
                return Progress::Finished(Ok((state.sum_uq / state.sum_omega) as f32));
            }
        }
        Progress::Running(Demand::Current {
            id: 0.0,
            iq: 0.0,
            feed_forward: false,
        })
    }
}

// ---------------------------------------------------------------------------------
// 5. Current-loop frequency response (loop-breaking injection)
// ---------------------------------------------------------------------------------

/// Largest number of lines of the multisine ([`multisine_lines`]).
pub const MAX_LINES: usize = 32;

/// Lines-per-octave ratios 2^(1/r) in Q10 (round(1024·2^(1/r)), r = 1…8): integer, so
/// the drive and the host compute the same harmonic numbers.
const OCTAVE_RATIO_Q10: [u32; 8] = [2048, 1448, 1290, 1218, 1176, 1149, 1131, 1117];

/// The harmonics of a multisine: line `j` is at k_j/(N·T_s).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lines {
    /// Harmonic numbers k_j of the period N, increasing; the first `count` are used.
    pub harmonics: [u16; MAX_LINES],
    /// Number of lines.
    pub count: usize,
}

impl Lines {
    /// The harmonic numbers in use.
    pub fn used(&self) -> &[u16] {
        self.harmonics.get(..self.count).unwrap_or(&[])
    }
}

/// The log-spaced harmonics of a period of `period` samples: from `first` (≥ 1), each
/// the previous times 2^(1/`per_octave`) rounded (at least the next harmonic), below the
/// Nyquist harmonic `period`/2, at most [`MAX_LINES`]. `None` when `first` is 0 or not
/// below `period`/2, or `per_octave` is outside 1–8.
pub fn multisine_lines(first: u16, per_octave: u8, period: u32) -> Option<Lines> {
    let ratio = *OCTAVE_RATIO_Q10.get(usize::from(per_octave).checked_sub(1)?)?;
    let nyquist = period / 2;
    if first == 0 || u32::from(first) >= nyquist {
        return None;
    }
    let mut lines = Lines {
        harmonics: [0; MAX_LINES],
        count: 0,
    };
    let mut k = u32::from(first);
    while k < nyquist && lines.count < MAX_LINES {
        if let Some(slot) = lines.harmonics.get_mut(lines.count) {
            *slot = u16::try_from(k).unwrap_or(u16::MAX);
        }
        lines.count = lines.count.saturating_add(1);
        let next = k.saturating_mul(ratio).saturating_add(512) >> 10;
        k = next.max(k.saturating_add(1));
    }
    Some(lines)
}

/// Schroeder's phase of line `j` of `count` (φ_j = −π·j·(j + 1)/count, Schroeder 1970,
/// "Synthesis of low-peak-factor signals"): a low crest factor for equal amplitudes.
pub fn schroeder_phase(j: usize, count: usize) -> f32 {
    let (j, m) = (j as f32, count.max(1) as f32);
    -core::f32::consts::PI * j * (j + 1.0) / m
}

/// Loop-breaking frequency response of one current-loop axis at standstill: both
/// currents are regulated to zero, and the injection d is added to the axis's
/// controller output (PI and active damping) after its limit, v = u_PI + d
/// ([`Demand::Injected`]). d is the multisine Σ a_j·sin(2π·k_j·n/N + φ_j) over the
/// [`Lines`] ([`FrequencyResponse::line_amplitude`]), clamped to ±`amplitude`; it repeats every N periods exactly (each line's
/// oscillator restarts from its initial phasor at every period boundary). After
/// `settle_periods` periods of N, one period of N samples (u_PI, v) is captured.
///
/// On the q axis the rotor must be held (the injected current makes torque); on the d
/// axis at the resolver's angle the current makes none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrequencyResponse {
    /// Injected axis.
    pub axis: Axis,
    /// Peak of the injection \[V\] (d is clamped to it).
    pub amplitude: f32,
    /// Trip level on |i_dq| \[A\].
    pub current_trip: f32,
    /// The multisine's period N \[samples\] (the capture length).
    pub period: u32,
    /// Periods of N before the captured one (the loop reaching its periodic steady state).
    pub settle_periods: u32,
    /// The lines.
    pub lines: Lines,
}

/// State of [`FrequencyResponse`]: per line the rotation e^(jω_jT_s), the initial phasor
/// a·e^(jφ_j) and the running phasor (re, im).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrequencyResponseState {
    n: u32,
    rotation: [(f32, f32); MAX_LINES],
    initial: [(f32, f32); MAX_LINES],
    phasor: [(f32, f32); MAX_LINES],
    /// The injection of the previous period \[V\].
    last: f32,
}

/// One captured period: the controller's output u_PI and the applied v = u_PI + d on the
/// injected axis \[V\].
pub type LoopSample = (f32, f32);

impl FrequencyResponse {
    /// The weight of line `j`: w_j = max(1, k_j/(4·k_0)), k_0 the first harmonic. The
    /// host puts the first line two octaves below the designed crossover, so the lines
    /// above the crossover grow with frequency as a first-order loop's |L| ≈ ω_c/ω falls:
    /// each line's u_PI = −L·v stays about the same size, and the gain margin, read
    /// where |L| is small, is measured with the crossover's resolution (the injected
    /// current a/|R + jωL| stays about constant there too).
    pub fn line_weight(&self, j: usize) -> f32 {
        let first = f32::from(self.lines.harmonics.first().copied().unwrap_or(1).max(1));
        let k = f32::from(self.lines.harmonics.get(j).copied().unwrap_or(0));
        (k / (4.0 * first)).max(1.0)
    }

    /// The amplitude a_j of line `j` for a peak of `amplitude`:
    /// a_j = amplitude·w_j/√(2·Σw²) (the sum's rms is amplitude/2; with Schroeder's
    /// phases its peak stays near the amplitude, and the clamp takes the rest).
    pub fn line_amplitude(&self, j: usize) -> f32 {
        let mut sum = 0.0f32;
        for i in 0..self.lines.count {
            let w = self.line_weight(i);
            sum += w * w;
        }
        self.amplitude * self.line_weight(j) / libm::sqrtf(2.0 * sum.max(1.0))
    }

    /// Periods the routine runs: (settle + 1)·N + 2 (the capture of period p is taken at
    /// period p + 1, from the previous control step; one more period to finish).
    pub fn total_periods(&self) -> u64 {
        u64::from(self.settle_periods)
            .saturating_add(1)
            .saturating_mul(u64::from(self.period))
            .saturating_add(2)
    }

    /// The initial state (the oscillators' rotations and phases; libm, once per run).
    pub fn start(&self) -> FrequencyResponseState {
        let mut st = FrequencyResponseState {
            n: 0,
            rotation: [(1.0, 0.0); MAX_LINES],
            initial: [(0.0, 0.0); MAX_LINES],
            phasor: [(0.0, 0.0); MAX_LINES],
            last: 0.0,
        };
        let period = self.period.max(1) as f32;
        for (j, &k) in self.lines.used().iter().enumerate() {
            let a = self.line_amplitude(j);
            let w = 2.0 * core::f32::consts::PI * f32::from(k) / period;
            let phi = schroeder_phase(j, self.lines.count);
            if let (Some(r), Some(i)) = (st.rotation.get_mut(j), st.initial.get_mut(j)) {
                *r = (libm::cosf(w), libm::sinf(w));
                *i = (a * libm::cosf(phi), a * libm::sinf(phi));
            }
        }
        st
    }

    /// One period with the measured currents `i_dq` \[A\] and the previous step's
    /// controller output on the injected axis `u_pi` \[V\]: the demand, and the
    /// capture of the previous period when it falls in the captured one.
    pub fn process(
        &self,
        st: &mut FrequencyResponseState,
        i_dq: Dq,
        u_pi: f32,
    ) -> (Progress<Result<(), CommissioningError>>, Option<LoopSample>) {
        let n = st.n;
        let magnitude = libm::sqrtf(i_dq.d * i_dq.d + i_dq.q * i_dq.q);
        if magnitude.is_nan() || magnitude > self.current_trip {
            return (
                Progress::Finished(Err(CommissioningError::Tripped {
                    sample: n,
                    current: magnitude,
                })),
                None,
            );
        }
        let period = u64::from(self.period.max(1));
        let from = u64::from(self.settle_periods).saturating_mul(period);
        let capture = match u64::from(n).checked_sub(1) {
            Some(p) if p >= from && p < from.saturating_add(period) => Some((u_pi, u_pi + st.last)),
            _ => None,
        };
        if u64::from(n).saturating_add(1) >= self.total_periods() {
            return (Progress::Finished(Ok(())), capture);
        }
        if u64::from(n).is_multiple_of(period) {
            st.phasor = st.initial;
        }
        let mut sum = 0.0f32;
        for ((re, im), &(c, s)) in st.phasor.iter_mut().zip(st.rotation.iter()).take(self.lines.count) {
            sum += *im;
            let (r, i) = (*re * c - *im * s, *im * c + *re * s);
            *re = r;
            *im = i;
        }
        // NaN (a NaN amplitude) becomes 0: no injection.
        let d = if sum.is_nan() {
            0.0
        } else {
            sum.max(-self.amplitude).min(self.amplitude)
        };
        st.last = d;
        st.n = n.saturating_add(1);
        let injection = match self.axis {
            Axis::D => Dq { d, q: 0.0 },
            Axis::Q => Dq { d: 0.0, q: d },
        };
        (
            Progress::Running(Demand::Injected {
                id: 0.0,
                iq: 0.0,
                injection,
            }),
            capture,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trig::SoftTrig;

    /// θ_off averaging across ±π: samples alternating just below +π and just above
    /// −π average to ±π, not to 0.
    #[test]
    fn resolver_offset_average_wraps() {
        let r = ResolverOffset {
            voltage: 2.0,
            ramp_samples: 4,
            settle_samples: 2,
            average_samples: 4,
        };
        let mut st = ResolverOffsetState::default();
        let mut demands = vec![];
        let samples = [
            0,
            0,
            0,
            0,
            0,
            0,
            i32::MAX - 99,
            i32::MIN + 100,
            i32::MAX - 99,
            i32::MIN + 100,
        ];
        let mut result = None;
        for &s in &samples {
            match r.process(&mut st, s) {
                Progress::Running(Demand::VoltageAlphaBeta(v)) => demands.push(v.alpha),
                Progress::Running(other) => panic!("{other:?}"),
                Progress::Finished(o) => result = Some(o),
            }
        }
        assert_eq!(demands[..6], [0.0, 0.5, 1.0, 1.5, 2.0, 2.0]);
        // Mean of (MAX−99, MIN+100) is π (i32::MIN) ± 1 LSB.
        let off = result.expect("finished");
        assert!(off.wrapping_sub(i32::MIN).unsigned_abs() <= 1, "{off}");
    }

    /// The capture buffer fills, then further samples are dropped (no panic).
    #[test]
    fn capture_buffer_is_bounded() {
        let r = VoltageStep {
            axis: Axis::D,
            voltage: 3.0,
            current_trip: 10.0,
            pre_samples: 2,
            step_samples: 10,
            decimation: 0,
        };
        let mut st = VoltageStepState::<4>::new();
        let mut n = 0;
        let done = loop {
            match r.process(
                &mut st,
                Dq {
                    d: 0.1 * n as f32,
                    q: 0.0,
                },
            ) {
                Progress::Running(Demand::VoltageDq(v)) => {
                    assert_eq!(v.d, if n < 2 { 0.0 } else { 3.0 });
                    n += 1;
                }
                Progress::Running(other) => panic!("{other:?}"),
                Progress::Finished(r) => break r,
            }
        };
        assert_eq!(done, Ok(StepRecorded { captures: 4 }));
        assert_eq!(n, 12);
        let c = st.captures();
        assert_eq!(c.len(), 4);
        assert_eq!((c[3].sample, c[3].voltage), (3, 3.0));
    }

    /// (6.3)–(6.8) on an ideal first-order record: R = U/i(∞), L = R·T_r/ln 9.
    #[test]
    fn identify_rl_on_exact_record() {
        let (u, r, l, ts) = (2.0f64, 0.5f64, 4e-3f64, 50e-6f64);
        let tau = l / r;
        let captures: Vec<Capture> = (0..4000u32)
            .map(|n| {
                let t = (f64::from(n) - 10.0) * ts;
                let i = if t <= 0.0 {
                    0.0
                } else {
                    u / r * (1.0 - (-t / tau).exp())
                };
                Capture {
                    sample: n,
                    voltage: if n >= 10 { u as f32 } else { 0.0 },
                    current: i as f32,
                }
            })
            .collect();
        let e = identify_rl(&captures, ts as f32).expect("estimate");
        // Final value from the last quarter (t > 37τ: exact to f32); the crossings are
        // interpolated linearly on a curve sampled at τ/160: ≤ 1e-4 relative.
        assert!((f64::from(e.resistance) - r).abs() < 1e-4 * r);
        assert!((f64::from(e.inductance) - l).abs() < 1e-3 * l);
        // 5 % crossing at −τ·ln 0.95.
        assert!((f64::from(e.delay) - tau * -(0.95f64.ln())).abs() < 0.1 * ts);
        assert_eq!(identify_rl(&[], 1e-4), None);
        assert_eq!(identify_rl(&captures[..5], 1e-4), None);
    }

    /// The rotating field of (6.4) turns by `step` per period and stops after the
    /// configured turns.
    #[test]
    fn pole_pair_ratio_generates_whole_turns() {
        let r = PolePairRatio {
            voltage: 1.0,
            step: -(1 << 30), // a quarter turn per period, negative direction
            turns: 2,
            settle_samples: 1,
        };
        let mut st = PolePairRatioState::default();
        let mut theta_r = 0i32;
        let mut angles = vec![];
        let result = loop {
            match r.process(&mut st, &mut SoftTrig, theta_r) {
                Progress::Running(Demand::VoltageAlphaBeta(v)) => {
                    angles.push((v.alpha.round() as i32, v.beta.round() as i32));
                    // A resolver turning half as fast, in the same direction.
                    theta_r = theta_r.wrapping_sub(1 << 29);
                }
                Progress::Running(other) => panic!("{other:?}"),
                Progress::Finished(r) => break r,
            }
        };
        assert_eq!(angles[..5], [(1, 0), (0, -1), (-1, 0), (0, 1), (1, 0)]);
        let res = result.expect("rotated");
        assert!(res.directions_agree);
        // 8 quarter turns generated. This resolver keeps turning (a real rotor stops
        // with the field): its travel is read on the 8 rotating periods, the
        // 1 hold period and the final call, 10 × 1/8 turn → ratio 2 turns/1.25 = 1.6.
        assert!((res.ratio - 1.6).abs() < 1e-6, "{}", res.ratio);
    }

    /// The line set by hand (ratio 1218/1024 for 4 per octave, rounded, at least one
    /// harmonic up): 1, 2, …, 8, then 8·1.189 = 9.5 → 10, 11.9 → 12, 14.3 → 14,
    /// 16.7 → 17, 20.2 → 20, 23.8 → 24, 28.5 → 29, and 34.5 is past the Nyquist
    /// harmonic 32.
    #[test]
    fn multisine_lines_by_hand() {
        let l = multisine_lines(1, 4, 64).expect("valid");
        assert_eq!(l.used(), [1, 2, 3, 4, 5, 6, 7, 8, 10, 12, 14, 17, 20, 24, 29]);
        assert_eq!(multisine_lines(0, 4, 64), None);
        assert_eq!(multisine_lines(32, 4, 64), None);
        assert_eq!(multisine_lines(1, 0, 64), None);
        assert_eq!(multisine_lines(1, 9, 64), None);
        // Capped at MAX_LINES.
        assert_eq!(multisine_lines(1, 8, 1 << 15).expect("valid").count, MAX_LINES);
    }

    /// On a static loop u_PI = −0.5·v (no delay: u_PI of period p answers v of period
    /// p), the capture holds N samples with u = −0.5·v, the injection repeats every N
    /// periods to the bit and never leaves ±amplitude, and a current above the trip
    /// ends the run.
    #[test]
    fn frequency_response_injects_a_periodic_bounded_multisine() {
        let r = FrequencyResponse {
            axis: Axis::Q,
            amplitude: 2.0,
            current_trip: 5.0,
            period: 64,
            settle_periods: 1,
            lines: multisine_lines(2, 2, 64).expect("valid"),
        };
        let mut st = r.start();
        let (mut u_pi, mut injected, mut captured) = (0.0f32, vec![], vec![]);
        loop {
            let (pr, c) = r.process(&mut st, Dq { d: 0.0, q: 1.0 }, u_pi);
            captured.extend(c);
            match pr {
                Progress::Running(Demand::Injected { id, iq, injection }) => {
                    assert_eq!((id, iq, injection.d), (0.0, 0.0, 0.0));
                    assert!(injection.q.abs() <= 2.0);
                    injected.push(injection.q);
                    // u_PI = −0.5·(u_PI + d) → u_PI = −d/3.
                    u_pi = -injection.q / 3.0;
                }
                Progress::Running(other) => panic!("{other:?}"),
                Progress::Finished(done) => {
                    assert_eq!(done, Ok(()));
                    break;
                }
            }
        }
        assert_eq!(injected.len() as u64, r.total_periods() - 1);
        assert_eq!(injected[..64], injected[64..128]);
        assert!(injected.iter().any(|d| d.abs() > 0.5));
        assert_eq!(captured.len(), 64);
        for (k, (u, v)) in captured.iter().enumerate() {
            assert!((u + 0.5 * v).abs() < 1e-6, "{k}: {u} {v}");
            // v − u is d up to the rounding of v = u + d in f32.
            assert!((*v - *u - injected[64 + k]).abs() < 1e-6);
        }
        let mut st = r.start();
        let (pr, c) = r.process(&mut st, Dq { d: 4.0, q: 4.0 }, 0.0);
        assert!(matches!(
            pr,
            Progress::Finished(Err(CommissioningError::Tripped { sample: 0, .. }))
        ));
        assert_eq!(c, None);
    }
}
