//! Why no filter was designed, with the spec key to point at and what would be accepted.

use std::fmt;

use super::{FMAC_MAX_TAPS, FMAC_MEMORY_WORDS, MAX_ATTENUATION_DB, MAX_KAISER_DB, MIN_ORDER, MIN_PASS_EDGE_NORMALISED};

/// Why no filter was designed; [`FirError::key`] names the spec key to point at.
///
/// Every `Display` message has the form "`<what is wrong>; accepted: <what is accepted>`".
#[derive(Debug, Clone, PartialEq)]
pub enum FirError {
    /// An input is NaN, infinite, zero or negative.
    NotFinitePositive {
        /// Spec key.
        key: &'static str,
        /// The value given [Hz or dB].
        value: f64,
    },
    /// pass_edge ≥ stop_edge.
    EdgesOutOfOrder {
        /// Pass edge \[Hz\].
        pass_edge_hz: f64,
        /// Stop edge \[Hz\].
        stop_edge_hz: f64,
    },
    /// An edge at or beyond the Nyquist frequency f_s/2.
    BeyondNyquist {
        /// `"pass_edge"` or `"stop_edge"`.
        key: &'static str,
        /// The edge \[Hz\].
        edge_hz: f64,
        /// f_s/2 \[Hz\].
        nyquist_hz: f64,
    },
    /// pass_edge below 1e-6·f_s (`MIN_PASS_EDGE_NORMALISED`), where the exchange does not converge.
    PassEdgeTooLow {
        /// The pass edge given \[Hz\].
        pass_edge_hz: f64,
        /// The lowest accepted pass edge \[Hz\].
        min_hz: f64,
    },
    /// pass_ripple outside (0, 0.5) or NaN.
    RippleOutOfRange {
        /// The value given \[linear\].
        ripple: f64,
    },
    /// Order below [`MIN_ORDER`] or more taps than the FMAC holds.
    OrderOutOfRange {
        /// The order given [taps − 1].
        order: usize,
    },
    /// No stop weight at this order keeps the quantised pass-band deviation within the request.
    RippleInfeasible {
        /// Requested pass ripple \[linear\].
        requested: f64,
        /// Order [taps − 1].
        order: usize,
        /// Smallest quantised pass-band deviation reached at this order, if any design quantised \[linear\].
        best: Option<f64>,
    },
    /// The design meeting the ripple at this order does not attenuate the stop band at all.
    NoAttenuation {
        /// Order [taps − 1].
        order: usize,
        /// Requested pass ripple \[linear\].
        ripple: f64,
        /// Achieved quantised stop-band attenuation \[dB\].
        attenuation_db: f64,
    },
    /// The order is so high for these band edges that the equiripple design falls below f64 resolution.
    OrderBeyondPrecision {
        /// The order given [taps − 1].
        order: usize,
        /// Highest order designable for these band edges [taps − 1].
        max_order: usize,
        /// Kaiser's −10·log10(δ_p·δ_s) at the given order \[dB\].
        kaiser_db: f64,
    },
    /// More attenuation than Q1.15 taps can hold.
    AttenuationBeyondQ15 {
        /// Requested attenuation \[dB\].
        requested_db: f64,
    },
    /// No order up to the FMAC limit meets the requested attenuation.
    AttenuationInfeasible {
        /// Longest filter tried \[taps\].
        taps: usize,
        /// Requested attenuation \[dB\].
        requested_db: f64,
        /// Best quantised attenuation at 127 taps within the pass ripple, if that design exists \[dB\].
        best_db: Option<f64>,
    },
    /// The minimum-order walk stopped: the quantised attenuation stopped improving
    /// (`STALL_ORDERS` = 6 orders without progress), the Q1.15 floor.
    AttenuationFloor {
        /// Requested attenuation \[dB\].
        requested_db: f64,
        /// Order with the best quantised attenuation [taps − 1].
        order: usize,
        /// Last order tried [taps − 1].
        last_order: usize,
        /// Best quantised attenuation at `order` within the pass ripple, if that design exists \[dB\].
        best_db: Option<f64>,
    },
    /// A tap falls outside the Q1.15 range [−1, 1 − 2^−15].
    TapOverflow {
        /// Order [taps − 1].
        order: usize,
        /// The offending tap \[1\].
        tap: f64,
    },
    /// The Parks–McClellan exchange failed (numerically degenerate bands).
    Remez {
        /// Order [taps − 1].
        order: usize,
        /// What `pm-remez` reported.
        message: String,
    },
}

