//! Resolver offset (thesis A §6.3, (6.9)) and pole-pair ratio with the direction check
//! (§6.4) from their recordings.
//!
//! Angles convert by (6.2): θ_e = n_p/n_r·(θ_r − θ_off).
//!
//! * Offset: +α voltage aligns the rotor with phase U (θ_e = 0), so θ_off = θ_r (6.9).
//!   The recording is the `ResolverOffset` run (`u_alpha_v`, `theta_r_rad`); the rows at
//!   full voltage are found, the first half of them is the settling time and θ_r is
//!   averaged (circular mean) over the second half, as the routine's averaging window
//!   does. The rotor can align at any of n_p electrical zeros, so θ_off is only defined
//!   modulo 2π·n_r/n_p (6.9 "not unique"); it is reported in [0, 2π·n_r/n_p), which
//!   also lets runs that aligned at different zeros be averaged.
//! * Ratio: the `PolePairRatio` run (`theta_e_rad` generated, `theta_r_rad` observed,
//!   either may be wrapped): both are unwrapped from row-to-row differences and
//!   n_p/n_r = |Δθ_e|/|Δθ_r|; the directions agree when both travels have one sign.

use std::f64::consts::{PI, TAU};

use super::recording::Recording;
use codegen::diagnostic::Diagnostics;

/// Wraps into [−π, π).
fn wrap(x: f64) -> f64 {
    x - TAU * ((x + PI) / TAU).floor()
}

/// θ_off from one alignment run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OffsetEstimate {
    /// θ_off in [0, 2π·n_r/n_p) [rad, resolver angle].
    pub offset_rad: f64,
    /// Largest deviation of θ_r from its mean in the averaging window \[rad\].
    pub deviation_rad: f64,
    /// Rows averaged.
    pub rows: usize,
}

/// Largest θ_r deviation in the averaging window accepted as "at rest", in electrical
/// degrees (converted to resolver angle with n_r/n_p).
pub const MAX_REST_DEVIATION_DEG_E: f64 = 2.0;

/// θ_off modulo 2π·n_r/n_p, in [0, 2π·n_r/n_p).
pub fn normalise_offset(theta: f64, motor_pole_pairs: u32, resolver_pole_pairs: u32) -> f64 {
    let k = f64::from(motor_pole_pairs) / f64::from(resolver_pole_pairs);
    (k * theta).rem_euclid(TAU) / k
}

/// Circular mean of offsets (each modulo 2π·n_r/n_p) and the largest deviation from it
/// [rad, resolver angle].
pub fn combine_offsets(offsets: &[f64], motor_pole_pairs: u32, resolver_pole_pairs: u32) -> Option<(f64, f64)> {
    if offsets.is_empty() {
        return None;
    }
    let k = f64::from(motor_pole_pairs) / f64::from(resolver_pole_pairs);
    let (s, c) = offsets
        .iter()
        .fold((0.0, 0.0), |(s, c), &o| (s + (k * o).sin(), c + (k * o).cos()));
    let mean = s.atan2(c);
    let dev = offsets
        .iter()
        .map(|&o| wrap(k * o - mean).abs() / k)
        .fold(0.0, f64::max);
    Some((normalise_offset(mean / k, motor_pole_pairs, resolver_pole_pairs), dev))
}

