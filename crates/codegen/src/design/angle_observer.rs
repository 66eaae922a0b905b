//! Angle tracking observer gains, thesis A §4.4.
//!
//! Continuous PI gains K_p = 2ζω_n, K_i = ω_n² (4.15). In firmware the angle is
//! stored as θ = 2^−31·π·θ^i, the speed as ω = 2^−31·f_s·π·ω^i (4.20) and the
//! update (4.22) uses K̃_p = K_p/(f_s·π), K̃_i = K_i/(f_s²·π) for the trig-identity
//! error, which is in radians. The atan2 (CORDIC) error is already normalised by
//! π, so its gains lose the 1/π: K̃_p = K_p/f_s, K̃_i = K_i/f_s².
//!
//! The trig-identity error scales with the resolver signals' amplitude g at the
//! observer's input, as a fraction of full scale: g·sin(θ_r − θ̂) (thesis A (4.10)), "this
//! slows down the observer". On a board whose front end and sampling give g < 1
//! (`crate::board::resolver_signal_gain`) its gains are divided by g, K̃ = K/(f_s^n·π·g),
//! so that the loop has the designed ω_n and ζ there; the atan2 error does not depend on
//! the amplitude.

use serde::Serialize;

use crate::spec::ObserverError;

/// 2^31, the Q1.31 scale.
pub const Q31_ONE: f64 = 2_147_483_648.0;

/// Observer gains in both physical and stored-integer form.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObserverGains {
    /// K_p = 2ζω_n [rad/s] (4.15).
    pub kp: f64,
    /// K_i = ω_n² [rad²/s²] (4.15).
    pub ki: f64,
    /// K̃_p as a real number in [−1, 1) (4.22).
    pub kp_scaled: f64,
    /// K̃_i as a real number in [−1, 1) (4.22).
    pub ki_scaled: f64,
    /// K̃_p stored integer, Q1.31, rounded to nearest.
    pub kp_q31: i32,
    /// K̃_i stored integer, Q1.31, rounded to nearest.
    pub ki_q31: i32,
    /// Relative error of K̃_i after rounding.
    pub ki_quantisation_error: f64,
    /// The resolver signals' amplitude at the observer's input as a fraction of full scale
    /// g the trig-identity gains are divided by (1 for atan2, or without a board).
    pub signal_gain: f64,
}

/// Why the gains cannot be stored.
#[derive(Debug, Clone, PartialEq)]
pub enum ObserverGainError {
    /// A scaled gain is ≥ 1 in magnitude and does not fit Q1.31.
    Overflow {
        /// "kp" or "ki".
        gain: &'static str,
        /// The scaled value.
        scaled: f64,
    },
    /// A scaled gain rounds to zero: the loop would lose that action.
    Underflow {
        /// "kp" or "ki".
        gain: &'static str,
        /// The scaled value.
        scaled: f64,
    },
}

fn to_q31(gain: &'static str, x: f64) -> Result<i32, ObserverGainError> {
    let i = (x * Q31_ONE).round();
    if !(i > -Q31_ONE - 0.5 && i < Q31_ONE) {
        return Err(ObserverGainError::Overflow { gain, scaled: x });
    }
    if i == 0.0 {
        return Err(ObserverGainError::Underflow { gain, scaled: x });
    }
    Ok(i as i32)
}

