//! Per-unit fixed-point scalings, thesis A (4.16), (4.20), Table 4.1.
//!
//! A stored integer p^i of an n-bit word with m = n − 1 fractional bits stands
//! for p = A·p^i/2^m (4.16), so p ∈ [−A, A) with resolution A/2^m.

use serde::Serialize;

/// A Q format (signed, one integer/sign bit).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum QFormat {
    /// 16-bit, 15 fractional bits.
    Q15,
    /// 32-bit, 31 fractional bits.
    Q31,
}

impl QFormat {
    /// Fractional bits m.
    pub fn fractional_bits(self) -> u32 {
        match self {
            QFormat::Q15 => 15,
            QFormat::Q31 => 31,
        }
    }

    /// Display name, "Q1.15" / "Q1.31".
    pub fn name(self) -> &'static str {
        match self {
            QFormat::Q15 => "Q1.15",
            QFormat::Q31 => "Q1.31",
        }
    }
}

/// One quantity's fixed-point representation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scaling {
    /// Full scale A in the quantity's SI unit (4.16).
    pub full_scale: f64,
    /// SI unit of `full_scale` and `resolution`.
    pub unit: &'static str,
    /// Q format name.
    pub q_format: &'static str,
    /// Fractional bits m.
    pub fractional_bits: u32,
    /// Resolution A/2^m.
    pub resolution: f64,
    /// Physical value per stored integer as f32-friendly multiplier (= resolution).
    pub si_per_lsb: f64,
    /// Stored integers per SI unit, 2^m/A.
    pub lsb_per_si: f64,
    /// Why this full scale.
    pub rule: String,
}

/// Builds a scaling from a full scale, a format and the reason.
pub fn scaling(full_scale: f64, unit: &'static str, q: QFormat, rule: impl Into<String>) -> Scaling {
    let m = q.fractional_bits();
    let two_m = 2f64.powi(m as i32);
    Scaling {
        full_scale,
        unit,
        q_format: q.name(),
        fractional_bits: m,
        resolution: full_scale / two_m,
        si_per_lsb: full_scale / two_m,
        lsb_per_si: two_m / full_scale,
        rule: rule.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thesis A Table 4.1: resolution 3.052e-5 (Q1.15) and 4.657e-10 (Q1.31) for A = 1.
    #[test]
    fn table_4_1_resolutions() {
        assert!((scaling(1.0, "1", QFormat::Q15, "").resolution - 3.052e-5).abs() < 1e-8);
        assert!((scaling(1.0, "1", QFormat::Q31, "").resolution - 4.657e-10).abs() < 1e-13);
    }

    /// Thesis A §4.4.3 example: u^i = −4000 in Q1.15 with A = 100 V is −12.2 V.
    #[test]
    fn stored_integer_example() {
        let s = scaling(100.0, "V", QFormat::Q15, "");
        assert!((-4000.0 * s.si_per_lsb + 12.207).abs() < 1e-3);
    }
}
