//! Q1.31 trigonometry in the CORDIC's number format, thesis A §4.4.3 and §7.2.
//!
//! Angles are stored integers scaled by π (4.20): `θ = 2^-31·π·θ^i`, so the whole
//! `i32` range is one turn `[-π, π)` and wrap-around is two's-complement overflow.
//! Sine, cosine and the atan2 result use the STM32G474 CORDIC's Q1.31 interface, so
//! the board layer can implement [`Trig`] with the coprocessor and the portable core
//! falls back to [`SoftTrig`] on the host and in tests.
//!
//! Accuracy of [`SoftTrig`] (checked against `f64` in the tests, exhaustively over
//! a dense grid plus random angles):
//! * [`sin_cos_q31`]: |error| ≤ 2 LSB of Q1.31 (≤ 9.4·10⁻¹⁰; measured 1.6 LSB),
//!   `+1.0` saturates to `i32::MAX`, `−1.0` is exact.
//! * [`atan2_q31`]: |error| ≤ 1 LSB of the π-scaled angle (≤ 1.5·10⁻⁹ rad;
//!   measured 0.85 LSB).
//!
//! Both use only `i64` integer arithmetic (Taylor polynomials in Horner form after
//! octant reduction) and never panic.

use crate::q31;

/// sin θ and cos θ as Q1.31 stored integers (value = `i/2^31`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SinCosQ31 {
    /// sin θ, Q1.31.
    pub sin: i32,
    /// cos θ, Q1.31.
    pub cos: i32,
}

impl SinCosQ31 {
    /// Converts to `f32` (value = `i·2^-31`), for the floating-point transforms.
    pub fn to_f32(self) -> crate::transforms::SinCos {
        crate::transforms::SinCos {
            sin: q31_to_f32(self.sin),
            cos: q31_to_f32(self.cos),
        }
    }
}

pub use q31::LSB_F32 as Q31_LSB_F32;
pub use q31::to_f32 as q31_to_f32;

/// Trigonometric primitives the control core needs, in the CORDIC's Q1.31 format.
///
/// `&mut self` so that a hardware implementation can own the peripheral.
pub trait Trig {
    /// sin θ and cos θ of the angle `θ = 2^-31·π·theta` (4.20), both Q1.31.
    fn sin_cos(&mut self, theta: i32) -> SinCosQ31;
    /// `atan2(y, x)/π` as a Q1.31 angle (the CORDIC "phase" function); `y`, `x`
    /// are Q1.31 (only their ratio matters). Returns 0 for `(0, 0)`.
    fn atan2(&mut self, y: i32, x: i32) -> i32;
    /// √x, correctly rounded as IEEE 754 requires of a square root (NaN for x < 0):
    /// `libm`'s software square root here; the board overrides it with the FPU's
    /// VSQRT.F32 (PM0214 §3.10, the Cortex-M4F's IEEE 754 square root), which gives the
    /// same bits — so the image and the host simulation compute the same numbers.
    fn sqrt(&mut self, x: f32) -> f32 {
        libm::sqrtf(x)
    }
}

/// Portable software implementation of [`Trig`] (no CORDIC needed).
#[derive(Clone, Copy, Debug, Default)]
pub struct SoftTrig;

impl Trig for SoftTrig {
    fn sin_cos(&mut self, theta: i32) -> SinCosQ31 {
        sin_cos_q31(theta)
    }
    fn atan2(&mut self, y: i32, x: i32) -> i32 {
        atan2_q31(y, x)
    }
}

/// Q1.31 one (2^31) held in `i64`.
const ONE: i64 = 1 << 31;
/// A quarter turn in the π-scaled angle format (π/2 ↔ 2^30).
const QUARTER_TURN: u32 = 1 << 30;
/// An eighth of a turn (π/4 ↔ 2^29).
const EIGHTH_TURN: u32 = 1 << 29;
/// π·2^32, rounded: converts a π-scaled angle to radians in Q.31.
const PI_Q32: u64 = 13_493_037_705;
/// 2^32/π, rounded: converts radians Q.31 to the π-scaled angle.
const INV_PI_Q32: i64 = 1_367_130_551;
/// tan(π/8)·2^31, rounded: octant split point of the atan series.
const TAN_PI_8_Q31: i64 = 889_516_852;

