//! Bounded fuzzing of everything a user file reaches (issue 18): mutated motor specs (and
//! board files) through the design, the check and the three templates, in-process
//! (mutated recordings: `motor-commission`'s `fuzz` tests; the harness:
//! `motor_test_support::fuzz`).
//!
//! Each case is derived from a seeded SplitMix64, so a failure prints the seed and the
//! mutated text and reproduces exactly. Per case: no panic (`catch_unwind`), every `Ok`
//! design has only finite numbers (its serialised form, what JSON and templates see) and
//! renders, every `Err` names the file, a line ≥ 1 and a column ≥ 1, what is wrong and what
//! is accepted. Work per case is bounded by construction (the spec is at most a few kB, the
//! recording a few thousand rows).
//!
//! CI runs a bounded slice (`SPEC_CASES`, `BOARD_CASES`, `RECORDING_CASES` below); more
//! locally with `MOTORGEN_FUZZ_CASES=100000 cargo test --release -p codegen --test it fuzz -- --nocapture`
//! (the count applies to each target; `MOTORGEN_FUZZ_SEED` shifts the seeds).

use codegen::design::finite::first_non_finite;
use codegen::render::{Output, render};
use codegen::{Design, Diagnostics};
use motor_test_support::fuzz::{self, Rng, cases, replace_line};

/// Spec cases in CI (debug build).
const SPEC_CASES: usize = 800;
/// Board cases in CI (debug build).
const BOARD_CASES: usize = 40;

/// Numbers that break formulas: zero, signs, extremes of f64, the examples, non-numbers.
const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1",
    "0.5",
    "1e-308",
    "5e-324",
    "1e-12",
    "1e-6",
    "1e6",
    "1e12",
    "1e300",
    "6.1e201",
    "1.7976931348623157e308",
    "99",
    "0.001",
    "2",
    "65",
    "127",
    "128",
    "1e15",
    "4294967297",
    "nan",
    "inf",
    "-inf",
    "1.5.2",
    "",
    "0x10",
    "1_000",
];

const UNITS: &[&str] = &[
    "", "A", "mA", "kA", "V", "kV", "Hz", "kHz", "MHz", "rad/s", "rpm", "krpm", "Ω", "mΩ", "H", "mH", "µH", "Wb",
    "mWb", "N·m", "N·m/A", "V·s/rad", "rpm/V", "kg·m²", "g·cm²", "dB", "s", "ms", "µs", "°C", "K", "°", "rad", "rpm/s",
    "F", "J", "W", "%", "furlong",
];

/// Whole values a key may be set to (wrong types and structures included).
const VALUES: &[&str] = &[
    "true",
    "[]",
    "{}",
    "\"\"",
    "0",
    "-5",
    "1e400",
    "nan",
    "inf",
    "{ value = \"1 Ω\", measured = \"line_to_line\" }",
    "{ value = \"1 Ω\", measured = \"winding\" }",
    "{ value = \"1 N·m/A\", current = \"peak\" }",
    "\"pole_placement\"",
    "\"imc\"",
    "\"x */ int injected; /*\"",
    "\"a\\nb\"",
    "9223372036854775807",
    "1970-01-01",
];

const LINES: &[&str] = &[
    "[sensorless]",
    "[field_weakening]",
    "[adc]",
    "[thermal]",
    "[inverter]",
    "[losses]",
    "[scaling]\nmargin = 1e300",
    "[motor.identified]\nphase_resistance = \"1e-300 Ω\"",
    "[motor.harmonics]\nd_flux_6 = \"1e300 Wb\"",
    "[motor.saturation]\nq_inductance = [{ current = \"0 A\", inductance = \"1 mH\" }, { current = \"0 A\", inductance = \"1 mH\" }]",
    "stop_attenuation = \"99 dB\"",
    "damping = 1e-300",
    "method = \"pole_placement\"",
    "compensate_delay = false",
    "lead_samples = 1e300",
    "natural_frequency = \"1e7 rad/s\"",
    "rated_frequency = \"1e-300 Hz\"",
    "nominal_speed = \"1 rpm\"",
    "inertia = \"1e-300 kg·m²\"",
    "max_acceleration = \"1e300 rad/s²\"",
    "[",
    "]]",
    "=",
    "\"",
];

