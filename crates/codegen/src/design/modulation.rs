//! Modulator constants, thesis A §3.2 (3.5)–(3.8) and DC-link feed-forward (5.1).

use serde::Serialize;

/// THPWM common-mode amplitude per volt of DC link, 1/(6√3) of (3.7).
pub fn thpwm_common_mode_ratio() -> f64 {
    1.0 / (6.0 * 3f64.sqrt())
}

/// Modulator constants at a given DC-link voltage.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Modulation {
    /// 1/(6√3): u_NM amplitude over U_dc (3.7).
    pub thpwm_common_mode_ratio: f64,
    /// u_NM amplitude at nominal U_dc \[V\].
    pub thpwm_common_mode_amplitude_v: f64,
    /// Largest phase-voltage amplitude with third-harmonic injection, U_dc/√3 \[V\] (thesis B 2.50).
    pub max_phase_voltage_v: f64,
    /// Largest phase-voltage amplitude with sinusoidal PWM, U_dc/2 \[V\] (3.4), (3.5).
    pub max_phase_voltage_spwm_v: f64,
    /// Modulation index reached with THPWM, M = 2/√3 (3.6).
    pub max_modulation_index: f64,
    /// Same at the lowest DC-link voltage \[V\].
    pub max_phase_voltage_at_min_dc_v: f64,
    /// Largest duty cycle of a leg (`design::duty_limit`; 1 without a board or with
    /// in-line sensing).
    pub max_duty: f64,
    /// The fraction of U_dc/√3 the duty limit leaves (`duty_limit::usable_voltage_fraction`).
    pub usable_voltage_fraction: f64,
    /// The usable phase-voltage amplitude at nominal U_dc \[V\]: that fraction of U_dc/√3.
    pub usable_phase_voltage_v: f64,
}

/// Constants for nominal `u_dc` \[V\] and minimum `u_dc_min` \[V\], duties up to
/// `max_duty` leaving `usable` of U_dc/√3.
pub fn modulation(u_dc: f64, u_dc_min: f64, max_duty: f64, usable: f64) -> Modulation {
    Modulation {
        max_duty,
        usable_voltage_fraction: usable,
        usable_phase_voltage_v: usable * u_dc / 3f64.sqrt(),
        thpwm_common_mode_ratio: thpwm_common_mode_ratio(),
        thpwm_common_mode_amplitude_v: u_dc * thpwm_common_mode_ratio(),
        max_phase_voltage_v: u_dc / 3f64.sqrt(),
        max_phase_voltage_spwm_v: u_dc / 2.0,
        max_modulation_index: 2.0 / 3f64.sqrt(),
        max_phase_voltage_at_min_dc_v: u_dc_min / 3f64.sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (3.5): SPWM reaches √3/2·U_dc line to line = U_dc/2 phase amplitude; adding
    /// u_NM of (3.7) lifts the phase amplitude to U_dc/√3, a 15.5 % gain (2/√3 = 1.1547).
    #[test]
    fn third_harmonic_extends_linear_range() {
        let m = modulation(600.0, 432.0, 1.0, 1.0);
        assert!((m.thpwm_common_mode_ratio - 0.096_225).abs() < 1e-6);
        assert!((m.max_phase_voltage_v / m.max_phase_voltage_spwm_v - 1.1547).abs() < 1e-4);
        // Check (3.7) numerically: at amplitude U_dc/√3, phase u plus u_NM never exceeds U_dc/2.
        let a = m.max_phase_voltage_v;
        let worst = (0..3600)
            .map(|k| {
                let th = k as f64 * std::f64::consts::TAU / 3600.0;
                (a * th.cos() - 600.0 * m.thpwm_common_mode_ratio * (3.0 * th).cos()).abs()
            })
            .fold(0.0, f64::max);
        assert!(worst <= 300.0 + 1e-9, "{worst}");
        assert!(worst >= 299.9);
    }
}
