//! The duty at its limit (issue 26 item 3): a torque step at the top speed, where the
//! back EMF leaves the current loop too little voltage, so the PI output reaches its
//! voltage circle (the usable fraction of U_dc/√3, `codegen::design::duty_limit`) and
//! the modulator's largest duty its limit `board::MAX_DUTY`. On the board with low-side
//! shunts the emulator's strict rule "ADC sampling inside a switching edge" holds every
//! phase-current conversion to its leg's low-side pulse, after the settling time; the
//! currents the image regulates to, sampled that way, must then give the torque and
//! currents `verify`'s bench gives with the same command and speed (the criteria and
//! tolerances of the at-speed scenario, [`crate::at_speed`]), compared over the second
//! half of the step.
//!
//! The run: boot, 20 ms at zero torque, a ramp at zero torque to the at-speed scenario's
//! top speed, [`HOLD_S`] there, then the MTPA torque on the board's current circle for
//! [`AFTER_S`]. The ramp is `verify`'s own field-weakening ramp
//! ([`motor_verify::field_weakening::Ramp`]: ω rises as (1 − cos πτ)/2, so the
//! acceleration ends smoothly), its peak acceleration the at-speed scenario's rule, its
//! values at every setpoint period joined by straight lines on both sides. Until stop 42
//! the ramp was linear: its acceleration stopped at once at the top, and the observer's
//! type-2 lag, released in one step, turned the frame against the back EMF — on
//! fischer-ti085 (9.8° electrical of lag at its drive's 2 000 rpm/s) the drive tripped
//! 8.3 ms after the ramp's end (fault 4), and on mit-mini-cheetah-actuator the step then
//! peaked at duty 0.98976, short of the limit.
//!
//! Pairs ([`BENCHES`]): every board in `boards/`, and on each the motors whose run fits
//! in CI and shows what it is for: the NUCLEO + X-NUCLEO-IHM08M1 (low-side shunts,
//! d_max < 1 from the sampling window) with maxon-ec45-flat-70w; the reference board
//! (in-line Hall sensors: d_max = 1 − p/ARR, the dead time's shortest pulse,
//! `codegen::design::duty_limit`) with maxon-ec45-flat-70w, mit-mini-cheetah-actuator and
//! fischer-ti085 (15.75 s simulated, 20 000 rpm); the 400 A variant of the reference
//! board (the same hardware with another sensing gain) with emrax-228-hv and
//! chalmers-hev50 (15.4 s of ramp at 10 kHz). The defect: the compare values one timer
//! tick beyond `MAX_COMPARE` (`Patches::compare_beyond`) and the rule fires.
//!
//! Until stop 42 the in-line boards' limit was d_max = 1, and at 20 000 rpm the legs
//! that came within p of a rail lost up to half a dead time of volt-seconds in the
//! emulated bridge (which swallows such pulses, as the hardware does) but not in
//! `verify`'s ideal inverter: fischer-ti085's step parted from verify's by 2.97 of the
//! torque tolerance and 8.66 A, amk-dd5-ipm's by 1.58 and 5.97 A.
//!
//! **Alignment (stop 43).** The image runs the step from the first sample after its main
//! loop took the frame off the bus (`Fdcan::last_ack_s`; the loop polls once per period,
//! after the control interrupt), and `verify`'s bench steps at that sample; until stop
//! 43 it stepped at the first sample after the frame's arrival, a period early whenever
//! the frame came after that period's poll. And the ramp starts on one of the image's
//! samples plus a fixed share of a period (`carrier_phase`), so where the rotor stands
//! against the carrier no longer depends on how long the boot took: a boot 12 µs longer
//! (stop 43's sixteenth fault-record word) had moved fischer-ti085's comparison from
//! 0.92 to 1.42 of the torque tolerance.
//!
//! **fischer-ti085 depends on that phase** (20 000 rpm, 15 periods per electrical turn,
//! 24° a period): at the carrier phases 0, ¼, ½ and ¾ of a period its torque is 1.68,
//! 0.73, 1.11 and 1.19 of the tolerance off verify's, its currents 5.00, 2.24, 3.27 and
//! 3.45 A (tolerance 3.61 A); `verify`'s own step does not change with the phase
//! (i_q 38.2 A 15 ms into the step at each), and the five pairs of
//! [`torque_step_at_top_speed_reaches_the_duty_limit`] stay within 0.50 of their
//! tolerances at all four. The cause, found by bisection: with the update at the
//! underflow, a leg's high pulse spans the update (CNT < CCR on both sides of CNT = 0),
//! and for a compare value below the dead time (85 ticks; the limit lets it fall to
//! p = 43) TIM1's delayed rising edge crosses into the next period. That period then gets
//! less volt-seconds and the one before more than their compare values say — by up to
//! ±10 ticks at 20 000 rpm, where a bottom leg goes 45 → 115 → 538 ticks in three
//! periods; `verify`'s ideal inverter gives each period exactly its compare value. Fed
//! the compare values as ideal duties instead of the pulses (an experiment), the
//! emulated fischer-ti085 agrees with verify at 0.84, 0.32 and 0.44 of the tolerance
//! (phases 0, ¼, ½). Until stop 43 the emulated TIM1 moreover started the window's first
//! high interval at the update itself, ignoring the dead time of its edge before it
//! (`Tim1::across_the_window_start`). Two remedies, neither built: a duty limit that
//! keeps every compare value at least the dead time from the rails (p = t_d: d_max
//! 0.98 at 20 kHz instead of 0.98988), or `verify` modelling the bridge's dead time (the
//! open item on issue 26). So fischer-ti085's run asserts what holds at every phase —
//! the duty reaches its limit and never passes it, and no conversion samples inside an
//! edge — and reports its comparison with verify without asserting it. The ignored test
//! [`duty_limit_at_four_carrier_phases`] prints these figures.
//!
//! The one motor with a flux linkage not run: amk-dd5-ipm (400 A board, 7.9 s
//! simulated, 18 s of CPU) reaches the limit (49 periods) and never passes it, but its
//! currents swing at the voltage limit for about 40 ms after the step (i_q between 14
//! and 50 A, `verify`'s bench), so the comparison's second half of [`AFTER_S`] falls in
//! the swing: torque 1.04 of the tolerance off verify's, currents 4.19 A (tolerance
//! 4.85 A). A longer step compares after amk's swing but inside fischer-ti085's, which
//! lasts beyond 100 ms (i_q between 3 and 53 A, image and verify within 2 A until 75 ms,
//! then 7 A apart at 95 ms): the field weakening's recovery from a full-torque step at
//! the top speed is lightly damped on both, a design property `verify`'s own
//! field-weakening scenario (the torque held from low speed up the ramp) does not
//! exercise.

