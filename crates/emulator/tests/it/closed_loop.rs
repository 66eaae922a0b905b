//! The closed loop on the real image, every board with every motor that fits it:
//! `motorgen verify`'s simulated drive (blocked rotor, as in its `current_step`) behind
//! the ADC inputs through the board's own sensing (its hardware description, not the
//! board file), driven by the switches the board's gate driver turns on from the pins
//! the image drives; a q-axis current step commanded as a CAN torque setpoint T =
//! i_q/K_t (the design's `iq_per_nm`), judged by `current_step`'s own criteria
//! (`motor_verify::scenarios::current_step_checks`).
//!
//! The d-axis step of `current_step` has no counterpart here: over CAN the image takes a
//! torque. Its torque stage (issue 30) puts a torque on the MTPA curve (3.10): on a salient
//! motor (chalmers-hev50, amk-dd5-ipm) the q-axis step is then the MTPA point's i_q for
//! the frame's torque (i_d < 0 adds reluctance torque, so less than T/K_t), found here by
//! bisection along codegen's MTPA point on a circle; on the others T/K_t.
//!
//! A design without a torque constant (unimotor-142umd300: no ψ_M in its spec, so
//! `iq_per_nm` is 0 and `motorgen check` warns) turns every torque into i_q = 0: it
//! cannot be stepped through CAN. For it the test asserts what must hold instead: under
//! a torque setpoint the drive stays on, untripped, and both currents stay within one
//! ADC step of the current sensing (its quantisation) of zero.

use crate::BOOT_LIMIT_S;
use motor_emulator::drive::{Drive, Sample};
use motor_emulator::rig::{Bench, Rig, benches};
use motor_sim::plant::SpeedProfile;
use motor_verify::Setup;
use motor_verify::scenarios::{current_step, current_step_checks, current_step_samples, step_amplitude};

/// Zero-torque time after the first enabled period before the step \[s\]: the image's
/// angle observer, acquired on the resolver during the offset calibration, settles at
/// zero torque meanwhile.
const SETTLE_S: f64 = 0.02;

/// Carrier periods from the frame to the first update with moved duties, beyond the
/// period the image's sample can fall in before its main loop has read the frame.
const SLACK_PERIODS: f64 = 2.0;

/// The step's outcome: verify's criteria measured on the image (name, measured, unit,
/// verify's figure, designed, criterion, pass).
pub struct Outcome {
    /// i_q reference of the step \[A\].
    pub target: f64,
    /// Every criterion as (name, pass, line for the report).
    pub checks: Vec<(String, bool, String)>,
    /// Time of the step's frame \[s\].
    pub at: f64,
    /// The step's torque setpoint \[N·m\] (quantised as the frame carries it).
    pub torque: f64,
}

impl Outcome {
    /// The criteria that failed.
    pub fn failed(&self) -> Vec<String> {
        self.checks.iter().filter(|c| !c.1).map(|c| c.0.clone()).collect()
    }
}

/// i_q \[A\] of the MTPA point (3.10) that makes `torque` \[N·m\] by (2.33): the circle
/// radius bisected until `mtpa_corner`'s point makes it (T/K_t without saliency).
fn mtpa_iq(d: &codegen::design::Design, torque: f64, iq_per_nm: f64) -> f64 {
    let m = &d.motor;
    let (psi, dl) = (m.flux_linkage_wb.unwrap_or(0.0), m.q_inductance_h - m.d_inductance_h);
    if dl == 0.0 || psi <= 0.0 {
        return torque * iq_per_nm;
    }
    let np = f64::from(m.pole_pairs);
    let point = |i: f64| codegen::design::loss_minimisation::mtpa_corner(psi, dl, i);
    let made = |i: f64| {
        let (id, iq) = point(i);
        1.5 * np * iq * (psi - dl * id)
    };
    let (mut lo, mut hi) = (0.0, 2.0 * torque * iq_per_nm);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if made(mid) < torque { lo = mid } else { hi = mid }
    }
    point(0.5 * (lo + hi)).1
}

