//! TIM1: centre-aligned complementary PWM at f_s with dead time, the over-current break
//! input, and the ADC trigger at the board's sampling instant (RM0440 advanced-control
//! timer chapter; the board's values from `motor::board`, register values from
//! `motor_config::registers`).
//!
//! * Centre-aligned mode 1, ARR = f_tim/(2·f_s) ([`crate::config::PWM_PERIOD`]), PWM
//!   mode 1 on CH1–CH3 with preload: a high side conducts while CNT < CCR, so duty =
//!   CCR/ARR, the high sides conduct around the carrier minimum and the low sides
//!   around the maximum.
//! * Repetition counter: one update event per carrier period, at the board's sampling
//!   instant — the *underflow* (carrier minimum) for sampling there, RCR = 1 loaded before
//!   the counter starts; the *overflow* (carrier maximum) for low-side shunts, RCR = 0 at
//!   the UG and RCR = 1 written right after the start (RM0440 §28.3.5;
//!   [`crate::config::REPETITION`]). The preloaded compare values from a control step
//!   take effect there, one period after the trigger they came from (with the
//!   currents' hold instants after the trigger and the half period, the loop delay the
//!   current loop is designed for: codegen `sections::board::control_timing`).
//! * The ADC trigger is not the update event: channel 4 (no pin) makes OC4REF rise at
//!   the board's `sensing.sample_instant` ([`crate::config::TRIGGER`]: one tick before
//!   the carrier maximum for low-side shunts, at the minimum otherwise), routed as TRGO2
//!   (MMS2 = OC4REF) to the injected conversions and as TRGO (MMS = OC4REF) to TIM3,
//!   which resets the resolver excitation at the same instant.
//! * Output polarities and idle levels come from the board's gate driver
//!   ([`crate::config::CCER`], [`crate::config::CR2`]: CCxP/CCxNP and OISx/OISxN, RM0440
//!   TIMx_CCER, TIMx_CR2), written before BDTR's LOCK freezes the idle levels: an
//!   active-low input (the L6398's LIN) is driven inverted and idles high.
//! * TIM1_BDTR is written once ([`crate::config::BDTR`]): dead time, OSSR = OSSI = 1 (with
//!   MOE = 0 all six outputs are driven to their idle, off, levels), break
//!   enable with the board's polarity and filter, LOCK level 1. LOCK and the fields it
//!   protects are write-once after reset (RM0440 §28.3.18): the old second write for
//!   LOCK never took effect.
//! * BKIN clears MOE in hardware; AOE = 0 keeps it cleared. BIF is armed only after the
//!   pin is routed ([`arm_break`]) and read again before MOE is set each period
//!   (`motor_config::bringup::finish_period`).

use stm32g4::stm32g474 as pac;

use crate::bringup::{self, BreakActive, BreakControl};
use crate::config::{BDTR, CCER, CR2, PWM_PERIOD, REPETITION, TRIGGER};
use crate::registers::PWM_MODE_1;

