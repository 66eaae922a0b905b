//! The per-unit section: thesis B App. A bases and the motor's values in pu, each from the
//! quantities its base needs (see [`per_unit`]).

use std::collections::BTreeMap;

use serde::Serialize;

use crate::design::per_unit;
use crate::spec::Spec;

/// Per-unit values of the motor (thesis B App. A).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PerUnitOut {
    /// Bases (`null` where the spec lacks a quantity the definition needs).
    pub bases: per_unit::Bases,
    /// Motor parameters in pu, by name, for every value whose base is known.
    pub values: BTreeMap<&'static str, f64>,
    /// The bases the spec does not determine and the key that would provide each.
    pub missing: Vec<String>,
}

/// Bases and pu values. V_base always exists (the DC link is required); the others
/// follow from `nominal_current`, the rated frequency, `rated_power` and `nominal_torque`.
pub(in crate::design) fn per_unit(spec: &Spec) -> PerUnitOut {
    let m = &spec.motor;
    let value = |p: &Option<crate::spec::Param>| p.as_ref().map(|p| p.value);
    let b = per_unit::bases(
        spec.drive.dc_link_voltage.value,
        value(&m.nominal_current),
        value(&m.rated_frequency),
        value(&m.rated_power),
        value(&m.nominal_torque),
    );
    let mut values = BTreeMap::new();
    if let Some(z) = b.impedance_ohm {
        values.insert("phase_resistance", m.phase_resistance.value / z);
    }
    if let Some(l) = b.inductance_h {
        values.insert("d_inductance", m.d_inductance.value / l);
        values.insert("q_inductance", m.q_inductance.value / l);
        if let Some(&(_, l_last)) = m.q_saturation.last() {
            values.insert("q_inductance_saturated", l_last / l);
        }
    }
    if let Some(psi) = b.flux_wb {
        if let Some(p) = &m.flux_linkage {
            values.insert("flux_linkage", p.value / psi);
        }
        for (name, h) in [
            ("d_flux_6", &m.harmonics.d_flux_6),
            ("d_flux_12", &m.harmonics.d_flux_12),
            ("q_flux_6", &m.harmonics.q_flux_6),
            ("q_flux_12", &m.harmonics.q_flux_12),
        ] {
            if let Some(h) = h {
                values.insert(name, h.value / psi);
            }
        }
    }
    if let Some(w) = b.angular_frequency_rad_s {
        values.insert("current_loop_bandwidth", spec.current_loop.bandwidth.value / w);
    }
    if let Some(i) = b.current_a {
        values.insert("peak_current", std::f64::consts::SQRT_2 * m.peak_current.value / i);
    }
    PerUnitOut {
        missing: per_unit::missing(&b),
        bases: b,
        values,
    }
}
