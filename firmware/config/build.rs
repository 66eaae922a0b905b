//! Generates `$OUT_DIR/motor.rs` for the motor named by `MOTOR` (a file stem in
//! `motors/`, default `fischer-ti085`) through the same `codegen` functions as
//! `motorgen`. `MOTORS_DIR` overrides the spec directory. A bad spec fails the
//! build with the CLI's located message, not a panic.
//! (Linker setup for the image is in `../app/build.rs`.)

use std::path::{Path, PathBuf};

const DEFAULT_MOTOR: &str = "fischer-ti085";

fn fail(message: &str) {
    for line in message.lines() {
        println!("cargo::error={line}");
    }
}

fn main() {
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").unwrap_or_default());
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
    write(&out_dir.join("motor.rs"), &code);
    write(&out_dir.join("design_extra.rs"), &design_extra(&design));
}

/// Writes through codegen's [`codegen::files::write_if_changed`] (an unchanged design
/// causes no rebuild); a failure fails the build with the path.
fn write(out: &Path, code: &str) {
    if let Err(e) = codegen::files::write_if_changed(out, code.as_bytes()) {
        fail(&format!("cannot write {}: {e}", out.display()));
    }
}

/// Design values the board needs that codegen's constant list does not carry yet
/// (reported to be added there): the observer error architecture the gains are
/// scaled for, the resolver offset and dead time if the spec gives them, the ADC
/// SMP code if the spec has an `[adc]` section.
fn design_extra(d: &codegen::design::Design) -> String {
    use codegen::spec::ObserverError;
    let error = match d.angle_observer.error {
        ObserverError::TrigIdentity => "TrigIdentity",
        ObserverError::Atan2 => "Atan2",
    };
    // θ_off [rad] → π-scaled Q1.31 (4.20), wrapped into one turn: the design's value
    // (motor_control::angle::from_radians_f64), 0 when the spec gives none.
    let offset = d.angle_observer.resolver_offset_q31.unwrap_or(0);
    let opt = |v: Option<String>| v.map_or_else(|| "None".to_string(), |v| format!("Some({v})"));
    let offset_doc = d.angle_observer.resolver_offset_rad.map_or_else(
        || "not in the spec: 0".to_string(),
        |rad| format!("{rad:.6} rad = {:.4}°, wrapped into ±π, ·2^31/π", rad.to_degrees()),
    );
    let dead_ns = d.drive.dead_time_s.map(|s| (s * 1e9).round() as u32);
    let dead = opt(dead_ns.map(|ns| ns.to_string()));
    let dead_doc = dead_ns.map_or_else(|| "not in the spec".to_string(), |ns| format!("{ns} ns"));
    let smp = opt(d.adc.sample_time.as_ref().map(|t| t.smp_code.to_string()));
    let smp_doc = d.adc.sample_time.as_ref().map_or_else(
        || "no `[adc]` section".to_string(),
        |t| {
            format!(
                "{} ADC cycles = {:.1} ns ≥ the settling time {:.1} ns",
                t.cycles,
                t.sample_time_s * 1e9,
                t.min_sample_time_s * 1e9
            )
        },
    );
    format!(
        "// @generated by firmware/config/build.rs from {spec}. Do not edit.\n\
         /// Observer error architecture the gains `motor::observer::KP`/`KI` are scaled for\n\
         /// (spec `[angle_observer] error`), thesis A (4.8)–(4.10), (4.22).\n\
         pub const OBSERVER_ERROR: motor_control::ato::ObserverError = motor_control::ato::ObserverError::{error};\n\
         /// Resolver offset θ_off (4.5), π-scaled Q1.31: spec `[resolver] offset`, else 0\n\
         /// (identified at commissioning, thesis A §6.3 (6.9)). θ_off = {offset_doc}.\n\
         pub const RESOLVER_OFFSET_Q31: i32 = {offset};\n\
         /// Inverter dead time \\[ns\\] from spec `[drive] dead_time`, if given: {dead_doc}.\n\
         pub const DEAD_TIME_NS: Option<u32> = {dead};\n\
         /// ADC_SMPR code chosen by the settling rule, thesis A (7.2), (7.4), if the spec has\n\
         /// `[adc]`: {smp_doc}.\n\
         pub const ADC_SMP_CODE: Option<u8> = {smp};\n",
        spec = d.spec_file,
    )
}
