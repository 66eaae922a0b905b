//! Field weakening to twice base speed (thesis B §2.3, Fig. 2.15): the firmware's
//! [`FieldWeakeningConfig::process`] turns a full torque demand into current references
//! for the firmware's control step, on the simulated motor, while the shaft speed ramps
//! from half to twice base speed.
//!
//! # Where the constants come from
//!
//! [`field_weakening_config`] takes every constant from the design
//! ([`codegen::design::field_weakening`], emitted as the `field_weakening` constants), so
//! the scenario, the report and the firmware (`firmware/app/src/config.rs`) run one
//! configuration.

use std::f64::consts::PI;

use motor_control::feedforward::effective_dc_link;
pub use motor_control::field_weakening::FieldWeakeningConfig;
use motor_control::field_weakening::{FieldWeakeningInput, FieldWeakeningState, MtpaCurve};
use motor_control::step::{Demand, StepOutput};
use motor_control::transforms::{Dq, INV_SQRT_3};

use super::scenarios::trace;
use super::{Check, ScenarioResult, Setup, format_value, series};
use codegen::design::Design;
use motor_sim::bench::Bench;
use motor_sim::plant::{MotorModel, Shaft, SpeedProfile};

/// Electrical base speed ω_base [rad/s] of (2.60), from the design.
pub fn base_speed(d: &Design) -> Option<f64> {
    d.field_weakening.as_ref().map(|fw| fw.base_speed_rad_s)
}

/// V'_max/V_max of the design (thesis B Fig. 2.15: 0.9), 0 without field weakening.
fn voltage_fraction(d: &Design) -> f64 {
    d.field_weakening.as_ref().map_or(0.0, |fw| fw.voltage_fraction)
}

/// The field-weakening constants of `d` (thesis B §2.3.3, [`codegen::design::field_weakening`]),
/// or `None` when ψ_M is unknown:
///
/// * `bandwidth` α_fw (10·α_s, α_s = α_c/100 of Fig. 2.15 unless the spec gives a speed
///   loop or J and b), `ld` L̂_d, `base_speed` ω_base — γ = α_fw/(2·ω_fw·L̂_d·V'_max)
///   (2.60) is evaluated by the firmware at the measured V'_max;
/// * `voltage_fraction` V'_max/V_max (spec, default 0.9 of Fig. 2.15);
/// * `current_max` I_max (2.50), (2.56);
/// * `mtpa` the design's MTPA table (3.10) as a [`MtpaCurve::Table`].
///
/// The control core's table borrows `'static` points (the firmware's are generated
/// constants); here the design's 17 points (136 bytes) are leaked once per call.
pub fn field_weakening_config(d: &Design) -> Option<FieldWeakeningConfig> {
    let fw = d.field_weakening.as_ref()?;
    let points: Vec<[f32; 2]> = fw
        .mtpa
        .iq_a
        .iter()
        .zip(&fw.mtpa.id_a)
        .map(|(&iq, &id)| [iq as f32, id as f32])
        .collect();
    Some(FieldWeakeningConfig {
        sample_period: d.drive.sample_period_s as f32,
        bandwidth: fw.bandwidth_rad_s as f32,
        ld: fw.d_inductance_h as f32,
        base_speed: fw.base_speed_rad_s as f32,
        voltage_fraction: fw.voltage_fraction as f32,
        current_max: fw.current_max_a as f32,
        mtpa: MtpaCurve::Table(Box::leak(points.into_boxed_slice())),
    })
}

/// Whether [`field_weakening`] applies to the setup's design.
pub fn applies(s: &Setup<'_>) -> bool {
    field_weakening_config(s.design).is_some()
}

/// Electromagnetic torque T = 3/2·n_p·i_q·(ψ_M + (L_d − L_q(i_q))·i_d) [N·m] (thesis A
/// (2.33)) of the simulated machine.
pub fn torque(m: &MotorModel, id: f64, iq: f64) -> f64 {
    1.5 * f64::from(m.pole_pairs) * iq * (m.psi + (m.ld - m.lq_at(iq)) * id)
}

/// Steady-state |v| \[V\] of the simulated machine at speed `w` (2.52), harmonics left out.
pub fn steady_voltage(m: &MotorModel, w: f64, id: f64, iq: f64) -> f64 {
    let vd = m.resistance * id - w * m.lq_at(iq) * iq;
    let vq = m.resistance * iq + w * (m.ld * id + m.psi);
    vd.hypot(vq)
}

