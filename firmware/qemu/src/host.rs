//! Host side of the emulated runs (the test `tests/qemu.rs` and the bench
//! `benches/icount.rs`): build a `motor-qemu` binary for the Cortex-M4F and run it on
//! QEMU's netduinoplus2 with semihosting.

extern crate std;

use std::format;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::string::{String, ToString};

/// The target of the emulated builds.
pub const TARGET: &str = "thumbv7em-none-eabihf";

/// Whether `program` is an executable file in one of `PATH`'s directories.
pub fn on_path(program: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
}

/// Builds the release binary `bin` of `motor-qemu` for [`TARGET`] in the firmware
/// `workspace` (with `MOTOR=<motor>` when given) and returns the ELF's path.
pub fn build(workspace: &Path, bin: &str, motor: Option<&str>) -> Result<PathBuf, String> {
    build_on(workspace, bin, motor, None)
}

/// [`build`] for the board `boards/<board>.toml` (`BOARD`; `motor-config`'s default
/// board without one).
pub fn build_on(workspace: &Path, bin: &str, motor: Option<&str>, board: Option<&str>) -> Result<PathBuf, String> {
    let mut cargo = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    cargo
        .args([
            "build",
            "--release",
            "--target",
            TARGET,
            "-p",
            "motor-qemu",
            "--bin",
            bin,
        ])
        .arg("--message-format=short")
        .current_dir(workspace);
    if let Some(motor) = motor {
        cargo.env("MOTOR", motor);
    }
    if let Some(board) = board {
        cargo.env("BOARD", board);
    }
    let out = cargo.output().map_err(|e| format!("running cargo: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "{}{}cargo build --release --target {TARGET} -p motor-qemu --bin {bin} failed ({}):\n{}",
            motor.map_or_else(String::new, |m| format!("MOTOR={m} ")),
            board.map_or_else(String::new, |b| format!("BOARD={b} ")),
            out.status,
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let target_dir = std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| workspace.join("target"), PathBuf::from);
    let target_dir = if target_dir.is_absolute() {
        target_dir
    } else {
        workspace.join(target_dir)
    };
    let elf = target_dir.join(TARGET).join("release").join(bin);
    if elf.is_file() {
        Ok(elf)
    } else {
        Err(format!("no ELF at {}", elf.display()))
    }
}

/// Runs `elf` on `qemu-system-arm -machine netduinoplus2` with semihosting and the
/// `extra` emulator options, killed after `timeout_s` seconds; returns its semihosting
/// output (line ends without `\r`), or an error with the exit status and both streams.
pub fn emulate(elf: &Path, extra: &[&str], timeout_s: u32) -> Result<String, String> {
    let out = Command::new("timeout")
        .arg(timeout_s.to_string())
        .args(["qemu-system-arm", "-machine", "netduinoplus2", "-nographic"])
        .args(extra)
        .args(["-semihosting-config", "enable=on,target=native", "-kernel"])
        .arg(elf)
        .output()
        .map_err(|e| format!("running qemu-system-arm: {e}"))?;
    let stdout = String::from_utf8_lossy(&out.stdout).replace('\r', "");
    if out.status.success() {
        Ok(stdout)
    } else {
        Err(format!(
            "qemu exited with {} (124 = timed out after {timeout_s} s)\nstdout:\n{stdout}\nstderr:\n{}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}