/// `round(n/d)` for `d > 0` (0 if `d` is not positive).
fn div_round(n: i64, d: i64) -> i64 {
    if d <= 0 {
        return 0;
    }
    let half = d >> 1;
    let n = if n < 0 {
        n.saturating_sub(half)
    } else {
        n.saturating_add(half)
    };
    n.checked_div(d).unwrap_or(0)
}

/// Taylor coefficients 1/k! in Q.31, rounded (sin: odd k, cos: even k).
const INV_FACT: [u32; 13] = [
    2_147_483_648, // 1/0!
    2_147_483_648, // 1/1!
    1_073_741_824, // 1/2!
    357_913_941,   // 1/3!
    89_478_485,    // 1/4!
    17_895_697,    // 1/5!
    2_982_616,     // 1/6!
    426_088,       // 1/7!
    53_261,        // 1/8!
    5_918,         // 1/9!
    592,           // 1/10!
    54,            // 1/11!
    4,             // 1/12!
];

/// sin z and cos z (unsigned Q.31) for z ∈ \[0, π/4\] in radians Q.31.
///
/// Horner form of the Taylor series; the first omitted terms are z¹³/13! ≤ 7·10⁻¹²
/// and z¹⁴/14! ≤ 4·10⁻¹³, far below one LSB (4.7·10⁻¹⁰). Every Horner partial sum
/// is positive on this interval, so unsigned arithmetic suffices.
fn sin_cos_octant(z: u32) -> (u32, u32) {
    let [c0, c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, c11, c12] = INV_FACT;
    let z2 = q31::mul_unsigned(z, z);
    let mut s = c11;
    for c in [c9, c7, c5, c3, c1] {
        s = c.saturating_sub(q31::mul_unsigned(z2, s));
    }
    let mut c = c12;
    for k in [c10, c8, c6, c4, c2, c0] {
        c = k.saturating_sub(q31::mul_unsigned(z2, c));
    }
    (q31::mul_unsigned(z, s), c)
}

/// Saturates an `i64` Q.31 value to the `i32` range (1.0 → `i32::MAX`).
fn saturate_i32(x: i64) -> i32 {
    x.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
}

/// sin θ and cos θ in Q1.31 of the π-scaled angle `θ = 2^-31·π·theta` (4.20).
///
/// Octant reduction on the stored integer (exact), then Taylor series on \[0, π/4\].
/// |error| ≤ 2 LSB.
pub fn sin_cos_q31(theta: i32) -> SinCosQ31 {
    // Reinterpret as unsigned: [0, 2^32) ↔ [0, 2π). Two's complement makes this the
    // same angle; the quadrant is the top two bits.
    let u = theta as u32;
    let quadrant = u >> 30;
    let r = u & (QUARTER_TURN - 1);
    let (a, swap) = if r <= EIGHTH_TURN {
        (r, false)
    } else {
        // π/2 − r: an angle difference (r < π/2, no wrap occurs).
        (QUARTER_TURN.wrapping_sub(r), true)
    };
    // a ≤ 2^29 and PI_Q32 < 2^34: the product is < 2^63, z < 2^31.
    let z = u64::from(a).saturating_mul(PI_Q32).saturating_add(1 << 31) >> 32;
    let (s, c) = sin_cos_octant(u32::try_from(z).unwrap_or(u32::MAX));
    let (s, c) = if swap { (c, s) } else { (s, c) };
    let (s, c) = (i64::from(s), i64::from(c));
    let (s, c) = match quadrant {
        0 => (s, c),
        1 => (c, s.saturating_neg()),
        2 => (s.saturating_neg(), c.saturating_neg()),
        _ => (c.saturating_neg(), s),
    };
    SinCosQ31 {
        sin: saturate_i32(s),
        cos: saturate_i32(c),
    }
}

