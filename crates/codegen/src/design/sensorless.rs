//! Sensorless estimator design rules, thesis B chapter 4 (Table 4.1): the PLL-type
//! speed and position estimator (4.1), (4.2) with γ1 = ρ², γ2 = 2ρ (4.7), signal
//! injection at low speed (4.18)–(4.20), (4.34), (4.35), back-EMF estimation above
//! ω_ls (4.51), (4.59), (4.69), the transition ω_ls → ω_hs (Fig. 4.9), and the resetting
//! term (4.83) with its i_q limit (4.92).
//!
//! All speeds here are electrical [rad/s] (thesis B writes ω_r for the electrical rotor
//! speed).
//!
//! Saliency of either sign. Thesis B's motor has ΔL = L_q − L_d > 0, but its rules hold
//! for inverse saliency (L_d > L_q) too, with the sign kept where it matters:
//! * (4.17)–(4.19): the carrier current carries ΔL·sin 2θ̃, so any ΔL ≠ 0 gives position
//!   information ("provided that the machine possesses saliency, i.e., ΔL ≠ 0"). K_e (4.19)
//!   keeps the sign of ΔL; the error e = e_si/(2K̂_e) (4.20) is then ≈ sin θ̃ for either
//!   sign, so the estimator dynamics (4.25), (4.26) are unchanged.
//! * (4.35), (4.24): derived from the carrier current's amplitude 2|K_e| (4.21) — |ΔL|.
//! * (4.59), (4.66), (4.92): bounds on |β|, |ψ_m/(ΔL·i_q)| and |i_q| over both signs of
//!   i_q — |ΔL|.
//! * (4.51), (4.69): ψ_m − ΔL·i_d, signed; at the MTPA point (3.10) i_d has the sign of
//!   −ΔL (positive for inverse saliency), so the term stays above ψ_m either way. With
//!   ΔL < 0 it vanishes at i_d = ψ_m/ΔL < 0, which a field-weakening i_d reaches when
//!   I_max ≥ ψ_m/|ΔL|: (4.51) is singular there and the design warns.

use serde::Serialize;

use super::loss_minimisation::mtpa_corner;

/// Everything the rules need, in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Inputs {
    /// R̂_s \[Ω\].
    pub resistance: f64,
    /// L̂_d \[H\].
    pub ld: f64,
    /// L̂_q \[H\].
    pub lq: f64,
    /// ψ̂_m \[Wb\].
    pub psi: f64,
    /// I_max, the peak phase current \[A\].
    pub current_max: f64,
    /// I_base = √2·I_n \[A\], the per-unit base current (thesis B App. A) of (4.24), (4.35)
    /// and of the ω_min2 (4.69) operating point.
    pub current_base: f64,
    /// ω_max, the largest electrical speed [rad/s] (4.92).
    pub speed_max: f64,
    /// α_c, the current-loop bandwidth [rad/s].
    pub current_bandwidth: f64,
    /// ω_sw = 2π·f_sw [rad/s].
    pub switching: f64,
    /// V_max = U_dc/√3, the largest phase-voltage amplitude \[V\].
    pub voltage_max: f64,
    /// ω_base of the per-unit system [rad/s], if the spec defines one.
    pub speed_base: Option<f64>,
    /// Motor pole pairs (mechanical → electrical acceleration).
    pub pole_pairs: f64,
    /// The spec's choices.
    pub choices: Choices,
}

/// What the spec's `[sensorless]` section fixes; `None` takes the thesis default.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Choices {
    /// ρ [rad/s].
    pub bandwidth: Option<f64>,
    /// Largest shaft acceleration [rad/s², mechanical].
    pub max_acceleration: Option<f64>,
    /// θ̃_max \[rad\].
    pub angle_error: f64,
    /// ω_e [rad/s].
    pub injection_frequency: Option<f64>,
    /// V_e \[V\].
    pub injection_voltage: Option<f64>,
    /// ω_hp [rad/s].
    pub highpass: Option<f64>,
    /// ω_lp [rad/s].
    pub lowpass: Option<f64>,
    /// R̃_s/R_s for (4.69).
    pub resistance_error: f64,
    /// ω_ν [rad/s] for (4.24).
    pub speed_noise: Option<f64>,
}

/// Where ρ came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RhoRule {
    /// `sensorless.bandwidth`.
    Given,
    /// ρ = √(|ω̇_r|max / sin θ̃max) (4.74).
    Acceleration,
    /// ρ = α_c/10, the bound of Table 4.1 (the choice of Figs. 4.17, 4.18).
    CurrentLoopBound,
}

