//! The standard scenarios. Each returns measured vs designed figures and a criterion:
//!
//! * [`current_step`] — i_d and i_q reference steps at standstill: rise time within 10 %
//!   of the designed one (ln 9/α, thesis A (5.8), thesis B (2.41); the second-order step
//!   of (5.14)–(5.16)) when the design compensates the delay, within 5 % of the design's
//!   sampled-loop prediction always, overshoot within the design's floor (designed + 2 %,
//!   `design::current_loop::analysis`).
//! * [`decoupling()`] — i_q step at speed with and without the feed-forward (5.3): the
//!   i_d excursion must shrink at least 3× (thesis A Figs. 5.4 vs 5.6); its operating
//!   point and criterion are the design's (`codegen::design::current_loop::decoupling`),
//!   whose bandwidth search judges the same figure on a model of the loop.
//! * [`dc_link_step`] — U_dc drops 20 % at speed under load; the 1/U_dc feed-forward
//!   (5.1) must limit the current error to the one-period kick (criterion below).
//!
//! The angle-observer scenarios are in [`super::observer`].

use motor_control::step::Demand;

use super::figures::{designed_rise_time, designed_step};
use super::{Check, ScenarioResult, Series, Setup, Trace, format_value};
use codegen::design::Design;
use codegen::design::current_loop::analysis::{OVERSHOOT_ALLOWANCE_PCT, RISE_TOLERANCE};
use codegen::design::current_loop::at_speed::{
    self as decoupling, KICK_ALLOWANCE, MIN_DECOUPLING_RATIO, SETTLED_SHARE,
};
use codegen::spec::Method;
use motor_sim::bench::Bench;
use motor_sim::figures::step_figures;

/// Most points kept per trace (the report plots them; more adds bytes, not information).
const TRACE_POINTS: usize = 1500;

pub(super) fn check(quantity: impl Into<String>, measured: f64, designed: Option<f64>, unit: &'static str) -> Check {
    Check {
        quantity: quantity.into(),
        measured,
        designed,
        limit: None,
        unit,
        criterion: String::new(),
        pass: false,
    }
}

impl Check {
    /// The criterion's bound ([`Check::limit`]).
    pub(super) fn limit(mut self, bound: f64) -> Check {
        self.limit = Some(bound);
        self
    }

