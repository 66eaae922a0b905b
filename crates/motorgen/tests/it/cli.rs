//! The `motorgen` CLI as a user runs it: the exit codes (0 success, 1 bad input,
//! 2 usage, 3 verification failed, 5 firmware build failed, 74 I/O — documented in
//! `--help` and the README), what goes to stdout and what to stderr, and file I/O. The
//! diagnostics themselves are tested at the library level (`tests/spec.rs`); here they
//! only have to reach stderr.

use crate::common::{EXIT_IO, motorgen, repo};

use std::path::{Path, PathBuf};

fn fischer() -> String {
    std::fs::read_to_string(repo().join("motors/fischer-ti085.toml")).unwrap()
}

/// Writes `bytes` to a fresh file under the test temp dir and returns its path.
fn write(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// 1-based line of the first occurrence of `needle` in `text` (the test's own locator).
fn line_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).unwrap_or_else(|| panic!("{needle:?} not in spec"));
    text[..at].matches('\n').count() + 1
}

#[test]
fn seed_motors_design_and_check() {
    for m in ["fischer-ti085", "unimotor-142umd300", "chalmers-hev50"] {
        let path = format!("motors/{m}.toml");
        let out = motorgen(&["design", &path, "--format", "json"]);
        assert!(out.status.success(), "{m}: {}", String::from_utf8_lossy(&out.stderr));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(json["spec_file"], path.as_str());
        assert_eq!(json["schema_version"], 1, "{m}: the JSON form's version");
        let out = motorgen(&["check", &path]);
        assert!(out.status.success());
    }
    let out = motorgen(&["list"]);
    let s = String::from_utf8_lossy(&out.stdout);
    for m in ["fischer-ti085", "unimotor-142umd300", "chalmers-hev50"] {
        assert!(s.contains(m), "{s}");
    }
}

/// A bad spec: exit 1, the located message on stderr, nothing on stdout, no panic —
/// for `design` (every format) and `check`.
#[test]
fn bad_spec_exits_1_with_the_message_on_stderr() {
    let text = fischer().replacen("pole_pairs = 4 ", "pole_pairs = = 4 ", 1);
    let line = line_of(&text, "pole_pairs = = 4");
    let path = write("syntax.toml", text.as_bytes());
    let p = path.to_str().unwrap();
    for args in [
        vec!["design", p],
        vec!["design", p, "--format", "json"],
        vec!["design", p, "--format", "c"],
        vec!["check", p],
    ] {
        let out = motorgen(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?} (a panic exits 101)\n{stderr}");
        assert!(out.stdout.is_empty(), "{args:?} wrote to stdout");
        assert!(
            stderr.contains(&format!("{p}:{line}:")),
            "{args:?}: not located\n{stderr}"
        );
        assert!(
            stderr.contains("TOML syntax error") && stderr.contains("accepted: "),
            "{stderr}"
        );
    }
}

/// The command line itself is wrong: clap's usage error, exit 2.
#[test]
fn usage_errors_exit_2() {
    for args in [
        vec!["design"],
        vec!["frobnicate"],
        vec!["design", "x.toml", "--format", "pdf"],
    ] {
        let out = motorgen(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty());
    }
}

/// `--help` lists the exit codes, and the value names are the ones the help text uses.
#[test]
fn help_documents_exit_codes_and_value_names() {
    let out = motorgen(&["--help"]);
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    for code in [
        "Exit codes:",
        "  0  success",
        "  1  bad input",
        "  2  usage",
        "  3  verification failed",
        "  5  the firmware build",
        "  74 I/O",
    ] {
        assert!(help.contains(code), "{code:?} not in\n{help}");
    }
    let help = String::from_utf8_lossy(&motorgen(&["report", "--help"]).stdout).into_owned();
    assert!(
        help.contains("<SPEC>") && help.contains("--out <DIR>") && help.contains("DIR/STEM.html"),
        "{help}"
    );
    let help = String::from_utf8_lossy(&motorgen(&["new", "--help"]).stdout).into_owned();
    assert!(
        help.contains("<STEM>")
            && help.contains("--motors-dir <DIR>")
            && help.contains("MOTORGEN_MOTORS_DIR")
            && help.contains("DIR/STEM.toml"),
        "{help}"
    );
    // `design` prints the summary unless --format says otherwise (it said "the whole
    // design", issue 31).
    let help = String::from_utf8_lossy(&motorgen(&["design", "--help"]).stdout).into_owned();
    let first = help.lines().next().unwrap_or_default();
    let (by_default, _) = first.split_once(", or with --format").unwrap_or((first, ""));
    assert!(
        by_default.contains("summary") && !by_default.contains("whole design"),
        "{first}"
    );
    assert!(help.contains("summary") && help.contains("(the default)"), "{help}");
}

