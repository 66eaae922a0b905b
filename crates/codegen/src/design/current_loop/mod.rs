//! The current-loop PI of one axis as one pipeline, for the plant M(s) = 1/(Ls + R)
//! (thesis A (5.5)), in four stages, each a module that uses only the ones before it:
//!
//! 1. [`continuous`] — the continuous design rules: IMC, thesis A (5.8), (5.9); pole
//!    placement, (5.14)–(5.16); IMC with active damping, thesis B (2.38), (2.39), (2.43);
//!    and what they promise: the designed step, its overshoot and rise time;
//! 2. [`discrete`] — the loop as the firmware samples it (ZOH plant, forward-difference
//!    PI (4.17b), the loop delay of thesis A §4.6) and the delay compensation that makes
//!    the sampled loop deliver the requested bandwidth;
//! 3. [`analysis`] — the sampled loop's poles, gain and phase margins, overshoot and rise
//!    time, and the floors it must meet;
//! 4. [`at_speed`] — the loop at speed, on the firmware's own controller: the axes kept
//!    apart after an i_q step with and without the feed-forward (5.3), and a DC-link step
//!    under the 1/U_dc feed-forward (5.1) — the figures `motorgen verify` judges there;
//! 5. [`bandwidth`] — the largest bandwidth whose sampled loop meets the floors on both
//!    axes and the at-speed figures (what an error names);
//! 6. [`rules`] — the verdict on a request with the message of its refusal, the one set
//!    of rules of the design's current-loop section and the `pi_gains!` proc-macro.
//!
//! One [`Request`] carries an axis's inputs through all of them; [`design()`] runs the
//! first three. The spec-facing side (the `current_loop` section of the design, its
//! checks and messages located at the spec's keys) is `design::sections::current_loop`.

pub mod analysis;
pub mod at_speed;
pub mod bandwidth;
pub mod continuous;
pub mod discrete;
pub mod rules;

pub use analysis::AxisGains;
pub use continuous::CurrentLoopError;
pub use motor_control::commissioning::Axis;

use crate::spec::Method;

/// The loop delay of thesis A §4.6 in sample periods: the ADC samples at the update
/// instant t_n, and the duties computed from those samples act during [t_{n+1}, t_{n+2}),
/// 1.5·T_s on average. A motor designed without a board, and the thesis's published
/// numbers, take it; on a board the design takes the delay its timing makes
/// (`sections::board::control_timing`: the sampling phase ends after the trigger, so a
/// little less).
pub const NOMINAL_LOOP_DELAY_PERIODS: f64 = 1.5;

/// One axis's current-loop request: everything the stages of the pipeline read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Request {
    /// Tuning method.
    pub method: Method,
    /// The axis (named in errors).
    pub axis: Axis,
    /// Phase resistance R \[Ω\].
    pub resistance_ohm: f64,
    /// The axis's inductance, L_d or L_q \[H\].
    pub inductance_h: f64,
    /// Requested closed-loop bandwidth α [rad/s].
    pub bandwidth_rad_s: f64,
    /// Damping ζ of pole placement (5.15); not read by the other methods.
    pub damping: f64,
    /// Sample period T_s = 1/f_s \[s\].
    pub sample_period_s: f64,
    /// Delay from a current sample to the mean of the voltage it causes \[s\]: the
    /// board's (`sections::board::control_timing`), or [`NOMINAL_LOOP_DELAY_PERIODS`]·T_s
    /// without one. The sampled model of [`discrete`] carries delays from just above
    /// 0.5·T_s to 1.5·T_s ([`discrete::plant`]).
    pub loop_delay_s: f64,
    /// Design for the sampled loop (`current_loop.compensate_delay`, [`discrete`]); else
    /// the continuous rules as they stand.
    pub compensate_delay: bool,
}

impl Request {
    /// The same request at bandwidth `alpha` [rad/s].
    pub fn at_bandwidth(&self, alpha: f64) -> Request {
        Request {
            bandwidth_rad_s: alpha,
            ..*self
        }
    }
}

/// `d` or `q`, as messages name an axis.
pub fn axis_letter(axis: Axis) -> char {
    match axis {
        Axis::D => 'd',
        Axis::Q => 'q',
    }
}

/// One axis through the pipeline: its gains (the continuous rules, or with
/// `compensate_delay` the ones designed for the sampled loop) and the sampled loop's
/// figures with them.
pub fn design(req: &Request) -> Result<AxisGains, CurrentLoopError> {
    discrete::gains(req).map(|pi| analysis::finish(pi, req))
}

/// A request for the tests: `method` on the d axis with R = `r` \[Ω\], L = `l` \[H\],
/// α = `alpha` [rad/s], ζ = `zeta`, T_s = `ts` \[s\] and the firmware's loop delay,
/// without delay compensation.
#[cfg(test)]
pub(crate) fn test_request(method: Method, r: f64, l: f64, alpha: f64, zeta: f64, ts: f64) -> Request {
    Request {
        method,
        axis: Axis::D,
        resistance_ohm: r,
        inductance_h: l,
        bandwidth_rad_s: alpha,
        damping: zeta,
        sample_period_s: ts,
        loop_delay_s: NOMINAL_LOOP_DELAY_PERIODS * ts,
        compensate_delay: false,
    }
}
