//! Stage 1 of the current-loop pipeline ([`super`]): the continuous design rules per
//! axis for the plant M(s) = 1/(Ls + R) (thesis A 5.5), and what they promise.
//!
//! * `imc` — first-order IMC, thesis A (5.8), (5.9): K_a = L·α, K_b = R/L.
//! * `pole_placement` — thesis A (5.14), (5.15): K_i = L·ω_n², K_p = 2ζω_n·L − R,
//!   ω_n from the bandwidth; prefilter (5.16) cancels the closed-loop zero.
//! * `imc_active_damping` — thesis B (2.38), (2.39), (2.43): k_p = α_c·L,
//!   R_a = α_c·L − R, k_i = α_c·(R + R_a).
//!
//! Parallel (K_p, K_i) and series (K_a, K_b) forms are related by (5.7).
//!
//! The designed closed-loop step of each method ([`designed_step`]) is the response the
//! user asks for: the sampled loop is judged against it ([`Promise`], [`super::analysis`])
//! and the simulation compared with it (`motor-verify`).

use motor_control::commissioning::Axis;
use serde::Serialize;

use super::Request;
use crate::spec::Method;

/// Guideline of thesis A §5.4.1: first-order loops below 30 % of f_s.
pub const FIRST_ORDER_BANDWIDTH_FRACTION: f64 = 0.30;
/// Guideline of thesis A §5.4.1: second-order loops below 17 % of f_s.
pub const SECOND_ORDER_BANDWIDTH_FRACTION: f64 = 0.17;

/// The reference prefilter D(s) = (K_i/L)/((K_p/L)s + K_i/L) = 1/(τ_f·s + 1) (5.16).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Prefilter {
    /// τ_f = K_p/K_i \[s\].
    pub time_constant_s: f64,
    /// Pole of D(s) = zero of (5.11) being cancelled, K_i/K_p [rad/s].
    pub pole_rad_s: f64,
    /// Exact (ZOH) discrete coefficient a = 1 − e^(−T_s/τ_f): y += a·(x − y).
    pub discrete_coefficient: f64,
}

/// One axis's PI before the sampled-loop analysis: what the design rules of this stage
/// and of [`super::discrete`] produce, completed by [`super::analysis::finish`].
#[derive(Debug, Clone, PartialEq)]
pub struct Pi {
    /// K_p [V/A].
    pub kp: f64,
    /// K_i [V/(A·s)].
    pub ki: f64,
    /// R_a \[Ω\].
    pub active_damping_ohm: f64,
    /// Reference prefilter (pole placement).
    pub prefilter: Option<Prefilter>,
    /// Designed closed-loop poles [rad/s].
    pub designed_poles: Vec<[f64; 2]>,
    /// Bandwidth α designed for [rad/s].
    pub bandwidth_rad_s: f64,
}

/// Why a current-loop design is refused.
#[derive(Debug, Clone, PartialEq)]
pub enum CurrentLoopError {
    /// ω_n·ζ < R/(2L): the closed loop gets a right-half-plane zero (thesis A §5.4.1).
    RhpZero {
        /// Which axis.
        axis: Axis,
        /// Smallest bandwidth α [rad/s] that avoids it.
        min_bandwidth_rad_s: f64,
    },
    /// α_c·L < R: the active damping (2.43) would be negative.
    NegativeActiveDamping {
        /// Which axis.
        axis: Axis,
        /// Smallest bandwidth α_c = R/L [rad/s] that avoids it.
        min_bandwidth_rad_s: f64,
    },
}

/// ω_n/α ratio of (5.15): ω_n = α / sqrt(1 − 2ζ² + sqrt(4ζ⁴ − 4ζ² + 2)).
pub fn natural_frequency(bandwidth: f64, zeta: f64) -> f64 {
    let z2 = zeta * zeta;
    bandwidth / (1.0 - 2.0 * z2 + (4.0 * z2 * z2 - 4.0 * z2 + 2.0).sqrt()).sqrt()
}

