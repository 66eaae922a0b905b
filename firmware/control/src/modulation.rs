//! Third-harmonic-injection PWM (THPWM), thesis A §3.2, in `f32`.
//!
//! 1. phase voltages from the inverse Clarke transformation of u_αβ (the αβ vector
//!    is the inverse Park of u_dq at the angle used for modulation);
//! 2. common-mode term (3.7) `u_NM = −U_dc/(6√3)·cos 3(θ_e + atan2(u_q, u_d))`;
//!    `θ_e + atan2(u_q, u_d)` is the angle φ of the αβ voltage vector, so we evaluate
//!    `cos 3φ = 4·cos³φ − 3·cos φ` with `cos φ = u_α/|u_αβ|` (no trigonometric call);
//! 3. (3.8) `u_x = ũ_x + u_NM`;
//! 4. duty (3.4)/(5.1): `DC_x = 1/2 + u_x/U_dc`, saturated to \[0, 1\].
//!
//! With a duty limit `d_max < 1` (low-side shunts need the low side on around the
//! carrier maximum for the sampling, and on every board each compare value stays a dead
//! time from the carrier's ends, so that each edge's dead interval falls in its own
//! period; the generated `board::MAX_DUTY`, `codegen::design::duty_limit`)
//! [`thpwm_limited`] scales the three phase voltages of
//! step 3 together by `(d_max − 1/2)·U_dc / max_x |u_x|` when their peak exceeds it: the
//! line-to-line voltages shrink by one factor, so the voltage vector keeps its angle and
//! only its length is cut, and every duty stays in `[1 − d_max, d_max]`. The step's
//! voltage limit is the usable fraction of U_dc/√3 that keeps the modulator inside this
//! range (`USABLE_VOLTAGE_FRACTION`), so the scaling only acts on what the limit lets
//! through by rounding or a DC link that moved within the period; clamping one duty
//! alone would turn the vector instead.
//!
//! Linear range: |u_αβ| ≤ U_dc/√3 (modulation index M = 1.15, (3.6)). There the
//! duties stay inside \[0, 1\] for every angle: the phase peak is
//! `max_x(a·cos x − b·cos 3x)` with `b = U_dc/(6√3)` fixed; it is convex in the
//! amplitude a, equal to b ≤ U_dc/2 at a = 0 and to U_dc/2 at a = 6b = U_dc/√3.

use crate::transforms::{AlphaBeta, Uvw, inverse_clarke};
use crate::trig::Trig;

/// 1/(6√3), the common-mode amplitude per volt of DC link (3.7).
pub const THIRD_HARMONIC_PER_VOLT: f32 = 0.096_225_045;

/// Common-mode voltage u_NM of (3.7) \[V\] for the αβ voltage `u` and DC-link `u_dc`
/// \[V\]; 0 for a zero vector (its angle is undefined).
pub fn common_mode<T: Trig + ?Sized>(u: AlphaBeta, u_dc: f32, trig: &mut T) -> f32 {
    let mag = trig.sqrt(u.alpha * u.alpha + u.beta * u.beta);
    if !(mag > 0.0 && mag.is_finite()) {
        return 0.0;
    }
    let c = (u.alpha / mag).clamp(-1.0, 1.0);
    let cos3 = (4.0 * c * c - 3.0) * c;
    -u_dc * THIRD_HARMONIC_PER_VOLT * cos3
}

/// Phase voltages with third-harmonic injection (3.8) \[V\], referred to the DC-link
/// midpoint M.
pub fn phase_voltages<T: Trig + ?Sized>(u: AlphaBeta, u_dc: f32, trig: &mut T) -> Uvw {
    let base = inverse_clarke(u);
    let nm = common_mode(u, u_dc, trig);
    Uvw {
        u: base.u + nm,
        v: base.v + nm,
        w: base.w + nm,
    }
}

/// Saturates to \[0, 1\]; NaN gives 0.
fn unit(x: f32) -> f32 {
    if x >= 1.0 {
        1.0
    } else if x > 0.0 {
        x
    } else {
        0.0
    }
}

/// Duty cycles `1/2 + u_x·(1/U_dc)` (3.4 inverted, DC-link feed-forward (5.1)),
/// saturated to \[0, 1\]. `inv_u_dc` comes from [`crate::feedforward::dc_link_gain`].
pub fn duties(phase: Uvw, inv_u_dc: f32) -> [f32; 3] {
    [
        unit(0.5 + phase.u * inv_u_dc),
        unit(0.5 + phase.v * inv_u_dc),
        unit(0.5 + phase.w * inv_u_dc),
    ]
}

