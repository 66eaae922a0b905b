//! Frequency response of taps: |H(f)| of any taps, and the zero-phase amplitude of
//! symmetric taps on the dense band grids where ripple and attenuation are measured.

use std::f64::consts::PI;

use super::validate::Spec;
use super::{GRID_POINTS_PER_TAP, Q15_ONE};

/// Magnitude response |H(f)| = |Σ h\[n\]·e^(−j2πfn/f_s)| of arbitrary taps at `f_hz` \[Hz\]
/// for sample rate `fs_hz` \[Hz\]; returns a linear gain \[1\] (NaN for non-finite inputs).
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
pub(super) struct Grid {
    pub(super) pass: Vec<(f64, f64)>,
    pub(super) stop: Vec<(f64, f64)>,
}

impl Grid {
    /// `GRID_POINTS_PER_TAP`·N + 1 points per band, both band edges included.
    pub(super) fn new(spec: &Spec, taps: usize) -> Grid {
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
pub(super) fn amplitude(taps: &[f64], (x, half): (f64, f64)) -> f64 {
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
pub(super) fn pass_deviation(taps: &[f64], grid: &Grid) -> f64 {
    grid.pass
        .iter()
        .map(|&p| (amplitude(taps, p).abs() - 1.0).abs())
        .fold(0.0, f64::max)
}

/// Min −20·log10|A| over the stop band [dB] (capped at 300 dB).
pub(super) fn stop_attenuation_db(taps: &[f64], grid: &Grid) -> f64 {
    let peak = grid.stop.iter().map(|&p| amplitude(taps, p).abs()).fold(0.0, f64::max);
    -20.0 * peak.max(1e-15).log10()
}

pub(super) fn q15_to_f64(q: &[i16]) -> Vec<f64> {
    q.iter().map(|&t| f64::from(t) / f64::from(Q15_ONE)).collect()
}