use std::f64::consts::PI;

use crate::at_speed::{CURRENT_TOLERANCE, TORQUE_FLOOR, TORQUE_TOLERANCE, mtpa_corner, top_speed};
use motor_emulator::Patches;
use motor_emulator::drive::{Drive, Sample};
use motor_emulator::rig::{Bench, benches};
use motor_emulator::wiring;
use motor_sim::plant::{Shaft, SpeedProfile};
use motor_verify::Setup;
use motor_verify::field_weakening::{Ramp, run as verify_run, torque as machine_torque};

/// Zero torque at the top speed before the step \[s\].
const HOLD_S: f64 = 0.01;
/// The step's length \[s\]; the comparison takes its second half.
const AFTER_S: f64 = 0.03;

/// What a run measured.
struct Outcome {
    /// Largest leg duty after the step (the bridge's volt-second average).
    peak_duty: f64,
    /// Periods with a duty within one compare tick of the limit.
    at_limit: usize,
    /// Worst |ΔT| over its tolerance, |Δi| and its tolerance, in the compared half.
    torque_ratio: f64,
    worst_i: f64,
    i_tol: f64,
    /// The design's limit and the auto-reload.
    max_duty: f64,
    arr: u16,
    /// CPU seconds of the emulated run.
    cpu_s: f64,
}

/// The scenario's (board, motor) pairs (module documentation): every board in `boards/`.
const BENCHES: [(&str, &str); 6] = [
    ("nucleo-g474re-ihm08m1", "maxon-ec45-flat-70w"),
    ("motorgen-reference", "maxon-ec45-flat-70w"),
    ("motorgen-reference", "mit-mini-cheetah-actuator"),
    ("motorgen-reference", "fischer-ti085"),
    ("motorgen-reference-400a", "emrax-228-hv"),
    ("motorgen-reference-400a", "chalmers-hev50"),
];

/// Panics unless `rig::benches` runs `motor` on `board`.
fn check_fits(motor: &str, board: &str) {
    assert!(
        benches().iter().any(|(m, b)| m == motor && b == board),
        "{motor} does not fit {board}"
    );
}