/// The rig with the closed-loop drive, booted and settled at zero torque, and the spec
/// (for `verify`'s `Setup`: the same machine model). `Err` names what stopped it first:
/// a strict-mode rule, or the criterion "boot" / "zero torque" with the fault record.
pub(crate) fn closed_loop(bench: Bench) -> Result<(Rig, codegen::spec::Spec), String> {
    let spec = motor_emulator::wiring::spec(&bench.motor)?;
    let mut rig = Rig::with_analog(bench, |d, hw| {
        Ok(Box::new(Drive::new(
            &Setup::new(&spec, d),
            SpeedProfile::constant(0.0),
            hw,
        )))
    })?;
    rig.boot(BOOT_LIMIT_S).map_err(|e| format!("boot: {e}"))?;
    let t = rig.machine.soc().time_s() + SETTLE_S;
    rig.run(t, |_| Some(0.0), |_| false)
        .map_err(|e| format!("zero torque: {e}; {}", rig.machine.summary()))?;
    if !rig.machine.soc().tim1.moe() {
        return Err(format!(
            "zero torque: the drive switched itself off (fault record: {})",
            rig.fault_cause().unwrap_or_else(|| "none".into())
        ));
    }
    Ok((rig, spec))
}

/// Sends zero torque until the next setpoint frame, `torque_nm` from then on, until
/// `periods` carrier periods after that frame; returns the frame's time \[s\].
fn step_torque(rig: &mut Rig, torque_nm: f64, periods: f64) -> Result<f64, String> {
    let now = rig.machine.soc().time_s();
    let frame = rig.setpoint_period_s();
    // Frames go out every setpoint period from reset (`Rig::run`).
    let at = (now / frame).ceil() * frame;
    let end = at + periods * rig.pwm_period_s();
    rig.run(end, |t| Some(if t >= at { torque_nm } else { 0.0 }), |_| false)
        .map_err(|e| format!("{e}; {}", rig.machine.summary()))?;
    Ok(at)
}

/// Runs verify's current step on `bench` and measures its criteria; `Err` when the run
/// stops before (a strict-mode rule, the boot, a trip at zero torque). `Ok(None)` for a
/// motor without a torque constant, after checking that it stays on at zero current.
pub fn current_step_on(bench: Bench) -> Result<Option<Outcome>, String> {
    current_step_rig(bench).map(|(out, _)| out)
}

