//! Closed-loop tests of the complete control step against the discrete PMSM model
//! (thesis A (2.26)) at f_s = 20 kHz, U_dc = 600 V, with the thesis' motors.
//!
//! The gains are computed here from the thesis formulas with the arithmetic written
//! out; in the firmware they come from the code generator through `ControllerConfig`.
//! Run with `--nocapture` to see the measured figures.

use crate::common::*;
use core::f64::consts::PI;
use motor_control::pi::PiConfig;
use motor_control::step::Demand;

/// Runs `settle` periods at zero current, then `steps` periods of the demand, and
/// returns the true plant currents (i_d, i_q) at each sample after the step.
fn run_step(
    bench: &mut Bench,
    settle: usize,
    steps: usize,
    id: f32,
    iq: f32,
    feed_forward: bool,
) -> (Vec<f64>, Vec<f64>) {
    for _ in 0..settle {
        bench.step(Demand::Current {
            id: 0.0,
            iq: 0.0,
            feed_forward,
        });
    }
    let (mut d, mut q) = (vec![bench.plant.i[0]], vec![bench.plant.i[1]]);
    for _ in 0..steps {
        bench.step(Demand::Current { id, iq, feed_forward });
        d.push(bench.plant.i[0]);
        q.push(bench.plant.i[1]);
    }
    (d, q)
}

/// ln 9/α: the 10–90 % rise time of the first-order closed loop (5.8), (2.41).
fn first_order_rise(alpha: f64) -> f64 {
    9f64.ln() / alpha
}

/// Checks a first-order response: rise time within 10 % of ln 9/α, no overshoot
/// (≤ 0.5 % of the step, the ADC resolution 5 mA is 0.025 % of 20 A) and settled.
fn assert_first_order(name: &str, samples: &[f64], target: f64, alpha: f64) {
    let f = step_figures(samples, samples[0], target);
    let want = first_order_rise(alpha);
    eprintln!(
        "{name}: rise {:.4} ms (ln9/α = {:.4} ms, {:+.1} %), overshoot {:.3} %",
        f.rise_time * 1e3,
        want * 1e3,
        (f.rise_time / want - 1.0) * 100.0,
        f.overshoot * 100.0
    );
    assert!(
        (f.rise_time / want - 1.0).abs() < 0.10,
        "{name}: rise time {} vs {want}",
        f.rise_time
    );
    assert!(f.overshoot < 0.005, "{name}: overshoot {}", f.overshoot);
    assert!(f.final_error.abs() < 0.01, "{name}: final error {}", f.final_error);
}

/// IMC (thesis A (5.9)): K_a = K_p = α·L, K_b = R/L → K_i = K_a·K_b = α·R.
///
/// Fischer TI085, α = 1000 rad/s (5 % of ω_s = 2π·20 kHz, inside the 30 % rule):
/// K_p = 1000·0.393e-3 = 0.393 V/A, K_i = 1000·0.126 = 126 V/(A·s);
/// ln 9/α = 2.197 ms = 44 samples.
#[test]
fn imc_fischer_rise_time_and_no_overshoot() {
    let m = FISCHER;
    let alpha = 1000.0;
    let (kp, ki) = (alpha * m.lq, alpha * m.r);
    assert!((kp - 0.393).abs() < 1e-12 && (ki - 126.0).abs() < 1e-9);
    for (axis, id, iq) in [("Fischer IMC α=1000 q", 0.0, 20.0), ("Fischer IMC α=1000 d", 20.0, 0.0)] {
        let cfg = config(m, current_loop(pi(alpha * m.ld, alpha * m.r), pi(kp, ki)));
        let mut bench = Bench::new(cfg, plant(m, fixed_speed(0.0)));
        let (d, q) = run_step(&mut bench, 200, 600, id, iq, true);
        let samples = if id != 0.0 { d } else { q };
        assert_first_order(axis, &samples, 20.0, alpha);
    }
}

