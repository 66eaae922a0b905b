//! Why an identification or a commissioning session failed: one variant per kind of
//! failure, so that a front end can give each its own exit code (`motorgen`: bad input
//! 1, unreadable input 74, bus unavailable 69, refused or aborted 6, timeout 75), and
//! one `Display` with the message it prints.

use std::fmt;
use std::time::Duration;

use codegen::Diagnostics;
use motor_control::can_protocol::{Reason, State};

/// A problem with a named thing that is not a place in a file (an option, an
/// interface): `error: <subject>: <problem>` and what would be accepted.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// What is wrong, e.g. `--trip` or ``CAN interface `can0` ``.
    pub subject: String,
    /// Why.
    pub problem: String,
    /// What would be accepted instead.
    pub accepted: String,
}

impl Problem {
    /// `subject`: `problem`, accepted: `accepted`.
    pub fn new(subject: impl Into<String>, problem: impl Into<String>, accepted: impl Into<String>) -> Self {
        Problem {
            subject: subject.into(),
            problem: problem.into(),
            accepted: accepted.into(),
        }
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "error: {}: {}\n  accepted: {}",
            self.subject, self.problem, self.accepted
        )
    }
}

/// Why an identification or a session ended without a result.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// Bad input: located problems of a spec, board file, recording, log or option
    /// (every problem found, not only the first).
    Input(Diagnostics),
    /// A bad option of a commissioning session (`--voltage`, `--trip`, `--decimation`,
    /// `--timeout`, `--date`) or a board without a CAN interface: bad input that is not
    /// a place in a file.
    Option(Problem),
    /// An input could not be read (the front end says why in [`crate::Input`]),
    /// together with the problems of the other inputs read with it.
    Unreadable(Diagnostics),
    /// The CAN interface cannot be opened (no such interface, not up, not Linux) or
    /// failed while in use.
    BusUnavailable(Problem),
    /// The drive refused the command: its status frame's reason.
    Refused {
        /// The interface's name.
        iface: String,
        /// The reason in the drive's status frame.
        reason: Reason,
    },
    /// The drive aborted the routine (a fault, the break or a setpoint timeout): its
    /// outputs are off.
    Aborted {
        /// The interface's name.
        iface: String,
    },
    /// No complete capture within the session's timeout.
    Timeout {
        /// The interface's name.
        iface: String,
        /// How long the session waited.
        waited: Duration,
        /// The last status received (state, reason), if any.
        last_status: Option<(State, Reason)>,
        /// Capture frames (header, data, end) received.
        capture_frames: usize,
        /// The timeout as the user gave it, e.g. `30 s`.
        limit: String,
    },
}

impl From<Diagnostics> for Error {
    fn from(d: Diagnostics) -> Self {
        Error::Input(d)
    }
}

impl From<codegen::Diagnostic> for Error {
    fn from(d: codegen::Diagnostic) -> Self {
        Error::Input(d.into())
    }
}

impl std::error::Error for Error {}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Input(d) | Error::Unreadable(d) => write!(f, "{d}"),
            Error::Option(p) | Error::BusUnavailable(p) => write!(f, "{p}"),
            Error::Refused { iface, reason } => write!(
                f,
                "error: the drive on `{iface}` refused the routine: {}\n  accepted: a drive at standstill (except the ψ_M run), with a zero torque setpoint, no fault and the break inactive, idle; nothing was written",
                reason_text(*reason)
            ),
            Error::Aborted { iface } => write!(
                f,
                "error: the drive on `{iface}` aborted the routine: {}; its outputs are off until an abort command (nothing was written)\n  accepted: a routine that runs to its end",
                reason_text(Reason::Aborted)
            ),
            Error::Timeout {
                iface,
                waited,
                last_status,
                capture_frames,
                limit,
            } => {
                let status = match last_status {
                    None => "no status frame from the drive (is it on the bus, at the board's bit rate?)".to_string(),
                    Some((s, r)) => format!("the last status said {s:?} ({})", reason_text(*r)),
                };
                write!(
                    f,
                    "error: no complete capture on `{iface}` within {:.1} s: {capture_frames} capture frames received, {status}; nothing was written\n  accepted: a capture that ends within --timeout (now {limit})",
                    waited.as_secs_f64()
                )
            }
        }
    }
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
        Reason::AmplitudeAboveLimit => "the injection amplitude is above the drive's INJECTION_LIMIT",
        Reason::PreflightFailed => {
            "the pre-flight check refused the drive (outputs off until reset; the fault record's cause 11–18 says which check)"
        }
    }
}
