//! The commissioning mode of this image (pure): the CAN interface and the chapter-6
//! routine parameters from the generated `can` and `commissioning` groups, bound into
//! `motor_control::commissioning_mode::ModeConfig` — the same values `motorgen`'s
//! `identify::candump::mode_config` reads from the design, so the host decodes what
//! this image encodes.
#![forbid(unsafe_code)]

use motor_control::can_protocol::Layout;
use motor_control::commissioning::FluxLinkage;
use motor_control::commissioning_mode::{CommissioningMode, ModeConfig};
use motor_control::preflight::Preflight;

use crate::motor::{board, can, commissioning};

/// Identifiers and signal scalings.
pub const LAYOUT: Layout = Layout {
    status_id: can::STATUS_ID,
    command_id: can::COMMAND_ID,
    header_id: can::CAPTURE_HEADER_ID,
    data_id: can::CAPTURE_DATA_ID,
    end_id: can::CAPTURE_END_ID,
    current_per_lsb: can::CURRENT_PER_LSB,
    voltage_per_lsb: can::VOLTAGE_PER_LSB,
    speed_per_lsb: can::SPEED_PER_LSB,
};

/// The routines' fixed parameters. A torque setpoint counts as zero below half its LSB
/// (a frame with any non-zero value is not zero).
pub const MODE: ModeConfig = ModeConfig {
    layout: LAYOUT,
    sample_period_units: can::SAMPLE_PERIOD_UNITS,
    standstill_speed: commissioning::STANDSTILL_SPEED,
    zero_torque: 0.5 * board::TORQUE_PER_LSB_NM,
    step_samples: (commissioning::STEP_PRE_SAMPLES, commissioning::STEP_SAMPLES),
    align_samples: (
        commissioning::ALIGN_RAMP_SAMPLES,
        commissioning::ALIGN_SETTLE_SAMPLES,
        commissioning::ALIGN_AVERAGE_SAMPLES,
    ),
    rotation: (
        commissioning::ROTATION_STEP,
        commissioning::ROTATION_TURNS,
        commissioning::ROTATION_SETTLE_SAMPLES,
    ),
    flux: FluxLinkage {
        settle_samples: commissioning::FLUX_SETTLE_SAMPLES,
        average_samples: commissioning::FLUX_AVERAGE_SAMPLES,
        min_speed: commissioning::FLUX_MIN_SPEED,
    },
    injection_limit: commissioning::INJECTION_LIMIT,
    preflight: PREFLIGHT,
};

/// The pre-flight check (issue 26 item 2): the generated `PREFLIGHT_*` figures; the
/// rotation holds as long as the §6.4 rotation and turns at its rate, or slower where a
/// following rotor's back-EMF would eat the rotation's voltage (`PREFLIGHT_ROTATION_STEP`).
pub const PREFLIGHT: Preflight = Preflight {
    voltage: commissioning::PREFLIGHT_VOLTAGE,
    level_samples: commissioning::PREFLIGHT_LEVEL_SAMPLES,
    rest_samples: commissioning::PREFLIGHT_REST_SAMPLES,
    average_samples: commissioning::PREFLIGHT_AVERAGE_SAMPLES,
    resistance: commissioning::PREFLIGHT_RESISTANCE,
    inductance: commissioning::PREFLIGHT_INDUCTANCE,
    resistance_ratio: commissioning::PREFLIGHT_RESISTANCE_RATIO,
    inductance_ratio: commissioning::PREFLIGHT_INDUCTANCE_RATIO,
    current_trip: commissioning::PREFLIGHT_CURRENT_TRIP,
    sum_bound: commissioning::PREFLIGHT_SUM_BOUND,
    open_fraction: commissioning::PREFLIGHT_OPEN_FRACTION,
    sample_period: crate::config::CONTROLLER.sample_period,
    tau_offset: commissioning::PREFLIGHT_TAU_OFFSET,
    rotation_voltage: commissioning::PREFLIGHT_VOLTAGE,
    rotation_step: commissioning::PREFLIGHT_ROTATION_STEP,
    settle_samples: commissioning::ROTATION_SETTLE_SAMPLES,
    ratio: commissioning::PREFLIGHT_RATIO,
    ratio_bound: commissioning::PREFLIGHT_RATIO_BOUND,
    angle_bound: commissioning::PREFLIGHT_ANGLE_BOUND,
};

