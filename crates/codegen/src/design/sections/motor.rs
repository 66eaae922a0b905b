//! The motor section: the values the design used, their provenance, the cross-checks of
//! every redundant pair the spec gives ([`cross_check`]) and the warnings about them.

use std::collections::BTreeMap;
use std::f64::consts::{PI, SQRT_2};
use std::ops::Range;

use serde::Serialize;

use super::Context;
use crate::design::cross_check::{self, CrossCheck};
use crate::spec::{Motor, Param, Provenance};

/// A value with where it came from, for the JSON provenance table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Origin {
    /// datasheet / identified / derived / default.
    pub source: Provenance,
    /// The key it was read from.
    pub key: String,
    /// Formula and inputs, for derived values.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl From<&Param> for Origin {
    fn from(p: &Param) -> Self {
        Origin {
            source: p.source,
            key: p.key.clone(),
            note: p.note.clone(),
        }
    }
}

/// Motor values the design used (SI).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MotorOut {
    /// n_p.
    pub pole_pairs: u32,
    /// R_s \[Ω\].
    pub phase_resistance_ohm: f64,
    /// R_s at the maximum winding temperature \[Ω\] (thesis B 2.24), if `[thermal]` is given.
    pub phase_resistance_hot_ohm: Option<f64>,
    /// L_d \[H\].
    pub d_inductance_h: f64,
    /// L_q \[H\].
    pub q_inductance_h: f64,
    /// ψ_M \[Wb\], null if unknown.
    pub flux_linkage_wb: Option<f64>,
    /// Every redundant pair the spec gives, compared (tolerance 5 %).
    pub cross_checks: Vec<CrossCheck>,
    /// τ_d = L_d/R \[s\].
    pub d_time_constant_s: f64,
    /// τ_q = L_q/R \[s\].
    pub q_time_constant_s: f64,
    /// Peak phase current, rms \[A\].
    pub peak_current_a_rms: f64,
    /// Nominal phase current, rms \[A\].
    pub nominal_current_a_rms: Option<f64>,
    /// Maximum shaft speed [rad/s].
    pub max_speed_rad_s: f64,
    /// Maximum shaft speed \[rpm\].
    pub max_speed_rpm: f64,
    /// f_e,max = n_p·n_max/60 \[Hz\] (Table 1.2).
    pub max_electrical_frequency_hz: f64,
    /// ω_e,max = 2π·f_e,max [rad/s] (2.19).
    pub max_electrical_speed_rad_s: f64,
    /// Peak phase-current amplitude √2·I_peak,rms \[A\] (current-circle radius, thesis B 2.51).
    pub peak_current_a: f64,
    /// Where each value came from.
    pub provenance: BTreeMap<&'static str, Origin>,
}

/// The motor section; `hot_resistance` is R_s at the maximum winding temperature, when
/// the current loop designed for it.
pub(in crate::design) fn motor(cx: &mut Context<'_>, hot_resistance: Option<f64>) -> MotorOut {
    let spec = cx.spec;
    let m = &spec.motor;
    let located = cross_checks(m);
    for (c, key, span) in located.iter().filter(|(c, _, _)| c.fails()) {
        cx.warn(span.clone(), key, format!("cross-check: {c}"));
    }
    let checks = located.into_iter().map(|(c, _, _)| c).collect();
    if m.flux_linkage.is_none() {
        let span = cx.src.table_span("motor.datasheet");
        cx.warn(
            span,
            "motor.datasheet.flux_linkage",
            "ψ_M is unknown: the back-EMF feed-forward term and torque → i_q conversion are omitted",
        );
    }
    let fe_max = cx.max_electrical_frequency();
    let r = m.phase_resistance.value;
    MotorOut {
        pole_pairs: m.pole_pairs,
        phase_resistance_ohm: r,
        phase_resistance_hot_ohm: hot_resistance,
        d_inductance_h: m.d_inductance.value,
        q_inductance_h: m.q_inductance.value,
        flux_linkage_wb: m.flux_linkage.as_ref().map(|p| p.value),
        cross_checks: checks,
        d_time_constant_s: m.d_inductance.value / r,
        q_time_constant_s: m.q_inductance.value / r,
        peak_current_a_rms: m.peak_current.value,
        nominal_current_a_rms: m.nominal_current.as_ref().map(|p| p.value),
        max_speed_rad_s: m.max_speed.value,
        max_speed_rpm: m.max_speed.value * 30.0 / PI,
        max_electrical_frequency_hz: fe_max,
        max_electrical_speed_rad_s: 2.0 * PI * fe_max,
        peak_current_a: SQRT_2 * m.peak_current.value,
        provenance: provenance(cx),
    }
}

