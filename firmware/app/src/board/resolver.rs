//! Resolver excitation locked to the PWM, thesis A §4.3: a square wave at f_s/2 on the
//! board's TIM3_CH1 pin, turned into the sinusoidal excitation (4.2) by the board's
//! excitation filter/amplifier (thesis A §4.4: "excitation filters").
//!
//! TIM3 runs from the same 170 MHz clock with one period equal to the carrier's
//! (ARR3 = 2·ARR1 − 1) and is reset by TIM1's TRGO (slave reset mode, ITR0 = TIM1),
//! which is OC4REF — the same instant as the ADC trigger (TRGO2), see `pwm`. OC1
//! toggles at CNT3 = ARR1 + `board::EXCITATION_SHIFT_TICKS` (`config::EXCITATION_CCR1`),
//! half a carrier period plus the shift after the reset, so the middle of each half
//! period of the square wave — the extremum of its fundamental — falls the shift after
//! the trigger: at the instant the ADCs hold SIN and COS (their mean, codegen
//! `sections::board::excitation_shift_ticks`). One sample per half period of the
//! excitation, at its maximum or minimum (synchronous demodulation, thesis A §4.3), with
//! the same envelope for both windings. The excitation's sign at that instant is read
//! back from the pin.
//!
//! Assumption (documented in firmware/README.md): the excitation filter and the
//! SIN/COS front ends have equal group delay, so the extremum is not shifted; a
//! residual shift only lowers the apparent amplitude (thesis A §4.4.1).

use stm32g4::stm32g474 as pac;

use crate::config::{EXCITATION_CCR1, PWM_PERIOD};

/// Toggle on match (OCxM = 0011).
const TOGGLE: u8 = 0b011;

/// TIM3 period: one carrier period, 2·ARR1 ticks.
const PERIOD: u32 = PWM_PERIOD as u32 * 2 - 1;

/// Configures and starts TIM3 (it runs free until TIM1 starts resetting it).
pub fn init(tim3: &pac::TIM3) {
    tim3.arr().write(|w| w.arr().set(PERIOD));
    tim3.ccr1().write(|w| w.ccr().set(EXCITATION_CCR1));
    tim3.ccmr1_output().write(|w| w.oc1m().set(TOGGLE));
    tim3.ccer().write(|w| w.cc1e().set_bit());
    // SAFETY: TS = 0 (ITR0 = TIM1 TRGO), SMS = 0b100 (reset mode), RM0440 §29.4.
    tim3.smcr().write(|w| unsafe { w.ts().bits(0).sms().bits(0b100) });
    tim3.egr().write(|w| w.ug().set_bit());
    tim3.cr1().write(|w| w.cen().set_bit());
}
