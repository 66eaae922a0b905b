//! Commissioning routines (thesis A chapter 6) driving the control step and the
//! simulated machine.

use crate::common::*;
use core::f64::consts::PI;
use motor_control::commissioning::*;
use motor_control::fir::{FirState, FmacFir};
use motor_control::step::Demand;

fn fischer_bench(shaft: Shaft) -> Bench {
    let m = FISCHER;
    let alpha = 1000.0;
    let cl = current_loop(pi(alpha * m.ld, alpha * m.r), pi(alpha * m.lq, alpha * m.r));
    Bench::new(config(m, cl), plant(m, shaft))
}

/// §6.2 on the Unimotor (Table 6.1), blocked rotor, 4 V step on q then on d:
/// final currents 4/0.65 = 6.2 A (below the 10 A trip). R and L from (6.3)–(6.8)
/// within 2 % of the plant (the 1-sample PWM delay and the 5 mA ADC step are the
/// error sources). A 10 V step (15 A final) trips.
#[test]
fn blocked_rotor_step_identifies_r_and_l() {
    let m = UNIMOTOR;
    let cl = current_loop(pi(0.54, 65.0), pi(0.76, 65.0));
    for (axis, l_true) in [(Axis::Q, m.lq), (Axis::D, m.ld)] {
        let mut bench = Bench::new(config(m, cl), plant(m, fixed_speed(0.0)));
        let routine = VoltageStep {
            axis,
            voltage: 4.0,
            current_trip: 10.0,
            pre_samples: 20,
            step_samples: 2000,
            decimation: 2,
        };
        let mut st = VoltageStepState::<1024>::new();
        let mut i_dq = bench.last.i_dq;
        let recorded = loop {
            match routine.process(&mut st, i_dq) {
                Progress::Running(demand) => i_dq = bench.step(demand).i_dq,
                Progress::Finished(r) => break r,
            }
        };
        let rec = recorded.expect("no trip");
        assert_eq!(rec.captures, 1010);
        let est = identify_rl(st.captures(), TS as f32).expect("estimate");
        eprintln!(
            "{axis:?}: R = {:.4} Ω (true {}), L = {:.3} mH (true {}), delay {:.1} µs",
            est.resistance,
            m.r,
            est.inductance * 1e3,
            l_true * 1e3,
            est.delay * 1e6
        );
        assert!((f64::from(est.resistance) / m.r - 1.0).abs() < 0.02);
        assert!((f64::from(est.inductance) / l_true - 1.0).abs() < 0.02);
    }

    let mut bench = Bench::new(config(m, cl), plant(m, fixed_speed(0.0)));
    let routine = VoltageStep {
        axis: Axis::Q,
        voltage: 10.0,
        current_trip: 10.0,
        pre_samples: 20,
        step_samples: 4000,
        decimation: 4,
    };
    let mut st = VoltageStepState::<256>::new();
    let mut i_dq = bench.last.i_dq;
    let result = loop {
        match routine.process(&mut st, i_dq) {
            Progress::Running(demand) => i_dq = bench.step(demand).i_dq,
            Progress::Finished(r) => break r,
        }
    };
    match result {
        Err(CommissioningError::Tripped { current, sample }) => {
            eprintln!("10 V step tripped at sample {sample}, |i| = {current:.2} A");
            assert!(current > 10.0 && current < 10.5);
            // Every 4th period up to the trip was captured.
            assert_eq!(st.captures().len(), (sample as usize).div_ceil(4));
        }
        other => panic!("expected a trip, got {other:?}"),
    }
}

