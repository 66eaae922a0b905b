//! The generated DBC file (`templates/motor.dbc.j2`) parsed with `can-dbc`, a maintained
//! DBC parser, for every seed motor on the reference board: every message has the
//! identifier and data length of the `can` constants group, and every signal decodes
//! the bytes the firmware's encoders (`motor_control::can_protocol`, the fault report's
//! included) produce back to the encoded value (within half an LSB of its factor; integers exactly). A signal of the
//! DBC that no check covers fails the test, as does a check whose signal is missing.

use std::collections::BTreeSet;

use can_dbc::{ByteOrder, Dbc, MessageId, MultiplexIndicator, Signal, SignalExtendedValueType, ValueType};
use codegen::render::{Output, render};
use motor_commission::candump::layout;
use motor_control::can_protocol::{self as p, Command, End, Header, Layout, Quantity, Reason, Routine, State};

use motor_test_support::repo;

/// The design of `stem` on the reference board, or on its 400 A variant for the traction
/// motors whose peak current the reference board cannot measure (refused there).
fn design(stem: &str) -> codegen::Design {
    let text = std::fs::read_to_string(repo().join(format!("motors/{stem}.toml"))).unwrap();
    let mut refusals = Vec::new();
    for board in ["boards/motorgen-reference.toml", "boards/motorgen-reference-400a.toml"] {
        let board_text = std::fs::read_to_string(repo().join(board)).unwrap();
        match codegen::design_with_board(&format!("motors/{stem}.toml"), &text, board, &board_text) {
            Ok(d) => return d,
            Err(e) => refusals.push(e.to_string()),
        }
    }
    panic!("{stem} fits neither reference board:\n{}", refusals.join("\n"))
}

/// The physical value of `sig` in `data` by the DBC's own definition: little-endian
/// ("@1") bits start_bit … start_bit + size − 1, two's complement if signed ("-"),
/// times factor plus offset.
fn decode(sig: &Signal, data: &[u8]) -> f64 {
    assert_eq!(sig.byte_order, ByteOrder::LittleEndian, "{}", sig.name);
    let word = data
        .iter()
        .enumerate()
        .fold(0u64, |w, (k, &b)| w | u64::from(b) << (8 * k));
    let raw = (word >> sig.start_bit) & ((1u64 << sig.size) - 1);
    let signed = sig.value_type == ValueType::Signed && (raw >> (sig.size - 1)) & 1 == 1;
    let v = if signed {
        raw as i64 - (1i64 << sig.size)
    } else {
        raw as i64
    };
    v as f64 * sig.factor + sig.offset
}

/// Checks signal `name` of a message against `want`: exact for factor 1, else within
/// half its factor (the encoder rounds to the nearest LSB).
fn check(sigs: &[Signal], seen: &mut BTreeSet<String>, name: &str, data: &[u8], want: f64) {
    let sig = sigs
        .iter()
        .find(|s| s.name == name)
        .unwrap_or_else(|| panic!("signal {name} missing"));
    let got = decode(sig, data);
    let tol = if sig.factor == 1.0 {
        0.0
    } else {
        0.5 * sig.factor * (1.0 + 1e-6)
    };
    assert!(
        (got - want).abs() <= tol,
        "{name}: DBC decodes {got}, encoded {want} (±{tol})"
    );
    seen.insert(name.to_string());
}

fn message<'a>(dbc: &'a Dbc, name: &str, id: u16, len: u8) -> &'a [Signal] {
    let m = dbc
        .messages
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("message {name} missing"));
    assert_eq!(m.id, MessageId::Standard(id), "{name}");
    assert_eq!(m.size, u64::from(len), "{name}");
    &m.signals
}

fn all_names(sigs: &[Signal]) -> BTreeSet<String> {
    sigs.iter().map(|s| s.name.clone()).collect()
}