/// The run of the module documentation on `motor` × `board` with `patches`; `Err` with
/// what stopped it (a strict-mode rule) or switched the drive off.
fn step_at_top_speed(motor: &str, board: &str, patches: Patches, carrier_phase: f64) -> Result<Outcome, String> {
    let (mut rig, spec) = crate::closed_loop::closed_loop(Bench::new(motor, board)?.patched(patches))?;
    let design = rig.design.clone();
    let setup = Setup::new(&spec, &design);
    let out = design.board.as_ref().expect("a design on a board");
    let b = &out.board;
    let m = &design.motor;
    let np = f64::from(m.pole_pairs);
    let psi = m.flux_linkage_wb.unwrap_or(0.0);
    let dl = m.q_inductance_h - m.d_inductance_h;
    if design.field_weakening.is_none() {
        return Err(format!("{motor}: no ψ_M, no torque stage to step"));
    }
    // The at-speed scenario's torque (MTPA on the board's circle) and top speed.
    let i_lim = m.peak_current_a.min(0.9 * b.over_current_a);
    let (id_c, iq_c) = mtpa_corner(psi, dl, i_lim);
    let res = b.torque_resolution_nm;
    let torque = (1.5 * np * iq_c * (psi - dl * id_c) / res).round() * res;
    let top = top_speed(&design, i_lim);
    let top_e = top.top_e;
    // At zero torque the ramp only has to keep the observer locked: as fast as its
    // allowance, not the drive's acceleration (the field-weakening loop is not judged
    // here), at least the at-speed scenario's.
    let acc_m = top.ramp_acceleration().max(top.follows_m);

    let period = rig.setpoint_period_s();
    let now = rig.machine.soc().time_s();
    // The ramp starts at one of the image's samples (the first after the next setpoint
    // frame's time, plus `carrier_phase` of a period): where the rotor stands against the
    // carrier then follows from the scenario alone, not from how long the boot took (at
    // 20 000 rpm fischer-ti085 turns 24° electrical a period, and its result depends on
    // that phase: module documentation).
    let ts = design.drive.sample_period_s;
    let sample_lead = (design.current_loop.loop_delay_s / ts - 0.5) * ts;
    let last_sample = rig
        .analog_as::<Drive>()
        .unwrap()
        .samples
        .last()
        .expect("a bridge change")
        .t
        - sample_lead;
    let grid = (now / period).ceil() * period;
    let at = last_sample + ((grid - last_sample) / ts).ceil() * ts + carrier_phase * ts;
    // verify's own field-weakening ramp (a cosine: the acceleration ends smoothly, so the
    // observer's lag is not released at once), its knots every setpoint period joined
    // by straight lines, the same profile on both sides.
    let ramp = Ramp::new(0.0, top_e / np, at, acc_m);
    let knot = move |t: f64| {
        let k = ((t - at) / period).floor();
        let (t0, t1) = (at + k * period, at + (k + 1.0) * period);
        let (w0, w1) = (ramp.at(t0), ramp.at(t1));
        (t0, w0, w1)
    };
    let speed = move |t: f64| {
        let (t0, w0, w1) = knot(t);
        w0 + (w1 - w0) * (t - t0) / period
    };
    let t_step = ((at + ramp.duration + HOLD_S) / period).ceil() * period;
    let end = t_step + AFTER_S;
    let command = move |tf: f64| if tf + 1e-9 >= t_step { torque } else { 0.0 };
    let started = std::time::Instant::now();
    let mut t = at;
    // When the image took the step's frame off the bus (RXF0A written in its main loop,
    // which runs once per period after the control interrupt).
    let mut step_taken: Option<f64> = None;
    while t < end - 1e-12 {
        let (t0, w0, w1) = knot(t + 1e-9);
        rig.analog_as::<Drive>().unwrap().plant.shaft = Shaft::Imposed(SpeedProfile::segment(t0, period, w0, w1));
        t = (t0 + period).min(end);
        rig.run(t, |t| Some(command(t)), |_| false)
            .map_err(|e| format!("{e}; {}", rig.machine.summary()))?;
        // The frames go out every setpoint period, one per chunk: the first
        // acknowledge at or after the step's frame is the step's.
        if step_taken.is_none() {
            step_taken = rig.machine.soc().fdcan.last_ack_s.filter(|&a| a >= t_step);
        }
    }
    let step_taken = step_taken.ok_or("the image did not take the step's frame within a setpoint period")?;
    let cpu_s = started.elapsed().as_secs_f64();
    let s: Vec<Sample> = rig.analog_as::<Drive>().unwrap().samples.clone();
    let k0 = s.iter().rposition(|x| x.t < at).expect("samples before the ramp") + 1;
    if let Some(off) = s[k0..].iter().position(|x| x.duties.is_none()) {
        return Err(format!(
            "the drive switched off {:.4} s after the ramp's start (fault record: {})",
            s[k0 + off].t - at,
            rig.fault_cause().unwrap_or_else(|| "none".into())
        ));
    }
    // verify's t = 0 is its first sample, whose duties its plant loads (D − 1/2)·T_s
    // later (`Plant::step_with`, D the design's loop delay); the image's update at t0
    // loads the duties of its sample that long before. So verify's time runs from that
    // sample, t_s = t0 − (D − 1/2)·T_s: both sample the rotor at the same angles of the
    // carrier (at 20 000 rpm fischer-ti085 turns 24° electrical a period, the carrier
    // repeating every 15 periods), and verify's period k + 1 samples the currents
    // (3/2 − D)·T_s after the image's bridge change k.
    let t0 = s[k0].t;
    let t_s = t0 - sample_lead;
    let n = s.len() - k0 + 1;
    // The step in verify at the image's sample that first ran it: the first sample after
    // the image took the frame off the bus (module documentation, "Alignment").
    let taken_at = s[k0..]
        .iter()
        .map(|x| x.t - sample_lead)
        .find(|&sigma| sigma > step_taken)
        .ok_or("no sample after the image took the step")?;
    let command_at = |tv: f64| if t_s + tv >= taken_at - 0.5 * ts { torque } else { 0.0 };
    let reference = verify_run(&setup, &command_at, &|t| speed(t_s + t), n, setup.signal_gain());
    let reference = &reference[1..];

    let arr = design.drive.pwm_period;
    let max_duty = out.duty_limit.max_duty;
    let tick = 1.0 / f64::from(arr);
    let after: Vec<&Sample> = s.iter().filter(|x| x.t >= t_step).collect();
    let leg_max = |x: &Sample| x.duties.map_or(0.0, |d| d[0].max(d[1]).max(d[2]));
    let peak_duty = after.iter().map(|x| leg_max(x)).fold(0.0, f64::max);
    let at_limit = after.iter().filter(|x| leg_max(x) >= max_duty - tick).count();

    let lsb = b.adc_reference_v / 4096.0 / b.current.gain_v_per_a.abs();
    let quantisation = 3.0 * lsb * 1.5 * np * psi.max(1e-9);
    let i_tol = CURRENT_TOLERANCE * i_lim + 3.0 * lsb;
    let (mut torque_ratio, mut worst_i) = (0.0f64, 0.0f64);
    for (k, r) in reference.iter().enumerate() {
        let img = &s[k0 + k];
        if img.t < t_step + 0.5 * AFTER_S {
            continue;
        }
        let dt = (machine_torque(&setup.motor, img.i[0], img.i[1]) - r.torque_nm).abs();
        let tol = TORQUE_TOLERANCE * torque + TORQUE_FLOOR * torque + quantisation;
        torque_ratio = torque_ratio.max(dt / tol);
        worst_i = worst_i.max((img.i[0] - r.sample.i[0]).hypot(img.i[1] - r.sample.i[1]));
    }
    println!(
        "{motor} on {board}: {torque:.3} N·m at {:.0} rpm (ramp {:.0} rpm/s): peak duty {peak_duty:.5} (limit {max_duty:.5}, compare {} of {arr}), {at_limit} periods within a tick of it; |ΔT| ≤ {torque_ratio:.2} of its tolerance, |Δi| ≤ {worst_i:.3} A (tolerance {i_tol:.3}); {:.3} s simulated in {cpu_s:.1} s",
        top_e / np * 30.0 / PI,
        acc_m * 30.0 / PI,
        out.duty_limit.max_compare,
        end - at
    );
    Ok(Outcome {
        peak_duty,
        at_limit,
        torque_ratio,
        worst_i,
        i_tol,
        max_duty,
        arr,
        cpu_s,
    })
}

