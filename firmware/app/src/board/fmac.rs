//! FMAC filter accelerator running the generated identification FIR
//! (`motor::filter::TAPS_Q15`, thesis A §6.2; RM0440 §18).
//!
//! Memory: X2 (coefficients) at 0, N words; X1 (input ring) at N, N + d words;
//! Y (output ring) at 2N + d, d words, with d = [`D`] where it fits and 1 for 127 taps
//! (RM0440 §18.3.8: an N-tap FIR needs at least 2N + 1 of the 256 words, so N ≤ 127;
//! the extra d1, d2 words only buy throughput, and [`Fmac::push`] moves one sample at a
//! time). The coefficient load (FUNC 2) writes the N
//! taps, the X1 load (FUNC 1) N − 1 zeros — the FMAC computes its first output once
//! N samples are present, so the first output is b_0·x(0) as for an all-zero
//! history — then FUNC 8 (FIR) runs with the gain R and CLIPEN of the
//! configuration. [`motor_control::fir::FmacFir`] is the bit-exact model; start-up
//! compares the two ([`Fmac::self_test`]).

use motor_control::fir::{FirState, FmacFir};
use stm32g4::stm32g474 as pac;

use super::clocks::{POLL_LIMIT, wait_for};

/// FUNC codes (RM0440 §18.4.4).
const FUNC_LOAD_X1: u32 = 1;
const FUNC_LOAD_X2: u32 = 2;
const FUNC_FIR: u32 = 8;
/// Extra X1 space and Y length where the memory has room for them.
const D: usize = 2;
/// Words of the FMAC's local memory.
const MEMORY: usize = 256;

/// The FMAC, owned.
pub struct Fmac {
    regs: pac::FMAC,
}

impl Fmac {
    /// Takes the peripheral (its clock must be enabled).
    pub fn new(regs: pac::FMAC) -> Self {
        Self { regs }
    }

    /// Writes PARAM (FUNC, P, Q = 0, R) with START set.
    fn start(&mut self, func: u32, p: usize, r: u8) {
        let bits = (1 << 31) | (func << 24) | (u32::from(r) << 16) | (p as u32 & 0xFF);
        // SAFETY: PARAM takes any FUNC/P/Q/R combination; the values are RM0440's.
        self.regs.param().write(|w| unsafe { w.bits(bits) });
    }

    /// Waits until a load function has consumed its data (START cleared).
    fn wait_done(&self) -> bool {
        wait_for(POLL_LIMIT, || self.regs.param().read().start().bit_is_clear())
    }

    fn write(&mut self, x: i16) {
        // SAFETY: WDATA takes any 16-bit value (Q1.15 sample or coefficient).
        self.regs.wdata().write(|w| unsafe { w.wdata().bits(x as u16) });
    }

    /// Loads the taps, clears the history and starts the FIR; `false` on a timeout.
    pub fn start_fir<const N: usize>(&mut self, fir: &FmacFir<N>) -> bool {
        const { assert!(2 * N + 2 <= MEMORY, "FIR too long for the FMAC memory") };
        let d = if 2 * N + 2 * D <= MEMORY {
            D
        } else {
            (MEMORY - 2 * N) / 2
        };
        self.regs.cr().write(|w| w.reset().set_bit());
        if !wait_for(POLL_LIMIT, || self.regs.cr().read().reset().bit_is_clear()) {
            return false;
        }
        let (x2, x1, y) = (0, N, 2 * N + d);
        // SAFETY: base/size fields are 8-bit word addresses inside the 256 words
        // (checked at compile time above).
        unsafe {
            self.regs
                .x2bufcfg()
                .write(|w| w.x2_base().bits(x2 as u8).x2_buf_size().bits(N as u8));
            self.regs
                .x1bufcfg()
                .write(|w| w.x1_base().bits(x1 as u8).x1_buf_size().bits((N + d) as u8));
            self.regs
                .ybufcfg()
                .write(|w| w.y_base().bits(y as u8).y_buf_size().bits(d as u8));
        }
        self.start(FUNC_LOAD_X2, N, 0);
        for &b in &fir.taps {
            self.write(b);
        }
        if !self.wait_done() {
            return false;
        }
        let history = N.saturating_sub(1);
        if history > 0 {
            self.start(FUNC_LOAD_X1, history, 0);
            for _ in 0..history {
                self.write(0);
            }
            if !self.wait_done() {
                return false;
            }
        }
        self.regs.cr().write(|w| w.clipen().bit(fir.clip));
        self.start(FUNC_FIR, N, fir.gain_shift.min(7));
        true
    }

    /// Filters one sample; `None` if the FMAC does not accept or deliver in time.
    pub fn push(&mut self, x: i16) -> Option<i16> {
        if !wait_for(POLL_LIMIT, || self.regs.sr().read().x1full().bit_is_clear()) {
            return None;
        }
        self.write(x);
        if !wait_for(POLL_LIMIT, || self.regs.sr().read().yempty().bit_is_clear()) {
            return None;
        }
        Some(self.regs.rdata().read().rdata().bits() as i16)
    }

    /// Stops the running function.
    pub fn stop(&mut self) {
        // SAFETY: clearing PARAM (START = 0) stops the function (RM0440 §18.3.5).
        self.regs.param().write(|w| unsafe { w.bits(0) });
    }

    /// Runs an impulse, a full-scale step and its reversal through the FMAC and the
    /// software model and compares every output bit for bit.
    pub fn self_test<const N: usize>(&mut self, fir: &FmacFir<N>) -> bool {
        if !self.start_fir(fir) {
            return false;
        }
        let mut model = FirState::<N>::new();
        let inputs = core::iter::once(i16::MAX)
            .chain(core::iter::repeat_n(0, N))
            .chain(core::iter::repeat_n(i16::MAX, N + 1))
            .chain(core::iter::repeat_n(i16::MIN, N + 1));
        let ok = inputs
            .into_iter()
            .all(|x| self.push(x) == Some(fir.process(&mut model, x)));
        self.stop();
        ok
    }
}
