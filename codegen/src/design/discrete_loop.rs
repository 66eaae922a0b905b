//! The current loop as the firmware realises it: sampled at T_s, with the forward-
//! difference PI (thesis A (4.17b)) and the 1.5·T_s delay of thesis A §4.6 (the ADC samples
//! at t_n, the duties computed from it act during [t_{n+1}, t_{n+2})).
//!
//! ```text
//! v(n)   = k_p·(r_f(n) − i(n)) + k_i·I(n) − R_a·i(n)        PI, active damping (B 2.31)
//! I(n+1) = I(n) + T_s·(r_f(n) − i(n))                       forward difference (4.17b)
//! i(n+1) = a·i(n) + b·v(n−1),  a = e^(−R·T_s/L), b = (1 − a)/R
//!          ZOH of 1/(Ls + R) (thesis A (5.5)) plus one period of computation delay
//! r_f(n+1) = r_f(n) + c·(1 − r_f(n))                         prefilter (5.16), c = 1 − e^(−T_s/τ_f)
//! ```
//!
//! The continuous designs (IMC (5.8)/(2.41): rise time ln 9/α) hold while α·T_s ≪ 1. Close to
//! the sampling rate the delay speeds the loop up (the discrete integrator and the delay turn
//! the first-order loop into a second-order one: for IMC z² − z + α·T_s = 0). With
//! `compensate_delay` the design lowers α per axis until this model rises in ln 9/α_spec.

use super::current_loop::{AxisGains, CurrentLoopError, design_axis};
use crate::spec::Method;

/// Unit step response of one axis at the sample instants t_n (index 0: the reference steps),
/// `n` samples, by the difference equations of the module documentation.
pub fn step_response(g: &AxisGains, r: f64, l: f64, ts: f64, n: usize) -> Vec<f64> {
    let a = (-r * ts / l).exp();
    let b = -(-r * ts / l).exp_m1() / r;
    let c = g.prefilter.as_ref().map_or(1.0, |p| p.discrete_coefficient);
    let (mut i, mut integral, mut rf, mut v_prev) = (0.0, 0.0, 0.0, 0.0);
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        out.push(i);
        rf += c * (1.0 - rf);
        let e = rf - i;
        let v = g.kp * e + g.ki * integral - g.active_damping_ohm * i;
        integral += ts * e;
        i = a * i + b * v_prev;
        v_prev = v;
    }
    out
}

/// First time [s] at which `y` (sampled every `dt`) reaches `level`, linearly interpolated.
fn crossing(y: &[f64], dt: f64, level: f64) -> Option<f64> {
    y.windows(2)
        .enumerate()
        .find_map(|(k, w)| (w[0] < level && w[1] >= level).then(|| (k as f64 + (level - w[0]) / (w[1] - w[0])) * dt))
}

/// 10–90 % rise time \[s\] of a unit step response sampled every `dt`; `None` if it never
/// reaches 90 %.
pub fn rise_time(y: &[f64], dt: f64) -> Option<f64> {
    Some(crossing(y, dt, 0.9)? - crossing(y, dt, 0.1)?)
}

/// Rise time \[s\] of one axis designed with bandwidth `alpha` (first-order methods).
pub fn predicted_rise_time(g: &AxisGains, r: f64, l: f64, ts: f64, alpha: f64) -> Option<f64> {
    // 12 time constants of the designed loop (or at least 200 samples) cover the 90 % point.
    let n = ((12.0 / alpha / ts).ceil() as usize).clamp(200, 2_000_000);
    rise_time(&step_response(g, r, l, ts, n), ts)
}

