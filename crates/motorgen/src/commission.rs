//! `motorgen commission SPEC --board B --can IFACE --out DIR <routine> …`: starts a
//! chapter-6 routine on the drive over CAN, receives its capture, writes the CSV
//! recording into DIR and identifies from it as `motorgen identify … --candump` does.
//!
//! The session ([`motor_commission::commission::run_session`]) records the received
//! frames as a `candump -l` log; from there the path is the candump path's
//! ([`crate::identify::captures_from_frames`], then `identify` with the captures), so a
//! live capture and a logged one are checked, written and identified by the same lines.
//! The bus is a SocketCAN socket on Linux ([`open`]); the tests put the firmware's
//! commissioning mode on the simulated motor in its place
//! (`motor_commission::sim_drive`).

use std::path::PathBuf;
use std::time::Duration;

use clap::{Args, Subcommand};
use codegen::units::{self, Kind};
use motor_commission::candump;
use motor_commission::commission::{FrameBus, SessionError, reason_text, run_session};
use motor_commission::writeback;
use motor_control::can_protocol::{Command, Layout, Routine};
use motor_control::commissioning_mode::{ModeConfig, capture_periods};

use crate::exit::{Exit, Failure};
use crate::identify::{AxisArg, Common, LoggedCapture, What};
use crate::output::outln;
use crate::{atomic, design_on};

/// `motorgen commission`'s options.
#[derive(Args)]
pub struct CommissionArgs {
    /// The motor spec (its scalings encode the command and decode the capture; the
    /// identified values are written into it).
    #[arg(value_name = "SPEC")]
    pub spec: PathBuf,
    /// The board file whose CAN identifiers the drive uses.
    #[arg(long, value_name = "BOARD_FILE")]
    pub board: PathBuf,
    /// The SocketCAN interface the drive is on, up at the board's bit rate (Linux).
    #[arg(long, value_name = "IFACE")]
    pub can: String,
    /// Directory for the CSV recording of the capture (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// How long to wait for the whole capture, e.g. "30 s".
    #[arg(long, default_value = "30 s", value_name = "TIME")]
    pub timeout: String,
    /// Control periods per captured sample (default: the smallest whose capture fits
    /// the drive's buffer).
    #[arg(long, value_name = "N")]
    pub decimation: Option<u16>,
    /// Print the change to the spec instead of writing it (the CSV is still written).
    #[arg(long)]
    pub dry_run: bool,
    /// Identification date written to `date` (YYYY-MM-DD; default: today, UTC).
    #[arg(long)]
    pub date: Option<String>,
    /// The routine.
    #[command(subcommand)]
    pub routine: RoutineArg,
}

/// The routines of thesis A chapter 6.
#[derive(Subcommand, Clone)]
pub enum RoutineArg {
    /// Blocked-rotor voltage step on one axis (§6.2): R and L of that axis.
    Step {
        /// The axis.
        #[arg(long, value_enum)]
        axis: AxisArg,
        /// Step voltage, e.g. "4 V".
        #[arg(long)]
        voltage: String,
        /// Current trip level, e.g. "10 A".
        #[arg(long)]
        trip: String,
    },
    /// ψ_M at zero current with the rotor driven at speed (§6.5).
    Flux,
    /// Resolver offset by α-axis alignment of a free rotor (§6.3).
    ResolverOffset {
        /// Alignment voltage on α, e.g. "3 V".
        #[arg(long)]
        voltage: String,
    },
    /// Pole-pair ratio and direction by a turning voltage vector (§6.4).
    PolePairRatio {
        /// Voltage of the turning vector, e.g. "3 V".
        #[arg(long)]
        voltage: String,
    },
}

/// A bad option value: bad input (exit 1), as `identify --date` is.
fn bad_option(option: &str, problem: String, accepted: &str) -> Failure {
    Failure::new(
        Exit::BadInput,
        format!("error: {option}: {problem}\n  accepted: {accepted}"),
    )
}

fn quantity(option: &str, kind: Kind, text: &str, accepted: &str) -> Result<f32, Failure> {
    units::parse(kind, text)
        .ok()
        .filter(|x| x.is_finite() && *x > 0.0)
        .map(|x| x as f32)
        .ok_or_else(|| bad_option(option, format!("`{text}` is not a positive value"), accepted))
}

