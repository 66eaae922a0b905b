//! The image at speed, every motor on the first board in `boards/` it fits (the default
//! board where it fits: the run is long, so one board per motor): `motorgen verify`'s simulated
//! drive behind the ADC inputs with the rotor on an imposed speed profile (the plant's
//! back EMF and the resolver follow it), a torque commanded over CAN, and the image's own
//! torque stage (`motor_control::torque`: MTPA, field weakening at the measured DC link,
//! MTPV, current circle) inside its control interrupt. The same profile and torque run
//! through `verify`'s bench ([`motor_verify::field_weakening::run`], the same control step
//! with the same constants); the true torque and currents of the two runs are compared
//! period by period.
//!
//! The profile: after the boot and 20 ms at zero torque, the torque frame; the rotor held
//! at standstill for [`STANDSTILL_S`], then a linear ramp to the top speed, where the run
//! ends. The ramp's acceleration is the drive's largest (`drive.max_acceleration` and its
//! application default, the one the observer and field-weakening designs are judged at)
//! or, to keep the run short, the one that reaches the top in [`RAMP_S`] — but never more
//! than [`MAX_SPEEDUP`] times the drive's, nor more than lets the emulated board's angle
//! observer lag by [`PROFILE_LAG_DEG`] electrical
//! (thesis A (4.12)–(4.15): K_i·sin Δ = n_r·ω̇_m for the trig-identity error, whose gains
//! the design divides by the board's resolver signal amplitude, K_i·Δ for atan2). Where
//! the drive's own acceleration is beyond that (fischer-ti085: ω_n = 70 rad/s, K_i·sin(3°/4)
//! = 64.1 rad/s² against its drive's 209.4) the drive's acceleration it is; amk-dd5-ipm's
//! observer allows 418.9 rad/s² (twice its drive's), chalmers-hev50's 128.3 (its drive's
//! 125.7).
//!
//! No hold at the top: a linear ramp's acceleration stops at once there, and the type-2
//! observer's lag, released in one step, swings past; on amk-dd5-ipm at 20 000 rpm both
//! the image and verify then let i_d run 20 A past its reference within a few
//! milliseconds, beyond this board's trip (verify's own scenario uses a cosine ramp, whose
//! acceleration ends smoothly).
//!
//! The board decides two limits: its over-current trip caps the current, so the torque
//! commanded is the MTPA torque (3.10) on the circle |i| = min(I_max, 90 % of the trip),
//! and the top speed is the motor's `max_speed` unless field weakening at zero torque
//! would need an |i_d| beyond that circle (i_d = −(ψ_M − V'_max/ω)/L_d). On the boards
//! the motors run on here (the traction motors on `motorgen-reference-400a`, which
//! `motorgen check` puts them on: the reference board's 100 A cannot carry them) every
//! motor reaches its `max_speed`.
//!
//! Cost: the emulated image runs at about 1–2 s of CPU per simulated second; the longest
//! profiles are fischer-ti085's 10.05 s and chalmers-hev50's 9.85 s of simulated time,
//! amk-dd5-ipm's 5.05 s (stop 41).

use std::f64::consts::PI;

use crate::BOOT_LIMIT_S;
use codegen::spec::ObserverError;
use motor_emulator::drive::{Drive, Sample};
use motor_emulator::image::motors;
use motor_emulator::periph::system::IRQ_ADC1_2;
use motor_emulator::rig::{Bench, Rig, benches};
use motor_emulator::wiring;
use motor_sim::plant::{Shaft, SpeedProfile};
use motor_verify::Setup;
use motor_verify::field_weakening::{max_torque_point, run as verify_run, torque as machine_torque};

