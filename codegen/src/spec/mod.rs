//! The motor spec: TOML text → SI values with provenance, or located diagnostics.
//!
//! Parsing is two passes. [`raw`] mirrors the file (unknown keys are errors);
//! [`resolve`] applies units, ranges and the merge rule: `[motor.identified]`
//! overrides `[motor.datasheet]` key by key, and ψ_M may be derived from K_t or
//! K_e (thesis A 2.34). Nothing here does file I/O.

mod field_weakening;
mod raw;
mod sensorless;

use std::ops::Range;

use serde::Serialize;

use crate::diagnostic::{Diagnostic, Diagnostics, Source};
use crate::units::{self, Kind};
pub use field_weakening::{DEFAULT_VOLTAGE_FRACTION, FieldWeakeningSpec};
pub(crate) use raw::Val;
pub use raw::{Amplitude, Between, Connection, Method, ObserverError, SpeedAxis};
use raw::{RawParams, RawSpec};
pub use sensorless::{DEFAULT_ANGLE_ERROR_DEG, DEFAULT_RESISTANCE_ERROR, SensorlessSpec, angle_error_rad};

/// Where a resolved value came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Provenance {
    /// `[motor.datasheet]` (or another section written by hand).
    Datasheet,
    /// `[motor.identified]`.
    Identified,
    /// Computed from other values by a stated formula.
    Derived,
    /// Not in the file; the documented default was used.
    Default,
}

/// A resolved value in SI units with its provenance and location.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// Value in SI units (see the field's name for the unit).
    pub value: f64,
    /// Where it came from.
    pub source: Provenance,
    /// Dotted key it was read from (or the key it was derived for).
    pub key: String,
    /// Byte span of the value in the file (for diagnostics).
    pub span: Range<usize>,
    /// For derived values: the formula and inputs.
    pub note: Option<String>,
}

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

/// Optional harmonic data (thesis B 2.14–2.16, 2.23), SI.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Harmonics {
    /// ψ_d,6 [Wb].
    pub d_flux_6: Option<Param>,
    /// ψ_d,12 [Wb].
    pub d_flux_12: Option<Param>,
    /// ψ_q,6 [Wb].
    pub q_flux_6: Option<Param>,
    /// ψ_q,12 [Wb].
    pub q_flux_12: Option<Param>,
    /// L_6 [H].
    pub inductance_6: Option<Param>,
}

/// The resolved motor.
#[derive(Debug, Clone, PartialEq)]
pub struct Motor {
    /// n_p.
    pub pole_pairs: u32,
    /// R_s [Ω].
    pub phase_resistance: Param,
    /// L_d [H].
    pub d_inductance: Param,
    /// L_q [H].
    pub q_inductance: Param,
    /// ψ_M [Wb], if known or derivable.
    pub flux_linkage: Option<Param>,
    /// Both derivations of ψ_M when both constants are given.
    pub flux_cross_check: Option<FluxCrossCheck>,
    /// Rated current, rms [A].
    pub nominal_current: Option<Param>,
    /// Peak current, rms [A].
    pub peak_current: Param,
    /// Maximum mechanical speed [rad/s].
    pub max_speed: Param,
    /// Rated torque [N·m].
    pub nominal_torque: Option<Param>,
    /// Peak torque [N·m].
    pub peak_torque: Option<Param>,
    /// Rated electrical frequency f_n [Hz] (given, or from the nominal speed).
    pub rated_frequency: Option<Param>,
    /// Rated power [W].
    pub rated_power: Option<Param>,
    /// Rotor inertia J [kg·m²].
    pub inertia: Option<Param>,
    /// Viscous friction b [N·m·s/rad].
    pub viscous_friction: Option<Param>,
    /// Harmonic data.
    pub harmonics: Harmonics,
    /// L_q(|i_q|) curve points ([A], [H]), sorted by current.
    pub q_saturation: Vec<(f64, f64)>,
    /// Winding connection, if stated.
    pub connection: Option<Connection>,
    /// When and from what the identified values were obtained (`date`, `source`).
    pub identification: Option<String>,
}

/// The resolved resolver.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolver {
    /// n_r.
    pub pole_pairs: u32,
    /// θ_off [rad] in resolver angle (4.5), if known.
    pub offset: Option<Param>,
}

/// The resolved drive.
#[derive(Debug, Clone, PartialEq)]
pub struct Drive {
    /// f_s = switching = sampling frequency [Hz].
    pub switching_frequency: Param,
    /// Nominal DC-link voltage U_dc [V].
    pub dc_link_voltage: Param,
    /// Lowest DC-link voltage the controller must work at [V] (defaults to U_dc).
    pub dc_link_voltage_min: Param,
    /// Dead time [s], if given.
    pub dead_time: Option<Param>,
}

