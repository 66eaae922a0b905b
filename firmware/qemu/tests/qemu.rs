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

/// A stack overflow reaches the HardFault handler (the image's entry and stack layout on
/// the emulated Cortex-M4F, `src/bin/overflow.rs`): unbounded recursion, then the
/// handler runs on a fresh stack and classifies the fault as a stack overflow. The
/// stacking BusFault sets CFSR.STKERR (bit 12, PM0214 §4.4.11) — what the image's
/// classification reads — and the stack pointer is at most one exception frame below
/// the stack's bottom 0x2000_0000.
#[test]
fn stack_overflow_reaches_the_hard_fault_handler() {
    assert!(on_path("qemu-system-arm"), "qemu-system-arm is not on PATH");
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the crate lies inside the firmware workspace");
    let elf = build(workspace, "overflow", None).unwrap_or_else(|e| panic!("{e}"));
    let stdout = emulate(&elf, &[], 60).unwrap_or_else(|e| panic!("{e}"));
    println!("{stdout}");
    let line = stdout
        .lines()
        .find_map(|l| l.strip_prefix("overflow: StackOverflow sp "))
        .unwrap_or_else(|| panic!("no stack-overflow line in\n{stdout}"));
    let mut words = line.split_whitespace();
    let hex = |s: Option<&str>| u32::from_str_radix(s.unwrap().trim_start_matches("0x"), 16).unwrap();
    let sp = hex(words.next());
    assert_eq!(words.next(), Some("cfsr"));
    let cfsr = hex(words.next());
    assert_ne!(cfsr & (1 << 12), 0, "CFSR {cfsr:#010x} without STKERR");
    // Basic frame 32 bytes, extended (FP) frame 104 bytes (PM0214 §2.3.7).
    assert!(
        (0x2000_0000 - 104..0x2000_0000 + 104).contains(&sp),
        "sp {sp:#010x} is not at the stack's bottom"
    );
}