#[test]
fn generated_dbc_matches_the_firmware_encoders() {
    let stems = [
        "fischer-ti085",
        "unimotor-142umd300",
        "chalmers-hev50",
        "maxon-ec45-flat-70w",
        "emrax-228-hv",
    ];
    for stem in stems {
        let d = design(stem);
        let text = render(&d, Output::Dbc).unwrap();
        let dbc = Dbc::try_from(text.as_str()).unwrap_or_else(|e| panic!("{stem}: {e:?}\n{text}"));
        let l: Layout = layout(&d).unwrap();
        let board = &d.board.as_ref().unwrap().board;
        assert_eq!(dbc.messages.len(), 7, "{stem}");
        // A value at 30 % of each quantity's full scale, and negative.
        let at = |q: Quantity| 0.3 * 32768.0 * l.per_lsb(q);

        // Setpoint: bytes 0–1 a little-endian i16 of TORQUE_PER_LSB_NM (firmware
        // `can_frame::decode_torque`): 0x0BB8 = 3000 LSB.
        let sigs = message(&dbc, "SETPOINT", board.setpoint_id, 2);
        let mut seen = BTreeSet::new();
        check(
            sigs,
            &mut seen,
            "TORQUE",
            &[0xB8, 0x0B],
            3000.0 * board.torque_resolution_nm,
        );
        assert_eq!(seen, all_names(sigs), "{stem} SETPOINT");

        let sigs = message(&dbc, "STATUS", l.status_id, p::STATUS_LEN);
        let f = p::encode_status(&l, State::Streaming, Reason::Tripped, 1, 0xA5);
        let mut seen = BTreeSet::new();
        check(sigs, &mut seen, "STATE", f.bytes(), 3.0);
        check(sigs, &mut seen, "REASON", f.bytes(), 7.0);
        check(sigs, &mut seen, "ROUTINE", f.bytes(), 1.0);
        check(sigs, &mut seen, "FAULTS", f.bytes(), 165.0);
        assert_eq!(seen, all_names(sigs), "{stem} STATUS");

        let sigs = message(&dbc, "COMMAND", l.command_id, p::COMMAND_LEN);
        let c = Command {
            routine: Some(Routine::PolePairRatio),
            axis_q: true,
            voltage: at(Quantity::Voltage),
            current_trip: at(Quantity::Current),
            decimation: 300,
        };
        let f = p::encode_command(&l, &c);
        let mut seen = BTreeSet::new();
        check(sigs, &mut seen, "ROUTINE", f.bytes(), 3.0);
        check(sigs, &mut seen, "AXIS", f.bytes(), 1.0);
        check(sigs, &mut seen, "VOLTAGE", f.bytes(), f64::from(c.voltage));
        check(sigs, &mut seen, "CURRENT_TRIP", f.bytes(), f64::from(c.current_trip));
        check(sigs, &mut seen, "DECIMATION", f.bytes(), 300.0);
        assert_eq!(seen, all_names(sigs), "{stem} COMMAND");

        let sigs = message(&dbc, "CAPTURE_HEADER", l.header_id, p::HEADER_LEN);
        let h = Header {
            routine: Routine::Flux,
            axis_q: true,
            tripped: true,
            decimation: 3,
            sample_period_units: 625,
            count: 1234,
            current_trip: -at(Quantity::Current),
        };
        let f = p::encode_header(&l, &h);
        let mut seen = BTreeSet::new();
        check(sigs, &mut seen, "ROUTINE", f.bytes(), 4.0);
        check(sigs, &mut seen, "AXIS", f.bytes(), 1.0);
        check(sigs, &mut seen, "TRIPPED", f.bytes(), 1.0);
        check(sigs, &mut seen, "DECIMATION", f.bytes(), 3.0);
        // 625 × 100 ns = 62.5 µs (the factor 1E-007 is not 1: half a unit).
        check(sigs, &mut seen, "SAMPLE_PERIOD", f.bytes(), 62.5e-6);
        check(sigs, &mut seen, "SAMPLE_COUNT", f.bytes(), 1234.0);
        check(sigs, &mut seen, "CURRENT_TRIP", f.bytes(), f64::from(h.current_trip));
        assert_eq!(seen, all_names(sigs), "{stem} CAPTURE_HEADER");

        // Data: the multiplexor selects each routine's two channels.
        let sigs = message(&dbc, "CAPTURE_DATA", l.data_id, p::DATA_LEN);
        let mux = sigs.iter().find(|s| s.name == "ROUTINE").unwrap();
        assert_eq!(mux.multiplexer_indicator, MultiplexIndicator::Multiplexor);
        let mut seen = BTreeSet::new();
        for (routine, [a_name, b_name]) in [
            (Routine::Step, ["STEP_VOLTAGE", "STEP_CURRENT"]),
            (Routine::ResolverOffset, ["ALIGN_U_ALPHA", "ALIGN_THETA_R"]),
            (Routine::PolePairRatio, ["RATIO_THETA_E", "RATIO_THETA_R"]),
            (Routine::Flux, ["FLUX_OMEGA_E", "FLUX_U_Q"]),
        ] {
            let [qa, qb] = routine.channels();
            let (a, b) = (at(qa), -at(qb));
            let f = p::encode_data(&l, routine, 4321, a, b);
            check(sigs, &mut seen, "ROUTINE", f.bytes(), f64::from(routine.code()));
            check(sigs, &mut seen, "SEQUENCE", f.bytes(), 4321.0);
            check(sigs, &mut seen, a_name, f.bytes(), f64::from(a));
            check(sigs, &mut seen, b_name, f.bytes(), f64::from(b));
            for n in [a_name, b_name] {
                let s = sigs.iter().find(|s| s.name == n).unwrap();
                assert_eq!(
                    s.multiplexer_indicator,
                    MultiplexIndicator::MultiplexedSignal(u64::from(routine.code())),
                    "{n}"
                );
            }
        }
        assert_eq!(seen, all_names(sigs), "{stem} CAPTURE_DATA");

        let sigs = message(&dbc, "CAPTURE_END", l.end_id, p::END_LEN);
        let e = End {
            crc: 0xDEAD_BEEF,
            trip_sample: 812,
            trip_current: at(Quantity::Current),
        };
        let f = p::encode_end(&l, &e);
        let mut seen = BTreeSet::new();
        check(sigs, &mut seen, "CRC32", f.bytes(), f64::from(0xDEAD_BEEFu32));
        check(sigs, &mut seen, "TRIP_SAMPLE", f.bytes(), 812.0);
        check(sigs, &mut seen, "TRIP_CURRENT", f.bytes(), f64::from(e.trip_current));
        assert_eq!(seen, all_names(sigs), "{stem} CAPTURE_END");

        // The fault report: identifier and i_q unit from the generated `can` group (the
        // firmware's `motor_config::fault_frame` uses the same constants and encoder).
        let groups = codegen::constants::constants(&d);
        let can = codegen::constants::group_named(&groups, "can").unwrap();
        let num = |name: &str| can.number(name).unwrap_or_else(|| panic!("{name} missing"));
        let (fault_id, amps) = (num("FAULT_REPORT_ID") as u16, num("FAULT_CURRENT_PER_LSB") as f32);
        assert!(fault_id < l.status_id.min(board.setpoint_id), "{stem}: {fault_id:#x}");
        let sigs = message(&dbc, "FAULT_REPORT", fault_id, p::FAULT_REPORT_LEN);
        let r = p::FaultReport {
            cause: 4,
            pc: Some(0x0800_1234),
            state: Some(p::FaultState {
                running: true,
                tripped: false,
                i_q: -212.26,
            }),
            measured: None,
        };
        let bytes = p::encode_fault_report(amps, &r);
        let mut seen = BTreeSet::new();
        check(sigs, &mut seen, "CAUSE", &bytes, 4.0);
        check(sigs, &mut seen, "PC_VALID", &bytes, 1.0);
        check(sigs, &mut seen, "STATE_VALID", &bytes, 1.0);
        check(sigs, &mut seen, "OUTPUTS_ON", &bytes, 1.0);
        check(sigs, &mut seen, "TRIPPED", &bytes, 0.0);
        check(sigs, &mut seen, "MEASURED_VALID", &bytes, 0.0);
        check(sigs, &mut seen, "MEASURED_INDEX", &bytes, 0.0);
        check(sigs, &mut seen, "PC", &bytes, f64::from(0x0800_1234u32));
        check(sigs, &mut seen, "I_Q", &bytes, -212.26);
        // A start-up check's refusal: no PC, so bytes 2–5 carry the measurement (the
        // multiplexor PC_VALID = 0 selects MEASURED, an IEEE single by SIG_VALTYPE_):
        // phase w's zero level 2 992 codes low (cause 10, index 2).
        let r = p::FaultReport {
            cause: 10,
            pc: None,
            measured: Some(p::FaultMeasurement::at(-2_992.0, 2)),
            ..r
        };
        let bytes = p::encode_fault_report(amps, &r);
        check(sigs, &mut seen, "CAUSE", &bytes, 10.0);
        check(sigs, &mut seen, "PC_VALID", &bytes, 0.0);
        check(sigs, &mut seen, "MEASURED_VALID", &bytes, 1.0);
        check(sigs, &mut seen, "MEASURED_INDEX", &bytes, 2.0);
        let fault_msg = MessageId::Standard(fault_id);
        for (name, mux) in [("PC", 1), ("MEASURED", 0)] {
            let sig = sigs.iter().find(|s| s.name == name).unwrap();
            assert_eq!(
                sig.multiplexer_indicator,
                MultiplexIndicator::MultiplexedSignal(mux),
                "{name}"
            );
        }
        let pc_valid = sigs.iter().find(|s| s.name == "PC_VALID").unwrap();
        assert_eq!(pc_valid.multiplexer_indicator, MultiplexIndicator::Multiplexor);
        let measured = sigs.iter().find(|s| s.name == "MEASURED").unwrap();
        assert_eq!(
            dbc.extended_value_type_for_signal(fault_msg, "MEASURED"),
            Some(&SignalExtendedValueType::IEEEfloat32Bit),
            "{stem}: MEASURED is declared a float"
        );
        // The raw 32 bits the DBC places (bits 16–47), read as the IEEE single it declares.
        let raw = u32::from_le_bytes(bytes[2..6].try_into().unwrap());
        assert_eq!((measured.start_bit, measured.size), (16, 32));
        assert_eq!(
            measured.byte_order,
            ByteOrder::LittleEndian,
            "{stem}: MEASURED byte order"
        );
        assert_eq!(f32::from_bits(raw), -2_992.0, "{stem}: MEASURED");
        seen.insert("MEASURED".to_string());
        assert_eq!(seen, all_names(sigs), "{stem} FAULT_REPORT");
    }
}

/// Without a board there is no CAN interface: no `can` group, so `generate` writes no DBC.
#[test]
fn no_board_no_interface() {
    let text = std::fs::read_to_string(repo().join("motors/fischer-ti085.toml")).unwrap();
    let d = codegen::design_source("fischer-ti085.toml", &text).unwrap();
    assert!(layout(&d).is_none());
}
