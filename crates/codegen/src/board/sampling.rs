//! ADC sampling time of one input from what drives it: the datasheet's table of the
//! largest source resistance per sampling time and channel class (DS12288 Table 67)
//! and the settling rule of thesis A (7.2), (7.4), whichever asks for more.
//!
//! DS12288 Table 67 ("Maximum ADC R_AIN", 12 bits) lists, for each sampling option at
//! f_ADC = 60 MHz, the sampling time and the largest R_AIN for fast channels
//! (ADCx_IN1–IN5) and slow channels (all others; 2.5 cycles is "N/A" there). It is the
//! sampling *time* that settles the input, so at another ADC clock the rule is: the
//! shortest sampling option whose time is at least the table time of the first row
//! that allows the source resistance.

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

/// DS12288 Table 67, 12-bit rows: (sampling cycles at 60 MHz, sampling time \[ns\],
/// R_AIN max fast \[Ω\], R_AIN max slow \[Ω\], `None` = not allowed).
pub const TABLE_67_12_BIT: [(f64, f64, f64, Option<f64>); 8] = [
    (2.5, 41.67, 100.0, None),
    (6.5, 108.33, 330.0, Some(100.0)),
    (12.5, 208.33, 680.0, Some(470.0)),
    (24.5, 408.33, 1_500.0, Some(1_200.0)),
    (47.5, 791.67, 2_200.0, Some(1_800.0)),
    (92.5, 1_541.67, 4_700.0, Some(3_900.0)),
    (247.5, 4_125.0, 12_000.0, Some(10_000.0)),
    (640.5, 10_675.0, 39_000.0, Some(33_000.0)),
];

/// Internal sample-and-hold capacitor C_ADC = 5 pF (DS12288 Table 66, typical).
pub const SAMPLE_CAPACITANCE_F: f64 = 5e-12;

/// ADC resolution the firmware converts with \[bit\] (ADC_CFGR.RES = 0).
pub const RESOLUTION_BITS: u32 = 12;

/// The sampling time an input needs and the option chosen for it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Sampling {
    /// Fast channel (IN1–IN5) or slow.
    pub fast: bool,
    /// Source resistance R_AIN \[Ω\].
    pub source_resistance_ohm: f64,
    /// Sampling time DS12288 Table 67 asks for \[s\].
    pub table_time_s: f64,
    /// n·R·C_ADC of thesis A (7.2), (7.4) \[s\] (n = ⌈N·ln 2⌉ = 9 for 12 bits).
    pub settling_time_s: f64,
    /// ADC_SMPR code of the shortest option meeting both (RM0440 §21.4.12).
    pub smp_code: u8,
    /// Its sampling cycles.
    pub cycles: f64,
}

/// Why no sampling option fits.
#[derive(Debug, Clone, PartialEq)]
pub struct TooSlow {
    /// The largest source resistance the class allows at 640.5 cycles \[Ω\].
    pub max_ohm: f64,
}

/// Required sampling time \[s\] of DS12288 Table 67 for `r_ohm` on a fast or slow channel.
pub fn table_time(r_ohm: f64, fast: bool) -> Result<f64, TooSlow> {
    TABLE_67_12_BIT
        .iter()
        .find(|(_, _, f, s)| {
            if fast {
                r_ohm <= *f
            } else {
                s.is_some_and(|s| r_ohm <= s)
            }
        })
        .map(|(_, ns, _, _)| ns * 1e-9)
        .ok_or(TooSlow {
            max_ohm: if fast { 39_000.0 } else { 33_000.0 },
        })
}

