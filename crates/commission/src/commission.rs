//! A commissioning session on a bus: the options checked into a command ([`plan`]),
//! the session itself (send the command frame, watch the drive's status frames, record
//! every frame until the capture's end frame: [`run_session`]), and what comes of it
//! ([`Plan::run`]: the captures' CSV recordings and the identification from them).
//!
//! The bus is a [`FrameBus`] (a SocketCAN socket, [`crate::socket`], in `motorgen
//! commission`; the simulated drive, [`crate::sim_drive`], in the tests). Every received
//! frame is written as a `candump -l` line into a [`Recorder`] and kept as the
//! [`LoggedFrame`] `candump::parse_log` would read from that line, so the captures are
//! then reassembled, checked, written as CSV and identified by exactly the functions
//! that read a `candump -l` file ([`super::candump::captures`],
//! [`super::identify::captures_from_frames`] and on): the socket read is the only
//! difference.
//!
//! Failures have their own [`Error`] variants: bad options and a board without CAN are
//! [`Error::Option`] (checked before the bus is touched), the bus
//! [`Error::BusUnavailable`], the drive's refusal [`Error::Refused`], its abort
//! [`Error::Aborted`], no capture in time [`Error::Timeout`].

use std::path::Path;
use std::time::Duration;

use codegen::units::{self, Kind};
use motor_control::can_protocol::{self as p, Command, Frame, Layout, Reason, Routine, State};
use motor_control::commissioning::Axis;
use motor_control::commissioning_mode::{ModeConfig, capture_periods};

use super::candump::{self, LoggedFrame, frame_line};
use super::error::{Error, Problem};
use super::identify::{self, Input, LoggedCapture, Request, What};
use super::writeback;

/// A frame as it came off the bus.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BusFrame {
    /// Identifier (11 or 29 bits).
    pub id: u32,
    /// Extended (29-bit) identifier.
    pub extended: bool,
    /// Data bytes (0–8).
    pub data: Vec<u8>,
}

/// Sends and receives classic CAN frames.
pub trait FrameBus {
    /// Sends `frame`; `Err` with the system's message.
    fn send(&mut self, frame: &Frame) -> Result<(), String>;
    /// The next frame within `timeout`, `Ok(None)` if none came; `Err` with the system's
    /// message.
    fn receive(&mut self, timeout: Duration) -> Result<Option<BusFrame>, String>;
    /// Time since the bus was opened (the simulated time for a simulated drive).
    fn elapsed(&self) -> Duration;
    /// The frame's receive time stamp \[s since the epoch\] for the log.
    fn timestamp(&self) -> f64;
}

/// The received frames as a `candump -l` log and as the frames read from it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Recorder {
    /// Interface name written on each line.
    pub iface: String,
    /// The log text.
    pub text: String,
    /// The frames, each with its line's offset in `text`.
    pub frames: Vec<LoggedFrame>,
    /// Each frame's receive time \[s since the epoch\].
    pub times: Vec<f64>,
}

impl Recorder {
    /// An empty log of `iface`.
    pub fn new(iface: &str) -> Self {
        Recorder {
            iface: iface.to_string(),
            ..Recorder::default()
        }
    }

    /// Appends `f` received at `t` \[s\].
    pub fn push(&mut self, t: f64, f: BusFrame) {
        let offset = self.text.len();
        self.text
            .push_str(&frame_line(t, &self.iface, f.id, f.extended, &f.data));
        self.text.push('\n');
        self.times.push(t);
        self.frames.push(LoggedFrame {
            offset,
            id: f.id,
            extended: f.extended,
            data: f.data,
        });
    }
}

/// Why a session ended without a capture.
#[derive(Debug, Clone, PartialEq)]
pub enum SessionError {
    /// The bus failed (sending or receiving).
    Bus(String),
    /// The drive refused the command (its status frame's reason).
    Refused(Reason),
    /// The drive aborted the routine (a fault, break or setpoint timeout): outputs off.
    Aborted,
    /// No end frame within the timeout.
    Timeout {
        /// How long the session waited.
        waited: Duration,
        /// The last status received (state, reason), if any.
        last_status: Option<(State, Reason)>,
        /// Capture frames (header, data, end) received.
        capture_frames: usize,
    },
}

pub use super::error::reason_text;

