//! `motorgen firmware` as a user runs it: the fischer-ti085 image is built into
//! `target/firmware/` with cargo's progress on stderr, is a valid STM32G474 flash image
//! and fits in 64 KiB; an unknown stem and a bad spec are refused (exit 1) before
//! anything is built or written; `--all` builds every motor on the default board and on
//! the NUCLEO-G474RE + X-NUCLEO-IHM08M1 board.
//!
//! The image builds in the firmware workspace's own target directory, `firmware/target`,
//! where `motorgen firmware` builds it for a user and where `tests/firmware.rs` builds the
//! control core: one target directory, so the STM32G4 PAC and the build script's design
//! engine compile once per profile.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::repo;

/// STM32G474RE memory map (RM0440 §2.2, Table 3 / §2.3): flash from 0x0800_0000
/// (512 KiB); SRAM1 80 KiB at 0x2000_0000, SRAM2 16 KiB at 0x2001_4000 and the CCM
/// SRAM's 32 KiB alias at 0x2001_8000 form 128 KiB of contiguous RAM ending at
/// 0x2000_0000 + 0x2_0000 = 0x2002_0000 (80 + 16 + 32 = 128 KiB = 0x2_0000).
const FLASH_START: u32 = 0x0800_0000;
const RAM_END: u32 = 0x2002_0000;

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
    assert_eq!(word(&bin, 0), RAM_END, "initial stack pointer = end of the G474's RAM");
    let reset = word(&bin, 4);
    assert_eq!(reset & 1, 1, "reset vector {reset:#010x} is not a Thumb address");
    let flash_end = FLASH_START + u32::try_from(flash).unwrap();
    assert!(
        (FLASH_START..flash_end).contains(&(reset & !1)),
        "reset vector {reset:#010x} outside the image {FLASH_START:#010x}..{flash_end:#010x}"
    );
}

/// `motorgen firmware --all [--board <board>]`: every motor's image is written into `dir`
/// (relative to `target/firmware/`), under 64 KiB with the G474's stack pointer, and a
/// flash line is printed for each; returns stderr (the board warnings).
fn every_motor_builds(board: Option<&str>) -> String {
    let mut args = vec!["--all"];
    args.extend(board.iter().flat_map(|b| ["--board", *b]));
    let out = firmware(&args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "motorgen firmware {args:?} failed:\n{stdout}\n{stderr}"
    );
    println!("{stdout}{stderr}");
    let mut dir = repo().join("target").join("firmware");
    if let Some(b) = board {
        dir = dir.join(b);
    }
    for stem in common::motor_stems() {
        let bin = std::fs::read(dir.join(format!("{stem}.bin"))).expect("the .bin is written");
        assert!(bin.len() < 64 * 1024, "{stem}: {} bytes", bin.len());
        assert_eq!(word(&bin, 0), RAM_END, "{stem}: initial stack pointer");
        assert!(
            stdout.contains(&format!("{stem}: flash {} bytes", bin.len())),
            "{stem}: no flash line for {} bytes in\n{stdout}",
            bin.len()
        );
    }
    stderr.into_owned()
}

/// `firmware --all` builds every motor on the default board into `target/firmware/`.
#[test]
fn every_motor_builds_on_the_default_board() {
    every_motor_builds(None);
}

/// Every motor builds on the second board, the NUCLEO-G474RE + X-NUCLEO-IHM08M1, into
/// `target/firmware/nucleo-g474re-ihm08m1/`; the motors its ±30.7 A / 63.2 V sensing
/// cannot serve are warned about at the board key (stderr), not refused.
#[test]
fn every_motor_builds_on_the_nucleo_ihm08m1_board() {
    let stderr = every_motor_builds(Some("nucleo-g474re-ihm08m1"));
    // Fischer's 600 V DC link is beyond the divider's 63.2 V: a warning at the key.
    assert!(
        stderr.contains("warning: fischer-ti085 on nucleo-g474re-ihm08m1:")
            && stderr.contains("`sensing.dc_link_divider`: the divider measures up to 63.2 V"),
        "{stderr}"
    );
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
    let stems = common::motor_stems();
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