/// Captured samples the image holds.
pub const CAPACITY: usize = commissioning::CAPTURE_CAPACITY as usize;

/// The commissioning supervisor of this image (its capture buffer holds [`CAPACITY`]
/// samples).
pub type Mode = CommissioningMode;

/// Control periods between status frames: the status period times the PWM frequency
/// (T_s = 100 ns · SAMPLE_PERIOD_UNITS), at least 1.
pub const STATUS_PERIODS: u32 = {
    let periods = can::STATUS_PERIOD_S / (can::SAMPLE_PERIOD_UNITS as f32 / 1e7);
    if periods >= 1.0 { periods as u32 } else { 1 }
};

/// A frame as the first four words of an FDCAN TX buffer element (RM0440 §44.3.3,
/// "Tx buffer element"): word 0 the standard identifier in bits 28:18 (XTD = RTR = 0),
/// word 1 the DLC in bits 19:16 (classic CAN: FDF = BRS = 0, no TX event), words 2–3
/// the data bytes little-endian.
pub fn tx_element(f: &motor_control::can_protocol::Frame) -> [u32; 4] {
    let [a, b, c, d, e, g, h, i] = f.data;
    [
        u32::from(f.id & 0x7FF) << 18,
        u32::from(f.len.min(8)) << 16,
        u32::from_le_bytes([a, b, c, d]),
        u32::from_le_bytes([e, g, h, i]),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use motor_control::can_protocol::{self as p, Command, Routine};

    /// The drive's frames follow the setpoint identifier (status +1 … capture end +5).
    #[test]
    fn identifiers_follow_the_setpoint() {
        let ids = [
            LAYOUT.status_id,
            LAYOUT.command_id,
            LAYOUT.header_id,
            LAYOUT.data_id,
            LAYOUT.end_id,
        ];
        for (k, id) in (1u16..).zip(ids) {
            assert_eq!(id, board::SETPOINT_ID + k);
        }
    }

    /// A command sent with this layout is the command received; the status frame is
    /// 4 bytes on STATUS_ID.
    #[test]
    fn command_round_trip() {
        let c = Command {
            routine: Some(Routine::Step),
            axis_q: false,
            voltage: 2.0 * can::VOLTAGE_PER_LSB * 100.0,
            current_trip: can::CURRENT_PER_LSB * 1000.0,
            decimation: 2,
        };
        let f = p::encode_command(&LAYOUT, &c);
        assert_eq!(p::decode_command(&LAYOUT, can::COMMAND_ID, f.bytes()), Some(c));
        let mode = Mode::new();
        let s = mode.status(&MODE, 0);
        assert_eq!((s.id, s.len), (can::STATUS_ID, can::STATUS_LEN));
    }

    /// Identifier 0x101 → 0x101 << 18 = 0x0404_0000; DLC 4 → 0x0004_0000; data
    /// 03 07 01 A5 → 0xA501_0703 (the inverse of `can_frame::RxFrame::from_words`).
    #[test]
    fn tx_element_words() {
        let f = p::Frame {
            id: 0x101,
            len: 4,
            data: [3, 7, 1, 0xA5, 0, 0, 0, 0],
        };
        assert_eq!(tx_element(&f), [0x0404_0000, 0x0004_0000, 0xA501_0703, 0]);
        let back = crate::can_frame::RxFrame::from_words(tx_element(&f));
        assert_eq!((back.standard_id, back.bytes()), (Some(0x101), &f.data[..4]));
    }

    /// The default image (Fischer, 20 kHz): 10 ms status period = 200 periods.
    #[test]
    fn status_rate() {
        if option_env!("MOTOR").is_some_and(|m| m != "fischer-ti085") {
            return;
        }
        assert_eq!(STATUS_PERIODS, 200);
    }
}
