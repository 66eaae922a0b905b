//! ADC codes → the control core's [`AdcSample`] (pure).
//!
//! The injected conversions deliver right-aligned 12-bit codes. The core works in
//! the per-unit Q1.15 format of thesis A (4.16), Table 4.1, so the codes are shifted
//! to 16 bits: phase currents are bipolar (mid-scale = 0 A, full ADC range = ±A),
//! the DC link unipolar (0 … A). The resolver SIN/COS inputs are bipolar around
//! mid-scale and are demodulated synchronously (thesis A §4.3): one sample per
//! half period of the excitation, at its extremum, multiplied by the excitation's
//! sign at that instant.
#![forbid(unsafe_code)]

use motor_control::AdcSample;
use motor_control::ato::ResolverSample;

use crate::hw::ADC_BITS;

/// The codes of one control period's injected conversions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RawConversions {
    /// Phase currents u, v, w (12-bit, right-aligned).
    pub phases: [u16; 3],
    /// DC-link voltage.
    pub dc_link: u16,
    /// Resolver SIN winding.
    pub sin: u16,
    /// Resolver COS winding.
    pub cos: u16,
}

/// Sign of the resolver excitation at the sampling instant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Excitation {
    /// At its positive extremum.
    Positive,
    /// At its negative extremum.
    Negative,
}

/// Largest code of the converter.
const FULL: u16 = (1 << ADC_BITS) - 1;

/// 12-bit code → 16-bit left-aligned (bipolar per-unit offset at 2^15).
fn left_aligned(code: u16) -> u16 {
    (code & FULL) << (16 - ADC_BITS)
}

/// Bipolar 12-bit code → Q1.31 about mid-scale, times the excitation sign.
fn demodulate(code: u16, excitation: Excitation) -> i32 {
    let centred = i32::from(left_aligned(code)) - (1 << 15);
    let q31 = centred << 16;
    match excitation {
        Excitation::Positive => q31,
        Excitation::Negative => q31.saturating_neg(),
    }
}

/// The core's sample of one control period.
pub fn to_sample(raw: &RawConversions, excitation: Excitation) -> AdcSample {
    AdcSample {
        phase_currents: raw.phases.map(left_aligned),
        resolver: ResolverSample {
            sin: demodulate(raw.sin, excitation),
            cos: demodulate(raw.cos, excitation),
        },
        dc_link: (raw.dc_link & FULL) << (15 - ADC_BITS),
    }
}

/// A phase-current code at either end of the converter's range: the current is
/// beyond the measurable full scale (1.25 × the peak current, thesis A Table 4.1),
/// so the control interrupt trips the outputs (in addition to the comparator on
/// the timer's break input).
pub fn overcurrent(raw: &RawConversions) -> bool {
    raw.phases.iter().any(|&c| {
        let c = c & FULL;
        c == 0 || c == FULL
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mid-scale 2048 → 32768 (0 A); 4095 → 65520; DC link 4095 → 32760 (≈ A);
    /// resolver 3072 = +0.5 of the half range → +2^30, negated in the negative
    /// half-period; 1024 → −2^30.
    #[test]
    fn codes_to_sample() {
        let raw = RawConversions {
            phases: [2048, 4095, 0],
            dc_link: 4095,
            sin: 3072,
            cos: 1024,
        };
        let s = to_sample(&raw, Excitation::Positive);
        assert_eq!(s.phase_currents, [32768, 65520, 0]);
        assert_eq!(s.dc_link, 32760);
        assert_eq!((s.resolver.sin, s.resolver.cos), (1 << 30, -(1 << 30)));
        let s = to_sample(&raw, Excitation::Negative);
        assert_eq!((s.resolver.sin, s.resolver.cos), (-(1 << 30), 1 << 30));
        // Code 0 is −1.0 and its negation saturates instead of overflowing.
        let zero = RawConversions { sin: 0, ..raw };
        assert_eq!(to_sample(&zero, Excitation::Negative).resolver.sin, i32::MAX);
    }

    /// Rails trip; anything inside does not; bits above 12 are ignored.
    #[test]
    fn overcurrent_at_the_rails() {
        let ok = RawConversions {
            phases: [1, 2048, 4094],
            ..Default::default()
        };
        assert!(!overcurrent(&ok));
        assert!(overcurrent(&RawConversions {
            phases: [0, 2048, 2048],
            ..ok
        }));
        assert!(overcurrent(&RawConversions {
            phases: [2048, 2048, 4095],
            ..ok
        }));
        assert!(!overcurrent(&RawConversions {
            phases: [0x1800, 2048, 2048],
            ..ok
        }));
    }
}
