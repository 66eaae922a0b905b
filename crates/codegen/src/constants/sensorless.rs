//! The `sensorless` group: thesis B chapter 4 estimator constants (Table 4.1).

use super::{Constant, Group, c, f32v, phys};
use crate::design::Design;
use crate::design::sensorless::RhoRule;

/// One entry: name, value, unit, formula, equation, inputs, JSON field below `/sensorless`.
type Row<'a> = (&'a str, f64, &'a str, &'a str, &'a str, String, &'a str);

/// The group; with ψ_M (or I_base) unknown the rules cannot be evaluated and every entry
/// is 0 (sensorless operation off), as for the field-weakening group. Without injection
/// (no saliency, or too little for the carrier rule) the injection entries are 0, with
/// the reason the design gives.
pub fn group(d: &Design) -> Group {
    let title = "Sensorless estimator: PLL gains, signal injection, transition, resetting term (thesis B ch. 4)";
    let s = d.sensorless.as_ref();
    let off_why = if d.motor.flux_linkage_wb.is_none() {
        "ψ_M unknown → 0 (sensorless off)"
    } else if d.per_unit.bases.current_a.is_none() {
        "I_n unknown: no I_base = √2·I_n for (4.24), (4.35), (4.69) → 0 (sensorless off)"
    } else {
        "sensorless off → 0"
    };
    let rho_in = s.map_or_else(
        || off_why.to_string(),
        |s| match s.rho_rule {
            RhoRule::Given => "ρ = sensorless.bandwidth (spec)".into(),
            RhoRule::Acceleration => format!(
                "ρ = √(n_p·|ω̇_m|max / sin θ̃max) (spec sensorless.max_acceleration), θ̃max = {:.1}°",
                s.angle_error_rad.to_degrees()
            ),
            RhoRule::CurrentLoopBound => format!(
                "ρ = α_c/10, α_c = {} (Table 4.1 bound, as in Figs. 4.17, 4.18)",
                phys(d.current_loop.bandwidth_rad_s, "rad/s")
            ),
        },
    );
    let get = |f: fn(&crate::design::sensorless::SensorlessOut) -> f64| s.map_or(0.0, f);
    let inj = s.and_then(|s| s.injection.as_ref());
    let get_inj = |f: fn(&crate::design::sensorless::InjectionOut) -> f64| inj.map_or(0.0, f);
    let inj_in = |detail: String| match (s, inj) {
        (None, _) => off_why.to_string(),
        (Some(s), None) => format!(
            "no signal injection → 0: {}",
            s.no_injection.as_ref().map_or_else(String::new, ToString::to_string)
        ),
        (Some(_), Some(_)) => detail,
    };
    let m = &d.motor;
    let motor_in = format!(
        "L_d = {}, L_q = {}, ψ_M = {}",
        phys(m.d_inductance_h, "H"),
        phys(m.q_inductance_h, "H"),
        phys(m.flux_linkage_wb.unwrap_or(0.0), "Wb")
    );
    let imax_in = format!("I_max = {}", phys(m.peak_current_a, "A"));
    let rows: Vec<Row<'_>> = vec![
        (
            "RHO",
            get(|s| s.rho_rad_s),
            "rad/s",
            "ρ: estimator bandwidth, ρ ≤ α_c/10",
            "thesis B (4.74), Table 4.1",
            rho_in.clone(),
            "rho_rad_s",
        ),
        (
            "GAMMA1",
            get(|s| s.gamma1),
            "1/s²",
            "γ1 = ρ²",
            "thesis B (4.7)",
            rho_in.clone(),
            "gamma1",
        ),
        (
            "GAMMA2",
            get(|s| s.gamma2),
            "1/s",
            "γ2 = 2ρ",
            "thesis B (4.7)",
            rho_in.clone(),
            "gamma2",
        ),
        (
            "INJECTION_FREQUENCY",
            get_inj(|i| i.frequency_rad_s),
            "rad/s",
            "ω_e, 5α_c ≤ ω_e ≤ ω_sw/10 (spec sensorless.injection_frequency, default ω_sw/10)",
            "thesis B (4.34)",
            inj_in(format!(
                "5α_c = {}, ω_sw/10 = {}",
                phys(get_inj(|i| i.frequency_min_rad_s), "rad/s"),
                phys(get_inj(|i| i.frequency_max_rad_s), "rad/s")
            )),
            "injection/frequency_rad_s",
        ),
        (
            "INJECTION_VOLTAGE",
            get_inj(|i| i.voltage_v),
            "V",
            "V_e ≥ I_base·ω_e·L_d·L_q/(10·|ΔL|) (spec sensorless.injection_voltage, default the minimum)",
            "thesis B (4.35)",
            inj_in(format!(
                "{motor_in}, minimum {}",
                phys(get_inj(|i| i.voltage_min_v), "V")
            )),
            "injection/voltage_v",
        ),
        (
            "INJECTION_GAIN",
            get_inj(|i| i.gain_ke_a),
            "A",
            "K_e = V_e·ΔL/(4·ω_e·L_d·L_q), ΔL = L_q − L_d signed (negative for inverse saliency; e = e_si/(2K̂_e) (4.20) either way)",
            "thesis B (4.19)",
            inj_in(motor_in.clone()),
            "injection/gain_ke_a",
        ),
        (
            "HIGHPASS",
            get_inj(|i| i.highpass_rad_s),
            "rad/s",
            "ω_hp: a few hertz (default 0.015 pu, §4.5.1; 2π·3 Hz without a per-unit base)",
            "thesis B §4.3, Table 4.1",
            inj_in("spec sensorless.highpass or the default".into()),
            "injection/highpass_rad_s",
        ),
        (
            "LOWPASS",
            get_inj(|i| i.lowpass_rad_s),
            "rad/s",
            "ω_lp, 5ρ ≤ ω_lp ≤ 10ρ (default 5ρ)",
            "thesis B Table 4.1",
            inj_in(rho_in.clone()),
            "injection/lowpass_rad_s",
        ),
        (
            "LOW_SPEED",
            get(|s| s.omega_ls_rad_s),
            "rad/s",
            "ω_ls = max(ω_min1, ω_min2), ω_min1 = 5ρ·|ΔL|·I_max/(3ψ_m), ω_min2 = |R̃·i_d/(θ̃·(ψ_m − ΔL·i_d))| at the MTPA i_d (3.10) of I_base",
            "thesis B (4.59), (4.69), Table 4.1",
            s.map_or_else(
                || off_why.to_string(),
                |s| {
                    format!(
                        "ω_min1 = {}, ω_min2 = {} (θ̃ = {:.1}°, i_d = {}), {imax_in}, I_base = {}",
                        phys(s.omega_min1_rad_s, "rad/s"),
                        phys(s.omega_min2_rad_s, "rad/s"),
                        s.angle_error_rad.to_degrees(),
                        phys(s.id_at_base_current_a, "A"),
                        phys(d.per_unit.bases.current_a.unwrap_or(0.0), "A")
                    )
                },
            ),
            "omega_ls_rad_s",
        ),
        (
            "HIGH_SPEED",
            get(|s| s.omega_hs_rad_s),
            "rad/s",
            "ω_hs = 2·ω_ls",
            "thesis B Table 4.1",
            rho_in.clone(),
            "omega_hs_rad_s",
        ),
        (
            "RESET_LOWER",
            get(|s| s.resetting_lower_rad_s),
            "rad/s",
            "Δω1 = ρ: γ0 = 0 below",
            "thesis B (4.83), §4.6",
            rho_in.clone(),
            "resetting_lower_rad_s",
        ),
        (
            "RESET_UPPER",
            get(|s| s.resetting_upper_rad_s),
            "rad/s",
            "Δω2 = 2ρ: γ0 = ρ above",
            "thesis B (4.83), §4.6",
            rho_in.clone(),
            "resetting_upper_rad_s",
        ),
        (
            "IQ_LIMIT_RESETTING_A",
            s.and_then(|s| s.iq_limit_resetting_a).unwrap_or(0.0),
            "A",
            "|i_q^ref| < ρ²·ψ_m/(γ0·ω_max·|ΔL|) with γ0 = ρ, while the resetting term acts (0: no limit needed)",
            "thesis B (4.92)",
            format!("{motor_in}, ω_max = {}", phys(m.max_electrical_speed_rad_s, "rad/s")),
            "iq_limit_resetting_a",
        ),
        (
            "IQ_LIMIT_BIFURCATION_A",
            s.and_then(|s| s.iq_limit_bifurcation_a).unwrap_or(0.0),
            "A",
            "|i_q| ≤ ψ_m/|ΔL|: no unwanted equilibria of the back-EMF estimator (0: no saliency)",
            "thesis B (4.66)",
            motor_in.clone(),
            "iq_limit_bifurcation_a",
        ),
    ];
    let mut constants: Vec<Constant> = rows
        .into_iter()
        .map(|(name, v, unit, formula, eq, inputs, field)| {
            // JSON null (sensorless off, no injection) reads as 0: point at the null.
            let path = match (s, inj) {
                (None, _) => "/sensorless".into(),
                (Some(_), None) if field.starts_with("injection/") => "/sensorless/injection".into(),
                _ => format!("/sensorless/{field}"),
            };
            c(name, f32v(v), phys(v, unit), formula, eq, inputs).at(path)
        })
        .collect();
    constants.push(
        c(
            "RS",
            f32v(m.phase_resistance_ohm),
            phys(m.phase_resistance_ohm, "Ω"),
            "R̂_s in the back-EMF error e_d (L̂_d, L̂_q, ψ̂_m: current_loop::FF_LD, FF_LQ, FF_PSI)",
            "thesis B (4.51)",
            "phase resistance (spec)".into(),
        )
        .at("/motor/phase_resistance_ohm"),
    );
    Group {
        name: "sensorless",
        title,
        constants,
    }
}
