//! CORDIC co-processor as the control core's [`Trig`] (thesis A §7.2, RM0440 §17).
//!
//! Q1.31 arguments and results (ARGSIZE = RESSIZE = 0), the angle scaled by π as in
//! (4.20), so the core's angles go in unchanged:
//! * sine/cosine: FUNC = cosine, ARG1 = θ/π, ARG2 = modulus 1 (`i32::MAX`), two
//!   results RES1 = cos θ, RES2 = sin θ — one calculation for both;
//! * atan2: FUNC = phase, ARG1 = x, ARG2 = y, RES1 = atan2(y, x)/π. The arguments
//!   are halved first so the modulus √(x² + y²) stays below 1 (only the ratio
//!   matters for the phase).
//!
//! PRECISION = 6: 24 iterations in 6 clock cycles, residual error of order 2^-19
//! for both functions per RM0440's precision table; start-up compares the CORDIC
//! with [`motor_control::trig::SoftTrig`] ([`Cordic::self_test`]). Reading RDATA
//! before the result is ready stalls the bus until it is, so no polling is needed.

use motor_control::trig::{SinCosQ31, SoftTrig, Trig};
use stm32g4::stm32g474 as pac;

use crate::hw;

/// FUNC codes (RM0440 §17.4.1).
const FUNC_COSINE: u8 = 0;
const FUNC_PHASE: u8 = 2;
/// Iterations/4.
const PRECISION: u8 = 6;

/// The CORDIC, owned.
pub struct Cordic {
    regs: pac::CORDIC,
}

impl Cordic {
    /// Takes the peripheral (its clock must be enabled).
    pub fn new(regs: pac::CORDIC) -> Self {
        Self { regs }
    }

    /// Selects the function: Q1.31, two arguments, `results` results.
    fn configure(&mut self, func: u8, two_results: bool) {
        // SAFETY: FUNC and PRECISION take the documented codes 0..=9 and 1..=15.
        self.regs.csr().write(|w| unsafe {
            w.func()
                .bits(func)
                .precision()
                .bits(PRECISION)
                .nargs()
                .set_bit()
                .nres()
                .bit(two_results)
        });
    }

    /// Compares sin/cos and atan2 at the eight octant midpoints with the software
    /// implementation: `true` if every result is within [`hw::CORDIC_TOLERANCE_LSB`].
    pub fn self_test(&mut self) -> bool {
        let close = |a: i32, b: i32| a.abs_diff(b) <= hw::CORDIC_TOLERANCE_LSB;
        (0..8i32).all(|k| {
            let theta = (k << 29).wrapping_add(1 << 28);
            let hw_sc = self.sin_cos(theta);
            let sw_sc = SoftTrig.sin_cos(theta);
            let phase = self.atan2(hw_sc.sin, hw_sc.cos);
            close(hw_sc.sin, sw_sc.sin) && close(hw_sc.cos, sw_sc.cos) && close(phase, theta)
        })
    }
}

impl Trig for Cordic {
    fn sin_cos(&mut self, theta: i32) -> SinCosQ31 {
        self.configure(FUNC_COSINE, true);
        self.regs.wdata().write(|w| w.arg().set(theta as u32));
        self.regs.wdata().write(|w| w.arg().set(i32::MAX as u32));
        let cos = self.regs.rdata().read().res().bits() as i32;
        let sin = self.regs.rdata().read().res().bits() as i32;
        SinCosQ31 { sin, cos }
    }

    fn atan2(&mut self, y: i32, x: i32) -> i32 {
        if x == 0 && y == 0 {
            return 0;
        }
        self.configure(FUNC_PHASE, false);
        self.regs.wdata().write(|w| w.arg().set((x >> 1) as u32));
        self.regs.wdata().write(|w| w.arg().set((y >> 1) as u32));
        self.regs.rdata().read().res().bits() as i32
    }
}
