//! Fault handling: every fault path records why (the fault record, kept across the
//! reset in `.uninit`: [`crate::fault_record`]), switches all six gate outputs off — MOE
//! cleared (the timer drives its idle levels) and the six pins forced to their off
//! levels as GPIO outputs (high for an active-low driver input such as the L6398's LIN,
//! `motor::board::GATE_OFF_LEVELS`), so no code that still runs can re-enable them — then waits for the
//! independent watchdog to reset the MCU (started here with its default timeout if it
//! was not running yet). A stack overflow reaches the HardFault handler (the stack lies
//! at the bottom of RAM, memory.x), whose entry switches to a fresh stack first.

use core::mem::MaybeUninit;

use cortex_m_rt::exception;
use stm32g4::stm32g474 as pac;

use super::can::Can;
use super::{clocks, pins, watchdog};
use crate::fault_frame::encode;
use crate::fault_record::{
    ControlState, FaultCause, FaultRecord, RECORD_WORDS, STATE_WORDS, at_boot, classify_hard_fault,
};
use crate::hw;
use motor_control::can_protocol::{FaultMeasurement, Frame};

/// Routes faults the software can no longer handle to TIM1's break input and stops TIM1
/// under a debugger halt (defect 6): SYSCFG_CFGR2.CLL (Cortex-M4 LOCKUP), SPL (SRAM
/// parity), ECCL (flash double ECC error) — write-once lock bits that connect the
/// error outputs to the break inputs of TIM1/8/20/15/16/17 (RM0440 §10.2.8); without
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

/// Bring-up failed: records [`FaultCause::BringUp`], switches the outputs off and waits
/// for the watchdog reset.
pub fn halt() -> ! {
    stop(FaultCause::BringUp)
}

/// Records `cause` (with the control state of the last period) and stops.
pub fn stop(cause: FaultCause) -> ! {
    cortex_m::interrupt::disable();
    let record = seal(FaultRecord::of(cause));
    outputs_off_and_wait(&record)
}

/// Switches the outputs off, logs `record` (with the `defmt` feature: only after the
/// outputs are off, since a probe in blocking mode may hold the log) and waits for the
/// watchdog reset.
fn outputs_off_and_wait(record: &FaultRecord) -> ! {
    cortex_m::interrupt::disable();
    // SAFETY: interrupts are disabled and this never returns, so the owners of
    // TIM1, GPIOA/B and the IWDG never run again; the writes below only move the
    // outputs towards the off state, which is safe whatever those owners did last.
    let dp = unsafe { pac::Peripherals::steal() };
    // A halt before the bring-up enabled the peripheral clocks (the option-byte check)
    // reaches here with TIM1 and the GPIO ports unclocked.
    clocks::enable_gate_peripherals(&dp.RCC);
    dp.TIM1.bdtr().modify(|_, w| w.moe().clear_bit());
    pins::gates_off(&dp.GPIOA, &dp.GPIOB, &dp.GPIOC);
    watchdog::start_default(&dp.IWDG);
    log_fault(record);
    loop {
        cortex_m::asm::nop();
    }
}

// HardFault entry (hard_fault_entry.s), before any Rust code: a stack overflow leaves MSP below the stack's
// bottom (memory.x), where every push faults again — inside the HardFault handler that
// is a lockup, not a handled fault (PM0214 §2.4.3, lockup). So the entry, which itself
// uses no stack:
// 1. passes the stack pointer the exception was stacked on (MSP: cortex-m-rt runs
//    everything on the main stack) to the handler in r0;
// 2. cancels a pending lazy floating-point state save (FPCCR.LSPACT = 0, PM0214
//    §4.6.2): the first FPU instruction of the handler would otherwise write the
//    interrupted context's FP registers into the reserved frame — below RAM after an
//    overflow;
// 3. moves MSP back to the top of the stack (`_stack_start`, memory.x): the interrupted
//    code never resumes, so its stack is given up;
// 4. jumps to `hard_fault`, which never returns.
core::arch::global_asm!(include_str!("hard_fault_entry.s"), handler = sym hard_fault);

