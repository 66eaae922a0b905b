//! Sensorless speed and position estimator of thesis B chapter 4: the PLL-type
//! estimator of Harnefors and Nee with the saliency-corrected back-EMF error, signal
//! injection at low speed, the transition between them and the "resetting" term.
//!
//! ```text
//! dω̂/dt = ρ²·e + γ0(ω̃')·ω̃'                                        (4.78), γ1 = ρ² (4.7)
//! dθ̂/dt = ω̂ + 2ρ·e                                                 (4.79), γ2 = 2ρ (4.7)
//! e = f_tr(ω̂)·e_si/(2K̂_e) + (1 − f_tr(ω̂))·e_d/(−ω̂·(ψ̂_m − ΔL̂·i_d^ref))  (4.80), (4.51)
//! e_d = v_d − R̂·i_d^ref + ω̂·L̂_q·i_q^ref                              (4.38)
//! e_q = v_q − R̂·i_q^ref − ω̂·L̂_d·i_d^ref                              (4.39)
//! ω̃' = √(e_d² + e_q²)/ψ̂_m·sign(ω̂) − ω̂                               (4.76), (4.77)
//! γ0 = 0 | ρ·(|ω̃'| − Δω1)/(Δω2 − Δω1) | ρ   (|ω̃'| ≤ Δω1 | between | ≥ Δω2)   (4.83)
//! |i_q^ref| < ρ²·ψ̂_m/(γ0·ω_max·ΔL̂)   while γ0 > 0                  (4.92)
//! e_si = LPF{HPF{i_q̂}·sin ω_e t} ≈ K_e·sin 2θ̃,  K_e = V_e·ΔL/(4ω_e·L_d·L_q)   (4.18), (4.19)
//! ```
//!
//! Discretised with the forward difference exactly as thesis B Appendix D (ω̂ is updated
//! first and the new ω̂ advances θ̂); the filters are second-order Butterworth
//! (§4.5.1), also forward difference. Speeds are electrical \[rad/s\]; θ̂ is a π-scaled
//! Q1.31 angle that wraps, like every angle in this crate. The sign convention of the
//! back-EMF error is Appendix D's `ed/(−wh·(psi − (Lq − Ld)·idref))`, i.e. (4.51).
//!
//! Inputs are the previous period's measured currents (in the estimated frame), applied
//! dq voltage without the carrier, and current references — Appendix D's order. The
//! carrier `V_e·cos ω_e t` (4.15) is returned for the d axis while |ω̂| ≤ 1.1·ω_hs (as in
//! Appendix D) and is added by [`crate::step::ControllerConfig::process_at_angle`].

use crate::angle::from_radians;
use crate::transforms::Dq;
use crate::trig::Trig;

/// √2, the Butterworth damping 2ζ (ζ = 1/√2).
const SQRT_2: f32 = core::f32::consts::SQRT_2;

/// Signal-injection constants (thesis B §4.3.5, Table 4.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InjectionConfig {
    /// Carrier amplitude V_e \[V\] (4.35).
    pub amplitude: f32,
    /// Carrier frequency ω_e \[rad/s\] (4.34).
    pub frequency: f32,
    /// K̂_e = V_e·ΔL̂/(4ω_e·L̂_d·L̂_q) \[A\] (4.19), with the saturated L̂_q (§4.3.2); signed
    /// like ΔL̂ = L̂_q − L̂_d (negative for inverse saliency), 0 = no injection.
    pub gain: f32,
    /// High-pass cut-off ω_hp \[rad/s\] (a few Hz, Table 4.1).
    pub highpass: f32,
    /// Low-pass cut-off ω_lp \[rad/s\], 5ρ…10ρ (Table 4.1).
    pub lowpass: f32,
    /// Delay \[samples\] between the carrier phase computed in a step and the current
    /// sample the estimator demodulates with it (computation + PWM + the one-period-old
    /// current input); the demodulating sine lags the carrier by it.
    pub delay: f32,
    /// ω_ls \[rad/s\]: below it only injection is used (Table 4.1, max(ω_min1, ω_min2)).
    pub low_speed: f32,
    /// ω_hs \[rad/s\]: above it only the back EMF is used (Table 4.1, 2·ω_ls).
    pub high_speed: f32,
}

