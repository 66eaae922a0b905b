//! Clarke and Park transformations, thesis A §2.1, in `f32`.
//!
//! * forward Clarke, amplitude invariant (2.7): `[i_α, i_β] = 2/3·T_C·[i_u, i_v, i_w]`;
//! * forward Park (2.8): rotation of the αβ vector into the frame turned by θ_e.
//!
//! Sign convention of Park: thesis A describes (2.8) as "a simple clockwise rotation
//! by θ_e", i.e. `i_d = cos θ_e·i_α + sin θ_e·i_β`, `i_q = −sin θ_e·i_α + cos θ_e·i_β`.
//! That is the convention under which the dq model (2.26) holds (back EMF `+ω_e·ψ_M`
//! in the q axis) and under which a positive α voltage aligns the rotor at θ_e = 0
//! (6.3). The matrix as printed in (2.8) has the signs of the sine terms swapped
//! (a counter-clockwise rotation); we follow the text and the model.

/// √3/2, from the Clarke matrix T_C (2.7).
pub const SQRT_3_OVER_2: f32 = 0.866_025_4;
/// 1/√3 (2.7 with i_w = −i_u − i_v; also V_max = U_dc/√3, thesis B §2.3).
pub const INV_SQRT_3: f32 = 0.577_350_26;
/// 2/3, the amplitude-invariant scaling K of (2.7).
pub const TWO_THIRDS: f32 = 2.0 / 3.0;

/// Three phase quantities (currents in A or voltages in V).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Uvw {
    /// Phase u.
    pub u: f32,
    /// Phase v.
    pub v: f32,
    /// Phase w.
    pub w: f32,
}

/// A vector in the stationary αβ frame (2.7).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AlphaBeta {
    /// α component (aligned with phase u).
    pub alpha: f32,
    /// β component.
    pub beta: f32,
}

/// A vector in the rotor dq frame (2.8).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dq {
    /// Direct (flux) axis.
    pub d: f32,
    /// Quadrature (torque) axis.
    pub q: f32,
}

/// sin θ_e and cos θ_e for the Park transformations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SinCos {
    /// sin θ_e.
    pub sin: f32,
    /// cos θ_e.
    pub cos: f32,
}

impl Default for SinCos {
    /// θ_e = 0.
    fn default() -> Self {
        Self { sin: 0.0, cos: 1.0 }
    }
}

/// Amplitude-invariant forward Clarke transformation from three phases (2.7):
/// `i_α = 2/3·(i_u − i_v/2 − i_w/2)`, `i_β = 2/3·√3/2·(i_v − i_w)`.
///
/// A zero-sequence part (`i_u + i_v + i_w ≠ 0`) does not enter αβ; see
/// [`zero_sequence`].
pub fn clarke(x: Uvw) -> AlphaBeta {
    AlphaBeta {
        alpha: TWO_THIRDS * (x.u - 0.5 * x.v - 0.5 * x.w),
        beta: TWO_THIRDS * SQRT_3_OVER_2 * (x.v - x.w),
    }
}

/// Forward Clarke transformation from phases u and v only, assuming the balanced
/// system (2.1) `i_u + i_v + i_w = 0`: (2.7) with `i_w = −i_u − i_v` gives
/// `i_α = i_u`, `i_β = (i_u + 2·i_v)/√3`.
pub fn clarke_uv(u: f32, v: f32) -> AlphaBeta {
    AlphaBeta {
        alpha: u,
        beta: INV_SQRT_3 * (u + 2.0 * v),
    }
}

/// Amplitude-invariant zero-sequence component `(i_u + i_v + i_w)/3` (thesis A §2.1.3:
/// non-zero only with a leakage path, e.g. an insulation fault).
pub fn zero_sequence(x: Uvw) -> f32 {
    (x.u + x.v + x.w) / 3.0
}

/// Forward Park transformation (2.8), clockwise rotation by θ_e:
/// `d = cos θ_e·α + sin θ_e·β`, `q = −sin θ_e·α + cos θ_e·β`.
pub fn park(x: AlphaBeta, sc: SinCos) -> Dq {
    Dq {
        d: sc.cos * x.alpha + sc.sin * x.beta,
        q: -sc.sin * x.alpha + sc.cos * x.beta,
    }
}

/// Inverse Park transformation, T_P⁻¹ of (2.29):
/// `α = cos θ_e·d − sin θ_e·q`, `β = sin θ_e·d + cos θ_e·q`.
pub fn inverse_park(x: Dq, sc: SinCos) -> AlphaBeta {
    AlphaBeta {
        alpha: sc.cos * x.d - sc.sin * x.q,
        beta: sc.sin * x.d + sc.cos * x.q,
    }
}

