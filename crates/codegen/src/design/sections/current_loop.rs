//! The current-loop section: both axes through the pipeline of `design::current_loop`,
//! judged on the sampled loop with the board's loop delay (1.5·T_s without a board; poles, margins, overshoot:
//! `current_loop::analysis`; a breach of its floors is an error at
//! `current_loop.bandwidth` naming the largest bandwidth that meets them, in the words of
//! `current_loop::rules`, which `pi_gains!` prints too), the bandwidth guidelines of thesis A §5.4.1 (warnings), the
//! hot-winding variant (thesis B 2.24) and the feed-forward constants (5.3), (2.34).

use std::f64::consts::PI;

use serde::Serialize;

use super::Context;
use crate::design::Design;
use crate::design::current_loop::analysis::{
    AxisGains, MIN_GAIN_MARGIN_DB, MIN_PHASE_MARGIN_DEG, OVERSHOOT_ALLOWANCE_PCT, RISE_TOLERANCE,
};
use crate::design::current_loop::at_speed;
use crate::design::current_loop::continuous::{self, CurrentLoopError, Promise};
use crate::design::current_loop::{self, Axis, Request, discrete, rules};
use crate::design::thermal;
use crate::diagnostic::{Diagnostic, Source};
use crate::spec::{Method, Spec};

/// Decoupling and back-EMF feed-forward constants (5.3), torque → i_q (2.34).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeedForward {
    /// L_d in u_q,ff = ω_e·(L_d·i_d + ψ_M) \[H\].
    pub d_inductance_h: f64,
    /// L_q in u_d,ff = −ω_e·L_q·i_q \[H\].
    pub q_inductance_h: f64,
    /// ψ_M in the back-EMF term \[Wb\]; null when unknown (term omitted).
    pub flux_linkage_wb: Option<f64>,
    /// K_t = 3/2·n_p·ψ_M per peak ampere [N·m/A] (2.34).
    pub torque_constant_nm_per_a: Option<f64>,
    /// 1/K_t: i_q per N·m [A/(N·m)].
    pub iq_per_nm: Option<f64>,
}

/// The current-loop design.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurrentLoopOut {
    /// Tuning method.
    pub method: Method,
    /// Requested closed-loop bandwidth α [rad/s].
    pub bandwidth_rad_s: f64,
    /// ζ (pole placement).
    pub damping: Option<f64>,
    /// ω_n from (5.15) (pole placement).
    pub natural_frequency_rad_s: Option<f64>,
    /// Guideline ceiling for α [rad/s]: 30 % (1st order) or 17 % (2nd order) of f_s
    /// (thesis A §5.4.1; a warning, the sampled-loop floors decide).
    pub bandwidth_limit_rad_s: f64,
    /// Designed 10–90 % rise time \[s\]: ln 9/α for first-order loops, the second-order
    /// step's with ω_n, ζ for pole placement (`current_loop::continuous`).
    pub rise_time_s: Option<f64>,
    /// 10–90 % rise time \[s\] of the sampled d- and q-axis loops with the loop delay
    /// (`current_loop::discrete`).
    pub sampled_rise_time_s: Option<[f64; 2]>,
    /// The loop delay the gains are designed and judged with \[s\]: the board's
    /// (`sections::board::control_timing`), or 1.5·T_s without one (thesis A §4.6).
    pub loop_delay_s: f64,
    /// Each axis designed so that the sampled loop delivers α (`current_loop::discrete`): on unless
    /// the spec sets `compensate_delay = false`.
    pub compensate_delay: bool,
    /// Designed step overshoot (with prefilter for pole placement), fraction.
    pub overshoot: f64,
    /// The floors every axis's sampled loop meets (`current_loop::analysis`).
    pub floors: Floors,
    /// Lag of the sampled loop behind a reference ramp \[s\], the larger axis
    /// (`current_loop::discrete::ramp_lag`): a current reference moving at di/dt is followed
    /// τ_v·di/dt behind.
    pub ramp_lag_s: f64,
    /// d-axis gains.
    pub d: AxisGains,
    /// q-axis gains.
    pub q: AxisGains,
    /// The same design with R at the maximum winding temperature (thesis B 2.24), if `[thermal]` is given.
    pub hot: Option<HotVariant>,
    /// Voltage limit of the PI output vector at the nominal U_dc \[V\]: V_max = U_dc/√3
    /// (thesis B 2.50), or the usable fraction of it a board's duty limit leaves
    /// (`design::duty_limit`).
    pub voltage_limit_v: f64,
    /// Feed-forward constants.
    pub feedforward: FeedForward,
}