/// Zero-torque time after the first enabled period \[s\] (the observer locks).
const SETTLE_S: f64 = 0.02;
/// Standstill under the torque before the ramp \[s\].
const STANDSTILL_S: f64 = 0.05;
/// The ramp's duration where the drive's and the observer's accelerations allow \[s\].
pub(crate) const RAMP_S: f64 = 0.5;
/// … and at most this many times the drive's largest acceleration (the field-weakening
/// loop is designed for the drive's acceleration).
pub(crate) const MAX_SPEEDUP: f64 = 3.0;
/// The control interrupt's budget on every motor \[instructions\]: issue 30 set 900 (of
/// 8 500 cycles at 20 kHz and 170 MHz); issue 26 added the start-up offset's per-phase
/// correction and the compare writes' UDIS window (the at-speed maximum went from at most
/// 900 to 901 on maxon-ec45-flat-70w), so 950: 22 % of the 4 250 cycles of a 40 kHz
/// period, the fastest carrier in `motors/`. Stop 42 bounded the in-line boards' duty by
/// the dead time (`codegen::design::duty_limit`: d_max = 0.97976 for maxon-ec45-flat-70w's
/// 40 kHz on the reference board, where it was 1; 0.96 since stop 44's p = t_d), so the
/// modulator's scaling to `MAX_DUTY` now runs where the voltage nears the circle: its
/// at-speed maximum went from 939 to 958. So 975: 23 % of the 4 250 cycles at 40 kHz.
pub const INTERRUPT_BUDGET: u64 = 975;

/// Tolerances of the comparison: torque within 2 % of the torque commanded at that period
/// plus 1 % of the full (standstill) torque (deep in field weakening little torque is left,
/// and 2 % of it is less than a current difference within the current tolerance makes),
/// currents within 4 % of the current circle, each plus 3 ADC steps of the board's current
/// sensing (its 12-bit quantisation against verify's 16-bit codes). The currents' tolerance
/// is the wider: deep in field weakening a small difference of the voltage limit (the
/// image measures the DC link in 12 bits) moves the operating point along the
/// constant-torque curve, i_d more than the torque (emrax-228-hv near 6 500 rpm: 3.1 A
/// apart, the torque within 1.0 N·m of 44.9).
pub(crate) const TORQUE_TOLERANCE: f64 = 0.02;
pub(crate) const TORQUE_FLOOR: f64 = 0.01;
pub(crate) const CURRENT_TOLERANCE: f64 = 0.04;
/// Where the motor's current circle is beyond the board's: the circle of the envelope
/// the frames follow in field weakening, as a share of the over-current trip, and the share
/// of that envelope's torque they command — margins for the field-weakening loop's lag
/// behind the ramp and the observer's (the controller's frame lags the rotor, so the stage
/// needs more current than on the true axes).
const ENVELOPE_CURRENT: f64 = 0.8;
const BOARD_ENVELOPE: f64 = 0.95;

/// The electrical lag of the emulated board's observer the ramp may cause at its peak
/// acceleration \[°\] where that is faster than the drive's (a third of the 10° of field
/// orientation the design allows).
pub(crate) const PROFILE_LAG_DEG: f64 = 3.0;

/// The MTPA point on the circle `i` \[A\] (3.10): (i_d, i_q).
pub(crate) fn mtpa_corner(psi: f64, dl: f64, i: f64) -> (f64, f64) {
    codegen::design::loss_minimisation::mtpa_corner(psi, dl, i)
}

/// The scenario's top speed and the fastest ramp its observer follows (module doc).
pub(crate) struct TopSpeed {
    /// Top electrical speed \[rad/s\]: the motor's, the board's at the current limit
    /// (V'/(ψ_M − L_d·i_lim), above which the voltage no longer carries that current),
    /// and 95 % of the over-speed trip, whichever is lowest.
    pub(crate) top_e: f64,
    /// The mechanical acceleration \[rad/s²\] at which the angle observer lags by
    /// [`PROFILE_LAG_DEG`] electrical: its type-2 loop's steady lag is the resolver
    /// acceleration over K_i (times the trig identity's amplitude, through its sine).
    pub(crate) follows_m: f64,
    /// The top mechanical speed \[rad/s\]: `top_e` over the pole pairs.
    pub(crate) top_m: f64,
    /// The drive's largest mechanical acceleration \[rad/s²\] (`drive.max_acceleration`).
    pub(crate) acc_drive: f64,
}