/// The resetting term (thesis B §4.6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResettingConfig {
    /// Δω1 \[rad/s\] (4.83): γ0 = 0 below it (thesis: ρ).
    pub lower: f32,
    /// Δω2 \[rad/s\] (4.83): γ0 = ρ above it (thesis: 2ρ).
    pub upper: f32,
    /// ω_max \[rad/s\], the highest electrical speed, for the i_q limit (4.92).
    pub speed_max: f32,
}

/// Estimator constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorConfig {
    /// Sample period T_s \[s\].
    pub sample_period: f32,
    /// Bandwidth ρ \[rad/s\]: γ1 = ρ², γ2 = 2ρ (4.7); ρ ≤ α_c/10 (Table 4.1), (4.74).
    pub rho: f32,
    /// R̂_s \[Ω\].
    pub rs: f32,
    /// L̂_d \[H\].
    pub ld: f32,
    /// L̂_q \[H\] (saturated value, §4.4.2).
    pub lq: f32,
    /// ψ̂_m \[Wb\].
    pub psi_m: f32,
    /// Resetting term (4.78), (4.83); `None` = γ0 ≡ 0 (the estimator of (4.70)–(4.72)).
    pub resetting: Option<ResettingConfig>,
    /// Low-speed signal injection; `None` = back EMF only (f_tr ≡ 0).
    pub injection: Option<InjectionConfig>,
}

/// State of a forward-difference second-order Butterworth section.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Butterworth2 {
    /// Low-pass output x1.
    pub x1: f32,
    /// Its derivative x2 = dx1/dt.
    pub x2: f32,
}

impl Butterworth2 {
    /// One step of `ẍ1 + √2·ω_c·ẋ1 + ω_c²·x1 = ω_c²·u` (forward difference, stable for
    /// ω_c·T_s < √2); returns `(low-pass, high-pass)` at this sample: the low-pass
    /// `ω_c²/(s² + √2ω_c·s + ω_c²)` is x1, the high-pass `s²/(…)` is `u − x1 − √2·x2/ω_c`.
    pub fn process(&mut self, wc: f32, ts: f32, u: f32) -> (f32, f32) {
        let low = self.x1;
        let high = if wc > 0.0 {
            u - self.x1 - SQRT_2 * self.x2 / wc
        } else {
            u
        };
        let dx2 = wc * wc * (u - self.x1) - SQRT_2 * wc * self.x2;
        let (x1, x2) = (self.x1 + ts * self.x2, self.x2 + ts * dx2);
        if x1.is_finite() && x2.is_finite() {
            (self.x1, self.x2) = (x1, x2);
        } else {
            *self = Self::default();
        }
        (low, high)
    }
}

/// Estimator state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EstimatorState {
    /// θ̂ (electrical, π-scaled Q1.31).
    pub theta: i32,
    /// ω̂ \[rad/s\] (electrical).
    pub omega: f32,
    /// Carrier phase ω_e·t (π-scaled Q1.31).
    pub carrier: i32,
    /// High-pass filter of i_q̂.
    pub highpass: Butterworth2,
    /// Low-pass filter of the demodulated signal.
    pub lowpass: Butterworth2,
}

/// What one estimator step reads (all from the previous control period).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EstimatorInput {
    /// Measured currents in the estimated frame \[A\].
    pub current: Dq,
    /// Applied dq voltage without the carrier \[V\] (v^ref of (4.38), (4.39)).
    pub voltage: Dq,
    /// Current references i_d^ref, i_q^ref \[A\].
    pub reference: Dq,
}

