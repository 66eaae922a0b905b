//! Permanent-magnet flux linkage ψ_M from a zero-current run at steady speed,
//! thesis A §6.5.
//!
//! With the rotor driven at a steady speed and both current references at 0 A, the
//! steady-state q equation of (6.1) leaves u_q ≈ ω_e·ψ_M (6.10); the firmware's
//! `FluxLinkage` routine accumulates ψ_M = Σu_q/Σω_e. When the recording also has the
//! measured currents, the small residual terms of the steady-state (6.1) are removed
//! instead of neglected: ψ_M = Σ(u_q − R·i_q − ω_e·L_d·i_d)/Σω_e.

use super::recording::Recording;
use codegen::diagnostic::Diagnostics;

/// What the design fixes for the ψ_M estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FluxSetup {
    /// R_s \[Ω\] (residual-term correction).
    pub resistance_ohm: f64,
    /// L_d \[H\] (residual-term correction).
    pub d_inductance_h: f64,
    /// |i_dq| above which the run is not "at zero current" \[A\].
    pub max_current_a: f64,
    /// |ω_e| below which R·i would not be negligible against the back EMF [rad/s].
    pub min_speed_rad_s: f64,
    /// Inverter voltage limit U_dc/√3 \[V\]: u_q at it means the loop was not in control.
    pub voltage_limit_v: f64,
}

/// ψ_M from one recording.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FluxEstimate {
    /// ψ_M \[Wb\].
    pub flux_linkage_wb: f64,
    /// Mean ω_e [rad/s].
    pub mean_speed_rad_s: f64,
    /// The part of ψ_M removed by the current correction \[Wb\] (0 without current columns).
    pub correction_wb: f64,
}

/// Fewest rows accepted.
pub const MIN_ROWS: usize = 10;
/// Largest (max − min)/|mean| of ω_e accepted as "steady speed".
pub const MAX_SPEED_VARIATION: f64 = 0.05;

