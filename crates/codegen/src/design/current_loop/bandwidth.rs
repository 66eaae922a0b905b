//! Stage 4 of the current-loop pipeline ([`super`]): the largest bandwidth whose sampled
//! loop meets the floors of [`super::analysis`] on both axes (phase and gain margin,
//! overshoot, rise time), searched above the smallest bandwidth each method accepts
//! (thesis A §5.4.1, thesis B (2.43)): what an error at `current_loop.bandwidth` names
//! when the requested one does not meet them.

use super::continuous::{Promise, natural_frequency};
use super::{Request, axis_letter, design};
use crate::spec::Method;

/// The axes' requests (d, q, or one axis) at bandwidth `alpha` [rad/s]: the first floor
/// breach or design error, `None` if every axis meets the floors.
pub fn breach_at(axes: &[Request], alpha: f64) -> Option<String> {
    for req in axes.iter().map(|r| r.at_bandwidth(alpha)) {
        match design(&req) {
            Ok(g) => {
                if let Some(b) = g.sampled.breach(&Promise::of(&req)) {
                    return Some(format!("{} axis: {b}", axis_letter(req.axis)));
                }
            }
            Err(e) => return Some(format!("{e:?}")),
        }
    }
    None
}

/// The smallest bandwidth the method accepts [rad/s]: above the right-half-plane-zero
/// limit of pole placement (thesis A §5.4.1), above R/L of active damping (thesis B
/// (2.43)), else 10⁻⁴ of the requested one.
fn lowest(axes: &[Request]) -> f64 {
    let Some(d) = axes.first() else { return 0.0 };
    let rl = axes
        .iter()
        .map(|a| a.resistance_ohm / a.inductance_h)
        .fold(0.0, f64::max);
    match d.method {
        Method::Imc => d.bandwidth_rad_s * 1e-4,
        Method::ImcActiveDamping => rl * 1.001,
        Method::PolePlacement => {
            let wn_over_alpha = natural_frequency(1.0, d.damping);
            rl / (2.0 * d.damping) / wn_over_alpha * 1.001
        }
    }
}

/// The largest bandwidth [rad/s] up to the requested one (the axes share it) whose
/// sampled loop meets the floors of [`super::analysis`] on every axis, by bisection on a
/// logarithmic scale (to 0.1 %); `None` if even the method's smallest bandwidth does not
/// (or there is no axis).
pub fn largest_bandwidth(axes: &[Request]) -> Option<f64> {
    let alpha = axes.first()?.bandwidth_rad_s;
    if breach_at(axes, alpha).is_none() {
        return Some(alpha);
    }
    let mut lo = lowest(axes).min(alpha);
    if breach_at(axes, lo).is_some() {
        return None;
    }
    let mut hi = alpha;
    while hi / lo > 1.001 {
        let mid = (lo * hi).sqrt();
        if breach_at(axes, mid).is_none() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(lo)
}