/// The sampled-loop floors of `current_loop::analysis`, as applied to this design.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Floors {
    /// Smallest phase margin [°].
    pub min_phase_margin_deg: f64,
    /// Smallest gain margin [dB].
    pub min_gain_margin_db: f64,
    /// Largest step overshoot [%]: the method's designed one plus the allowance.
    pub max_overshoot_pct: f64,
    /// Largest relative deviation of the sampled rise time from the designed one (with
    /// delay compensation; null without).
    pub rise_tolerance: Option<f64>,
}

/// Gains designed for the hot winding resistance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HotVariant {
    /// Winding temperature [°C].
    pub temperature_c: f64,
    /// R_s(T) \[Ω\].
    pub phase_resistance_ohm: f64,
    /// d-axis gains.
    pub d: AxisGains,
    /// q-axis gains.
    pub q: AxisGains,
}

/// The current-loop section, or `None` with the broken rules in `cx.errors`.
pub(in crate::design) fn current_loop(cx: &mut Context<'_>) -> Option<CurrentLoopOut> {
    let spec = cx.spec;
    let m = &spec.motor;
    let c = &spec.current_loop;
    let fs = cx.switching_frequency();
    let ts = 1.0 / fs;
    let limit = continuous::bandwidth_limit(c.method, fs);
    if c.bandwidth.value >= limit {
        let pct = if c.method == Method::PolePlacement { 17 } else { 30 };
        cx.warn_at(
            &c.bandwidth,
            format!(
                "current loop: α = {:.1} rad/s ({:.0} Hz) is not below {pct} % of f_s = {fs} Hz, the guideline of thesis A §5.4.1 (the sampled-loop margins are what the design checks)",
                c.bandwidth.value,
                c.bandwidth.value / (2.0 * PI)
            ),
        );
    }
    let r = m.phase_resistance.value;
    let delay = cx.loop_delay_periods;
    let requests = requests(spec, r, ts, delay);
    let gains = axes(&requests)
        .map_err(|e| {
            cx.errors
                .push(refused(&cx.src, spec, rules::design_error(&requests, e)))
        })
        .ok();
    let promise = Promise::of(&requests[0]);
    let designed_os = promise.overshoot_pct;
    let drive = drive(cx, r, ts);
    // The floors on both axes, then the at-speed figures (`verify`'s decoupling and
    // DC-link-step criteria): the rules `pi_gains!` applies, and those of a motor.
    if let Some((gd, gq)) = &gains {
        let refusal = rules::floor_breach(&requests, &[gd.clone(), gq.clone()], Some(&drive))
            .or_else(|| rules::at_speed_refusal(&requests, [gd, gq], &drive));
        if let Some(r) = refusal {
            cx.errors.push(refused(&cx.src, spec, r));
        }
    }
    let sampled_rise = gains
        .as_ref()
        .and_then(|(gd, gq)| Some([gd.sampled.rise_time_s?, gq.sampled.rise_time_s?]));
    if let (Some(t), true) = (sampled_rise, c.method != Method::PolePlacement) {
        let want = 9f64.ln() / c.bandwidth.value;
        let worst = t[0].min(t[1]);
        if (worst / want - 1.0).abs() > 0.10 {
            let text = format!(
                "current loop: sampled at f_s = {fs} Hz with the {delay:.4}·T_s delay the step rises in {:.3} ms, not ln 9/α = {:.3} ms; {}",
                worst * 1e3,
                want * 1e3,
                if c.compensate_delay {
                    "the delay compensation cannot reach α: lower the bandwidth or raise f_s"
                } else if worst < want {
                    "remove current_loop.compensate_delay = false or raise f_s"
                } else {
                    "raise f_s or lower the bandwidth"
                }
            );
            cx.warn_at(&c.bandwidth, text);
        }
    }
    let hot = hot_variant(cx, r, ts);
    let (d, q) = gains?;
    let ramp_lag = [(&d, &requests[0]), (&q, &requests[1])]
        .iter()
        .map(|(g, req)| discrete::ramp_lag(&g.loop_gains(), &discrete::plant(req), g.bandwidth_rad_s))
        .fold(0.0, f64::max);
    let psi = m.flux_linkage.as_ref().map(|p| p.value);
    let kt = psi.map(|p| 1.5 * f64::from(m.pole_pairs) * p);
    Some(CurrentLoopOut {
        method: c.method,
        bandwidth_rad_s: c.bandwidth.value,
        damping: c.damping.as_ref().map(|p| p.value),
        natural_frequency_rad_s: c
            .damping
            .as_ref()
            .map(|z| continuous::natural_frequency(c.bandwidth.value, z.value)),
        bandwidth_limit_rad_s: limit,
        rise_time_s: Some(continuous::designed_rise_time(
            c.bandwidth.value,
            continuous::second_order(&requests[0]),
        )),
        sampled_rise_time_s: sampled_rise,
        loop_delay_s: delay * ts,
        compensate_delay: c.compensate_delay,
        overshoot: designed_os / 100.0,
        floors: Floors {
            min_phase_margin_deg: MIN_PHASE_MARGIN_DEG,
            min_gain_margin_db: MIN_GAIN_MARGIN_DB,
            max_overshoot_pct: designed_os + OVERSHOOT_ALLOWANCE_PCT,
            rise_tolerance: promise.rise_time_s.map(|_| RISE_TOLERANCE),
        },
        ramp_lag_s: ramp_lag,
        d,
        q,
        hot,
        voltage_limit_v: cx.usable_voltage_v(),
        feedforward: FeedForward {
            d_inductance_h: m.d_inductance.value,
            q_inductance_h: m.q_inductance.value,
            flux_linkage_wb: psi,
            torque_constant_nm_per_a: kt,
            iq_per_nm: kt.map(|k| 1.0 / k),
        },
    })
}