/// State and reason of a status frame on `layout`, `None` for any other frame.
pub fn decode_status(layout: &Layout, f: &BusFrame) -> Option<(State, Reason)> {
    let id = u16::try_from(f.id).ok().filter(|_| !f.extended)?;
    p::decode_status(layout, id, &f.data).map(|(s, r, ..)| (s, r))
}

/// Sends `cmd` and records the bus until the capture's end frame, for at most
/// `timeout`.
///
/// The drive answers a command in its next status frames: a state of commissioning or
/// streaming means it runs; idle or fault with a refusal reason, seen in two status
/// frames in a row after the command (the first may have been sent before the drive
/// read it), is a refusal; fault with [`Reason::Aborted`] after the routine started is
/// an abort.
pub fn run_session<B: FrameBus>(
    bus: &mut B,
    iface: &str,
    layout: &Layout,
    cmd: &Command,
    timeout: Duration,
) -> Result<Recorder, SessionError> {
    let mut rec = Recorder::new(iface);
    let start = bus.elapsed();
    bus.send(&p::encode_command(layout, cmd)).map_err(SessionError::Bus)?;
    let mut started = false;
    let mut refusals = 0;
    let mut header_seen = false;
    let mut capture_frames = 0;
    let mut last_status = None;
    loop {
        let timed_out = |bus: &B| SessionError::Timeout {
            waited: bus.elapsed().saturating_sub(start),
            last_status,
            capture_frames,
        };
        let waited = bus.elapsed().saturating_sub(start);
        let Some(left) = timeout.checked_sub(waited).filter(|d| !d.is_zero()) else {
            return Err(timed_out(bus));
        };
        let Some(f) = bus.receive(left).map_err(SessionError::Bus)? else {
            return Err(timed_out(bus));
        };
        let t = bus.timestamp();
        let ours = |id: u16| !f.extended && f.id == u32::from(id);
        let is_header = ours(layout.header_id);
        let is_end = ours(layout.end_id) && header_seen;
        if is_header || ours(layout.data_id) || ours(layout.end_id) {
            capture_frames += 1;
        }
        header_seen |= is_header;
        if let Some((state, reason)) = decode_status(layout, &f) {
            last_status = Some((state, reason));
            match state {
                State::Commissioning | State::Streaming => {
                    started = true;
                    refusals = 0;
                }
                State::Fault if started && reason == Reason::Aborted => return Err(SessionError::Aborted),
                State::Idle | State::Fault
                    if !started && !header_seen && !matches!(reason, Reason::None | Reason::Tripped) =>
                {
                    refusals += 1;
                    if refusals >= 2 {
                        return Err(SessionError::Refused(reason));
                    }
                }
                _ => {}
            }
        }
        rec.push(t, f);
        if is_end {
            return Ok(rec);
        }
    }
}

/// A commissioning session's options, as the user gave them (`motorgen commission`).
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// The interface's name (in messages, and the live log's `IFACE (live)`).
    pub iface: String,
    /// How long to wait for the whole capture, e.g. `30 s` (at most an hour).
    pub timeout: String,
    /// Control periods per captured sample (`None`: the smallest whose capture fits the
    /// drive's buffer).
    pub decimation: Option<u16>,
    /// The identification date written to `date` (YYYY-MM-DD; `None`: today).
    pub date: Option<String>,
    /// The routine and its parameters.
    pub routine: RoutineOptions,
}

/// The routines of thesis A chapter 6 and their parameters as given (quantities with
/// their unit, e.g. `4 V`).
#[derive(Debug, Clone, PartialEq)]
pub enum RoutineOptions {
    /// Blocked-rotor voltage step on one axis (§6.2): R and L of that axis.
    Step {
        /// The axis.
        axis: Axis,
        /// Step voltage, e.g. `4 V`.
        voltage: String,
        /// Current trip level, e.g. `10 A`.
        trip: String,
    },
    /// ψ_M at zero current with the rotor driven at speed (§6.5).
    Flux,
    /// Resolver offset by α-axis alignment of a free rotor (§6.3).
    ResolverOffset {
        /// Alignment voltage on α, e.g. `3 V`.
        voltage: String,
    },
    /// Pole-pair ratio and direction by a turning voltage vector (§6.4).
    PolePairRatio {
        /// Voltage of the turning vector, e.g. `3 V`.
        voltage: String,
    },
}

