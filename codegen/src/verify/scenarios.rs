//! The standard scenarios. Each returns measured vs designed figures and a criterion:
//!
//! * [`current_step`] — i_d and i_q reference steps at standstill: IMC rise time within
//!   10 % of ln 9/α and no overshoot (thesis A (5.8), thesis B (2.41)); pole placement
//!   overshoot ≤ 5 % with the prefilter (thesis A (5.14)–(5.16), ζ = 1/√2 → e^(−π)).
//! * [`decoupling`] — i_q step at speed with and without the feed-forward (5.3): the
//!   i_d excursion must shrink at least 3× (thesis A Figs. 5.4 vs 5.6).
//! * [`dc_link_step`] — U_dc drops 20 % at speed under load; the 1/U_dc feed-forward
//!   (5.1) must limit the current error to the one-period kick (criterion below).
//! * [`ato_lock`] — observer started π/2 off: it locks, no cycle slip, within the
//!   designed linear settling time plus margin (thesis A (4.12)–(4.15)).
//! * [`ato_ramp`] — speed ramp to the maximum speed: the lag during the ramp is the
//!   designed a/K_i, and zero (within the integer dead zone) at constant speed (type-2
//!   loop, thesis A §4.4).

use std::f64::consts::PI;

use motor_control::ato::AtoState;
use motor_control::step::Demand;

use super::figures::{designed_rise_time, designed_step};
use super::{Check, ScenarioResult, Series, Setup, Trace, format_value};
use crate::design::discrete_loop::step_response;
use crate::spec::{Method, ObserverError};
use motor_control::angle::from_radians_f64;
use motor_sim::bench::{Bench, q31_angle};
use motor_sim::figures::{settling_time, step_figures};
use motor_sim::plant::{SpeedProfile, wrap};

/// Most points kept per trace (the report plots them; more adds bytes, not information).
const TRACE_POINTS: usize = 1500;

fn check(quantity: impl Into<String>, measured: f64, designed: Option<f64>, unit: &'static str) -> Check {
    Check {
        quantity: quantity.into(),
        measured,
        designed,
        unit,
        criterion: String::new(),
        pass: false,
    }
}

impl Check {
    fn criterion(mut self, text: impl Into<String>, pass: bool) -> Check {
        self.criterion = text.into();
        self.pass = pass;
        self
    }
}

/// Keeps every k-th point so that at most [`TRACE_POINTS`] remain.
fn decimate(t: &[f64], series: Vec<Series>) -> (Vec<f64>, Vec<Series>) {
    let k = t.len().div_ceil(TRACE_POINTS).max(1);
    let pick = |v: &[f64]| v.iter().step_by(k).copied().collect::<Vec<_>>();
    (
        pick(t),
        series
            .into_iter()
            .map(|s| Series {
                values: pick(&s.values),
                label: s.label,
            })
            .collect(),
    )
}

pub(super) fn trace(title: impl Into<String>, y_label: &str, t_s: &[f64], series: Vec<Series>) -> Trace {
    let t_ms: Vec<f64> = t_s.iter().map(|t| t * 1e3).collect();
    let (t_ms, series) = decimate(&t_ms, series);
    Trace {
        title: title.into(),
        y_label: y_label.into(),
        t_ms,
        series,
    }
}

fn series(label: impl Into<String>, values: Vec<f64>) -> Series {
    Series {
        label: label.into(),
        values,
    }
}

/// Samples for `seconds` at T_s.
fn samples(s: &Setup<'_>, seconds: f64) -> usize {
    (seconds / s.design.drive.sample_period_s).ceil() as usize
}

/// Current step height \[A\]: a quarter of the current-circle radius √2·I_peak, kept so
/// that the proportional kick k_p·Δi stays within half the voltage circle (so the
/// linear design is what is measured, not the voltage limit).
pub fn step_amplitude(s: &Setup<'_>) -> f64 {
    let d = s.design;
    let kp = d.current_loop.d.kp.max(d.current_loop.q.kp);
    (0.25 * d.motor.peak_current_a).min(0.5 * d.current_loop.voltage_limit_v / kp)
}

