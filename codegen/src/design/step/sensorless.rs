//! The sensorless section (thesis B chapter 4) for a motor with known ψ_M: the
//! estimator design, with ρ above α_c/10 (Table 4.1) an error at the `[sensorless]` key
//! that set it.

use std::f64::consts::{PI, SQRT_2};

use super::Context;
use super::per_unit::PerUnitOut;
use crate::design::sensorless;
use crate::diagnostic::Diagnostic;
use crate::spec::{DEFAULT_RESISTANCE_ERROR, Param, angle_error_rad};

/// The estimator design and its notes (warnings), `None` without ψ_M.
pub(in crate::design) fn sensorless(
    cx: &Context<'_>,
    per_unit: Option<&PerUnitOut>,
) -> Result<Option<(sensorless::SensorlessOut, Vec<String>)>, Box<Diagnostic>> {
    let spec = cx.spec;
    let src = &cx.src;
    let speed_max = 2.0 * PI * cx.max_electrical_frequency();
    let m = &spec.motor;
    let Some(psi) = m.flux_linkage.as_ref().map(|p| p.value) else {
        return Ok(None);
    };
    let s = &spec.sensorless;
    let i_max = SQRT_2 * m.peak_current.value;
    let value = |p: &Option<Param>| p.as_ref().map(|p| p.value);
    let inp = sensorless::Inputs {
        resistance: m.phase_resistance.value,
        ld: m.d_inductance.value,
        lq: m.q_inductance.value,
        psi,
        current_max: i_max,
        current_base: per_unit.map_or(i_max, |p| p.bases.current_a),
        speed_max,
        current_bandwidth: spec.current_loop.bandwidth.value,
        switching: 2.0 * PI * spec.drive.switching_frequency.value,
        voltage_max: spec.drive.dc_link_voltage.value / 3f64.sqrt(),
        speed_base: per_unit.map(|p| p.bases.angular_frequency_rad_s),
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
    Ok(Some((out, notes)))
}