/// ψ_M from a `flux` recording (6.10).
pub fn identify_flux(rec: &Recording, setup: &FluxSetup) -> Result<FluxEstimate, Diagnostics> {
    let n = rec.samples.len();
    let (Some(w), Some(uq)) = (rec.series("omega_e_rad_s"), rec.series("u_q_v")) else {
        return Err(rec.error_at(0, "", "omega_e_rad_s or u_q_v missing", "sample,omega_e_rad_s,u_q_v"));
    };
    let wcol = rec.column("omega_e_rad_s").unwrap_or(0) + 1;
    let ucol = rec.column("u_q_v").unwrap_or(0) + 1;
    if n < MIN_ROWS {
        return Err(rec.error_at_cell(
            n - 1,
            0,
            format!("the recording is too short: {n} rows"),
            format!("at least {MIN_ROWS} rows at steady speed (FluxLinkage::average_samples)"),
        ));
    }
    let mean_w = w.iter().sum::<f64>() / n as f64;
    if let Some(k) = w.iter().position(|&x| x * mean_w <= 0.0) {
        return Err(rec.error_at_cell(
            k,
            wcol,
            "the speed is zero or changes sign: not a steady-speed run",
            "a run at one steady speed in one direction",
        ));
    }
    if mean_w.abs() < setup.min_speed_rad_s {
        return Err(rec.error_at_cell(
            0,
            wcol,
            format!(
                "the speed {:.1} rad/s is too slow: below {:.1} rad/s the back EMF does not dominate R·i (6.10)",
                mean_w.abs(),
                setup.min_speed_rad_s
            ),
            "a run at a higher, steady speed (e.g. driven by a dynamometer)",
        ));
    }
    let (lo, hi) = w
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
    if (hi - lo) / mean_w.abs() > MAX_SPEED_VARIATION {
        let k = w
            .iter()
            .position(|&x| (x - mean_w).abs() >= 0.5 * (hi - lo))
            .unwrap_or(0);
        return Err(rec.error_at_cell(
            k,
            wcol,
            format!(
                "the speed varies from {lo:.1} to {hi:.1} rad/s ({:.1} %): not a steady speed",
                100.0 * (hi - lo) / mean_w.abs()
            ),
            format!(
                "a run whose speed varies by at most {:.0} %",
                100.0 * MAX_SPEED_VARIATION
            ),
        ));
    }
    if let Some(k) = uq.iter().position(|u| u.abs() >= setup.voltage_limit_v) {
        return Err(rec.error_at_cell(
            k,
            ucol,
            format!(
                "u_q = {} V reaches the voltage limit U_dc/√3 = {:.1} V: saturated, the current loop was not in control",
                uq[k], setup.voltage_limit_v
            ),
            "a run at a speed where the back EMF stays below U_dc/√3",
        ));
    }
    let currents = rec.series("i_d_a").zip(rec.series("i_q_a"));
    let mut correction = 0.0;
    if let Some((id, iq)) = &currents {
        let icol = rec.column("i_d_a").unwrap_or(0) + 1;
        if let Some(k) = (0..n).find(|&k| id[k].hypot(iq[k]) > setup.max_current_a) {
            return Err(rec.error_at_cell(
                k,
                icol,
                format!(
                    "|i_dq| = {:.3} A is not near zero (limit {:.3} A): the loop did not hold i = 0",
                    id[k].hypot(iq[k]),
                    setup.max_current_a
                ),
                "a run with both current references at 0 A and the feed-forward off (§6.5)",
            ));
        }
        let residual: f64 = (0..n)
            .map(|k| setup.resistance_ohm * iq[k] + w[k] * setup.d_inductance_h * id[k])
            .sum();
        correction = residual / w.iter().sum::<f64>();
    }
    let psi = uq.iter().sum::<f64>() / w.iter().sum::<f64>() - correction;
    if psi <= 0.0 {
        return Err(rec.error_at_cell(
            0,
            ucol,
            format!("u_q and ω_e have opposite signs (ψ_M would be {psi:.5} Wb)"),
            "u_q in the direction of rotation: check the phase order and the resolver direction (identify resolver)",
        ));
    }
    Ok(FluxEstimate {
        flux_linkage_wb: psi,
        mean_speed_rad_s: mean_w,
        correction_wb: correction,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recording::{self, RecordingKind};

    fn setup() -> FluxSetup {
        FluxSetup {
            resistance_ohm: 0.126,
            d_inductance_h: 0.393e-3,
            max_current_a: 5.0,
            min_speed_rad_s: 100.0,
            voltage_limit_v: 346.0,
        }
    }

    /// Fischer (thesis A Table 1.2): ψ_M = 0.058 Wb; at ω_e = 800 rad/s u_q = 46.4 V.
    /// With i_d = −1 A, i_q = 2 A the recorded u_q also holds R·i_q + ω_e·L_d·i_d =
    /// 0.252 − 0.3144 = −0.0624 V, which the correction removes: ψ_M = 0.058 exactly.
    #[test]
    fn flux_with_current_correction() {
        let mut text = String::from("# motorgen recording: flux\nsample,omega_e_rad_s,u_q_v,i_d_a,i_q_a\n");
        for n in 0..20 {
            let w = 800.0 + if n % 2 == 0 { 1.0 } else { -1.0 };
            let uq = w * 0.058 + 0.126 * 2.0 + -(w * 0.393e-3);
            text.push_str(&format!("{n},{w},{uq},-1,2\n"));
        }
        let rec = recording::parse("f.csv", &text, RecordingKind::Flux, 50e-6).unwrap();
        let e = identify_flux(&rec, &setup()).unwrap();
        assert!((e.flux_linkage_wb - 0.058).abs() < 1e-12, "{e:?}");
        assert!((e.correction_wb - (0.252 / 800.0 - 0.393e-3)).abs() < 1e-12, "{e:?}");
    }

    #[test]
    fn unsteady_slow_and_short_runs_are_rejected() {
        let rows = |f: &dyn Fn(usize) -> (f64, f64), n: usize| {
            let mut t = String::from("sample,omega_e_rad_s,u_q_v\n");
            for k in 0..n {
                let (w, u) = f(k);
                t.push_str(&format!("{k},{w},{u}\n"));
            }
            recording::parse("f.csv", &t, RecordingKind::Flux, 50e-6).unwrap()
        };
        let e = identify_flux(&rows(&|k| (800.0 + 10.0 * k as f64, 46.0), 20), &setup())
            .unwrap_err()
            .0[0]
            .clone();
        assert!(e.problem.contains("not a steady speed"), "{e}");
        let e = identify_flux(&rows(&|_| (50.0, 3.0), 20), &setup()).unwrap_err().0[0].clone();
        assert!(e.problem.contains("too slow"), "{e}");
        let e = identify_flux(&rows(&|_| (800.0, 46.0), 5), &setup()).unwrap_err().0[0].clone();
        assert!(e.problem.contains("too short"), "{e}");
        let e = identify_flux(&rows(&|_| (800.0, 400.0), 20), &setup()).unwrap_err().0[0].clone();
        assert!(e.problem.contains("saturated"), "{e}");
        let e = identify_flux(&rows(&|_| (800.0, -46.0), 20), &setup()).unwrap_err().0[0].clone();
        assert!(e.problem.contains("opposite signs"), "{e}");
    }
}
