//! The `board` group: the inverter board's facts with this motor (only for a design on a
//! board, `crate::design_with_board`). It declares the gate and I/O pins and their
//! alternate functions (DS12288 Table 13), per converter (`ADC1_…`, `ADC2_…`, one table
//! for both) the injected sequence's channels, signals and sampling times (RM0440
//! §21.4.21; DS12288 Table 67, thesis A (7.2), (7.4)), the ADC clock, the ADC-to-SI
//! scalings of the sensing (thesis A (4.16), Table 4.1), the measured phases (thesis A
//! (2.7)), the dead time (thesis A §3.2), the sampling instant, break polarity and BOOT0
//! handling (RM0440 §28, §3.4.1; DS12288 §3.7), the trips, the CAN timing, the watchdog
//! and the conversion time (DS12288 Table 66). Every entry is taken from the board file
//! (its key is named) or computed from it with the formula given.

use super::Source::{Custom, F32};
use super::Text::{Lit, Of};
use super::{Decl, Group, Json, Value, count, declare, intv, phys, u8_array};
use crate::board::{ADC_CLOCK_HZ, AdcSlot, Board};
use crate::design::BoardOut;
use crate::design::Design;

/// `port·16 + pin` codes as pin names, `—` for none.
fn pins(list: &[u8]) -> String {
    list.iter()
        .map(|&p| {
            if p == u8::MAX {
                "—".to_string()
            } else {
                format!("P{}{}", (b'A' + p / 16) as char, p % 16)
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// What the board's entries read.
struct OnBoard<'a> {
    d: &'a Design,
    o: &'a BoardOut,
    b: &'a Board,
    /// V_REF+, the current sensing's gain and offset.
    current: String,
    /// V_REF+ and the DC-link divider.
    dc_link: String,
}

impl<'a> OnBoard<'a> {
    /// The pins, before the converters' entries.
    const PINS: &'a [Decl<Self>] = &[
        Decl {
            name: "GATE_PINS",
            value: Custom(|c| {
                let physical = format!("{}: u/v/w high, u/v/w low", pins(&c.o.gate_pins));
                (u8_array(&c.o.gate_pins), physical)
            }),
            formula: Lit("port·16 + pin of TIM1_CH1..3, CH1N..3N"),
            equation: Lit("DS12288 / RM0440 (board file)"),
            inputs: Of(|c| c.key("pins.gate_*")),
            json: Json::At("/board/gate_pins"),
        },
        Decl {
            name: "GATE_AFS",
            value: Custom(|c| (u8_array(&c.o.gate_afs), format!("AF {:?}", c.o.gate_afs))),
            formula: Lit("GPIOx_AFRL/AFRH alternate function of each gate pin (chip pin table)"),
            equation: Lit("DS12288 Table 13"),
            inputs: Of(|c| c.key("pins.gate_*")),
            json: Json::At("/board/gate_afs"),
        },
        Decl {
            name: "IO_PINS",
            value: Custom(|c| {
                let physical = format!("{}: break, excitation, CAN RX, CAN TX", pins(&c.o.io_pins));
                (u8_array(&c.o.io_pins), physical)
            }),
            formula: Lit("port·16 + pin of TIM1_BKIN, TIM3_CH1, FDCAN1_RX, FDCAN1_TX"),
            equation: Lit("DS12288 / RM0440 (board file)"),
            inputs: Of(|c| c.key("pins")),
            json: Json::At("/board/io_pins"),
        },
        Decl {
            name: "IO_AFS",
            value: Custom(|c| (u8_array(&c.o.io_afs), format!("AF {:?}", c.o.io_afs))),
            formula: Lit("alternate function of each (chip pin table)"),
            equation: Lit("DS12288 Table 13"),
            inputs: Of(|c| c.key("pins")),
            json: Json::At("/board/io_afs"),
        },
    ];

    /// Clock, scalings, dead time, polarities, trips, CAN, watchdog: after the converters.
    const DRIVE: &'a [Decl<Self>] = &[
        Decl {
            name: "ADC_CLOCK_HZ",
            value: Custom(|_| (intv(ADC_CLOCK_HZ as i64, "u32", "uint32_t"), phys(ADC_CLOCK_HZ, "Hz"))),
            formula: Lit("f_ADC the sampling codes are chosen for: HCLK/4"),
            equation: Lit("RM0440 §21.4.3"),
            inputs: Lit("the firmware's clock tree"),
            json: Json::None,
        },
        Decl {
            name: "TIMER_CLOCK_HZ",
            value: Custom(|_| {
                let f = crate::firmware::TIMER_CLOCK_HZ;
                (intv(f.into(), "u32", "uint32_t"), phys(f64::from(f), "Hz"))
            }),
            formula: Lit("TIM1 kernel clock the dead-time and auto-reload limits were checked with: SYSCLK, APB2 ×1"),
            equation: Lit("RM0440 §7.2.17; DS12288 §3.9"),
            inputs: Lit("the firmware's clock tree"),
            json: Json::None,
        },
        Decl {
            name: "FDCAN_CLOCK_HZ",
            value: Custom(|c| {
                let f = c.o.can_timing.kernel_clock_hz;
                (intv(f.into(), "u32", "uint32_t"), phys(f64::from(f), "Hz"))
            }),
            formula: Lit(
                "FDCAN kernel clock the bit timing is computed from: the board's HSE crystal (RCC_CCIPR.FDCANSEL = 0b00), else PCLK1 (0b10)",
            ),
            equation: Lit("RM0440 §7.4.26"),
            inputs: Of(|c| c.key("clock.hse")),
            json: Json::None,
        },
        Decl {
            name: "LSI_HZ",
            value: Custom(|_| {
                let f = crate::firmware::LSI_HZ;
                (intv(f.into(), "u32", "uint32_t"), phys(f64::from(f), "Hz"))
            }),
            formula: Lit("LSI clock the watchdog-timeout limit was checked with (typical)"),
            equation: Lit("DS12288 Table 56"),
            inputs: Lit("the chip"),
            json: Json::None,
        },
        Decl {
            name: "CURRENT_OFFSET_CODE",
            value: Custom(|c| {
                let physical = format!("{} V at 0 A", c.b.current.offset_v);
                (intv(c.o.current_offset_code.into(), "i32", "int32_t"), physical)
            }),
            formula: Lit("V_0/V_REF+·2^16 (16-bit left-aligned code)"),
            equation: Lit("thesis A (4.16)"),
            inputs: Of(|c| c.current.clone()),
            json: Json::At("/board/current_offset_code"),
        },
        Decl {
            name: "CURRENT_PER_LSB",
            value: F32(|c| c.o.amps_per_lsb, "A"),
            formula: Lit(
                "V_REF+/(G·2^16), G the signed gain at the pin (shunt: gain·R, −R for low-side shunts; Hall: ±sensitivity)",
            ),
            equation: Lit("thesis A (4.16)"),
            inputs: Of(|c| c.current.clone()),
            json: Json::At("/board/amps_per_lsb"),
        },
        Decl {
            name: "CURRENT_FULL_SCALE_A",
            value: F32(|c| c.o.current_full_scale_a, "A"),
            formula: Lit("min(V_0, V_REF+ − V_0)/G"),
            equation: Lit("thesis A (4.16), Table 4.1"),
            inputs: Of(|c| c.current.clone()),
            json: Json::At("/board/current_full_scale_a"),
        },
        Decl {
            name: "OFFSET_SAMPLES",
            value: Custom(|c| count(c.o.offset_samples.into(), "u32", "uint32_t")),
            formula: Lit(
                "smallest power of two N with 3·σ/√N ≤ 1/4 LSB, σ = 1 LSB rms taken for the converter (conversions per phase averaged at start-up, gates off)",
            ),
            equation: Lit("standard error of a mean; design::sections::board::offset_samples"),
            inputs: Lit("the ADC's 12-bit resolution"),
            json: Json::At("/board/offset_samples"),
        },
        Decl {
            name: "OFFSET_BOUND_CODE",
            value: Custom(|c| {
                let code = c.o.offset_bound_code;
                let volts = f64::from(code) / 65_536.0 * c.b.adc_reference_v;
                let physical = format!(
                    "{volts:.4} V = {:.2} A from the nominal zero level",
                    volts / c.b.current.gain_v_per_a.abs()
                );
                (intv(code.into(), "i32", "int32_t"), physical)
            }),
            formula: Lit(
                "(min(V_0, V_REF+ − V_0) − |G|·I_oc)/V_REF+·2^16, rounded down: the room between the over-current ceiling and the nearer ADC rail (16-bit left-aligned codes)",
            ),
            equation: Lit("thesis A (4.16); design::sections::board::offset_bound_code"),
            inputs: Of(|c| format!("{}, protection.over_current", c.current)),
            json: Json::At("/board/offset_bound_code"),
        },
        Decl {
            name: "CURRENT_PHASES",
            value: Custom(|c| count(c.o.current_phases.into(), "u8", "uint8_t")),
            formula: Lit("phase currents measured (the third from i_u + i_v + i_w = 0 when 2)"),
            equation: Lit("thesis A (2.7)"),
            inputs: Of(|c| c.key("pins.current_w")),
            json: Json::At("/board/current_phases"),
        },
        Decl {
            name: "DC_LINK_PER_LSB",
            value: F32(|c| c.o.dc_link_volts_per_lsb, "V"),
            formula: Lit("V_REF+/(ratio·2^15)"),
            equation: Lit("thesis A (4.16)"),
            inputs: Of(|c| c.dc_link.clone()),
            json: Json::At("/board/dc_link_volts_per_lsb"),
        },
        Decl {
            name: "DC_LINK_FULL_SCALE_V",
            value: F32(|c| c.o.dc_link_full_scale_v, "V"),
            formula: Lit("V_REF+/ratio"),
            equation: Lit("thesis A (4.16)"),
            inputs: Of(|c| c.dc_link.clone()),
            json: Json::At("/board/dc_link_full_scale_v"),
        },
        Decl {
            name: "DEAD_TIME_NS",
            value: Custom(|c| {
                let ns = c.o.dead_time_ns;
                (intv(ns.into(), "u32", "uint32_t"), format!("{ns} ns"))
            }),
            formula: Lit("max(pwm.dead_time, spec drive.dead_time), rounded up to 1 ns"),
            equation: Lit("thesis A §3.2"),
            inputs: Of(|c| c.key("pwm.dead_time")),
            json: Json::At("/board/dead_time_ns"),
        },
        Decl {
            name: "SAMPLE_AT_CARRIER_MAXIMUM",
            value: Custom(|c| {
                let physical = format!("{:?}", c.b.sample_instant);
                (intv(c.o.sample_at_carrier_maximum.into(), "u8", "uint8_t"), physical)
            }),
            formula: Lit(
                "1: ADC trigger TRGO2 = OC4REF at the carrier maximum (low-side pulse centre); 0: at the minimum",
            ),
            equation: Lit("RM0440 §28.3.5, §28.6.2"),
            inputs: Of(|c| c.key("sensing.sample_instant")),
            json: Json::At("/board/sample_at_carrier_maximum"),
        },
        Decl {
            name: "EXCITATION_SHIFT_TICKS",
            value: Custom(|c| {
                let ticks = c.o.excitation_shift_ticks;
                let ns = f64::from(ticks) / f64::from(crate::firmware::TIMER_CLOCK_HZ) * 1e9;
                (
                    intv(ticks.into(), "u16", "uint16_t"),
                    format!("{ticks} ticks = {ns:.1} ns"),
                )
            }),
            formula: Lit(
                "round(t_res·170 MHz), t_res the resolver's mean hold instant after the ADC trigger: TIM3 toggles the f_s/2 excitation ARR + shift ticks after each trigger, so its fundamental peaks when SIN and COS are held",
            ),
            equation: Lit("thesis A §4.3, §4.4.1; RM0440 §21.4.12"),
            inputs: Of(|c| c.key("sensing.source_resistance.resolver")),
            json: Json::At("/board/excitation_shift_ticks"),
        },
        Decl {
            name: "RESOLVER_SIGNAL",
            value: F32(|c| c.o.resolver_signal, ""),
            formula: Lit(
                "A/(V_REF+/2)·cos(π·f_s·Δt/2): the front end's SIN/COS peak over the ADC's half range, times the f_s/2 excitation's envelope at windings held Δt apart about its peak — the resolver signal's fraction of full scale the image measures at start-up (fault 19 outside RESOLVER_SIGNAL_MIN … RESOLVER_SIGNAL_MAX of it)",
            ),
            equation: Lit("thesis A §4.3, (4.10)"),
            inputs: Of(|c| c.key("sensing.resolver_amplitude")),
            json: Json::At("/board/resolver_signal"),
        },
        Decl {
            name: "RESOLVER_SIGNAL_MIN",
            value: F32(|c| c.o.resolver_signal_ratio_min, ""),
            formula: Lit(
                "(1 − 0.2)²: the least measured/designed resolver signal the start-up check accepts — the trig-identity observer's ω_n and ζ scale with its square root (4.10), so ω_n stays within 20 % of the design",
            ),
            equation: Lit("thesis A (4.10)"),
            inputs: Lit("—"),
            json: Json::At("/board/resolver_signal_ratio_min"),
        },
        Decl {
            name: "RESOLVER_SIGNAL_MAX",
            value: F32(|c| c.o.resolver_signal_ratio_max, ""),
            formula: Lit("(1 + 0.2)²: the largest measured/designed resolver signal the start-up check accepts"),
            equation: Lit("thesis A (4.10)"),
            inputs: Lit("—"),
            json: Json::At("/board/resolver_signal_ratio_max"),
        },
        Decl {
            name: "BREAK_ACTIVE_HIGH",
            value: Custom(|c| {
                let physical = format!("{:?}", c.b.break_polarity);
                (intv(c.o.break_active_high.into(), "u8", "uint8_t"), physical)
            }),
            formula: Lit("TIM1_BDTR.BKP"),
            equation: Lit("RM0440 §28.6.20"),
            inputs: Of(|c| c.key("break_input.polarity")),
            json: Json::At("/board/break_active_high"),
        },
        Decl {
            name: "BREAK_PULL",
            value: Custom(|c| {
                let physical = match c.o.break_pull {
                    1 => "pull-up",
                    2 => "pull-down",
                    _ => "none",
                };
                (intv(c.o.break_pull.into(), "u8", "uint8_t"), physical.to_string())
            }),
            formula: Lit(
                "GPIOx_PUPDR of the break pin: none for a push-pull comparator, else a pull to the inactive level",
            ),
            equation: Lit("RM0440 GPIOx_PUPDR"),
            inputs: Of(|c| c.key("break_input.output, break_input.polarity")),
            json: Json::At("/board/break_pull"),
        },
        Decl {
            name: "TIM1_CCER_POLARITY",
            value: Custom(|c| {
                let v = c.o.tim1_ccer_polarity;
                (intv(v.into(), "u32", "uint32_t"), format!("{v:#06x}"))
            }),
            formula: Lit(
                "CCxP (bit 4x−3) for an inverted high-side input, CCxNP (bit 4x−1) for an inverted low-side input, x = 1..3",
            ),
            equation: Lit("RM0440 TIMx_CCER; gate-driver datasheet (parts table)"),
            inputs: Of(|c| c.key("gate_driver")),
            json: Json::At("/board/tim1_ccer_polarity"),
        },
        Decl {
            name: "TIM1_CR2_IDLE",
            value: Custom(|c| {
                let v = c.o.tim1_cr2_idle;
                (intv(v.into(), "u32", "uint32_t"), format!("{v:#06x}"))
            }),
            formula: Lit(
                "OISx (bit 2x+6) / OISxN (bit 2x+7) = the input's off level (1 for an inverted input), x = 1..3; written before BDTR's LOCK",
            ),
            equation: Lit("RM0440 TIMx_CR2, TIMx_BDTR LOCK level 1"),
            inputs: Of(|c| c.key("gate_driver")),
            json: Json::At("/board/tim1_cr2_idle"),
        },
        Decl {
            name: "GATE_OFF_LEVELS",
            value: Custom(|c| {
                let physical = format!("{:?}: u/v/w high, u/v/w low", c.o.gate_off_levels);
                (u8_array(&c.o.gate_off_levels), physical)
            }),
            formula: Lit("pin level that turns each switch off: 0 for an in-phase input, 1 for an inverted one"),
            equation: Lit("gate-driver datasheet (parts table)"),
            inputs: Of(|c| c.key("gate_driver")),
            json: Json::At("/board/gate_off_levels"),
        },
        Decl {
            name: "HSE_HZ",
            value: Custom(|c| {
                let f = c.o.hse_hz;
                let physical = if f == 0 {
                    "no crystal".to_string()
                } else {
                    phys(f64::from(f), "Hz")
                };
                (intv(f.into(), "u32", "uint32_t"), physical)
            }),
            formula: Lit("HSE crystal frequency on the board, 0 = none"),
            equation: Lit("DS12288 §5.3.7 (4–48 MHz)"),
            inputs: Of(|c| c.key("clock.hse")),
            json: Json::At("/board/hse_hz"),
        },
        Decl {
            name: "BOOT0_OPTION_BYTES",
            value: Custom(|c| {
                let physical = format!("{:?}", c.b.boot0);
                (intv(c.o.boot0_option_bytes.into(), "u8", "uint8_t"), physical)
            }),
            formula: Lit(
                "1: the image requires FLASH_OPTR.nSWBOOT0 = 0, nBOOT0 = 1 (PB8 does not select the boot mode)",
            ),
            equation: Lit("DS12288 §3.7; RM0440 §3.4.1"),
            inputs: Of(|c| c.key("boot0.handling")),
            json: Json::At("/board/boot0_option_bytes"),
        },
        Decl {
            name: "OVER_CURRENT_A",
            value: F32(|c| c.o.trips.over_current_a.value, "A"),
            formula: Lit(
                "trip when any |i_phase| exceeds min(margin·√2·I_peak (the motor's full scale), protection.over_current (the board's ceiling))",
            ),
            equation: Lit("thesis A Table 4.1"),
            inputs: Of(|c| c.trip(&c.o.trips.over_current_a, "A", 1.0)),
            json: Json::At("/board/trips/over_current_a/value"),
        },
        Decl {
            name: "OVER_VOLTAGE_V",
            value: F32(|c| c.o.trips.over_voltage_v.value, "V"),
            formula: Lit(
                "trip when U_dc exceeds min(margin·U_dc (the motor's full scale), protection.over_voltage (the board's ceiling))",
            ),
            equation: Lit("thesis A Table 4.1"),
            inputs: Of(|c| c.trip(&c.o.trips.over_voltage_v, "V", 1.0)),
            json: Json::At("/board/trips/over_voltage_v/value"),
        },
        Decl {
            name: "OVER_SPEED_E_RAD_S",
            value: F32(|c| c.o.over_speed_electrical_rad_s, "rad/s"),
            formula: Lit(
                "n_p·min(margin·n_max (the motor's), protection.over_speed (the board's ceiling)): trip when |ω_e| exceeds it",
            ),
            equation: Lit("thesis A (2.19)"),
            inputs: Of(|c| {
                format!(
                    "{}; n_p = {}",
                    c.trip(&c.o.trips.over_speed_rad_s, "rpm", 30.0 / std::f64::consts::PI),
                    c.d.motor.pole_pairs
                )
            }),
            json: Json::At("/board/over_speed_electrical_rad_s"),
        },
        Decl {
            name: "CAN_BIT_RATE",
            value: Custom(|c| {
                let rate = c.o.can_bit_rate;
                (intv(rate.into(), "u32", "uint32_t"), phys(f64::from(rate), "bit/s"))
            }),
            formula: Lit("FDCAN1 nominal bit rate"),
            equation: Lit("RM0440 §44.4.7"),
            inputs: Of(|c| c.key("can.bit_rate")),
            json: Json::At("/board/can_bit_rate"),
        },
        Decl {
            name: "CAN_NBTP",
            value: Custom(|c| {
                let t = &c.o.can_timing;
                let physical = format!(
                    "{:#010x}: prescaler {}, {} quanta = 1 + {} + {}, sample point {:.2} %, SJW {}",
                    t.nbtp,
                    t.prescaler,
                    t.tq_per_bit,
                    t.tseg1,
                    t.tseg2,
                    t.sample_point * 100.0,
                    t.sjw
                );
                (intv(t.nbtp.into(), "u32", "uint32_t"), physical)
            }),
            formula: Lit(
                "f_FDCAN = rate·prescaler·(1 + TSEG1 + TSEG2), sample point nearest 87.5 %, smallest prescaler, SJW = TSEG2; fields value − 1",
            ),
            equation: Lit("RM0440 §44.4.7 (FDCAN_NBTP); CiA 601-3"),
            inputs: Of(|c| {
                format!(
                    "{}, FDCAN kernel clock {} Hz",
                    c.key("can.bit_rate"),
                    c.o.can_timing.kernel_clock_hz
                )
            }),
            json: Json::At("/board/can_timing/nbtp"),
        },
        Decl {
            name: "SETPOINT_ID",
            value: Custom(|c| {
                let id = c.b.setpoint_id;
                (intv(id.into(), "u16", "uint16_t"), format!("{id:#05x}"))
            }),
            formula: Lit("standard identifier of the torque setpoint"),
            equation: Lit("—"),
            inputs: Of(|c| c.key("can.setpoint_id")),
            json: Json::At("/board/board/setpoint_id"),
        },
        Decl {
            name: "SETPOINT_PERIOD_S",
            value: F32(|c| c.b.setpoint_period_s, "s"),
            formula: Lit("period the vehicle unit sends at"),
            equation: Lit("—"),
            inputs: Of(|c| c.key("can.setpoint_period")),
            json: Json::At("/board/board/setpoint_period_s"),
        },
        Decl {
            name: "SETPOINT_TIMEOUT_S",
            value: F32(|c| c.b.setpoint_timeout_s, "s"),
            formula: Lit("no setpoint for this long → ramp to zero"),
            equation: Lit("—"),
            inputs: Of(|c| c.key("can.setpoint_timeout")),
            json: Json::At("/board/board/setpoint_timeout_s"),
        },
        Decl {
            name: "SETPOINT_RAMP_S",
            value: F32(|c| c.b.setpoint_ramp_s, "s"),
            formula: Lit("time from the peak current to zero"),
            equation: Lit("—"),
            inputs: Of(|c| c.key("can.setpoint_ramp")),
            json: Json::At("/board/board/setpoint_ramp_s"),
        },
        Decl {
            name: "TORQUE_PER_LSB_NM",
            value: F32(|c| c.b.torque_resolution_nm, "N·m"),
            formula: Lit("torque of one LSB of the frame's i16"),
            equation: Lit("—"),
            inputs: Of(|c| c.key("can.torque_resolution")),
            json: Json::At("/board/board/torque_resolution_nm"),
        },
        Decl {
            name: "WATCHDOG_TIMEOUT_S",
            value: F32(|c| c.b.watchdog_timeout_s, "s"),
            formula: Lit("independent-watchdog timeout"),
            equation: Lit("RM0440 §42"),
            inputs: Of(|c| c.key("watchdog.timeout")),
            json: Json::At("/board/board/watchdog_timeout_s"),
        },
        Decl {
            name: "CONVERSION_TIME_S",
            value: F32(|c| c.o.conversion_time_s, "s"),
            formula: Lit("3.125 + Σ(t_s + 12.5) ADC cycles of the longer sequence"),
            equation: Lit("DS12288 Table 66; RM0440 §21.4.12"),
            inputs: Of(|c| c.key("sensing")),
            json: Json::At("/board/conversion_time_s"),
        },
        Decl {
            name: "SAMPLING_HALF_WINDOW_S",
            value: F32(|c| c.o.duty_limit.half_window_s, "s"),
            formula: Lit(
                "h = max over the current ranks of (t_d + t_set − (t_k − t_tick), t_k + t_s,k − t_tick): the low-side on-time each side of the carrier maximum the sampling needs (0: in-line sensing, no limit from the sampling)",
            ),
            equation: Lit("RM0440 §28.3.15 (dead time), §21.4.12 (sampling); DS12288 Table 66; design::duty_limit"),
            inputs: Of(|c| {
                format!(
                    "current_sensing.placement, current_sensing.settling_time, pwm.dead_time, sensing.source_resistance.current ({}), bound: {:?}",
                    c.b.file, c.o.duty_limit.bound
                )
            }),
            json: Json::At("/board/duty_limit/half_window_s"),
        },
        Decl {
            name: "MIN_PULSE",
            value: Custom(|c| c.compare_ticks(c.o.duty_limit.min_pulse)),
            formula: Lit(
                "p = t_d, TIM1's dead time in timer ticks (DTG decoded): a compare value within p of 0 or ARR puts the dead interval of its edge in the neighbouring period (below p/2 swallows the pulse), so MAX_COMPARE ≤ ARR − p",
            ),
            equation: Lit("RM0440 §28.3.15 (dead-time insertion), §28.6.20 (DTG); design::duty_limit"),
            inputs: Of(|c| format!("pwm.dead_time ({}), drive.dead_time ({})", c.b.file, c.d.spec_file)),
            json: Json::At("/board/duty_limit/min_pulse"),
        },
        Decl {
            name: "MAX_COMPARE",
            value: Custom(|c| c.compare_ticks(c.o.duty_limit.max_compare)),
            formula: Lit(
                "min(ARR − ⌈h·f_TIM⌉, ARR − MIN_PULSE): the largest compare value whose low-side pulse 2·(ARR − CCR) covers ±h and keeps its dead intervals in its own period",
            ),
            equation: Lit("RM0440 §28.3.10 (centre-aligned PWM); design::duty_limit"),
            inputs: Of(|c| {
                format!(
                    "SAMPLING_HALF_WINDOW_S, MIN_PULSE, drive.switching_frequency ({}), bound: {:?}",
                    c.d.spec_file, c.o.duty_limit.bound
                )
            }),
            json: Json::At("/board/duty_limit/max_compare"),
        },
        Decl {
            name: "MAX_DUTY",
            value: F32(|c| c.o.duty_limit.max_duty, ""),
            formula: Lit(
                "d_max = MAX_COMPARE/ARR: 1 − 2·h/T_s rounded down to a whole compare value, at most 1 − MIN_PULSE/ARR",
            ),
            equation: Lit("design::duty_limit"),
            inputs: Of(|c| format!("SAMPLING_HALF_WINDOW_S, MIN_PULSE ({})", c.b.file)),
            json: Json::At("/board/duty_limit/max_duty"),
        },
        Decl {
            name: "USABLE_VOLTAGE_FRACTION",
            value: F32(|c| c.o.duty_limit.usable_voltage_fraction, ""),
            formula: Lit(
                "largest m with max_φ (m/√3·cos φ − cos 3φ/(6√3)) ≤ d_max − 1/2: the voltage amplitude, over U_dc/√3, whose THPWM duties stay within [1 − d_max, d_max]",
            ),
            equation: Lit("thesis A (3.7), (3.8); thesis B (2.50); design::duty_limit::usable_voltage_fraction"),
            inputs: Lit("MAX_DUTY"),
            json: Json::At("/board/duty_limit/usable_voltage_fraction"),
        },
    ];

    /// A trip's inputs: which limit set it and the other one.
    fn trip(&self, t: &crate::design::Trip, unit: &str, scale: f64) -> String {
        format!("{}, {}", t.describe(unit, scale), self.b.file)
    }

    /// A compare value of TIM1 as a `u16` constant, "ticks of ARR …".
    fn compare_ticks(&self, ticks: u16) -> (Value, String) {
        (
            intv(ticks.into(), "u16", "uint16_t"),
            format!("ticks of ARR {}", self.d.drive.pwm_period),
        )
    }

    /// The board file's key `k` as an input: `pins.gate_* (boards/x.toml)`.
    fn key(&self, k: &str) -> String {
        format!("{k} ({})", self.b.file)
    }
}

/// What one converter's entries read.
struct Adc<'a> {
    on: &'a OnBoard<'a>,
    /// 0 for ADC1, 1 for ADC2.
    k: usize,
}