/// Configures TIM1 with the outputs disabled (MOE = 0) and 50 % duty.
pub fn init(tim1: &pac::TIM1) {
    tim1.cr1().write(|w| w.cms().set(0b01).arpe().set_bit());
    tim1.psc().write(|w| w.psc().set(0));
    tim1.arr().write(|w| w.arr().set(u32::from(PWM_PERIOD)));
    // REP_CNT is loaded from it by the UG at the end.
    tim1.rcr().write(|w| w.rep().set(u16::from(REPETITION.0)));
    let half = u32::from(PWM_PERIOD / 2);
    tim1.ccr1().write(|w| w.ccr().set(half));
    tim1.ccr2().write(|w| w.ccr().set(half));
    tim1.ccr3().write(|w| w.ccr().set(half));
    let (oc4m, ccr4) = TRIGGER;
    tim1.ccr4().write(|w| w.ccr().set(u32::from(ccr4)));
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
    tim1.ccmr2_output().write(|w| {
        w.oc3m()
            .set(PWM_MODE_1)
            .oc3pe()
            .set_bit()
            .oc4m()
            .set(oc4m)
            .oc4pe()
            .set_bit()
    });
    // SAFETY: the host-tested value (motor_config::registers::cr2): MMS and MMS2 take
    // OC4REF's code (RM0440 TIMx_CR2; ST's LL_TIM_TRGO_OC4REF, LL_TIM_TRGO2_OC4) and
    // OIS1..OIS3N the gate driver's off levels — before the BDTR write below, whose LOCK
    // level 1 freezes them (RM0440 TIMx_BDTR LOCK[1:0] = 01), as ST's HAL writes the idle
    // states in HAL_TIM_PWM_ConfigChannel before HAL_TIMEx_ConfigBreakDeadTime.
    tim1.cr2().write(|w| unsafe { w.bits(CR2) });
    // SAFETY: the host-tested value (motor_config::registers::ccer): CC1E..CC3NE and the
    // gate driver's polarities CCxP/CCxNP (an active-low input such as the L6398's LIN
    // needs its output inverted, RM0440 TIMx_CCER).
    tim1.ccer().write(|w| unsafe { w.bits(CCER) });
    // BKIN from the pin (reset value, made explicit), not inverted: the polarity is
    // BDTR.BKP (TIMx_AF1.BKINP must be programmed together with it).
    tim1.af1().modify(|_, w| w.bkine().set_bit().bkinp().clear_bit());
    // SAFETY: one write of the host-tested value (motor_config::registers::bdtr).
    tim1.bdtr().write(|w| unsafe { w.bits(BDTR) });
    // Load ARR, CCRx and the repetition counter before the start.
    tim1.egr().write(|w| w.ug().set_bit());
}

/// TIM1's break flag and main output, for the host-tested sequences.
pub struct Break<'a>(pub &'a pac::TIM1);

impl BreakControl for Break<'_> {
    fn break_flag(&mut self) -> bool {
        self.0.sr().read().bif().bit_is_set()
    }
    fn clear_break_flag(&mut self) {
        self.0.sr().write(|w| w.bif().clear());
    }
    fn set_main_output(&mut self, on: bool) {
        if self.0.bdtr().read().moe().bit_is_set() != on {
            self.0.bdtr().modify(|_, w| w.moe().bit(on));
        }
    }
}

/// After the break pin is routed: clears the break flag latched while BKE was set on an
/// unrouted pin and checks it stays clear (`Err` if the comparator reports a fault).
pub fn arm_break(tim1: &pac::TIM1) -> Result<(), BreakActive> {
    bringup::arm_break(&mut Break(tim1))
}

/// Starts the carrier (and with it the ADC triggers).
pub fn start(tim1: &pac::TIM1) {
    tim1.cr1().modify(|_, w| w.cen().set_bit());
    // With the update at the overflow: RCR written after the launch, long before the
    // first overflow half a carrier period later (RM0440 §28.3.5).
    if let Some(rep) = REPETITION.1 {
        tim1.rcr().write(|w| w.rep().set(u16::from(rep)));
    }
}

/// Compare values for the next period (preloaded, applied at the next update), written
/// atomically with respect to the update event: TIMx_CR1.UDIS is held for the three
/// writes (RM0440 §28.6.1, UDIS: "the update event is not generated, shadow registers
/// keep their value"), so an update can never load one new and two old values — it loads
/// all three of this period, or, held off, the previous three for one more period. The
/// writes follow the conversions well before the update one period after the trigger
/// (`codegen` `sections::board::control_timing`); the emulator counts updates held off
/// and its test requires none.
pub fn set_compare(tim1: &pac::TIM1, compare: [u16; 3]) {
    let [u, v, w] = compare;
    tim1.cr1().modify(|_, r| r.udis().set_bit());
    tim1.ccr1().write(|r| r.ccr().set(u32::from(u)));
    tim1.ccr2().write(|r| r.ccr().set(u32::from(v)));
    tim1.ccr3().write(|r| r.ccr().set(u32::from(w)));
    tim1.cr1().modify(|_, r| r.udis().clear_bit());
}

/// Disables the gates at once (MOE = 0, outputs to their off level).
pub fn outputs_off(tim1: &pac::TIM1) {
    Break(tim1).set_main_output(false);
}
