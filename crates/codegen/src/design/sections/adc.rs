//! The ADC section: the settling rule (7.4) and, with `[adc]`, the sampling time chosen
//! from the STM32G474's settings.

use serde::Serialize;

use super::Context;
use crate::board::sampling::{settling_multiple, settling_time_constants};
use crate::design::adc;

/// The ADC settling rule.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AdcOut {
    /// N bits.
    pub resolution_bits: u32,
    /// −ln(2^−N) (7.4).
    pub settling_time_constants: f64,
    /// ⌈N·ln 2⌉ time constants used.
    pub settling_multiple: u32,
    /// The chosen sampling time, if `[adc]` is given.
    pub sample_time: Option<adc::SampleTime>,
}

/// The ADC section; a source no sampling time can settle is an error at `adc.source_resistance`.
pub(in crate::design) fn adc(cx: &mut Context<'_>) -> AdcOut {
    let (bits, sample_time) = match &cx.spec.adc {
        Some(a) => {
            let st = adc::choose_sample_time(
                a.resolution_bits,
                a.clock.value,
                a.sample_capacitance.value,
                a.switch_resistance.value,
                a.source_resistance.value,
            );
            if st.is_none() {
                cx.errors.push(cx.src.error(
                    a.source_resistance.span.clone(),
                    &a.source_resistance.key,
                    format!(
                        "even 640.5 ADC cycles at {} Hz cannot settle the sample-and-hold to 1 LSB (7.4)",
                        a.clock.value
                    ),
                    "a lower source resistance or a slower ADC clock",
                ));
            }
            (a.resolution_bits, st)
        }
        None => (12, None),
    };
    AdcOut {
        resolution_bits: bits,
        settling_time_constants: settling_time_constants(bits),
        settling_multiple: settling_multiple(bits),
        sample_time,
    }
}
