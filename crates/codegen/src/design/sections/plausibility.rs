//! Physical plausibility, before any design: the motor values checked against each other
//! and against the drive, so that a value off by a unit prefix (Ω for mΩ, H for mH, Wb
//! for mWb) is refused at the key most likely wrong instead of surfacing as a confusing
//! design error further on (or as a simulation that diverges).
//!
//! With V_max = U_dc/√3 (thesis B (2.50)–(2.53)), Î = √2·I_peak (2.51), ω_e,max = n_p·ω_max
//! (2.19), T_s = 1/f_s:
//!
//! | rule | refused when | key |
//! |---|---|---|
//! | voltage at standstill | R·Î > V_max: the peak current cannot be driven at all | `phase_resistance` |
//! | electrical time constant | L/R < T_s: the current settles within one PWM period; the sampled current is not the period's average and the PI (4.17) acts on what already happened | the inductance, or `phase_resistance` when R·Î fails too |
//! | armature reaction | L_q·Î > 10·ψ_M: the winding's own flux at the peak current ten times the magnet's (a PMSM's ratio is around 0.1 … 3) | the inductance when ω_e,max·L_q·Î > 3·V_max too, else ψ_M's key |
//! | back EMF at top speed | ω_e,max·(ψ_M − L_d·Î) > 10·V_max: ten times more voltage than the drive has, even with the whole peak current weakening the field (2.55)–(2.57) | ψ_M's key |
//! | back EMF at rated speed | ω_e,n·ψ_M > V_max: the rated point needs field weakening (a rated point lies at or below base speed) | ψ_M's key |
//! | without ψ_M: q-axis voltage | ω_e,max·L_q·Î > 10·V_max | the inductance |
//! | ψ_M given twice | two forms more than a factor 2 apart (the 5 % tolerance of the cross-checks is a warning; a factor 2 is a wrong unit or convention) | the form farthest from the others, or from the voltage budget when there are two |
//!
//! The factors 10 leave every real machine inside (the seed motors are at most 1.7 on the
//! armature reaction, 0.64 on the back EMF, 0.31 on the standstill voltage): they refuse
//! the prefix errors, not designs. Each message shows the numbers, and every error of a
//! design that fails carries the spec's cross-checks that disagree as notes.

use std::f64::consts::SQRT_2;
use std::ops::Range;

use super::Context;
use crate::spec::Param;

/// Largest L_q·Î/ψ_M accepted.
pub const MAX_ARMATURE_REACTION: f64 = 10.0;
/// Largest multiple of V_max a voltage demand may reach before it is refused.
pub const MAX_VOLTAGE_MULTIPLE: f64 = 10.0;
/// ω_e,max·L_q·Î above this multiple of V_max makes the inductance the suspect of an
/// armature-reaction breach (else ψ_M).
pub const INDUCTANCE_SUSPECT_MULTIPLE: f64 = 3.0;
/// Two forms of ψ_M further apart than this factor are refused.
pub const MAX_FLUX_FACTOR: f64 = 2.0;

