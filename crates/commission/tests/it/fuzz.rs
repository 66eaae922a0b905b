//! Bounded fuzzing of the recordings a user brings (issue 18): mutated recordings of
//! every routine through the CSV parser and the identification of that routine,
//! in-process, with `motor_test_support::fuzz`'s harness (seeded, reproducible; a panic
//! is a failure with its seed). Per case: no panic, every identified number finite,
//! every refusal located (file, line ≥ 1, column ≥ 1, what is wrong, what is accepted).
//!
//! CI runs `RECORDING_CASES`; more locally with
//! `MOTORGEN_FUZZ_CASES=100000 cargo test --release -p motor-commission --test it fuzz -- --nocapture`.

use codegen::{Design, Diagnostics};
use motor_commission::flux::{FluxSetup, identify_flux};
use motor_commission::recording::{self, RecordingKind};
use motor_commission::resolver::{identify_offset, identify_ratio};
use motor_commission::step::{StepSetup, identify_step};
use motor_commission::synthetic::step_recording;
use motor_control::commissioning::Axis;
use motor_test_support::fuzz::{self, Rng, cases, replace_line};

/// Recording cases in CI (debug build).
const RECORDING_CASES: usize = 3000;

/// Every diagnostic of `e` is located in `file` (`fuzz::located`).
fn located(e: &Diagnostics, file: &str) -> Result<(), String> {
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
        &[file],
    )
}

/// The design the recordings are identified against (its FIR, scalings and limits).
fn unimotor() -> Design {
    let text = motor_test_support::read("motors/unimotor-142umd300.toml");
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
        // Not identified from a recording (the session computes it from the capture).
        RecordingKind::FrequencyResponse => Err("the fuzz seeds have no frequency-response recording".into()),
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
    fuzz::run("recordings", cases(RECORDING_CASES), |seed| {
        let mut rng = Rng::new(seed);
        let (kind, base) = rng.pick(&seeds);
        let mut text = base.clone();
        for _ in 0..=rng.below(3) {
            text = mutate_recording(&mut rng, &text);
        }
        let verdict =
            fuzz::caught(|| judge_identification(&d, *kind, &text)).unwrap_or_else(|p| Err(format!("panic: {p}")));
        (text, verdict)
    });
}
