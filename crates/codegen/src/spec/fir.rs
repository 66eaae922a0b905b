//! `[fir]`: band edges, ripple and either the order or the stop-band attenuation of the
//! identification low-pass (thesis A §6.2).

use std::ops::Range;

use super::raw::RawSpec;
use super::resolve::ResolveContext;
use super::{Param, Provenance};
use crate::units::Kind;

/// The resolved FIR request.
#[derive(Debug, Clone, PartialEq)]
pub struct FirSpec {
    /// Pass-band edge \[Hz\].
    pub pass_edge: Param,
    /// Stop-band edge \[Hz\].
    pub stop_edge: Param,
    /// Maximal relative pass-band deviation.
    pub pass_ripple: Param,
    /// Order, if given.
    pub order: Option<(usize, Param)>,
    /// Required stop-band attenuation \[dB\], if given.
    pub stop_attenuation: Option<Param>,
    /// Span of the `[fir]` table (for whole-section errors).
    pub span: Range<usize>,
}

impl ResolveContext<'_> {
    pub(super) fn fir(&mut self, raw: &RawSpec) -> Option<FirSpec> {
        let f = raw.fir.get_ref();
        let pass_edge = self.quantity(
            "fir.pass_edge",
            &f.pass_edge,
            Kind::Frequency,
            Provenance::Datasheet,
            true,
        );
        let stop_edge = self.quantity(
            "fir.stop_edge",
            &f.stop_edge,
            Kind::Frequency,
            Provenance::Datasheet,
            true,
        );
        let pass_ripple = self.number(
            "fir.pass_ripple",
            &f.pass_ripple,
            0.0,
            0.5,
            "a relative pass-band deviation with 0 < ripple < 0.5, e.g. 0.001",
        );
        let order = f
            .order
            .as_ref()
            .and_then(|v| {
                self.integer(
                    "fir.order",
                    v,
                    2,
                    126,
                    "a whole filter order from 2 to 126 (the STM32G474 FMAC holds at most 127 taps)",
                )
            })
            .map(|(i, p)| (i as usize, p));
        let stop_attenuation = f
            .stop_attenuation
            .as_ref()
            .and_then(|v| self.quantity("fir.stop_attenuation", v, Kind::Decibel, Provenance::Datasheet, true));
        let span = raw.fir.span();
        match (&f.order, &f.stop_attenuation) {
            (None, None) => self.err(
                span.clone(),
                "fir.order",
                "[fir] gives neither `order` nor `stop_attenuation`",
                "order = 20, or stop_attenuation = \"40 dB\" for the minimum order that meets it",
            ),
            (Some(_), Some(a)) => self.err(
                a.span(),
                "fir.stop_attenuation",
                "[fir] gives both `order` and `stop_attenuation`",
                "one of them: `order` fixes the length, `stop_attenuation` asks for the minimum order",
            ),
            _ => {}
        }
        Some(FirSpec {
            pass_edge: pass_edge?,
            stop_edge: stop_edge?,
            pass_ripple: pass_ripple?,
            order,
            stop_attenuation,
            span,
        })
    }
}
