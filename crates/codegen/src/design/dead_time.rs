//! The inverter dead time's voltage error.
//!
//! During each dead time t_d both switches of a leg are off and the phase follows the
//! sign of its current through a freewheeling diode, not the command: once per switching
//! period the leg loses (or gains) U_dc·t_d of volt-seconds against the current. Averaged
//! over the period T_s = 1/f_s that is a voltage error of magnitude
//!
//! ```text
//! ΔU = U_dc·t_d·f_s        (opposite in sign to the phase current)
//! ```
//!
//! Thesis B's laboratory inverter compensates it (Appendix B.1, "conducting voltage drops
//! and dead time of the inverter are compensated for"), and §4.3.4 names it as a source of
//! error for signal injection on motors with small saliency. The firmware's current loop
//! sees it as a disturbance its integral action removes in steady state.

/// ΔU = U_dc·t_d·f_s \[V\]: the average phase-leg voltage error of a dead time `t_dead` \[s\]
/// at DC link `u_dc` \[V\] and switching frequency `f_s` \[Hz\].
pub fn voltage_error(u_dc: f64, t_dead: f64, f_s: f64) -> f64 {
    u_dc * t_dead * f_s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// By hand: 600 V·1 µs·20 kHz = 12 V (3.5 % of V_max = 600/√3 = 346.4 V); thesis A's
    /// drive (Table 1.1: 600 V, 20 kHz).
    #[test]
    fn voltage_error_by_hand() {
        assert!((voltage_error(600.0, 1e-6, 20e3) - 12.0).abs() < 1e-12);
        assert!((voltage_error(24.0, 500e-9, 20e3) - 0.24).abs() < 1e-12);
    }
}