/// Inverse amplitude-invariant Clarke transformation, T_C⁻¹ of (2.29), zero-sequence
/// free: `u = α`, `v = −α/2 + √3/2·β`, `w = −α/2 − √3/2·β`.
pub fn inverse_clarke(x: AlphaBeta) -> Uvw {
    Uvw {
        u: x.alpha,
        v: -0.5 * x.alpha + SQRT_3_OVER_2 * x.beta,
        w: -0.5 * x.alpha - SQRT_3_OVER_2 * x.beta,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// f64 reference of (2.7): 2/3·T_C·x.
    fn clarke_ref(u: f64, v: f64, w: f64) -> (f64, f64) {
        let s = 3f64.sqrt() / 2.0;
        (2.0 / 3.0 * (u - 0.5 * v - 0.5 * w), 2.0 / 3.0 * (s * v - s * w))
    }

    /// f64 reference of (2.8) in the clockwise convention (see module docs).
    fn park_ref(a: f64, b: f64, th: f64) -> (f64, f64) {
        (th.cos() * a + th.sin() * b, -th.sin() * a + th.cos() * b)
    }

    /// f32 evaluation of a handful of products and sums of operands ≤ M: error
    /// ≤ (number of roundings)·ε_f32·M with ε_f32 = 2^-24 relative; we use 8·2^-24·M.
    fn bound(m: f64) -> f64 {
        8.0 * f64::from(f32::EPSILON) / 2.0 * m.max(1.0)
    }

    proptest! {
        #[test]
        fn clarke_matches_f64(u in -500f32..500.0, v in -500f32..500.0, w in -500f32..500.0) {
            let r = clarke(Uvw { u, v, w });
            let (a, b) = clarke_ref(u.into(), v.into(), w.into());
            // Bound: f32 rounding of operands ≤ 500 A, see `bound`.
            prop_assert!((f64::from(r.alpha) - a).abs() <= bound(1000.0));
            prop_assert!((f64::from(r.beta) - b).abs() <= bound(1000.0));
        }

        #[test]
        fn two_phase_clarke_equals_three_phase(u in -500f32..500.0, v in -500f32..500.0) {
            let w = -u - v;
            let r = clarke_uv(u, v);
            let (a, b) = clarke_ref(u.into(), v.into(), -f64::from(u) - f64::from(v));
            prop_assert!((f64::from(r.alpha) - a).abs() <= bound(1000.0));
            prop_assert!((f64::from(r.beta) - b).abs() <= bound(1000.0));
            let r3 = clarke(Uvw { u, v, w });
            prop_assert!((r3.beta - r.beta).abs() as f64 <= 2.0 * bound(1000.0));
        }

        #[test]
        fn park_matches_f64(a in -500f32..500.0, b in -500f32..500.0, th in -3.2f64..3.2) {
            let sc = SinCos { sin: th.sin() as f32, cos: th.cos() as f32 };
            let r = park(AlphaBeta { alpha: a, beta: b }, sc);
            let (d, q) = park_ref(a.into(), b.into(), th);
            // sin/cos rounded to f32 (ε/2 relative each) plus two products and a sum.
            prop_assert!((f64::from(r.d) - d).abs() <= bound(1000.0));
            prop_assert!((f64::from(r.q) - q).abs() <= bound(1000.0));
        }

        #[test]
        fn inverse_park_then_park_is_identity(d in -500f32..500.0, q in -500f32..500.0, th in -3.2f64..3.2) {
            let sc = SinCos { sin: th.sin() as f32, cos: th.cos() as f32 };
            let back = park(inverse_park(Dq { d, q }, sc), sc);
            // Two rotations: sin²+cos² = 1 only to ~2ε in f32.
            prop_assert!((back.d - d).abs() as f64 <= 2.0 * bound(1000.0));
            prop_assert!((back.q - q).abs() as f64 <= 2.0 * bound(1000.0));
        }

        #[test]
        fn inverse_clarke_then_clarke_is_identity(a in -500f32..500.0, b in -500f32..500.0) {
            let uvw = inverse_clarke(AlphaBeta { alpha: a, beta: b });
            prop_assert!(zero_sequence(uvw).abs() as f64 <= bound(1000.0));
            let back = clarke(uvw);
            prop_assert!((back.alpha - a).abs() as f64 <= 2.0 * bound(1000.0));
            prop_assert!((back.beta - b).abs() as f64 <= 2.0 * bound(1000.0));
        }
    }

    /// A balanced set of amplitude Î at electrical angle θ maps to the dq vector
    /// (Î, 0) — the amplitude invariance of (2.7) — and Park at θ gives d = Î, q = 0.
    #[test]
    fn balanced_set_is_amplitude_invariant() {
        let amp = 10.0f64;
        for k in 0..360 {
            let th = f64::from(k).to_radians();
            let third = 2.0 * core::f64::consts::PI / 3.0;
            let x = Uvw {
                u: (amp * th.cos()) as f32,
                v: (amp * (th - third).cos()) as f32,
                w: (amp * (th + third).cos()) as f32,
            };
            let ab = clarke(x);
            let sc = SinCos {
                sin: th.sin() as f32,
                cos: th.cos() as f32,
            };
            let dq = park(ab, sc);
            // f32 rounding on 10 A operands: ≤ 1e-5 A.
            assert!((f64::from(dq.d) - amp).abs() < 1e-5, "{k}: {dq:?}");
            assert!(f64::from(dq.q).abs() < 1e-5, "{k}: {dq:?}");
        }
    }
}
