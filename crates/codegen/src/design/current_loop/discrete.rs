//! Stage 2 of the current-loop pipeline ([`super`]): the loop as the firmware realises
//! it, sampled at T_s, with the forward-difference PI (thesis A (4.17b)) and the loop
//! delay D·T_s from a current sample to the mean of the voltage it causes. Thesis A §4.6
//! samples at the update instant: the duties computed from the samples at t_n act during
//! [t_{n+1}, t_{n+2}), D = 1.5. A board samples a little after its ADC trigger (the
//! sampling phase ends later than the trigger: `sections::board::control_timing`), so
//! the update that loads the step's duties falls λ·T_s after the sample with
//! λ = D − 1/2 ≤ 1, and the duties of t_n act during [t_n + λ·T_s, t_{n+1} + λ·T_s).
//! Over [t_n, t_{n+1}) the plant then sees v(n−1) for λ·T_s and v(n) for the rest (the
//! modified z-transform of the ZOH plant, Franklin, Powell & Workman, *Digital Control
//! of Dynamic Systems*, §4.4.2):
//!
//! ```text
//! v(n)   = k_p·(r_f(n) − i(n)) + k_i·I(n) − R_a·i(n)        PI, active damping (B 2.31)
//! I(n+1) = I(n) + T_s·(r_f(n) − i(n))                       forward difference (4.17b)
//! i(n+1) = a·i(n) + b·v(n−1) + b₀·v(n),  a = e^(−R·T_s/L),
//!          b = (e^(−R·(1−λ)·T_s/L) − a)/R,  b₀ = (1 − e^(−R·(1−λ)·T_s/L))/R
//!          ZOH of 1/(Ls + R) (thesis A (5.5)) switching λ·T_s into the period
//! r_f(n+1) = r_f(n) + c·(1 − r_f(n))                         prefilter (5.16), c = 1 − e^(−T_s/τ_f)
//! ```
//!
//! At λ = 1 (D = 1.5) b₀ = 0 and b = (1 − a)/R: one whole period of computation delay.
//!
//! The continuous designs ([`super::continuous`]; IMC (5.8)/(2.41): rise time ln 9/α;
//! pole placement (5.14): poles at −ζω_n ± jω_n√(1 − ζ²)) hold while α·T_s ≪ 1. Close to
//! the sampling rate the delay speeds the loop up and then destabilises it (the discrete
//! integrator and the delay turn the first-order loop into a second-order one: for IMC
//! at D = 1.5 z² − z + α·T_s = 0; [`super::analysis`] computes its poles and margins).
//!
//! # Delay compensation (`current_loop.compensate_delay`, on by default)
//!
//! A user asks for α and gets α in the sampled loop:
//!
//! * first-order methods (IMC, IMC with active damping): "α" is the rise time ln 9/α of
//!   (5.8)/(2.41). Each axis is designed by the method's own rule for the bandwidth
//!   α' ≤ α at which this model's step rises in ln 9/α ([`first_order_compensated`]);
//! * pole placement: "α" is the dominant pole pair of (5.13)–(5.15). The two gains place
//!   two roots of the sampled loop's cubic characteristic polynomial exactly at
//!   z = e^{s·T_s} of the designed s = −ζω_n ± jω_n√(1 − ζ²); the third root is what the
//!   delay adds, and the prefilter coefficient c = k_i·T_s/k_p cancels the discrete PI zero
//!   1 − k_i·T_s/k_p exactly, as (5.16) cancels the continuous one
//!   ([`pole_placement`]).

use super::Request;
use super::continuous::{self, CurrentLoopError, Pi, Prefilter, natural_frequency, rise_time};
use crate::spec::Method;

/// The loop delays this model carries, in sample periods, (exclusive, inclusive): from
/// the ZOH's half period plus a sample-to-update lag λ just above 0 to λ = 1 (thesis A
/// §4.6: 1.5).
pub const MODELLED_DELAY_PERIODS: (f64, f64) = (0.5, 1.5);