/// The command frame's content for `routine`, decimation from `--decimation` or the
/// smallest that fits the capture into `capacity` samples.
fn command(a: &CommissionArgs, cfg: &ModeConfig, capacity: usize) -> Result<Command, Failure> {
    let volts = |v: &str| quantity("--voltage", Kind::Voltage, v, "a voltage, e.g. \"4 V\"");
    let (routine, axis_q, voltage, current_trip) = match &a.routine {
        RoutineArg::Step { axis, voltage, trip } => (
            Routine::Step,
            matches!(axis, AxisArg::Q),
            volts(voltage)?,
            quantity("--trip", Kind::Current, trip, "a current, e.g. \"10 A\"")?,
        ),
        RoutineArg::Flux => (Routine::Flux, false, 0.0, 0.0),
        RoutineArg::ResolverOffset { voltage } => (Routine::ResolverOffset, false, volts(voltage)?, 0.0),
        RoutineArg::PolePairRatio { voltage } => (Routine::PolePairRatio, false, volts(voltage)?, 0.0),
    };
    let periods = capture_periods(cfg, routine);
    let fitting = periods.div_ceil(capacity.max(1) as u64).max(1);
    let decimation = match a.decimation {
        Some(d) if d >= 1 && u64::from(d) >= fitting && d <= u16::from(u8::MAX) => d,
        Some(d) => {
            return Err(bad_option(
                "--decimation",
                format!(
                    "{d} does not fit: the routine runs {periods} periods and the drive captures {capacity} samples"
                ),
                &format!("an integer from {fitting} to 255"),
            ));
        }
        None if fitting <= u64::from(u8::MAX) => fitting as u16,
        None => {
            return Err(bad_option(
                "--decimation",
                format!("the routine's {periods} periods do not fit {capacity} samples at any decimation up to 255"),
                "a design whose commissioning routine is shorter",
            ));
        }
    };
    Ok(Command {
        routine: Some(routine),
        axis_q,
        voltage,
        current_trip,
        decimation,
    })
}

/// `t` \[s since the epoch\] as `YYYY-MM-DDTHHMMSS` (UTC), for file names.
fn stamp(t: f64) -> String {
    let secs = t.max(0.0) as u64;
    let day = writeback::date_from_unix_days((secs / 86_400) as i64);
    let s = secs % 86_400;
    format!("{day}T{:02}{:02}{:02}", s / 3600, s / 60 % 60, s % 60)
}

/// The failure of a session, with the exit code of its kind.
fn session_failure(e: SessionError, iface: &str, timeout: &str) -> Failure {
    match e {
        SessionError::Bus(m) => Failure::new(
            Exit::CanUnavailable,
            format!(
                "error: CAN interface `{iface}`: {m}\n  accepted: an interface that is up (`ip link show {iface}`)"
            ),
        ),
        SessionError::Refused(r) => Failure::new(
            Exit::Refused,
            format!(
                "error: the drive on `{iface}` refused the routine: {}\n  accepted: a drive at standstill (except the ψ_M run), with a zero torque setpoint, no fault and the break inactive, idle; nothing was written",
                reason_text(r)
            ),
        ),
        SessionError::Aborted => Failure::new(
            Exit::Refused,
            format!(
                "error: the drive on `{iface}` aborted the routine: {}; its outputs are off until an abort command (nothing was written)\n  accepted: a routine that runs to its end",
                reason_text(motor_control::can_protocol::Reason::Aborted)
            ),
        ),
        SessionError::Timeout {
            waited,
            last_status,
            capture_frames,
        } => {
            let status = match last_status {
                None => "no status frame from the drive (is it on the bus, at the board's bit rate?)".to_string(),
                Some((s, r)) => format!("the last status said {s:?} ({})", reason_text(r)),
            };
            Failure::new(
                Exit::Timeout,
                format!(
                    "error: no complete capture on `{iface}` within {:.1} s: {capture_frames} capture frames received, {status}; nothing was written\n  accepted: a capture that ends within --timeout (now {timeout})",
                    waited.as_secs_f64()
                ),
            )
        }
    }
}

