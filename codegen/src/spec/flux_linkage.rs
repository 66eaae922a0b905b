//! The flux linkage ψ_M: given, or derived from the back-EMF constant K_e (6.11) or the
//! torque constant K_t (thesis A 2.34), with a cross-check when both constants are given.

use std::ops::Range;

use serde::Serialize;

use super::raw::RawMotor;
use super::resolve::Resolver_;
use super::{Param, Provenance};
use crate::units::Kind;

/// ψ_M derived from both K_t and K_e, and how far apart they are.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FluxCrossCheck {
    /// ψ_M from the torque constant, (2.34): K_t,peak / (3/2·n_p) [Wb].
    pub from_torque_constant_wb: f64,
    /// ψ_M from the back-EMF constant, (6.11): phase-peak volts per electrical rad/s [Wb].
    pub from_back_emf_constant_wb: f64,
    /// |a − b| / mean, in percent.
    pub disagreement_percent: f64,
}

impl Resolver_<'_> {
    /// ψ_M: given, or derived from K_e (preferred: it is ψ_M by definition, 6.11) or K_t (2.34).
    pub(super) fn flux(&mut self, m: &RawMotor, np: u32) -> (Option<Param>, Option<FluxCrossCheck>) {
        let given = self.motor_key(m, "flux_linkage", |p| p.flux_linkage.as_ref(), Kind::FluxLinkage, true);
        let mut from_kt = None;
        let mut from_ke = None;
        for (section, prov, name) in [
            (&m.identified, Provenance::Identified, "identified"),
            (&m.datasheet, Provenance::Datasheet, "datasheet"),
        ] {
            let Some(s) = section else { continue };
            let p = s.get_ref();
            if from_kt.is_none()
                && let Some(kt) = &p.torque_constant
            {
                let k = kt.get_ref();
                let key = format!("motor.{name}.torque_constant");
                if let Some(v) = self.quantity(&format!("{key}.value"), &k.value, Kind::TorqueConstant, prov, true) {
                    let psi = crate::design::flux_linkage::from_torque_constant(v.value, *k.current.get_ref(), np);
                    from_kt = Some((psi, key, kt.span(), prov));
                }
            }
            if from_ke.is_none()
                && let Some(ke) = &p.back_emf_constant
            {
                let k = ke.get_ref();
                let key = format!("motor.{name}.back_emf_constant");
                if let Some(v) = self.quantity(&format!("{key}.value"), &k.value, Kind::BackEmfConstant, prov, true) {
                    let psi = crate::design::flux_linkage::from_back_emf_constant(
                        v.value,
                        *k.voltage.get_ref(),
                        *k.measured.get_ref(),
                        *k.speed.get_ref(),
                        np,
                    );
                    from_ke = Some((psi, key, ke.span(), prov));
                }
            }
        }
        let check = match (&from_kt, &from_ke) {
            (Some((a, ..)), Some((b, ..))) => Some(FluxCrossCheck {
                from_torque_constant_wb: *a,
                from_back_emf_constant_wb: *b,
                disagreement_percent: 100.0 * (a - b).abs() / (0.5 * (a + b)),
            }),
            _ => None,
        };
        let derived = |(psi, key, span, _): (f64, String, Range<usize>, Provenance), eq: &str| Param {
            value: psi,
            source: Provenance::Derived,
            key: "motor.flux_linkage".into(),
            span,
            note: Some(format!("{eq} from {key}")),
        };
        let flux = given
            .or_else(|| {
                from_ke.map(|k| derived(k, "ψ_M = K_e converted to phase-peak volts per electrical rad/s (6.11)"))
            })
            .or_else(|| from_kt.map(|k| derived(k, "ψ_M = K_t,peak/(3/2·n_p) (2.34)")));
        (flux, check)
    }
}
