//! Equiripple FIR low-pass for the STM32G474 FMAC (thesis A §6.2, RM0440 §17.3.7–17.3.8).
//!
//! # Source
//!
//! Thesis A §6.2 filters the blocked-rotor current response with a low-pass FIR
//! before estimating the motor resistance: pass band up to F_pass = 100 Hz with
//! maximal relative pass-band ripple D_pass = 0.001 ("to achieve unity
//! steady-state gain, required for precise estimation of motor resistance"),
//! frequencies above 2 kHz attenuated, f_s = 20 kHz, order 20. Linear phase
//! delays every component by order/2 samples: 10 samples = 0.5 ms, the delay the
//! thesis reads off its data tips. The coefficients are loaded into the FMAC.
//!
//! # Design
//!
//! Parks–McClellan (`pm-remez`), pass weight 1 and stop weight `w`, desired
//! response 1 on [0, pass_edge] and 0 on [stop_edge, f_s/2]. The DC gain is
//! built into the approximation rather than fixed afterwards: with x = cos ω
//! the zero-phase amplitude of an odd-length filter is written
//! A(ω) = 1 − (1 − cos ω)·Q(ω) (even length: A(ω) = cos(ω/2)·(1 − (1 − cos ω)·Q(ω))),
//! so A(0) = 1 exactly and the Remez exchange designs Q (a type-I filter 2 or 3
//! taps shorter) with the transformed desired response and weight. The whole
//! pass-band tolerance [1 − δ_p, 1 + δ_p] is then available instead of only half
//! of it, as it would be if an unconstrained design were rescaled to unit DC
//! gain. Orders 2 and 3 (where Q would have a single tap) fall back to an
//! unconstrained design divided by its DC gain.
//!
//! * Order given: at fixed order δ_p·δ_s is nearly constant and δ_p ≈ √(K·w),
//!   so a safeguarded secant search on ln w (at most [`MAX_WEIGHT_EVALUATIONS`]
//!   Remez runs) finds the largest stop weight whose *quantised* pass-band
//!   deviation is ≤ `pass_ripple`; the stop band gets everything else.
//! * Attenuation given: w = pass_ripple/δ_s with δ_s = 10^(−A/20); the order
//!   search starts from Kaiser's estimate minus 3 and walks up (or down, if
//!   that order already passes) to the lowest order whose quantised design
//!   meets both the ripple and A.
//!
//! Quantisation rounds to Q1.15, then forces Σ taps = 2^15 = 32768 (DC gain
//! exactly 1 on the FMAC) by moving symmetric pairs by ±1 each (or the centre
//! tap of an odd-length filter), largest rounding residual first, so the taps
//! stay exactly symmetric (linear phase). Ripple and attenuation are
//! re-measured on a dense grid ([`GRID_POINTS_PER_TAP`]·N + 1 points per band,
//! band edges included).
//!
//! # FMAC (RM0440 §17.3.7–17.3.8)
//!
//! Inputs, outputs and coefficients are q1.15 (i16); the accumulator is 26 bits,
//! q4.22, and wraps (it is not saturated); an optional gain of 0–42 dB (left
//! shift by 0–7) is applied at the output, which is then clipped to q1.15 if
//! CLIPEN is set or else truncated to its 16 low bits. An N-tap FIR needs
//! 2N + 1 of the 256 words of local memory, so N ≤ 127 ([`FMAC_MAX_TAPS`]).
//! See [`fmac_fir_output`] for the bit-level model this module assumes.

use std::f64::consts::PI;
use std::fmt;
use std::panic::{AssertUnwindSafe, catch_unwind};

use pm_remez::{Band, PMParameters, pm_remez};
use serde::Serialize;

/// Words of FMAC local memory (RM0440 §17.3.8) [16-bit words].
pub const FMAC_MEMORY_WORDS: usize = 256;
/// Largest tap count the FMAC holds: 2N + 1 ≤ 256 ⇒ N ≤ 127 [taps].
pub const FMAC_MAX_TAPS: usize = (FMAC_MEMORY_WORDS - 1) / 2;
/// Smallest accepted filter order [taps − 1].
pub const MIN_ORDER: usize = 2;
/// Q1.15 representation of 1.0 [LSB]; the quantised taps sum to exactly this.
pub const Q15_ONE: i32 = 1 << 15;
/// Dense-grid points per tap and per band used to measure ripple and attenuation [points/tap].
pub const GRID_POINTS_PER_TAP: usize = 64;
/// Upper bound on the Remez runs of the stop-weight search at a given order [runs].
pub const MAX_WEIGHT_EVALUATIONS: usize = 24;

/// How the filter length is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FirLength {
    /// Filter order (taps − 1) given by the user [taps − 1].
    Order(usize),
    /// Minimum order whose quantised design meets this stop-band attenuation [dB, positive].
    StopAttenuationDb(f64),
}

/// What the user asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct FirRequest {
    /// Sampling frequency f_s [Hz].
    pub sample_rate_hz: f64,
    /// Pass-band edge; the pass band is [0, pass_edge] [Hz].
    pub pass_edge_hz: f64,
    /// Stop-band edge; the stop band is [stop_edge, f_s/2] [Hz].
    pub stop_edge_hz: f64,
    /// Maximal relative pass-band deviation ||H| − 1| [linear, e.g. 0.001].
    pub pass_ripple: f64,
    /// Order or attenuation.
    pub length: FirLength,
}

/// The designed filter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FirDesign {
    /// Requested pass-band edge [Hz].
    pub pass_edge_hz: f64,
    /// Requested stop-band edge [Hz].
    pub stop_edge_hz: f64,
    /// Requested maximal pass-band deviation [linear].
    pub pass_ripple: f64,
    /// Filter order N − 1 [taps − 1].
    pub order: usize,
    /// Floating-point equiripple taps, symmetric, Σ = 1 (to f64 rounding) [1].
    pub taps: Vec<f64>,
    /// Q1.15 taps for the FMAC: symmetric, Σ = 32768 exactly (DC gain 1) [LSB of 2^−15].
    pub taps_q15: Vec<i16>,
    /// Achieved max ||H| − 1| over [0, pass_edge], float taps [linear].
    pub pass_ripple_design: f64,
    /// Same for the Q1.15 taps; ≤ the requested `pass_ripple` [linear].
    pub pass_ripple_quantised: f64,
    /// Achieved min attenuation −20·log10|H| over [stop_edge, f_s/2], float taps [dB].
    pub stop_attenuation_db_design: f64,
    /// Same for the Q1.15 taps [dB].
    pub stop_attenuation_db_quantised: f64,
    /// Group delay order/2 (exact, linear phase) [samples].
    pub group_delay_samples: f64,
    /// Group delay order/(2·f_s) [s].
    pub group_delay_s: f64,
    /// FMAC local-memory words used, 2N + 1 [16-bit words].
    pub fmac_memory_words: usize,
    /// Stop-band/pass-band weight ratio w of the Remez design [1].
    pub stop_weight: f64,
}