/// The gains of one axis as the sampled loop sees them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopGains {
    /// k_p [V/A].
    pub kp: f64,
    /// k_i [V/(A·s)].
    pub ki: f64,
    /// R_a \[Ω\] (0 without active damping).
    pub active_damping: f64,
    /// Prefilter coefficient c of r_f += c·(r − r_f) (1: no prefilter).
    pub prefilter: f64,
}

/// The plant 1/(Ls + R) sampled with a ZOH at T_s, its voltage switching λ·T_s after
/// the sample (module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampledPlant {
    /// a = e^(−R·T_s/L).
    pub a: f64,
    /// b = (e^(−R·(1−λ)·T_s/L) − a)/R [A/V]: the weight of the previous period's voltage.
    pub b: f64,
    /// b₀ = (1 − e^(−R·(1−λ)·T_s/L))/R [A/V]: the weight of the voltage computed from
    /// this period's sample (0 at λ = 1).
    pub b0: f64,
    /// λ: sample to update, in periods (the loop delay is λ + 1/2 periods).
    pub lag: f64,
    /// T_s \[s\].
    pub ts: f64,
}

impl SampledPlant {
    /// The ZOH equivalent of 1/(Ls + R) at sample period `ts` with one whole period of
    /// computation delay (λ = 1, D = 1.5: thesis A §4.6).
    pub fn new(r: f64, l: f64, ts: f64) -> Self {
        Self::with_lag(r, l, ts, 1.0)
    }

    /// The same with the voltage switching `lag` = λ periods (0 < λ ≤ 1) after the
    /// sample: b and b₀ of the module documentation.
    pub fn with_lag(r: f64, l: f64, ts: f64, lag: f64) -> Self {
        let x = -r * ts / l;
        // e^(−R·(1−λ)·T_s/L) − 1, without cancellation for small R·T_s/L.
        let rest = (x * (1.0 - lag)).exp_m1();
        Self {
            a: x.exp(),
            b: (x.exp_m1() - rest) / -r,
            b0: -rest / r,
            lag,
            ts,
        }
    }

    /// P(z) = (b₀·z + b)/(z·(z − a)) at `z`: the current per volt of the PI output
    /// ([`super::analysis`]).
    pub fn transfer(&self, z: nalgebra::Complex<f64>) -> nalgebra::Complex<f64> {
        (self.b0 * z + self.b) / (z * (z - self.a))
    }
}

impl LoopGains {
    /// The gains of `pi` as the sampled loop sees them.
    pub fn of(pi: &Pi) -> LoopGains {
        LoopGains {
            kp: pi.kp,
            ki: pi.ki,
            active_damping: pi.active_damping_ohm,
            prefilter: pi.prefilter.as_ref().map_or(1.0, |p| p.discrete_coefficient),
        }
    }
}

/// The sampled plant of `req`'s axis (R, L, T_s), seen through its loop delay
/// D = `req.loop_delay_s`/T_s: λ = D − 1/2.
///
/// # Panics
///
/// If D lies outside [`MODELLED_DELAY_PERIODS`] (beyond 10⁻⁹ of T_s) or equals its lower
/// end: the difference equations above hold a voltage that switches inside the period
/// after the sample, and another delay needs another model. The board section refuses a
/// board whose timing makes one (`sections::board`).
pub fn plant(req: &Request) -> SampledPlant {
    let ts = req.sample_period_s;
    let periods = req.loop_delay_s / ts;
    let (lo, hi) = MODELLED_DELAY_PERIODS;
    assert!(
        periods > lo && periods < hi + 1e-9,
        "the sampled current-loop model carries a loop delay from above {lo}·T_s to {hi}·T_s, not {periods}·T_s"
    );
    SampledPlant::with_lag(req.resistance_ohm, req.inductance_h, ts, (periods - 0.5).min(1.0))
}

