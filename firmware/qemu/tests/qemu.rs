//! Runs the `motor-qemu` binary on QEMU's netduinoplus2 (Cortex-M4F) and checks that
//! its semihosting output equals the host's [`motor_qemu::vectors::run_all`] lines
//! exactly, i.e. the control core is bit-exact between the host and the target.
//!
//! Needs `qemu-system-arm` on `PATH` (Debian: `apt-get install qemu-system-arm`);
//! without it the test fails rather than skipping.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The target of the emulated build.
const TARGET: &str = "thumbv7em-none-eabihf";

/// Whether `program` is an executable file in one of `PATH`'s directories.
fn on_path(program: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
}

/// Builds the release binary for [`TARGET`] and returns the ELF's path.
fn build_elf() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let workspace = manifest.parent().expect("the crate lies inside the firmware workspace");
    let output = Command::new(env!("CARGO"))
        .args([
            "build",
            "--release",
            "--target",
            TARGET,
            "-p",
            "motor-qemu",
            "--message-format=short",
        ])
        .current_dir(workspace)
        .output()
        .expect("running cargo");
    assert!(
        output.status.success(),
        "cargo build --release --target {TARGET} -p motor-qemu failed ({}):\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    let target_dir = std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| workspace.join("target"), PathBuf::from);
    let target_dir = if target_dir.is_absolute() {
        target_dir
    } else {
        workspace.join(target_dir)
    };
    let elf = target_dir.join(TARGET).join("release").join("motor-qemu");
    assert!(elf.is_file(), "no ELF at {}", elf.display());
    elf
}

#[test]
fn emulated_cortex_m4f_matches_host_bit_for_bit() {
    assert!(
        on_path("qemu-system-arm"),
        "qemu-system-arm is not on PATH: install it (`apt-get install qemu-system-arm`) to run the \
         emulated Cortex-M4F test vectors"
    );
    assert!(
        on_path("timeout"),
        "`timeout` (GNU coreutils) is not on PATH; it bounds the emulator's run time"
    );
    let expected: Vec<String> = motor_qemu::vectors::run_all().iter().map(ToString::to_string).collect();
    assert_eq!(expected.len(), motor_qemu::vectors::FUNCTIONS);

    let elf = build_elf();
    let output = Command::new("timeout")
        .arg("60")
        .args(["qemu-system-arm", "-machine", "netduinoplus2", "-nographic"])
        .args(["-semihosting-config", "enable=on,target=native", "-kernel"])
        .arg(&elf)
        .output()
        .expect("running qemu-system-arm");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "qemu exited with {} (124 = timed out after 60 s)\nstdout:\n{stdout}\nstderr:\n{stderr}",
        output.status
    );
    let actual: Vec<&str> = stdout.lines().map(|l| l.trim_end_matches('\r')).collect();
    assert_eq!(
        actual, expected,
        "emulated output differs from the host's (left: qemu, right: host)\nstderr:\n{stderr}"
    );
}
