//! Resolver angle → electrical angle (4.5) and the transport-delay angle lead (4.23),
//! on Q1.31 stored integers scaled by π (4.20): `θ = 2^-31·π·θ^i`.
//!
//! Angles wrap (two's complement, one turn = 2^32); speeds saturate.

/// π·2^-31: radians per LSB of a π-scaled Q1.31 angle (4.20).
pub const RADIANS_PER_LSB: f32 = core::f32::consts::PI / 2_147_483_648.0;

/// π-scaled Q1.31 angle → radians in `[-π, π)` (4.20).
pub fn to_radians(theta: i32) -> f32 {
    theta as f32 * RADIANS_PER_LSB
}

/// Radians → π-scaled Q1.31 (4.20), truncating and saturating: for the angle increments
/// and small angles (|θ| < π) the control step computes in `f32`.
pub fn from_radians(rad: f32) -> i32 {
    (rad / RADIANS_PER_LSB) as i32
}

/// Any angle \[rad\] → π-scaled Q1.31 stored integer (4.20), rounded to nearest and
/// wrapped into one turn: θ and θ + 2π give the same integer, +π gives −2^31 (= −π).
/// The host-side conversion: the code generator writes θ_off with it, and the
/// simulations lock the observer with it.
pub fn from_radians_f64(rad: f64) -> i32 {
    // θ/π + 1 reduced into [0, 2) (Euclidean remainder; fmod is exact), minus 1: [−1, 1).
    let r = libm::fmod(rad / core::f64::consts::PI + 1.0, 2.0);
    let wrapped = if r < 0.0 { r + 2.0 } else { r } - 1.0;
    // |wrapped·2^31| ≤ 2^31: the i64 is exact; +2^31 (θ just below +π) wraps to −2^31.
    libm::round(wrapped * 2_147_483_648.0) as i64 as i32
}

/// π-scaled Q1.31 stored integer → angle \[rad\] in `[−π, π)` (4.20), in `f64`: the
/// exact inverse of [`from_radians_f64`] on its range (every `i32` is exact in `f64`).
/// The host-side conversion: the simulations read the controller's angles and the
/// design's θ_off with it.
pub fn to_radians_f64(theta: i32) -> f64 {
    f64::from(theta) * core::f64::consts::PI / 2_147_483_648.0
}

/// Observer speed stored integer → rad/s: `ω = 2^-31·f_s·π·ω^i` (4.20), where
/// `rad_per_s_per_lsb = π·f_s/2^31` (a configuration constant, see
/// [`crate::step::ControllerConfig::speed_per_lsb`]).
pub fn speed_to_rad_per_s(omega: i32, rad_per_s_per_lsb: f32) -> f32 {
    omega as f32 * rad_per_s_per_lsb
}

/// `θ_e = (n_p/n_r)·(θ_r − θ_off)` (4.5) on stored integers.
///
/// With `n_r = 1` (or `n_r` dividing `n_p`) this is a wrapping multiplication. With
/// `n_r > 1` the resolver angle only determines the mechanical angle modulo 2π/n_r,
/// so the conversion keeps a count of resolver cycles modulo `n_r` in
/// [`ResolverTurns`] and evaluates (4.5) on the extended angle `θ_r + 2π·turn`;
/// the result is then exact modulo 2π for any `n_p`, `n_r`. Which of the `n_r` cycles
/// is "turn 0" is fixed by [`ResolverTurns::align`] (done at the resolver offset
/// calibration, 6.3) — before that it is arbitrary, which only matters if `n_r` does
/// not divide `n_p`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResolverToElectrical {
    /// Motor pole pairs n_p (2.19).
    pub motor_pole_pairs: u16,
    /// Resolver pole pairs n_r ≥ 1 (4.4); 0 is treated as 1.
    pub resolver_pole_pairs: u16,
    /// Resolver offset θ_off, π-scaled Q1.31 (4.5), identified by (6.9).
    pub offset: i32,
}