/// HardFault (entered through the stack-switching entry above): classifies the fault
/// (stack overflow or not, `motor_config::fault_record::classify_hard_fault`), reads the
/// stacked PC when the frame lies inside the stack, records it with CFSR and HFSR
/// (PM0214 §4.4.11, §4.4.12), switches the outputs off and waits for the watchdog.
extern "C" fn hard_fault(sp: u32) -> ! {
    // SAFETY: CFSR and HFSR are read-only here (SCB at 0xE000_ED00, always mapped).
    let (cfsr, hfsr) = unsafe {
        let scb = &*cortex_m::peripheral::SCB::PTR;
        (scb.cfsr.read(), scb.hfsr.read())
    };
    let (cause, pc_at) = classify_hard_fault(sp, stack_bounds(), cfsr);
    // SAFETY: `classify_hard_fault` returns an address only when the whole exception
    // frame lies inside the stack region, which is RAM.
    let pc = pc_at.map(|a| unsafe { core::ptr::read_volatile(a as *const u32) });
    let record = seal(FaultRecord {
        pc,
        cfsr,
        hfsr,
        ..FaultRecord::of(cause)
    });
    outputs_off_and_wait(&record)
}

/// The main stack's `[bottom, top)` addresses, from memory.x.
fn stack_bounds() -> (u32, u32) {
    unsafe extern "C" {
        static _stack_start: u32;
        static _stack_end: u32;
    }
    // Only the symbols' addresses are taken, never their contents.
    ((&raw const _stack_end) as u32, (&raw const _stack_start) as u32)
}

/// Any interrupt without a handler (none is enabled): outputs off, wait.
#[exception]
unsafe fn DefaultHandler(_irqn: i16) {
    stop(FaultCause::UnhandledInterrupt)
}

// The fault record (README, "Fault record"): two word arrays in `.uninit`, which
// cortex-m-rt neither loads nor zeroes, so they survive the watchdog reset. Named and
// unmangled so that a probe finds them by symbol.

/// The sealed record (`motor_config::fault_record::FaultRecord::to_words` layout).
#[unsafe(no_mangle)]
#[unsafe(link_section = ".uninit.MOTOR_FAULT_RECORD")]
static mut MOTOR_FAULT_RECORD: MaybeUninit<[u32; RECORD_WORDS]> = MaybeUninit::uninit();

/// The live control state of the last period (`ControlState::to_words` layout).
#[unsafe(no_mangle)]
#[unsafe(link_section = ".uninit.MOTOR_CONTROL_STATE")]
static mut MOTOR_CONTROL_STATE: MaybeUninit<[u32; STATE_WORDS]> = MaybeUninit::uninit();

/// Reads `N` words at `p` (volatile: the compiler must not assume the contents).
fn read_words<const N: usize>(p: *const [u32; N]) -> [u32; N] {
    let p = p.cast::<u32>();
    // SAFETY: `p` points at one of the two word arrays above (aligned, N words).
    core::array::from_fn(|i| unsafe { p.add(i).read_volatile() })
}

/// Writes `N` words at `p`.
fn write_words<const N: usize>(p: *mut [u32; N], words: &[u32; N]) {
    let p = p.cast::<u32>();
    for (i, w) in words.iter().enumerate() {
        // SAFETY: as in `read_words`; only the fault path, the boot code and the
        // control interrupt write them, never at the same time (the fault path runs
        // with interrupts disabled or at HardFault priority).
        unsafe { p.add(i).write_volatile(*w) };
    }
}

/// The control interrupt's state of this period, kept for the fault record.
pub fn keep_state(state: &ControlState) {
    write_words((&raw mut MOTOR_CONTROL_STATE).cast(), &state.to_words());
}

/// Records a trip of the control interrupt (the outputs are already off; the drive
/// stays off until reset), with what the start-up check that refused the drive measured.
pub fn record(cause: FaultCause, measured: Option<FaultMeasurement>) {
    seal(FaultRecord {
        measured,
        ..FaultRecord::of(cause)
    });
}

/// Seals `record` with the live control state; returns it.
fn seal(record: FaultRecord) -> FaultRecord {
    let state = read_words((&raw const MOTOR_CONTROL_STATE).cast());
    let record = FaultRecord {
        state: ControlState::from_words(&state),
        ..record
    };
    write_words((&raw mut MOTOR_FAULT_RECORD).cast(), &record.to_words());
    record
}

