//! FDCAN1 transmission through its TX FIFO: the status frame and the commissioning
//! capture (`motor_config::can_commissioning`). Reception stays in [`super::can`]; this
//! module touches only the TX side (TXFQS, TXBAR and the TX buffer elements of the
//! message RAM), which [`super::can::Can`] never uses.
//!
//! The message RAM layout is fixed on the STM32G4 (RM0440 §44.3.3): FDCAN1's TX
//! buffers start at 0x278, three elements of 18 words; TXBC.TFQM = 0 at reset selects
//! FIFO order.

use stm32g4::stm32g474 as pac;

use crate::hw;
use motor_config::can_commissioning::tx_element;
use motor_control::can_protocol::Frame;

/// Offset of the TX buffers in the FDCAN1 message RAM \[bytes\] (RM0440 §44.3.3).
const TX_OFFSET: usize = 0x278;
/// TX buffer elements (RM0440 §44.3.3).
const TX_ELEMENTS: u8 = 3;

/// FDCAN1's TX side.
pub struct CanTx {
    regs: pac::FDCAN1,
}

impl CanTx {
    /// The TX side of the FDCAN1 that [`super::can::Can::new`] configured.
    pub fn new() -> Self {
        // SAFETY: a second handle on FDCAN1 used only for TXFQS (read), TXBAR (write)
        // and the TX buffer elements, which the receive driver never touches.
        Self {
            regs: unsafe { pac::FDCAN1::steal() },
        }
    }

    /// The TX FIFO can take a frame.
    pub fn has_room(&self) -> bool {
        self.regs.txfqs().read().tfqf().bit_is_clear()
    }

    /// Queues `frame`; `false` if the TX FIFO is full (nothing written).
    pub fn send(&mut self, frame: &Frame) -> bool {
        let status = self.regs.txfqs().read();
        if status.tfqf().bit_is_set() {
            return false;
        }
        let index = status.tfqpi().bits();
        if index >= TX_ELEMENTS {
            return false;
        }
        // TX and RX elements have the same size (18 words, RM0440 §44.3.3).
        let base = hw::FDCAN1_RAM + TX_OFFSET + usize::from(index) * hw::FDCAN_RX_ELEMENT_BYTES;
        for (k, word) in tx_element(frame).into_iter().enumerate() {
            // SAFETY: `base` is TX buffer element `index` (< 3) of the FDCAN1 message
            // RAM, free while its add request is not set (TXFQS put index).
            unsafe { core::ptr::write_volatile((base + 4 * k) as *mut u32, word) };
        }
        // SAFETY: AR takes the bit of the element just written.
        self.regs.txbar().write(|w| unsafe { w.ar().bits(1 << index) });
        true
    }
}
