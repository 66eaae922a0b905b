//! The [`ControllerConfig`] of the motor `motor-firmware` is built for (`MOTOR=<stem>`),
//! from its generated constants ([`motor_firmware::motor`]), and the operating point
//! of the instruction-count benchmark.

use motor_control::adc::{CurrentSense, DcLinkSense, MeasuredPhases};
use motor_control::angle::ResolverToElectrical;
use motor_control::ato::{AtoConfig, ObserverError};
use motor_control::feedforward::FeedForwardConfig;
use motor_control::pi::{CurrentPiConfig, PiConfig, VoltageLimit};
use motor_control::step::ControllerConfig;
use motor_control::transforms::Dq;
use motor_firmware::motor::{current_loop as cl, limits, observer, scaling};

use crate::icount::OperatingPoint;

/// Mid-scale code of the 12-bit phase-current ADCs (bipolar sensors) \[LSB\].
const CURRENT_ADC_MID: i32 = 2048;
/// Codes of a 12-bit ADC.
const ADC_CODES: f32 = 4096.0;

/// One axis of the current PI: the generated parallel gains, back-calculation and
/// active damping (thesis B (2.31), (2.49)).
const fn axis(kp: f32, ki: f32, anti_windup: f32, active_damping: f32) -> PiConfig {
    PiConfig {
        kp,
        ki,
        anti_windup,
        active_damping,
        reference_filter: 1.0,
    }
}

/// The controller configuration of this image's motor.
pub const CONFIG: ControllerConfig = ControllerConfig {
    sample_period: limits::SAMPLE_PERIOD_S,
    speed_per_lsb: scaling::SPEED_PER_LSB,
    current_sense: CurrentSense {
        offset: [CURRENT_ADC_MID; 3],
        // ±full scale over the 12-bit range.
        amps_per_lsb: [2.0 * scaling::CURRENT_FULL_SCALE / ADC_CODES; 3],
        phases: MeasuredPhases::UV,
    },
    dc_link_sense: DcLinkSense {
        offset: 0,
        volts_per_lsb: scaling::DC_LINK_FULL_SCALE / ADC_CODES,
    },
    observer: AtoConfig {
        kp: observer::KP,
        ki: observer::KI,
        error: ObserverError::TrigIdentity,
    },
    angle: ResolverToElectrical {
        motor_pole_pairs: observer::MOTOR_POLE_PAIRS as u16,
        resolver_pole_pairs: observer::RESOLVER_POLE_PAIRS as u16,
        offset: 0,
    },
    angle_lead: observer::LEAD_Q16,
    current_loop: CurrentPiConfig {
        d: axis(cl::D_KP, cl::D_KI, cl::D_ANTI_WINDUP, cl::D_ACTIVE_DAMPING),
        q: axis(cl::Q_KP, cl::Q_KI, cl::Q_ANTI_WINDUP, cl::Q_ACTIVE_DAMPING),
        limit: VoltageLimit::Proportional,
    },
    feed_forward: FeedForwardConfig {
        ld: cl::FF_LD,
        lq: cl::FF_LQ,
        psi_m: cl::FF_PSI,
    },
    dc_link_min: limits::DC_LINK_MIN_V,
    voltage_margin: 1.0,
    pwm_period: 4250,
};

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
