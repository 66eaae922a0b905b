//! Stage 5 of the current-loop pipeline ([`super`]): the largest bandwidth whose sampled
//! loop meets the floors of [`super::analysis`] on both axes (phase and gain margin,
//! overshoot, rise time) and, for a drive, the at-speed figures of [`super::at_speed`]
//! (decoupling, DC-link step) — every criterion `motorgen verify` applies that depends on α —
//! searched above the smallest bandwidth each method accepts (thesis A §5.4.1, thesis B
//! (2.43)): what an error at `current_loop.bandwidth` names when the requested one does
//! not meet them.

use super::at_speed::{self, DESIGN_MARGIN, Drive, MIN_DECOUPLING_RATIO};
use super::continuous::{Promise, natural_frequency};
use super::{Request, axis_letter, design};
use crate::spec::Method;

/// The axes' requests (d, q, or one axis) at bandwidth `alpha` [rad/s]: the first floor
/// breach or design error, then (with a `drive` and both axes, d then q) an at-speed
/// figure that fails ([`at_speed_breach`]); `None` if every axis meets them.
pub fn breach_at(axes: &[Request], drive: Option<&Drive>, alpha: f64) -> Option<String> {
    let mut gains = Vec::new();
    for req in axes.iter().map(|r| r.at_bandwidth(alpha)) {
        match design(&req) {
            Ok(g) => {
                if let Some(b) = g.sampled.breach(&Promise::of(&req)) {
                    return Some(format!("{} axis: {b}", axis_letter(req.axis)));
                }
                gains.push(g);
            }
            Err(e) => return Some(format!("{e:?}")),
        }
    }
    match (drive, gains.as_slice()) {
        (Some(dr), [gd, gq]) => at_speed_breach(dr, [gd, gq], alpha),
        _ => None,
    }
}

/// The at-speed figures of the gains `[d, q]` at `alpha` against `verify`'s criteria with
/// the design's [`DESIGN_MARGIN`]: the decoupling ratio, then the DC-link step; the first
/// that fails, described, or `None`.
pub fn at_speed_breach(dr: &Drive, gains: [&super::AxisGains; 2], alpha: f64) -> Option<String> {
    let x = at_speed::decoupling(dr, gains, alpha);
    if x.ratio < MIN_DECOUPLING_RATIO * DESIGN_MARGIN {
        return Some(format!(
            "keeps the axes apart only {:.2}× (thesis A (5.3), Figs. 5.4 vs 5.6): an i_q step of {:.3} A at ω_e = {:.1} rad/s moves i_d by {:.4} A without the decoupling feed-forward and {:.4} A with it; `motorgen verify` asks ≥ {MIN_DECOUPLING_RATIO}× (the design {:.2}×, for what its model leaves out): a wide loop rejects the coupling itself, while the feed-forward of the sampled current lags the step",
            x.ratio,
            x.amplitude_a,
            x.speed_rad_s,
            x.excursion_a[0],
            x.excursion_a[1],
            MIN_DECOUPLING_RATIO * DESIGN_MARGIN
        ));
    }
    let s = at_speed::dc_link_step(dr, gains, alpha);
    (!s.passes(DESIGN_MARGIN)).then(|| {
        format!(
            "does not ride a DC-link step (thesis A (5.1), §4.6): U_dc {} → {} V at ω_e = {:.1} rad/s, i_q = {:.3} A leaves |i − i_ref| at {:.4} A (peak {:.4} A) after {}/α, where `motorgen verify` asks ≤ {} % of i_q + the ripple {:.4} A = {:.4} A (peak ≤ {}·Δi_1 + ripple = {:.4} A), the design {} % less: the one-period kick of the 1/U_dc feed-forward decays at the loop's disturbance pole (R/L for IMC), slower than 10/α for a wide loop",
            s.dc_link_v[0],
            s.dc_link_v[1],
            x.speed_rad_s,
            s.amplitude_a,
            s.last_a,
            s.peak_a,
            at_speed::STEP_SPANS,
            at_speed::SETTLED_SHARE * 100.0,
            s.ripple_a,
            at_speed::SETTLED_SHARE * s.amplitude_a + s.ripple_a,
            at_speed::KICK_ALLOWANCE,
            at_speed::KICK_ALLOWANCE * s.kick_a + s.ripple_a,
            ((DESIGN_MARGIN - 1.0) * 100.0).round()
        )
    })
}

/// The smallest bandwidth the method accepts [rad/s]: above the right-half-plane-zero
/// limit of pole placement (thesis A §5.4.1), above R/L of active damping (thesis B
/// (2.43)), else 10⁻⁴ of the requested one.
fn lowest(axes: &[Request]) -> f64 {
    let Some(d) = axes.first() else {
        return 0.0;
    };
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
/// sampled loop meets the floors of [`super::analysis`] on both axes and (with a `drive`)
/// the at-speed figures of [`super::at_speed`] (`verify`'s decoupling and DC-link-step
/// criteria), by bisection on a logarithmic scale (to 0.1 %); `None` if even the method's
/// smallest bandwidth does not (or there is no axis). (The figures worsen with α, the floors hold below their
/// first breach: the accepted set is an interval from below; the sweep of
/// `motor-verify`'s `bandwidth_sweep.rs` runs `verify` at the result.)
pub fn largest_bandwidth(axes: &[Request], drive: Option<&Drive>) -> Option<f64> {
    let alpha = axes.first()?.bandwidth_rad_s;
    if breach_at(axes, drive, alpha).is_none() {
        return Some(alpha);
    }
    let mut lo = lowest(axes).min(alpha);
    if breach_at(axes, drive, lo).is_some() {
        return None;
    }
    let mut hi = alpha;
    while hi / lo > 1.001 {
        let mid = (lo * hi).sqrt();
        if breach_at(axes, drive, mid).is_none() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(lo)
}