/// Unit step response of one axis with gains `g` on plant `p` at the sample instants t_n
/// (index 0: the reference steps), `n` samples, by the difference equations of the module
/// documentation.
pub fn step_response(g: &LoopGains, p: &SampledPlant, n: usize) -> Vec<f64> {
    let ts = p.ts;
    let c = g.prefilter;
    let (mut i, mut integral, mut rf, mut v_prev) = (0.0, 0.0, 0.0, 0.0);
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        out.push(i);
        rf += c * (1.0 - rf);
        let e = rf - i;
        let v = g.kp * e + g.ki * integral - g.active_damping * i;
        integral += ts * e;
        i = p.a * i + p.b * v_prev + p.b0 * v;
        v_prev = v;
    }
    out
}

/// Rise time \[s\] of one axis with gains `g` on plant `p`, designed with bandwidth
/// `alpha` [rad/s] (first-order methods).
pub fn predicted_rise_time(g: &LoopGains, p: &SampledPlant, alpha: f64) -> Option<f64> {
    let ts = p.ts;
    // 12 time constants of the designed loop (or at least 200 samples) cover the 90 % point.
    let n = ((12.0 / alpha / ts).ceil() as usize).clamp(200, 2_000_000);
    rise_time(&step_response(g, p, n), ts)
}

/// `req`'s gains: with `compensate_delay` designed so that the sampled loop delivers the
/// requested α (module documentation: [`first_order_compensated`] for IMC and IMC with
/// active damping, [`pole_placement`] for pole placement), else the continuous rules.
pub fn gains(req: &Request) -> Result<Pi, CurrentLoopError> {
    if !req.compensate_delay {
        return continuous::design(req);
    }
    match req.method {
        Method::PolePlacement => pole_placement(req),
        _ => Ok(first_order_compensated(req)?.0),
    }
}

/// Designs `req`'s axis with the bandwidth α' ≤ α whose discrete loop (this module) rises
/// in ln 9/α, found by bisection (the rise time falls monotonically with α'). First-order
/// methods only (IMC, IMC with active damping); returns the gains and α'.
pub fn first_order_compensated(req: &Request) -> Result<(Pi, f64), CurrentLoopError> {
    let (r, l, alpha) = (req.resistance_ohm, req.inductance_h, req.bandwidth_rad_s);
    let p = plant(req);
    let target = 9f64.ln() / alpha;
    let rise = |a: f64| -> Result<(Pi, Option<f64>), CurrentLoopError> {
        let g = continuous::design(&req.at_bandwidth(a))?;
        let t = predicted_rise_time(&LoopGains::of(&g), &p, a);
        Ok((g, t))
    };
    let (g, t) = rise(alpha)?;
    if t.is_some_and(|t| t >= target) {
        return Ok((g, alpha)); // the sampled loop is not faster than designed: nothing to do
    }
    // Active damping needs α' > R/L (2.43); IMC only α' > 0.
    let floor = if req.method == Method::ImcActiveDamping {
        r / l
    } else {
        0.0
    };
    let (mut lo, mut hi) = (floor.max(alpha * 1e-3), alpha);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        match rise(mid)?.1 {
            Some(t) if t < target => hi = mid,
            _ => lo = mid,
        }
    }
    let a = 0.5 * (lo + hi);
    Ok((continuous::design(&req.at_bandwidth(a))?, a))
}

