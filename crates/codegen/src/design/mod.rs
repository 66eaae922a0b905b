//! The design: every constant the controller needs, computed from a resolved [`Spec`].
//!
//! Each submodule computes one thing and cites its equation. [`design()`] assembles
//! them through `step`, one step per section of the [`Design`]; each step applies its
//! design-rule checks and reports violations at the key that caused them.

pub mod acceleration;
pub mod adc;
pub mod angle_observer;
pub mod cross_check;
pub mod current_loop;
pub mod dead_time;
pub mod designed_response;
pub mod discrete_loop;
pub mod sampled_loop;

pub mod field_weakening;
pub mod finite;
pub mod fir;
pub mod loss_minimisation;
pub mod modulation;
pub mod per_unit;
pub mod sampling;
pub mod scaling;
pub mod sensorless;
mod step;
pub mod thermal;

use serde::Serialize;

use crate::diagnostic::{Diagnostics, Source};
use crate::spec::Spec;
use step::Context;
pub use step::adc::AdcOut;
pub use step::angle_observer::ObserverOut;
pub use step::current_loop::{CurrentLoopOut, FeedForward, HotVariant};
pub use step::drive::DriveOut;
pub use step::motor::{MotorOut, Origin};
pub use step::per_unit::PerUnitOut;
pub use step::scaling::ScalingsOut;

/// Version of the design's JSON form (`motorgen design --format json`): raised whenever
/// a key is removed or renamed or changes meaning or unit, so that a consumer can refuse
/// a form it does not know. New keys do not raise it.
pub const SCHEMA_VERSION: u32 = 1;

/// Every constant of one motor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Design {
    /// [`SCHEMA_VERSION`] of this form (the first key of the JSON).
    pub schema_version: u32,
    /// Spec file as given.
    pub spec_file: String,
    /// Motor name.
    pub name: String,
    /// Motor values.
    pub motor: MotorOut,
    /// Drive values.
    pub drive: DriveOut,
    /// Current loop.
    pub current_loop: CurrentLoopOut,
    /// Angle tracking observer.
    pub angle_observer: ObserverOut,
    /// Fixed-point scalings.
    pub scaling: ScalingsOut,
    /// Thesis-B per-unit system: every base the spec determines (Appendix A).
    pub per_unit: PerUnitOut,
    /// FIR low-pass for identification.
    pub fir: fir::FirDesign,
    /// Modulator.
    pub modulation: modulation::Modulation,
    /// ADC.
    pub adc: AdcOut,
    /// Field weakening and MTPA / loss-minimising tables (thesis B §2.3, ch. 3), if ψ_M is known.
    pub field_weakening: Option<field_weakening::FieldWeakeningOut>,
    /// Sensorless estimator (thesis B chapter 4), when ψ_M is known.
    pub sensorless: Option<sensorless::SensorlessOut>,
    /// The inverter board's values with this motor (`crate::design_with_board`); `None`
    /// for a motor designed on its own.
    pub board: Option<crate::board::design::BoardOut>,
    /// Non-fatal observations.
    pub warnings: Vec<String>,
}

/// Computes the design, or every rule it breaks, each at its key; a design with a
/// non-finite number is never returned ([`finite`]).
pub fn design(spec: &Spec, src: Source<'_>) -> Result<Design, Diagnostics> {
    let mut cx = Context {
        spec,
        src,
        errors: Vec::new(),
        warnings: Vec::new(),
    };
    let drive = step::drive::drive(&mut cx);
    let current_loop = step::current_loop::current_loop(&mut cx);
    let angle_observer = step::angle_observer::angle_observer(&mut cx);
    let fir = step::fir::fir(&mut cx);
    let adc = step::adc::adc(&mut cx);
    let field_weakening = step::field_weakening::field_weakening(&mut cx, current_loop.as_ref());
    let (true, Some(current_loop), Some(angle_observer), Some(fir)) =
        (cx.errors.is_empty(), current_loop, angle_observer, fir)
    else {
        return Err(Diagnostics(cx.errors));
    };
    let motor = step::motor::motor(&mut cx, current_loop.hot.as_ref().map(|h| h.phase_resistance_ohm));
    let per_unit = step::per_unit::per_unit(spec);
    let sensorless = match step::sensorless::sensorless(&cx, &per_unit) {
        Ok((out, notes)) => {
            cx.warnings.extend(notes);
            out
        }
        Err(e) => return Err(Diagnostics(vec![*e])),
    };
    let design = Design {
        schema_version: SCHEMA_VERSION,
        spec_file: src.file.to_string(),
        name: spec.name.clone(),
        motor,
        drive,
        current_loop,
        angle_observer,
        scaling: step::scaling::scalings(spec),
        per_unit,
        fir,
        modulation: modulation::modulation(spec.drive.dc_link_voltage.value, spec.drive.dc_link_voltage_min.value),
        adc,
        field_weakening,
        sensorless,
        board: None,
        warnings: cx.warnings,
    };
    finite::check(&design, spec, src).map_err(|e| Diagnostics(vec![*e]))?;
    Ok(design)
}