impl TopSpeed {
    /// The ramp's mechanical acceleration \[rad/s²\] under torque (module doc): the one
    /// that reaches the top in [`RAMP_S`], as far as the observer follows it and at most
    /// [`MAX_SPEEDUP`] times the drive's, and never less than the drive's.
    pub(crate) fn ramp_acceleration(&self) -> f64 {
        self.acc_drive.max(
            (self.top_m / RAMP_S)
                .min(self.follows_m)
                .min(MAX_SPEEDUP * self.acc_drive),
        )
    }
}

/// [`TopSpeed`] of `design` (on a board) at the current limit `i_lim` \[A\].
pub(crate) fn top_speed(design: &codegen::design::Design, i_lim: f64) -> TopSpeed {
    let m = &design.motor;
    let board = &design.board.as_ref().expect("a design on a board").board;
    let np = f64::from(m.pole_pairs);
    let psi = m.flux_linkage_wb.unwrap_or(0.0);
    let v_prime = design.field_weakening.as_ref().map_or(0.0, |f| f.voltage_limit_v);
    let w_board = if psi > m.d_inductance_h * i_lim {
        v_prime / (psi - m.d_inductance_h * i_lim)
    } else {
        f64::INFINITY
    };
    let top_e = m
        .max_electrical_speed_rad_s
        .min(w_board)
        .min(0.95 * board.over_speed_rad_s * np);
    let obs = &design.angle_observer;
    let nr = f64::from(obs.resolver_pole_pairs);
    let allowed_r = PROFILE_LAG_DEG.to_radians() * nr / np;
    let follows_r = match obs.error {
        // The design divides the trig-identity gains by the signal's fraction of full
        // scale, which the emulated front end gives (`boot.rs` checks it): the loop gain
        // is K_i.
        ObserverError::TrigIdentity => obs.gains.ki * allowed_r.sin(),
        ObserverError::Atan2 => obs.gains.ki * allowed_r,
    };
    TopSpeed {
        top_e,
        follows_m: follows_r / nr,
        top_m: top_e / np,
        acc_drive: design.drive.max_acceleration_rad_s2,
    }
}