impl FirError {
    /// The spec key (one of "pass_edge", "stop_edge", "pass_ripple", "order",
    /// "stop_attenuation", "sample_rate") the error belongs to, so the caller can point at its line.
    pub fn key(&self) -> &'static str {
        match self {
            FirError::NotFinitePositive { key, .. } | FirError::BeyondNyquist { key, .. } => key,
            FirError::EdgesOutOfOrder { .. } => "stop_edge",
            FirError::RippleOutOfRange { .. } | FirError::RippleInfeasible { .. } => "pass_ripple",
            FirError::OrderOutOfRange { .. } | FirError::NoAttenuation { .. } | FirError::Remez { .. } => "order",
            FirError::OrderBeyondPrecision { .. } => "order",
            FirError::AttenuationInfeasible { .. }
            | FirError::AttenuationBeyondQ15 { .. }
            | FirError::AttenuationFloor { .. } => "stop_attenuation",
            FirError::TapOverflow { .. } | FirError::PassEdgeTooLow { .. } => "pass_edge",
        }
    }
}

/// "12 kHz", "100 Hz", "NaN Hz".
fn hz(v: f64) -> String {
    if v.is_finite() && v.abs() >= 1000.0 {
        format!("{} kHz", v / 1000.0)
    } else {
        format!("{v} Hz")
    }
}

