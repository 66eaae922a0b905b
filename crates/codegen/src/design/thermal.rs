//! Winding resistance at temperature, thesis B (2.24): R_s = (235+T)/(235+T_0)·R_s0.

/// Copper's inferred zero-resistance temperature magnitude in (2.24) [°C].
pub const COPPER_INFERRED_ZERO_C: f64 = 235.0;

/// R_s at `t_c` \[Ω\] given R_s0 \[Ω\] measured at `t0_c` [°C], (2.24).
pub fn resistance_at(r0_ohm: f64, t0_c: f64, t_c: f64) -> f64 {
    (COPPER_INFERRED_ZERO_C + t_c) / (COPPER_INFERRED_ZERO_C + t0_c) * r0_ohm
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thesis B §2.1.6: at 130 °C versus 20 °C the increase is "approximately 40 %":
    /// (235+130)/(235+20) = 365/255 = 1.4314.
    #[test]
    fn thesis_b_forty_percent_at_130_c() {
        let r = resistance_at(1.0, 20.0, 130.0);
        assert!((r - 365.0 / 255.0).abs() < 1e-12);
        assert!((r - 1.4).abs() < 0.05);
    }
}
