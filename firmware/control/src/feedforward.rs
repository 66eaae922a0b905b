//! Feed-forward terms of the current loop, in `f32`:
//!
//! * decoupling and back-EMF compensation, thesis A (5.3):
//!   `u_ff = [[0, −ω_e·L_q], [ω_e·L_d, 0]]·i_dq + [0, ω_e·ψ_M]`;
//! * DC-link compensation, thesis A (5.1): `u/DC = U_dc`, inverted as
//!   `DC = u/U_dc`, with U_dc kept above a minimum so the gain stays bounded;
//! * torque → q current, thesis A (2.34): `i_q = T/K_t`, `K_t = 3/2·n_p·ψ_M`.

use crate::transforms::Dq;

/// 3/2, the amplitude-invariant power factor of (2.30) in K_t (2.34).
pub const THREE_HALVES: f32 = 1.5;

/// Motor model for the decoupling feed-forward (5.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeedForwardConfig {
    /// d-axis inductance L_d \[H\].
    pub ld: f32,
    /// q-axis inductance L_q \[H\].
    pub lq: f32,
    /// Permanent-magnet flux linkage ψ_M \[Wb\] (peak, phase).
    pub psi_m: f32,
}

impl FeedForwardConfig {
    /// u_ff of (5.3) \[V\] for the electrical speed `omega_e` \[rad/s\] and the measured
    /// currents `i` \[A\]: `u_d,ff = −ω_e·L_q·i_q`, `u_q,ff = ω_e·(L_d·i_d + ψ_M)`.
    pub fn decoupling(&self, omega_e: f32, i: Dq) -> Dq {
        Dq {
            d: -omega_e * self.lq * i.q,
            q: omega_e * (self.ld * i.d + self.psi_m),
        }
    }
}

/// DC-link feed-forward gain `1/U_dc` \[1/V\] (inverse of (5.1)), with U_dc raised to
/// at least `u_dc_min` \[V\]. Returns 0 (no output voltage) if neither is a positive
/// finite number, so the gain can never be infinite or NaN.
pub fn dc_link_gain(u_dc: f32, u_dc_min: f32) -> f32 {
    let u = effective_dc_link(u_dc, u_dc_min);
    if u > 0.0 && u.is_finite() { 1.0 / u } else { 0.0 }
}

/// The DC-link voltage used for modulation: `max(U_dc, U_dc,min)` \[V\] (a NaN
/// measurement yields the minimum).
pub fn effective_dc_link(u_dc: f32, u_dc_min: f32) -> f32 {
    if u_dc >= u_dc_min { u_dc } else { u_dc_min }
}

/// Torque constant `K_t = 3/2·n_p·ψ_M` \[N·m/A\] (2.34).
pub const fn torque_constant(pole_pairs: u16, psi_m: f32) -> f32 {
    THREE_HALVES * pole_pairs as f32 * psi_m
}

/// `1/K_t` \[A/(N·m)\], or 0 if K_t is not a positive finite number.
pub fn amps_per_newton_metre(k_t: f32) -> f32 {
    if k_t > 0.0 && k_t.is_finite() { 1.0 / k_t } else { 0.0 }
}

/// q-axis current reference for a torque \[N·m\] (2.34): `i_q = T·(1/K_t)`.
pub fn iq_from_torque(torque: f32, amps_per_newton_metre: f32) -> f32 {
    torque * amps_per_newton_metre
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// (5.3) against f64; three products and a sum in f32: ≤ 4·ε_f32·|term|.
        #[test]
        fn decoupling_matches_f64(w in -9000f32..9000.0, id in -200f32..200.0, iq in -200f32..200.0) {
            let cfg = FeedForwardConfig { ld: 0.393e-3, lq: 0.5e-3, psi_m: 0.058 };
            let u = cfg.decoupling(w, Dq { d: id, q: iq });
            let (w, id, iq) = (f64::from(w), f64::from(id), f64::from(iq));
            let ud = -w * f64::from(cfg.lq) * iq;
            let uq = w * (f64::from(cfg.ld) * id + f64::from(cfg.psi_m));
            let eps = f64::from(f32::EPSILON);
            prop_assert!((f64::from(u.d) - ud).abs() <= 4.0 * eps * ud.abs() + 1e-9);
            prop_assert!((f64::from(u.q) - uq).abs()
                <= 4.0 * eps * (w.abs() * (f64::from(cfg.ld) * id.abs() + f64::from(cfg.psi_m))) + 1e-9);
        }

        /// 1/U_dc is finite and ≤ 1/U_dc,min for every input, including NaN.
        #[test]
        fn dc_link_gain_is_bounded(u in proptest::num::f32::ANY, min in 1f32..1000.0) {
            let g = dc_link_gain(u, min);
            prop_assert!(g.is_finite() && g >= 0.0 && g <= 1.0 / min);
            // Relative accuracy ε_f32 while 1/U_dc is a normal f32 (U_dc < 8.5e37).
            if u >= min && u < 1e37 {
                prop_assert!((f64::from(g) - 1.0 / f64::from(u)).abs() <= f64::from(f32::EPSILON) / f64::from(u));
            }
        }
    }

    /// Fischer TI085: K_t = 3/2·4·ψ_M; with ψ_M = 0.058 Wb, K_t = 0.348 N·m/A.
    #[test]
    fn torque_to_current() {
        let kt = torque_constant(4, 0.058);
        assert!((kt - 0.348).abs() < 1e-6);
        let inv = amps_per_newton_metre(kt);
        assert!((iq_from_torque(10.0, inv) - 10.0 / 0.348).abs() < 1e-4);
        assert_eq!(amps_per_newton_metre(0.0), 0.0);
        assert_eq!(amps_per_newton_metre(f32::NAN), 0.0);
        assert_eq!(dc_link_gain(0.0, 0.0), 0.0);
    }
}
