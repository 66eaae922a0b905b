//! `motorgen firmware` as a user runs it: the fischer-ti085 image is built into
//! `target/firmware/` with cargo's progress on stderr, is a valid STM32G474 flash image
//! and fits in 64 KiB; an unknown stem, a bad spec and a motor on a board it does not fit
//! are refused (exit 1) before anything is built or written; `--all` builds every motor
//! the board fits, on the default board and on the NUCLEO-G474RE + X-NUCLEO-IHM08M1 board,
//! and names the others with the board keys they do not fit.
//!
//! The image builds in the firmware workspace's own target directory, `firmware/target`,
//! where `motorgen firmware` builds it for a user and where `tests/firmware.rs` builds the
//! control core: one target directory, so the STM32G4 PAC and the build script's design
//! engine compile once per profile.

use std::path::Path;
use std::process::{Command, Output};

use crate::common::repo;

/// STM32G474RE memory map (RM0440 §2.2, Table 3 / §2.3): flash from 0x0800_0000
/// (512 KiB); SRAM1 80 KiB at 0x2000_0000, SRAM2 16 KiB at 0x2001_4000 and the CCM
/// SRAM's 32 KiB alias at 0x2001_8000 form 128 KiB of contiguous RAM ending at
/// 0x2000_0000 + 0x2_0000 = 0x2002_0000 (80 + 16 + 32 = 128 KiB = 0x2_0000).
const FLASH_START: u32 = 0x0800_0000;
const RAM_START: u32 = 0x2000_0000;
const RAM_END: u32 = 0x2002_0000;
/// The image's initial stack pointer: the top of the 32 KiB main stack that
/// firmware/app/memory.x places at the bottom of RAM (0x2000_0000 + 0x8000).
const STACK_TOP: u32 = RAM_START + 32 * 1024;

/// Runs `motorgen firmware <args>` from the repository root.
fn firmware(args: &[&str]) -> Output {
    let repo = repo();
    Command::new(env!("CARGO_BIN_EXE_motorgen"))
        .arg("firmware")
        .args(args)
        .current_dir(&repo)
        .env("CARGO_TARGET_DIR", repo.join("firmware").join("target"))
        .env_remove("MOTOR")
        .env_remove("MOTORS_DIR")
        .env_remove("BOARD")
        .env_remove("BOARDS_DIR")
        .output()
        .expect("motorgen runs")
}

fn word(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
}

#[test]
fn fischer_image_is_a_g474_flash_image_under_64_kib() {
    let out = firmware(&["fischer-ti085"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "motorgen firmware failed:\n{stdout}\n{stderr}");
    println!("{stdout}");
    // cargo's progress is relayed on stderr as it comes: the command, then cargo's own
    // lines, at least the closing "Finished" (also when nothing needs compiling).
    assert!(
        stderr.contains("fischer-ti085: MOTOR=fischer-ti085 BOARD=motorgen-reference cargo build --release")
            && stderr.contains("Finished"),
        "no build progress on stderr:\n{stderr}"
    );
    // The design's warnings once each on stderr (issue 27: the board's came three times,
    // twice more from the build script through cargo), none in the summary on stdout.
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.starts_with("warning: ")).collect();
    let unique: std::collections::BTreeSet<&&str> = warnings.iter().collect();
    assert_eq!(unique.len(), warnings.len(), "a warning twice:\n{stderr}");
    assert!(!stderr.contains("warning: motor-config@"), "{stderr}");
    assert!(!stdout.contains("warning"), "{stdout}");

    // "fischer-ti085: flash <bytes> bytes (…)"
    let flash: usize = stdout
        .lines()
        .find_map(|l| l.strip_prefix("fischer-ti085: flash "))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no flash line in\n{stdout}"));
    assert!(
        stdout.contains("fischer-ti085: static RAM "),
        "no RAM line in\n{stdout}"
    );

    let dir = repo().join("target").join("firmware");
    let elf = std::fs::read(dir.join("fischer-ti085.elf")).expect("the .elf is written");
    assert_eq!(&elf[..4], b"\x7fELF");
    let bin = std::fs::read(dir.join("fischer-ti085.bin")).expect("the .bin is written");
    assert_eq!(bin.len(), flash, "the .bin is as long as the flash use printed");
    assert!(flash < 64 * 1024, "{flash} bytes of flash");

    // Cortex-M vector table: initial SP, then the reset handler's address with the
    // Thumb bit set, inside the image.
    assert_eq!(
        word(&bin, 0),
        STACK_TOP,
        "initial stack pointer = top of the stack below the statics"
    );
    let reset = word(&bin, 4);
    assert_eq!(reset & 1, 1, "reset vector {reset:#010x} is not a Thumb address");
    let flash_end = FLASH_START + u32::try_from(flash).unwrap();
    assert!(
        (FLASH_START..flash_end).contains(&(reset & !1)),
        "reset vector {reset:#010x} outside the image {FLASH_START:#010x}..{flash_end:#010x}"
    );
}