impl<'a> Adc<'a> {
    /// The entries of each converter.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "CHANNELS",
            value: Custom(|c| {
                let physical = c.list(|s| format!("{} IN{}", s.pin, s.channel));
                (u8_array(&c.on.o.adc_channels[c.k]), physical)
            }),
            formula: Lit("injected ranks JSQ1.. (currents first, ADC_JSQR, RM0440 §21.7.16)"),
            equation: Lit("RM0440 §21.7.16 (ADC_JSQR)"),
            inputs: Of(|c| c.on.key("pins")),
            json: Json::Of(|c| format!("/board/adc_channels/{}", c.k)),
        },
        Decl {
            name: "SIGNALS",
            value: Custom(|c| {
                (
                    u8_array(&c.on.o.adc_signals[c.k]),
                    c.list(|s| format!("{:?}", s.signal)),
                )
            }),
            formula: Lit("0 i_u, 1 i_v, 2 i_w, 3 U_dc, 4 SIN, 5 COS"),
            equation: Lit("—"),
            inputs: Of(|c| c.on.key("pins")),
            json: Json::Of(|c| format!("/board/adc_signals/{}", c.k)),
        },
        Decl {
            name: "SMP",
            value: Custom(|c| {
                let physical = c.list(|s| {
                    format!(
                        "{} cycles ({}, {:.0} Ω)",
                        s.sampling.cycles,
                        if s.sampling.fast { "fast" } else { "slow" },
                        s.sampling.source_resistance_ohm
                    )
                });
                (u8_array(&c.on.o.adc_smp[c.k]), physical)
            }),
            formula: Lit(
                "shortest SMP with t_s ≥ max(DS12288 Table 67 time for R_AIN and channel class, 9·R_AIN·C_ADC)",
            ),
            equation: Lit("DS12288 Table 67; thesis A (7.2), (7.4)"),
            inputs: Of(|c| c.on.key("sensing.source_resistance")),
            json: Json::Of(|c| format!("/board/adc_smp/{}", c.k)),
        },
    ];

    /// Each slot of the converter's sequence described by `f`, comma-separated.
    fn list(&self, f: fn(&AdcSlot) -> String) -> String {
        self.on.b.adc[self.k].iter().map(f).collect::<Vec<_>>().join(", ")
    }
}

/// The group, `None` for a motor designed without a board.
pub fn group(d: &Design) -> Option<Group> {
    let o = d.board.as_ref()?;
    let b = &o.board;
    let file = &b.file;
    let on = OnBoard {
        d,
        o,
        b,
        current: format!(
            "V_REF+ = {} V, G = {} ([current_sensing]), V_0 = {} V (current_sensing.offset), {file}",
            b.adc_reference_v,
            phys(b.current.gain_v_per_a, "V/A"),
            b.current.offset_v
        ),
        dc_link: format!(
            "V_REF+ = {} V, ratio {} (sensing.dc_link_divider), {file}",
            b.adc_reference_v, b.dc_link_divider
        ),
    };
    let adcs = [("ADC1_", Adc { on: &on, k: 0 }), ("ADC2_", Adc { on: &on, k: 1 })];
    let converters = adcs.iter().flat_map(|(prefix, a)| declare(Adc::DECLS, a, prefix));
    Some(Group {
        name: "board",
        title: "Inverter board: pins, ADC sequences and scalings, dead time, trips, CAN, watchdog",
        constants: declare(OnBoard::PINS, &on, "")
            .chain(converters)
            .chain(declare(OnBoard::DRIVE, &on, ""))
            .collect(),
    })
}