/// The captured step filtered through the FMAC model with the 21-tap identification
/// low-pass (thesis A §6.2) still identifies R and L: the linear-phase FIR delays
/// 10 samples uniformly, which cancels in T_r = t_90 − t_10, and has unity DC gain.
#[test]
fn filtered_step_identifies_r_and_l() {
    let m = UNIMOTOR;
    let cl = current_loop(pi(0.54, 65.0), pi(0.76, 65.0));
    let mut bench = Bench::new(config(m, cl), plant(m, fixed_speed(0.0)));
    let routine = VoltageStep {
        axis: Axis::Q,
        voltage: 4.0,
        current_trip: 10.0,
        pre_samples: 40,
        step_samples: 2000,
        decimation: 1,
    };
    let mut st = VoltageStepState::<2048>::new();
    let mut i_dq = bench.last.i_dq;
    while let Progress::Running(demand) = routine.process(&mut st, i_dq) {
        i_dq = bench.step(demand).i_dq;
    }
    let fir = FmacFir::new([
        -852i16, -332, -177, 176, 730, 1447, 2256, 3054, 3730, 4182, 4340, 4182, 3730, 3054, 2256, 1447, 730, 176,
        -177, -332, -852,
    ]);
    let mut fs = FirState::new();
    // Q1.15 with a 16 A full scale.
    let full_scale = 16.0f32;
    let filtered: Vec<Capture> = st
        .captures()
        .iter()
        .map(|c| {
            let x = (c.current / full_scale * 32768.0).round().clamp(-32768.0, 32767.0) as i16;
            let y = fir.process(&mut fs, x);
            Capture {
                current: f32::from(y) / 32768.0 * full_scale,
                ..*c
            }
        })
        .collect();
    let est = identify_rl(&filtered, TS as f32).expect("estimate");
    eprintln!(
        "FIR-filtered q step: R = {:.4} Ω, L = {:.3} mH, delay {:.0} µs (FIR group delay 500 µs)",
        est.resistance,
        est.inductance * 1e3,
        est.delay * 1e6
    );
    assert!((f64::from(est.resistance) / m.r - 1.0).abs() < 0.02);
    assert!((f64::from(est.inductance) / m.lq - 1.0).abs() < 0.02);
}

/// §6.3: +α voltage aligns the rotor at θ_e = 0; θ_off = θ_r (6.9). The rotor
/// starts at θ_e = 1 rad; Fischer with an assumed J = 1e-3 kg·m², b = 0.05 N·m·s.
/// With the identified offset, n_p·(θ_r − θ_off) equals the true θ_e.
#[test]
fn resolver_offset_by_alignment() {
    let mut bench = fischer_bench(free(1e-3, 0.05));
    bench.plant.theta_m = 1.0 / 4.0;
    bench.plant.resolver_offset = -2.0;
    bench.state.observer = motor_control::ato::AtoState::locked((bench.plant.theta_r() / PI * Q31) as i32, 0);
    let routine = ResolverOffset {
        voltage: 1.0, // 1 V/0.126 Ω = 7.9 A
        ramp_samples: 200,
        settle_samples: 20_000,
        average_samples: 1000,
    };
    let mut st = ResolverOffsetState::default();
    let mut theta_r = bench.last.theta_r;
    let offset = loop {
        match routine.process(&mut st, theta_r) {
            Progress::Running(demand) => theta_r = bench.step(demand).theta_r,
            Progress::Finished(o) => break o,
        }
    };
    bench.cfg.angle.offset = offset;
    bench.state.turns.align(theta_r);
    // True electrical angle after alignment ≈ 0 (mod 2π).
    let th_e = bench.plant.theta_e();
    let wrapped = th_e - 2.0 * PI * ((th_e + PI) / (2.0 * PI)).floor();
    let off = f64::from(offset) * PI / Q31;
    eprintln!("rotor aligned at θ_e = {wrapped:.5} rad, θ_off = {off:.5} rad");
    assert!(wrapped.abs() < 1e-3);
    // The offset differs from the plant's −2 rad by a multiple of 2π/n_p (the
    // rotor can align at any of the n_p electrical zeros, (6.9) is not unique).
    let k = (off + 2.0) / (2.0 * PI / 4.0);
    assert!((k - k.round()).abs() < 1e-3, "{k}");
    // Now run the step once more: θ_e from the controller matches the plant.
    let out = bench.step(Demand::Off);
    let th = f64::from(out.theta_e) * PI / Q31;
    let e = th - bench.plant.theta_e();
    assert!((e - 2.0 * PI * ((e + PI) / (2.0 * PI)).floor()).abs() < 5e-3, "{e}");
}

