//! The commissioning flow of `motorgen commission` as a library (`commission::plan`,
//! `Plan::run`, the identification of its `Captured::request`) on the simulated drive
//! (`sim_drive`: the firmware's commissioning mode and CAN encoder on a simulated motor)
//! in place of the socket: the same session, candump path, CSV and identification as on
//! a bench, and each failure as its own `Error` variant (the exit codes are `motorgen`'s,
//! tested there).
//!
//! The bench is `motor_verify::Setup::bench` — the firmware's control step configured
//! from the design and `verify`'s plant — as in the command line's tests (a
//! dev-dependency: the library itself does not depend on `motor-verify`).

use std::time::Duration;

use codegen::units::{self, Kind};
use codegen::{Design, Source};
use motor_commission::commission::{self, BusFrame, Captured, FrameBus, Options, Plan, RoutineOptions};
use motor_commission::sim_drive::SimulatedDrive;
use motor_commission::{Error, Input, socket};
use motor_control::can_protocol::{Frame, Reason};
use motor_control::commissioning::Axis;
use motor_test_support::repo;

const SPEC: &str = "motors/fischer-ti085.toml";
const BOARD: &str = "boards/motorgen-reference.toml";

/// The Fischer spec and the reference board as read, the design, and the plant's R and
/// L_d.
struct Bench {
    spec: Input,
    board: Input,
    design: Design,
    r: f64,
    ld: f64,
    i_max: f64,
}

fn bench() -> Bench {
    let text = std::fs::read_to_string(repo().join(SPEC)).unwrap();
    let board = std::fs::read_to_string(repo().join(BOARD)).unwrap();
    let design = codegen::design_with_board(SPEC, &text, BOARD, &board).unwrap();
    let d = &design;
    Bench {
        r: d.motor.phase_resistance_ohm,
        ld: d.motor.d_inductance_h,
        i_max: d.motor.peak_current_a.min(d.scaling.phase_current.full_scale),
        spec: Input::new(SPEC, text),
        board: Input::new(BOARD, board),
        design,
    }
}

impl Bench {
    /// The drive on the simulated motor at standstill.
    fn drive(&self) -> SimulatedDrive {
        let text = self.spec.text().unwrap();
        let spec = codegen::spec::parse(Source { file: SPEC, text }).unwrap();
        let setup = motor_verify::Setup::new(&spec, &self.design);
        SimulatedDrive::new(&self.design, setup.bench(0.0), 0.0).unwrap()
    }

    /// A d-axis step to 30 % of the current limit, tripping at 80 %, on `sim0`.
    fn options(&self) -> Options {
        Options {
            iface: "sim0".into(),
            timeout: "60 s".into(),
            decimation: None,
            date: Some("2025-03-14".into()),
            routine: RoutineOptions::Step {
                axis: Axis::D,
                voltage: format!("{} V", 0.3 * self.i_max * self.r),
                trip: format!("{} A", 0.8 * self.i_max),
            },
        }
    }

    fn plan(&self, o: &Options) -> Result<Plan, Error> {
        commission::plan(o, &self.spec, &self.board)
    }

    /// The spec's text after identifying from `captured` (and the results table).
    fn identify(&self, captured: &Captured) -> (String, String) {
        let date = captured.request.check("2000-01-01").unwrap();
        assert_eq!(date, "2025-03-14");
        let text = self.spec.text().unwrap();
        let source = Source { file: SPEC, text };
        let mut table = String::new();
        let update = captured.request.identify(&source, &date, &mut table).unwrap().unwrap();
        assert_eq!(update.keys, ["phase_resistance", "d_inductance"]);
        assert!(!update.diff(text).is_empty());
        (update.text, table)
    }
}

/// The SI value of `key = "… unit"` in the spec text.
fn value(text: &str, key: &str, kind: Kind) -> f64 {
    let line = text
        .lines()
        .find(|l| l.starts_with(&format!("{key} = ")))
        .unwrap_or_else(|| panic!("no {key} in\n{text}"));
    units::parse(kind, line.split('"').nth(1).unwrap()).unwrap()
}

