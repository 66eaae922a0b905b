//! The inductances L_d and L_q: either one `inductance` (L_d = L_q) or
//! `d_inductance` and `q_inductance` per section, identified over datasheet axis by axis.

use super::raw::RawMotor;
use super::resolve::ResolveContext;
use super::{Param, Provenance};
use crate::units::Kind;

impl ResolveContext<'_> {
    /// At most one inductance form per section, and both axes where d/q is used.
    pub(super) fn inductance_forms(&mut self, m: &RawMotor) {
        for (section, name) in [(&m.datasheet, "datasheet"), (&m.identified, "identified")] {
            let Some(s) = section else { continue };
            let p = s.get_ref();
            if let (Some(_), Some(dq)) = (&p.inductance, p.d_inductance.as_ref().or(p.q_inductance.as_ref())) {
                self.err(dq.span(), &format!("motor.{name}.d_inductance"), format!("conflicting inductance forms in [motor.{name}]: `inductance` and `d_inductance`/`q_inductance` are both given"), "either `inductance` (L_d = L_q) or both `d_inductance` and `q_inductance`, not both forms");
            }
            // Identified values win key by key: one identified axis may stand next to a
            // datasheet value for the other (`motorgen identify step` does one axis a run).
            let datasheet_has = |q: bool| {
                name == "identified"
                    && m.datasheet.as_ref().is_some_and(|s| {
                        let ds = s.get_ref();
                        ds.inductance.is_some()
                            || if q {
                                ds.q_inductance.is_some()
                            } else {
                                ds.d_inductance.is_some()
                            }
                    })
            };
            match (&p.d_inductance, &p.q_inductance) {
                (Some(_), None) if datasheet_has(true) => {}
                (None, Some(_)) if datasheet_has(false) => {}
                (Some(d), None) => self.err(
                    d.span(),
                    &format!("motor.{name}.q_inductance"),
                    "`d_inductance` is given without `q_inductance`",
                    "both `d_inductance` and `q_inductance`, or a single `inductance`",
                ),
                (None, Some(q)) => self.err(
                    q.span(),
                    &format!("motor.{name}.d_inductance"),
                    "`q_inductance` is given without `d_inductance`",
                    "both `d_inductance` and `q_inductance`, or a single `inductance`",
                ),
                _ => {}
            }
        }
    }

    /// L_d (`d = true`) or L_q: identified d/q, identified L, datasheet d/q, datasheet L;
    /// each as a phase value or a measured terminal/winding value ([`super::winding`]).
    pub(super) fn inductance(&mut self, m: &RawMotor, d: bool) -> Option<Param> {
        let connection = m.connection.as_ref().map(|c| *c.get_ref());
        for (section, prov, name) in [
            (&m.identified, Provenance::Identified, "identified"),
            (&m.datasheet, Provenance::Datasheet, "datasheet"),
        ] {
            let Some(s) = section else { continue };
            let p = s.get_ref();
            let axis = if d { &p.d_inductance } else { &p.q_inductance };
            if let Some(v) = axis {
                let key = format!("motor.{name}.{}_inductance", if d { "d" } else { "q" });
                return self.phase_value(&key, v, Kind::Inductance, prov, connection);
            }
            if let Some(v) = &p.inductance {
                let key = format!("motor.{name}.inductance");
                // Report a bad `inductance` once (for L_d), not twice.
                let reported = self.errors.len();
                let l = self.phase_value(&key, v, Kind::Inductance, prov, connection);
                if !d {
                    self.errors.truncate(reported);
                }
                return l;
            }
        }
        None
    }
}
