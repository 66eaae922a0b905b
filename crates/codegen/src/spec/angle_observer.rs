//! `[angle_observer]`: natural frequency, damping, error form and angle lead of the
//! angle-tracking observer (thesis A §4).

use super::raw::{ObserverError, RawSpec};
use super::resolve::ResolveContext;
use super::{Param, Provenance};
use crate::units::Kind;

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

impl ResolveContext<'_> {
    pub(super) fn observer(&mut self, raw: &RawSpec) -> Option<ObserverSpec> {
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
                note: Some(
                    "the board's delay from the resolver's sample to the voltage's mean; T_delay = 1.5·T_s without a board (thesis A §4.6)".into(),
                ),
            }),
        };
        Some(ObserverSpec {
            natural_frequency: wn?,
            damping: zeta?,
            error: *o.error.get_ref(),
            lead_samples: lead?,
        })
    }
}
