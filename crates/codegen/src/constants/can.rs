//! The `can` group: the drive's CAN interface described once — identifiers, data
//! lengths and signal scalings of the setpoint, status, commissioning-command,
//! capture and fault-report frames (only for a design on a board: the identifiers follow the board's
//! `can.setpoint_id`). The byte layouts are `motor_control::can_protocol`'s (firmware
//! and host share them); `templates/motor.dbc.j2` renders this group as a DBC file.
//! The signal scalings are the per-unit ones of thesis A (4.16), (4.20), Table 4.1.
//!
//! With it, the `commissioning` group: the fixed parameters of the thesis A chapter 6
//! routines the CAN command starts — step response (6.4), (6.7), rotor alignment §6.3,
//! (6.9), resolver rotation §6.4, (6.2), flux-linkage measurement §6.5, (6.10) — and the
//! capture buffer's size (DS12288 §3.5).

use std::collections::BTreeMap;

use motor_control::can_protocol as p;

use super::Source::{Custom, F32};
use super::Text::{Lit, Of};
use super::{Decl, Group, Json, Value, declare, intv, phys};
use crate::board::Board;
use crate::design::BoardOut;
use crate::design::Design;

/// Standard identifier of the fault report, a choice of the firmware: low (high
/// priority on the bus), below the drive's other frames on the seed boards; a board's
/// setpoint identifier keeps its frames off it (`crate::firmware::setpoint_id`).
pub use crate::firmware::FAULT_REPORT_ID;

/// The fault report's current unit \[A per LSB\].
pub const FAULT_CURRENT_PER_LSB: f64 = 0.1;

/// Data length of the setpoint frame (a little-endian i16 torque, `can_frame`).
pub const SETPOINT_LEN: u8 = 2;

/// The equation column of the entries the protocol defines.
const PROTOCOL: &str = "motor_control::can_protocol";

/// What the CAN interface's entries read.
struct Can<'a> {
    d: &'a Design,
    b: &'a Board,
}

