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
//!
//! Configured once, fed one argument per call (as the best G474 drives do: moteus writes
//! CSR once; embassy-stm32's CORDIC driver sets ARG2 = +1 by one two-argument calculation
//! and then switches to one argument "for the hot loop"): the cosine function keeps its
//! CSR between calls, and with NARGS = 0 a calculation starts on one write of ARG1
//! (RM0440 §17.4.2, CORDIC_WDATA) with ARG2 as last written, so selecting the cosine
//! writes ARG2 = +1 (`i32::MAX`) once by a two-argument calculation and then sets
//! NARGS = 0. CSR is written again only when the function changes (an atan2 observer's
//! phase calculation writes ARG2 = y, so the cosine is selected afresh after it).
//!
//! The FPU's square root (VSQRT.F32) is this board's [`Trig::sqrt`]: one instruction
//! instead of `libm`'s software square root, with the same, correctly rounded result
//! (PM0214 §3.10: VSQRT is IEEE 754 compliant).

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
    /// The FUNC code CSR holds (`None` before the first selection).
    func: Option<u8>,
}

impl Cordic {
    /// Takes the peripheral (its clock must be enabled) and selects the cosine.
    pub fn new(regs: pac::CORDIC) -> Self {
        let mut c = Self { regs, func: None };
        c.select_cosine();
        c
    }

    /// Selects the function: Q1.31, `two_args` arguments, `two_results` results.
    fn configure(&mut self, func: u8, two_args: bool, two_results: bool) {
        // SAFETY: FUNC and PRECISION take the documented codes 0..=9 and 1..=15.
        self.regs.csr().write(|w| unsafe {
            w.func()
                .bits(func)
                .precision()
                .bits(PRECISION)
                .nargs()
                .bit(two_args)
                .nres()
                .bit(two_results)
        });
        self.func = Some(func);
    }

    /// The cosine with one argument and ARG2 = +1: one two-argument calculation
    /// (θ = 0, m = +1, both results read) leaves ARG2 at +1, then NARGS = 0.
    fn select_cosine(&mut self) {
        self.configure(FUNC_COSINE, true, true);
        self.regs.wdata().write(|w| w.arg().set(0));
        self.regs.wdata().write(|w| w.arg().set(i32::MAX as u32));
        let _ = self.regs.rdata().read();
        let _ = self.regs.rdata().read();
        self.configure(FUNC_COSINE, false, true);
    }

    /// Compares sin/cos and atan2 at the eight octant midpoints with the software
    /// implementation: `true` if every result is within [`hw::CORDIC_TOLERANCE_LSB`], and
    /// the FPU's square root equals the software one bit for bit on a few values across
    /// the exponent range.
    pub fn self_test(&mut self) -> bool {
        let close = |a: i32, b: i32| a.abs_diff(b) <= hw::CORDIC_TOLERANCE_LSB;
        // 2, 0.5 and, as bit patterns (no decimal literals in the firmware, literals.rs),
        // 3.0e-7, 12 345.678 and 8.1e9: small, odd-mantissa and large arguments.
        let roots = [2.0f32, 0.5]
            .into_iter()
            .chain([0x34A1_0FB0u32, 0x4640_E6B6, 0x4FF1_6618].map(f32::from_bits))
            .all(|x| self.sqrt(x).to_bits() == SoftTrig.sqrt(x).to_bits());
        roots
            && (0..8i32).all(|k| {
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
        if self.func != Some(FUNC_COSINE) {
            self.select_cosine();
        }
        self.regs.wdata().write(|w| w.arg().set(theta as u32));
        let cos = self.regs.rdata().read().res().bits() as i32;
        let sin = self.regs.rdata().read().res().bits() as i32;
        SinCosQ31 { sin, cos }
    }

    fn atan2(&mut self, y: i32, x: i32) -> i32 {
        if x == 0 && y == 0 {
            return 0;
        }
        if self.func != Some(FUNC_PHASE) {
            self.configure(FUNC_PHASE, true, false);
        }
        self.regs.wdata().write(|w| w.arg().set((x >> 1) as u32));
        self.regs.wdata().write(|w| w.arg().set((y >> 1) as u32));
        self.regs.rdata().read().res().bits() as i32
    }

    fn sqrt(&mut self, x: f32) -> f32 {
        let mut bits = x.to_bits();
        // Rust's `asm!` offers FPU registers (`sreg`) only with the double-precision
        // `vfp2` feature, which the Cortex-M4F (single-precision FPv4-SP) lacks: the
        // operand goes in a core register and S15 is saved and restored around its use.
        // SAFETY: VMOV and VSQRT.F32 touch no memory and no core flags (only the FPSCR's
        // cumulative exception bits); S15 is left as it was found.
        unsafe {
            core::arch::asm!(
                "vmov {save}, s15",
                "vmov s15, {x}",
                "vsqrt.f32 s15, s15",
                "vmov {x}, s15",
                "vmov s15, {save}",
                x = inout(reg) bits,
                save = out(reg) _,
                options(pure, nomem, nostack, preserves_flags)
            );
        }
        f32::from_bits(bits)
    }
}
