//! Angle tracking observer (ATO), thesis A §4.4, in Q1.31 stored integers.
//!
//! Scaling (4.20): `θ̂_r = 2^-31·π·θ̂^i` \[rad\], `ω̂_r = 2^-31·f_s·π·ω̂^i` \[rad/s\],
//! `ẽ = 2^-31·ẽ^i`. With the forward-difference discretisation (4.17) the update is
//!
//! * (4.19) `θ̂^i(n) = ω̂^i(n−1) + θ̂^i(n−1)` — wrapping (angle);
//! * (4.22) `ω̂^i(n) = ω̂^i(n−1) + K̃_i·ẽ^i(n−1) + K̃_p·(ẽ^i(n) − ẽ^i(n−1))` — saturating,
//!   each product formed in `i64` and rounded to nearest on the `>> 31`;
//!
//! with `K̃_p = K_p/(f_s·π)`, `K̃_i = K_i/(f_s²·π)` (4.22) and `K_p = 2ζω_n`,
//! `K_i = ω_n²` (4.15), computed off-line (by the code generator).
//!
//! Observation error, two architectures (§4.4.1):
//! * [`ObserverError::TrigIdentity`] (4.8): `ẽ = sin θ_r·cos θ̂ − cos θ_r·sin θ̂
//!   = sin(θ_r − θ̂)` in radians (small-angle), Q1.31;
//! * [`ObserverError::Atan2`]: `ẽ = wrap(atan2(sin θ_r, cos θ_r)/π − θ̂/π)`, i.e. the
//!   exact angle error normalised by π. Its loop gain is 1/π of the trig-identity one
//!   for the same K̃, so its gains must be π times larger (`K̃_p = K_p/f_s`,
//!   `K̃_i = K_i/f_s²`) for the same dynamics.
//!
//! Steady state: a type-2 loop, so a constant speed is tracked with zero angle
//! error and a speed ramp (constant acceleration a) with zero speed error and a
//! constant angle error `a/K_i`. Quantisation leaves a dead zone: the integral term
//! `K̃_i·ẽ^i` rounds to 0 while `|ẽ^i| < 2^30/K̃_i^i`.

use crate::q31;
use crate::trig::Trig;
use fixed::types::I1F31;

/// Which observation error the observer uses (thesis A §4.4.1, §4.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObserverError {
    /// "TRIGIDEN": `sin θ_r·cos θ̂ − cos θ_r·sin θ̂` (4.8).
    TrigIdentity,
    /// "CORDIC": `atan2(sin θ_r, cos θ_r)/π − θ̂/π`, wrapped.
    Atan2,
}

/// ATO configuration: the discrete gains of (4.22).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AtoConfig {
    /// K̃_p = K_p/(f_s·π) (trig identity) or K_p/f_s (atan2), Q1.31 (4.22).
    pub kp: I1F31,
    /// K̃_i = K_i/(f_s²·π) (trig identity) or K_i/f_s² (atan2), Q1.31 (4.22).
    pub ki: I1F31,
    /// Error architecture.
    pub error: ObserverError,
}

/// ATO state (stored integers of (4.20)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AtoState {
    /// θ̂^i: estimated resolver angle, π-scaled Q1.31.
    pub theta: i32,
    /// ω̂^i: estimated resolver speed, per-sample angle increment (4.19).
    pub omega: i32,
    /// ẽ^i(n−1): previous observation error.
    pub error: i32,
}

impl AtoState {
    /// At rest at θ̂ = 0.
    pub const fn new() -> Self {
        Self {
            theta: 0,
            omega: 0,
            error: 0,
        }
    }

    /// Started at a known angle and speed (e.g. from a first atan2 of the resolver
    /// signals), with zero error history.
    pub const fn locked(theta: i32, omega: i32) -> Self {
        Self { theta, omega, error: 0 }
    }

