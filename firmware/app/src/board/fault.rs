//! Fault handling: every fault path switches all six gate outputs off — MOE cleared
//! (the timer drives its idle levels) and the six pins forced low as GPIO outputs,
//! so no code that still runs can re-enable them — then waits for the independent
//! watchdog to reset the MCU (started here with its default timeout if it was
//! not running yet).

use cortex_m_rt::{ExceptionFrame, exception};
use stm32g4::stm32g474 as pac;

use super::{pins, watchdog};

/// Routes faults the software can no longer handle to TIM1's break input and stops TIM1
/// under a debugger halt (defect 6): SYSCFG_CFGR2.CLL (Cortex-M4 LOCKUP), SPL (SRAM
/// parity), ECCL (flash double ECC error) — write-once lock bits that connect the
/// error outputs to the break inputs of TIM1/8/20/15/16/17 (RM0440 §11.3.10); without
/// them a core in lockup (a fault inside the HardFault handler) leaves the bridge
/// switching with the last compare values. DBGMCU_APB2FZ.DBG_TIM1_STOP: TIM1's counter
/// stops and its outputs go to their safe state while the core is halted (RM0440
/// debug chapter, DBGMCU_APB2FZ).
pub fn route_faults_to_break(syscfg: &pac::SYSCFG, dbgmcu: &pac::DBGMCU) {
    syscfg
        .cfgr2()
        .modify(|_, w| w.cll().set_bit().spl().set_bit().eccl().set_bit());
    dbgmcu.apb2_fz().modify(|_, w| w.dbg_tim1_stop().set_bit());
}

/// Switches the outputs off and waits for the watchdog reset.
pub fn halt() -> ! {
    cortex_m::interrupt::disable();
    // SAFETY: interrupts are disabled and this never returns, so the owners of
    // TIM1, GPIOA/B and the IWDG never run again; the writes below only move the
    // outputs towards the off state, which is safe whatever those owners did last.
    let dp = unsafe { pac::Peripherals::steal() };
    dp.TIM1.bdtr().modify(|_, w| w.moe().clear_bit());
    pins::gates_low(&dp.GPIOA, &dp.GPIOB, &dp.GPIOC);
    watchdog::start_default(&dp.IWDG);
    loop {
        cortex_m::asm::nop();
    }
}

/// HardFault: outputs off, wait for the watchdog.
// cortex-m-rt requires this handler to be `unsafe fn` (the stack may be corrupt);
// nothing in the body relies on the frame.
#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    halt()
}

/// Any interrupt without a handler (none is enabled): outputs off, wait.
#[exception]
unsafe fn DefaultHandler(_irqn: i16) {
    halt()
}

/// A panic in a development build: outputs off, wait for the watchdog.
#[cfg(debug_assertions)]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    halt()
}

/// Release builds prove that no panic is reachable anywhere in the image — the
/// control interrupt included: the panic handler calls a function that does not
/// exist, so the image links only if the optimiser removed every path to a panic.
#[cfg(not(debug_assertions))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    unsafe extern "C" {
        /// Intentionally undefined (see above).
        fn motor_firmware_panic_is_reachable() -> !;
    }
    // SAFETY: never executed — an image containing this call does not link.
    unsafe { motor_firmware_panic_is_reachable() }
}