/// Unimotor 142UMD300 (Table 6.1), α = 100 rad/s as in thesis A §5.4.1:
/// d: K_p = 100·5.4e-3 = 0.54 V/A, K_i = 100·0.65 = 65 V/(A·s);
/// q: K_p = 100·7.6e-3 = 0.76 V/A, K_i = 65 V/(A·s); ln 9/α = 21.97 ms.
#[test]
fn imc_unimotor_rise_time_and_no_overshoot() {
    let m = UNIMOTOR;
    let alpha = 100.0;
    let (kpd, kpq, ki) = (alpha * m.ld, alpha * m.lq, alpha * m.r);
    assert!((kpd - 0.54).abs() < 1e-12 && (kpq - 0.76).abs() < 1e-12 && (ki - 65.0).abs() < 1e-9);
    for (axis, id, iq) in [("Unimotor IMC α=100 q", 0.0, 5.0), ("Unimotor IMC α=100 d", 5.0, 0.0)] {
        let cfg = config(m, current_loop(pi(kpd, ki), pi(kpq, ki)));
        let mut bench = Bench::new(cfg, plant(m, fixed_speed(0.0)));
        let (d, q) = run_step(&mut bench, 200, 4000, id, iq, true);
        let samples = if id != 0.0 { d } else { q };
        assert_first_order(axis, &samples, 5.0, alpha);
    }
}

/// IMC with active damping (thesis B (2.38), (2.39), (2.43)): R_a = α·L − R,
/// k_p = α·L, k_i = α·(R + R_a) = α²·L. Fischer, α = 1000 rad/s:
/// R_a = 0.393 − 0.126 = 0.267 Ω, k_i = 1000·0.393 = 393 V/(A·s).
/// The reference response is still first order (2.41).
#[test]
fn imc_active_damping_fischer() {
    let m = FISCHER;
    let alpha = 1000.0;
    let ra = alpha * m.lq - m.r;
    assert!((ra - 0.267).abs() < 1e-12);
    let axis = PiConfig {
        active_damping: ra as f32,
        ..pi(alpha * m.lq, alpha * (m.r + ra))
    };
    let cfg = config(m, current_loop(axis, axis));
    let mut bench = Bench::new(cfg, plant(m, fixed_speed(0.0)));
    let (_, q) = run_step(&mut bench, 200, 600, 0.0, 20.0, true);
    assert_first_order("Fischer IMC+R_a α=1000 q", &q, 20.0, alpha);
}

/// Pole placement (thesis A (5.14), (5.15)) with ζ = 1/√2:
/// ω_n = α/√(1 − 2ζ² + √(4ζ⁴ − 4ζ² + 2)) = α/√(0 + √(1 − 2 + 2)) = α;
/// K_i = L·ω_n², K_p = 2ζω_n·L − R; the RHP-zero check ω_n·ζ ≥ R/(2L).
/// The closed loop (5.11) has a zero at −K_i/K_p; the shaping filter (5.16)
/// D(s) = 1/((K_p/K_i)·s + 1) cancels it, discretised exactly
/// (a = 1 − e^{−T_s·K_i/K_p}). With it the step response is that of (4.14) with
/// ζ = 1/√2: overshoot e^{−π} = 4.3 % ≤ 5 %.
///
/// Fischer, α = 1000: K_i = 0.393e-3·1e6 = 393, K_p = √2·1000·0.393e-3 − 0.126 = 0.4298.
/// Unimotor, α = 100: d: K_i = 5.4e-3·1e4 = 54, K_p = √2·100·5.4e-3 − 0.65 = 0.1137;
/// q: K_i = 76, K_p = √2·100·7.6e-3 − 0.65 = 0.4248.
#[test]
fn pole_placement_overshoot() {
    let zeta = 1.0 / 2f64.sqrt();
    let omega_n =
        |alpha: f64| alpha / (1.0 - 2.0 * zeta * zeta + (4.0 * zeta.powi(4) - 4.0 * zeta * zeta + 2.0).sqrt()).sqrt();
    let design = |l: f64, r: f64, alpha: f64, shaped: bool| -> PiConfig {
        let wn = omega_n(alpha);
        assert!((wn - alpha).abs() < 1e-9 * alpha);
        assert!(wn * zeta >= r / (2.0 * l), "RHP zero");
        let (ki, kp) = (l * wn * wn, 2.0 * zeta * wn * l - r);
        PiConfig {
            reference_filter: if shaped {
                (1.0 - (-TS * ki / kp).exp()) as f32
            } else {
                1.0
            },
            ..pi(kp, ki)
        }
    };
    for (name, m, alpha, steps, target) in [
        ("Fischer PP α=1000", FISCHER, 1000.0, 1000, 20.0),
        ("Unimotor PP α=100", UNIMOTOR, 100.0, 6000, 5.0),
    ] {
        for (axis, id, iq) in [("q", 0.0, target), ("d", target, 0.0)] {
            let mut overshoot = [0.0; 2];
            for shaped in [false, true] {
                let cl = current_loop(design(m.ld, m.r, alpha, shaped), design(m.lq, m.r, alpha, shaped));
                let mut bench = Bench::new(config(m, cl), plant(m, fixed_speed(0.0)));
                let (d, q) = run_step(&mut bench, 200, steps, id as f32, iq as f32, true);
                let samples = if axis == "d" { d } else { q };
                let f = step_figures(&samples, 0.0, target);
                eprintln!(
                    "{name} {axis}, shaping filter {shaped}: rise {:.4} ms, overshoot {:.2} %",
                    f.rise_time * 1e3,
                    f.overshoot * 100.0
                );
                assert!(f.final_error.abs() < 0.01);
                overshoot[usize::from(shaped)] = f.overshoot;
            }
            assert!(overshoot[1] <= 0.05, "{name} {axis}: {}", overshoot[1]);
            assert!(overshoot[1] < overshoot[0]);
        }
    }
}

