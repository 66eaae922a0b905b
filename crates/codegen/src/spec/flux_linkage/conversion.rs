//! PM flux linkage ψ_M from datasheet motor constants: the unit conversions the spec
//! applies when it derives ψ_M (below the design, which reads the derived value).
//!
//! Thesis A (2.34): T_e = 3/2·n_p·ψ_M·i_q with i_q the peak phase current of the
//! amplitude-invariant transform, so K_t = 3/2·n_p·ψ_M per peak ampere. Thesis A
//! (6.10), (6.11): the back-EMF constant is ψ_M itself when expressed as phase-peak
//! volts per electrical rad/s.
//!
//! Block commutation (maxon's k_M and k_n). With 120° block commutation two phases carry
//! the supply current I at a time and the supply sees the line-to-line back EMF of the
//! conducting pair, switched every 60° so that the pair's EMF is within ±30° of its peak.
//! For a sinusoidal back EMF (the dq model of thesis A (2.26), (2.27)), peak line-to-line
//! √3·ω_e·ψ_M, the induced DC voltage is its mean over the 60° sector:
//!
//! ```text
//! U_ind = √3·ω_e·ψ_M · (1/(π/3))·∫_{−π/6}^{π/6} cos x dx = (3√3/π)·ω_e·ψ_M
//! ```
//!
//! so a speed constant k_n = ω_m/U_ind gives ψ_M = π/(3√3·n_p·k_n), and by the power
//! balance T·ω_m = U_ind·I the torque constant k_M = T/I = (3√3/π)·n_p·ψ_M (k_M = 1/k_n in
//! SI units, as maxon's tables print). 3√3/π = 1.654 against 3/2 for the peak current of
//! sinusoidal commutation. A trapezoidal back EMF would give other factors; the
//! conversion assumes the sinusoidal one the controller is designed for.

use crate::spec::{Amplitude, SpeedAxis};

/// 3√3/π: U_ind/(ω_e·ψ_M) and k_M/(n_p·ψ_M) of block commutation.
pub const BLOCK_COMMUTATION_FACTOR: f64 = 1.653_986_686_265_376_7;

/// ψ_M \[Wb\] from K_t [N·m/A] quoted per `current` ampere: rms or peak phase current
/// (2.34), or the DC supply current of block commutation.
pub fn from_torque_constant(kt: f64, current: Amplitude, pole_pairs: u32) -> f64 {
    let np = f64::from(pole_pairs);
    match current {
        Amplitude::Rms => kt / std::f64::consts::SQRT_2 / (1.5 * np),
        Amplitude::Peak => kt / (1.5 * np),
        Amplitude::BlockCommutation => kt / (BLOCK_COMMUTATION_FACTOR * np),
    }
}

/// ψ_M \[Wb\] from K_e [V per rad/s of `speed`] quoted in the given conventions (6.11):
/// rms or peak, line to line or phase; or the induced DC voltage of block commutation
/// (line to line by construction).
pub fn from_back_emf_constant(
    ke: f64,
    voltage: Amplitude,
    line_to_line: bool,
    speed: SpeedAxis,
    pole_pairs: u32,
) -> f64 {
    let electrical = match voltage {
        Amplitude::BlockCommutation => ke / BLOCK_COMMUTATION_FACTOR,
        Amplitude::Rms | Amplitude::Peak => {
            let peak = if voltage == Amplitude::Rms {
                ke * std::f64::consts::SQRT_2
            } else {
                ke
            };
            if line_to_line { peak / 3f64.sqrt() } else { peak }
        }
    };
    match speed {
        SpeedAxis::Mechanical => electrical / f64::from(pole_pairs),
        SpeedAxis::Electrical => electrical,
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
        let psi = from_back_emf_constant(0.296, Amplitude::Rms, true, SpeedAxis::Mechanical, 4);
        assert!((psi - 0.060_420_7).abs() < 1e-7, "{psi}");
    }

    #[test]
    fn peak_phase_electrical_is_identity() {
        assert_eq!(
            from_back_emf_constant(0.1, Amplitude::Peak, false, SpeedAxis::Electrical, 7),
            0.1
        );
        // K_t = 3/2·n_p·ψ exactly inverts for peak current.
        assert!((from_torque_constant(1.5 * 3.0 * 0.07, Amplitude::Peak, 3) - 0.07).abs() < 1e-15);
    }

    /// The block-commutation factor 3√3/π, checked by integrating the conducting pair's
    /// line-to-line EMF √3·cos x over its 60° sector numerically (midpoint rule, 10⁵ steps)
    /// instead of in closed form.
    #[test]
    fn block_commutation_factor_by_numerical_mean() {
        let n = 100_000;
        let h = (std::f64::consts::PI / 3.0) / f64::from(n);
        let mean = (0..n)
            .map(|k| 3f64.sqrt() * (-std::f64::consts::PI / 6.0 + (f64::from(k) + 0.5) * h).cos())
            .sum::<f64>()
            / f64::from(n);
        assert!((mean - BLOCK_COMMUTATION_FACTOR).abs() < 1e-9, "{mean}");
        assert!((BLOCK_COMMUTATION_FACTOR - 3.0 * 3f64.sqrt() / std::f64::consts::PI).abs() < 1e-15);
    }

    /// maxon EC 45 flat ∅43.5 mm, 70 W, 24 V (maxon catalogue, "Motor Data (provisional)",
    /// online.flippingbook.com/view/1042987/324): k_M = 40.4 mN·m/A, k_n = 236 rpm/V, 8 pole
    /// pairs. By hand: ψ = 0.0404/(1.65399·8) = 3.0532 mWb from k_M; k_n = 236·π/30 =
    /// 24.7139 rad/s per V, K_e = 1/k_n = 0.0404631 V·s/rad, ψ = 0.0404631/(1.65399·8)
    /// = 3.0580 mWb from k_n (0.16 % apart: k_M·k_n = 0.9984 in SI).
    #[test]
    fn maxon_block_commutation_constants() {
        let from_km = from_torque_constant(0.0404, Amplitude::BlockCommutation, 8);
        let ke = 30.0 / (236.0 * std::f64::consts::PI);
        let from_kn = from_back_emf_constant(ke, Amplitude::BlockCommutation, true, SpeedAxis::Mechanical, 8);
        assert!((from_km - 3.0532e-3).abs() < 1e-7, "{from_km}");
        assert!((from_kn - 3.0580e-3).abs() < 1e-7, "{from_kn}");
    }
}
