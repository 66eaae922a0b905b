//! The resolver signal measured at start-up (pure; issue 26, first power-up).
//!
//! While the current sensing's zero level is measured with the gates off
//! ([`crate::offset`]), the demodulated SIN and COS (Q1.31 of the ADC's half range,
//! [`crate::adc_frame::to_sample`]) give the signal's amplitude √(sin² + cos²) whatever
//! the rotor's angle. The angle observer's trig-identity gains are designed for the
//! board's signal `board::RESOLVER_SIGNAL` (codegen `board::resolver_signal_gain`: the
//! front end's amplitude over V_REF/2 times the excitation's envelope where SIN and COS
//! are held), and its ω_n and ζ scale with the square root of measured/designed (thesis A
//! (4.10)). A ratio outside `board::RESOLVER_SIGNAL_MIN` … `RESOLVER_SIGNAL_MAX` is a
//! fault (`FaultCause::ResolverSignal`): no excitation, a resolver unplugged, a front end
//! unlike the board file's. The first half of the calibration's periods is skipped (the
//! excitation filter settles; the emulated excitation reads 0 before TIM3's second edge),
//! the second half averaged: sin² + cos² per period, its mean compared with the bounds
//! squared (no square root needed).
#![forbid(unsafe_code)]

use motor_control::ato::ResolverSample;
use motor_control::q31;

/// What the check is judged by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SignalBounds {
    /// The designed signal, a fraction of full scale (`board::RESOLVER_SIGNAL`).
    pub designed: f32,
    /// Least and largest accepted measured/designed (`board::RESOLVER_SIGNAL_MIN`, `_MAX`).
    pub ratio: (f32, f32),
    /// Periods of the calibration (`board::OFFSET_SAMPLES`); the last half are averaged.
    pub periods: u32,
}

/// The verdict at the calibration's end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SignalStatus {
    /// Still measuring.
    Measuring,
    /// Done: the measured signal lies within the bounds; the mean of sin² + cos²
    /// (the signal's square, a fraction of full scale squared).
    Within(f32),
    /// Done: the measured signal lies outside them; the mean of sin² + cos².
    Outside(f32),
}

impl SignalBounds {
    /// The measured/designed ratio of a mean of sin² + cos² (what [`SignalStatus`]
    /// carries): √square/designed, the figure judged against `ratio` and the one the
    /// fault record keeps (`FaultCause::ResolverSignal`).
    pub fn ratio_of(&self, square: f32) -> f32 {
        libm::sqrtf(square) / self.designed
    }
}

/// The running sum of sin² + cos² over the averaged periods.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SignalCheck {
    /// Periods seen.
    seen: u32,
    /// Σ (sin² + cos²) over the averaged ones.
    sum: f32,
}

impl SignalCheck {
    /// Nothing seen yet.
    pub const fn new() -> Self {
        Self { seen: 0, sum: 0.0 }
    }

    /// Whether the last sample added fell in the averaged half (the excitation has
    /// settled: the demodulated signals are the resolver's).
    pub fn averaging(&self, bounds: &SignalBounds) -> bool {
        self.seen > bounds.periods / 2
    }

    /// One period's sample; the verdict once `bounds.periods` have been seen (and on
    /// every later call).
    pub fn add(&mut self, bounds: &SignalBounds, sample: ResolverSample) -> SignalStatus {
        let skip = bounds.periods / 2;
        if self.seen < bounds.periods {
            if self.seen >= skip {
                let (s, c) = (q31::to_f32(sample.sin), q31::to_f32(sample.cos));
                self.sum += s * s + c * c;
            }
            self.seen += 1;
        }
        if self.seen < bounds.periods {
            return SignalStatus::Measuring;
        }
        let n = (bounds.periods - skip).max(1) as f32;
        let square = self.sum / n;
        let (lo, hi) = (bounds.ratio.0 * bounds.designed, bounds.ratio.1 * bounds.designed);
        if square >= lo * lo && square <= hi * hi {
            SignalStatus::Within(square)
        } else {
            SignalStatus::Outside(square)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BOUNDS: SignalBounds = SignalBounds {
        designed: 0.4,
        ratio: (0.64, 1.44),
        periods: 256,
    };

    fn at(amplitude: f64, theta: f64) -> ResolverSample {
        let q = |x: f64| (x * 2_147_483_648.0) as i32;
        ResolverSample {
            sin: q(amplitude * theta.sin()),
            cos: q(amplitude * theta.cos()),
        }
    }

    /// The designed 0.4 at any angle: mean square 0.16 (ratio 1), after exactly 256 periods;
    /// the first 128 (zeros: no excitation yet) do not count.
    #[test]
    fn designed_signal_passes_whatever_the_angle() {
        for theta in [0.0, 1.0, -2.5] {
            let mut c = SignalCheck::new();
            for k in 0..255 {
                let s = if k < 128 { at(0.0, 0.0) } else { at(0.4, theta) };
                assert_eq!(c.add(&BOUNDS, s), SignalStatus::Measuring);
            }
            match c.add(&BOUNDS, at(0.4, theta)) {
                SignalStatus::Within(m) => assert!((m - 0.16).abs() < 1e-4, "{m}"),
                s => panic!("{s:?}"),
            }
        }
    }

    /// By hand, bounds 0.64·0.4 = 0.256 and 1.44·0.4 = 0.576: 0.26 passes, 0.25 fails;
    /// 0.57 passes, 0.58 fails; no signal (0) fails.
    #[test]
    fn bounds_by_hand() {
        let verdict = |a: f64| {
            let mut c = SignalCheck::new();
            let mut v = SignalStatus::Measuring;
            for _ in 0..256 {
                v = c.add(&BOUNDS, at(a, 0.7));
            }
            v
        };
        assert!(matches!(verdict(0.26), SignalStatus::Within(_)));
        assert!(matches!(verdict(0.25), SignalStatus::Outside(_)));
        assert!(matches!(verdict(0.57), SignalStatus::Within(_)));
        assert!(matches!(verdict(0.58), SignalStatus::Outside(_)));
        assert!(matches!(verdict(0.0), SignalStatus::Outside(m) if m == 0.0));
        // The ratio the record keeps: 0.58/0.4 = 1.45, 0.25/0.4 = 0.625.
        for (a, ratio) in [(0.58, 1.45), (0.25, 0.625)] {
            let SignalStatus::Outside(m) = verdict(a) else {
                panic!("{a}")
            };
            assert!((BOUNDS.ratio_of(m) - ratio).abs() < 1e-4, "{a}: {}", BOUNDS.ratio_of(m));
        }
    }
}