/// atan(num/den) for 0 ≤ num ≤ den ≤ 2^31, den > 0, as a π-scaled angle in
/// \[0, 2^29\].
fn atan_first_octant(num: i64, den: i64) -> i64 {
    // t = num/den in Q.31, rounded; num ≤ 2^31 so num·2^31 ≤ 2^62.
    let t = div_round(num << 31, den);
    let (t, offset) = if t > TAN_PI_8_Q31 {
        // atan t = π/4 + atan((t−1)/(t+1)), with (t−1)/(t+1) ∈ (−tan π/8, 0].
        let q = div_round(num.saturating_sub(den) << 31, num.saturating_add(den));
        (q, i64::from(EIGHTH_TURN))
    } else {
        (t, 0)
    };
    // atan t = t·(1 − t²/3 + t⁴/5 − … − t²⁰/21), |t| ≤ tan(π/8): the first omitted term
    // t²³/23 ≤ 7·10⁻¹¹.
    const INV_ODD: [i64; 11] = [
        2_147_483_648, // 1/1
        715_827_883,   // 1/3
        429_496_730,   // 1/5
        306_783_378,   // 1/7
        238_609_294,   // 1/9
        195_225_786,   // 1/11
        165_191_050,   // 1/13
        143_165_577,   // 1/15
        126_322_567,   // 1/17
        113_025_455,   // 1/19
        102_261_126,   // 1/21
    ];
    let t2 = q31::mul(t, t);
    let mut p = 0;
    for c in INV_ODD.iter().rev() {
        p = c.saturating_sub(q31::mul(t2, p));
    }
    let radians = q31::mul(t, p);
    // radians (Q.31, |.| ≤ π/4·2^31) × 2^32/π → π-scaled angle.
    let scaled = radians.saturating_mul(INV_PI_Q32).saturating_add(1 << 31) >> 32;
    offset.saturating_add(scaled)
}

