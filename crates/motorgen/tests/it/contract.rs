//! Issue 27 at the command line: `check SPEC --board BOARD` shows the trips the image will
//! use (and refuses a motor the board does not fit, at the board key); every command that
//! designs prints the design's warnings on stderr, once each, located at their key,
//! whatever the output format (`generate` and the machine formats included).

use std::collections::BTreeSet;

use crate::common::{motorgen, repo, text_of, tmp};

/// The "Done when": `motorgen check maxon-ec45-flat-70w.toml --board
/// motorgen-reference` (names resolved in motors/ and boards/) shows the trips the image
/// will use, each the lower of the motor's limit and the board's ceiling, by hand:
/// over-current 1.25·√2·10 A = 17.68 A (ceiling 100 A), over-voltage 1.25·24 V = 30 V
/// (ceiling 700 V), over-speed 1.25·4500 rpm = 5625 rpm (ceiling 22 000 rpm) — and they
/// are the generated constants the image is compiled with (OVER_CURRENT_A, OVER_VOLTAGE_V,
/// OVER_SPEED_E_RAD_S = 5625·2π/60·8 = 4712.389 rad/s electrical).
#[test]
fn check_with_a_board_shows_the_trips_the_image_uses() {
    let out = motorgen(&["check", "maxon-ec45-flat-70w.toml", "--board", "motorgen-reference"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", text_of(&out));
    for line in [
        "ok: motors/maxon-ec45-flat-70w.toml (maxon EC 45 flat 70 W 24 V) on boards/motorgen-reference.toml",
        "over-current 17.68 A, set by the motor: 17.68 A (scaling.margin·√2·peak_current = 1.25·√2·10 A); board ceiling 100.00 A (protection.over_current)",
        "over-voltage 30.00 V, set by the motor",
        "board ceiling 700.00 V (protection.over_voltage)",
        "over-speed 5625 rpm, set by the motor",
        "board ceiling 22000.00 rpm (protection.over_speed)",
    ] {
        assert!(stdout.contains(line), "{line:?} not in\n{stdout}");
    }
    let out = motorgen(&[
        "design",
        "maxon-ec45-flat-70w",
        "--board",
        "motorgen-reference",
        "--format",
        "rust",
    ]);
    let rust = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", text_of(&out));
    for constant in [
        "pub const OVER_CURRENT_A: f32 = 17.67767;",
        "pub const OVER_VOLTAGE_V: f32 = 30.0;",
        "pub const OVER_SPEED_E_RAD_S: f32 = 4712.389;",
    ] {
        assert!(rust.contains(constant), "{constant} not generated");
    }
}

/// A 600 V motor on the 48 V NUCLEO board: exit 1, the DC link refused at the board's
/// `sensing.dc_link_divider` (3.3 V/0.05221 = 63.2 V) on stderr, no "ok" on stdout.
/// Before: accepted (and the image built with exit 0).
#[test]
fn check_refuses_a_motor_the_board_does_not_fit_at_the_board_key() {
    let out = motorgen(&[
        "check",
        "motors/fischer-ti085.toml",
        "--board",
        "boards/nucleo-g474re-ihm08m1.toml",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{}", text_of(&out));
    let board = std::fs::read_to_string(repo().join("boards/nucleo-g474re-ihm08m1.toml")).unwrap();
    let line = board.lines().position(|l| l.starts_with("dc_link_divider")).unwrap() + 1;
    let at = format!(
        "error: boards/nucleo-g474re-ihm08m1.toml:{line}:19: `sensing.dc_link_divider`: the divider measures up to 63.2 V"
    );
    assert!(stderr.contains(&at), "{at:?} not in\n{stderr}");
    assert!(
        !String::from_utf8_lossy(&out.stdout).contains("ok:"),
        "{}",
        text_of(&out)
    );
}

/// The warning lines (`warning: …`) of `text`.
fn warnings(text: &str) -> Vec<String> {
    text.lines()
        .filter(|l| l.starts_with("warning: "))
        .map(String::from)
        .collect()
}

/// Chalmers HEV50 without delay compensation warns (its sampled loop is slow, its
/// injection carrier outside thesis B (4.34)'s band, its peak current above ψ_m/|ΔL|).
/// Every command prints the same warnings on stderr, each once, located at its key, and
/// the human outputs none on stdout: `check`, `design` in every format, `generate` and `verify`. Before:
/// the human `design` printed them on stdout, `design --format c|rust` and `generate`
/// printed none.
#[test]
fn every_command_prints_each_warning_once_on_stderr_located() {
    let dir = tmp("contract", "warnings");
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(repo().join("motors/chalmers-hev50.toml"))
        .unwrap()
        .replacen(
            "bandwidth = \"1470 rad/s\"",
            "bandwidth = \"1470 rad/s\"\ncompensate_delay = false",
            1,
        );
    let spec = dir.join("chalmers-plain.toml");
    std::fs::write(&spec, &text).unwrap();
    let spec = spec.to_str().unwrap();
    let out_dir = dir.join("generated");
    let out_dir = out_dir.to_str().unwrap();
    let reference = warnings(&String::from_utf8_lossy(&motorgen(&["check", spec]).stderr));
    assert!(reference.len() >= 3, "{reference:?}");
    let compensate = text.lines().position(|l| l.contains("compensate_delay")).unwrap();
    for w in &reference {
        let rest = w
            .strip_prefix(&format!("warning: {spec}:"))
            .unwrap_or_else(|| panic!("not located in the spec: {w}"));
        let mut parts = rest.splitn(3, ':');
        let line: usize = parts.next().unwrap().parse().unwrap_or_else(|_| panic!("{w}"));
        let _col: usize = parts.next().unwrap().parse().unwrap_or_else(|_| panic!("{w}"));
        assert!(line >= 1 && line <= text.lines().count() && line != 1, "{w}");
        assert!(parts.next().unwrap().starts_with(" `"), "no key: {w}");
    }
    // The delay warning is at the bandwidth key, the line before compensate_delay.
    assert!(
        reference
            .iter()
            .any(|w| w.contains(&format!(":{compensate}:")) && w.contains("`current_loop.bandwidth`")),
        "{reference:?}"
    );
    let want: BTreeSet<&String> = reference.iter().collect();
    for args in [
        vec!["design", spec],
        vec!["design", spec, "--format", "json"],
        vec!["design", spec, "--format", "c"],
        vec!["design", spec, "--format", "rust"],
        vec!["design", spec, "--format", "markdown"],
        vec!["design", spec, "--board", "motorgen-reference-400a"],
        vec!["generate", spec, "--out", out_dir],
        vec!["verify", spec],
    ] {
        let out = motorgen(&args);
        assert!(matches!(out.status.code(), Some(0 | 3)), "{args:?}: {}", text_of(&out));
        let stderr = String::from_utf8_lossy(&out.stderr);
        let got = warnings(&stderr);
        let unique: BTreeSet<&String> = got.iter().collect();
        assert_eq!(unique.len(), got.len(), "{args:?}: a warning printed twice:\n{stderr}");
        // The board's own warnings come on top with --board; the motor's are all there —
        // the current loop's delay warning at its key with the board's loop delay
        // (`design::timing_of`) and the rise time it makes, so it is compared up to there.
        let upto_delay = |w: &&String| w.split(" with the ").next().unwrap_or(w).to_string();
        let (want_cut, unique_cut): (BTreeSet<String>, BTreeSet<String>) = (
            want.iter().map(upto_delay).collect(),
            unique.iter().map(upto_delay).collect(),
        );
        assert!(
            want_cut.is_subset(&unique_cut),
            "{args:?}: {want:?} not all in\n{stderr}"
        );
        if !args.contains(&"--board") {
            assert_eq!(unique, want, "{args:?}");
        }
        // The human outputs carry no warning (the machine formats may hold them as data:
        // the JSON design's `warnings`).
        if args.contains(&"--format") {
            continue;
        }
        let stdout = String::from_utf8_lossy(&out.stdout);
        for w in &reference {
            let body = w.strip_prefix("warning: ").unwrap();
            assert!(!stdout.contains(body), "{args:?}: a warning on stdout: {w}");
        }
    }
}
