//! The sensorless section (thesis B chapter 4) for a spec with a `[sensorless]` section
//! and a motor with known ψ_M: the estimator design, with ρ above α_c/10 (Table 4.1) an
//! error at the `[sensorless]` key that set it, and I_base (4.24), (4.35), (4.69)
//! required from the key that provides it.

use std::f64::consts::{PI, SQRT_2};

use super::Context;
use super::per_unit::PerUnitOut;
use crate::design::sensorless;
use crate::diagnostic::Diagnostic;
use crate::spec::{DEFAULT_RESISTANCE_ERROR, Param, angle_error_rad};

/// The estimator design and its notes (warnings, each located at its key: the spec's
/// value where it gives one, else the `[sensorless]` header); `None` without a
/// `[sensorless]` section. Without ψ_M or I_n the section is an error (the rules need both).
pub(in crate::design) fn sensorless(
    cx: &Context<'_>,
    per_unit: &PerUnitOut,
) -> Result<(Option<sensorless::SensorlessOut>, Vec<String>), Box<Diagnostic>> {
    let spec = cx.spec;
    let src = &cx.src;
    let speed_max = 2.0 * PI * cx.max_electrical_frequency();
    let m = &spec.motor;
    let Some(s) = spec.sensorless.as_ref() else {
        return Ok((None, Vec::new()));
    };
    let Some(psi) = m.flux_linkage.as_ref().map(|p| p.value) else {
        return Err(Box::new(src.error(
            s.span.clone(),
            "sensorless",
            "the sensorless estimator (thesis B chapter 4) needs the flux linkage ψ_M (back-EMF estimation (4.51), (4.59))",
            "motor.datasheet.flux_linkage (or torque_constant / back_emf_constant), or remove [sensorless]",
        )));
    };
    let Some(current_base) = per_unit.bases.current_a else {
        return Err(missing_base_current(cx));
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
    let notes: Vec<String> = notes
        .into_iter()
        .map(|(key, text)| {
            let given = match key {
                "sensorless.injection_frequency" => s.injection_frequency.as_ref(),
                "sensorless.injection_voltage" => s.injection_voltage.as_ref(),
                "sensorless.lowpass" => s.lowpass.as_ref(),
                "motor.peak_current" => Some(&m.peak_current),
                _ => None,
            };
            match given {
                Some(p) => src.warning(p.span.clone(), &p.key, text),
                None => src.warning(s.span.clone(), key, text),
            }
        })
        .collect();
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
    // The estimator must follow the drive's largest acceleration within θ̃max (4.74).
    let (acc, rule) = cx.max_acceleration();
    let rho_needed = sensorless::rho_from_acceleration(inp.pole_pairs * acc, out.angle_error_rad);
    if out.rho_rad_s < rho_needed * (1.0 - 1e-9) {
        let tracked = out.rho_rad_s.powi(2) * out.angle_error_rad.sin() / inp.pole_pairs;
        let what = format!(
            "the estimator bandwidth ρ = {:.1} rad/s follows a shaft acceleration of at most ρ²·sin θ̃max/n_p = {tracked:.1} rad/s² ({:.0} rpm/s) within θ̃max = {:.1}° (thesis B (4.74)), but the drive accelerates at {acc:.1} rad/s² ({:.0} rpm/s; {}): that needs ρ ≥ {rho_needed:.1} rad/s",
            out.rho_rad_s,
            tracked * 30.0 / PI,
            out.angle_error_rad.to_degrees(),
            acc * 30.0 / PI,
            rule.describe(),
        );
        let (span, key, accepted) = match (&s.bandwidth, &s.max_acceleration) {
            (Some(p), _) => (
                p.span.clone(),
                p.key.clone(),
                format!(
                    "a bandwidth of at least {rho_needed:.1} rad/s (and at most α_c/10 = {:.1} rad/s)",
                    out.rho_max_rad_s
                ),
            ),
            (None, Some(p)) => (
                p.span.clone(),
                p.key.clone(),
                format!("at least the drive's acceleration, {:.0} rpm/s", acc * 30.0 / PI),
            ),
            (None, None) => {
                let b = &spec.current_loop.bandwidth;
                (
                    b.span.clone(),
                    b.key.clone(),
                    format!(
                        "a current-loop bandwidth of at least 10·ρ = {:.0} rad/s (the default ρ = α_c/10, Table 4.1), a larger sensorless.max_angle_error, or a smaller drive.max_acceleration",
                        10.0 * rho_needed
                    ),
                )
            }
        };
        return Err(Box::new(src.error(span, key, what, accepted)));
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
/// lacks: I_base = √2·I_n (thesis B Table A.1), an error at the key that provides I_n.
/// No other current stands in for I_base.
fn missing_base_current(cx: &Context<'_>) -> Box<Diagnostic> {
    let why = "I_base = √2·I_n (thesis B Table A.1), which sets the carrier amplitude (4.35), the filterless ρ bound (4.24) and the MTPA operating point of ω_min2 (4.69)";
    Box::new(cx.src.error(
        cx.spec.motor.span.clone(),
        "motor.datasheet.nominal_current",
        format!("the sensorless estimator ([sensorless]) needs {why}; the spec gives no rated current"),
        "nominal_current = \"<rated rms phase current>\" in [motor.datasheet], e.g. nominal_current = \"160 A\"",
    ))
}
