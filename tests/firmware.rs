//! The firmware workspace lives apart from the host workspace (Cargo has no stable
//! per-package target); these tests run its host tests and its target build so that
//! `cargo test --workspace` covers everything.

use std::process::Command;

fn cargo_in_firmware(args: &[&str], target_dir: &str) {
    let repo = motor_tests::repo();
    let out = Command::new(env!("CARGO"))
        .args(args)
        .current_dir(repo.join("firmware"))
        .env("CARGO_TARGET_DIR", repo.join("target").join(target_dir))
        .output()
        .expect("cargo runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "cargo {args:?} in firmware/ failed:\n{stdout}\n{stderr}");
    // Echo the inner test summary so it shows in the outer log.
    for line in stdout.lines().filter(|l| l.starts_with("test result:")) {
        println!("firmware: {line}");
    }
}

#[test]
fn firmware_control_core_host_tests_pass() {
    cargo_in_firmware(&["test", "--locked"], "firmware-host");
}

#[test]
fn firmware_control_core_builds_for_the_cortex_m4f() {
    cargo_in_firmware(&["build", "--locked", "--release", "--target", "thumbv7em-none-eabihf"], "firmware-target");
}
