//! ADC1 and ADC2: injected conversions triggered by TIM1 TRGO at the carrier
//! maximum (RM0440 §21.4.21), sampling time [`crate::config::ADC_SMP`] from the
//! settling rule (thesis A (7.2), (7.4)).
//!
//! | rank | ADC1 | ADC2 |
//! |---|---|---|
//! | 1 | SIN (IN2) | COS (IN4) |
//! | 2 | i_u (IN1) | i_v (IN3) |
//! | 3 | U_dc (IN3) | i_w (IN17) |
//!
//! Both converters start on the same trigger with equal sequences, so SIN/COS and
//! i_u/i_v are sampled simultaneously. ADC1's end of injected sequence (JEOS) is the
//! control interrupt.

use stm32g4::stm32g474 as pac;

use super::clocks::{POLL_LIMIT, delay_us, wait_for};
use crate::adc_frame::RawConversions;
use crate::config::ADC_SMP;
use crate::hw;

/// Injected sequence of one converter: three channel numbers, rank order.
struct Sequence([u8; 3]);

const ADC1_SEQUENCE: Sequence = Sequence([2, 1, 3]);
const ADC2_SEQUENCE: Sequence = Sequence([4, 3, 17]);

/// Regulator start-up, calibration and enable of one converter (RM0440 §21.4.6–9).
fn power_up(adc: &pac::adc1::RegisterBlock) -> bool {
    // Leave deep power-down, then enable the regulator (CR bits must be changed
    // one at a time with read-modify-write: DEEPPWD resets to 1).
    adc.cr().modify(|_, w| w.deeppwd().clear_bit());
    adc.cr().modify(|_, w| w.advregen().set_bit());
    delay_us(hw::ADC_VREG_STARTUP_US);
    adc.cr().modify(|_, w| w.adcaldif().clear_bit().adcal().set_bit());
    if !wait_for(POLL_LIMIT, || adc.cr().read().adcal().bit_is_clear()) {
        return false;
    }
    adc.isr().write(|w| w.adrdy().clear_bit_by_one());
    adc.cr().modify(|_, w| w.aden().set_bit());
    wait_for(POLL_LIMIT, || adc.isr().read().adrdy().bit_is_set())
}

/// Sampling times and the injected sequence, triggered on TIM1 TRGO rising edges.
fn configure(adc: &pac::adc1::RegisterBlock, seq: &Sequence) {
    adc.smpr1().write(|w| {
        w.smp1()
            .set(ADC_SMP)
            .smp2()
            .set(ADC_SMP)
            .smp3()
            .set(ADC_SMP)
            .smp4()
            .set(ADC_SMP)
    });
    adc.smpr2().write(|w| w.smp17().set(ADC_SMP));
    let [a, b, c] = seq.0;
    // SAFETY: channel numbers 1..=17 are valid JSQx codes; JEXTSEL 0 = TIM1_TRGO.
    adc.jsqr().write(|w| unsafe {
        w.jl()
            .bits(2)
            .jextsel()
            .bits(0)
            .jexten()
            .bits(0b01)
            .jsq1()
            .bits(a)
            .jsq2()
            .bits(b)
            .jsq3()
            .bits(c)
    });
}

/// Brings up both converters and arms the injected conversions; `false` if a
/// converter does not calibrate or become ready.
pub fn init(common: &pac::ADC12_COMMON, adc1: &pac::ADC1, adc2: &pac::ADC2) -> bool {
    // Synchronous clock HCLK/4 (CKMODE = 0b11) = hw::ADC_CLOCK_HZ.
    common.ccr().write(|w| w.ckmode().set(0b11));
    if !(power_up(adc1) && power_up(adc2)) {
        return false;
    }
    configure(adc1, &ADC1_SEQUENCE);
    configure(adc2, &ADC2_SEQUENCE);
    adc1.isr()
        .write(|w| w.jeos().clear_bit_by_one().jeoc().clear_bit_by_one());
    adc2.isr()
        .write(|w| w.jeos().clear_bit_by_one().jeoc().clear_bit_by_one());
    adc1.ier().write(|w| w.jeosie().set_bit());
    adc1.cr().modify(|_, w| w.jadstart().set_bit());
    adc2.cr().modify(|_, w| w.jadstart().set_bit());
    true
}

/// Reads one control period's conversions and acknowledges them. ADC2 finishes with
/// ADC1 (same sequence and timing); `None` if it has not (a missed sample).
pub fn read(adc1: &pac::ADC1, adc2: &pac::ADC2) -> Option<RawConversions> {
    adc1.isr()
        .write(|w| w.jeos().clear_bit_by_one().jeoc().clear_bit_by_one());
    if !wait_for(hw::ADC_SLAVE_POLLS, || adc2.isr().read().jeos().bit_is_set()) {
        return None;
    }
    adc2.isr()
        .write(|w| w.jeos().clear_bit_by_one().jeoc().clear_bit_by_one());
    Some(RawConversions {
        sin: adc1.jdr1().read().jdata().bits(),
        phases: [
            adc1.jdr2().read().jdata().bits(),
            adc2.jdr2().read().jdata().bits(),
            adc2.jdr3().read().jdata().bits(),
        ],
        dc_link: adc1.jdr3().read().jdata().bits(),
        cos: adc2.jdr1().read().jdata().bits(),
    })
}
