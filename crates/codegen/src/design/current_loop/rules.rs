//! Stage 5 of the current-loop pipeline ([`super`]): the verdict on a request, as one
//! set of rules for every path to the gains — the design's current-loop section (what
//! `motorgen check` and `design` report at `current_loop.bandwidth`) and the `pi_gains!`
//! proc-macro (a compile error at its `bandwidth` argument) call [`verdict`] and print its
//! [`Refusal`]: the rule that is broken, the figure that breaks it, and the bandwidth that
//! works ([`super::bandwidth::largest_bandwidth`], rounded down to three significant
//! figures).

use std::fmt;

use super::analysis::{AxisGains, MIN_GAIN_MARGIN_DB, MIN_PHASE_MARGIN_DEG, OVERSHOOT_ALLOWANCE_PCT, RISE_TOLERANCE};
use super::at_speed::Drive;
use super::continuous::{CurrentLoopError, Promise};
use super::{Request, axis_letter, bandwidth, design};

/// Why a current-loop request is refused: what is wrong (the rule and the figure that
/// breaks it) and what would be accepted (the bandwidth that works).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refusal {
    /// What is wrong, with the rule and its source.
    pub problem: String,
    /// What would be accepted instead.
    pub accepted: String,
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}; accepted: {}", self.problem, self.accepted)
    }
}

/// `x` > 0 rounded down to three significant figures: the bandwidth a refusal names lies
/// inside the floors, not on the bisected boundary (where the firmware's fixed-point step
/// may land a hair past the overshoot floor).
pub fn round_down_3(x: f64) -> f64 {
    let unit = 10f64.powi(x.log10().floor() as i32 - 2);
    (x / unit).floor() * unit
}

/// The bandwidth a refusal names \[rad/s\]: [`bandwidth::largest_bandwidth`] rounded down to
/// three significant figures, and that value itself checked — the at-speed figures are
/// not monotone in α to the last digit (amk-dd5-ipm, IMC without delay compensation: the
/// bisection's 1575 rad/s meets the DC-link step, 1570 misses it by 0.5 %) — lowered by
/// 1 % until it meets every rule it was searched for; `None` if none does within 50 steps.
pub fn named_bandwidth(axes: &[Request], drive: Option<&Drive>) -> Option<f64> {
    let mut a = round_down_3(bandwidth::largest_bandwidth(axes, drive)?);
    for _ in 0..50 {
        if bandwidth::breach_at(axes, drive, a).is_none() {
            return Some(a);
        }
        a = round_down_3(a * 0.99);
    }
    None
}

/// The axes (d then q, or one axis alone) through the pipeline and judged by the rules
/// that need only R, L and the sampling: each axis's gains, or the first rule a request
/// breaks — a design rule of the method (a right-half-plane zero of pole placement,
/// negative active damping) or a floor of the sampled loop (stability, margins,
/// overshoot, rise time; [`super::analysis`]). A motor's design adds the at-speed figures
/// ([`at_speed_refusal`]), which need its ψ_M, speed and DC link.
pub fn verdict(axes: &[Request]) -> Result<Vec<AxisGains>, Refusal> {
    let gains = axes
        .iter()
        .map(design)
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| design_error(axes, e))?;
    match floor_breach(axes, &gains, None) {
        Some(r) => Err(r),
        None => Ok(gains),
    }
}

/// The refusal of a design rule of the method (`axes` names the bandwidth and method).
pub fn design_error(axes: &[Request], e: CurrentLoopError) -> Refusal {
    let alpha = axes.first().map_or(0.0, |r| r.bandwidth_rad_s);
    let loop_of = |axis| {
        if axes.len() > 1 {
            format!("the {}-axis loop", axis_letter(axis))
        } else {
            "the loop".to_string()
        }
    };
    match e {
        CurrentLoopError::RhpZero {
            axis,
            min_bandwidth_rad_s,
        } => Refusal {
            problem: format!(
                "pole placement at α = {alpha:.4} rad/s puts a right-half-plane zero in {} (ω_n·ζ < R/(2L), thesis A §5.4.1)",
                loop_of(axis)
            ),
            accepted: format!(
                "a bandwidth above {min_bandwidth_rad_s:.1} rad/s, a larger damping, or method = \"imc\""
            ),
        },
        CurrentLoopError::NegativeActiveDamping {
            axis,
            min_bandwidth_rad_s,
        } => Refusal {
            problem: format!(
                "α_c·L < R {}: the active damping R_a = α_c·L − R (thesis B 2.43) would be negative",
                if axes.len() > 1 {
                    format!("on the {} axis", axis_letter(axis))
                } else {
                    "on this axis".to_string()
                }
            ),
            accepted: format!("a bandwidth above R/L = {min_bandwidth_rad_s:.1} rad/s, or method = \"imc\""),
        },
    }
}

