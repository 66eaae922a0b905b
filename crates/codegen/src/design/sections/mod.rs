//! The sections of the [`super::Design`], one module each, named after the section it
//! returns (its key in the JSON form): each reads the resolved spec through [`Context`],
//! calls the computation modules of `design` (each computing one thing and citing its
//! equations), checks the design rules of its section (reporting a violation at the key
//! that caused it) and returns the section.
//!
//! [`super::design`] runs them in a fixed order, so diagnostics and warnings keep a
//! stable order; `board` runs last, on the motor's finished design ([`super::on_board`]).

pub(super) mod adc;
pub(super) mod angle_observer;
pub(super) mod board;
pub(super) mod current_loop;
pub(super) mod drive;
pub(super) mod field_weakening;
pub(super) mod fir;
pub(super) mod motor;
pub(super) mod per_unit;
pub(super) mod plausibility;
pub(super) mod scaling;
pub(super) mod sensorless;

use crate::diagnostic::{Diagnostic, Source};
use crate::spec::Spec;

/// What every section reads and where it reports.
pub(super) struct Context<'a> {
    /// The resolved spec.
    pub spec: &'a Spec,
    /// Its file and text, for located diagnostics.
    pub src: Source<'a>,
    /// Rules broken so far; the design fails if any.
    pub errors: Vec<Diagnostic>,
    /// Non-fatal observations so far.
    pub warnings: Vec<String>,
    /// The fraction of the THPWM linear range U_dc/√3 the board's duty limit leaves
    /// (`design::duty_limit`): 1 for a motor designed on its own or on a board with
    /// in-line sensing.
    pub usable_voltage_fraction: f64,
    /// The loop delay the current loop is designed for, in periods of T_s (the board's,
    /// `design::BoardTerms`).
    pub loop_delay_periods: f64,
    /// The angle lead the board's timing makes, in periods of T_s (`design::BoardTerms`).
    pub board_angle_lead_periods: f64,
    /// The resolver signals at the observer's input as a fraction of full scale (the
    /// board's, `design::BoardTerms`; 1 without a board).
    pub resolver_signal_gain: f64,
}

impl Context<'_> {
    /// The angle lead k (thesis A (4.23)) [periods of T_s]: the spec's
    /// `angle_observer.lead_samples`, or by default the board's (from its resolver's
    /// sample to the voltage's mean; 1.5 without a board, thesis A §4.6).
    pub fn angle_lead_periods(&self) -> f64 {
        let lead = &self.spec.angle_observer.lead_samples;
        if lead.source == crate::spec::Provenance::Default {
            self.board_angle_lead_periods
        } else {
            lead.value
        }
    }

    /// f_s [Hz].
    pub fn switching_frequency(&self) -> f64 {
        self.spec.drive.switching_frequency.value
    }

    /// The largest shaft acceleration [rad/s², mechanical] and its rule
    /// (`design::acceleration`).
    pub fn max_acceleration(&self) -> (f64, super::acceleration::AccelerationRule) {
        let m = &self.spec.motor;
        let v = |p: &Option<crate::spec::Param>| p.as_ref().map(|p| p.value);
        super::acceleration::max_acceleration(
            v(&self.spec.drive.max_acceleration),
            self.spec.drive.application,
            v(&m.peak_torque),
            v(&m.inertia),
            m.max_speed.value,
        )
    }

    /// A warning located at byte `span` of the spec, at `key`.
    pub fn warn(&mut self, span: std::ops::Range<usize>, key: &str, text: impl std::fmt::Display) {
        let w = self.src.warning(span, key, text);
        self.warnings.push(w);
    }

    /// A warning at `p`'s key and value.
    pub fn warn_at(&mut self, p: &crate::spec::Param, text: impl std::fmt::Display) {
        self.warn(p.span.clone(), &p.key.clone(), text);
    }

    /// The voltage the current loop and the field weakening may use \[V\]: the usable
    /// fraction of V_max = U_dc/√3 (thesis B (2.50), `design::duty_limit`) at the nominal
    /// U_dc.
    pub fn usable_voltage_v(&self) -> f64 {
        self.usable_voltage_fraction * self.spec.drive.dc_link_voltage.value / 3f64.sqrt()
    }

    /// f_e,max = n_p·n_max/60 [Hz] (Table 1.2).
    pub fn max_electrical_frequency(&self) -> f64 {
        let m = &self.spec.motor;
        super::sampling::max_electrical_frequency(m.pole_pairs, m.max_speed.value)
    }
}
