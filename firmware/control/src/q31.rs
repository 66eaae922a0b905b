//! Q1.31 arithmetic shared by the control core: a stored `i32` `i` stands for the real
//! value `i·2^-31` (angles additionally scaled by π, see [`crate::angle`]).
//!
//! Saturating throughout, as the crate's numeric convention demands; only angles wrap,
//! and they do so in [`crate::angle`].

/// 2^31 as `f32`: a real value in [−1, 1] → Q1.31 stored integer.
pub const ONE_F32: f32 = 2_147_483_648.0;

/// `2^-31` as `f32` (exact).
pub const LSB_F32: f32 = 1.0 / 2_147_483_648.0;

/// Q1.31 stored integer → real value `i·2^-31`.
pub fn to_f32(i: i32) -> f32 {
    i as f32 * LSB_F32
}

/// A real value in [−1, 1] → Q1.31 stored integer (truncating, saturating at the ends).
pub fn from_f32(v: f32) -> i32 {
    (v * ONE_F32) as i32
}

/// `round(a·b/2^31)` on `i64`, saturating: the product of two Q1.31 values (or of a
/// Q1.31 gain and a wider integer) back in the wider operand's scale. Exact for
/// |a|, |b| ≤ 2^32, where neither the product nor the rounding term saturates.
pub fn mul(a: i64, b: i64) -> i64 {
    a.saturating_mul(b).saturating_add(1 << 30) >> 31
}

/// `round(a·b/2^31)` for unsigned Q.31 magnitudes a, b ≤ 2^31: the product of two
/// `u32` cannot overflow `u64` (≤ 2^62) and the rounded result is ≤ 2^31, so the
/// saturating forms never saturate (the compiler reduces them to one UMULL).
pub fn mul_unsigned(a: u32, b: u32) -> u32 {
    let p = u64::from(a).saturating_mul(u64::from(b)).saturating_add(1 << 30) >> 31;
    u32::try_from(p).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand values: 0.5·0.5 = 0.25 (2^30·2^30/2^31 = 2^29); −0.5·0.5 = −0.25; the
    /// rounding goes half up: 3·2^30/2^31 = 1.5 → 2, and 2^31·2^31/2^31 = 2^31 needs i64.
    #[test]
    fn products() {
        assert_eq!(mul(1 << 30, 1 << 30), 1 << 29);
        assert_eq!(mul(-(1 << 30), 1 << 30), -(1 << 29));
        assert_eq!(mul(3, 1 << 30), 2);
        assert_eq!(mul(1 << 31, 1 << 31), 1 << 31);
        assert_eq!(mul(i64::MAX, i64::MAX), i64::MAX >> 31);
        assert_eq!(mul_unsigned(1 << 30, 1 << 30), 1 << 29);
        assert_eq!(mul_unsigned(1 << 31, 1 << 31), 1 << 31);
    }

    #[test]
    fn conversions() {
        assert_eq!(from_f32(0.5), 1 << 30);
        assert_eq!(from_f32(-1.0), i32::MIN);
        assert_eq!(from_f32(1.0), i32::MAX);
        assert_eq!(to_f32(1 << 30), 0.5);
        assert_eq!(to_f32(i32::MIN), -1.0);
    }
}
