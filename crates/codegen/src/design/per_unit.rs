//! Per-unit base system of thesis B, Appendix A (Table A.1).
//!
//! V_base = V_max = V_dc/√3, I_base = √2·I_n, Z_base = V_base/I_base, ω_base = 2π·f_n,
//! ψ_base = V_base/ω_base, L_base = Z_base/ω_base, J_base = V_base·I_base/ω_base³,
//! P_base = P_n, T_base = T_n.
//!
//! Each base is computed from exactly the quantities its definition names, so a base the
//! spec determines never waits for an unrelated key: V_base needs only the DC link,
//! I_base and Z_base only the rated current, ψ_base only the rated frequency; L_base
//! and J_base need both.

use serde::Serialize;

/// The base values; `None` where the spec lacks a quantity the definition needs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Bases {
    /// V_base = V_max = V_dc/√3 \[V\].
    pub voltage_v: f64,
    /// I_base = √2·I_n \[A\] (needs I_n).
    pub current_a: Option<f64>,
    /// Z_base = V_base/I_base \[Ω\] (needs I_n).
    pub impedance_ohm: Option<f64>,
    /// ω_base = 2π·f_n [rad/s] (needs f_n).
    pub angular_frequency_rad_s: Option<f64>,
    /// ψ_base = V_base/ω_base \[Wb\] (needs f_n).
    pub flux_wb: Option<f64>,
    /// L_base = Z_base/ω_base \[H\] (needs I_n and f_n).
    pub inductance_h: Option<f64>,
    /// J_base = V_base·I_base/ω_base³ [kg·m²] as Table A.1 defines it (needs I_n and f_n).
    pub inertia: Option<f64>,
    /// P_base = P_n \[W\], if given.
    pub power_w: Option<f64>,
    /// T_base = T_n [N·m], if given.
    pub torque_nm: Option<f64>,
}

/// Bases from the DC link \[V\] and, where given, the rated rms current \[A\], the rated
/// electrical frequency \[Hz\], the rated power \[W\] and torque [N·m].
pub fn bases(v_dc: f64, i_n_rms: Option<f64>, f_n: Option<f64>, p_n: Option<f64>, t_n: Option<f64>) -> Bases {
    let v = v_dc / 3f64.sqrt();
    let i = i_n_rms.map(|i| std::f64::consts::SQRT_2 * i);
    let w = f_n.map(|f| 2.0 * std::f64::consts::PI * f);
    let z = i.map(|i| v / i);
    Bases {
        voltage_v: v,
        current_a: i,
        impedance_ohm: z,
        angular_frequency_rad_s: w,
        flux_wb: w.map(|w| v / w),
        inductance_h: z.zip(w).map(|(z, w)| z / w),
        inertia: i.zip(w).map(|(i, w)| v * i / (w * w * w)),
        power_w: p_n,
        torque_nm: t_n,
    }
}

/// The bases the spec does not determine, each with the key that would provide it.
pub fn missing(b: &Bases) -> Vec<String> {
    let mut out = Vec::new();
    if b.current_a.is_none() {
        out.push("I_base = √2·I_n, Z_base: need motor.datasheet.nominal_current".to_string());
    }
    if b.angular_frequency_rad_s.is_none() {
        out.push("ω_base = 2π·f_n, ψ_base: need motor.datasheet.rated_frequency or nominal_speed".to_string());
    }
    if b.inductance_h.is_none() {
        out.push("L_base, J_base: need both".to_string());
    }
    if b.power_w.is_none() {
        out.push("P_base = P_n: needs motor.datasheet.rated_power".to_string());
    }
    if b.torque_nm.is_none() {
        out.push("T_base = T_n: needs motor.datasheet.nominal_torque".to_string());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pu(x: f64, base: Option<f64>, digits: i32) -> f64 {
        let s = 10f64.powi(digits);
        (x / base.unwrap() * s).round() / s
    }

    /// Thesis B Table B.1/B.2 with V_dc = 320 V (V_base = 184.75 V): every pu value of
    /// Table B.2 to its printed digits. Hand calculation: I_base = √2·160 = 226.27 A,
    /// ω_base = 2π·200 = 1256.64 rad/s, Z_base = 0.8165 Ω, L_base = 0.6497 mH, ψ_base = 0.14702 Wb.
    #[test]
    fn table_b2_per_unit_column() {
        let b = bases(320.0, Some(160.0), Some(200.0), None, None);
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
        assert_eq!(pu(28.0, Some(b.voltage_v), 2), 0.15);
    }

    /// Each base depends on the quantities of its own definition only: without f_n the
    /// voltage, current and impedance bases are the same numbers (R_s = 0.010 pu of
    /// Table B.2 needs no f_n); without I_n the flux base still is (ψ_m = 0.71 pu).
    #[test]
    fn bases_need_only_their_own_quantities() {
        let all = bases(320.0, Some(160.0), Some(200.0), Some(50e3), Some(80.0));
        let no_f = bases(320.0, Some(160.0), None, None, None);
        assert_eq!(
            (no_f.voltage_v, no_f.current_a, no_f.impedance_ohm),
            (all.voltage_v, all.current_a, all.impedance_ohm)
        );
        assert_eq!(pu(7.9e-3, no_f.impedance_ohm, 3), 0.010);
        assert!(no_f.angular_frequency_rad_s.is_none() && no_f.inductance_h.is_none() && no_f.flux_wb.is_none());
        let no_i = bases(320.0, None, Some(200.0), None, None);
        assert_eq!(
            (no_i.angular_frequency_rad_s, no_i.flux_wb),
            (all.angular_frequency_rad_s, all.flux_wb)
        );
        assert_eq!(pu(104e-3, no_i.flux_wb, 2), 0.71);
        assert!(no_i.current_a.is_none() && no_i.inductance_h.is_none() && no_i.inertia.is_none());
        assert!(missing(&all).is_empty());
        let m = missing(&no_f).join("; ");
        assert!(m.contains("rated_frequency") && !m.contains("nominal_current"), "{m}");
    }
}