/// Slowest pole [rad/s] of the current loop's response to a voltage disturbance: IMC
/// cancels the plant pole R/L, which then governs disturbances; active damping moves it
/// to α (thesis B (2.43)); pole placement puts both poles at ω_n with real part ζω_n.
pub fn disturbance_pole(s: &Setup<'_>) -> f64 {
    let d = s.design;
    let cl = &d.current_loop;
    match cl.method {
        Method::Imc => d.motor.phase_resistance_ohm / d.motor.d_inductance_h.max(d.motor.q_inductance_h),
        Method::ImcActiveDamping => cl.bandwidth_rad_s,
        Method::PolePlacement => cl.damping.unwrap_or(1.0) * cl.natural_frequency_rad_s.unwrap_or(cl.bandwidth_rad_s),
    }
}

/// Electrical speed [rad/s] of the at-speed scenarios: the back EMF ω_e·ψ_M at half the
/// voltage circle, the coupling ω_e·L_q·Δi at most 30 % of it, not above ω_e,max.
pub fn operating_speed(s: &Setup<'_>) -> f64 {
    let d = s.design;
    let v = d.current_loop.voltage_limit_v;
    let mut w = d.motor.max_electrical_speed_rad_s;
    if let Some(psi) = d.motor.flux_linkage_wb.filter(|p| *p > 0.0) {
        w = w.min(0.5 * v / psi);
    }
    w.min(0.3 * v / (d.motor.q_inductance_h * step_amplitude(s)))
}

fn current(id: f64, iq: f64, feed_forward: bool) -> Demand {
    Demand::Current {
        id: id as f32,
        iq: iq as f32,
        feed_forward,
    }
}

/// i_d and i_q reference steps at standstill (feed-forward on, ω = 0).
pub fn current_step(s: &Setup<'_>) -> ScenarioResult {
    let d = s.design;
    let cl = &d.current_loop;
    let ts = d.drive.sample_period_s;
    let a = step_amplitude(s);
    let alpha = cl.bandwidth_rad_s;
    let second = match cl.method {
        Method::PolePlacement => Some((
            cl.natural_frequency_rad_s.unwrap_or(alpha),
            cl.damping.unwrap_or(std::f64::consts::FRAC_1_SQRT_2),
        )),
        _ => None,
    };
    let rise_design = designed_rise_time(alpha, second);
    let n = samples(s, 12.0 / alpha);
    let settle = 20;
    let mut checks = Vec::new();
    let mut traces = Vec::new();
    for (axis, k) in [("d", 0usize), ("q", 1usize)] {
        let mut b = s.bench(0.0);
        for _ in 0..settle {
            b.step(current(0.0, 0.0, true));
        }
        let demand = if k == 0 {
            current(a, 0.0, true)
        } else {
            current(0.0, a, true)
        };
        let mut y = vec![b.plant.i[k]];
        let mut other = vec![b.plant.i[1 - k]];
        for _ in 0..n {
            b.step(demand);
            y.push(b.plant.i[k]);
            other.push(b.plant.i[1 - k]);
        }
        let f = step_figures(&y, ts, y[0], a);
        let rise = f.rise_time * 1e3;
        let want = rise_design * 1e3;
        let rise_ok = (f.rise_time / rise_design - 1.0).abs() <= 0.10;
        checks.push(
            check(format!("{axis}-axis rise time 10–90 %"), rise, Some(want), "ms")
                .criterion("within 10 % of designed (continuous)", rise_ok),
        );
        // The same gains in the discrete loop with the 1.5·T_s delay (frequency.rs): tells
        // a sampling effect (both measured and predicted off the design) from an
        // implementation fault (measured off the prediction).
        let (g, l) = if k == 0 {
            (&cl.d, d.motor.d_inductance_h)
        } else {
            (&cl.q, d.motor.q_inductance_h)
        };
        let z = step_response(g, d.motor.phase_resistance_ohm, l, ts, n + 2);
        let zf = step_figures(&z, ts, 0.0, 1.0);
        checks.push(
            check(
                format!("{axis}-axis rise time vs the discrete loop (T_s, 1.5·T_s delay)"),
                rise,
                Some(zf.rise_time * 1e3),
                "ms",
            )
            .criterion(
                "within 5 % of the z-domain prediction",
                (f.rise_time / zf.rise_time - 1.0).abs() <= 0.05,
            ),
        );
        let (limit, why) = match cl.method {
            Method::PolePlacement => (0.05, "≤ 5 % (ζ = 1/√2 with prefilter: e^−π = 4.3 %, thesis A §5.4.1)"),
            _ => (0.005, "none (≤ 0.5 %: first-order loop, thesis A (5.8))"),
        };
        checks.push(
            check(
                format!("{axis}-axis overshoot"),
                f.overshoot * 100.0,
                Some(cl.overshoot * 100.0),
                "%",
            )
            .criterion(why, f.overshoot <= limit),
        );
        checks.push(
            check(
                format!("{axis}-axis error after 12/α"),
                f.final_error.abs() * 100.0,
                Some(0.0),
                "%",
            )
            .criterion("≤ 1 % (integral action)", f.final_error.abs() <= 0.01),
        );
        let t: Vec<f64> = (0..y.len()).map(|j| j as f64 * ts).collect();
        let designed: Vec<f64> = t.iter().map(|&t| a * designed_step(t, alpha, second)).collect();
        let (this, that) = if k == 0 { ("i_d", "i_q") } else { ("i_q", "i_d") };
        traces.push(trace(
            format!(
                "{axis}-axis current step {} A at standstill",
                format_value(a, "").trim()
            ),
            "current [A]",
            &t,
            vec![
                series(format!("{this} simulated"), y),
                series(format!("{this} designed"), designed),
                series(format!("{that} simulated"), other),
            ],
        ));
    }
    ScenarioResult {
        id: "current_step",
        title: format!(
            "Current steps of {} at standstill, {} current loop at α = {}",
            format_value(a, "A"),
            match cl.method {
                Method::Imc => "IMC",
                Method::PolePlacement => "pole-placement",
                Method::ImcActiveDamping => "IMC + active damping",
            },
            format_value(alpha, "rad/s")
        ),
        reference: "thesis A (5.8), (5.9), (5.14)–(5.16); thesis B (2.38)–(2.41)",
        checks,
        traces,
    }
}

