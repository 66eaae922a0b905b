//! The current loop's frequency response on the emulated G474 (issue 28, item 5): the
//! image's commissioning routine `frequency_response`, its own control interrupt, the
//! emulated board's sensing and `verify`'s motor (blocked rotor) in closed loop, driven
//! over the emulated FDCAN by the bench host's own session
//! (`motor_commission::frequency_response::Plan::run` on [`CanBus`]) — the code
//! `motorgen commission --can` runs. The same plan then runs on `--sim`'s simulated
//! drive (`motor_commission::sim_drive`); the margins read from the two captures agree
//! within ±0.5 dB, ±3° and ±5 % of the crossover per axis. Before, the image refuses an
//! amplitude above its generated `INJECTION_LIMIT` (`Reason::AmplitudeAboveLimit`).
//!
//! Cost: one multisine period is the capture buffer's 4096 samples, run twice (settle,
//! capture) and streamed over CAN; a few pairs only (README, "Frequency response").

use std::time::{Duration, Instant};

use motor_commission::commission::{SessionError, run_session};
use motor_commission::frequency_response::{self as fr, Margins, Measurement, Options};
use motor_commission::sim_drive::SimulatedDrive;
use motor_control::can_protocol::{Quantity, Reason};
use motor_control::commissioning::Axis;
use motor_emulator::can_bus::CanBus;
use motor_emulator::rig::{Bench, Rig};
use motor_verify::Setup;

/// The session's options: the host's defaults (amplitude, lines), as a bench user runs it.
fn options(axis: Axis) -> Options {
    Options {
        iface: "emu0".into(),
        timeout: "10 s".into(),
        axis,
        amplitude: None,
        frequencies: None,
    }
}

/// Measured on the emulated board and on the simulated bench, the wall time of each
/// \[s\].
struct Pair {
    emulated: Measurement,
    simulated: Measurement,
    emulated_wall_s: f64,
    emulated_s: f64,
}

/// Boots `motor` on `board` with the closed-loop drive, runs the frequency response of
/// each axis in `axes` over the emulated CAN, then the same plan on the simulated drive.
fn measure(motor: &str, board: &str, axes: &[Axis]) -> Result<Vec<Pair>, String> {
    let (mut rig, spec) = crate::closed_loop::closed_loop(Bench::new(motor, board)?)?;
    let design = rig.design.clone();
    let rel = format!("motors/{motor}.toml");
    refuses_above_the_limit(&mut rig, &design, &rel)?;
    let mut out = Vec::new();
    for &axis in axes {
        let plan = fr::plan_design(&options(axis), design.clone(), &rel).map_err(|e| format!("{e:?}"))?;
        let (wall, t0) = (Instant::now(), rig.machine.soc().time_s());
        let emulated = plan.run(&mut CanBus::new(&mut rig)).map_err(|e| {
            format!(
                "{motor} on {board}, {axis:?} axis, emulated: {e:?} (fault record: {:?})",
                rig.fault_cause()
            )
        })?;
        let (emulated_wall_s, emulated_s) = (wall.elapsed().as_secs_f64(), rig.machine.soc().time_s() - t0);
        let mut sim =
            SimulatedDrive::new(&design, Setup::new(&spec, &design).bench(0.0), 0.0).ok_or("no CAN interface")?;
        let simulated = plan
            .run(&mut sim)
            .map_err(|e| format!("{motor} on {board}, {axis:?} axis, --sim: {e:?}"))?;
        out.push(Pair {
            emulated,
            simulated,
            emulated_wall_s,
            emulated_s,
        });
    }
    Ok(out)
}

/// The image's own bound: the host's command with the amplitude one voltage LSB above
/// the generated `INJECTION_LIMIT` (the host itself refuses to send it, so the frame is
/// built here) is refused by the image with `Reason::AmplitudeAboveLimit`, and nothing
/// runs (the outputs stay as they were: the drive at zero torque).
fn refuses_above_the_limit(rig: &mut Rig, design: &codegen::Design, rel: &str) -> Result<(), String> {
    let plan = fr::plan_design(&options(Axis::D), design.clone(), rel).map_err(|e| format!("{e:?}"))?;
    let (cfg, _) = motor_commission::candump::mode_config(design).ok_or("no CAN interface")?;
    let per = cfg.layout.per_lsb(Quantity::Voltage);
    let mut command = plan.command;
    // The default is the limit (in whole LSBs); two LSBs more decode above it.
    command.voltage = plan.command.voltage + 2.0 * per;
    if command.voltage <= cfg.injection_limit {
        return Err(format!(
            "the test's amplitude {} V is not above the limit {} V",
            command.voltage, cfg.injection_limit
        ));
    }
    let mut bus = CanBus::new(rig);
    match run_session(&mut bus, "emu0", &cfg.layout, &command, Duration::from_millis(100)) {
        Err(SessionError::Refused(Reason::AmplitudeAboveLimit)) => Ok(()),
        other => Err(format!(
            "amplitude {} V above INJECTION_LIMIT = {} V: {other:?}, not refused with AmplitudeAboveLimit",
            command.voltage, cfg.injection_limit
        )),
    }
}