/// `motorgen` (the binary, as `cargo install` leaves it) outside the repository: `list`
/// and `new` without a motors folder name the option and the variable that give one
/// (exit 2, nothing written) instead of falling back to the source tree it was built
/// from; with `--motors-dir` (or `--dir`, or `MOTORGEN_MOTORS_DIR`) they work.
#[test]
fn outside_the_repository_the_motors_folder_is_asked_for() {
    let empty = crate::common::tmp("cli", "no-motors-folder");
    let run = |args: &[&str], env: Option<&std::path::Path>| {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_motorgen"));
        c.args(args)
            .current_dir(&empty)
            .env_remove("MOTORGEN_MOTORS_DIR")
            .env_remove("MOTORGEN_BOARDS_DIR");
        if let Some(dir) = env {
            c.env("MOTORGEN_MOTORS_DIR", dir);
        }
        c.output().unwrap()
    };
    for args in [
        &["list"][..],
        &["new", "my-motor"][..],
        &["firmware", "fischer-ti085"][..],
    ] {
        let o = run(args, None);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", crate::common::text_of(&o));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.starts_with("error: no motors folder")
                && err.contains("--motors-dir DIR")
                && err.contains("MOTORGEN_MOTORS_DIR=DIR"),
            "{args:?}: {err}"
        );
        assert!(o.stdout.is_empty());
    }
    assert_eq!(std::fs::read_dir(&empty).unwrap().count(), 0, "nothing written");
    let motors = repo().join("motors");
    let m = motors.to_str().unwrap();
    for o in [
        run(&["list", "--motors-dir", m], None),
        run(&["list", "--dir", m], None),
        run(&["list"], Some(&motors)),
    ] {
        assert!(o.status.success(), "{}", crate::common::text_of(&o));
        let listed = String::from_utf8_lossy(&o.stdout);
        for stem in crate::common::motor_stems() {
            assert!(
                listed.lines().any(|l| l.starts_with(&format!("{stem} "))),
                "{stem}:\n{listed}"
            );
        }
    }
}

/// `list` keeps one column for the names however long a stem is (a fixed 24-character
/// column misaligned longer stems, issue 31).
#[test]
fn list_aligns_the_names_after_long_stems() {
    let dir = crate::common::tmp("cli", "long-stems");
    let long = "a-motor-stem-much-longer-than-twenty-four-characters";
    std::fs::write(dir.join(format!("{long}.toml")), fischer()).unwrap();
    std::fs::write(dir.join("m.toml"), fischer()).unwrap();
    std::fs::write(dir.join("broken.toml"), "not a spec").unwrap();
    let o = motorgen(&["list", "--motors-dir", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", crate::common::text_of(&o));
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3, "{out}");
    // Each line: the stem, padding, one space, then the name (or INVALID) — all from
    // the same column, one past the longest stem.
    let column = long.chars().count() + 1;
    for line in &lines {
        let (stem, rest) = line.split_at(column);
        assert!(stem.ends_with(' ') && !rest.starts_with(' '), "{out}");
    }
    assert!(lines.iter().any(|l| l[column..].starts_with("INVALID")), "{out}");
    assert!(lines.iter().any(|l| l[column..].starts_with("Fischer TI085")), "{out}");
}

/// An unreadable `--board` file is named as a board file in the "accepted" line (it was
/// "a readable motor spec", issue 31); an unreadable spec still as a motor spec.
#[test]
fn an_unreadable_board_is_named_as_a_board() {
    let o = motorgen(&[
        "design",
        "motors/fischer-ti085.toml",
        "--board",
        "boards/no-such-board.toml",
    ]);
    assert_eq!(o.status.code(), Some(EXIT_IO), "{}", crate::common::text_of(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("boards/no-such-board.toml:1:1") && err.contains("accepted: a readable board file"),
        "{err}"
    );
    let o = motorgen(&[
        "design",
        "motors/no-such-motor.toml",
        "--board",
        "boards/motorgen-reference.toml",
    ]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("accepted: a readable motor spec"));
}

/// The Chalmers HEV50 spec with `compensate_delay = false`, written as `name`: its
/// sampled current loop is slower than designed (a warning, and a failing rise time).
fn chalmers_without_delay_compensation(name: &str) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("motors/chalmers-hev50.toml"))
        .unwrap()
        .replacen(
            "bandwidth = \"1470 rad/s\"",
            "bandwidth = \"1470 rad/s\"\ncompensate_delay = false",
            1,
        );
    assert!(text.contains("compensate_delay = false"));
    write(name, text.as_bytes())
}