/// Overshoot of a second-order step response, exp(−πζ/√(1−ζ²)) for ζ < 1 (thesis A §5.4.1).
pub fn overshoot(zeta: f64) -> f64 {
    if zeta >= 1.0 {
        0.0
    } else {
        (-std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp()
    }
}

/// The continuous design rules of the module documentation for `req` (its method, axis,
/// R, L, α, ζ; T_s for the prefilter's discrete coefficient).
pub fn design(req: &Request) -> Result<Pi, CurrentLoopError> {
    let (axis, r, l, alpha, zeta, ts) = (
        req.axis,
        req.resistance_ohm,
        req.inductance_h,
        req.bandwidth_rad_s,
        req.damping,
        req.sample_period_s,
    );
    let (kp, ki, ra, prefilter, poles) = match req.method {
        Method::Imc => {
            let ka = l * alpha; // (5.9)
            let kb = r / l;
            (ka, ka * kb, 0.0, None, vec![[-alpha, 0.0], [-r / l, 0.0]])
        }
        Method::PolePlacement => {
            let wn = natural_frequency(alpha, zeta);
            if wn * zeta < r / (2.0 * l) {
                let wn_min = r / (2.0 * l * zeta);
                return Err(CurrentLoopError::RhpZero {
                    axis,
                    min_bandwidth_rad_s: wn_min * alpha / wn,
                });
            }
            let ki = l * wn * wn; // (5.14)
            let kp = 2.0 * zeta * wn * l - r;
            let tau_f = kp / ki;
            let pre = Prefilter {
                time_constant_s: tau_f,
                pole_rad_s: ki / kp,
                discrete_coefficient: -(-ts / tau_f).exp_m1(),
            };
            let (re, im) = if zeta < 1.0 {
                (-zeta * wn, wn * (1.0 - zeta * zeta).sqrt())
            } else {
                (-zeta * wn, 0.0)
            };
            let poles = if zeta < 1.0 {
                vec![[re, im], [re, -im]]
            } else {
                let d = wn * (zeta * zeta - 1.0).sqrt();
                vec![[re + d, 0.0], [re - d, 0.0]]
            };
            (kp, ki, 0.0, Some(pre), poles)
        }
        Method::ImcActiveDamping => {
            let ra = alpha * l - r; // (2.43)
            if ra < 0.0 {
                return Err(CurrentLoopError::NegativeActiveDamping {
                    axis,
                    min_bandwidth_rad_s: r / l,
                });
            }
            (
                alpha * l,
                alpha * (r + ra),
                ra,
                None,
                vec![[-alpha, 0.0], [-alpha, 0.0]],
            ) // (2.38), (2.39)
        }
    };
    Ok(Pi {
        kp,
        ki,
        active_damping_ohm: ra,
        prefilter,
        designed_poles: poles,
        bandwidth_rad_s: alpha,
    })
}

/// Upper bandwidth guideline [rad/s] for `method` at switching frequency `fs` \[Hz\]: α/(2π) < fraction·f_s.
pub fn bandwidth_limit(method: Method, fs: f64) -> f64 {
    let fraction = match method {
        Method::Imc | Method::ImcActiveDamping => FIRST_ORDER_BANDWIDTH_FRACTION,
        Method::PolePlacement => SECOND_ORDER_BANDWIDTH_FRACTION,
    };
    2.0 * std::f64::consts::PI * fraction * fs
}

/// The method's designed step overshoot [%]: 0 for the first-order methods (thesis A
/// (5.8), thesis B (2.41)), e^(−πζ/√(1−ζ²)) for pole placement (thesis A §5.4.1).
pub fn designed_overshoot_pct(method: Method, zeta: f64) -> f64 {
    match method {
        Method::PolePlacement => 100.0 * overshoot(zeta),
        _ => 0.0,
    }
}

/// (ω_n of (5.15), ζ) of `req`'s designed step for pole placement; `None` for the
/// first-order methods.
pub fn second_order(req: &Request) -> Option<(f64, f64)> {
    (req.method == Method::PolePlacement).then(|| (natural_frequency(req.bandwidth_rad_s, req.damping), req.damping))
}

/// What the method designs the step to do: the reference of the overshoot and rise floors
/// of [`super::analysis`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Promise {
    /// Designed overshoot [%].
    pub overshoot_pct: f64,
    /// Designed 10–90 % rise time \[s\], when the design promises it (delay compensation).
    pub rise_time_s: Option<f64>,
}

impl Promise {
    /// What `req`'s method designs at its bandwidth (damping ζ for pole placement): its
    /// overshoot, and with `compensate_delay` its rise time, ln 9/α (thesis A (5.8)) or the
    /// second-order step's with ω_n of (5.15) ([`designed_rise_time`]).
    pub fn of(req: &Request) -> Promise {
        Promise {
            overshoot_pct: designed_overshoot_pct(req.method, req.damping),
            rise_time_s: req
                .compensate_delay
                .then(|| designed_rise_time(req.bandwidth_rad_s, second_order(req))),
        }
    }
}