/// The differences (gain margin \[dB\], phase margin \[°\], crossover ratio − 1) of
/// `a` from `b`, `Err` when a figure is missing or outside ±0.5 dB, ±3°, ±5 %.
fn agree(a: &Margins, b: &Margins) -> Result<(f64, f64, f64), String> {
    let (Some(gm), Some(pm), Some(wc), Some(bgm), Some(bpm), Some(bwc)) = (
        a.gain_margin_db,
        a.phase_margin_deg,
        a.crossover_rad_s,
        b.gain_margin_db,
        b.phase_margin_deg,
        b.crossover_rad_s,
    ) else {
        return Err(format!("not measured: {a:?} vs {b:?}"));
    };
    let e = (gm - bgm, pm - bpm, wc / bwc - 1.0);
    if e.0.abs() <= 0.5 && e.1.abs() <= 3.0 && e.2.abs() <= 0.05 {
        Ok(e)
    } else {
        Err(format!(
            "{a:?} vs {b:?}: ΔGM {:.3} dB, ΔPM {:.3}°, Δω_c {:.3} %",
            e.0,
            e.1,
            100.0 * e.2
        ))
    }
}

fn figures(m: &Margins) -> String {
    let f = |x: Option<f64>, p: usize| x.map_or("—".into(), |v| format!("{v:.p$}"));
    format!(
        "GM {} dB, PM {}°, ω_c {} rad/s",
        f(m.gain_margin_db, 2),
        f(m.phase_margin_deg, 2),
        f(m.crossover_rad_s, 0)
    )
}

/// The pairs run: maxon-ec45-flat-70w on the reference board with both axes, on the
/// NUCLEO with the q axis, chalmers-hev50 on the 400 A reference board (the motor no
/// other board takes) with the q axis — one pair per board in `boards/`.
const PAIRS: &[(&str, &str, &[Axis])] = &[
    ("maxon-ec45-flat-70w", "motorgen-reference", &[Axis::D, Axis::Q]),
    ("maxon-ec45-flat-70w", "nucleo-g474re-ihm08m1", &[Axis::Q]),
    ("chalmers-hev50", "motorgen-reference-400a", &[Axis::Q]),
];

#[test]
fn emulated_bench_measures_the_margins_of_the_simulated_bench() {
    let only = std::env::var("EMULATOR_MOTORS").ok();
    let mut failures = Vec::new();
    let mut ran = 0;
    for &(motor, board, axes) in PAIRS {
        if only.as_deref().is_some_and(|o| !o.split(',').any(|m| m == motor)) {
            continue;
        }
        ran += 1;
        match measure(motor, board, axes) {
            Err(e) => failures.push(format!("{motor} on {board}: {e}")),
            Ok(pairs) => {
                for p in pairs {
                    let axis = p.emulated.axis;
                    let r = agree(&p.emulated.measured, &p.simulated.measured);
                    println!(
                        "{motor} on {board}, {axis:?} axis (A = {:.3} V, {} lines): designed {}; --sim {} (fitted delay {:.4} T_s); emulated {} (fitted delay {:.4} T_s; {:.3} s emulated in {:.1} s); {r:?}",
                        p.emulated.amplitude_v,
                        p.emulated.points.len(),
                        figures(&p.emulated.designed),
                        figures(&p.simulated.measured),
                        p.simulated.fit.plant.delay_periods,
                        figures(&p.emulated.measured),
                        p.emulated.fit.plant.delay_periods,
                        p.emulated_s,
                        p.emulated_wall_s,
                    );
                    if let Err(e) = r {
                        failures.push(format!("{motor} on {board}, {axis:?} axis: {e}"));
                    }
                }
            }
        }
    }
    assert!(ran > 0, "no pair ran (EMULATOR_MOTORS = {only:?})");
    assert!(failures.is_empty(), "{failures:#?}");
}
