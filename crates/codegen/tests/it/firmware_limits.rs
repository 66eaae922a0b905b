//! One validation table, two callers: every limit the firmware's build enforces at
//! compile time is a row of `codegen::firmware::FIRMWARE_LIMITS`, and `check` refuses what
//! would break it, at its key.
//!
//! * The firmware's sources (control core, `motor-config`, the image) are read, test
//!   modules and comments left out, and every `panic!`, `assert!`, `unreachable!`,
//!   `.unwrap()` and `.expect(` that remains — in a `no_std` image that links no panic
//!   path, each is a const-evaluation failure of the build — must be a row's
//!   `firmware_message`; every row's message must still be in the sources. A new firmware
//!   limit without a row (and so without a `check` rule) fails here.
//! * Every row with a rule has boundary cases, each a hand calculation: the accepted value
//!   passes `check` (the spec alone, the board alone, and the pair with the default
//!   motor or board), the refused one is refused at its key with the accepted range.
//!   `tests/it/firmware_limits.rs` of the end-to-end tests builds the image of the
//!   accepted values.

use codegen::firmware::{FIRMWARE_LIMITS, Home};
use motor_test_support::{read, repo, set_toml_key};

/// Every `.rs` file under `dir`.
fn sources(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let p = e.unwrap().path();
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// `text` without its `#[cfg(test)]` modules (from the attribute to the end of the file:
/// the firmware keeps its tests last) and without `//` comments (outside string literals).
fn code(text: &str) -> String {
    let text = text.find("#[cfg(test)]\nmod tests").map_or(text, |i| &text[..i]);
    let mut out = String::new();
    for line in text.lines() {
        let mut in_str = false;
        let mut prev = ' ';
        let mut cut = line.len();
        for (i, c) in line.char_indices() {
            if c == '"' && prev != '\\' {
                in_str = !in_str;
            }
            if !in_str && c == '/' && prev == '/' {
                cut = i - 1;
                break;
            }
            prev = c;
        }
        out.push_str(&line[..cut]);
        out.push('\n');
    }
    out
}

/// The arguments of the macro call whose `(` is at `open`: up to the matching `)`.
fn arguments(text: &str, open: usize) -> &str {
    let mut depth = 0;
    for (i, c) in text[open..].char_indices() {
        match c {
            '(' => depth += 1,
            ')' => {
                depth -= 1;
                if depth == 0 {
                    return &text[open + 1..open + i];
                }
            }
            _ => {}
        }
    }
    &text[open + 1..]
}

/// The firmware's build-time failures in `text`: each panic's message, an assertion's
/// message or (without one) its expression, whitespace collapsed.
fn failures(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for mac in ["panic!(", "assert!(", "unreachable!(", ".unwrap()", ".expect("] {
        let mut from = 0;
        while let Some(i) = text[from..].find(mac) {
            let at = from + i;
            from = at + mac.len();
            // `debug_assert!` is compiled out of the release image; `assert_eq!` is not
            // matched by `assert!(`.
            if mac == "assert!(" && text[..at].ends_with("debug_") {
                continue;
            }
            let what = if mac.ends_with('(') {
                let args = arguments(text, at + mac.len() - 1);
                // A string literal (the message) or the first argument.
                match args.find('"') {
                    Some(q) if mac != "assert!(" || args[..q].contains(',') => {
                        let rest = &args[q + 1..];
                        rest[..rest.find('"').unwrap_or(rest.len())].to_string()
                    }
                    _ => args.split(',').next().unwrap_or("").to_string(),
                }
            } else {
                mac.to_string()
            };
            out.push(what.split_whitespace().collect::<Vec<_>>().join(" "));
        }
    }
    out
}

#[test]
fn every_firmware_build_failure_is_a_row_of_the_table() {
    let mut files = Vec::new();
    for dir in ["firmware/control/src", "firmware/config/src", "firmware/app/src"] {
        sources(&repo().join(dir), &mut files);
    }
    assert!(files.len() > 20, "the firmware's sources: {files:?}");
    let mut found = Vec::new();
    let mut missing = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for failure in failures(&code(&text)) {
            let rel = f.strip_prefix(repo()).unwrap().display().to_string();
            if !FIRMWARE_LIMITS
                .iter()
                .any(|l| l.firmware_messages.contains(&failure.as_str()))
            {
                missing.push(format!("{rel}: {failure:?}"));
            }
            found.push(failure);
        }
    }
    assert!(
        missing.is_empty(),
        "firmware build failures without a row in codegen::firmware::FIRMWARE_LIMITS (and so without a `check` rule):\n{}",
        missing.join("\n")
    );
    for l in FIRMWARE_LIMITS {
        for m in l.firmware_messages {
            assert!(
                found.iter().any(|f| f == m),
                "row {m:?} ({}) names no failure left in the firmware's sources",
                l.firmware_item
            );
        }
        if l.rule.is_empty() {
            assert!(l.cases.is_empty(), "{}: cases without a rule", l.firmware_item);
        } else {
            assert!(!l.cases.is_empty(), "{}: a rule needs boundary cases", l.firmware_item);
        }
    }
}

