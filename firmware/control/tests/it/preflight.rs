//! The pre-flight check (issue 26 item 2) driving the control step and the simulated
//! machine (`motor-sim`, the plant `motorgen verify` runs), free rotor: a healthy
//! drive passes; each defect is refused with its own reason.
//!
//! Fischer TI085 (thesis A Table 1.2): R = 0.126 Ω, L = 0.393 mH (τ = 3.1 ms), n_p = 4.
//! Pulse current 10 A → V = R·I = 1.26 V; levels of 8τ (25 ms = 500 periods at 20 kHz);
//! the rotation one electrical turn per second at the same voltage; R and L accepted
//! within a factor 2, n_p/n_r within ±0.5, the end angle within 30° electrical. The
//! rotor's inertia J = 1e-3 kg·m² with b = 1e-3 N·m·s/rad (a motor on the bench, shaft
//! free).

use crate::common::*;
use core::f64::consts::PI;
use motor_control::can_protocol::FaultMeasurement;
use motor_control::commissioning::Progress;
use motor_control::preflight::{Preflight, PreflightFault, PreflightInput, PreflightState, PulseFigures, Refusal};

fn check() -> Preflight {
    let m = FISCHER;
    Preflight {
        voltage: (m.r * 10.0) as f32,
        level_samples: 500,
        rest_samples: 500,
        average_samples: 50,
        resistance: m.r as f32,
        inductance: m.ld as f32,
        resistance_ratio: 2.0,
        inductance_ratio: 2.0,
        // The most the lowest accepted R (R/2) draws, +20 %.
        current_trip: (1.2 * 2.0 * 10.0) as f32,
        sum_bound: 1.0,
        open_fraction: 0.5,
        sample_period: TS as f32,
        // Loop delay 1.5·T_s (thesis A §4.6, the bench's timing) + T_s/2.
        tau_offset: (2.0 * TS) as f32,
        rotation_voltage: (m.r * 10.0) as f32,
        // One electrical turn per second: 2^32·T_s LSB per period.
        rotation_step: (4_294_967_296.0 * TS).round() as i32,
        settle_samples: 10_000,
        ratio: 4.0,
        ratio_bound: 0.5,
        // 30° electrical = π/6 → 2^31/6.
        angle_bound: (Q31 / 6.0) as i32,
    }
}

fn bench() -> Bench {
    let m = FISCHER;
    let alpha = 1000.0;
    let cl = current_loop(pi(alpha * m.ld, alpha * m.r), pi(alpha * m.lq, alpha * m.r));
    Bench::new(config(m, cl), plant(m, free(1e-3, 1e-3)))
}

/// The refusal of `r`, its fault and measured figure (panics on a pass).
fn refused(r: Result<PulseFigures, Refusal>) -> (PreflightFault, FaultMeasurement) {
    let r = r.expect_err("refused");
    println!("refused: {r:?}");
    (r.fault, r.measured)
}

/// Runs the check to its verdict; the periods it took and the largest |phase current|.
fn run(mut bench: Bench, check: &Preflight) -> (Result<PulseFigures, Refusal>, u64, f64) {
    let mut st = PreflightState::default();
    let mut periods = 0u64;
    let mut peak = 0.0f64;
    loop {
        let o = bench.last;
        let input = PreflightInput {
            i_uvw: o.i_uvw,
            theta_e: o.theta_e,
            theta_r: o.theta_r,
        };
        match check.process(&mut st, &mut motor_control::SoftTrig, &input) {
            Progress::Running(d) => {
                bench.step(d);
                periods += 1;
                let m = bench.plant.measure();
                peak = m.phase_currents.iter().fold(peak, |a, i| a.max(i.abs()));
            }
            Progress::Finished(r) => return (r, periods, peak),
        }
        assert!(periods <= check.periods(), "ran past its {} periods", check.periods());
    }
}

/// A healthy drive passes; R and L within 5 % of the plant's (the dead time is not
/// modelled here; the 5 mA current LSB and the loop delay's approximation are the error
/// sources); the current never beyond 10.5 A.
#[test]
fn healthy_drive_passes() {
    let c = check();
    let (r, periods, peak) = run(bench(), &c);
    let f = r.expect("healthy");
    eprintln!("healthy: {f:?}, {periods} periods, peak {peak:.2} A");
    for r in f.resistance {
        assert!((f64::from(r) / FISCHER.r - 1.0).abs() < 0.05, "R {r}");
    }
    for l in f.inductance {
        assert!((f64::from(l) / FISCHER.ld - 1.0).abs() < 0.05, "L {l}");
    }
    assert!(f.sum < 0.05, "sum {}", f.sum);
    assert!(peak < 10.5, "peak {peak}");
}

/// The board's sensing inverted (the plant's currents read with the opposite sign):
/// refused at the end of the first hold, before the turn: after its 10 000 periods.
#[test]
fn inverted_sensing_is_refused() {
    let mut b = bench();
    b.current_gain = [-1.0; 3];
    let c = check();
    let (r, periods, _) = run(b, &c);
    let (fault, m) = refused(r);
    assert_eq!(fault, PreflightFault::InvertedSensing);
    assert_eq!(periods, u64::from(c.settle_samples), "{periods}");
    // The hold's current along its voltage, read inverted: −V_rot/R = −10 A once settled
    // (the held voltage draws R·I = V through the star: 1.26 V/0.126 Ω), within 0.5 %.
    assert_eq!(m.index, 0);
    assert!((f64::from(m.value) + 10.0).abs() < 0.05, "{m:?}");
}