impl<'a> Can<'a> {
    /// The entries: identifiers, data lengths, signal scalings.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "STATUS_ID",
            value: Custom(|c| c.id(1)),
            formula: Lit("setpoint_id + 1: standard identifier of the status frame (drive → bus, every status period)"),
            equation: Lit(PROTOCOL),
            inputs: Of(|c| c.setpoint_id()),
            json: Json::None,
        },
        Decl {
            name: "COMMAND_ID",
            value: Custom(|c| c.id(2)),
            formula: Lit("setpoint_id + 2: standard identifier of the commissioning command (bus → drive)"),
            equation: Lit(PROTOCOL),
            inputs: Of(|c| c.setpoint_id()),
            json: Json::None,
        },
        Decl {
            name: "CAPTURE_HEADER_ID",
            value: Custom(|c| c.id(3)),
            formula: Lit("setpoint_id + 3: standard identifier of the capture header (drive → bus)"),
            equation: Lit(PROTOCOL),
            inputs: Of(|c| c.setpoint_id()),
            json: Json::None,
        },
        Decl {
            name: "CAPTURE_DATA_ID",
            value: Custom(|c| c.id(4)),
            formula: Lit(
                "setpoint_id + 4: standard identifier of the capture data, one sample per frame (drive → bus)",
            ),
            equation: Lit(PROTOCOL),
            inputs: Of(|c| c.setpoint_id()),
            json: Json::None,
        },
        Decl {
            name: "CAPTURE_END_ID",
            value: Custom(|c| c.id(5)),
            formula: Lit("setpoint_id + 5: standard identifier of the capture end with the CRC-32 (drive → bus)"),
            equation: Lit(PROTOCOL),
            inputs: Of(|c| c.setpoint_id()),
            json: Json::None,
        },
        Decl {
            name: "FAULT_REPORT_ID",
            value: Custom(|_| identifier(FAULT_REPORT_ID)),
            formula: Lit(
                "fixed: standard identifier of the fault report (drive → bus, once after a boot that found a fault record)",
            ),
            equation: Lit(PROTOCOL),
            inputs: Lit("the firmware's choice, outside setpoint_id … setpoint_id + 5 (checked when the image builds)"),
            json: Json::None,
        },
        Decl {
            name: "SETPOINT_LEN",
            value: Custom(|_| length(SETPOINT_LEN)),
            formula: Lit("data length code of the setpoint: bytes 0–1 torque (i16)"),
            equation: Lit(PROTOCOL),
            inputs: Lit("the firmware's frame layout"),
            json: Json::None,
        },
        Decl {
            name: "STATUS_LEN",
            value: Custom(|_| length(p::STATUS_LEN)),
            formula: Lit("data length code of the status: state, reason, routine, faults"),
            equation: Lit(PROTOCOL),
            inputs: Lit("the firmware's frame layout"),
            json: Json::None,
        },
        Decl {
            name: "COMMAND_LEN",
            value: Custom(|_| length(p::COMMAND_LEN)),
            formula: Lit("data length code of the command: routine, axis, voltage, current trip, decimation"),
            equation: Lit(PROTOCOL),
            inputs: Lit("the firmware's frame layout"),
            json: Json::None,
        },
        Decl {
            name: "CAPTURE_HEADER_LEN",
            value: Custom(|_| length(p::HEADER_LEN)),
            formula: Lit("data length code of the header: routine/axis/tripped, decimation, T_s, count, trip level"),
            equation: Lit(PROTOCOL),
            inputs: Lit("the firmware's frame layout"),
            json: Json::None,
        },
        Decl {
            name: "CAPTURE_DATA_LEN",
            value: Custom(|_| length(p::DATA_LEN)),
            formula: Lit("data length code of the data: routine (multiplexor), sequence, channels A and B"),
            equation: Lit(PROTOCOL),
            inputs: Lit("the firmware's frame layout"),
            json: Json::None,
        },
        Decl {
            name: "CAPTURE_END_LEN",
            value: Custom(|_| length(p::END_LEN)),
            formula: Lit("data length code of the end: CRC-32, trip sample, trip current"),
            equation: Lit(PROTOCOL),
            inputs: Lit("the firmware's frame layout"),
            json: Json::None,
        },
        Decl {
            name: "FAULT_REPORT_LEN",
            value: Custom(|_| length(p::FAULT_REPORT_LEN)),
            formula: Lit(
                "data length code of the fault report: cause, flags, PC or a start-up check's measurement, i_q",
            ),
            equation: Lit(PROTOCOL),
            inputs: Lit("the firmware's frame layout"),
            json: Json::None,
        },
        Decl {
            name: "CURRENT_PER_LSB",
            value: F32(|c| c.d.scaling.phase_current.full_scale / 32768.0, "A"),
            formula: Lit("A/2^15: a 16-bit signal is the phase current in Q1.15 of its full scale"),
            equation: Lit("thesis A (4.16), Table 4.1"),
            inputs: Of(|c| full_scale(c.d.scaling.phase_current.full_scale, "A")),
            json: Json::None,
        },
        Decl {
            name: "VOLTAGE_PER_LSB",
            value: F32(|c| c.d.scaling.phase_voltage.full_scale / 32768.0, "V"),
            formula: Lit("A/2^15: a 16-bit signal is the phase voltage in Q1.15 of its full scale"),
            equation: Lit("thesis A (4.16), Table 4.1"),
            inputs: Of(|c| full_scale(c.d.scaling.phase_voltage.full_scale, "V")),
            json: Json::None,
        },
        Decl {
            name: "SPEED_PER_LSB",
            value: F32(|c| c.d.scaling.speed.full_scale / 32768.0, "rad/s"),
            formula: Lit("A/2^15: a 16-bit signal is the electrical speed in Q1.15 of its full scale"),
            equation: Lit("thesis A (4.16), Table 4.1"),
            inputs: Of(|c| full_scale(c.d.scaling.speed.full_scale, "rad/s")),
            json: Json::None,
        },
        Decl {
            name: "FAULT_CURRENT_PER_LSB",
            value: F32(|_| FAULT_CURRENT_PER_LSB, "A"),
            formula: Lit(
                "fixed: the fault report's i_q unit, ±3276.7 A in an i16 (beyond any phase-current full scale, so a trip's current is never cut)",
            ),
            equation: Lit(PROTOCOL),
            inputs: Lit("the fault report's layout"),
            json: Json::None,
        },
        Decl {
            name: "ANGLE_PER_LSB",
            value: F32(|_| f64::from(p::ANGLE_PER_LSB), "rad"),
            formula: Lit("π/2^15: the top 16 bits of the π-scaled Q1.31 angle"),
            equation: Lit("thesis A (4.20)"),
            inputs: Lit("the angle format"),
            json: Json::None,
        },
        Decl {
            name: "SAMPLE_PERIOD_UNITS",
            value: Custom(|c| {
                let ts = c.d.drive.sample_period_s;
                let units = (ts * p::SAMPLE_PERIOD_UNITS_PER_S)
                    .round()
                    .clamp(1.0, f64::from(u16::MAX));
                (
                    intv(units as i64, "u16", "uint16_t"),
                    format!("{} (T_s = {})", units, phys(ts, "s")),
                )
            }),
            formula: Lit("T_s/100 ns, rounded: the capture header's sample period"),
            equation: Lit("thesis A §6.2"),
            inputs: Lit("drive.switching_frequency (spec)"),
            json: Json::None,
        },
        Decl {
            name: "STATUS_PERIOD_S",
            value: F32(|c| c.b.setpoint_period_s, "s"),
            formula: Lit("the status frame is sent at the setpoint period"),
            equation: Lit("—"),
            inputs: Of(|c| format!("can.setpoint_period ({})", c.b.file)),
            json: Json::At("/board/board/setpoint_period_s"),
        },
    ];

    /// The identifier `k` after the setpoint's.
    fn id(&self, k: u16) -> (Value, String) {
        identifier(self.b.setpoint_id + k)
    }

    /// The board's setpoint identifier as an input.
    fn setpoint_id(&self) -> String {
        format!("can.setpoint_id = {:#05x} ({})", self.b.setpoint_id, self.b.file)
    }
}

