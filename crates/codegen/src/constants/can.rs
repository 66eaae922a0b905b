//! The `can` group: the drive's CAN interface described once — identifiers, data
//! lengths and signal scalings of the setpoint, status, commissioning-command,
//! capture and fault-report frames (only for a design on a board: the identifiers follow the board's
//! `can.setpoint_id`). The byte layouts are `motor_control::can_protocol`'s (firmware
//! and host share them); `templates/motor.dbc.j2` renders this group as a DBC file.

use std::collections::BTreeMap;

use motor_control::can_protocol as p;

use super::{Constant, Group, c, f32v, intv, phys};
use crate::design::Design;

/// Standard identifier of the fault report, a choice of the firmware: low (high
/// priority on the bus), below the drive's other frames on the seed boards.
pub const FAULT_REPORT_ID: u16 = 0x0E0;

/// The fault report's current unit \[A per LSB\].
pub const FAULT_CURRENT_PER_LSB: f64 = 0.1;

/// Data length of the setpoint frame (a little-endian i16 torque, `can_frame`).
pub const SETPOINT_LEN: u8 = 2;

/// The group, `None` for a motor designed without a board.
pub fn group(d: &Design) -> Option<Group> {
    let o = d.board.as_ref()?;
    let b = &o.board;
    let file = &b.file;
    let base = b.setpoint_id;
    let proto = "motor_control::can_protocol";
    let mut v: Vec<Constant> = Vec::new();
    for (k, name, what) in [
        (1u16, "STATUS_ID", "status frame (drive → bus, every status period)"),
        (2, "COMMAND_ID", "commissioning command (bus → drive)"),
        (3, "CAPTURE_HEADER_ID", "capture header (drive → bus)"),
        (4, "CAPTURE_DATA_ID", "capture data, one sample per frame (drive → bus)"),
        (5, "CAPTURE_END_ID", "capture end with the CRC-32 (drive → bus)"),
    ] {
        let id = base + k;
        v.push(c(
            name,
            intv(i64::from(id), "u16", "uint16_t"),
            format!("{id:#05x}"),
            &format!("setpoint_id + {k}: standard identifier of the {what}"),
            proto,
            format!("can.setpoint_id = {base:#05x} ({file})"),
        ));
    }
    v.push(c(
        "FAULT_REPORT_ID",
        intv(i64::from(FAULT_REPORT_ID), "u16", "uint16_t"),
        format!("{FAULT_REPORT_ID:#05x}"),
        "fixed: standard identifier of the fault report (drive → bus, once after a boot that found a fault record)",
        proto,
        "the firmware's choice, outside setpoint_id … setpoint_id + 5 (checked when the image builds)".into(),
    ));
    for (name, len, what) in [
        ("SETPOINT_LEN", SETPOINT_LEN, "setpoint: bytes 0–1 torque (i16)"),
        ("STATUS_LEN", p::STATUS_LEN, "status: state, reason, routine, faults"),
        (
            "COMMAND_LEN",
            p::COMMAND_LEN,
            "command: routine, axis, voltage, current trip, decimation",
        ),
        (
            "CAPTURE_HEADER_LEN",
            p::HEADER_LEN,
            "header: routine/axis/tripped, decimation, T_s, count, trip level",
        ),
        (
            "CAPTURE_DATA_LEN",
            p::DATA_LEN,
            "data: routine (multiplexor), sequence, channels A and B",
        ),
        ("CAPTURE_END_LEN", p::END_LEN, "end: CRC-32, trip sample, trip current"),
        (
            "FAULT_REPORT_LEN",
            p::FAULT_REPORT_LEN,
            "fault report: cause, flags, PC, i_q",
        ),
    ] {
        v.push(c(
            name,
            intv(i64::from(len), "u8", "uint8_t"),
            format!("{len} bytes"),
            &format!("data length code of the {what}"),
            proto,
            "the firmware's frame layout".into(),
        ));
    }
    let s = &d.scaling;
    for (name, sc, unit, what) in [
        ("CURRENT_PER_LSB", &s.phase_current, "A", "phase current"),
        ("VOLTAGE_PER_LSB", &s.phase_voltage, "V", "phase voltage"),
        ("SPEED_PER_LSB", &s.speed, "rad/s", "electrical speed"),
    ] {
        let x = sc.full_scale / 32768.0;
        v.push(c(
            name,
            f32v(x),
            phys(x, unit),
            &format!("A/2^15: a 16-bit signal is the {what} in Q1.15 of its full scale"),
            "thesis A (4.16), Table 4.1",
            format!("A = {} (scaling)", phys(sc.full_scale, unit)),
        ));
    }
    v.push(c(
        "FAULT_CURRENT_PER_LSB",
        f32v(FAULT_CURRENT_PER_LSB),
        phys(FAULT_CURRENT_PER_LSB, "A"),
        "fixed: the fault report's i_q unit, ±3276.7 A in an i16 (beyond any phase-current full scale, so a trip's current is never cut)",
        proto,
        "the fault report's layout".into(),
    ));
    v.push(c(
        "ANGLE_PER_LSB",
        f32v(f64::from(p::ANGLE_PER_LSB)),
        phys(f64::from(p::ANGLE_PER_LSB), "rad"),
        "π/2^15: the top 16 bits of the π-scaled Q1.31 angle",
        "thesis A (4.20)",
        "the angle format".into(),
    ));
    let units = (d.drive.sample_period_s * p::SAMPLE_PERIOD_UNITS_PER_S)
        .round()
        .clamp(1.0, f64::from(u16::MAX));
    v.push(c(
        "SAMPLE_PERIOD_UNITS",
        intv(units as i64, "u16", "uint16_t"),
        format!("{} (T_s = {})", units, phys(d.drive.sample_period_s, "s")),
        "T_s/100 ns, rounded: the capture header's sample period",
        "thesis A §6.2",
        "drive.switching_frequency (spec)".into(),
    ));
    v.push(
        c(
            "STATUS_PERIOD_S",
            f32v(b.setpoint_period_s),
            phys(b.setpoint_period_s, "s"),
            "the status frame is sent at the setpoint period",
            "—",
            format!("can.setpoint_period ({file})"),
        )
        .at("/board/board/setpoint_period_s"),
    );
    Some(Group {
        name: "can",
        title: "CAN interface: identifiers, data lengths and signal scalings (also as the DBC file)",
        constants: v,
    })
}