/// The resolved current-loop request.
#[derive(Debug, Clone, PartialEq)]
pub struct CurrentLoopSpec {
    /// Tuning method.
    pub method: Method,
    /// Span of the method value.
    pub method_span: Range<usize>,
    /// Closed-loop bandwidth α [rad/s].
    pub bandwidth: Param,
    /// ζ for pole placement.
    pub damping: Option<Param>,
    /// Design each axis for the rise time ln 9/α of the sampled loop with its 1.5·T_s delay
    /// (first-order methods; see `design::discrete_loop`).
    pub compensate_delay: bool,
}

/// The resolved angle-observer request.
#[derive(Debug, Clone, PartialEq)]
pub struct ObserverSpec {
    /// ω_n [rad/s].
    pub natural_frequency: Param,
    /// ζ.
    pub damping: Param,
    /// Error architecture.
    pub error: ObserverError,
    /// Samples of delay the angle lead compensates (4.23), default 1.5.
    pub lead_samples: Param,
}

/// The resolved FIR request.
#[derive(Debug, Clone, PartialEq)]
pub struct FirSpec {
    /// Pass-band edge [Hz].
    pub pass_edge: Param,
    /// Stop-band edge [Hz].
    pub stop_edge: Param,
    /// Maximal relative pass-band deviation.
    pub pass_ripple: Param,
    /// Order, if given.
    pub order: Option<(usize, Param)>,
    /// Required stop-band attenuation [dB], if given.
    pub stop_attenuation: Option<Param>,
    /// Span of the `[fir]` table (for whole-section errors).
    pub span: Range<usize>,
}

/// The ADC sample-and-hold data (7.2), if given.
#[derive(Debug, Clone, PartialEq)]
pub struct AdcSpec {
    /// N bits.
    pub resolution_bits: u32,
    /// f_ADC [Hz].
    pub clock: Param,
    /// C_ADC [F].
    pub sample_capacitance: Param,
    /// R_ADC [Ω].
    pub switch_resistance: Param,
    /// R_EXT [Ω].
    pub source_resistance: Param,
}

/// Winding temperatures (thesis B 2.24).
#[derive(Debug, Clone, PartialEq)]
pub struct ThermalSpec {
    /// T_0 at which R_s was measured [°C] (default 20 °C as in thesis B).
    pub reference_temperature: Param,
    /// Upper winding temperature [°C].
    pub max_winding_temperature: Param,
}

/// Inverter switch data (thesis B Table B.3).
#[derive(Debug, Clone, PartialEq)]
pub struct InverterSpec {
    /// Part name.
    pub part: Option<String>,
    /// I_c,nom [A].
    pub nominal_current: Param,
    /// r_CE [Ω].
    pub transistor_resistance: Param,
    /// V_CE0 [V].
    pub transistor_threshold: Param,
    /// E_on + E_off [J].
    pub switching_energy: Param,
    /// r_T [Ω].
    pub diode_resistance: Param,
    /// V_T0 [V].
    pub diode_threshold: Param,
    /// E_rr [J].
    pub recovery_energy: Param,
}

/// A whole resolved spec.
#[derive(Debug, Clone, PartialEq)]
pub struct Spec {
    /// Motor name.
    pub name: String,
    /// Free description.
    pub description: Option<String>,
    /// Motor data.
    pub motor: Motor,
    /// Resolver data.
    pub resolver: Resolver,
    /// Inverter operating point.
    pub drive: Drive,
    /// Current-loop request.
    pub current_loop: CurrentLoopSpec,
    /// Angle-observer request.
    pub angle_observer: ObserverSpec,
    /// FIR request.
    pub fir: FirSpec,
    /// Full-scale headroom over the ratings (default 1.25).
    pub scaling_margin: Param,
    /// ADC settling data, if given.
    pub adc: Option<AdcSpec>,
    /// Winding temperatures, if given.
    pub thermal: Option<ThermalSpec>,
    /// Inverter loss data, if given.
    pub inverter: Option<InverterSpec>,
    /// `[field_weakening]` and `[losses]` (thesis B §2.3, chapter 3).
    pub field_weakening: FieldWeakeningSpec,
    /// `[sensorless]` (thesis B chapter 4).
    pub sensorless: SensorlessSpec,
}

