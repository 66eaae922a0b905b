//! Helpers every crate's integration tests share, defined once: the repository root,
//! the motors and boards in it, and fresh temporary directories.
//!
//! A list that comes out empty (a moved or unreadable `motors/`, a typo in a filter
//! variable) is a failure, never a loop that runs zero times and passes.

pub mod budget;
pub mod fuzz;

use std::path::{Path, PathBuf};
use std::process::Command;

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

/// `text` (a spec or board file) with the value of the dotted `key` set to `value` (TOML
/// text, e.g. `"\"5929 ns\""` or `0x0DA`): the line `name = …` in the key's `[table]` is
/// replaced (its trailing comment dropped), or added under the table's header when the
/// table lacks it. Panics (fails the test) when the table is not in the file.
pub fn set_toml_key(text: &str, key: &str, value: &str) -> String {
    let (table, name) = key.rsplit_once('.').unwrap_or(("", key));
    let lines: Vec<&str> = text.lines().collect();
    let header = |l: &str| l.trim_start().starts_with('[');
    let table_of = |l: &str| {
        let t = l.trim();
        t.trim_start_matches('[')
            .split(']')
            .next()
            .unwrap_or("")
            .trim()
            .to_string()
    };
    // The table's lines: from after its header to the next header (the top level: from
    // the start).
    let start = if table.is_empty() {
        0
    } else {
        lines
            .iter()
            .position(|l| header(l) && !l.trim().starts_with("[[") && table_of(l) == table)
            .unwrap_or_else(|| panic!("no [{table}] in the file for `{key}`"))
            + 1
    };
    let end = lines[start..]
        .iter()
        .position(|l| header(l))
        .map_or(lines.len(), |i| start + i);
    let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    let found = (start..end).find(|&i| {
        let t = lines[i].trim_start();
        t.strip_prefix(name)
            .is_some_and(|rest| rest.trim_start().starts_with('='))
    });
    match found {
        Some(i) => out[i] = format!("{name} = {value}"),
        None => out.insert(start, format!("{name} = {value}")),
    }
    let mut joined = out.join("\n");
    joined.push('\n');
    joined
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

/// The target triple of the STM32G474 image.
pub const FIRMWARE_TARGET: &str = "thumbv7em-none-eabihf";

/// `cargo build --locked --release --target thumbv7em-none-eabihf -p motor-firmware` in
/// the repository's `firmware/`, in its shared `firmware/target` (so only the app crate
/// rebuilds per motor and board), for `motor` (a stem) on `board` of `boards_dir`.
/// The caller adds `MOTORS_DIR` when the motor is not one of `motors/`. The image lands
/// at [`firmware_image_path`].
pub fn firmware_image_build(motor: &str, board: &str, boards_dir: &Path) -> Command {
    let firmware = repo().join("firmware");
    let mut cmd = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    cmd.args([
        "build",
        "--locked",
        "--release",
        "--target",
        FIRMWARE_TARGET,
        "-p",
        "motor-firmware",
    ])
    .current_dir(&firmware)
    .env("CARGO_TARGET_DIR", firmware.join("target"))
    .env("MOTOR", motor)
    .env("BOARD", board)
    .env("BOARDS_DIR", boards_dir)
    .env_remove("MOTORS_DIR");
    cmd
}

/// Where [`firmware_image_build`] leaves the image (an ELF).
pub fn firmware_image_path() -> PathBuf {
    repo()
        .join("firmware/target")
        .join(FIRMWARE_TARGET)
        .join("release/motor-firmware")
}

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
    fn sets_a_key_in_its_table() {
        let text = "name = \"x\"\n[a]\nk = 1 # c\n[a.b]\nk = 2\n";
        assert_eq!(
            set_toml_key(text, "a.k", "5"),
            "name = \"x\"\n[a]\nk = 5\n[a.b]\nk = 2\n"
        );
        assert_eq!(
            set_toml_key(text, "a.b.k", "7"),
            "name = \"x\"\n[a]\nk = 1 # c\n[a.b]\nk = 7\n"
        );
        assert_eq!(
            set_toml_key(text, "a.j", "3"),
            "name = \"x\"\n[a]\nj = 3\nk = 1 # c\n[a.b]\nk = 2\n"
        );
        assert_eq!(
            set_toml_key(text, "name", "\"y\""),
            "name = \"y\"\n[a]\nk = 1 # c\n[a.b]\nk = 2\n"
        );
        assert!(std::panic::catch_unwind(|| set_toml_key(text, "c.k", "1")).is_err());
    }

    #[test]
    fn the_repository_has_motors_and_boards() {
        assert!(motor_stems().contains(&"fischer-ti085".to_string()));
        assert!(board_stems().contains(&"motorgen-reference".to_string()));
    }
}