/// θ_off from a `resolver_offset` recording (6.9).
pub fn identify_offset(
    rec: &Recording,
    motor_pole_pairs: u32,
    resolver_pole_pairs: u32,
) -> Result<OffsetEstimate, Diagnostics> {
    let (Some(u), Some(th)) = (rec.series("u_alpha_v"), rec.series("theta_r_rad")) else {
        return Err(rec.error_at(
            0,
            "",
            "u_alpha_v or theta_r_rad missing",
            "sample,u_alpha_v,theta_r_rad",
        ));
    };
    let ucol = rec.column("u_alpha_v").unwrap_or(0) + 1;
    let tcol = rec.column("theta_r_rad").unwrap_or(0) + 1;
    let top = u.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if top <= 0.0 {
        return Err(rec.error_at_cell(
            0,
            ucol,
            "no alignment voltage found: u_alpha_v is never positive",
            "the ResolverOffset run: a positive α voltage (ramp, settle, average)",
        ));
    }
    let full: Vec<usize> = (0..u.len()).filter(|&k| u[k] >= top * (1.0 - 1e-6)).collect();
    let window = &full[full.len() / 2..];
    if window.len() < 4 {
        return Err(rec.error_at_cell(
            rec.samples.len() - 1,
            0,
            format!("the recording is too short: {} rows at full voltage", full.len()),
            "at least 8 rows at full voltage (half settling, half averaged)",
        ));
    }
    let (s, c) = window
        .iter()
        .fold((0.0, 0.0), |(s, c), &k| (s + th[k].sin(), c + th[k].cos()));
    let mean = s.atan2(c);
    let (worst, deviation) = window
        .iter()
        .map(|&k| (k, wrap(th[k] - mean).abs()))
        .fold((window[0], 0.0), |a, b| if b.1 > a.1 { b } else { a });
    let limit = MAX_REST_DEVIATION_DEG_E.to_radians() * f64::from(resolver_pole_pairs) / f64::from(motor_pole_pairs);
    if deviation > limit {
        return Err(rec.error_at_cell(
            worst,
            tcol,
            format!(
                "the rotor is not at rest while θ_r is averaged: θ_r deviates {deviation:.4} rad from its mean (limit {limit:.4} rad = {MAX_REST_DEVIATION_DEG_E}° electrical)"
            ),
            "a longer settling time (ResolverOffset::settle_samples) or an unloaded shaft",
        ));
    }
    Ok(OffsetEstimate {
        offset_rad: normalise_offset(mean, motor_pole_pairs, resolver_pole_pairs),
        deviation_rad: deviation,
        rows: window.len(),
    })
}

/// n_p/n_r and the direction from one rotation run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RatioEstimate {
    /// |Δθ_e|/|Δθ_r|.
    pub ratio: f64,
    /// Both angles travelled in the same direction.
    pub directions_agree: bool,
    /// Generated electrical travel \[rad\].
    pub electrical_travel_rad: f64,
    /// Observed resolver travel \[rad\].
    pub resolver_travel_rad: f64,
}

