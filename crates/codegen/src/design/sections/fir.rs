//! The FIR section: the `[fir]` request handed to [`crate::design::fir`], its errors
//! reported at the spec key they name; a filter of a given order that attenuates its stop
//! band by less than [`MIN_STOP_ATTENUATION_DB`] after quantisation is a warning at
//! `fir.order` naming the order that reaches it.

use super::Context;
use crate::design::fir::{self, FirDesign};

/// Quantised stop-band attenuation below which the identification filter is warned
/// about [dB]: 20 dB, a tenth of the stop-band amplitude left on the recorded step (thesis
/// A §6.2's filter reaches 27.8 dB at 20 kHz; the same order at 40 kHz reaches 8 dB).
pub const MIN_STOP_ATTENUATION_DB: f64 = 20.0;

/// The FMAC low-pass, or `None` with the error in `cx.errors`.
pub(in crate::design) fn fir(cx: &mut Context<'_>) -> Option<FirDesign> {
    let out = design(cx)?;
    let f = &cx.spec.fir;
    if let Some((n, p)) = &f.order
        && out.stop_attenuation_db_quantised < MIN_STOP_ATTENUATION_DB
    {
        // The order that reaches it, by the same search `stop_attenuation` runs.
        let better = fir::design_fir(&fir::FirRequest {
            sample_rate_hz: cx.switching_frequency(),
            pass_edge_hz: f.pass_edge.value,
            stop_edge_hz: f.stop_edge.value,
            pass_ripple: f.pass_ripple.value,
            length: fir::FirLength::StopAttenuationDb(MIN_STOP_ATTENUATION_DB),
        })
        .ok();
        let fix = match better {
            Some(b) => format!(
                "order = {} (or stop_attenuation = \"{MIN_STOP_ATTENUATION_DB} dB\") reaches {:.1} dB",
                b.order, b.stop_attenuation_db_quantised
            ),
            None => "a higher order or wider band edges".to_string(),
        };
        let text = format!(
            "the identification FIR of order {n} attenuates its stop band (from {} Hz at f_s = {} Hz) by only {:.1} dB after Q1.15 quantisation, less than {MIN_STOP_ATTENUATION_DB} dB: the recorded steps keep {:.0} % of the noise above the stop edge; {fix}",
            f.stop_edge.value,
            cx.switching_frequency(),
            out.stop_attenuation_db_quantised,
            100.0 * 10f64.powf(-out.stop_attenuation_db_quantised / 20.0)
        );
        cx.warn(p.span.clone(), &p.key.clone(), text);
    }
    Some(out)
}

/// The `[fir]` request through [`fir::design_fir`], its error at its key.
fn design(cx: &mut Context<'_>) -> Option<FirDesign> {
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
