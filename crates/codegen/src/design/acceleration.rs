//! The largest shaft acceleration the drive must follow: the physical operating point at
//! which the angle observer, the field-weakening controller and the sensorless
//! estimator are judged (`motorgen verify` ramps the shaft at it; the observer's lag at
//! it is a design rule, [`super::angle_observer::ramp_lag`]).
//!
//! In order of precedence:
//!
//! 1. `[drive] max_acceleration` (e.g. `"3000 rpm/s"`): what the application allows (a
//!    vehicle's traction limit through its gear, a servo's load inertia);
//! 2. `peak_torque / inertia` from `[motor.datasheet]` when both are given: the motor's
//!    own rotor at its peak torque, i.e. unloaded on a bench — the fastest the shaft can
//!    turn up (thesis A (2.17): J·dω_m/dt + b·ω_m = T_e − T_load);
//! 3. the maximum speed reached in [`DEFAULT_RUN_UP_S`] = 10 s: a traction drive, the
//!    application of both theses, whose shaft carries the vehicle's inertia ("very large",
//!    thesis B §2.1.5). A faster drive must say so with the key; the design prints which
//!    rule it used.

use serde::Serialize;

/// Run-up time from standstill to the maximum speed of the default acceleration \[s\].
pub const DEFAULT_RUN_UP_S: f64 = 10.0;

/// Where the acceleration came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AccelerationRule {
    /// `drive.max_acceleration`.
    Spec,
    /// `motor.datasheet.peak_torque / motor.datasheet.inertia`.
    PeakTorqueOverInertia,
    /// `motor.max_speed / DEFAULT_RUN_UP_S`.
    Default,
}

impl AccelerationRule {
    /// The rule in words, naming the keys that set it.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Spec => "drive.max_acceleration",
            Self::PeakTorqueOverInertia => {
                "peak torque / rotor inertia (motor.datasheet.peak_torque, inertia: the unloaded motor)"
            }
            Self::Default => {
                "default: motor.max_speed in 10 s, a traction drive (set drive.max_acceleration for a faster one)"
            }
        }
    }
}

/// The largest shaft acceleration [rad/s², mechanical] and its rule, from the spec's
/// `key` [rad/s²], `peak_torque` [N·m], `inertia` [kg·m²] and `max_speed` [rad/s].
pub fn max_acceleration(
    key: Option<f64>,
    peak_torque: Option<f64>,
    inertia: Option<f64>,
    max_speed: f64,
) -> (f64, AccelerationRule) {
    match (key, peak_torque, inertia) {
        (Some(a), _, _) => (a, AccelerationRule::Spec),
        (None, Some(t), Some(j)) => (t / j, AccelerationRule::PeakTorqueOverInertia),
        _ => (max_speed / DEFAULT_RUN_UP_S, AccelerationRule::Default),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// EMRAX 228 technical data (motors/emrax-228-hv.toml): 230 N·m / 0.0383 kg·m² =
    /// 6005.2 rad/s² = 57 346 rpm/s; the key wins over it; without either, Fischer's
    /// 20 000 rpm in 10 s = 2000 rpm/s = 209.44 rad/s².
    #[test]
    fn precedence_and_hand_values() {
        let (a, rule) = max_acceleration(None, Some(230.0), Some(0.0383), 680.7);
        assert!((a - 6005.22).abs() < 0.01, "{a}");
        assert_eq!(rule, AccelerationRule::PeakTorqueOverInertia);
        let (a, rule) = max_acceleration(Some(314.16), Some(230.0), Some(0.0383), 680.7);
        assert_eq!((a, rule), (314.16, AccelerationRule::Spec));
        let w = 20_000.0 * std::f64::consts::PI / 30.0;
        let (a, rule) = max_acceleration(None, Some(29.1), None, w);
        assert!((a - 209.44).abs() < 0.01, "{a}");
        assert_eq!(rule, AccelerationRule::Default);
    }
}
