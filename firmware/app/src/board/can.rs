//! FDCAN1 receiving the torque setpoint (classic CAN at the board's
//! `motor::board::CAN_BIT_RATE`).
//!
//! Every standard frame goes to RX FIFO 0 (no filter elements; extended and remote
//! frames are rejected) and the main loop picks out the setpoint identifier
//! ([`crate::can_frame`]). The message RAM layout is fixed on the STM32G4
//! (RM0440 §44.3.3).

use stm32g4::stm32g474 as pac;

use super::clocks::{POLL_LIMIT, wait_for};
use crate::can_commissioning::tx_element;
use crate::can_frame::{RxFrame, nbtp_bit_rate};
use crate::hw;
use crate::motor::board;
use motor_control::can_protocol::Frame;

/// FDCAN_NBTP of the bus: the generated `board::CAN_NBTP` (codegen computes it from the
/// FDCAN kernel clock for the board's bit rate, sample point near 87.5 %), checked here
/// again: a build error unless it makes exactly the board's rate from this image's clock.
const NBTP: u32 = match nbtp_bit_rate(hw::FDCAN_CLOCK_HZ, board::CAN_NBTP) {
    Some(rate) if rate == board::CAN_BIT_RATE => board::CAN_NBTP,
    _ => panic!("the generated CAN bit timing does not make the board's bit rate from the FDCAN clock"),
};

/// Number of RX FIFO 0 elements.
const RX_FIFO_ELEMENTS: u8 = 3;
/// Number of Tx buffers (RM0440 §44.3.3).
const TX_BUFFERS: u8 = 3;

/// FDCAN1, owned.
pub struct Can {
    regs: pac::FDCAN1,
}

impl Can {
    /// Configures the bit timing and acceptance and joins the bus; `None` if the
    /// controller does not enter or leave initialisation.
    pub fn new(regs: pac::FDCAN1) -> Option<Self> {
        regs.cccr().modify(|_, w| w.init().set_bit());
        if !wait_for(POLL_LIMIT, || regs.cccr().read().init().bit_is_set()) {
            return None;
        }
        regs.cccr().modify(|_, w| w.cce().set_bit());
        // SAFETY: NBTP holds the computed bit timing; RXGFC: ANFS = 0 (accept
        // non-matching standard frames into FIFO 0), ANFE = 2 (reject extended),
        // RRFS = RRFE = 1 (reject remote frames), no filter elements.
        unsafe {
            regs.nbtp().write(|w| w.bits(NBTP));
            regs.rxgfc()
                .write(|w| w.anfs().bits(0).anfe().bits(0b10).rrfs().set_bit().rrfe().set_bit());
        }
        regs.cccr().modify(|_, w| w.init().clear_bit());
        if !wait_for(POLL_LIMIT, || regs.cccr().read().init().bit_is_clear()) {
            return None;
        }
        Some(Self { regs })
    }

    /// Bus-off recovery. On bus-off (transmit error count past 255, ISO 11898-1) the
    /// FDCAN sets FDCAN_PSR.BO and CCCR.INIT and stops taking part in bus traffic
    /// (RM0440 §44.3.2 "Software initialization": INIT is set "by going Bus_Off"; the
    /// M_CAN core it is built on behaves the same); it stays so until software clears
    /// INIT, after which it counts 128 occurrences of 11 recessive bits (ISO 11898-1's
    /// recovery) before PSR.BO clears and it joins the bus again with its configuration
    /// kept. Clears INIT when bus-off left it set; `true` if it did (one bus-off, recovery
    /// started). The configuration registers are not touched (CCE is cleared with INIT).
    pub fn recover_bus_off(&mut self) -> bool {
        if self.regs.psr().read().bo().bit_is_clear() || self.regs.cccr().read().init().bit_is_clear() {
            return false;
        }
        self.regs.cccr().modify(|_, w| w.init().clear_bit());
        true
    }

    /// The oldest received frame, if any (acknowledged, so the FIFO never fills).
    pub fn poll(&mut self) -> Option<RxFrame> {
        let status = self.regs.rxf0s().read();
        if status.f0fl().bits() == 0 {
            return None;
        }
        let index = status.f0gi().bits();
        if index >= RX_FIFO_ELEMENTS {
            return None;
        }
        let base = hw::FDCAN1_RAM + hw::FDCAN_RXF0_OFFSET + usize::from(index) * hw::FDCAN_RX_ELEMENT_BYTES;
        let word = |k: usize| {
            // SAFETY: `base` is the start of RX FIFO 0 element `index` (< 3) in the
            // FDCAN1 message RAM; its first four words are word-aligned and owned by
            // this driver while the element is not acknowledged.
            unsafe { core::ptr::read_volatile((base + 4 * k) as *const u32) }
        };
        let frame = RxFrame::from_words([word(0), word(1), word(2), word(3)]);
        // SAFETY: F0AI takes the get index just read.
        self.regs.rxf0a().write(|w| unsafe { w.f0ai().bits(index) });
        Some(frame)
    }

    /// The Tx FIFO can take a frame (TXFQS.TFQF clear, RM0440 §44.4.27).
    pub fn has_room(&self) -> bool {
        self.regs.txfqs().read().tfqf().bit_is_clear()
    }

    /// Queues one classic frame in the Tx FIFO (TXBC.TFQM = 0 after reset) as the first
    /// four words of a Tx buffer element (`motor_config::can_commissioning::tx_element`)
    /// and requests its transmission; `false` if the FIFO is full (nothing written). The
    /// FDCAN retransmits until the frame is acknowledged (CCCR.DAR = 0). The only
    /// transmit path of the image: status, capture and fault-report frames.
    pub fn send(&mut self, frame: &Frame) -> bool {
        let status = self.regs.txfqs().read();
        let index = status.tfqpi().bits();
        if status.tfqf().bit_is_set() || index >= TX_BUFFERS {
            return false;
        }
        let base = hw::FDCAN1_RAM + hw::FDCAN_TXBUF_OFFSET + usize::from(index) * hw::FDCAN_TX_ELEMENT_BYTES;
        for (k, w) in tx_element(frame).into_iter().enumerate() {
            // SAFETY: `base` is Tx buffer `index` (< 3) of the FDCAN1 message RAM, free
            // (TXFQS put index of a FIFO that is not full); word-aligned.
            unsafe { core::ptr::write_volatile((base + 4 * k) as *mut u32, w) };
        }
        // SAFETY: AR takes a mask of the buffers to send; bit `index` < 3.
        self.regs.txbar().write(|w| unsafe { w.ar().bits(1 << index) });
        true
    }
}
