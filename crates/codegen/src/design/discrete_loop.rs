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
//! The continuous designs (IMC (5.8)/(2.41): rise time ln 9/α; pole placement (5.14):
//! poles at −ζω_n ± jω_n√(1 − ζ²)) hold while α·T_s ≪ 1. Close to the sampling rate the
//! delay speeds the loop up and then destabilises it (the discrete integrator and the
//! delay turn the first-order loop into a second-order one: for IMC z² − z + α·T_s = 0;
//! [`super::sampled_loop`] computes its poles and margins).
//!
//! # Delay compensation (`current_loop.compensate_delay`, on by default)
//!
//! A user asks for α and gets α in the sampled loop:
//!
//! * first-order methods (IMC, IMC with active damping): "α" is the rise time ln 9/α of
//!   (5.8)/(2.41). Each axis is designed by the method's own rule for the bandwidth
//!   α' ≤ α at which this model's step rises in ln 9/α ([`delay_compensated`]);
//! * pole placement: "α" is the dominant pole pair of (5.13)–(5.15). The two gains place
//!   two roots of the sampled loop's cubic characteristic polynomial exactly at
//!   z = e^{s·T_s} of the designed s = −ζω_n ± jω_n√(1 − ζ²); the third root is what the
//!   delay adds, and the prefilter coefficient c = k_i·T_s/k_p cancels the discrete PI zero
//!   1 − k_i·T_s/k_p exactly, as (5.16) cancels the continuous one
//!   ([`pole_placement`]).

use super::current_loop::{AxisGains, CurrentLoopError, Pi, Prefilter, continuous, natural_frequency};
use super::designed_response::designed_rise_time;
use super::sampled_loop::{LoopGains, Promise, SampledPlant};
use crate::spec::Method;