/// A d step over the simulated bus: one command sent, one CSV named after the spec,
/// routine, axis and header time, R and L_d within 2 % of the plant's (the accuracy the
/// identify tests state) in the updated spec, whose provenance names the live log.
#[test]
fn step_over_the_simulated_bus_identifies_r_and_ld() {
    let b = bench();
    let mut drive = b.drive();
    let captured = b.plan(&b.options()).unwrap().run(&mut drive).unwrap();
    assert_eq!(drive.commands, 1);
    assert_eq!(captured.files.len(), 1);
    let (name, csv) = &captured.files[0];
    // Period 0 of the simulation is 1.7e9 s = 2023-11-14 22:13:20 UTC.
    assert!(name.starts_with("fischer-ti085-step-d-2023-11-14T2213"), "{name}");
    assert!(name.ends_with(".csv"), "{name}");
    assert!(csv.starts_with("# motorgen recording: step\n"), "{csv}");
    let (text, table) = b.identify(&captured);
    assert!(table.starts_with("d axis, 1 recording(s)"), "{table}");
    let r = value(&text, "phase_resistance", Kind::Resistance);
    let ld = value(&text, "d_inductance", Kind::Inductance);
    assert!((r / b.r - 1.0).abs() < 0.02, "R = {r}, plant {}", b.r);
    assert!((ld / b.ld - 1.0).abs() < 0.02, "L_d = {ld}, plant {}", b.ld);
    assert!(text.contains("sim0 (live)"), "{text}");
}

/// A torque setpoint: the drive refuses (status reason 2), the error names the reason.
#[test]
fn refusal_names_the_reason() {
    let b = bench();
    let mut drive = b.drive();
    drive.guards.torque_setpoint = 1.0;
    let e = b.plan(&b.options()).unwrap().run(&mut drive).unwrap_err();
    assert!(
        matches!(&e, Error::Refused { iface, reason: Reason::TorqueNotZero } if iface == "sim0"),
        "{e:?}"
    );
    assert!(e.to_string().contains("the torque setpoint is not zero"), "{e}");
}

/// The simulated drive with the break arriving after `after` received frames.
struct Breaking {
    drive: SimulatedDrive,
    after: usize,
}

impl FrameBus for Breaking {
    fn send(&mut self, f: &Frame) -> Result<(), String> {
        self.drive.send(f)
    }
    fn receive(&mut self, timeout: Duration) -> Result<Option<BusFrame>, String> {
        self.after = self.after.saturating_sub(1);
        self.drive.guards.break_active = self.after == 0;
        self.drive.receive(timeout)
    }
    fn elapsed(&self) -> Duration {
        self.drive.elapsed()
    }
    fn timestamp(&self) -> f64 {
        self.drive.timestamp()
    }
}

/// The break during the step: the drive aborts (status fault, reason aborted).
#[test]
fn break_during_the_routine_is_an_abort() {
    let b = bench();
    let mut bus = Breaking {
        drive: b.drive(),
        after: 4,
    };
    let e = b.plan(&b.options()).unwrap().run(&mut bus).unwrap_err();
    assert!(matches!(&e, Error::Aborted { .. }), "{e:?}");
    assert!(e.to_string().contains("aborted"), "{e}");
}

/// A bus on which nothing answers.
struct Silent(Duration);

impl FrameBus for Silent {
    fn send(&mut self, _: &Frame) -> Result<(), String> {
        Ok(())
    }
    fn receive(&mut self, timeout: Duration) -> Result<Option<BusFrame>, String> {
        self.0 += timeout;
        Ok(None)
    }
    fn elapsed(&self) -> Duration {
        self.0
    }
    fn timestamp(&self) -> f64 {
        self.0.as_secs_f64()
    }
}

/// No drive on the bus: a timeout after `--timeout`, saying no status came.
#[test]
fn silence_is_a_timeout() {
    let b = bench();
    let mut o = b.options();
    o.timeout = "2 s".into();
    let e = b.plan(&o).unwrap().run(&mut Silent(Duration::ZERO)).unwrap_err();
    assert!(
        matches!(
            &e,
            Error::Timeout {
                last_status: None,
                capture_frames: 0,
                ..
            }
        ),
        "{e:?}"
    );
    let m = e.to_string();
    assert!(m.contains("within 2.0 s") && m.contains("no status frame"), "{m}");
}