/// Every board in `boards/` has a pair in [`BENCHES`].
#[test]
fn every_board_has_a_duty_limit_scenario() {
    for board in motor_test_support::board_stems() {
        assert!(
            BENCHES.iter().any(|(b, _)| *b == board),
            "{board} has no duty-limit scenario"
        );
    }
}

/// The pairs of [`BENCHES`] whose motor is (`long`) or is not fischer-ti085, the one
/// long run (15.75 s simulated): two tests, so the two test threads share the work.
fn pairs(long: bool) -> impl Iterator<Item = (&'static str, &'static str)> {
    BENCHES
        .into_iter()
        .filter(move |(_, m)| (*m == "fischer-ti085") == long)
}

/// [`step_at_top_speed`] on `pairs` at the carrier phase 0: the duty reaches its limit
/// and never passes it, no conversion samples inside a switching edge (the strict rule
/// would have stopped the run), and — with `compare` — the image's torque and currents
/// are verify's.
fn reaches_the_duty_limit(pairs: impl Iterator<Item = (&'static str, &'static str)>, compare: bool) {
    for (board, motor) in pairs {
        check_fits(motor, board);
        let o = step_at_top_speed(motor, board, Patches::default(), 0.0)
            .unwrap_or_else(|e| panic!("{motor} on {board}: {e}"));
        let tick = 1.0 / f64::from(o.arr);
        assert!(
            o.peak_duty >= o.max_duty - tick && o.at_limit > 0,
            "{motor} on {board}: the duty reached only {} (limit {})",
            o.peak_duty,
            o.max_duty
        );
        assert!(
            o.peak_duty <= o.max_duty + 1e-9,
            "{motor} on {board}: duty {} beyond the limit {}",
            o.peak_duty,
            o.max_duty
        );
        if compare {
            assert!(
                o.torque_ratio <= 1.0,
                "{motor} on {board}: torque off verify's by {} of the tolerance",
                o.torque_ratio
            );
            assert!(
                o.worst_i <= o.i_tol,
                "{motor} on {board}: currents off verify's by {} A (tolerance {})",
                o.worst_i,
                o.i_tol
            );
        } else {
            println!(
                "{motor} on {board}: compared with verify, not asserted (module documentation): torque {:.2} of the tolerance, currents {:.3} A of {:.3}",
                o.torque_ratio, o.worst_i, o.i_tol
            );
        }
        println!("{motor} on {board}: {:.1} s CPU", o.cpu_s);
    }
}

