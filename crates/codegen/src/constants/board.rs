//! The `board` group: the inverter board's facts with this motor (only for a design on a
//! board, `crate::design_with_board`): pins and alternate functions, the ADC sequences
//! and sampling times, the ADC-to-SI scalings from the sensing, dead time, trips, CAN
//! timing, watchdog. Every entry is taken from the board file (its key is named) or
//! computed from it with the formula given.

use super::{Constant, Group, c, f32v, intv, phys, u8_array};
use crate::board::Signal;
use crate::design::Design;

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

/// The group, `None` for a motor designed without a board.
pub fn group(d: &Design) -> Option<Group> {
    let o = d.board.as_ref()?;
    let b = &o.board;
    let file = &b.file;
    let key = |k: &str| format!("{k} ({file})");
    let ds = "DS12288 / RM0440 (board file)";
    let gates = "u/v/w high, u/v/w low";
    let mut v: Vec<Constant> = vec![
        c(
            "GATE_PINS",
            u8_array(&o.gate_pins),
            format!("{}: {gates}", pins(&o.gate_pins)),
            "port·16 + pin of TIM1_CH1..3, CH1N..3N",
            ds,
            key("pins.gate_*"),
        )
        .at("/board/gate_pins"),
        c(
            "GATE_AFS",
            u8_array(&o.gate_afs),
            format!("AF {:?}", o.gate_afs),
            "GPIOx_AFRL/AFRH alternate function of each gate pin (chip pin table)",
            "DS12288 Table 13",
            key("pins.gate_*"),
        )
        .at("/board/gate_afs"),
        c(
            "IO_PINS",
            u8_array(&o.io_pins),
            format!("{}: break, excitation, CAN RX, CAN TX", pins(&o.io_pins)),
            "port·16 + pin of TIM1_BKIN, TIM3_CH1, FDCAN1_RX, FDCAN1_TX",
            ds,
            key("pins"),
        )
        .at("/board/io_pins"),
        c(
            "IO_AFS",
            u8_array(&o.io_afs),
            format!("AF {:?}", o.io_afs),
            "alternate function of each (chip pin table)",
            "DS12288 Table 13",
            key("pins"),
        )
        .at("/board/io_afs"),
    ];
    for (k, name) in [(0usize, "ADC1"), (1, "ADC2")] {
        let slots = &b.adc[k];
        let list = |f: &dyn Fn(&crate::board::AdcSlot) -> String| slots.iter().map(f).collect::<Vec<_>>().join(", ");
        v.push(
            c(
                format!("{name}_CHANNELS"),
                u8_array(&o.adc_channels[k]),
                list(&|s| format!("{} IN{}", s.pin, s.channel)),
                "injected ranks JSQ1.. (currents first, RM0440 §21.4.21)",
                "RM0440 §21.4.21",
                key("pins"),
            )
            .at(format!("/board/adc_channels/{k}")),
        );
        v.push(
            c(
                format!("{name}_SIGNALS"),
                u8_array(&o.adc_signals[k]),
                list(&|s| format!("{:?}", s.signal)),
                "0 i_u, 1 i_v, 2 i_w, 3 U_dc, 4 SIN, 5 COS",
                "—",
                key("pins"),
            )
            .at(format!("/board/adc_signals/{k}")),
        );
        v.push(
            c(
                format!("{name}_SMP"),
                u8_array(&o.adc_smp[k]),
                list(&|s| {
                    format!(
                        "{} cycles ({}, {:.0} Ω)",
                        s.sampling.cycles,
                        if s.sampling.fast { "fast" } else { "slow" },
                        s.sampling.source_resistance_ohm
                    )
                }),
                "shortest SMP with t_s ≥ max(DS12288 Table 67 time for R_AIN and channel class, 9·R_AIN·C_ADC)",
                "DS12288 Table 67; thesis A (7.2), (7.4)",
                key("sensing.source_resistance"),
            )
            .at(format!("/board/adc_smp/{k}")),
        );
    }
    let gain_in = format!(
        "V_REF+ = {} V, G = {} (sensing.current_gain), V_0 = {} V (sensing.current_offset), {file}",
        b.adc_reference_v,
        phys(b.current_gain_v_per_a, "V/A"),
        b.current_offset_v
    );
    let dc_in = format!(
        "V_REF+ = {} V, ratio {} (sensing.dc_link_divider), {file}",
        b.adc_reference_v, b.dc_link_divider
    );
    let f = |n: &str, x: f64, unit: &str, formula: &str, eq: &str, inputs: String, path: &str| {
        c(n, f32v(x), phys(x, unit), formula, eq, inputs).at(format!("/board/{path}"))
    };
    v.extend([
        c(
            "ADC_CLOCK_HZ",
            intv(crate::board::ADC_CLOCK_HZ as i64, "u32", "uint32_t"),
            phys(crate::board::ADC_CLOCK_HZ, "Hz"),
            "f_ADC the sampling codes are chosen for: HCLK/4",
            "RM0440 §21.4.3",
            "the firmware's clock tree".into(),
        )
        .at("/board/adc_clock_hz"),
        c(
            "CURRENT_OFFSET_CODE",
            intv(i64::from(o.current_offset_code), "i32", "int32_t"),
            format!("{} V at 0 A", b.current_offset_v),
            "V_0/V_REF+·2^16 (16-bit left-aligned code)",
            "thesis A (4.16)",
            gain_in.clone(),
        )
        .at("/board/current_offset_code"),
        f(
            "CURRENT_PER_LSB",
            o.amps_per_lsb,
            "A",
            "V_REF+/(G·2^16)",
            "thesis A (4.16)",
            gain_in.clone(),
            "amps_per_lsb",
        ),
        f(
            "CURRENT_FULL_SCALE_A",
            o.current_full_scale_a,
            "A",
            "min(V_0, V_REF+ − V_0)/G",
            "thesis A (4.16), Table 4.1",
            gain_in,
            "current_full_scale_a",
        ),
        c(
            "CURRENT_PHASES",
            intv(i64::from(o.current_phases), "u8", "uint8_t"),
            o.current_phases.to_string(),
            "phase currents measured (the third from i_u + i_v + i_w = 0 when 2)",
            "thesis A (2.7)",
            key("pins.current_w"),
        )
        .at("/board/current_phases"),
        f(
            "DC_LINK_PER_LSB",
            o.dc_link_volts_per_lsb,
            "V",
            "V_REF+/(ratio·2^15)",
            "thesis A (4.16)",
            dc_in.clone(),
            "dc_link_volts_per_lsb",
        ),
        f(
            "DC_LINK_FULL_SCALE_V",
            o.dc_link_full_scale_v,
            "V",
            "V_REF+/ratio",
            "thesis A (4.16)",
            dc_in,
            "dc_link_full_scale_v",
        ),
        c(
            "DEAD_TIME_NS",
            intv(i64::from(o.dead_time_ns), "u32", "uint32_t"),
            format!("{} ns", o.dead_time_ns),
            "max(pwm.dead_time, spec drive.dead_time), rounded up to 1 ns",
            "thesis A §3.2",
            key("pwm.dead_time"),
        )
        .at("/board/dead_time_ns"),
        c(
            "SAMPLE_AT_CARRIER_MAXIMUM",
            intv(i64::from(o.sample_at_carrier_maximum), "u8", "uint8_t"),
            format!("{:?}", b.sample_instant),
            "1: ADC trigger TRGO2 = OC4REF at the carrier maximum (low-side pulse centre); 0: at the minimum",
            "RM0440 §29.3.5, §29.6.2",
            key("sensing.sample_instant"),
        )
        .at("/board/sample_at_carrier_maximum"),
        c(
            "BREAK_ACTIVE_HIGH",
            intv(i64::from(o.break_active_high), "u8", "uint8_t"),
            format!("{:?}", b.break_polarity),
            "TIM1_BDTR.BKP",
            "RM0440 §29.6.20",
            key("break_input.polarity"),
        )
        .at("/board/break_active_high"),
        c(
            "BOOT0_OPTION_BYTES",
            intv(i64::from(o.boot0_option_bytes), "u8", "uint8_t"),
            format!("{:?}", b.boot0),
            "1: the image requires FLASH_OPTR.nSWBOOT0 = 0, nBOOT0 = 1 (PB8 does not select the boot mode)",
            "DS12288 §3.7; RM0440 §3.4.1",
            key("boot0.handling"),
        )
        .at("/board/boot0_option_bytes"),
        f(
            "OVER_CURRENT_A",
            b.over_current_a,
            "A",
            "trip when any |i_phase| exceeds it",
            "—",
            key("protection.over_current"),
            "board/over_current_a",
        ),
        f(
            "OVER_VOLTAGE_V",
            b.over_voltage_v,
            "V",
            "trip when U_dc exceeds it",
            "—",
            key("protection.over_voltage"),
            "board/over_voltage_v",
        ),
        f(
            "OVER_SPEED_E_RAD_S",
            o.over_speed_electrical_rad_s,
            "rad/s",
            "n_p·ω_m,trip: trip when |ω_e| exceeds it",
            "thesis A (2.19)",
            format!("{}, n_p = {}", key("protection.over_speed"), d.motor.pole_pairs),
            "over_speed_electrical_rad_s",
        ),
        c(
            "CAN_BIT_RATE",
            intv(i64::from(o.can_bit_rate), "u32", "uint32_t"),
            phys(f64::from(o.can_bit_rate), "bit/s"),
            "FDCAN1 nominal bit rate",
            "RM0440 §44.4.9",
            key("can.bit_rate"),
        )
        .at("/board/can_bit_rate"),
        c(
            "SETPOINT_ID",
            intv(i64::from(b.setpoint_id), "u16", "uint16_t"),
            format!("{:#05x}", b.setpoint_id),
            "standard identifier of the torque setpoint",
            "—",
            key("can.setpoint_id"),
        )
        .at("/board/board/setpoint_id"),
        f(
            "SETPOINT_PERIOD_S",
            b.setpoint_period_s,
            "s",
            "period the vehicle unit sends at",
            "—",
            key("can.setpoint_period"),
            "board/setpoint_period_s",
        ),
        f(
            "SETPOINT_TIMEOUT_S",
            b.setpoint_timeout_s,
            "s",
            "no setpoint for this long → ramp to zero",
            "—",
            key("can.setpoint_timeout"),
            "board/setpoint_timeout_s",
        ),
        f(
            "SETPOINT_RAMP_S",
            b.setpoint_ramp_s,
            "s",
            "time from the peak current to zero",
            "—",
            key("can.setpoint_ramp"),
            "board/setpoint_ramp_s",
        ),
        f(
            "TORQUE_PER_LSB_NM",
            b.torque_resolution_nm,
            "N·m",
            "torque of one LSB of the frame's i16",
            "—",
            key("can.torque_resolution"),
            "board/torque_resolution_nm",
        ),
        f(
            "WATCHDOG_TIMEOUT_S",
            b.watchdog_timeout_s,
            "s",
            "independent-watchdog timeout",
            "RM0440 §41",
            key("watchdog.timeout"),
            "board/watchdog_timeout_s",
        ),
        f(
            "CONVERSION_TIME_S",
            o.conversion_time_s,
            "s",
            "3.125 + Σ(t_s + 12.5) ADC cycles of the longer sequence",
            "DS12288 Table 66; RM0440 §21.4.12",
            key("sensing"),
            "conversion_time_s",
        ),
    ]);
    let _ = Signal::ALL;
    Some(Group {
        name: "board",
        title: "Inverter board: pins, ADC sequences and scalings, dead time, trips, CAN, watchdog",
        constants: v,
    })
}