/// Runs `settle` periods of `before`, then `n` of `after`; returns times and true currents.
fn run(b: &mut Bench, settle: usize, before: Demand, n: usize, after: Demand) -> (Vec<f64>, Vec<[f64; 2]>) {
    for _ in 0..settle {
        b.step(before);
    }
    let (mut t, mut i) = (vec![b.plant.t], vec![b.plant.i]);
    for _ in 0..n {
        b.step(after);
        t.push(b.plant.t);
        i.push(b.plant.i);
    }
    (t, i)
}

/// i_q step at speed with and without the decoupling/back-EMF feed-forward (5.3).
pub fn decoupling(s: &Setup<'_>) -> ScenarioResult {
    let d = s.design;
    let a = step_amplitude(s);
    let we = operating_speed(s);
    let wm = we / f64::from(d.motor.pole_pairs);
    let n = samples(s, 10.0 / d.current_loop.bandwidth_rad_s);
    let mut excursion = [0.0; 2];
    let mut traces_i = Vec::new();
    let mut t0 = Vec::new();
    for ff in [false, true] {
        let mut b = s.bench(wm);
        if !ff {
            // Start from the steady state at i = 0: the q integrator holds the back EMF
            // ω_e·ψ_M the feed-forward would otherwise supply (u_q = k_i·I_q). Settling
            // into it from rest can take long: without decoupling, ω_e ≫ α leaves a
            // lightly damped cross-coupled mode.
            let psi = d.motor.flux_linkage_wb.unwrap_or(0.0);
            b.state.current.q.integral = (we * psi / d.current_loop.q.ki) as f32;
        }
        let (t, i) = run(&mut b, 20, current(0.0, 0.0, ff), n, current(0.0, a, ff));
        excursion[usize::from(ff)] = i.iter().map(|x| x[0].abs()).fold(0.0, f64::max);
        traces_i.push(i);
        t0 = t.iter().map(|x| x - t[0]).collect();
    }
    let ratio = excursion[0] / excursion[1];
    let checks = vec![
        check(
            format!(
                "i_d excursion without/with decoupling ({} / {})",
                format_value(excursion[0], "A"),
                format_value(excursion[1], "A")
            ),
            ratio,
            None,
            "×",
        )
        .criterion("≥ 3× smaller with decoupling (thesis A Figs. 5.4 vs 5.6)", ratio >= 3.0),
    ];
    let col = |k: usize, j: usize| traces_i[k].iter().map(|x| x[j]).collect::<Vec<_>>();
    let traces = vec![trace(
        format!(
            "i_q step {} at ω_e = {}",
            format_value(a, "A"),
            format_value(we, "rad/s")
        ),
        "current [A]",
        &t0,
        vec![
            series("i_d without decoupling", col(0, 0)),
            series("i_d with decoupling", col(1, 0)),
            series("i_q without decoupling", col(0, 1)),
            series("i_q with decoupling", col(1, 1)),
        ],
    )];
    ScenarioResult {
        id: "decoupling",
        title: format!(
            "i_q step of {} at ω_e = {} with and without the decoupling feed-forward",
            format_value(a, "A"),
            format_value(we, "rad/s")
        ),
        reference: "thesis A (5.3), Figs. 5.4, 5.6",
        checks,
        traces,
    }
}

