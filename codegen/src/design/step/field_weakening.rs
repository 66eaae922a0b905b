//! The field-weakening section (thesis B §2.3, chapter 3) for a motor with known ψ_M:
//! α_fw ≪ α_c is enforced at the key that set α_fw.

use std::f64::consts::{PI, SQRT_2};

use super::Context;
use crate::design::field_weakening::{self, FieldWeakeningOut};
use crate::design::{loss_minimisation, sampling};

/// The field-weakening design, or `None` without ψ_M or with the broken rule in `cx.errors`.
pub(in crate::design) fn field_weakening(cx: &mut Context<'_>) -> Option<FieldWeakeningOut> {
    let spec = cx.spec;
    let m = &spec.motor;
    let psi = m.flux_linkage.as_ref().map(|p| p.value).filter(|p| *p > 0.0)?;
    let f = &spec.field_weakening;
    let fs = spec.drive.switching_frequency.value;
    let mech = match (&m.inertia, &m.viscous_friction) {
        (Some(j), Some(b)) => Some((b.value / j.value, j)),
        _ => None,
    };
    let inp = field_weakening::Inputs {
        model: loss_minimisation::LossModel {
            pole_pairs: m.pole_pairs,
            rs: m.phase_resistance.value,
            ld: m.d_inductance.value,
            lq: m.q_inductance.value,
            psi,
            rc: f.core_resistance.as_ref().map(|p| p.value),
            inverter: spec
                .inverter
                .as_ref()
                .filter(|_| f.include_inverter)
                .map(|i| field_weakening::inverter_loss(i, fs)),
            i_max: SQRT_2 * m.peak_current.value,
        },
        voltage_max: spec.drive.dc_link_voltage.value / 3f64.sqrt(),
        voltage_fraction: f.voltage_fraction.value,
        current_bandwidth: spec.current_loop.bandwidth.value,
        rated_speed: m.rated_frequency.as_ref().map(|f| 2.0 * PI * f.value),
        speed_loop_bandwidth: f.speed_loop_bandwidth.as_ref().map(|p| p.value),
        mechanical_bandwidth: mech.map(|(bj, _)| bj),
        max_speed: 2.0 * PI * sampling::max_electrical_frequency(m.pole_pairs, m.max_speed.value),
    };
    let (alpha_fw, rule, _) = field_weakening::bandwidth(&inp);
    let ceiling = field_weakening::MAX_BANDWIDTH_FRACTION * inp.current_bandwidth;
    if alpha_fw > ceiling {
        let (span, key, what, fix) = match (rule, &f.speed_loop_bandwidth, mech) {
            (field_weakening::BandwidthRule::SpeedLoop, Some(p), _) => (
                p.span.clone(),
                p.key.clone(),
                format!("α_fw = 10·α_s = {alpha_fw:.1} rad/s"),
                format!("a speed-loop bandwidth of at most {:.2} rad/s", ceiling / 10.0),
            ),
            (_, _, Some((bj, j))) => (
                j.span.clone(),
                j.key.clone(),
                format!("α_fw = 10·b/J = 10·{bj:.3} s⁻¹ = {alpha_fw:.1} rad/s"),
                format!(
                    "an inertia and friction with b/J ≤ {:.3} s⁻¹, or a faster current loop",
                    ceiling / 10.0
                ),
            ),
            _ => (
                spec.current_loop.bandwidth.span.clone(),
                spec.current_loop.bandwidth.key.clone(),
                format!("α_fw = {alpha_fw:.1} rad/s"),
                "a faster current loop".to_string(),
            ),
        };
        cx.errors.push(cx.src.error(
            span,
            key,
            format!(
                "{what} is not ≪ α_c = {:.1} rad/s: the field-weakening pole at −α_fw (2.61) needs α_fw ≤ α_c/5 (thesis B §2.3.3)",
                inp.current_bandwidth
            ),
            fix,
        ));
        return None;
    }
    if !within_circle_speed_limit(cx, &inp, psi) {
        return None;
    }
    let out = field_weakening::design(&inp);
    if out.is_none() {
        let p = &spec.drive.dc_link_voltage;
        cx.errors.push(cx.src.error(
            p.span.clone(),
            &p.key,
            format!(
                "R_s·I_max = {:.2} V reaches V'_max = {:.2} V: the peak current cannot be driven at any speed, so \
                 there is no corner speed for ω_base (2.60) (no motor.datasheet.rated_frequency given)",
                inp.model.rs * inp.model.i_max,
                inp.voltage_fraction * inp.voltage_max
            ),
            "a DC link with U_dc/√3·field_weakening.voltage_fraction above R_s·√2·I_peak, a lower peak_current, or the motor's rated_frequency",
        ));
    }
    out
}

/// Whether thesis B's field weakening (2.55)–(2.57), which holds the current on the circle
/// |i| = I_max, still gives the largest torque the limits allow at the top speed; if not,
/// an error at `motor.datasheet.max_speed` with the highest speed where it does
/// ([`field_weakening::circle_speed_limit`]).
fn within_circle_speed_limit(cx: &mut Context<'_>, inp: &field_weakening::Inputs, psi: f64) -> bool {
    let Some((limit, why)) = field_weakening::circle_speed_limit(inp) else {
        return true;
    };
    if inp.max_speed <= limit * (1.0 + 1e-9) {
        return true;
    }
    let m = &cx.spec.motor;
    let p = &m.max_speed;
    let rpm = 30.0 / PI / f64::from(m.pole_pairs);
    let (i_max, v) = (inp.model.i_max, inp.voltage_fraction * inp.voltage_max);
    let what = match why {
        field_weakening::CircleLimit::MaxTorquePerVolt => format!(
            "above {:.0} rpm (ω_e = {limit:.0} rad/s) the largest torque within |i| ≤ I_max = {i_max:.1} A and |v| ≤ V'_max = {v:.1} V (R_s included) lies inside the current circle (maximum torque per volt{}), which the field weakening of thesis B (2.55)–(2.57) does not reach: it holds the current on the circle, so up to the top speed {:.0} rpm it would give less torque than the drive can",
            limit * rpm,
            if psi < inp.model.ld * i_max {
                format!("; ψ_m = {psi:.4} Wb < L_d·I_max = {:.4} Wb", inp.model.ld * i_max)
            } else {
                String::new()
            },
            inp.max_speed * rpm,
        ),
        field_weakening::CircleLimit::Voltage => format!(
            "above {:.0} rpm (ω_e = {limit:.0} rad/s) no point of the current circle |i| = I_max = {i_max:.1} A meets V'_max = {v:.1} V (2.50), (2.53), R_s included: the field weakening of thesis B (2.55)–(2.57) keeps the current on that circle, so at the top speed {:.0} rpm the loop saturates",
            limit * rpm,
            inp.max_speed * rpm,
        ),
    };
    cx.errors.push(cx.src.error(
        p.span.clone(),
        &p.key,
        what,
        format!(
            "a maximum speed of at most {:.0} rpm, a higher DC link, or a lower peak current",
            (limit * rpm).floor()
        ),
    ));
    false
}
