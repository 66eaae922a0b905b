//! Sensorless recovery from a large speed-estimation error (thesis B §4.6.2, Figs.
//! 4.17, 4.18): the firmware's estimator ([`EstimatorConfig::process`]) supplies θ̂, ω̂
//! to the firmware's control step ([`ControllerConfig::process_at_angle`]) on the
//! simulated motor; the estimate starts 5ρ too fast (Fig. 4.17: the rotor drops from 1 to
//! 0.5 pu with ρ = 0.1 pu). Cycle slips are counted with and without the resetting term.
//!
//! # Where the constants come from
//!
//! [`estimator_config`] takes them from the design (`Design::sensorless`, the thesis B
//! chapter 4 rules of [`codegen::design::sensorless`]), as the firmware's generated
//! constants do.
//!
//! [`ControllerConfig::process_at_angle`]: motor_control::step::ControllerConfig::process_at_angle

use std::f64::consts::PI;

use motor_control::SoftTrig;
use motor_control::angle::to_radians;
pub use motor_control::estimator::EstimatorConfig;
use motor_control::estimator::{EstimatorInput, EstimatorState, InjectionConfig, ResettingConfig};
use motor_control::step::{Demand, StepOutput};
use motor_control::transforms::Dq;

use super::{Check, ScenarioResult, Setup, format_value, series};
use codegen::design::Design;
use motor_control::angle::from_radians_f64;
use motor_sim::plant::{SpeedProfile, wrap};

/// Initial speed error in units of ρ: Fig. 4.17's 0.5 pu drop at ρ = 0.1 pu.
pub const INITIAL_ERROR_RHO: f64 = 5.0;
/// Samples between the carrier phase of a step and the current the estimator
/// demodulates with it: the voltage acts 1.5 periods later (thesis A §4.6) and the
/// estimator reads the previous period's current, 1 more.
pub const CARRIER_DELAY_SAMPLES: f64 = 2.5;

/// The estimator constants of the design (`d.sensorless`, thesis B chapter 4 rules in
/// [`codegen::design::sensorless`]), or `None` when ψ_M is unknown. R̂, L̂_d, L̂_q, ψ̂_M
/// are the design's motor values; ω_max of (4.92) is ω_e,max; the injection's `delay`
/// is the firmware's timing ([`CARRIER_DELAY_SAMPLES`]).
pub fn estimator_config(d: &Design) -> Option<EstimatorConfig> {
    let m = &d.motor;
    let s = d.sensorless.as_ref()?;
    let injection = s.injection.as_ref().map(|inj| InjectionConfig {
        amplitude: inj.voltage_v as f32,
        frequency: inj.frequency_rad_s as f32,
        gain: inj.gain_ke_a as f32,
        highpass: inj.highpass_rad_s as f32,
        lowpass: inj.lowpass_rad_s as f32,
        delay: CARRIER_DELAY_SAMPLES as f32,
        low_speed: s.omega_ls_rad_s as f32,
        high_speed: s.omega_hs_rad_s as f32,
    });
    Some(EstimatorConfig {
        sample_period: d.drive.sample_period_s as f32,
        rho: s.rho_rad_s as f32,
        rs: m.phase_resistance_ohm as f32,
        ld: m.d_inductance_h as f32,
        lq: m.q_inductance_h as f32,
        psi_m: m.flux_linkage_wb? as f32,
        resetting: Some(ResettingConfig {
            lower: s.resetting_lower_rad_s as f32,
            upper: s.resetting_upper_rad_s as f32,
            speed_max: m.max_electrical_speed_rad_s as f32,
        }),
        injection,
    })
}

/// Whether [`estimator_recovery`] applies to the setup's design.
pub fn applies(s: &Setup<'_>) -> bool {
    estimator_config(s.design).is_some()
}

