//! The exit codes of `motorgen`, one per kind of failure, so that scripts and CI can
//! tell a bad spec from a failed verification or a full disk. Documented in `--help`
//! ([`HELP`]) and in the README.

use std::process::ExitCode;

use codegen::Diagnostics;

use crate::atomic::IoFailure;
use crate::output::{err, errln};

/// Why `motorgen` stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exit {
    /// 0: done.
    Success = 0,
    /// 1: the input is wrong — a spec, recording, template or motor name; the message
    /// names the file, line:column and key, and what would be accepted.
    BadInput = 1,
    /// 2: the command line is wrong (clap's own exit code for usage errors).
    Usage = 2,
    /// 3: the design was made but does not hold up: `verify`/`report` measured a
    /// failing figure, or the `firmware` image exceeds its flash budget.
    VerificationFailed = 3,
    /// 74 (sysexits' EX_IOERR, [`crate::output::EXIT_IO`]): a file or directory could
    /// not be read or written (standard output included), or cargo could not be run.
    Io = crate::output::EXIT_IO as isize,
    /// 5: the firmware build (cargo) failed.
    BuildFailed = 5,
    /// 6: `commission`: the drive refused the routine or aborted it (its status
    /// frame's reason is on stderr).
    Refused = 6,
    /// 69 (sysexits' EX_UNAVAILABLE): `commission`: the CAN interface cannot be opened
    /// (no such interface, not up, not Linux) or failed while in use.
    CanUnavailable = 69,
    /// 75 (sysexits' EX_TEMPFAIL): `commission`: no complete capture within `--timeout`.
    Timeout = 75,
}

impl Exit {
    /// The exit code of a run that went on after failures (`check`: bad input or I/O):
    /// the gravest one, the largest code (I/O over a failed build over a failed
    /// verification over bad input).
    pub fn gravest(failed: &[Exit]) -> Option<Exit> {
        failed.iter().copied().max_by_key(|e| *e as u8)
    }
}

impl From<Exit> for ExitCode {
    fn from(e: Exit) -> Self {
        ExitCode::from(e as u8)
    }
}

/// The exit-code table shown at the end of `motorgen --help`.
pub const HELP: &str = "\
Exit codes:
  0  success
  1  bad input: a spec, recording, template or motor name is wrong (located message on stderr)
  2  usage: the command line is wrong
  3  verification failed: a simulated figure failed, or the image exceeds its flash budget
  5  the firmware build (cargo) failed
  6  commission: the drive refused or aborted the routine (its reason on stderr)
  69 commission: the CAN interface cannot be opened or failed (no such interface, not up, not Linux)
  74 I/O: a file, directory or standard output could not be read or written, or cargo could not be run
  75 commission: no complete capture from the drive within --timeout";

/// A failed command: the message for stderr and the exit code.
#[derive(Debug)]
pub struct Failure {
    /// Exit code.
    pub exit: Exit,
    /// Printed on stderr (a trailing newline is added if missing).
    pub message: String,
}

impl Failure {
    /// A failure of kind `exit` with `message`.
    pub fn new(exit: Exit, message: impl Into<String>) -> Self {
        Self {
            exit,
            message: message.into(),
        }
    }

    /// Prints the message on stderr and returns the exit code.
    pub fn report(self) -> ExitCode {
        if self.message.ends_with('\n') {
            err!("{}", self.message);
        } else {
            errln!("{}", self.message);
        }
        self.exit.into()
    }
}

/// A file that could not be written is an I/O failure.
impl From<IoFailure> for Failure {
    fn from(e: IoFailure) -> Self {
        Failure::new(Exit::Io, format!("error: {e}"))
    }
}

/// Located diagnostics are bad input.
impl From<Diagnostics> for Failure {
    fn from(d: Diagnostics) -> Self {
        Failure::new(Exit::BadInput, d.to_string())
    }
}

/// The library's failures, each with its exit code: bad input 1, an unreadable input
/// 74, the CAN interface 69, the drive's refusal or abort 6, no capture in time 75.
impl From<motor_commission::Error> for Failure {
    fn from(e: motor_commission::Error) -> Self {
        use motor_commission::Error as E;
        let exit = match &e {
            E::Input(_) | E::Option(_) => Exit::BadInput,
            E::Unreadable(_) => Exit::Io,
            E::BusUnavailable(_) => Exit::CanUnavailable,
            E::Refused { .. } | E::Aborted { .. } => Exit::Refused,
            E::Timeout { .. } => Exit::Timeout,
        };
        Failure::new(exit, e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table in `--help` lists every code with its number.
    #[test]
    fn help_lists_every_code() {
        for e in [
            Exit::Success,
            Exit::BadInput,
            Exit::Usage,
            Exit::VerificationFailed,
            Exit::Io,
            Exit::BuildFailed,
            Exit::Refused,
            Exit::CanUnavailable,
            Exit::Timeout,
        ] {
            let code = e as u8;
            let row = if code < 10 {
                format!("\n  {code}  ")
            } else {
                format!("\n  {code} ")
            };
            assert!(HELP.contains(&row), "{e:?}");
        }
    }

    /// Each of the library's failures has the exit code the README documents, and its
    /// message unchanged.
    #[test]
    fn library_failures_have_their_exit_codes() {
        use motor_commission::{Error, Problem};
        use motor_control::can_protocol::Reason;
        let located = Diagnostics(vec![codegen::Diagnostic {
            file: "m.toml".into(),
            line: 3,
            column: 1,
            key: String::new(),
            problem: "bad".into(),
            accepted: "good".into(),
            excerpt: String::new(),
            notes: Vec::new(),
        }]);
        let problem = Problem::new("--trip", "bad", "good");
        let iface = || "can0".to_string();
        for (e, exit) in [
            (Error::Input(located.clone()), Exit::BadInput),
            (Error::Option(problem.clone()), Exit::BadInput),
            (Error::Unreadable(located), Exit::Io),
            (Error::BusUnavailable(problem), Exit::CanUnavailable),
            (
                Error::Refused {
                    iface: iface(),
                    reason: Reason::Busy,
                },
                Exit::Refused,
            ),
            (Error::Aborted { iface: iface() }, Exit::Refused),
            (
                Error::Timeout {
                    iface: iface(),
                    waited: std::time::Duration::from_secs(2),
                    last_status: None,
                    capture_frames: 0,
                    limit: "2 s".into(),
                },
                Exit::Timeout,
            ),
        ] {
            let message = e.to_string();
            let f = Failure::from(e);
            assert_eq!((f.exit, f.message), (exit, message));
        }
    }
}
