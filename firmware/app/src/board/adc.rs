//! ADC1 and ADC2: the board's injected sequences ([`crate::config::JSQR`], from
//! `motor::board::ADCx_CHANNELS`: currents in the first ranks), each channel's sampling
//! time ([`crate::config::SMPR`]: DS12288 Table 67 for its class and source
//! resistance), triggered together by TIM1_TRGO2 at the board's sampling instant (see
//! `pwm`). ADC1's end of injected sequence (JEOS) is the control interrupt.

use stm32g4::stm32g474 as pac;

use super::clocks::{POLL_LIMIT, delay_us, wait_for};
use crate::adc_frame::{self, RawConversions};
use crate::bringup::{self, AdcEnable};
use crate::config::{JSQR, SMPR};
use crate::hw;
use crate::motor::board;
use crate::registers::{
    ADC_CR_ADCAL, ADC_CR_ADCALDIF, ADC_CR_ADEN, ADC_CR_ADVREGEN, ADC_CR_DEEPPWD, ADC_CR_JADSTART, Field, adc_cr_command,
};

/// Writes ADC_CR with the set-only command `bit` alone ([`adc_cr_command`]: ADEN, ADCAL,
/// JADSTART … are set-only, RM0440 §21.7.3; a `modify` would write the ADEN that reads 1
/// again next to the command), the read/write bits as they read with `clear` cleared.
fn cr_command(adc: &pac::adc1::RegisterBlock, clear: u32, bit: u32) {
    // SAFETY: host-tested value (motor_config::registers::adc_cr_command): the read/write
    // bits as read (less `clear`), one set-only bit.
    adc.cr()
        .modify(|r, w| unsafe { w.bits(adc_cr_command(r.bits() & !clear, bit)) });
}

/// One converter's ADEN/ADRDY, for the host-tested enable sequence.
struct Enable<'a>(&'a pac::adc1::RegisterBlock);

impl AdcEnable for Enable<'_> {
    fn aden(&mut self) -> bool {
        self.0.cr().read().aden().bit_is_set()
    }
    fn set_aden(&mut self) {
        cr_command(self.0, 0, ADC_CR_ADEN);
    }
    fn adrdy(&mut self) -> bool {
        self.0.isr().read().adrdy().bit_is_set()
    }
}

/// Regulator start-up, calibration and enable of one converter (RM0440 §21.4.6–9):
/// DEEPPWD off, ADVREGEN, t_ADCVREG_STUP, ADCAL until it reads 0, then ADEN re-written
/// until ADRDY (defect 1: an ADEN written less than 4 ADC cycles after ADCAL clears is
/// reset by the calibration logic; ST's `ADC_Enable` retries the same way).
fn power_up(adc: &pac::adc1::RegisterBlock) -> bool {
    // CR bits must be changed one at a time: DEEPPWD resets to 1. No set-only bit is
    // written with them (`cr_command` with none).
    cr_command(adc, ADC_CR_DEEPPWD, 0);
    // SAFETY: host-tested value (adc_cr_command): the read/write bits as read plus
    // ADVREGEN, no set-only bit.
    adc.cr()
        .modify(|r, w| unsafe { w.bits(adc_cr_command(r.bits() | ADC_CR_ADVREGEN, 0)) });
    delay_us(hw::ADC_VREG_STARTUP_US);
    cr_command(adc, ADC_CR_ADCALDIF, ADC_CR_ADCAL);
    if !wait_for(POLL_LIMIT, || adc.cr().read().adcal().bit_is_clear()) {
        return false;
    }
    adc.isr().write(|w| w.adrdy().clear_bit_by_one());
    bringup::enable_adc(&mut Enable(adc), POLL_LIMIT)
}

/// Sampling times and the injected sequence of converter `k` (0 = ADC1, 1 = ADC2).
fn configure(adc: &pac::adc1::RegisterBlock, k: usize) {
    let [s1, s2]: [Field; 2] = SMPR[k];
    // SAFETY: only the sampling fields of the board's channels change (host-tested
    // motor_config::registers::smpr): SMPR1 channels 0–9, SMPR2 10–18.
    adc.smpr1().modify(|r, w| unsafe { w.bits(s1.apply(r.bits())) });
    // SAFETY: as above.
    adc.smpr2().modify(|r, w| unsafe { w.bits(s2.apply(r.bits())) });
    // SAFETY: host-tested JSQR value (motor_config::registers::jsqr): JL, JEXTSEL =
    // TIM1_TRGO2, JEXTEN = rising edge, the channels of each rank.
    adc.jsqr().write(|w| unsafe { w.bits(JSQR[k]) });
}

/// Brings up both converters and arms the injected conversions; `false` if a
/// converter does not calibrate or become ready.
pub fn init(common: &pac::ADC12_COMMON, adc1: &pac::ADC1, adc2: &pac::ADC2) -> bool {
    // Synchronous clock HCLK/4 (CKMODE = 0b11) = hw::ADC_CLOCK_HZ.
    common.ccr().write(|w| w.ckmode().set(0b11));
    if !(power_up(adc1) && power_up(adc2)) {
        return false;
    }
    configure(adc1, 0);
    configure(adc2, 1);
    adc1.isr()
        .write(|w| w.jeos().clear_bit_by_one().jeoc().clear_bit_by_one());
    adc2.isr()
        .write(|w| w.jeos().clear_bit_by_one().jeoc().clear_bit_by_one());
    adc1.ier().write(|w| w.jeosie().set_bit());
    // JADSTART alone: ADEN is not written again (ST's LL_ADC_INJ_StartConversion).
    cr_command(adc1, 0, ADC_CR_JADSTART);
    cr_command(adc2, 0, ADC_CR_JADSTART);
    true
}

/// The four injected data registers.
fn jdr(adc: &pac::adc1::RegisterBlock) -> [u16; 4] {
    [
        adc.jdr1().read().jdata().bits(),
        adc.jdr2().read().jdata().bits(),
        adc.jdr3().read().jdata().bits(),
        adc.jdr4().read().jdata().bits(),
    ]
}

/// Reads one control period's conversions and acknowledges them. ADC2's sequence is
/// never longer than ADC1's (codegen's plan), so it has finished or is about to; `None`
/// if it has not within [`hw::ADC_SLAVE_POLLS`] polls (a missed sample).
pub fn read(adc1: &pac::ADC1, adc2: &pac::ADC2) -> Option<RawConversions> {
    adc1.isr()
        .write(|w| w.jeos().clear_bit_by_one().jeoc().clear_bit_by_one());
    if !wait_for(hw::ADC_SLAVE_POLLS, || adc2.isr().read().jeos().bit_is_set()) {
        return None;
    }
    adc2.isr()
        .write(|w| w.jeos().clear_bit_by_one().jeoc().clear_bit_by_one());
    Some(adc_frame::assemble(
        &jdr(adc1),
        &board::ADC1_SIGNALS,
        &jdr(adc2),
        &board::ADC2_SIGNALS,
    ))
}
