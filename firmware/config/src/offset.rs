//! The current sensing's zero level measured at start-up (pure; issue 26 item 1).
//!
//! With the gates off no phase current can flow (all six switches off, the motor's
//! windings open at the inverter), so every conversion of a phase-current channel is
//! that channel's zero level plus the converter's noise. The control interrupt feeds
//! the first [`OffsetBounds::samples`] periods' conversions to [`OffsetCalibration`]
//! with the outputs held off; their mean per phase (16-bit left-aligned codes, the
//! core's format, thesis A (4.16)) replaces the board's nominal zero level
//! (`board::CURRENT_OFFSET_CODE`) for the rest of the run, unless one phase deviates
//! from the nominal level by more than [`OffsetBounds::bound`] — then the drive faults
//! (`FaultCause::CurrentOffset`) and never switches on. N and the bound are generated
//! (`board::OFFSET_SAMPLES`, `board::OFFSET_BOUND_CODE`: codegen's
//! `design::sections::board::offset_samples`, `offset_bound_code`).
#![forbid(unsafe_code)]

use crate::adc_frame::RawConversions;
use crate::hw::ADC_BITS;

/// What the calibration is judged by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OffsetBounds {
    /// The board's nominal zero level \[16-bit code\].
    pub nominal: i32,
    /// Largest accepted |measured − nominal| \[16-bit codes\].
    pub bound: i32,
    /// Conversions averaged per phase (≥ 1).
    pub samples: u32,
}

/// Where the calibration stands after a period's conversions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffsetStatus {
    /// Still averaging: the outputs stay off.
    Measuring,
    /// Done: the zero level of phases u, v, w \[16-bit codes\] (an unmeasured third
    /// phase keeps the nominal level).
    Measured([i32; 3]),
    /// Done, and phase `phase` (0 = u) lies `deviation` codes from the nominal level,
    /// beyond the bound.
    OutOfBound {
        /// The first phase beyond the bound (0 = u, 1 = v, 2 = w).
        phase: u8,
        /// Its measured − nominal level \[16-bit codes\].
        deviation: i32,
    },
}

/// The running sums.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OffsetCalibration {
    sums: [u32; 3],
    taken: u32,
}

impl OffsetCalibration {
    /// Nothing measured yet.
    pub const fn new() -> Self {
        Self { sums: [0; 3], taken: 0 }
    }

    /// Adds one period's conversions of the `phases` measured phases (2 or 3) and says
    /// where the calibration stands; after the last sample every further call repeats
    /// the result.
    pub fn add(&mut self, bounds: &OffsetBounds, raw: &RawConversions, phases: usize) -> OffsetStatus {
        let n = bounds.samples.max(1);
        if self.taken < n {
            let full = (1u16 << ADC_BITS) - 1;
            for (sum, &code) in self.sums.iter_mut().zip(&raw.phases) {
                // 12-bit code → 16-bit left-aligned; N·65 520 < 2^32 for N < 65 553.
                let code16 = u32::from(code & full) << (16 - ADC_BITS);
                *sum = sum.saturating_add(code16);
            }
            self.taken = self.taken.saturating_add(1);
        }
        if self.taken < n {
            return OffsetStatus::Measuring;
        }
        let mut levels = [bounds.nominal; 3];
        for (k, (level, &sum)) in levels.iter_mut().zip(&self.sums).enumerate().take(phases.min(3)) {
            // Rounded mean: (sum + N/2)/N.
            let mean = sum.saturating_add(n / 2) / n;
            let mean = i32::try_from(mean).unwrap_or(i32::MAX);
            let deviation = mean.saturating_sub(bounds.nominal);
            if deviation.saturating_abs() > bounds.bound {
                return OffsetStatus::OutOfBound {
                    phase: k as u8,
                    deviation,
                };
            }
            *level = mean;
        }
        OffsetStatus::Measured(levels)
    }
}

/// The 16-bit phase-current codes `codes` moved from the measured zero levels `levels`
/// to the nominal one: `code − (level − nominal)`, saturated to the code range. The
/// control core's sensing ([`motor_control::adc::CurrentSense`], offset = nominal) then
/// computes `(code − level)·scale`, the current about the measured zero.
pub fn to_nominal(codes: [u16; 3], levels: [i32; 3], nominal: i32) -> [u16; 3] {
    let mut out = codes;
    for (c, &level) in out.iter_mut().zip(&levels) {
        let moved = i32::from(*c).saturating_sub(level.saturating_sub(nominal));
        *c = moved.clamp(0, i32::from(u16::MAX)) as u16;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const BOUNDS: OffsetBounds = OffsetBounds {
        nominal: 32_768,
        bound: 2_978,
        samples: 4,
    };

    fn raw(u: u16, v: u16, w: u16) -> RawConversions {
        RawConversions {
            phases: [u, v, w],
            ..Default::default()
        }
    }

    /// Four periods: u at 2048 (= 32 768) throughout, v alternating 2100/2101 (mean
    /// 33 608 = 32 768 + 840), w 2000 (32 000): measured [32 768, 33 608, 32 000], only
    /// after the fourth.
    #[test]
    fn mean_of_n_periods() {
        let mut c = OffsetCalibration::new();
        for k in 0..3u16 {
            assert_eq!(
                c.add(&BOUNDS, &raw(2048, 2100 + k % 2, 2000), 3),
                OffsetStatus::Measuring
            );
        }
        assert_eq!(
            c.add(&BOUNDS, &raw(2048, 2101, 2000), 3),
            OffsetStatus::Measured([32_768, 33_608, 32_000])
        );
        // Further periods change nothing.
        assert_eq!(
            c.add(&BOUNDS, &raw(0, 0, 0), 3),
            OffsetStatus::Measured([32_768, 33_608, 32_000])
        );
    }

    /// Bound 2 978 codes = 186.1 12-bit codes: w at 2048 + 186 (= 35 744, 2 976 off)
    /// passes, at 2048 − 187 (29 776, −2 992) fails with phase 2 and −2 992; with two
    /// measured phases w is not judged and keeps the nominal level.
    #[test]
    fn judged_against_the_bound() {
        let run = |w: u16, phases: usize| {
            let mut c = OffsetCalibration::new();
            (0..4)
                .map(|_| c.add(&BOUNDS, &raw(2048, 2048, w), phases))
                .last()
                .unwrap()
        };
        assert_eq!(run(2048 + 186, 3), OffsetStatus::Measured([32_768, 32_768, 35_744]));
        assert_eq!(
            run(2048 - 187, 3),
            OffsetStatus::OutOfBound {
                phase: 2,
                deviation: -2_992
            }
        );
        assert_eq!(run(2048 - 187, 2), OffsetStatus::Measured([32_768; 3]));
        // A dead sensor at the rail (code 0) is far beyond any bound.
        assert!(matches!(run(0, 3), OffsetStatus::OutOfBound { phase: 2, .. }));
    }

    /// A code at the measured zero becomes the nominal code; the rails saturate.
    #[test]
    fn codes_moved_to_the_nominal_zero() {
        let levels = [33_608, 32_000, 32_768];
        assert_eq!(
            to_nominal([33_608, 32_000, 40_000], levels, 32_768),
            [32_768, 32_768, 40_000]
        );
        assert_eq!(to_nominal([100, 65_520, 0], levels, 32_768), [0, 65_535, 0]);
    }
}