/// Decoupling feed-forward (5.3) at speed: Fischer at ω_e = 3000 rad/s
/// (ω_m = 750 rad/s, 7160 rpm; back EMF ω_e·ψ_M = 174 V), IMC α = 1000 rad/s,
/// i_q step 0 → 50 A. The cross-coupling voltage ω_e·L_q·i_q = 59 V drives i_d; with
/// the feed-forward the i_d excursion must be at least 3× smaller.
#[test]
fn decoupling_cuts_id_excursion() {
    let m = FISCHER;
    let alpha = 1000.0;
    let cl = current_loop(pi(alpha * m.ld, alpha * m.r), pi(alpha * m.lq, alpha * m.r));
    let wm = 3000.0 / f64::from(m.np);
    let mut excursion = [0.0f64; 2];
    for ff in [false, true] {
        let mut bench = Bench::new(config(m, cl), plant(m, fixed_speed(wm)));
        // 0.1 s at i = 0 lets the integrators take over the back EMF without
        // feed-forward.
        let (d, q) = run_step(&mut bench, 2000, 600, 0.0, 50.0, ff);
        let peak = d.iter().fold(0.0f64, |a, &x| a.max(x.abs()));
        let f = step_figures(&q, q[0], 50.0);
        eprintln!(
            "Fischer ω_e = 3000 rad/s, i_q 0→50 A, feed-forward {ff}: max |i_d| = {peak:.3} A, i_q rise {:.4} ms, overshoot {:.2} %",
            f.rise_time * 1e3,
            f.overshoot * 100.0
        );
        excursion[usize::from(ff)] = peak;
    }
    let ratio = excursion[0] / excursion[1];
    eprintln!("i_d excursion ratio without/with feed-forward: {ratio:.1}");
    assert!(ratio >= 3.0, "ratio {ratio}");
}

/// At speed with the feed-forward, the q step is still first order within 10 %
/// (the lead angle (4.23) keeps the output frame aligned despite the 1.5·T_s delay).
#[test]
fn imc_at_speed_with_feed_forward() {
    let m = FISCHER;
    let alpha = 1000.0;
    let cl = current_loop(pi(alpha * m.ld, alpha * m.r), pi(alpha * m.lq, alpha * m.r));
    let mut bench = Bench::new(config(m, cl), plant(m, fixed_speed(2000.0 / 4.0)));
    let (_, q) = run_step(&mut bench, 2000, 600, 0.0, 20.0, true);
    assert_first_order("Fischer IMC α=1000 q at ω_e = 2000 rad/s", &q, 20.0, alpha);
}

/// Sanity: the observer at speed agrees with the plant's angle, and θ_e from the
/// step equals n_p·(θ_r − θ_off).
#[test]
fn electrical_angle_follows_rotor() {
    let m = FISCHER;
    let cl = current_loop(pi(0.393, 126.0), pi(0.393, 126.0));
    let mut bench = Bench::new(config(m, cl), plant(m, fixed_speed(500.0)));
    let mut worst = 0.0f64;
    for _ in 0..4000 {
        let th_true = bench.plant.theta_e();
        let out = bench.step(Demand::Current {
            id: 0.0,
            iq: 5.0,
            feed_forward: true,
        });
        let th = f64::from(out.theta_e) * PI / Q31;
        let e = th - th_true;
        worst = worst.max((e - 2.0 * PI * ((e + PI) / (2.0 * PI)).floor()).abs());
    }
    // Observer dead zone (6e-5 rad resolver) × n_p plus the lag of the f64 plant:
    // < 1e-3 rad electrical.
    assert!(worst < 1e-3, "{worst}");
}
