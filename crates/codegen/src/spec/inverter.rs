//! `[inverter]`: switch and diode loss data (thesis B Table B.3) for the loss model (3.11)–(3.14).

use super::raw::RawInverter;
use super::resolve::ResolveContext;
use super::{Param, Provenance};
use crate::units::Kind;

/// Inverter switch data (thesis B Table B.3).
#[derive(Debug, Clone, PartialEq)]
pub struct InverterSpec {
    /// Part name.
    pub part: Option<String>,
    /// I_c,nom \[A\].
    pub nominal_current: Param,
    /// r_CE \[Ω\].
    pub transistor_resistance: Param,
    /// V_CE0 \[V\].
    pub transistor_threshold: Param,
    /// E_on + E_off \[J\].
    pub switching_energy: Param,
    /// r_T \[Ω\].
    pub diode_resistance: Param,
    /// V_T0 \[V\].
    pub diode_threshold: Param,
    /// E_rr \[J\].
    pub recovery_energy: Param,
}

impl ResolveContext<'_> {
    pub(super) fn inverter(&mut self, i: &RawInverter) -> Option<InverterSpec> {
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
