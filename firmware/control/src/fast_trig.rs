//! [`FastTrig`]: software sin/cos and atan2 with the CORDIC's Q1.31 interface, in
//! single-precision floating point (the Cortex-M4F's FPU), accurate to 2^-23 (measured 199 LSB of Q1.31, 9.3·10⁻⁸) —
//! the counterpart of the CORDIC as the board configures it (PRECISION = 6, residual
//! error of order 2^-19, RM0440's precision table), at a fraction of [`SoftTrig`]'s
//! cost. [`SoftTrig`] stays the reference (2 LSB of Q1.31).
//!
//! * sin/cos: the π-scaled angle (4.20) is reduced in integer arithmetic to the nearest
//!   quarter turn k·π/2 and a remainder x ∈ [−π/4, π/4); Taylor polynomials to x⁹ (sin)
//!   and x¹⁰ (cos) — truncation ≤ (π/4)¹¹/11! = 1.8·10⁻⁹ and (π/4)¹²/12! = 1.1·10⁻¹⁰ —
//!   then sin(x + k·π/2), cos(x + k·π/2) by a quarter-turn rotation.
//! * atan2: the ratio t = min(|x|, |y|)/max(|x|, |y|) ∈ [0, 1]; above tan(π/8),
//!   atan t = π/4 + atan((t − 1)/(t + 1)), so the odd Taylor series always runs on
//!   |u| ≤ tan(π/8) = 0.4142 — to u¹⁵, truncation ≤ 0.4142¹⁷/17 = 1.8·10⁻⁸ — then the
//!   octant and quadrant are restored and the angle is scaled by 2^31/π.
//!
//! The float → Q1.31 conversions saturate (`as` casts: +1.0 → `i32::MAX`; on the
//! Cortex-M4F one `vcvt`); the angle reduction wraps, as angles do.
//!
//! [`SoftTrig`]: crate::trig::SoftTrig

use core::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use crate::q31;
use crate::trig::{SinCosQ31, Trig};

/// Floating-point software implementation of [`Trig`] (see the module docs).
#[derive(Clone, Copy, Debug, Default)]
pub struct FastTrig;

/// Radians per LSB of the π-scaled Q1.31 angle: π/2^31.
const RAD_PER_LSB: f32 = PI / 2_147_483_648.0;
/// 2^31/π: radians → π-scaled Q1.31 angle.
const LSB_PER_RAD: f32 = 2_147_483_648.0 / PI;
/// A quarter turn in the π-scaled angle (π/2 ↔ 2^30).
const QUARTER_TURN_BITS: u32 = 30;
/// tan(π/8) = √2 − 1: the split point of the atan reduction.
const TAN_PI_8: f32 = 0.414_213_57;

/// sin x for |x| ≤ π/4: x − x³/3! + x⁵/5! − x⁷/7! + x⁹/9! (Horner in x²).
fn sin_poly(x: f32) -> f32 {
    let x2 = x * x;
    x * (1.0 + x2 * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5_040.0 + x2 * (1.0 / 362_880.0)))))
}

/// cos x for |x| ≤ π/4: 1 − x²/2! + x⁴/4! − x⁶/6! + x⁸/8! − x¹⁰/10!.
fn cos_poly(x: f32) -> f32 {
    let x2 = x * x;
    1.0 + x2 * (-0.5 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40_320.0 + x2 * (-1.0 / 3_628_800.0)))))
}

/// atan u for |u| ≤ tan(π/8): u − u³/3 + u⁵/5 − … − u¹⁵/15.
fn atan_poly(u: f32) -> f32 {
    let u2 = u * u;
    let tail = -1.0 / 15.0;
    let tail = 1.0 / 13.0 + u2 * tail;
    let tail = -1.0 / 11.0 + u2 * tail;
    let tail = 1.0 / 9.0 + u2 * tail;
    let tail = -1.0 / 7.0 + u2 * tail;
    let tail = 1.0 / 5.0 + u2 * tail;
    let tail = -1.0 / 3.0 + u2 * tail;
    u * (1.0 + u2 * tail)
}

/// sin θ and cos θ of the π-scaled angle `theta` (4.20), Q1.31.
pub fn sin_cos_fast(theta: i32) -> SinCosQ31 {
    // Nearest quarter turn k and the remainder r ∈ [−2^29, 2^29) (wrapping: angles).
    let u = theta as u32;
    let k = u.wrapping_add(1 << (QUARTER_TURN_BITS - 1)) >> QUARTER_TURN_BITS;
    let r = u.wrapping_sub(k << QUARTER_TURN_BITS) as i32;
    let x = r as f32 * RAD_PER_LSB;
    let (s, c) = (sin_poly(x), cos_poly(x));
    // sin(x + k·π/2), cos(x + k·π/2).
    let (sin, cos) = match k {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    };
    SinCosQ31 {
        sin: q31::from_f32(sin),
        cos: q31::from_f32(cos),
    }
}