/// A standard identifier and its hexadecimal spelling.
fn identifier(id: u16) -> (Value, String) {
    (intv(id.into(), "u16", "uint16_t"), format!("{id:#05x}"))
}

/// A data length code in bytes.
fn length(len: u8) -> (Value, String) {
    (intv(len.into(), "u8", "uint8_t"), format!("{len} bytes"))
}

/// A scaling's full scale as an input.
fn full_scale(x: f64, unit: &str) -> String {
    format!("A = {} (scaling)", phys(x, unit))
}

/// The group, `None` for a motor designed without a board.
pub fn group(d: &Design) -> Option<Group> {
    let o = d.board.as_ref()?;
    let can = Can { d, b: &o.board };
    Some(Group {
        name: "can",
        title: "CAN interface: identifiers, data lengths and signal scalings (also as the DBC file)",
        constants: declare(Can::DECLS, &can, "").collect(),
    })
}

/// Captured samples the image has room for: 4096 × 8 bytes (two `f32` channels) =
/// 32 KiB of the STM32G474's 128 KiB SRAM (DS12288 §3.5).
pub const CAPTURE_CAPACITY: u32 = 4096;

/// R accepted by the pre-flight check in [R/ρ, R·ρ].
pub const PREFLIGHT_RESISTANCE_RATIO: f64 = 2.0;
/// L accepted by the pre-flight check in [L_d/ρ, L_d·ρ].
pub const PREFLIGHT_INDUCTANCE_RATIO: f64 = 2.0;

/// What the commissioning entries read.
struct Commissioning<'a> {
    d: &'a Design,
    /// The board's values with this motor.
    b: &'a BoardOut,
    /// T_s \[s\].
    ts: f64,
    /// τ = max(L_d, L_q)/R \[s\].
    tau: f64,
    /// T_s as an input.
    ts_in: String,
    /// τ and T_s as inputs.
    tau_in: String,
}

