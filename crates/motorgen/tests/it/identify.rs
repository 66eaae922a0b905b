//! Identification from recorded commissioning data (thesis A chapter 6), end to end.
//!
//! * Every seed motor: blocked-rotor step recordings generated from the motor's known
//!   R, L_d, L_q with the plant's blocked-rotor equation (thesis A (6.4) with a dead
//!   time: i = U/R·(1 − e^(−(t − T_d)/τ)), the `verify` plant at ω = 0), Gaussian noise,
//!   12-bit ADC quantisation and a 1.5-sample transport delay; R and L recovered within
//!   2 %, the delay within one sample.
//! * The firmware's `VoltageStep` routine run against the `verify` bench (firmware control
//!   step + plant), its capture written by `write_step_csv` and identified.
//! * The CLI round trip: identify → the spec file is updated with its comments kept →
//!   `motorgen design` shows provenance "identified" → `motorgen verify` passes.
//! * Bad recordings fail with located errors and write nothing.

use crate::common::{motorgen, repo};
use motor_commission::synthetic::{DELAY, step_recording};

use std::path::PathBuf;

use codegen::{Design, Source};
use motor_commission::Spread;
use motor_commission::recording::{self, RecordingKind, StepRun, write_step_csv};
use motor_commission::step::{StepSetup, identify_step};
use motor_control::commissioning::{Axis, Progress, VoltageStep, VoltageStepState};

fn tmp(name: &str) -> PathBuf {
    crate::common::tmp("identify", name)
}

fn design_of(stem: &str) -> (String, Design) {
    let text = std::fs::read_to_string(repo().join(format!("motors/{stem}.toml"))).unwrap();
    let d = codegen::design_source(stem, &text).unwrap();
    (text, d)
}

fn setup(d: &Design, axis: Axis) -> StepSetup {
    StepSetup {
        axis,
        taps_q15: d.fir.taps_q15.clone(),
        current_full_scale_a: d.scaling.phase_current.full_scale,
        current_limit_a: d.motor.peak_current_a,
        voltage_limit_v: d.current_loop.voltage_limit_v,
    }
}

/// Each seed motor, both axes, 10 noisy recordings each: R and L of every recording
/// within 2 % of the values the recordings were generated with, and the delay averaged
/// over the 10 recordings within one sample of 1.5 (a single 5 % crossing of the slow
/// Chalmers q axis, τ = 709 samples, moves by one to two samples with the noise).
#[test]
fn recovers_r_l_and_delay_of_every_seed_motor() {
    for stem in ["fischer-ti085", "unimotor-142umd300", "chalmers-hev50"] {
        let (_, d) = design_of(stem);
        let r = d.motor.phase_resistance_ohm;
        for (axis, name, l) in [
            (Axis::D, "d", d.motor.d_inductance_h),
            (Axis::Q, "q", d.motor.q_inductance_h),
        ] {
            let mut rs = vec![];
            let mut ls = vec![];
            let mut ds = vec![];
            for seed in 1..=10u64 {
                let text = step_recording(&d, name, r, l, seed + if name == "q" { 100 } else { 0 });
                let rec = recording::parse("gen.csv", &text, RecordingKind::Step, 0.0).unwrap();
                let e = identify_step(&rec, &setup(&d, axis)).unwrap();
                assert!(
                    (e.resistance_ohm / r - 1.0).abs() < 0.02,
                    "{stem} {name} seed {seed}: {e:?}"
                );
                assert!(
                    (e.inductance_h / l - 1.0).abs() < 0.02,
                    "{stem} {name} seed {seed}: {e:?}"
                );
                rs.push(e.resistance_ohm);
                ls.push(e.inductance_h);
                ds.push(e.delay_samples);
            }
            let (rs, ls, ds) = (
                Spread::of(&rs).unwrap(),
                Spread::of(&ls).unwrap(),
                Spread::of(&ds).unwrap(),
            );
            eprintln!(
                "{stem} {name}: R error {:+.3} % (±{:.3} %), L error {:+.3} % (±{:.3} %), delay {:.2} ± {:.2} samples (true {DELAY})",
                100.0 * (rs.mean / r - 1.0),
                rs.relative_percent(),
                100.0 * (ls.mean / l - 1.0),
                ls.relative_percent(),
                ds.mean,
                ds.std_dev
            );
            assert!((rs.mean / r - 1.0).abs() < 0.02);
            assert!((ls.mean / l - 1.0).abs() < 0.02);
            assert!((ds.mean - DELAY).abs() < 1.0);
        }
    }
}

