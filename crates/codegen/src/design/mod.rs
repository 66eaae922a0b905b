//! The design: every constant the controller needs, computed from a resolved [`Spec`].
//!
//! Two layers. The computation modules (`current_loop`, `angle_observer`, `fir`, …)
//! each compute one thing and cite its equation; they read no spec file and report at
//! no key, so the proc-macros and `motor-verify` call them directly. Above them,
//! `sections` has one module per section of the [`Design`] (named after it): each reads
//! the resolved spec, applies its section's design-rule checks and reports violations
//! at the key that caused them. [`design()`] assembles the sections of a motor;
//! [`on_board()`] adds the section of a motor on an inverter board.

pub mod acceleration;
pub mod adc;
pub mod angle_observer;
pub mod cross_check;
pub mod current_loop;
pub mod dead_time;
pub mod duty_limit;

pub mod field_weakening;
pub mod finite;
pub mod fir;
pub mod loss_minimisation;
pub mod modulation;
pub mod per_unit;
pub mod sampling;
pub mod scaling;
mod sections;
pub mod sensorless;
pub mod thermal;

use serde::Serialize;

use crate::board::Board;
use crate::diagnostic::{Diagnostics, Source};
use crate::spec::Spec;
use sections::Context;
pub use sections::adc::AdcOut;
pub use sections::angle_observer::ObserverOut;
pub use sections::board::{
    BoardOut, MIN_USABLE_VOLTAGE_FRACTION, RESOLVER_SIGNAL_RATIO, Trip, TripSource, Trips, duty_limit_key,
    refuse_duty_limit, timing_of,
};
pub use sections::current_loop::{CurrentLoopOut, FeedForward, HotVariant};
pub use sections::drive::DriveOut;
pub use sections::motor::{MotorOut, Origin};
pub use sections::per_unit::PerUnitOut;
pub use sections::scaling::ScalingsOut;

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
    /// The inverter board's values with this motor ([`on_board()`]); `None` for a motor
    /// designed on its own.
    pub board: Option<BoardOut>,
    /// Non-fatal observations.
    pub warnings: Vec<String>,
}

/// Computes the design, or every rule it breaks, each at its key; a design with a
/// non-finite number is never returned ([`finite`]).
pub fn design(spec: &Spec, src: Source<'_>) -> Result<Design, Diagnostics> {
    design_on(spec, src, BoardTerms::NONE)
}

/// What a board imposes on a motor's design before its own section checks the pair
/// (`crate::design_with_board`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoardTerms {
    /// The largest duty its current sensing's sampling window leaves ([`duty_limit`]): the
    /// current loop's voltage limit and the field weakening's V_max are the usable
    /// fraction of U_dc/√3 it leaves ([`duty_limit::usable_voltage_fraction`]).
    pub max_duty: f64,
    /// The loop delay D its timing makes, in periods of T_s
    /// ([`timing_of`]): the current loop is designed for it
    /// ([`current_loop::discrete`]).
    pub loop_delay_periods: f64,
    /// The delay from its resolver sample to the voltage's mean, in periods of T_s
    /// ([`timing_of`]): the angle lead k (thesis A (4.23)) unless the spec sets
    /// `angle_observer.lead_samples`.
    pub angle_lead_periods: f64,
    /// The resolver signals at the observer's input as a fraction of full scale
    /// ([`crate::board::resolver_signal_gain`]): the trig-identity observer's gains are
    /// divided by it, so that its loop has the designed ω_n and ζ on the board (thesis A
    /// (4.10)).
    pub resolver_signal_gain: f64,
}

impl BoardTerms {
    /// No board: the whole linear range, thesis A §4.6's 1.5·T_s
    /// ([`current_loop::NOMINAL_LOOP_DELAY_PERIODS`]) and resolver signals at full scale.
    pub const NONE: BoardTerms = BoardTerms {
        max_duty: 1.0,
        loop_delay_periods: current_loop::NOMINAL_LOOP_DELAY_PERIODS,
        angle_lead_periods: current_loop::NOMINAL_LOOP_DELAY_PERIODS,
        resolver_signal_gain: 1.0,
    };
}