impl<'a> Commissioning<'a> {
    /// The entries.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "CAPTURE_CAPACITY",
            value: Custom(|_| {
                let n = CAPTURE_CAPACITY;
                (intv(n.into(), "u32", "uint32_t"), format!("{n} samples"))
            }),
            formula: Lit("two f32 channels each: 32 KiB of the 128 KiB SRAM"),
            equation: Lit("DS12288 §3.5"),
            inputs: Lit("the firmware's RAM budget"),
            json: Json::None,
        },
        Decl {
            name: "STEP_PRE_SAMPLES",
            value: Custom(|c| c.samples(40.0)),
            formula: Lit("periods at 0 V before the step (baseline)"),
            equation: Lit("thesis A §6.2"),
            inputs: Lit("—"),
            json: Json::None,
        },
        Decl {
            name: "STEP_SAMPLES",
            value: Custom(|c| c.samples(c.periods(12.0 * c.tau).max(3000.0))),
            formula: Lit("max(⌈12·τ/T_s⌉, 3000), τ = max(L_d, L_q)/R: the step settles (identify needs 8 τ)"),
            equation: Lit("thesis A (6.4), (6.7)"),
            inputs: Of(|c| c.tau_in.clone()),
            json: Json::None,
        },
        Decl {
            name: "ALIGN_RAMP_SAMPLES",
            value: Custom(|c| c.samples(c.periods(0.05))),
            formula: Lit("⌈50 ms/T_s⌉: voltage ramp to the alignment level"),
            equation: Lit("thesis A §6.3"),
            inputs: Of(|c| c.ts_in.clone()),
            json: Json::None,
        },
        Decl {
            name: "ALIGN_SETTLE_SAMPLES",
            value: Custom(|c| c.samples(c.periods((30.0 * c.tau).max(0.5)))),
            formula: Lit(
                "⌈max(30·τ, 500 ms)/T_s⌉: the rotor comes to rest on the α axis (the rotor's motion and the currents form a mode as slow as τ = max(L_d, L_q)/R)",
            ),
            equation: Lit("thesis A §6.3"),
            inputs: Of(|c| c.tau_in.clone()),
            json: Json::None,
        },
        Decl {
            name: "ALIGN_AVERAGE_SAMPLES",
            value: Custom(|c| c.samples(c.periods(0.1))),
            formula: Lit("⌈100 ms/T_s⌉: θ_r averaged"),
            equation: Lit("thesis A (6.9)"),
            inputs: Of(|c| c.ts_in.clone()),
            json: Json::None,
        },
        Decl {
            name: "ROTATION_STEP",
            value: Custom(|c| {
                // One electrical turn per second: 2^32 LSB of the π-scaled angle per second.
                let step = angle_step(1.0, c.ts);
                (
                    intv(step as i64, "i32", "int32_t"),
                    format!("{step} LSB per period (1 electrical turn/s)"),
                )
            }),
            formula: Lit("2^32·T_s: the field turns once a second, slow enough for the rotor to follow"),
            equation: Lit("thesis A §6.4"),
            inputs: Of(|c| c.ts_in.clone()),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_ROTATION_STEP",
            value: Custom(|c| {
                let rate = c.preflight_rotation_rate();
                let step = angle_step(rate / std::f64::consts::TAU, c.ts);
                (
                    intv(step as i64, "i32", "int32_t"),
                    format!(
                        "{step} LSB per period ({:.4} electrical turns/s, the turn in {})",
                        rate / std::f64::consts::TAU,
                        phys(std::f64::consts::TAU / rate, "s")
                    ),
                )
            }),
            formula: Lit(
                "2^32·T_s·ω/2π, ω = min(2π rad/s, R·I_p/(2·ψ_M)): the pre-flight's field turns at §6.4's once a second unless a rotor following it would induce ψ_M·ω beyond half the rotation's voltage V = R·I_p — the rotor follows at the load angle δ with sin δ = ψ_M·ω/V (≤ 30° here); at ψ_M·ω ≥ V it cannot follow at all",
            ),
            equation: Lit("thesis A §6.4, (2.25)"),
            inputs: Of(|c| {
                format!(
                    "ψ_M = {}, R = {}, I_p = {}, {}",
                    c.d.motor
                        .flux_linkage_wb
                        .map_or("— (none: no back-EMF)".into(), |p| phys(p, "Wb")),
                    phys(c.d.motor.phase_resistance_ohm, "Ω"),
                    phys(c.preflight_current(), "A"),
                    c.ts_in
                )
            }),
            json: Json::None,
        },
        Decl {
            name: "ROTATION_TURNS",
            value: Custom(|c| {
                let o = &c.d.angle_observer;
                let turns = 2 * o.motor_pole_pairs / o.resolver_pole_pairs.max(1);
                (
                    intv(turns.into(), "u32", "uint32_t"),
                    format!("{turns} electrical turns"),
                )
            }),
            formula: Lit("2·n_p/n_r: two resolver turns"),
            equation: Lit("thesis A (6.2)"),
            inputs: Of(|c| {
                let o = &c.d.angle_observer;
                format!("n_p = {}, n_r = {}", o.motor_pole_pairs, o.resolver_pole_pairs)
            }),
            json: Json::None,
        },
        Decl {
            name: "ROTATION_SETTLE_SAMPLES",
            value: Custom(|c| c.samples(c.periods(0.5))),
            formula: Lit("⌈500 ms/T_s⌉ held at the start and the end angle"),
            equation: Lit("thesis A §6.4"),
            inputs: Of(|c| c.ts_in.clone()),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_CURRENT",
            value: F32(|c| c.preflight_current(), "A"),
            formula: Lit(
                "I_p = ¼·min(rated amplitude, over-current trip): the pre-flight pulses' and rotation's current — well inside the rating and the board's trip, large against the sensing's quantisation",
            ),
            equation: Lit("issue 26 item 2"),
            inputs: Of(|c| c.rating_in()),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_VOLTAGE",
            value: F32(|c| c.d.motor.phase_resistance_ohm * c.preflight_current(), "V"),
            formula: Lit("V = R·I_p: the pulses' second level (the first is V/2) and the rotation's αβ voltage"),
            equation: Lit("thesis A (6.3)"),
            inputs: Of(|c| format!("R = {}, {}", phys(c.d.motor.phase_resistance_ohm, "Ω"), c.rating_in())),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_LEVEL_SAMPLES",
            value: Custom(|c| c.samples(c.level_periods())),
            formula: Lit("⌈max(8·τ, 2 ms)/T_s⌉, τ = max(L_d, L_q)/R: each pulse level settles to e⁻⁸"),
            equation: Lit("thesis A (6.4)"),
            inputs: Of(|c| c.tau_in.clone()),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_REST_SAMPLES",
            value: Custom(|c| c.samples(c.level_periods())),
            formula: Lit("as a level: the current decays to e⁻⁸ at 0 V before the next pulse"),
            equation: Lit("thesis A (6.4)"),
            inputs: Of(|c| c.tau_in.clone()),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_AVERAGE_SAMPLES",
            value: Custom(|c| c.samples((c.level_periods() / 10.0).ceil().max(1.0))),
            formula: Lit(
                "⌈levels/10⌉: the last tenth of a level (and as many periods at the end of each of the rotation's holds) averaged",
            ),
            equation: Lit("—"),
            inputs: Of(|c| c.tau_in.clone()),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_RESISTANCE_RATIO",
            value: F32(|_| PREFLIGHT_RESISTANCE_RATIO, ""),
            formula: Lit(
                "R accepted in [R/2, 2·R]: copper from −40 to +180 °C is 0.76…1.63 of R at 20 °C (thesis B (2.24)), plus leads and switches; a wrong motor, a wrong sensing gain or a bad connection is outside",
            ),
            equation: Lit("thesis B (2.24)"),
            inputs: Lit("—"),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_INDUCTANCE_RATIO",
            value: F32(|_| PREFLIGHT_INDUCTANCE_RATIO, ""),
            formula: Lit(
                "L accepted in [L_d/2, 2·L_d]: saturation and the d/q difference stay inside; a wrong motor or a sensing whose bandwidth or gain is wrong does not",
            ),
            equation: Lit("thesis A (6.8)"),
            inputs: Lit("—"),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_CURRENT_TRIP",
            value: F32(|c| 1.2 * PREFLIGHT_RESISTANCE_RATIO * c.preflight_current(), "A"),
            formula: Lit(
                "1.2·ρ_R·I_p: 20 % above what the lowest accepted R draws at V; ends the check (R out of bound)",
            ),
            equation: Lit("—"),
            inputs: Of(|c| c.rating_in()),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_SUM_BOUND",
            value: F32(|c| c.sum_bound(), "A"),
            formula: Lit(
                "0.1·I_p + 3 codes of a 12-bit conversion (0 with two measured phases: the third is computed from them): one phase's gain 10 % off, or an offset of that size, is refused",
            ),
            equation: Lit("thesis A (2.1)"),
            inputs: Of(|c| {
                format!(
                    "{} phases measured, {} per 12-bit code",
                    c.b.current_phases,
                    phys(16.0 * c.b.amps_per_lsb.abs(), "A")
                )
            }),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_OPEN_FRACTION",
            value: F32(|_| 0.5, ""),
            formula: Lit(
                "a phase must carry ½ of its expected current (of the least the rotation draws; of its share cos(θ − 2πk/3) of a pulse within 60° of its axis)",
            ),
            equation: Lit("thesis A (2.7)"),
            inputs: Lit("—"),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_TAU_OFFSET",
            value: F32(|c| c.b.loop_delay_s + 0.5 * c.ts, "s"),
            formula: Lit(
                "loop delay + T_s/2: the rise's area from the sample of the period that computed the step (a left-rectangle sum) is (delay + τ + T_s/2)·ΔI",
            ),
            equation: Lit("thesis A §4.6"),
            inputs: Of(|c| format!("loop delay {}, {}", phys(c.b.loop_delay_s, "s"), c.ts_in)),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_RESISTANCE",
            value: F32(|c| c.d.motor.phase_resistance_ohm, "Ω"),
            formula: Lit("the spec's phase resistance R, the pre-flight check's reference"),
            equation: Lit("thesis A (6.3)"),
            inputs: Lit("motor.phase_resistance"),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_INDUCTANCE",
            value: F32(|c| c.d.motor.d_inductance_h, "H"),
            formula: Lit("the spec's L_d: the pulses are on the d axis"),
            equation: Lit("thesis A (6.8)"),
            inputs: Lit("motor.d_inductance"),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_RATIO",
            value: F32(
                |c| {
                    let o = &c.d.angle_observer;
                    f64::from(o.motor_pole_pairs) / f64::from(o.resolver_pole_pairs.max(1))
                },
                "",
            ),
            formula: Lit("n_p/n_r: electrical turns per resolver turn the rotation must show"),
            equation: Lit("thesis A (4.5), (6.2)"),
            inputs: Of(|c| {
                let o = &c.d.angle_observer;
                format!("n_p = {}, n_r = {}", o.motor_pole_pairs, o.resolver_pole_pairs)
            }),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_RATIO_BOUND",
            value: F32(|c| 0.5 / f64::from(c.d.angle_observer.resolver_pole_pairs.max(1)), ""),
            formula: Lit("0.5/n_r: half-way to the neighbouring pole-pair counts (n_p ± 1)/n_r"),
            equation: Lit("thesis A (4.5), (6.2)"),
            inputs: Of(|c| format!("n_r = {}", c.d.angle_observer.resolver_pole_pairs)),
            json: Json::None,
        },
        Decl {
            name: "PREFLIGHT_ANGLE_BOUND",
            value: Custom(|_| {
                // 30° electrical = π/6 in π-scaled Q1.31: 2^31/6.
                let bound = (2_147_483_648.0f64 / 6.0).round() as i64;
                (intv(bound, "i32", "int32_t"), format!("{bound} LSB (30° electrical)"))
            }),
            formula: Lit(
                "30° electrical: a resolver offset off by more costs over 13 % of the torque per ampere (1 − cos 30°) and sets a field-weakening current on q",
            ),
            equation: Lit("thesis A (4.5)"),
            inputs: Lit("—"),
            json: Json::None,
        },
        Decl {
            name: "FLUX_SETTLE_SAMPLES",
            value: Custom(|c| c.samples(c.periods(0.2))),
            formula: Lit("⌈200 ms/T_s⌉: the current loop settles at i = 0"),
            equation: Lit("thesis A §6.5"),
            inputs: Of(|c| c.ts_in.clone()),
            json: Json::None,
        },
        Decl {
            name: "FLUX_AVERAGE_SAMPLES",
            value: Custom(|c| c.samples(c.periods(0.1))),
            formula: Lit("⌈100 ms/T_s⌉ averaged (and captured)"),
            equation: Lit("thesis A (6.10)"),
            inputs: Of(|c| c.ts_in.clone()),
            json: Json::None,
        },
        Decl {
            name: "FLUX_MIN_SPEED",
            value: F32(|c| 0.05 * c.d.motor.max_electrical_speed_rad_s, "rad/s"),
            formula: Lit("5 % of the maximum electrical speed: the back EMF dominates R·i"),
            equation: Lit("thesis A (6.10)"),
            inputs: Of(|c| c.max_speed()),
            json: Json::None,
        },
        Decl {
            name: "INJECTION_LIMIT",
            value: F32(|c| c.injection_limit().map_or(0.0, |l| l.volts), "V"),
            formula: Lit(
                "min over d, q of min(½·I_trip/G_i, U_max/G_v): the frequency response's injection peak A keeps the injected current within half the routine's trip I_trip = ½·I_peak and the applied voltage within the linear modulation range U_max = U_dc/√3 at standstill (operating point v = 0); G_i = Σ (a_j/A)·|P/(1+L)|, G_v = 1 + Σ (a_j/A)·|L/(1+L)| over the default multisine lines on the design's sampled loop (each line's steady-state peak added); a larger commanded amplitude is refused",
            ),
            equation: Lit("triangle inequality over the lines on the sampled loop of thesis A (5.8)–(5.16)"),
            inputs: Of(|c| {
                c.injection_limit().map_or("—".into(), |l| {
                    format!(
                        "I_peak = {}, U_max = {}, G_i = {:.4} A/V, G_v = {:.4} (axis {})",
                        phys(c.d.motor.peak_current_a, "A"),
                        phys(c.d.current_loop.voltage_limit_v, "V"),
                        l.current_gain,
                        l.voltage_gain,
                        l.axis
                    )
                })
            }),
            json: Json::None,
        },
        Decl {
            name: "STANDSTILL_SPEED",
            value: F32(|c| 0.01 * c.d.motor.max_electrical_speed_rad_s, "rad/s"),
            formula: Lit("1 % of the maximum electrical speed: a command is accepted below it"),
            equation: Lit("—"),
            inputs: Of(|c| c.max_speed()),
            json: Json::None,
        },
    ];

    /// The frequency response's injection limit ([`injection_limit`]).
    fn injection_limit(&self) -> Option<InjectionLimit> {
        injection_limit(self.d)
    }

    /// Whole control periods lasting at least `t` seconds (at least one).
    fn periods(&self, t: f64) -> f64 {
        (t / self.ts).ceil().clamp(1.0, f64::from(u32::MAX))
    }

    /// `periods` control periods as a `u32` constant, with their duration.
    fn samples(&self, periods: f64) -> (Value, String) {
        (
            intv(periods as i64, "u32", "uint32_t"),
            format!("{periods} periods ({})", phys(periods * self.ts, "s")),
        )
    }

    /// The pre-flight current I_p = ¼·min(rated amplitude, over-current trip) \[A\].
    fn preflight_current(&self) -> f64 {
        0.25 * self.rated_amplitude().min(self.b.trips.over_current_a.value)
    }

    /// The pre-flight rotation's electrical rate ω = min(2π, R·I_p/(2·ψ_M)) \[rad/s\]:
    /// the back-EMF ψ_M·ω of a following rotor at most half the rotation's voltage.
    fn preflight_rotation_rate(&self) -> f64 {
        let v = self.d.motor.phase_resistance_ohm * self.preflight_current();
        match self.d.motor.flux_linkage_wb {
            Some(psi) if psi > 0.0 => std::f64::consts::TAU.min(0.5 * v / psi),
            _ => std::f64::consts::TAU,
        }
    }

    /// The rating's amplitude: √2·I_n, else √2·I_peak \[A\].
    fn rated_amplitude(&self) -> f64 {
        let m = &self.d.motor;
        std::f64::consts::SQRT_2 * m.nominal_current_a_rms.unwrap_or(m.peak_current_a_rms)
    }

    /// The rating and the trip as inputs.
    fn rating_in(&self) -> String {
        format!(
            "rated amplitude {} ({}), over-current trip {}",
            phys(self.rated_amplitude(), "A"),
            if self.d.motor.nominal_current_a_rms.is_some() {
                "√2·nominal_current"
            } else {
                "√2·peak_current"
            },
            phys(self.b.trips.over_current_a.value, "A")
        )
    }

    /// Periods of a pulse level: ⌈max(8·τ, 2 ms)/T_s⌉.
    fn level_periods(&self) -> f64 {
        self.periods((8.0 * self.tau).max(2e-3))
    }

    /// |i_u + i_v + i_w| accepted \[A\] (0: two measured phases).
    fn sum_bound(&self) -> f64 {
        if self.b.current_phases < 3 {
            0.0
        } else {
            0.1 * self.preflight_current() + 3.0 * 16.0 * self.b.amps_per_lsb.abs()
        }
    }

    /// ω_e,max as an input.
    fn max_speed(&self) -> String {
        format!("ω_e,max = {}", phys(self.d.motor.max_electrical_speed_rad_s, "rad/s"))
    }
}

