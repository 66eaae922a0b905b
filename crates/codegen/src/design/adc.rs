//! ADC sampling time from the sample-and-hold settling rule, thesis A (7.2)–(7.4).

use serde::Serialize;

/// STM32G4 ADC_SMPR sampling-time options in ADC clock cycles, codes 0..=7 (RM0440).
pub const STM32G4_SAMPLE_CYCLES: [f64; 8] = [2.5, 6.5, 12.5, 24.5, 47.5, 92.5, 247.5, 640.5];

/// t_sample/τ needed to settle to 1 LSB of an N-bit converter: −ln(2^−N) (7.4).
pub fn settling_time_constants(bits: u32) -> f64 {
    f64::from(bits) * std::f64::consts::LN_2
}

/// The whole number of time constants used: ⌈N·ln 2⌉ (thesis A: 8.32 → "use ≥ 9").
pub fn settling_multiple(bits: u32) -> u32 {
    settling_time_constants(bits).ceil() as u32
}

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

    /// Thesis A (7.4): −ln(1/2^12) ≈ 8.32, rounded up to 9.
    #[test]
    fn twelve_bits_need_nine_time_constants() {
        assert!((settling_time_constants(12) - 8.3178).abs() < 1e-4);
        assert_eq!(settling_multiple(12), 9);
    }

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