/// Why the design has no signal injection.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "reason")]
pub enum NoInjection {
    /// L_d = L_q: the carrier current holds no position information (4.17).
    NoSaliency,
    /// Salient, but |ΔL| is too small for the carrier rule: (4.35) with V_e ≤ 0.2·V_max
    /// needs ω_e ≤ `frequency_limit_rad_s`, below 5α_c (4.34).
    SaliencyTooSmall {
        /// |ΔL|/max(L_d, L_q).
        saliency: f64,
        /// The largest ω_e at which (4.35) stays within 0.2·V_max [rad/s].
        frequency_limit_rad_s: f64,
        /// 5α_c [rad/s].
        frequency_min_rad_s: f64,
    },
    /// ω_sw/10 (4.34) is below 5α_c: no carrier fits between the switching frequency and
    /// the current loop.
    SwitchingTooSlow {
        /// ω_sw/10 [rad/s].
        frequency_max_rad_s: f64,
        /// 5α_c [rad/s].
        frequency_min_rad_s: f64,
    },
}

impl std::fmt::Display for NoInjection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NoInjection::NoSaliency => write!(
                f,
                "L_q = L_d: no saliency, the carrier current holds no position information (thesis B (4.17))"
            ),
            NoInjection::SaliencyTooSmall {
                saliency,
                frequency_limit_rad_s,
                frequency_min_rad_s,
            } => write!(
                f,
                "saliency |L_q − L_d|/L = {:.1} % too small for the carrier rule: V_e (4.35) ≤ {:.0} % of V_max needs \
                 ω_e ≤ {frequency_limit_rad_s:.0} rad/s, below 5α_c = {frequency_min_rad_s:.0} rad/s (4.34)",
                saliency * 100.0,
                MAX_INJECTION_SHARE * 100.0
            ),
            NoInjection::SwitchingTooSlow {
                frequency_max_rad_s,
                frequency_min_rad_s,
            } => write!(
                f,
                "no carrier between 5α_c = {frequency_min_rad_s:.0} rad/s and ω_sw/10 = {frequency_max_rad_s:.0} rad/s (4.34): \
                 the switching frequency is too low for the current-loop bandwidth"
            ),
        }
    }
}

/// Signal-injection constants (motors with ΔL ≠ 0).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InjectionOut {
    /// ω_e [rad/s].
    pub frequency_rad_s: f64,
    /// Lower end of (4.34): 5·α_c [rad/s].
    pub frequency_min_rad_s: f64,
    /// Upper end of (4.34): ω_sw/10 [rad/s].
    pub frequency_max_rad_s: f64,
    /// V_e \[V\].
    pub voltage_v: f64,
    /// Smallest V_e of (4.35) \[V\].
    pub voltage_min_v: f64,
    /// K_e = V_e·ΔL/(4·ω_e·L_d·L_q) (4.19) \[A\], with the sign of ΔL = L_q − L_d.
    pub gain_ke_a: f64,
    /// ω_hp [rad/s].
    pub highpass_rad_s: f64,
    /// ω_lp [rad/s].
    pub lowpass_rad_s: f64,
    /// The largest ρ without demodulation filters (4.24) [rad/s], when ω_ν is known.
    pub rho_max_without_filters_rad_s: Option<f64>,
    /// ω_ν used for (4.24) [rad/s].
    pub speed_noise_rad_s: Option<f64>,
}

/// The estimator design.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorlessOut {
    /// ρ [rad/s].
    pub rho_rad_s: f64,
    /// How ρ was chosen.
    pub rho_rule: RhoRule,
    /// α_c/10, the upper bound of ρ (Table 4.1) [rad/s].
    pub rho_max_rad_s: f64,
    /// γ1 = ρ² (4.7) [1/s²].
    pub gamma1: f64,
    /// γ2 = 2ρ (4.7) [1/s].
    pub gamma2: f64,
    /// θ̃_max \[rad\].
    pub angle_error_rad: f64,
    /// Electrical acceleration tracked within θ̃_max: ρ²·sin θ̃max (4.74) [rad/s²].
    pub acceleration_tracked_rad_s2: f64,
    /// Injection, for a salient motor (ΔL = L_q − L_d ≠ 0).
    pub injection: Option<InjectionOut>,
    /// Why there is no injection, when there is none.
    pub no_injection: Option<NoInjection>,
    /// ω_min1 (4.59) [rad/s].
    pub omega_min1_rad_s: f64,
    /// ω_min2 (4.69) [rad/s].
    pub omega_min2_rad_s: f64,
    /// ω_ls = max(ω_min1, ω_min2) (Table 4.1) [rad/s].
    pub omega_ls_rad_s: f64,
    /// ω_hs = 2·ω_ls (Table 4.1) [rad/s].
    pub omega_hs_rad_s: f64,
    /// Δω1 = ρ (§4.6) [rad/s].
    pub resetting_lower_rad_s: f64,
    /// Δω2 = 2ρ (§4.6) [rad/s].
    pub resetting_upper_rad_s: f64,
    /// i_d of the MTPA point (3.10) at I_base: the operating point of ω_min2 (4.69) \[A\].
    pub id_at_base_current_a: f64,
    /// |i_q^ref| limit while the resetting term acts (4.92) with γ0 = ρ \[A\] (salient).
    pub iq_limit_resetting_a: Option<f64>,
    /// |i_q| ≤ ψ_m/|ΔL|, no bifurcation (4.66) \[A\] (salient).
    pub iq_limit_bifurcation_a: Option<f64>,
}

