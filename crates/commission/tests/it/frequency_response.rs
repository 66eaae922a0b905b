//! The current loop's frequency response on the simulated drive (`sim_drive`: the
//! firmware's commissioning mode, its `frequency_response` routine and CAN encoder on
//! the firmware's control step and `verify`'s plant), for every motor in `motors/` on
//! the reference board (or the first board that fits it): the margins read from the
//! measured points must be the design's — ±0.5 dB gain margin, ±3° phase margin, ±5 %
//! crossover per axis (issue 28). The designed figures are the design's sampled-loop
//! analysis (a fine grid refined by bisection), an independent computation from the
//! measured DFT ratio of the captured u_PI and v.

use codegen::{Design, Source};
use motor_commission::frequency_response::{self as fr, Margins, Measurement, Options, SimScale};
use motor_commission::sim_drive::SimulatedDrive;
use motor_control::commissioning::Axis;
use motor_test_support::repo;

const BOARD: &str = "boards/motorgen-reference.toml";

/// The design of `stem` on the reference board or the first board that fits, and its
/// parsed spec.
pub fn motor(stem: &str) -> (String, Design, codegen::spec::Spec) {
    let rel = format!("motors/{stem}.toml");
    let text = std::fs::read_to_string(repo().join(&rel)).unwrap();
    let mut boards: Vec<String> = motor_test_support::board_stems()
        .into_iter()
        .map(|b| format!("boards/{b}.toml"))
        .collect();
    boards.sort_by_key(|b| b != BOARD);
    let design = boards
        .into_iter()
        .find_map(|b| {
            let board_text = std::fs::read_to_string(repo().join(&b)).unwrap();
            codegen::design_with_board(&rel, &text, &b, &board_text).ok()
        })
        .unwrap_or_else(|| panic!("{stem} fits no board"));
    let spec = codegen::spec::parse(Source {
        file: &rel,
        text: &text,
    })
    .unwrap();
    (rel, design, spec)
}

/// The measurement of `axis` on the simulated bench of `d`.
pub fn measure(rel: &str, d: &Design, spec: &codegen::spec::Spec, axis: Axis) -> Measurement {
    measure_scaled(rel, d, spec, axis, &SimScale::default())
}

/// The design's loop delay \[periods\].
fn design_delay(d: &Design) -> f64 {
    let req = d.current_loop_request(Axis::D);
    req.loop_delay_s / req.sample_period_s
}

/// [`measure`] on the plant perturbed by `scale`.
pub fn measure_scaled(rel: &str, d: &Design, spec: &codegen::spec::Spec, axis: Axis, scale: &SimScale) -> Measurement {
    let options = Options {
        iface: "sim0".into(),
        timeout: "60 s".into(),
        axis,
        amplitude: None,
        frequencies: None,
    };
    let plan = fr::plan_design(&options, d.clone(), rel).unwrap();
    let setup = motor_verify::Setup::new(spec, d);
    let mut bench = setup.bench(0.0);
    scale.apply(&mut bench.plant, design_delay(d));
    let mut drive = SimulatedDrive::new(d, bench, 0.0).unwrap();
    plan.run(&mut drive).unwrap()
}

/// Measured within ±0.5 dB, ±3°, ±5 % of `expected`; the differences.
pub fn within(measured: &Margins, expected: &Margins) -> Result<(f64, f64, f64), String> {
    let (Some(gm), Some(pm), Some(wc)) = (
        measured.gain_margin_db,
        measured.phase_margin_deg,
        measured.crossover_rad_s,
    ) else {
        return Err(format!("not measured: {measured:?}"));
    };
    let (Some(egm), Some(epm), Some(ewc)) = (
        expected.gain_margin_db,
        expected.phase_margin_deg,
        expected.crossover_rad_s,
    ) else {
        return Err(format!("no expected figures: {expected:?}"));
    };
    let e = (gm - egm, pm - epm, wc / ewc - 1.0);
    if e.0.abs() <= 0.5 && e.1.abs() <= 3.0 && e.2.abs() <= 0.05 {
        Ok(e)
    } else {
        Err(format!("measured {measured:?} vs {expected:?}: {e:?}"))
    }
}