/// Resolver cycle counter for [`ResolverToElectrical`] (state).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ResolverTurns {
    /// Extended resolver angle `(θ_r + 2π·turn)` in units of 2^-31·π, modulo
    /// `n_r·2^32`.
    extended: u64,
    /// Previous resolver angle, to detect wrap-arounds.
    previous: i32,
}

impl ResolverTurns {
    /// Turn 0 at θ_r = 0.
    pub const fn new() -> Self {
        Self {
            extended: 0,
            previous: 0,
        }
    }

    /// Declares the current resolver angle `theta_r` to lie in turn 0 (use together
    /// with setting θ_off = θ_r after the alignment of (6.3)).
    pub fn align(&mut self, theta_r: i32) {
        self.previous = theta_r;
        self.extended = u64::from(theta_r as u32);
    }

    /// Resolver cycle index in `0..n_r`.
    pub fn turn(&self) -> u32 {
        (self.extended >> 32) as u32
    }
}

impl ResolverToElectrical {
    /// n_r, never 0.
    fn n_r(&self) -> u64 {
        u64::from(self.resolver_pole_pairs.max(1))
    }

    /// θ_e from the (observed) resolver angle `theta_r` (4.5), wrapping.
    ///
    /// `theta_r` must advance by less than π per call (true for the observer output
    /// at any physical speed: f_s ≥ 12·f_e, thesis A §1.2).
    pub fn process(&self, state: &mut ResolverTurns, theta_r: i32) -> i32 {
        let n_r = self.n_r();
        // n_r·2^32 ≤ 2^48.
        let modulus = n_r << 32;
        let delta = theta_r.wrapping_sub(state.previous);
        state.previous = theta_r;
        let step = if delta >= 0 {
            u64::from(delta.unsigned_abs())
        } else {
            modulus.saturating_sub(u64::from(delta.unsigned_abs()))
        };
        // Arithmetic modulo n_r·2^32 (the extended angle wraps there). extended <
        // modulus and step ≤ modulus: the sum is < 2^49, never saturates.
        state.extended = state.extended.saturating_add(step).checked_rem(modulus).unwrap_or(0);
        // (θ_r − θ_off) on the extended circle, θ_off lying in turn 0.
        let offset = u64::from(self.offset as u32);
        let relative = state
            .extended
            .saturating_add(modulus)
            .saturating_sub(offset)
            .checked_rem(modulus)
            .unwrap_or(0);
        // relative < 2^48 and n_p < 2^16: the product is < 2^64, never saturates.
        let electrical = relative
            .saturating_mul(u64::from(self.motor_pole_pairs))
            .checked_div(n_r)
            .unwrap_or(0);
        // Keep the angle modulo one electrical turn (2^32): truncation is the wrap.
        electrical as u32 as i32
    }

    /// Electrical speed stored integer from the resolver speed stored integer:
    /// `ω_e^i = (n_p/n_r)·ω_r^i` (4.5 differentiated), saturating.
    ///
    /// In the scaling (4.20) ω^i is the per-sample angle increment (4.19), so the
    /// result is the electrical angle advanced per sample.
    pub fn electrical_speed(&self, omega_r: i32) -> i32 {
        let n_r = self.n_r() as i64;
        let scaled = i64::from(omega_r)
            .saturating_mul(i64::from(self.motor_pole_pairs))
            .checked_div(n_r)
            .unwrap_or(0);
        scaled.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
    }
}

