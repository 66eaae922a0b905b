//! A commissioning session on a live bus: send the command frame, watch the drive's
//! status frames, and record every frame until the capture's end frame.
//!
//! The bus is a [`FrameBus`] (a SocketCAN socket in `motorgen commission`, a simulated
//! drive in the tests). Every received frame is written as a `candump -l` line into a
//! [`Recorder`] and kept as the [`LoggedFrame`] `candump::parse_log` would read from
//! that line, so the captures are then reassembled, checked, written as CSV and
//! identified by exactly the functions that read a `candump -l` file
//! ([`super::candump::captures`] and on): the socket read is the only difference.

use std::time::Duration;

use motor_control::can_protocol::{self as p, Command, Frame, Layout, Reason, State};

use super::candump::{LoggedFrame, frame_line};

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

/// The text of a refusal or abort reason, as the firmware means it
/// (`motor_control::can_protocol::Reason`).
pub fn reason_text(r: Reason) -> &'static str {
    match r {
        Reason::None => "no reason",
        Reason::NotAtStandstill => "the rotor is turning (|ω_e| above the standstill threshold)",
        Reason::TorqueNotZero => "the torque setpoint is not zero",
        Reason::FaultActive => "a fault or the break is active",
        Reason::BadCommand => {
            "the command is out of range (routine, voltage, trip, or a decimation whose capture does not fit the buffer)"
        }
        Reason::Busy => "a routine or capture is already in progress",
        Reason::Aborted => "aborted: a fault, the break or a setpoint timeout switched the outputs off",
        Reason::Tripped => "the routine's current trip fired",
    }
}

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