/// Designs the observer for natural frequency `wn` [rad/s], damping `zeta`, sample rate
/// `fs` \[Hz\] and resolver signals at `signal_gain` of full scale (module documentation;
/// 1 where the signals span the ADC's range).
pub fn design(
    wn: f64,
    zeta: f64,
    fs: f64,
    error: ObserverError,
    signal_gain: f64,
) -> Result<ObserverGains, ObserverGainError> {
    let kp = 2.0 * zeta * wn;
    let ki = wn * wn;
    let signal_gain = match error {
        ObserverError::TrigIdentity => signal_gain,
        ObserverError::Atan2 => 1.0,
    };
    let norm = match error {
        ObserverError::TrigIdentity => std::f64::consts::PI * signal_gain,
        ObserverError::Atan2 => 1.0,
    };
    let kp_scaled = kp / (fs * norm);
    let ki_scaled = ki / (fs * fs * norm);
    let kp_q31 = to_q31("kp", kp_scaled)?;
    let ki_q31 = to_q31("ki", ki_scaled)?;
    Ok(ObserverGains {
        kp,
        ki,
        kp_scaled,
        ki_scaled,
        kp_q31,
        ki_q31,
        ki_quantisation_error: (f64::from(ki_q31) / Q31_ONE - ki_scaled) / ki_scaled,
        signal_gain,
    })
}

/// Largest electrical angle the observer may lag by at the drive's largest acceleration
/// [°]: the transient angle error thesis B §4.4.2 allows its estimator ("allowing for an
/// angular error of 10°"; the default of `sensorless.max_angle_error`). At 10° the
/// torque-producing current keeps cos 10° = 98.5 % of its value.
pub const MAX_TRACKING_ERROR_DEG: f64 = 10.0;

/// Steady lag [rad of resolver angle] of the type-2 observer while the resolver angle
/// accelerates at `a_r` [rad/s²]: the double integrator follows the parabola only through
/// a constant error whose integral action supplies the acceleration, K_i·e = a_r (thesis A
/// (4.12)–(4.15)); e = sin Δ for the trig-identity error (4.8), e = Δ for atan2. `None`
/// when no steady lag exists (a_r ≥ K_i with the trig identity: the observer slips).
pub fn ramp_lag(a_r: f64, ki: f64, error: ObserverError) -> Option<f64> {
    let x = a_r / ki;
    match error {
        ObserverError::TrigIdentity => (x < 1.0).then(|| x.asin()),
        ObserverError::Atan2 => Some(x),
    }
}

/// Smallest ω_n [rad/s] whose [`ramp_lag`] at `a_r` [rad/s²] is `lag` [rad of resolver
/// angle, < π/2]: K_i = ω_n² (4.15) = a_r/sin(lag) (trig identity) or a_r/lag (atan2).
pub fn min_natural_frequency(a_r: f64, lag: f64, error: ObserverError) -> f64 {
    match error {
        ObserverError::TrigIdentity => (a_r / lag.sin()).sqrt(),
        ObserverError::Atan2 => (a_r / lag).sqrt(),
    }
}

