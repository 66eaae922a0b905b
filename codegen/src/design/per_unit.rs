//! Per-unit base system of thesis B, Appendix A (Table A.1).
//!
//! V_base = V_dc/√3, I_base = √2·I_n, Z_base = V_base/I_base, ω_base = 2π·f_n,
//! ψ_base = V_base/ω_base, L_base = Z_base/ω_base, J_base = V_base·I_base/ω_base³,
//! P_base = P_n, T_base = T_n.

use serde::Serialize;

/// The base values.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Bases {
    /// V_base = V_dc/√3 \[V\].
    pub voltage_v: f64,
    /// I_base = √2·I_n \[A\].
    pub current_a: f64,
    /// Z_base \[Ω\].
    pub impedance_ohm: f64,
    /// ω_base = 2π·f_n [rad/s].
    pub angular_frequency_rad_s: f64,
    /// ψ_base \[Wb\].
    pub flux_wb: f64,
    /// L_base = Z_base/ω_base \[H\].
    pub inductance_h: f64,
    /// J_base [kg·m²] as Table A.1 defines it.
    pub inertia: f64,
    /// P_base = P_n \[W\], if given.
    pub power_w: Option<f64>,
    /// T_base = T_n [N·m], if given.
    pub torque_nm: Option<f64>,
}

/// Bases from the DC link \[V\], rated rms current \[A\] and rated electrical frequency \[Hz\].
pub fn bases(v_dc: f64, i_n_rms: f64, f_n: f64, p_n: Option<f64>, t_n: Option<f64>) -> Bases {
    let v = v_dc / 3f64.sqrt();
    let i = std::f64::consts::SQRT_2 * i_n_rms;
    let w = 2.0 * std::f64::consts::PI * f_n;
    let z = v / i;
    Bases {
        voltage_v: v,
        current_a: i,
        impedance_ohm: z,
        angular_frequency_rad_s: w,
        flux_wb: v / w,
        inductance_h: z / w,
        inertia: v * i / (w * w * w),
        power_w: p_n,
        torque_nm: t_n,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thesis B Table B.1/B.2 with V_dc = 320 V (V_base = 184.75 V): every pu value of
    /// Table B.2 to its printed digits. Hand calculation: I_base = √2·160 = 226.27 A,
    /// ω_base = 2π·200 = 1256.64 rad/s, Z_base = 0.8165 Ω, L_base = 0.6497 mH, ψ_base = 0.14702 Wb.
    #[test]
    fn table_b2_per_unit_column() {
        let b = bases(320.0, 160.0, 200.0, None, None);
        let pu = |x: f64, base: f64, digits: i32| {
            let s = 10f64.powi(digits);
            (x / base * s).round() / s
        };
        assert_eq!(pu(7.9e-3, b.impedance_ohm, 3), 0.010);
        assert_eq!(pu(0.23e-3, b.inductance_h, 2), 0.35);
        assert_eq!(pu(0.56e-3, b.inductance_h, 2), 0.86);
        assert_eq!(pu(0.42e-3, b.inductance_h, 2), 0.65);
        assert_eq!(pu(104e-3, b.flux_wb, 2), 0.71);
        assert_eq!(pu(2.1e-3, b.flux_wb, 3), 0.014);
        assert_eq!(pu(0.5e-3, b.flux_wb, 4), 0.0034);
        assert_eq!(pu(6.0e-3, b.flux_wb, 3), 0.041);
        assert_eq!(pu(1.2e-3, b.flux_wb, 4), 0.0082);
        // Thesis B §4: V_e ≥ 0.15 pu ⇔ 28 V.
        assert_eq!(pu(28.0, b.voltage_v, 2), 0.15);
    }
}
