//! Bounded fuzzing of everything a user file reaches (issue 18): mutated motor specs (and
//! board files) through the design, the check and the three templates, and mutated
//! recordings through the CSV parser and the identification of their routine, all
//! in-process.
//!
//! Each case is derived from a seeded SplitMix64, so a failure prints the seed and the
//! mutated text and reproduces exactly. Per case: no panic (`catch_unwind`), every `Ok`
//! design has only finite numbers (its serialised form, what JSON and templates see) and
//! renders, every `Err` names the file, a line ≥ 1 and a column ≥ 1, what is wrong and what
//! is accepted. Work per case is bounded by construction (the spec is at most a few kB, the
//! recording a few thousand rows).
//!
//! CI runs a bounded slice (`SPEC_CASES`, `BOARD_CASES`, `RECORDING_CASES` below); more
//! locally with `MOTORGEN_FUZZ_CASES=100000 cargo test --release -p codegen --test fuzz -- --nocapture`
//! (the count applies to each of the three targets; `MOTORGEN_FUZZ_SEED` shifts the seeds).

mod common;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Instant;

use codegen::design::finite::first_non_finite;
use codegen::identify::flux::{FluxSetup, identify_flux};
use codegen::identify::recording::{self, RecordingKind};
use codegen::identify::resolver::{identify_offset, identify_ratio};
use codegen::identify::step::{StepSetup, identify_step};
use codegen::render::{Output, render};
use codegen::{Design, Diagnostics};
use common::recordings::{Noise, step_recording};
use motor_control::commissioning::Axis;

/// Spec cases in CI (debug build).
const SPEC_CASES: usize = 800;
/// Board cases in CI (debug build).
const BOARD_CASES: usize = 40;
/// Recording cases in CI (debug build).
const RECORDING_CASES: usize = 3000;