/// The frequency response's injection limit and what set it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InjectionLimit {
    /// The limit A_max \[V\], rounded to the `f32` the firmware holds.
    pub volts: f64,
    /// G_i: peak injected current per volt of A \[A/V\] on the limiting axis.
    pub current_gain: f64,
    /// G_v: peak applied voltage per volt of A on the limiting axis.
    pub voltage_gain: f64,
    /// The limiting axis, "d" or "q".
    pub axis: &'static str,
}

/// The default line set of the frequency response of `axis` (`(first harmonic, lines
/// per octave)`) for a multisine period of `n` samples: the first line two octaves
/// below the designed crossover (at least harmonic 1), as many lines per octave (1–8)
/// as `motor_control::commissioning::MAX_LINES` allows up to the Nyquist harmonic N/2.
/// The host's default (`motorgen commission … frequency-response` without
/// `--frequencies`) and [`injection_limit`]'s.
pub fn default_lines(d: &Design, axis: motor_control::commissioning::Axis, n: u32) -> Option<(u16, u8)> {
    use motor_control::commissioning::Axis;
    let ts = d.drive.sample_period_s;
    let w0 = 2.0 * std::f64::consts::PI / (f64::from(n) * ts);
    let gains = match axis {
        Axis::D => &d.current_loop.d,
        Axis::Q => &d.current_loop.q,
    };
    let wc = gains
        .sampled
        .gain_crossover_rad_s
        .unwrap_or(d.current_loop.bandwidth_rad_s);
    let first = ((wc / 4.0 / w0).floor() as u32).clamp(1, 255);
    lines_spanning(first, n)
}