/// Every motor, both axes: the measured margins are the designed ones.
#[test]
fn simulated_bench_measures_the_designed_margins_on_every_motor() {
    let mut failures = vec![];
    for (stem, _, _) in motor_test_support::motors() {
        let (rel, d, spec) = motor(&stem);
        for axis in [Axis::D, Axis::Q] {
            let m = measure(&rel, &d, &spec, axis);
            let r = within(&m.measured, &m.designed);
            println!(
                "{stem} {axis:?}: measured GM {:?} dB PM {:?}° ω_c {:?} rad/s; designed GM {:?} PM {:?} ω_c {:?}; A = {:.3} V, {} lines; {r:?}",
                m.measured.gain_margin_db,
                m.measured.phase_margin_deg,
                m.measured.crossover_rad_s,
                m.designed.gain_margin_db,
                m.designed.phase_margin_deg,
                m.designed.crossover_rad_s,
                m.amplitude_v,
                m.points.len(),
            );
            if let Err(e) = r {
                failures.push(format!("{stem} {axis:?}: {e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Every motor with the plant perturbed: the q axis with L_q × 0.7, the d axis with the
/// loop delay × 1.5. The measured margins follow the perturbed plant's sampled-loop model
/// (`fr::model_margins`, the design's gains on R, L and delay of the perturbed plant),
/// not the design, within the same tolerances; the fit recovers the perturbed L and
/// delay within 5 %.
#[test]
fn measurement_follows_the_perturbed_plant_and_the_fit_recovers_it() {
    let mut failures = vec![];
    for (stem, _, _) in motor_test_support::motors() {
        let (rel, d, spec) = motor(&stem);
        let ts = d.drive.sample_period_s;
        let delay = design_delay(&d);
        for (axis, options) in [(Axis::Q, ["Lq=0.7".to_string()]), (Axis::D, ["delay=1.5".to_string()])] {
            let scale = SimScale::parse(&options, delay).unwrap();
            let m = measure_scaled(&rel, &d, &spec, axis, &scale);
            let gains = fr::axis_gains(&d, axis).loop_gains();
            let truth = scale.plant_of(&d, axis);
            let expected = fr::model_margins(&gains, &truth, ts);
            let r = within(&m.measured, &expected);
            let design_plant = SimScale::default().plant_of(&d, axis);
            let fit = fr::fit_plant(&m.points, &gains, ts, &design_plant);
            let e_l = fit.plant.inductance_h / truth.inductance_h - 1.0;
            let e_d = fit.plant.delay_periods / truth.delay_periods - 1.0;
            let e_r = fit.plant.resistance_ohm / truth.resistance_ohm - 1.0;
            println!(
                "{stem} {axis:?} {options:?}: measured GM {:?} PM {:?} ω_c {:?}; model GM {:?} PM {:?} ω_c {:?}; {r:?}; fit L {e_l:+.4} D {e_d:+.4} R {e_r:+.4} (determined {}), rms {:.2e}",
                m.measured.gain_margin_db,
                m.measured.phase_margin_deg,
                m.measured.crossover_rad_s,
                expected.gain_margin_db,
                expected.phase_margin_deg,
                expected.crossover_rad_s,
                fit.resistance_determined,
                fit.rms_relative_error,
            );
            if let Err(e) = r {
                failures.push(format!("{stem} {axis:?}: {e}"));
            }
            if e_l.abs() > 0.05 || e_d.abs() > 0.05 || (fit.resistance_determined && e_r.abs() > 0.05) {
                failures.push(format!("{stem} {axis:?}: fit {fit:?} vs {truth:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The sampled-loop model at the design's delay is the design's own L(z) (its
/// analysis), and its margins on the grid are the design's.
#[test]
fn the_model_at_the_design_delay_is_the_designs_loop() {
    let (_, d, _) = motor("fischer-ti085");
    let ts = d.drive.sample_period_s;
    for axis in [Axis::D, Axis::Q] {
        let gains = fr::axis_gains(&d, axis).loop_gains();
        let plant = SimScale::default().plant_of(&d, axis);
        for w in [10.0, 300.0, 3000.0, 30000.0] {
            let a = fr::model_point(&gains, &plant, ts, w);
            let b = fr::designed_point(&d, axis, w);
            assert!(
                (a.re - b.re).abs() + (a.im - b.im).abs() < 1e-9 * b.re.hypot(b.im),
                "{a:?} {b:?}"
            );
        }
        within(&fr::model_margins(&gains, &plant, ts), &fr::designed_margins(&d, axis)).unwrap();
    }
}

/// The retune on the design's own plant names at least the designed bandwidth (the
/// design meets the floors there; its bandwidth may be lower for the at-speed figures),
/// and a longer loop delay lowers it.
#[test]
fn retune_follows_the_measured_plant() {
    let (_, d, _) = motor("chalmers-hev50");
    let alpha = d.current_loop.bandwidth_rad_s;
    let own = SimScale::default().plant_of(&d, Axis::D);
    let a_own = fr::retune(&d, Axis::D, &own).unwrap();
    let late = fr::PlantModel {
        delay_periods: 1.5 * own.delay_periods,
        ..own
    };
    let a_late = fr::retune(&d, Axis::D, &late).unwrap();
    println!("chalmers-hev50 d: α = {alpha}, retune {a_own:.0} (design plant), {a_late:.0} (delay × 1.5)");
    assert!(a_own >= alpha, "{a_own} < {alpha}");
    assert!(a_late < a_own, "{a_late} ≥ {a_own}");
}

/// The injection limit (the generated `INJECTION_LIMIT`) acting, every motor on its
/// board: the host's default amplitude is the limit in whole voltage LSBs; an
/// `--amplitude` above it is refused before the bus is touched, naming the limit; the
/// simulated drive (the firmware's supervisor) refuses a command two LSBs above it with
/// `Reason::AmplitudeAboveLimit`; and at the default amplitude on the q axis the
/// routine runs with its trip lowered to half the host's trip level (the current the
/// limit promises) and every captured applied voltage v stays within U_dc/√3.
#[test]
fn injection_limit_bounds_the_amplitude_on_host_and_drive() {
    use motor_commission::Error;
    use motor_commission::commission::{SessionError, run_session};
    use motor_control::can_protocol::{Quantity, Reason};
    let mut failures = vec![];
    for (stem, _, _) in motor_test_support::motors() {
        let (rel, d, spec) = motor(&stem);
        let (cfg, _) = motor_commission::candump::mode_config(&d).unwrap();
        let limit = cfg.injection_limit;
        let per = cfg.layout.per_lsb(Quantity::Voltage);
        let options = |amplitude: Option<String>| Options {
            iface: "sim0".into(),
            timeout: "60 s".into(),
            axis: Axis::Q,
            amplitude,
            frequencies: None,
        };
        let mut plan = fr::plan_design(&options(None), d.clone(), &rel).unwrap();
        let a = plan.command.voltage;
        if !(a <= limit && a > limit - per) {
            failures.push(format!(
                "{stem}: default {a} V is not the limit {limit} V in whole LSBs of {per} V"
            ));
        }
        match fr::plan_design(&options(Some(format!("{} V", 1.01 * limit))), d.clone(), &rel) {
            Err(Error::Option(p)) if p.to_string().contains("INJECTION_LIMIT") => {}
            other => failures.push(format!(
                "{stem}: 1.01 × the limit not refused: {:?}",
                other.map(|p| p.command)
            )),
        }
        let bench = || motor_verify::Setup::new(&spec, &d).bench(0.0);
        let mut above = plan.command;
        above.voltage = a + 2.0 * per;
        let mut drive = SimulatedDrive::new(&d, bench(), 0.0).unwrap();
        match run_session(
            &mut drive,
            "sim0",
            &cfg.layout,
            &above,
            std::time::Duration::from_secs(1),
        ) {
            Err(SessionError::Refused(Reason::AmplitudeAboveLimit)) => {}
            other => failures.push(format!(
                "{stem}: {} V not refused by the drive: {other:?}",
                above.voltage
            )),
        }
        plan.command.current_trip *= 0.5;
        let mut drive = SimulatedDrive::new(&d, bench(), 0.0).unwrap();
        match plan.run(&mut drive) {
            Ok(m) => {
                let u_max = d.current_loop.voltage_limit_v;
                let peak = m
                    .csv
                    .1
                    .lines()
                    .skip_while(|l| !l.starts_with(|c: char| c.is_ascii_digit() || c == '-'))
                    .filter_map(|l| l.split(',').nth(2)?.trim().parse::<f64>().ok())
                    .fold(0.0f64, |p, v| p.max(v.abs()));
                println!("{stem}: A = {a} V (limit {limit} V), peak |v| {peak:.3} V of U_max {u_max:.3} V");
                if peak > u_max || peak < 0.5 * f64::from(a) {
                    failures.push(format!("{stem}: peak |v| {peak} V outside [A/2, U_max = {u_max}]"));
                }
            }
            Err(e) => failures.push(format!("{stem}: at the limit with half the trip: {e:?}")),
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
