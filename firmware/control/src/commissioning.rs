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
}
