//! PM flux linkage ψ_M from datasheet motor constants.
//!
//! Thesis A (2.34): T_e = 3/2·n_p·ψ_M·i_q with i_q the peak phase current of the
//! amplitude-invariant transform, so K_t = 3/2·n_p·ψ_M per peak ampere. Thesis A
//! (6.10), (6.11): the back-EMF constant is ψ_M itself when expressed as phase-peak
//! volts per electrical rad/s.

use crate::spec::{Amplitude, Between, SpeedAxis};

/// ψ_M \[Wb\] from K_t [N·m/A] quoted per `current` ampere (rms or peak), (2.34).
pub fn from_torque_constant(kt: f64, current: Amplitude, pole_pairs: u32) -> f64 {
    let kt_peak = match current {
        Amplitude::Rms => kt / std::f64::consts::SQRT_2,
        Amplitude::Peak => kt,
    };
    kt_peak / (1.5 * f64::from(pole_pairs))
}

/// ψ_M \[Wb\] from K_e [V·s/rad] quoted in the given conventions, (6.11).
pub fn from_back_emf_constant(
    ke: f64,
    voltage: Amplitude,
    measured: Between,
    speed: SpeedAxis,
    pole_pairs: u32,
) -> f64 {
    let peak = match voltage {
        Amplitude::Rms => ke * std::f64::consts::SQRT_2,
        Amplitude::Peak => ke,
    };
    let phase = match measured {
        Between::LineToLine => peak / 3f64.sqrt(),
        Between::Phase => peak,
    };
    match speed {
        SpeedAxis::Mechanical => phase / f64::from(pole_pairs),
        SpeedAxis::Electrical => phase,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fischer TI085, thesis A Table 1.2: K_t = 0.492 N·m/A (rms), n_p = 4.
    /// Hand calculation: 0.492/√2 = 0.347897; /(1.5·4) = 0.0579828 Wb.
    #[test]
    fn fischer_torque_constant_gives_58_mwb() {
        let psi = from_torque_constant(0.492, Amplitude::Rms, 4);
        assert!((psi - 0.057_982_8).abs() < 1e-7, "{psi}");
    }

    /// Fischer TI085, thesis A Table 1.2: K_e = 0.296 V·s/rad, rms line-to-line per mechanical rad/s.
    /// Hand calculation: 0.296·√2 = 0.418607; /√3 = 0.241683; /4 = 0.0604207 Wb.
    #[test]
    fn fischer_back_emf_constant_gives_60_mwb() {
        let psi = from_back_emf_constant(0.296, Amplitude::Rms, Between::LineToLine, SpeedAxis::Mechanical, 4);
        assert!((psi - 0.060_420_7).abs() < 1e-7, "{psi}");
    }

    #[test]
    fn peak_phase_electrical_is_identity() {
        assert_eq!(
            from_back_emf_constant(0.1, Amplitude::Peak, Between::Phase, SpeedAxis::Electrical, 7),
            0.1
        );
        // K_t = 3/2·n_p·ψ exactly inverts for peak current.
        assert!((from_torque_constant(1.5 * 3.0 * 0.07, Amplitude::Peak, 3) - 0.07).abs() < 1e-15);
    }
}