/// The refusal of the first floor an axis's sampled loop breaks (`gains` in the order
/// of `axes`), `None` if every axis meets them. With the motor's `drive` (both axes) the
/// bandwidth it names also meets the at-speed figures ([`at_speed_refusal`]).
pub fn floor_breach(axes: &[Request], gains: &[AxisGains], drive: Option<&Drive>) -> Option<Refusal> {
    let first = axes.first()?;
    let promise = Promise::of(first);
    let (axis, breach) = axes
        .iter()
        .zip(gains)
        .find_map(|(req, g)| g.sampled.breach(&promise).map(|b| (req.axis, b)))?;
    let fs = 1.0 / first.sample_period_s;
    let alpha = first.bandwidth_rad_s;
    let designed_os = promise.overshoot_pct;
    let both = axes.len() > 1;
    let which = if both {
        format!("sampled {}-axis loop", axis_letter(axis))
    } else {
        "sampled loop".to_string()
    };
    let best = named_bandwidth(axes, drive);
    let accepted = match (best, drive) {
        (Some(a), Some(_)) => format!(
            "a bandwidth up to {a:.0} rad/s, the largest that meets the floors on both axes and the at-speed figures `motorgen verify` checks (decoupling, DC-link step) for this motor at f_s = {fs} Hz{}, or a higher f_s",
            // Where the at-speed figures bind, the floors' own limit too.
            match named_bandwidth(axes, None) {
                Some(f) if f > a => format!(" (the floors alone allow up to {f:.0} rad/s)"),
                _ => String::new(),
            }
        ),
        (Some(a), None) => format!(
            "a bandwidth up to {a:.0} rad/s, the largest that meets the floors {} at f_s = {fs} Hz, or a higher f_s",
            if both {
                "on both axes for this motor"
            } else {
                "for this R and L"
            }
        ),
        (None, Some(_)) => format!(
            "a higher f_s or another method: no bandwidth from the method's smallest up meets both the floors and the at-speed figures `motorgen verify` checks for this motor at this f_s{}",
            match named_bandwidth(axes, None) {
                Some(f) => format!(" (the floors alone allow up to {f:.0} rad/s)"),
                None => String::new(),
            }
        ),
        (None, None) => format!(
            "a higher f_s: no bandwidth meets the floors {} at this f_s",
            if both { "for this motor" } else { "for this R and L" }
        ),
    };
    Some(Refusal {
        problem: format!(
            "the {which} at α = {alpha:.1} rad/s (f_s = {fs} Hz, {:.4}·T_s delay{}) is {breach}; the floors are phase margin ≥ {MIN_PHASE_MARGIN_DEG}°, gain margin ≥ {MIN_GAIN_MARGIN_DB} dB (Åström & Murray §10.3), overshoot ≤ {:.1} % (designed {designed_os:.1} % + {OVERSHOOT_ALLOWANCE_PCT} %){}",
            first.loop_delay_s / first.sample_period_s,
            if first.compensate_delay {
                ", delay-compensated"
            } else {
                ""
            },
            designed_os + OVERSHOOT_ALLOWANCE_PCT,
            promise.rise_time_s.map_or(String::new(), |t| format!(
                " and a rise time within {:.0} % of the designed {:.4} ms",
                RISE_TOLERANCE * 100.0,
                t * 1e3
            )),
        ),
        accepted,
    })
}

/// The refusal of the at-speed figures of a motor's design (`verify`'s decoupling and
/// DC-link-step criteria on the firmware's own controller, [`super::at_speed`]) at the
/// requested bandwidth, for gains `[d, q]` that meet the floors; `None` if they hold.
pub fn at_speed_refusal(axes: &[Request], gains: [&AxisGains; 2], drive: &Drive) -> Option<Refusal> {
    let first = axes.first()?;
    let alpha = first.bandwidth_rad_s;
    let fs = 1.0 / first.sample_period_s;
    let breach = bandwidth::at_speed_breach(drive, gains, alpha)?;
    let best = named_bandwidth(axes, Some(drive));
    Some(Refusal {
        problem: format!("at α = {alpha:.1} rad/s (f_s = {fs} Hz) the loop {breach}"),
        accepted: match best {
            Some(a) => format!(
                "a bandwidth up to {a:.0} rad/s, the largest that meets the sampled-loop floors and the at-speed figures for this motor at f_s = {fs} Hz"
            ),
            None => "a higher f_s: no bandwidth meets the floors and the at-speed figures for this motor at this f_s"
                .to_string(),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::round_down_3;

    #[test]
    fn named_bandwidth_is_rounded_down() {
        assert_eq!(round_down_3(13_694.6), 13_600.0);
        assert_eq!(round_down_3(6280.3), 6280.0);
        assert_eq!(round_down_3(999.99), 999.0);
    }
}
