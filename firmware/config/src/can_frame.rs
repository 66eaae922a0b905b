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

/// The bit rate \[bit/s\] FDCAN_NBTP `nbtp` makes from a `clock_hz` kernel clock, or
/// `None` if its fields are out of range or the rate is not a whole number: prescaler
/// NBRP + 1 (1 … 512), bit 1 + (NTSEG1 + 1) + (NTSEG2 + 1) quanta with NTSEG1 ≥ 1 (RM0440
/// §44.4.7: NTSEG1 1 … 255, NTSEG2 0 … 127), SJW ≤ TSEG2. The generated `board::CAN_NBTP`
/// is computed by the code generator for the board's bit rate (`motorgen check` refuses a
/// rate the clock cannot make); the image checks it again with this at compile time.
pub const fn nbtp_bit_rate(clock_hz: u32, nbtp: u32) -> Option<u32> {
    let sjw = (nbtp >> 25) + 1;
    let brp = ((nbtp >> 16) & 0x1FF) + 1;
    let tseg1 = ((nbtp >> 8) & 0xFF) + 1;
    let tseg2 = (nbtp & 0x7F) + 1;
    if nbtp & 0x80 != 0 || tseg1 < 2 || sjw > tseg2 {
        return None;
    }
    let per_bit = brp * (1 + tseg1 + tseg2);
    if !clock_hz.is_multiple_of(per_bit) {
        return None;
    }
    Some(clock_hz / per_bit)
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

    /// NBTP 0x2801_9314 (codegen's 500 kbit/s at 170 MHz): NSJW 20, NBRP 1, NTSEG1 147,
    /// NTSEG2 20 → prescaler 2, 1 + 148 + 21 = 170 quanta → 170 MHz/340 = 500 000 bit/s
    /// (hand calculation); the old fixed timing 0x0610_0E03 (prescaler 17, 1 + 15 + 4) →
    /// 170 MHz/340 = 500 000 too; NTSEG2 bit 7 set, a 0-quantum TSEG1 or SJW > TSEG2 → None;
    /// 170 MHz does not divide by 3·(1 + 15 + 4) = 60 → None.
    #[test]
    fn bit_timing() {
        assert_eq!(nbtp_bit_rate(170_000_000, 0x2801_9314), Some(500_000));
        assert_eq!(nbtp_bit_rate(170_000_000, 0x0610_0E03), Some(500_000));
        assert_eq!(nbtp_bit_rate(170_000_000, 0x2801_9394), None);
        assert_eq!(nbtp_bit_rate(170_000_000, 0x0610_0003), None);
        assert_eq!(nbtp_bit_rate(170_000_000, 0x0A10_0E03), None);
        assert_eq!(nbtp_bit_rate(170_000_000, 0x0602_0E03), None);
        assert_eq!(
            nbtp_bit_rate(crate::hw::FDCAN_CLOCK_HZ, board::CAN_NBTP),
            Some(board::CAN_BIT_RATE),
            "the generated timing makes the board's rate from the image's kernel clock"
        );
        // The NUCLEO-G474RE's 24 MHz HSE crystal at 500 kbit/s: 48 quanta, prescaler 1,
        // 1 + 41 + 6 → sample point 42/48 = 87.5 % (CiA 601-3); NBTP = NSJW 5 << 25 |
        // NBRP 0 << 16 | NTSEG1 40 << 8 | NTSEG2 5 = 0x0A00_2805 (hand calculation).
        assert_eq!(nbtp_bit_rate(24_000_000, 0x0A00_2805), Some(500_000));
    }
}