/// ρ = √(|ω̇_r|max / sin θ̃max) (4.74): the bandwidth that keeps the transient angle
/// error within θ̃max at the acceleration `acceleration` [rad/s², electrical].
pub fn rho_from_acceleration(acceleration: f64, angle_error: f64) -> f64 {
    (acceleration / angle_error.sin()).sqrt()
}

/// Smallest carrier amplitude (4.35): V_e = I_base·ω_e·L_d·L_q/(10·|ΔL|) (the carrier
/// current 2|K_e| of (4.21) at 5 % of I_base).
pub fn injection_voltage_min(current_base: f64, omega_e: f64, ld: f64, lq: f64) -> f64 {
    current_base * omega_e * ld * lq / (10.0 * (lq - ld).abs())
}

/// K_e = V_e·ΔL/(4·ω_e·L_d·L_q) (4.19), signed: negative for inverse saliency.
pub fn injection_gain(voltage: f64, omega_e: f64, ld: f64, lq: f64) -> f64 {
    voltage * (lq - ld) / (4.0 * omega_e * ld * lq)
}

/// The largest ρ without low- and high-pass filters (4.24):
/// ρ ≤ √(ω_ν·|ΔL|·V_e/(2·L_d·L_q·I_base)).
pub fn rho_max_without_filters(speed_noise: f64, voltage: f64, ld: f64, lq: f64, current_base: f64) -> f64 {
    (speed_noise * (lq - ld).abs() * voltage / (2.0 * ld * lq * current_base)).sqrt()
}

/// ω_min1 = 5ρ·|ΔL|·I_max/(3ψ_m) (4.59): below it the back-EMF error's poles leave the
/// 45° sector (|β| > 0.3 for some sign of i_q).
pub fn omega_min1(rho: f64, delta_l: f64, current_max: f64, psi: f64) -> f64 {
    5.0 * rho * delta_l.abs() * current_max / (3.0 * psi)
}

/// ω_min2 = |R̃_s·i_d/(θ̃·(ψ_m − ΔL·i_d))| (4.69), ΔL signed.
pub fn omega_min2(resistance_error: f64, id: f64, angle_error: f64, psi: f64, delta_l: f64) -> f64 {
    (resistance_error * id / (angle_error * (psi - delta_l * id))).abs()
}

/// |i_q| ≤ ψ_m/|ΔL| (4.66).
pub fn iq_limit_bifurcation(psi: f64, delta_l: f64) -> f64 {
    psi / delta_l.abs()
}

/// |i_q^ref| < ρ²·ψ̂_m/(γ0·ω_max·|ΔL̂|) (4.92).
pub fn iq_limit_resetting(rho: f64, psi: f64, gamma0: f64, speed_max: f64, delta_l: f64) -> f64 {
    rho * rho * psi / (gamma0 * speed_max * delta_l.abs())
}

/// The largest share of V_max the carrier may take by default: thesis B §4.3.1 allows
/// V_e = 0.2 pu "for high-frequency signal injection" (V_max = 1 pu at the nominal DC
/// link, Appendix A).
pub const MAX_INJECTION_SHARE: f64 = 0.2;

