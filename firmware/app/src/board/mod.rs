//! Board layer (target only): owns the STM32G474's peripherals and runs the
//! control core on them. Register access needs `unsafe` here (and only here); each
//! block carries a SAFETY comment.
//!
//! | module | drives |
//! |---|---|
//! | [`clocks`] | 170 MHz system clock, peripheral clocks |
//! | [`pins`] | the board's pins (from the board file), gate pins forced to their off levels |
//! | [`pwm`] | TIM1: PWM, dead time, break, ADC trigger at the board's sampling instant |
//! | [`resolver`] | TIM3: resolver excitation locked to the carrier |
//! | [`adc`] | ADC1/ADC2 injected conversions |
//! | [`cordic`] | CORDIC as the core's `Trig` |
//! | [`fmac`] | FMAC start-up self-test of the generated FIR against the bit-exact model |
//! | [`can`] | FDCAN1: setpoint reception; status, capture and fault-report transmission |
//! | [`commissioning`] | the commissioning mode between main loop and interrupt |
//! | [`watchdog`] | IWDG |
//! | [`control`] | the control interrupt |
//! | [`fault`] | HardFault (also on stack overflow), unhandled interrupts, panics; the fault record |
#![allow(unsafe_code)]

pub mod adc;
pub mod can;
pub mod clocks;
pub mod commissioning;
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

use crate::motor::board;
use crate::{can_frame, config, registers};
use control::{Control, HANDOFF, TICKS, count_bus_off, publish_setpoint};
use fault::halt;

/// Brings the board up, starts the control interrupt and runs the main loop:
/// setpoint reception and the watchdog refresh (only while the control interrupt
/// advances). Any bring-up failure — option bytes that let PB8 select the bootloader, a
/// clock or converter that does not become ready, a break input that is active, a
/// CORDIC or FMAC result that disagrees with the software model — halts with the
/// outputs off.
///
/// Order (each step's reason in its module):
/// 0. the fault record of the previous run, read and validated before anything can
///    fault again ([`fault::take_at_boot`]); sent on CAN once FDCAN1 is up;
/// 1. clocks; the boot source (defect 2): with `boot0.handling = "option_bytes"` the
///    image runs only if FLASH_OPTR.nSWBOOT0 = 0 and nBOOT0 = 1, so PB8's level at the
///    next reset cannot start the system bootloader (DS12288 §3.7);
/// 2. fault routing (defect 6): SYSCFG_CFGR2 locks the Cortex-M4 LOCKUP output, SRAM
///    parity and flash ECC errors onto TIM1's break (RM0440 §10.2.8 — a locked-up core
///    can no longer clear MOE itself), and DBGMCU_APB2FZ.DBG_TIM1_STOP stops TIM1 with its
///    outputs in the safe state while a debugger halts the core;
/// 3. TIM1 with MOE = 0 and its one BDTR write (defects 4, 8), then the pins (the gate
///    pins are routed to a timer that already drives them to their off level), then the
///    break armed on the routed pin (defect 3);
/// 4. CORDIC and FMAC self-tests, ADCs (defect 1), TIM3, FDCAN, start.
pub fn run() -> ! {
    let Some(dp) = pac::Peripherals::take() else { halt() };
    let previous_fault = fault::take_at_boot(&dp.RCC);
    if !clocks::init(&dp.RCC, &dp.PWR, &dp.FLASH) {
        halt()
    }
    if board::BOOT0_OPTION_BYTES == 1 && !registers::boots_from_flash_regardless_of_pb8(dp.FLASH.optr().read().bits()) {
        halt()
    }
    if !clocks::enable_peripherals(&dp.RCC) {
        halt()
    }
    fault::route_faults_to_break(&dp.SYSCFG, &dp.DBGMCU);
    pwm::init(&dp.TIM1);
    pins::init(&dp.GPIOA, &dp.GPIOB, &dp.GPIOC);
    if pwm::arm_break(&dp.TIM1).is_err() {
        halt()
    }
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
    if let Some(record) = previous_fault {
        fault::report(&mut can, record);
    }
    pwm::start(&dp.TIM1);
    let control = Control::new(dp.TIM1, dp.ADC1, dp.ADC2, cordic);
    cortex_m::interrupt::free(|cs| HANDOFF.borrow(cs).set(Some(control)));
    // SAFETY: the handler's data has been handed over; no critical section of this
    // thread relies on the interrupt being masked.
    unsafe { cortex_m::peripheral::NVIC::unmask(pac::Interrupt::ADC1_2) };
    watchdog::start(&dp.IWDG);

    let mut last = TICKS.load(Ordering::Relaxed);
    let mut last_status = last;
    loop {
        // A bus-off (FDCAN_PSR.BO) silences the setpoint: zero torque at once rather
        // than after the setpoint timeout — the vehicle unit can no longer reach the
        // drive — then the recovery is started and counted (fault record, state word
        // `bus_off`). A setpoint after the recovery drives again.
        if can.recover_bus_off() {
            publish_setpoint(0.0);
            count_bus_off();
        }
        if let Some(frame) = can.poll() {
            match can_frame::decode_torque(frame.standard_id, frame.bytes()) {
                Some(torque) => {
                    commissioning::torque_received(torque);
                    publish_setpoint(torque);
                }
                None => commissioning::frame_received(frame.standard_id, frame.bytes()),
            }
        }
        let now = TICKS.load(Ordering::Relaxed);
        commissioning::transmit(&mut can, now, &mut last_status);
        if now != last {
            watchdog::refresh(&dp.IWDG);
            last = now;
        }
        // Sleep until the next interrupt — the control interrupt, every carrier period
        // (PM0214 §2.5.2, §3.11.12: WFI): the loop's work (one received frame, the
        // transmissions, the watchdog) is once per period at most. A setpoint frame at
        // 500 kbit/s takes ≥ 94 µs on the bus, longer than a period at f_s ≥ 10.6 kHz,
        // and the RX FIFO holds three (RM0440 §44.3.3).
        cortex_m::asm::wfi();
    }
}