/// n_p/n_r from a `pole_pair_ratio` recording (§6.4).
pub fn identify_ratio(rec: &Recording) -> Result<RatioEstimate, Diagnostics> {
    let (Some(te), Some(tr)) = (rec.series("theta_e_rad"), rec.series("theta_r_rad")) else {
        return Err(rec.error_at(
            0,
            "",
            "theta_e_rad or theta_r_rad missing",
            "sample,theta_e_rad,theta_r_rad",
        ));
    };
    let travel = |x: &[f64]| x.windows(2).map(|w| wrap(w[1] - w[0])).sum::<f64>();
    let (e, r) = (travel(&te), travel(&tr));
    let last = rec.samples.len() - 1;
    if e.abs() < PI {
        return Err(rec.error_at_cell(
            last,
            1 + rec.column("theta_e_rad").unwrap_or(0),
            format!("the generated field turned only {e:.3} rad: too short a rotation"),
            "a PolePairRatio run of at least one electrical turn",
        ));
    }
    if r.abs() < PI / 2.0 {
        return Err(rec.error_at_cell(
            last,
            1 + rec.column("theta_r_rad").unwrap_or(0),
            format!("the rotor did not turn: the resolver travelled {r:.3} rad (less than a quarter turn)"),
            "a run with the rotor free to follow the field (brake released, low load)",
        ));
    }
    Ok(RatioEstimate {
        ratio: e.abs() / r.abs(),
        directions_agree: (e > 0.0) == (r > 0.0),
        electrical_travel_rad: e,
        resolver_travel_rad: r,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recording::{self, RecordingKind};

    /// n_p = 4, n_r = 1: electrical zeros every π/2 of resolver angle, so θ_r = 2.0 rad
    /// is the offset 2.0 − π/2 = 0.4292 rad, and −0.1 rad is −0.1 + π/2 = 1.4708 rad.
    #[test]
    fn offsets_are_reduced_modulo_an_electrical_turn() {
        assert!((normalise_offset(2.0, 4, 1) - (2.0 - PI / 2.0)).abs() < 1e-12);
        assert!((normalise_offset(-0.1, 4, 1) - (PI / 2.0 - 0.1)).abs() < 1e-12);
        // Runs aligned at different zeros average: 0.3 and 0.3 + π/2 + 0.002.
        let (m, d) = combine_offsets(&[0.3, 0.302 + PI / 2.0], 4, 1).unwrap();
        assert!((m - 0.301).abs() < 1e-9 && (d - 0.001).abs() < 1e-9, "{m} {d}");
        // Across the wrap: 0.001 and π/2 − 0.001 average to 0 (reported as 0 or π/2).
        let (m, _) = combine_offsets(&[0.001, PI / 2.0 - 0.001], 4, 1).unwrap();
        assert!(m.min(PI / 2.0 - m) < 1e-9, "{m}");
    }

    fn offset_rec(theta: &dyn Fn(usize) -> f64) -> Recording {
        let mut t = String::from("# motorgen recording: resolver_offset\nsample,u_alpha_v,theta_r_rad\n");
        for k in 0..100 {
            let u = if k < 10 { k as f64 / 10.0 } else { 1.0 };
            t.push_str(&format!("{k},{u},{}\n", theta(k)));
        }
        recording::parse("o.csv", &t, RecordingKind::ResolverOffset, 50e-6).unwrap()
    }

    /// θ_r settles at π − 0.002 ± 0.004 rad (samples wrap across ±π in the window): θ_off
    /// for n_p = 4, n_r = 1 is π − 0.002 − π/2 = π/2 − 0.002 rad. The 90 rows at full voltage are
    /// half settling, half (45) averaged.
    #[test]
    fn offset_from_alignment_run() {
        let rec = offset_rec(&|k| {
            if k < 40 {
                1.0
            } else {
                wrap(PI - 0.002 + if k % 2 == 0 { 0.004 } else { -0.004 })
            }
        });
        let e = identify_offset(&rec, 4, 1).unwrap();
        // 45 rows (23 high, 22 low): the mean is π − 0.002 + 0.004/45.
        assert!((e.offset_rad - (PI / 2.0 - 0.002)).abs() < 1e-4, "{e:?}");
        assert_eq!(e.rows, 45);
        let moving = offset_rec(&|k| 0.01 * k as f64);
        let err = identify_offset(&moving, 4, 1).unwrap_err().0[0].clone();
        assert!(err.problem.contains("not at rest"), "{err}");
    }

    /// 8 electrical turns forward, resolver 2 turns backwards (wrapped): ratio 4,
    /// directions disagree.
    #[test]
    fn ratio_and_direction() {
        let mut t = String::from("sample,theta_e_rad,theta_r_rad\n");
        for k in 0..=800 {
            let e = TAU * 8.0 * k as f64 / 800.0;
            t.push_str(&format!("{k},{},{}\n", wrap(e), wrap(-e / 4.0 + 0.3)));
        }
        let rec = recording::parse("r.csv", &t, RecordingKind::PolePairRatio, 50e-6).unwrap();
        let e = identify_ratio(&rec).unwrap();
        assert!((e.ratio - 4.0).abs() < 1e-9, "{e:?}");
        assert!(!e.directions_agree);
        let mut t = String::from("sample,theta_e_rad,theta_r_rad\n");
        for k in 0..=800 {
            t.push_str(&format!("{k},{},0.5\n", wrap(TAU * 8.0 * k as f64 / 800.0)));
        }
        let rec = recording::parse("r.csv", &t, RecordingKind::PolePairRatio, 50e-6).unwrap();
        assert!(
            identify_ratio(&rec).unwrap_err().0[0]
                .clone()
                .problem
                .contains("did not turn")
        );
    }
}
