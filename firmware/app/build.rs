//! Generates `$OUT_DIR/motor.rs` for the motor named by `MOTOR` (a file stem in
//! `motors/`, default `fischer-ti085`) through the same `codegen` functions as
//! `motorgen`. `MOTORS_DIR` overrides the spec directory. A bad spec fails the
//! build with the CLI's located message, not a panic.

use std::path::{Path, PathBuf};

const DEFAULT_MOTOR: &str = "fischer-ti085";

fn fail(message: &str) {
    for line in message.lines() {
        println!("cargo::error={line}");
    }
}

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default());
    let repo = manifest.join("../..");
    println!("cargo::rerun-if-env-changed=MOTOR");
    println!("cargo::rerun-if-env-changed=MOTORS_DIR");
    let motors = std::env::var_os("MOTORS_DIR").map_or_else(|| repo.join("motors"), PathBuf::from);
    let templates = repo.join("templates");
    println!("cargo::rerun-if-changed={}", motors.display());
    println!("cargo::rerun-if-changed={}", templates.display());
    if let Ok(entries) = std::fs::read_dir(&templates) {
        for e in entries.flatten() {
            println!("cargo::rerun-if-changed={}", e.path().display());
        }
    }
    let stem = std::env::var("MOTOR").unwrap_or_else(|_| DEFAULT_MOTOR.to_string());
    let spec = motors.join(format!("{stem}.toml"));
    println!("cargo::rerun-if-changed={}", spec.display());
    let known = || {
        let mut v: Vec<String> = std::fs::read_dir(&motors)
            .map(|rd| {
                rd.flatten()
                    .filter_map(|e| {
                        let p = e.path();
                        (p.extension().is_some_and(|x| x == "toml"))
                            .then(|| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
                    })
                    .flatten()
                    .collect()
            })
            .unwrap_or_default();
        v.sort();
        v.join(", ")
    };
    let text = match std::fs::read(&spec) {
        Ok(bytes) => match String::from_utf8(bytes) {
            Ok(t) => t,
            Err(e) => {
                return fail(&format!(
                    "{}: the file is not valid UTF-8 (byte {})",
                    spec.display(),
                    e.utf8_error().valid_up_to()
                ));
            }
        },
        Err(e) => {
            return fail(&format!(
                "MOTOR={stem}: cannot read {}: {e}\n  accepted: MOTOR set to one of: {}",
                spec.display(),
                known()
            ));
        }
    };
    let shown = format!("motors/{stem}.toml");
    let design = match codegen::design_source(&shown, &text) {
        Ok(d) => d,
        Err(e) => return fail(&e.to_string()),
    };
    let code = match codegen::render::render(&design, codegen::render::Output::Rust) {
        Ok(c) => c,
        Err(e) => return fail(&e.to_string()),
    };
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap_or_default()).join("motor.rs");
    // Write only when the bytes change, so an unchanged design causes no rebuild.
    if std::fs::read(&out).ok().as_deref() != Some(code.as_bytes())
        && let Err(e) = std::fs::write(&out, code)
    {
        fail(&format!("cannot write {}: {e}", Path::new(&out).display()));
    }
}
