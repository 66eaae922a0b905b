//! Verification by simulation: every seed motor holds its scenarios, deliberately
//! mis-tuned designs fail the scenario that should catch them, and the firmware
//! configuration the simulation runs is the generated constants' values.

use std::path::{Path, PathBuf};

use codegen::constants::{Constant, constants};
use codegen::design::Design;
use codegen::{Source, design, spec};
use motor_verify::{Scenario, Setup, Verification, controller::controller_config, verify};

/// Every motor's spec path (a non-empty list, `motor_test_support`).
fn motors() -> Vec<PathBuf> {
    motor_test_support::motor_stems().iter().map(|s| motor(s)).collect()
}

fn stem(p: &Path) -> String {
    p.file_stem().unwrap().to_string_lossy().into_owned()
}

/// Spec and design of `path`.
fn load(path: &Path) -> (spec::Spec, Design) {
    let text = std::fs::read_to_string(path).unwrap();
    let file = path.display().to_string();
    let src = Source {
        file: &file,
        text: &text,
    };
    let s = spec::parse(src).unwrap();
    let d = design::design(&s, src).unwrap();
    (s, d)
}

fn run(spec: &spec::Spec, d: &Design) -> Verification {
    verify(&Setup::new(spec, d))
}

/// Every motor in `motors/` passes every scenario of the standard set. (chalmers-hev50
/// relies on the default delay compensation: at 10 kHz its plain design rises in 1.14 ms
/// instead of 1.5 ms — `delay_compensation_is_what_makes_chalmers_pass` below.)
#[test]
fn every_seed_motor_passes_its_scenarios() {
    let mut problems = Vec::new();
    for path in motors() {
        let name = stem(&path);
        let (s, d) = load(&path);
        let v = run(&s, &d);
        let ids: Vec<&str> = v.scenarios.iter().map(|x| x.id).collect();
        let want: Vec<&str> = Scenario::applicable(&Setup::new(&s, &d)).iter().map(|x| x.id).collect();
        assert_eq!(ids, want, "{name}");
        println!("{}", v.table());
        // The field-weakening ramp reaches the spec's own `max_speed = "… rpm"` (read from
        // the file's text, not from the design) wherever there is a ψ_M.
        if let Some(fw) = v
            .scenarios
            .iter()
            .find(|x| x.id == "field_weakening" && !x.checks.is_empty())
        {
            let text = std::fs::read_to_string(&path).unwrap();
            let max_rpm: f64 = text
                .lines()
                .find_map(|l| l.trim().strip_prefix("max_speed = \""))
                .and_then(|r| r.split(" rpm\"").next())
                .and_then(|n| n.parse().ok())
                .unwrap_or_else(|| panic!("{name}: no max_speed in rpm"));
            let reached = fw.reached_speed_rpm.unwrap();
            assert!(
                reached >= max_rpm,
                "{name}: the ramp reached {reached} of {max_rpm} rpm"
            );
        }
        for sc in &v.scenarios {
            assert!(!sc.checks.is_empty(), "{name}: {} has no checks", sc.id);
            for c in &sc.checks {
                if !c.pass {
                    problems.push(format!(
                        "{name}: {} / {}: measured {} vs designed {:?} ({}) — FAILS",
                        sc.id, c.quantity, c.measured, c.designed, c.criterion
                    ));
                }
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The check of `v` named `quantity` in scenario `id`.
fn check<'a>(v: &'a Verification, id: &str, quantity: &str) -> &'a motor_verify::Check {
    v.scenarios
        .iter()
        .find(|s| s.id == id)
        .and_then(|s| s.checks.iter().find(|c| c.quantity.starts_with(quantity)))
        .unwrap_or_else(|| panic!("no check {id}/{quantity}"))
}

fn motor(stem: &str) -> PathBuf {
    motor_test_support::repo().join(format!("motors/{stem}.toml"))
}

/// IMC gains of α = 200 rad/s in a design that claims α = 100 rad/s (Fischer): the
/// loop rises in about ln 9/200 = 11 ms instead of 21.97 ms, so the rise-time check fails
/// (and only it: the loop is still a stable first-order loop).
#[test]
fn doubled_pi_gains_fail_the_rise_time() {
    let (s, mut d) = load(&motor("fischer-ti085"));
    for g in [&mut d.current_loop.d, &mut d.current_loop.q] {
        g.kp *= 2.0;
        g.ki *= 2.0;
        g.anti_windup_gain /= 2.0;
    }
    let v = run(&s, &d);
    let c = check(&v, "current_step", "q-axis rise time 10–90 %");
    assert!(!c.pass, "{c:?}");
    assert!((c.measured / 21.97 - 0.5).abs() < 0.05, "{c:?}");
    assert!(check(&v, "current_step", "q-axis overshoot").pass);
}

/// chalmers-hev50 with `compensate_delay = false`: α_c·T_s = 0.147, and the sampled loop's
/// dominant root of z² − z + α_c·T_s (IMC with the delay, hand calculation in
/// `design::current_loop::discrete`) is 0.821 ↔ 1973 rad/s, so the step rises in about 1.1 ms, not
/// ln 9/1470 = 1.495 ms, and the design warns about it. Without the key (the default
/// compensation) the step rises in 1.495 ms ± 10 %.
#[test]
fn delay_compensation_is_what_makes_chalmers_pass() {
    let path = motor("chalmers-hev50");
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "bandwidth = \"1470 rad/s\"",
        "bandwidth = \"1470 rad/s\"\ncompensate_delay = false",
    );
    let src = Source {
        file: "chalmers-plain.toml",
        text: &text,
    };
    let s = spec::parse(src).unwrap();
    let d = design::design(&s, src).unwrap();
    assert!(
        d.warnings.iter().any(|w| w.contains("compensate_delay")),
        "{:?}",
        d.warnings
    );
    let v = run(&s, &d);
    let c = check(&v, "current_step", "q-axis rise time vs the sampled loop");
    assert!(c.measured < 1.2 && c.measured > 1.0, "{c:?}");
    let (s, d) = load(&path);
    let v = run(&s, &d);
    let c = check(&v, "current_step", "q-axis rise time 10–90 %");
    assert!(c.pass && (c.measured / 1.495 - 1.0).abs() < 0.1, "{c:?}");
}

/// Pole placement without the prefilter (5.16): the PI zero −K_i/K_p is not cancelled
/// (Unimotor, thesis A Fig. 5.6's continuous design (5.14), `compensate_delay = false`).
/// Hand calculation, q axis: K_p = 2ζω_n·L − R = 1.0748 − 0.65 = 0.4248 V/A, K_i = ω_n²·L =
/// 76 V/(A·s), zero at K_i/K_p = 179 rad/s = 1.79·ω_n; the step of
/// (K_p·s + K_i)/(L·s² + (R + K_p)·s + K_i), integrated by hand (Euler, 1 µs), overshoots
/// 5.57 % instead of the prefiltered e^(−π) = 4.32 %. The floor (designed + 2 % = 6.3 %) does
/// not catch this mild zero, so the test holds the measured value to the hand figure.
#[test]
fn pole_placement_without_prefilter_overshoots_as_its_zero_says() {
    let text = std::fs::read_to_string(motor("unimotor-142umd300")).unwrap().replace(
        "damping = 0.7071           # ζ = 1/√2, thesis A §5.4.1",
        "damping = 0.7071\ncompensate_delay = false",
    );
    let src = Source {
        file: "unimotor-plain.toml",
        text: &text,
    };
    let s = spec::parse(src).unwrap();
    let mut d = design::design(&s, src).unwrap();
    assert!(!d.current_loop.compensate_delay);
    for axis in [&mut d.current_loop.d, &mut d.current_loop.q] {
        axis.prefilter = None;
        // The coefficient the controller runs: 1 passes the reference unfiltered.
        axis.reference_filter = 1.0;
    }
    let v = run(&s, &d);
    let c = check(&v, "current_step", "q-axis overshoot");
    assert!((c.measured - 5.57).abs() < 0.3, "{c:?}");
}

/// Feed-forward inductances zeroed (only the back EMF ω_e·ψ_M left): the cross-coupling is
/// no longer compensated and the i_d excursion ratio falls to about 1.
#[test]
fn missing_decoupling_fails_the_decoupling_scenario() {
    let (s, mut d) = load(&motor("fischer-ti085"));
    d.current_loop.feedforward.d_inductance_h = 0.0;
    d.current_loop.feedforward.q_inductance_h = 0.0;
    let v = run(&s, &d);
    let c = check(&v, "decoupling", "i_d excursion");
    assert!(!c.pass && c.measured < 3.0, "{c:?}");
}

/// K̃_i a quarter of the designed integer (a wrong scaling in (4.22)): on the observer's
/// own ramp at a = 0.1·K_i (`ato_type2`) the lag becomes sin⁻¹(4·0.1) = 23.58° instead of
/// sin⁻¹ 0.1 = 5.74°.
#[test]
fn mis_scaled_observer_gain_fails_the_ramp() {
    let (s, mut d) = load(&motor("fischer-ti085"));
    d.angle_observer.gains.ki_q31 /= 4;
    let v = run(&s, &d);
    let c = check(&v, "ato_type2", "angle lag during the ramp");
    assert!(!c.pass, "{c:?}");
    assert!((c.measured - 23.58).abs() < 1.0, "{c:?}");
}

/// Field weakening with γ = 0 (α_fw = 0 in (2.60)): i_d^ref stays on the MTPA curve, the
/// back EMF above base speed drives the current loop into the voltage circle V_max, and
/// the peak |v| check (never past (V'_max + V_max)/2) fails, as does |v| = V'_max at the
/// top speed. The working controller passes both (every seed motor it applies to).
#[test]
fn field_weakening_without_gain_exceeds_the_voltage_margin() {
    use motor_verify::field_weakening::field_weakening as fw_run;
    for stem in ["chalmers-hev50", "fischer-ti085"] {
        let (s, d) = load(&motor(stem));
        let setup = Setup::new(&s, &d);
        let mut broken = setup.clone();
        broken.cfg.torque.bandwidth = 0.0;
        let r = fw_run(&broken);
        let peak = r.checks.iter().find(|c| c.quantity.starts_with("peak |v|")).unwrap();
        assert!(!peak.pass, "{stem}: {peak:?}");
        // The current loop saturates: |v| reaches V_max = U_dc/√3 (to f32 rounding).
        assert!(
            (peak.measured / d.current_loop.voltage_limit_v - 1.0).abs() < 1e-3,
            "{stem}: {peak:?}"
        );
        assert!(fw_run(&setup).passed(), "{stem}");
    }
}

/// A motor without ψ_M (unimotor) gets neither field weakening nor the estimator: the
/// scenarios are not listed for it.
#[test]
fn scenarios_needing_the_flux_are_skipped_without_it() {
    let (s, d) = load(&motor("unimotor-142umd300"));
    let ids: Vec<&str> = run(&s, &d).scenarios.iter().map(|x| x.id).collect();
    assert!(
        !ids.contains(&"field_weakening") && !ids.contains(&"estimator_recovery"),
        "{ids:?}"
    );
    let (s, d) = load(&motor("chalmers-hev50"));
    let ids: Vec<&str> = run(&s, &d).scenarios.iter().map(|x| x.id).collect();
    assert!(
        ids.contains(&"field_weakening") && ids.contains(&"estimator_recovery"),
        "{ids:?}"
    );
}

/// The estimator with its resetting term switched off (γ0 ≡ 0) in the run that should
/// have it: from ω̃ = −5ρ the PLL slips cycles (thesis B Fig. 4.17: 14), so the
/// "no cycle slip" check fails; with the term (Fig. 4.18) none.
#[test]
fn estimator_without_resetting_term_slips_cycles() {
    use motor_verify::estimator::{estimator_config, run as est_run};
    // The only motor with a `[sensorless]` section.
    let stem = "chalmers-hev50";
    let (s, d) = load(&motor(stem));
    let setup = Setup::new(&s, &d);
    let good = estimator_config(&d).unwrap();
    let broken = motor_verify::estimator::EstimatorConfig {
        resetting: None,
        ..good
    };
    let r = est_run(&setup, &broken);
    let slips = r.checks.iter().find(|c| c.quantity.starts_with("cycle slips")).unwrap();
    assert!(!slips.pass && slips.measured.abs() >= 1.0, "{stem}: {slips:?}");
    assert!(est_run(&setup, &good).passed(), "{stem}");
}

fn number(groups: &[codegen::constants::Group], group: &str, name: &str) -> f64 {
    let c: &Constant = codegen::constants::group_named(groups, group)
        .and_then(|g| g.constant(name))
        .unwrap_or_else(|| panic!("no constant {group}::{name}"));
    c.value.number.as_f64().unwrap()
}

/// The simulated controller runs exactly the generated constants: every field of the
/// `ControllerConfig` built from the design equals the value the generated module
/// carries (f32 values bit for bit, Q1.31 and integer values exactly).
#[test]
fn controller_config_is_the_generated_constants() {
    for path in motors() {
        let name = stem(&path);
        let (_, d) = load(&path);
        let cfg = controller_config(&d);
        let g = constants(&d);
        let f = |group: &str, n: &str| number(&g, group, n) as f32;
        assert_eq!(cfg.sample_period, f("limits", "SAMPLE_PERIOD_S"), "{name}");
        assert_eq!(cfg.speed_per_lsb, f("scaling", "SPEED_PER_LSB"), "{name}");
        assert_eq!(
            cfg.current_sense.amps_per_lsb,
            [f("scaling", "CURRENT_PER_LSB"); 3],
            "{name}"
        );
        assert_eq!(
            cfg.dc_link_sense.volts_per_lsb,
            f("scaling", "DC_LINK_PER_LSB"),
            "{name}"
        );
        assert_eq!(
            i64::from(cfg.observer.kp.to_bits()),
            number(&g, "observer", "KP") as i64,
            "{name}"
        );
        assert_eq!(
            i64::from(cfg.observer.ki.to_bits()),
            number(&g, "observer", "KI") as i64,
            "{name}"
        );
        // The error form the gains were scaled for (generated ERROR_FORM: 0 trig identity, 1 atan2).
        assert_eq!(
            u8::from(cfg.observer.error == motor_control::ato::ObserverError::Atan2),
            number(&g, "observer", "ERROR_FORM") as u8,
            "{name}"
        );
        assert_eq!(
            f64::from(cfg.angle.motor_pole_pairs),
            number(&g, "observer", "MOTOR_POLE_PAIRS"),
            "{name}"
        );
        assert_eq!(
            f64::from(cfg.angle.resolver_pole_pairs),
            number(&g, "observer", "RESOLVER_POLE_PAIRS"),
            "{name}"
        );
        assert_eq!(f64::from(cfg.angle_lead), number(&g, "observer", "LEAD_Q16"), "{name}");
        for (axis, pi) in [("D", cfg.current_loop.d), ("Q", cfg.current_loop.q)] {
            assert_eq!(pi.kp, f("current_loop", &format!("{axis}_KP")), "{name} {axis}");
            assert_eq!(pi.ki, f("current_loop", &format!("{axis}_KI")), "{name} {axis}");
            assert_eq!(
                pi.anti_windup,
                f("current_loop", &format!("{axis}_ANTI_WINDUP")),
                "{name} {axis}"
            );
            assert_eq!(
                pi.active_damping,
                f("current_loop", &format!("{axis}_ACTIVE_DAMPING")),
                "{name} {axis}"
            );
            assert_eq!(
                pi.reference_filter,
                f("current_loop", &format!("{axis}_PREFILTER")),
                "{name} {axis}"
            );
        }
        assert_eq!(cfg.feed_forward.ld, f("current_loop", "FF_LD"), "{name}");
        assert_eq!(cfg.feed_forward.lq, f("current_loop", "FF_LQ"), "{name}");
        assert_eq!(cfg.feed_forward.psi_m, f("current_loop", "FF_PSI"), "{name}");
        assert_eq!(cfg.dc_link_min, f("limits", "DC_LINK_MIN_V"), "{name}");
        // The voltage circle the step applies, margin·U_dc/√3, is VOLTAGE_LIMIT_V at U_dc.
        let udc = d.drive.dc_link_voltage_v;
        let v_max = f64::from(cfg.voltage_margin) * udc / 3f64.sqrt();
        assert!(
            (v_max / number(&g, "limits", "VOLTAGE_LIMIT_V") - 1.0).abs() < 1e-6,
            "{name}"
        );
        // Centre-aligned TIM1 at 170 MHz (STM32G474 maximum SYSCLK): ARR = 170e6/(2·f_s), 4250 at 20 kHz.
        assert_eq!(
            f64::from(cfg.pwm_period),
            (170e6 / (2.0 * number(&g, "limits", "SWITCHING_FREQUENCY_HZ"))).round(),
            "{name}"
        );
    }
}

/// The generated array constant `group::name` as f32 values.
fn array(groups: &[codegen::constants::Group], group: &str, name: &str) -> Vec<f32> {
    let c: &Constant = codegen::constants::group_named(groups, group)
        .and_then(|g| g.constant(name))
        .unwrap_or_else(|| panic!("no constant {group}::{name}"));
    let values = c
        .value
        .number
        .as_array()
        .unwrap_or_else(|| panic!("{group}::{name} is no array"));
    values.iter().map(|v| v.as_f64().unwrap() as f32).collect()
}

/// verify and the image run the same torque stage with the same configuration. The
/// image's control interrupt (`firmware/app/src/board/control.rs`) runs
/// `CONTROLLER.process` with `Demand::Torque`, and `CONTROLLER` is
/// `ControllerConfig::from_parameters` of `motor_config::config::PARAMETERS`, whose `torque`
/// is `TORQUE`, the generated constants named below (`firmware/config/src/config.rs`;
/// the source lines are checked here, so a change of that mapping fails this test).
/// verify's bench runs `ControllerConfig::process` with `Demand::Torque` too
/// (`field_weakening::run`), with [`controller_config`] of the design: its torque stage
/// equals, field for field, the one `from_parameters` makes of those generated constants.
#[test]
fn verify_and_the_image_run_the_same_torque_stage() {
    use motor_control::step::{ControllerConfig, ControllerParameters};
    use motor_control::torque::{TorqueConfig, TorqueParameters};
    let repo = motor_test_support::repo();
    let read = |p: &str| std::fs::read_to_string(repo.join(p)).unwrap();
    let control = read("firmware/app/src/board/control.rs");
    assert!(control.contains("Demand::Torque(torque)"), "the interrupt's demand");
    assert!(
        control.contains("CONTROLLER.process(&mut self.state"),
        "the interrupt's step"
    );
    let config = read("firmware/config/src/config.rs");
    for line in [
        "pub const CONTROLLER: ControllerConfig = ControllerConfig::from_parameters(&PARAMETERS);",
        "pub const TORQUE: TorqueParameters = TorqueParameters {",
        "torque: TORQUE,",
        "sample_period: limits::SAMPLE_PERIOD_S,",
        "pole_pairs: observer::MOTOR_POLE_PAIRS,",
        "psi_m: cl::FF_PSI,",
        "ld: fw::LD,",
        "lq: cl::FF_LQ,",
        "bandwidth: fw::BANDWIDTH,",
        "base_speed: fw::BASE_SPEED,",
        "voltage_fraction: fw::VOLTAGE_FRACTION,",
        "current_max: fw::CURRENT_MAX_A,",
        "mtpa_torque_max: fw::MTPA_TORQUE_MAX_NM,",
        "mtpa_id: fw::MTPA_ID_BY_TORQUE_A,",
    ] {
        assert!(config.contains(line), "firmware/config/src/config.rs: no `{line}`");
    }
    let bench = read("crates/verify/src/field_weakening.rs");
    assert!(bench.contains("b.step(Demand::Torque("), "verify's bench demand");
    for path in motors() {
        let name = stem(&path);
        let (_, d) = load(&path);
        let g = constants(&d);
        let f = |group: &str, n: &str| number(&g, group, n) as f32;
        let mut mtpa_id = [0.0f32; motor_control::torque::MTPA_POINTS];
        let table = array(&g, "field_weakening", "MTPA_ID_BY_TORQUE_A");
        assert_eq!(table.len(), mtpa_id.len(), "{name}");
        mtpa_id.copy_from_slice(&table);
        let generated = TorqueParameters {
            sample_period: f("limits", "SAMPLE_PERIOD_S"),
            pole_pairs: number(&g, "observer", "MOTOR_POLE_PAIRS") as u32,
            psi_m: f("current_loop", "FF_PSI"),
            ld: f("field_weakening", "LD"),
            lq: f("current_loop", "FF_LQ"),
            bandwidth: f("field_weakening", "BANDWIDTH"),
            base_speed: f("field_weakening", "BASE_SPEED"),
            voltage_fraction: f("field_weakening", "VOLTAGE_FRACTION"),
            current_max: f("field_weakening", "CURRENT_MAX_A"),
            mtpa_torque_max: f("field_weakening", "MTPA_TORQUE_MAX_NM"),
            mtpa_id,
        };
        let params: ControllerParameters = motor_verify::controller::controller_parameters(&d);
        assert_eq!(params.torque, generated, "{name}: the torque parameters");
        let cfg: ControllerConfig = controller_config(&d);
        assert_eq!(
            cfg.torque,
            TorqueConfig::from_parameters(&generated),
            "{name}: the torque stage"
        );
        // The stage is on wherever there is a ψ_M (and off, every torque → 0 A, without).
        assert_eq!(cfg.torque.current_max > 0.0, d.field_weakening.is_some(), "{name}");
    }
}

/// A too-slow angle observer in field weakening (Fischer, ω_n = 40 rad/s instead of 70):
/// the controller's frame lags and the current vector turns off its reference. Hand
/// calculation at the default acceleration 2000 rpm/s = 209.44 rad/s² (n_r = 1): K_i =
/// 1600 rad/s², sin Δ = 209.44/1600 = 0.1309 → Δ = 7.52° resolver = 30.1° electrical
/// (n_p = 4), beyond the 10° allowance; a 30° turn moves the current by 2·sin 15° = 0.52
/// of |i^ref|, beyond the 2·sin 9.1° = 0.32 of the tracking bound. Both checks fail;
/// the designed observer passes both.
#[test]
fn slow_observer_loses_current_tracking_in_field_weakening() {
    use codegen::design::angle_observer::design as observer;
    use motor_verify::field_weakening::field_weakening as fw_run;
    let (s, mut d) = load(&motor("fischer-ti085"));
    let good = fw_run(&Setup::new(&s, &d));
    let find = |r: &motor_verify::ScenarioResult, q: &str| {
        r.checks.iter().find(|c| c.quantity.starts_with(q)).cloned().unwrap()
    };
    assert!(find(&good, "peak |i_dq − i_dq^ref|").pass, "{:?}", good.checks);
    assert!(find(&good, "peak electrical angle error").pass);
    let g = observer(
        40.0,
        1.0,
        20e3,
        d.angle_observer.error,
        d.angle_observer.gains.signal_gain,
    )
    .unwrap();
    d.angle_observer.gains.kp_q31 = g.kp_q31;
    d.angle_observer.gains.ki_q31 = g.ki_q31;
    let r = fw_run(&Setup::new(&s, &d));
    let angle = find(&r, "peak electrical angle error");
    assert!(!angle.pass && (angle.measured - 30.1).abs() < 3.0, "{angle:?}");
    let track = find(&r, "peak |i_dq − i_dq^ref|");
    assert!(!track.pass, "{track:?}");
}

/// Issue 27: a design `check` now refuses (fischer-ti085 with R = 126 Ω, its 0.126 Ω read
/// as Ω·10³: L/R = 3.1 µs ≪ T_s = 50 µs, so the plant's sampled model diverges) made
/// `verify` print "NaN ms" rise times and currents of 1e300 A. A simulation that diverges
/// is a failed run with its reason; no figure prints as NaN or inf.
#[test]
fn a_diverging_simulation_fails_with_its_reason_never_nan() {
    let (s, mut d) = load(&motor("fischer-ti085"));
    d.motor.phase_resistance_ohm *= 1000.0;
    let v = run(&s, &d);
    let table = v.table();
    println!("{table}");
    assert!(!v.passed(), "{table}");
    for bad in ["NaN", "inf"] {
        assert!(!table.contains(bad), "{bad} in\n{table}");
    }
    let diverged: Vec<&str> = v
        .scenarios
        .iter()
        .filter(|sc| sc.checks.iter().any(|c| c.quantity == "simulation stays finite"))
        .map(|sc| sc.id)
        .collect();
    assert!(!diverged.is_empty(), "no scenario reports its divergence:\n{table}");
    for sc in &v.scenarios {
        for c in &sc.checks {
            assert!(c.pass || !c.criterion.is_empty(), "{}: {c:?}", sc.id);
            if !c.measured.is_finite() {
                assert!(!c.pass, "{}: a non-finite figure passes: {c:?}", sc.id);
            }
        }
    }
}

/// The guard itself, on a hand-made result: a NaN figure and an infinite sample fail the
/// scenario and are counted; a finite result is left as it was.
#[test]
fn non_finite_figures_and_samples_fail_the_scenario() {
    let check = |measured: f64| motor_verify::Check {
        quantity: "q-axis rise time 10–90 %".into(),
        measured,
        designed: Some(1.5),
        limit: Some(0.15),
        unit: "ms",
        criterion: "within 10 % of designed".into(),
        pass: true,
    };
    let result = |measured: f64, sample: f64| motor_verify::ScenarioResult {
        id: "current_step",
        title: "step".into(),
        reference: "hand-made",
        checks: vec![check(measured)],
        traces: vec![motor_verify::Trace {
            title: "i_q".into(),
            y_label: "A".into(),
            t_ms: vec![0.0, 0.05],
            series: vec![motor_verify::Series {
                label: "i_q".into(),
                values: vec![0.0, sample],
            }],
        }],
        reached_speed_rpm: None,
        torque_speed: None,
    };
    let fine = result(1.49, 1.0);
    assert_eq!(motor_verify::diverged_fails(fine.clone()), fine);
    let r = motor_verify::diverged_fails(result(f64::NAN, f64::INFINITY));
    assert!(!r.passed());
    assert!(!r.checks[0].pass);
    let last = r.checks.last().unwrap();
    assert_eq!(
        (last.quantity.as_str(), last.measured),
        ("simulation stays finite", 2.0)
    );
    assert_eq!(motor_verify::format_value(f64::NAN, "ms"), "diverged");
    assert_eq!(motor_verify::format_value(f64::NEG_INFINITY, "A"), "diverged");
}

/// Hand-checked renderings: 4 significant digits below 10⁷, scientific from there.
#[test]
fn values_print_with_four_digits_and_never_hundreds() {
    assert_eq!(motor_verify::format_value(21.97, "ms"), "21.97 ms");
    assert_eq!(motor_verify::format_value(9_999_999.0, "A"), "9999999 A");
    assert_eq!(motor_verify::format_value(1.1597e305, "A"), "1.160e305 A");
    assert_eq!(motor_verify::format_value(-2.5e7, "V"), "-2.500e7 V");
}