/// `atan2(y, x)/π` as a Q1.31 angle (the π-scaled format of (4.20)), 0 for (0, 0).
///
/// Octant reduction (exact), one division, and the Taylor series of atan on
/// |t| ≤ tan(π/8). |error| ≤ 1 LSB.
pub fn atan2_q31(y: i32, x: i32) -> i32 {
    if x == 0 && y == 0 {
        return 0;
    }
    let (ax, ay) = (i64::from(x.unsigned_abs()), i64::from(y.unsigned_abs()));
    let first = if ay <= ax {
        atan_first_octant(ay, ax)
    } else {
        // π/2 − atan(x/y)
        i64::from(QUARTER_TURN).saturating_sub(atan_first_octant(ax, ay))
    };
    // π − φ in the left half-plane.
    let half = if x < 0 { ONE.saturating_sub(first) } else { first };
    // `half` ∈ [0, 2^31]; 2^31 (= π) wraps to −π, the same angle.
    let angle = half as u32 as i32;
    if y < 0 { angle.wrapping_neg() } else { angle }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;
    use proptest::prelude::*;

    const Q31: f64 = 2_147_483_648.0;

    /// f64 reference, clamped to the Q1.31 range as the CORDIC saturates +1.0.
    fn sin_cos_ref(theta: i32) -> (f64, f64) {
        let x = f64::from(theta) * PI / Q31;
        let clamp = |v: f64| (v * Q31).clamp(-Q31, Q31 - 1.0);
        (clamp(x.sin()), clamp(x.cos()))
    }

    /// Error in LSB of a π-scaled angle against a reference in radians, wrapped.
    fn angle_err_lsb(a: i32, reference: f64) -> f64 {
        let d = f64::from(a) * PI / Q31 - reference;
        let d = d - 2.0 * PI * ((d + PI) / (2.0 * PI)).floor();
        d.abs() / PI * Q31
    }

    /// Dense sweep of the whole turn (every 2^12-th angle plus the octant
    /// boundaries ±2): |error| ≤ 2 LSB of Q1.31 (measured 1.59). Reports the maximum.
    #[test]
    fn sin_cos_sweep() {
        let mut worst = 0.0f64;
        let mut check = |t: i32| {
            let r = sin_cos_q31(t);
            let (s, c) = sin_cos_ref(t);
            worst = worst
                .max((f64::from(r.sin) - s).abs())
                .max((f64::from(r.cos) - c).abs());
        };
        for k in 0..(1u32 << 20) {
            check((k << 12) as i32);
        }
        for oct in 0..8u32 {
            let b = (oct << 29) as i32;
            for d in -2..=2 {
                check(b.wrapping_add(d));
            }
        }
        assert!(worst <= 2.0, "worst sin/cos error {worst} LSB");
        eprintln!("sin_cos_q31 worst error: {worst:.3} LSB");
    }

    #[test]
    fn exact_points() {
        assert_eq!(sin_cos_q31(0), SinCosQ31 { sin: 0, cos: i32::MAX });
        assert_eq!(sin_cos_q31(1 << 30), SinCosQ31 { sin: i32::MAX, cos: 0 });
        assert_eq!(sin_cos_q31(i32::MIN), SinCosQ31 { sin: 0, cos: i32::MIN });
        assert_eq!(sin_cos_q31(-(1 << 30)), SinCosQ31 { sin: i32::MIN, cos: 0 });
        assert_eq!(atan2_q31(0, 0), 0);
        assert_eq!(atan2_q31(0, 1000), 0);
        assert_eq!(atan2_q31(1000, 0), 1 << 30);
        assert_eq!(atan2_q31(-1000, 0), -(1 << 30));
        assert_eq!(atan2_q31(0, -1000), i32::MIN);
        assert_eq!(atan2_q31(1000, 1000), 1 << 29);
        assert_eq!(atan2_q31(i32::MIN, i32::MIN), -(3 << 29));
    }

    /// Sweep of atan2 on a circle of radius 0.9 (as from the resolver): ≤ 1 LSB
    /// (measured 0.85).
    #[test]
    fn atan2_sweep() {
        let mut worst = 0.0f64;
        for k in 0..(1u32 << 18) {
            let th = f64::from(k) / f64::from(1u32 << 18) * 2.0 * PI - PI;
            let (y, x) = ((0.9 * th.sin() * Q31) as i32, (0.9 * th.cos() * Q31) as i32);
            let reference = f64::from(y).atan2(f64::from(x));
            worst = worst.max(angle_err_lsb(atan2_q31(y, x), reference));
        }
        assert!(worst <= 1.0, "worst atan2 error {worst} LSB");
        eprintln!("atan2_q31 worst error: {worst:.3} LSB");
    }

    proptest! {
        #[test]
        fn sin_cos_random(t in any::<i32>()) {
            let r = sin_cos_q31(t);
            let (s, c) = sin_cos_ref(t);
            // Bound: 2 LSB of Q1.31 (Horner rounding ≤ 0.5 LSB per step damped by
            // z² ≤ 0.62, coefficient and π rounding, final product 0.5 LSB).
            prop_assert!((f64::from(r.sin) - s).abs() <= 2.0);
            prop_assert!((f64::from(r.cos) - c).abs() <= 2.0);
        }

        #[test]
        fn atan2_random(y in any::<i32>(), x in any::<i32>()) {
            prop_assume!(x != 0 || y != 0);
            let reference = f64::from(y).atan2(f64::from(x));
            // Bound: 1 LSB of the π-scaled angle (ratio rounding 0.5 LSB of Q.31
            // radians = 0.16 LSB here, series ≤ 0.2, conversion by 1/π 0.5).
            prop_assert!(angle_err_lsb(atan2_q31(y, x), reference) <= 1.0);
        }

        /// atan2 inverts sin/cos: round trip within 2 LSB (sin/cos error 2 LSB of
        /// Q1.31 moves the angle by ≤ 2·2^-31 rad = 2/π LSB, plus atan2's 1).
        #[test]
        fn round_trip(t in any::<i32>()) {
            let sc = sin_cos_q31(t);
            let back = atan2_q31(sc.sin, sc.cos);
            prop_assert!((back.wrapping_sub(t)).unsigned_abs() <= 2);
        }
    }
}
