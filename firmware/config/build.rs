//! Generates `$OUT_DIR/motor.rs` for the motor named by `MOTOR` (a file stem in
//! `motors/`, default `fischer-ti085`) on the board named by `BOARD` (a file stem in
//! `boards/`, default `motorgen-reference`) through the same `codegen` functions as
//! `motorgen` (`codegen::design_with_board` → the Rust template): the motor's constants
//! and the `board` group. `MOTORS_DIR` and `BOARDS_DIR` override the folders. A bad
//! spec or board file fails the build with the CLI's located message, not a panic; the
//! board's warnings for this motor (a current range below its peak current, …) are
//! printed as cargo warnings.
//! (Linker setup for the image is in `../app/build.rs`.)

use std::path::{Path, PathBuf};

const DEFAULT_MOTOR: &str = "fischer-ti085";

fn fail(message: &str) {
    for line in message.lines() {
        println!("cargo::error={line}");
    }
}

/// The `*.toml` stems of `dir`, sorted and comma-separated (for "accepted:" lines).
fn stems(dir: &Path) -> String {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.flatten()
                .filter_map(|e| {
                    let p = e.path();
                    (p.extension().is_some_and(|x| x == "toml"))
                        .then(|| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
                        .flatten()
                })
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v.join(", ")
}

/// The text of `<dir>/<stem>.toml` named by the variable `var`, or a located failure.
fn read(var: &str, dir: &Path, stem: &str) -> Option<String> {
    let path = dir.join(format!("{stem}.toml"));
    println!("cargo::rerun-if-changed={}", path.display());
    match std::fs::read(&path) {
        Ok(bytes) => match String::from_utf8(bytes) {
            Ok(t) => Some(t),
            Err(e) => {
                fail(&format!(
                    "{}: the file is not valid UTF-8 (byte {})",
                    path.display(),
                    e.utf8_error().valid_up_to()
                ));
                None
            }
        },
        Err(e) => {
            fail(&format!(
                "{var}={stem}: cannot read {}: {e}\n  accepted: {var} set to one of: {}",
                path.display(),
                stems(dir)
            ));
            None
        }
    }
}

fn main() {
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").unwrap_or_default());
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default());
    let repo = manifest.join("../..");
    for var in ["MOTOR", "MOTORS_DIR", "BOARD", "BOARDS_DIR"] {
        println!("cargo::rerun-if-env-changed={var}");
    }
    let motors = std::env::var_os("MOTORS_DIR").map_or_else(|| repo.join("motors"), PathBuf::from);
    let boards = std::env::var_os("BOARDS_DIR").map_or_else(|| repo.join("boards"), PathBuf::from);
    let templates = repo.join("templates");
    for dir in [&motors, &boards, &templates] {
        println!("cargo::rerun-if-changed={}", dir.display());
    }
    if let Ok(entries) = std::fs::read_dir(&templates) {
        for e in entries.flatten() {
            println!("cargo::rerun-if-changed={}", e.path().display());
        }
    }
    let motor = std::env::var("MOTOR").unwrap_or_else(|_| DEFAULT_MOTOR.to_string());
    let board = std::env::var("BOARD").unwrap_or_else(|_| codegen::board::DEFAULT_BOARD.to_string());
    let (Some(spec), Some(board_text)) = (read("MOTOR", &motors, &motor), read("BOARD", &boards, &board)) else {
        return;
    };
    let design = match codegen::design_with_board(
        &format!("motors/{motor}.toml"),
        &spec,
        &format!("boards/{board}.toml"),
        &board_text,
    ) {
        Ok(d) => d,
        Err(e) => return fail(&e.to_string()),
    };
    // What does not fit between the board and the motor (the motor's own design notes
    // are `motorgen design`'s to print).
    for w in design.board.iter().flat_map(|b| &b.warnings) {
        println!("cargo::warning={w}");
    }
    let code = match codegen::render::render(&design, codegen::render::Output::Rust) {
        Ok(c) => c,
        Err(e) => return fail(&e.to_string()),
    };
    write(&out_dir.join("motor.rs"), &code);
}

/// Writes through codegen's [`codegen::files::write_if_changed`] (an unchanged design
/// causes no rebuild); a failure fails the build with the path.
fn write(out: &Path, code: &str) {
    if let Err(e) = codegen::files::write_if_changed(out, code.as_bytes()) {
        fail(&format!("cannot write {}: {e}", out.display()));
    }
}
