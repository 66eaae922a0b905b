//! The identification of `motorgen identify` as a library (`identify::Request`): texts
//! in, the results table, the spec's update or each kind of failure out, with no file
//! touched. The command line's files, lock and exit codes are tested in
//! `crates/motorgen/tests/it` (`identify.rs`, `writeback.rs`).

use codegen::units::{self, Kind};
use codegen::{Design, Source};
use motor_commission::identify::{Request, What, capture_files};
use motor_commission::synthetic::step_recording;
use motor_commission::{Error, Input};
use motor_control::commissioning::Axis;
use motor_test_support::repo;

const SPEC: &str = "motors/fischer-ti085.toml";

fn fischer() -> (String, Design) {
    let text = std::fs::read_to_string(repo().join(SPEC)).unwrap();
    let d = codegen::design_source(SPEC, &text).unwrap();
    (text, d)
}

fn request(what: What) -> Request {
    Request {
        what,
        date: Some("2025-03-14".into()),
        sample_period: None,
        logs: Vec::new(),
        board: None,
        live: Vec::new(),
    }
}

/// Three q-axis step recordings of a motor 5 % off the datasheet: the table lists each,
/// the update writes R and L_q within 2 % with the date and the recordings' file names,
/// and the diff shows only changed lines.
#[test]
fn step_recordings_update_the_spec() {
    let (text, d) = fischer();
    let (r, l) = (1.05 * d.motor.phase_resistance_ohm, 1.05 * d.motor.q_inductance_h);
    let csv = (1..=3)
        .map(|k| Input::new(format!("runs/q{k}.csv"), step_recording(&d, "q", r, l, k)))
        .collect();
    let req = request(What::Step { axis: Axis::Q, csv });
    let date = req.check("2000-01-01").unwrap();
    let mut table = String::new();
    let spec = Source {
        file: SPEC,
        text: &text,
    };
    let update = req.identify(&spec, &date, &mut table).unwrap().unwrap();
    assert!(table.starts_with("q axis, 3 recording(s)"), "{table}");
    for k in 1..=3 {
        assert!(table.contains(&format!("\n  q{k}.csv ")), "{table}");
    }
    assert_eq!(update.keys, ["phase_resistance", "q_inductance"]);
    let value = |key: &str, kind: Kind| {
        let line = update
            .text
            .lines()
            .find(|x| x.starts_with(&format!("{key} = ")))
            .unwrap();
        units::parse(kind, line.split('"').nth(1).unwrap()).unwrap()
    };
    assert!((value("phase_resistance", Kind::Resistance) / r - 1.0).abs() < 0.02);
    assert!((value("q_inductance", Kind::Inductance) / l - 1.0).abs() < 0.02);
    assert!(
        update.text.contains("2025-03-14") && update.text.contains("q1.csv"),
        "{}",
        update.text
    );
    assert!(
        update.provenance.contains(&"phase_resistance: identified".to_string()),
        "{:?}",
        update.provenance
    );
    let diff = update.diff(&text);
    assert!(diff.contains("phase_resistance") && diff.lines().count() < 20, "{diff}");
}

/// An unreadable recording and a bad one are reported together as unreadable input
/// (the command's I/O exit code), each at its file; bad recordings alone are bad input.
#[test]
fn recording_problems_are_reported_together() {
    let (text, _) = fischer();
    let spec = Source {
        file: SPEC,
        text: &text,
    };
    let gone = Input::unreadable("gone.csv", "cannot read the recording: gone".into(), "a readable CSV");
    let bad = Input::new(
        "bad.csv",
        "# motorgen recording: step\nsample,voltage_v,current_a\n0,1,x\n",
    );
    let req = request(What::Step {
        axis: Axis::D,
        csv: vec![bad.clone(), gone],
    });
    match req.identify(&spec, "2025-03-14", &mut String::new()) {
        Err(Error::Unreadable(d)) => {
            let files: Vec<&str> = d.0.iter().map(|d| d.file.as_str()).collect();
            assert_eq!(files, ["bad.csv", "gone.csv"], "{d}");
        }
        other => panic!("{other:?}"),
    }
    let req = request(What::Flux { csv: vec![bad] });
    assert!(matches!(
        req.identify(&spec, "2025-03-14", &mut String::new()),
        Err(Error::Input(_))
    ));
}

