//! The flux linkage ψ_M: given, or derived from the back-EMF constant K_e (6.11), the
//! speed constant k_n (its reciprocal) or the torque constant K_t (thesis A 2.34), in the
//! conventions the datasheet states (rms, peak or block commutation; line to line, phase
//! or winding). Every form the spec gives is kept, so the design can cross-check them.
//! The conversions themselves, with their derivations, are in [`conversion`].

mod conversion;

use std::ops::Range;

use serde::Serialize;

use super::raw::{Amplitude, Between, Connection, RawMotor, RawParams, SpeedAxis, Val};
use super::resolve::ResolveContext;
use super::{Param, Provenance};
use crate::units::Kind;

/// One way the spec gives ψ_M, and the ψ_M it gives.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FluxSource {
    /// The key it was read from, e.g. `motor.datasheet.torque_constant`.
    pub key: String,
    /// What it is, as written: `K_t = "0.492 N·m/A" per rms ampere`.
    pub written: String,
    /// ψ_M \[Wb\] by (2.34) or (6.11).
    pub flux_wb: f64,
    /// Byte span of the value in the file (warnings about it are located there).
    #[serde(skip)]
    pub span: Range<usize>,
}

/// A motor constant in the spec's sections, identified before datasheet.
struct Found<'a, T> {
    key: String,
    prov: Provenance,
    span: Range<usize>,
    raw: &'a T,
}

fn find<'a, T>(
    m: &'a RawMotor,
    name: &str,
    pick: fn(&'a RawParams) -> Option<&'a serde_spanned::Spanned<T>>,
) -> Option<Found<'a, T>> {
    [
        (&m.identified, Provenance::Identified, "identified"),
        (&m.datasheet, Provenance::Datasheet, "datasheet"),
    ]
    .into_iter()
    .find_map(|(section, prov, sect)| {
        let v = pick(section.as_ref()?.get_ref())?;
        Some(Found {
            key: format!("motor.{sect}.{name}"),
            prov,
            span: v.span(),
            raw: v.get_ref(),
        })
    })
}

fn text(v: &Val) -> String {
    match v.get_ref() {
        toml::Value::String(s) => format!("\"{s}\""),
        other => other.to_string(),
    }
}

fn amplitude_name(a: Amplitude) -> &'static str {
    match a {
        Amplitude::Rms => "rms",
        Amplitude::Peak => "peak",
        Amplitude::BlockCommutation => "block-commutation DC",
    }
}

/// The voltage a back-EMF or speed constant refers to: `rms line-to-line`, `peak phase`,
/// or `block-commutation DC` (line to line by construction).
fn voltage_name(a: Amplitude, line_to_line: bool) -> String {
    match a {
        Amplitude::BlockCommutation => amplitude_name(a).to_string(),
        _ if line_to_line => format!("{} line-to-line", amplitude_name(a)),
        _ => format!("{} phase", amplitude_name(a)),
    }
}