/// The drive the at-speed figures are judged on (`current_loop::at_speed`).
/// Its voltage limit is the usable voltage at the nominal U_dc ([`Context::usable_voltage_v`]),
/// its loop delay the board's ([`Context::loop_delay_periods`]).
fn drive(cx: &Context<'_>, r: f64, ts: f64) -> at_speed::Drive {
    let spec = cx.spec;
    let m = &spec.motor;
    let c = &spec.current_loop;
    let zeta = c.damping.as_ref().map_or(0.0, |z| z.value);
    at_speed::Drive {
        resistance_ohm: r,
        ld: m.d_inductance.value,
        lq: m.q_inductance.value,
        flux_linkage_wb: m.flux_linkage.as_ref().map(|p| p.value),
        peak_current_a: std::f64::consts::SQRT_2 * m.peak_current.value,
        voltage_limit_v: cx.usable_voltage_v(),
        max_electrical_speed: 2.0 * PI * cx.max_electrical_frequency(),
        sample_period_s: ts,
        dc_link_voltage_v: spec.drive.dc_link_voltage.value,
        dc_link_voltage_min_v: spec.drive.dc_link_voltage_min.value,
        method: c.method,
        damping: zeta,
        loop_delay_periods: cx.loop_delay_periods,
        // The lead from the resolver's sample, plus its lag behind the currents'
        // (D − k_board: the two samples' distance in periods).
        angle_lead_periods: cx.angle_lead_periods() + cx.loop_delay_periods - cx.board_angle_lead_periods,
    }
}

