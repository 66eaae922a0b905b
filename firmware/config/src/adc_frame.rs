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

/// Signal codes of the board's ADC sequences (`motor::board::ADCx_SIGNALS`).
pub mod signal {
    /// Phase u current.
    pub const CURRENT_U: u8 = 0;
    /// Phase v current.
    pub const CURRENT_V: u8 = 1;
    /// Phase w current.
    pub const CURRENT_W: u8 = 2;
    /// DC-link voltage.
    pub const DC_LINK: u8 = 3;
    /// Resolver SIN.
    pub const SIN: u8 = 4;
    /// Resolver COS.
    pub const COS: u8 = 5;
}

/// The conversions of one period from the injected data registers of both converters
/// (`jdr[k]` = JDRk+1) and the signal each rank holds. Ranks beyond a sequence and a
/// missing third phase read as 0.
pub fn assemble(adc1: &[u16; 4], signals1: &[u8], adc2: &[u16; 4], signals2: &[u8]) -> RawConversions {
    let mut raw = RawConversions::default();
    for (codes, signals) in [(adc1, signals1), (adc2, signals2)] {
        for (&code, &sig) in codes.iter().zip(signals) {
            match sig {
                signal::CURRENT_U => raw.phases[0] = code,
                signal::CURRENT_V => raw.phases[1] = code,
                signal::CURRENT_W => raw.phases[2] = code,
                signal::DC_LINK => raw.dc_link = code,
                signal::SIN => raw.sin = code,
                signal::COS => raw.cos = code,
                _ => {}
            }
        }
    }
    raw
}

/// The board's trip levels in the units of the conversions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trips {
    /// 16-bit code at zero current, per phase u, v, w: the board's nominal level until
    /// the start-up measurement ([`crate::offset`]) replaces it.
    pub current_offset: [i32; 3],
    /// |code − offset| above which a phase current trips (over-current level / A per code).
    pub current_codes: i32,
    /// 15-bit DC-link code above which the drive trips (over-voltage level / V per code).
    pub dc_link_code: u16,
    /// |ω_e| above which the drive trips \[rad/s\].
    pub speed: f32,
}

impl Trips {
    /// Whether the period's conversions or the observer's speed call for a trip: a
    /// measured phase current beyond the over-current level or at either ADC rail (beyond
    /// the measurable range; this adds to the comparator on the timer's break input), the
    /// DC link beyond the over-voltage level, the electrical speed beyond the over-speed
    /// level. `phases` is 2 or 3 (the third code is unused with two).
    pub fn tripped(&self, raw: &RawConversions, phases: usize, omega_e: f32) -> bool {
        let current = raw
            .phases
            .iter()
            .zip(&self.current_offset)
            .take(phases)
            .any(|(&c, &offset)| {
                let c = c & FULL;
                let code16 = i32::from(left_aligned(c));
                c == 0 || c == FULL || code16.saturating_sub(offset).saturating_abs() > self.current_codes
            });
        let dc_link = (raw.dc_link & FULL) << (15 - ADC_BITS);
        current || dc_link > self.dc_link_code || omega_e.abs() > self.speed || omega_e.is_nan()
    }
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

    /// A board with 0 A at code 32 768, a trip 8 000 codes away, U_dc trip at code
    /// 20 000, ω_e trip at 4 000 rad/s: 12-bit 2048 (= 32 768) and 2500 (40 000, 7 232
    /// away) and 1600 (25 600, 7 168 away) pass; 2600 (41 600, 8 832 away) trips, so does the rail 4095 and code 0;
    /// DC link 2501 → 20 008 > 20 000 trips; ω_e 4 001 trips.
    #[test]
    fn trips_at_the_board_levels() {
        let t = Trips {
            current_offset: [32_768; 3],
            current_codes: 8_000,
            dc_link_code: 20_000,
            speed: 4_000.0,
        };
        let ok = RawConversions {
            phases: [2048, 2500, 1600],
            dc_link: 2500,
            ..Default::default()
        };
        assert!(!t.tripped(&ok, 3, 3_999.0));
        assert!(t.tripped(
            &RawConversions {
                phases: [2048, 2600, 2048],
                ..ok
            },
            3,
            0.0
        ));
        assert!(t.tripped(
            &RawConversions {
                phases: [4095, 2048, 2048],
                ..ok
            },
            3,
            0.0
        ));
        assert!(t.tripped(
            &RawConversions {
                phases: [2048, 2048, 0],
                ..ok
            },
            3,
            0.0
        ));
        // With two phases the third code is not a measurement.
        assert!(!t.tripped(
            &RawConversions {
                phases: [2048, 2048, 0],
                ..ok
            },
            2,
            0.0
        ));
        assert!(t.tripped(&RawConversions { dc_link: 2501, ..ok }, 3, 0.0));
        assert!(t.tripped(&ok, 3, -4_001.0));
        assert!(t.tripped(&ok, 3, f32::NAN));
        // A measured zero level per phase: v's at 40 000, so 2500 (40 000) is 0 A there
        // and 2048 (32 768) is 7 232 away — inside; 1900 (30 400, 9 600 away) trips.
        let moved = Trips {
            current_offset: [32_768, 40_000, 32_768],
            ..t
        };
        assert!(!moved.tripped(
            &RawConversions {
                phases: [2048, 2500, 2048],
                ..ok
            },
            3,
            0.0
        ));
        assert!(!moved.tripped(
            &RawConversions {
                phases: [2048, 2048, 2048],
                ..ok
            },
            3,
            0.0
        ));
        assert!(moved.tripped(
            &RawConversions {
                phases: [2048, 1900, 2048],
                ..ok
            },
            3,
            0.0
        ));
    }

    /// The reference board's ranks: ADC1 [i_u, SIN, U_dc], ADC2 [i_v, i_w, COS].
    #[test]
    fn conversions_by_signal() {
        let raw = assemble(
            &[100, 200, 300, 0],
            &[signal::CURRENT_U, signal::SIN, signal::DC_LINK],
            &[400, 500, 600, 0],
            &[signal::CURRENT_V, signal::CURRENT_W, signal::COS],
        );
        assert_eq!(
            raw,
            RawConversions {
                phases: [100, 400, 500],
                dc_link: 300,
                sin: 200,
                cos: 600
            }
        );
    }
}
