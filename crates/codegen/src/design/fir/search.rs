//! The stop-weight search at a fixed order and the minimum-order search for an
//! attenuation, each judged on the quantised taps.

use super::error::FirError;
use super::quantise::quantise;
use super::remez::remez_taps;
use super::response::{Grid, pass_deviation, q15_to_f64, stop_attenuation_db};
use super::validate::Spec;
use super::{FMAC_MAX_TAPS, FirDesign, MAX_ATTENUATION_DB, MAX_KAISER_DB, MAX_WEIGHT_EVALUATIONS, MIN_ORDER};

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
pub(super) fn kaiser_db(spec: &Spec, order: f64) -> f64 {
    14.6 * (spec.fst - spec.fp) * order + 13.0
}

/// Smallest ripple (pass or stop) the weight search lets the exact design aim for [linear].
const MIN_DESIGN_RIPPLE: f64 = 1e-6;

/// Highest order whose Kaiser estimate stays within [`MAX_KAISER_DB`], and within the FMAC [taps − 1].
pub(super) fn max_order(spec: &Spec) -> usize {
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
pub(super) fn design_order(spec: &Spec, order: usize) -> Result<FirDesign, FirError> {
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

/// Orders the upward walk of [`design_min_order`] tries past the best quantised attenuation
/// seen before it stops: once Q1.15 rounding sets the stop-band floor, more taps only add
/// rounding noise (the thesis-A band edges peak near 72 dB at order ≈ 50, issue 18), so the
/// walk ends there instead of running every order up to the FMAC limit.
pub const STALL_ORDERS: usize = 6;
/// Smallest gain in quantised attenuation that counts as progress in the walk \[dB\].
const PROGRESS_DB: f64 = 0.05;

/// Fixed order and weight: the quantised design, if it meets the pass ripple.
fn weighted(spec: &Spec, order: usize, weight: f64) -> Option<FirDesign> {
    let grid = Grid::new(spec, order + 1);
    let t = trial(spec, &grid, order, weight).ok()?;
    (t.ripple_q <= spec.ripple).then(|| finish(spec, &grid, t))
}

/// Fixed order and weight: the quantised design, if it meets ripple and attenuation.
pub(super) fn design_weighted(spec: &Spec, order: usize, weight: f64, attenuation_db: f64) -> Option<FirDesign> {
    weighted(spec, order, weight).filter(|d| d.stop_attenuation_db_quantised >= attenuation_db)
}

fn meets(d: &Option<FirDesign>, attenuation_db: f64) -> bool {
    d.as_ref()
        .is_some_and(|d| d.stop_attenuation_db_quantised >= attenuation_db)
}

/// Minimum order meeting `attenuation_db` with w = pass_ripple/δ_s. The walk is bounded:
/// at most [`FMAC_MAX_TAPS`] orders, and it stops [`STALL_ORDERS`] orders after the
/// quantised attenuation last improved; the refusal then names the best attenuation (by
/// the stop-weight search at the best order) as the accepted bound.
pub(super) fn design_min_order(spec: &Spec, attenuation_db: f64) -> Result<FirDesign, FirError> {
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
    let first = weighted(spec, start, weight);
    if meets(&first, attenuation_db) {
        let mut best = first.expect("meets() implies a design");
        // Already meets it: walk down to the first order that does not.
        for order in (MIN_ORDER..start).rev() {
            match design_weighted(spec, order, weight, attenuation_db) {
                Some(d) => best = d,
                None => break,
            }
        }
        return Ok(best);
    }
    let mut best: (f64, usize) = (
        first.map_or(f64::NEG_INFINITY, |d| d.stop_attenuation_db_quantised),
        start,
    );
    let mut last = start;
    for order in start + 1..=max_order {
        last = order;
        let d = weighted(spec, order, weight);
        if meets(&d, attenuation_db) {
            return Ok(d.expect("meets() implies a design"));
        }
        let db = d.map_or(f64::NEG_INFINITY, |d| d.stop_attenuation_db_quantised);
        if db > best.0 + PROGRESS_DB {
            best = (db, order);
        } else if order - best.1 >= STALL_ORDERS {
            break;
        }
    }
    let at = if last < max_order { best.1 } else { max_order };
    let best_db = design_order(spec, at).ok().map(|d| d.stop_attenuation_db_quantised);
    Err(if last < max_order {
        FirError::AttenuationFloor {
            requested_db: attenuation_db,
            order: at,
            last_order: last,
            best_db,
        }
    } else {
        FirError::AttenuationInfeasible {
            taps: max_order + 1,
            requested_db: attenuation_db,
            best_db,
        }
    })
}
