//! `motorgen identify`'s write-back under concurrency and faults, as a user meets them on
//! a shared bench machine: two identifications of one spec at once, read-only, 0600,
//! symlinked and hard-linked specs, CRLF and BOM files, inline tables, a bad `--date`,
//! an update that would break the design, a writer killed mid-write, and `--dry-run` on
//! a spec of 40,000 comment lines.

#![cfg(unix)]

use crate::common::{EXIT_IO, SIGXFSZ, repo, text_of};
use motor_commission::synthetic::step_recording;

use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn fischer_text() -> String {
    std::fs::read_to_string(repo().join("motors/fischer-ti085.toml")).unwrap()
}

/// A fresh directory with a copy of the Fischer spec (`fischer.toml`, text `spec`) and
/// a d-axis and a q-axis step recording of a "measured" motor: d with R = 0.130 Ω and
/// L_d = 1.05 × 0.393 mH, q with R = 0.140 Ω and L_q = 1.10 × 0.393 mH (different R, so
/// `phase_resistance` tells which axis was written last).
struct Bench {
    dir: PathBuf,
    spec: PathBuf,
    d: String,
    q: String,
}

impl Bench {
    fn new(name: &str, spec: &str) -> Bench {
        let dir = crate::common::tmp("writeback", name);
        let path = dir.join("fischer.toml");
        std::fs::write(&path, spec).unwrap();
        let d = codegen::design_source("fischer.toml", &fischer_text()).unwrap();
        let rec = |axis: &str, r: f64, l: f64| {
            let f = dir.join(format!("{axis}.csv"));
            std::fs::write(&f, step_recording(&d, axis, r, l, 7)).unwrap();
            f.display().to_string()
        };
        let (d_csv, q_csv) = (rec("d", 0.130, 1.05 * 0.393e-3), rec("q", 0.140, 1.10 * 0.393e-3));
        Bench {
            dir,
            spec: path,
            d: d_csv,
            q: q_csv,
        }
    }

    /// `motorgen identify step <spec> --axis <axis> --csv <axis>.csv <extra>`, with
    /// `--date 2025-03-14` unless `extra` has a date.
    fn identify(&self, spec: &Path, axis: &str, extra: &[&str]) -> Command {
        let mut c = Command::new(env!("CARGO_BIN_EXE_motorgen"));
        let csv = if axis == "d" { &self.d } else { &self.q };
        c.args(["identify", "step"])
            .arg(spec)
            .args(["--axis", axis, "--csv", csv])
            .args(extra);
        if !extra.contains(&"--date") {
            c.args(["--date", "2025-03-14"]);
        }
        c
    }

    fn run(&self, spec: &Path, axis: &str, extra: &[&str]) -> Output {
        self.identify(spec, axis, extra).output().unwrap()
    }

    fn text(&self) -> String {
        std::fs::read_to_string(&self.spec).unwrap()
    }

    /// Temporary files left in the directory.
    fn leftovers(&self) -> Vec<String> {
        crate::common::temporaries(&self.dir)
    }
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", text_of(o));
}

/// The 1-based line of the first occurrence of `needle` in `text`.
fn line_of(text: &str, needle: &str) -> usize {
    text[..text.find(needle).unwrap_or_else(|| panic!("{needle:?} not in\n{text}"))]
        .matches('\n')
        .count()
        + 1
}

