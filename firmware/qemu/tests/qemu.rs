//! Runs the `motor-qemu` binary on QEMU's netduinoplus2 (Cortex-M4F) and checks that
//! its semihosting output equals the host's [`motor_qemu::vectors::run_all`] lines
//! exactly, i.e. the control core is bit-exact between the host and the target.
//!
//! Needs `qemu-system-arm` on `PATH` (Debian: `apt-get install qemu-system-arm`);
//! without it the test fails rather than skipping.

use std::path::Path;

use motor_qemu::host::{build, emulate, on_path};

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

    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the crate lies inside the firmware workspace");
    let elf = build(workspace, "motor-qemu", None).unwrap_or_else(|e| panic!("{e}"));
    let stdout = emulate(&elf, &[], 60).unwrap_or_else(|e| panic!("{e}"));
    let actual: Vec<&str> = stdout.lines().collect();
    assert_eq!(
        actual, expected,
        "emulated output differs from the host's (left: qemu, right: host)"
    );
}