/// `check`: the verdict on stdout, warnings on stderr (Chalmers without delay
/// compensation warns that its sampled loop is slow).
#[test]
fn check_prints_warnings_on_stderr() {
    let path = chalmers_without_delay_compensation("chalmers-plain.toml");
    let out = motorgen(&["check", path.to_str().unwrap()]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.starts_with("ok: ") && !stdout.contains("warning"), "{stdout}");
    assert!(
        stderr.contains("warning: ") && stderr.contains("compensate_delay"),
        "{stderr}"
    );
}

/// A design that `check` accepts but that verifies badly: exit 3, the table still on
/// stdout. The spec is the inverse-saliency variant of thesis B's motor
/// (tests/motor_data.rs `inverse_saliency_variant`: L_d = 0.70 mH, 4200 rpm, 100 Hz
/// carrier), whose estimator_recovery slips one electrical cycle with the resetting term
/// (a limit of the estimator with these larger inductances, documented there).
#[test]
fn failed_verification_exits_3() {
    let text = std::fs::read_to_string(repo().join("motors/chalmers-hev50.toml"))
        .unwrap()
        .replacen("d_inductance = \"0.23 mH\"", "d_inductance = \"0.70 mH\"", 1)
        .replacen("max_speed = \"12000 rpm\"", "max_speed = \"4200 rpm\"", 1)
        .replacen(
            "injection_frequency = \"500 Hz\"",
            "injection_frequency = \"100 Hz\"",
            1,
        );
    let path = write("chalmers-inverse-unverified.toml", text.as_bytes());
    let out = motorgen(&["verify", path.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("verification failed: ") && stderr.contains("estimator_recovery"),
        "{stderr}"
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("estimator_recovery"));
}

#[test]
fn invalid_utf8_is_bad_input() {
    let mut bytes = fischer().into_bytes();
    let at = fischer().find("Ω").unwrap();
    bytes[at] = 0xFF;
    let line = line_of(&fischer(), "Ω");
    let path = write("utf8.toml", &bytes);
    let out = motorgen(&["check", path.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains(&format!("utf8.toml:{line}:")), "{stderr}");
    assert!(stderr.contains("not valid UTF-8"), "{stderr}");
}

/// An unreadable spec is an I/O failure (exit 74), located at the file.
#[test]
fn missing_file_is_an_io_error() {
    let out = motorgen(&["check", "motors/no-such-motor.toml"]);
    assert_eq!(out.status.code(), Some(EXIT_IO));
    assert!(String::from_utf8_lossy(&out.stderr).contains("motors/no-such-motor.toml:1:1"));
    let out = motorgen(&["design", "motors/no-such-motor.toml"]);
    assert_eq!(out.status.code(), Some(EXIT_IO));
    assert!(out.stdout.is_empty());
}

#[test]
fn new_writes_a_spec_that_designs_and_never_overwrites() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("new");
    let _ = std::fs::remove_dir_all(&dir);
    let d = dir.to_str().unwrap();
    let out = motorgen(&["new", "test-motor", "--dir", d]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let path = dir.join("test-motor.toml");
    let out = motorgen(&["check", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = motorgen(&["list", "--dir", d]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("test-motor"));
    let out = motorgen(&["new", "test-motor", "--dir", d]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("already exists"));
    let out = motorgen(&["new", "Bad Name", "--dir", d]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn generate_writes_only_changed_files_and_templates_errors_name_the_file() {
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("generate");
    let _ = std::fs::remove_dir_all(&out_dir);
    let o = out_dir.to_str().unwrap();
    let first = motorgen(&["generate", "motors/fischer-ti085.toml", "--out", o]);
    assert!(first.status.success());
    assert_eq!(String::from_utf8_lossy(&first.stdout).matches("wrote").count(), 3);
    let second = motorgen(&["generate", "motors/fischer-ti085.toml", "--out", o]);
    assert_eq!(String::from_utf8_lossy(&second.stdout).matches("unchanged").count(), 3);
    // A user template with an undefined variable on line 2: strict undefined, located error.
    let tdir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("templates");
    std::fs::create_dir_all(&tdir).unwrap();
    std::fs::write(tdir.join("motor.rs.j2"), "// {{ name }}\n// {{ no_such_variable }}\n").unwrap();
    let bad = motorgen(&[
        "design",
        "motors/fischer-ti085.toml",
        "--format",
        "rust",
        "--templates",
        tdir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(bad.status.code(), Some(1));
    assert!(stderr.contains("motor.rs.j2:2"), "{stderr}");
    assert!(bad.stdout.is_empty());
    // An output directory that cannot be created (a file is in the way): I/O, exit 74.
    let blocked = out_dir.join("fischer_ti085.rs");
    let under = blocked.join("sub");
    let out = motorgen(&[
        "generate",
        "motors/fischer-ti085.toml",
        "--out",
        under.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(EXIT_IO),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot create"));
}

/// The plain (uncompensated) IMC loop of Fischer, whose PI zero 1 − R·T_s/L = 0.98397 all
/// but cancels the ZOH plant pole e^(−R·T_s/L) = 0.98409, leaving L(z) = k/(z·(z − 1)) with
/// k = α·T_s (`design::sampled_loop`). Hand calculations (T_s = 50 µs):
/// * α = 12 000 rad/s, k = 0.6: |L| = k/(2·sin(ωT_s/2)) = 1 at ωT_s = 2·asin 0.3 = 0.6094,
///   ∠L = −90° − 1.5·ωT_s = −142.4°, so the phase margin is 37.6° < 45°;
/// * the largest α meeting the 2 % overshoot floor: the step of k/(z² − z + k), iterated by
///   hand (y_n = y_(n−1) − k·y_(n−2) + k) and bisected on k, overshoots 2 % at k = 0.3120,
///   α = 6239 rad/s: what the floors alone allow; the bandwidth named is lower, where
///   `verify`'s at-speed figures hold too (the DC-link step, README).
#[test]
fn sampled_loop_refusal_names_the_hand_figures() {
    let t = fischer().replacen(
        "bandwidth = \"100 rad/s\"",
        "bandwidth = \"12000 rad/s\"\ncompensate_delay = false",
        1,
    );
    let path = write("plain_12k.toml", t.as_bytes());
    let out = motorgen(&["check", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    let number_after = |tag: &str| -> f64 {
        let at = err.find(tag).unwrap_or_else(|| panic!("{tag} missing:\n{err}")) + tag.len();
        err[at..]
            .split(|c: char| !(c.is_ascii_digit() || c == '.'))
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    assert!(err.contains("`current_loop.bandwidth`"), "{err}");
    let pm = number_after("is phase margin ");
    assert!((pm - 37.6).abs() < 1.0, "{pm}\n{err}");
    let floors = number_after("the floors alone allow up to ");
    assert!((floors / 6239.0 - 1.0).abs() < 0.02, "{floors}\n{err}");
    let best = number_after("a bandwidth up to ");
    assert!(best < floors, "{best}\n{err}");
}

/// Issue 18's non-finite examples: each is refused at its key with the accepted range
/// (exit 1, located on stderr), `design --format json` prints nothing (no `null` where a
/// number is promised) and `generate` writes no file.
#[test]
fn values_beyond_physical_ranges_are_refused_at_their_key_and_nothing_is_written() {
    for &(from, to, key, range) in crate::common::ISSUE_18_RANGE_EXAMPLES {
        let text = fischer().replacen(from, to, 1);
        assert_ne!(text, fischer(), "{from} not in the Fischer spec");
        let line = line_of(&text, to);
        let path = write(&format!("range-{}.toml", key.replace('.', "-")), text.as_bytes());
        let p = path.to_str().unwrap();
        let out = motorgen(&["design", p, "--format", "json"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{key}\n{stderr}");
        assert!(out.stdout.is_empty(), "{key}: printed a design");
        assert!(stderr.contains(&format!("{p}:{line}:")), "{key}: not located\n{stderr}");
        assert!(
            stderr.contains(&format!("`{key}`")) && stderr.contains(range),
            "{stderr}"
        );
        let dir = crate::common::tmp("ranges", key);
        let out = motorgen(&["generate", p, "--out", dir.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(1), "{key}");
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            0,
            "{key}: generate wrote files"
        );
    }
}

/// `motorgen check` takes board files next to motor specs: the seed boards pass, a bad
/// one fails with its located error and a non-zero exit; `design --board` prints the
/// motor-vs-board warnings and adds the `board` constants.
#[test]
fn check_and_design_take_board_files() {
    let root = repo();
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_motorgen"))
            .args(args)
            .current_dir(&root)
            .output()
            .expect("motorgen runs")
    };
    let out = run(&[
        "check",
        "boards/motorgen-reference.toml",
        "boards/nucleo-g474re-ihm08m1.toml",
        "motors/fischer-ti085.toml",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        stdout.contains(
            "ok: boards/nucleo-g474re-ihm08m1.toml (board: NUCLEO-G474RE + X-NUCLEO-IHM08M1, STM32G474RE LQFP64)"
        ),
        "{stdout}"
    );
    let bad = root.join("crates/codegen/tests/bad-boards/wrong-af.toml");
    let out = run(&["check", bad.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("wrong-af.toml:16:14: `pins.gate_u_low`: PA5 has no TIM1_CH1N"),
        "{stderr}"
    );
    // A stated polarity contradicting the named driver: accepted, warned at the key with
    // the datasheet's passage (issue 25).
    let nucleo = std::fs::read_to_string(root.join("boards/nucleo-g474re-ihm08m1.toml")).unwrap();
    let stated = nucleo.replace(
        "part = \"L6398\"",
        "part = \"L6398\"\nlow_side_input = \"in_phase\"\nlow_side_pull = \"down\"",
    );
    let dir = motor_test_support::tmp("motorgen-cli", "stated-polarity");
    let file = dir.join("stated.toml");
    std::fs::write(&file, &stated).unwrap();
    let out = run(&["check", file.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let line = stated[..stated.find("\"in_phase\"").unwrap()].matches('\n').count() + 1;
    assert!(
        stderr.contains(&format!("warning: {}:{line}:18: `gate_driver.low_side_input`: the board states in_phase but its part L6398 has inverted (L6398 datasheet §3 truth table", file.display())),
        "{stderr}"
    );
    let out = run(&[
        "design",
        "motors/chalmers-hev50.toml",
        "--board",
        "boards/motorgen-reference-400a.toml",
        "--format",
        "rust",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        stdout.contains("pub mod board {") && stdout.contains("pub const DEAD_TIME_NS: u32 = 500;"),
        "{stdout}"
    );
}

/// `verify --format json` on the salient IPM motor (the one whose whole 0–20 000 rpm
/// envelope the field-weakening ramp crosses): the verdict as data, every scenario with its
/// criteria, and the field-weakening ramp's `reached_speed_rpm` at least the spec's
/// `max_speed = "20000 rpm"` (motors/amk-dd5-ipm.toml) — what a user's CI gates on. The
/// other motors' reached speeds are checked by motor-verify's
/// `every_seed_motor_passes_its_scenarios`.
#[test]
fn verify_json_gives_every_criterion_and_the_reached_speed() {
    let out = motorgen(&["verify", "motors/amk-dd5-ipm.toml", "--format", "json"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["passed"], true);
    let scenarios = json["scenarios"].as_array().unwrap();
    assert!(scenarios.len() >= 7, "{scenarios:?}");
    for sc in scenarios {
        assert_eq!(sc["passed"], true, "{sc}");
        let criteria = sc["criteria"].as_array().unwrap();
        assert!(!criteria.is_empty(), "{sc}");
        for c in criteria {
            for key in ["name", "measured", "designed", "limit", "unit", "pass", "criterion"] {
                assert!(c.get(key).is_some(), "{key} missing in {c}");
            }
            assert_eq!(c["pass"], true, "{c}");
        }
    }
    let fw = scenarios.iter().find(|s| s["name"] == "field_weakening").unwrap();
    let reached = fw["reached_speed_rpm"].as_f64().unwrap();
    assert!(reached >= 20000.0, "{reached}");
    // Only the field-weakening scenario has a ramp speed.
    assert!(
        scenarios
            .iter()
            .filter(|s| s.get("reached_speed_rpm").is_some())
            .count()
            == 1
    );
}
