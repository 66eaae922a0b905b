//! Helpers of the CLI-level tests: `motorgen` run as a user runs it, exit codes; the
//! repository, its motors and temporary directories come from `motor-test-support`.

pub use motor_test_support::{ISSUE_18_RANGE_EXAMPLES, motor_stems, repo, temporaries, tmp};
use std::process::{Command, Output};

/// `motorgen`'s exit code for an I/O failure (EX_IOERR, see the CLI's `output` module).
pub const EXIT_IO: i32 = 74;
/// SIGXFSZ (Linux: 25): the default action of exceeding RLIMIT_FSIZE (`ulimit -f`).
pub const SIGXFSZ: i32 = 25;

/// `motorgen <args>` in the repository root.
pub fn motorgen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_motorgen"))
        .args(args)
        .current_dir(repo())
        .output()
        .unwrap()
}

/// A finished process's status, stdout and stderr, for assertion messages.
pub fn text_of(o: &Output) -> String {
    format!(
        "status {:?}\nstdout:\n{}\nstderr:\n{}",
        o.status,
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}
