//! `[field_weakening]` and `[losses]`: inputs of the field-weakening and
//! loss-minimisation design rules (thesis B §2.3, chapter 3). Both sections are
//! optional; every key has a documented default or is optional.

use super::raw::RawSpec;
use super::{Param, Provenance, ResolveContext};
use crate::units::Kind;

/// Smallest accepted V'_max/V_max: below half the inverter's voltage the field-weakening
/// region starts at half the speed the inverter allows, and the gain α_fw·L/V'_max (2.57)
/// grows without bound as the fraction goes to zero.
pub const MIN_VOLTAGE_FRACTION: f64 = 0.5;
/// V'_max/V_max when `field_weakening.voltage_fraction` is not given: thesis B Fig. 2.15
/// ("V'_max is set to 0.9 pu", V_max = 1 pu).
pub const DEFAULT_VOLTAGE_FRACTION: f64 = 0.9;

/// The resolved field-weakening and loss inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldWeakeningSpec {
    /// V'_max/V_max (default [`DEFAULT_VOLTAGE_FRACTION`]).
    pub voltage_fraction: Param,
    /// α_s [rad/s], if a speed loop is specified.
    pub speed_loop_bandwidth: Option<Param>,
    /// R_c \[Ω\] (thesis B Fig. 2.7, (3.4)), if given.
    pub core_resistance: Option<Param>,
    /// Whether the loss minimum includes the inverter losses (3.14).
    pub include_inverter: bool,
}

impl ResolveContext<'_> {
    pub(super) fn field_weakening(&mut self, raw: &RawSpec) -> Option<FieldWeakeningSpec> {
        let fw = raw.field_weakening.as_ref().map(|s| s.get_ref());
        let losses = raw.losses.as_ref().map(|s| s.get_ref());
        let voltage_fraction = match fw.and_then(|f| f.voltage_fraction.as_ref()) {
            Some(v) => self.number(
                "field_weakening.voltage_fraction",
                v,
                MIN_VOLTAGE_FRACTION - 1e-12,
                1.0,
                "a fraction V'_max/V_max from 0.5 to below 1, e.g. 0.9 (thesis B Fig. 2.15); V'_max must stay below the inverter's V_max (2.55), and below half of it the field-weakening gain α_fw·L/V'_max (2.57) grows without bound",
            ),
            None => Some(Param {
                value: DEFAULT_VOLTAGE_FRACTION,
                source: Provenance::Default,
                key: "field_weakening.voltage_fraction".into(),
                span: 0..0,
                note: Some("V'_max = 0.9·V_max (thesis B Fig. 2.15)".into()),
            }),
        };
        let speed_loop_bandwidth = self.opt_quantity(
            "field_weakening.speed_loop_bandwidth",
            fw.and_then(|f| f.speed_loop_bandwidth.as_ref()),
            Kind::AngularFrequency,
            true,
        );
        let core_resistance = self.opt_quantity(
            "losses.core_resistance",
            losses.and_then(|l| l.core_resistance.as_ref()),
            Kind::Resistance,
            true,
        );
        let include_inverter = match losses.and_then(|l| l.include_inverter.as_ref()) {
            Some(b) if *b.get_ref() && raw.inverter.is_none() => {
                self.err(
                    b.span(),
                    "losses.include_inverter",
                    "include_inverter = true but the spec has no [inverter] section with the switch data (3.11)–(3.14)",
                    "an [inverter] section (nominal_current, transistor_/diode_resistance and _threshold, switching_energy, recovery_energy; thesis B Table B.3), or include_inverter = false",
                );
                false
            }
            Some(b) => *b.get_ref(),
            None => false,
        };
        Some(FieldWeakeningSpec {
            voltage_fraction: voltage_fraction?,
            speed_loop_bandwidth,
            core_resistance,
            include_inverter,
        })
    }
}