/// Lead of the angle used for the inverse Park transformation (4.23):
/// `θ_lead = θ + k·ω^i`, with the delay `k` in samples as Q16.16 (1.5 samples =
/// `3 << 15`) and `omega` the per-sample increment of the same angle (4.19).
///
/// Compensates the lag `Δθ_e = k·ω_e·T_s` of the ADC and PWM zero-order holds
/// (thesis A §4.6, `T_delay = 1.5·T_s`). Wrapping.
pub fn lead(theta: i32, omega: i32, k_q16: i32) -> i32 {
    // |ω·k| ≤ 2^62: the saturating forms never saturate.
    let increment = i64::from(omega)
        .saturating_mul(i64::from(k_q16))
        .saturating_add(1 << 15)
        >> 16;
    // The increment is an angle: keeping it modulo 2^32 is the wrap.
    theta.wrapping_add(increment as i32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const TURN: f64 = 4_294_967_296.0;

    /// f64 reference: angle in turns, wrapped to [−0.5, 0.5).
    fn wrap_turns(x: f64) -> f64 {
        x - (x + 0.5).floor()
    }

    /// Hand values of (4.20): π/2 ↔ 2^30, −π/2 ↔ −2^30, π ↔ −2^31 (one turn wraps),
    /// 3π/2 ≡ −π/2, 2π + 0.3 ≡ 0.3, and 0.6 LSB rounds to 1 LSB.
    #[test]
    fn radians_to_stored_integer() {
        use core::f64::consts::PI;
        assert_eq!(from_radians_f64(0.0), 0);
        assert_eq!(from_radians_f64(PI / 2.0), 1 << 30);
        assert_eq!(from_radians_f64(-PI / 2.0), -(1 << 30));
        assert_eq!(from_radians_f64(PI), i32::MIN);
        assert_eq!(from_radians_f64(-PI), i32::MIN);
        assert_eq!(from_radians_f64(1.5 * PI), -(1 << 30));
        assert_eq!(from_radians_f64(2.0 * PI + 0.3), from_radians_f64(0.3));
        assert_eq!(from_radians_f64(0.6 * PI / 2_147_483_648.0), 1);
        // 0.3 rad = 0.3/π·2^31 = 205 069 582.67 LSB.
        assert_eq!(from_radians_f64(0.3), 205_069_583);
        // The inverse: 2^30 LSB = π/2, −2^31 = −π, 205 069 583 LSB = 0.3 rad to within half
        // an LSB (π/2^32 = 7.3e-10 rad).
        assert_eq!(to_radians_f64(1 << 30), PI / 2.0);
        assert_eq!(to_radians_f64(i32::MIN), -PI);
        assert!((to_radians_f64(205_069_583) - 0.3).abs() < PI / 4_294_967_296.0);
        // The f32 form truncates, within the f32 resolution (24 bits: 2^28/2^24 = 16 LSB here).
        assert!((from_radians(0.3) - 205_069_583).abs() < 64);
    }

    fn turns(i: i32) -> f64 {
        f64::from(i) / TURN
    }

    /// Angular distance in LSB between a stored angle and a reference in turns.
    fn err_lsb(i: i32, reference_turns: f64) -> f64 {
        wrap_turns(turns(i) - reference_turns).abs() * TURN
    }

    proptest! {
        /// (4.5) with n_r = 1 is exact (integer multiply modulo 2^32): error 0 LSB.
        #[test]
        fn single_speed_resolver(np in 1u16..=12, th in any::<i32>(), off in any::<i32>()) {
            let conv = ResolverToElectrical { motor_pole_pairs: np, resolver_pole_pairs: 1, offset: off };
            let mut st = ResolverTurns::new();
            // Walk to θ in steps < π so the turn counter follows.
            let half = th.wrapping_sub(0) / 2;
            conv.process(&mut st, half);
            let e = conv.process(&mut st, th);
            let reference = wrap_turns(f64::from(np) * (turns(th) - turns(off)));
            prop_assert!(err_lsb(e, reference) == 0.0);
        }

        /// (4.5) with n_r > 1: follow a rotation over several mechanical turns, in
        /// steps < π of resolver angle, and compare with n_p/n_r·(θ_r,total − θ_off)
        /// in f64. The integer division floors: error < 1 LSB.
        #[test]
        fn multi_speed_resolver(np in 1u16..=12, nr in 1u16..=4, off in any::<i32>(),
                                steps in proptest::collection::vec(-0x7000_0000i32..0x7000_0000, 1..40)) {
            let conv = ResolverToElectrical { motor_pole_pairs: np, resolver_pole_pairs: nr, offset: off };
            let mut st = ResolverTurns::new();
            st.align(0);
            let mut total: i64 = 0; // resolver angle travelled, LSB
            let mut th = 0i32;
            for s in steps {
                th = th.wrapping_add(s);
                total += i64::from(s);
                let e = conv.process(&mut st, th);
                let reference = wrap_turns(
                    f64::from(np) / f64::from(nr) * (total as f64 - f64::from(off as u32)) / TURN);
                prop_assert!(err_lsb(e, reference) < 1.0 + 1e-6, "e={e} ref={reference}");
            }
        }

        /// Lead (4.23): θ + k·ω with k in Q16.16; rounding to nearest: ≤ 0.5 LSB.
        #[test]
        fn lead_matches_f64(th in any::<i32>(), w in any::<i32>(), k in 0i32..(8 << 16)) {
            let r = lead(th, w, k);
            let reference = wrap_turns(turns(th) + f64::from(w) * f64::from(k) / 65536.0 / TURN);
            prop_assert!(err_lsb(r, reference) <= 0.5 + 1e-6);
        }
    }

    /// Angle arithmetic wraps across ±π: θ_e for θ_r just below +π and just above −π
    /// are one LSB·n_p apart.
    #[test]
    fn wraps_across_pi() {
        let conv = ResolverToElectrical {
            motor_pole_pairs: 4,
            resolver_pole_pairs: 1,
            offset: 0,
        };
        let mut st = ResolverTurns::new();
        let a = conv.process(&mut st, i32::MAX);
        let b = conv.process(&mut st, i32::MIN);
        assert_eq!(b.wrapping_sub(a), 4);
        // Lead across +π: π − ε + 1.5·(2ε) lands at −π + 2ε.
        assert_eq!(lead(i32::MAX - 9, 20, 3 << 15), i32::MIN + 20);
    }

    /// The electrical speed with n_r = 2, n_p = 4 doubles the resolver speed and
    /// saturates instead of overflowing.
    #[test]
    fn electrical_speed_scales_and_saturates() {
        let conv = ResolverToElectrical {
            motor_pole_pairs: 4,
            resolver_pole_pairs: 2,
            offset: 0,
        };
        assert_eq!(conv.electrical_speed(1000), 2000);
        assert_eq!(conv.electrical_speed(-1001), -2002);
        assert_eq!(conv.electrical_speed(i32::MAX), i32::MAX);
        assert_eq!(conv.electrical_speed(i32::MIN), i32::MIN);
    }

    /// n_r = 2, n_p = 3 (n_r does not divide n_p): one resolver cycle is 1.5
    /// electrical turns, so the two resolver cycles give electrical angles that
    /// differ by π — the turn counter must tell them apart.
    #[test]
    fn non_integer_ratio_uses_turn_counter() {
        let conv = ResolverToElectrical {
            motor_pole_pairs: 3,
            resolver_pole_pairs: 2,
            offset: 0,
        };
        let mut st = ResolverTurns::new();
        st.align(0);
        let mut th = 0i32;
        let step = 1 << 28; // π/8 resolver
        let mut first_cycle_at_zero = None;
        for n in 1..=32 {
            th = th.wrapping_add(step);
            let e = conv.process(&mut st, th);
            if n == 16 {
                // one full resolver cycle = 1.5 electrical turns → θ_e = π
                first_cycle_at_zero = Some(e);
                assert_eq!(st.turn(), 1);
            }
            if n == 32 {
                // two cycles = 3 electrical turns → θ_e = 0
                assert_eq!(e, 0);
                assert_eq!(st.turn(), 0);
            }
        }
        assert_eq!(first_cycle_at_zero, Some(i32::MIN));
    }

    #[test]
    fn radians_scaling() {
        assert!((to_radians(1 << 30) - core::f32::consts::FRAC_PI_2).abs() < 1e-6);
        assert!((to_radians(i32::MIN) + core::f32::consts::PI).abs() < 1e-6);
        // ω^i = 2^31/f_s·… : one LSB at f_s = 20 kHz is π·20000/2^31 rad/s.
        let per_lsb = core::f32::consts::PI * 20_000.0 / 2_147_483_648.0;
        assert!((speed_to_rad_per_s(1 << 20, per_lsb) - 30.679_616).abs() < 1e-4);
    }
}
