//! The controller configuration of the motor `motor-firmware` is built for
//! (`MOTOR=<stem>`) and the operating point of the instruction-count benchmark.

use motor_config::motor::limits;
use motor_control::transforms::Dq;

use crate::icount::OperatingPoint;

/// The controller configuration of this image's motor: the one the firmware runs
/// ([`motor_config::config::CONTROLLER`], from the generated constants).
pub const CONFIG: motor_control::step::ControllerConfig = motor_config::config::CONTROLLER;

/// The benchmark's operating point: half the maximum electrical speed, i_q at half
/// and i_d at −10 % of the peak current, at the nominal DC link (V_max·√3).
pub fn operating_point() -> OperatingPoint {
    OperatingPoint {
        omega_e: 0.5 * limits::MAX_ELECTRICAL_SPEED,
        current: Dq {
            d: -0.1 * limits::PEAK_CURRENT_A,
            q: 0.5 * limits::PEAK_CURRENT_A,
        },
        u_dc: limits::VOLTAGE_LIMIT_V * 1.732_050_8,
    }
}