/// The phase voltages scaled together so that their peak is at most
/// `(max_duty − 1/2)·u_dc` (module documentation): unchanged within it; the vector's
/// angle kept beyond it. A non-finite peak gives zeros (the duties then 1/2).
pub fn limit_phase_peak(phase: Uvw, u_dc: f32, max_duty: f32) -> Uvw {
    // Comparisons, not `f32::max` (a libm call on the Cortex-M4, whose FPU has no
    // VMAXNM): a NaN phase leaves the peak finite here and its duty saturates to 0.
    let (av, aw) = (phase.v.abs(), phase.w.abs());
    let mut peak = phase.u.abs();
    if av > peak {
        peak = av;
    }
    if aw > peak {
        peak = aw;
    }
    let room = (max_duty - 0.5) * u_dc;
    if peak <= room {
        return phase;
    }
    let k = if peak.is_finite() && room > 0.0 {
        room / peak
    } else {
        0.0
    };
    let s = |x: f32| {
        let y = x * k;
        if y.is_finite() { y } else { 0.0 }
    };
    Uvw {
        u: s(phase.u),
        v: s(phase.v),
        w: s(phase.w),
    }
}

/// THPWM duties for the αβ voltage `u` \[V\] at the DC-link voltage `u_dc` \[V\]
/// (already guarded, see [`crate::feedforward::effective_dc_link`]) with
/// `inv_u_dc = 1/u_dc`.
pub fn thpwm<T: Trig + ?Sized>(u: AlphaBeta, u_dc: f32, inv_u_dc: f32, trig: &mut T) -> [f32; 3] {
    duties(phase_voltages(u, u_dc, trig), inv_u_dc)
}

/// [`thpwm`] with the duties limited to `max_duty` (and `1 − max_duty`) by scaling the
/// phase voltages together ([`limit_phase_peak`]), then each duty saturated to
/// \[0, `max_duty`\] against rounding.
pub fn thpwm_limited<T: Trig + ?Sized>(
    u: AlphaBeta,
    u_dc: f32,
    inv_u_dc: f32,
    max_duty: f32,
    trig: &mut T,
) -> [f32; 3] {
    let phase = limit_phase_peak(phase_voltages(u, u_dc, trig), u_dc, max_duty);
    duties(phase, inv_u_dc).map(|d| if d > max_duty { max_duty } else { d })
}

/// Timer compare values `round(DC·period)` for centre-aligned PWM with auto-reload
/// `period`, each in `0..=period`.
pub fn compare_values(duties: [f32; 3], period: u16) -> [u16; 3] {
    let p = f32::from(period);
    // `as u16` saturates (NaN and negatives → 0, beyond 65 535 → 65 535) and `min` keeps
    // the result within the period: the same as saturating the duty to [0, 1] first,
    // without doing it twice (`duties` already has).
    duties.map(|d| ((d * p + 0.5) as u16).min(period))
}