/// Designs one axis with the bandwidth α' ≤ `alpha` whose discrete loop (this module) rises in
/// ln 9/`alpha`, found by bisection (the rise time falls monotonically with α'). First-order
/// methods only (IMC, IMC with active damping); returns the gains and α'.
pub fn delay_compensated(
    method: Method,
    axis: char,
    r: f64,
    l: f64,
    alpha: f64,
    ts: f64,
) -> Result<(AxisGains, f64), CurrentLoopError> {
    let target = 9f64.ln() / alpha;
    let rise = |a: f64| -> Result<(AxisGains, Option<f64>), CurrentLoopError> {
        let g = design_axis(method, axis, r, l, a, 0.0, ts)?;
        let t = predicted_rise_time(&g, r, l, ts, a);
        Ok((g, t))
    };
    let (g, t) = rise(alpha)?;
    if t.is_some_and(|t| t >= target) {
        return Ok((g, alpha)); // the sampled loop is not faster than designed: nothing to do
    }
    // Active damping needs α' > R/L (2.43); IMC only α' > 0.
    let floor = if method == Method::ImcActiveDamping { r / l } else { 0.0 };
    let (mut lo, mut hi) = (floor.max(alpha * 1e-3), alpha);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        match rise(mid)?.1 {
            Some(t) if t < target => hi = mid,
            _ => lo = mid,
        }
    }
    let a = 0.5 * (lo + hi);
    Ok((design_axis(method, axis, r, l, a, 0.0, ts)?, a))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Far below the sampling rate the sampled IMC loop rises as the continuous design,
    /// ln 9/α (thesis A (5.8)): Fischer, α = 100 rad/s at 20 kHz → 21.97 ms ± 1 %.
    #[test]
    fn slow_loop_rises_as_designed() {
        let g = design_axis(Method::Imc, 'd', 0.126, 0.393e-3, 100.0, 0.0, 5e-5).unwrap();
        let t = predicted_rise_time(&g, 0.126, 0.393e-3, 5e-5, 100.0).unwrap();
        assert!((t / (9f64.ln() / 100.0) - 1.0).abs() < 0.01, "{t}");
    }

    /// Hand calculation: the PI zero 1 − R·T_s/L ≈ a cancels the ZOH plant pole, leaving
    /// L(z) = k_p·b/(z·(z − 1)) with k_p·b = α·L·(1 − a)/R ≈ α·T_s, i.e. the characteristic
    /// polynomial z² − z + α·T_s.
    /// Thesis B motor (R = 7.9 mΩ, L = 0.23 mH) at α = 1470 rad/s, T_s = 100 µs: the
    /// dominant root (1 + √(1 − 4·0.147))/2 = 0.8209 ↔ −ln(0.8209)/T_s = 1973 rad/s, so
    /// the loop rises in about ln 9/1973 = 1.11 ms instead of 1.49 ms.
    #[test]
    fn fast_loop_rises_early_as_the_root_locus_says() {
        let (r, l, ts, alpha) = (7.9e-3, 0.23e-3, 1e-4, 1470.0);
        let g = design_axis(Method::Imc, 'd', r, l, alpha, 0.0, ts).unwrap();
        let t = predicted_rise_time(&g, r, l, ts, alpha).unwrap();
        let root = (1.0 + (1.0f64 - 4.0 * alpha * ts).sqrt()) / 2.0;
        let hand = 9f64.ln() / (-root.ln() / ts);
        assert!((t / hand - 1.0).abs() < 0.08, "{t} vs {hand}");
        assert!(t < 0.8 * 9f64.ln() / alpha);
    }

    /// Compensation: the compensated loop rises in ln 9/α_spec (bisection to 1e-9), with a
    /// lower α', no overshoot and DC gain 1; a slow loop's α changes by under 2 %.
    #[test]
    fn compensation_restores_the_rise_time() {
        let (r, l, ts, alpha) = (7.9e-3, 0.23e-3, 1e-4, 1470.0);
        for m in [Method::Imc, Method::ImcActiveDamping] {
            let (g, a) = delay_compensated(m, 'd', r, l, alpha, ts).unwrap();
            assert!(a < alpha && a > 0.5 * alpha, "{m:?}: {a}");
            let y = step_response(&g, r, l, ts, 2_000);
            let t = rise_time(&y, ts).unwrap();
            assert!((t / (9f64.ln() / alpha) - 1.0).abs() < 1e-6, "{m:?}: {t}");
            let peak = y.iter().copied().fold(0.0, f64::max);
            assert!(peak < 1.005, "{m:?}: overshoot {peak}");
            // The plant pole R/L = 34 rad/s is cancelled only approximately in discrete time:
            // a slow residue remains, gone after 40 time constants.
            let y = step_response(&g, r, l, ts, 12_000);
            assert!((y[11_999] - 1.0).abs() < 1e-6, "{m:?}: DC gain 1: {}", y[11_999]);
        }
        let (_, a) = delay_compensated(Method::Imc, 'd', 0.126, 0.393e-3, 100.0, 5e-5).unwrap();
        assert!((a / 100.0 - 1.0).abs() < 0.02, "{a}");
    }
}
