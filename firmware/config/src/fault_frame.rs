//! The fault-report CAN frame (pure), sent once after a boot that found a fault record
//! ([`crate::fault_record`]): the generated `can::FAULT_REPORT_ID` (also in the DBC file
//! `motorgen generate` writes), eight data bytes laid out by
//! `motor_control::can_protocol::encode_fault_report` (the encoder the DBC test checks):
//!
//! | byte | content |
//! |---|---|
//! | 0 | cause code ([`FaultCause`] as `u8`: 1 HardFault, 2 stack overflow, 3 break, 4 trip, 5 lost conversion, 6 bring-up, 7 unhandled interrupt, 8 panic, 9 watchdog, 10 current offset, 11–18 the pre-flight check's refusals, 19 resolver signal) |
//! | 1 | flags: bit 0 PC valid, bit 1 state valid, bit 2 outputs were on, bit 3 tripped, bit 4 measurement valid, bits 5–6 the measurement's index |
//! | 2–5 | stacked PC, little-endian, when valid; else the start-up check's measurement (causes 10–19: IEEE 754 single, little-endian; its unit and index by cause, README "What a refusal reports"); else 0 |
//! | 6–7 | i_q of the last period, little-endian `i16` in units of the generated `can::FAULT_CURRENT_PER_LSB`, rounded, saturating; `i16::MIN` when not a number; 0 when the state is not valid |
//!
//! The full record (currents, angle, speed, DC link, CFSR/HFSR) is read with a probe
//! (firmware/README.md, "Fault record").
#![forbid(unsafe_code)]

use motor_control::can_protocol::{FaultReport, FaultState, encode_fault_report};

use crate::fault_record::{FaultCause, FaultRecord};
use crate::motor::{board, can};

// The report must not be taken for a setpoint or another drive frame by the vehicle
// unit, nor the reverse: its identifier lies outside the board's setpoint identifier and
// the generated `can` group's status … capture-end identifiers.
const _: () = {
    let id = can::FAULT_REPORT_ID;
    assert!(
        id != board::SETPOINT_ID && (id < can::STATUS_ID || id > can::CAPTURE_END_ID),
        "the fault report's identifier (can::FAULT_REPORT_ID) collides with a drive frame's"
    );
};

/// The eight data bytes of the report of `r`.
pub fn encode(r: &FaultRecord) -> [u8; 8] {
    encode_fault_report(
        can::FAULT_CURRENT_PER_LSB,
        &FaultReport {
            cause: r.cause as u8,
            pc: r.pc,
            state: r.state.map(|s| FaultState {
                running: s.running,
                tripped: s.tripped,
                i_q: s.i_q,
            }),
            measured: r.measured,
        },
    )
}

/// The cause byte of a report, decoded (for a receiver written in Rust).
pub fn cause_of(data: &[u8; 8]) -> Option<FaultCause> {
    FaultCause::from_code(u32::from(data[0]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fault_record::ControlState;
    use motor_control::can_protocol::FaultMeasurement;

    fn state(i_q: f32) -> ControlState {
        ControlState {
            i_d: 0.0,
            i_q,
            theta_e: 0,
            omega_e: 0.0,
            u_dc: 600.0,
            periods: 1,
            bus_off: 0,
            running: true,
            tripped: true,
        }
    }

    /// A trip at i_q = 212.26 A with PC 0x0800_1234: i_q/0.1 A = 2122.6 → 2123 =
    /// 0x084B; flags = PC | state | on | tripped = 0x0F.
    #[test]
    fn trip_report() {
        assert_eq!(can::FAULT_CURRENT_PER_LSB, 0.1);
        let r = FaultRecord {
            pc: Some(0x0800_1234),
            state: Some(state(212.26)),
            ..FaultRecord::of(FaultCause::Trip)
        };
        let d = encode(&r);
        assert_eq!(d, [4, 0x0F, 0x34, 0x12, 0x00, 0x08, 0x4B, 0x08]);
        assert_eq!(cause_of(&d), Some(FaultCause::Trip));
    }

    /// No PC, no state: only the cause; −5000 A saturates at −32768 (0x8000), as does a
    /// NaN (documented as "not a number").
    #[test]
    fn bare_and_saturated() {
        let mut r = FaultRecord::of(FaultCause::Watchdog);
        assert_eq!(encode(&r), [9, 0, 0, 0, 0, 0, 0, 0]);
        r.state = Some(state(5000.0));
        assert_eq!(&encode(&r)[6..], &0x7FFFu16.to_le_bytes());
        r.state = Some(state(f32::NAN));
        assert_eq!(&encode(&r)[6..], &[0x00, 0x80]);
    }

    /// A start-up check's refusal: the resolver signal at 0.25 of the designed one
    /// (0.25 = 2^−2: exponent 125 = 0x7D, mantissa 0 → 0x3E80_0000, bytes 00 00 80 3E);
    /// flags = state | measurement = 0x12, index 0; phase w's offset (index 2) sets bits
    /// 5–6 to 0b10: 0x52. A record with a PC sends the PC and clears the measurement's
    /// flag.
    #[test]
    fn measurement_report() {
        let mut r = FaultRecord {
            state: Some(ControlState {
                running: false,
                tripped: false,
                ..state(0.0)
            }),
            measured: Some(FaultMeasurement::of(0.25)),
            ..FaultRecord::of(FaultCause::ResolverSignal)
        };
        assert_eq!(encode(&r), [19, 0x12, 0x00, 0x00, 0x80, 0x3E, 0, 0]);
        r.cause = FaultCause::CurrentOffset;
        r.measured = Some(FaultMeasurement::at(-2_992.0, 2));
        // −2 992.0 = 0xC53B_0000 (fault_record's layout test).
        assert_eq!(encode(&r), [10, 0x52, 0x00, 0x00, 0x3B, 0xC5, 0, 0]);
        r.pc = Some(0x0800_1234);
        assert_eq!(encode(&r)[1..6], [0x03, 0x34, 0x12, 0x00, 0x08]);
    }

    /// The generated identifier is 0x0E0; ID 0x0E0 → T0 = 0x0E0 << 18 = 0x0380_0000; DLC 8 → T1 = 0x0008_0000; the
    /// element decodes back through the receive path's `RxFrame::from_words` (same
    /// layout of the first words for Rx and Tx elements, RM0440 §44.3.3).
    #[test]
    fn tx_element_layout() {
        assert_eq!(can::FAULT_REPORT_ID, 0x0E0);
        let data = [1, 2, 3, 4, 5, 6, 7, 8];
        let w = crate::can_commissioning::tx_element(&motor_control::can_protocol::Frame {
            id: 0x0E0,
            len: 8,
            data,
        });
        assert_eq!(w, [0x0380_0000, 0x0008_0000, 0x0403_0201, 0x0807_0605]);
        let back = crate::can_frame::RxFrame::from_words(w);
        assert_eq!(back.standard_id, Some(0x0E0));
        assert_eq!(back.bytes(), &data);
    }
}
