//! The second pass: raw TOML values → SI [`Param`]s with provenance, collecting every
//! problem as a located [`Diagnostic`] instead of stopping at the first.
//!
//! This module holds the pass's state ([`ResolveContext`]) and the value parsers every
//! section uses (quantities with units, plain numbers, whole numbers); each section's own
//! rules live in the module named after it.

use std::ops::Range;

use super::raw::{RawSpec, Val};
use super::{Param, Provenance, Spec, plausible};
use crate::diagnostic::{Diagnostic, Source};
use crate::units::{self, Kind};

/// The state of the second pass over one file: its text and every problem found so far
/// (the pass collects them instead of stopping at the first). Each section is resolved by
/// a method on it in the module named after the section; its value readers (`quantity`,
/// `number`, `integer`) also read board files (`crate::board`).
pub(crate) struct ResolveContext<'a> {
    pub(crate) src: Source<'a>,
    pub(crate) errors: Vec<Diagnostic>,
}

fn kind_example(kind: Kind) -> &'static str {
    kind.accepted()
}

impl<'a> ResolveContext<'a> {
    /// A resolver with no problems found yet.
    pub(crate) fn new(src: Source<'a>) -> Self {
        ResolveContext {
            src,
            errors: Vec::new(),
        }
    }

    pub(crate) fn err(
        &mut self,
        span: Range<usize>,
        key: &str,
        problem: impl Into<String>,
        accepted: impl Into<String>,
    ) {
        let d = self.src.error(span, key, problem, accepted);
        self.errors.push(d);
    }

    /// A `"<value> <unit>"` string of `kind`; `positive` requires > 0.
    pub(crate) fn quantity(
        &mut self,
        key: &str,
        v: &Val,
        kind: Kind,
        source: Provenance,
        positive: bool,
    ) -> Option<Param> {
        let span = v.span();
        let text = match v.get_ref() {
            toml::Value::String(s) => s,
            toml::Value::Integer(_) | toml::Value::Float(_) => {
                self.err(
                    span,
                    key,
                    format!(
                        "bare number {} where {} belongs: a number without a unit is never taken as SI",
                        v.get_ref(),
                        kind.name()
                    ),
                    format!("a quoted quantity with its unit: {}", kind_example(kind)),
                );
                return None;
            }
            other => {
                self.err(
                    span,
                    key,
                    format!(
                        "expected {} as a quoted string, found a {}",
                        kind.name(),
                        other.type_str()
                    ),
                    kind_example(kind).to_string(),
                );
                return None;
            }
        };
        match units::parse(kind, text) {
            Ok(value) if positive && value <= 0.0 => {
                self.err(
                    span,
                    key,
                    format!("{} must be greater than zero, found \"{text}\"", kind.name()),
                    format!("a positive value: {}", kind_example(kind)),
                );
                None
            }
            Ok(value) if !self.plausible(key, span.clone(), value, kind, positive, text) => None,
            Ok(value) => Some(Param {
                value,
                source,
                key: key.to_string(),
                span,
                // Compound datasheet units (mN·m/A, rpm/V, g·cm², …) keep what was written.
                note: matches!(
                    kind,
                    Kind::Inertia | Kind::TorqueConstant | Kind::SpeedConstant | Kind::BackEmfConstant
                )
                .then(|| format!("converted from \"{text}\"")),
            }),
            Err(e) => {
                self.err(span, key, e.problem, kind_example(kind).to_string());
                None
            }
        }
    }

    /// Whether `value` (written `text`) of `key` lies in its physically sensible range
    /// ([`super::plausible`]); if not, the error names the range and why.
    pub(crate) fn plausible(
        &mut self,
        key: &str,
        span: Range<usize>,
        value: f64,
        kind: Kind,
        positive: bool,
        text: &str,
    ) -> bool {
        let Some(p) = plausible::plausible(key, kind) else {
            return true;
        };
        if plausible::contains(&p, value, positive) {
            return true;
        }
        let (_, range) = plausible::interval(&p, positive);
        self.err(
            span,
            key,
            format!(
                "{} must be in {range}: {}; found \"{text}\"",
                key.rsplit('.').next().unwrap_or(key),
                p.reason
            ),
            format!("{} in {range}", kind.name()),
        );
        false
    }