/// Relative DC-link rise of [`dc_link_step`] when the design compensates no drop.
pub const DC_LINK_RISE: f64 = 0.2;

/// DC-link step at speed with i_q at the step amplitude: down to U_dc,min, the lowest
/// voltage the 1/U_dc feed-forward compensates (thesis A §5.1: 600 V → 432 V, the
/// discharged accumulator), or, when the design has U_dc,min = U_dc, up by
/// [`DC_LINK_RISE`] (regenerative braking).
///
/// Criterion. The 1/U_dc feed-forward (5.1) scales the duties with the U_dc sampled at
/// t_n, and they act during [t_{n+1}, t_{n+2}) (thesis A §4.6). A step between two
/// samples therefore goes uncompensated for exactly one period: the applied voltage is
/// off by ρ·u_dq (ρ = ΔU_dc/U_dc), which moves the current by the one-period kick
/// `Δi_1 = |ρ|·T_s·|(u_d/L_d, u_q/L_q)|` with the steady-state `u_d = −ω_e·L_q·i_q`,
/// `u_q = R·i_q + ω_e·ψ_M` (2.26). From the next sample on the voltage is right again
/// and the PI only removes that kick. Pass: peak current error ≤ 2·Δi_1 plus the ripple
/// already present before the step (harmonics, quantisation), and back within 1 % of
/// i_q plus that ripple after 10/α. For contrast the same step is run with the DC-link
/// reading frozen at the old value (no compensation): the PI alone then has to reject a
/// lasting ρ·u_dq disturbance.
pub fn dc_link_step(s: &Setup<'_>) -> ScenarioResult {
    let d = s.design;
    let m = &d.motor;
    let ts = d.drive.sample_period_s;
    let a = step_amplitude(s);
    let we = operating_speed(s);
    let wm = we / f64::from(m.pole_pairs);
    let u0 = d.drive.dc_link_voltage_v;
    let u_min = d.drive.dc_link_voltage_min_v;
    let u1 = if u_min < u0 { u_min } else { u0 * (1.0 + DC_LINK_RISE) };
    let rho = (u1 - u0).abs() / u0;
    let settle = samples(s, 10.0 / disturbance_pole(s) + 10.0 / d.current_loop.bandwidth_rad_s);
    let n = samples(s, 10.0 / d.current_loop.bandwidth_rad_s);
    let pre = n / 2;
    let err = |i: &[f64; 2]| (i[0] * i[0] + (i[1] - a) * (i[1] - a)).sqrt();
    let mut peak = [0.0; 2];
    let mut ripple = 0.0;
    let mut last = 0.0;
    let mut traces_iq = Vec::new();
    let mut t0 = Vec::new();
    for compensated in [true, false] {
        let mut b = s.bench(wm);
        let (_, before) = run(&mut b, settle, current(0.0, a, true), pre, current(0.0, a, true));
        let before_ripple = before.iter().map(err).fold(0.0, f64::max);
        b.plant.dc_link = u1;
        if !compensated {
            b.frozen_dc_link = Some(u0);
        }
        let (_, after) = run(&mut b, 0, current(0.0, a, true), n, current(0.0, a, true));
        peak[usize::from(!compensated)] = after.iter().map(err).fold(0.0, f64::max);
        if compensated {
            ripple = before_ripple;
            last = after.iter().rev().take(n / 10 + 1).map(err).fold(0.0, f64::max);
        }
        let mut iq: Vec<f64> = before.iter().map(|x| x[1]).collect();
        iq.extend(after.iter().skip(1).map(|x| x[1]));
        traces_iq.push(iq);
        t0 = (0..pre + n + 1).map(|k| (k as f64 - pre as f64) * ts).collect();
    }
    let ud = -we * m.q_inductance_h * a;
    let uq = m.phase_resistance_ohm * a + we * m.flux_linkage_wb.unwrap_or(0.0);
    let kick = rho * ts * ((ud / m.d_inductance_h).powi(2) + (uq / m.q_inductance_h).powi(2)).sqrt();
    let checks = vec![
        check(
            format!(
                "peak |i − i_ref| after U_dc {} → {} (uncompensated: {})",
                format_value(u0, "V"),
                format_value(u1, "V"),
                format_value(peak[1], "A")
            ),
            peak[0],
            Some(kick),
            "A",
        )
        .criterion(
            format!(
                "≤ 2·Δi_1 + ripple before the step ({}) — one-period kick of the 1/U_dc feed-forward (5.1)",
                format_value(ripple, "A")
            ),
            peak[0] <= 2.0 * kick + ripple,
        ),
        check("|i − i_ref| after 10/α", last, Some(0.0), "A").criterion(
            format!("≤ 1 % of i_q + ripple ({})", format_value(0.01 * a + ripple, "A")),
            last <= 0.01 * a + ripple,
        ),
    ];
    let traces = vec![trace(
        format!(
            "U_dc step {} → {} at t = 0",
            format_value(u0, "V"),
            format_value(u1, "V")
        ),
        "i_q [A]",
        &t0,
        vec![
            series("i_q with 1/U_dc feed-forward", traces_iq[0].clone()),
            series("i_q, U_dc reading frozen", traces_iq[1].clone()),
        ],
    )];
    ScenarioResult {
        id: "dc_link_step",
        title: format!(
            "DC-link step {:+.0} % at ω_e = {}, i_q = {}",
            (u1 / u0 - 1.0) * 100.0,
            format_value(we, "rad/s"),
            format_value(a, "A")
        ),
        reference: "thesis A (5.1), Fig. 5.2, §4.6",
        checks,
        traces,
    }
}