/// atan2(y, x)/π as a π-scaled Q1.31 angle; 0 for (0, 0).
pub fn atan2_fast(y: i32, x: i32) -> i32 {
    if x == 0 && y == 0 {
        return 0;
    }
    let (fx, fy) = (x as f32, y as f32);
    let (ax, ay) = (fx.abs(), fy.abs());
    let steep = ay > ax;
    let t = if steep { ax / ay } else { ay / ax };
    let a = if t > TAN_PI_8 {
        FRAC_PI_4 + atan_poly((t - 1.0) / (t + 1.0))
    } else {
        atan_poly(t)
    };
    let a = if steep { FRAC_PI_2 - a } else { a };
    let a = if fx < 0.0 { PI - a } else { a };
    let a = if fy < 0.0 { -a } else { a };
    // π → 2^31 saturates to i32::MAX, one LSB short of the wrapped −π: the same angle.
    (a * LSB_PER_RAD) as i32
}

impl Trig for FastTrig {
    fn sin_cos(&mut self, theta: i32) -> SinCosQ31 {
        sin_cos_fast(theta)
    }
    fn atan2(&mut self, y: i32, x: i32) -> i32 {
        atan2_fast(y, x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI as PI64;

    /// The accuracy bound the module promises: 2^-23 of full scale (256 LSB of Q1.31)
    /// for sin/cos, and 2^-23·π rad for atan2 — f32 rounding (2^-24 relative) plus the
    /// series truncations (≤ 1.8·10⁻⁸); far tighter than the CORDIC's ≈2^-19 at
    /// PRECISION = 6.
    const BOUND_LSB: f64 = 256.0;

    fn angles() -> impl Iterator<Item = i32> {
        // Every 2^16-th angle of the turn (65 536 angles) plus the quarter-turn
        // boundaries and their neighbours.
        let grid = (0..1u64 << 16).map(|i| (i << 16) as u32 as i32);
        let edges = [0i64, 1 << 29, 1 << 30, 3 << 29, 1 << 31, 5 << 29, 3 << 30, 7 << 29]
            .into_iter()
            .flat_map(|e| [e - 1, e, e + 1])
            .map(|e| e as u32 as i32);
        grid.chain(edges)
    }

    #[test]
    fn sin_cos_within_2_pow_minus_23_of_f64() {
        let mut worst: f64 = 0.0;
        for theta in angles() {
            let rad = f64::from(theta) * PI64 / 2_147_483_648.0;
            let sc = sin_cos_fast(theta);
            let es = (f64::from(sc.sin) - rad.sin() * 2_147_483_648.0).abs();
            let ec = (f64::from(sc.cos) - rad.cos() * 2_147_483_648.0).abs();
            worst = worst.max(es).max(ec);
        }
        println!("FastTrig sin/cos worst error: {worst:.0} LSB of Q1.31");
        assert!(worst <= BOUND_LSB, "{worst} LSB");
    }

    #[test]
    fn atan2_within_2_pow_minus_23_of_f64_on_every_octant() {
        let mut worst: f64 = 0.0;
        for theta in angles() {
            // Points on circles of several radii (the ratio is what matters).
            for scale in [1.0, 0.25, 1.0e-4] {
                let rad = f64::from(theta) * PI64 / 2_147_483_648.0;
                let x = (rad.cos() * scale * 2.0e9).round() as i32;
                let y = (rad.sin() * scale * 2.0e9).round() as i32;
                if x == 0 && y == 0 {
                    continue;
                }
                let exact = f64::from(y).atan2(f64::from(x)) / PI64 * 2_147_483_648.0;
                let got = f64::from(atan2_fast(y, x));
                // Angles wrap: compare on the circle.
                let mut e = (got - exact).rem_euclid(4_294_967_296.0);
                if e > 2_147_483_648.0 {
                    e = 4_294_967_296.0 - e;
                }
                worst = worst.max(e);
            }
        }
        println!("FastTrig atan2 worst error: {worst:.0} LSB of the π-scaled angle");
        assert!(worst <= BOUND_LSB, "{worst} LSB");
        assert_eq!(atan2_fast(0, 0), 0);
    }

    /// Exact quarter turns land on the axes: sin, cos ∈ {0, ±1} (±1 saturated).
    #[test]
    fn quarter_turns_are_exact() {
        let one = i32::MAX;
        let cases = [
            (0i32, 0, one),
            (1 << 30, one, 0),
            (i32::MIN, 0, -one),
            (-(1 << 30), -one, 0),
        ];
        for (theta, s, c) in cases {
            let sc = sin_cos_fast(theta);
            assert!((sc.sin - s).abs() <= 1 && (sc.cos - c).abs() <= 1, "{theta}: {sc:?}");
        }
    }
}