/// Parses and resolves a spec. `source.file` is only used in messages.
pub fn parse(source: Source<'_>) -> Result<Spec, Diagnostics> {
    if source.text.trim().is_empty() {
        return Err(source
            .error(
                0..0,
                "",
                "the file is empty",
                "a motor spec with at least `name`, [motor], [resolver], [drive], [current_loop], [angle_observer] and [fir] (see `motorgen new`)",
            )
            .into());
    }
    let raw: RawSpec = deserialize(source, "motors/fischer-ti085.toml")?;
    let mut cx = Resolver_::new(source);
    let spec = cx.spec(&raw);
    match spec {
        Some(spec) if cx.errors.is_empty() => Ok(spec),
        _ => Err(Diagnostics(cx.errors)),
    }
}

/// TOML text → the raw (spanned) structure `T`, every syntax or shape problem (unknown
/// key, missing key, wrong type, unknown value) located at its key; `example` names a
/// complete file of the same kind for the "accepted" line. Shared by motor specs and
/// board files (`crate::board`).
pub(crate) fn deserialize<T: serde::de::DeserializeOwned>(source: Source<'_>, example: &str) -> Result<T, Diagnostics> {
    let de = toml::Deserializer::parse(source.text).map_err(|e| syntax_error(source, &e))?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        shape_error(source, &path, &inner, example)
    })
}

fn syntax_error(source: Source<'_>, e: &toml::de::Error) -> Diagnostics {
    let span = e.span().unwrap_or(0..0);
    source
        .error(
            span,
            "",
            format!("TOML syntax error: {}", e.message().trim()),
            "valid TOML 1.0 (https://toml.io): `key = value` lines, [section] headers, quoted strings",
        )
        .into()
}

/// A serde error (unknown key, missing key, wrong type, unknown variant) at its key path.
fn shape_error(source: Source<'_>, path: &str, e: &toml::de::Error, example: &str) -> Diagnostics {
    let span = e.span().unwrap_or(0..0);
    let message = e.message().trim().to_string();
    // serde_spanned wraps values in a private field; it is not part of the user's key.
    let path = path
        .split('.')
        .filter(|seg| !seg.starts_with("$__serde_spanned") && !seg.is_empty())
        .collect::<Vec<_>>()
        .join(".");
    let (problem, accepted) = if let Some(rest) = message.strip_prefix("unknown field ") {
        let (field, expected) = rest.split_once(", expected ").unwrap_or((rest, "no other keys"));
        (
            format!("unknown key {field} (is it misspelt?)"),
            format!("one of {}", expected.trim_start_matches("one of ")),
        )
    } else if let Some(field) = message.strip_prefix("missing field ") {
        let key = if path.is_empty() {
            field.trim_matches('`').to_string()
        } else {
            format!("{path}.{}", field.trim_matches('`'))
        };
        (
            format!("missing required key `{key}`"),
            format!("the key with a value; see {example} for a complete file"),
        )
    } else if let Some(rest) = message.strip_prefix("unknown variant ") {
        let (value, expected) = rest.split_once(", expected ").unwrap_or((rest, "?"));
        (
            format!("{value} is not a known value"),
            format!("one of {}", expected.trim_start_matches("one of ")),
        )
    } else {
        (message, format!("a value of the type this key takes; see {example}"))
    };
    source.error(span, path, problem, accepted).into()
}

/// The second pass; collects every problem instead of stopping at the first. Its value
/// readers (`quantity`, `number`, `integer`) also read board files (`crate::board`).
pub(crate) struct Resolver_<'a> {
    pub(crate) src: Source<'a>,
    pub(crate) errors: Vec<Diagnostic>,
}

fn kind_example(kind: Kind) -> &'static str {
    kind.accepted()
}