/// Time \[s\] for the continuous ATO (thesis A (4.12)–(4.14)) started `e0` rad off at rest
/// to stay within `threshold`: ë + K_p·ė + K_i·e = 0, e(0) = e0, ė(0) = −K_p·e0.
pub fn designed_lock_time(kp: f64, ki: f64, e0: f64, threshold: f64) -> f64 {
    let wn = ki.sqrt();
    let dt = 1e-3 / wn;
    let (mut e, mut v) = (e0, -kp * e0);
    let mut t = 0.0;
    let mut last_out = 0.0;
    let f = |e: f64, v: f64| (v, -kp * v - ki * e);
    while t < 60.0 / wn {
        let k1 = f(e, v);
        let k2 = f(e + dt / 2.0 * k1.0, v + dt / 2.0 * k1.1);
        let k3 = f(e + dt / 2.0 * k2.0, v + dt / 2.0 * k2.1);
        let k4 = f(e + dt * k3.0, v + dt * k3.1);
        e += dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        v += dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        t += dt;
        if e.abs() >= threshold {
            last_out = t;
        }
    }
    last_out
}

/// Initial observer error of [`ato_lock`] \[rad\].
pub const LOCK_INITIAL_ERROR: f64 = PI / 2.0;
/// Lock threshold \[rad\] (1°).
pub const LOCK_THRESHOLD: f64 = PI / 180.0;