#[test]
fn torque_along_a_speed_ramp_matches_verify() {
    let pairs = benches();
    for motor in motors() {
        let board = pairs
            .iter()
            .filter(|(m, _)| *m == motor)
            .map(|(_, b)| b.clone())
            .min_by_key(|b| b != codegen::board::DEFAULT_BOARD)
            .unwrap_or_else(|| panic!("{motor} fits no board"));
        let spec = wiring::spec(&motor).unwrap_or_else(|e| panic!("{motor}: {e}"));
        let bench = Bench::new(&motor, &board).unwrap_or_else(|e| panic!("{motor} on {board}: {e}"));
        let mut rig = Rig::with_analog(bench, |d, hw| {
            Ok(Box::new(Drive::new(
                &Setup::new(&spec, d),
                SpeedProfile::constant(0.0),
                hw,
            )))
        })
        .unwrap_or_else(|e| panic!("{motor} on {board}: {e}"));
        rig.boot(BOOT_LIMIT_S).unwrap_or_else(|e| panic!("{motor}: {e}"));
        let settled = rig.machine.soc().time_s() + SETTLE_S;
        rig.run(settled, |_| Some(0.0), |_| false)
            .unwrap_or_else(|e| panic!("{motor}: {e}"));
        let design = rig.design.clone();
        let setup = Setup::new(&spec, &design);
        let board = design.board.as_ref().unwrap().board.clone();
        let m = &design.motor;
        let np = f64::from(m.pole_pairs);
        let ts = design.drive.sample_period_s;
        let psi = m.flux_linkage_wb.unwrap_or(0.0);

        // The current the board can carry, the torque at its MTPA point, the top speed.
        let i_lim = m.peak_current_a.min(0.9 * board.over_current_a);
        let dl = m.q_inductance_h - m.d_inductance_h;
        let (id_c, iq_c) = mtpa_corner(psi, dl, i_lim);
        // Without ψ_M the stage is off and the image limits every setpoint to 0 N·m.
        let torque_want = if design.field_weakening.is_some() {
            1.5 * np * iq_c * (psi - dl * id_c)
        } else {
            0.0
        };
        // What a frame carries for a torque: an i16 in the board's resolution (`[can]`).
        let res = board.torque_resolution_nm;
        let quantised = move |nm: f64| (nm / res).round().clamp(-32768.0, 32767.0) * res;
        let torque = quantised(torque_want);
        let v_prime = design.field_weakening.as_ref().map_or(0.0, |f| f.voltage_limit_v);
        let top = top_speed(&design, i_lim);
        let (top_e, acc_drive) = (top.top_e, top.acc_drive);
        // Without ψ_M the stage gives no current at any speed: the ramp takes RAMP_S.
        let acc_m = if torque > 0.0 {
            top.ramp_acceleration()
        } else {
            top.top_m / RAMP_S
        };

        // The frame, then standstill, the ramp and the hold (times from the frame).
        let now = rig.machine.soc().time_s();
        let period = rig.setpoint_period_s();
        let at = (now / period).ceil() * period;
        let t_ramp = at + STANDSTILL_S;
        let imposed = SpeedProfile {
            from: 0.0,
            to: top_e / np,
            start: t_ramp,
            acceleration: acc_m,
        };
        // The run ends as the ramp reaches the top (module doc: no hold there).
        let length = STANDSTILL_S + top_e / np / acc_m;
        let speed = move |t: f64| imposed.at(t);
        let profile_rpm = |t: f64| speed(t) * 30.0 / PI;
        // The torque each frame commands (frame time t_f): the MTPA torque on the board's
        // circle. The stage's own circle is the motor's I_max (the design's, from the
        // motor's peak current): where that is beyond i_lim (a motor on a board whose trip
        // is below its peak current), a full demand in
        // field weakening would drive |i| to it and trip the board, so there each frame
        // commands, once the ramp starts, at most BOARD_ENVELOPE of the most torque within
        // |i| ≤ ENVELOPE_CURRENT of the trip and |v| ≤ V'_max (R_s included, searched on
        // the machine model) at the speed the shaft reaches by the next frame.
        let limited = m.peak_current_a > i_lim && torque > 0.0;
        let i_env = ENVELOPE_CURRENT * board.over_current_a;
        let commands: Vec<f64> = (0..)
            .map(|k| at + f64::from(k) * period)
            .take_while(|&tf| tf <= at + length + period)
            .map(|tf| {
                if !limited || tf + period <= t_ramp {
                    torque
                } else {
                    let w_e = np * speed(tf + period);
                    let most = max_torque_point(&setup.motor, w_e, i_env, v_prime).0;
                    quantised(torque.min(BOARD_ENVELOPE * most))
                }
            })
            .collect();
        let command = |tf: f64| {
            let k = ((tf - at) / period).round();
            if k < 0.0 {
                0.0
            } else {
                commands[(k as usize).min(commands.len() - 1)]
            }
        };
        let before = rig.machine.handler_instructions(16 + IRQ_ADC1_2).len();
        let started = std::time::Instant::now();
        rig.analog_as::<Drive>().unwrap().plant.shaft = Shaft::Imposed(imposed);
        rig.run(at + length, |t| Some(command(t)), |_| false)
            .unwrap_or_else(|e| panic!("{motor}: {e}; {}", rig.machine.summary()));
        let cpu = started.elapsed().as_secs_f64();
        let counts = rig.machine.handler_instructions(16 + IRQ_ADC1_2)[before..].to_vec();
        let max_isr = counts.iter().copied().max().unwrap_or(0);

        let drive = rig.analog_as::<Drive>().unwrap();
        let s: Vec<Sample> = drive.samples.clone();
        let reached_rpm = drive.plant.omega_m() * 30.0 / PI;
        // The first sample of the torque: the one before the first update whose duties
        // moved after the frame (as the closed-loop test; the image samples at t_n and its
        // compare values act from t_{n+1}).
        let first = s.iter().rposition(|x| x.t < at).expect("samples before the frame");
        let k0 = if torque == 0.0 {
            // No torque constant (ψ_M unknown): the frame moves nothing; compare from it.
            first + 1
        } else {
            let moved = (first + 1..s.len())
                .find(|&k| s[k].duties != s[first].duties)
                .unwrap_or_else(|| panic!("{motor}: the duties never moved after the frame"));
            moved - 1
        };
        let t0 = s[k0].t;
        let n = s.len() - k0;
        // verify's bench: the same torque from its first period, the same profile shifted
        // to its time (its t = 0 is the image's t0).
        // verify's bench reads the resolver at the fraction of full scale the design
        // expects of the board (`Setup::signal_gain`), which the emulated front end gives
        // (`boot.rs` checks it).
        let verify_started = std::time::Instant::now();
        // The frames' torques in verify's time: the first frame acts from its t = 0.
        let command_at = |tv: f64| command(at + (tv / period + 1e-9).floor() * period);
        let reference = verify_run(&setup, &command_at, &|t| speed(t0 + t), n, setup.signal_gain());
        let verify_cpu = verify_started.elapsed().as_secs_f64();
        if let Some(off) = s[k0..].iter().position(|x| x.duties.is_none()) {
            let x = &s[k0 + off];
            let r = &reference[off - 1];
            let before = &s[k0 + off - 1];
            let peak = reference
                .iter()
                .map(|r| r.sample.i[0].hypot(r.sample.i[1]))
                .fold(0.0, f64::max);
            panic!(
                "{motor}: the drive switched off at {:.4} s after the torque (speed {:.0} rpm, {:.2} N·m commanded; true i_dq {:?} A, the period before {:?} A where verify had {:?} A for the references {:?}, verify's peak |i| {peak:.1} A): {}",
                x.t - t0,
                profile_rpm(x.t),
                command_at(x.t - t0),
                x.i,
                before.i,
                r.sample.i,
                r.reference,
                rig.machine.summary()
            );
        }
        let lsb = board.adc_reference_v / 4096.0 / board.current.gain_v_per_a.abs();
        let quantisation = 3.0 * lsb * 1.5 * np * psi.max(1e-9);
        let i_tol = CURRENT_TOLERANCE * i_lim + 3.0 * lsb;
        // The worst torque difference relative to its tolerance at that period (2 % of the
        // torque commanded then, plus the quantisation term), and where it was.
        let (mut worst_t, mut t_tol, mut worst_ratio, mut at_worst) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let (mut worst_i, mut peak_i) = (0.0f64, 0.0f64);
        for (k, r) in reference.iter().enumerate() {
            let img = &s[k0 + k];
            let t_img = machine_torque(&setup.motor, img.i[0], img.i[1]);
            let dt = (t_img - r.torque_nm).abs();
            let tol = TORQUE_TOLERANCE * command_at(img.t - t0).abs() + TORQUE_FLOOR * torque + quantisation;
            if dt / tol > worst_ratio {
                (worst_ratio, worst_t, t_tol, at_worst) = (dt / tol, dt, tol, img.t - t0);
            }
            worst_i = worst_i.max((img.i[0] - r.sample.i[0]).hypot(img.i[1] - r.sample.i[1]));
            peak_i = peak_i.max(img.i[0].hypot(img.i[1]));
        }
        let top_torque = command(at + length);
        // i_d = 0 control's torque at the same current, for the salient motors' record.
        let kt_i = 1.5 * np * psi * i_lim;
        println!(
            "{motor}: {torque:.2} N·m (i_d = 0 at |i| = {i_lim:.1} A: {kt_i:.2} N·m), standstill then 0 → {:.0} rpm at {:.0} rpm/s{}, {top_torque:.2} N·m commanded at the top: reached {reached_rpm:.0} rpm in {:.3} s simulated ({cpu:.1} s emulated, {verify_cpu:.1} s verify); \
             worst |ΔT| {worst_t:.4} N·m (at {:.1} ms, {:.0} rpm; tolerance there {t_tol:.4}), |Δi| ≤ {worst_i:.3} A (tolerance {i_tol:.3}), peak |i| {peak_i:.1} A; control interrupt {} / {max_isr} / {:.0} instructions (min / max / mean) over {} periods",
            top_e / np * 30.0 / PI,
            acc_m * 30.0 / PI,
            if acc_m > acc_drive {
                format!(
                    " (the drive's {:.0} rpm/s: {:.2} s)",
                    acc_drive * 30.0 / PI,
                    top_e / np / acc_drive
                )
            } else {
                String::new()
            },
            length,
            at_worst * 1e3,
            profile_rpm(t0 + at_worst),
            counts.iter().min().unwrap_or(&0),
            counts.iter().sum::<u64>() as f64 / counts.len().max(1) as f64,
            counts.len(),
        );
        assert!(
            worst_ratio <= 1.0,
            "{motor}: the image's torque left verify's by {worst_t} N·m (at {} ms after the torque; tolerance {t_tol})",
            at_worst * 1e3
        );
        assert!(
            worst_i <= i_tol,
            "{motor}: the image's currents left verify's by {worst_i} A (tolerance {i_tol})"
        );
        assert!(
            max_isr <= INTERRUPT_BUDGET,
            "{motor}: the control interrupt took {max_isr} instructions at speed (budget {INTERRUPT_BUDGET})"
        );
        assert!(
            reached_rpm >= 0.999 * top_e / np * 30.0 / PI,
            "{motor}: the ramp reached {reached_rpm} rpm"
        );
        if psi > 0.0 && dl.abs() > 0.0 && torque > 0.0 {
            // A salient motor at standstill: the stage puts the torque on the MTPA corner
            // (id_c, iq_c) of the circle (3.10), so the machine makes what the simulated
            // machine makes there — L_q's saturation included (the spec's
            // [[motor.saturation.q_inductance]]: the design's MTPA takes the unsaturated
            // L_q, so at chalmers-hev50's 317 A the machine makes 14 % less than the
            // design's torque, in the image and in verify alike) — and more than i_d = 0
            // gives at the same current (the point of MTPA).
            let held = &s[k0 + (0.8 * STANDSTILL_S / ts) as usize..k0 + (STANDSTILL_S / ts) as usize];
            let mean = held
                .iter()
                .map(|x| machine_torque(&setup.motor, x.i[0], x.i[1]))
                .sum::<f64>()
                / held.len() as f64;
            let at_corner = machine_torque(&setup.motor, id_c, iq_c);
            let at_id0 = machine_torque(&setup.motor, 0.0, i_lim);
            println!(
                "{motor}: at standstill {mean:.3} N·m for {torque:.3} N·m commanded (the machine at the MTPA corner {id_c:.1}/{iq_c:.1} A: {at_corner:.3} N·m; at i_d = 0 and that current: {at_id0:.3} N·m)"
            );
            assert!(
                (mean / at_corner - 1.0).abs() <= TORQUE_TOLERANCE,
                "{motor}: standstill torque {mean} where the machine makes {at_corner} at the MTPA corner"
            );
            assert!(
                mean > at_id0,
                "{motor}: standstill torque {mean}, not above i_d = 0's {at_id0}"
            );
        }
    }
}
