//! The request checked and normalised to cycles/sample.

use super::error::FirError;
use super::{FMAC_MAX_TAPS, FirLength, FirRequest, MIN_ORDER, MIN_PASS_EDGE_NORMALISED};

/// Validated request in normalised frequency (cycles/sample).
#[derive(Debug, Clone, Copy)]
pub(super) struct Spec {
    pub(super) fs: f64,
    /// Pass edge [Hz].
    pub(super) pass_hz: f64,
    /// Stop edge [Hz].
    pub(super) stop_hz: f64,
    /// pass_edge/f_s.
    pub(super) fp: f64,
    /// stop_edge/f_s.
    pub(super) fst: f64,
    pub(super) ripple: f64,
}

pub(super) fn validate(req: &FirRequest) -> Result<Spec, FirError> {
    for (key, value) in [
        ("sample_rate", req.sample_rate_hz),
        ("pass_edge", req.pass_edge_hz),
        ("stop_edge", req.stop_edge_hz),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(FirError::NotFinitePositive { key, value });
        }
    }
    if !(req.pass_ripple > 0.0 && req.pass_ripple < 0.5) {
        return Err(FirError::RippleOutOfRange {
            ripple: req.pass_ripple,
        });
    }
    let min_pass_hz = MIN_PASS_EDGE_NORMALISED * req.sample_rate_hz;
    if req.pass_edge_hz < min_pass_hz {
        return Err(FirError::PassEdgeTooLow {
            pass_edge_hz: req.pass_edge_hz,
            min_hz: min_pass_hz,
        });
    }
    let nyquist_hz = req.sample_rate_hz / 2.0;
    if req.pass_edge_hz >= nyquist_hz {
        return Err(FirError::BeyondNyquist {
            key: "pass_edge",
            edge_hz: req.pass_edge_hz,
            nyquist_hz,
        });
    }
    if req.pass_edge_hz >= req.stop_edge_hz {
        return Err(FirError::EdgesOutOfOrder {
            pass_edge_hz: req.pass_edge_hz,
            stop_edge_hz: req.stop_edge_hz,
        });
    }
    if req.stop_edge_hz >= nyquist_hz {
        return Err(FirError::BeyondNyquist {
            key: "stop_edge",
            edge_hz: req.stop_edge_hz,
            nyquist_hz,
        });
    }
    match req.length {
        FirLength::Order(order) => check_order(order)?,
        FirLength::StopAttenuationDb(value) => {
            if !(value.is_finite() && value > 0.0) {
                return Err(FirError::NotFinitePositive {
                    key: "stop_attenuation",
                    value,
                });
            }
        }
    }
    Ok(Spec {
        fs: req.sample_rate_hz,
        pass_hz: req.pass_edge_hz,
        stop_hz: req.stop_edge_hz,
        fp: req.pass_edge_hz / req.sample_rate_hz,
        fst: req.stop_edge_hz / req.sample_rate_hz,
        ripple: req.pass_ripple,
    })
}

fn check_order(order: usize) -> Result<(), FirError> {
    if (MIN_ORDER..FMAC_MAX_TAPS).contains(&order) {
        Ok(())
    } else {
        Err(FirError::OrderOutOfRange { order })
    }
}