/// Opens the SocketCAN interface `iface` (for a drive at `bit_rate` bit/s).
#[cfg(target_os = "linux")]
pub fn open(iface: &str, bit_rate: u32) -> Result<socket::LiveBus, Failure> {
    socket::LiveBus::open(iface).map_err(|e| {
        Failure::new(
            Exit::CanUnavailable,
            format!(
                "error: CAN interface `{iface}`: cannot open it: {e}\n  accepted: a SocketCAN interface that exists and is up at the board's bit rate, e.g. `sudo ip link set {iface} up type can bitrate {bit_rate}`"
            ),
        )
    })
}

/// `motorgen commission`.
pub fn run(a: &CommissionArgs) -> Result<(), Failure> {
    #[cfg(target_os = "linux")]
    {
        // Everything that does not need the bus is checked first.
        let plan = plan(a)?;
        let mut bus = open(&a.can, plan.bit_rate)?;
        run_planned(&mut bus, a, plan)
    }
    #[cfg(not(target_os = "linux"))]
    {
        plan(a)?;
        Err(Failure::new(
            Exit::CanUnavailable,
            format!(
                "error: --can {}: SocketCAN is Linux only\n  accepted: a Linux host; elsewhere log the bus with another tool and use `motorgen identify … --candump LOG`",
                a.can
            ),
        ))
    }
}

/// What `run` checks before touching the bus.
pub struct Plan {
    layout: Layout,
    bit_rate: u32,
    command: Command,
    timeout: Duration,
}

fn plan(a: &CommissionArgs) -> Result<Plan, Failure> {
    atomic::check_out_dir(&a.out).map_err(|e| Failure::new(Exit::BadInput, e))?;
    if let Some(d) = &a.date {
        writeback::parse_date(d).map_err(|e| bad_option("--date", e, "a date YYYY-MM-DD, e.g. --date 2025-03-14"))?;
    }
    let d = design_on(&a.spec, Some(&a.board))?;
    let Some((cfg, capacity)) = candump::mode_config(&d) else {
        return Err(bad_option(
            &a.board.display().to_string(),
            "the design has no CAN interface".into(),
            "a board file with a [can] section",
        ));
    };
    let timeout = units::parse(Kind::Time, &a.timeout)
        .ok()
        .filter(|t| *t > 0.0 && *t <= 3600.0)
        .ok_or_else(|| {
            bad_option(
                "--timeout",
                format!("`{}` is not a time up to an hour", a.timeout),
                "a time, e.g. \"30 s\"",
            )
        })?;
    let bit_rate = d.board.as_ref().map_or(0, |b| b.board.can_bit_rate.round() as u32);
    Ok(Plan {
        layout: cfg.layout,
        bit_rate,
        command: command(a, &cfg, capacity)?,
        timeout: Duration::from_secs_f64(timeout),
    })
}

/// `motorgen commission` on `bus` (the tests' simulated drive).
#[cfg(test)]
pub fn run_on<B: FrameBus>(bus: &mut B, a: &CommissionArgs) -> Result<(), Failure> {
    let plan = plan(a)?;
    run_planned(bus, a, plan)
}

fn run_planned<B: FrameBus>(bus: &mut B, a: &CommissionArgs, plan: Plan) -> Result<(), Failure> {
    let Plan {
        layout,
        command,
        timeout,
        ..
    } = plan;
    let rec =
        run_session(bus, &a.can, &layout, &command, timeout).map_err(|e| session_failure(e, &a.can, &a.timeout))?;
    // From here on, the candump path.
    let name = format!("{} (live)", a.can);
    let captures: Vec<LoggedCapture> = crate::identify::captures_from_frames(&name, rec.text, &rec.frames, &layout)?;
    let spec_stem = a
        .spec
        .file_stem()
        .map_or_else(|| "motor".into(), |s| s.to_string_lossy().into_owned());
    let header_time = |c: &candump::Capture| {
        rec.frames
            .iter()
            .position(|f| f.offset == c.header_offset)
            .map_or(0.0, |k| rec.times[k])
    };
    let files: Vec<(PathBuf, Vec<u8>)> = captures
        .iter()
        .map(|(_, _, c, csv)| {
            let kind = candump::kind_of(c.header.routine).name();
            let axis = match (c.header.routine, c.header.axis_q) {
                (Routine::Step, true) => "-q",
                (Routine::Step, false) => "-d",
                _ => "",
            };
            let file = format!("{spec_stem}-{kind}{axis}-{}.csv", stamp(header_time(c)));
            (a.out.join(file), csv.clone().into_bytes())
        })
        .collect();
    let written = atomic::write_set(&a.out, &files)?;
    for ((path, _), w) in files.iter().zip(written) {
        outln!("{} {}", if w { "wrote" } else { "unchanged" }, path.display());
    }
    let common = Common::live(a.dry_run, a.date.clone(), a.board.clone(), captures);
    let spec = a.spec.clone();
    let what = match &a.routine {
        RoutineArg::Step { axis, .. } => What::Step {
            spec,
            axis: *axis,
            csv: Vec::new(),
            common,
        },
        RoutineArg::Flux => What::Flux {
            spec,
            csv: Vec::new(),
            common,
        },
        RoutineArg::ResolverOffset { .. } | RoutineArg::PolePairRatio { .. } => What::Resolver {
            spec,
            offset: Vec::new(),
            ratio: Vec::new(),
            common,
        },
    };
    crate::identify::run(what)
}