/// `first` with the most lines per octave whose set still reaches the highest octave
/// below N/2 within `motor_control::commissioning::MAX_LINES` lines.
pub fn lines_spanning(first: u32, n: u32) -> Option<(u16, u8)> {
    use motor_control::commissioning::{Lines, multisine_lines};
    let first = u16::try_from(first).ok()?;
    // The last line within an octave of N/2 (a set cut at MAX_LINES ends lower).
    let reach = |l: &Lines| l.used().last().is_some_and(|&k| u32::from(k) * 2 >= n / 2);
    (1..=8u8)
        .rev()
        .find(|&r| multisine_lines(first, r, n).is_some_and(|l| reach(&l)))
        .map(|r| (first, r))
}

/// The largest injection peak A \[V\] of the frequency response (`INJECTION_LIMIT`).
///
/// The routine injects d = Σ a_j·sin(ω_j·t + φ_j) (clamped to ±A) at the controller's
/// output, a_j = A·w_j/√(2·Σw²) (`motor_control::commissioning::FrequencyResponse::
/// line_amplitude`), on the design's default lines ([`default_lines`], the capture
/// buffer's period). On the design's sampled loop (gains, plant R, L, the loop delay:
/// L(z) of `design::current_loop::analysis::open_loop`, plant P(z) = (b₀·z + b)/(z·(z − a))) the
/// injection reaches the current through P/(1 + L) and the controller's output through
/// −L/(1 + L); in periodic steady state each line's peak adds at most:
///
/// ```text
/// |i| ≤ A·G_i,  G_i = Σ_j (a_j/A)·|P/(1 + L)|(ω_j)
/// |v| ≤ |d| + |u_PI| ≤ A·G_v,  G_v = 1 + Σ_j (a_j/A)·|L/(1 + L)|(ω_j)
/// ```
///
/// A_max = min over d, q of min(½·I_trip/G_i, U_max/G_v): the injected current within
/// half the routine's trip I_trip = ½·I_peak (the host's trip level), the applied
/// voltage within the linear modulation range U_max = U_dc/√3 (at standstill the
/// operating point is v = 0). The clamp only lowers |d|; the settling transient is not
/// bounded (the trip still guards it). `None` without a board or default lines.
pub fn injection_limit(d: &Design) -> Option<InjectionLimit> {
    use crate::design::current_loop::{analysis, discrete};
    use motor_control::commissioning::{Axis, FrequencyResponse, multisine_lines};
    use motor_control::commissioning_mode::{FREQUENCY_RESPONSE_SETTLE_PERIODS, frequency_response_period};
    d.board.as_ref()?;
    let n = frequency_response_period(CAPTURE_CAPACITY as usize);
    let trip = 0.5 * d.motor.peak_current_a;
    let u_max = d.current_loop.voltage_limit_v;
    let ts = d.drive.sample_period_s;
    let mut best: Option<InjectionLimit> = None;
    for (name, axis) in [("d", Axis::D), ("q", Axis::Q)] {
        let (first, per_octave) = default_lines(d, axis, n)?;
        let lines = multisine_lines(first, per_octave, n)?;
        let r = FrequencyResponse {
            axis,
            amplitude: 1.0,
            current_trip: 1.0,
            period: n,
            settle_periods: FREQUENCY_RESPONSE_SETTLE_PERIODS,
            lines,
        };
        let req = d.current_loop_request(axis);
        let plant = discrete::plant(&req);
        let gains = match axis {
            Axis::D => &d.current_loop.d,
            Axis::Q => &d.current_loop.q,
        }
        .loop_gains();
        let (mut gi, mut gv) = (0.0, 1.0);
        for (j, &k) in lines.used().iter().enumerate() {
            let omega = 2.0 * std::f64::consts::PI * f64::from(k) / (f64::from(n) * ts);
            let l = analysis::open_loop(&gains, &plant, omega);
            let z = nalgebra::Complex::from_polar(1.0, omega * ts);
            let p = plant.transfer(z);
            let one = nalgebra::Complex::new(1.0, 0.0);
            let a = f64::from(r.line_amplitude(j));
            gi += a * (p / (one + l)).norm();
            gv += a * (l / (one + l)).norm();
        }
        let volts = f64::from(((0.5 * trip / gi).min(u_max / gv)) as f32);
        if best.is_none_or(|b| volts < b.volts) {
            best = Some(InjectionLimit {
                volts,
                current_gain: gi,
                voltage_gain: gv,
                axis: name,
            });
        }
    }
    best
}