/// [`current_step_on`], keeping the rig (at the step's end, the step torque's frames
/// still going out) for a scenario after it.
fn current_step_rig(bench: Bench) -> Result<(Option<Outcome>, Rig), String> {
    let name = bench.name();
    let (mut rig, spec) = closed_loop(bench)?;
    let design = rig.design.clone();
    let setup = Setup::new(&spec, &design);
    let ts = design.drive.sample_period_s;
    assert!(
        (rig.pwm_period_s() / ts - 1.0).abs() < 1e-9,
        "{name}: one sample per carrier period assumed"
    );
    let n = current_step_samples(&setup);
    let board = design.board.as_ref().unwrap().board.clone();
    let lsb_a = board.adc_reference_v / 4096.0 / board.current.gain_v_per_a.abs();
    let Some(iq_per_nm) = design.current_loop.feedforward.iq_per_nm.filter(|k| *k > 0.0) else {
        // No torque constant: every torque is i_q = 0.
        let torque = board.torque_resolution_nm * 1000.0;
        let at = step_torque(&mut rig, torque, n as f64 + 10.0)?;
        let drive = rig.analog_as::<Drive>().unwrap();
        let after: Vec<Sample> = drive.samples.iter().filter(|s| s.t >= at).copied().collect();
        let peak = after.iter().map(|s| s.i[0].abs().max(s.i[1].abs())).fold(0.0, f64::max);
        assert!(
            after.len() > n && after.iter().all(|s| s.duties.is_some()),
            "{name}: the drive did not stay on under {torque} N·m"
        );
        assert!(
            peak <= lsb_a,
            "{name}: |i_dq| reached {peak} A under {torque} N·m without a torque constant (one ADC step: {lsb_a} A)"
        );
        println!(
            "{name}: no torque constant (iq_per_nm = 0): {torque} N·m → on, |i_dq| ≤ {peak:.3e} A \
             (one ADC step {lsb_a:.3} A) over {} periods",
            after.len()
        );
        return Ok((None, rig));
    };
    // verify's step height, as a torque setpoint; the reference the image gets is the
    // frame's quantised torque times K_t⁻¹.
    let a = step_amplitude(&setup);
    let frame = rig.setpoint(a / iq_per_nm);
    let raw = i16::from_le_bytes([frame.data[0], frame.data[1]]);
    let target = mtpa_iq(&design, f64::from(raw) * board.torque_resolution_nm, iq_per_nm);
    let at = step_torque(&mut rig, f64::from(raw) * board.torque_resolution_nm, n as f64 + 10.0)?;
    let drive = rig.analog_as::<Drive>().unwrap();
    let s = &drive.samples;
    // The image samples at t_n, its compare values act from the update at t_{n+1}
    // (thesis A §4.6, as verify's bench): the step's first sample is the one before the
    // first update whose duties moved after the frame.
    let before = s.iter().rposition(|x| x.t < at).expect("samples before the step");
    let moved = (before + 1..s.len())
        .find(|&k| s[k].duties != s[before].duties)
        .ok_or_else(|| format!("the duties never moved after the frame at {at} s"))?;
    assert!(
        s[moved].t - at <= SLACK_PERIODS * ts + ts,
        "{name}: the image took the setpoint only {} s after the frame",
        s[moved].t - at
    );
    let first = moved - 1;
    if s.len() <= first + n || !s[first..=first + n].iter().all(|x| x.duties.is_some()) {
        return Err(format!(
            "stays on: the drive switched off during the step (fault record: {})",
            rig.fault_cause().unwrap_or_else(|| "none".into())
        ));
    }
    let window = &s[first..=first + n];
    let y: Vec<f64> = window.iter().map(|x| x.i[1]).collect();
    let checks = current_step_checks(&design, 1, &y, target);
    let verified = current_step(&setup);
    let checks = checks
        .iter()
        .map(|c| {
            let sim = verified.checks.iter().find(|v| v.quantity == c.quantity);
            let line = format!(
                "  {}: image {:.4} {}, verify {} , designed {}, {} → {}",
                c.quantity,
                c.measured,
                c.unit,
                sim.map_or("—".into(), |v| format!("{:.4}", v.measured)),
                c.designed.map_or("—".into(), |d| format!("{d:.4}")),
                c.criterion,
                if c.pass { "pass" } else { "FAIL" }
            );
            (c.quantity.clone(), c.pass, line)
        })
        .collect();
    Ok((
        Some(Outcome {
            target,
            checks,
            at,
            torque: f64::from(raw) * board.torque_resolution_nm,
        }),
        rig,
    ))
}

/// True i_q \[A\] of the drive at the first sample at or after `t` \[s\].
fn iq_at(rig: &mut Rig, t: f64) -> f64 {
    let drive = rig.analog_as::<Drive>().unwrap();
    drive.samples.iter().find(|x| x.t >= t).map_or(f64::NAN, |x| x.i[1])
}