/// Where the design's main motor values came from; identified values carry the
/// identification's date and source.
fn provenance(cx: &Context<'_>) -> BTreeMap<&'static str, Origin> {
    let m = &cx.spec.motor;
    let mut provenance = BTreeMap::new();
    provenance.insert("phase_resistance", Origin::from(&m.phase_resistance));
    provenance.insert("d_inductance", Origin::from(&m.d_inductance));
    provenance.insert("q_inductance", Origin::from(&m.q_inductance));
    provenance.insert("peak_current", Origin::from(&m.peak_current));
    provenance.insert("max_speed", Origin::from(&m.max_speed));
    if let Some(p) = &m.flux_linkage {
        provenance.insert("flux_linkage", Origin::from(p));
    }
    if let Some(p) = &cx.spec.resolver.offset {
        provenance.insert("resolver_offset", Origin::from(p));
    }
    for (name, p) in [
        ("nominal_current", &m.nominal_current),
        ("nominal_torque", &m.nominal_torque),
        ("peak_torque", &m.peak_torque),
        ("rated_frequency", &m.rated_frequency),
        ("nominal_speed", &m.nominal_speed),
        ("rated_power", &m.rated_power),
        ("inertia", &m.inertia),
        ("viscous_friction", &m.viscous_friction),
    ] {
        if let Some(p) = p {
            provenance.insert(name, Origin::from(p));
        }
    }
    if let Some(note) = &m.identification {
        for o in provenance.values_mut().filter(|o| o.source == Provenance::Identified) {
            o.note = Some(note.clone());
        }
    }
    provenance
}

/// The redundant pairs of `m`: every two forms of ψ_M; with ψ_M, the peak and rated torques
/// against the MTPA torque (3.7), (3.10) at the peak and rated currents; the rated power
/// against T_n·ω_m,n; a given rated frequency against the nominal speed (2.19). Each with
/// the key and span its warning is located at (the pair's second value, the one checked).
pub(in crate::design) fn cross_checks(m: &Motor) -> Vec<(CrossCheck, String, Range<usize>)> {
    let mut out = Vec::new();
    let from = |p: &Param| p.key.clone();
    for (i, a) in m.flux_sources.iter().enumerate() {
        for b in &m.flux_sources[i + 1..] {
            out.push((
                CrossCheck::new(
                    "ψ_M [Wb]",
                    (a.flux_wb, format!("{} ({})", a.key, a.written)),
                    (b.flux_wb, format!("{} ({})", b.key, b.written)),
                ),
                b.key.clone(),
                b.span.clone(),
            ));
        }
    }
    if let Some(psi) = &m.flux_linkage {
        let torque = |i_rms: f64| {
            cross_check::mtpa_torque(
                m.pole_pairs,
                psi.value,
                m.d_inductance.value,
                m.q_inductance.value,
                SQRT_2 * i_rms,
            )
        };
        for (t, i, what) in [
            (&m.peak_torque, Some(&m.peak_current), "peak"),
            (&m.nominal_torque, m.nominal_current.as_ref(), "rated"),
        ] {
            if let (Some(t), Some(i)) = (t, i) {
                let at = (t.key.clone(), t.span.clone());
                out.push((
                    CrossCheck::new(
                        &format!("{what} torque [N·m]"),
                        (t.value, from(t)),
                        (
                            torque(i.value),
                            format!(
                                "(3.7) at the MTPA point (3.10) of {} = {:.4} A rms with ψ_M = {:.6} Wb",
                                i.key, i.value, psi.value
                            ),
                        ),
                    ),
                    at.0,
                    at.1,
                ));
            }
        }
    }
    let speed = m.nominal_speed.as_ref().map(|n| (n.value, n.key.clone())).or_else(|| {
        m.rated_frequency
            .as_ref()
            .map(|f| (2.0 * PI * f.value / f64::from(m.pole_pairs), format!("{} / n_p", f.key)))
    });
    if let (Some(p), Some(t), Some((w, w_from))) = (&m.rated_power, &m.nominal_torque, speed) {
        out.push((
            CrossCheck::new(
                "rated power [W]",
                (p.value, from(p)),
                (t.value * w, format!("T_n·ω_m,n from {} and {w_from}", t.key)),
            ),
            p.key.clone(),
            p.span.clone(),
        ));
    }
    if let (Some(f), Some(n)) = (&m.rated_frequency, &m.nominal_speed)
        && f.source != Provenance::Derived
    {
        out.push((
            CrossCheck::new(
                "rated frequency [Hz]",
                (f.value, from(f)),
                (
                    n.value * f64::from(m.pole_pairs) / (2.0 * PI),
                    format!("n_p·ω_m,n/(2π) (2.19) from {}", n.key),
                ),
            ),
            f.key.clone(),
            f.span.clone(),
        ));
    }
    out
}
