//! The torque-setpoint CAN frame (pure): standard identifier
//! [`hw::SETPOINT_CAN_ID`], at least two data bytes, bytes 0–1 a little-endian `i16`
//! torque in units of [`hw::SETPOINT_TORQUE_MNM_PER_LSB`] mN·m.
#![forbid(unsafe_code)]

use crate::hw;

/// Millinewton-metres per newton-metre.
const MNM_PER_NM: f32 = 1_000.0;

/// Torque \[N·m\] carried by a frame, `None` if the frame is not a setpoint (other
/// identifier, extended identifier, or fewer than two bytes).
pub fn decode_torque(standard_id: Option<u16>, data: &[u8]) -> Option<f32> {
    if standard_id != Some(hw::SETPOINT_CAN_ID) {
        return None;
    }
    let [lo, hi, ..] = *data else {
        return None;
    };
    let raw = i16::from_le_bytes([lo, hi]);
    Some(f32::from(raw) * hw::SETPOINT_TORQUE_MNM_PER_LSB as f32 / MNM_PER_NM)
}

/// q-axis current reference \[A\] for a torque \[N·m\], i_q = T/K_t (2.34) with the
/// generated `IQ_PER_NM` (i_d = 0; the setpoint supervision limits it).
pub fn torque_to_iq(torque_nm: f32, iq_per_nm: f32) -> f32 {
    torque_nm * iq_per_nm
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 0x0BB8 = 3000 LSB · 10 mN·m = 30 N·m; 0xF448 = −3000 → −30 N·m.
    #[test]
    fn decodes_setpoints() {
        let id = Some(hw::SETPOINT_CAN_ID);
        assert_eq!(decode_torque(id, &[0xB8, 0x0B]), Some(30.0));
        assert_eq!(decode_torque(id, &[0x48, 0xF4, 0xFF, 0x00]), Some(-30.0));
        assert_eq!(decode_torque(id, &[0xB8]), None);
        assert_eq!(decode_torque(None, &[0xB8, 0x0B]), None);
        assert_eq!(decode_torque(Some(hw::SETPOINT_CAN_ID + 1), &[0xB8, 0x0B]), None);
    }

    /// Fischer: K_t = 3/2·n_p·ψ_M = 6·0.060421 = 0.36252 N·m/A → 10 N·m needs 27.584 A.
    #[test]
    fn torque_to_current() {
        let iq_per_nm = 1.0 / (1.5 * 4.0 * 0.060_420_75);
        assert!((torque_to_iq(10.0, iq_per_nm) - 27.584).abs() < 1e-3);
    }
}