/// Captured samples the image has room for: 4096 × 8 bytes (two `f32` channels) =
/// 32 KiB of the STM32G474's 128 KiB SRAM (DS12288 §3.5).
pub const CAPTURE_CAPACITY: u32 = 4096;

/// The `commissioning` group: the fixed parameters of the chapter-6 routines the CAN
/// command starts (the command gives voltage, trip and decimation), emitted with the
/// CAN interface (only for a design on a board).
pub fn commissioning_group(d: &Design) -> Option<Group> {
    d.board.as_ref()?;
    let m = &d.motor;
    let ts = d.drive.sample_period_s;
    let periods = |t: f64| (t / ts).ceil().clamp(1.0, f64::from(u32::MAX));
    let tau = m.d_inductance_h.max(m.q_inductance_h) / m.phase_resistance_ohm;
    let ts_in = format!("T_s = {} (drive.switching_frequency)", phys(ts, "s"));
    let u32c = |name: &str, x: f64, formula: &str, eq: &str, inputs: String| {
        c(
            name,
            intv(x as i64, "u32", "uint32_t"),
            format!("{x} periods ({})", phys(x * ts, "s")),
            formula,
            eq,
            inputs,
        )
    };
    let np = d.angle_observer.motor_pole_pairs;
    let nr = d.angle_observer.resolver_pole_pairs;
    // One electrical turn per second: 2^32 LSB of the π-scaled angle per second.
    let rotation_step = (4_294_967_296.0 * ts).round().clamp(1.0, f64::from(i32::MAX));
    let v = vec![
        c(
            "CAPTURE_CAPACITY",
            intv(i64::from(CAPTURE_CAPACITY), "u32", "uint32_t"),
            format!("{CAPTURE_CAPACITY} samples"),
            "two f32 channels each: 32 KiB of the 128 KiB SRAM",
            "DS12288 §3.5",
            "the firmware's RAM budget".into(),
        ),
        u32c(
            "STEP_PRE_SAMPLES",
            40.0,
            "periods at 0 V before the step (baseline)",
            "thesis A §6.2",
            "—".into(),
        ),
        u32c(
            "STEP_SAMPLES",
            periods(12.0 * tau).max(3000.0),
            "max(⌈12·τ/T_s⌉, 3000), τ = max(L_d, L_q)/R: the step settles (identify needs 8 τ)",
            "thesis A (6.4), (6.7)",
            format!("τ = {}, {ts_in}", phys(tau, "s")),
        ),
        u32c(
            "ALIGN_RAMP_SAMPLES",
            periods(0.05),
            "⌈50 ms/T_s⌉: voltage ramp to the alignment level",
            "thesis A §6.3",
            ts_in.clone(),
        ),
        u32c(
            "ALIGN_SETTLE_SAMPLES",
            periods((30.0 * tau).max(0.5)),
            "⌈max(30·τ, 500 ms)/T_s⌉: the rotor comes to rest on the α axis (the rotor's motion and the currents form a mode as slow as τ = max(L_d, L_q)/R)",
            "thesis A §6.3",
            format!("τ = {}, {ts_in}", phys(tau, "s")),
        ),
        u32c(
            "ALIGN_AVERAGE_SAMPLES",
            periods(0.1),
            "⌈100 ms/T_s⌉: θ_r averaged",
            "thesis A (6.9)",
            ts_in.clone(),
        ),
        c(
            "ROTATION_STEP",
            intv(rotation_step as i64, "i32", "int32_t"),
            format!("{rotation_step} LSB per period (1 electrical turn/s)"),
            "2^32·T_s: the field turns once a second, slow enough for the rotor to follow",
            "thesis A §6.4",
            ts_in.clone(),
        ),
        c(
            "ROTATION_TURNS",
            intv(i64::from(2 * np / nr.max(1)), "u32", "uint32_t"),
            format!("{} electrical turns", 2 * np / nr.max(1)),
            "2·n_p/n_r: two resolver turns",
            "thesis A (6.2)",
            format!("n_p = {np}, n_r = {nr}"),
        ),
        u32c(
            "ROTATION_SETTLE_SAMPLES",
            periods(0.5),
            "⌈500 ms/T_s⌉ held at the start and the end angle",
            "thesis A §6.4",
            ts_in.clone(),
        ),
        u32c(
            "FLUX_SETTLE_SAMPLES",
            periods(0.2),
            "⌈200 ms/T_s⌉: the current loop settles at i = 0",
            "thesis A §6.5",
            ts_in.clone(),
        ),
        u32c(
            "FLUX_AVERAGE_SAMPLES",
            periods(0.1),
            "⌈100 ms/T_s⌉ averaged (and captured)",
            "thesis A (6.10)",
            ts_in,
        ),
        c(
            "FLUX_MIN_SPEED",
            f32v(0.05 * m.max_electrical_speed_rad_s),
            phys(0.05 * m.max_electrical_speed_rad_s, "rad/s"),
            "5 % of the maximum electrical speed: the back EMF dominates R·i",
            "thesis A (6.10)",
            format!("ω_e,max = {}", phys(m.max_electrical_speed_rad_s, "rad/s")),
        ),
        c(
            "STANDSTILL_SPEED",
            f32v(0.01 * m.max_electrical_speed_rad_s),
            phys(0.01 * m.max_electrical_speed_rad_s, "rad/s"),
            "1 % of the maximum electrical speed: a command is accepted below it",
            "—",
            format!("ω_e,max = {}", phys(m.max_electrical_speed_rad_s, "rad/s")),
        ),
    ];
    Some(Group {
        name: "commissioning",
        title: "Commissioning routines started over CAN (thesis A chapter 6)",
        constants: v,
    })
}

/// The `can` group (and the board's setpoint identifier and torque resolution) as
/// name → DBC text: integers in decimal, floats as the shortest decimal of their f32
/// (exactly the value the firmware uses). Empty without a board.
pub fn dbc_values(groups: &[Group]) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for g in groups.iter().filter(|g| g.name == "can" || g.name == "board") {
        for k in &g.constants {
            if g.name == "board" && !matches!(k.name.as_str(), "SETPOINT_ID" | "TORQUE_PER_LSB_NM") {
                continue;
            }
            let text = match &k.value.number {
                serde_json::Value::Number(n) if k.value.rust_type == "f32" => {
                    super::f32_literal(n.as_f64().unwrap_or(0.0))
                }
                other => other.to_string(),
            };
            out.insert(k.name.clone(), text);
        }
    }
    out
}