    /// A plain positive number (ratios, damping); integers are accepted as floats.
    pub(crate) fn number(
        &mut self,
        key: &str,
        v: &Val,
        lo_exclusive: f64,
        hi_exclusive: f64,
        accepted: &str,
    ) -> Option<Param> {
        let span = v.span();
        let value = match v.get_ref() {
            toml::Value::Float(f) => *f,
            toml::Value::Integer(i) => *i as f64,
            toml::Value::String(s) => {
                self.err(
                    span,
                    key,
                    format!("expected a plain number, found the string \"{s}\""),
                    accepted.to_string(),
                );
                return None;
            }
            other => {
                self.err(
                    span,
                    key,
                    format!("expected a number, found a {}", other.type_str()),
                    accepted.to_string(),
                );
                return None;
            }
        };
        if !value.is_finite() || value <= lo_exclusive || value >= hi_exclusive {
            self.err(span, key, format!("{value} is out of range"), accepted.to_string());
            return None;
        }
        Some(Param {
            value,
            source: Provenance::Datasheet,
            key: key.to_string(),
            span,
            note: None,
        })
    }

    /// A whole number in `[lo, hi]`.
    pub(crate) fn integer(&mut self, key: &str, v: &Val, lo: i64, hi: i64, accepted: &str) -> Option<(i64, Param)> {
        let span = v.span();
        match v.get_ref() {
            toml::Value::Integer(i) if (lo..=hi).contains(i) => Some((
                *i,
                Param {
                    value: *i as f64,
                    source: Provenance::Datasheet,
                    key: key.to_string(),
                    span,
                    note: None,
                },
            )),
            toml::Value::Integer(i) => {
                self.err(span, key, format!("{i} is out of range"), accepted.to_string());
                None
            }
            toml::Value::Float(f) => {
                self.err(span, key, format!("{f} is not a whole number"), accepted.to_string());
                None
            }
            other => {
                self.err(
                    span,
                    key,
                    format!("expected a whole number, found {} `{other}`", other.type_str()),
                    accepted.to_string(),
                );
                None
            }
        }
    }

    pub(crate) fn opt_quantity(&mut self, key: &str, v: Option<&Val>, kind: Kind, positive: bool) -> Option<Param> {
        v.and_then(|v| self.quantity(key, v, kind, Provenance::Datasheet, positive))
    }

    /// Resolves every section of the spec.
    pub(super) fn spec(&mut self, raw: &RawSpec) -> Option<Spec> {
        let name = raw.name.get_ref().trim().to_string();
        if name.is_empty() {
            self.err(
                raw.name.span(),
                "name",
                "the motor name is empty",
                "a non-empty string such as \"Fischer TI085\"",
            );
        }
        let motor = self.motor(raw);
        let resolver = self.resolver(raw);
        let drive = self.drive(raw);
        let current_loop = self.current_loop(raw);
        let angle_observer = self.observer(raw);
        let fir = self.fir(raw);
        let scaling_margin = match raw.scaling.as_ref().and_then(|s| s.get_ref().margin.as_ref()) {
            Some(v) => self.number(
                "scaling.margin",
                v,
                1.0 - 1e-12,
                10.0,
                "a headroom factor ≥ 1 and < 10, e.g. 1.25",
            ),
            None => Some(Param {
                value: 1.25,
                source: Provenance::Default,
                key: "scaling.margin".into(),
                span: 0..0,
                note: Some("default headroom 1.25".into()),
            }),
        };
        let adc = raw.adc.as_ref().and_then(|a| self.adc(a.get_ref()));
        let thermal = raw.thermal.as_ref().and_then(|t| self.thermal(t.get_ref()));
        let inverter = raw.inverter.as_ref().and_then(|i| self.inverter(i.get_ref()));
        let field_weakening = self.field_weakening(raw);
        let sensorless = self.sensorless(raw);
        Some(Spec {
            name,
            description: raw.description.clone(),
            motor: motor?,
            resolver: resolver?,
            drive: drive?,
            current_loop: current_loop?,
            angle_observer: angle_observer?,
            fir: fir?,
            scaling_margin: scaling_margin?,
            adc,
            thermal,
            inverter,
            field_weakening: field_weakening?,
            sensorless: sensorless?,
        })
    }
}