/// Issue 26: a CAN bus-off under torque. After the step, the bus fails (the FDCAN goes
/// bus-off, no frame arrives); the image must go to zero torque at once — not after the
/// setpoint timeout — start the recovery and count it; frames after the recovery drive
/// again. Zero torque from the step's torque is the step mirrored: by the current loop's
/// linearity i_q(t_b + τ) ≈ target − y(τ), y the step's own measured response τ after its
/// frame; the return, frames again after the recovery, is the step again: i_q ≈ y(τ). τ
/// = the lesser of 90 % of the setpoint timeout (before it could act) and the step's
/// window (12/α). Tolerance: 5 % of the target plus 3 ADC steps (the step's final-error
/// criterion's scale, and the bus-off seen at the next main-loop pass as a frame is).
/// Returns the report line.
fn bus_off_under_torque(rig: &mut Rig, name: &str, step: Option<&Outcome>, window_s: f64, lsb_a: f64) -> String {
    let board = rig.design.board.as_ref().unwrap().board.clone();
    let t_b = rig.machine.soc().time_s();
    rig.machine.soc_mut().fdcan.bus_off();
    let tau = (0.9 * board.setpoint_timeout_s).min(window_s);
    // Silence at least until the recovery (128 × 11 bits after the image clears INIT, at
    // its next main-loop pass) is over, however short the step's window.
    let recovery = motor_emulator::periph::fdcan::RECOVERY_BITS / board.can_bit_rate + 3.0 * rig.pwm_period_s();
    // Two periods beyond, so that a drive sample at or after t_b + τ exists.
    rig.run(t_b + tau.max(recovery) + 2.0 * rig.pwm_period_s(), |_| None, |_| false)
        .unwrap_or_else(|e| panic!("{name}: bus-off: {e}"));
    let fdcan = &rig.machine.soc().fdcan;
    assert_eq!(
        fdcan.recoveries, 1,
        "{name}: the image did not start the bus-off recovery"
    );
    assert!(!fdcan.is_bus_off(), "{name}: still bus-off {tau} s later");
    assert_eq!(
        rig.bus_off_count(),
        Some(1),
        "{name}: bus-off not counted in the control state"
    );
    assert!(rig.machine.soc().tim1.moe(), "{name}: switched off at a bus-off");
    let tol = |target: f64| 0.05 * target.abs() + 3.0 * lsb_a;
    let Some(step) = step else {
        // No torque constant: i_q stays 0 whatever the torque; the count and the
        // recovery are what is checked.
        return format!("{name}: bus-off → recovered, counted 1");
    };
    let (target, at) = (step.target, step.at);
    let y_tau = iq_at(rig, at + tau);
    let down = iq_at(rig, t_b + tau);
    assert!(
        (down - (target - y_tau)).abs() <= tol(target),
        "{name}: {tau} s after the bus-off i_q = {down} A, the step mirrored {} A (± {} A): not zero torque at once",
        target - y_tau,
        tol(target)
    );
    let again = step_torque(rig, step.torque, tau / rig.pwm_period_s() + 1.0)
        .unwrap_or_else(|e| panic!("{name}: after the recovery: {e}"));
    let up = iq_at(rig, again + tau);
    // From the residual r at the frame instead of 0: y(τ) + r·(1 − y(τ)/target), within
    // |r| of the step's own y(τ).
    let residual = iq_at(rig, again);
    assert!(
        (up - y_tau).abs() <= tol(target) + residual.abs(),
        "{name}: {tau} s after the first frame past the recovery i_q = {up} A, the step {y_tau} A"
    );
    assert_eq!(rig.bus_off_count(), Some(1));
    format!(
        "{name}: bus-off under {target:.3} A → i_q {down:.3} A after {:.1} ms (step mirrored: {:.3} A), recovered, counted 1; frames again → {up:.3} A (step: {y_tau:.3} A)",
        tau * 1e3,
        target - y_tau
    )
}

#[test]
fn current_step_through_a_can_torque_setpoint_meets_verifys_criteria() {
    for (motor, board) in benches() {
        let bench = Bench::new(&motor, &board).unwrap();
        let name = bench.name();
        let (out, mut rig) = current_step_rig(bench).unwrap_or_else(|e| panic!("{name}: {e}"));
        let setup_window = {
            let spec = motor_emulator::wiring::spec(&motor).unwrap();
            current_step_samples(&Setup::new(&spec, &rig.design)) as f64 * rig.design.drive.sample_period_s
        };
        let b = rig.design.board.as_ref().unwrap().board.clone();
        let lsb_a = b.adc_reference_v / 4096.0 / b.current.gain_v_per_a.abs();
        println!(
            "{}",
            bus_off_under_torque(&mut rig, &name, out.as_ref(), setup_window, lsb_a)
        );
        let Some(out) = out else {
            continue;
        };
        println!("{name}: i_q step 0 → {:.3} A", out.target);
        for c in &out.checks {
            println!("{}", c.2);
        }
        assert!(
            out.failed().is_empty(),
            "{name}: {:?} failed on the emulated image",
            out.failed()
        );
    }
}