/// One estimator step's results.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EstimatorOutput {
    /// θ̂ (electrical, π-scaled Q1.31).
    pub theta: i32,
    /// ω̂ \[rad/s\].
    pub omega: f32,
    /// ω̂ as a per-sample Q1.31 increment (the `omega_e_i` of the control step).
    pub omega_increment: i32,
    /// Carrier voltage to add in the estimated dq frame \[V\] (zero above 1.1·ω_hs).
    pub injection: Dq,
    /// Bound on |i_q^ref| from (4.92) \[A\]; `f32::INFINITY` while γ0 = 0.
    pub iq_limit: f32,
    /// γ0 (4.83) \[rad/s\].
    pub gamma0: f32,
    /// Approximate speed error ω̃' (4.77) \[rad/s\].
    pub speed_error: f32,
    /// Transition function f_tr(ω̂) (Fig. 4.9).
    pub blend: f32,
    /// Error signal e (4.80) \[-\] (≈ sin θ̃).
    pub error: f32,
}

impl EstimatorConfig {
    /// f_tr(ω̂) (Fig. 4.9): 1 up to ω_ls, linear to 0 at ω_hs, 0 above; 0 without injection.
    pub fn blend(&self, omega: f32) -> f32 {
        let Some(inj) = self.injection else {
            return 0.0;
        };
        let w = libm::fabsf(omega);
        if w <= inj.low_speed {
            1.0
        } else if w >= inj.high_speed {
            0.0
        } else {
            (inj.high_speed - w) / (inj.high_speed - inj.low_speed)
        }
    }

    /// γ0(ω̃') (4.83) \[rad/s\]; 0 without the resetting term.
    pub fn gamma0(&self, speed_error: f32) -> f32 {
        let Some(r) = self.resetting else {
            return 0.0;
        };
        let x = libm::fabsf(speed_error);
        if x.is_nan() || x <= r.lower {
            0.0
        } else if x >= r.upper {
            self.rho
        } else {
            self.rho * (x - r.lower) / (r.upper - r.lower)
        }
    }

    /// The i_q bound (4.92) \[A\] at γ0: ρ²·ψ̂_m/(γ0·ω_max·|ΔL̂|), `f32::INFINITY` when
    /// γ0 = 0 or ΔL̂ = 0.
    pub fn iq_limit(&self, gamma0: f32) -> f32 {
        let Some(r) = self.resetting else {
            return f32::INFINITY;
        };
        let den = gamma0 * r.speed_max * libm::fabsf(self.lq - self.ld);
        let lim = self.rho * self.rho * self.psi_m / den;
        if den > 0.0 && lim.is_finite() {
            lim
        } else {
            f32::INFINITY
        }
    }