/// §6.4: rotate the stator field 8 electrical turns at 2 Hz; the resolver travels
/// 2 turns for n_p = 4, n_r = 1 → ratio 4; with a 2-pole-pair resolver 2; with a
/// reversed resolver the directions disagree.
#[test]
fn pole_pair_ratio_and_direction() {
    for (nr, sign, expected, agree) in [(1, 1.0, 4.0, true), (2, 1.0, 2.0, true), (1, -1.0, 4.0, false)] {
        let mut bench = fischer_bench(free(1e-3, 0.05));
        bench.plant.resolver_pole_pairs = nr;
        bench.plant.resolver_reversed = sign < 0.0;
        bench.state.observer = motor_control::ato::AtoState::locked((bench.plant.theta_r() / PI * Q31) as i32, 0);
        let routine = PolePairRatio {
            voltage: 1.0,
            // 2 Hz electrical: 2/20000 of a turn per period = 2^32·1e-4 LSB.
            step: (4_294_967_296.0f64 * 2.0 / FS).round() as i32,
            turns: 8,
            settle_samples: 10_000,
        };
        let mut st = PolePairRatioState::default();
        let mut theta_r = bench.last.theta_r;
        let result = loop {
            match routine.process(&mut st, &mut motor_control::SoftTrig, theta_r) {
                Progress::Running(demand) => theta_r = bench.step(demand).theta_r,
                Progress::Finished(r) => break r,
            }
        };
        let r = result.expect("rotation");
        eprintln!(
            "n_r = {nr}, sign {sign}: ratio {:.4}, directions agree {}",
            r.ratio, r.directions_agree
        );
        assert!((f64::from(r.ratio) - expected).abs() < 0.01 * expected);
        assert_eq!(r.directions_agree, agree);
    }
}

/// A locked rotor does not turn: the routine reports it.
#[test]
fn pole_pair_ratio_without_rotation() {
    let mut bench = fischer_bench(fixed_speed(0.0));
    let routine = PolePairRatio {
        voltage: 1.0,
        step: 1 << 22,
        turns: 2,
        settle_samples: 10,
    };
    let mut st = PolePairRatioState::default();
    let mut theta_r = bench.last.theta_r;
    let result = loop {
        match routine.process(&mut st, &mut motor_control::SoftTrig, theta_r) {
            Progress::Running(demand) => theta_r = bench.step(demand).theta_r,
            Progress::Finished(r) => break r,
        }
    };
    assert_eq!(result, Err(CommissioningError::NoRotation));
}

/// §6.5: driven at ω_m = 200 rad/s (ω_e = 800 rad/s), zero current, feed-forward
/// off: ψ_M = Σu_q/Σω_e (6.10) within 1 % of the plant's 0.058 Wb.
#[test]
fn flux_linkage_at_zero_current() {
    let mut bench = fischer_bench(fixed_speed(200.0));
    let routine = FluxLinkage {
        settle_samples: 4000,
        average_samples: 4000,
        min_speed: 100.0,
    };
    let mut st = FluxLinkageState::default();
    let (mut uq, mut we) = (0.0, 0.0);
    let psi = loop {
        match routine.process(&mut st, uq, we) {
            Progress::Running(demand) => {
                let out = bench.step(demand);
                uq = out.u_dq.q;
                we = out.omega_e;
            }
            Progress::Finished(r) => break r.expect("fast enough"),
        }
    };
    eprintln!("ψ_M estimate {psi:.5} Wb (plant 0.058)");
    assert!((f64::from(psi) / FISCHER.psi - 1.0).abs() < 0.01);

    let mut bench = fischer_bench(fixed_speed(5.0));
    let mut st = FluxLinkageState::default();
    let (mut uq, mut we) = (0.0, 0.0);
    let r = loop {
        match routine.process(&mut st, uq, we) {
            Progress::Running(demand) => {
                let out = bench.step(demand);
                uq = out.u_dq.q;
                we = out.omega_e;
            }
            Progress::Finished(r) => break r,
        }
    };
    assert_eq!(r, Err(CommissioningError::TooSlow));
}

/// `Demand::Off` gives zero voltage: all duties 1/2, compare = round(0.5·4250).
#[test]
fn off_is_zero_voltage() {
    let mut bench = fischer_bench(fixed_speed(0.0));
    let out = bench.step(Demand::Off);
    assert_eq!(out.duties, [0.5; 3]);
    assert_eq!(out.compare, [2125; 3]);
}
