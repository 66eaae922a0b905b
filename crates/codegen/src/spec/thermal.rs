//! `[thermal]`: the winding temperatures of the copper-resistance rule (thesis B 2.24).

use super::raw::RawThermal;
use super::resolve::ResolveContext;
use super::{Param, Provenance};
use crate::units::Kind;

/// Winding temperatures (thesis B 2.24).
#[derive(Debug, Clone, PartialEq)]
pub struct ThermalSpec {
    /// T_0 at which R_s was measured [°C] (default 20 °C as in thesis B).
    pub reference_temperature: Param,
    /// Upper winding temperature [°C].
    pub max_winding_temperature: Param,
}

impl ResolveContext<'_> {
    pub(super) fn thermal(&mut self, t: &RawThermal) -> Option<ThermalSpec> {
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
}
