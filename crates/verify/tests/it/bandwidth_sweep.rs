//! `check`'s verdict on the current loop against `verify`'s measured step, swept over the
//! bandwidth α for each method on every motor in `motors/`.
//!
//! At each α (a fraction of ω_s = 2π·f_s) the spec's `[current_loop]` is replaced by the
//! method at α (ζ = 1/√2 for pole placement, delay compensation on: the default):
//!
//! * accepted ⇒ the firmware's control step in the simulated drive (`current_step`)
//!   passes every criterion: rise time, overshoot within the design's floor, settling;
//! * refused at `current_loop.bandwidth` ⇒ the message names a largest bandwidth below α;
//!   the design at that bandwidth is accepted and its `current_step` passes; and the
//!   refused gains, put into that design, fail `current_step` when the refusal was for a
//!   margin or overshoot breach (the sampled loop's prediction, checked on the firmware's
//!   fixed-point step and the continuous plant).
//!
//! Errors at other keys (a right-half-plane zero of pole placement, field-weakening or
//! estimator rules that depend on α_c) are not current-loop feasibility verdicts and are
//! skipped; the test requires enough accepted and refused points to mean something.

use codegen::design::Design;
use codegen::design::current_loop;
use codegen::{Source, design, spec};
use motor_verify::{Setup, scenarios::current_step};

/// `text` with its `[current_loop]` section replaced by `body`.
fn with_loop(text: &str, body: &str) -> String {
    let start = text.find("\n[current_loop]").expect("a [current_loop] section") + 1;
    let rest = &text[start + 1..];
    let end = rest.find("\n[").map_or(text.len(), |i| start + 1 + i + 1);
    format!("{}[current_loop]\n{body}\n{}", &text[..start], &text[end..])
}

fn body(method: &str, alpha: f64, compensate: bool) -> String {
    let damping = if method == "pole_placement" {
        "\ndamping = 0.7071"
    } else {
        ""
    };
    format!("method = \"{method}\"\nbandwidth = \"{alpha:.1} rad/s\"{damping}\ncompensate_delay = {compensate}")
}

enum Verdict {
    Accepted(Box<(spec::Spec, Design)>),
    /// Refused at `current_loop.bandwidth` by the sampled-loop floors: the problem text,
    /// the largest bandwidth named, and what is accepted.
    Refused(String, Option<f64>, String),
    /// Refused at `current_loop.bandwidth` by the at-speed figures (decoupling, DC-link
    /// step: issue 27), which `current_step` does not judge: the problem text and the
    /// largest bandwidth named.
    AtSpeed(String, Option<f64>),
    /// An error at another key.
    Other(String),
}

fn judge(file: &str, text: &str) -> Verdict {
    let src = Source { file, text };
    let s = spec::parse(src).unwrap_or_else(|e| panic!("{file}: {e:?}"));
    match design::design(&s, src) {
        Ok(d) => Verdict::Accepted(Box::new((s, d))),
        Err(e) => match e.0.iter().find(|d| d.key == "current_loop.bandwidth") {
            Some(d) => {
                let best = d
                    .accepted
                    .strip_prefix("a bandwidth up to ")
                    .and_then(|r| r.split(' ').next())
                    .and_then(|n| n.parse().ok());
                if d.problem.starts_with("at α = ") {
                    Verdict::AtSpeed(d.problem.clone(), best)
                } else {
                    Verdict::Refused(d.problem.clone(), best, d.accepted.clone())
                }
            }
            None => Verdict::Other(format!(
                "{:?}",
                e.0.iter().map(|d| (&d.key, &d.problem)).collect::<Vec<_>>()
            )),
        },
    }
}

/// Phase margins this close under the 45° floor are not required to fail the step \[°\].
const NEAR_FLOOR_DEG: f64 = 1.0;

/// The phase margin of a "phase margin X° < 45°" refusal \[°\].
fn phase_margin_breach(problem: &str) -> Option<f64> {
    let rest = &problem[problem.find("phase margin ")? + "phase margin ".len()..];
    let value = rest.split('°').next()?;
    rest[value.len()..]
        .starts_with("° < 45°")
        .then(|| value.parse().ok())
        .flatten()
}

/// Failed checks of `current_step` for `d`.
fn step_failures(s: &spec::Spec, d: &Design) -> Vec<String> {
    current_step(&Setup::new(s, d))
        .checks
        .iter()
        .filter(|c| !c.pass)
        .map(|c| format!("{}: {} ({})", c.quantity, c.measured, c.criterion))
        .collect()
}

