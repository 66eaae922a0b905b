//! The Parks–McClellan exchange (`pm-remez`) wrapped for this filter: panics, NaN and
//! an unlevelled ripple become errors, and the DC gain is built in (module docs of
//! [`super`]).

use std::f64::consts::PI;
use std::panic::{AssertUnwindSafe, catch_unwind};

use pm_remez::{Band, PMParameters, pm_remez};

use super::validate::Spec;

/// Largest relative spread (max − min)/max of the error extrema accepted as converged [1].
const MAX_FLATNESS: f64 = 1e-2;

#[cfg(test)]
thread_local! {
    /// Parks–McClellan runs on this thread, so a test can bound a search's work.
    pub(super) static RUNS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Runs the Parks–McClellan exchange for a symmetric filter of `num_taps` taps on
/// `bands` (cycles/sample), turning panics, NaN and an unlevelled ripple into errors.
pub(super) fn remez<D, W>(num_taps: usize, bands: Vec<(f64, f64)>, desired: D, weight: W) -> Result<Vec<f64>, String>
where
    D: Fn(f64) -> f64,
    W: Fn(f64) -> f64,
{
    #[cfg(test)]
    RUNS.with(|r| r.set(r.get() + 1));
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
pub(super) fn remez_taps(spec: &Spec, num_taps: usize, w: f64) -> Result<Vec<f64>, String> {
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
