//! The current-loop section: the bandwidth guideline (thesis A §5.4.1), both axes' gains,
//! the sampled loop's rise time with its 1.5·T_s delay, the hot-winding variant
//! (thesis B 2.24) and the feed-forward constants (5.3), (2.34).

use std::f64::consts::PI;

use serde::Serialize;

use super::Context;
use crate::design::current_loop::{self, AxisGains, CurrentLoopError};
use crate::design::{discrete_loop, thermal};
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
    /// Guideline ceiling for α [rad/s]: 30 % (1st order) or 17 % (2nd order) of f_s.
    pub bandwidth_limit_rad_s: f64,
    /// Designed 10–90 % rise time \[s\]: ln 9/α for first-order loops.
    pub rise_time_s: Option<f64>,
    /// 10–90 % rise time \[s\] of the sampled d- and q-axis loops with the 1.5·T_s delay
    /// (`discrete_loop`), first-order methods.
    pub sampled_rise_time_s: Option<[f64; 2]>,
    /// Each axis designed for a lower α so that the sampled loop rises in ln 9/α.
    pub compensate_delay: bool,
    /// Designed step overshoot (with prefilter for pole placement), fraction.
    pub overshoot: f64,
    /// d-axis gains.
    pub d: AxisGains,
    /// q-axis gains.
    pub q: AxisGains,
    /// The same design with R at the maximum winding temperature (thesis B 2.24), if `[thermal]` is given.
    pub hot: Option<HotVariant>,
    /// Voltage limit of the PI output vector, U_dc/√3 \[V\] (thesis B 2.50).
    pub voltage_limit_v: f64,
    /// Feed-forward constants.
    pub feedforward: FeedForward,
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
    let limit = current_loop::bandwidth_limit(c.method, fs);
    if c.bandwidth.value >= limit {
        let pct = if c.method == Method::PolePlacement { 17 } else { 30 };
        cx.errors.push(cx.src.error(
            c.bandwidth.span.clone(),
            &c.bandwidth.key,
            format!(
                "bandwidth α = {:.1} rad/s ({:.0} Hz) is not below {pct} % of f_s = {fs} Hz (thesis A §5.4.1)",
                c.bandwidth.value,
                c.bandwidth.value / (2.0 * PI)
            ),
            format!("a bandwidth below {:.0} rad/s", limit),
        ));
    }
    let r = m.phase_resistance.value;
    let gains = axes(spec, r, ts)
        .map_err(|e| cx.errors.push(loop_error(&cx.src, spec, e)))
        .ok();
    let sampled_rise = gains.as_ref().and_then(|(gd, gq)| {
        if c.method == Method::PolePlacement {
            return None;
        }
        let rise = |g: &AxisGains, l: f64| discrete_loop::predicted_rise_time(g, r, l, ts, g.bandwidth_rad_s);
        Some([rise(gd, m.d_inductance.value)?, rise(gq, m.q_inductance.value)?])
    });
    if let Some(t) = sampled_rise {
        let want = 9f64.ln() / c.bandwidth.value;
        let worst = t[0].min(t[1]);
        if (worst / want - 1.0).abs() > 0.10 {
            cx.warnings.push(format!(
                "current loop: sampled at f_s = {fs} Hz with the 1.5·T_s delay the step rises in {:.3} ms, not ln 9/α = {:.3} ms; {}",
                worst * 1e3,
                want * 1e3,
                if worst < want {
                    "set current_loop.compensate_delay = true or raise f_s"
                } else {
                    "raise f_s or lower the bandwidth"
                }
            ));
        }
    }
    let hot = hot_variant(cx, r, ts);
    let (d, q) = gains?;
    let psi = m.flux_linkage.as_ref().map(|p| p.value);
    let kt = psi.map(|p| 1.5 * f64::from(m.pole_pairs) * p);
    Some(CurrentLoopOut {
        method: c.method,
        bandwidth_rad_s: c.bandwidth.value,
        damping: c.damping.as_ref().map(|p| p.value),
        natural_frequency_rad_s: c
            .damping
            .as_ref()
            .map(|z| current_loop::natural_frequency(c.bandwidth.value, z.value)),
        bandwidth_limit_rad_s: limit,
        rise_time_s: (c.method != Method::PolePlacement).then(|| 9f64.ln() / c.bandwidth.value),
        sampled_rise_time_s: sampled_rise,
        compensate_delay: c.compensate_delay,
        overshoot: c.damping.as_ref().map_or(0.0, |z| current_loop::overshoot(z.value)),
        d,
        q,
        hot,
        voltage_limit_v: spec.drive.dc_link_voltage.value / 3f64.sqrt(),
        feedforward: FeedForward {
            d_inductance_h: m.d_inductance.value,
            q_inductance_h: m.q_inductance.value,
            flux_linkage_wb: psi,
            torque_constant_nm_per_a: kt,
            iq_per_nm: kt.map(|k| 1.0 / k),
        },
    })
}

/// The same gains for R_s at the maximum winding temperature (2.24), if `[thermal]` is given;
/// a warning (not an error) when that design is infeasible.
fn hot_variant(cx: &mut Context<'_>, r: f64, ts: f64) -> Option<HotVariant> {
    let t = cx.spec.thermal.as_ref()?;
    let r_hot = thermal::resistance_at(r, t.reference_temperature.value, t.max_winding_temperature.value);
    match axes(cx.spec, r_hot, ts) {
        Ok((d, q)) => Some(HotVariant {
            temperature_c: t.max_winding_temperature.value,
            phase_resistance_ohm: r_hot,
            d,
            q,
        }),
        Err(_) => {
            cx.warnings.push(format!(
                "no hot-resistance variant: the design is infeasible with R_s({} °C) = {r_hot:.4} Ω",
                t.max_winding_temperature.value
            ));
            None
        }
    }
}

/// Both axes' gains for resistance `r` [Ω] and sample period `ts` [s].
fn axes(spec: &Spec, r: f64, ts: f64) -> Result<(AxisGains, AxisGains), CurrentLoopError> {
    let c = &spec.current_loop;
    let zeta = c.damping.as_ref().map_or(0.0, |d| d.value);
    let axis = |name: char, l: f64| {
        if c.compensate_delay {
            discrete_loop::delay_compensated(c.method, name, r, l, c.bandwidth.value, ts).map(|(g, _)| g)
        } else {
            current_loop::design_axis(c.method, name, r, l, c.bandwidth.value, zeta, ts)
        }
    };
    Ok((
        axis('d', spec.motor.d_inductance.value)?,
        axis('q', spec.motor.q_inductance.value)?,
    ))
}

fn loop_error(src: &Source<'_>, spec: &Spec, e: CurrentLoopError) -> Diagnostic {
    let b = &spec.current_loop.bandwidth;
    match e {
        CurrentLoopError::RhpZero { axis, min_bandwidth_rad_s } => src.error(
            b.span.clone(),
            &b.key,
            format!("pole placement at α = {:.4} rad/s puts a right-half-plane zero in the {axis}-axis loop (ω_n·ζ < R/(2L), thesis A §5.4.1)", b.value),
            format!("a bandwidth above {:.1} rad/s, a larger damping, or method = \"imc\"", min_bandwidth_rad_s),
        ),
        CurrentLoopError::NegativeActiveDamping { axis, min_bandwidth_rad_s } => src.error(
            b.span.clone(),
            &b.key,
            format!("α_c·L < R on the {axis} axis: the active damping R_a = α_c·L − R (thesis B 2.43) would be negative"),
            format!("a bandwidth above R/L = {:.1} rad/s, or method = \"imc\"", min_bandwidth_rad_s),
        ),
    }
}