#[test]
fn check_verdict_matches_the_simulated_step() {
    let (mut accepted, mut refused, mut unstable_seen) = (0, 0, 0);
    let mut problems = Vec::new();
    for stem in motor_test_support::motor_stems() {
        let text = std::fs::read_to_string(motor_test_support::repo().join(format!("motors/{stem}.toml"))).unwrap();
        let fs = {
            let src = Source {
                file: &stem,
                text: &text,
            };
            spec::parse(src).unwrap().drive.switching_frequency.value
        };
        let ws = 2.0 * std::f64::consts::PI * fs;
        // Delay compensation on (the default) at three bandwidths, and off at the two
        // higher ones, where the plain loop loses its margins or its stability.
        let points = [(0.02, true), (0.06, true), (0.2, true), (0.06, false), (0.2, false)];
        for method in ["imc", "pole_placement", "imc_active_damping"] {
            for (frac, compensate) in points {
                let alpha = frac * ws;
                let name = format!("{stem} {method} α = {alpha:.0} rad/s compensate_delay = {compensate}");
                match judge(&name, &with_loop(&text, &body(method, alpha, compensate))) {
                    Verdict::Accepted(sd) => {
                        accepted += 1;
                        let f = step_failures(&sd.0, &sd.1);
                        if !f.is_empty() {
                            problems.push(format!("{name}: accepted but current_step fails: {f:?}"));
                        }
                    }
                    Verdict::AtSpeed(problem, best) => {
                        // Judged by the at-speed scenarios, not the step: see
                        // `the_largest_bandwidth_check_names_passes_verify`.
                        println!("{name}: refused by the at-speed figures (named {best:?} rad/s): {problem}");
                    }
                    Verdict::Refused(problem, best, _) => {
                        refused += 1;
                        let Some(best) = best else {
                            println!("{name}: refused, no bandwidth meets the floors: {problem}");
                            continue;
                        };
                        if best >= alpha {
                            problems.push(format!("{name}: refused but names {best} rad/s ≥ α"));
                            continue;
                        }
                        // The named bandwidth is accepted and its step passes.
                        let sd = match judge(&name, &with_loop(&text, &body(method, best, compensate))) {
                            Verdict::Accepted(sd) => sd,
                            // A rule at another key that depends on α_c (the field-weakening
                            // rules of a fast-accelerating drive): not a current-loop verdict.
                            Verdict::Other(keys) => {
                                println!("{name}: the named {best} rad/s is refused at other keys: {keys}");
                                continue;
                            }
                            _ => {
                                problems.push(format!("{name}: the named {best} rad/s is not accepted"));
                                continue;
                            }
                        };
                        let (s, mut d) = *sd;
                        let f = step_failures(&s, &d);
                        if !f.is_empty() {
                            problems.push(format!("{name}: named {best} rad/s accepted but its step fails: {f:?}"));
                        }
                        // The refused gains in that design fail the step (margin or
                        // overshoot breaches; a rise-time breach is not about stability).
                        if problem.contains("rise time")
                            && !problem.contains("margin")
                            && !problem.contains("overshoot")
                        {
                            continue;
                        }
                        // A phase margin just under the 45° floor, alone, is a breach of the
                        // design rule the step's criteria (2 % overshoot, 10 % rise time)
                        // cannot see: amk-dd5-ipm's q axis at 0.06·ω_s has 44.2° and steps
                        // within them (fischer-ti085 at 43.2° fails them). Only breaches of more than
                        // NEAR_FLOOR_DEG must fail.
                        // (What was breached precedes "; the floors are …".)
                        let breach = problem.split("; the floors").next().unwrap_or(&problem);
                        if let Some(pm) = phase_margin_breach(breach)
                            && pm > 45.0 - NEAR_FLOOR_DEG
                            && !breach.contains("gain margin")
                            && !breach.contains("overshoot")
                            && !breach.contains("unstable")
                        {
                            println!(
                                "{name}: refused at phase margin {pm}°, within {NEAR_FLOOR_DEG}° of the floor: the step is not judged"
                            );
                            continue;
                        }
                        let m = &s.motor;
                        let zeta = s.current_loop.damping.as_ref().map_or(0.0, |z| z.value);
                        let ts = 1.0 / fs;
                        let r = m.phase_resistance.value;
                        // The loop delay of this board at this f_s, as the design has it.
                        let delay_s = d.current_loop.loop_delay_s;
                        let request = |axis, l| current_loop::Request {
                            method: s.current_loop.method,
                            axis,
                            resistance_ohm: r,
                            inductance_h: l,
                            bandwidth_rad_s: alpha,
                            damping: zeta,
                            sample_period_s: ts,
                            loop_delay_s: delay_s,
                            compensate_delay: compensate,
                        };
                        let (Ok(gd), Ok(gq)) = (
                            current_loop::design(&request(current_loop::Axis::D, m.d_inductance.value)),
                            current_loop::design(&request(current_loop::Axis::Q, m.q_inductance.value)),
                        ) else {
                            continue;
                        };
                        let unstable = gd.sampled.spectral_radius >= 1.0 || gq.sampled.spectral_radius >= 1.0;
                        unstable_seen += usize::from(unstable);
                        d.current_loop.d = gd;
                        d.current_loop.q = gq;
                        if step_failures(&s, &d).is_empty() {
                            problems.push(format!("{name}: refused ({problem}) but its gains pass current_step"));
                        }
                    }
                    Verdict::Other(keys) => println!("{name}: skipped (errors at {keys})"),
                }
            }
        }
    }
    println!("accepted {accepted}, refused {refused} (of which unstable in the model: {unstable_seen})");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert!(
        accepted >= 10 && refused >= 10 && unstable_seen >= 3,
        "accepted {accepted}, refused {refused}, unstable {unstable_seen}"
    );
}