/// Two identifications of one spec at once (the d and the q axis, as a bench script
/// starts them), TRIALS times (env `MOTORGEN_WRITEBACK_TRIALS`, default 25): both exit
/// 0 and print "wrote", and the spec is byte for byte what running them one after the
/// other gives, in one order or the other, so both axes' values are on disk; the
/// spec's `source` (and `phase_resistance`, which each axis writes) name the process
/// that wrote last. No temporary file is left.
#[test]
fn concurrent_identifications_lose_nothing() {
    let b = Bench::new("concurrent", &fischer_text());
    let sequential = |first: &str, second: &str| {
        std::fs::write(&b.spec, fischer_text()).unwrap();
        ok(&b.run(&b.spec, first, &[]));
        ok(&b.run(&b.spec, second, &[]));
        b.text()
    };
    let (d_then_q, q_then_d) = (sequential("d", "q"), sequential("q", "d"));
    assert_ne!(d_then_q, q_then_d);
    for t in [&d_then_q, &q_then_d] {
        assert!(
            t.contains("d_inductance = \"0.41") && t.contains("q_inductance = \"0.43"),
            "{t}"
        );
    }
    assert!(d_then_q.contains("phase_resistance = \"0.14") && d_then_q.contains("step d: d.csv; step q: q.csv"));
    assert!(q_then_d.contains("phase_resistance = \"0.13") && q_then_d.contains("step q: q.csv; step d: d.csv"));
    let trials: usize = std::env::var("MOTORGEN_WRITEBACK_TRIALS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(25);
    let (mut q_last, mut d_last) = (0, 0);
    for trial in 0..trials {
        std::fs::write(&b.spec, fischer_text()).unwrap();
        // Alternate which process starts first.
        let order = if trial % 2 == 0 { ["d", "q"] } else { ["q", "d"] };
        let children: Vec<_> = order
            .iter()
            .map(|axis| {
                b.identify(&b.spec, axis, &[])
                    .stdout(std::process::Stdio::piped())
                    .stderr(std::process::Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for (axis, child) in order.iter().zip(children) {
            let o = child.wait_with_output().unwrap();
            ok(&o);
            let stdout = String::from_utf8_lossy(&o.stdout);
            assert!(
                stdout.contains(&format!("wrote [motor.identified] phase_resistance, {axis}_inductance")),
                "trial {trial}: {}",
                text_of(&o)
            );
        }
        let t = b.text();
        if t == d_then_q {
            q_last += 1;
        } else if t == q_then_d {
            d_last += 1;
        } else {
            panic!("trial {trial}: the spec is neither d-then-q nor q-then-d:\n{t}");
        }
        assert!(b.leftovers().is_empty(), "{:?}", b.leftovers());
    }
    eprintln!("{trials} trials: q written last {q_last} times, d last {d_last} times; no update lost");
}

/// Modes are kept (0600, 0640); a read-only spec (0444: no write bit, refused even for
/// root, who could write it) is refused with an I/O error naming it, and stays as it
/// was; `--dry-run` still shows the change.
#[test]
fn modes_are_kept_and_read_only_specs_refused() {
    let b = Bench::new("modes", &fischer_text());
    for mode in [0o600, 0o640] {
        std::fs::write(&b.spec, fischer_text()).unwrap();
        std::fs::set_permissions(&b.spec, std::fs::Permissions::from_mode(mode)).unwrap();
        ok(&b.run(&b.spec, "q", &[]));
        assert!(b.text().contains("[motor.identified]"));
        let m = std::fs::metadata(&b.spec).unwrap().mode() & 0o7777;
        assert_eq!(m, mode, "mode {m:o} after writing a {mode:o} spec");
    }
    std::fs::write(&b.spec, fischer_text()).unwrap();
    std::fs::set_permissions(&b.spec, std::fs::Permissions::from_mode(0o444)).unwrap();
    let o = b.run(&b.spec, "q", &[]);
    assert_eq!(o.status.code(), Some(EXIT_IO), "{}", text_of(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&b.spec.display().to_string()) && err.contains("read-only"),
        "{err}"
    );
    assert_eq!(b.text(), fischer_text());
    assert_eq!(std::fs::metadata(&b.spec).unwrap().mode() & 0o7777, 0o444);
    let o = b.run(&b.spec, "q", &["--dry-run"]);
    ok(&o);
    assert!(String::from_utf8_lossy(&o.stdout).contains("+"));
    assert!(b.leftovers().is_empty(), "{:?}", b.leftovers());
}

/// A symlinked spec is written through: the link stays a link and its target holds the
/// identified values. A hard-linked spec is replaced by a new file (what keeps the
/// write atomic): the command warns, the other name keeps the old text.
#[test]
fn symlinks_are_written_through_and_hard_links_reported() {
    let b = Bench::new("links", &fischer_text());
    let real_dir = b.dir.join("real");
    std::fs::create_dir_all(&real_dir).unwrap();
    let target = real_dir.join("motor.toml");
    std::fs::write(&target, fischer_text()).unwrap();
    let link = b.dir.join("link.toml");
    std::os::unix::fs::symlink("real/motor.toml", &link).unwrap();
    ok(&b.run(&link, "q", &[]));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert_eq!(std::fs::read_link(&link).unwrap(), Path::new("real/motor.toml"));
    assert!(
        std::fs::read_to_string(&target)
            .unwrap()
            .contains("q_inductance = \"0.43")
    );
    let in_real: Vec<_> = std::fs::read_dir(&real_dir).unwrap().collect();
    assert_eq!(in_real.len(), 1, "{in_real:?}");

    let other = b.dir.join("other-name.toml");
    std::fs::write(&b.spec, fischer_text()).unwrap();
    std::fs::hard_link(&b.spec, &other).unwrap();
    let o = b.run(&b.spec, "q", &[]);
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("warning:") && err.contains("2 hard links"), "{err}");
    assert!(b.text().contains("q_inductance"));
    assert_eq!(std::fs::read_to_string(&other).unwrap(), fischer_text());
    assert_eq!(std::fs::metadata(&b.spec).unwrap().nlink(), 1);
}

/// A CRLF spec with a UTF-8 byte-order mark is written exactly as the LF spec is,
/// with CRLF line endings and the BOM kept.
#[test]
fn crlf_and_bom_are_kept() {
    let b = Bench::new("crlf", &fischer_text());
    ok(&b.run(&b.spec, "q", &[]));
    let lf = b.text();
    let crlf_spec = format!("\u{feff}{}", fischer_text().replace('\n', "\r\n"));
    std::fs::write(&b.spec, &crlf_spec).unwrap();
    ok(&b.run(&b.spec, "q", &[]));
    assert_eq!(b.text(), format!("\u{feff}{}", lf.replace('\n', "\r\n")));
}

/// A comment line just before a single `inductance` in `[motor.identified]` stays
/// above the axis that keeps that value when one axis is identified.
#[test]
fn comment_before_a_single_inductance_is_kept() {
    let spec = fischer_text().replace(
        "[motor.datasheet]",
        "[motor.identified]\n# LCR meter at 1 kHz, both axes\ninductance = \"0.40 mH\"\n\n[motor.datasheet]",
    );
    let b = Bench::new("split_comment", &spec);
    ok(&b.run(&b.spec, "q", &[]));
    let t = b.text();
    assert!(
        t.contains("# LCR meter at 1 kHz, both axes\nd_inductance = \"0.40 mH\"\nq_inductance = \"0.43"),
        "{t}"
    );
}

/// An inline `identified = {…}` table (which `check` accepts) is refused at its own
/// line, with what to write instead.
#[test]
fn inline_identified_table_is_refused_at_its_line() {
    let spec = fischer_text().replacen("[motor]\n", "[motor]\nidentified = { inductance = \"0.40 mH\" }\n", 1);
    let b = Bench::new("inline", &spec);
    let check = crate::common::motorgen(&["check", &b.spec.display().to_string()]);
    ok(&check);
    let o = b.run(&b.spec, "q", &[]);
    assert_eq!(o.status.code(), Some(1), "{}", text_of(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    let line = line_of(&spec, "identified = {");
    assert!(
        err.contains(&format!("{}:{line}:14: `motor.identified`", b.spec.display())),
        "{err}"
    );
    assert!(
        err.contains("inline table") && err.contains("[motor.identified]"),
        "{err}"
    );
    assert_eq!(b.text(), spec);
}

/// A bad `--date` is blamed on `--date`, not on the spec, before anything is read.
#[test]
fn bad_date_is_blamed_on_the_option() {
    let b = Bench::new("date", &fischer_text());
    let o = b.run(&b.spec, "q", &["--date", "2025-02-30"]);
    assert_eq!(o.status.code(), Some(1), "{}", text_of(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("error: --date") && err.contains("2025-02-30"), "{err}");
    assert!(!err.contains("fischer.toml"), "{err}");
    assert_eq!(b.text(), fischer_text());
}

/// An identification whose values break the design is refused at the rule's key in the
/// file on disk (not in the unwritten text), saying the identified values cause it: the
/// Chalmers motor (`imc_active_damping`, α_c = 1470 rad/s) with a "measured" L_q a
/// quarter of the datasheet's and R = 2·α_c·L_q breaks R_a = α_c·L − R > 0 (thesis B
/// 2.43), first on the d axis (the identified R is both axes'; the step stays below
/// U_dc/√3 with the smaller L and R).
#[test]
fn design_failure_is_located_in_the_file_on_disk() {
    let dir = crate::common::tmp("writeback", "design_failure");
    let text = std::fs::read_to_string(repo().join("motors/chalmers-hev50.toml")).unwrap();
    let spec = dir.join("chalmers.toml");
    std::fs::write(&spec, &text).unwrap();
    let d = codegen::design_source("chalmers.toml", &text).unwrap();
    let l = d.motor.q_inductance_h / 4.0;
    let csv = dir.join("q.csv");
    std::fs::write(&csv, step_recording(&d, "q", 2.0 * 1470.0 * l, l, 3)).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_motorgen"))
        .args(["identify", "step"])
        .arg(&spec)
        .args(["--axis", "q", "--date", "2025-03-14", "--csv"])
        .arg(&csv)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", text_of(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    let line = line_of(&text, "bandwidth = \"1470 rad/s\"");
    assert!(
        err.contains(&format!(
            "{}:{line}:13: `current_loop.bandwidth`: with the identified phase_resistance, q_inductance written, the spec would not design: α_c·L < R on the",
            spec.display()
        )),
        "{err}"
    );
    assert!(err.contains(&format!("{line} | bandwidth = \"1470 rad/s\"")), "{err}");
    assert_eq!(std::fs::read_to_string(&spec).unwrap(), text);
}

/// A writer killed mid-write by the file-size limit (RLIMIT_FSIZE 1 KiB: bash's
/// `ulimit -f 1`; the spec is 1.8 kB) leaves the spec intact and at most its own
/// temporary file, named `.fischer.toml.XXXXXX.motorgen.tmp`; the next identification
/// removes it (and says so). With SIGXFSZ ignored the write fails instead: an I/O error,
/// exit 74, nothing left behind.
#[test]
fn a_killed_writer_leaves_the_spec_intact() {
    let b = Bench::new("killed", &fischer_text());
    let limited = |trap: &str| {
        let inner = b.identify(&b.spec, "q", &[]);
        let mut c = Command::new("bash");
        c.arg("-c")
            .arg(format!("{trap} ulimit -f 1; exec \"$@\""))
            .arg("bash")
            .arg(inner.get_program())
            .args(inner.get_args());
        c.output().unwrap()
    };
    let o = limited("");
    assert_eq!(o.status.signal(), Some(SIGXFSZ), "{}", text_of(&o));
    assert_eq!(b.text(), fischer_text());
    let left = b.leftovers();
    assert_eq!(left.len(), 1, "{left:?}");
    assert!(
        left[0].starts_with(".fischer.toml.") && left[0].ends_with(".motorgen.tmp"),
        "{left:?}"
    );
    let o = b.run(&b.spec, "q", &[]);
    ok(&o);
    assert!(String::from_utf8_lossy(&o.stderr).contains(&format!("removed {}", b.dir.join(&left[0]).display())));
    assert!(b.leftovers().is_empty(), "{:?}", b.leftovers());

    std::fs::write(&b.spec, fischer_text()).unwrap();
    let o = limited("trap '' XFSZ;");
    assert_eq!(o.status.code(), Some(EXIT_IO), "{}", text_of(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("cannot write") && err.contains("fischer.toml"), "{err}");
    assert_eq!(b.text(), fischer_text());
    assert!(b.leftovers().is_empty(), "{:?}", b.leftovers());
}

/// `--dry-run` on a spec with 40,000 comment lines (the old quadratic diff aborted on
/// allocation failure): only the changed lines, numbered as in the old and new file.
/// Memory and time are measured by the `writeback` bench, not here.
#[test]
fn dry_run_on_a_long_spec() {
    let comments: String = (0..40_000).map(|k| format!("# note {k}\n")).collect();
    let spec = format!("{comments}{}", fischer_text());
    let b = Bench::new("long", &spec);
    let o = b.run(&b.spec, "q", &["--dry-run"]);
    ok(&o);
    let stdout = String::from_utf8_lossy(&o.stdout);
    let diff: Vec<&str> = stdout
        .lines()
        .filter(|l| (l.starts_with('+') || l.starts_with('-')) && l.contains(" | "))
        .collect();
    // The new [motor.identified] section: header, 2 values, date, source and a blank line.
    assert!(diff.iter().all(|l| l.starts_with('+')), "{stdout}");
    assert_eq!(diff.len(), 6, "{stdout}");
    let header = 40_000 + line_of(&fischer_text(), "[motor.datasheet]");
    assert!(
        diff.iter()
            .any(|l| l.trim_start_matches('+').trim_start() == format!("{header} | [motor.identified]")),
        "{stdout}"
    );
    assert_eq!(b.text(), spec);
}
