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
    Some(field_weakening::design(&inp))
}