/// A warning of the design and the spec key it is about (`sensorless.<key>`, or
/// `sensorless` for the section, or `motor.peak_current` for the peak current).
pub type Note = (&'static str, String);

/// The design, with the warnings it raises, each with its key. ρ above α_c/10 is not
/// checked here (the caller reports it at the spec key that set it).
pub fn design(inp: &Inputs) -> (SensorlessOut, Vec<Note>) {
    let c = &inp.choices;
    let mut warnings = Vec::new();
    let rho_max = inp.current_bandwidth / 10.0;
    let (rho, rho_rule) = match (c.bandwidth, c.max_acceleration) {
        (Some(r), _) => (r, RhoRule::Given),
        (None, Some(a)) => (
            rho_from_acceleration(inp.pole_pairs * a, c.angle_error),
            RhoRule::Acceleration,
        ),
        (None, None) => (rho_max, RhoRule::CurrentLoopBound),
    };
    let delta_l = inp.lq - inp.ld;
    let salient = delta_l != 0.0;
    // Default carrier: as high as (4.34) allows, ω_sw/10, but no higher than the ω_e at
    // which (4.35) takes MAX_INJECTION_SHARE of V_max. A default must meet (4.34)'s lower
    // bound 5α_c too; where it cannot, injection is left to the spec
    // (`injection_frequency`, `injection_voltage`), as the thesis does for its own motor.
    let lo = 5.0 * inp.current_bandwidth;
    let hi = inp.switching / 10.0;
    let voltage_limited = if salient {
        MAX_INJECTION_SHARE * inp.voltage_max * 10.0 * delta_l.abs() / (inp.current_base * inp.ld * inp.lq)
    } else {
        0.0
    };
    let we_default = hi.min(voltage_limited);
    let chosen = c.injection_frequency.is_some() || c.injection_voltage.is_some();
    let no_injection = if !salient {
        Some(NoInjection::NoSaliency)
    } else if chosen || we_default >= lo {
        None
    } else if voltage_limited < lo {
        Some(NoInjection::SaliencyTooSmall {
            saliency: delta_l.abs() / inp.ld.max(inp.lq),
            frequency_limit_rad_s: voltage_limited,
            frequency_min_rad_s: lo,
        })
    } else {
        Some(NoInjection::SwitchingTooSlow {
            frequency_max_rad_s: hi,
            frequency_min_rad_s: lo,
        })
    };
    if let Some(why @ (NoInjection::SaliencyTooSmall { .. } | NoInjection::SwitchingTooSlow { .. })) = &no_injection {
        warnings.push((
            "sensorless.injection_frequency",
            format!(
                "sensorless: no signal injection by default: {why}; set sensorless.injection_frequency (and \
             injection_voltage) to inject below 5α_c (thesis B §4.3.5)"
            ),
        ));
    }
    let injection = no_injection.is_none().then(|| {
        let we = c.injection_frequency.unwrap_or(we_default);
        if we < lo || we > hi {
            warnings.push(("sensorless.injection_frequency", format!(
                "sensorless: carrier ω_e = {we:.0} rad/s is outside 5α_c = {lo:.0} … ω_sw/10 = {hi:.0} rad/s \
                 (thesis B (4.34)); below 5α_c use the reference currents in the decoupling terms (thesis B §4.3.5)"
            )));
        }
        let v_min = injection_voltage_min(inp.current_base, we, inp.ld, inp.lq);
        let ve = c.injection_voltage.unwrap_or(v_min);
        if ve < v_min {
            warnings.push(("sensorless.injection_voltage", format!(
                "sensorless: carrier amplitude V_e = {ve:.2} V is below I_base·ω_e·L_d·L_q/(10·|ΔL|) = {v_min:.2} V \
                 (thesis B (4.35)): the carrier current stays under 5 % of I_base"
            )));
        }
        if ve > MAX_INJECTION_SHARE * inp.voltage_max * (1.0 + 1e-9) {
            warnings.push(("sensorless.injection_voltage", format!(
                "sensorless: the carrier takes V_e = {ve:.1} V = {:.0} % of V_max (thesis B §4.3.1 allows {:.0} %): \
                 less voltage is left for the fundamental currents",
                100.0 * ve / inp.voltage_max,
                100.0 * MAX_INJECTION_SHARE
            )));
        }
        let lowpass = c.lowpass.unwrap_or(5.0 * rho);
        if lowpass < 5.0 * rho * (1.0 - 1e-9) || lowpass > 10.0 * rho * (1.0 + 1e-9) {
            warnings.push(("sensorless.lowpass", format!(
                "sensorless: low-pass ω_lp = {lowpass:.1} rad/s is outside 5ρ … 10ρ = {:.1} … {:.1} rad/s (thesis B Table 4.1)",
                5.0 * rho,
                10.0 * rho
            )));
        }
        // Thesis B §4.5.1: ω_hp = 0.015 pu; "a few Hertz" (§4.3) without a per-unit base.
        let highpass = c
            .highpass
            .unwrap_or_else(|| inp.speed_base.map_or(2.0 * std::f64::consts::PI * 3.0, |b| 0.015 * b));
        let speed_noise = c.speed_noise.or(inp.speed_base.map(|b| 0.01 * b));
        InjectionOut {
            frequency_rad_s: we,
            frequency_min_rad_s: lo,
            frequency_max_rad_s: hi,
            voltage_v: ve,
            voltage_min_v: v_min,
            gain_ke_a: injection_gain(ve, we, inp.ld, inp.lq),
            highpass_rad_s: highpass,
            lowpass_rad_s: lowpass,
            rho_max_without_filters_rad_s: speed_noise
                .map(|n| rho_max_without_filters(n, ve, inp.ld, inp.lq, inp.current_base)),
            speed_noise_rad_s: speed_noise,
        }
    });
    let w1 = if salient {
        omega_min1(rho, delta_l, inp.current_max, inp.psi)
    } else {
        0.0
    };
    // (4.69) at the MTPA d-current (3.10) of base current: with R̃ = 2R and θ̃ = 10° this
    // is thesis B's "ω_min2 ≈ 0.05 pu" for its motor (i_d = −0.44 pu). For inverse saliency
    // the MTPA i_d is positive (the branch of (3.10) that maximises the torque).
    let (id_base, _) = mtpa_corner(inp.psi, delta_l, inp.current_base);
    let w2 = omega_min2(
        c.resistance_error * inp.resistance,
        id_base,
        c.angle_error,
        inp.psi,
        delta_l,
    );
    let ls = w1.max(w2);
    if !salient {
        warnings.push((
            "sensorless",
            format!(
                "sensorless: L_q = L_d, no saliency for signal injection (thesis B (4.17)): the estimator has no \
             position information below ω_ls = {ls:.1} rad/s"
            ),
        ));
    }
    let bifurcation = salient.then(|| iq_limit_bifurcation(inp.psi, delta_l));
    if let Some(b) = bifurcation
        && inp.current_max > b
    {
        warnings.push((
            "motor.peak_current",
            format!(
                "sensorless: the peak current {:.1} A exceeds ψ_m/|ΔL| = {b:.1} A (thesis B (4.66)): above it the \
             back-EMF estimator has unwanted equilibria; limit |i_q| in sensorless operation",
                inp.current_max
            ),
        ));
    }
    if delta_l < 0.0 && inp.current_max >= inp.psi / -delta_l {
        warnings.push(("sensorless", format!(
            "sensorless: inverse saliency (L_d > L_q): ψ_m − ΔL·i_d in the back-EMF error (thesis B (4.51)) vanishes \
             at i_d = ψ_m/ΔL = {:.1} A, inside the current circle (−I_max = {:.1} A): the error is singular if field \
             weakening drives i_d there (thesis B derives (4.51) for ΔL > 0, where i_d < 0 only strengthens the term)",
            inp.psi / delta_l,
            -inp.current_max
        )));
    }
    let out = SensorlessOut {
        rho_rad_s: rho,
        rho_rule,
        rho_max_rad_s: rho_max,
        gamma1: rho * rho,
        gamma2: 2.0 * rho,
        angle_error_rad: c.angle_error,
        acceleration_tracked_rad_s2: rho * rho * c.angle_error.sin(),
        injection,
        no_injection,
        omega_min1_rad_s: w1,
        omega_min2_rad_s: w2,
        omega_ls_rad_s: ls,
        omega_hs_rad_s: 2.0 * ls,
        resetting_lower_rad_s: rho,
        resetting_upper_rad_s: 2.0 * rho,
        id_at_base_current_a: id_base,
        iq_limit_resetting_a: salient.then(|| iq_limit_resetting(rho, inp.psi, rho, inp.speed_max, delta_l)),
        iq_limit_bifurcation_a: bifurcation,
    };
    (out, warnings)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    // Thesis B Appendix B (Tables B.1, B.2) in SI units, and its per-unit bases
    // (Appendix A): I_base = √2·160 A, ω_base = 2π·200 Hz, V_base = 320 V/√3
    // (the DC link that reproduces Table B.2, see motors/chalmers-hev50.toml).
    const LD: f64 = 0.23e-3;
    const LQ: f64 = 0.56e-3;
    const PSI: f64 = 0.104;
    const R: f64 = 7.9e-3;
    fn i_base() -> f64 {
        2f64.sqrt() * 160.0
    }
    fn w_base() -> f64 {
        2.0 * PI * 200.0
    }
    fn v_base() -> f64 {
        320.0 / 3f64.sqrt()
    }

    /// Thesis B §4.3.5, footnote 6: "a carrier frequency of f_e = 500 Hz … gives
    /// V_e ≥ 0.15 pu, which corresponds to 28 V".
    #[test]
    fn carrier_amplitude_at_500_hz_is_0_15_pu_28_v() {
        let v = injection_voltage_min(i_base(), 2.0 * PI * 500.0, LD, LQ);
        // Hand: 226.27 A · 3141.6 rad/s · 0.23 mH · 0.56 mH / (10 · 0.33 mH) = 27.74 V.
        assert!((v - 27.74).abs() < 0.01, "{v}");
        assert_eq!((v / v_base() * 100.0).round() / 100.0, 0.15);
        assert_eq!(v.round(), 28.0);
    }

    /// Thesis B §4.4.1 after (4.59): "ρ = 0.1 pu … gives ω_min1 ≈ 0.1 pu" (I_max = 1 pu).
    #[test]
    fn omega_min1_is_0_1_pu_at_rho_0_1_pu() {
        let w = omega_min1(0.1 * w_base(), LQ - LD, i_base(), PSI);
        // Hand: 5 · 125.66 · 0.33e-3 · 226.27 / (3 · 0.104) = 150.4 rad/s = 0.120 pu.
        assert!((w - 150.4).abs() < 0.1, "{w}");
        assert_eq!((w / w_base() * 10.0).round() / 10.0, 0.1);
    }

    /// Thesis B after (4.66): "(4.66) sets the limit |i_q| ≤ 1.4 pu".
    #[test]
    fn bifurcation_limit_is_1_4_pu() {
        let i = iq_limit_bifurcation(PSI, LQ - LD);
        // Hand: 0.104 Wb / 0.33 mH = 315.2 A = 1.393 pu.
        assert!((i - 315.15).abs() < 0.01, "{i}");
        assert_eq!((i / i_base() * 10.0).round() / 10.0, 1.4);
    }

    /// Thesis B after (4.24): V_e = 0.2 pu, ω_ν = 0.01 pu at I_base "gives the limit
    /// ρ ≤ 0.04 pu".
    #[test]
    fn rho_without_filters_is_0_04_pu() {
        let r = rho_max_without_filters(0.01 * w_base(), 0.2 * v_base(), LD, LQ, i_base());
        // Hand: √(12.566 · 0.33e-3 · 36.95 / (2 · 0.23e-3 · 0.56e-3 · 226.27)) = 51.3 rad/s.
        assert!((r - 51.3).abs() < 0.1, "{r}");
        assert_eq!((r / w_base() * 100.0).round() / 100.0, 0.04);
    }

    /// (4.74) by hand, and its inverse: the tracked acceleration ρ²·sin θ̃.
    #[test]
    fn rho_from_acceleration_by_hand() {
        // 1000 rad/s² electrical, θ̃ = 10°: √(1000 / 0.173648) = 75.89 rad/s.
        let rho = rho_from_acceleration(1000.0, 10f64.to_radians());
        assert!((rho - 75.887).abs() < 1e-3, "{rho}");
        let inp = chalmers(Choices {
            max_acceleration: Some(500.0),
            ..choices()
        });
        let (out, _) = design(&inp);
        // n_p = 2: 500 rad/s² at the shaft is 1000 rad/s² electrical.
        assert_eq!(out.rho_rule, RhoRule::Acceleration);
        assert!((out.rho_rad_s - 75.887).abs() < 1e-3);
        assert!((out.acceleration_tracked_rad_s2 - 1000.0).abs() < 1e-9);
    }

    /// Thesis B after (4.69): θ̃ = 10°, R̃_s = 2R_s "gives ω_min2 ≈ 0.05 pu", at the MTPA
    /// d-current of base current.
    #[test]
    fn omega_min2_is_0_05_pu() {
        let (id, _) = mtpa_corner(PSI, LQ - LD, i_base());
        // Hand: (0.104 − √(0.010816 + 0.044603))/(1.32e-3) = (0.104 − 0.235413)/1.32e-3
        // = −99.56 A = −0.44 pu.
        assert!((id + 99.56).abs() < 0.01, "{id}");
        let w = omega_min2(2.0 * R, id, 10f64.to_radians(), PSI, LQ - LD);
        // Hand: 0.0158·99.56/(0.174533·(0.104 + 0.032855)) = 1.5730/0.023886 = 65.86 rad/s.
        assert!((w - 65.86).abs() < 0.02, "{w}");
        assert_eq!((w / w_base() * 100.0).round() / 100.0, 0.05);
    }

    /// (4.69) by hand for the Chalmers motor with R̃ = 2R at i_d = −I_base, θ̃ = 10°.
    #[test]
    fn omega_min2_by_hand() {
        let w = omega_min2(2.0 * R, -i_base(), 10f64.to_radians(), PSI, LQ - LD);
        // |0.0158 · (−226.27)| / (0.174533 · (0.104 + 0.33e-3 · 226.27)) = 3.5751/0.031184 = 114.6
        assert!((w - 114.6).abs() < 0.1, "{w}");
    }

    fn choices() -> Choices {
        Choices {
            angle_error: 10f64.to_radians(),
            resistance_error: 2.0,
            ..Choices::default()
        }
    }

    fn chalmers(choices: Choices) -> Inputs {
        Inputs {
            resistance: R,
            ld: LD,
            lq: LQ,
            psi: PSI,
            current_max: 1.4 * i_base(),
            current_base: i_base(),
            speed_max: 2.0 * w_base(),
            current_bandwidth: 1470.0,
            switching: 2.0 * PI * 10e3,
            voltage_max: v_base(),
            speed_base: Some(w_base()),
            pole_pairs: 2.0,
            choices,
        }
    }

    /// Table 4.1 defaults and the properties tying the outputs together; the carrier
    /// at 500 Hz as the spec sets it (thesis B §4.5.1).
    #[test]
    fn defaults_follow_table_4_1() {
        let (out, warnings) = design(&chalmers(Choices {
            injection_frequency: Some(2.0 * PI * 500.0),
            ..choices()
        }));
        assert_eq!(out.rho_rule, RhoRule::CurrentLoopBound);
        assert_eq!(out.rho_rad_s, 147.0);
        assert_eq!(out.gamma1, 147.0 * 147.0);
        assert_eq!(out.gamma2, 294.0);
        assert_eq!(out.omega_hs_rad_s, 2.0 * out.omega_ls_rad_s);
        assert_eq!(out.omega_ls_rad_s, out.omega_min1_rad_s.max(out.omega_min2_rad_s));
        assert_eq!((out.resetting_lower_rad_s, out.resetting_upper_rad_s), (147.0, 294.0));
        let inj = out.injection.as_ref().unwrap();
        // 500 Hz is below 5α_c = 7350 rad/s: warned (4.34).
        assert!(warnings.iter().any(|(_, w)| w.contains("(4.34)")));
        assert_eq!(inj.voltage_v, inj.voltage_min_v);
        assert_eq!(inj.lowpass_rad_s, 5.0 * 147.0);
        assert!((inj.highpass_rad_s - 0.015 * w_base()).abs() < 1e-12);
        // K_e (4.19) with V_e at its minimum (4.35): I_base/40 exactly.
        assert!((inj.gain_ke_a - i_base() / 40.0).abs() < 1e-9);
        // The peak current 1.4 pu is above ψ/ΔL = 1.393 pu: warned (4.66).
        assert!(warnings.iter().any(|(_, w)| w.contains("(4.66)")));
        // (4.92) with γ0 = ρ: ρ·ψ/(ω_max·ΔL).
        let lim = out.iq_limit_resetting_a.unwrap();
        assert!((lim - 147.0 * PSI / (2.0 * w_base() * (LQ - LD))).abs() < 1e-9);
    }

    /// Without a carrier in the spec: (4.35) at 0.2·V_max allows ω_e ≤
    /// 0.2·184.75·10·0.33e-3/(226.27·0.23e-3·0.56e-3) = 4184 rad/s, below 5α_c = 7350
    /// rad/s, so the default cannot meet (4.34): no injection, warned.
    #[test]
    fn no_default_carrier_when_4_34_and_4_35_cannot_both_hold() {
        let (out, warnings) = design(&chalmers(choices()));
        assert!(out.injection.is_none());
        let (key, w) = warnings
            .iter()
            .find(|(_, w)| w.contains("no signal injection by default"))
            .unwrap();
        assert_eq!(*key, "sensorless.injection_frequency");
        assert!(w.contains("4184"), "{w}");
        // A faster switching frequency does not help; a slower current loop does:
        // α_c = 800 rad/s → 5α_c = 4000 rad/s ≤ 4184 rad/s, so ω_e = 4184 rad/s.
        let mut slow = chalmers(choices());
        slow.current_bandwidth = 800.0;
        let inj = design(&slow).0.injection.unwrap();
        assert!((inj.frequency_rad_s - 4184.0).abs() < 1.0, "{}", inj.frequency_rad_s);
        assert!((inj.voltage_v - 0.2 * v_base()).abs() < 1e-9);
    }

    /// Inverse saliency, a labelled variant of the thesis B motor with L_d = 0.70 mH >
    /// L_q = 0.56 mH (ΔL = −0.14 mH), carrier at 100 Hz (ω_e = 628.32 rad/s). By hand:
    /// (4.35) with |ΔL|: V_e = 226.274·628.32·0.70e-3·0.56e-3/(10·0.14e-3) = 39.808 V;
    /// (4.19) keeps the sign: K_e = 39.808·(−0.14e-3)/(4·628.32·3.92e-7) = −5.657 A = −I_base/40;
    /// (4.66): ψ/|ΔL| = 742.86 A; (4.59): 5·147·0.14e-3·316.78/(3·0.104) = 104.48 rad/s;
    /// (4.69) at the MTPA point of I_base, now on the positive branch: i_d = 2·0.14e-3·51200
    /// /(0.104 + √(0.010816 + 8·1.96e-8·51200)) = +59.418 A, ω_min2 = 0.0158·59.418/
    /// (0.174533·(0.104 + 0.14e-3·59.418)) = 47.890 rad/s; (4.92): 147·0.104/(2513.27·0.14e-3)
    /// = 43.449 A. The default carrier rule: (4.35) ≤ 0.2·V_max allows only ω_e ≤
    /// 0.2·184.75·10·0.14e-3/(226.27·3.92e-7) = 583.2 rad/s < 5α_c: saliency too small.
    #[test]
    fn inverse_saliency_by_hand() {
        let mut inp = chalmers(Choices {
            injection_frequency: Some(2.0 * PI * 100.0),
            ..choices()
        });
        inp.ld = 0.70e-3;
        let (out, warnings) = design(&inp);
        let inj = out.injection.as_ref().unwrap();
        assert!((inj.voltage_v - 39.808).abs() < 1e-3, "{}", inj.voltage_v);
        assert!((inj.gain_ke_a + i_base() / 40.0).abs() < 1e-9, "{}", inj.gain_ke_a);
        assert!((out.iq_limit_bifurcation_a.unwrap() - 742.857).abs() < 1e-3);
        assert!(
            (out.omega_min1_rad_s - 104.478).abs() < 1e-3,
            "{}",
            out.omega_min1_rad_s
        );
        assert!(
            (out.id_at_base_current_a - 59.418).abs() < 1e-3,
            "{}",
            out.id_at_base_current_a
        );
        assert!((out.omega_min2_rad_s - 47.890).abs() < 1e-3, "{}", out.omega_min2_rad_s);
        assert!((out.iq_limit_resetting_a.unwrap() - 43.449).abs() < 1e-3);
        // ψ/|ΔL| = 742.9 A lies outside I_max = 316.8 A: (4.51) is not singular in the circle.
        assert!(!warnings.iter().any(|(_, w)| w.contains("(4.51)")), "{warnings:?}");
        let (out, warnings) = design(&Inputs {
            choices: choices(),
            ..inp.clone()
        });
        match out.no_injection {
            Some(NoInjection::SaliencyTooSmall {
                frequency_limit_rad_s, ..
            }) => assert!((frequency_limit_rad_s - 583.21).abs() < 0.01),
            other => panic!("{other:?}"),
        }
        assert!(
            warnings
                .iter()
                .any(|(_, w)| w.contains("too small for the carrier rule"))
        );
        // A stronger inverse saliency puts ψ/|ΔL| inside the current circle: warned.
        inp.ld = 1.0e-3;
        let (_, warnings) = design(&inp);
        assert!(warnings.iter().any(|(_, w)| w.contains("(4.51)")), "{warnings:?}");
    }

    /// The real reason for no injection: L_q = 130 µH > L_d = 125 µH is salient, but
    /// |ΔL| = 5 µH is too small for the carrier rule — not "L_q ≤ L_d".
    #[test]
    fn small_saliency_is_not_reported_as_none() {
        let mut inp = chalmers(choices());
        inp.ld = 125e-6;
        inp.lq = 130e-6;
        let (out, warnings) = design(&inp);
        assert!(matches!(out.no_injection, Some(NoInjection::SaliencyTooSmall { .. })));
        let why = out.no_injection.unwrap().to_string();
        assert!(why.contains("3.8 % too small for the carrier rule"), "{why}");
        assert!(!warnings.iter().any(|(_, w)| w.contains("no saliency")), "{warnings:?}");
        // The bifurcation and resetting limits exist for any ΔL ≠ 0.
        assert!(out.iq_limit_bifurcation_a.is_some() && out.iq_limit_resetting_a.is_some());
    }

    /// A non-salient motor has no injection and no ω_min1; its ω_ls comes from (4.69).
    #[test]
    fn non_salient_motor_has_no_injection() {
        let mut inp = chalmers(choices());
        inp.lq = inp.ld;
        let (out, warnings) = design(&inp);
        assert!(out.injection.is_none() && out.iq_limit_bifurcation_a.is_none());
        assert_eq!(out.no_injection, Some(NoInjection::NoSaliency));
        assert_eq!(out.omega_min1_rad_s, 0.0);
        assert_eq!(out.omega_ls_rad_s, out.omega_min2_rad_s);
        assert!(warnings.iter().any(|(_, w)| w.contains("no saliency")));
    }
}
