//! The sensorless section (thesis B chapter 4) for a motor with known ψ_M: the
//! estimator design, with ρ above α_c/10 (Table 4.1) an error at the `[sensorless]` key
//! that set it, and I_base (4.24), (4.35), (4.69) required from the key that provides it.

use std::f64::consts::{PI, SQRT_2};

use super::Context;
use super::per_unit::PerUnitOut;
use crate::design::sensorless;
use crate::diagnostic::Diagnostic;
use crate::spec::{DEFAULT_RESISTANCE_ERROR, Param, angle_error_rad};

/// The estimator design (`None` without ψ_M, or without I_n when the spec has no
/// `[sensorless]` section) and its notes (warnings).
pub(in crate::design) fn sensorless(
    cx: &Context<'_>,
    per_unit: &PerUnitOut,
) -> Result<(Option<sensorless::SensorlessOut>, Vec<String>), Box<Diagnostic>> {
    let spec = cx.spec;
    let src = &cx.src;
    let speed_max = 2.0 * PI * cx.max_electrical_frequency();
    let m = &spec.motor;
    let Some(psi) = m.flux_linkage.as_ref().map(|p| p.value) else {
        return Ok((None, Vec::new()));
    };
    let s = &spec.sensorless;
    let Some(current_base) = per_unit.bases.current_a else {
        return missing_base_current(cx).map(|note| (None, vec![note]));
    };
    let i_max = SQRT_2 * m.peak_current.value;
    let value = |p: &Option<Param>| p.as_ref().map(|p| p.value);
    let inp = sensorless::Inputs {
        resistance: m.phase_resistance.value,
        ld: m.d_inductance.value,
        lq: m.q_inductance.value,
        psi,
        current_max: i_max,
        current_base,
        speed_max,
        current_bandwidth: spec.current_loop.bandwidth.value,
        switching: 2.0 * PI * spec.drive.switching_frequency.value,
        voltage_max: per_unit.bases.voltage_v,
        speed_base: per_unit.bases.angular_frequency_rad_s,
        pole_pairs: f64::from(m.pole_pairs),
        choices: sensorless::Choices {
            bandwidth: value(&s.bandwidth),
            max_acceleration: value(&s.max_acceleration),
            angle_error: angle_error_rad(s).0,
            injection_frequency: value(&s.injection_frequency),
            injection_voltage: value(&s.injection_voltage),
            highpass: value(&s.highpass),
            lowpass: value(&s.lowpass),
            resistance_error: value(&s.resistance_error).unwrap_or(DEFAULT_RESISTANCE_ERROR),
            speed_noise: value(&s.speed_noise),
        },
    };
    let (out, notes) = sensorless::design(&inp);
    if out.rho_rad_s > out.rho_max_rad_s * (1.0 + 1e-9)
        && let Some(p) = s.bandwidth.as_ref().or(s.max_acceleration.as_ref())
    {
        let accepted = if s.bandwidth.is_some() {
            format!(
                "a bandwidth up to α_c/10 = {:.1} rad/s, or a faster current loop",
                out.rho_max_rad_s
            )
        } else {
            format!(
                "a shaft acceleration up to (α_c/10)²·sin θ̃max/n_p = {:.1} rad/s² ({:.0} rpm/s), a larger sensorless.max_angle_error, or a faster current loop",
                out.rho_max_rad_s.powi(2) * out.angle_error_rad.sin() / inp.pole_pairs,
                out.rho_max_rad_s.powi(2) * out.angle_error_rad.sin() / inp.pole_pairs * 30.0 / PI
            )
        };
        return Err(Box::new(src.error(
            p.span.clone(),
            &p.key,
            format!(
                "the estimator bandwidth ρ = {:.1} rad/s{} exceeds α_c/10 = {:.1} rad/s (thesis B Table 4.1): the current loop would not follow the estimated frame",
                out.rho_rad_s,
                if s.bandwidth.is_some() { "" } else { " = √(n_p·|ω̇_m|max/sin θ̃max) (thesis B (4.74))" },
                out.rho_max_rad_s
            ),
            accepted,
        )));
    }
    if let Some(inj) = &out.injection
        && inj.voltage_v >= inp.voltage_max
        && let Some(p) = s.injection_voltage.as_ref().or(s.injection_frequency.as_ref())
    {
        return Err(Box::new(src.error(
            p.span.clone(),
            &p.key,
            format!(
                "the carrier amplitude V_e = {:.1} V (thesis B (4.35) at ω_e = {:.0} rad/s) reaches V_max = U_dc/√3 = {:.1} V: the inverter cannot produce it",
                inj.voltage_v, inj.frequency_rad_s, inp.voltage_max
            ),
            format!(
                "a carrier amplitude below V_max, e.g. at most {:.1} V (0.2·V_max, thesis B §4.3.1): a lower sensorless.injection_frequency (V_e ∝ ω_e) or injection_voltage",
                0.2 * inp.voltage_max
            ),
        )));
    }
    Ok((Some(out), notes))
}

/// What the rules (4.24), (4.35) and the ω_min2 (4.69) operating point need and the spec
/// lacks: I_base = √2·I_n (thesis B Table A.1). With a `[sensorless]` section that is an
/// error at the key that provides I_n; without one the estimator is left out, and the
/// returned warning says why. No other current stands in for I_base.
fn missing_base_current(cx: &Context<'_>) -> Result<String, Box<Diagnostic>> {
    let why = "I_base = √2·I_n (thesis B Table A.1), which sets the carrier amplitude (4.35), the filterless ρ bound (4.24) and the MTPA operating point of ω_min2 (4.69)";
    let key = "motor.datasheet.nominal_current";
    if cx.spec.sensorless.section.is_some() {
        return Err(Box::new(cx.src.error(
            cx.spec.motor.span.clone(),
            key,
            format!("the sensorless estimator ([sensorless]) needs {why}; the spec gives no rated current"),
            "nominal_current = \"<rated rms phase current>\" in [motor.datasheet], e.g. nominal_current = \"160 A\"",
        )));
    }
    Ok(format!(
        "sensorless: estimator not designed: it needs {why}; set `{key}` (the rated rms phase current)"
    ))
}
