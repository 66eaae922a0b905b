//! The field-weakening section (thesis B §2.3, chapter 3) for a motor with known ψ_M:
//! α_fw ≪ α_c, and α_fw fast enough to keep |v| within the voltage margin at the drive's
//! largest acceleration, are enforced at the key that set α_fw.

use std::f64::consts::{PI, SQRT_2};

use super::Context;
use super::current_loop::CurrentLoopOut;
use crate::design::field_weakening::{self, BandwidthRule, FieldWeakeningOut};
use crate::design::{loss_minimisation, sampling};

/// The field-weakening design, or `None` without ψ_M or with the broken rule in `cx.errors`;
/// `current_loop` (if designed) gives the current loop's ramp lag for the acceleration rule.
pub(in crate::design) fn field_weakening(
    cx: &mut Context<'_>,
    current_loop: Option<&CurrentLoopOut>,
) -> Option<FieldWeakeningOut> {
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
        voltage_max: cx.usable_voltage_v(),
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
            (BandwidthRule::SpeedLoop, Some(p), _) => (
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
    let Some(mut out) = field_weakening::design(&inp) else {
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
        return None;
    };
    if !within_torque_speed_limit(cx, &inp, &out) {
        return None;
    }
    // |v| must stay within half the margin V_max − V'_max while the shaft accelerates at the
    // drive's largest rate (`motorgen verify` holds the field-weakening run to it).
    let lag = current_loop?.ramp_lag_s;
    let (acc, acc_rule) = cx.max_acceleration();
    let acc_e = f64::from(m.pole_pairs) * acc;
    let allowed = 0.5 * (inp.voltage_max - out.voltage_limit_v);
    let onset = field_weakening::onset_speed(&inp.model, out.voltage_limit_v);
    let op = field_weakening::OperatingPoint {
        voltage_limit_v: out.voltage_limit_v,
        onset_speed_rad_s: onset,
        base_speed_rad_s: out.base_speed_rad_s,
        acceleration_rad_s2: acc_e,
        current_lag_s: lag,
    };
    let delta = field_weakening::voltage_overshoot(&inp.model, &op, alpha_fw);
    out.voltage_overshoot_at_max_acceleration_v = Some(delta);
    if delta > allowed {
        let need = field_weakening::min_bandwidth_for_overshoot(&inp.model, &op, allowed);
        let a_max = acc * allowed / delta;
        let (span, key, how) = match (rule, &f.speed_loop_bandwidth, mech) {
            (BandwidthRule::SpeedLoop, Some(p), _) => (
                p.span.clone(),
                p.key.clone(),
                "a speed-loop bandwidth α_s = α_fw/10 of at least",
            ),
            (_, _, Some((_, j))) => (j.span.clone(), j.key.clone(), "b/J = α_fw/10 of at least"),
            _ => (
                spec.current_loop.bandwidth.span.clone(),
                spec.current_loop.bandwidth.key.clone(),
                "a current-loop bandwidth α_c = 10·α_fw (default α_fw = α_c/10, Fig. 2.15) of at least",
            ),
        };
        let fix = match need {
            Some(n) if n <= ceiling => format!(
                "{how} {:.1} (α_fw ≥ {n:.0} rad/s), a smaller field_weakening.voltage_fraction (more margin), or a drive.max_acceleration of at most {:.0} rpm/s (drive.application sets the default)",
                if rule == BandwidthRule::DefaultSpeedLoop {
                    10.0 * n
                } else {
                    n / 10.0
                },
                a_max * 30.0 / PI
            ),
            _ => format!(
                "a smaller field_weakening.voltage_fraction (more margin), a faster current loop, or a drive.max_acceleration of at most {:.0} rpm/s (drive.application sets the default)",
                a_max * 30.0 / PI
            ),
        };
        cx.errors.push(cx.src.error(
            span,
            key,
            format!(
                "at the drive's largest acceleration {acc:.1} rad/s² ({:.0} rpm/s; {}) the field-weakening loop (α_fw = {alpha_fw:.1} rad/s, current-loop ramp lag {:.3} ms) lets |v| rise {delta:.1} V above V'_max = {:.1} V, more than half the margin to V_max = {:.1} V ({allowed:.1} V): δ = (V'_max/ω_on)·n_p·ω̇_m·(1/α + τ_v) at the onset ω_on = {onset:.0} rad/s, α = α_fw·(∂|v|/∂i_d)/(ω_fw·L_d): (2.55), (2.60) linearised",
                acc * 30.0 / PI,
                acc_rule.describe(),
                lag * 1e3,
                out.voltage_limit_v,
                inp.voltage_max
            ),
            fix,
        ));
        return None;
    }
    Some(out)
}

/// Whether any current within |i| ≤ I_max still produces torque at the top speed: without
/// maximum torque per volt (ψ_M ≥ L_d·I_max) the field weakening (2.55)–(2.57) walks the
/// circle down to i_d = −I_max, and above the largest corner speed on that path
/// ([`field_weakening::top_speed_on_circle`]) no current meets V'_max with any torque —
/// an error at `motor.datasheet.max_speed` naming that speed. With the MTPV line inside
/// the circle (ψ_M < L_d·I_max) the line reaches zero stator flux at i_d = −ψ_M/L_d, so
/// some torque is possible at every speed: no limit.
fn within_torque_speed_limit(cx: &mut Context<'_>, inp: &field_weakening::Inputs, out: &FieldWeakeningOut) -> bool {
    let Some(limit) = out.torque_speed_limit_rad_s else {
        return true;
    };
    if inp.max_speed <= limit * (1.0 + 1e-9) {
        return true;
    }
    let m = &cx.spec.motor;
    let p = &m.max_speed;
    let rpm = 30.0 / PI / f64::from(m.pole_pairs);
    let (i_max, v) = (inp.model.i_max, inp.voltage_fraction * inp.voltage_max);
    cx.errors.push(cx.src.error(
        p.span.clone(),
        &p.key,
        format!(
            "above {:.0} rpm (ω_e = {limit:.0} rad/s) no current within |i| ≤ I_max = {i_max:.1} A meets V'_max = {v:.1} V with any torque (2.50), (2.53), R_s included: ψ_m = {:.4} Wb ≥ L_d·I_max = {:.4} Wb, so even i_d = −I_max leaves flux, and at the top speed {:.0} rpm the drive could give no torque",
            limit * rpm,
            inp.model.psi,
            inp.model.ld * i_max,
            inp.max_speed * rpm,
        ),
        format!(
            "a maximum speed of at most {:.0} rpm, a higher DC link, or a higher peak current (more negative i_d)",
            (limit * rpm).floor()
        ),
    ));
    false
}