/// The `commissioning` group: the fixed parameters of the chapter-6 routines the CAN
/// command starts (the command gives voltage, trip and decimation), emitted with the
/// CAN interface (only for a design on a board).
pub fn commissioning_group(d: &Design) -> Option<Group> {
    let b = d.board.as_ref()?;
    let m = &d.motor;
    let ts = d.drive.sample_period_s;
    let tau = m.d_inductance_h.max(m.q_inductance_h) / m.phase_resistance_ohm;
    let ts_in = format!("T_s = {} (drive.switching_frequency)", phys(ts, "s"));
    let commissioning = Commissioning {
        d,
        b,
        ts,
        tau,
        tau_in: format!("τ = {}, {ts_in}", phys(tau, "s")),
        ts_in,
    };
    Some(Group {
        name: "commissioning",
        title: "Commissioning routines started over CAN (thesis A chapter 6)",
        constants: declare(Commissioning::DECLS, &commissioning, "").collect(),
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

/// The per-period increment of a π-scaled Q1.31 angle (2^32 LSB per electrical turn)
/// turning at `turns_per_s` electrical turns per second, sampled every `ts` seconds:
/// 2^32·T_s·turns/s, rounded, at least 1 LSB and at most i32::MAX.
fn angle_step(turns_per_s: f64, ts: f64) -> f64 {
    (4_294_967_296.0 * ts * turns_per_s)
        .round()
        .clamp(1.0, f64::from(i32::MAX))
}