/// Unit step response of one axis at the sample instants t_n (index 0: the reference steps),
/// `n` samples, by the difference equations of the module documentation.
pub fn step_response(g: &LoopGains, r: f64, l: f64, ts: f64, n: usize) -> Vec<f64> {
    let p = SampledPlant::new(r, l, ts);
    let c = g.prefilter;
    let (mut i, mut integral, mut rf, mut v_prev) = (0.0, 0.0, 0.0, 0.0);
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        out.push(i);
        rf += c * (1.0 - rf);
        let e = rf - i;
        let v = g.kp * e + g.ki * integral - g.active_damping * i;
        integral += ts * e;
        i = p.a * i + p.b * v_prev;
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
pub fn predicted_rise_time(g: &LoopGains, r: f64, l: f64, ts: f64, alpha: f64) -> Option<f64> {
    // 12 time constants of the designed loop (or at least 200 samples) cover the 90 % point.
    let n = ((12.0 / alpha / ts).ceil() as usize).clamp(200, 2_000_000);
    rise_time(&step_response(g, r, l, ts, n), ts)
}

/// One axis designed so that the sampled loop delivers the requested `alpha` (module
/// documentation): [`first_order_compensated`] for IMC and IMC with active damping,
/// [`pole_placement`] for pole placement (damping `zeta`).
pub fn delay_compensated(
    method: Method,
    axis: char,
    r: f64,
    l: f64,
    alpha: f64,
    zeta: f64,
    ts: f64,
) -> Result<AxisGains, CurrentLoopError> {
    let pi = match method {
        Method::PolePlacement => pole_placement(axis, r, l, alpha, zeta, ts)?,
        _ => first_order_compensated(method, axis, r, l, alpha, ts)?.0,
    };
    Ok(pi.finish(r, l, ts))
}

/// Designs one axis with the bandwidth α' ≤ `alpha` whose discrete loop (this module) rises in
/// ln 9/`alpha`, found by bisection (the rise time falls monotonically with α'). First-order
/// methods only (IMC, IMC with active damping); returns the gains and α'.
pub fn first_order_compensated(
    method: Method,
    axis: char,
    r: f64,
    l: f64,
    alpha: f64,
    ts: f64,
) -> Result<(Pi, f64), CurrentLoopError> {
    let target = 9f64.ln() / alpha;
    let rise = |a: f64| -> Result<(Pi, Option<f64>), CurrentLoopError> {
        let g = continuous(method, axis, r, l, a, 0.0, ts)?;
        let t = predicted_rise_time(&g.loop_gains(), r, l, ts, a);
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
    Ok((continuous(method, axis, r, l, a, 0.0, ts)?, a))
}

/// Pole placement on the sampled loop (module documentation): the roots p₁, p₂ = e^{s·T_s}
/// of the designed pair (5.13)–(5.15) and the third p₃ = 1 + a − (p₁ + p₂) (the z² coefficient
/// −(1 + a) is fixed by the plant and the delay) give, from
/// z³ − (1 + a)z² + (a + b·k_p)z + b(k_i·T_s − k_p) = (z² − S·z + P)(z − p₃),
/// S = p₁ + p₂, P = p₁·p₂:
///
/// ```text
/// k_p = (P + S·p₃ − a)/b,   k_i·T_s = k_p − P·p₃/b,   c = k_i·T_s/k_p
/// ```
///
/// A k_p ≤ 0 within twice the continuous rule's smallest bandwidth (the discrete
/// counterpart of ω_n·ζ < R/(2L), thesis A §5.4.1) is refused as a right-half-plane zero
/// with that bandwidth. Close to the sampling rate p₃ leaves the unit circle (and k_p or
/// k_i may turn negative): such gains are returned and refused by the floors of
/// [`super::sampled_loop`].
pub fn pole_placement(axis: char, r: f64, l: f64, alpha: f64, zeta: f64, ts: f64) -> Result<Pi, CurrentLoopError> {
    // The continuous design: its RHP-zero rule, its designed poles.
    let cont = continuous(Method::PolePlacement, axis, r, l, alpha, zeta, ts)?;
    let wn = natural_frequency(alpha, zeta);
    let p = SampledPlant::new(r, l, ts);
    let (sum, product) = if zeta < 1.0 {
        let (re, im) = (-zeta * wn * ts, wn * (1.0 - zeta * zeta).sqrt() * ts);
        (2.0 * re.exp() * im.cos(), (2.0 * re).exp())
    } else {
        let d = wn * (zeta * zeta - 1.0).sqrt() * ts;
        let (s1, s2) = (-zeta * wn * ts + d, -zeta * wn * ts - d);
        (s1.exp() + s2.exp(), (s1 + s2).exp())
    };
    let p3 = 1.0 + p.a - sum;
    let kp = (product + sum * p3 - p.a) / p.b;
    let ki_ts = kp - product * p3 / p.b;
    // k_p ≤ 0 near the continuous rule's limit is its right-half-plane zero; far above it
    // (poles faster than one period of delay lets the loop place) the gains go to the
    // floors, which refuse them and name the largest bandwidth that works.
    let min_bandwidth_rad_s = r / (2.0 * l * zeta) * alpha / wn;
    if kp <= 0.0 && alpha <= 2.0 * min_bandwidth_rad_s {
        return Err(CurrentLoopError::RhpZero {
            axis,
            min_bandwidth_rad_s,
        });
    }
    let c = ki_ts / kp;
    Ok(Pi {
        kp,
        ki: ki_ts / ts,
        prefilter: Some(Prefilter {
            time_constant_s: kp / (ki_ts / ts),
            pole_rad_s: ki_ts / ts / kp,
            discrete_coefficient: c,
        }),
        ..cont
    })
}

/// The sampled loop's lag behind a reference ramp \[s\]: the steady error to a unit ramp of
/// the type-1 loop, Σ T_s·(1 − y(n)) over its unit step y (the velocity-error constant
/// 1/K_v; delays included), for gains `g` designed at bandwidth `alpha` [rad/s].
pub fn ramp_lag(g: &LoopGains, r: f64, l: f64, ts: f64, alpha: f64) -> f64 {
    let n = ((40.0 / (alpha * ts)).ceil() as usize).clamp(400, 400_000);
    ts * step_response(g, r, l, ts, n).iter().map(|y| 1.0 - y).sum::<f64>()
}

/// One axis as the design step builds it: [`delay_compensated`] when `compensate`, else the
/// continuous rule of [`super::current_loop`], analysed on the sampled loop.
#[allow(clippy::too_many_arguments)]
pub fn axis(
    method: Method,
    axis: char,
    r: f64,
    l: f64,
    alpha: f64,
    zeta: f64,
    ts: f64,
    compensate: bool,
) -> Result<AxisGains, CurrentLoopError> {
    if compensate {
        delay_compensated(method, axis, r, l, alpha, zeta, ts)
    } else {
        super::current_loop::design_axis(method, axis, r, l, alpha, zeta, ts)
    }
}

/// The method's designed step overshoot [%]: 0 for the first-order methods (thesis A
/// (5.8), thesis B (2.41)), e^(−πζ/√(1−ζ²)) for pole placement (thesis A §5.4.1).
pub fn designed_overshoot_pct(method: Method, zeta: f64) -> f64 {
    match method {
        Method::PolePlacement => 100.0 * super::current_loop::overshoot(zeta),
        _ => 0.0,
    }
}

/// What the method designs at bandwidth `alpha` [rad/s] (damping `zeta` for pole
/// placement): its overshoot, and with `compensate` its rise time, ln 9/α (thesis A (5.8))
/// or the second-order step's with ω_n of (5.15) ([`designed_rise_time`]).
pub fn promise(method: Method, alpha: f64, zeta: f64, compensate: bool) -> Promise {
    let second = (method == Method::PolePlacement).then(|| (natural_frequency(alpha, zeta), zeta));
    Promise {
        overshoot_pct: designed_overshoot_pct(method, zeta),
        rise_time_s: compensate.then(|| designed_rise_time(alpha, second)),
    }
}

/// A current-loop request shared by both axes, for [`largest_bandwidth`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Request {
    /// Tuning method.
    pub method: Method,
    /// R \[Ω\].
    pub r: f64,
    /// L_d, L_q \[H\].
    pub l: [f64; 2],
    /// ζ (pole placement).
    pub zeta: f64,
    /// T_s \[s\].
    pub ts: f64,
    /// `compensate_delay`.
    pub compensate: bool,
}

impl Request {
    /// Both axes at bandwidth `alpha`, or the first floor breach or design error.
    pub fn breach_at(&self, alpha: f64) -> Option<String> {
        let promise = promise(self.method, alpha, self.zeta, self.compensate);
        for (name, l) in [('d', self.l[0]), ('q', self.l[1])] {
            match axis(self.method, name, self.r, l, alpha, self.zeta, self.ts, self.compensate) {
                Ok(g) => {
                    if let Some(b) = g.sampled.breach(&promise) {
                        return Some(format!("{name} axis: {b}"));
                    }
                }
                Err(e) => return Some(format!("{e:?}")),
            }
        }
        None
    }

    /// The smallest bandwidth the method accepts [rad/s]: above the right-half-plane-zero
    /// limit of pole placement, above R/L of active damping (2.43), else 10⁻⁴ of `alpha`.
    fn lowest(&self, alpha: f64) -> f64 {
        let rl = self.l.iter().map(|l| self.r / l).fold(0.0, f64::max);
        match self.method {
            Method::Imc => alpha * 1e-4,
            Method::ImcActiveDamping => rl * 1.001,
            Method::PolePlacement => {
                let wn_over_alpha = natural_frequency(1.0, self.zeta);
                rl / (2.0 * self.zeta) / wn_over_alpha * 1.001
            }
        }
    }
}

/// The largest bandwidth [rad/s] up to `alpha` whose sampled loop meets the floors of
/// [`super::sampled_loop`] on both axes, by bisection on a logarithmic scale (to 0.1 %);
/// `None` if even the method's smallest bandwidth does not.
pub fn largest_bandwidth(req: &Request, alpha: f64) -> Option<f64> {
    if req.breach_at(alpha).is_none() {
        return Some(alpha);
    }
    let mut lo = req.lowest(alpha).min(alpha);
    if req.breach_at(lo).is_some() {
        return None;
    }
    let mut hi = alpha;
    while hi / lo > 1.001 {
        let mid = (lo * hi).sqrt();
        if req.breach_at(mid).is_none() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(lo)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::current_loop::design_axis;

    /// Hand calculation: the ramp error of a type-1 sampled loop is 1/K_v with
    /// K_v = lim_{z→1} (z − 1)·C(z)·G(z)/T_s. Near z = 1 the forward-difference PI is
    /// k_i·T_s/(z − 1) and the ZOH plant (delays included) has DC gain 1/R, so
    /// K_v = k_i/R = α·R/R = α: the delays shift the response but not the steady lag, which
    /// is exactly 1/α. Fischer at α = 100 rad/s, 20 kHz: 10 ms.
    #[test]
    fn ramp_lag_is_one_over_alpha() {
        let (r, l, ts) = (0.126, 0.393e-3, 5e-5);
        let g = design_axis(Method::Imc, 'd', r, l, 100.0, 0.0, ts).unwrap();
        let lag = ramp_lag(&g.loop_gains(), r, l, ts, 100.0);
        assert!((lag / 0.01 - 1.0).abs() < 1e-3, "{lag}");
    }

    /// Far below the sampling rate the sampled IMC loop rises as the continuous design,
    /// ln 9/α (thesis A (5.8)): Fischer, α = 100 rad/s at 20 kHz → 21.97 ms ± 1 %.
    #[test]
    fn slow_loop_rises_as_designed() {
        let g = design_axis(Method::Imc, 'd', 0.126, 0.393e-3, 100.0, 0.0, 5e-5).unwrap();
        let t = predicted_rise_time(&g.loop_gains(), 0.126, 0.393e-3, 5e-5, 100.0).unwrap();
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
        let t = predicted_rise_time(&g.loop_gains(), r, l, ts, alpha).unwrap();
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
            let (g, a) = first_order_compensated(m, 'd', r, l, alpha, ts).unwrap();
            assert!(a < alpha && a > 0.5 * alpha, "{m:?}: {a}");
            let y = step_response(&g.loop_gains(), r, l, ts, 2_000);
            let t = rise_time(&y, ts).unwrap();
            assert!((t / (9f64.ln() / alpha) - 1.0).abs() < 1e-6, "{m:?}: {t}");
            let peak = y.iter().copied().fold(0.0, f64::max);
            assert!(peak < 1.005, "{m:?}: overshoot {peak}");
            // The plant pole R/L = 34 rad/s is cancelled only approximately in discrete time:
            // a slow residue remains, gone after 40 time constants.
            let y = step_response(&g.loop_gains(), r, l, ts, 12_000);
            assert!((y[11_999] - 1.0).abs() < 1e-6, "{m:?}: DC gain 1: {}", y[11_999]);
        }
        let (_, a) = first_order_compensated(Method::Imc, 'd', 0.126, 0.393e-3, 100.0, 5e-5).unwrap();
        assert!((a / 100.0 - 1.0).abs() < 0.02, "{a}");
    }

    /// Sampled pole placement puts two closed-loop poles exactly at e^{s·T_s} of the
    /// designed pair. Hand numbers (30-digit arithmetic), Unimotor q axis (R = 0.65 Ω,
    /// L = 7.6 mH, thesis A Table 6.1), α = 100 rad/s, ζ = 1/√2 (so ω_n = α), T_s = 50 µs:
    /// s = −70.711 ± 70.711j rad/s, ζω_n·T_s = 0.0035355, so
    /// S = 2·e^{−0.0035355}·cos 0.0035355 = 1.9929290, P = e^{−0.0070711} = 0.9929539;
    /// a = e^{−0.65·50e-6/7.6e-3} = 0.9957328, b = (1 − a)/R = 0.0065649;
    /// p₃ = 1 + a − S = 0.0028039; k_p = (P + S·p₃ − a)/b = 0.427872 V/A (continuous
    /// (5.14): 0.424802), k_i·T_s = k_p − P·p₃/b = 0.0037841, i.e. k_i = 75.681 V/(A·s)
    /// (continuous: 76), prefilter c = k_i·T_s/k_p = 0.0088439.
    #[test]
    fn sampled_pole_placement_by_hand() {
        let (r, l, ts) = (0.65, 7.6e-3, 5e-5);
        let z = std::f64::consts::FRAC_1_SQRT_2;
        let pi = pole_placement('q', r, l, 100.0, z, ts).unwrap();
        assert!((pi.kp - 0.427_872).abs() < 1e-6, "{}", pi.kp);
        assert!((pi.ki - 75.681).abs() < 1e-3, "{}", pi.ki);
        let c = pi.prefilter.as_ref().unwrap().discrete_coefficient;
        assert!((c - 0.008_843_9).abs() < 1e-7, "{c}");
        let g = pi.finish(r, l, ts);
        let want = nalgebra::Complex::new(-70.710_678, 70.710_678);
        let hit = g
            .sampled
            .poles_s_rad_s
            .iter()
            .flatten()
            .filter(|p| (nalgebra::Complex::new(p[0], p[1].abs()) - want).norm() < 1e-6)
            .count();
        assert_eq!(hit, 2, "{:?}", g.sampled.poles_s_rad_s);
        // The prefilter cancels the PI zero: the step is that of c·b·k_p·z/char(z), with
        // DC gain 1 and the designed overshoot e^(−π) = 4.32 % to within the third pole.
        let y = step_response(&g.loop_gains(), r, l, ts, 40_000);
        assert!((y[39_999] - 1.0).abs() < 1e-6, "{}", y[39_999]);
        let os = g.sampled.overshoot_pct.unwrap();
        assert!((os - 100.0 * (-std::f64::consts::PI).exp()).abs() < 0.1, "{os}");
    }

    /// Near the sampling rate the third pole p₃ = 1 + a − S leaves the unit circle: the
    /// sampled loop is then unstable although two poles sit where designed.
    #[test]
    fn sampled_pole_placement_fails_where_the_delay_pole_escapes() {
        // ω_n·T_s = 1, ζ = 0.7071: S = 2e^{−0.7071}·cos 0.7071 = 0.7498, so
        // p₃ = 1 + 0.9957 − 0.7498 = 1.246 > 1.
        let (r, l, ts) = (0.65, 7.6e-3, 5e-5);
        let z = std::f64::consts::FRAC_1_SQRT_2;
        let g = pole_placement('q', r, l, 1.0 / ts, z, ts).unwrap().finish(r, l, ts);
        assert!(
            (g.sampled.spectral_radius - 1.246).abs() < 1e-3,
            "{}",
            g.sampled.spectral_radius
        );
        assert!(
            g.sampled
                .breach(&crate::design::sampled_loop::Promise {
                    overshoot_pct: 4.32,
                    rise_time_s: None
                })
                .is_some()
        );
        assert!(g.sampled.spectral_radius > 1.0, "{}", g.sampled.spectral_radius);
    }
}