/// The firmware's `VoltageStep` (thesis A §6.2) on the `verify` bench — firmware control
/// step, ADC quantisation of the phase currents, and the plant with its one-period PWM
/// update delay — for the Unimotor q axis (Table 6.1: R = 0.65 Ω, L_q = 7.6 mH); the
/// capture buffer is written with `write_step_csv` and identified: R, L within 2 %.
/// Delay: the routine is handed the i_dq the control step measured in the previous
/// period (it must choose the demand before the step runs), and the bench applies a
/// duty from the period after it was computed, so the captured response starts
/// 2 periods after the commanded step: delay within one sample of 2.
#[test]
fn firmware_voltage_step_capture_identifies() {
    let (text, d) = design_of("unimotor-142umd300");
    let spec = codegen::spec::parse(Source {
        file: "u.toml",
        text: &text,
    })
    .unwrap();
    let setup_v = motor_verify::Setup::new(&spec, &d);
    let run = |voltage: f32, trip: f32| {
        let mut bench = setup_v.bench(0.0);
        let routine = VoltageStep {
            axis: Axis::Q,
            voltage,
            current_trip: trip,
            pre_samples: 40,
            step_samples: 3000,
            decimation: 1,
        };
        let mut st = VoltageStepState::<3100>::new();
        let mut i_dq = motor_control::transforms::Dq { d: 0.0, q: 0.0 };
        let outcome = loop {
            match routine.process(&mut st, i_dq) {
                Progress::Running(demand) => i_dq = bench.step(demand).out.i_dq,
                Progress::Finished(r) => break r,
            }
        };
        let run = StepRun {
            axis: Axis::Q,
            current_trip: trip,
            outcome: outcome.map(|_| ()),
        };
        write_step_csv(st.captures(), d.drive.sample_period_s, &run)
    };
    let csv = run(4.0, 10.0);
    let rec = recording::parse("capture.csv", &csv, RecordingKind::Step, 0.0).unwrap();
    let e = identify_step(&rec, &setup(&d, Axis::Q)).unwrap();
    eprintln!(
        "firmware capture: R = {:.4} Ω, L_q = {:.4} mH, delay {:.2} samples",
        e.resistance_ohm,
        e.inductance_h * 1e3,
        e.delay_samples
    );
    assert!((e.resistance_ohm / 0.65 - 1.0).abs() < 0.02, "{e:?}");
    assert!((e.inductance_h / 7.6e-3 - 1.0).abs() < 0.02, "{e:?}");
    assert!((e.delay_samples - 2.0).abs() < 1.0, "{e:?}");

    // 10 V/0.65 Ω = 15.4 A: the routine trips at 10 A; its capture says so and the
    // identification refuses it.
    let csv = run(10.0, 10.0);
    assert!(csv.contains("# tripped = sample"), "{csv}");
    let rec = recording::parse("tripped.csv", &csv, RecordingKind::Step, 0.0).unwrap();
    let err = identify_step(&rec, &setup(&d, Axis::Q)).unwrap_err();
    assert!(err.to_string().contains("tripped"), "{err}");
}

