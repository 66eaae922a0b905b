//! Rendered Rust, C and Markdown of the seed motors against reviewed golden files,
//! rustfmt-cleanliness of the Rust output, and the C header compiled with
//! `cc -Wall -Werror` holding the same values as the JSON design.
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
    let text = std::fs::read_to_string(motor_tests::repo().join(&rel)).unwrap();
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
    let dir = motor_tests::repo().join("tests/golden");
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
    for (stem, _, _) in motor_tests::motors() {
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

#[test]
fn c_header_compiles_with_warnings_as_errors_and_holds_the_same_values() {
    let dir = tmp("c");
    for (stem, _, _) in motor_tests::motors() {
        let d = design(&stem);
        let header = Output::C.file_name(&stem);
        std::fs::write(dir.join(&header), render(&d, Output::C).unwrap()).unwrap();
        // A program that prints every constant, one value per line.
        let mut main = format!("#include <stdio.h>\n#include \"{header}\"\nint main(void) {{\n");
        let mut expected = Vec::new();
        let json = serde_json::to_value(&d).unwrap();
        for g in constants(&d) {
            for k in &g.constants {
                let name = format!("{}_{}", g.name.to_uppercase(), k.name);
                let fmt = if k.value.c_type == "float" { "%.9g" } else { "%lld" };
                let cast = if k.value.c_type == "float" {
                    "(double)"
                } else {
                    "(long long)"
                };
                if k.value.c_array.is_empty() {
                    writeln!(main, "  printf(\"{fmt}\\n\", {cast}{name});").unwrap();
                } else {
                    writeln!(main, "  for (unsigned i = 0; i < sizeof {name} / sizeof {name}[0]; i++) printf(\"{fmt}\\n\", {cast}{name}[i]);").unwrap();
                }
                let values = match json.pointer(&k.json_path) {
                    Some(serde_json::Value::Array(a)) => a.iter().map(|x| x.as_f64().unwrap()).collect(),
                    Some(serde_json::Value::Null) => vec![0.0],
                    Some(x) => vec![x.as_f64().unwrap()],
                    None => panic!("{stem}: {} has no JSON value", k.json_path),
                };
                expected.extend(values.into_iter().map(|v| (name.clone(), k.value.c_type == "float", v)));
            }
        }
        main.push_str("  return 0;\n}\n");
        let src = dir.join(format!("{}.c", stem.replace('-', "_")));
        let exe = dir.join(stem.replace('-', "_"));
        std::fs::write(&src, main).unwrap();
        let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
        let out = Command::new(&cc)
            .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-o"])
            .arg(&exe)
            .arg(&src)
            .output()
            .expect("a C compiler (cc) must be installed");
        assert!(out.status.success(), "{stem}: {}", String::from_utf8_lossy(&out.stderr));
        let run = Command::new(&exe).output().unwrap();
        let printed = String::from_utf8(run.stdout).unwrap();
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