/// The sampling option for an input with source resistance `r_ohm` on a fast or slow
/// channel at ADC clock `adc_hz`.
pub fn sampling(r_ohm: f64, fast: bool, adc_hz: f64) -> Result<Sampling, TooSlow> {
    let table = table_time(r_ohm, fast)?;
    let settling = f64::from(settling_multiple(RESOLUTION_BITS)) * r_ohm * SAMPLE_CAPACITANCE_F;
    let need = table.max(settling);
    // The table prints times to 0.01 ns (2.5 cycles at 60 MHz = 41.667 ns as 41.67): a
    // relative tolerance of 10⁻³ keeps each row on its own option at 60 MHz.
    let (code, cycles) = STM32G4_SAMPLE_CYCLES
        .iter()
        .enumerate()
        .find(|&(_, &c)| c / adc_hz >= need * (1.0 - 1e-3))
        .ok_or(TooSlow {
            max_ohm: if fast { 39_000.0 } else { 33_000.0 },
        })?;
    Ok(Sampling {
        fast,
        source_resistance_ohm: r_ohm,
        table_time_s: table,
        settling_time_s: settling,
        smp_code: code as u8,
        cycles: *cycles,
    })
}

/// The smallest option of `STM32G4_SAMPLE_CYCLES` with at least `cycles` cycles, if
/// `cycles` is one of them.
pub fn code_of(cycles: f64) -> Option<u8> {
    STM32G4_SAMPLE_CYCLES
        .iter()
        .position(|&c| (c - cycles).abs() < 1e-9)
        .map(|i| i as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    const F: f64 = 42.5e6;

    /// Thesis A (7.4): −ln(1/2^12) ≈ 8.32, rounded up to 9.
    #[test]
    fn twelve_bits_need_nine_time_constants() {
        assert!((settling_time_constants(12) - 8.3178).abs() < 1e-4);
        assert_eq!(settling_multiple(12), 9);
    }

    /// The case: PA4 is ADC2_IN17, a slow channel; 1.1 kΩ needs the 1.2 kΩ row
    /// (24.5 cycles, 408.33 ns); at 42.5 MHz 12.5 cycles is 294 ns (too short), 24.5
    /// cycles is 576 ns: code 3. The (7.4) rule alone (9·1.1 kΩ·5 pF = 49.5 ns) would
    /// have allowed 2.5 cycles (58.8 ns), the old firmware's choice.
    #[test]
    fn slow_channel_at_1k1_needs_24_5_cycles() {
        let s = sampling(1_100.0, false, F).unwrap();
        assert_eq!((s.smp_code, s.cycles), (3, 24.5));
        assert!((s.table_time_s - 408.33e-9).abs() < 1e-12);
        assert!((s.settling_time_s - 49.5e-9).abs() < 1e-15);
    }

    /// Fast channels: 100 Ω is the only source 2.5 cycles allows (Table 67, 41.67 ns;
    /// 2.5/42.5 MHz = 58.8 ns ≥ it); 101 Ω needs the 330 Ω row (108.33 ns → 6.5 cycles
    /// = 153 ns); a slow channel never gets 2.5 cycles, even at 10 Ω (100 Ω row of 6.5
    /// cycles).
    #[test]
    fn two_and_a_half_cycles_only_for_fast_low_impedance() {
        assert_eq!(sampling(100.0, true, F).unwrap().smp_code, 0);
        assert_eq!(sampling(101.0, true, F).unwrap().smp_code, 1);
        assert_eq!(sampling(10.0, false, F).unwrap().smp_code, 1);
    }

    /// Beyond the last row (39 kΩ fast, 33 kΩ slow) there is no option; at the table's
    /// own 60 MHz every row maps onto its own option.
    #[test]
    fn table_rows_at_sixty_megahertz_and_the_limits() {
        assert_eq!(sampling(40_000.0, true, F), Err(TooSlow { max_ohm: 39_000.0 }));
        assert_eq!(sampling(34_000.0, false, F), Err(TooSlow { max_ohm: 33_000.0 }));
        for (k, (cycles, _, fast, _)) in TABLE_67_12_BIT.iter().enumerate() {
            // R at the row's limit, large enough that (7.4) does not dominate (9·R·5 pF
            // < the row's time for every row: 9·39 kΩ·5 pF = 1.76 µs < 10.7 µs).
            let s = sampling(*fast, true, 60e6).unwrap();
            assert_eq!((s.smp_code as usize, s.cycles), (k, *cycles));
        }
        assert_eq!(code_of(24.5), Some(3));
        assert_eq!(code_of(3.0), None);
    }
}