    /// One estimator step (Appendix D order). `trig` supplies the carrier's sin/cos.
    pub fn process<T: Trig>(&self, state: &mut EstimatorState, trig: &mut T, input: EstimatorInput) -> EstimatorOutput {
        let ts = self.sample_period;
        let wh = state.omega;

        // Signal injection (4.15)–(4.20).
        let (e_si, injection) = match self.injection {
            Some(inj) => {
                state.carrier = state.carrier.wrapping_add(from_radians(inj.frequency * ts));
                let carrier = trig.sin_cos(state.carrier).to_f32();
                let demod = trig
                    .sin_cos(state.carrier.wrapping_sub(from_radians(inj.delay * inj.frequency * ts)))
                    .to_f32();
                let (_, iq_high) = state.highpass.process(inj.highpass, ts, input.current.q);
                let (e_si, _) = state.lowpass.process(inj.lowpass, ts, iq_high * demod.sin);
                let on = libm::fabsf(wh) <= 1.1 * inj.high_speed;
                let ud = if on { inj.amplitude * carrier.cos } else { 0.0 };
                // K̂_e carries the sign of ΔL (negative for inverse saliency, L_d > L_q), as
                // e_si does: e ≈ sin θ̃ (4.20) for either sign.
                let e = if inj.gain != 0.0 { e_si / (2.0 * inj.gain) } else { 0.0 };
                (e, Dq { d: ud, q: 0.0 })
            }
            None => (0.0, Dq::default()),
        };

        // Back EMF (4.38), (4.39), saliency-corrected error (4.51).
        let r = input.reference;
        let ed = input.voltage.d + self.lq * wh * r.q - self.rs * r.d;
        let eq = input.voltage.q - self.ld * wh * r.d - self.rs * r.q;
        let den = -wh * (self.psi_m - (self.lq - self.ld) * r.d);
        let e_bemf = if libm::fabsf(den) > 0.0 { ed / den } else { 0.0 };

        // Resetting term (4.76), (4.77), (4.83).
        let sign = if wh < 0.0 { -1.0 } else { 1.0 };
        let speed_error = if self.psi_m > 0.0 {
            libm::sqrtf(ed * ed + eq * eq) / self.psi_m * sign - wh
        } else {
            0.0
        };
        let gamma0 = self.gamma0(speed_error);

        // (4.80), then the forward-difference update of (4.78), (4.79).
        let blend = self.blend(wh);
        let mut e = blend * e_si + (1.0 - blend) * e_bemf;
        if !e.is_finite() {
            e = 0.0;
        }
        let reset = if gamma0 > 0.0 && speed_error.is_finite() {
            gamma0 * speed_error
        } else {
            0.0
        };
        let omega = wh + ts * (self.rho * self.rho * e + reset);
        state.omega = if omega.is_finite() { omega } else { 0.0 };
        state.theta = state
            .theta
            .wrapping_add(from_radians(ts * (state.omega + 2.0 * self.rho * e)));

        EstimatorOutput {
            theta: state.theta,
            omega: state.omega,
            omega_increment: from_radians(state.omega * ts),
            injection,
            iq_limit: self.iq_limit(gamma0),
            gamma0,
            speed_error,
            blend,
            error: e,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::angle::to_radians;
    use crate::trig::SoftTrig;
    use core::f32::consts::PI;

    /// Thesis B motor (Table B.2) with ρ = 0.1 pu (ω_base = 1256.6 rad/s).
    fn config(resetting: bool) -> EstimatorConfig {
        let rho = 125.66;
        EstimatorConfig {
            sample_period: 1e-4,
            rho,
            rs: 7.9e-3,
            ld: 0.23e-3,
            lq: 0.56e-3,
            psi_m: 0.104,
            resetting: resetting.then_some(ResettingConfig {
                lower: rho,
                upper: 2.0 * rho,
                speed_max: 2.0 * 1256.6,
            }),
            injection: None,
        }
    }

    /// Voltage the estimator sees at zero current when the true rotor is θ̃ ahead and
    /// turns at ω: v̂ = e^{Jθ̃}·ω·ψ_m·[0, 1]ᵀ = ω·ψ_m·[−sin θ̃, cos θ̃] (from (4.36)).
    fn bemf(c: &EstimatorConfig, w: f32, err: f32) -> EstimatorInput {
        EstimatorInput {
            voltage: Dq {
                d: -w * c.psi_m * libm::sinf(err),
                q: w * c.psi_m * libm::cosf(err),
            },
            ..EstimatorInput::default()
        }
    }

    /// Runs the estimator against a rotor at constant speed `w` for `seconds`; returns
    /// θ̃ (unwrapped) and ω̃ per sample and the number of cycle slips (turns of θ̃).
    fn track(c: &EstimatorConfig, w: f32, theta_err0: f32, omega_err0: f32, seconds: f32) -> (Vec<(f32, f32)>, i32) {
        let ts = c.sample_period;
        let mut st = EstimatorState {
            theta: from_radians(-theta_err0),
            omega: w - omega_err0,
            ..EstimatorState::default()
        };
        let mut theta = 0.0f32;
        let mut err = theta_err0;
        let mut out = Vec::new();
        for _ in 0..(seconds / ts) as usize {
            let wrapped = theta - to_radians(st.theta);
            // Unwrap: θ̃ moves by less than π per sample.
            let d = libm::remainderf(wrapped - err, 2.0 * PI);
            err += d;
            out.push((err, w - st.omega));
            c.process(&mut st, &mut SoftTrig, bemf(c, w, wrapped));
            theta = libm::remainderf(theta + w * ts, 2.0 * PI);
        }
        let slips = libm::roundf(err / (2.0 * PI)) as i32;
        (out, slips)
    }

    /// Linearised error dynamics (4.6) with (4.7): double pole at −ρ. From θ̃(0) = θ̃0,
    /// ω̃(0) = 0: θ̃'' + 2ρθ̃' + ρ²θ̃ = 0, θ̃'(0) = −2ρθ̃0 (from (4.5)), so
    /// θ̃(t) = θ̃0·(1 − ρt)·e^{−ρt}: zero at t = 1/ρ, minimum −θ̃0·e^{−2} at t = 2/ρ.
    #[test]
    fn double_pole_at_minus_rho() {
        let c = config(false);
        let th0 = 0.02;
        let (out, slips) = track(&c, 1256.6, th0, 0.0, 0.1);
        let ts = c.sample_period;
        let at = |t: f32| out[libm::roundf(t / ts) as usize].0;
        let rho = c.rho;
        for k in [0.5f32, 1.0, 2.0, 3.0, 5.0] {
            let t = k / rho;
            let want = th0 * (1.0 - k) * libm::expf(-k);
            // Forward difference at ρ·T_s = 0.0126: ≤ 2 % of θ̃0.
            assert!((at(t) - want).abs() < 0.02 * th0, "t = {k}/ρ: {} vs {want}", at(t));
        }
        assert_eq!(slips, 0);
    }

    /// (4.83) at the thesis's thresholds Δω1 = ρ, Δω2 = 2ρ: off up to ρ, half-way at
    /// 1.5ρ, fully ρ from 2ρ; the estimator computes ω̃' from |e| = |ω|ψ (4.76).
    #[test]
    fn resetting_term_thresholds() {
        let c = config(true);
        let rho = c.rho;
        assert_eq!(c.gamma0(0.99 * rho), 0.0);
        assert!((c.gamma0(-1.5 * rho) - 0.5 * rho).abs() < 1e-3);
        assert_eq!(c.gamma0(2.0 * rho), rho);
        assert_eq!(c.gamma0(f32::NAN), 0.0);
        assert_eq!(config(false).gamma0(10.0 * rho), 0.0);
        // True speed 1000 rad/s, estimate 1000 − 2.5ρ: ω̃' = 2.5ρ → γ0 = ρ.
        let mut st = EstimatorState {
            omega: 1000.0 - 2.5 * rho,
            ..EstimatorState::default()
        };
        let out = c.process(&mut st, &mut SoftTrig, bemf(&c, 1000.0, 0.3));
        assert!((out.speed_error - 2.5 * rho).abs() < 1e-2 * rho, "{}", out.speed_error);
        assert_eq!(out.gamma0, rho);
        // (4.92): ρ²ψ/(ρ·ω_max·ΔL) = 125.66·0.104/(2513.2·0.33e-3) = 15.76 A.
        assert!((out.iq_limit - 15.76).abs() < 0.01, "{}", out.iq_limit);
        let w = st.omega;
        let quiet = c.process(&mut st, &mut SoftTrig, bemf(&c, w, 0.0));
        assert_eq!(quiet.gamma0, 0.0);
        assert_eq!(quiet.iq_limit, f32::INFINITY);
    }

    /// §4.2.1/§4.6: started at θ̃ = 0 with ω̃ = 6ρ (the separatrices are dense beyond
    /// 3ρ), the plain estimator slips cycles; with the resetting term none ("an initial
    /// speed estimation error of |ω̃_r| ≈ 7ρ can now be handled without risk for cycle
    /// slips") and it is back within 0.01ρ sooner. Both directions.
    #[test]
    fn resetting_term_prevents_cycle_slips() {
        for sign in [1.0f32, -1.0] {
            let rho = config(false).rho;
            let (plain, slips_plain) = track(&config(false), sign * 1256.6, 0.0, sign * 6.0 * rho, 0.3);
            let (reset, slips_reset) = track(&config(true), sign * 1256.6, 0.0, sign * 6.0 * rho, 0.3);
            println!(
                "ω̃(0) = {}ρ: {slips_plain} cycle slips without, {slips_reset} with the resetting term",
                sign * 6.0
            );
            assert!(slips_plain.abs() >= 1, "plain: {slips_plain}");
            assert_eq!(slips_reset, 0);
            let settle = |v: &[(f32, f32)]| v.iter().rposition(|x| libm::fabsf(x.1) > 0.01 * rho).unwrap_or(0);
            assert!(
                settle(&reset) < settle(&plain),
                "{} vs {}",
                settle(&reset),
                settle(&plain)
            );
        }
    }

    /// The forward-difference Butterworth sections: low-pass DC gain 1, high-pass blocks
    /// DC, both −3 dB (1/√2) at ω_c.
    #[test]
    fn butterworth_sections() {
        let (wc, ts) = (100.0f32, 1e-4f32);
        let mut f = Butterworth2::default();
        let mut last = (0.0, 0.0);
        for _ in 0..20_000 {
            last = f.process(wc, ts, 1.0);
        }
        assert!((last.0 - 1.0).abs() < 1e-4 && last.1.abs() < 1e-4, "{last:?}");
        let amplitude = |high: bool| {
            let mut f = Butterworth2::default();
            let mut peak = 0.0f32;
            for n in 0..200_000 {
                let (lo, hi) = f.process(wc, ts, libm::sinf(wc * ts * n as f32));
                if n > 100_000 {
                    peak = peak.max(libm::fabsf(if high { hi } else { lo }));
                }
            }
            peak
        };
        for high in [false, true] {
            let a = amplitude(high);
            assert!((a - core::f32::consts::FRAC_1_SQRT_2).abs() < 0.01, "{high}: {a}");
        }
    }

    /// Demodulation (4.18)/(4.19): i_q̂ = 2K_e·sin(ω_e t)·sin 2θ̃ + i_q0 (4.21) gives
    /// e = e_si/(2K_e) → sin(2θ̃)/2 (4.20) with the DC i_q0 removed, at standstill — for
    /// K_e > 0 (L_q > L_d) and K_e < 0 (inverse saliency, L_d > L_q: the carrier current's
    /// sin 2θ̃ term changes sign with ΔL (4.17), and so does K̂_e).
    #[test]
    fn injection_error_signal() {
        for ke in [2.0f32, -2.0] {
            let e = demodulated_error(ke, 0.2);
            let want = libm::sinf(2.0 * 0.2) / 2.0;
            // LPF ripple at 2ω_e attenuated by (ω_lp/2ω_e)² ≈ 2e-4.
            assert!((e - want).abs() < 0.01 * want, "K_e = {ke}: {e} vs {want}");
        }
    }

    /// The error e after 4 s of a carrier current with gain `ke` at angle error `err`.
    fn demodulated_error(ke: f32, err: f32) -> f32 {
        let ts = 1e-4f32;
        let inj = InjectionConfig {
            amplitude: 28.0,
            frequency: 2.0 * PI * 500.0,
            gain: ke,
            highpass: 2.0 * PI * 3.0,
            lowpass: 60.0,
            delay: 0.0,
            low_speed: 125.0,
            high_speed: 250.0,
        };
        let c = EstimatorConfig {
            injection: Some(inj),
            rho: 1e-3, // keep θ̂ still: this test looks at e only
            ..config(false)
        };
        let mut st = EstimatorState::default();
        let mut e = 0.0;
        for n in 0..40_000u32 {
            // The carrier phase the estimator will use at this step.
            let phase = to_radians(st.carrier.wrapping_add(from_radians(inj.frequency * ts)));
            let iq = 2.0 * ke * libm::sinf(phase) * libm::sinf(2.0 * err) + 30.0;
            let out = c.process(
                &mut st,
                &mut SoftTrig,
                EstimatorInput {
                    current: Dq { d: 0.0, q: iq },
                    ..EstimatorInput::default()
                },
            );
            assert_eq!(out.blend, 1.0);
            if n == 0 {
                assert!((out.injection.d - 28.0 * libm::cosf(phase)).abs() < 1e-3);
            }
            e = out.error;
        }
        e
    }

    /// Non-finite inputs do not poison the state.
    #[test]
    fn nan_input() {
        let c = config(true);
        let mut st = EstimatorState {
            omega: 500.0,
            ..EstimatorState::default()
        };
        let out = c.process(
            &mut st,
            &mut SoftTrig,
            EstimatorInput {
                voltage: Dq { d: f32::NAN, q: 1.0 },
                ..EstimatorInput::default()
            },
        );
        assert!(out.omega.is_finite() && st.omega == 500.0);
    }
}
