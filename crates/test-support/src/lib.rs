//! Helpers every crate's integration tests share, defined once: the repository root,
//! the motors and boards in it, and fresh temporary directories.
//!
//! A list that comes out empty (a moved or unreadable `motors/`, a typo in a filter
//! variable) is a failure, never a loop that runs zero times and passes.

pub mod budget;
pub mod fuzz;

use std::path::{Path, PathBuf};

/// The repository root (this crate lives at `crates/test-support`).
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("the repository root exists")
}

/// Stems of every `*.toml` in `dir`, sorted; panics (fails the test) if `dir` cannot be
/// read or holds none.
pub fn stems_in(dir: &Path) -> Vec<String> {
    let rd = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()));
    let mut v: Vec<String> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    v.sort();
    assert!(!v.is_empty(), "{} holds no *.toml file: nothing to test", dir.display());
    v
}

/// Stems of every motor in `motors/`, sorted, non-empty.
pub fn motor_stems() -> Vec<String> {
    stems_in(&repo().join("motors"))
}

/// Stems of every board in `boards/`, sorted, non-empty.
pub fn board_stems() -> Vec<String> {
    stems_in(&repo().join("boards"))
}

/// `motor_stems()` restricted by the environment variable `var` (a comma-separated list
/// of stems, for a quicker local run); every name in it must be a motor in `motors/`,
/// so a typo fails instead of selecting nothing.
pub fn motor_stems_filtered(var: &str) -> Vec<String> {
    let all = motor_stems();
    let Ok(only) = std::env::var(var) else { return all };
    let only: Vec<String> = only
        .split(',')
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect();
    for m in &only {
        assert!(
            all.contains(m),
            "{var} names `{m}`, which is not a motor in motors/ (motors: {})",
            all.join(", ")
        );
    }
    assert!(!only.is_empty(), "{var} is set but names no motor");
    all.into_iter().filter(|m| only.contains(m)).collect()
}

/// `(stem, "motors/<stem>.toml", text)` of every motor, sorted, non-empty.
pub fn motors() -> Vec<(String, String, String)> {
    motor_stems()
        .into_iter()
        .map(|stem| {
            let rel = format!("motors/{stem}.toml");
            let text = std::fs::read_to_string(repo().join(&rel)).unwrap_or_else(|e| panic!("cannot read {rel}: {e}"));
            (stem, rel, text)
        })
        .collect()
}

/// The text of a file given relative to the repository root.
pub fn read(rel: &str) -> String {
    std::fs::read_to_string(repo().join(rel)).unwrap_or_else(|e| panic!("cannot read {rel}: {e}"))
}

/// A fresh, empty directory `<system temp>/motorgen-tests/<group>/<name>` (removed and
/// recreated, so a previous run's files never leak into this one).
pub fn tmp(group: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join("motorgen-tests").join(group).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("cannot create {}: {e}", dir.display()));
    dir
}

/// Names of the temporary files (`*.tmp`) in `dir`.
pub fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .map(|e| e.expect("a directory entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_folder_fails() {
        let dir = tmp("test-support", "empty");
        let r = std::panic::catch_unwind(|| stems_in(&dir));
        assert!(r.is_err(), "an empty folder must fail, not give an empty list");
    }

    #[test]
    fn a_missing_folder_fails() {
        let r = std::panic::catch_unwind(|| stems_in(Path::new("/nonexistent/motors")));
        assert!(r.is_err());
    }

    #[test]
    fn the_repository_has_motors_and_boards() {
        assert!(motor_stems().contains(&"fischer-ti085".to_string()));
        assert!(board_stems().contains(&"motorgen-reference".to_string()));
    }
}
