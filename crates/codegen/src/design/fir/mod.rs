//! Equiripple FIR low-pass for the STM32G474 FMAC (thesis A §6.2, RM0440 §18.3.7–18.3.8).
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
//! # FMAC (RM0440 §18.3.7–18.3.8)
//!
//! Inputs, outputs and coefficients are q1.15 (i16); the accumulator is 26 bits,
//! q4.22, and wraps (it is not saturated); an optional gain of 0–42 dB (left
//! shift by 0–7) is applied at the output, which is then clipped to q1.15 if
//! CLIPEN is set or else truncated to its 16 low bits. An N-tap FIR needs
//! 2N + 1 of the 256 words of local memory, so N ≤ 127 ([`FMAC_MAX_TAPS`]).
//! The bit-level model this module designs for is the firmware's own,
//! [`motor_control::fir::output`] (the filter checks in the tests run on it).
//!
//! # Modules
//!
//! In the order they use each other: `error` (why no filter was designed; the limits it
//! names are the constants of this module), `validate` (the request normalised to
//! cycles/sample), `response` and `quantise` (measuring and rounding taps), `remez` (the
//! exchange), `search` (the weight and order searches over the other four).

mod error;
mod quantise;
mod remez;
mod response;
mod search;
#[cfg(test)]
mod tests;
mod validate;

use serde::Serialize;

pub use error::FirError;
pub use response::magnitude;

/// Words of FMAC local memory (RM0440 §18.3.8) [16-bit words].
pub const FMAC_MEMORY_WORDS: usize = 256;
/// Largest tap count the FMAC holds: 2N + 1 ≤ 256 ⇒ N ≤ 127 \[taps\].
pub const FMAC_MAX_TAPS: usize = (FMAC_MEMORY_WORDS - 1) / 2;
/// Smallest accepted filter order [taps − 1].
pub const MIN_ORDER: usize = 2;
/// Q1.15 representation of 1.0 \[LSB\]; the quantised taps sum to exactly this.
pub const Q15_ONE: i32 = 1 << 15;
/// Dense-grid points per tap and per band used to measure ripple and attenuation [points/tap].
pub const GRID_POINTS_PER_TAP: usize = 64;
/// Upper bound on the Remez runs of the stop-weight search at a given order \[runs\].
pub const MAX_WEIGHT_EVALUATIONS: usize = 24;
/// Lowest pass_edge/f_s accepted [cycles/sample]. Below it the pass band (0.01·f_p, f_p)
/// of the Parks–McClellan exchange is so narrow (its weight (1 − cos ω) ≈ 2π²f² < 2e−11)
/// that one exchange iteration's extrema search stalls: measured on the thesis-A request
/// (f_s = 20 kHz, stop_edge 2 kHz, order 20), pass_edge/f_s = 2.5e−7 designs in 0.6 s
/// (debug build) and 1e−7 runs past 15 s (issue 18). 1e−6 keeps a factor 4 from the
/// last good point; at it, orders up to 70 and the 60 dB minimum-order search design in
/// under a second.
pub const MIN_PASS_EDGE_NORMALISED: f64 = 1e-6;
/// Kaiser's −10·log10(δ_p·δ_s) \[dB\] above which an order is refused: the equiripple design
/// would need ripples near 1e−7 and below, where the f64 Remez exchange stalls (seen at
/// δ_s ≈ 5e−9); Q1.15 rounding caps the attenuation near 90 dB long before.
pub const MAX_KAISER_DB: f64 = 120.0;
/// Largest stop-band attenuation accepted in minimum-order mode \[dB\]; Q1.15 rounding
/// (±2^−16 per tap) leaves a floor near −90 dB.
pub const MAX_ATTENUATION_DB: f64 = 100.0;

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
    /// Sampling frequency f_s \[Hz\].
    pub sample_rate_hz: f64,
    /// Pass-band edge; the pass band is [0, pass_edge] \[Hz\].
    pub pass_edge_hz: f64,
    /// Stop-band edge; the stop band is [stop_edge, f_s/2] \[Hz\].
    pub stop_edge_hz: f64,
    /// Maximal relative pass-band deviation ||H| − 1| [linear, e.g. 0.001].
    pub pass_ripple: f64,
    /// Order or attenuation.
    pub length: FirLength,
}

/// The designed filter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FirDesign {
    /// Requested pass-band edge \[Hz\].
    pub pass_edge_hz: f64,
    /// Requested stop-band edge \[Hz\].
    pub stop_edge_hz: f64,
    /// Requested maximal pass-band deviation \[linear\].
    pub pass_ripple: f64,
    /// Filter order N − 1 [taps − 1].
    pub order: usize,
    /// Floating-point equiripple taps, symmetric, Σ = 1 (to f64 rounding) \[1\].
    pub taps: Vec<f64>,
    /// Q1.15 taps for the FMAC: symmetric, Σ = 32768 exactly (DC gain 1) [LSB of 2^−15].
    pub taps_q15: Vec<i16>,
    /// Achieved max ||H| − 1| over [0, pass_edge], float taps \[linear\].
    pub pass_ripple_design: f64,
    /// Same for the Q1.15 taps; ≤ the requested `pass_ripple` \[linear\].
    pub pass_ripple_quantised: f64,
    /// Achieved min attenuation −20·log10|H| over [stop_edge, f_s/2], float taps \[dB\].
    pub stop_attenuation_db_design: f64,
    /// Same for the Q1.15 taps \[dB\].
    pub stop_attenuation_db_quantised: f64,
    /// Group delay order/2 (exact, linear phase) \[samples\].
    pub group_delay_samples: f64,
    /// Group delay order/(2·f_s) \[s\].
    pub group_delay_s: f64,
    /// FMAC local-memory words used, 2N + 1 [16-bit words].
    pub fmac_memory_words: usize,
    /// Stop-band/pass-band weight ratio w of the Remez design \[1\].
    pub stop_weight: f64,
}

/// Designs the FMAC low-pass the request describes (frequencies in Hz, ripple linear,
/// attenuation in dB); see the module documentation for the method.
pub fn design_fir(req: &FirRequest) -> Result<FirDesign, FirError> {
    let spec = validate::validate(req)?;
    match req.length {
        FirLength::Order(order) if order > search::max_order(&spec) => Err(FirError::OrderBeyondPrecision {
            order,
            max_order: search::max_order(&spec),
            kaiser_db: search::kaiser_db(&spec, order as f64),
        }),
        FirLength::Order(order) => search::design_order(&spec, order),
        FirLength::StopAttenuationDb(a) => search::design_min_order(&spec, a),
    }
}
