//! The firmware workspace lives apart from the host workspace (Cargo has no stable
//! per-package target); these tests run its host tests and its target build so that
//! `cargo test --workspace` covers everything.
//!
//! Every cargo run here uses the firmware workspace's own target directory,
//! `firmware/target` — the one a user's `motorgen firmware` and `cargo clippy` in
//! `firmware/` use — so each profile's dependencies (the STM32G4 PAC, the build script's
//! design engine) compile once; cargo's lock serialises the runs.

use std::process::Command;

/// `cargo` in `firmware/`, building in `firmware/target`.
fn cargo(args: &[&str]) -> Command {
    let firmware = motor_test_support::repo().join("firmware");
    let mut cargo = Command::new(env!("CARGO"));
    cargo
        .args(args)
        .current_dir(&firmware)
        .env("CARGO_TARGET_DIR", firmware.join("target"));
    cargo
}

fn cargo_in_firmware(args: &[&str]) {
    let out = cargo(args).output().expect("cargo runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "cargo {args:?} in firmware/ failed:\n{stdout}\n{stderr}"
    );
    // Echo the inner test summary so it shows in the outer log.
    for line in stdout.lines().filter(|l| l.starts_with("test result:")) {
        println!("firmware: {line}");
    }
}

#[test]
fn firmware_control_core_host_tests_pass() {
    cargo_in_firmware(&["test", "--locked", "--workspace"]);
}

/// Builds the release image (and the control core, motor-config) for the Cortex-M4F, then
/// checks that the image carries no defmt logging (firmware/README.md, "defmt logging"):
/// no `.defmt` section (defmt's string table), no `_defmt_*` symbol (its encoder and
/// logger hooks), no `_SEGGER_RTT` control block (the RTT transport). The image has
/// symbols (`debug = true`, not stripped), so the names are there to be found.
#[test]
fn firmware_control_core_builds_for_the_cortex_m4f() {
    use object::{Object, ObjectSection, ObjectSymbol};
    cargo_in_firmware(&["build", "--locked", "--release", "--target", "thumbv7em-none-eabihf"]);
    let elf = motor_test_support::repo().join("firmware/target/thumbv7em-none-eabihf/release/motor-firmware");
    let bytes = std::fs::read(&elf).unwrap_or_else(|e| panic!("{}: {e}", elf.display()));
    let file = object::File::parse(&*bytes).unwrap_or_else(|e| panic!("{}: {e}", elf.display()));
    let sections: Vec<&str> = file.sections().filter_map(|s| s.name().ok()).collect();
    assert!(sections.contains(&".vector_table"), "not the image: {sections:?}");
    assert!(
        !sections.iter().any(|s| s.starts_with(".defmt")),
        "defmt section in the release image: {sections:?}"
    );
    let symbols: Vec<&str> = file.symbols().filter_map(|s| s.name().ok()).collect();
    assert!(symbols.contains(&"MOTOR_FAULT_RECORD"), "image without symbols");
    let logging: Vec<&&str> = symbols
        .iter()
        .filter(|s| s.contains("_defmt_") || s.starts_with("__defmt") || s.contains("SEGGER_RTT"))
        .collect();
    assert!(logging.is_empty(), "defmt/RTT in the release image: {logging:?}");
}

/// A bad spec fails the firmware build with the CLI's located message (`cargo::error=`),
/// and an unknown `MOTOR` lists the motors that exist; never a build-script panic.
#[test]
fn firmware_build_reports_spec_errors_like_the_cli() {
    let repo = motor_test_support::repo();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("bad-motors");
    std::fs::create_dir_all(&dir).unwrap();
    let good = std::fs::read_to_string(repo.join("motors/fischer-ti085.toml")).unwrap();
    let bad = good.replacen("inductance = \"0.393 mH\"", "inductance = 0.000393", 1);
    let line = bad[..bad.find("inductance = 0.000393").unwrap()].matches('\n').count() + 1;
    std::fs::write(dir.join("bad-motor.toml"), bad).unwrap();
    std::fs::write(dir.join("good-motor.toml"), good).unwrap();
    for (motor, expect) in [
        (
            "bad-motor",
            vec![
                format!("motors/bad-motor.toml:{line}:14"),
                "`motor.datasheet.inductance`".into(),
                "bare number".into(),
                "accepted:".into(),
            ],
        ),
        (
            "no-such-motor",
            vec!["MOTOR=no-such-motor".into(), "bad-motor, good-motor".into()],
        ),
    ] {
        let out = cargo(&["build", "--locked", "-p", "motor-firmware"])
            .env("MOTOR", motor)
            .env("MOTORS_DIR", &dir)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{motor}: build succeeded");
        assert!(
            !stderr.contains("panicked"),
            "{motor}: build script panicked:\n{stderr}"
        );
        for e in expect {
            assert!(stderr.contains(&e), "{motor}: expected {e:?} in\n{stderr}");
        }
    }
}
