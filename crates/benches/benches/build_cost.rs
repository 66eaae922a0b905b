//! Build-cost benchmark (a bench binary, `harness = false`):
//!
//! 1. the compile time `motor_constants!` adds: a scratch crate whose only item is the
//!    macro call for one seed motor, against the same crate `include!`-ing the
//!    template-rendered module (identical tokens), each rebuilt after touching its
//!    `lib.rs`; the difference is the macro's expansion cost (spec parse, design with
//!    FIR, render, tokenise);
//! 2. the incremental rebuild of the firmware image (`motor-firmware`, thumbv7em, release)
//!    after touching `motors/fischer-ti085.toml`: the build script re-designs the motor
//!    and the crate recompiles against the new constants.
//!
//! Run with `cargo bench -p motor-benches --bench build_cost`. Each figure is the median of
//! [`RUNS`] timed builds after one warm-up build; the machine's load shows in the spread,
//! which is printed too.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant, SystemTime};

use codegen::render::{Output, render};

/// Timed builds per figure.
const RUNS: usize = 5;

fn cargo(dir: &Path, target_dir: &Path, args: &[&str]) -> Duration {
    let t = Instant::now();
    let out = Command::new(env!("CARGO"))
        .args(args)
        .current_dir(dir)
        .env("CARGO_TARGET_DIR", target_dir)
        .output()
        .expect("cargo runs");
    let elapsed = t.elapsed();
    assert!(
        out.status.success(),
        "cargo {args:?} in {} failed:\n{}",
        dir.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    elapsed
}

fn touch(path: &Path) {
    let f = std::fs::File::options().append(true).open(path).expect("file to touch");
    f.set_modified(SystemTime::now()).expect("set mtime");
}

/// (median, min, max) of `RUNS` rebuilds, each after touching `file`.
fn rebuilds(dir: &Path, target_dir: &Path, args: &[&str], file: &Path) -> (Duration, Duration, Duration) {
    cargo(dir, target_dir, args);
    let mut t: Vec<Duration> = (0..RUNS)
        .map(|_| {
            touch(file);
            cargo(dir, target_dir, args)
        })
        .collect();
    t.sort();
    (t[RUNS / 2], t[0], t[RUNS - 1])
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// A scratch crate `name` under `root` with `lib` as its `src/lib.rs`.
fn scratch_crate(root: &Path, name: &str, lib: &str) -> PathBuf {
    let repo = motor_test_support::repo().canonicalize().expect("repo");
    let dir = root.join(name);
    std::fs::create_dir_all(dir.join("src")).unwrap();
    let manifest = format!(
        "[package]\nname = \"{name}\"\nversion = \"0.0.0\"\nedition = \"2024\"\npublish = false\n\n\
         [dependencies]\nmotor-macros = {{ path = \"{m}\" }}\nfixed = \"1\"\n\n[workspace]\n\n\
         [profile.dev.package.\"*\"]\nopt-level = 2\n\n[profile.dev.build-override]\nopt-level = 2\n",
        m = repo.join("macros").display()
    );
    std::fs::write(dir.join("Cargo.toml"), manifest).unwrap();
    // Same dependency versions as the workspace, resolved offline.
    std::fs::copy(repo.join("Cargo.lock"), dir.join("Cargo.lock")).unwrap();
    let lib_rs = dir.join("src/lib.rs");
    if std::fs::read_to_string(&lib_rs).ok().as_deref() != Some(lib) {
        std::fs::write(&lib_rs, lib).unwrap();
    }
    dir
}

fn main() {
    let repo = motor_test_support::repo().canonicalize().expect("repo");
    let root = repo.join("target/build-cost");
    let target_dir = root.join("target");
    let build = ["build", "--offline", "--quiet"];

    println!("motor_constants! expansion cost (median of {RUNS} rebuilds after touching lib.rs, min–max):");
    for (stem, rel, text) in motor_test_support::motors() {
        let ident = stem.replace('-', "_");
        let design = codegen::design_source(&rel, &text).expect("seed motor designs");
        let rendered = render(&design, Output::Rust).expect("renders");
        let spec = repo.join(&rel);
        let with_macro = scratch_crate(
            &root,
            &format!("cost-macro-{ident}"),
            &format!(
                "#![allow(missing_docs)]\nmotor_macros::motor_constants!(\"{}\");\n",
                spec.display()
            ),
        );
        let with_include = scratch_crate(
            &root,
            &format!("cost-include-{ident}"),
            "#![allow(missing_docs)]\ninclude!(\"rendered.rs\");\n",
        );
        std::fs::write(with_include.join("src/rendered.rs"), &rendered).unwrap();
        let (m, m_lo, m_hi) = rebuilds(&with_macro, &target_dir, &build, &with_macro.join("src/lib.rs"));
        let (i, i_lo, i_hi) = rebuilds(&with_include, &target_dir, &build, &with_include.join("src/lib.rs"));
        // In-process cost of what the macro runs, for comparison (median of 21).
        let mut inproc: Vec<Duration> = (0..21)
            .map(|_| {
                let t = Instant::now();
                let d = codegen::design_source(&rel, &text).unwrap();
                let code = render(&d, Output::Rust).unwrap();
                std::hint::black_box(code.parse::<proc_macro2::TokenStream>().unwrap());
                t.elapsed()
            })
            .collect();
        inproc.sort();
        println!(
            "  {stem:<22} macro {:7.1} ms ({:.1}–{:.1})   include! {:7.1} ms ({:.1}–{:.1})   added {:6.1} ms   \
             design+render+tokenise in-process {:.2} ms",
            ms(m),
            ms(m_lo),
            ms(m_hi),
            ms(i),
            ms(i_lo),
            ms(i_hi),
            ms(m) - ms(i),
            ms(inproc[10]),
        );
    }

    println!("firmware incremental rebuild after touching motors/fischer-ti085.toml (thumbv7em, release):");
    let firmware = repo.join("firmware");
    let fw_args = [
        "build",
        "--offline",
        "--quiet",
        "--release",
        "-p",
        "motor-firmware",
        "--target",
        "thumbv7em-none-eabihf",
    ];
    let (f, f_lo, f_hi) = rebuilds(
        &firmware,
        // Its own target directory, so a concurrent build in firmware/target cannot hold the lock.
        &root.join("firmware-target"),
        &fw_args,
        &repo.join("motors/fischer-ti085.toml"),
    );
    println!("  median {:.0} ms ({:.0}–{:.0})", ms(f), ms(f_lo), ms(f_hi));
}
