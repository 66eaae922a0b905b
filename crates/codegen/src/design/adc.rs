//! ADC sampling time from the sample-and-hold settling rule, thesis A (7.2)–(7.4), for
//! the spec's `[adc]` circuit: τ = (R_ADC + R_EXT)·C_ADC (7.2) and the shortest STM32G4
//! sampling option of at least ⌈N·ln 2⌉·τ. The settling multiple (7.4) and the chip's
//! sampling options are facts the board checks use too, so they live in the board layer
//! ([`crate::board::sampling`]).

use serde::Serialize;

use crate::board::sampling::{STM32G4_SAMPLE_CYCLES, settling_multiple};

/// A chosen STM32G4 sampling time.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SampleTime {
    /// τ = (R_ADC + R_EXT)·C_ADC (7.2) \[s\].
    pub time_constant_s: f64,
    /// Minimum sampling time = multiple·τ \[s\].
    pub min_sample_time_s: f64,
    /// ADC_SMPR code (0..=7).
    pub smp_code: u8,
    /// Sampling cycles of that code.
    pub cycles: f64,
    /// Resulting sampling time \[s\].
    pub sample_time_s: f64,
}

/// Smallest STM32G4 sampling time that settles the S&H capacitor, or `None` if even 640.5 cycles is too short.
pub fn choose_sample_time(
    bits: u32,
    clock_hz: f64,
    c_adc_f: f64,
    r_adc_ohm: f64,
    r_ext_ohm: f64,
) -> Option<SampleTime> {
    let tau = (r_adc_ohm + r_ext_ohm) * c_adc_f;
    let t_min = f64::from(settling_multiple(bits)) * tau;
    let (code, cycles) = STM32G4_SAMPLE_CYCLES
        .iter()
        .enumerate()
        .find(|&(_, &c)| c / clock_hz >= t_min)?;
    Some(SampleTime {
        time_constant_s: tau,
        min_sample_time_s: t_min,
        smp_code: code as u8,
        cycles: *cycles,
        sample_time_s: cycles / clock_hz,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand calculation: τ = (1 kΩ + 0.1 kΩ)·5 pF = 5.5 ns; 9τ = 49.5 ns;
    /// at 42.5 MHz that is 2.10 cycles → 2.5 cycles (code 0). With R_EXT = 10 kΩ:
    /// τ = 50.5 ns, 9τ = 454.5 ns = 19.3 cycles → 24.5 cycles (code 3).
    #[test]
    fn picks_the_smallest_sufficient_option() {
        let s = choose_sample_time(12, 42.5e6, 5e-12, 100.0, 1_000.0).unwrap();
        assert_eq!((s.smp_code, s.cycles), (0, 2.5));
        let s = choose_sample_time(12, 42.5e6, 5e-12, 100.0, 10_000.0).unwrap();
        assert_eq!((s.smp_code, s.cycles), (3, 24.5));
        assert!(choose_sample_time(12, 42.5e6, 5e-12, 100.0, 1e9).is_none());
    }
}
