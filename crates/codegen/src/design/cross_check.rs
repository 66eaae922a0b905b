//! Cross-checks of the values a datasheet gives twice: ψ_M against K_t, K_e and k_n
//! (thesis A (2.34), (6.11)), the peak and rated torques against the MTPA torque (3.7),
//! (3.10) at the peak and rated currents, the rated power against torque × speed, and the
//! rated frequency against the nominal speed (2.19). Each pair is compared, and pairs
//! further apart than [`TOLERANCE_PERCENT`] are reported with both values.

use serde::Serialize;

use super::loss_minimisation::mtpa_corner;

/// Disagreement above which a redundant pair is reported: 5 %, the spread of a datasheet's
/// own rounding and tolerances (the Fischer TI085's K_t and K_e of thesis A Table 1.2 give
/// ψ_M 4.1 % apart).
pub const TOLERANCE_PERCENT: f64 = 5.0;

/// One compared pair.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrossCheck {
    /// The quantity compared, with its unit, e.g. `ψ_M [Wb]`.
    pub quantity: String,
    /// First value and where it came from.
    pub a: f64,
    /// `a`'s source (key and form as written).
    pub a_from: String,
    /// Second value.
    pub b: f64,
    /// `b`'s source.
    pub b_from: String,
    /// |a − b| / mean(|a|, |b|), in percent.
    pub disagreement_percent: f64,
}

impl CrossCheck {
    /// A compared pair.
    pub fn new(quantity: &str, (a, a_from): (f64, String), (b, b_from): (f64, String)) -> CrossCheck {
        CrossCheck {
            quantity: quantity.to_string(),
            a,
            a_from,
            b,
            b_from,
            disagreement_percent: disagreement_percent(a, b),
        }
    }

    /// Whether the pair is further apart than [`TOLERANCE_PERCENT`].
    pub fn fails(&self) -> bool {
        self.disagreement_percent > TOLERANCE_PERCENT
    }
}

impl std::fmt::Display for CrossCheck {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {:.5} from {} vs {:.5} from {}: {:.1} % apart (tolerance {TOLERANCE_PERCENT} %)",
            self.quantity, self.a, self.a_from, self.b, self.b_from, self.disagreement_percent
        )
    }
}

/// |a − b| / mean(|a|, |b|) in percent (0 when both are 0).
pub fn disagreement_percent(a: f64, b: f64) -> f64 {
    let mean = 0.5 * (a.abs() + b.abs());
    if mean > 0.0 { 100.0 * (a - b).abs() / mean } else { 0.0 }
}

/// The largest torque [N·m] at current amplitude `i` \[A\]: (3.7) at the MTPA point (3.10)
/// on |i| = `i`, T = 3/2·n_p·i_q·(ψ_m − ΔL·i_d).
pub fn mtpa_torque(pole_pairs: u32, psi: f64, ld: f64, lq: f64, i: f64) -> f64 {
    let (id, iq) = mtpa_corner(psi, lq - ld, i);
    1.5 * f64::from(pole_pairs) * iq * (psi - (lq - ld) * id)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fischer TI085 (thesis A Tables 1.1, 1.2): n_p = 4, L_d = L_q, ψ_M = 60.4207 mWb from
    /// K_e; at the peak current 61 A rms (86.267 A amplitude) T = 1.5·4·86.267·0.0604207
    /// = 31.274 N·m against the printed 29.1 N·m: 7.2 % apart (the datasheet's peak torque
    /// includes saturation the linear model leaves out); at 22.6 A rms (31.961 A):
    /// 11.587 N·m against 11.1 N·m, 4.3 %.
    #[test]
    fn fischer_torques_by_hand() {
        let t = mtpa_torque(4, 0.060_420_7, 0.393e-3, 0.393e-3, 61.0 * std::f64::consts::SQRT_2);
        assert!((t - 31.274).abs() < 1e-3, "{t}");
        let c = CrossCheck::new("T", (29.1, "a".into()), (t, "b".into()));
        assert!(c.fails() && (c.disagreement_percent - 7.20).abs() < 0.01, "{c}");
        let t = mtpa_torque(4, 0.060_420_7, 0.393e-3, 0.393e-3, 22.6 * std::f64::consts::SQRT_2);
        assert!((t - 11.587).abs() < 1e-3, "{t}");
        assert!(!CrossCheck::new("T", (11.1, "a".into()), (t, "b".into())).fails());
    }

    /// Thesis B (Tables B.1, B.2): at I_base = √2·160 A the MTPA point is (−99.56 A,
    /// 203.19 A) and T = 3·203.19·(0.104 + 0.33e-3·99.56) = 83.42 N·m against the rated 80 N·m
    /// (4.2 %); P_n = T_n·ω_n = 80·2π·6000/60 = 50.27 kW against 50 kW (0.5 %).
    #[test]
    fn thesis_b_rated_point_by_hand() {
        let t = mtpa_torque(2, 0.104, 0.23e-3, 0.56e-3, 160.0 * std::f64::consts::SQRT_2);
        assert!((t - 83.42).abs() < 0.01, "{t}");
        assert!(!CrossCheck::new("T", (80.0, "a".into()), (t, "b".into())).fails());
        let p = 80.0 * 2.0 * std::f64::consts::PI * 100.0;
        assert!((disagreement_percent(50e3, p) - 0.53).abs() < 0.01);
    }
}