/// Stack overflow protection and the fault record, read from the fischer-ti085 ELF:
/// * the main stack is `[0x2000_0000, _stack_start)`: nothing lies below it (RM0440
///   memory map: reserved below SRAM1), every RAM section (.data, .bss, .uninit) lies
///   above it, so an overflow faults instead of overwriting statics;
/// * the HardFault vector points at the entry in app/src/board/fault.rs, which moves
///   MSP to `_stack_start` before anything could push onto the overflowed stack;
/// * the fault record and the live control state are in `.uninit` (not zeroed at boot)
///   under their documented symbols, 16 and 8 words.
#[test]
fn stack_below_the_statics_and_the_fault_record_in_uninit() {
    use object::{Object, ObjectSection, ObjectSymbol};

    let out = firmware(&["fischer-ti085"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(repo().join("target/firmware/fischer-ti085.elf")).expect("the .elf is written");
    let file = object::File::parse(&*bytes).expect("an ELF");
    let symbol = |name: &str| {
        file.symbols()
            .find(|s| s.name() == Ok(name))
            .map(|s| (s.address() as u32, s.size() as u32))
            .unwrap_or_else(|| panic!("no symbol {name}"))
    };
    let (stack_top, _) = symbol("_stack_start");
    let (stack_bottom, _) = symbol("_stack_end");
    assert_eq!(stack_bottom, RAM_START, "the stack grows down to the start of RAM");
    assert_eq!(stack_top, STACK_TOP);
    let mut ram_sections = 0;
    for s in file.sections() {
        // Every section placed in RAM (.data, .bss, .uninit).
        if (u64::from(RAM_START)..u64::from(RAM_END)).contains(&s.address()) && s.size() > 0 {
            ram_sections += 1;
            let name = s.name().unwrap_or("?");
            assert!(
                s.address() >= u64::from(stack_top) && s.address() + s.size() <= u64::from(RAM_END),
                "{name} at {:#010x} (+{}) is not above the stack (top {stack_top:#010x})",
                s.address(),
                s.size()
            );
        }
    }
    assert!(ram_sections >= 2, "found .bss and .uninit");

    // The record: 7 + 8 + 1 words (magic, cause, flags, PC, CFSR, HFSR, the start-up
    // check's measurement; state with the bus-off count; CRC).
    let (uninit_start, _) = symbol("__suninit");
    let (uninit_end, _) = symbol("__euninit");
    for (name, words) in [("MOTOR_FAULT_RECORD", 16), ("MOTOR_CONTROL_STATE", 8)] {
        let (at, size) = symbol(name);
        assert_eq!(size, 4 * words, "{name} size");
        assert!(
            at >= uninit_start && at + size <= uninit_end,
            "{name} at {at:#010x} is not in .uninit [{uninit_start:#010x}, {uninit_end:#010x})"
        );
    }

    // HardFault: the vector (word 3, PM0214 §2.3.4 vector table) is the entry's address
    // with the Thumb bit; its first instruction is `mrs r0, MSP` (Thumb-2 F3EF 8008) and
    // `msr MSP, r1` (F381 8808) follows within its first 24 bytes with no push (16-bit
    // B4xx/B5xx, 32-bit E92D) before it.
    // (A Thumb function's ELF symbol value carries the Thumb bit: clear it.)
    let hard_fault = symbol("HardFault").0 & !1;
    let text = file.section_by_name(".text").expect(".text");
    let vectors = file.section_by_name(".vector_table").expect(".vector_table");
    let table = vectors.data().unwrap();
    assert_eq!(word(table, 12), hard_fault | 1, "HardFault vector");
    let at = (u64::from(hard_fault) - text.address()) as usize;
    let code = &text.data().unwrap()[at..at + 24];
    let halfwords: Vec<u16> = code.chunks(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect();
    assert_eq!(&halfwords[..2], &[0xF3EF, 0x8008], "HardFault starts with mrs r0, MSP");
    let msr = halfwords
        .windows(2)
        .position(|w| w == [0xF381, 0x8808])
        .expect("msr MSP, r1 in the HardFault entry");
    for &h in &halfwords[..msr] {
        assert!(
            h >> 9 != 0b101_1010 && h != 0xE92D,
            "a push ({h:#06x}) before MSP is reset"
        );
    }
}

/// `motorgen firmware --all [--board <board>]`: the image of every motor in `fits` is
/// written into `dir` (relative to `target/firmware/`), under 64 KiB with the G474's stack
/// pointer, and a flash line is printed for each; every other motor is left out with a
/// warning on stderr that names it and the board keys it does not fit (and this run writes
/// no image of it); returns stderr.
fn every_fitting_motor_builds(board: Option<&str>, fits: &[&str]) -> String {
    let mut args = vec!["--all"];
    args.extend(board.iter().flat_map(|b| ["--board", *b]));
    let mut dir = repo().join("target").join("firmware");
    if let Some(b) = board {
        dir = dir.join(b);
    }
    let stems = crate::common::motor_stems();
    let out = firmware(&args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "motorgen firmware {args:?} failed:\n{stdout}\n{stderr}"
    );
    println!("{stdout}{stderr}");
    let board_name = board.unwrap_or("motorgen-reference");
    for stem in &stems {
        let bin = dir.join(format!("{stem}.bin"));
        if !fits.contains(&stem.as_str()) {
            assert!(
                !stdout.contains(&format!("{stem}: ")),
                "{stem}: built on a board it does not fit:\n{stdout}"
            );
            let warning = format!("warning: {stem} is not built for {board_name}: it does not fit the board\n  ");
            assert!(stderr.contains(&warning), "{stem}: no warning {warning:?} in\n{stderr}");
            continue;
        }
        let bin = std::fs::read(&bin).expect("the .bin is written");
        assert!(bin.len() < 64 * 1024, "{stem}: {} bytes", bin.len());
        assert_eq!(word(&bin, 0), STACK_TOP, "{stem}: initial stack pointer");
        assert!(
            stdout.contains(&format!("{stem}: flash {} bytes", bin.len())),
            "{stem}: no flash line for {} bytes in\n{stdout}",
            bin.len()
        );
    }
    stderr.into_owned()
}

/// `firmware --all` builds every motor the default board fits into `target/firmware/`:
/// the reference board measures ±1.65 V/15 mV/A = ±110 A, so the two traction motors
/// (Chalmers HEV50 √2·224 = 316.8 A, EMRAX 228 √2·240 = 339.4 A peak) are left out, and
/// so is the AMK DD5 (√2·74.2 = 105.0 A peak over the board's 100 A ceiling); they build
/// on motorgen-reference-400a. The Mini Cheetah actuator (24 V, √2·28.28 = 40.0 A peak) fits.
#[test]
fn every_motor_builds_on_the_default_board() {
    every_fitting_motor_builds(
        None,
        &[
            "fischer-ti085",
            "maxon-ec45-flat-70w",
            "mit-mini-cheetah-actuator",
            "unimotor-142umd300",
        ],
    );
}

/// On the NUCLEO-G474RE + X-NUCLEO-IHM08M1 (±30.7 A, 63.2 V, 25 A / 52 V / 6000 rpm
/// ceilings) only the 24 V maxon servo (√2·10 = 14.1 A) fits; the 600 V Fischer is left
/// out with its DC link refused at `sensing.dc_link_divider` (issue 27: it used to build,
/// its DC-link reading saturated).
#[test]
fn every_motor_builds_on_the_nucleo_ihm08m1_board() {
    let stderr = every_fitting_motor_builds(Some("nucleo-g474re-ihm08m1"), &["maxon-ec45-flat-70w"]);
    let fischer = stderr
        .split("warning: ")
        .find(|w| w.starts_with("fischer-ti085 is not built"))
        .unwrap_or_else(|| panic!("{stderr}"));
    assert!(
        fischer.contains("`sensing.dc_link_divider`: the divider measures up to 63.2 V"),
        "{fischer}"
    );
}

/// A motor named on a board it does not fit is refused (exit 1) at the board key, before
/// cargo runs, and nothing is written.
#[test]
fn a_named_motor_on_a_board_it_does_not_fit_is_refused() {
    let out = firmware(&["fischer-ti085", "--board", "nucleo-g474re-ihm08m1"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("nucleo-g474re-ihm08m1.toml:") && stderr.contains("`sensing.dc_link_divider`"),
        "{stderr}"
    );
    assert!(!stderr.contains("cargo build"), "cargo ran:\n{stderr}");
    assert!(out.stdout.is_empty(), "{}", String::from_utf8_lossy(&out.stdout));
}

/// A bad board file is refused with its location before cargo runs.
#[test]
fn bad_board_fails_with_its_location_before_cargo_runs() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("firmware-bad-boards");
    std::fs::create_dir_all(&dir).unwrap();
    let good = std::fs::read_to_string(repo().join("boards/motorgen-reference.toml")).unwrap();
    let bad = good.replacen("gate_u_low = \"PB13\"", "gate_u_low = \"PA5\" ", 1);
    assert_ne!(bad, good);
    let line = bad[..bad.find("gate_u_low = \"PA5\"").unwrap()].matches('\n').count() + 1;
    std::fs::write(dir.join("bad.toml"), bad).unwrap();
    let out = firmware(&["fischer-ti085", "--board", "bad", "--boards-dir", dir.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    for expected in [
        format!("bad.toml:{line}:14"),
        "`pins.gate_u_low`".into(),
        "PA5 has no TIM1_CH1N".into(),
    ] {
        assert!(stderr.contains(&expected), "expected {expected:?} in\n{stderr}");
    }
    assert!(!stderr.contains("Compiling"), "cargo ran for a bad board:\n{stderr}");
    // An unknown board lists the boards that exist.
    let out = firmware(&["fischer-ti085", "--board", "no-such-board"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("no board `no-such-board`") && stderr.contains("nucleo-g474re-ihm08m1"),
        "{stderr}"
    );
}

#[test]
fn unknown_stem_lists_the_motors_and_writes_nothing() {
    let out = firmware(&["no-such-motor"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(out.stdout.is_empty());
    assert!(stderr.contains("no motor `no-such-motor`"), "{stderr}");
    let stems = crate::common::motor_stems();
    assert!(stems.len() >= 3, "the seed motors are in motors/: {stems:?}");
    for stem in stems {
        assert!(stderr.contains(&stem), "accepted stems should list {stem}:\n{stderr}");
    }
    let dir = repo().join("target").join("firmware");
    for ext in ["elf", "bin"] {
        assert!(!dir.join(format!("no-such-motor.{ext}")).exists());
    }
}

#[test]
fn bad_spec_fails_with_its_location_before_cargo_runs() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("firmware-bad-motors");
    std::fs::create_dir_all(&dir).unwrap();
    let good = std::fs::read_to_string(repo().join("motors/fischer-ti085.toml")).unwrap();
    let bad = good.replacen("inductance = \"0.393 mH\"", "inductance = 0.000393", 1);
    assert_ne!(bad, good);
    // 1-based line of the edited key, counted by the test itself; column 14 is the value.
    let line = bad[..bad.find("inductance = 0.000393").unwrap()].matches('\n').count() + 1;
    let spec = dir.join("bad-image.toml");
    std::fs::write(&spec, bad).unwrap();

    let out = firmware(&["bad-image", "--dir", dir.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let at = format!("{}:{line}:14", spec.display());
    for expected in [at.as_str(), "`motor.datasheet.inductance`", "bare number", "accepted:"] {
        assert!(stderr.contains(expected), "expected {expected:?} in\n{stderr}");
    }
    assert!(!stderr.contains("Compiling"), "cargo ran for a bad spec:\n{stderr}");
    let out_dir = repo().join("target").join("firmware");
    assert!(!out_dir.join("bad-image.elf").exists());
    assert!(!out_dir.join("bad-image.bin").exists());
}