/// The spec's current-loop requests for the d and q axes with resistance `r` \[Ω\] at
/// sample period `ts` \[s\], with the loop delay `delay` [periods of T_s].
fn requests(spec: &Spec, r: f64, ts: f64, delay: f64) -> [Request; 2] {
    let c = &spec.current_loop;
    let m = &spec.motor;
    [(Axis::D, m.d_inductance.value), (Axis::Q, m.q_inductance.value)].map(|(axis, l)| Request {
        method: c.method,
        axis,
        resistance_ohm: r,
        inductance_h: l,
        bandwidth_rad_s: c.bandwidth.value,
        damping: c.damping.as_ref().map_or(0.0, |d| d.value),
        sample_period_s: ts,
        loop_delay_s: delay * ts,
        compensate_delay: c.compensate_delay,
    })
}

impl Design {
    /// The request the design's `axis` was designed from (the spec's R, the axis's L,
    /// α, ζ, T_s, the loop delay and delay compensation), for a consumer that compares
    /// a measured loop with the designed one (`motor_commission::frequency_response`).
    pub fn current_loop_request(&self, axis: Axis) -> Request {
        let c = &self.current_loop;
        let ts = self.drive.sample_period_s;
        Request {
            method: c.method,
            axis,
            resistance_ohm: self.motor.phase_resistance_ohm,
            inductance_h: match axis {
                Axis::D => self.motor.d_inductance_h,
                Axis::Q => self.motor.q_inductance_h,
            },
            bandwidth_rad_s: c.bandwidth_rad_s,
            damping: c.damping.unwrap_or(0.0),
            sample_period_s: ts,
            loop_delay_s: c.loop_delay_s,
            compensate_delay: c.compensate_delay,
        }
    }
}

/// The same gains for R_s at the maximum winding temperature (2.24), if `[thermal]` is given;
/// a warning (not an error) when that design is infeasible.
fn hot_variant(cx: &mut Context<'_>, r: f64, ts: f64) -> Option<HotVariant> {
    let t = cx.spec.thermal.as_ref()?;
    let r_hot = thermal::resistance_at(r, t.reference_temperature.value, t.max_winding_temperature.value);
    let requests = requests(cx.spec, r_hot, ts, cx.loop_delay_periods);
    match axes(&requests) {
        Ok((d, q)) => {
            let promise = Promise::of(&requests[0]);
            for (axis, g) in [('d', &d), ('q', &q)] {
                if let Some(b) = g.sampled.breach(&promise) {
                    cx.warn_at(
                        &t.max_winding_temperature,
                        format!("hot-resistance variant (R_s = {r_hot:.4} Ω): the sampled {axis}-axis loop is {b}"),
                    );
                }
            }
            Some(HotVariant {
                temperature_c: t.max_winding_temperature.value,
                phase_resistance_ohm: r_hot,
                d,
                q,
            })
        }
        Err(_) => {
            let text = format!(
                "no hot-resistance variant: the design is infeasible with R_s({} °C) = {r_hot:.4} Ω",
                t.max_winding_temperature.value
            );
            cx.warn_at(&t.max_winding_temperature, text);
            None
        }
    }
}

/// Both axes through the pipeline (d first).
fn axes([d, q]: &[Request; 2]) -> Result<(AxisGains, AxisGains), CurrentLoopError> {
    Ok((current_loop::design(d)?, current_loop::design(q)?))
}

/// A refusal of the current-loop rules ([`rules::verdict`]'s), located at the spec's
/// `current_loop.bandwidth`.
fn refused(src: &Source<'_>, spec: &Spec, r: rules::Refusal) -> Diagnostic {
    let b = &spec.current_loop.bandwidth;
    src.error(b.span.clone(), &b.key, r.problem, r.accepted)
}
