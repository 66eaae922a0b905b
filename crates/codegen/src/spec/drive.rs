//! `[drive]`: the inverter operating point (switching frequency, DC-link voltage range, dead
//! time) and the largest shaft acceleration the drive must follow.

use super::raw::{Application, RawSpec};
use super::resolve::ResolveContext;
use super::{Param, Provenance};
use crate::units::Kind;

/// The resolved drive.
#[derive(Debug, Clone, PartialEq)]
pub struct Drive {
    /// f_s = switching = sampling frequency \[Hz\].
    pub switching_frequency: Param,
    /// Nominal DC-link voltage U_dc \[V\].
    pub dc_link_voltage: Param,
    /// Lowest DC-link voltage the controller must work at \[V\] (defaults to U_dc).
    pub dc_link_voltage_min: Param,
    /// Dead time \[s\], if given.
    pub dead_time: Option<Param>,
    /// Largest shaft acceleration |dω_m/dt| [rad/s², mechanical], if given
    /// (`design::acceleration` otherwise takes the application's default).
    pub max_acceleration: Option<Param>,
    /// What the drive moves (`drive.application`), `None` when not given (traction).
    pub application: Option<Application>,
}

impl ResolveContext<'_> {
    pub(super) fn drive(&mut self, raw: &RawSpec) -> Option<Drive> {
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
        let max_acceleration = self.opt_quantity(
            "drive.max_acceleration",
            d.max_acceleration.as_ref(),
            Kind::AngularAcceleration,
            true,
        );
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
            max_acceleration,
            application: d.application.as_ref().map(|a| *a.get_ref()),
        })
    }
}