impl ResolveContext<'_> {
    /// ψ_M: given, or derived from K_e (preferred: it is ψ_M by definition, 6.11), k_n, or
    /// K_t (2.34); and every source the spec gives, for the design's cross-check.
    pub(super) fn flux(&mut self, m: &RawMotor, np: u32) -> (Option<Param>, Vec<FluxSource>) {
        let connection = m.connection.as_ref().map(|c| *c.get_ref());
        let given = self.motor_key(m, "flux_linkage", |p| p.flux_linkage.as_ref(), Kind::FluxLinkage, true);
        let mut sources = Vec::new();
        if let Some(p) = &given {
            sources.push(FluxSource {
                key: p.key.clone(),
                written: "ψ_M".to_string(),
                flux_wb: p.value,
                span: p.span.clone(),
            });
        }
        let mut derived: Vec<(Param, usize)> = Vec::new();
        let mut add = |sources: &mut Vec<FluxSource>,
                       (key, span): (&str, &Range<usize>),
                       written: String,
                       psi: f64,
                       eq: &str,
                       rank: usize| {
            sources.push(FluxSource {
                key: key.to_string(),
                written: written.clone(),
                flux_wb: psi,
                span: span.clone(),
            });
            derived.push((
                Param {
                    value: psi,
                    source: Provenance::Derived,
                    key: "motor.flux_linkage".into(),
                    span: span.clone(),
                    note: Some(format!("{eq} from {key} ({written})")),
                },
                rank,
            ));
        };
        if let Some(f) = find(m, "back_emf_constant", |p| p.back_emf_constant.as_ref()) {
            let k = f.raw;
            if let (Some(v), Some(ll)) = (
                self.quantity(
                    &format!("{}.value", f.key),
                    &k.value,
                    Kind::BackEmfConstant,
                    f.prov,
                    true,
                ),
                self.line_to_line(&f.key, *k.voltage.get_ref(), k.measured.as_ref(), connection, &f.span),
            ) {
                let psi = conversion::from_back_emf_constant(v.value, *k.voltage.get_ref(), ll, *k.speed.get_ref(), np);
                let written = format!(
                    "K_e = {} {} per {} rad/s",
                    text(&k.value),
                    voltage_name(*k.voltage.get_ref(), ll),
                    speed_name(*k.speed.get_ref())
                );
                add(
                    &mut sources,
                    (&f.key, &f.span),
                    written,
                    psi,
                    "ψ_M = K_e in phase-peak volts per electrical rad/s (6.11)",
                    1,
                );
            }
        }
        if let Some(f) = find(m, "speed_constant", |p| p.speed_constant.as_ref()) {
            let k = f.raw;
            let speed = k.speed.as_ref().map_or(SpeedAxis::Mechanical, |s| *s.get_ref());
            if let (Some(v), Some(ll)) = (
                self.quantity(&format!("{}.value", f.key), &k.value, Kind::SpeedConstant, f.prov, true),
                self.line_to_line(&f.key, *k.voltage.get_ref(), k.measured.as_ref(), connection, &f.span),
            ) {
                let psi = conversion::from_back_emf_constant(1.0 / v.value, *k.voltage.get_ref(), ll, speed, np);
                let written = format!(
                    "k_n = {} per {} volt, K_e = 1/k_n",
                    text(&k.value),
                    voltage_name(*k.voltage.get_ref(), ll),
                );
                add(
                    &mut sources,
                    (&f.key, &f.span),
                    written,
                    psi,
                    "ψ_M = (1/k_n) in phase-peak volts per electrical rad/s (6.11)",
                    2,
                );
            }
        }
        if let Some(f) = find(m, "torque_constant", |p| p.torque_constant.as_ref()) {
            let k = f.raw;
            if let Some(v) = self.quantity(
                &format!("{}.value", f.key),
                &k.value,
                Kind::TorqueConstant,
                f.prov,
                true,
            ) {
                let psi = conversion::from_torque_constant(v.value, *k.current.get_ref(), np);
                let written = format!(
                    "K_t = {} per {} ampere",
                    text(&k.value),
                    amplitude_name(*k.current.get_ref())
                );
                let eq = if *k.current.get_ref() == Amplitude::BlockCommutation {
                    "ψ_M = k_M/((3√3/π)·n_p) (block commutation)"
                } else {
                    "ψ_M = K_t,peak/(3/2·n_p) (2.34)"
                };
                add(&mut sources, (&f.key, &f.span), written, psi, eq, 3);
            }
        }
        let flux = given.or_else(|| derived.into_iter().min_by_key(|(_, r)| *r).map(|(p, _)| p));
        (flux, sources)
    }

    /// Whether a back-EMF voltage is line to line: block commutation's induced voltage is
    /// (an explicit `measured` must then say `line_to_line`); rms and peak need `measured`,
    /// and `winding` needs the connection (delta: line to line, star: phase).
    fn line_to_line(
        &mut self,
        key: &str,
        voltage: Amplitude,
        measured: Option<&serde_spanned::Spanned<Between>>,
        connection: Option<Connection>,
        span: &Range<usize>,
    ) -> Option<bool> {
        let accepted =
            "measured = \"line_to_line\", \"phase\" (line to neutral) or \"winding\" (with [motor] connection)";
        match (voltage, measured.map(|m| (*m.get_ref(), m.span()))) {
            (Amplitude::BlockCommutation, None | Some((Between::LineToLine, _))) => Some(true),
            (Amplitude::BlockCommutation, Some((_, s))) => {
                self.err(
                    s,
                    &format!("{key}.measured"),
                    "the induced voltage of block commutation is the line-to-line voltage of the conducting pair",
                    "measured = \"line_to_line\", or no `measured` with voltage = \"block_commutation\"",
                );
                None
            }
            (_, None) => {
                self.err(
                    span.clone(),
                    &format!("{key}.measured"),
                    "an rms or peak back-EMF voltage needs `measured`: line to line and phase differ by √3",
                    accepted,
                );
                None
            }
            (_, Some((Between::LineToLine, _))) => Some(true),
            (_, Some((Between::Phase, _))) => Some(false),
            (_, Some((Between::Winding, s))) => match connection {
                Some(Connection::Delta) => Some(true),
                Some(Connection::Star) => Some(false),
                None => {
                    self.err(
                        s,
                        &format!("{key}.measured"),
                        "measured = \"winding\" depends on the connection, which the spec does not state",
                        "connection = \"star\" or \"delta\" under [motor], or measured = \"line_to_line\" / \"phase\"",
                    );
                    None
                }
            },
        }
    }
}

fn speed_name(s: SpeedAxis) -> &'static str {
    match s {
        SpeedAxis::Mechanical => "mechanical",
        SpeedAxis::Electrical => "electrical",
    }
}