impl<'a> Resolver_<'a> {
    /// A resolver with no problems found yet.
    pub(crate) fn new(src: Source<'a>) -> Self {
        Resolver_ {
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
            Ok(value) => Some(Param {
                value,
                source,
                key: key.to_string(),
                span,
                note: None,
            }),
            Err(e) => {
                self.err(span, key, e.problem, kind_example(kind).to_string());
                None
            }
        }
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

    fn spec(&mut self, raw: &RawSpec) -> Option<Spec> {
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

    /// The value of one motor key: identified over datasheet.
    fn motor_key(
        &mut self,
        raw: &raw::RawMotor,
        field: &str,
        pick: fn(&RawParams) -> Option<&Val>,
        kind: Kind,
        positive: bool,
    ) -> Option<Param> {
        for (section, prov) in [
            (&raw.identified, Provenance::Identified),
            (&raw.datasheet, Provenance::Datasheet),
        ] {
            if let Some(v) = section.as_ref().and_then(|s| pick(s.get_ref())) {
                let sect = if prov == Provenance::Identified {
                    "identified"
                } else {
                    "datasheet"
                };
                return self.quantity(&format!("motor.{sect}.{field}"), v, kind, prov, positive);
            }
        }
        None
    }

    fn motor(&mut self, raw: &RawSpec) -> Option<Motor> {
        let m = raw.motor.get_ref();
        let motor_span = raw.motor.span();
        let pole_pairs = self
            .integer(
                "motor.pole_pairs",
                &m.pole_pairs,
                1,
                64,
                "a whole number of pole pairs from 1 to 64, e.g. 4",
            )
            .map(|(i, _)| i as u32);
        if m.datasheet.is_none() && m.identified.is_none() {
            self.err(motor_span.clone(), "motor", "neither [motor.datasheet] nor [motor.identified] is given", "at least one of the two sections with phase_resistance, inductance (or d_/q_inductance), peak_current and max_speed");
            return None;
        }
        // Inductance forms: one per section.
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
        let missing = |this: &mut Self, key: &str, what: &str| {
            this.err(
                motor_span.clone(),
                &format!("motor.datasheet.{key}"),
                format!("missing required key `{key}` in [motor.datasheet] or [motor.identified]"),
                what.to_string(),
            );
        };
        let phase_resistance = self.motor_key(
            m,
            "phase_resistance",
            |p| p.phase_resistance.as_ref(),
            Kind::Resistance,
            true,
        );
        if phase_resistance.is_none() && !self.has(m, |p| p.phase_resistance.is_some()) {
            missing(
                self,
                "phase_resistance",
                "the phase (star-equivalent) resistance, e.g. phase_resistance = \"0.126 Ω\"",
            );
        }
        let d_inductance = self.inductance(m, true);
        let q_inductance = self.inductance(m, false);
        if d_inductance.is_none() && !self.has(m, |p| p.inductance.is_some() || p.d_inductance.is_some()) {
            missing(
                self,
                "inductance",
                "inductance = \"0.393 mH\" (L_d = L_q) or d_inductance and q_inductance",
            );
        }
        let peak_current = self.motor_key(m, "peak_current", |p| p.peak_current.as_ref(), Kind::Current, true);
        if peak_current.is_none() && !self.has(m, |p| p.peak_current.is_some()) {
            missing(
                self,
                "peak_current",
                "the peak phase current (rms), e.g. peak_current = \"61 A\"; it sets the current full scale",
            );
        }
        let max_speed = self.motor_key(m, "max_speed", |p| p.max_speed.as_ref(), Kind::Speed, true);
        if max_speed.is_none() && !self.has(m, |p| p.max_speed.is_some()) {
            missing(
                self,
                "max_speed",
                "the maximum shaft speed, e.g. max_speed = \"20000 rpm\"; it sets f_e,max (1.1)",
            );
        }
        let nominal_current = self.motor_key(
            m,
            "nominal_current",
            |p| p.nominal_current.as_ref(),
            Kind::Current,
            true,
        );
        let nominal_torque = self.motor_key(m, "nominal_torque", |p| p.nominal_torque.as_ref(), Kind::Torque, true);
        let peak_torque = self.motor_key(m, "peak_torque", |p| p.peak_torque.as_ref(), Kind::Torque, true);
        let rated_power = self.motor_key(m, "rated_power", |p| p.rated_power.as_ref(), Kind::Power, true);
        let inertia = self.motor_key(m, "inertia", |p| p.inertia.as_ref(), Kind::Inertia, true);
        let viscous_friction = self.motor_key(
            m,
            "viscous_friction",
            |p| p.viscous_friction.as_ref(),
            Kind::ViscousFriction,
            true,
        );
        let rated_frequency = self.motor_key(
            m,
            "rated_frequency",
            |p| p.rated_frequency.as_ref(),
            Kind::Frequency,
            true,
        );
        let nominal_speed = self.motor_key(m, "nominal_speed", |p| p.nominal_speed.as_ref(), Kind::Speed, true);
        let rated_frequency = match (rated_frequency, nominal_speed, pole_pairs) {
            (Some(f), _, _) => Some(f),
            (None, Some(n), Some(np)) => Some(Param {
                value: n.value * np as f64 / (2.0 * std::f64::consts::PI),
                source: Provenance::Derived,
                key: "motor.rated_frequency".into(),
                span: n.span.clone(),
                note: Some(format!("f_n = n_p·ω_m,n/(2π) (2.19) from {}", n.key)),
            }),
            _ => None,
        };
        let (flux_linkage, flux_cross_check) = match pole_pairs {
            Some(np) => self.flux(m, np),
            None => (None, None),
        };
        let harmonics = m.harmonics.as_ref().map(|h| {
            let h = h.get_ref();
            Harmonics {
                d_flux_6: self.opt_quantity(
                    "motor.harmonics.d_flux_6",
                    h.d_flux_6.as_ref(),
                    Kind::FluxLinkage,
                    false,
                ),
                d_flux_12: self.opt_quantity(
                    "motor.harmonics.d_flux_12",
                    h.d_flux_12.as_ref(),
                    Kind::FluxLinkage,
                    false,
                ),
                q_flux_6: self.opt_quantity(
                    "motor.harmonics.q_flux_6",
                    h.q_flux_6.as_ref(),
                    Kind::FluxLinkage,
                    false,
                ),
                q_flux_12: self.opt_quantity(
                    "motor.harmonics.q_flux_12",
                    h.q_flux_12.as_ref(),
                    Kind::FluxLinkage,
                    false,
                ),
                inductance_6: self.opt_quantity(
                    "motor.harmonics.inductance_6",
                    h.inductance_6.as_ref(),
                    Kind::Inductance,
                    false,
                ),
            }
        });
        let q_saturation = self.saturation(m);
        let identification = m.identified.as_ref().and_then(|s| {
            let p = s.get_ref();
            let text = |v: &toml::Value| match v {
                toml::Value::String(s) => s.clone(),
                other => other.to_string(),
            };
            match (p.date.as_ref().map(text), p.source.as_ref().map(text)) {
                (None, None) => None,
                (d, s) => Some(format!(
                    "identified{}{}",
                    d.map_or(String::new(), |d| format!(" on {d}")),
                    s.map_or(String::new(), |s| format!(" from {s}"))
                )),
            }
        });
        Some(Motor {
            connection: m.connection.as_ref().map(|c| *c.get_ref()),
            identification,
            pole_pairs: pole_pairs?,
            phase_resistance: phase_resistance?,
            d_inductance: d_inductance?,
            q_inductance: q_inductance?,
            flux_linkage,
            flux_cross_check,
            nominal_current,
            peak_current: peak_current?,
            max_speed: max_speed?,
            nominal_torque,
            peak_torque,
            rated_frequency,
            rated_power,
            inertia,
            viscous_friction,
            harmonics: harmonics.unwrap_or_default(),
            q_saturation,
        })
    }

    fn has(&self, m: &raw::RawMotor, f: fn(&RawParams) -> bool) -> bool {
        [&m.identified, &m.datasheet]
            .into_iter()
            .flatten()
            .any(|s| f(s.get_ref()))
    }

    /// L_d (`d = true`) or L_q: identified d/q, identified L, datasheet d/q, datasheet L.
    fn inductance(&mut self, m: &raw::RawMotor, d: bool) -> Option<Param> {
        for (section, prov, name) in [
            (&m.identified, Provenance::Identified, "identified"),
            (&m.datasheet, Provenance::Datasheet, "datasheet"),
        ] {
            let Some(s) = section else { continue };
            let p = s.get_ref();
            let axis = if d { &p.d_inductance } else { &p.q_inductance };
            if let Some(v) = axis {
                let key = format!("motor.{name}.{}_inductance", if d { "d" } else { "q" });
                return self.quantity(&key, v, Kind::Inductance, prov, true);
            }
            if let Some(v) = &p.inductance {
                // Report a bad `inductance` once (for L_d), not twice.
                let key = format!("motor.{name}.inductance");
                if d {
                    return self.quantity(&key, v, Kind::Inductance, prov, true);
                }
                let text = match v.get_ref() {
                    toml::Value::String(s) => s.clone(),
                    _ => return None,
                };
                return units::parse(Kind::Inductance, &text)
                    .ok()
                    .filter(|x| *x > 0.0)
                    .map(|value| Param {
                        value,
                        source: prov,
                        key,
                        span: v.span(),
                        note: None,
                    });
            }
        }
        None
    }

    /// ψ_M: given, or derived from K_e (preferred: it is ψ_M by definition, 6.11) or K_t (2.34).
    fn flux(&mut self, m: &raw::RawMotor, np: u32) -> (Option<Param>, Option<FluxCrossCheck>) {
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

    fn saturation(&mut self, m: &raw::RawMotor) -> Vec<(f64, f64)> {
        let Some(s) = &m.saturation else { return Vec::new() };
        let mut points = Vec::new();
        let mut last = -1.0;
        for (i, p) in s.get_ref().q_inductance.iter().enumerate() {
            let key = format!("motor.saturation.q_inductance[{i}]");
            let c = self.quantity(
                &format!("{key}.current"),
                &p.get_ref().current,
                Kind::Current,
                Provenance::Datasheet,
                false,
            );
            let l = self.quantity(
                &format!("{key}.inductance"),
                &p.get_ref().inductance,
                Kind::Inductance,
                Provenance::Datasheet,
                true,
            );
            if let (Some(c), Some(l)) = (c, l) {
                if c.value < 0.0 || c.value <= last {
                    self.err(
                        p.span(),
                        &key,
                        "curve points must have increasing, non-negative currents",
                        "points ordered by |i_q| from 0 A upwards",
                    );
                }
                last = c.value;
                points.push((c.value, l.value));
            }
        }
        points
    }

    fn resolver(&mut self, raw: &RawSpec) -> Option<Resolver> {
        let r = raw.resolver.get_ref();
        let pole_pairs = self.integer(
            "resolver.pole_pairs",
            &r.pole_pairs,
            1,
            64,
            "a whole number of resolver pole pairs from 1 to 64, e.g. 1",
        );
        let ident = raw
            .motor
            .get_ref()
            .identified
            .as_ref()
            .and_then(|s| s.get_ref().resolver_offset.as_ref());
        let offset = match ident {
            Some(v) => self.angle("motor.identified.resolver_offset", v, Provenance::Identified),
            None => r
                .offset
                .as_ref()
                .and_then(|v| self.angle("resolver.offset", v, Provenance::Datasheet)),
        };
        Some(Resolver {
            pole_pairs: pole_pairs?.0 as u32,
            offset,
        })
    }

    fn angle(&mut self, key: &str, v: &Val, prov: Provenance) -> Option<Param> {
        let accepted = "an angle such as \"0.52 rad\" or \"30 deg\" (units: rad, deg, °)";
        let text = match v.get_ref() {
            toml::Value::String(s) => s.clone(),
            other => {
                self.err(
                    v.span(),
                    key,
                    format!(
                        "expected an angle string with its unit, found {} `{other}`",
                        other.type_str()
                    ),
                    accepted,
                );
                return None;
            }
        };
        let parsed = text
            .trim()
            .strip_suffix("rad")
            .map(|n| (n, 1.0))
            .or_else(|| {
                text.trim()
                    .strip_suffix("deg")
                    .map(|n| (n, std::f64::consts::PI / 180.0))
            })
            .or_else(|| text.trim().strip_suffix('°').map(|n| (n, std::f64::consts::PI / 180.0)))
            .and_then(|(n, k)| n.trim().parse::<f64>().ok().filter(|x| x.is_finite()).map(|x| x * k));
        match parsed {
            Some(value) => Some(Param {
                value,
                source: prov,
                key: key.into(),
                span: v.span(),
                note: None,
            }),
            None => {
                self.err(v.span(), key, format!("\"{text}\" is not an angle"), accepted);
                None
            }
        }
    }

    fn drive(&mut self, raw: &RawSpec) -> Option<Drive> {
        let d = raw.drive.get_ref();
        let fs = self.quantity(
            "drive.switching_frequency",
            &d.switching_frequency,
            Kind::Frequency,
            Provenance::Datasheet,
            true,
        );
        let udc = self.quantity(
            "drive.dc_link_voltage",
            &d.dc_link_voltage,
            Kind::Voltage,
            Provenance::Datasheet,
            true,
        );
        let umin = self.opt_quantity(
            "drive.dc_link_voltage_min",
            d.dc_link_voltage_min.as_ref(),
            Kind::Voltage,
            true,
        );
        if let (Some(lo), Some(hi)) = (&umin, &udc)
            && lo.value > hi.value
        {
            self.err(
                lo.span.clone(),
                "drive.dc_link_voltage_min",
                format!(
                    "minimum DC-link voltage {} V is above the nominal {} V",
                    lo.value, hi.value
                ),
                "a voltage ≤ drive.dc_link_voltage",
            );
        }
        let dead_time = self.opt_quantity("drive.dead_time", d.dead_time.as_ref(), Kind::Time, true);
        let udc = udc?;
        let dc_link_voltage_min = umin.unwrap_or_else(|| Param {
            source: Provenance::Default,
            key: "drive.dc_link_voltage_min".into(),
            note: Some("defaults to drive.dc_link_voltage".into()),
            ..udc.clone()
        });
        Some(Drive {
            switching_frequency: fs?,
            dc_link_voltage: udc,
            dc_link_voltage_min,
            dead_time,
        })
    }

    fn current_loop(&mut self, raw: &RawSpec) -> Option<CurrentLoopSpec> {
        let c = raw.current_loop.get_ref();
        let method = *c.method.get_ref();
        let bandwidth = self.quantity(
            "current_loop.bandwidth",
            &c.bandwidth,
            Kind::AngularFrequency,
            Provenance::Datasheet,
            true,
        );
        let damping = match (&c.damping, method) {
            (Some(v), Method::PolePlacement) => self.number(
                "current_loop.damping",
                v,
                0.0,
                10.0,
                "a damping ratio ζ with 0 < ζ < 10, e.g. 0.7071 (= 1/√2, thesis A §5.4.1)",
            ),
            (Some(v), _) => {
                self.err(
                    v.span(),
                    "current_loop.damping",
                    "`damping` is only used by method = \"pole_placement\"",
                    "remove `damping`, or set method = \"pole_placement\"",
                );
                None
            }
            (None, Method::PolePlacement) => {
                self.err(
                    raw.current_loop.span(),
                    "current_loop.damping",
                    "method = \"pole_placement\" needs `damping`",
                    "damping = 0.7071 (ζ = 1/√2, recommended in thesis A §5.4.1)",
                );
                None
            }
            (None, _) => None,
        };
        let compensate_delay = match (&c.compensate_delay, method) {
            (Some(v), Method::PolePlacement) if *v.get_ref() => {
                self.err(
                    v.span(),
                    "current_loop.compensate_delay",
                    "delay compensation is designed for the first-order loops only",
                    "compensate_delay = false, or method = \"imc\" or \"imc_active_damping\"",
                );
                false
            }
            (Some(v), _) => *v.get_ref(),
            (None, _) => false,
        };
        Some(CurrentLoopSpec {
            method,
            method_span: c.method.span(),
            bandwidth: bandwidth?,
            damping,
            compensate_delay,
        })
    }

    fn observer(&mut self, raw: &RawSpec) -> Option<ObserverSpec> {
        let o = raw.angle_observer.get_ref();
        let wn = self.quantity(
            "angle_observer.natural_frequency",
            &o.natural_frequency,
            Kind::AngularFrequency,
            Provenance::Datasheet,
            true,
        );
        let zeta = self.number(
            "angle_observer.damping",
            &o.damping,
            0.0,
            10.0,
            "a damping ratio ζ with 0 < ζ < 10, e.g. 1.0",
        );
        let lead = match &o.lead_samples {
            Some(v) => self.number(
                "angle_observer.lead_samples",
                v,
                -1e-12,
                10.0,
                "a delay in samples from 0 to 10, e.g. 1.5 (thesis A §4.6)",
            ),
            None => Some(Param {
                value: 1.5,
                source: Provenance::Default,
                key: "angle_observer.lead_samples".into(),
                span: raw.angle_observer.span(),
                note: Some("T_delay = 1.5·T_s (thesis A §4.6)".into()),
            }),
        };
        Some(ObserverSpec {
            natural_frequency: wn?,
            damping: zeta?,
            error: *o.error.get_ref(),
            lead_samples: lead?,
        })
    }

    fn fir(&mut self, raw: &RawSpec) -> Option<FirSpec> {
        let f = raw.fir.get_ref();
        let pass_edge = self.quantity(
            "fir.pass_edge",
            &f.pass_edge,
            Kind::Frequency,
            Provenance::Datasheet,
            true,
        );
        let stop_edge = self.quantity(
            "fir.stop_edge",
            &f.stop_edge,
            Kind::Frequency,
            Provenance::Datasheet,
            true,
        );
        let pass_ripple = self.number(
            "fir.pass_ripple",
            &f.pass_ripple,
            0.0,
            0.5,
            "a relative pass-band deviation with 0 < ripple < 0.5, e.g. 0.001",
        );
        let order = f
            .order
            .as_ref()
            .and_then(|v| {
                self.integer(
                    "fir.order",
                    v,
                    2,
                    126,
                    "a whole filter order from 2 to 126 (the STM32G474 FMAC holds at most 127 taps)",
                )
            })
            .map(|(i, p)| (i as usize, p));
        let stop_attenuation = f
            .stop_attenuation
            .as_ref()
            .and_then(|v| self.quantity("fir.stop_attenuation", v, Kind::Decibel, Provenance::Datasheet, true));
        let span = raw.fir.span();
        match (&f.order, &f.stop_attenuation) {
            (None, None) => self.err(
                span.clone(),
                "fir.order",
                "[fir] gives neither `order` nor `stop_attenuation`",
                "order = 20, or stop_attenuation = \"40 dB\" for the minimum order that meets it",
            ),
            (Some(_), Some(a)) => self.err(
                a.span(),
                "fir.stop_attenuation",
                "[fir] gives both `order` and `stop_attenuation`",
                "one of them: `order` fixes the length, `stop_attenuation` asks for the minimum order",
            ),
            _ => {}
        }
        Some(FirSpec {
            pass_edge: pass_edge?,
            stop_edge: stop_edge?,
            pass_ripple: pass_ripple?,
            order,
            stop_attenuation,
            span,
        })
    }

    fn adc(&mut self, a: &raw::RawAdc) -> Option<AdcSpec> {
        let bits = match &a.resolution_bits {
            Some(v) => self
                .integer(
                    "adc.resolution_bits",
                    v,
                    6,
                    16,
                    "an ADC resolution from 6 to 16 bits, e.g. 12",
                )
                .map(|(i, _)| i as u32),
            None => Some(12),
        };
        Some(AdcSpec {
            resolution_bits: bits?,
            clock: self.quantity("adc.clock", &a.clock, Kind::Frequency, Provenance::Datasheet, true)?,
            sample_capacitance: self.quantity(
                "adc.sample_capacitance",
                &a.sample_capacitance,
                Kind::Capacitance,
                Provenance::Datasheet,
                true,
            )?,
            switch_resistance: self.quantity(
                "adc.switch_resistance",
                &a.switch_resistance,
                Kind::Resistance,
                Provenance::Datasheet,
                true,
            )?,
            source_resistance: self.quantity(
                "adc.source_resistance",
                &a.source_resistance,
                Kind::Resistance,
                Provenance::Datasheet,
                true,
            )?,
        })
    }

    fn thermal(&mut self, t: &raw::RawThermal) -> Option<ThermalSpec> {
        let reference_temperature = match &t.reference_temperature {
            Some(v) => self.quantity(
                "thermal.reference_temperature",
                v,
                Kind::TemperatureCelsius,
                Provenance::Datasheet,
                false,
            ),
            None => Some(Param {
                value: 20.0,
                source: Provenance::Default,
                key: "thermal.reference_temperature".into(),
                span: 0..0,
                note: Some("T_0 = 20 °C (thesis B 2.24)".into()),
            }),
        };
        let max = self.quantity(
            "thermal.max_winding_temperature",
            &t.max_winding_temperature,
            Kind::TemperatureCelsius,
            Provenance::Datasheet,
            false,
        );
        for p in [&reference_temperature, &max].into_iter().flatten() {
            if p.value <= -235.0 {
                self.err(
                    p.span.clone(),
                    &p.key.clone(),
                    "temperature at or below −235 °C, where copper resistance (2.24) vanishes",
                    "a winding temperature above −235 °C",
                );
            }
        }
        Some(ThermalSpec {
            reference_temperature: reference_temperature?,
            max_winding_temperature: max?,
        })
    }

    fn inverter(&mut self, i: &raw::RawInverter) -> Option<InverterSpec> {
        Some(InverterSpec {
            part: i.part.clone(),
            nominal_current: self.quantity(
                "inverter.nominal_current",
                &i.nominal_current,
                Kind::Current,
                Provenance::Datasheet,
                true,
            )?,
            transistor_resistance: self.quantity(
                "inverter.transistor_resistance",
                &i.transistor_resistance,
                Kind::Resistance,
                Provenance::Datasheet,
                true,
            )?,
            transistor_threshold: self.quantity(
                "inverter.transistor_threshold",
                &i.transistor_threshold,
                Kind::Voltage,
                Provenance::Datasheet,
                true,
            )?,
            switching_energy: self.quantity(
                "inverter.switching_energy",
                &i.switching_energy,
                Kind::Energy,
                Provenance::Datasheet,
                true,
            )?,
            diode_resistance: self.quantity(
                "inverter.diode_resistance",
                &i.diode_resistance,
                Kind::Resistance,
                Provenance::Datasheet,
                true,
            )?,
            diode_threshold: self.quantity(
                "inverter.diode_threshold",
                &i.diode_threshold,
                Kind::Voltage,
                Provenance::Datasheet,
                true,
            )?,
            recovery_energy: self.quantity(
                "inverter.recovery_energy",
                &i.recovery_energy,
                Kind::Energy,
                Provenance::Datasheet,
                true,
            )?,
        })
    }
}