/// Electrical speed [rad/s] of the run: half of ω_e,max, with the back EMF at most 60 %
/// of V_max, and at most α_c — the thesis's runs have ω_r ≤ α_c (Fig. 4.17: α_c = 1 pu,
/// ω_r = 0.5 pu; Fig. 4.20: α_c = 0.87 pu, ω_r = 0.32 pu): the back EMF (4.38), (4.39) is
/// taken from the current loop's voltage with i = i^ref, which a loop slower than the
/// rotation cannot hold while the frame is off; then kept above 2·ω_hs (back EMF only,
/// as in Figs. 4.17/4.18).
pub fn test_speed(d: &Design, c: &EstimatorConfig) -> f64 {
    let m = &d.motor;
    let mut w = (0.5 * m.max_electrical_speed_rad_s)
        .min(0.6 * d.current_loop.voltage_limit_v / f64::from(c.psi_m))
        .min(d.current_loop.bandwidth_rad_s);
    if let Some(inj) = &c.injection {
        w = w.max(2.0 * f64::from(inj.high_speed));
    }
    w
}

/// One sensorless run.
struct Run {
    t: Vec<f64>,
    theta_err: Vec<f64>,
    omega_err: Vec<f64>,
    id: Vec<f64>,
    iq: Vec<f64>,
    slips: i64,
}

fn simulate(s: &Setup<'_>, c: &EstimatorConfig, w: f64, seconds: f64) -> Run {
    let d = s.design;
    let np = f64::from(d.motor.pole_pairs);
    let ts = d.drive.sample_period_s;
    let mut b = s.bench_on(SpeedProfile::constant(w / np));
    let rho = f64::from(c.rho);
    let mut st = EstimatorState {
        theta: from_radians_f64(b.plant.theta_e()),
        omega: (w + INITIAL_ERROR_RHO * rho) as f32,
        ..EstimatorState::default()
    };
    let mut prev = StepOutput::default();
    let n = (seconds / ts).ceil() as usize;
    let mut r = Run {
        t: Vec::with_capacity(n),
        theta_err: Vec::with_capacity(n),
        omega_err: Vec::with_capacity(n),
        id: Vec::with_capacity(n),
        iq: Vec::with_capacity(n),
        slips: 0,
    };
    let mut unwrapped = 0.0f64;
    for k in 0..n {
        let est = c.process(
            &mut st,
            &mut SoftTrig,
            EstimatorInput {
                current: prev.i_dq,
                voltage: prev.u_dq,
                reference: Dq::default(),
            },
        );
        let sample = b.adc();
        let t = b.plant.t;
        let i = b.plant.i;
        let err = wrap(b.plant.theta_e() - f64::from(to_radians(est.theta)));
        unwrapped = if k == 0 { err } else { unwrapped + wrap(err - unwrapped) };
        let demand = Demand::Current {
            id: 0.0,
            iq: 0.0,
            feed_forward: true,
        };
        let out = b.cfg.process_at_angle(
            &mut b.state,
            &mut SoftTrig,
            &sample,
            demand,
            est.theta,
            est.omega_increment,
            est.injection,
        );
        b.plant.step_with(Some(out.duties));
        prev = out;
        r.t.push(t);
        r.theta_err.push(unwrapped);
        r.omega_err.push(w - f64::from(est.omega));
        r.id.push(i[0]);
        r.iq.push(i[1]);
    }
    r.slips = (unwrapped / (2.0 * PI)).round() as i64;
    r
}

/// Last time [s] at which |ω̃| exceeded `bound`, or 0.
fn recovery_time(r: &Run, bound: f64) -> f64 {
    r.omega_err
        .iter()
        .rposition(|x| x.abs() > bound)
        .map_or(0.0, |k| r.t[k])
}

/// Recovery from ω̃ = −5ρ at [`test_speed`], i_ref = 0 (Figs. 4.17, 4.18).
///
/// Criteria: with the resetting term (4.83) no cycle slip (Fig. 4.18); it recovers
/// (|ω̃| < 0.1ρ for good) sooner than the same estimator without it (γ0 ≡ 0, Fig. 4.17,
/// whose cycle slips are reported); the final angle error is below 10° (§4.5.1).
pub fn estimator_recovery(s: &Setup<'_>) -> ScenarioResult {
    match estimator_config(s.design) {
        Some(c) => run(s, &c),
        None => ScenarioResult {
            id: "estimator_recovery",
            title: "Sensorless estimator: not applicable (ψ_M unknown)".into(),
            reference: "thesis B §4.6",
            checks: vec![],
            traces: vec![],
            reached_speed_rpm: None,
            torque_speed: None,
        },
    }
}