/// A case's file with its edits: (file name, text).
fn edited(home: Home, base: &str, edits: &[(&str, &str)]) -> (String, String) {
    let rel = match home {
        Home::Spec => format!("motors/{base}.toml"),
        Home::Board => format!("boards/{base}.toml"),
    };
    let mut text = read(&rel);
    for (k, v) in edits {
        text = set_toml_key(&text, k, v);
    }
    (rel, text)
}

/// The verdict of `check` on a case's file alone and on the pair with the default motor
/// (for a board) or board (for a spec), that file edited by `partner`.
fn check(home: Home, file: &str, text: &str, partner: &[(&str, &str)]) -> Result<(), codegen::Diagnostics> {
    let other = home.partner();
    let other_text = partner.iter().fold(read(&other), |t, (k, v)| set_toml_key(&t, k, v));
    match home {
        Home::Spec => {
            codegen::design_source(file, text)?;
            codegen::design_with_board(file, text, &other, &other_text).map(|_| ())
        }
        Home::Board => {
            codegen::board_source(file, text)?;
            codegen::design_with_board(&other, &other_text, file, text).map(|_| ())
        }
    }
}

#[test]
fn every_limit_is_refused_at_its_key_and_its_boundary_accepted() {
    let mut n = 0;
    for l in FIRMWARE_LIMITS {
        for c in l.cases {
            let mut edits: Vec<(&str, &str)> = c.also.to_vec();
            edits.push((c.key, c.accepted));
            let (file, text) = edited(c.home, c.base, &edits);
            if let Err(e) = check(c.home, &file, &text, c.partner) {
                panic!(
                    "{} = {} ({}): accepted by hand, refused:\n{e}",
                    c.key, c.accepted, c.why
                );
            }
            edits.pop();
            edits.push((c.key, c.refused));
            let (file, text) = edited(c.home, c.base, &edits);
            let e = check(c.home, &file, &text, c.partner)
                .err()
                .unwrap_or_else(|| panic!("{} = {} ({}): refused by hand, accepted", c.key, c.refused, c.why));
            let d =
                e.0.iter()
                    .find(|d| d.key == c.key)
                    .unwrap_or_else(|| panic!("{} = {}: refused, but not at its key:\n{e}", c.key, c.refused));
            let line = text
                .lines()
                .position(|x| x.starts_with(c.key.rsplit('.').next().unwrap()))
                .unwrap()
                + 1;
            assert_eq!(d.line, line, "{e}");
            assert!(!d.accepted.is_empty(), "{e}");
            n += 1;
        }
    }
    assert!(n >= 10, "{n} cases");
}

/// Issue 27's examples: each was accepted by `check` and then failed the firmware build
/// with a rustc const-evaluation panic (exit 5, no file, no key).
#[test]
fn issue_27_unbuildable_values_are_refused_at_their_key() {
    let board = read("boards/motorgen-reference.toml");
    for (key, value, words) in [
        ("can.bit_rate", "\"800 kbit/s\"", "1 Mbit/s"),
        ("pwm.dead_time", "\"6 µs\"", "up to 5929 ns"),
        ("watchdog.timeout", "\"40 s\"", "up to 32.76 s"),
    ] {
        let text = set_toml_key(&board, key, value);
        let e = codegen::board_source("b.toml", &text).unwrap_err();
        let d = e.0.iter().find(|d| d.key == key).unwrap_or_else(|| panic!("{e}"));
        assert!(d.accepted.contains(words), "{key}: {e}");
    }
    // 1 Mbit/s was refused by the build (20 fixed quanta: 170 MHz/20 Mbit/s = 8.5):
    // now it works.
    let text = set_toml_key(&board, "can.bit_rate", "\"1 Mbit/s\"");
    assert!(codegen::board_source("b.toml", &text).is_ok());
    // 2 Mbit/s the clock makes exactly (170 MHz/2 Mbit/s = 85 = 5 × 17 quanta) and the
    // image would build, but classic CAN ends at 1 Mbit/s (ISO 11898-1): refused at its key.
    let text = set_toml_key(&board, "can.bit_rate", "\"2 Mbit/s\"");
    let e = codegen::board_source("b.toml", &text).unwrap_err();
    let d =
        e.0.iter()
            .find(|d| d.key == "can.bit_rate")
            .unwrap_or_else(|| panic!("{e}"));
    assert!(
        d.problem.contains("classic CAN") && d.problem.contains("ISO 11898-1"),
        "{e}"
    );
    assert!(
        d.accepted.contains("up to 1 Mbit/s") && d.accepted.contains("1 Mbit/s (CiA 301)"),
        "{e}"
    );
    // f_s in [1 kHz, 1.297 kHz): inside the plausible range, beyond the 16-bit ARR.
    let spec = set_toml_key(
        &set_toml_key(
            &read("motors/unimotor-142umd300.toml"),
            "motor.datasheet.max_speed",
            "\"1000 rpm\"",
        ),
        "drive.switching_frequency",
        "\"1.2 kHz\"",
    );
    let e = codegen::design_source("m.toml", &spec).unwrap_err();
    let d =
        e.0.iter()
            .find(|d| d.key == "drive.switching_frequency")
            .unwrap_or_else(|| panic!("{e}"));
    assert!(d.accepted.contains("at least 1297.03 Hz"), "{e}");
}