/// An interface that does not exist: the bus is unavailable, the message names it.
#[test]
fn missing_interface_is_unavailable() {
    let Err(e) = socket::open("mgnone0", 500_000) else {
        panic!("mgnone0 opened");
    };
    assert!(matches!(&e, Error::BusUnavailable(_)), "{e:?}");
    assert!(e.to_string().contains("mgnone0"), "{e}");
}

/// Bad options are refused by the plan, before any bus: a trip that is no current, a
/// decimation whose capture does not fit, a timeout above an hour, a bad date; a spec
/// that does not design is bad input located in it.
#[test]
fn bad_options_are_bad_input() {
    let b = bench();
    let option = |o: &Options| match b.plan(o) {
        Err(Error::Option(p)) => p.subject,
        other => panic!("{other:?}"),
    };
    let mut o = b.options();
    o.routine = RoutineOptions::Step {
        axis: Axis::Q,
        voltage: "2 V".into(),
        trip: "10 V".into(),
    };
    assert_eq!(option(&o), "--trip");
    let mut o = b.options();
    o.decimation = Some(0);
    assert_eq!(option(&o), "--decimation");
    let mut o = b.options();
    o.timeout = "2 h".into();
    assert_eq!(option(&o), "--timeout");
    let mut o = b.options();
    o.date = Some("2025-13-01".into());
    assert_eq!(option(&o), "--date");
    let bad = Input::new("bad.toml", "[motor]\n");
    match commission::plan(&b.options(), &bad, &b.board) {
        Err(Error::Input(d)) => assert!(d.0.iter().all(|d| d.file == "bad.toml"), "{d}"),
        other => panic!("{other:?}"),
    }
}

/// On a real (virtual) CAN interface named by `MOTORGEN_VCAN` (e.g. `vcan0`, made with
/// `ip link add dev vcan0 type vcan && ip link set vcan0 up`): the simulated drive
/// answers on a second socket of the interface, the session runs on
/// [`socket::open`]'s, as in `motorgen commission`. It needs a virtual CAN interface,
/// which CI does not have (and the development machine's kernel has no vcan module):
/// ignored, with the reason in the test log; README ("On the bench over CAN") says how
/// to run it. Run without `MOTORGEN_VCAN`, it fails saying so.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "needs a SocketCAN interface: sudo ip link add dev vcan0 type vcan && sudo ip link set vcan0 up; then MOTORGEN_VCAN=vcan0 cargo test -p motor-commission --test it virtual_can_interface -- --ignored"]
fn step_over_a_virtual_can_interface() {
    use socketcan::{CanFrame, CanSocket, EmbeddedFrame, Frame as _, Socket, StandardId};
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};

    let iface = std::env::var("MOTORGEN_VCAN")
        .expect("MOTORGEN_VCAN names the virtual CAN interface to run on, e.g. MOTORGEN_VCAN=vcan0");
    let b = bench();
    let mut drive = b.drive();
    let board = CanSocket::open(&iface).unwrap();
    let done = Arc::new(AtomicBool::new(false));
    let stop = done.clone();
    let server = std::thread::spawn(move || {
        while !stop.load(Ordering::Relaxed) {
            if let Ok(CanFrame::Data(f)) = board.read_frame_timeout(Duration::from_micros(200)) {
                let frame = Frame {
                    id: f.raw_id() as u16,
                    len: f.data().len() as u8,
                    data: {
                        let mut d = [0; 8];
                        d[..f.data().len()].copy_from_slice(f.data());
                        d
                    },
                };
                drive.send(&frame).unwrap();
            }
            // The drive's next frame onto the bus.
            if let Some(f) = drive.receive(Duration::from_millis(10)).unwrap() {
                let id = StandardId::new(f.id as u16).unwrap();
                board.write_frame_insist(&CanFrame::new(id, &f.data).unwrap()).unwrap();
            }
        }
    });
    let mut o = b.options();
    o.iface = iface;
    let plan = b.plan(&o).unwrap();
    let result = socket::open(&o.iface, plan.bit_rate).and_then(|mut bus| plan.run(&mut bus));
    done.store(true, Ordering::Relaxed);
    server.join().unwrap();
    let (text, _) = b.identify(&result.unwrap());
    let r = value(&text, "phase_resistance", Kind::Resistance);
    assert!((r / b.r - 1.0).abs() < 0.02, "R = {r}, plant {}", b.r);
}