/// The SocketCAN bus (Linux): a raw CAN socket bound to one interface.
#[cfg(target_os = "linux")]
pub mod socket {
    use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

    use motor_commission::commission::{BusFrame, FrameBus};
    use motor_control::can_protocol::Frame;
    use socketcan::{CanFrame, CanSocket, EmbeddedFrame, Frame as _, Socket, StandardId};

    /// A raw CAN socket on one interface.
    pub struct LiveBus {
        socket: CanSocket,
        start: Instant,
    }

    impl LiveBus {
        /// Opens and binds the socket.
        pub fn open(iface: &str) -> std::io::Result<Self> {
            Ok(LiveBus {
                socket: CanSocket::open(iface)?,
                start: Instant::now(),
            })
        }
    }

    impl FrameBus for LiveBus {
        fn send(&mut self, f: &Frame) -> Result<(), String> {
            let id = StandardId::new(f.id).ok_or_else(|| format!("identifier {:#x} is not 11 bits", f.id))?;
            let frame = CanFrame::new(id, f.bytes()).ok_or("a frame of more than 8 bytes")?;
            self.socket
                .write_frame_insist(&frame)
                .map_err(|e| format!("cannot send: {e}"))
        }

        fn receive(&mut self, timeout: Duration) -> Result<Option<BusFrame>, String> {
            let deadline = Instant::now() + timeout;
            loop {
                let left = deadline.saturating_duration_since(Instant::now());
                if left.is_zero() {
                    return Ok(None);
                }
                match self.socket.read_frame_timeout(left) {
                    Ok(CanFrame::Data(d)) => {
                        return Ok(Some(BusFrame {
                            id: d.raw_id(),
                            extended: d.is_extended(),
                            data: d.data().to_vec(),
                        }));
                    }
                    // Remote and error frames: the drive sends neither.
                    Ok(_) => {}
                    Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {
                        return Ok(None);
                    }
                    Err(e) => return Err(format!("cannot receive: {e}")),
                }
            }
        }

        fn elapsed(&self) -> Duration {
            self.start.elapsed()
        }

        fn timestamp(&self) -> f64 {
            SystemTime::now()
                .duration_since(UNIX_EPOCH)
                .map_or(0.0, |d| d.as_secs_f64())
        }
    }
}

#[cfg(test)]
mod tests {
    //! The whole command on the simulated drive (`motor_commission::sim_drive`: the
    //! firmware's commissioning mode and CAN encoder on the motor simulation of
    //! `verify`) in place of the socket: the same session, candump path, CSV and
    //! identification as on a bench.

    use std::path::Path;
    use std::time::Duration;

    use motor_commission::commission::{BusFrame, FrameBus};
    use motor_commission::sim_drive::SimulatedDrive;
    use motor_control::can_protocol::Frame;

    use super::*;

    const BOARD: &str = "boards/motorgen-reference.toml";