/// [`estimator_recovery`] with the given constants (tests pass broken ones); the
/// comparison run uses the same constants without the resetting term.
pub fn run(s: &Setup<'_>, c: &EstimatorConfig) -> ScenarioResult {
    let d = s.design;
    let rho = f64::from(c.rho);
    let w = test_speed(d, c);
    // Time scale from the designed ρ (not the config under test).
    let designed_rho = d.sensorless.as_ref().map_or(rho, |s| s.rho_rad_s);
    let seconds = 60.0 / designed_rho;
    let angle_limit = d.sensorless.as_ref().map_or(10f64.to_radians(), |s| s.angle_error_rad);
    let with = simulate(s, c, w, seconds);
    let plain_cfg = EstimatorConfig { resetting: None, ..*c };
    let without = simulate(s, &plain_cfg, w, seconds);
    let bound = 0.1 * rho;
    let (t_with, t_without) = (recovery_time(&with, bound), recovery_time(&without, bound));
    let final_err = with.theta_err.last().map_or(0.0, |x| wrap(*x).abs());
    let np = f64::from(d.motor.pole_pairs);
    let checks = vec![
        Check {
            quantity: format!("cycle slips with the resetting term (without: {})", without.slips),
            measured: with.slips as f64,
            designed: Some(0.0),
            limit: Some(0.0),
            unit: "",
            criterion: "0 (Fig. 4.18)".into(),
            pass: with.slips == 0,
        },
        Check {
            quantity: format!(
                "recovery time |ω̃| < 0.1ρ (without the term: {})",
                format_value(t_without * 1e3, "ms")
            ),
            measured: t_with * 1e3,
            designed: None,
            limit: Some(t_without * 1e3),
            unit: "ms",
            criterion: "shorter than without the resetting term (Figs. 4.17 vs 4.18)".into(),
            pass: t_with < t_without,
        },
        Check {
            quantity: "final angle error".into(),
            measured: final_err.to_degrees(),
            designed: Some(0.0),
            limit: Some(angle_limit.to_degrees()),
            unit: "°",
            criterion: format!(
                "≤ θ̃max = {:.0}° (sensorless.max_angle_error, thesis B §4.4.2)",
                angle_limit.to_degrees()
            ),
            pass: final_err <= angle_limit,
        },
    ];
    let deg = |v: &[f64]| v.iter().map(|x| x.to_degrees()).collect::<Vec<_>>();
    let per_rho = |v: &[f64]| v.iter().map(|x| x / rho).collect::<Vec<_>>();
    let traces = vec![
        super::scenarios::trace(
            "Speed estimation error ω̃/ρ",
            "ω̃/ρ [-]",
            &with.t,
            vec![
                series("with resetting term", per_rho(&with.omega_err)),
                series("without (γ0 = 0)", per_rho(&without.omega_err)),
            ],
        ),
        super::scenarios::trace(
            "Angle estimation error θ̃ (unwrapped: 360° per cycle slip)",
            "θ̃ [°]",
            &with.t,
            vec![
                series("with resetting term", deg(&with.theta_err)),
                series("without (γ0 = 0)", deg(&without.theta_err)),
            ],
        ),
        super::scenarios::trace(
            "Currents during the recovery (i_ref = 0)",
            "current [A]",
            &with.t,
            vec![
                series("i_d with", with.id),
                series("i_q with", with.iq),
                series("i_d without", without.id),
                series("i_q without", without.iq),
            ],
        ),
    ];
    ScenarioResult {
        id: "estimator_recovery",
        title: format!(
            "Sensorless estimator recovering from ω̃ = −{}ρ at {} (ρ = {})",
            INITIAL_ERROR_RHO,
            format_value(w / np * 30.0 / PI, "rpm"),
            format_value(rho, "rad/s")
        ),
        reference: "thesis B (4.7), (4.51), (4.76)–(4.83), Figs. 4.17, 4.18, App. D",
        checks,
        traces,
        reached_speed_rpm: None,
        torque_speed: None,
    }
}
