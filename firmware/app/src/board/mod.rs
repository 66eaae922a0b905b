//! Board layer (target only): owns the STM32G474's peripherals and runs the
//! control core on them. Register access needs `unsafe` here (and only here); each
//! block carries a SAFETY comment.
//!
//! | module | drives |
//! |---|---|
//! | [`clocks`] | 170 MHz system clock, peripheral clocks |
//! | [`pins`] | pin assignment, gate pins forced low |
//! | [`pwm`] | TIM1: PWM, dead time, break, ADC trigger |
//! | [`resolver`] | TIM3: resolver excitation locked to the carrier |
//! | [`adc`] | ADC1/ADC2 injected conversions |
//! | [`cordic`] | CORDIC as the core's `Trig` |
//! | [`fmac`] | FMAC running the generated FIR |
//! | [`can`] | FDCAN1 setpoint reception |
//! | [`watchdog`] | IWDG |
//! | [`control`] | the control interrupt |
//! | [`fault`] | HardFault, unhandled interrupts, panics |
#![allow(unsafe_code)]

pub mod adc;
pub mod can;
pub mod clocks;
pub mod control;
pub mod cordic;
pub mod fault;
pub mod fmac;
pub mod pins;
pub mod pwm;
pub mod resolver;
pub mod watchdog;

use core::sync::atomic::Ordering;

use stm32g4::stm32g474 as pac;

use crate::{can_frame, config};
use control::{Control, HANDOFF, TICKS, publish_setpoint};
use fault::halt;

/// Brings the board up, starts the control interrupt and runs the main loop:
/// setpoint reception and the watchdog refresh (only while the control interrupt
/// advances). Any bring-up failure — a clock or converter that does not become
/// ready, a CORDIC or FMAC result that disagrees with the software model — halts
/// with the outputs off.
pub fn run() -> ! {
    let Some(dp) = pac::Peripherals::take() else { halt() };
    if !clocks::init(&dp.RCC, &dp.PWR, &dp.FLASH) {
        halt()
    }
    clocks::enable_peripherals(&dp.RCC);
    // TIM1 first: its outputs are disabled before the pins are routed to it.
    pwm::init(&dp.TIM1);
    pins::init(&dp.GPIOA, &dp.GPIOB, &dp.GPIOC);
    let mut cordic = cordic::Cordic::new(dp.CORDIC);
    let mut fmac = fmac::Fmac::new(dp.FMAC);
    if !cordic.self_test() || !fmac.self_test(&config::FILTER) {
        halt()
    }
    if !adc::init(&dp.ADC12_COMMON, &dp.ADC1, &dp.ADC2) {
        halt()
    }
    resolver::init(&dp.TIM3);
    let Some(mut can) = can::Can::new(dp.FDCAN1) else {
        halt()
    };
    pwm::start(&dp.TIM1);
    let control = Control::new(dp.TIM1, dp.ADC1, dp.ADC2, dp.GPIOC, cordic);
    cortex_m::interrupt::free(|cs| HANDOFF.borrow(cs).set(Some(control)));
    // SAFETY: the handler's data has been handed over; no critical section of this
    // thread relies on the interrupt being masked.
    unsafe { cortex_m::peripheral::NVIC::unmask(pac::Interrupt::ADC1_2) };
    watchdog::start(&dp.IWDG);

    let mut last = TICKS.load(Ordering::Relaxed);
    loop {
        if let Some(frame) = can.poll()
            && let Some(torque) = can_frame::decode_torque(frame.standard_id, frame.bytes())
        {
            publish_setpoint(can_frame::torque_to_iq(torque, config::IQ_PER_NM));
        }
        let now = TICKS.load(Ordering::Relaxed);
        if now != last {
            watchdog::refresh(&dp.IWDG);
            last = now;
        }
    }
}