    fn repo() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
    }

    /// The Fischer spec copied into a fresh directory, its design on the reference
    /// board, and the plant's R and L_d.
    struct Bench {
        dir: tempfile::TempDir,
        spec: PathBuf,
        design: codegen::Design,
        r: f64,
        ld: f64,
        i_max: f64,
    }

    fn bench() -> Bench {
        let dir = tempfile::tempdir().unwrap();
        let spec = dir.path().join("fischer-ti085.toml");
        std::fs::copy(repo().join("motors/fischer-ti085.toml"), &spec).unwrap();
        let text = std::fs::read_to_string(&spec).unwrap();
        let board = std::fs::read_to_string(repo().join(BOARD)).unwrap();
        let design = codegen::design_with_board("fischer.toml", &text, BOARD, &board).unwrap();
        let d = &design;
        Bench {
            r: d.motor.phase_resistance_ohm,
            ld: d.motor.d_inductance_h,
            i_max: d.motor.peak_current_a.min(d.scaling.phase_current.full_scale),
            design: design.clone(),
            spec,
            dir,
        }
    }

    impl Bench {
        /// The drive on the simulated motor at standstill.
        fn drive(&self) -> SimulatedDrive {
            let text = std::fs::read_to_string(&self.spec).unwrap();
            let spec = codegen::spec::parse(codegen::Source {
                file: "fischer.toml",
                text: &text,
            })
            .unwrap();
            let setup = motor_verify::Setup::new(&spec, &self.design);
            SimulatedDrive::new(&self.design, setup.bench(0.0), 0.0).unwrap()
        }

        /// A d-axis step to 30 % of the current limit, tripping at 80 %.
        fn args(&self, dry_run: bool) -> CommissionArgs {
            CommissionArgs {
                spec: self.spec.clone(),
                board: repo().join(BOARD),
                can: "sim0".into(),
                out: self.dir.path().join("out"),
                timeout: "60 s".into(),
                decimation: None,
                dry_run,
                date: Some("2025-03-14".into()),
                routine: RoutineArg::Step {
                    axis: AxisArg::D,
                    voltage: format!("{} V", 0.3 * self.i_max * self.r),
                    trip: format!("{} A", 0.8 * self.i_max),
                },
            }
        }

        fn spec_text(&self) -> String {
            std::fs::read_to_string(&self.spec).unwrap()
        }

        fn outputs(&self) -> Vec<PathBuf> {
            match std::fs::read_dir(self.dir.path().join("out")) {
                Ok(d) => d.map(|e| e.unwrap().path()).collect(),
                Err(_) => Vec::new(),
            }
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

    /// A d step over the simulated bus: one command sent, the CSV written, R and L_d
    /// within 2 % of the plant's (the accuracy the identify tests state) in the spec.
    #[test]
    fn step_over_the_simulated_bus_identifies_r_and_ld() {
        let b = bench();
        let mut drive = b.drive();
        run_on(&mut drive, &b.args(false)).unwrap();
        assert_eq!(drive.commands, 1);
        let out = b.outputs();
        assert_eq!(out.len(), 1, "{out:?}");
        let name = out[0].file_name().unwrap().to_string_lossy().into_owned();
        // Period 0 of the simulation is 1.7e9 s = 2023-11-14 22:13:20 UTC.
        assert!(name.starts_with("fischer-ti085-step-d-2023-11-14T2213"), "{name}");
        let csv = std::fs::read_to_string(&out[0]).unwrap();
        assert!(csv.starts_with("# motorgen recording: step\n"), "{csv}");
        let text = b.spec_text();
        let r = value(&text, "phase_resistance", Kind::Resistance);
        let ld = value(&text, "d_inductance", Kind::Inductance);
        assert!((r / b.r - 1.0).abs() < 0.02, "R = {r}, plant {}", b.r);
        assert!((ld / b.ld - 1.0).abs() < 0.02, "L_d = {ld}, plant {}", b.ld);
        assert!(text.contains("sim0 (live)"), "{text}");
    }

    /// `--dry-run`: the CSV is written, the spec is not.
    #[test]
    fn dry_run_leaves_the_spec() {
        let b = bench();
        let before = b.spec_text();
        run_on(&mut b.drive(), &b.args(true)).unwrap();
        assert_eq!(b.spec_text(), before);
        assert_eq!(b.outputs().len(), 1);
    }

    /// A torque setpoint: the drive refuses (status reason 2) → exit 6 with the reason,
    /// nothing written.
    #[test]
    fn refusal_names_the_reason() {
        let b = bench();
        let before = b.spec_text();
        let mut drive = b.drive();
        drive.guards.torque_setpoint = 1.0;
        let e = run_on(&mut drive, &b.args(false)).unwrap_err();
        assert_eq!(e.exit, Exit::Refused, "{}", e.message);
        assert!(e.message.contains("the torque setpoint is not zero"), "{}", e.message);
        assert_eq!(b.spec_text(), before);
        assert!(b.outputs().is_empty());
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

    /// The break during the step: the drive aborts (status fault, reason aborted) →
    /// exit 6, nothing written.
    #[test]
    fn break_during_the_routine_is_an_abort() {
        let b = bench();
        let before = b.spec_text();
        let mut bus = Breaking {
            drive: b.drive(),
            after: 4,
        };
        let e = run_on(&mut bus, &b.args(false)).unwrap_err();
        assert_eq!(e.exit, Exit::Refused, "{}", e.message);
        assert!(e.message.contains("aborted"), "{}", e.message);
        assert_eq!(b.spec_text(), before);
        assert!(b.outputs().is_empty());
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

    /// No drive on the bus: exit 75 after the timeout, saying no status came.
    #[test]
    fn silence_is_a_timeout() {
        let b = bench();
        let mut a = b.args(false);
        a.timeout = "2 s".into();
        let e = run_on(&mut Silent(Duration::ZERO), &a).unwrap_err();
        assert_eq!(e.exit, Exit::Timeout, "{}", e.message);
        assert!(
            e.message.contains("within 2.0 s") && e.message.contains("no status frame"),
            "{}",
            e.message
        );
        assert!(b.outputs().is_empty());
    }

    /// An interface that does not exist: exit 69 naming it, nothing written.
    #[test]
    fn missing_interface_is_unavailable() {
        let b = bench();
        let mut a = b.args(false);
        a.can = "mgnone0".into();
        let e = run(&a).unwrap_err();
        assert_eq!(e.exit, Exit::CanUnavailable, "{}", e.message);
        assert!(e.message.contains("`mgnone0`"), "{}", e.message);
        assert!(b.outputs().is_empty());
    }

    /// Bad options are refused before the bus is touched: a trip that is no current, a
    /// decimation whose capture does not fit.
    #[test]
    fn bad_options_are_bad_input() {
        let b = bench();
        let mut a = b.args(false);
        a.routine = RoutineArg::Step {
            axis: AxisArg::Q,
            voltage: "2 V".into(),
            trip: "10 V".into(),
        };
        let e = run_on(&mut Silent(Duration::ZERO), &a).unwrap_err();
        assert_eq!(e.exit, Exit::BadInput, "{}", e.message);
        assert!(e.message.contains("--trip"), "{}", e.message);
        let mut a = b.args(false);
        a.decimation = Some(0);
        let e = run_on(&mut Silent(Duration::ZERO), &a).unwrap_err();
        assert!(e.message.contains("--decimation"), "{}", e.message);
    }

    /// On a real (virtual) CAN interface named by `MOTORGEN_VCAN` (e.g. `vcan0`, made
    /// with `ip link add dev vcan0 type vcan && ip link set vcan0 up`): the simulated
    /// drive answers on a second socket of the interface, `motorgen commission` runs
    /// against the first. Without the variable the test returns at once (this
    /// machine's kernel has no vcan module).
    #[cfg(target_os = "linux")]
    #[test]
    fn step_over_a_virtual_can_interface() {
        use socketcan::{CanFrame, CanSocket, EmbeddedFrame, Frame as _, Socket, StandardId};
        use std::sync::Arc;
        use std::sync::atomic::{AtomicBool, Ordering};

        let Ok(iface) = std::env::var("MOTORGEN_VCAN") else {
            eprintln!("MOTORGEN_VCAN not set: the live interface test does not run");
            return;
        };
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
        let mut a = b.args(false);
        a.can = iface;
        let result = run(&a);
        done.store(true, Ordering::Relaxed);
        server.join().unwrap();
        result.unwrap();
        let r = value(&b.spec_text(), "phase_resistance", Kind::Resistance);
        assert!((r / b.r - 1.0).abs() < 0.02, "R = {r}, plant {}", b.r);
    }
}