/// Extreme but syntactically valid `[fir]` corners (issue 31: a narrow pass band, a stop
/// edge near f_s/2 and a 99 dB target hung the design): band edges at the validator's
/// limits and next to f_s/2 for the seed motors' 10 and 20 kHz, orders up to the FMAC's.
const FIR_PASS: &[&str] = &["0.02 Hz", "0.01 Hz", "1 Hz", "100 Hz", "4 kHz", "4999 Hz"];
const FIR_STOP: &[&str] = &[
    "101 Hz", "2 kHz", "4990 Hz", "4999 Hz", "9900 Hz", "9990 Hz", "9999 Hz", "10 kHz",
];
const FIR_LENGTH: &[&str] = &[
    "order = 2",
    "order = 8",
    "order = 14",
    "order = 40",
    "order = 126",
    "stop_attenuation = \"99 dB\"",
    "stop_attenuation = \"100 dB\"",
    "stop_attenuation = \"60 dB\"",
    "stop_attenuation = \"1 dB\"",
];
const FIR_RIPPLE: &[&str] = &["0.001", "1e-6", "0.5"];

/// One mutation of `text`.
fn mutate(rng: &mut Rng, text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    match rng.below(11) {
        // One very long line (issue 31: an error located past column 65 535 panicked in
        // the diagnostic's Display): a value pushed far right, or a long bad value.
        9 => {
            let candidates: Vec<usize> = lines
                .iter()
                .enumerate()
                .filter(|(_, l)| l.contains('=') && !l.trim_start().starts_with('#'))
                .map(|(i, _)| i)
                .collect();
            if candidates.is_empty() {
                return text.to_string();
            }
            let i = *rng.pick(&candidates);
            let (key, value) = lines[i].split_once('=').unwrap();
            let n = *rng.pick(&[300, 65_530, 65_536, 70_000, 200_000]);
            let line = match rng.below(3) {
                0 => format!("{key}={}{value}", " ".repeat(n)),
                1 => format!("{key}= \"{}\"", "9".repeat(n)),
                _ => format!("{key}={value} # {}", "x".repeat(n)),
            };
            replace_line(&lines, i, &line)
        }
        // The `[fir]` section replaced by an extreme corner.
        10 => {
            let Some(h) = lines.iter().position(|l| l.trim_start().starts_with("[fir]")) else {
                return text.to_string();
            };
            let end = (h + 1..lines.len())
                .find(|&k| lines[k].trim_start().starts_with('['))
                .unwrap_or(lines.len());
            let fir = [
                "[fir]".to_string(),
                format!("pass_edge = \"{}\"", rng.pick(FIR_PASS)),
                format!("stop_edge = \"{}\"", rng.pick(FIR_STOP)),
                format!("pass_ripple = {}", rng.pick(FIR_RIPPLE)),
                rng.pick(FIR_LENGTH).to_string(),
            ];
            let mut out: Vec<String> = lines[..h].iter().map(|l| (*l).to_string()).collect();
            out.extend(fir);
            out.extend(lines[end..].iter().map(|l| (*l).to_string()));
            out.join("\n")
        }
        // A number inside a quoted quantity (or a bare number) replaced, its unit maybe too.
        0 | 1 => {
            let candidates: Vec<usize> = lines
                .iter()
                .enumerate()
                .filter(|(_, l)| l.contains('=') && !l.trim_start().starts_with('#'))
                .map(|(i, _)| i)
                .collect();
            if candidates.is_empty() {
                return text.to_string();
            }
            let i = *rng.pick(&candidates);
            let (key, _) = lines[i].split_once('=').unwrap();
            let number = rng.pick(NUMBERS);
            let value = if rng.chance(0.7) {
                let unit = if rng.chance(0.5) {
                    unit_of(lines[i]).unwrap_or("")
                } else {
                    rng.pick(UNITS)
                };
                format!("\"{number} {unit}\"")
            } else {
                number.to_string()
            };
            replace_line(&lines, i, &format!("{key}= {value}"))
        }
        // A key set to another kind of value.
        2 => {
            let i = rng.below(lines.len().max(1));
            match lines.get(i).and_then(|l| l.split_once('=')) {
                Some((key, _)) => replace_line(&lines, i, &format!("{key}= {}", rng.pick(VALUES))),
                None => text.to_string(),
            }
        }
        // A line dropped (a key or a section header).
        3 => {
            let i = rng.below(lines.len().max(1));
            lines
                .iter()
                .enumerate()
                .filter(|(k, _)| *k != i)
                .map(|(_, l)| *l)
                .collect::<Vec<_>>()
                .join("\n")
        }
        // A whole section dropped, header to the next header.
        4 => {
            let headers: Vec<usize> = (0..lines.len())
                .filter(|&k| lines[k].trim_start().starts_with('['))
                .collect();
            if headers.is_empty() {
                return text.to_string();
            }
            let h = rng.below(headers.len());
            let end = headers.get(h + 1).copied().unwrap_or(lines.len());
            let mut out: Vec<&str> = lines[..headers[h]].to_vec();
            out.extend(&lines[end..]);
            out.join("\n")
        }
        // Truncated at a character boundary.
        5 => {
            let mut at = rng.below(text.len() + 1);
            while !text.is_char_boundary(at) {
                at -= 1;
            }
            text[..at].to_string()
        }
        // Bytes flipped (the result read as the CLI reads a file: lossy UTF-8).
        6 => {
            let mut bytes = text.as_bytes().to_vec();
            for _ in 0..=rng.below(4) {
                if bytes.is_empty() {
                    break;
                }
                let k = rng.below(bytes.len());
                bytes[k] = match rng.below(3) {
                    0 => bytes[k] ^ (1 << rng.below(8)),
                    1 => *rng.pick(b"0123456789.-e\"=[]{},#\n "),
                    _ => (rng.below(256)) as u8,
                };
            }
            String::from_utf8_lossy(&bytes).into_owned()
        }
        // A line inserted somewhere (sections, keys, broken syntax).
        7 => {
            let i = rng.below(lines.len() + 1);
            let mut out: Vec<&str> = lines[..i].to_vec();
            out.push(*rng.pick(LINES));
            out.extend(&lines[i..]);
            out.join("\n")
        }
        // A line duplicated (duplicate keys or tables).
        _ => {
            let i = rng.below(lines.len().max(1));
            let mut out: Vec<&str> = lines.to_vec();
            if let Some(l) = lines.get(i) {
                out.insert(i, l);
            }
            out.join("\n")
        }
    }
}

