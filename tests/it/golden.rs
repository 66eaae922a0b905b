//! Rendered Rust, C and Markdown of the seed motors against reviewed golden files,
//! rustfmt-cleanliness of the Rust output, and the C header compiled as C99, C11
//! (`-pedantic -Wall -Wextra -Werror`) and C++17 holding the same values as the JSON
//! design, with several motors' headers in one translation unit.
//!
//! To accept an intended change of the output: `UPDATE_GOLDEN=1 cargo test -p motor-tests --test golden`,
//! then review `git diff tests/golden/`.

use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use codegen::constants::constants;
use codegen::render::{Output, render};

const SEEDS: [&str; 3] = ["fischer-ti085", "unimotor-142umd300", "chalmers-hev50"];

fn design(stem: &str) -> codegen::Design {
    let rel = format!("motors/{stem}.toml");
    let text = std::fs::read_to_string(motor_test_support::repo().join(&rel)).unwrap();
    codegen::design_source(&rel, &text).unwrap()
}

fn tmp(sub: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(sub);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn rendered_outputs_match_golden_files() {
    let update = std::env::var_os("UPDATE_GOLDEN").is_some();
    let dir = motor_test_support::repo().join("tests/golden");
    let mut stale = Vec::new();
    for stem in SEEDS {
        let d = design(stem);
        for out in Output::ALL {
            let text = render(&d, out).unwrap();
            assert_eq!(text, render(&d, out).unwrap(), "rendering is not deterministic");
            let path = dir.join(out.file_name(stem));
            if update {
                std::fs::write(&path, &text).unwrap();
            } else if std::fs::read_to_string(&path).ok().as_deref() != Some(text.as_str()) {
                stale.push(path.display().to_string());
            }
        }
    }
    assert!(
        stale.is_empty(),
        "output differs from golden files {stale:?}; if intended: UPDATE_GOLDEN=1 cargo test -p motor-tests --test golden"
    );
}

#[test]
fn rust_output_is_rustfmt_clean() {
    // Checked with rustfmt's default configuration: an empty rustfmt.toml beside the file
    // shadows the repository's own (max_width = 120), which rustfmt would otherwise find.
    let dir = tmp("rustfmt");
    std::fs::write(dir.join("rustfmt.toml"), "").unwrap();
    for (stem, _, _) in motor_test_support::motors() {
        let path = dir.join(Output::Rust.file_name(&stem));
        std::fs::write(&path, render(&design(&stem), Output::Rust).unwrap()).unwrap();
        let out = Command::new("rustfmt")
            .args(["--edition", "2024", "--check"])
            .arg(&path)
            .current_dir(&dir)
            .output()
            .expect("rustfmt (rustup component) must be installed");
        assert!(
            out.status.success(),
            "{stem}: not rustfmt-clean:\n{}",
            String::from_utf8_lossy(&out.stdout)
        );
    }
}

/// The language modes every header must compile in, warnings as errors:
/// (compiler, environment variable naming another one, flags).
const C_MODES: [(&str, &str, &str); 3] = [
    ("cc", "CC", "-std=c99"),
    ("cc", "CC", "-std=c11"),
    ("c++", "CXX", "-std=c++17"),
];

/// Compiles `src` to `exe` in every mode of [`C_MODES`] and returns each run's stdout.
fn compile_and_run(src: &Path, exe: &Path) -> Vec<String> {
    let mut outputs = Vec::new();
    for (default, var, std) in C_MODES {
        let compiler = std::env::var(var).unwrap_or_else(|_| default.into());
        let mut cmd = Command::new(&compiler);
        if default == "c++" {
            // The source is C; compile it as C++ (the header must work there too).
            cmd.args(["-x", "c++"]);
        }
        let out = cmd
            .args([std, "-pedantic", "-Wall", "-Wextra", "-Werror", "-o"])
            .arg(exe)
            .arg(src)
            .output()
            .unwrap_or_else(|e| panic!("{compiler} ({var}): {e}; install gcc and g++ (apt-get install gcc g++)"));
        assert!(
            out.status.success(),
            "{} {std}: {}",
            src.display(),
            String::from_utf8_lossy(&out.stderr)
        );
        let run = Command::new(exe).output().unwrap();
        assert!(run.status.success(), "{} {std}: exit {}", exe.display(), run.status);
        outputs.push(String::from_utf8(run.stdout).unwrap());
    }
    outputs
}

/// The JSON value(s) of a constant (null reads as 0, as documented in the constant).
fn json_values(json: &serde_json::Value, pointer: &str, len: Option<usize>) -> Vec<f64> {
    match json.pointer(pointer) {
        Some(serde_json::Value::Array(a)) => a.iter().map(|x| x.as_f64().unwrap()).collect(),
        // A result the design does not have: zero, as many as the constant has entries (a
        // fixed-length table the firmware reads, e.g. the 17 MTPA points without ψ_M).
        Some(serde_json::Value::Null) => vec![0.0; len.unwrap_or(1)],
        Some(x) => vec![x.as_f64().unwrap()],
        None => panic!("{pointer} has no JSON value"),
    }
}

#[test]
fn c_header_compiles_as_c99_c11_and_cxx17_and_holds_the_same_values() {
    let dir = tmp("c");
    for (stem, _, _) in motor_test_support::motors() {
        let d = design(&stem);
        let prefix = codegen::render::c_prefix(&d.spec_file);
        let header = Output::C.file_name(&stem);
        std::fs::write(dir.join(&header), render(&d, Output::C).unwrap()).unwrap();
        // A program that prints every constant, one value per line.
        let mut main = format!("#include <stdio.h>\n#include \"{header}\"\nint main(void) {{\n");
        let mut expected = Vec::new();
        let json = serde_json::to_value(&d).unwrap();
        for g in constants(&d) {
            for k in &g.constants {
                let name = format!("{prefix}_{}_{}", g.name.to_uppercase(), k.name);
                let float = k.value.c_type == "float";
                let (fmt, cast) = if float {
                    ("%.9g", "(double)")
                } else {
                    ("%lld", "(long long)")
                };
                match k.value.c_len {
                    None => writeln!(main, "  printf(\"{fmt}\\n\", {cast}{name});").unwrap(),
                    Some(_) => writeln!(
                        main,
                        "  for (unsigned i = 0; i < {name}_LEN; i++) printf(\"{fmt}\\n\", {cast}{name}[i]);"
                    )
                    .unwrap(),
                }
                let values = json_values(&json, &k.json_path, k.value.c_len);
                if let Some(n) = k.value.c_len {
                    assert_eq!(n, values.len(), "{stem}: {name}_LEN");
                }
                expected.extend(values.into_iter().map(|v| (name.clone(), float, v)));
            }
        }
        main.push_str("  return 0;\n}\n");
        let src = dir.join(format!("{}.c", stem.replace('-', "_")));
        std::fs::write(&src, main).unwrap();
        for printed in compile_and_run(&src, &dir.join(stem.replace('-', "_"))) {
            let lines: Vec<&str> = printed.lines().collect();
            assert_eq!(lines.len(), expected.len(), "{stem}");
            for (line, (name, is_float, want)) in lines.iter().zip(&expected) {
                if *is_float {
                    let got: f64 = line.parse().unwrap();
                    assert_eq!(
                        (got as f32).to_bits(),
                        (*want as f32).to_bits(),
                        "{stem}: {name} = {got}, JSON {want}"
                    );
                } else {
                    assert_eq!(line.parse::<i64>().unwrap() as f64, *want, "{stem}: {name}");
                }
            }
        }
    }
}

/// Every motor's header in one translation unit: each keeps its own values (per-motor
/// include guard and prefix), and the integer constants work where C demands constant
/// expressions — `#if`, array sizes, `case` labels — in C99, C11 and C++17.
#[test]
fn several_motor_headers_share_a_translation_unit() {
    let dir = tmp("c-many");
    let motors = motor_test_support::motors();
    assert!(motors.len() >= 2, "needs two motors");
    let mut src = String::from("#include <stdio.h>\n");
    let mut body = String::new();
    let mut expected = Vec::new();
    for (i, (stem, _, _)) in motors.iter().enumerate() {
        let d = design(stem);
        let p = codegen::render::c_prefix(&d.spec_file);
        let header = Output::C.file_name(stem);
        std::fs::write(dir.join(&header), render(&d, Output::C).unwrap()).unwrap();
        writeln!(src, "#include \"{header}\"").unwrap();
        // Preprocessor arithmetic, an array size and a case label.
        writeln!(
            src,
            "#if {p}_FILTER_ORDER + 1 != {p}_FILTER_TAPS_Q15_LEN\n#error \"{p}: order + 1 != taps\"\n#endif\n\
             static int16_t copy_{i}[{p}_FILTER_TAPS_Q15_LEN];\n\
             static int pole_pairs_{i}(unsigned long n) {{\n  switch (n) {{\n  case {p}_OBSERVER_MOTOR_POLE_PAIRS: return 1;\n  default: return 0;\n  }}\n}}"
        )
        .unwrap();
        writeln!(
            body,
            "  for (unsigned k = 0; k < sizeof copy_{i} / sizeof copy_{i}[0]; k++) copy_{i}[k] = {p}_FILTER_TAPS_Q15[k];\n  \
             printf(\"%d %u %d %d\\n\", pole_pairs_{i}({p}_OBSERVER_MOTOR_POLE_PAIRS), (unsigned)(sizeof copy_{i} / sizeof copy_{i}[0]), (int)copy_{i}[0], (int)(-{p}_OBSERVER_LEAD_Q16 < 0));"
        )
        .unwrap();
        expected.push(format!(
            "1 {} {} {}",
            d.fir.taps_q15.len(),
            d.fir.taps_q15[0],
            i32::from(-d.angle_observer.lead_q16 < 0)
        ));
    }
    src.push_str("int main(void) {\n");
    src.push_str(&body);
    src.push_str("  return 0;\n}\n");
    let path = dir.join("all_motors.c");
    std::fs::write(&path, src).unwrap();
    for printed in compile_and_run(&path, &dir.join("all_motors")) {
        assert_eq!(printed.lines().collect::<Vec<_>>(), expected);
    }
    // The seeds differ where it shows: one header's values did not shadow another's.
    let firsts: std::collections::BTreeSet<&String> = expected.iter().collect();
    assert!(firsts.len() > 1, "all motors print the same figures: {expected:?}");
}