/// Observer started π/2 away from the resolver angle at standstill (gates off).
pub fn ato_lock(s: &Setup<'_>) -> ScenarioResult {
    let o = &s.design.angle_observer;
    let ts = s.design.drive.sample_period_s;
    let mut b = s.bench(0.0);
    b.state.observer = AtoState::locked(from_radians_f64(b.plant.theta_r() - LOCK_INITIAL_ERROR), 0);
    let wn = o.natural_frequency_rad_s;
    let n = samples(s, 25.0 / (o.damping.min(1.0) * wn));
    let mut e = Vec::with_capacity(n);
    let mut unwrapped = Vec::with_capacity(n);
    let mut acc = 0.0f64;
    for k in 0..n {
        let smp = b.step(Demand::Off);
        let err = wrap(smp.theta_r - q31_angle(smp.out.theta_r));
        acc = if k == 0 { err } else { acc + wrap(err - acc) };
        e.push(err);
        unwrapped.push(acc);
    }
    let lock = settling_time(&e, ts, LOCK_THRESHOLD);
    let designed = designed_lock_time(o.kp, o.ki, LOCK_INITIAL_ERROR, LOCK_THRESHOLD);
    let slips = unwrapped.last().map_or(0.0, |x| (x / (2.0 * PI)).round().abs());
    // Started at +π/2 (estimate behind), the trig-identity error sin Δ is only 2/π of the
    // linear one at the start: allow 25 % over the linear design.
    let checks = vec![
        check(
            "lock time (|θ_r − θ̂_r| < 1° for good) from π/2",
            lock.map_or(f64::INFINITY, |t| t * 1e3),
            Some(designed * 1e3),
            "ms",
        )
        .criterion(
            "locks within 1.25× the linear design",
            lock.is_some_and(|t| t <= 1.25 * designed),
        ),
        check("cycle slips", slips, Some(0.0), "").criterion("0", slips == 0.0),
    ];
    let t: Vec<f64> = (0..n).map(|k| k as f64 * ts).collect();
    let deg = |v: &[f64]| v.iter().map(|x| x.to_degrees()).collect::<Vec<_>>();
    let linear: Vec<f64> = {
        // The designed linear response on the same grid, for the plot.
        let (kp, ki) = (o.kp, o.ki);
        let (mut x, mut v) = (LOCK_INITIAL_ERROR, -kp * LOCK_INITIAL_ERROR);
        let sub = 10;
        let h = ts / sub as f64;
        t.iter()
            .map(|_| {
                let out = x;
                for _ in 0..sub {
                    let acc = -kp * v - ki * x;
                    // Semi-implicit Euler on a 1/(10 f_s) grid: ω_n·h ≤ 1e-3, plot accuracy.
                    v += h * acc;
                    x += h * v;
                }
                out
            })
            .collect()
    };
    let traces = vec![trace(
        "ATO lock from π/2 at standstill",
        "θ_r − θ̂_r [°]",
        &t,
        vec![
            series("simulated (firmware ATO)", deg(&e)),
            series("designed (linear)", deg(&linear)),
        ],
    )];
    ScenarioResult {
        id: "ato_lock",
        title: format!(
            "Angle tracking observer locking from a π/2 error (ω_n = {}, ζ = {}, {})",
            format_value(wn, "rad/s"),
            o.damping,
            match o.error {
                ObserverError::TrigIdentity => "trig-identity error",
                ObserverError::Atan2 => "atan2 error",
            }
        ),
        reference: "thesis A (4.8)–(4.15), (4.19), (4.22)",
        checks,
        traces,
    }
}

/// Designed lag of [`ato_ramp`] as a fraction of K_i: a = 0.1·K_i → Δ = asin 0.1 (trig
/// identity) or 0.1 rad (atan2).
pub const RAMP_LAG_FRACTION: f64 = 0.1;