/// The unit of a `key = "<number> <unit>"` line, if it has one.
fn unit_of(line: &str) -> Option<&str> {
    let v = line.split_once('=')?.1.trim();
    let inner = v.strip_prefix('"')?.split('"').next()?;
    inner.split_once(' ').map(|(_, u)| u)
}

/// Every diagnostic of `e` is located in one of `files` (`fuzz::located`).
fn located_in(e: &Diagnostics, files: &[&str]) -> Result<(), String> {
    fuzz::located(
        e.0.iter().map(|d| {
            (
                d.file.as_str(),
                d.line,
                d.column,
                d.problem.as_str(),
                d.accepted.as_str(),
            )
        }),
        files,
    )
}

/// An `Ok` design is all-finite and renders; an `Err` is located. `Ok(true)`: accepted.
fn judge_design(result: Result<Design, Diagnostics>, files: &[&str]) -> Result<bool, String> {
    match result {
        Ok(d) => {
            if let Some((path, x)) = first_non_finite(&minijinja::Value::from(minijinja::value::Serde(&d))) {
                return Err(format!("accepted design has `{path}` = {x}"));
            }
            for out in Output::ALL {
                let text = render(&d, out).map_err(|e| format!("{out:?} did not render: {e}"))?;
                if text.contains("NaN") || text.contains("inf;") || text.contains("inf,") {
                    return Err(format!("{out:?} output holds a non-finite number"));
                }
            }
            Ok(true)
        }
        Err(e) => {
            // The message as the CLI prints it (its Display panicked past column 65 535).
            let shown = e.to_string();
            if !files.iter().any(|f| shown.contains(f)) {
                return Err(format!("the printed diagnostics name no file: {shown}"));
            }
            located_in(&e, files).map(|()| false)
        }
    }
}