/// Unit step response of the designed closed loop at `t` \[s\]: first order
/// `1 − e^(−αt)` (thesis A (5.8), thesis B (2.41)) when `zeta` is `None`, else the
/// second-order system of thesis A (4.14) with ω_n, ζ (the prefilter (5.16) having
/// cancelled the zero).
pub fn designed_step(t: f64, alpha: f64, second_order: Option<(f64, f64)>) -> f64 {
    match second_order {
        None => 1.0 - (-alpha * t).exp(),
        Some((wn, zeta)) if zeta < 1.0 => {
            let wd = wn * (1.0 - zeta * zeta).sqrt();
            1.0 - (-zeta * wn * t).exp() * ((wd * t).cos() + zeta / (1.0 - zeta * zeta).sqrt() * (wd * t).sin())
        }
        Some((wn, 1.0)) => 1.0 - (-wn * t).exp() * (1.0 + wn * t),
        Some((wn, zeta)) => {
            let r = (zeta * zeta - 1.0).sqrt();
            let (p1, p2) = (wn * (zeta - r), wn * (zeta + r));
            1.0 - (p2 * (-p1 * t).exp() - p1 * (-p2 * t).exp()) / (p2 - p1)
        }
    }
}

/// 10–90 % rise time of [`designed_step`] \[s\], found on a grid of 1/(2000·α).
pub fn designed_rise_time(alpha: f64, second_order: Option<(f64, f64)>) -> f64 {
    let dt = 1.0 / (2000.0 * alpha);
    let y: Vec<f64> = (0..40_000)
        .map(|k| designed_step(k as f64 * dt, alpha, second_order))
        .collect();
    rise_time(&y, dt).unwrap_or(f64::NAN)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::current_loop::analysis::AxisGains;
    use crate::design::current_loop::{design as pipeline, test_request};
    use nalgebra::{Complex, Matrix2};
    use proptest::prelude::*;

    /// Closed loop of L·di/dt = −R·i + u, u = K_p(r − i) + K_i·I − R_a·i, dI/dt = r − i,
    /// written independently of the design code: state [i, I].
    fn closed_loop_poles(r: f64, l: f64, g: &AxisGains) -> Vec<Complex<f64>> {
        let a = Matrix2::new(-(r + g.active_damping_ohm + g.kp) / l, g.ki / l, -1.0, 0.0);
        a.complex_eigenvalues().iter().copied().collect()
    }

    fn same_poles(mut got: Vec<Complex<f64>>, want: &[[f64; 2]], tol: f64) -> bool {
        let mut want: Vec<Complex<f64>> = want.iter().map(|p| Complex::new(p[0], p[1])).collect();
        let key = |c: &Complex<f64>| (c.re, c.im);
        got.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
        want.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
        got.iter()
            .zip(&want)
            .all(|(g, w)| (g - w).norm() <= tol * w.norm().max(1.0))
    }

    /// Thesis A Table 6.1 (Unimotor): R = 0.65 Ω, L_d = 5.4 mH, α = 100 rad/s.
    /// IMC (5.9) by hand: K_a = 5.4e-3·100 = 0.54 V/A, K_b = 0.65/5.4e-3 = 120.37 rad/s,
    /// K_i = K_a·K_b = 0.65·100 = 65 V/(A·s).
    #[test]
    fn unimotor_imc_d_axis() {
        let g = pipeline(&test_request(Method::Imc, 0.65, 5.4e-3, 100.0, 0.0, 5e-5)).unwrap();
        assert!((g.ka - 0.54).abs() < 1e-12);
        assert!((g.kb - 120.370_370).abs() < 1e-5);
        assert!((g.ki - 65.0).abs() < 1e-9);
    }

    /// Pole placement for ζ = 1/√2: (5.15) gives ω_n = α (1 − 1 + √(1 − 2 + 2) = 1).
    /// Unimotor L_q = 7.6 mH, α = 100: K_i = 7.6e-3·100² = 76, K_p = 2·0.70711·100·7.6e-3 − 0.65 = 0.42480.
    #[test]
    fn unimotor_pole_placement_q_axis() {
        let z = std::f64::consts::FRAC_1_SQRT_2;
        assert!((natural_frequency(100.0, z) - 100.0).abs() < 1e-9);
        let g = pipeline(&Request {
            axis: Axis::Q,
            ..test_request(Method::PolePlacement, 0.65, 7.6e-3, 100.0, z, 5e-5)
        })
        .unwrap();
        assert!((g.ki - 76.0).abs() < 1e-9);
        assert!((g.kp - 0.424_802_5).abs() < 1e-6, "{}", g.kp);
        let pre = g.prefilter.unwrap();
        assert!((pre.time_constant_s - g.kp / g.ki).abs() < 1e-15);
        // Thesis A §5.4.1: ζ = 1/√2 gives overshoot below 5 % (exp(−π) = 4.32 %).
        assert!((overshoot(z) - (-std::f64::consts::PI).exp()).abs() < 1e-12);
    }

    /// Fischer (R = 0.126 Ω, L = 0.393 mH): R/(2L) = 160.3 rad/s, so pole placement at
    /// α = 100 rad/s, ζ = 1/√2 has a RHP zero; the smallest bandwidth is 160.3/0.70711 = 226.7 rad/s.
    #[test]
    fn fischer_pole_placement_at_100_rad_s_has_rhp_zero() {
        let z = std::f64::consts::FRAC_1_SQRT_2;
        match pipeline(&test_request(Method::PolePlacement, 0.126, 0.393e-3, 100.0, z, 5e-5)) {
            Err(CurrentLoopError::RhpZero {
                min_bandwidth_rad_s, ..
            }) => assert!((min_bandwidth_rad_s - 226.7).abs() < 0.1, "{min_bandwidth_rad_s}"),
            other => panic!("expected RHP zero, got {other:?}"),
        }
        assert!(pipeline(&test_request(Method::PolePlacement, 0.126, 0.393e-3, 226.8, z, 5e-5)).is_ok());
    }

    /// Thesis B: α_c = 1.17 pu ⇔ rise time 1.5 ms with ω_base = 2π·200 Hz: ln 9/(1.17·1256.64) = 1.494 ms.
    /// Active damping (2.43) with L_d = 0.23 mH, R = 7.9 mΩ: R_a = 1470.3·0.23e-3 − 7.9e-3 = 0.3303 Ω.
    #[test]
    fn thesis_b_active_damping() {
        let alpha = 1.17 * 2.0 * std::f64::consts::PI * 200.0;
        assert!((9f64.ln() / alpha - 1.5e-3).abs() < 0.01e-3);
        let g = pipeline(&test_request(
            Method::ImcActiveDamping,
            7.9e-3,
            0.23e-3,
            alpha,
            0.0,
            1e-4,
        ))
        .unwrap();
        assert!((g.active_damping_ohm - (alpha * 0.23e-3 - 7.9e-3)).abs() < 1e-12);
        assert!((g.ki - alpha * alpha * 0.23e-3).abs() < 1e-9); // α(R + αL − R) = α²L
    }

    #[test]
    fn bandwidth_guidelines_scale_with_fs() {
        assert!((bandwidth_limit(Method::Imc, 20e3) - 2.0 * std::f64::consts::PI * 6000.0).abs() < 1e-6);
        assert!((bandwidth_limit(Method::PolePlacement, 20e3) - 2.0 * std::f64::consts::PI * 3400.0).abs() < 1e-6);
    }

    proptest! {
        /// For random plausible motors the closed-loop poles (nalgebra eigenvalues of the loop
        /// built above) sit where each method designs them.
        #[test]
        fn closed_loop_poles_land_where_designed(
            r in 0.005f64..5.0, l in 20e-6f64..50e-3, alpha_over_rl in 1.05f64..50.0, zeta in 0.4f64..1.5,
        ) {
            let alpha = alpha_over_rl * r / l; // above R/L so every method is feasible
            let alpha = alpha.max(2.0 * r / l / zeta);
            for m in [Method::Imc, Method::ImcActiveDamping, Method::PolePlacement] {
                let g = pipeline(&test_request(m, r, l, alpha, zeta, 1e-4)).unwrap();
                let got = closed_loop_poles(r, l, &g);
                // Double poles (active damping) are ill-conditioned: tolerance ~sqrt(eps).
                let tol = if m == Method::ImcActiveDamping { 1e-6 } else { 1e-9 };
                prop_assert!(same_poles(got.clone(), &g.designed_poles, tol), "{m:?}: {got:?} vs {:?}", g.designed_poles);
            }
        }
    }

    /// ln 9/α for a first-order loop (thesis A (5.8)): α = 100 rad/s → 21.97 ms.
    #[test]
    fn first_order_rise_time_is_ln9_over_alpha() {
        let t = designed_rise_time(100.0, None);
        assert!((t - 9f64.ln() / 100.0).abs() < 1e-5, "{t}");
    }

    /// ζ = 1/√2: the 10–90 % rise time from the usual empirical fit
    /// ω_n·t_r ≈ 1 − 0.4167·ζ + 2.917·ζ² = 1 − 0.2947 + 1.4585 = 2.164 (good to about
    /// 1 % for 0.3 < ζ < 0.8), and the peak e^(−π) = 4.32 % above 1 (thesis A §5.4.1).
    #[test]
    fn second_order_figures() {
        let z = std::f64::consts::FRAC_1_SQRT_2;
        let t = designed_rise_time(1.0, Some((1.0, z)));
        assert!((t - 2.164).abs() < 0.03, "{t}");
        let dt = 1e-3;
        let y: Vec<f64> = (0..20_000)
            .map(|k| designed_step(k as f64 * dt, 1.0, Some((1.0, z))))
            .collect();
        let peak = y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!((peak - 1.0 - (-std::f64::consts::PI).exp()).abs() < 1e-5, "{peak}");
    }
}