/// Pole placement on the sampled loop (module documentation): the roots p₁, p₂ = e^{s·T_s}
/// of the designed pair (5.13)–(5.15), S = p₁ + p₂, P = p₁·p₂, and the third root p₃,
/// from the characteristic polynomial of [`super::analysis`] with M = k_i·T_s − k_p,
/// z³ + (b₀·k_p − 1 − a)z² + (a + b·k_p + b₀·M)z + b·M = (z² − S·z + P)(z − p₃):
/// matching z², z¹ and z⁰ gives p₃ = 1 + a − S − b₀·k_p, M = −P·p₃/b and
///
/// ```text
/// k_p = (P + (1 + a − S)·σ − a)/(b + b₀·σ),  σ = S + b₀·P/b
/// k_i·T_s = k_p − P·p₃/b,   c = k_i·T_s/k_p
/// ```
///
/// (at λ = 1, b₀ = 0: p₃ = 1 + a − S, k_p = (P + S·p₃ − a)/b).
///
/// A k_p ≤ 0 within twice the continuous rule's smallest bandwidth (the discrete
/// counterpart of ω_n·ζ < R/(2L), thesis A §5.4.1) is refused as a right-half-plane zero
/// with that bandwidth. Close to the sampling rate p₃ leaves the unit circle (and k_p or
/// k_i may turn negative): such gains are returned and refused by the floors of
/// [`super::analysis`].
pub fn pole_placement(req: &Request) -> Result<Pi, CurrentLoopError> {
    let (r, l, alpha, zeta, ts) = (
        req.resistance_ohm,
        req.inductance_h,
        req.bandwidth_rad_s,
        req.damping,
        req.sample_period_s,
    );
    // The continuous design: its RHP-zero rule, its designed poles.
    let cont = continuous::design(req)?;
    let wn = natural_frequency(alpha, zeta);
    let p = plant(req);
    let (sum, product) = if zeta < 1.0 {
        let (re, im) = (-zeta * wn * ts, wn * (1.0 - zeta * zeta).sqrt() * ts);
        (2.0 * re.exp() * im.cos(), (2.0 * re).exp())
    } else {
        let d = wn * (zeta * zeta - 1.0).sqrt() * ts;
        let (s1, s2) = (-zeta * wn * ts + d, -zeta * wn * ts - d);
        (s1.exp() + s2.exp(), (s1 + s2).exp())
    };
    let sigma = sum + p.b0 * product / p.b;
    let kp = (product + (1.0 + p.a - sum) * sigma - p.a) / (p.b + p.b0 * sigma);
    let p3 = 1.0 + p.a - sum - p.b0 * kp;
    let ki_ts = kp - product * p3 / p.b;
    // k_p ≤ 0 near the continuous rule's limit is its right-half-plane zero; far above it
    // (poles faster than one period of delay lets the loop place) the gains go to the
    // floors, which refuse them and name the largest bandwidth that works.
    let min_bandwidth_rad_s = r / (2.0 * l * zeta) * alpha / wn;
    if kp <= 0.0 && alpha <= 2.0 * min_bandwidth_rad_s {
        return Err(CurrentLoopError::RhpZero {
            axis: req.axis,
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
/// 1/K_v; delays included), for gains `g` on plant `p` designed at bandwidth `alpha`
/// [rad/s].
pub fn ramp_lag(g: &LoopGains, p: &SampledPlant, alpha: f64) -> f64 {
    let ts = p.ts;
    let n = ((40.0 / (alpha * ts)).ceil() as usize).clamp(400, 400_000);
    ts * step_response(g, p, n).iter().map(|y| 1.0 - y).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::current_loop::analysis;
    use crate::design::current_loop::continuous::Promise;
    use crate::design::current_loop::{Axis, design as pipeline, test_request};

    /// Hand calculation: the ramp error of a type-1 sampled loop is 1/K_v with
    /// K_v = lim_{z→1} (z − 1)·C(z)·G(z)/T_s. Near z = 1 the forward-difference PI is
    /// k_i·T_s/(z − 1) and the ZOH plant (delays included) has DC gain 1/R, so
    /// K_v = k_i/R = α·R/R = α: the delays shift the response but not the steady lag, which
    /// is exactly 1/α. Fischer at α = 100 rad/s, 20 kHz: 10 ms.
    #[test]
    fn ramp_lag_is_one_over_alpha() {
        let (r, l, ts) = (0.126, 0.393e-3, 5e-5);
        let g = pipeline(&test_request(Method::Imc, r, l, 100.0, 0.0, ts)).unwrap();
        let lag = ramp_lag(&g.loop_gains(), &SampledPlant::new(r, l, ts), 100.0);
        assert!((lag / 0.01 - 1.0).abs() < 1e-3, "{lag}");
    }

    /// Far below the sampling rate the sampled IMC loop rises as the continuous design,
    /// ln 9/α (thesis A (5.8)): Fischer, α = 100 rad/s at 20 kHz → 21.97 ms ± 1 %.
    #[test]
    fn slow_loop_rises_as_designed() {
        let g = pipeline(&test_request(Method::Imc, 0.126, 0.393e-3, 100.0, 0.0, 5e-5)).unwrap();
        let t = predicted_rise_time(&g.loop_gains(), &SampledPlant::new(0.126, 0.393e-3, 5e-5), 100.0).unwrap();
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
        let g = pipeline(&test_request(Method::Imc, r, l, alpha, 0.0, ts)).unwrap();
        let t = predicted_rise_time(&g.loop_gains(), &SampledPlant::new(r, l, ts), alpha).unwrap();
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
            let (g, a) = first_order_compensated(&test_request(m, r, l, alpha, 0.0, ts)).unwrap();
            assert!(a < alpha && a > 0.5 * alpha, "{m:?}: {a}");
            let y = step_response(&LoopGains::of(&g), &SampledPlant::new(r, l, ts), 2_000);
            let t = rise_time(&y, ts).unwrap();
            assert!((t / (9f64.ln() / alpha) - 1.0).abs() < 1e-6, "{m:?}: {t}");
            let peak = y.iter().copied().fold(0.0, f64::max);
            assert!(peak < 1.005, "{m:?}: overshoot {peak}");
            // The plant pole R/L = 34 rad/s is cancelled only approximately in discrete time:
            // a slow residue remains, gone after 40 time constants.
            let y = step_response(&LoopGains::of(&g), &SampledPlant::new(r, l, ts), 12_000);
            assert!((y[11_999] - 1.0).abs() < 1e-6, "{m:?}: DC gain 1: {}", y[11_999]);
        }
        let (_, a) = first_order_compensated(&test_request(Method::Imc, 0.126, 0.393e-3, 100.0, 0.0, 5e-5)).unwrap();
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
        let req = Request {
            axis: Axis::Q,
            ..test_request(Method::PolePlacement, r, l, 100.0, z, ts)
        };
        let pi = pole_placement(&req).unwrap();
        assert!((pi.kp - 0.427_872).abs() < 1e-6, "{}", pi.kp);
        assert!((pi.ki - 75.681).abs() < 1e-3, "{}", pi.ki);
        let c = pi.prefilter.as_ref().unwrap().discrete_coefficient;
        assert!((c - 0.008_843_9).abs() < 1e-7, "{c}");
        let g = analysis::finish(pi, &req);
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
        let y = step_response(&g.loop_gains(), &SampledPlant::new(r, l, ts), 40_000);
        assert!((y[39_999] - 1.0).abs() < 1e-6, "{}", y[39_999]);
        let os = g.sampled.overshoot_pct.unwrap();
        assert!((os - 100.0 * (-std::f64::consts::PI).exp()).abs() < 0.1, "{os}");
    }

    /// The model with the voltage switching λ·T_s into the period, against an independent
    /// simulation: the RL circuit L·di/dt = v − R·i integrated by forward Euler on 20 000
    /// sub-steps per period, the PI (4.17b) with active damping run at each sample and
    /// its voltage applied from λ·T_s after it. Fischer d axis (R = 0.126 Ω,
    /// L = 0.393 mH), IMC with active damping at α = 2000 rad/s, 20 kHz, λ = 0.9622
    /// (a board's 1.4622·T_s); the step agrees to 10⁻⁴, and b + b₀ = (1 − a)/R.
    #[test]
    fn fractional_lag_matches_a_fine_simulation() {
        let (r, l, ts, lag) = (0.126, 0.393e-3, 5e-5, 0.9622);
        let req = Request {
            loop_delay_s: (lag + 0.5) * ts,
            ..test_request(Method::ImcActiveDamping, r, l, 2000.0, 0.0, ts)
        };
        let p = plant(&req);
        assert!((p.b + p.b0 - (1.0 - p.a) / r).abs() < 1e-12 * (1.0 - p.a) / r);
        assert!(p.b0 > 0.0 && p.b0 < 0.05 * p.b, "{} {}", p.b0, p.b);
        let g = LoopGains::of(&gains(&req).unwrap());
        let y = step_response(&g, &p, 60);
        let steps = 20_000;
        let h = ts / f64::from(steps);
        let (mut i, mut integral, mut v_prev) = (0.0, 0.0, 0.0);
        let mut rf = 0.0;
        for (n, &want) in y.iter().enumerate() {
            assert!((i - want).abs() < 1e-4, "sample {n}: {i} against {want}");
            rf += g.prefilter * (1.0 - rf);
            let e = rf - i;
            let v = g.kp * e + g.ki * integral - g.active_damping * i;
            integral += ts * e;
            for k in 0..steps {
                let u = if f64::from(k) < lag * f64::from(steps) {
                    v_prev
                } else {
                    v
                };
                i += h * (u - r * i) / l;
            }
            v_prev = v;
        }
        assert!(y[59] > 0.9, "{}", y[59]);
    }

    /// Sampled pole placement places the designed pair at any lag λ: Unimotor q axis as
    /// in the hand calculation above, at λ = 0.95 two closed-loop poles are e^{s·T_s} of
    /// s = −70.711 ± 70.711j rad/s, and k_p differs from λ = 1's 0.427 872 V/A.
    #[test]
    fn sampled_pole_placement_at_a_fractional_lag() {
        let (r, l, ts) = (0.65, 7.6e-3, 5e-5);
        let req = Request {
            axis: Axis::Q,
            loop_delay_s: 1.45 * ts,
            ..test_request(Method::PolePlacement, r, l, 100.0, std::f64::consts::FRAC_1_SQRT_2, ts)
        };
        let pi = pole_placement(&req).unwrap();
        assert!((pi.kp - 0.427_872).abs() > 1e-5, "{}", pi.kp);
        let roots = analysis::cubic_roots(analysis::characteristic(&LoopGains::of(&pi), &plant(&req)));
        let want = nalgebra::Complex::new(-70.710_678 * ts, 70.710_678 * ts).exp();
        let hit = roots
            .iter()
            .filter(|z| (nalgebra::Complex::new(z.re, z.im.abs()) - want).norm() < 1e-9)
            .count();
        assert_eq!(hit, 2, "{roots:?}");
    }

    /// Near the sampling rate the third pole p₃ = 1 + a − S leaves the unit circle: the
    /// sampled loop is then unstable although two poles sit where designed.
    #[test]
    fn sampled_pole_placement_fails_where_the_delay_pole_escapes() {
        // ω_n·T_s = 1, ζ = 0.7071: S = 2e^{−0.7071}·cos 0.7071 = 0.7498, so
        // p₃ = 1 + 0.9957 − 0.7498 = 1.246 > 1.
        let (r, l, ts) = (0.65, 7.6e-3, 5e-5);
        let z = std::f64::consts::FRAC_1_SQRT_2;
        let req = Request {
            axis: Axis::Q,
            ..test_request(Method::PolePlacement, r, l, 1.0 / ts, z, ts)
        };
        let g = analysis::finish(pole_placement(&req).unwrap(), &req);
        assert!(
            (g.sampled.spectral_radius - 1.246).abs() < 1e-3,
            "{}",
            g.sampled.spectral_radius
        );
        assert!(
            g.sampled
                .breach(&Promise {
                    overshoot_pct: 4.32,
                    rise_time_s: None
                })
                .is_some()
        );
        assert!(g.sampled.spectral_radius > 1.0, "{}", g.sampled.spectral_radius);
    }
}
