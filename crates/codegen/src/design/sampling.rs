//! Sampling frequency versus the maximum electrical frequency, thesis A (1.1), (2.19).

/// f_e,max = n_p·ω_m,max/(2π) \[Hz\] (thesis A Table 1.2: f_e = n_p·n_max/60).
pub fn max_electrical_frequency(pole_pairs: u32, max_speed_rad_s: f64) -> f64 {
    f64::from(pole_pairs) * max_speed_rad_s / (2.0 * std::f64::consts::PI)
}

/// Samples per electrical period required by (1.1): f_s ≥ 12·f_e.
pub const SAMPLES_PER_ELECTRICAL_PERIOD: f64 = 12.0;

/// Lowest permissible switching frequency \[Hz\], (1.1).
pub fn min_switching_frequency(f_e_max: f64) -> f64 {
    SAMPLES_PER_ELECTRICAL_PERIOD * f_e_max
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thesis A Table 1.2 and (1.1): n_p = 4, 20 000 rpm → f_e = 1333 Hz, f_s ≥ 16 kHz.
    #[test]
    fn fischer_needs_16_khz() {
        let w = 20_000.0 * 2.0 * std::f64::consts::PI / 60.0;
        let fe = max_electrical_frequency(4, w);
        assert!((fe - 1333.33).abs() < 0.01, "{fe}");
        assert!((min_switching_frequency(fe) - 16_000.0).abs() < 1e-6);
    }
}