    /// Acquired at rest on a sample: θ̂ = atan2(sin θ_r, cos θ_r) (π-scaled Q1.31, the
    /// angle the atan2 error compares with, §4.4.1), ω̂ = 0. An observer that pulls in
    /// from θ̂ = 0 instead answers an initial error Δ with a speed kick in its first
    /// period, K_p·sin Δ with the trig identity and K_p·Δ with atan2 (K_p = 2ζω_n: up to
    /// 4 000 and 12 566 rad/s of resolver speed for ω_n = 2000 rad/s), which an over-speed
    /// trip takes for a runaway; seeded from the sample the rotor's angle needs no
    /// pull-in. (0, 0) — no excitation yet — gives θ̂ = 0.
    pub fn acquired<T: Trig>(trig: &mut T, resolver: ResolverSample) -> Self {
        Self::locked(trig.atan2(resolver.sin, resolver.cos), 0)
    }
}

/// The observer's start on a rotor that may be turning: each period the resolver's
/// angle by atan2 (as [`AtoState::acquired`]) and, over the periods counted, the mean of
/// its per-period increments — ω̂ in the observer's own unit (4.19), the travel between
/// the first and the last counted angle over their distance in periods (only increments
/// between two counted angles: the first counted angle is the reference; each increment
/// taken wrapping, so a turn through ±π counts as the small step it is: a resolver turns
/// far less than half a turn per control period, f_s ≥ 12·f_e, thesis A (1.1)). Seeded
/// at rest ([`AtoState::acquired`]: ω̂ = 0) an observer on a turning rotor must pull in
/// from a speed error of the whole speed, a transient of about 4/ω_n whose speed kick
/// an over-speed trip takes for a runaway (fischer-ti085 at 6 000 rpm on the emulated
/// board: fault 4 at the first enabled periods); seeded with θ and ω it starts locked.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Acquisition {
    /// The last counted angle (π-scaled Q1.31), once one was.
    previous: Option<i32>,
    /// Σ of the counted increments (π-scaled LSB).
    travel: i64,
    /// Increments counted.
    steps: u32,
}

impl Acquisition {
    /// Nothing seen.
    pub const fn new() -> Self {
        Self {
            previous: None,
            travel: 0,
            steps: 0,
        }
    }

    /// One period's sample; `counted`: the angle is the resolver's (false while the
    /// excitation settles, when the demodulated signals are not yet the resolver's), and
    /// its increment over the previous counted angle enters the mean. Returns the
    /// observer state for the next period: θ̂ = this angle, ω̂ = the mean increment so far
    /// (0 before the second counted angle).
    pub fn add<T: Trig>(&mut self, trig: &mut T, resolver: ResolverSample, counted: bool) -> AtoState {
        let theta = trig.atan2(resolver.sin, resolver.cos);
        if counted {
            if let Some(previous) = self.previous {
                self.travel = self.travel.saturating_add(i64::from(theta.wrapping_sub(previous)));
                self.steps = self.steps.saturating_add(1);
            }
            self.previous = Some(theta);
        }
        AtoState::locked(theta, self.speed())
    }

    /// The mean increment \[π-scaled LSB per period\] (0 before any was counted).
    pub fn speed(&self) -> i32 {
        let mean = self.travel.checked_div(i64::from(self.steps)).unwrap_or(0);
        // |mean| ≤ 2^31: each increment is an i32.
        i32::try_from(mean).unwrap_or(0)
    }
}

/// One demodulated resolver sample (4.3): envelopes of the SIN and COS windings,
/// Q1.31 (amplitude ≤ 1; a common gain only scales the trig-identity error, 4.10).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ResolverSample {
    /// sin θ_r, Q1.31.
    pub sin: i32,
    /// cos θ_r, Q1.31.
    pub cos: i32,
}

impl AtoConfig {
    /// Observation error ẽ^i(n) for the measured sample and the predicted θ̂^i(n).
    pub fn observation_error<T: Trig>(&self, trig: &mut T, resolver: ResolverSample, theta_hat: i32) -> i32 {
        match self.error {
            ObserverError::TrigIdentity => {
                let est = trig.sin_cos(theta_hat);
                // Q1.31·Q1.31 = Q2.62, |product| ≤ 2^62.
                let a = i64::from(resolver.sin).saturating_mul(i64::from(est.cos));
                let b = i64::from(resolver.cos).saturating_mul(i64::from(est.sin));
                let e = a.saturating_sub(b).saturating_add(1 << 30) >> 31;
                e.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
            }
            ObserverError::Atan2 => {
                let measured = trig.atan2(resolver.sin, resolver.cos);
                // An angle difference: wraps into [−π, π).
                measured.wrapping_sub(theta_hat)
            }
        }
    }