/// Inverted sensing on a drive whose hold cannot see it — phase u open with the hold's
/// voltage along u (θ_e = 0: legs v and w at one potential, no current during the
/// hold): the hold passes it and the turn refuses the open phase.
#[test]
fn inverted_sensing_with_no_hold_current_is_left_to_the_turn() {
    let mut b = bench();
    b.current_gain = [-1.0; 3];
    b.plant.open_phase = Some(0);
    // The resolver's θ_e at rest is the hold's angle: 0, phase u's axis.
    assert_eq!(b.plant.theta_e(), 0.0);
    let c = check();
    let (r, periods, _) = run(b, &c);
    let (fault, m) = refused(r);
    assert_eq!(fault, PreflightFault::OpenPhase);
    assert!(periods > u64::from(c.settle_samples), "{periods}");
    // Phase u (index 0) carried nothing during the turn.
    assert_eq!(m.index, 0);
    assert!(m.value.abs() < 0.05, "{m:?}");
}

/// One phase's gain 20 % high: the currents no longer sum to zero.
#[test]
fn a_wrong_gain_breaks_the_sum() {
    let mut b = bench();
    b.current_gain[0] = 1.2;
    let (fault, m) = refused(run(b, &check()).0);
    assert_eq!(fault, PreflightFault::CurrentSum);
    // |Σ| = 0.2·|i_u| beyond the 1 A bound, at most 0.2 of the 10 A pulse.
    assert!(m.value > 1.0 && m.value <= 2.1, "{m:?}");
}

/// Phase w open with the resolver's θ_e = 0.3·4 rad (69° from w's axis at 240°: |cos| =
/// 0.36, not judged by the pulse): found by the rotation. Phase u open (θ_e 69° from
/// it… and 171° from v): the pulse finds it.
#[test]
fn an_open_phase_is_refused() {
    for k in [0usize, 1, 2] {
        let mut b = bench();
        b.plant.open_phase = Some(k);
        let (r, periods, _) = run(b, &check());
        eprintln!("phase {k} open: {r:?} after {periods} periods");
        let (fault, m) = refused(r);
        assert_eq!(fault, PreflightFault::OpenPhase, "phase {k}");
        // The open phase is the one named, and it carried nothing.
        assert_eq!(usize::from(m.index), k, "{m:?}");
        assert!(m.value.abs() < 0.05, "phase {k}: {m:?}");
    }
}

/// A too-high R (a bad connection, 3·R): refused on R.
#[test]
fn a_high_resistance_is_refused() {
    let mut b = bench();
    b.plant.motor.resistance *= 3.0;
    let (fault, m) = refused(run(b, &check()).0);
    assert_eq!(fault, PreflightFault::Resistance);
    // The + pulse's R: 3·0.126 = 0.378 Ω within the healthy drive's 5 %.
    assert_eq!(m.index, 0);
    assert!((f64::from(m.value) / (3.0 * FISCHER.r) - 1.0).abs() < 0.05, "{m:?}");
}

/// L three times the spec's: refused on L.
#[test]
fn a_wrong_inductance_is_refused() {
    let mut b = bench();
    b.plant.motor.ld *= 3.0;
    b.plant.motor.lq *= 3.0;
    let mut c = check();
    // Long enough levels for the slower rise (8τ of 3·L).
    c.level_samples = 1500;
    let (fault, m) = refused(run(b, &c).0);
    assert_eq!(fault, PreflightFault::Inductance);
    // The + pulse's L: 3·0.393 = 1.179 mH within the healthy drive's 5 %.
    assert_eq!(m.index, 0);
    assert!((f64::from(m.value) / (3.0 * FISCHER.ld) - 1.0).abs() < 0.05, "{m:?}");
}

/// Two motor leads swapped: the field turns the other way, and so does the resolver —
/// the same as a resolver mounted the other way round.
#[test]
fn reversed_rotation_is_refused() {
    let mut b = bench();
    b.plant.resolver_reversed = true;
    b.sim = motor_sim::bench::Bench::new(b.cfg, b.plant.clone());
    let (fault, m) = refused(run(b, &check()).0);
    assert_eq!(fault, PreflightFault::Direction);
    // The resolver travelled the whole expected turn, backwards: −1.
    assert!((m.value + 1.0).abs() < 0.01, "{m:?}");
}

/// The motor has 5 pole pairs, the configuration says 4: the resolver turns 4/5 of the
/// expected travel, ratio 5 ≠ 4 ± 0.5.
#[test]
fn a_wrong_pole_pair_count_is_refused() {
    let mut b = bench();
    b.plant.motor.pole_pairs = 5;
    let (fault, m) = refused(run(b, &check()).0);
    assert_eq!(fault, PreflightFault::PolePairRatio);
    // The measured n_p/n_r is the plant's 5.
    assert!((m.value - 5.0).abs() < 0.01, "{m:?}");
}

/// The resolver offset 90° electrical off (the plant's θ_off moved by π/2 /n_p·n_r):
/// refused at the end angle.
#[test]
fn a_resolver_offset_is_refused() {
    let mut b = bench();
    b.plant.resolver_offset += PI / 2.0 / 4.0;
    b.sim = motor_sim::bench::Bench::new(b.cfg, b.plant.clone());
    let (fault, m) = refused(run(b, &check()).0);
    assert_eq!(fault, PreflightFault::ResolverOffset);
    // 90° electrical off (the rotor at rest under the hold: no load angle).
    assert!((m.value.abs() - 90.0).abs() < 0.5, "{m:?}");
}