/// The checks before the spec is read: a resolver run needs recordings, `--date` is a
/// date; without one, today's is written.
#[test]
fn checks_before_the_spec() {
    let mut req = request(What::Resolver {
        offset: Vec::new(),
        ratio: Vec::new(),
    });
    match req.check("2000-01-01") {
        Err(Error::Input(d)) => assert!(d.to_string().contains("no recordings given"), "{d}"),
        other => panic!("{other:?}"),
    }
    req.what = What::Flux { csv: Vec::new() };
    req.date = Some("14.03.2025".into());
    match req.check("2000-01-01") {
        Err(Error::Input(d)) => assert_eq!(d.0[0].file, "--date"),
        other => panic!("{other:?}"),
    }
    req.date = None;
    assert_eq!(req.check("2000-01-01").unwrap(), "2000-01-01");
}

/// Identified values that would break the design are refused at the rule's line in the
/// spec as given, saying that the identified values cause it (the Chalmers motor with
/// L_q a quarter of the datasheet's and R = 2·α_c·L_q: α_c·L < R, thesis B (2.43), as
/// the command line's `writeback.rs` runs it).
#[test]
fn an_update_that_breaks_the_design_is_refused() {
    let file = "motors/chalmers-hev50.toml";
    let text = std::fs::read_to_string(repo().join(file)).unwrap();
    let d = codegen::design_source(file, &text).unwrap();
    let l = d.motor.q_inductance_h / 4.0;
    let csv = vec![Input::new("q.csv", step_recording(&d, "q", 2.0 * 1470.0 * l, l, 3))];
    let req = request(What::Step { axis: Axis::Q, csv });
    let spec = Source { file, text: &text };
    let line = text
        .lines()
        .position(|x| x.starts_with("bandwidth = \"1470 rad/s\""))
        .unwrap()
        + 1;
    match req.identify(&spec, "2025-03-14", &mut String::new()) {
        Err(Error::Input(e)) => {
            assert_eq!(
                (e.0[0].line, e.0[0].key.as_str()),
                (line, "current_loop.bandwidth"),
                "{e}"
            );
            assert!(
                e.0[0]
                    .problem
                    .starts_with("with the identified phase_resistance, q_inductance written"),
                "{e}"
            );
        }
        Ok(u) => panic!("accepted: {:?}", u.map(|u| u.keys)),
        Err(e) => panic!("{e:?}"),
    }
}

/// `capture`'s files: a log that is not a `candump -l` log is a located error, an
/// unreadable one an unreadable input; a board without a CAN section is refused.
#[test]
fn capture_files_refuse_bad_logs() {
    let (text, _) = fischer();
    let spec = Input::new(SPEC, text);
    let board_file = "boards/motorgen-reference.toml";
    let board = Input::new(board_file, std::fs::read_to_string(repo().join(board_file)).unwrap());
    let log = Input::new("x.log", "not a candump line\n");
    match capture_files(&spec, &board, &[log]) {
        Err(Error::Input(d)) => assert_eq!((d.0[0].file.as_str(), d.0[0].line), ("x.log", 1), "{d}"),
        other => panic!("{other:?}"),
    }
    let gone = Input::unreadable("gone.log", "cannot read the log: gone".into(), "a log");
    assert!(matches!(
        capture_files(&spec, &board, &[gone]),
        Err(Error::Unreadable(_))
    ));
    let no_can = Input::new("b.toml", "");
    assert!(capture_files(&spec, &no_can, &[]).is_err());
}

/// A file that is not UTF-8 is bad input at its first invalid byte; one that could not
/// be read carries the front end's reason as an unreadable input.
#[test]
fn inputs_carry_why_they_cannot_be_read() {
    let bad = Input::from_bytes("m.toml", b"a = 1\nb = \"\xff\"\n".to_vec());
    match bad.text() {
        Err(Error::Input(d)) => {
            assert_eq!(
                (d.0[0].file.as_str(), d.0[0].line, d.0[0].column),
                ("m.toml", 2, 6),
                "{d}"
            );
            assert!(d.0[0].problem.contains("not valid UTF-8 (byte 11)"), "{d}");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(Input::from_bytes("m.toml", b"a = 1\n".to_vec()).text(), Ok("a = 1\n"));
    let gone = Input::unreadable("m.toml", "cannot read the file: gone".into(), "a file");
    assert!(matches!(gone.text(), Err(Error::Unreadable(_))));
    assert!(
        gone.text()
            .unwrap_err()
            .to_string()
            .starts_with("error: m.toml:1:1: cannot read the file: gone\n")
    );
}