/// The largest bandwidth `check` names passes `verify`: on every motor in `motors/` and
/// for every method (delay compensation on, ζ = 1/√2), a bandwidth of 40 % of ω_s is
/// refused at `current_loop.bandwidth` naming a largest one; that one is accepted and its
/// current-loop scenarios — the ones whose criteria depend on α: `current_step`,
/// `decoupling`, `dc_link_step` — pass every criterion. (Issue 27: the search judged
/// margins, overshoot and rise only; the bandwidth it named failed `decoupling` on every
/// motor, 2.66–2.80× against ≥ 3×.)
#[test]
fn the_largest_bandwidth_check_names_passes_verify() {
    let mut problems = Vec::new();
    let mut n = 0;
    for stem in motor_test_support::motor_stems() {
        let text = std::fs::read_to_string(motor_test_support::repo().join(format!("motors/{stem}.toml"))).unwrap();
        let fs = spec::parse(Source {
            file: &stem,
            text: &text,
        })
        .unwrap()
        .drive
        .switching_frequency
        .value;
        let alpha = 0.4 * 2.0 * std::f64::consts::PI * fs;
        for method in ["imc", "pole_placement", "imc_active_damping"] {
            let name = format!("{stem} {method}");
            let (problem, best) = match judge(&name, &with_loop(&text, &body(method, alpha, true))) {
                Verdict::Refused(problem, Some(best), _) | Verdict::AtSpeed(problem, Some(best)) => (problem, best),
                // No bandwidth meets both the floors and the at-speed figures (the
                // mit-mini-cheetah-actuator with active damping at 40 kHz: above R/L the
                // loop is too slow for the DC-link step before it is fast enough to breach
                // a floor): nothing is named, so nothing named can fail verify — but the
                // refusal must say so.
                Verdict::Refused(problem, None, accepted) if accepted.contains("at-speed figures") => {
                    println!("{name}: refused naming no bandwidth: {problem}; accepted: {accepted}");
                    continue;
                }
                _ => {
                    problems.push(format!(
                        "{name}: α = {alpha:.0} rad/s is not refused naming a bandwidth"
                    ));
                    continue;
                }
            };
            let Verdict::Accepted(sd) = judge(&name, &with_loop(&text, &body(method, best, true))) else {
                problems.push(format!("{name}: the named {best} rad/s is not accepted ({problem})"));
                continue;
            };
            let (s, d) = *sd;
            let setup = Setup::new(&s, &d);
            for scenario in [
                motor_verify::scenarios::current_step,
                motor_verify::scenarios::decoupling,
                motor_verify::scenarios::dc_link_step,
            ] {
                let r = scenario(&setup);
                for c in r.checks.iter().filter(|c| !c.pass) {
                    problems.push(format!(
                        "{name}: named {best} rad/s, {}: {} = {} ({})",
                        r.id, c.quantity, c.measured, c.criterion
                    ));
                }
                if r.id == "decoupling" {
                    println!("{name}: named {best} rad/s, decoupling {:.3}×", r.checks[0].measured);
                }
            }
            n += 1;
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert!(n >= 15, "{n} motor × method pairs");
}