impl fmt::Display for FirError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FirError::NotFinitePositive { key, value } => {
                let (unit, what) = match *key {
                    "stop_attenuation" => (" dB", "an attenuation above 0 dB"),
                    "sample_rate" => (" Hz", "a sampling frequency above 0 Hz"),
                    _ => (" Hz", "a frequency above 0 Hz"),
                };
                write!(
                    f,
                    "{key} {value}{unit} is not a finite positive number; accepted: {what}"
                )
            }
            FirError::EdgesOutOfOrder {
                pass_edge_hz,
                stop_edge_hz,
            } => write!(
                f,
                "stop_edge {} is not above pass_edge {}; accepted: pass_edge < stop_edge < f_s/2",
                hz(*stop_edge_hz),
                hz(*pass_edge_hz)
            ),
            FirError::BeyondNyquist {
                key,
                edge_hz,
                nyquist_hz,
            } => write!(
                f,
                "{key} {} is at or beyond the Nyquist frequency {}; accepted: pass_edge < stop_edge < f_s/2",
                hz(*edge_hz),
                hz(*nyquist_hz)
            ),
            FirError::PassEdgeTooLow { pass_edge_hz, min_hz } => write!(
                f,
                "pass_edge {} is below {MIN_PASS_EDGE_NORMALISED:e}·f_s = {}: the Parks–McClellan exchange does not converge on so narrow a pass band; accepted: {} ≤ pass_edge < stop_edge < f_s/2",
                hz(*pass_edge_hz),
                hz(*min_hz),
                hz(*min_hz)
            ),
            FirError::RippleOutOfRange { ripple } => write!(
                f,
                "pass_ripple {ripple} is outside (0, 0.5); accepted: a relative pass-band deviation 0 < pass_ripple < 0.5, e.g. 0.001"
            ),
            FirError::OrderOutOfRange { order } if *order < MIN_ORDER => write!(
                f,
                "order {order} is below the minimum {MIN_ORDER}; accepted: {MIN_ORDER} ≤ order ≤ {}",
                FMAC_MAX_TAPS - 1
            ),
            FirError::OrderOutOfRange { order } => write!(
                f,
                "order {order} needs {} taps but the STM32G474 FMAC holds at most {FMAC_MAX_TAPS} (an N-tap FIR uses 2N + 1 ≤ {FMAC_MEMORY_WORDS} words of local memory); accepted: {MIN_ORDER} ≤ order ≤ {}",
                order.saturating_add(1),
                FMAC_MAX_TAPS - 1
            ),
            FirError::RippleInfeasible {
                requested,
                order,
                best: Some(best),
            } => write!(
                f,
                "pass_ripple {requested} cannot be met by a Q1.15 filter of order {order}; the smallest ripple reached at this order is {best:.3e}; accepted: pass_ripple ≥ {best:.3e}, or a higher order"
            ),
            FirError::RippleInfeasible {
                requested,
                order,
                best: None,
            } => write!(
                f,
                "pass_ripple {requested} cannot be met by a Q1.15 filter of order {order}; accepted: a larger pass_ripple or a higher order"
            ),
            FirError::NoAttenuation {
                order,
                ripple,
                attenuation_db,
            } => write!(
                f,
                "order {order} with pass_ripple {ripple} leaves no stop-band attenuation ({attenuation_db:.2} dB); accepted: a higher order, a larger pass_ripple or a wider transition band"
            ),
            FirError::OrderBeyondPrecision {
                order,
                max_order,
                kaiser_db,
            } => write!(
                f,
                "order {order} is far more than these band edges need: Kaiser's estimate puts −10·log10(δp·δs) at {kaiser_db:.0} dB, beyond the {MAX_KAISER_DB} dB a double-precision Parks–McClellan design resolves (Q1.15 taps hold about {MAX_ATTENUATION_DB} dB anyway); accepted: {MIN_ORDER} ≤ order ≤ {max_order} for these band edges"
            ),
            FirError::AttenuationBeyondQ15 { requested_db } => write!(
                f,
                "stop_attenuation {requested_db} dB is more than Q1.15 taps can hold (rounding each tap by up to 2^−16 leaves a stop-band floor near −90 dB); accepted: 0 < stop_attenuation ≤ {MAX_ATTENUATION_DB} dB"
            ),
            FirError::AttenuationInfeasible {
                taps,
                requested_db,
                best_db: Some(best),
            } => write!(
                f,
                "stop_attenuation {requested_db} dB needs more than {taps} taps (the FMAC holds at most {FMAC_MAX_TAPS}; best at {taps} taps: {best:.1} dB); accepted: stop_attenuation ≤ {:.1} dB, a wider transition band or a larger pass_ripple",
                (best * 10.0).floor() / 10.0
            ),
            FirError::AttenuationInfeasible {
                taps,
                requested_db,
                best_db: None,
            } => write!(
                f,
                "stop_attenuation {requested_db} dB cannot be met within {taps} taps (the FMAC holds at most {FMAC_MAX_TAPS}), and no {taps}-tap design meets pass_ripple; accepted: a lower stop_attenuation, a wider transition band or a larger pass_ripple"
            ),
            FirError::AttenuationFloor {
                requested_db,
                order,
                last_order,
                best_db: Some(best),
            } => write!(
                f,
                "stop_attenuation {requested_db} dB is below the Q1.15 rounding floor of these band edges: the quantised attenuation peaks at {0:.1} dB (order {order}) and orders up to {last_order} add only rounding noise; accepted: stop_attenuation ≤ {0:.1} dB, a wider transition band or a larger pass_ripple",
                (best * 10.0).floor() / 10.0
            ),
            FirError::AttenuationFloor {
                requested_db,
                order,
                last_order,
                best_db: None,
            } => write!(
                f,
                "stop_attenuation {requested_db} dB is below the Q1.15 rounding floor of these band edges: no design from order {order} to {last_order} improves the quantised attenuation, and none at order {order} meets pass_ripple; accepted: a lower stop_attenuation, a wider transition band or a larger pass_ripple"
            ),
            FirError::TapOverflow { order, tap } => write!(
                f,
                "the order-{order} design has a tap {tap:.5}, outside the Q1.15 range [−1, 1); accepted: band edges whose midpoint (pass_edge + stop_edge)/2 is well below f_s/2 (the centre tap is ≈ (pass_edge + stop_edge)/f_s)"
            ),
            FirError::Remez { order, message } => write!(
                f,
                "the Parks–McClellan design of order {order} failed ({message}); accepted: another order, or band edges not extremely close to 0 Hz, to each other or to f_s/2"
            ),
        }
    }
}

impl std::error::Error for FirError {}
