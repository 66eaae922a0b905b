//! The closed loop on the real image, every motor on the default board: `motorgen
//! verify`'s simulated drive (blocked rotor, as in its `current_step`) behind the ADC
//! inputs, driven by the compare values the image programs; a q-axis current step
//! commanded as a CAN torque setpoint T = i_q/K_t (the design's `iq_per_nm`), judged by
//! `current_step`'s own criteria (`motor_verify::scenarios::current_step_checks`).
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
use motor_emulator::image::motors;
use motor_emulator::rig::Rig;
use motor_emulator::{Patches, wiring};
use motor_sim::plant::SpeedProfile;
use motor_verify::Setup;
use motor_verify::scenarios::{current_step, current_step_checks, current_step_samples, step_amplitude};

/// Zero-torque time after the first enabled period before the step \[s\]: the image's
/// angle observer starts at 0 and locks onto the resolver (its offset) meanwhile.
const SETTLE_S: f64 = 0.02;

/// Carrier periods from the frame to the first update with moved duties, beyond the
/// period the image's sample can fall in before its main loop has read the frame.
const SLACK_PERIODS: f64 = 2.0;

/// The rig with the closed-loop drive, booted and settled at zero torque, and the spec
/// (for `verify`'s `Setup`: the same machine model).
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

fn closed_loop(motor: &str) -> (Rig, codegen::spec::Spec) {
    let spec = wiring::spec(motor).unwrap_or_else(|e| panic!("{motor}: {e}"));
    let mut rig = Rig::with_analog(motor, Patches::default(), |d| {
        Ok(Box::new(Drive::new(
            &Setup::new(&spec, d),
            SpeedProfile::constant(0.0),
        )?))
    })
    .unwrap_or_else(|e| panic!("{motor}: {e}"));
    rig.boot(BOOT_LIMIT_S).unwrap_or_else(|e| panic!("{motor}: {e}"));
    let t = rig.machine.soc().time_s() + SETTLE_S;
    rig.run(t, |_| Some(0.0), |_| false)
        .unwrap_or_else(|e| panic!("{motor}: {e}; {}", rig.machine.summary()));
    (rig, spec)
}

/// Sends zero torque until the next setpoint frame, `torque_nm` from then on, until
/// `periods` carrier periods after that frame; returns the frame's time \[s\].
fn step_torque(rig: &mut Rig, motor: &str, torque_nm: f64, periods: f64) -> f64 {
    let now = rig.machine.soc().time_s();
    let frame = rig.setpoint_period_s();
    // Frames go out every setpoint period from reset (`Rig::run`).
    let at = (now / frame).ceil() * frame;
    let end = at + periods * rig.pwm_period_s();
    rig.run(end, |t| Some(if t >= at { torque_nm } else { 0.0 }), |_| false)
        .unwrap_or_else(|e| panic!("{motor}: {e}; {}", rig.machine.summary()));
    at
}

#[test]
fn current_step_through_a_can_torque_setpoint_meets_verifys_criteria() {
    for motor in motors() {
        let (mut rig, spec) = closed_loop(&motor);
        let design = rig.design.clone();
        let setup = Setup::new(&spec, &design);
        let ts = design.drive.sample_period_s;
        assert!(
            (rig.pwm_period_s() / ts - 1.0).abs() < 1e-9,
            "{motor}: one sample per carrier period assumed"
        );
        let n = current_step_samples(&setup);
        let board = design.board.as_ref().unwrap().board.clone();
        let lsb_a = board.adc_reference_v / 4096.0 / board.current_gain_v_per_a;
        let Some(iq_per_nm) = design.current_loop.feedforward.iq_per_nm.filter(|k| *k > 0.0) else {
            // No torque constant: every torque is i_q = 0.
            let torque = board.torque_resolution_nm * 1000.0;
            let at = step_torque(&mut rig, &motor, torque, n as f64 + 10.0);
            let drive = rig.analog_as::<Drive>().unwrap();
            let after: Vec<Sample> = drive.samples.iter().filter(|s| s.t >= at).copied().collect();
            let peak = after.iter().map(|s| s.i[0].abs().max(s.i[1].abs())).fold(0.0, f64::max);
            assert!(
                after.len() > n && after.iter().all(|s| s.duties.is_some()),
                "{motor}: the drive did not stay on under {torque} N·m"
            );
            assert!(
                peak <= lsb_a,
                "{motor}: |i_dq| reached {peak} A under {torque} N·m without a torque constant (one ADC step: {lsb_a} A)"
            );
            println!(
                "{motor}: no torque constant (iq_per_nm = 0): {torque} N·m → on, |i_dq| ≤ {peak:.3e} A \
                 (one ADC step {lsb_a:.3} A) over {} periods",
                after.len()
            );
            continue;
        };
        // verify's step height, as a torque setpoint; the reference the image gets is the
        // frame's quantised torque times K_t⁻¹.
        let a = step_amplitude(&setup);
        let frame = rig.setpoint(a / iq_per_nm);
        let raw = i16::from_le_bytes([frame.data[0], frame.data[1]]);
        let target = mtpa_iq(&design, f64::from(raw) * board.torque_resolution_nm, iq_per_nm);
        let at = step_torque(
            &mut rig,
            &motor,
            f64::from(raw) * board.torque_resolution_nm,
            n as f64 + 10.0,
        );

        let drive = rig.analog_as::<Drive>().unwrap();
        let s = &drive.samples;
        // The image samples at t_n, its compare values act from the update at t_{n+1}
        // (thesis A §4.6, as verify's bench): the step's first sample is the one before
        // the first update whose duties moved after the frame.
        let before = s.iter().rposition(|x| x.t < at).expect("samples before the step");
        let moved = (before + 1..s.len())
            .find(|&k| s[k].duties != s[before].duties)
            .unwrap_or_else(|| panic!("{motor}: the duties never moved after the frame"));
        assert!(
            s[moved].t - at <= SLACK_PERIODS * ts + ts,
            "{motor}: the image took the setpoint only {} s after the frame",
            s[moved].t - at
        );
        let first = moved - 1;
        assert!(s.len() > first + n, "{motor}: record too short");
        let window = &s[first..=first + n];
        assert!(
            window.iter().all(|x| x.duties.is_some()),
            "{motor}: the drive switched off"
        );
        let y: Vec<f64> = window.iter().map(|x| x.i[1]).collect();
        let checks = current_step_checks(&design, 1, &y, target);
        let verified = current_step(&setup);
        let mut failed = Vec::new();
        println!(
            "{motor}: i_q step 0 → {target:.3} A as {raw} × {} N·m",
            board.torque_resolution_nm
        );
        for c in &checks {
            let sim = verified.checks.iter().find(|v| v.quantity == c.quantity);
            println!(
                "  {}: image {:.4} {}, verify {} , designed {}, {} → {}",
                c.quantity,
                c.measured,
                c.unit,
                sim.map_or("—".into(), |v| format!("{:.4}", v.measured)),
                c.designed.map_or("—".into(), |d| format!("{d:.4}")),
                c.criterion,
                if c.pass { "pass" } else { "FAIL" }
            );
            if !c.pass {
                failed.push(c.quantity.clone());
            }
        }
        assert!(failed.is_empty(), "{motor}: {failed:?} failed on the emulated image");
    }
}