/// A session checked before the bus is touched: the command to send and everything the
/// captures need afterwards.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The CAN interface of the design on the board.
    pub layout: Layout,
    /// The board's CAN bit rate \[bit/s\] (for the message when the interface cannot be
    /// opened).
    pub bit_rate: u32,
    /// The command frame's content.
    pub command: Command,
    /// How long the whole session may take.
    pub timeout: Duration,
    options: Options,
    /// The spec's file stem, for the CSV files' names.
    spec_stem: String,
    /// The board file, for the identification from the captures.
    board: Input,
}

/// What a session brought: the captures' CSV recordings to write, and the
/// identification from them.
#[derive(Debug, Clone, PartialEq)]
pub struct Captured {
    /// (file name, CSV recording) of each capture: `SPECSTEM-ROUTINE[-AXIS]-TIME.csv`,
    /// TIME the UTC time stamp of the capture's header frame (`YYYY-MM-DDTHHMMSS`).
    pub files: Vec<(String, String)>,
    /// The identification from the captures, as `identify … --candump` would run it on
    /// a log of them ([`Request::check`], then [`Request::identify`] on the spec).
    pub request: Request,
}

/// A bad option value: bad input, as `identify --date` is.
fn bad_option(option: &str, problem: String, accepted: &str) -> Error {
    Error::Option(Problem::new(option, problem, accepted))
}

fn quantity(option: &str, kind: Kind, text: &str, accepted: &str) -> Result<f32, Error> {
    units::parse(kind, text)
        .ok()
        .filter(|x| x.is_finite() && *x > 0.0)
        .map(|x| x as f32)
        .ok_or_else(|| bad_option(option, format!("`{text}` is not a positive value"), accepted))
}

