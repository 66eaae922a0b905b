//! TIM1: centre-aligned complementary PWM at f_s with dead time, the over-current
//! break input, and TRGO at the carrier maximum for the injected ADC conversions
//! (RM0440 §28).
//!
//! * Centre-aligned mode 1, ARR = f_tim/(2·f_s) ([`crate::config::PWM_PERIOD`]),
//!   PWM mode 1 on CH1–CH3 with preload: the high side conducts while CNT < CCR, so
//!   duty = CCR/ARR and the low sides conduct around the carrier maximum.
//! * Repetition counter RCR = 1, written before the counter starts: one update
//!   event per carrier period, at the overflow (carrier maximum, RM0440 §28.3.3).
//!   TRGO = update (MMS = 010) starts the injected conversions there, and the new
//!   compare values computed from them load at the next maximum (the 1.5-sample
//!   delay the angle lead (4.23) compensates).
//! * Dead time [`crate::config::DEAD_TIME_DTG`]; OSSR = OSSI = 1 and idle levels 0:
//!   with MOE = 0 all six outputs are driven to their inactive (off) level.
//! * BKIN (PB12, active low, filtered) clears MOE in hardware; AOE = 0 keeps it
//!   cleared until software sets it again, which the control interrupt never does
//!   after a break. LOCK level 1 freezes the dead time and break configuration.

use stm32g4::stm32g474 as pac;

use crate::config::{DEAD_TIME_DTG, PWM_PERIOD};
use crate::hw;

/// PWM mode 1 (OCxM = 0110).
const PWM_MODE_1: u8 = 0b110;

/// Configures TIM1 with the outputs disabled (MOE = 0) and 50 % duty.
pub fn init(tim1: &pac::TIM1) {
    tim1.cr1().write(|w| w.cms().set(0b01).arpe().set_bit());
    tim1.psc().write(|w| w.psc().set(0));
    tim1.arr().write(|w| w.arr().set(u32::from(PWM_PERIOD)));
    tim1.rcr().write(|w| w.rep().set(1));
    let half = u32::from(PWM_PERIOD / 2);
    tim1.ccr1().write(|w| w.ccr().set(half));
    tim1.ccr2().write(|w| w.ccr().set(half));
    tim1.ccr3().write(|w| w.ccr().set(half));
    tim1.ccmr1_output().write(|w| {
        w.oc1m()
            .set(PWM_MODE_1)
            .oc1pe()
            .set_bit()
            .oc2m()
            .set(PWM_MODE_1)
            .oc2pe()
            .set_bit()
    });
    tim1.ccmr2_output()
        .write(|w| w.oc3m().set(PWM_MODE_1).oc3pe().set_bit());
    // SAFETY: MMS = 0b010 selects the update event as TRGO (RM0440 §28.6.2).
    tim1.cr2().write(|w| unsafe { w.mms().bits(0b010) });
    tim1.ccer().write(|w| {
        w.cc1e()
            .set_bit()
            .cc1ne()
            .set_bit()
            .cc2e()
            .set_bit()
            .cc2ne()
            .set_bit()
            .cc3e()
            .set_bit()
            .cc3ne()
            .set_bit()
    });
    // BKIN from the pin (reset value, made explicit), active low.
    tim1.af1().modify(|_, w| w.bkine().set_bit().bkinp().clear_bit());
    // SAFETY: BKF is a 4-bit filter code; DTG any 8-bit code.
    tim1.bdtr().write(|w| unsafe {
        w.dtg()
            .bits(DEAD_TIME_DTG)
            .ossr()
            .set_bit()
            .ossi()
            .set_bit()
            .bke()
            .set_bit()
            .bkp()
            .clear_bit()
            .bkf()
            .bits(hw::BREAK_FILTER)
            .aoe()
            .clear_bit()
            .moe()
            .clear_bit()
    });
    tim1.bdtr().modify(|_, w| w.lock().set(0b01));
    // Load ARR, CCRx and the repetition counter before the start.
    tim1.egr().write(|w| w.ug().set_bit());
    tim1.sr().write(|w| unsafe { w.bits(0) });
}

/// Starts the carrier (and with it the ADC triggers).
pub fn start(tim1: &pac::TIM1) {
    tim1.cr1().modify(|_, w| w.cen().set_bit());
}

/// Compare values for the next period (preloaded, applied at the next update).
pub fn set_compare(tim1: &pac::TIM1, compare: [u16; 3]) {
    let [u, v, w] = compare;
    tim1.ccr1().write(|r| r.ccr().set(u32::from(u)));
    tim1.ccr2().write(|r| r.ccr().set(u32::from(v)));
    tim1.ccr3().write(|r| r.ccr().set(u32::from(w)));
}

/// The break input has fired (latched in SR.BIF until cleared; never cleared here).
pub fn break_tripped(tim1: &pac::TIM1) -> bool {
    tim1.sr().read().bif().bit_is_set()
}

/// Enables (MOE = 1) or disables (MOE = 0, outputs to their off level) the gates.
pub fn set_outputs(tim1: &pac::TIM1, on: bool) {
    if tim1.bdtr().read().moe().bit_is_set() != on {
        tim1.bdtr().modify(|_, w| w.moe().bit(on));
    }
}
