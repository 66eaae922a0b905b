//! A deliberate stack overflow on the emulated Cortex-M4F (netduinoplus2), with the
//! image's stack layout (the stack at the bottom of RAM, memory.x) and the image's
//! HardFault entry (`app/src/board/hard_fault_entry.s`, included, not copied): unbounded
//! recursion pushes below 0x2000_0000, the push is a bus error, and the HardFault
//! handler runs on a fresh stack. It prints
//! `overflow: <cause> sp <sp> cfsr <cfsr>` and exits with status 0; `tests/qemu.rs`
//! checks the line. Reaching the end of `main` or any other handler exits with 1.
#![cfg_attr(target_os = "none", no_std, no_main)]

// The HardFault entry is assembly and the handler reads the SCB and linker symbols.
#[cfg(target_os = "none")]
#[allow(unsafe_code)]
mod target {
    use core::panic::PanicInfo;

    use cortex_m_rt::entry;
    use cortex_m_semihosting::{debug, hprintln};
    use motor_config::fault_record::classify_hard_fault;

    fn exit(status: debug::ExitStatus) -> ! {
        debug::exit(status);
        loop {
            cortex_m::asm::wfi();
        }
    }

    /// Recurses without end: each level keeps 256 bytes alive across the call, so the
    /// optimiser can neither drop the frame nor turn the recursion into a loop.
    #[inline(never)]
    #[allow(unconditional_recursion)] // the point: it only ends in the HardFault
    fn deep(level: u32) -> u32 {
        let mut frame = [level; 64];
        core::hint::black_box(&mut frame);
        let below = deep(level.wrapping_add(1));
        core::hint::black_box(frame[(below % 64) as usize]).wrapping_add(below)
    }

    #[entry]
    fn main() -> ! {
        hprintln!("overflow: recursing");
        let n = deep(0);
        hprintln!("overflow: recursion returned {}", n);
        exit(debug::EXIT_FAILURE)
    }

    core::arch::global_asm!(
        include_str!("../../../app/src/board/hard_fault_entry.s"),
        handler = sym on_hard_fault
    );

    /// The handler the entry jumps to, on the fresh stack: classifies the fault as the
    /// image does and reports it.
    extern "C" fn on_hard_fault(sp: u32) -> ! {
        unsafe extern "C" {
            static _stack_start: u32;
            static _stack_end: u32;
        }
        let stack = ((&raw const _stack_end) as u32, (&raw const _stack_start) as u32);
        // SAFETY: a read of the SCB's CFSR (always mapped).
        let cfsr = unsafe { (*cortex_m::peripheral::SCB::PTR).cfsr.read() };
        let (cause, _) = classify_hard_fault(sp, stack, cfsr);
        hprintln!("overflow: {:?} sp {:#010x} cfsr {:#010x}", cause, sp, cfsr);
        exit(debug::EXIT_SUCCESS)
    }

    #[panic_handler]
    fn panic(info: &PanicInfo) -> ! {
        hprintln!("panic: {}", info);
        exit(debug::EXIT_FAILURE)
    }
}

/// Host build: nothing to emulate.
#[cfg(not(target_os = "none"))]
fn main() {}