/// The command frame's content for the routine of `o`, the decimation from
/// `o.decimation` or the smallest that fits the capture into `capacity` samples.
pub fn command(o: &Options, cfg: &ModeConfig, capacity: usize) -> Result<Command, Error> {
    let volts = |v: &str| quantity("--voltage", Kind::Voltage, v, "a voltage, e.g. \"4 V\"");
    let (routine, axis_q, voltage, current_trip) = match &o.routine {
        RoutineOptions::Step { axis, voltage, trip } => (
            Routine::Step,
            matches!(axis, Axis::Q),
            volts(voltage)?,
            quantity("--trip", Kind::Current, trip, "a current, e.g. \"10 A\"")?,
        ),
        RoutineOptions::Flux => (Routine::Flux, false, 0.0, 0.0),
        RoutineOptions::ResolverOffset { voltage } => (Routine::ResolverOffset, false, volts(voltage)?, 0.0),
        RoutineOptions::PolePairRatio { voltage } => (Routine::PolePairRatio, false, volts(voltage)?, 0.0),
    };
    let periods = capture_periods(cfg, routine);
    let fitting = periods.div_ceil(capacity.max(1) as u64).max(1);
    let decimation = match o.decimation {
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

/// Checks everything that does not need the bus, in this order: `--date`, the spec and
/// the board (read, designed together, with a CAN interface), `--timeout`, the routine's
/// quantities and the decimation.
pub fn plan(options: &Options, spec: &Input, board: &Input) -> Result<Plan, Error> {
    if let Some(d) = &options.date {
        writeback::parse_date(d).map_err(|e| bad_option("--date", e, "a date YYYY-MM-DD, e.g. --date 2025-03-14"))?;
    }
    let spec_text = spec.text()?;
    let board_text = board.text()?;
    let d = codegen::design_with_board(&spec.name, spec_text, &board.name, board_text)?;
    let Some((cfg, capacity)) = candump::mode_config(&d) else {
        return Err(bad_option(
            &board.name,
            "the design has no CAN interface".into(),
            "a board file with a [can] section",
        ));
    };
    let timeout = units::parse(Kind::Time, &options.timeout)
        .ok()
        .filter(|t| *t > 0.0 && *t <= 3600.0)
        .ok_or_else(|| {
            bad_option(
                "--timeout",
                format!("`{}` is not a time up to an hour", options.timeout),
                "a time, e.g. \"30 s\"",
            )
        })?;
    let bit_rate = d.board.as_ref().map_or(0, |b| b.board.can_bit_rate.round() as u32);
    let spec_stem = Path::new(&spec.name)
        .file_stem()
        .map_or_else(|| "motor".into(), |s| s.to_string_lossy().into_owned());
    Ok(Plan {
        layout: cfg.layout,
        bit_rate,
        command: command(options, &cfg, capacity)?,
        timeout: Duration::from_secs_f64(timeout),
        options: options.clone(),
        spec_stem,
        board: board.clone(),
    })
}

/// `t` \[s since the epoch\] as `YYYY-MM-DDTHHMMSS` (UTC), for file names.
pub fn stamp(t: f64) -> String {
    let secs = t.max(0.0) as u64;
    let day = writeback::date_from_unix_days((secs / 86_400) as i64);
    let s = secs % 86_400;
    format!("{day}T{:02}{:02}{:02}", s / 3600, s / 60 % 60, s % 60)
}

/// The failure of a session on `iface`, with the timeout as the user gave it.
pub fn session_error(e: SessionError, iface: &str, timeout: &str) -> Error {
    let iface = iface.to_string();
    match e {
        SessionError::Bus(m) => Error::BusUnavailable(Problem::new(
            format!("CAN interface `{iface}`"),
            m,
            format!("an interface that is up (`ip link show {iface}`)"),
        )),
        SessionError::Refused(reason) => Error::Refused { iface, reason },
        SessionError::Aborted => Error::Aborted { iface },
        SessionError::Timeout {
            waited,
            last_status,
            capture_frames,
        } => Error::Timeout {
            iface,
            waited,
            last_status,
            capture_frames,
            limit: timeout.to_string(),
        },
    }
}

impl Plan {
    /// Runs the session on `bus` and checks the captures received as a log's; their
    /// CSV files and the identification from them. Nothing of a failed session is
    /// returned (nothing is to be written).
    pub fn run<B: FrameBus>(&self, bus: &mut B) -> Result<Captured, Error> {
        let o = &self.options;
        let rec = run_session(bus, &o.iface, &self.layout, &self.command, self.timeout)
            .map_err(|e| session_error(e, &o.iface, &o.timeout))?;
        // From here on, the candump path.
        let name = format!("{} (live)", o.iface);
        let captures: Vec<LoggedCapture> = identify::captures_from_frames(&name, rec.text, &rec.frames, &self.layout)?;
        let header_time = |c: &candump::Capture| {
            rec.frames
                .iter()
                .position(|f| f.offset == c.header_offset)
                .map_or(0.0, |k| rec.times[k])
        };
        let files = captures
            .iter()
            .map(|c| {
                let h = &c.capture.header;
                let kind = candump::kind_of(h.routine).name();
                let axis = match (h.routine, h.axis_q) {
                    (Routine::Step, true) => "-q",
                    (Routine::Step, false) => "-d",
                    _ => "",
                };
                let file = format!("{}-{kind}{axis}-{}.csv", self.spec_stem, stamp(header_time(&c.capture)));
                (file, c.csv.clone())
            })
            .collect();
        let what = match &o.routine {
            RoutineOptions::Step { axis, .. } => What::Step {
                axis: *axis,
                csv: Vec::new(),
            },
            RoutineOptions::Flux => What::Flux { csv: Vec::new() },
            RoutineOptions::ResolverOffset { .. } | RoutineOptions::PolePairRatio { .. } => What::Resolver {
                offset: Vec::new(),
                ratio: Vec::new(),
            },
        };
        Ok(Captured {
            files,
            request: Request {
                what,
                date: o.date.clone(),
                sample_period: None,
                logs: Vec::new(),
                board: Some(self.board.clone()),
                live: captures,
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::candump::parse_log;
    use super::*;

    /// The recorder's frames are exactly what `parse_log` reads back from its text,
    /// extended and empty frames included.
    #[test]
    fn recorder_matches_the_log_reader() {
        let mut r = Recorder::new("can0");
        let frames = [
            BusFrame {
                id: 0x104,
                extended: false,
                data: vec![1, 0, 0, 0x20, 0x03, 0x6A, 0xFF],
            },
            BusFrame {
                id: 0x18FF_0001,
                extended: true,
                data: vec![],
            },
            BusFrame {
                id: 0x7FF,
                extended: false,
                data: vec![0xFF; 8],
            },
        ];
        for (k, f) in frames.iter().enumerate() {
            r.push(1.7e9 + k as f64 * 1e-3, f.clone());
        }
        assert_eq!(parse_log("can0", &r.text).unwrap(), r.frames);
        assert!(r.text.starts_with("(1700000000.000000) can0 104#0100002003"));
    }
}
