//! The torque-setpoint CAN frame (pure): standard identifier `board::SETPOINT_ID`, at
//! least two data bytes, bytes 0–1 a little-endian `i16` torque in units of
//! `board::TORQUE_PER_LSB_NM` (both from the board file's `[can]`).
#![forbid(unsafe_code)]

use crate::motor::board;

/// Torque \[N·m\] carried by a frame, `None` if the frame is not a setpoint (other
/// identifier, extended identifier, or fewer than two bytes).
pub fn decode_torque(standard_id: Option<u16>, data: &[u8]) -> Option<f32> {
    if standard_id != Some(board::SETPOINT_ID) {
        return None;
    }
    let [lo, hi, ..] = *data else {
        return None;
    };
    let raw = i16::from_le_bytes([lo, hi]);
    Some(f32::from(raw) * board::TORQUE_PER_LSB_NM)
}

/// A received classic-CAN frame as the FDCAN stores it in an RX FIFO element
/// (RM0440 §44.3.3, "Rx FIFO element"): word 0 holds XTD (bit 30) and the standard
/// identifier (bits 28:18), word 1 the DLC (bits 19:16), words 2–3 the data bytes
/// little-endian.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RxFrame {
    /// Standard identifier, `None` for an extended frame.
    pub standard_id: Option<u16>,
    /// Data bytes; only the first `len` are valid.
    pub data: [u8; 8],
    /// Data length (DLC 0–8; larger DLCs of classic CAN mean 8).
    pub len: usize,
}

impl RxFrame {
    /// Decodes the first four words of an RX FIFO element.
    pub fn from_words(words: [u32; 4]) -> Self {
        let [w0, w1, w2, w3] = words;
        let extended = w0 & (1 << 30) != 0;
        let standard_id = (!extended).then_some(((w0 >> 18) & 0x7FF) as u16);
        let dlc = ((w1 >> 16) & 0xF) as usize;
        let [a, b, c, d] = w2.to_le_bytes();
        let [e, f, g, h] = w3.to_le_bytes();
        Self {
            standard_id,
            data: [a, b, c, d, e, f, g, h],
            len: dlc.min(8),
        }
    }

    /// The valid data bytes.
    pub fn bytes(&self) -> &[u8] {
        self.data.get(..self.len).unwrap_or(&[])
    }
}

/// FDCAN_NBTP for the nominal bit timing: prescaler `f_clk/(bitrate·tq_per_bit)`
/// (must divide exactly), TSEG1 = tq_per_bit − 1 − TSEG2, SJW = TSEG2
/// (RM0440 §44.4.9: each field holds value − 1). `None` if the clock does not divide.
pub const fn nominal_bit_timing(clock_hz: u32, bitrate: u32, tq_per_bit: u32, tseg2: u32) -> Option<u32> {
    let per_bit = bitrate as u64 * tq_per_bit as u64;
    if per_bit == 0 || !(clock_hz as u64).is_multiple_of(per_bit) || tseg2 == 0 || tq_per_bit < tseg2 + 3 {
        return None;
    }
    let brp = (clock_hz as u64 / per_bit) as u32;
    let tseg1 = tq_per_bit - 1 - tseg2;
    if brp > 512 || tseg1 > 256 || tseg2 > 128 {
        return None;
    }
    Some(((tseg2 - 1) << 25) | ((brp - 1) << 16) | ((tseg1 - 1) << 8) | (tseg2 - 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 0x0BB8 = 3000 LSB · 0.01 N·m = 30 N·m; 0xF448 = −3000 → −30 N·m (both seed
    /// boards: `torque_resolution = "0.01 N·m"`).
    #[test]
    fn decodes_setpoints() {
        let id = Some(board::SETPOINT_ID);
        let lsb = board::TORQUE_PER_LSB_NM;
        assert_eq!(decode_torque(id, &[0xB8, 0x0B]), Some(3000.0 * lsb));
        assert_eq!(decode_torque(id, &[0x48, 0xF4, 0xFF, 0x00]), Some(-3000.0 * lsb));
        assert_eq!(decode_torque(id, &[0xB8]), None);
        assert_eq!(decode_torque(None, &[0xB8, 0x0B]), None);
        assert_eq!(decode_torque(Some(board::SETPOINT_ID ^ 1), &[0xB8, 0x0B]), None);
    }

    /// Standard ID 0x100 → word 0 = 0x100 << 18 = 0x0400_0000; DLC 2 → word 1 =
    /// 0x0002_0000; data B8 0B.
    #[test]
    fn rx_element() {
        let f = RxFrame::from_words([0x0400_0000, 0x0002_0000, 0x0000_0BB8, 0]);
        assert_eq!(f.standard_id, Some(0x100));
        assert_eq!(f.bytes(), &[0xB8, 0x0B]);
        let ext = RxFrame::from_words([0x4400_0000, 0x000F_0000, 0, 0]);
        assert_eq!(ext.standard_id, None);
        assert_eq!(ext.len, 8);
    }

    /// 170 MHz, 500 kbit/s, 20 tq: prescaler 17, TSEG1 15, TSEG2 4, SJW 4 →
    /// (3 << 25) | (16 << 16) | (14 << 8) | 3 = 0x0610_0E03 (hand calculation).
    #[test]
    fn bit_timing() {
        assert_eq!(nominal_bit_timing(170_000_000, 500_000, 20, 4), Some(0x0610_0E03));
        assert_eq!(nominal_bit_timing(170_000_000, 1_000_000, 20, 4), None); // 8.5
        assert_eq!(nominal_bit_timing(170_000_000, 500_000, 20, 0), None);
    }
}