    /// One observer step, (4.19) then (4.22). Returns the new angle estimate θ̂^i(n).
    pub fn process<T: Trig>(&self, state: &mut AtoState, trig: &mut T, resolver: ResolverSample) -> i32 {
        // (4.19): the angle integrates the previous speed; wrap-around is the
        // periodicity of the angle.
        let theta = state.theta.wrapping_add(state.omega);
        let e = self.observation_error(trig, resolver, theta);
        let e_prev = i64::from(state.error);
        // (4.22), i64 throughout, saturated once at the end.
        let integral = q31::mul(i64::from(self.ki.to_bits()), e_prev);
        let proportional = q31::mul(i64::from(self.kp.to_bits()), i64::from(e).saturating_sub(e_prev));
        let omega = i64::from(state.omega)
            .saturating_add(integral)
            .saturating_add(proportional);
        state.theta = theta;
        state.omega = omega.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
        state.error = e;
        theta
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trig::SoftTrig;
    use core::f64::consts::PI;

    const Q31: f64 = 2_147_483_648.0;
    const FS: f64 = 20_000.0;

    /// Gains from (4.15) and (4.22), arithmetic written out (thesis: ω_n = 70 rad/s,
    /// ζ = 1): K_p = 2·1·70 = 140 rad/s, K_i = 70² = 4900 rad²/s²;
    /// trig identity: K̃_p = 140/(2e4·π) = 2.228e-3 → 4 784 957; K̃_i = 4900/(4e8·π)
    /// = 3.899e-6 → 8 374. atan2: π× larger: 15 032 386 and 26 307.
    fn config(error: ObserverError, wn: f64, zeta: f64) -> AtoConfig {
        let kp = 2.0 * zeta * wn;
        let ki = wn * wn;
        let norm = match error {
            ObserverError::TrigIdentity => PI,
            ObserverError::Atan2 => 1.0,
        };
        AtoConfig {
            kp: I1F31::from_bits((kp / (FS * norm) * Q31).round() as i32),
            ki: I1F31::from_bits((ki / (FS * FS * norm) * Q31).round() as i32),
            error,
        }
    }

    /// A rotor turning −0.3 rad per period from 3.0 rad (through −π at periods 21 and
    /// 42): the first 10 periods are not counted (a wild angle among them, as before the
    /// excitation settles, does not count either) and, with the first counted one the
    /// reference, give ω̂ = 0 up to period 10; over the next 49 increments the mean is
    /// −0.3 rad = −0.3/π·2^31 = −205 069 583 LSB within the atan2's error (the
    /// CORDIC-free `SoftTrig`: a few LSB); θ̂ is each period's angle. At rest the mean is
    /// 0 and nothing counted gives 0.
    #[test]
    fn acquisition_measures_the_speed_across_the_wrap() {
        let mut trig = SoftTrig;
        let mut a = Acquisition::new();
        let step = -0.3;
        let mut st = AtoState::new();
        for k in 0..60 {
            let theta = if k == 9 { 2.0 } else { 3.0 + step * f64::from(k) };
            st = a.add(&mut trig, sample(theta), k >= 10);
            assert!((wrap(rad(st.theta) - theta)).abs() < 1e-6, "θ̂ at {k}");
            if k <= 10 {
                assert_eq!(st.omega, 0, "period {k}: nothing counted yet");
            }
        }
        let want = (step / PI * Q31).round();
        assert!((f64::from(st.omega) - want).abs() < 64.0, "{} vs {want}", st.omega);
        let mut rest = Acquisition::new();
        for _ in 0..20 {
            st = rest.add(&mut trig, sample(-2.0), true);
        }
        assert!(st.omega.abs() <= 2, "{}", st.omega);
        assert_eq!(Acquisition::new().speed(), 0);
    }

    fn sample(theta: f64) -> ResolverSample {
        let q = |x: f64| (x * Q31).round().clamp(-Q31, Q31 - 1.0) as i32;
        ResolverSample {
            sin: q(theta.sin()),
            cos: q(theta.cos()),
        }
    }

    fn wrap(x: f64) -> f64 {
        x - 2.0 * PI * ((x + PI) / (2.0 * PI)).floor()
    }

    fn rad(theta: i32) -> f64 {
        f64::from(theta) * PI / Q31
    }

    fn rad_per_s(omega: i32) -> f64 {
        f64::from(omega) * PI * FS / Q31
    }

    #[test]
    fn thesis_gains() {
        let c = config(ObserverError::TrigIdentity, 70.0, 1.0);
        assert_eq!((c.kp.to_bits(), c.ki.to_bits()), (4_784_957, 8_374));
        let c = config(ObserverError::Atan2, 70.0, 1.0);
        assert_eq!((c.kp.to_bits(), c.ki.to_bits()), (15_032_386, 26_307));
    }

    /// f64 reference of (4.21) (forward-difference ATO in physical units) against the
    /// integer implementation on the same input: the integer states stay within
    /// the quantisation of (4.20) of the reference.
    #[test]
    fn matches_f64_reference_observer() {
        for error in [ObserverError::TrigIdentity, ObserverError::Atan2] {
            let cfg = config(error, 200.0, 1.0);
            let (kp, ki) = (2.0 * 200.0, 200.0 * 200.0);
            let mut st = AtoState::new();
            let (mut th, mut w, mut e_prev) = (0.0f64, 0.0f64, 0.0f64);
            let ts = 1.0 / FS;
            let mut max_dth = 0.0f64;
            for n in 0..4000 {
                let t = f64::from(n) * ts;
                let theta_r = 0.3 + 150.0 * t + 200.0 * t * t;
                cfg.process(&mut st, &mut SoftTrig, sample(theta_r));
                // Reference (4.18), (4.21); the error in radians for both.
                th += ts * w;
                let e = match error {
                    ObserverError::TrigIdentity => (theta_r - th).sin(),
                    ObserverError::Atan2 => wrap(theta_r - th),
                };
                w += ki * ts * e_prev + kp * (e - e_prev);
                e_prev = e;
                max_dth = max_dth.max(wrap(rad(st.theta) - th).abs());
            }
            // The integer loop differs from the f64 one by the rounding of K̃ to
            // Q1.31 (relative 2^-31/K̃ ≈ 2e-7 for K̃_p, 1e-5 for K̃_i), the >>31
            // rounding of each product (≤ 0.5 LSB of ω^i = 1.5e-5 rad/s per step) and
            // the Q1.31 resolver samples; integrated over 0.2 s these stay below
            // 1e-5 rad (measured 2.6e-6).
            eprintln!("ATO {error:?} vs f64 reference: max |Δθ| = {max_dth:.3e} rad");
            assert!(max_dth < 1e-5, "{error:?}: {max_dth}");
        }
    }

    /// Constant speed: zero steady-state angle error (up to the dead zone of the
    /// rounded integral term, |ẽ^i| < 2^30/K̃_i^i ≈ 128 000 LSB = 6e-5 rad for the
    /// thesis gains) and the speed estimate exact.
    #[test]
    fn tracks_constant_speed() {
        for error in [ObserverError::TrigIdentity, ObserverError::Atan2] {
            let cfg = config(error, 70.0, 1.0);
            let mut st = AtoState::new();
            let w = 300.0; // rad/s (resolver), ~2900 rpm
            for n in 0..40_000 {
                let t = f64::from(n) / FS;
                cfg.process(&mut st, &mut SoftTrig, sample(w * t));
            }
            let t = 39_999.0 / FS;
            let e = wrap(w * t - rad(st.theta));
            let dead_zone = (1u64 << 30) as f64 / f64::from(cfg.ki.to_bits()) / Q31
                * match error {
                    ObserverError::TrigIdentity => 1.0,
                    ObserverError::Atan2 => PI,
                };
            eprintln!(
                "ATO {error:?} constant speed: e = {e:.3e} rad (dead zone {dead_zone:.3e}), ω error {:.3e} rad/s",
                rad_per_s(st.omega) - w
            );
            assert!(e.abs() <= 2.0 * dead_zone, "{error:?}: e = {e}, bound {dead_zone}");
            // speed: 1 LSB of ω^i is π·f_s/2^31 = 2.9e-5 rad/s; allow the dead-zone
            // limit cycle: |Δω| ≤ K̃_p·dead zone per step → ≤ 0.05 rad/s.
            assert!(
                (rad_per_s(st.omega) - w).abs() < 0.05,
                "{error:?}: {}",
                rad_per_s(st.omega)
            );
        }
    }

    /// Speed ramp (constant acceleration a): the speed estimate tracks with zero
    /// steady-state error, the angle error settles at the type-2 value a/K_i.
    #[test]
    fn tracks_speed_ramp() {
        for error in [ObserverError::TrigIdentity, ObserverError::Atan2] {
            let wn = 70.0;
            let cfg = config(error, wn, 1.0);
            let mut st = AtoState::new();
            let a = 500.0; // rad/s²
            let mut last = (0.0, 0.0);
            for n in 0..60_000 {
                let t = f64::from(n) / FS;
                cfg.process(&mut st, &mut SoftTrig, sample(0.5 * a * t * t));
                last = (t, a * t);
            }
            let (t, w) = last;
            let e = wrap(0.5 * a * t * t - rad(st.theta));
            let expected = a / (wn * wn);
            eprintln!(
                "ATO {error:?} speed ramp 500 rad/s²: e = {e:.4e} rad (a/K_i = {expected:.4e}), ω error {:.3e} rad/s",
                rad_per_s(st.omega) - w
            );
            // Forward-difference discretisation shifts the error by O(a·T_s/K_p)
            // ≈ 2e-4 of itself; the bound is 2 % of a/K_i plus the dead zone.
            assert!(
                (e - expected).abs() < 0.02 * expected + 1.2e-4,
                "{error:?}: e = {e}, a/K_i = {expected}"
            );
            // The speed estimate lags the true speed by the discretisation only:
            // ω̂(n) estimates ω at n−1 (4.19) → a·T_s = 0.025 rad/s.
            assert!(
                (rad_per_s(st.omega) - w).abs() < 0.1,
                "{error:?}: {} vs {w}",
                rad_per_s(st.omega)
            );
        }
    }

    /// Re-lock after a π/2 angle error at speed (a "step-like" disturbance, §4.5):
    /// the observer returns to < 1e-3 rad within 0.2 s (≈ 14/ω_n).
    #[test]
    fn relocks_from_quarter_turn() {
        for error in [ObserverError::TrigIdentity, ObserverError::Atan2] {
            let cfg = config(error, 70.0, 1.0);
            let w = 100.0;
            let mut st = AtoState::locked(1 << 30, (w / (PI * FS) * Q31).round() as i32);
            for n in 0..4_000 {
                let t = f64::from(n) / FS;
                cfg.process(&mut st, &mut SoftTrig, sample(w * t));
            }
            let t = 3_999.0 / FS;
            let e = wrap(w * t - rad(st.theta));
            eprintln!("ATO {error:?} re-lock from π/2: e after 0.2 s = {e:.3e} rad");
            assert!(e.abs() < 1e-3, "{error:?}: {e}");
        }
    }

    /// Acquisition at rest: seeded on a sample at any angle (here 2.5 rad, and −3 rad near
    /// the ±π wrap) at 0.4 of full scale, the next steps on the same sample keep the angle
    /// within 2^−20 rad and the speed at zero (no kick), where the observer pulled in
    /// from θ̂ = 0 kicks its speed by K_p·g·sin Δ (rad/s) in the first period: with
    /// ω_n = 2000 rad/s and g = 0.4, by hand 4000·0.4·sin 2.5 = 4000·0.4·0.598 = 957.6 rad/s.
    #[test]
    fn acquired_at_rest_needs_no_pull_in() {
        let cfg = config(ObserverError::TrigIdentity, 2000.0, 1.0);
        for theta in [2.5, -3.0] {
            let s = ResolverSample {
                sin: (0.4 * f64::sin(theta) * Q31) as i32,
                cos: (0.4 * f64::cos(theta) * Q31) as i32,
            };
            let mut st = AtoState::acquired(&mut SoftTrig, s);
            assert!(
                wrap(rad(st.theta) - theta).abs() < 2f64.powi(-20),
                "{theta}: {}",
                rad(st.theta)
            );
            for _ in 0..100 {
                cfg.process(&mut st, &mut SoftTrig, s);
                assert!(rad_per_s(st.omega).abs() < 1e-3, "{theta}: ω̂ = {}", rad_per_s(st.omega));
            }
            assert!(wrap(rad(st.theta) - theta).abs() < 2f64.powi(-20));
        }
        let mut cold = AtoState::new();
        let s = ResolverSample {
            sin: (0.4 * f64::sin(2.5) * Q31) as i32,
            cos: (0.4 * f64::cos(2.5) * Q31) as i32,
        };
        cfg.process(&mut cold, &mut SoftTrig, s);
        let kick = rad_per_s(cold.omega);
        assert!((kick - 4000.0 * 0.4 * 2.5f64.sin()).abs() < 1.0, "{kick}");
    }

    /// Wrap-around across ±π: tracking continues through many turns at high speed
    /// (1333 Hz electrical / 4 pole pairs → 2094 rad/s resolver), angle error small.
    #[test]
    fn wraps_across_pi_at_speed() {
        let cfg = config(ObserverError::TrigIdentity, 70.0, 1.0);
        let w = 2094.0;
        // State at n = −1 (one increment before the first sample at θ = 0).
        let omega = (w / (PI * FS) * Q31).round() as i32;
        let mut st = AtoState::locked(-omega, omega);
        let mut worst: f64 = 0.0;
        for n in 0..20_000 {
            let t = f64::from(n) / FS;
            cfg.process(&mut st, &mut SoftTrig, sample(w * t));
            worst = worst.max(wrap(w * t - rad(st.theta)).abs());
        }
        eprintln!("ATO at 2094 rad/s through 333 wraps: worst |e| = {worst:.3e} rad");
        // Initial speed rounding (0.5 LSB of ω^i) and the dead zone: < 1e-3 rad.
        assert!(worst < 1e-3, "{worst}");
    }

    /// Saturating speed: an error that drives ω̂^i past the i32 range leaves it at the
    /// bound, never wrapped to the other sign. By hand, atan2 error, K̃_p = K̃_i = 1 − 2^-31:
    /// from θ̂ = 0, ω̂ = 2^31 − 6 with the resolver at −π/2 (atan2 = −2^30), (4.19) gives
    /// θ̂ = 2^31 − 6 and ẽ = −2^30 − (2^31 − 6) wrapped into [−2^31, 2^31) = 2^30 + 6;
    /// (4.22): ω̂ = 2^31 − 6 + 0 (ẽ(n−1) = 0) + K̃_p·ẽ ≈ 2^31 + 2^30 → i32::MAX. The mirror
    /// image (ω̂ = −2^31 + 5, resolver at +π/2) ends at i32::MIN (a wrapped sum would land
    /// near the other bound; an unchecked i32 sum would panic: overflow checks are on in
    /// the test profile).
    #[test]
    fn speed_saturates() {
        let cfg = AtoConfig {
            kp: I1F31::MAX,
            ki: I1F31::MAX,
            error: ObserverError::Atan2,
        };
        let mut st = AtoState::locked(0, i32::MAX - 5);
        let theta = cfg.process(&mut st, &mut SoftTrig, sample(-PI / 2.0));
        assert_eq!(theta, i32::MAX - 5);
        // atan2 to 2 LSB (trig.rs).
        assert!((st.error - ((1 << 30) + 6)).abs() <= 2, "ẽ = {}", st.error);
        assert_eq!(st.omega, i32::MAX);

        let mut st = AtoState::locked(0, i32::MIN + 5);
        cfg.process(&mut st, &mut SoftTrig, sample(PI / 2.0));
        assert!((st.error - (-(1 << 30) - 5)).abs() <= 2, "ẽ = {}", st.error);
        assert_eq!(st.omega, i32::MIN);
    }
}
