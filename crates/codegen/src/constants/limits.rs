//! The `limits` group: the switching (= sampling) frequency and the sample period (thesis
//! A (1.1), (4.17)), the voltage circle U_dc/√3 (thesis B (2.50)), the lowest DC-link
//! voltage of the 1/U_dc feed-forward (thesis A (5.1)), the third-harmonic modulator's
//! common mode (thesis A (3.7)), the current circle (thesis B (2.51)), the maximum
//! electrical speed (thesis A (2.19)), the ADC's settling multiple (thesis A (7.4)) and,
//! with an `[adc]` section in the spec, its sampling-time code (thesis A (7.2), (7.4)).

use super::Source::{Custom, F32};
use super::Text::{Lit, Of};
use super::{Decl, Group, Json, count, declare, fs_input, intv, phys, provenance};
use crate::design::Design;
use crate::design::adc::SampleTime;

/// What the limits' entries read.
struct Limits<'a> {
    d: &'a Design,
    /// f_s.
    fs: String,
}

impl<'a> Limits<'a> {
    /// The entries every design has.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "SWITCHING_FREQUENCY_HZ",
            value: F32(|c| c.d.drive.switching_frequency_hz, "Hz"),
            formula: Lit("f_s = sampling frequency"),
            equation: Lit("thesis A (1.1)"),
            inputs: Of(|c| c.fs.clone()),
            json: Json::At("/drive/switching_frequency_hz"),
        },
        Decl {
            name: "SAMPLE_PERIOD_S",
            value: F32(|c| c.d.drive.sample_period_s, "s"),
            formula: Lit("T_s = 1/f_s"),
            equation: Lit("thesis A (4.17)"),
            inputs: Of(|c| c.fs.clone()),
            json: Json::At("/drive/sample_period_s"),
        },
        Decl {
            name: "VOLTAGE_LIMIT_V",
            value: F32(|c| c.d.current_loop.voltage_limit_v, "V"),
            formula: Lit(
                "k·U_dc/√3 (voltage circle), k the usable fraction the board's duty limit leaves (1 without a board; with in-line sensing the dead time's gap p = t_d at either end of the carrier leaves a little less)",
            ),
            equation: Lit("thesis B (2.50); design::duty_limit"),
            inputs: Of(|c| {
                format!(
                    "U_dc = {} (spec), k = {}",
                    phys(c.d.drive.dc_link_voltage_v, "V"),
                    c.d.modulation.usable_voltage_fraction
                )
            }),
            json: Json::At("/current_loop/voltage_limit_v"),
        },
        Decl {
            name: "DC_LINK_MIN_V",
            value: F32(|c| c.d.drive.dc_link_voltage_min_v, "V"),
            formula: Lit("lowest U_dc for the 1/U_dc feed-forward (5.1)"),
            equation: Lit("thesis A (5.1)"),
            inputs: Lit("spec"),
            json: Json::At("/drive/dc_link_voltage_min_v"),
        },
        Decl {
            name: "THPWM_COMMON_MODE",
            value: F32(|c| c.d.modulation.thpwm_common_mode_ratio, ""),
            formula: Lit("u_NM/U_dc amplitude 1/(6√3)"),
            equation: Lit("thesis A (3.7)"),
            inputs: Lit("—"),
            json: Json::At("/modulation/thpwm_common_mode_ratio"),
        },
        Decl {
            name: "PEAK_CURRENT_A",
            value: F32(|c| c.d.motor.peak_current_a, "A"),
            formula: Lit("√2·I_peak,rms (current-circle radius)"),
            equation: Lit("thesis B (2.51)"),
            inputs: Of(|c| {
                format!(
                    "I_peak = {} rms ({})",
                    phys(c.d.motor.peak_current_a_rms, "A"),
                    provenance(c.d, "peak_current")
                )
            }),
            json: Json::At("/motor/peak_current_a"),
        },
        Decl {
            name: "MAX_ELECTRICAL_SPEED",
            value: F32(|c| c.d.motor.max_electrical_speed_rad_s, "rad/s"),
            formula: Lit("ω_e,max = n_p·ω_m,max"),
            equation: Lit("thesis A (2.19)"),
            inputs: Of(|c| format!("n_max ({})", provenance(c.d, "max_speed"))),
            json: Json::At("/motor/max_electrical_speed_rad_s"),
        },
        Decl {
            name: "ADC_SETTLING_TIME_CONSTANTS",
            value: Custom(|c| count(c.d.adc.settling_multiple.into(), "u32", "uint32_t")),
            formula: Lit("⌈−ln 2^−N⌉"),
            equation: Lit("thesis A (7.4)"),
            inputs: Of(|c| format!("N = {} bits", c.d.adc.resolution_bits)),
            json: Json::At("/adc/settling_multiple"),
        },
    ];
}

/// What the sampling-time entry reads: the sampling time chosen for the spec's `[adc]`.
struct Adc<'a> {
    t: &'a SampleTime,
}

impl<'a> Adc<'a> {
    /// The entry, after the others.
    const DECLS: &'a [Decl<Self>] = &[Decl {
        name: "ADC_SMP_CODE",
        value: Custom(|c| {
            (
                intv(c.t.smp_code.into(), "u8", "uint8_t"),
                format!("{} cycles = {}", c.t.cycles, phys(c.t.sample_time_s, "s")),
            )
        }),
        formula: Lit("smallest STM32G4 SMP ≥ multiple·(R_ADC + R_EXT)·C_ADC"),
        equation: Lit("thesis A (7.2), (7.4)"),
        inputs: Lit("adc section (spec)"),
        json: Json::At("/adc/sample_time/smp_code"),
    }];
}

/// The group.
pub fn group(d: &Design) -> Group {
    let limits = Limits { d, fs: fs_input(d) };
    let adc = d.adc.sample_time.as_ref().map(|t| Adc { t });
    Group {
        name: "limits",
        title: "Sampling, voltage and current limits, modulator and ADC",
        constants: declare(Limits::DECLS, &limits, "")
            .chain(adc.iter().flat_map(|a| declare(Adc::DECLS, a, "")))
            .collect(),
    }
}
