//! The FIR section: the `[fir]` request handed to [`crate::design::fir`], its errors
//! reported at the spec key they name.

use super::Context;
use crate::design::fir::{self, FirDesign};

/// The FMAC low-pass, or `None` with the error in `cx.errors`.
pub(in crate::design) fn fir(cx: &mut Context<'_>) -> Option<FirDesign> {
    let f = &cx.spec.fir;
    let request = fir::FirRequest {
        sample_rate_hz: cx.switching_frequency(),
        pass_edge_hz: f.pass_edge.value,
        stop_edge_hz: f.stop_edge.value,
        pass_ripple: f.pass_ripple.value,
        length: match (&f.order, &f.stop_attenuation) {
            (Some((n, _)), _) => fir::FirLength::Order(*n),
            (None, Some(a)) => fir::FirLength::StopAttenuationDb(a.value),
            (None, None) => fir::FirLength::Order(0),
        },
    };
    fir::design_fir(&request)
        .map_err(|e| {
            let (span, key) = match e.key() {
                "pass_edge" => (f.pass_edge.span.clone(), f.pass_edge.key.clone()),
                "stop_edge" | "sample_rate" => (f.stop_edge.span.clone(), f.stop_edge.key.clone()),
                "pass_ripple" => (f.pass_ripple.span.clone(), f.pass_ripple.key.clone()),
                "stop_attenuation" => f
                    .stop_attenuation
                    .as_ref()
                    .map_or((f.span.clone(), "fir.stop_attenuation".into()), |a| {
                        (a.span.clone(), a.key.clone())
                    }),
                _ => f.order.as_ref().map_or((f.span.clone(), "fir.order".into()), |(_, p)| {
                    (p.span.clone(), p.key.clone())
                }),
            };
            let text = e.to_string();
            let (problem, accepted) = text
                .split_once("; accepted: ")
                .map_or((text.clone(), "see the message".to_string()), |(a, b)| {
                    (a.to_string(), b.to_string())
                });
            cx.errors.push(cx.src.error(span, key, problem, accepted));
        })
        .ok()
}
