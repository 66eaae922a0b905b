//! `motorgen firmware` as a user runs it: the fischer-ti085 image is built into
//! `target/firmware/`, is a valid STM32G474 flash image and fits in 64 KiB; an unknown
//! stem and a bad spec are refused before anything is built or written.
//!
//! `CARGO_BIN_EXE_motorgen` exists only inside the codegen package, so the binary is
//! built here with cargo (in its own target directory: the outer `cargo test` holds
//! the lock of the default one) and run as a process.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// STM32G474RE memory map (RM0440 §2.2, Table 3 / §2.3): flash from 0x0800_0000
/// (512 KiB); SRAM1 80 KiB at 0x2000_0000, SRAM2 16 KiB at 0x2001_4000 and the CCM
/// SRAM's 32 KiB alias at 0x2001_8000 form 128 KiB of contiguous RAM ending at
/// 0x2000_0000 + 0x2_0000 = 0x2002_0000 (80 + 16 + 32 = 128 KiB = 0x2_0000).
const FLASH_START: u32 = 0x0800_0000;
const RAM_END: u32 = 0x2002_0000;

/// Builds `motorgen` once and returns its path.
fn motorgen_exe() -> &'static Path {
    static EXE: OnceLock<PathBuf> = OnceLock::new();
    EXE.get_or_init(|| {
        let repo = motor_tests::repo();
        let out = Command::new(env!("CARGO"))
            .args([
                "build",
                "--locked",
                "-p",
                "codegen",
                "--bin",
                "motorgen",
                "--message-format=json",
            ])
            .current_dir(&repo)
            .env("CARGO_TARGET_DIR", repo.join("target").join("motorgen-cli"))
            .output()
            .expect("cargo runs");
        assert!(
            out.status.success(),
            "building motorgen failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
            .filter(|m| m["reason"] == "compiler-artifact" && m["target"]["name"] == "motorgen")
            .find_map(|m| m["executable"].as_str().map(PathBuf::from))
            .expect("cargo reports the motorgen executable")
    })
}

/// Runs `motorgen firmware <args>` from the repository root; the firmware builds in the
/// target directory `tests/firmware.rs` also uses for the thumbv7em build.
fn firmware(args: &[&str]) -> Output {
    let repo = motor_tests::repo();
    Command::new(motorgen_exe())
        .arg("firmware")
        .args(args)
        .current_dir(&repo)
        .env("CARGO_TARGET_DIR", repo.join("target").join("firmware-target"))
        .env_remove("MOTOR")
        .env_remove("MOTORS_DIR")
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

    let dir = motor_tests::repo().join("target").join("firmware");
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

#[test]
fn unknown_stem_lists_the_motors_and_writes_nothing() {
    let out = firmware(&["no-such-motor"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(out.stdout.is_empty());
    assert!(stderr.contains("no motor `no-such-motor`"), "{stderr}");
    for (stem, _, _) in motor_tests::motors() {
        assert!(stderr.contains(&stem), "accepted stems should list {stem}:\n{stderr}");
    }
    let dir = motor_tests::repo().join("target").join("firmware");
    for ext in ["elf", "bin"] {
        assert!(!dir.join(format!("no-such-motor.{ext}")).exists());
    }
}

#[test]
fn bad_spec_fails_with_its_location_before_cargo_runs() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("firmware-bad-motors");
    std::fs::create_dir_all(&dir).unwrap();
    let good = std::fs::read_to_string(motor_tests::repo().join("motors/fischer-ti085.toml")).unwrap();
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
    let out_dir = motor_tests::repo().join("target").join("firmware");
    assert!(!out_dir.join("bad-image.elf").exists());
    assert!(!out_dir.join("bad-image.bin").exists());
}
