//! The largest shaft acceleration the drive must follow: the physical operating point at
//! which the angle observer, the field-weakening controller and the sensorless
//! estimator are judged (`motorgen verify` ramps the shaft at it; the observer's lag at
//! it is a design rule, [`super::angle_observer::ramp_lag`]).
//!
//! `[drive] max_acceleration` (e.g. `"3000 rpm/s"`) is what the application allows (a
//! vehicle's traction limit through its gear, a servo's load inertia). Without it the
//! default follows `[drive] application`, what the drive moves:
//!
//! * `"traction"` (also when the key is absent): the maximum speed reached in
//!   [`TRACTION_RUN_UP_S`] = 10 s — a vehicle, the application of both theses, whose
//!   shaft carries the vehicle's inertia ("very large", thesis B §2.1.5);
//! * `"servo"`: with `peak_torque` and `inertia` in `[motor.datasheet]`, the peak torque
//!   accelerating the rotor and a load of [`SERVO_LOAD_RATIO`] = 10 times its inertia
//!   (thesis A (2.17): J·dω_m/dt = T_e with J = 11·J_rotor), ten to one being the
//!   load-to-motor inertia ratio servo sizing guides take as the limit for good tuning
//!   (KEB America, "4 Key Factors to Consider When Sizing Servo Motors", 2023: inertia
//!   matching); without them the maximum speed in [`SERVO_RUN_UP_S`] = 0.1 s;
//! * `"robot"`: the maximum speed in [`ROBOT_RUN_UP_S`] = 0.1 s — a legged robot's joint
//!   actuator, which reaches its top speed within a leg's swing (assumption: half of a
//!   0.2 s swing phase).
//!
//! The bare rotor's acceleration (peak torque/rotor inertia, no load) is no default: it is
//! the fastest the shaft can ever turn up, a bench case no application runs, and it made
//! an ordinary servo spec fail the field-weakening rule. The design prints the value and
//! the rule, naming the key that sets it.

use serde::Serialize;

use crate::spec::Application;

/// Run-up time from standstill to the maximum speed of the traction default \[s\].
pub const TRACTION_RUN_UP_S: f64 = 10.0;
/// Load inertia of the servo default, in rotor inertias.
pub const SERVO_LOAD_RATIO: f64 = 10.0;
/// Run-up time of the servo default without peak torque and inertia \[s\].
pub const SERVO_RUN_UP_S: f64 = 0.1;
/// Run-up time of the robot default \[s\].
pub const ROBOT_RUN_UP_S: f64 = 0.1;

/// Where the acceleration came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AccelerationRule {
    /// `drive.max_acceleration`.
    Spec,
    /// Traction (`drive.application = "traction"` or absent): `motor.max_speed` in 10 s.
    Traction,
    /// Servo with peak torque and inertia: T_peak/(J·(1 + 10)).
    ServoLoad,
    /// Servo without them: `motor.max_speed` in 0.1 s.
    ServoRunUp,
    /// Robot actuator: `motor.max_speed` in 0.1 s.
    Robot,
}

impl AccelerationRule {
    /// The rule in words, naming the keys that set it.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Spec => "drive.max_acceleration",
            Self::Traction => {
                "default of drive.application = \"traction\" (the default application): motor.max_speed in 10 s, a vehicle; drive.max_acceleration or drive.application sets another"
            }
            Self::ServoLoad => {
                "default of drive.application = \"servo\": motor.datasheet.peak_torque into the rotor inertia and a load of 10× it; drive.max_acceleration sets another"
            }
            Self::ServoRunUp => {
                "default of drive.application = \"servo\" without peak_torque and inertia: motor.max_speed in 0.1 s; drive.max_acceleration sets another"
            }
            Self::Robot => {
                "default of drive.application = \"robot\": motor.max_speed in 0.1 s; drive.max_acceleration sets another"
            }
        }
    }
}

/// The largest shaft acceleration [rad/s², mechanical] and its rule, from the spec's
/// `key` [rad/s²], `application`, `peak_torque` [N·m], `inertia` [kg·m²] and `max_speed`
/// [rad/s].
pub fn max_acceleration(
    key: Option<f64>,
    application: Option<Application>,
    peak_torque: Option<f64>,
    inertia: Option<f64>,
    max_speed: f64,
) -> (f64, AccelerationRule) {
    if let Some(a) = key {
        return (a, AccelerationRule::Spec);
    }
    match (application.unwrap_or(Application::Traction), peak_torque, inertia) {
        (Application::Traction, _, _) => (max_speed / TRACTION_RUN_UP_S, AccelerationRule::Traction),
        (Application::Servo, Some(t), Some(j)) => (t / (j * (1.0 + SERVO_LOAD_RATIO)), AccelerationRule::ServoLoad),
        (Application::Servo, _, _) => (max_speed / SERVO_RUN_UP_S, AccelerationRule::ServoRunUp),
        (Application::Robot, _, _) => (max_speed / ROBOT_RUN_UP_S, AccelerationRule::Robot),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// By hand: the key wins; traction (also unset): Fischer's 20 000 rpm = 2094.4 rad/s
    /// in 10 s = 209.44 rad/s²; servo with the EMRAX 228's 230 N·m and 0.0383 kg·m²:
    /// 230/(11·0.0383) = 545.93 rad/s² (the bare rotor's 6005 rad/s² is no default any
    /// more); servo without them: 2094.4/0.1 = 20 944 rad/s²; robot: the Mini Cheetah's
    /// 240 rad/s in 0.1 s = 2400 rad/s².
    #[test]
    fn rules_and_hand_values() {
        let w = 20_000.0 * std::f64::consts::PI / 30.0;
        assert_eq!(
            max_acceleration(Some(314.16), Some(Application::Servo), Some(230.0), Some(0.0383), w),
            (314.16, AccelerationRule::Spec)
        );
        for app in [None, Some(Application::Traction)] {
            let (a, rule) = max_acceleration(None, app, Some(230.0), Some(0.0383), w);
            assert!((a - 209.44).abs() < 0.01 && rule == AccelerationRule::Traction, "{a}");
        }
        let (a, rule) = max_acceleration(None, Some(Application::Servo), Some(230.0), Some(0.0383), w);
        assert!((a - 545.93).abs() < 0.01 && rule == AccelerationRule::ServoLoad, "{a}");
        let (a, rule) = max_acceleration(None, Some(Application::Servo), Some(230.0), None, w);
        assert!(
            (a - 20_943.95).abs() < 0.01 && rule == AccelerationRule::ServoRunUp,
            "{a}"
        );
        let (a, rule) = max_acceleration(None, Some(Application::Robot), None, None, 240.0);
        assert!((a - 2400.0).abs() < 1e-9 && rule == AccelerationRule::Robot, "{a}");
    }
}
