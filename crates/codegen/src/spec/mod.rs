//! The motor spec: TOML text → SI values with provenance, or located diagnostics.
//!
//! Parsing is two passes. `raw` mirrors the file (unknown keys are errors; its
//! syntax and shape errors are rewritten by `syntax`); `resolve` applies units,
//! ranges and the merge rule: `[motor.identified]` overrides `[motor.datasheet]` key
//! by key, and ψ_M may be derived from K_t or K_e (thesis A 2.34). Each section is
//! resolved in the module named after it. Nothing here does file I/O.

mod adc;
mod angle_observer;
mod current_loop;
mod drive;
mod field_weakening;
mod fir;
mod flux_linkage;
mod inductance;
mod inverter;
mod motor;
mod plausible;
mod raw;
mod resolve;
mod resolver;
mod sensorless;
mod syntax;
mod thermal;
mod winding;

use std::ops::Range;

use serde::Serialize;

use crate::diagnostic::{Diagnostics, Source};
pub use adc::AdcSpec;
pub use angle_observer::ObserverSpec;
pub use current_loop::CurrentLoopSpec;
pub use drive::Drive;
pub use field_weakening::{DEFAULT_VOLTAGE_FRACTION, FieldWeakeningSpec};
pub use fir::FirSpec;
pub use flux_linkage::FluxSource;
pub use inverter::InverterSpec;
pub use motor::{Harmonics, Motor};
use raw::RawSpec;
pub(crate) use raw::Val;
pub use raw::{Amplitude, Application, Between, Connection, Method, ObserverError, SpeedAxis};
pub(crate) use resolve::ResolveContext;
pub use resolver::Resolver;
pub use sensorless::{DEFAULT_ANGLE_ERROR_DEG, DEFAULT_RESISTANCE_ERROR, SensorlessSpec, angle_error_rad};
pub use thermal::ThermalSpec;

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
    /// `[sensorless]` (thesis B chapter 4), if the spec has the section: only then is the
    /// estimator designed.
    pub sensorless: Option<SensorlessSpec>,
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
    let mut cx = ResolveContext::new(source);
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
    let de = toml::Deserializer::parse(source.text).map_err(|e| syntax::syntax_error(source, &e))?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        syntax::shape_error(source, &path, &inner, example)
    })
}