/// [`reaches_the_duty_limit`] on every pair but fischer-ti085, compared with verify.
#[test]
fn torque_step_at_top_speed_reaches_the_duty_limit() {
    reaches_the_duty_limit(pairs(false), true);
}

/// [`reaches_the_duty_limit`] on fischer-ti085 (reference board, 20 000 rpm): the duty
/// properties only; its comparison with verify depends on the carrier phase (module
/// documentation) and is reported.
#[test]
fn torque_step_at_20000_rpm_reaches_the_duty_limit_on_fischer() {
    reaches_the_duty_limit(pairs(true), false);
}

/// The defect: compare values one tick beyond the NUCLEO's `MAX_COMPARE` (a modulator
/// without the limit) — the conversion that samples the phase at the limit now ends
/// after its low side switched off, and the rule stops the run.
#[test]
fn a_duty_one_tick_beyond_the_limit_samples_inside_an_edge() {
    let (board, motor) = BENCHES[0];
    check_fits(motor, board);
    let (file, text) = wiring::read(&format!("boards/{board}.toml")).unwrap();
    let limit = wiring::design(motor, &file, &text)
        .unwrap_or_else(|e| panic!("{motor} on {board}: {e}"))
        .board
        .expect("a design on a board")
        .duty_limit
        .max_compare;
    let patches = Patches {
        compare_beyond: Some(limit),
        ..Patches::default()
    };
    match step_at_top_speed(motor, board, patches, 0.0) {
        Err(e) => {
            println!("{motor} on {board}, compare {} (one beyond the limit): {e}", limit + 1);
            assert!(e.contains("ADC sampling inside a switching edge"), "{e}");
        }
        Ok(o) => panic!(
            "{motor} on {board}: compare values one tick beyond the limit passed (peak duty {})",
            o.peak_duty
        ),
    }
}

/// The figures of the module documentation's carrier-phase paragraph, reproducible: every
/// pair of [`BENCHES`] at the carrier phases 0, ¼, ½ and ¾ of a period, printed, nothing
/// asserted (the comparison is asserted at phase 0 by the tests above). Ignored in CI
/// (about 3 minutes of CPU, fischer-ti085's four runs the most):
/// `cargo test -p motor-emulator --test it -- --ignored duty_limit_at_four_carrier_phases --nocapture`.
#[test]
#[ignore = "a measurement, printed: about 3 minutes of CPU"]
fn duty_limit_at_four_carrier_phases() {
    for (board, motor) in BENCHES {
        check_fits(motor, board);
        for phase in [0.0, 0.25, 0.5, 0.75] {
            match step_at_top_speed(motor, board, Patches::default(), phase) {
                Ok(o) => println!(
                    "{motor} on {board}, carrier phase {phase}: torque {:.2} of the tolerance, currents {:.3} A of {:.3}, {} periods within a tick of the limit, peak duty {:.5}",
                    o.torque_ratio, o.worst_i, o.i_tol, o.at_limit, o.peak_duty
                ),
                Err(e) => println!("{motor} on {board}, carrier phase {phase}: {e}"),
            }
        }
    }
}