    pub(super) fn criterion(mut self, text: impl Into<String>, pass: bool) -> Check {
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

pub(super) fn series(label: impl Into<String>, values: Vec<f64>) -> Series {
    Series {
        label: label.into(),
        values,
    }
}

/// Samples for `seconds` at T_s.
pub(super) fn samples(s: &Setup<'_>, seconds: f64) -> usize {
    (seconds / s.design.drive.sample_period_s).ceil() as usize
}

/// Current step height \[A\]: a quarter of the current-circle radius √2·I_peak, kept so
/// that the proportional kick k_p·Δi stays within half the voltage circle (so the
/// linear design is what is measured, not the voltage limit) — the design's
/// `current_loop::decoupling::step_amplitude`, which its bandwidth search judges with.
pub fn step_amplitude(s: &Setup<'_>) -> f64 {
    let d = s.design;
    let kp = d.current_loop.d.kp.max(d.current_loop.q.kp);
    decoupling::step_amplitude(d.motor.peak_current_a, kp, d.current_loop.voltage_limit_v)
}

/// Slowest pole [rad/s] of the current loop's response to a voltage disturbance
/// (`codegen::design::current_loop::at_speed::disturbance_pole`): R/L for IMC, α for
/// active damping, ζω_n for pole placement.
pub fn disturbance_pole(s: &Setup<'_>) -> f64 {
    let d = s.design;
    let cl = &d.current_loop;
    decoupling::disturbance_pole(
        cl.method,
        d.motor.phase_resistance_ohm,
        d.motor.d_inductance_h.max(d.motor.q_inductance_h),
        cl.bandwidth_rad_s,
        cl.damping.unwrap_or(1.0),
        cl.natural_frequency_rad_s.unwrap_or(cl.bandwidth_rad_s),
    )
}

/// Electrical speed [rad/s] of the at-speed scenarios: the back EMF ω_e·ψ_M at half the
/// voltage circle, the coupling ω_e·L_q·Δi at most 30 % of it, not above ω_e,max.
pub fn operating_speed(s: &Setup<'_>) -> f64 {
    let d = s.design;
    decoupling::operating_speed(
        d.motor.max_electrical_speed_rad_s,
        d.motor.flux_linkage_wb,
        d.motor.q_inductance_h,
        step_amplitude(s),
        d.current_loop.voltage_limit_v,
    )
}

fn current(id: f64, iq: f64, feed_forward: bool) -> Demand {
    Demand::Current {
        id: id as f32,
        iq: iq as f32,
        feed_forward,
    }
}

/// Samples of [`current_step`]'s record after the step: 12/α at T_s (the error after
/// 12/α is judged on the last one).
pub fn current_step_samples(s: &Setup<'_>) -> usize {
    samples(s, 12.0 / s.design.current_loop.bandwidth_rad_s)
}

/// [`current_step`]'s criteria for one axis (`k` = 0: d, 1: q) of `design`: `y` is the
/// true current sampled every T_s, `y[0]` at the sample where the step is first
/// processed, then [`current_step_samples`] more; `target` \[A\] the reference after the
/// step. Rise time within [`RISE_TOLERANCE`] of the designed one (delay-compensated
/// designs), within 5 % of the sampled-loop prediction, overshoot within the design's
/// floor, error after 12/α ≤ 1 %. Also used by the emulated image's closed loop
/// (`motor-emulator`, `tests/closed_loop.rs`), so both are judged alike.
pub fn current_step_checks(d: &Design, k: usize, y: &[f64], target: f64) -> Vec<Check> {
    let cl = &d.current_loop;
    let ts = d.drive.sample_period_s;
    let axis = if k == 0 { "d" } else { "q" };
    let rise_design = cl
        .rise_time_s
        .unwrap_or_else(|| designed_rise_time(cl.bandwidth_rad_s, second_order(d)));
    let mut checks = Vec::new();
    let f = step_figures(y, ts, y[0], target);
    let rise = f.rise_time * 1e3;
    let want = rise_design * 1e3;
    if cl.compensate_delay {
        // The design promises the requested α in the sampled loop (`current_loop::discrete`).
        let rise_ok = (f.rise_time / rise_design - 1.0).abs() <= RISE_TOLERANCE;
        checks.push(
            check(format!("{axis}-axis rise time 10–90 %"), rise, Some(want), "ms")
                .limit(want * (1.0 + RISE_TOLERANCE))
                .criterion(
                    format!(
                        "within {:.0} % of designed (continuous, delay-compensated)",
                        RISE_TOLERANCE * 100.0
                    ),
                    rise_ok,
                ),
        );
    }
    // The same gains in the design's sampled-loop model (`current_loop::analysis`, T_s,
    // the design's loop delay): tells a sampling effect (both measured and predicted off the
    // design) from an implementation fault (measured off the prediction).
    let g = if k == 0 { &cl.d } else { &cl.q };
    let predicted = g.sampled.rise_time_s.unwrap_or(f64::NAN);
    checks.push(
        check(
            format!(
                "{axis}-axis rise time vs the sampled loop (T_s, {:.4}·T_s delay)",
                g.sampled.loop_delay_periods
            ),
            rise,
            Some(predicted * 1e3),
            "ms",
        )
        .limit(predicted * 1e3 * 1.05)
        .criterion(
            "within 5 % of the design's z-domain prediction",
            (f.rise_time / predicted - 1.0).abs() <= 0.05,
        ),
    );
    let limit = cl.floors.max_overshoot_pct;
    checks.push(
        check(
            format!("{axis}-axis overshoot"),
            f.overshoot * 100.0,
            g.sampled.overshoot_pct,
            "%",
        )
        .limit(limit)
        .criterion(
            format!(
                "≤ {limit:.1} % (designed {:.1} % + {OVERSHOOT_ALLOWANCE_PCT} %, the design's floor)",
                cl.overshoot * 100.0
            ),
            f.overshoot * 100.0 <= limit,
        ),
    );
    checks.push(
        check(
            format!("{axis}-axis error after 12/α"),
            f.final_error.abs() * 100.0,
            Some(0.0),
            "%",
        )
        .limit(1.0)
        .criterion("≤ 1 % (integral action)", f.final_error.abs() <= 0.01),
    );
    checks
}

/// ω_n and ζ of a pole-placement design (the second-order step of thesis A (5.14)–(5.16)).
fn second_order(d: &Design) -> Option<(f64, f64)> {
    let cl = &d.current_loop;
    match cl.method {
        Method::PolePlacement => Some((
            cl.natural_frequency_rad_s.unwrap_or(cl.bandwidth_rad_s),
            cl.damping.unwrap_or(std::f64::consts::FRAC_1_SQRT_2),
        )),
        _ => None,
    }
}

/// i_d and i_q reference steps at standstill (feed-forward on, ω = 0).
pub fn current_step(s: &Setup<'_>) -> ScenarioResult {
    let d = s.design;
    let cl = &d.current_loop;
    let ts = d.drive.sample_period_s;
    let a = step_amplitude(s);
    let alpha = cl.bandwidth_rad_s;
    let second = second_order(d);
    let n = current_step_samples(s);
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
        checks.extend(current_step_checks(d, k, &y, a));
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
        reached_speed_rpm: None,
        torque_speed: None,
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
    let n = samples(s, decoupling::STEP_SPANS / d.current_loop.bandwidth_rad_s);
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
        let (t, i) = run(
            &mut b,
            decoupling::SETTLE_PERIODS,
            current(0.0, 0.0, ff),
            n,
            current(0.0, a, ff),
        );
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
        .limit(MIN_DECOUPLING_RATIO)
        .criterion(
            format!("≥ {MIN_DECOUPLING_RATIO}× smaller with decoupling (thesis A Figs. 5.4 vs 5.6)"),
            ratio >= MIN_DECOUPLING_RATIO,
        ),
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
        reached_speed_rpm: None,
        torque_speed: None,
    }
}

/// Relative DC-link rise of [`dc_link_step`] when the design compensates no drop (the
/// design's `at_speed::DC_LINK_RISE`).
pub const DC_LINK_RISE: f64 = decoupling::DC_LINK_RISE;

/// DC-link step at speed with i_q at the step amplitude: down to U_dc,min, the lowest
/// voltage the 1/U_dc feed-forward compensates (thesis A §5.1: 600 V → 432 V, the
/// discharged accumulator), or, when the design has U_dc,min = U_dc, up by
/// [`DC_LINK_RISE`] (regenerative braking).
///
/// Criterion. The 1/U_dc feed-forward (5.1) scales the duties with the U_dc sampled at
/// t_n, and they act for the period after the next update (thesis A §4.6). A step between two
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
    let u1 = decoupling::dc_link_after(u0, u_min);
    let rho = (u1 - u0).abs() / u0;
    let spans = decoupling::STEP_SPANS;
    let settle = samples(s, spans / disturbance_pole(s) + spans / d.current_loop.bandwidth_rad_s);
    let n = samples(s, spans / d.current_loop.bandwidth_rad_s);
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
        .limit(KICK_ALLOWANCE * kick + ripple)
        .criterion(
            format!(
                "≤ {KICK_ALLOWANCE}·Δi_1 + ripple before the step ({}) — one-period kick of the 1/U_dc feed-forward (5.1)",
                format_value(ripple, "A")
            ),
            peak[0] <= KICK_ALLOWANCE * kick + ripple,
        ),
        check("|i − i_ref| after 10/α", last, Some(0.0), "A")
            .limit(SETTLED_SHARE * a + ripple)
            .criterion(
                format!(
                    "≤ {} % of i_q + ripple ({})",
                    SETTLED_SHARE * 100.0,
                    format_value(SETTLED_SHARE * a + ripple, "A")
                ),
                last <= SETTLED_SHARE * a + ripple,
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
        reached_speed_rpm: None,
        torque_speed: None,
    }
}