/// The auto-reload of a centre-aligned (up/down) carrier at `switching_hz` from a
/// `timer_hz` kernel clock: one carrier period is `2·ARR` timer ticks, so
/// `ARR = round(f_tim/(2·f_s))` (RM0440 §28.3.3, thesis A Fig. 3.4) — the `period` of
/// [`compare_values`]. `None` if it does not fit the 16-bit register or is zero.
pub const fn centre_aligned_period(timer_hz: u32, switching_hz: f32) -> Option<u16> {
    let arr = timer_hz as f32 / (2.0 * switching_hz) + 0.5;
    // Also rejects NaN, ∞ and f_s ≤ 0 (the comparisons are false).
    if arr >= 1.0 && arr <= u16::MAX as f32 {
        Some(arr as u16)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trig::SoftTrig;
    use core::f64::consts::PI;
    use proptest::prelude::*;

    /// Thesis A: f_s = 20 kHz from a 170 MHz timer clock, centre-aligned:
    /// 170e6/(2·20e3) = 4250 (hand calculation); 16 kHz → 5312.5 → 5313; 1 kHz → 85 000,
    /// beyond the 16-bit register.
    #[test]
    fn pwm_period() {
        assert_eq!(centre_aligned_period(170_000_000, 20_000.0), Some(4250));
        assert_eq!(centre_aligned_period(170_000_000, 16_000.0), Some(5313));
        assert_eq!(centre_aligned_period(170_000_000, 1_000.0), None);
        assert_eq!(centre_aligned_period(170_000_000, 0.0), None);
        assert_eq!(centre_aligned_period(170_000_000, f32::NAN), None);
    }

    /// f64 reference of (3.7), (3.8), (3.4) with the thesis' formula literally:
    /// u_NM = −U_dc/(6√3)·cos 3(θ + atan2(u_q, u_d)).
    fn reference(ud: f64, uq: f64, th: f64, udc: f64) -> [f64; 3] {
        let alpha = th.cos() * ud - th.sin() * uq;
        let beta = th.sin() * ud + th.cos() * uq;
        let s = 3f64.sqrt() / 2.0;
        let ph = [alpha, -0.5 * alpha + s * beta, -0.5 * alpha - s * beta];
        let nm = -udc / (6.0 * 3f64.sqrt()) * (3.0 * (th + uq.atan2(ud))).cos();
        ph.map(|p| 0.5 + (p + nm) / udc)
    }

    proptest! {
        /// Inside the linear range |u| ≤ U_dc/√3 the duties match the f64 reference
        /// (f32 operands ≤ U_dc: error ≤ ~16·ε_f32 in duty ≈ 1e-6; we allow 1e-5 since
        /// sin/cos of θ are rounded to f32 before the inverse Park) and lie in \[0, 1\].
        #[test]
        fn duties_match_f64_and_stay_in_range(m in 0f64..=1.0, phi in -PI..PI, th in -PI..PI, udc in 50f64..800.0) {
            let mag = m * udc / 3f64.sqrt();
            let (ud, uq) = (mag * phi.cos(), mag * phi.sin());
            let sc = crate::transforms::SinCos { sin: th.sin() as f32, cos: th.cos() as f32 };
            let ab = crate::transforms::inverse_park(crate::transforms::Dq { d: ud as f32, q: uq as f32 }, sc);
            let d = thpwm(ab, udc as f32, 1.0 / udc as f32, &mut SoftTrig);
            let r = reference(ud, uq, th, udc);
            for k in 0..3 {
                prop_assert!(d[k] >= 0.0 && d[k] <= 1.0);
                // The reference may exceed [0, 1] by rounding only at the boundary.
                prop_assert!((f64::from(d[k]) - r[k].clamp(0.0, 1.0)).abs() < 1e-5, "{k}: {} vs {}", d[k], r[k]);
            }
        }

        /// The duties reproduce the requested line-to-line voltages:
        /// (DC_u − DC_v)·U_dc = ũ_u − ũ_v for |u| ≤ U_dc/√3 (common mode cancels).
        #[test]
        fn line_to_line_voltages(m in 0f64..=0.999, phi in -PI..PI, udc in 50f64..800.0) {
            let mag = m * udc / 3f64.sqrt();
            let ab = AlphaBeta { alpha: (mag * phi.cos()) as f32, beta: (mag * phi.sin()) as f32 };
            let d = thpwm(ab, udc as f32, 1.0 / udc as f32, &mut SoftTrig);
            let ph = inverse_clarke(ab);
            let want = [ph.u - ph.v, ph.v - ph.w, ph.w - ph.u];
            let got = [d[0] - d[1], d[1] - d[2], d[2] - d[0]];
            for k in 0..3 {
                // f32 duty resolution near 0.5: 2^-24 → ×U_dc, a few roundings.
                let err = (f64::from(got[k]) * udc - f64::from(want[k])).abs();
                prop_assert!(err <= 8.0 * f64::from(f32::EPSILON) * udc, "{k}: {err}");
            }
        }

        /// Beyond the linear range the duties saturate but stay in \[0, 1\]; also for
        /// non-finite inputs.
        #[test]
        fn saturates(alpha in proptest::num::f32::ANY, beta in proptest::num::f32::ANY) {
            let d = thpwm(AlphaBeta { alpha, beta }, 600.0, 1.0 / 600.0, &mut SoftTrig);
            for x in d {
                prop_assert!((0.0..=1.0).contains(&x));
            }
            for c in compare_values(d, 4250) {
                prop_assert!(c <= 4250);
            }
        }
    }

    /// At exactly |u| = U_dc/√3 the largest duty reaches 1 (full DC-link use) and the
    /// smallest 0, up to f32 rounding.
    #[test]
    fn linear_limit_uses_full_dc_link() {
        let udc = 600.0f32;
        let mag = udc * crate::transforms::INV_SQRT_3;
        let mut hi = 0.0f32;
        let mut lo = 1.0f32;
        for k in 0..3600 {
            let phi = (k as f32 / 10.0).to_radians();
            let d = thpwm(
                AlphaBeta {
                    alpha: mag * phi.cos(),
                    beta: mag * phi.sin(),
                },
                udc,
                1.0 / udc,
                &mut SoftTrig,
            );
            hi = hi.max(d[0].max(d[1]).max(d[2]));
            lo = lo.min(d[0].min(d[1]).min(d[2]));
        }
        assert!(hi > 0.9999 && lo < 1e-4, "{lo} {hi}");
    }

    proptest! {
        /// With a duty limit every duty lies in [1 − d_max, d_max] (any input, also
        /// non-finite) and inside it nothing changes; beyond it the line-to-line voltages
        /// keep their ratios (the vector's angle): (d_u − d_v)/(d_v − d_w) equals the
        /// unlimited phases' (u_u − u_v)/(u_v − u_w).
        #[test]
        fn duty_limit_keeps_the_angle(m in 0f64..=1.5, phi in -PI..PI, udc in 10f64..800.0, dmax in 0.6f64..=1.0) {
            let (udc, dmax) = (udc as f32, dmax as f32);
            let mag = m as f32 * udc * crate::transforms::INV_SQRT_3;
            let ab = AlphaBeta { alpha: mag * (phi as f32).cos(), beta: mag * (phi as f32).sin() };
            let d = thpwm_limited(ab, udc, 1.0 / udc, dmax, &mut SoftTrig);
            let free = phase_voltages(ab, udc, &mut SoftTrig);
            let peak = free.u.abs().max(free.v.abs()).max(free.w.abs());
            for x in d {
                prop_assert!(x <= dmax && x >= 1.0 - dmax - 1e-6, "{x} {dmax}");
            }
            if peak <= (dmax - 0.5) * udc {
                let plain = thpwm(ab, udc, 1.0 / udc, &mut SoftTrig);
                prop_assert_eq!(d, plain);
            } else {
                // Compare the line-to-line vector's direction: cross product ≈ 0.
                let got = [d[0] - d[1], d[1] - d[2]];
                let want = [free.u - free.v, free.v - free.w];
                let cross = got[0] * want[1] - got[1] * want[0];
                let scale = (got[0].hypot(got[1]) * want[0].hypot(want[1])).max(1e-6);
                prop_assert!((cross / scale).abs() < 1e-4, "{cross} {scale}");
            }
        }

        /// Non-finite inputs stay within [0, d_max].
        #[test]
        fn duty_limit_saturates(alpha in proptest::num::f32::ANY, beta in proptest::num::f32::ANY) {
            for x in thpwm_limited(AlphaBeta { alpha, beta }, 48.0, 1.0 / 48.0, 0.9, &mut SoftTrig) {
                prop_assert!((0.0..=0.9).contains(&x), "{x}");
            }
        }
    }

    /// Hand calculation: U_dc = 48 V, d_max = 0.9 leaves a phase peak of 0.4·48 = 19.2 V.
    /// Phases (24, −12, −12) V scale by 19.2/24 = 0.8 to (19.2, −9.6, −9.6) V: duties
    /// 0.5 + 19.2/48 = 0.9 and 0.5 − 9.6/48 = 0.3.
    #[test]
    fn duty_limit_by_hand() {
        let p = limit_phase_peak(
            Uvw {
                u: 24.0,
                v: -12.0,
                w: -12.0,
            },
            48.0,
            0.9,
        );
        assert!(
            (p.u - 19.2).abs() < 1e-5 && (p.v + 9.6).abs() < 1e-5 && (p.w + 9.6).abs() < 1e-5,
            "{p:?}"
        );
        let d = duties(p, 1.0 / 48.0);
        assert!((d[0] - 0.9).abs() < 1e-6 && (d[1] - 0.3).abs() < 1e-6, "{d:?}");
        // Within the room: unchanged.
        let q = Uvw {
            u: 10.0,
            v: -5.0,
            w: -5.0,
        };
        assert_eq!(limit_phase_peak(q, 48.0, 0.9), q);
    }

    #[test]
    fn compare_values_round() {
        assert_eq!(compare_values([0.0, 0.5, 1.0], 4250), [0, 2125, 4250]);
        assert_eq!(compare_values([f32::NAN, -1.0, 2.0], 100), [0, 0, 100]);
    }
}