/// The largest torque [N·m] at speed `w` with |i| ≤ `i_max` (2.50) and the steady-state
/// |v| ≤ `v_max` (2.52), by search over i_d (2001 points on [−i_max, 0]) and bisection
/// on i_q (|v| grows with i_q on the torque-producing side), on the simulated
/// machine's own L_q(i_q).
pub fn max_torque(m: &MotorModel, w: f64, i_max: f64, v_max: f64) -> f64 {
    let mut best = 0.0f64;
    for k in 0..=2000 {
        let id = -i_max * f64::from(k) / 2000.0;
        let circle = (i_max * i_max - id * id).max(0.0).sqrt();
        if steady_voltage(m, w, id, 0.0) > v_max {
            continue;
        }
        let iq = if steady_voltage(m, w, id, circle) <= v_max {
            circle
        } else {
            let (mut lo, mut hi) = (0.0, circle);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if steady_voltage(m, w, id, mid) <= v_max {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        };
        best = best.max(torque(m, id, iq));
    }
    best
}

/// The top speed of the run [rad/s, electrical]: 2·ω_base (Fig. 2.15), at most ω_e,max and
/// at most 90 % of the speed where even i_d = −I_max cannot hold V'_max with i_q = 0
/// (ω·(ψ_M − L_d·I_max) = V'_max, when ψ_M > L_d·I_max): beyond it no torque is possible.
pub fn top_speed(d: &Design, base: f64) -> f64 {
    let m = &d.motor;
    let psi = m.flux_linkage_wb.unwrap_or(0.0);
    let v = voltage_fraction(d) * d.current_loop.voltage_limit_v;
    let mut w = (2.0 * base).min(m.max_electrical_speed_rad_s);
    let residual = psi - m.d_inductance_h * m.peak_current_a;
    if residual > 0.0 {
        w = w.min(0.9 * v / residual);
    }
    w
}

/// cos φ of the largest turn of the current vector the tracking criterion of
/// [`field_weakening`] allows: 95 % of it stays along the reference, as the torque
/// criterion asks.
pub const TRACKING_TURN_COS: f64 = 0.95;

/// Speed ramp (cosine-shaped, peak acceleration the drive's largest,
/// `drive.max_acceleration_rad_s2`) from ω_base/2 to [`top_speed`] under full torque
/// demand (i_q^0 = I_max), then held.
///
/// Criteria (thesis B §2.3, Fig. 2.15):
/// * the voltage never uses up the margin: peak |v| ≤ (V'_max + V_max)/2 — without field
///   weakening the current loop saturates at V_max;
/// * at the top speed |v| settles on V'_max (2.55) within 2 %;
/// * the current stays in the circle (2.50): peak |i| ≤ 1.05·I_max (tracking and
///   harmonics);
/// * the torque at the top speed is at least 95 % of the most the current circle and the
///   V'_max ellipse allow there ([`max_torque`]);
/// * the electrical angle the controller transforms with stays within the design's
///   field-orientation allowance (`angle_observer.max_lag_deg`, 10°: thesis B §4.4.2)
///   of the true one during and after the ramp;
/// * the currents track their references during and after the ramp:
///   `|i_dq − i_dq^ref| ≤ 2·sin(φ/2)·|i^ref|max + |di^ref/dt|max·τ_v + ripple` with
///   φ = acos 0.95 = 18.2°. A current vector turned by φ off its reference (a frame error
///   turns it so) moves by 2·sin(φ/2)·|i| and keeps cos φ of it along the reference: φ is the
///   largest turn that leaves the 95 % of the torque criterion above. The sampled current
///   loop follows a reference moving at di^ref/dt with the steady lag τ_v·di^ref/dt of its
///   type-1 loop (`current_loop.ramp_lag_s`); the ripple is |i − i^ref| in the last half
///   of the hold before the ramp (harmonics, quantisation).
pub fn field_weakening(s: &Setup<'_>) -> ScenarioResult {
    let cfg = field_weakening_config(s.design);
    run(s, cfg)
}

/// [`field_weakening`] with the given controller constants (tests pass broken ones).
pub fn run(s: &Setup<'_>, fw: Option<FieldWeakeningConfig>) -> ScenarioResult {
    let d = s.design;
    let m = &d.motor;
    let Some(fw) = fw else {
        return ScenarioResult {
            id: "field_weakening",
            title: "Field weakening: not applicable (ψ_M unknown)".into(),
            reference: "thesis B §2.3",
            checks: vec![],
            traces: vec![],
        };
    };
    let np = f64::from(m.pole_pairs);
    let ts = d.drive.sample_period_s;
    let base = f64::from(fw.base_speed);
    let top = top_speed(d, base);
    let start = 0.5 * base;
    // Cosine speed profile ω(t) = ω_0 + Δ·(1 − cos πτ)/2, τ = (t − t_0)/T: the
    // acceleration rises and falls smoothly (no step for the observer), peaking at
    // a = Δ·π/(2T) = n_p·ω̇_m,max (electrical), the drive's largest acceleration.
    let acc_e = np * d.drive.max_acceleration_rad_s2;
    let alpha_fw = f64::from(fw.bandwidth);
    // Time scale from the designed α_fw (not the config under test, which may be broken,
    // e.g. α_fw = 0).
    let t_fw = 1.0 / d.field_weakening.as_ref().map_or(alpha_fw, |x| x.bandwidth_rad_s);
    let t0 = 10.0 * t_fw;
    let ramp = (top - start).max(0.0) * PI / (2.0 * acc_e);
    let hold = 20.0 * t_fw;
    let speed_at = |t: f64| {
        let tau = if ramp > 0.0 {
            ((t - t0) / ramp).clamp(0.0, 1.0)
        } else {
            f64::from(u8::from(t >= t0))
        };
        start + (top - start) * 0.5 * (1.0 - (PI * tau).cos())
    };
    let segment = |t: f64| {
        let (a, b) = (speed_at(t), speed_at(t + ts));
        SpeedProfile {
            from: a / np,
            to: b / np,
            start: t,
            acceleration: (b - a).abs() / ts / np,
        }
    };
    let mut b = Bench::new(s.cfg, s.plant(SpeedProfile::constant(start / np)));
    let n = ((t0 + ramp + hold) / ts).ceil() as usize;
    let i_max = f64::from(fw.current_max);
    let v_max_design = d.current_loop.voltage_limit_v;
    let v_prime = voltage_fraction(d) * v_max_design;
    let mut st = FieldWeakeningState::default();
    let mut prev = StepOutput::default();
    let (mut t, mut w, mut id, mut iq, mut idr, mut iqr, mut v, mut ang) =
        (vec![], vec![], vec![], vec![], vec![], vec![], vec![], vec![]);
    let (mut peak_v, mut peak_i) = (0.0f64, 0.0f64);
    // Tracking: ripple in the hold before the ramp, then the peak error, the reference
    // magnitude and rate during and after it, and the peak angle error.
    let (mut ripple, mut peak_err, mut peak_ref, mut peak_rate, mut peak_angle) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut prev_ref: Option<(f64, f64)> = None;
    for _ in 0..n {
        b.plant.shaft = Shaft::Imposed(segment(b.plant.t));
        let v_max = s.cfg.voltage_margin * effective_dc_link(prev.u_dc, s.cfg.dc_link_min) * INV_SQRT_3;
        let (id_ref, iq_ref) = fw.process(
            &mut st,
            FieldWeakeningInput {
                iq_demand: fw.current_max,
                omega: prev.omega_e,
                voltage: prev.u_dq,
                voltage_max: v_max,
                iq_limit: f32::INFINITY,
            },
        );
        let smp = b.step(Demand::Current {
            id: id_ref,
            iq: iq_ref,
            feed_forward: true,
        });
        prev = smp.out;
        let Dq { d: ud, q: uq } = smp.out.u_dq;
        let vm = f64::from(ud).hypot(f64::from(uq));
        t.push(smp.t);
        w.push(np * smp.omega_m);
        id.push(smp.i[0]);
        iq.push(smp.i[1]);
        idr.push(f64::from(id_ref));
        iqr.push(f64::from(iq_ref));
        v.push(vm);
        let (rd, rq) = (f64::from(id_ref), f64::from(iq_ref));
        let err = (smp.i[0] - rd).hypot(smp.i[1] - rq);
        let angle = smp.angle_error();
        ang.push(angle.to_degrees());
        if smp.t >= 0.5 * t0 && smp.t < t0 {
            ripple = ripple.max(err);
        }
        if smp.t >= t0 {
            peak_v = peak_v.max(vm);
            peak_i = peak_i.max(smp.i[0].hypot(smp.i[1]));
            peak_err = peak_err.max(err);
            peak_ref = peak_ref.max(rd.hypot(rq));
            peak_angle = peak_angle.max(angle.abs());
            if let Some((pd, pq)) = prev_ref {
                peak_rate = peak_rate.max((rd - pd).hypot(rq - pq) / ts);
            }
        }
        prev_ref = Some((rd, rq));
    }
    let theta_allowed = d.angle_observer.max_lag_deg.to_radians();
    let lag = d.current_loop.ramp_lag_s;
    let frame_term = 2.0 * (0.5 * TRACKING_TURN_COS.acos()).sin() * peak_ref;
    let bound = frame_term + peak_rate * lag + ripple;
    let tail = ((0.25 * hold / ts) as usize).clamp(1, n);
    let mean = |x: &[f64]| x[n - tail..].iter().sum::<f64>() / tail as f64;
    let v_end = mean(&v);
    let torque_end = {
        let tq: Vec<f64> = id.iter().zip(&iq).map(|(a, b)| torque(&s.motor, *a, *b)).collect();
        mean(&tq)
    };
    let t_max = max_torque(&s.motor, top, i_max, v_prime);
    let rpm = |w: f64| w / np * 30.0 / PI;
    let checks = vec![
        Check {
            quantity: "peak |v| on the ramp".into(),
            measured: peak_v,
            designed: Some(v_prime),
            unit: "V",
            criterion: format!(
                "≤ (V'_max + V_max)/2 = {} (V_max = {}: the margin is never used up, Fig. 2.15)",
                format_value(0.5 * (v_prime + v_max_design), "V"),
                format_value(v_max_design, "V")
            ),
            pass: peak_v <= 0.5 * (v_prime + v_max_design),
        },
        Check {
            quantity: format!("|v| at {}", format_value(rpm(top), "rpm")),
            measured: v_end,
            designed: Some(v_prime),
            unit: "V",
            criterion: "within 2 % of V'_max (2.55)".into(),
            pass: (v_end / v_prime - 1.0).abs() <= 0.02,
        },
        Check {
            quantity: "peak |i|".into(),
            measured: peak_i,
            designed: Some(i_max),
            unit: "A",
            criterion: "≤ 1.05·I_max (current circle 2.50, 2.57)".into(),
            pass: peak_i <= 1.05 * i_max,
        },
        Check {
            quantity: format!("torque at {}", format_value(rpm(top), "rpm")),
            measured: torque_end,
            designed: Some(t_max),
            unit: "N·m",
            criterion: "≥ 95 % of the most |i| ≤ I_max and |v| ≤ V'_max allow there".into(),
            pass: torque_end >= 0.95 * t_max,
        },
        Check {
            quantity: format!(
                "peak electrical angle error |θ̂_e − θ_e| (ω̇_m = {}, {})",
                format_value(d.drive.max_acceleration_rad_s2 * 30.0 / PI, "rpm/s"),
                d.drive.max_acceleration_rule.describe()
            ),
            measured: peak_angle.to_degrees(),
            designed: Some(d.angle_observer.lag_at_max_acceleration_deg),
            unit: "°",
            criterion: format!(
                "≤ θ̃ = {}° (the design's field-orientation allowance, thesis B §4.4.2)",
                d.angle_observer.max_lag_deg
            ),
            pass: peak_angle <= theta_allowed,
        },
        Check {
            quantity: "peak |i_dq − i_dq^ref| during and after the ramp".into(),
            measured: peak_err,
            designed: Some(bound),
            unit: "A",
            criterion: format!(
                "≤ 2·sin(φ/2)·|i^ref|max ({}, φ = acos 0.95) + |di^ref/dt|max·τ_v ({} · {}) + ripple ({})",
                format_value(frame_term, "A"),
                format_value(peak_rate, "A/s"),
                format_value(lag * 1e3, "ms"),
                format_value(ripple, "A")
            ),
            pass: peak_err <= bound,
        },
    ];
    let traces = vec![
        trace(
            "Field weakening: currents on the speed ramp",
            "current [A]",
            &t,
            vec![
                series("i_d simulated", id),
                series("i_q simulated", iq),
                series("i_d^ref", idr),
                series("i_q^ref", iqr),
            ],
        ),
        trace(
            "Field weakening: voltage magnitude",
            "|v| [V]",
            &t,
            vec![
                series("|v| (current-loop output)", v),
                series("V'_max", vec![v_prime; n]),
                series("V_max", vec![v_max_design; n]),
            ],
        ),
        trace(
            "Field weakening: electrical speed",
            "ω_e [rad/s]",
            &t,
            vec![series("ω_e", w)],
        ),
        trace(
            "Field weakening: electrical angle error of the controller's frame",
            "θ̂_e − θ_e [°]",
            &t,
            vec![series("θ̂_e − θ_e", ang)],
        ),
    ];
    ScenarioResult {
        id: "field_weakening",
        title: format!(
            "Field weakening, ramp {} → {} under full torque demand (i_q^0 = {}), α_fw = {}, V'_max = {}",
            format_value(rpm(start), "rpm"),
            format_value(rpm(top), "rpm"),
            format_value(i_max, "A"),
            format_value(alpha_fw, "rad/s"),
            format_value(v_prime, "V"),
        ),
        reference: "thesis B (2.50)–(2.57), (2.60), Fig. 2.15, App. D",
        checks,
        traces,
    }
}