/// Angular lag of a delay of `k` samples at electrical speed `we` [rad/s], Δθ_e = k·ω_e·T_s (4.23) \[rad\].
pub fn lag_angle(k: f64, we: f64, fs: f64) -> f64 {
    k * we / fs
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thesis A §4.4.2: ω_n = 70 rad/s, ζ = 1 → K_p = 140, K_i = 4900; f_s = 20 kHz.
    /// Hand calculation (4.22), trig identity:
    ///   K̃_p = 140/(20000·π) = 2.2281692e-3 → ·2^31 = 4 784 956.9 → 4 784 957
    ///   K̃_i = 4900/(4e8·π) = 3.899296e-6 → ·2^31 = 8 373.6 → 8 374
    #[test]
    fn thesis_observer_trig_identity() {
        let g = design(70.0, 1.0, 20e3, ObserverError::TrigIdentity, 1.0).unwrap();
        assert_eq!((g.kp, g.ki), (140.0, 4900.0));
        assert!((g.kp_scaled - 2.228_169e-3).abs() < 1e-9);
        assert!((g.ki_scaled - 3.899_296e-6).abs() < 1e-12);
        assert_eq!(g.kp_q31, 4_784_957);
        assert_eq!(g.ki_q31, 8_374);
    }

    /// atan2 error is normalised by π, so its gains are π times larger:
    /// K̃_p = 140/20000 = 0.007 → 15 032 385.5 → 15 032 386 (half rounds away from zero);
    /// K̃_i = 4900/4e8 = 1.225e-5 → 26 306.7 → 26 307.
    #[test]
    fn thesis_observer_atan2() {
        let g = design(70.0, 1.0, 20e3, ObserverError::Atan2, 1.0).unwrap();
        assert_eq!(g.kp_q31, 15_032_386);
        assert_eq!(g.ki_q31, 26_307);
    }

    /// Resolver signals at g = 0.4 of full scale (thesis A (4.10): the trig-identity error
    /// is g·sin Δ): the gains are divided by g, K̃_p = 140/(20000·π·0.4) = 5.570423e-3,
    /// K̃_i = 4900/(4e8·π·0.4) = 9.748240e-6, so g·K̃ is the full-scale design's; the atan2
    /// error does not scale, its gains stay those of `thesis_observer_atan2`.
    #[test]
    fn trig_identity_gains_follow_the_signal_amplitude() {
        let g = design(70.0, 1.0, 20e3, ObserverError::TrigIdentity, 0.4).unwrap();
        assert!((g.kp_scaled - 5.570_423e-3).abs() < 1e-9);
        assert!((g.ki_scaled - 9.748_240e-6).abs() < 1e-12);
        assert_eq!(g.signal_gain, 0.4);
        let a = design(70.0, 1.0, 20e3, ObserverError::Atan2, 0.4).unwrap();
        assert_eq!((a.kp_q31, a.ki_q31, a.signal_gain), (15_032_386, 26_307, 1.0));
    }

    #[test]
    fn refuses_what_does_not_fit_q31() {
        // K̃_p = 2·1·70000/(20000·π) = 2.23 ≥ 1.
        assert!(matches!(
            design(70_000.0, 1.0, 20e3, ObserverError::TrigIdentity, 1.0),
            Err(ObserverGainError::Overflow { gain: "kp", .. })
        ));
        // K̃_i = 0.01²/(4e8·π) ≈ 8e-14 → rounds to 0.
        assert!(matches!(
            design(0.01, 1.0, 20e3, ObserverError::TrigIdentity, 1.0),
            Err(ObserverGainError::Underflow { gain: "ki", .. })
        ));
    }

    /// The ATO of thesis A §4.4.2 (ω_n = 70 rad/s, K_i = 4900 rad/s²) on Fischer's
    /// default acceleration, 20 000 rpm in 10 s = 209.44 rad/s² (`acceleration`, n_r = 1):
    /// sin Δ = 209.44/4900 = 0.042743 → Δ = 2.4497° of resolver angle = 9.799° electrical
    /// (n_p = 4), inside the 10° allowance; the ω_n that lags exactly 10° electrical
    /// (2.5° resolver) is √(209.44/sin 2.5°) = √(209.44/0.043619) = √4801.5 = 69.293 rad/s.
    #[test]
    fn type_2_lag_by_hand() {
        let lag = ramp_lag(209.44, 4900.0, ObserverError::TrigIdentity).unwrap();
        assert!((lag.to_degrees() - 2.4497).abs() < 1e-4, "{}", lag.to_degrees());
        let wn = min_natural_frequency(209.44, 2.5f64.to_radians(), ObserverError::TrigIdentity);
        assert!((wn - 69.293).abs() < 1e-3, "{wn}");
        assert_eq!(ramp_lag(4900.0, 4900.0, ObserverError::TrigIdentity), None);
        // atan2: linear in Δ, 209.44/4900 rad = 2.4490°.
        let lag = ramp_lag(209.44, 4900.0, ObserverError::Atan2).unwrap();
        assert!((lag.to_degrees() - 2.4490).abs() < 1e-4, "{}", lag.to_degrees());
    }

    /// Thesis A (4.23): one sample of delay at f_e = 1333 Hz and f_s = 20 kHz lags by 24°.
    #[test]
    fn one_sample_lag_is_24_degrees_for_fischer() {
        let we = 2.0 * std::f64::consts::PI * 1333.33;
        assert!((lag_angle(1.0, we, 20e3).to_degrees() - 24.0).abs() < 0.01);
    }
}
