//! Helpers shared by the CLI-level integration tests: the repository root, `motorgen`
//! run as a user runs it, and fresh temp directories.

#![allow(dead_code)] // each test crate uses its own subset

pub mod recordings;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `motorgen`'s exit code for an I/O failure (EX_IOERR, see the CLI's `output` module).
pub const EXIT_IO: i32 = 74;
/// SIGXFSZ (Linux: 25): the default action of exceeding RLIMIT_FSIZE (`ulimit -f`).
pub const SIGXFSZ: i32 = 25;

/// Issue 18's examples on the Fischer spec: (text replaced, replacement, key, range the
/// refusal names). Each overflowed or underflowed the design before it had a range.
pub const ISSUE_18_RANGE_EXAMPLES: &[(&str, &str, &str, &str)] = &[
    (
        "peak_current = \"61 A\"",
        "peak_current = \"6.1e201 A\"",
        "motor.datasheet.peak_current",
        "[1 mA, 100 kA]",
    ),
    (
        "dc_link_voltage = \"600 V\"",
        "dc_link_voltage = \"1.7976931348623157e308 V\"",
        "drive.dc_link_voltage",
        "[1 V, 2000 V]",
    ),
    (
        "bandwidth = \"100 rad/s\"",
        "bandwidth = \"1e-308 rad/s\"",
        "current_loop.bandwidth",
        "[1 rad/s, 1e6 rad/s]",
    ),
];

/// The repository root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Stems of every `*.toml` in `motors/`, sorted.
pub fn motor_stems() -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(repo().join("motors"))
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// `motorgen <args>` in the repository root.
pub fn motorgen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_motorgen"))
        .args(args)
        .current_dir(repo())
        .output()
        .unwrap()
}

/// An empty directory `<target tmp>/<group>/<name>`.
pub fn tmp(group: &str, name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(group).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
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

/// Names of the temporary files (`*.tmp`) in `dir`.
pub fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}