fn cases(default: usize) -> usize {
    std::env::var("MOTORGEN_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

fn seed_base() -> u64 {
    std::env::var("MOTORGEN_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0)
}

/// The seeded generator (SplitMix64, as the recordings' noise).
struct Rng(Noise);

impl Rng {
    fn new(seed: u64) -> Rng {
        Rng(Noise(seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ 0x1234_5678))
    }
    fn below(&mut self, n: usize) -> usize {
        ((self.0.uniform() * n as f64) as usize).min(n.saturating_sub(1))
    }
    fn pick<'a, T>(&mut self, xs: &'a [T]) -> &'a T {
        &xs[self.below(xs.len())]
    }
    fn chance(&mut self, p: f64) -> bool {
        self.0.uniform() < p
    }
}

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

/// One mutation of `text`.
fn mutate(rng: &mut Rng, text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    match rng.below(9) {
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

fn replace_line(lines: &[&str], i: usize, new: &str) -> String {
    let mut out: Vec<&str> = lines.to_vec();
    out[i] = new;
    out.join("\n")
}

/// Every diagnostic names its file, a position and what would be accepted.
fn located(e: &Diagnostics, file: &str) -> Result<(), String> {
    located_in(e, &[file])
}

/// As [`located`], for an input of several files.
fn located_in(e: &Diagnostics, files: &[&str]) -> Result<(), String> {
    if e.0.is_empty() {
        return Err("an error without any diagnostic".into());
    }
    for d in &e.0 {
        if !files.contains(&d.file.as_str())
            || d.line == 0
            || d.column == 0
            || d.problem.is_empty()
            || d.accepted.is_empty()
        {
            return Err(format!("unlocated diagnostic: {d:?}"));
        }
    }
    Ok(())
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
        Err(e) => located_in(&e, files).map(|()| false),
    }
}

fn seeds() -> Vec<(String, String)> {
    common::motor_stems()
        .into_iter()
        .map(|stem| {
            let path = common::repo().join("motors").join(format!("{stem}.toml"));
            (stem, std::fs::read_to_string(path).unwrap())
        })
        .collect()
}

/// Runs `n` cases of `one` from seed `base`, printing counts and the slowest case.
fn run(name: &str, n: usize, mut one: impl FnMut(u64) -> (String, Result<bool, String>)) {
    let started = Instant::now();
    let mut failures = Vec::new();
    let mut accepted = 0usize;
    let mut slowest = (0.0f64, 0u64);
    for k in 0..n as u64 {
        let seed = seed_base() + k;
        let t = Instant::now();
        let (input, verdict) = one(seed);
        let dt = t.elapsed().as_secs_f64();
        if dt > slowest.0 {
            slowest = (dt, seed);
        }
        if verdict == Ok(true) {
            accepted += 1;
        }
        if n >= 10_000 && (k + 1) % (n as u64 / 10) == 0 {
            eprintln!("{name}: {} cases, {:.0} s", k + 1, started.elapsed().as_secs_f64());
        }
        if n == 1 {
            eprintln!("seed {seed} ({dt:.2} s): {verdict:?}\n--- input ---\n{input}\n---");
        }
        if let Err(why) = verdict {
            // Printed at once: a long run shows its findings while it goes on.
            eprintln!("FAILURE seed {seed}: {why}\n--- input ---\n{input}\n---");
            failures.push(format!("seed {seed}: {why}\n--- input ---\n{input}\n---"));
            if failures.len() >= 5 {
                break;
            }
        }
    }
    eprintln!(
        "{name}: {n} cases ({accepted} accepted, the rest refused with a located error) in {:.1} s, slowest {:.2} s (seed {}), {} failures",
        started.elapsed().as_secs_f64(),
        slowest.0,
        slowest.1,
        failures.len()
    );
    // The cases silence the panic hook (a caught panic is a finding, not noise); the
    // verdict must be heard.
    let _ = std::panic::take_hook();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn panic_text(p: Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "non-string panic".into())
}

/// Mutated specs (1–3 mutations of a file in motors/) through design, check and render.
#[test]
fn mutated_specs_never_panic_and_every_design_is_finite() {
    let seeds = seeds();
    std::panic::set_hook(Box::new(|_| {}));
    run("specs", cases(SPEC_CASES), |seed| {
        let mut rng = Rng::new(seed);
        let (_, base) = rng.pick(&seeds);
        let mut text = base.clone();
        for _ in 0..=rng.below(3) {
            text = mutate(&mut rng, &text);
        }
        let file = "fuzz.toml";
        let verdict = catch_unwind(AssertUnwindSafe(|| {
            judge_design(codegen::design_source(file, &text), &[file])
        }))
        .unwrap_or_else(|p| Err(format!("panic: {}", panic_text(p))));
        (text, verdict)
    });
}

/// Mutated board files (1–3 mutations of a file in boards/) with each motor, through
/// `design_with_board` (the board checks and the board's constants) and the templates.
#[test]
fn mutated_boards_never_panic_and_every_design_is_finite() {
    let motors = seeds();
    let mut boards = Vec::new();
    for e in std::fs::read_dir(common::repo().join("boards")).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_some_and(|x| x == "toml") {
            boards.push(std::fs::read_to_string(path).unwrap());
        }
    }
    boards.sort();
    std::panic::set_hook(Box::new(|_| {}));
    run("boards", cases(BOARD_CASES), |seed| {
        let mut rng = Rng::new(seed ^ 0xB0A4D);
        let (_, motor) = rng.pick(&motors);
        let mut text = rng.pick(&boards).clone();
        for _ in 0..=rng.below(3) {
            text = mutate(&mut rng, &text);
        }
        let verdict = catch_unwind(AssertUnwindSafe(|| {
            judge_design(
                codegen::design_with_board("m.toml", motor, "board.toml", &text),
                &["m.toml", "board.toml"],
            )
        }))
        .unwrap_or_else(|p| Err(format!("panic: {}", panic_text(p))));
        (text, verdict)
    });
}

/// The design the recordings are identified against (its FIR, scalings and limits).
fn unimotor() -> Design {
    let text = std::fs::read_to_string(common::repo().join("motors/unimotor-142umd300.toml")).unwrap();
    codegen::design_source("unimotor-142umd300.toml", &text).unwrap()
}

/// Seed recordings of every kind, in the format the firmware writes.
fn recording_seeds(d: &Design) -> Vec<(RecordingKind, String)> {
    // A short step (R = 0.65 Ω, L = 7.6 mH, as tests/identify.rs) keeps debug cases fast:
    // τ = 11.7 ms = 117 periods at 10 kHz, 40 + 12τ rows.
    let step = step_recording(d, "q", 0.65, 7.6e-3, 7);
    let mut flux = String::from("# motorgen recording: flux\nsample,omega_e_rad_s,u_q_v,i_d_a,i_q_a\n");
    for n in 0..200 {
        let w = 300.0 + 0.5 * ((n as f64) * 0.1).sin();
        flux.push_str(&format!("{n},{w},{},0.01,-0.02\n", w * 0.1));
    }
    let mut offset = String::from("# motorgen recording: resolver_offset\nsample,u_alpha_v,theta_r_rad\n");
    for n in 0..200 {
        offset.push_str(&format!(
            "{n},{},{}\n",
            if n < 20 { 0.0 } else { 5.0 },
            0.42 + 1e-4 * n as f64
        ));
    }
    let mut ratio = String::from("# motorgen recording: pole_pair_ratio\nsample,theta_e_rad,theta_r_rad\n");
    for n in 0..400 {
        let te = 0.05 * n as f64;
        let wrap = |x: f64| (x + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        ratio.push_str(&format!("{n},{},{}\n", wrap(te), wrap(te / 3.0 + 0.1)));
    }
    vec![
        (RecordingKind::Step, step),
        (RecordingKind::Flux, flux),
        (RecordingKind::ResolverOffset, offset),
        (RecordingKind::PolePairRatio, ratio),
    ]
}

const CELLS: &[&str] = &[
    "0",
    "-0",
    "1e300",
    "-1e300",
    "1e-300",
    "5e-324",
    "1.7976931348623157e308",
    "nan",
    "inf",
    "-inf",
    "",
    "x",
    "1e15",
    "9007199254740993",
    "3.14159",
    "-6.3",
    "0.5",
];

const HEADERS: &[&str] = &[
    "# sample_period = 1e300 s",
    "# sample_period = 0 s",
    "# sample_period = 1e-300 s",
    "# sample_period = -1 µs",
    "# sample_period = nan s",
    "# sample_period = 50",
    "# axis = d",
    "# axis = z",
    "# motorgen recording: flux",
    "# motorgen recording: step",
    "time_s,voltage_v,current_a",
    "sample,u_alpha_v,theta_r_rad",
];

/// One mutation of a recording: cells, rows, header keys, the time column, truncation.
fn mutate_recording(rng: &mut Rng, text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let data: Vec<usize> = (0..lines.len())
        .filter(|&k| lines[k].starts_with(|c: char| c.is_ascii_digit() || c == '-'))
        .collect();
    match rng.below(7) {
        // One cell replaced.
        0 | 1 if !data.is_empty() => {
            let i = *rng.pick(&data);
            let mut cells: Vec<&str> = lines[i].split(',').collect();
            let c = rng.below(cells.len());
            cells[c] = *rng.pick(CELLS);
            replace_line(&lines, i, &cells.join(","))
        }
        // Every row's time offset by a huge amount (or the time scaled).
        2 if !data.is_empty() => {
            let offset = *rng.pick(&[1e15, 1e300, -1e6, 4.5e15, 0.5]);
            let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
            for &i in &data {
                let mut cells: Vec<String> = lines[i].split(',').map(str::to_string).collect();
                if let Ok(t) = cells[0].parse::<f64>() {
                    cells[0] = format!("{}", t + offset);
                }
                out[i] = cells.join(",");
            }
            out.join("\n")
        }
        // A header line inserted at the top.
        3 => format!("{}\n{text}", rng.pick(HEADERS)),
        // Rows dropped down to a few (empty, one row, two rows).
        4 => {
            let keep = rng.below(4);
            let first_data = data.first().copied().unwrap_or(lines.len());
            let mut out: Vec<&str> = lines[..first_data].to_vec();
            out.extend(data.iter().take(keep).map(|&i| lines[i]));
            out.join("\n")
        }
        // Truncated.
        5 => {
            let mut at = rng.below(text.len() + 1);
            while !text.is_char_boundary(at) {
                at -= 1;
            }
            text[..at].to_string()
        }
        // A column scaled so a ratio or a mean degenerates (every value of a column set).
        _ if !data.is_empty() => {
            let width = lines[data[0]].split(',').count();
            let c = rng.below(width);
            let v = *rng.pick(CELLS);
            let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
            for &i in &data {
                let mut cells: Vec<&str> = lines[i].split(',').collect();
                if c < cells.len() {
                    cells[c] = v;
                }
                out[i] = cells.join(",");
            }
            out.join("\n")
        }
        _ => text.to_string(),
    }
}

/// Every finite identified number, or a located error. `Ok(true)`: identified.
fn judge_identification(d: &Design, kind: RecordingKind, text: &str) -> Result<bool, String> {
    let file = "fuzz.csv";
    let rec = match recording::parse(file, text, kind, d.drive.sample_period_s) {
        Ok(r) => r,
        Err(e) => return located(&e, file).map(|()| false),
    };
    let finite = |xs: &[f64]| {
        if xs.iter().all(|x| x.is_finite()) {
            Ok(true)
        } else {
            Err(format!("an identified value is not finite: {xs:?}"))
        }
    };
    match kind {
        RecordingKind::Step => match identify_step(
            &rec,
            &StepSetup {
                axis: Axis::Q,
                taps_q15: d.fir.taps_q15.clone(),
                current_full_scale_a: d.scaling.phase_current.full_scale,
                current_limit_a: d.motor.peak_current_a,
                voltage_limit_v: d.current_loop.voltage_limit_v,
            },
        ) {
            Ok(e) => finite(&[
                e.voltage_v,
                e.current_change_a,
                e.resistance_ohm,
                e.rise_time_s,
                e.time_constant_s,
                e.inductance_h,
                e.crossing_5_samples,
                e.delay_samples,
            ]),
            Err(e) => located(&e, file).map(|()| false),
        },
        RecordingKind::Flux => match identify_flux(
            &rec,
            &FluxSetup {
                resistance_ohm: d.motor.phase_resistance_ohm,
                d_inductance_h: d.motor.d_inductance_h,
                max_current_a: 0.1 * d.motor.peak_current_a,
                min_speed_rad_s: 0.05 * d.motor.max_electrical_speed_rad_s,
                voltage_limit_v: d.current_loop.voltage_limit_v,
            },
        ) {
            Ok(e) => finite(&[e.flux_linkage_wb, e.mean_speed_rad_s, e.correction_wb]),
            Err(e) => located(&e, file).map(|()| false),
        },
        RecordingKind::ResolverOffset => match identify_offset(&rec, 3, 1) {
            Ok(e) => finite(&[e.offset_rad, e.deviation_rad]),
            Err(e) => located(&e, file).map(|()| false),
        },
        RecordingKind::PolePairRatio => match identify_ratio(&rec) {
            Ok(e) => finite(&[e.ratio, e.electrical_travel_rad, e.resolver_travel_rad]),
            Err(e) => located(&e, file).map(|()| false),
        },
    }
}

/// Mutated recordings (1–3 mutations of a valid recording of each kind) through the parser
/// and the identification of their routine.
#[test]
fn mutated_recordings_never_panic_and_every_estimate_is_finite() {
    let d = unimotor();
    let seeds = recording_seeds(&d);
    // The unmutated seeds identify: the mutations start from working recordings.
    for (kind, text) in &seeds {
        judge_identification(&d, *kind, text).unwrap();
        assert!(recording::parse("s.csv", text, *kind, d.drive.sample_period_s).is_ok());
    }
    std::panic::set_hook(Box::new(|_| {}));
    run("recordings", cases(RECORDING_CASES), |seed| {
        let mut rng = Rng::new(seed);
        let (kind, base) = rng.pick(&seeds);
        let mut text = base.clone();
        for _ in 0..=rng.below(3) {
            text = mutate_recording(&mut rng, &text);
        }
        let verdict = catch_unwind(AssertUnwindSafe(|| judge_identification(&d, *kind, &text)))
            .unwrap_or_else(|p| Err(format!("panic: {}", panic_text(p))));
        (text, verdict)
    });
}

/// Finding of the 10^5-case release run (seed 71809): `voltage_fraction = 1e-308` on the
/// Chalmers spec was accepted and the field-weakening gain α_fw·L/V'_max (1e300-odd, finite
/// in f64) was written as `pub const GAIN_AT_BASE_SPEED: f32 = inf;`. Now the fraction has
/// a range and the finite gate judges numbers in f32 too.
#[test]
fn finding_voltage_fraction_overflowing_f32_is_refused_at_its_key() {
    let text = std::fs::read_to_string(common::repo().join("motors/chalmers-hev50.toml")).unwrap();
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
