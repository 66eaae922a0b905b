//! Runs the `motor-qemu` binary on QEMU's netduinoplus2 (Cortex-M4F) and checks that
//! its semihosting output equals the host's [`motor_qemu::vectors::run_all`] lines
//! exactly, i.e. the control core is bit-exact between the host and the target.
//!
//! Needs `qemu-system-arm` on `PATH` (Debian: `apt-get install qemu-system-arm`);
//! without it the test fails rather than skipping.

use std::path::Path;

use motor_qemu::host::{build, build_on, emulate, on_path};

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

/// The board the `icount` binary is built for: `motor-config`'s default without `BOARD`
/// (`codegen::board::DEFAULT_BOARD`, not a dependency of this workspace's tests).
const DEFAULT_BOARD: &str = "motorgen-reference";

/// Instructions per control step on the emulated Cortex-M4F (`src/bin/icount.rs`, the
/// `FastTrig` step the image runs, 1000 measured steps, `-icount shift=5`), per motor in
/// `motors/`: the largest count must lie within ±10 % of the figure recorded in
/// `firmware/instruction-budgets.txt` (`qemu_control_step`; `MOTORGEN_RECORD_BUDGETS=1`
/// records a deliberate change). The 1024-`nop` calibration must read 1024 instructions
/// (5505 ± 1 ticks), or the tick → instruction conversion (and every figure) is wrong.
#[test]
fn control_step_instructions_within_budget() {
    assert!(on_path("qemu-system-arm"), "qemu-system-arm is not on PATH");
    assert!(on_path("timeout"), "`timeout` (GNU coreutils) is not on PATH");
    let boards = motor_test_support::board_stems();
    assert!(
        boards.iter().any(|b| b == DEFAULT_BOARD),
        "{DEFAULT_BOARD} is not in boards/: {boards:?}"
    );
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the crate lies inside the firmware workspace");
    let mut measured = Vec::new();
    // The default board first, then the others: each motor on the first board that its
    // build accepts (`motorgen check --board`'s verdict, which the build script applies:
    // the traction motors do not fit the default board's 100 A).
    let mut order = boards.clone();
    order.sort_by_key(|b| b != DEFAULT_BOARD);
    for motor in motor_test_support::motor_stems() {
        let mut refusals = Vec::new();
        let (elf, board) = order
            .iter()
            .find_map(|b| match build_on(workspace, "icount", Some(&motor), Some(b)) {
                Ok(elf) => Some((elf, b.clone())),
                Err(e) => {
                    refusals.push(e);
                    None
                }
            })
            .unwrap_or_else(|| panic!("{motor} builds on no board:\n{}", refusals.join("\n")));
        let stdout = emulate(&elf, &["-icount", "shift=5"], 120).unwrap_or_else(|e| panic!("{motor}: {e}"));
        let get = |name: &str| {
            stdout
                .lines()
                .filter_map(motor_qemu::icount::Measurement::parse)
                .find(|m| m.name == name)
                .unwrap_or_else(|| panic!("{motor}: no `{name}` line in\n{stdout}"))
                .stats
        };
        let nops = get("nop-1024");
        assert!(
            nops.min >= 5_504 && nops.max <= 5_506,
            "{motor}: 1024 nops took {}..{} ticks, expected 5505 ± 1",
            nops.min,
            nops.max
        );
        let step = get("step-fast-trig");
        assert!(step.count >= 1000, "{motor}: {} measured steps", step.count);
        // Instructions × 10, rounded; the figure is whole instructions.
        let max = (motor_qemu::icount::deci_instructions(u64::from(step.max), 1) + 5) / 10;
        measured.push(motor_test_support::budget::Figure {
            figure: "qemu_control_step".into(),
            motor: motor.clone(),
            board,
            instructions: max,
        });
    }
    motor_test_support::budget::check(&measured).unwrap_or_else(|e| panic!("{e}"));
}