/// [`design()`] for a drive on a board with `terms`.
pub fn design_on(spec: &Spec, src: Source<'_>, terms: BoardTerms) -> Result<Design, Diagnostics> {
    let max_duty = terms.max_duty;
    let usable = duty_limit::usable_voltage_fraction(max_duty);
    let mut cx = Context {
        spec,
        src,
        errors: Vec::new(),
        warnings: Vec::new(),
        usable_voltage_fraction: usable,
        loop_delay_periods: terms.loop_delay_periods,
        board_angle_lead_periods: terms.angle_lead_periods,
        resolver_signal_gain: terms.resolver_signal_gain,
    };
    // The motor values against each other and the drive first: a value off by a unit
    // prefix is refused at its key before it makes the sections below fail confusingly.
    sections::plausibility::plausibility(&mut cx);
    if !cx.errors.is_empty() {
        return Err(failed(cx));
    }
    let drive = sections::drive::drive(&mut cx);
    let errors_before = cx.errors.len();
    let current_loop = sections::current_loop::current_loop(&mut cx);
    // A refused current loop (unstable, below its floors) has no ramp lag worth judging
    // the field weakening with: its rule would only add an error of nonsense numbers.
    let loop_refused = cx.errors.len() > errors_before;
    let angle_observer = sections::angle_observer::angle_observer(&mut cx);
    let fir = sections::fir::fir(&mut cx);
    let adc = sections::adc::adc(&mut cx);
    let field_weakening =
        sections::field_weakening::field_weakening(&mut cx, current_loop.as_ref().filter(|_| !loop_refused));
    let (true, Some(current_loop), Some(angle_observer), Some(fir)) =
        (cx.errors.is_empty(), current_loop, angle_observer, fir)
    else {
        return Err(failed(cx));
    };
    let motor = sections::motor::motor(&mut cx, current_loop.hot.as_ref().map(|h| h.phase_resistance_ohm));
    let per_unit = sections::per_unit::per_unit(spec);
    let sensorless = match sections::sensorless::sensorless(&cx, &per_unit) {
        Ok((out, notes)) => {
            cx.warnings.extend(notes);
            out
        }
        Err(e) => {
            cx.errors.push(*e);
            return Err(failed(cx));
        }
    };
    let design = Design {
        schema_version: SCHEMA_VERSION,
        spec_file: src.file.to_string(),
        name: spec.name.clone(),
        motor,
        drive,
        current_loop,
        angle_observer,
        scaling: sections::scaling::scalings(spec),
        per_unit,
        fir,
        modulation: modulation::modulation(
            spec.drive.dc_link_voltage.value,
            spec.drive.dc_link_voltage_min.value,
            max_duty,
            usable,
        ),
        adc,
        field_weakening,
        sensorless,
        board: None,
        warnings: cx.warnings,
    };
    finite::check(&design, spec, src).map_err(|e| Diagnostics(vec![*e]))?;
    Ok(design)
}

/// The errors of a design that fails, the first carrying the spec's cross-checks that
/// disagree as notes (a design that succeeds has them as warnings): a wrong value often
/// shows in a cross-check before it breaks a rule.
fn failed(cx: Context<'_>) -> Diagnostics {
    let notes = sections::plausibility::cross_check_notes(&cx);
    let mut errors = cx.errors;
    if let Some(first) = errors.first_mut() {
        first.notes.extend(notes);
    }
    Diagnostics(errors)
}

/// The motor's `design` on `board` (read from `board_src`): the board section (the
/// board's constants with this motor and the trips the image uses, see `sections::board`),
/// added to the design with its warnings; errors at the board keys where the motor does
/// not fit the board (current and DC-link sensing, power-stage ceilings, over-speed), or
/// where a board value comes out non-finite with this motor.
pub fn on_board(mut design: Design, board: &Board, board_src: Source<'_>) -> Result<Design, Diagnostics> {
    let (out, warnings) = sections::board::board(board, board_src, &design).map_err(Diagnostics)?;
    if let Some((path, x)) = finite::first_non_finite(&minijinja::Value::from(minijinja::value::Serde(&out))) {
        let keys = finite::deciding_board_keys(&path);
        let key = keys.first().copied().unwrap_or("");
        return Err(board_src
            .error(
                board.span(key),
                key,
                format!(
                    "the board design's `board.{path}` comes out as {x}: the board's values with this motor overflow f64 (decided by {})",
                    keys.join(", ")
                ),
                format!(
                    "board values in their physically sensible ranges, as in boards/{}.toml",
                    crate::board::DEFAULT_BOARD
                ),
            )
            .into());
    }
    design.warnings.extend(warnings);
    design.board = Some(out);
    Ok(design)
}