/// Speed ramp 0 → maximum speed at a = 0.1·K_i (resolver angle), then constant.
pub fn ato_ramp(s: &Setup<'_>) -> ScenarioResult {
    let d = s.design;
    let o = &d.angle_observer;
    let nr = f64::from(o.resolver_pole_pairs);
    // Design intent K_i = ω_n² (4.15); the Q1.31 integer realises it to ki_quantisation_error.
    let acc_r = RAMP_LAG_FRACTION * o.ki;
    let lag_design = match o.error {
        ObserverError::TrigIdentity => RAMP_LAG_FRACTION.asin(),
        ObserverError::Atan2 => RAMP_LAG_FRACTION,
    };
    let w_max = d.motor.max_speed_rad_s;
    let ramp = w_max / (acc_r / nr);
    let hold = 20.0 / (o.damping.min(1.0) * o.natural_frequency_rad_s);
    let profile = SpeedProfile {
        from: 0.0,
        to: w_max,
        start: 0.0,
        acceleration: acc_r / nr,
    };
    let mut b = Bench::new(s.cfg, s.plant(profile));
    let n = samples(s, ramp + hold);
    let mut t = Vec::with_capacity(n);
    let mut e = Vec::with_capacity(n);
    let mut w_true = Vec::with_capacity(n);
    let mut w_est = Vec::with_capacity(n);
    let speed_per_lsb = f64::from(s.cfg.speed_per_lsb);
    for _ in 0..n {
        let smp = b.step(Demand::Off);
        t.push(smp.t);
        e.push(wrap(smp.theta_r - q31_angle(smp.out.theta_r)));
        w_true.push(nr * smp.omega_m);
        w_est.push(f64::from(smp.out.omega_r) * speed_per_lsb);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let in_ramp: Vec<f64> = t
        .iter()
        .zip(&e)
        .filter(|(t, _)| **t >= 0.5 * ramp && **t < ramp)
        .map(|(_, e)| *e)
        .collect();
    let lag = mean(&in_ramp);
    let tail = (n / 10).max(1).min(samples(s, 0.25 * hold).max(1));
    let e_ss = e.iter().rev().take(tail).fold(0.0f64, |m, x| m.max(x.abs()));
    let w_err = mean(&w_est[n - tail..]) - mean(&w_true[n - tail..]);
    // Integer dead zone (ato.rs): the integral term K̃_i·ẽ^i rounds to 0 while
    // |ẽ^i| < 2^30/K̃_i^i, i.e. |sin Δ| < 1/(2·K̃_i^i) (trig) or |Δ| < π/(2·K̃_i^i) (atan2).
    let dead = match o.error {
        ObserverError::TrigIdentity => (0.5 / f64::from(o.ki_q31)).min(1.0).asin(),
        ObserverError::Atan2 => PI * 0.5 / f64::from(o.ki_q31),
    };
    let checks = vec![
        check(
            format!("angle lag during the ramp (a = {})", format_value(acc_r, "rad/s²")),
            lag.to_degrees(),
            Some(lag_design.to_degrees()),
            "°",
        )
        .criterion(
            "within 10 % of designed (type-2 loop: sin Δ = a/K_i)",
            (lag / lag_design - 1.0).abs() <= 0.10,
        ),
        check(
            format!(
                "angle error at {} (constant speed)",
                format_value(w_max * 30.0 / PI, "rpm")
            ),
            e_ss.to_degrees(),
            Some(0.0),
            "°",
        )
        .criterion(
            format!(
                "zero: ≤ 2× the Q1.31 integral dead zone ({})",
                format_value(dead.to_degrees(), "°")
            ),
            e_ss <= 2.0 * dead,
        ),
        check("speed error at constant speed", w_err, Some(0.0), "rad/s").criterion(
            format!("≤ 0.1 % of ω_r,max ({})", format_value(1e-3 * nr * w_max, "rad/s")),
            w_err.abs() <= 1e-3 * nr * w_max,
        ),
    ];
    let traces = vec![
        trace(
            "ATO angle error on a speed ramp to the maximum speed",
            "θ_r − θ̂_r [°]",
            &t,
            vec![series("simulated", e.iter().map(|x| x.to_degrees()).collect())],
        ),
        trace(
            "ATO speed on the ramp",
            "resolver speed [rad/s]",
            &t,
            vec![series("true", w_true), series("observed ω̂_r", w_est)],
        ),
    ];
    ScenarioResult {
        id: "ato_ramp",
        title: format!(
            "Angle tracking observer on a ramp 0 → {} at {} (resolver)",
            format_value(w_max * 30.0 / PI, "rpm"),
            format_value(acc_r, "rad/s²")
        ),
        reference: "thesis A §4.4 (4.12)–(4.15), (4.22)",
        checks,
        traces,
    }
}