/// Checks the motor values against each other and the drive; errors go to `cx.errors`.
pub(in crate::design) fn plausibility(cx: &mut Context<'_>) {
    let spec = cx.spec;
    let m = &spec.motor;
    let r = m.phase_resistance.value;
    let (ld, lq) = (m.d_inductance.value, m.q_inductance.value);
    let i_hat = SQRT_2 * m.peak_current.value;
    let udc = spec.drive.dc_link_voltage.value;
    let v_max = udc / 3f64.sqrt();
    let ts = 1.0 / cx.switching_frequency();
    let we_max = 2.0 * std::f64::consts::PI * cx.max_electrical_frequency();
    let budget = format!(
        "V_max = U_dc/√3 = {v_max:.2} V (drive.dc_link_voltage = {udc} V), Î = √2·{} A = {i_hat:.2} A",
        m.peak_current.value
    );

    // Standstill: R·Î against V_max.
    let standstill = r * i_hat;
    let r_fails = standstill > v_max;
    // Time constants against T_s.
    let tau = [("d", ld, &m.d_inductance), ("q", lq, &m.q_inductance)];
    let (axis, l_short, p_short) = tau
        .iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(a, l, p)| (*a, *l, *p))
        .unwrap_or(("d", ld, &m.d_inductance));
    let tau_min = l_short / r;
    let tau_fails = tau_min < ts;
    if r_fails {
        let mut problem = format!(
            "R·Î = {r} Ω·{i_hat:.2} A = {standstill:.1} V exceeds {budget}: the drive cannot push the peak current through the winding even at standstill"
        );
        if tau_fails {
            problem.push_str(&format!(
                "; with L_{axis} = {l_short:e} H the electrical time constant L/R = {:.3} µs is shorter than T_s = {:.1} µs too: both point at R (a resistance in Ω where the datasheet gives mΩ?)",
                tau_min * 1e6,
                ts * 1e6
            ));
        }
        let p = &m.phase_resistance;
        cx.errors.push(cx.src.error(
            p.span.clone(),
            &p.key,
            problem,
            format!(
                "R ≤ V_max/Î = {:.4} Ω (phase, star-equivalent), or a lower peak_current (≤ {:.2} A rms), or a higher DC link",
                v_max / i_hat,
                v_max / r / SQRT_2
            ),
        ));
    } else if tau_fails {
        cx.errors.push(cx.src.error(
            p_short.span.clone(),
            &p_short.key,
            format!(
                "L_{axis}/R = {l_short:e} H/{r} Ω = {:.3} µs is shorter than the control period T_s = {:.1} µs (f_s = {} Hz): the current settles within one PWM period, so the sample is not the period's average and the current loop acts on what already happened",
                tau_min * 1e6,
                ts * 1e6,
                cx.switching_frequency()
            ),
            format!(
                "L_{axis} ≥ R·T_s = {:.3e} H (an inductance in H where the datasheet gives mH or µH?), or f_s ≥ R/L_{axis} = {:.0} Hz",
                r * ts,
                r / l_short
            ),
        ));
    }

    // ψ_M given twice, grossly apart.
    let sources = &m.flux_sources;
    let mut psi_suspect: Option<(String, Range<usize>, String)> = None;
    if sources.len() >= 2 {
        let fluxes: Vec<f64> = sources.iter().map(|s| s.flux_wb).collect();
        let (lo, hi) = fluxes
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        if hi > MAX_FLUX_FACTOR * lo {
            // The odd one out: farthest (in log) from the median of three or more, or with
            // two, farthest from a back EMF of V_max at top speed.
            let mut sorted = fluxes.clone();
            sorted.sort_by(f64::total_cmp);
            let reference = if sources.len() >= 3 {
                sorted[sorted.len() / 2]
            } else {
                v_max / we_max
            };
            let odd = sources
                .iter()
                .max_by(|a, b| {
                    (a.flux_wb / reference)
                        .ln()
                        .abs()
                        .total_cmp(&(b.flux_wb / reference).ln().abs())
                })
                .unwrap_or(&sources[0]);
            let all: Vec<String> = sources
                .iter()
                .map(|s| format!("{:.6} Wb from {} ({})", s.flux_wb, s.key, s.written))
                .collect();
            let others: Vec<_> = sources.iter().filter(|s| s.key != odd.key).collect();
            cx.errors.push(cx.src.error(
                odd.span.clone(),
                &odd.key,
                format!(
                    "the spec gives ψ_M {} ways, up to {:.1}× apart: {}; {} disagrees with the rest{} (a unit, rms/peak, line/phase or mechanical/electrical convention?)",
                    sources.len(),
                    hi / lo,
                    all.join(", "),
                    odd.key,
                    if sources.len() >= 3 {
                        String::new()
                    } else {
                        format!(
                            " and with the voltage budget (a back EMF of V_max at top speed is ψ_M = {:.6} Wb)",
                            v_max / we_max
                        )
                    }
                ),
                format!(
                    "a value within a factor {MAX_FLUX_FACTOR} of {} (the cross-checks warn beyond 5 %)",
                    others
                        .iter()
                        .map(|s| format!("{:.6} Wb ({})", s.flux_wb, s.key))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
            psi_suspect = Some((odd.key.clone(), odd.span.clone(), String::new()));
        }
    }

    // L_q's key (`inductance` when the spec gives one value for both axes).
    let inductance: &Param = &m.q_inductance;
    match m.flux_linkage.as_ref().map(|p| p.value) {
        Some(psi) if psi_suspect.is_none() => {
            let source = sources.first();
            let (psi_key, psi_span) = source.map_or_else(
                || {
                    let p = m.flux_linkage.as_ref();
                    (
                        p.map_or("motor.datasheet.flux_linkage".to_string(), |p| p.key.clone()),
                        p.map_or(0..0, |p| p.span.clone()),
                    )
                },
                |s| (s.key.clone(), s.span.clone()),
            );
            let reaction = lq * i_hat / psi;
            let q_voltage = we_max * lq * i_hat;
            let weakened = we_max * (psi - ld * i_hat);
            let rated = m
                .nominal_speed
                .as_ref()
                .map(|n| (n.value * f64::from(m.pole_pairs), n.key.clone()))
                .or_else(|| {
                    m.rated_frequency
                        .as_ref()
                        .map(|f| (2.0 * std::f64::consts::PI * f.value, f.key.clone()))
                });
            if reaction > MAX_ARMATURE_REACTION {
                let l_suspect = q_voltage > INDUCTANCE_SUSPECT_MULTIPLE * v_max;
                let figures = format!(
                    "L_q·Î = {lq:e} H·{i_hat:.2} A = {:.4} Wb is {reaction:.0}× ψ_M = {psi:.6} Wb (a PMSM's winding flux at peak current is 0.1 … 3 times its magnet's; accepted up to {MAX_ARMATURE_REACTION}×)",
                    lq * i_hat
                );
                if l_suspect {
                    let p = inductance;
                    cx.errors.push(cx.src.error(
                        p.span.clone(),
                        &p.key,
                        format!(
                            "{figures}; and at top speed ω_e,max·L_q·Î = {q_voltage:.1} V is {:.0}× {budget}: the inductance is the suspect (H where the datasheet gives mH or µH?)",
                            q_voltage / v_max
                        ),
                        format!(
                            "L_q ≤ {MAX_ARMATURE_REACTION}·ψ_M/Î = {:.4e} H",
                            MAX_ARMATURE_REACTION * psi / i_hat
                        ),
                    ));
                } else {
                    cx.errors.push(cx.src.error(
                        psi_span.clone(),
                        &psi_key,
                        format!(
                            "{figures}; the inductance fits the drive (ω_e,max·L_q·Î = {q_voltage:.1} V against V_max = {v_max:.2} V), so ψ_M is the suspect: its back EMF at top speed would be only {:.3} V",
                            we_max * psi
                        ),
                        format!(
                            "ψ_M ≥ L_q·Î/{MAX_ARMATURE_REACTION} = {:.6} Wb (Wb where the datasheet gives mWb? rms/peak, line/phase, mechanical/electrical?)",
                            lq * i_hat / MAX_ARMATURE_REACTION
                        ),
                    ));
                }
            } else if weakened > MAX_VOLTAGE_MULTIPLE * v_max {
                cx.errors.push(cx.src.error(
                    psi_span.clone(),
                    &psi_key,
                    format!(
                        "at the top speed ({:.0} rpm, ω_e,max = {we_max:.1} rad/s) the back EMF ω_e,max·ψ_M = {:.1} V, and still {weakened:.1} V with the whole peak current weakening the field (ω_e,max·(ψ_M − L_d·Î), thesis B (2.55)–(2.57)): {:.0}× {budget}",
                        m.max_speed.value * 30.0 / std::f64::consts::PI,
                        we_max * psi,
                        weakened / v_max
                    ),
                    format!(
                        "ψ_M ≤ {:.6} Wb for this top speed (Wb where the datasheet gives mWb? rms/peak, line/phase, mechanical/electrical?), or a lower motor.max_speed",
                        MAX_VOLTAGE_MULTIPLE * v_max / we_max + ld * i_hat
                    ),
                ));
            } else if let Some((wn, key)) = rated
                && wn * psi > v_max
            {
                cx.errors.push(cx.src.error(
                    psi_span.clone(),
                    &psi_key,
                    format!(
                        "at the rated speed ({key}: ω_e,n = {wn:.1} rad/s) the back EMF ω_e,n·ψ_M = {:.1} V exceeds {budget}: the rated point would need field weakening (a rated point lies at or below base speed)",
                        wn * psi
                    ),
                    format!(
                        "ψ_M ≤ V_max/ω_e,n = {:.6} Wb, or a higher DC link, or the rated speed as the datasheet gives it",
                        v_max / wn
                    ),
                ));
            }
        }
        None => {
            let q_voltage = we_max * lq * i_hat;
            if q_voltage > MAX_VOLTAGE_MULTIPLE * v_max {
                let p = inductance;
                cx.errors.push(cx.src.error(
                    p.span.clone(),
                    &p.key,
                    format!(
                        "at top speed ω_e,max·L_q·Î = {we_max:.1} rad/s·{lq:e} H·{i_hat:.2} A = {q_voltage:.1} V is {:.0}× {budget} (H where the datasheet gives mH or µH?)",
                        q_voltage / v_max
                    ),
                    format!(
                        "L_q ≤ {MAX_VOLTAGE_MULTIPLE}·V_max/(ω_e,max·Î) = {:.4e} H, or a lower max_speed",
                        MAX_VOLTAGE_MULTIPLE * v_max / (we_max * i_hat)
                    ),
                ));
            }
        }
        Some(_) => {}
    }
}

/// The spec's cross-checks that disagree beyond the 5 % tolerance, as notes for the errors
/// of a design that fails (they are warnings of a design that succeeds).
pub(in crate::design) fn cross_check_notes(cx: &Context<'_>) -> Vec<String> {
    super::motor::cross_checks(&cx.spec.motor)
        .into_iter()
        .filter(|(c, _, _)| c.fails())
        .map(|(c, key, span)| {
            let at = cx.src.warning(span, &key, "");
            format!("cross-check ({}): {c}", at.trim_end().trim_end_matches(':'))
        })
        .collect()
}
