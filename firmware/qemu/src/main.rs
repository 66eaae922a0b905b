//! Runs the control-core test vectors of [`motor_qemu::vectors`] on an emulated
//! Cortex-M4F and prints one line per function over semihosting:
//! `<name> <count> <FNV-1a 64 hash as 16 hex digits>`; then exits with status 0.
//! A panic or a HardFault prints a message and exits with status 1.
//!
//! The lines must equal the host's bit for bit (`tests/qemu.rs` checks this):
//!
//! ```text
//! cd firmware
//! cargo build --release --target thumbv7em-none-eabihf -p motor-qemu
//! qemu-system-arm -machine netduinoplus2 -nographic \
//!     -semihosting-config enable=on,target=native \
//!     -kernel target/thumbv7em-none-eabihf/release/motor-qemu
//! ```
//!
//! `qemu-system-arm` comes with Debian's `qemu-system-arm` package. On the host
//! (`cargo run -p motor-qemu`) the same binary prints the host's lines.
#![cfg_attr(target_os = "none", no_std, no_main)]

/// Bare-metal entry point, exception and panic handlers (netduinoplus2, STM32F405).
#[cfg(target_os = "none")]
mod target {
    use core::panic::PanicInfo;

    use cortex_m_rt::{ExceptionFrame, entry, exception};
    use cortex_m_semihosting::{debug, hprintln};

    /// Exits QEMU with `status` and never returns (waits for interrupts should the
    /// debugger ignore the exit request).
    fn exit(status: debug::ExitStatus) -> ! {
        debug::exit(status);
        loop {
            cortex_m::asm::wfi();
        }
    }

    /// Prints every function's summary line, then exits with success.
    #[entry]
    fn main() -> ! {
        for summary in motor_qemu::vectors::run_all() {
            hprintln!("{}", summary);
        }
        exit(debug::EXIT_SUCCESS)
    }

    /// A fault fails the run with the faulting program counter.
    // cortex-m-rt requires this signature (the handler may be entered with a
    // corrupted stack); the body itself does nothing unsafe.
    #[allow(unsafe_code)]
    #[exception]
    unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
        hprintln!("HardFault at pc {:#010x}: {:?}", frame.pc(), frame);
        exit(debug::EXIT_FAILURE)
    }

    /// A panic fails the run with its message.
    #[panic_handler]
    fn panic(info: &PanicInfo) -> ! {
        hprintln!("panic: {}", info);
        exit(debug::EXIT_FAILURE)
    }
}

/// Host build: prints the host's lines (what the emulated run must reproduce).
#[cfg(not(target_os = "none"))]
fn main() {
    for summary in motor_qemu::vectors::run_all() {
        println!("{summary}");
    }
}
