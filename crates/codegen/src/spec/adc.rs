//! `[adc]`: the sample-and-hold data of the settling rule (7.2)–(7.4).

use super::raw::RawAdc;
use super::resolve::ResolveContext;
use super::{Param, Provenance};
use crate::units::Kind;

/// The ADC sample-and-hold data (7.2), if given.
#[derive(Debug, Clone, PartialEq)]
pub struct AdcSpec {
    /// N bits.
    pub resolution_bits: u32,
    /// f_ADC \[Hz\].
    pub clock: Param,
    /// C_ADC \[F\].
    pub sample_capacitance: Param,
    /// R_ADC \[Ω\].
    pub switch_resistance: Param,
    /// R_EXT \[Ω\].
    pub source_resistance: Param,
}

impl ResolveContext<'_> {
    pub(super) fn adc(&mut self, a: &RawAdc) -> Option<AdcSpec> {
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
}
