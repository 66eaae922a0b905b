//! The per-unit section: thesis B App. A bases and the motor's values in pu, when the
//! rated current and frequency are known.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::design::per_unit;
use crate::spec::Spec;

/// Per-unit values of the motor (thesis B App. A).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PerUnitOut {
    /// Bases.
    pub bases: per_unit::Bases,
    /// Motor parameters in pu, by name.
    pub values: BTreeMap<&'static str, f64>,
}

/// Bases and pu values, if `nominal_current` and the rated frequency are known.
pub(in crate::design) fn per_unit(spec: &Spec) -> Option<PerUnitOut> {
    let m = &spec.motor;
    let (Some(i_n), Some(f_n)) = (&m.nominal_current, &m.rated_frequency) else {
        return None;
    };
    let b = per_unit::bases(
        spec.drive.dc_link_voltage.value,
        i_n.value,
        f_n.value,
        m.rated_power.as_ref().map(|p| p.value),
        m.nominal_torque.as_ref().map(|p| p.value),
    );
    let mut values = BTreeMap::new();
    values.insert("phase_resistance", m.phase_resistance.value / b.impedance_ohm);
    values.insert("d_inductance", m.d_inductance.value / b.inductance_h);
    values.insert("q_inductance", m.q_inductance.value / b.inductance_h);
    if let Some(p) = &m.flux_linkage {
        values.insert("flux_linkage", p.value / b.flux_wb);
    }
    for (name, h) in [
        ("d_flux_6", &m.harmonics.d_flux_6),
        ("d_flux_12", &m.harmonics.d_flux_12),
        ("q_flux_6", &m.harmonics.q_flux_6),
        ("q_flux_12", &m.harmonics.q_flux_12),
    ] {
        if let Some(h) = h {
            values.insert(name, h.value / b.flux_wb);
        }
    }
    if let Some(&(_, l_last)) = m.q_saturation.last() {
        values.insert("q_inductance_saturated", l_last / b.inductance_h);
    }
    values.insert(
        "current_loop_bandwidth",
        spec.current_loop.bandwidth.value / b.angular_frequency_rad_s,
    );
    Some(PerUnitOut { bases: b, values })
}