/// With the `defmt` feature: a fault entry on the probe's RTT channel — the cause
/// (`FaultCause` code), the stacked PC, CFSR and HFSR. Never from the control
/// interrupt: its trips only [`record`]; the record reaches the log at the next boot.
/// Logs once per boot: a fault inside the logger (a HardFault while a line is written,
/// or the logger's own panic) must not log again and re-enter it.
#[cfg(feature = "defmt")]
fn log_fault(r: &FaultRecord) {
    use core::sync::atomic::{AtomicBool, Ordering};
    static LOGGED: AtomicBool = AtomicBool::new(false);
    if LOGGED.swap(true, Ordering::Relaxed) {
        return;
    }
    defmt::error!(
        "fault: cause {=u32}, PC {=?}, CFSR {=u32:#010x}, HFSR {=u32:#010x}; outputs off, waiting for the watchdog reset",
        r.cause as u32,
        r.pc,
        r.cfsr,
        r.hfsr
    );
}

/// Without the `defmt` feature: nothing.
#[cfg(not(feature = "defmt"))]
fn log_fault(_: &FaultRecord) {}

/// At boot, before anything can fault: the record of the previous run
/// (`motor_config::fault_record::at_boot`), from RCC_CSR's reset flags (RM0440 §7.4,
/// RCC_CSR: set by the reset source, kept until RMVF is written) and the `.uninit` words. After a
/// brown-out or power-on reset (BORRSTF) the words are not read: SRAM lost power, and
/// with SRAM parity enabled (FLASH_OPTR.SRAM_PE = 0) reading never-written words could
/// raise parity errors. Then the flags are cleared, the live state zeroed and the record
/// rewritten (sealed again, or zeroed when there is none), so every word is written
/// once per boot.
pub fn take_at_boot(rcc: &pac::RCC) -> Option<FaultRecord> {
    let csr = rcc.csr().read();
    #[cfg(feature = "defmt")]
    defmt::info!("boot: RCC_CSR {=u32:#010x} (reset flags, RM0440 §7.4)", csr.bits());
    let record = if csr.borrstf().bit_is_set() {
        None
    } else {
        at_boot(
            &read_words((&raw const MOTOR_FAULT_RECORD).cast()),
            &read_words((&raw const MOTOR_CONTROL_STATE).cast()),
            csr.iwdgrstf().bit_is_set(),
        )
    };
    #[cfg(feature = "defmt")]
    match &record {
        Some(r) => defmt::warn!(
            "previous run: fault record cause {=u32}, PC {=?}, CFSR {=u32:#010x}, HFSR {=u32:#010x}, control state {=bool}, sent on CAN {=bool}, measured {=?} (index {=?})",
            r.cause as u32,
            r.pc,
            r.cfsr,
            r.hfsr,
            r.state.is_some(),
            r.reported,
            r.measured.map(|m| m.value),
            r.measured.map(|m| m.index)
        ),
        None => defmt::info!("previous run: no fault record"),
    }
    rcc.csr().modify(|_, w| w.rmvf().set_bit());
    write_words((&raw mut MOTOR_CONTROL_STATE).cast(), &[0; STATE_WORDS]);
    write_words(
        (&raw mut MOTOR_FAULT_RECORD).cast(),
        &record.map_or([0; RECORD_WORDS], |r| r.to_words()),
    );
    record
}

/// Sends the record on CAN once ([`crate::fault_frame`], identifier
/// [`crate::hw::FAULT_REPORT_ID`]) unless an earlier boot did, and marks it sent.
pub fn report(can: &mut Can, record: FaultRecord) {
    if record.reported {
        return;
    }
    let frame = Frame {
        id: hw::FAULT_REPORT_ID,
        len: 8,
        data: encode(&record),
    };
    if can.send(&frame) {
        let sent = FaultRecord {
            reported: true,
            ..record
        };
        write_words((&raw mut MOTOR_FAULT_RECORD).cast(), &sent.to_words());
    }
}

/// A panic in a development build, or in an image with the `defmt` feature (defmt-rtt's
/// logger panics when taken re-entrantly, so that image cannot prove the absence of
/// panics below): outputs off, wait for the watchdog.
#[cfg(any(debug_assertions, feature = "defmt"))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    stop(FaultCause::Panic)
}

/// Release builds (without the `defmt` feature) prove that no panic is reachable
/// anywhere in the image — the control interrupt included: the panic handler calls a
/// function that does not exist, so the image links only if the optimiser removed every
/// path to a panic.
#[cfg(not(any(debug_assertions, feature = "defmt")))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    unsafe extern "C" {
        /// Intentionally undefined (see above).
        fn motor_firmware_panic_is_reachable() -> !;
    }
    // SAFETY: never executed — an image containing this call does not link.
    unsafe { motor_firmware_panic_is_reachable() }
}