/// The CLI round trip on a copy of the Fischer spec (datasheet values only).
#[test]
fn identify_design_verify_round_trip() {
    let dir = tmp("round_trip");
    let original = std::fs::read_to_string(repo().join("motors/fischer-ti085.toml")).unwrap();
    let spec = dir.join("fischer.toml");
    std::fs::write(&spec, &original).unwrap();
    let (_, d) = design_of("fischer-ti085");
    // A "measured" motor 5 % off the datasheet: R = 0.1323 Ω, L = 0.4127 mH.
    let (r, l) = (0.126 * 1.05, 0.393e-3 * 1.05);
    let mut files = vec![];
    for seed in 1..=3u64 {
        let f = dir.join(format!("q{seed}.csv"));
        std::fs::write(&f, step_recording(&d, "q", r, l, seed)).unwrap();
        files.push(f.display().to_string());
    }
    let spec_s = spec.display().to_string();
    let mut args = vec![
        "identify",
        "step",
        &spec_s,
        "--axis",
        "q",
        "--date",
        "2025-03-14",
        "--csv",
    ];
    args.extend(files.iter().map(String::as_str));

    // --dry-run: the change is printed, the file is untouched.
    let mut dry = args.clone();
    dry.push("--dry-run");
    let out = motorgen(&dry);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        stdout.contains("+") && stdout.contains("[motor.identified]"),
        "{stdout}"
    );
    assert_eq!(std::fs::read_to_string(&spec).unwrap(), original);

    let out = motorgen(&args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    let updated = std::fs::read_to_string(&spec).unwrap();
    // Every original line is still there (comments and layout kept); only the new
    // section was added.
    let mut rest = updated.as_str();
    for line in original.lines() {
        let at = rest
            .find(line)
            .unwrap_or_else(|| panic!("line lost: {line:?}\n{updated}"));
        rest = &rest[at + line.len()..];
    }
    assert!(
        updated.contains("[motor.identified]\nphase_resistance = \""),
        "{updated}"
    );
    assert!(
        updated.contains("date = 2025-03-14\nsource = \"step q: q1.csv, q2.csv, q3.csv\""),
        "{updated}"
    );

    // The design uses the identified values: provenance "identified", within 2 % of the
    // generating values; L_d stays the datasheet's.
    let out = motorgen(&["design", &spec_s, "--format", "json"]);
    assert!(out.status.success());
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let m = &json["motor"];
    assert_eq!(m["provenance"]["phase_resistance"]["source"], "identified", "{m}");
    assert_eq!(m["provenance"]["q_inductance"]["source"], "identified", "{m}");
    assert_eq!(m["provenance"]["d_inductance"]["source"], "datasheet", "{m}");
    assert!(
        (m["phase_resistance_ohm"].as_f64().unwrap() / r - 1.0).abs() < 0.02,
        "{m}"
    );
    assert!((m["q_inductance_h"].as_f64().unwrap() / l - 1.0).abs() < 0.02, "{m}");
    assert_eq!(m["d_inductance_h"].as_f64().unwrap(), 0.393e-3);
    let out = motorgen(&["design", &spec_s, "--format", "markdown"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("(identified)"));

    let out = motorgen(&["verify", &spec_s]);
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );

    // The d axis next: both axes identified, the `source` lists both runs.
    let f = dir.join("d1.csv");
    std::fs::write(&f, step_recording(&d, "d", r, l, 9)).unwrap();
    let fd = f.display().to_string();
    let out = motorgen(&[
        "identify",
        "step",
        &spec_s,
        "--axis",
        "d",
        "--date",
        "2025-03-15",
        "--csv",
        &fd,
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let updated = std::fs::read_to_string(&spec).unwrap();
    assert!(
        updated.contains("source = \"step q: q1.csv, q2.csv, q3.csv; step d: d1.csv\""),
        "{updated}"
    );
    let out = motorgen(&["verify", &spec_s]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stdout));
}

/// Runs `identify step` on one bad recording and checks the located error and that the
/// spec was not touched.
fn rejects(name: &str, csv: &str, line: usize, words: &[&str]) {
    let dir = tmp(name);
    let original = std::fs::read_to_string(repo().join("motors/unimotor-142umd300.toml")).unwrap();
    let spec = dir.join("u.toml");
    std::fs::write(&spec, &original).unwrap();
    let f = dir.join(format!("{name}.csv"));
    std::fs::write(&f, csv).unwrap();
    let (spec_s, f_s) = (spec.display().to_string(), f.display().to_string());
    let out = motorgen(&["identify", "step", &spec_s, "--axis", "q", "--csv", &f_s]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success(),
        "{name}: accepted\n{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(err.contains(&format!("{f_s}:{line}:")), "{name}: {err}");
    for w in words {
        assert!(err.contains(w), "{name}: {w:?} missing in {err}");
    }
    assert!(err.contains("accepted:"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(std::fs::read_to_string(&spec).unwrap(), original, "{name}");
    let leftovers: Vec<_> = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).collect();
    assert_eq!(leftovers.len(), 2, "{name}: temporary files left");
}

/// Each bad-recording class of the issue: too short, saturated, no step, current limit
/// tripped, non-monotonic time, NaN.
#[test]
fn bad_recordings_are_located_errors() {
    let (_, d) = design_of("unimotor-142umd300");
    let (r, l) = (0.65, 7.6e-3);
    let good = step_recording(&d, "q", r, l, 1);
    let header_lines = 4; // 3 comments + the column line
    let lines: Vec<&str> = good.lines().collect();

    // Too short: the first 1000 rows (40 + 960 periods = 4 τ).
    let short = lines[..header_lines + 1000].join("\n") + "\n";
    rejects("short", &short, header_lines + 1000, &["too short", "sample"]);

    // Saturated: one current at the measurement full scale (17.68 A).
    let with_current = |line: &str, i: &str| {
        let mut p: Vec<&str> = line.split(',').collect();
        p[2] = i;
        p.join(",")
    };
    let mut sat = lines.clone();
    let row = with_current(lines[header_lines + 500], "17.7");
    sat[header_lines + 500] = &row;
    rejects(
        "saturated",
        &(sat.join("\n") + "\n"),
        header_lines + 501,
        &["saturated", "current_a"],
    );

    // No step: the voltage column all zero.
    let flat: String = lines
        .iter()
        .enumerate()
        .map(|(k, l)| {
            if k < header_lines {
                format!("{l}\n")
            } else {
                let mut p: Vec<&str> = l.split(',').collect();
                p[1] = "0";
                p.join(",") + "\n"
            }
        })
        .collect();
    rejects("no_step", &flat, lines.len(), &["no step found", "voltage_v"]);

    // Current limit: the recording's own trip level below the final current (7.1 A).
    let tripped = good.replace("# axis = q\n", "# axis = q\n# current_trip = 5 A\n");
    let first_over = tripped
        .lines()
        .position(|l| {
            l.split(',')
                .nth(2)
                .and_then(|x| x.parse::<f64>().ok())
                .is_some_and(|i| i >= 5.0)
        })
        .unwrap();
    rejects("tripped", &tripped, first_over + 1, &["current limit tripped"]);

    // Non-monotonic time: row 300 repeats sample 299.
    let mut back = lines.clone();
    let replaced = back[header_lines + 300].replacen("300,", "299,", 1);
    back[header_lines + 300] = &replaced;
    rejects(
        "non_monotonic",
        &(back.join("\n") + "\n"),
        header_lines + 301,
        &["non-monotonic"],
    );

    // NaN current.
    let mut nan = lines.clone();
    let row = with_current(lines[header_lines + 700], "NaN");
    nan[header_lines + 700] = &row;
    rejects(
        "nan",
        &(nan.join("\n") + "\n"),
        header_lines + 701,
        &["NaN", "current_a"],
    );
}

/// `identify flux` on the Fischer spec: runs at ω_e = 800 and 1200 rad/s whose u_q holds
/// ω_e·ψ_M for ψ_M = 60.0 mWb plus the R·i_q and ω_e·L_d·i_d terms of small residual
/// currents (steady-state (6.1)); the command writes flux_linkage = "60.00 mWb", which
/// the design then takes over the datasheet's K_e-derived value.
#[test]
fn flux_round_trip() {
    let dir = tmp("flux");
    let spec = dir.join("fischer.toml");
    std::fs::copy(repo().join("motors/fischer-ti085.toml"), &spec).unwrap();
    let mut files = vec![];
    for (k, w) in [800.0f64, 1200.0].into_iter().enumerate() {
        let mut s = String::from("# motorgen recording: flux\nsample,omega_e_rad_s,u_q_v,i_d_a,i_q_a\n");
        for n in 0..200 {
            let (id, iq) = (0.05 * (n as f64 * 0.1).sin(), 0.08 * (n as f64 * 0.07).cos());
            let uq = w * 0.060 + 0.126 * iq + w * 0.393e-3 * id;
            s.push_str(&format!("{n},{w},{uq},{id},{iq}\n"));
        }
        let f = dir.join(format!("flux{k}.csv"));
        std::fs::write(&f, s).unwrap();
        files.push(f.display().to_string());
    }
    let spec_s = spec.display().to_string();
    let out = motorgen(&[
        "identify",
        "flux",
        &spec_s,
        "--date",
        "2025-03-14",
        "--csv",
        &files[0],
        &files[1],
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let updated = std::fs::read_to_string(&spec).unwrap();
    assert!(updated.contains("flux_linkage = \"60.00 mWb\""), "{updated}");
    let out = motorgen(&["design", &spec_s, "--format", "json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["motor"]["provenance"]["flux_linkage"]["source"], "identified");
    assert!((json["motor"]["flux_linkage_wb"].as_f64().unwrap() - 0.060).abs() < 1e-12);
}

/// `identify resolver` on the Fischer spec (n_p = 4, n_r = 1): a rotation run with the
/// resolver turning a quarter as far as the field checks the ratio; an alignment run
/// at θ_r = 2.0 rad gives θ_off = 2.0 − π/2 = 0.42920 rad (6.9, modulo 2π·n_r/n_p). A
/// run with the resolver turning backwards, or half as far (ratio 2), is refused at
/// `motor.pole_pairs` and nothing is written.
#[test]
fn resolver_round_trip_and_ratio_check() {
    use std::f64::consts::{PI, TAU};
    let wrap = |x: f64| x - TAU * ((x + PI) / TAU).floor();
    let dir = tmp("resolver");
    let spec = dir.join("fischer.toml");
    std::fs::copy(repo().join("motors/fischer-ti085.toml"), &spec).unwrap();
    let original = std::fs::read_to_string(&spec).unwrap();
    let rotation = |name: &str, per_turn: f64| {
        let mut s = String::from("# motorgen recording: pole_pair_ratio\nsample,theta_e_rad,theta_r_rad\n");
        for n in 0..=1000 {
            let e = TAU * 8.0 * n as f64 / 1000.0;
            s.push_str(&format!("{n},{},{}\n", wrap(e), wrap(0.7 + e * per_turn)));
        }
        let f = dir.join(name);
        std::fs::write(&f, s).unwrap();
        f.display().to_string()
    };
    let mut s = String::from("# motorgen recording: resolver_offset\nsample,u_alpha_v,theta_r_rad\n");
    for n in 0..400 {
        let u = (n as f64 / 100.0).min(1.0);
        let th = if n < 200 { 1.0 } else { 2.0 + 1e-4 * (n as f64).sin() };
        s.push_str(&format!("{n},{u},{th}\n"));
    }
    let offset = dir.join("align.csv");
    std::fs::write(&offset, s).unwrap();
    let (spec_s, offset_s) = (spec.display().to_string(), offset.display().to_string());

    for (name, per_turn, words) in [
        ("backwards.csv", -0.25, "turns against the stator field"),
        ("half.csv", 0.5, "disagrees with the spec's 4/1"),
    ] {
        let f = rotation(name, per_turn);
        let out = motorgen(&["identify", "resolver", &spec_s, "--ratio", &f, "--offset", &offset_s]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(err.contains(words) && err.contains("`motor.pole_pairs`"), "{err}");
        // The line of `[motor]`'s `pole_pairs = 4`, column of its value.
        let line = original[..original.find("pole_pairs = 4").unwrap()]
            .matches('\n')
            .count()
            + 1;
        assert!(err.contains(&format!("{spec_s}:{line}:14")), "{err}");
        assert_eq!(std::fs::read_to_string(&spec).unwrap(), original);
    }
    let good = rotation("good.csv", 0.25);
    let out = motorgen(&[
        "identify",
        "resolver",
        &spec_s,
        "--date",
        "2025-03-14",
        "--ratio",
        &good,
        "--offset",
        &offset_s,
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("n_p/n_r = 4.0000"), "{stdout}");
    let updated = std::fs::read_to_string(&spec).unwrap();
    assert!(updated.contains("resolver_offset = \"0.42920 rad\""), "{updated}");
    let out = motorgen(&["design", &spec_s, "--format", "json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

/// The merge rule: one identified axis next to the datasheet's other axis is accepted;
/// alone (no datasheet inductance for the other axis) it is still an error.
#[test]
fn one_identified_axis_needs_the_other_from_the_datasheet() {
    let text = std::fs::read_to_string(repo().join("motors/fischer-ti085.toml")).unwrap();
    let with = text.replace(
        "[motor.datasheet]",
        "[motor.identified]\nq_inductance = \"0.41 mH\"\n\n[motor.datasheet]",
    );
    let d = codegen::design_source("f.toml", &with).unwrap();
    assert_eq!(d.motor.q_inductance_h, 0.41e-3);
    assert_eq!(d.motor.d_inductance_h, 0.393e-3);
    let without = with.replace("inductance = \"0.393 mH\"", "");
    let err = codegen::design_source("f.toml", &without).unwrap_err().to_string();
    assert!(err.contains("`q_inductance` is given without `d_inductance`"), "{err}");
}

/// §6.5 on the `verify` bench: the Chalmers motor (ψ_M = 104 mWb, thesis B Table B.2)
/// driven at ω_m = 300 rad/s (ω_e = 600 rad/s), the firmware's current loop holding
/// i = 0 with the feed-forward off, as `FluxLinkage` demands. The inputs that routine
/// receives each period (u_q, ω_e) and the measured i_dq are written as a `flux`
/// recording; `identify_flux` recovers ψ_M within 1 %.
#[test]
fn flux_from_the_firmware_bench() {
    use motor_commission::flux::{FluxSetup, identify_flux};
    use motor_control::step::Demand;
    let (text, d) = design_of("chalmers-hev50");
    let spec = codegen::spec::parse(Source {
        file: "c.toml",
        text: &text,
    })
    .unwrap();
    let setup_v = motor_verify::Setup::new(&spec, &d);
    let mut bench = setup_v.bench(300.0);
    let demand = Demand::Current {
        id: 0.0,
        iq: 0.0,
        feed_forward: false,
    };
    for _ in 0..4000 {
        bench.step(demand);
    }
    let mut csv = String::from("# motorgen recording: flux\nsample,omega_e_rad_s,u_q_v,i_d_a,i_q_a\n");
    for n in 0..2000 {
        let o = bench.step(demand).out;
        csv.push_str(&format!("{n},{},{},{},{}\n", o.omega_e, o.u_dq.q, o.i_dq.d, o.i_dq.q));
    }
    let rec = recording::parse("flux.csv", &csv, RecordingKind::Flux, d.drive.sample_period_s).unwrap();
    let e = identify_flux(
        &rec,
        &FluxSetup {
            resistance_ohm: d.motor.phase_resistance_ohm,
            d_inductance_h: d.motor.d_inductance_h,
            max_current_a: 0.1 * d.motor.peak_current_a,
            min_speed_rad_s: 0.05 * d.motor.max_electrical_speed_rad_s,
            voltage_limit_v: d.current_loop.voltage_limit_v,
        },
    )
    .unwrap();
    eprintln!(
        "bench flux: ψ_M = {:.5} Wb at ω_e = {:.1} rad/s (correction {:.2e} Wb)",
        e.flux_linkage_wb, e.mean_speed_rad_s, e.correction_wb
    );
    assert!((e.mean_speed_rad_s - 600.0).abs() < 1.0, "{e:?}");
    assert!((e.flux_linkage_wb / 0.104 - 1.0).abs() < 0.01, "{e:?}");
}