fn seeds() -> Vec<(String, String)> {
    motor_test_support::motors()
        .into_iter()
        .map(|(stem, _, text)| (stem, text))
        .collect()
}

/// Mutated specs (1–3 mutations of a file in motors/) through design, check and render.
#[test]
fn mutated_specs_never_panic_and_every_design_is_finite() {
    let seeds = seeds();
    fuzz::run("specs", cases(SPEC_CASES), |seed| {
        let mut rng = Rng::new(seed);
        let (_, base) = rng.pick(&seeds);
        let mut text = base.clone();
        for _ in 0..=rng.below(3) {
            text = mutate(&mut rng, &text);
        }
        let file = "fuzz.toml";
        let verdict = fuzz::caught(|| judge_design(codegen::design_source(file, &text), &[file]))
            .unwrap_or_else(|p| Err(format!("panic: {p}")));
        (text, verdict)
    });
}

/// Mutated board files (1–3 mutations of a file in boards/) with each motor, through
/// `design_with_board` (the board checks and the board's constants) and the templates.
#[test]
fn mutated_boards_never_panic_and_every_design_is_finite() {
    let motors = seeds();
    let boards: Vec<String> = motor_test_support::board_stems()
        .iter()
        .map(|b| motor_test_support::read(&format!("boards/{b}.toml")))
        .collect();
    fuzz::run("boards", cases(BOARD_CASES), |seed| {
        let mut rng = Rng::new(seed ^ 0xB0A4D);
        let (_, motor) = rng.pick(&motors);
        let mut text = rng.pick(&boards).clone();
        for _ in 0..=rng.below(3) {
            text = mutate(&mut rng, &text);
        }
        let verdict = fuzz::caught(|| {
            judge_design(
                codegen::design_with_board("m.toml", motor, "board.toml", &text),
                &["m.toml", "board.toml"],
            )
        })
        .unwrap_or_else(|p| Err(format!("panic: {p}")));
        (text, verdict)
    });
}

/// Finding of the 10^5-case release run (seed 71809): `voltage_fraction = 1e-308` on the
/// Chalmers spec was accepted and the field-weakening gain α_fw·L/V'_max (1e300-odd, finite
/// in f64) was written as `pub const GAIN_AT_BASE_SPEED: f32 = inf;`. Now the fraction has
/// a range and the finite gate judges numbers in f32 too.
#[test]
fn finding_voltage_fraction_overflowing_f32_is_refused_at_its_key() {
    let text = std::fs::read_to_string(motor_test_support::repo().join("motors/chalmers-hev50.toml")).unwrap();
    let from = "voltage_fraction = 0.9 ";
    assert!(text.contains(from));
    let bad = text.replacen(from, "voltage_fraction = 1e-308 ", 1);
    let e = codegen::design_source("c.toml", &bad).unwrap_err();
    let d = &e.0[0];
    assert_eq!(d.key, "field_weakening.voltage_fraction", "{e}");
    assert_eq!(
        d.line,
        bad[..bad.find("voltage_fraction = 1e-308").unwrap()]
            .matches('\n')
            .count()
            + 1
    );
    assert!(d.accepted.contains("from 0.5 to below 1"), "{e}");
    // The bound itself designs.
    let edge = text.replacen(from, "voltage_fraction = 0.5 ", 1);
    let design = codegen::design_source("c.toml", &edge).unwrap();
    assert!(judge_design(Ok(design), &["c.toml"]).unwrap());
}