/// Why no filter was designed; [`FirError::key`] names the spec key to point at.
///
/// Every `Display` message has the form "<what is wrong>; accepted: <what is accepted>".
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
        /// Pass edge [Hz].
        pass_edge_hz: f64,
        /// Stop edge [Hz].
        stop_edge_hz: f64,
    },
    /// An edge at or beyond the Nyquist frequency f_s/2.
    BeyondNyquist {
        /// `"pass_edge"` or `"stop_edge"`.
        key: &'static str,
        /// The edge [Hz].
        edge_hz: f64,
        /// f_s/2 [Hz].
        nyquist_hz: f64,
    },
    /// pass_ripple outside (0, 0.5) or NaN.
    RippleOutOfRange {
        /// The value given [linear].
        ripple: f64,
    },
    /// Order below [`MIN_ORDER`] or more taps than the FMAC holds.
    OrderOutOfRange {
        /// The order given [taps − 1].
        order: usize,
    },
    /// No stop weight at this order keeps the quantised pass-band deviation within the request.
    RippleInfeasible {
        /// Requested pass ripple [linear].
        requested: f64,
        /// Order [taps − 1].
        order: usize,
        /// Smallest quantised pass-band deviation reached at this order, if any design quantised [linear].
        best: Option<f64>,
    },
    /// The design meeting the ripple at this order does not attenuate the stop band at all.
    NoAttenuation {
        /// Order [taps − 1].
        order: usize,
        /// Requested pass ripple [linear].
        ripple: f64,
        /// Achieved quantised stop-band attenuation [dB].
        attenuation_db: f64,
    },
    /// The order is so high for these band edges that the equiripple design falls below f64 resolution.
    OrderBeyondPrecision {
        /// The order given [taps − 1].
        order: usize,
        /// Highest order designable for these band edges [taps − 1].
        max_order: usize,
        /// Kaiser's −10·log10(δ_p·δ_s) at the given order [dB].
        kaiser_db: f64,
    },
    /// More attenuation than Q1.15 taps can hold.
    AttenuationBeyondQ15 {
        /// Requested attenuation [dB].
        requested_db: f64,
    },
    /// No order up to the FMAC limit meets the requested attenuation.
    AttenuationInfeasible {
        /// Longest filter tried [taps].
        taps: usize,
        /// Requested attenuation [dB].
        requested_db: f64,
        /// Best quantised attenuation at 127 taps within the pass ripple, if that design exists [dB].
        best_db: Option<f64>,
    },
    /// A tap falls outside the Q1.15 range [−1, 1 − 2^−15].
    TapOverflow {
        /// Order [taps − 1].
        order: usize,
        /// The offending tap [1].
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
            FirError::AttenuationInfeasible { .. } | FirError::AttenuationBeyondQ15 { .. } => "stop_attenuation",
            FirError::TapOverflow { .. } => "pass_edge",
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

/// Validated request in normalised frequency (cycles/sample).
#[derive(Debug, Clone, Copy)]
struct Spec {
    fs: f64,
    /// Pass edge [Hz].
    pass_hz: f64,
    /// Stop edge [Hz].
    stop_hz: f64,
    /// pass_edge/f_s.
    fp: f64,
    /// stop_edge/f_s.
    fst: f64,
    ripple: f64,
}

fn validate(req: &FirRequest) -> Result<Spec, FirError> {
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

/// Magnitude response |H(f)| = |Σ h[n]·e^(−j2πfn/f_s)| of arbitrary taps at `f_hz` [Hz]
/// for sample rate `fs_hz` [Hz]; returns a linear gain [1] (NaN for non-finite inputs).
pub fn magnitude(taps: &[f64], f_hz: f64, fs_hz: f64) -> f64 {
    let w = 2.0 * PI * f_hz / fs_hz;
    let (s, c) = (-w).sin_cos();
    // Horner in z^−1 = e^(−jω), from the last tap down.
    let (re, im) = taps.iter().rev().fold((0.0_f64, 0.0_f64), |(re, im), &h| {
        (re * c - im * s + h, re * s + im * c)
    });
    re.hypot(im)
}

/// Frequency grid of one band: for each point x = cos ω and cos(ω/2).
struct Grid {
    pass: Vec<(f64, f64)>,
    stop: Vec<(f64, f64)>,
}

impl Grid {
    /// `GRID_POINTS_PER_TAP`·N + 1 points per band, both band edges included.
    fn new(spec: &Spec, taps: usize) -> Grid {
        let k = GRID_POINTS_PER_TAP * taps.max(1);
        let band = |a: f64, b: f64| -> Vec<(f64, f64)> {
            (0..=k)
                .map(|i| {
                    let f = a + (b - a) * i as f64 / k as f64;
                    ((2.0 * PI * f).cos(), (PI * f).cos())
                })
                .collect()
        };
        Grid {
            pass: band(0.0, spec.fp),
            stop: band(spec.fst, 0.5),
        }
    }
}

/// Zero-phase amplitude A(ω) of symmetric taps at one grid point, by the
/// Chebyshev recurrence t_{k+1} = 2x·t_k − t_{k−1} over cos(kω) (odd length)
/// or cos((k − ½)ω) (even length).
fn amplitude(taps: &[f64], (x, half): (f64, f64)) -> f64 {
    let n = taps.len();
    let m = n / 2;
    let (mut sum, mut prev, mut cur) = if n % 2 == 1 {
        // A = h[m] + Σ_{k≥1} 2·h[m+k]·cos(kω); t_0 = 1, t_1 = x.
        (taps[m], 1.0, x)
    } else {
        // A = Σ_{k≥1} 2·h[m−1+k]·cos((k−½)ω); t_0 = cos(−ω/2), t_1 = cos(ω/2).
        (0.0, half, half)
    };
    let first = if n % 2 == 1 { m + 1 } else { m };
    for (i, &h) in taps[first..].iter().enumerate() {
        if i > 0 {
            let next = 2.0 * x * cur - prev;
            prev = cur;
            cur = next;
        }
        sum += 2.0 * h * cur;
    }
    sum
}

/// Max ||A| − 1| over the pass band.
fn pass_deviation(taps: &[f64], grid: &Grid) -> f64 {
    grid.pass
        .iter()
        .map(|&p| (amplitude(taps, p).abs() - 1.0).abs())
        .fold(0.0, f64::max)
}

/// Min −20·log10|A| over the stop band [dB] (capped at 300 dB).
fn stop_attenuation_db(taps: &[f64], grid: &Grid) -> f64 {
    let peak = grid.stop.iter().map(|&p| amplitude(taps, p).abs()).fold(0.0, f64::max);
    -20.0 * peak.max(1e-15).log10()
}

fn q15_to_f64(q: &[i16]) -> Vec<f64> {
    q.iter().map(|&t| f64::from(t) / f64::from(Q15_ONE)).collect()
}

/// Largest relative spread (max − min)/max of the error extrema accepted as converged [1].
const MAX_FLATNESS: f64 = 1e-2;

/// Runs the Parks–McClellan exchange for a symmetric filter of `num_taps` taps on
/// `bands` (cycles/sample), turning panics, NaN and an unlevelled ripple into errors.
fn remez<D, W>(num_taps: usize, bands: Vec<(f64, f64)>, desired: D, weight: W) -> Result<Vec<f64>, String>
where
    D: Fn(f64) -> f64,
    W: Fn(f64) -> f64,
{
    let bands = bands
        .into_iter()
        .map(|(a, b)| Band::new(a, b).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    let params = PMParameters::new(num_taps, bands, desired, weight).map_err(|e| e.to_string())?;
    // pm-remez unwraps comparisons that fail on NaN; keep a numerical breakdown an error, not a panic.
    let design = catch_unwind(AssertUnwindSafe(|| pm_remez::<f64, _>(&params)))
        .map_err(|_| "numerical breakdown in the Remez exchange".to_string())?
        .map_err(|e| e.to_string())?;
    if design.flatness.is_nan() || design.flatness > MAX_FLATNESS {
        return Err(format!(
            "the Remez exchange did not converge (ripple flatness {:.2e})",
            design.flatness
        ));
    }
    let h = design.impulse_response;
    if h.len() != num_taps || h.iter().any(|v| !v.is_finite()) {
        return Err("the Remez exchange returned non-finite taps".into());
    }
    Ok(h)
}

/// 2·sin²(πf) = 1 − cos 2πf without cancellation.
fn one_minus_cos(f: f64) -> f64 {
    let s = (PI * f).sin();
    2.0 * s * s
}

/// Equiripple taps of `num_taps` taps with stop weight `w`, A(0) = 1, symmetric, Σ = 1.
fn remez_taps(spec: &Spec, num_taps: usize, w: f64) -> Result<Vec<f64>, String> {
    let odd = num_taps % 2 == 1;
    // Length of Q: A = c·(1 − (1 − cos ω)·Q) has 2 (odd) or 3 (even) more taps than Q.
    let q_len = if odd {
        num_taps.saturating_sub(2)
    } else {
        num_taps.saturating_sub(3)
    };
    let (fp, fst) = (spec.fp, spec.fst);
    let mid = 0.5 * (fp + fst);
    let mut h = if q_len >= 3 {
        // Pass band for Q starts just above 0, where its weight (1 − cos ω) vanishes; A(0) = 1 by construction.
        let eps = 0.01 * fp;
        let stop_end = if odd {
            0.5
        } else {
            0.5 - (1e-4_f64).min(0.5 * (0.5 - fst))
        };
        // c = cos(πf) for even length (type II), 1 for odd.
        let c = move |f: f64| if odd { 1.0 } else { (PI * f).cos() };
        let desired = move |f: f64| {
            let s = one_minus_cos(f);
            if f < mid {
                // (c − 1)/(c·s); c − 1 = −2·sin²(πf/2).
                if odd { 0.0 } else { -one_minus_cos(0.5 * f) / (c(f) * s) }
            } else {
                1.0 / s
            }
        };
        let weight = move |f: f64| {
            let cs = c(f) * one_minus_cos(f);
            if f < mid { cs } else { w * cs }
        };
        let q = remez(q_len, vec![(eps, fp), (fst, stop_end)], desired, weight)?;
        // p = δ − q ∗ [−½, 1, −½]  (zero-phase: P = 1 − (1 − cos ω)·Q), length q_len + 2.
        let mut p = vec![0.0; q_len + 2];
        for (j, &qj) in q.iter().enumerate() {
            p[j] += 0.5 * qj;
            p[j + 1] -= qj;
            p[j + 2] += 0.5 * qj;
        }
        p[q_len.div_ceil(2)] += 1.0;
        if odd {
            p
        } else {
            // h = p ∗ [½, ½]  (zero-phase factor cos(ω/2)).
            let mut h = vec![0.0; q_len + 3];
            for (j, &pj) in p.iter().enumerate() {
                h[j] += 0.5 * pj;
                h[j + 1] += 0.5 * pj;
            }
            h
        }
    } else {
        // Orders 2 and 3: unconstrained design, rescaled to unit DC gain below.
        run_remez_plain(num_taps, fp, fst, w)?
    };
    // Exact symmetry, then Σ = 1.
    let n = h.len();
    for i in 0..n / 2 {
        let v = 0.5 * (h[i] + h[n - 1 - i]);
        h[i] = v;
        h[n - 1 - i] = v;
    }
    let sum: f64 = h.iter().sum();
    if !sum.is_finite() || sum.abs() < 1e-6 {
        return Err("the design has no DC gain".into());
    }
    h.iter_mut().for_each(|v| *v /= sum);
    for _ in 0..4 {
        let err = 1.0 - h.iter().sum::<f64>();
        if err == 0.0 {
            break;
        }
        if n % 2 == 1 {
            h[n / 2] += err;
        } else {
            h[n / 2 - 1] += 0.5 * err;
            h[n / 2] += 0.5 * err;
        }
    }
    Ok(h)
}

/// Plain two-band design (desired 1/0, weights 1/w) of any length ≥ 3, not normalised.
fn run_remez_plain(num_taps: usize, fp: f64, fst: f64, w: f64) -> Result<Vec<f64>, String> {
    let mid = 0.5 * (fp + fst);
    let desired = move |f: f64| if f < mid { 1.0 } else { 0.0 };
    let weight = move |f: f64| if f < mid { 1.0 } else { w };
    remez(num_taps, vec![(0.0, fp), (fst, 0.5)], desired, weight)
}

/// Rounds symmetric taps to Q1.15 and forces Σ = 32768 keeping h[n] = h[N−1−n].
///
/// The deficit 32768 − Σ round(h·2^15) is removed one step at a time: a symmetric
/// pair moves by ±1 each (2 LSB of sum) or, for odd N, the centre tap by ±1,
/// choosing the candidate whose rounding residual points furthest in the needed
/// direction. Returns `Err(tap)` with the offending value if a tap leaves i16.
fn quantise(taps: &[f64]) -> Result<Vec<i16>, f64> {
    let n = taps.len();
    let one = f64::from(Q15_ONE);
    let mut scaled: Vec<f64> = taps.iter().map(|h| h * one).collect();
    for i in 0..n / 2 {
        let v = 0.5 * (scaled[i] + scaled[n - 1 - i]);
        scaled[i] = v;
        scaled[n - 1 - i] = v;
    }
    if let Some(&bad) = scaled.iter().find(|v| !(v.is_finite() && v.abs() < 4.0 * one)) {
        return Err(bad / one);
    }
    // |scaled| < 2^17, so the casts are exact after rounding.
    let mut q: Vec<i64> = scaled.iter().map(|v| v.round() as i64).collect();
    let mut deficit = i64::from(Q15_ONE) - q.iter().sum::<i64>();
    let centre = (n % 2 == 1).then_some(n / 2);
    // Each step reduces |deficit| by 1 or 2; the bound only guards against a logic error.
    for _ in 0..(4 * n + 8) {
        if deficit == 0 {
            break;
        }
        let dir = deficit.signum();
        let residual = |i: usize| (scaled[i] - q[i] as f64) * dir as f64;
        let pick = if deficit.abs() == 1 {
            centre
        } else {
            (0..n / 2)
                .chain(centre)
                .max_by(|&a, &b| residual(a).total_cmp(&residual(b)))
        };
        let Some(i) = pick else { break };
        q[i] += dir;
        if Some(i) == centre {
            deficit -= dir;
        } else {
            q[n - 1 - i] += dir;
            deficit -= 2 * dir;
        }
    }
    if deficit != 0 {
        // Only reachable for an even N with an odd deficit, impossible as Σ of pairs is even.
        return Err(f64::NAN);
    }
    q.iter()
        .map(|&v| i16::try_from(v).map_err(|_| v as f64 / one))
        .collect()
}

/// One design at a fixed order and stop weight, quantised, with its quantised pass deviation.
struct Trial {
    weight: f64,
    taps: Vec<f64>,
    q15: Vec<i16>,
    ripple_q: f64,
}

fn trial(spec: &Spec, grid: &Grid, order: usize, weight: f64) -> Result<Trial, FirError> {
    let taps = remez_taps(spec, order + 1, weight).map_err(|message| FirError::Remez { order, message })?;
    let q15 = quantise(&taps).map_err(|tap| FirError::TapOverflow { order, tap })?;
    let ripple_q = pass_deviation(&q15_to_f64(&q15), grid);
    Ok(Trial {
        weight,
        taps,
        q15,
        ripple_q,
    })
}

fn finish(spec: &Spec, grid: &Grid, t: Trial) -> FirDesign {
    let qf = q15_to_f64(&t.q15);
    let order = t.taps.len() - 1;
    FirDesign {
        pass_edge_hz: spec.pass_hz,
        stop_edge_hz: spec.stop_hz,
        pass_ripple: spec.ripple,
        order,
        pass_ripple_design: pass_deviation(&t.taps, grid),
        pass_ripple_quantised: t.ripple_q,
        stop_attenuation_db_design: stop_attenuation_db(&t.taps, grid),
        stop_attenuation_db_quantised: stop_attenuation_db(&qf, grid),
        group_delay_samples: order as f64 / 2.0,
        group_delay_s: order as f64 / (2.0 * spec.fs),
        fmac_memory_words: 2 * (order + 1) + 1,
        stop_weight: t.weight,
        taps: t.taps,
        taps_q15: t.q15,
    }
}

/// Kaiser's estimate −10·log10(δ_p·δ_s) ≈ 14.6·Δf·N + 13 [dB], Δf = (stop_edge − pass_edge)/f_s.
fn kaiser_db(spec: &Spec, order: f64) -> f64 {
    14.6 * (spec.fst - spec.fp) * order + 13.0
}

/// Kaiser's −10·log10(δ_p·δ_s) [dB] above which an order is refused: the equiripple design
/// would need ripples near 1e−7 and below, where the f64 Remez exchange stalls (seen at
/// δ_s ≈ 5e−9); Q1.15 rounding caps the attenuation near 90 dB long before.
pub const MAX_KAISER_DB: f64 = 120.0;
/// Largest stop-band attenuation accepted in minimum-order mode [dB]; Q1.15 rounding
/// (±2^−16 per tap) leaves a floor near −90 dB.
pub const MAX_ATTENUATION_DB: f64 = 100.0;
/// Smallest ripple (pass or stop) the weight search lets the exact design aim for [linear].
const MIN_DESIGN_RIPPLE: f64 = 1e-6;

/// Highest order whose Kaiser estimate stays within [`MAX_KAISER_DB`], and within the FMAC [taps − 1].
fn max_order(spec: &Spec) -> usize {
    let n = (MAX_KAISER_DB - 13.0) / (14.6 * (spec.fst - spec.fp));
    if n.is_finite() && n < (FMAC_MAX_TAPS - 1) as f64 {
        (n.floor() as usize).max(MIN_ORDER)
    } else {
        FMAC_MAX_TAPS - 1
    }
}
/// Accept a weight once the quantised ripple is within this fraction below the request.
const RIPPLE_TOLERANCE: f64 = 0.02;

/// Fixed order: the largest stop weight whose quantised pass deviation is ≤ the request.
fn design_order(spec: &Spec, order: usize) -> Result<FirDesign, FirError> {
    let grid = Grid::new(spec, order + 1);
    let r = spec.ripple;
    let aim = (1.0 - 0.5 * RIPPLE_TOLERANCE).ln(); // target ln(ripple_q/R)
    // Kaiser: δ_p·δ_s = K = 10^(−K_dB/10) and w = δ_p/δ_s, so δ_p = √(K·w), δ_s = √(K/w).
    // Keep both ≥ MIN_DESIGN_RIPPLE: ln w ∈ [2·ln δ_min − ln K, ln K − 2·ln δ_min].
    let ln_k = -kaiser_db(spec, order as f64) * std::f64::consts::LN_10 / 10.0;
    let ln_w_max = ln_k - 2.0 * MIN_DESIGN_RIPPLE.ln();
    let ln_w_min = (2.0 * MIN_DESIGN_RIPPLE.ln() - ln_k).min(ln_w_max);
    // Start where δ_p = R: w = R²/K.
    let mut x = (2.0 * r.ln() - ln_k).clamp(ln_w_min, ln_w_max);
    let mut lo: Option<(f64, f64, Trial)> = None; // accepted: (ln w, ln(rq/R), trial), largest ln w
    let mut hi: Option<(f64, f64)> = None; // rejected: smallest ln w
    let mut last: Option<(f64, f64)> = None;
    let mut best_rq = f64::INFINITY;
    let mut last_err = None;
    for _ in 0..MAX_WEIGHT_EVALUATIONS {
        let tr = trial(spec, &grid, order, x.exp());
        let y = match tr {
            Ok(t) => {
                best_rq = best_rq.min(t.ripple_q);
                let y = (t.ripple_q / r).ln();
                if t.ripple_q <= r {
                    if lo.as_ref().is_none_or(|l| x > l.0) {
                        lo = Some((x, y, t));
                    }
                } else if hi.is_none_or(|h| x < h.0) {
                    hi = Some((x, y));
                }
                y
            }
            Err(e) => {
                last_err = Some(e);
                if hi.is_none_or(|h| x < h.0) {
                    hi = Some((x, f64::INFINITY));
                }
                f64::INFINITY
            }
        };
        // Local slope d ln(rq)/d ln w, ≈ ½ from δ_p ≈ √(K·w).
        let slope = match last {
            Some((xl, yl)) if y.is_finite() && yl.is_finite() && (x - xl).abs() > 1e-9 => {
                ((y - yl) / (x - xl)).clamp(0.1, 2.0)
            }
            _ => 0.5,
        };
        last = Some((x, y));
        x = match (&lo, hi) {
            (Some(l), _) if l.1 >= (1.0 - RIPPLE_TOLERANCE).ln() => break,
            (Some(l), Some(h)) => {
                let d = h.0 - l.0;
                if d < 1e-3 {
                    break;
                }
                let guess = if h.1.is_finite() && h.1 > l.1 {
                    l.0 + (aim - l.1) * d / (h.1 - l.1)
                } else {
                    l.0 + 0.5 * d
                };
                guess.clamp(l.0 + 0.1 * d, h.0 - 0.1 * d)
            }
            (Some(l), None) => {
                if l.0 >= ln_w_max {
                    break;
                }
                (l.0 + ((aim - l.1) / slope).clamp(0.01, 6.9)).min(ln_w_max)
            }
            (None, Some(h)) => {
                if h.0 <= ln_w_min {
                    break;
                }
                let step = if h.1.is_finite() {
                    ((aim - h.1) / slope).clamp(-6.9, -0.01)
                } else {
                    -2.3
                };
                (h.0 + step).max(ln_w_min)
            }
            (None, None) => break,
        };
    }
    match lo {
        Some((_, _, t)) => {
            let d = finish(spec, &grid, t);
            if d.stop_attenuation_db_quantised > 0.0 {
                Ok(d)
            } else {
                Err(FirError::NoAttenuation {
                    order,
                    ripple: r,
                    attenuation_db: d.stop_attenuation_db_quantised,
                })
            }
        }
        None if best_rq.is_finite() => Err(FirError::RippleInfeasible {
            requested: r,
            order,
            best: Some(best_rq),
        }),
        None => Err(last_err.unwrap_or(FirError::RippleInfeasible {
            requested: r,
            order,
            best: None,
        })),
    }
}

/// Fixed order and weight: the quantised design and whether it meets ripple and attenuation.
fn design_weighted(spec: &Spec, order: usize, weight: f64, attenuation_db: f64) -> Option<FirDesign> {
    let grid = Grid::new(spec, order + 1);
    let t = trial(spec, &grid, order, weight).ok()?;
    if t.ripple_q > spec.ripple {
        return None;
    }
    let d = finish(spec, &grid, t);
    (d.stop_attenuation_db_quantised >= attenuation_db).then_some(d)
}

/// Minimum order meeting `attenuation_db` with w = pass_ripple/δ_s.
fn design_min_order(spec: &Spec, attenuation_db: f64) -> Result<FirDesign, FirError> {
    let ds = 10f64.powf(-attenuation_db / 20.0);
    let weight = spec.ripple / ds;
    // Kaiser: N ≈ (−10·log10(δ_p·δ_s) − 13)/(14.6·Δf).
    let estimate = (-10.0 * (spec.ripple * ds).log10() - 13.0) / (14.6 * (spec.fst - spec.fp));
    if attenuation_db > MAX_ATTENUATION_DB {
        return Err(FirError::AttenuationBeyondQ15 {
            requested_db: attenuation_db,
        });
    }
    let max_order = max_order(spec);
    let start = if estimate.is_finite() {
        (estimate.floor() - 3.0).clamp(MIN_ORDER as f64, max_order as f64) as usize
    } else {
        max_order
    };
    if let Some(mut best) = design_weighted(spec, start, weight, attenuation_db) {
        // Already meets it: walk down to the first order that does not.
        for order in (MIN_ORDER..start).rev() {
            match design_weighted(spec, order, weight, attenuation_db) {
                Some(d) => best = d,
                None => break,
            }
        }
        return Ok(best);
    }
    for order in start + 1..=max_order {
        if let Some(d) = design_weighted(spec, order, weight, attenuation_db) {
            return Ok(d);
        }
    }
    let best_db = design_order(spec, max_order)
        .ok()
        .map(|d| d.stop_attenuation_db_quantised);
    Err(FirError::AttenuationInfeasible {
        taps: max_order + 1,
        requested_db: attenuation_db,
        best_db,
    })
}

/// Designs the FMAC low-pass the request describes (frequencies in Hz, ripple linear,
/// attenuation in dB); see the module documentation for the method.
pub fn design_fir(req: &FirRequest) -> Result<FirDesign, FirError> {
    let spec = validate(req)?;
    match req.length {
        FirLength::Order(order) if order > max_order(&spec) => Err(FirError::OrderBeyondPrecision {
            order,
            max_order: max_order(&spec),
            kaiser_db: kaiser_db(&spec, order as f64),
        }),
        FirLength::Order(order) => design_order(&spec, order),
        FirLength::StopAttenuationDb(a) => design_min_order(&spec, a),
    }
}

/// Bit-exact model of what the FMAC computes for one FIR output sample
/// (0 dB gain, CLIPEN set), in q1.15 [LSB of 2^−15].
///
/// `window` holds the most recent input samples, newest last; `taps_q15[k]`
/// multiplies the input k samples old: y[n] = Σ_k b[k]·x[n − k]. If the slices
/// differ in length only the newest min(len) samples are used (older ones count
/// as zero, like a cleared input buffer). See [`fmac_fir_output_with`].
pub fn fmac_fir_output(taps_q15: &[i16], window: &[i16]) -> i16 {
    fmac_fir_output_with(taps_q15, window, 0, true)
}

/// Bit-exact FMAC FIR output with output gain 2^`gain_shift` (FMAC_PARAM.R,
/// 0–7 ⇒ 0–42 dB; larger values are taken as 7) and clipping on or off, in q1.15 [LSB of 2^−15].
///
/// Assumed arithmetic (RM0440 §17.3.7 fixes the formats; the product alignment
/// and the truncation are this model's assumptions):
/// 1. each product b·x of two q1.15 values is a q2.30 integer; it enters the
///    26-bit q4.22 accumulator shifted right by 8 bits, arithmetic shift, i.e.
///    truncated towards −∞: p = (b·x) >> 8;
/// 2. the accumulator wraps at 26 bits (two's complement, range −8 to +8 − 2^−22),
///    without saturation;
/// 3. the output is the accumulator shifted left by the gain, then right by 7
///    (q4.22 → q1.15, truncated towards −∞); with CLIPEN it is saturated to
///    [−32768, 32767], without it only its 16 low bits are kept.
///
/// Error bound (no saturation, no wrapping): with y = Σ b·x·2^−30 exact, each
/// product loses [0, 255]·2^−30 and the final shift [0, 127]·2^−22, so at 0 dB
/// y − out·2^−15 ∈ [0, N·255·2^−30 + 127·2^−22], i.e. out is below the exact
/// value by less than N·255/2^15 + 127/128 LSB (1.16 LSB for N = 21).
pub fn fmac_fir_output_with(taps_q15: &[i16], window: &[i16], gain_shift: u32, clip: bool) -> i16 {
    const ACC_BITS: u32 = 26;
    let wrap = |v: i64| (v << (64 - ACC_BITS)) >> (64 - ACC_BITS);
    let n = taps_q15.len().min(window.len());
    let acc = taps_q15
        .iter()
        .zip(window.iter().rev())
        .take(n)
        .fold(0_i64, |acc, (&b, &x)| wrap(acc + ((i64::from(b) * i64::from(x)) >> 8)));
    let out = (acc << gain_shift.min(7)) >> 7;
    if clip {
        // Clamped into the i16 range, so the narrowing is exact.
        out.clamp(i64::from(i16::MIN), i64::from(i16::MAX)) as i16
    } else {
        // Truncation to the low 16 bits (intended wrap).
        out as i16
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Thesis A §6.2: f_s = 20 kHz, F_pass = 100 Hz, D_pass = 0.001, stop from 2 kHz, order 20.
    fn thesis() -> FirRequest {
        FirRequest {
            sample_rate_hz: 20e3,
            pass_edge_hz: 100.0,
            stop_edge_hz: 2e3,
            pass_ripple: 0.001,
            length: FirLength::Order(20),
        }
    }

    fn sum_q15(q: &[i16]) -> i32 {
        q.iter().map(|&t| i32::from(t)).sum()
    }

    fn symmetric<T: PartialEq>(v: &[T]) -> bool {
        v.iter().eq(v.iter().rev())
    }

    #[test]
    fn thesis_filter() {
        let d = design_fir(&thesis()).unwrap();
        // Order 20 ⇒ 21 taps, 2·21 + 1 = 43 FMAC words.
        assert_eq!(d.order, 20);
        assert_eq!(d.taps.len(), 21);
        assert_eq!(d.taps_q15.len(), 21);
        assert_eq!(d.fmac_memory_words, 43);
        assert!(symmetric(&d.taps_q15) && symmetric(&d.taps));
        assert_eq!(sum_q15(&d.taps_q15), 32768);
        assert!((d.taps.iter().sum::<f64>() - 1.0).abs() <= 4.0 * f64::EPSILON);
        // Thesis: "a delay of 0.5 ms, i.e. 10 sampling periods".
        assert_eq!(d.group_delay_samples, 10.0);
        assert!((d.group_delay_s - 0.5e-3).abs() < 1e-15);
        assert!(d.pass_ripple_quantised <= 0.001 && d.pass_ripple_design <= 0.001);
        // Something is attenuated at 2 kHz.
        assert!(magnitude(&q15_to_f64(&d.taps_q15), 2e3, 20e3) < 1.0);
        assert!(d.stop_attenuation_db_quantised > 0.0);
        // Independent reference: scipy.signal.remez(21, [0, 100, 2000, 10000], [1, 0], weight=[1, w],
        // fs=20000, grid_density=64), normalised to Σ = 1, with w bisected until max||H| − 1| over
        // [0, 100 Hz] = 0.001 (w = 0.01234), measured on a 200 000-point freqz grid: 27.84 dB.
        // Our DC-constrained design, after Q1.15 rounding, must land within 0.5 dB of it.
        assert!(
            (d.stop_attenuation_db_quantised - 27.84).abs() < 0.5,
            "{} dB vs 27.84 dB (scipy remez)",
            d.stop_attenuation_db_quantised
        );
        // Kaiser's fit, N = 20, Δf = (2000 − 100)/20000 = 0.095:
        //   −10·log10(δp·δs) = 14.6·0.095·20 + 13 = 40.74 dB ⇒ δs = 10^(−4.074)/0.001 = 0.0843 ⇒ 21.5 dB,
        // pessimistic for so narrow a pass band; the design must not be worse than it.
        assert!(d.stop_attenuation_db_quantised > 21.5);
    }

    #[test]
    fn magnitude_by_hand() {
        // Two-tap average [½, ½]: |H(f)| = |cos(πf/f_s)|; at f_s/4: cos(π/4) = 0.7071.
        let h = [0.5, 0.5];
        assert!((magnitude(&h, 0.0, 1.0) - 1.0).abs() < 1e-15);
        assert!((magnitude(&h, 0.25, 1.0) - 0.5f64.sqrt()).abs() < 1e-15);
        assert!(magnitude(&h, 0.5, 1.0).abs() < 1e-15);
        // Delay does not change magnitude: [0, 0, 1] has |H| = 1 everywhere.
        assert!((magnitude(&[0.0, 0.0, 1.0], 0.123, 1.0) - 1.0).abs() < 1e-15);
        // amplitude() agrees with magnitude() on symmetric taps of both parities.
        let spec = Spec {
            fs: 1.0,
            pass_hz: 0.1,
            stop_hz: 0.2,
            fp: 0.1,
            fst: 0.2,
            ripple: 0.01,
        };
        for taps in [vec![0.1, 0.3, 0.3, 0.1, 0.2], vec![0.1, -0.2, 0.6, 0.6, -0.2, 0.1]] {
            let t: Vec<f64> = taps.iter().zip(taps.iter().rev()).map(|(a, b)| 0.5 * (a + b)).collect();
            let grid = Grid::new(&spec, t.len());
            for (i, &p) in grid.stop.iter().enumerate().step_by(37) {
                let f = 0.2 + 0.3 * i as f64 / (grid.stop.len() - 1) as f64;
                assert!((amplitude(&t, p).abs() - magnitude(&t, f, 1.0)).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn minimum_order_meets_attenuation_and_one_less_does_not() {
        let req = FirRequest {
            length: FirLength::StopAttenuationDb(40.0),
            ..thesis()
        };
        let d = design_fir(&req).unwrap();
        assert!(
            d.stop_attenuation_db_quantised >= 40.0,
            "{}",
            d.stop_attenuation_db_quantised
        );
        assert!(d.pass_ripple_quantised <= 0.001);
        assert_eq!(sum_q15(&d.taps_q15), 32768);
        assert!(symmetric(&d.taps_q15));
        // Weight by hand: δs = 10^(−40/20) = 0.01, w = 0.001/0.01 = 0.1.
        assert!((d.stop_weight - 0.1).abs() < 1e-12);
        // The same weight one order lower misses the ripple or the attenuation.
        let spec = validate(&req).unwrap();
        assert!(
            design_weighted(&spec, d.order - 1, d.stop_weight, 40.0).is_none(),
            "order {} also meets it",
            d.order - 1
        );
        // Kaiser: −10·log10(0.001·0.01) = 50 dB ⇒ N ≈ (50 − 13)/(14.6·0.095) = 37/1.387 = 26.7.
        assert!((20..=34).contains(&d.order), "order {}", d.order);
    }

    #[test]
    fn fixed_order_beats_the_thesis_order_by_attenuation_mode() {
        // Designing at order 20 reaches some attenuation A20; asking for A20 − 0.5 dB needs at most order 20.
        let d20 = design_fir(&thesis()).unwrap();
        let req = FirRequest {
            length: FirLength::StopAttenuationDb(d20.stop_attenuation_db_quantised - 0.5),
            ..thesis()
        };
        let d = design_fir(&req).unwrap();
        assert!(d.order <= 20, "order {}", d.order);
    }

    #[test]
    fn fmac_dc_gain_is_one() {
        let d = design_fir(&thesis()).unwrap();
        let n = d.taps_q15.len();
        // v a multiple of 2^8: every product b·v is a multiple of 2^8, so nothing is truncated and
        // acc = Σ b·v/2^8 = 32768·v/2^8 = 128·v ⇒ out = v exactly.
        for v in [-32768i16, -16384, -256, 0, 256, 1024, 16384, 32512] {
            assert_eq!(fmac_fir_output(&d.taps_q15, &vec![v; n]), v, "v = {v}");
        }
        // Any v: out ∈ [v − 1, v] (truncation bound 1.16 LSB for N = 21, and out is an integer ≤ v).
        for v in [-32767i16, -12345, -1, 1, 1000, 12345, 32767] {
            let y = fmac_fir_output(&d.taps_q15, &vec![v; n]);
            assert!(y == v || y == v - 1, "{v} → {y}");
        }
    }

    #[test]
    fn fmac_impulse_returns_the_taps() {
        let d = design_fir(&thesis()).unwrap();
        let n = d.taps_q15.len();
        for k in 0..n {
            let mut w = vec![0i16; n];
            // Input k samples old is at index n − 1 − k (newest last).
            w[n - 1 - k] = i16::MIN; // −1.0: b·(−2^15) >> 8 = −b·2^7 exactly, >> 7 = −b.
            assert_eq!(i32::from(fmac_fir_output(&d.taps_q15, &w)), -i32::from(d.taps_q15[k]));
            w[n - 1 - k] = 16384; // 0.5: b·2^14 >> 8 = b·2^6, >> 7 = ⌊b/2⌋.
            assert_eq!(
                i32::from(fmac_fir_output(&d.taps_q15, &w)),
                i32::from(d.taps_q15[k]).div_euclid(2)
            );
        }
    }

    #[test]
    fn fmac_gain_clip_and_wrap() {
        // Tap 0.5 (16384) × input 0.75 (24576) = 0.375; +6 dB ⇒ 0.75 = 24576.
        assert_eq!(fmac_fir_output_with(&[16384], &[24576], 1, true), 24576);
        // +12 dB ⇒ 1.5: clipped to 32767, or truncated to 16 bits: 49152 − 65536 = −16384.
        assert_eq!(fmac_fir_output_with(&[16384], &[24576], 2, true), 32767);
        assert_eq!(fmac_fir_output_with(&[16384], &[24576], 2, false), -16384);
        // Accumulator wraps at 26 bits: 9 products of (−1)·(−1) = +1 each sum to 9 ≥ 8 ⇒ 9 − 16 = −7 ⇒ clipped −1.
        assert_eq!(fmac_fir_output(&[i16::MIN; 9], &[i16::MIN; 9]), i16::MIN);
        // Mismatched lengths use only the newest samples.
        assert_eq!(fmac_fir_output(&[16384, 16384], &[8192]), 4096);
        assert_eq!(fmac_fir_output(&[], &[]), 0);
    }

    #[test]
    fn quantiser_keeps_symmetry_and_sum() {
        // 5 equal taps of 0.2: 6553.6 rounds to 6554, Σ = 32770, deficit −2 ⇒ one pair −1 each
        // (residual −0.4 everywhere; ties resolved deterministically).
        let q = quantise(&[0.2; 5]).unwrap();
        assert_eq!(sum_q15(&q), 32768);
        assert!(symmetric(&q));
        // Odd deficit goes to the centre: [0.25, 0.5, 0.25] + rounding noise.
        let q = quantise(&[0.25 + 1e-6, 0.5 - 2e-6, 0.25 + 1e-6]).unwrap();
        assert_eq!(q, vec![8192, 16384, 8192]);
        // A centre tap of 1.0 does not fit i16.
        assert!(quantise(&[0.0, 1.0, 0.0]).is_err());
    }

    #[test]
    fn errors_name_their_key() {
        let key = |r: FirRequest| design_fir(&r).unwrap_err().key();
        // Edges out of order.
        assert_eq!(
            key(FirRequest {
                stop_edge_hz: 50.0,
                ..thesis()
            }),
            "stop_edge"
        );
        assert_eq!(
            key(FirRequest {
                stop_edge_hz: 100.0,
                ..thesis()
            }),
            "stop_edge"
        );
        // Beyond Nyquist.
        assert_eq!(
            key(FirRequest {
                stop_edge_hz: 12e3,
                ..thesis()
            }),
            "stop_edge"
        );
        assert_eq!(
            key(FirRequest {
                stop_edge_hz: 10e3,
                ..thesis()
            }),
            "stop_edge"
        );
        assert_eq!(
            key(FirRequest {
                pass_edge_hz: 11e3,
                stop_edge_hz: 12e3,
                ..thesis()
            }),
            "pass_edge"
        );
        // 128+ taps, and too low an order.
        assert_eq!(
            key(FirRequest {
                length: FirLength::Order(127),
                ..thesis()
            }),
            "order"
        );
        assert_eq!(
            key(FirRequest {
                length: FirLength::Order(usize::MAX),
                ..thesis()
            }),
            "order"
        );
        assert_eq!(
            key(FirRequest {
                length: FirLength::Order(1),
                ..thesis()
            }),
            "order"
        );
        // Infeasible attenuation.
        assert_eq!(
            key(FirRequest {
                length: FirLength::StopAttenuationDb(200.0),
                ..thesis()
            }),
            "stop_attenuation"
        );
        // NaN and non-positive inputs.
        assert_eq!(
            key(FirRequest {
                sample_rate_hz: f64::NAN,
                ..thesis()
            }),
            "sample_rate"
        );
        assert_eq!(
            key(FirRequest {
                sample_rate_hz: -20e3,
                ..thesis()
            }),
            "sample_rate"
        );
        assert_eq!(
            key(FirRequest {
                pass_edge_hz: f64::NAN,
                ..thesis()
            }),
            "pass_edge"
        );
        assert_eq!(
            key(FirRequest {
                pass_edge_hz: 0.0,
                ..thesis()
            }),
            "pass_edge"
        );
        assert_eq!(
            key(FirRequest {
                stop_edge_hz: f64::INFINITY,
                ..thesis()
            }),
            "stop_edge"
        );
        assert_eq!(
            key(FirRequest {
                pass_ripple: f64::NAN,
                ..thesis()
            }),
            "pass_ripple"
        );
        assert_eq!(
            key(FirRequest {
                pass_ripple: 0.5,
                ..thesis()
            }),
            "pass_ripple"
        );
        assert_eq!(
            key(FirRequest {
                pass_ripple: 0.0,
                ..thesis()
            }),
            "pass_ripple"
        );
        assert_eq!(
            key(FirRequest {
                length: FirLength::StopAttenuationDb(f64::NAN),
                ..thesis()
            }),
            "stop_attenuation"
        );
        assert_eq!(
            key(FirRequest {
                length: FirLength::StopAttenuationDb(0.0),
                ..thesis()
            }),
            "stop_attenuation"
        );
    }

    #[test]
    fn error_messages_say_what_is_accepted() {
        let msg = |r: FirRequest| design_fir(&r).unwrap_err().to_string();
        assert_eq!(
            msg(FirRequest {
                stop_edge_hz: 12e3,
                ..thesis()
            }),
            "stop_edge 12 kHz is at or beyond the Nyquist frequency 10 kHz; accepted: pass_edge < stop_edge < f_s/2"
        );
        let m = msg(FirRequest {
            length: FirLength::Order(127),
            ..thesis()
        });
        assert!(
            m.contains("128 taps") && m.contains("127") && m.contains("2N + 1 ≤ 256"),
            "{m}"
        );
        // Transition 100 → 150 Hz: Kaiser at 126 taps gives 14.6·0.0025·126 + 13 = 17.6 dB for
        // −10·log10(δp·δs), nowhere near the 30 + 80 = 110 dB that 0.001 ripple and 80 dB need.
        let m = msg(FirRequest {
            stop_edge_hz: 150.0,
            length: FirLength::StopAttenuationDb(80.0),
            ..thesis()
        });
        assert!(m.contains("best at 127 taps"), "{m}");
        let m = msg(FirRequest {
            length: FirLength::StopAttenuationDb(200.0),
            ..thesis()
        });
        assert!(m.contains("≤ 100 dB"), "{m}");
        // Thesis edges at order 126: Kaiser 14.6·0.095·126 + 13 = 187.8 dB > 120 dB; the highest
        // order allowed is ⌊(120 − 13)/(14.6·0.095)⌋ = ⌊77.15⌋ = 77.
        let m = msg(FirRequest {
            length: FirLength::Order(126),
            ..thesis()
        });
        assert!(m.contains("order ≤ 77"), "{m}");
        // Every message splits into problem and accepted values.
        for r in [
            FirRequest {
                stop_edge_hz: 50.0,
                ..thesis()
            },
            FirRequest {
                pass_ripple: 2.0,
                ..thesis()
            },
            FirRequest {
                length: FirLength::Order(0),
                ..thesis()
            },
            FirRequest {
                pass_edge_hz: -1.0,
                ..thesis()
            },
        ] {
            assert!(msg(r).contains("; accepted: "));
        }
    }

    #[test]
    fn infeasible_ripple_reports_the_smallest_reached() {
        // 1e−9 is far below one Q1.15 LSB (3e−5) of quantisation error at 100 Hz.
        let e = design_fir(&FirRequest {
            pass_ripple: 1e-9,
            ..thesis()
        })
        .unwrap_err();
        assert_eq!(e.key(), "pass_ripple");
        match e {
            FirError::RippleInfeasible {
                best: Some(b),
                order: 20,
                ..
            } => assert!(b > 1e-9 && b < 1e-3, "{b}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn odd_orders_and_the_smallest_orders_work() {
        for order in [2, 3, 4, 5, 21] {
            let d = design_fir(&FirRequest {
                pass_ripple: 0.01,
                stop_edge_hz: 4e3,
                length: FirLength::Order(order),
                ..thesis()
            })
            .unwrap_or_else(|e| panic!("order {order}: {e}"));
            assert_eq!(d.taps_q15.len(), order + 1);
            assert_eq!(sum_q15(&d.taps_q15), 32768);
            assert!(symmetric(&d.taps_q15));
            assert!(d.pass_ripple_quantised <= 0.01);
            assert_eq!(d.group_delay_samples, order as f64 / 2.0);
        }
    }

    #[test]
    fn largest_fmac_filter() {
        // Transition 100 → 400 Hz (Δf = 0.015): Kaiser at order 126 gives 14.6·0.015·126 + 13 = 40.6 dB.
        let d = design_fir(&FirRequest {
            stop_edge_hz: 400.0,
            length: FirLength::Order(126),
            ..thesis()
        })
        .unwrap();
        assert_eq!(d.taps_q15.len(), 127);
        assert_eq!(d.fmac_memory_words, 255);
        assert_eq!(sum_q15(&d.taps_q15), 32768);
        assert!(d.pass_ripple_quantised <= 0.001);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(40))]

        /// Random plausible requests: a clean error, or symmetric Q1.15 taps with Σ = 32768 within the ripple.
        #[test]
        fn designs_are_symmetric_unity_gain_and_within_ripple(
            fs in 1e3f64..100e3,
            pass_frac in 0.001f64..0.3,
            gap_frac in 0.005f64..0.5,
            ripple in 1e-5f64..0.3,
            order in 0usize..140,
        ) {
            let pass = pass_frac * fs;
            let stop = pass + gap_frac * (0.5 * fs - pass);
            let req = FirRequest { sample_rate_hz: fs, pass_edge_hz: pass, stop_edge_hz: stop, pass_ripple: ripple, length: FirLength::Order(order) };
            match design_fir(&req) {
                Ok(d) => {
                    prop_assert_eq!(d.order, order);
                    prop_assert_eq!(d.taps_q15.len(), order + 1);
                    prop_assert_eq!(sum_q15(&d.taps_q15), 32768);
                    prop_assert!(symmetric(&d.taps_q15));
                    prop_assert!(d.pass_ripple_quantised <= ripple);
                    prop_assert!(d.stop_attenuation_db_quantised > 0.0);
                }
                Err(e) => {
                    let text = e.to_string();
                    prop_assert!(text.contains("; accepted: "), "{}", text);
                    if !(2..=126).contains(&order) {
                        prop_assert_eq!(e.key(), "order");
                    }
                }
            }
        }

        /// Minimum-order mode: the result meets the spec and one order less (same weight) does not.
        #[test]
        fn minimum_order_is_minimal(
            pass_frac in 0.002f64..0.1,
            gap_frac in 0.05f64..0.4,
            ripple in 1e-3f64..0.05,
            att in 20.0f64..60.0,
        ) {
            let fs = 20e3;
            let pass = pass_frac * fs;
            let stop = pass + gap_frac * (0.5 * fs - pass);
            let req = FirRequest { sample_rate_hz: fs, pass_edge_hz: pass, stop_edge_hz: stop, pass_ripple: ripple, length: FirLength::StopAttenuationDb(att) };
            if let Ok(d) = design_fir(&req) {
                prop_assert!(d.stop_attenuation_db_quantised >= att && d.pass_ripple_quantised <= ripple);
                prop_assert_eq!(sum_q15(&d.taps_q15), 32768);
                if d.order > MIN_ORDER {
                    let spec = validate(&req).unwrap();
                    prop_assert!(design_weighted(&spec, d.order - 1, d.stop_weight, att).is_none());
                }
            }
        }

        /// The FMAC model stays within the derived truncation bound of the exact convolution.
        #[test]
        fn fmac_matches_exact_convolution(
            taps in proptest::collection::vec(-4096i16..4096, 1..=127),
            seed in proptest::collection::vec(any::<i16>(), 127),
        ) {
            let n = taps.len();
            let window = &seed[..n];
            // Exact Σ b·x in units of 2^−30 (integers, exact in f64 below 2^53).
            let exact: f64 = taps.iter().zip(window.iter().rev()).map(|(&b, &x)| f64::from(b) * f64::from(x)).sum();
            let exact_lsb = exact / 32768.0; // units of 2^−15
            // |Σ b·x| ≤ 127·4096·32768·2^−30 < 16: may exceed q4.22; only compare when partial sums
            // cannot wrap and the output does not clip (|Σ|b||·1 < 8 and |y| < 1 − 2 LSB).
            let abs_sum: f64 = taps.iter().map(|&b| f64::from(b).abs()).sum::<f64>() / 32768.0;
            prop_assume!(abs_sum < 8.0 && exact_lsb.abs() < 32766.0);
            let y = f64::from(fmac_fir_output(&taps, window));
            let bound = n as f64 * 255.0 / 32768.0 + 127.0 / 128.0;
            prop_assert!(exact_lsb - y >= 0.0 && exact_lsb - y <= bound, "exact {} out {} bound {}", exact_lsb, y, bound);
        }
    }
}
