//! Resistances and inductances as datasheets print them. A plain string is the
//! star-equivalent phase value the model uses (thesis A (2.26), (2.27)); a table says what
//! was measured and is converted to it, the conversion kept in the value's note:
//!
//! * `{ value = "0.608 Ω", measured = "line_to_line" }`: a terminal-to-terminal value is two
//!   star-equivalent phases in series, ÷2 — for a star winding (2·R_Y) and a delta winding
//!   alike (R_Δ ∥ 2R_Δ = 2R_Δ/3 with R_Y = R_Δ/3);
//! * `measured = "winding"`: one winding, as is in star, ÷3 in delta (the star equivalent
//!   of a delta; needs `[motor] connection`);
//! * `measured = "phase"`: the star-equivalent phase value itself.
//!
//! For inductances the same holds for the balanced self-plus-mutual inductance a datasheet
//! quotes (for a salient motor, each axis measured at its aligned position).

use super::raw::{Connection, RawMotor, RawParams, Val};
use super::resolve::ResolveContext;
use super::{Param, Provenance};
use crate::units::{self, Kind};

const FORMS: &str = "a quoted phase value such as \"0.304 Ω\", or { value = \"0.608 Ω\", measured = \"line_to_line\" } (measured: \"line_to_line\", \"phase\", or \"winding\" with [motor] connection)";

impl ResolveContext<'_> {
    /// A phase resistance or inductance in either form, as the star-equivalent phase value.
    pub(super) fn phase_value(
        &mut self,
        key: &str,
        v: &Val,
        kind: Kind,
        source: Provenance,
        connection: Option<Connection>,
    ) -> Option<Param> {
        let toml::Value::Table(t) = v.get_ref() else {
            return self.quantity(key, v, kind, source, true);
        };
        let span = v.span();
        if let Some(k) = t.keys().find(|k| *k != "value" && *k != "measured") {
            self.err(
                span,
                key,
                format!("unknown key `{k}` in the {} table", kind.name()),
                FORMS,
            );
            return None;
        }
        let (Some(toml::Value::String(text)), Some(measured)) = (t.get("value"), t.get("measured")) else {
            self.err(
                span,
                key,
                format!(
                    "{} given as a table needs `value` (a quoted quantity) and `measured`",
                    kind.name()
                ),
                FORMS,
            );
            return None;
        };
        let (factor, what) = match (measured.as_str(), connection) {
            (Some("line_to_line"), _) => (0.5, "line-to-line"),
            (Some("phase"), _) => (1.0, ""),
            (Some("winding"), Some(Connection::Star)) => (1.0, ""),
            (Some("winding"), Some(Connection::Delta)) => (1.0 / 3.0, "one delta winding's"),
            (Some("winding"), None) => {
                self.err(
                    span,
                    &format!("{key}.measured"),
                    "measured = \"winding\" depends on the connection, which the spec does not state",
                    "connection = \"star\" or \"delta\" under [motor], or measured = \"line_to_line\" / \"phase\"",
                );
                return None;
            }
            _ => {
                self.err(
                    span,
                    &format!("{key}.measured"),
                    format!("`measured = {measured}` is not a known value"),
                    "\"line_to_line\", \"phase\" or \"winding\"",
                );
                return None;
            }
        };
        let value = match units::parse(kind, text) {
            Ok(x) if x > 0.0 => {
                if !self.plausible(key, span.clone(), x * factor, kind, true, text) {
                    return None;
                }
                x
            }
            Ok(_) => {
                self.err(
                    span,
                    key,
                    format!("{} must be greater than zero, found \"{text}\"", kind.name()),
                    kind.accepted(),
                );
                return None;
            }
            Err(e) => {
                self.err(span, key, e.problem, kind.accepted());
                return None;
            }
        };
        Some(Param {
            value: value * factor,
            source,
            key: key.to_string(),
            span,
            note: (factor != 1.0).then(|| {
                format!(
                    "converted from {what} \"{text}\": {} (star-equivalent phase value)",
                    if factor == 0.5 { "÷2" } else { "÷3" }
                )
            }),
        })
    }

    /// A phase resistance (or inductance) key of `[motor.identified]` over `[motor.datasheet]`.
    pub(super) fn phase_motor_key(
        &mut self,
        m: &RawMotor,
        field: &str,
        pick: fn(&RawParams) -> Option<&Val>,
        kind: Kind,
    ) -> Option<Param> {
        let connection = m.connection.as_ref().map(|c| *c.get_ref());
        for (section, prov, sect) in [
            (&m.identified, Provenance::Identified, "identified"),
            (&m.datasheet, Provenance::Datasheet, "datasheet"),
        ] {
            if let Some(v) = section.as_ref().and_then(|s| pick(s.get_ref())) {
                return self.phase_value(&format!("motor.{sect}.{field}"), v, kind, prov, connection);
            }
        }
        None
    }
}
