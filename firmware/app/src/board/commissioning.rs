//! The commissioning mode on the board: shared between the main loop (commands in,
//! status and capture frames out) and the control interrupt (the routine, one step per
//! period), each access inside a critical section.
//!
//! The supervisor (`motor_control::commissioning_mode`) decides; this module only moves
//! data: the interrupt publishes the guards it sees (trip, break, setpoint timeout, ω_e) for
//! the command check, the main loop publishes the last received torque.

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use cortex_m::interrupt::{self, Mutex};
use motor_control::can_protocol::decode_command;
use motor_control::commissioning_mode::{Control, Guards, Measured, Sample, prepare};
use motor_control::preflight::Refusal;
use motor_control::{Demand, Trig};

use super::can::Can;
use motor_config::can_commissioning::{CAPACITY, LAYOUT, MODE, Mode, STATUS_PERIODS};

/// The supervisor.
static SUPERVISOR: Mutex<RefCell<Mode>> = Mutex::new(RefCell::new(Mode::new()));
/// The capture buffer: zero-initialised, so it lives in .bss and costs no flash.
static BUFFER: Mutex<RefCell<[Sample; CAPACITY]>> = Mutex::new(RefCell::new([(0.0, 0.0); CAPACITY]));
/// ω_e of the last control period \[rad/s\] as `f32` bits.
static OMEGA_E: AtomicU32 = AtomicU32::new(0);
/// The drive has tripped.
static FAULT: AtomicBool = AtomicBool::new(false);
/// The setpoint has timed out.
static TIMED_OUT: AtomicBool = AtomicBool::new(false);
/// The break was latched (TIM1_SR.BIF) when the interrupt last looked.
static BREAK: AtomicBool = AtomicBool::new(false);
/// The last received torque setpoint \[N·m\] as `f32` bits.
static TORQUE: AtomicU32 = AtomicU32::new(0);

/// Main loop: a received torque setpoint \[N·m\].
pub fn torque_received(torque: f32) {
    TORQUE.store(torque.to_bits(), Ordering::Relaxed);
}

/// Main loop: a received frame; a commissioning command goes to the supervisor (its
/// answer is in the next status frame).
pub fn frame_received(id: Option<u16>, data: &[u8]) {
    let Some(command) = id.and_then(|id| decode_command(&LAYOUT, id, data)) else {
        return;
    };
    let guards = Guards {
        torque_setpoint: f32::from_bits(TORQUE.load(Ordering::Relaxed)),
        fault: FAULT.load(Ordering::Relaxed),
        break_active: BREAK.load(Ordering::Relaxed),
        setpoint_timeout: TIMED_OUT.load(Ordering::Relaxed),
    };
    let omega_e = f32::from_bits(OMEGA_E.load(Ordering::Relaxed));
    // The frequency response's oscillators are computed here, with the control
    // interrupt enabled (`motor_control::commissioning_mode::Prepared`).
    let prepared = prepare(&MODE, &command, CAPACITY);
    interrupt::free(|cs| {
        if let Ok(mut m) = SUPERVISOR.borrow(cs).try_borrow_mut() {
            m.command_prepared(&MODE, &command, &prepared, &guards, omega_e, CAPACITY);
        }
    });
}

/// Main loop: the status frame every [`STATUS_PERIODS`] control periods, otherwise the
/// next capture frame while one is being sent (as fast as the TX FIFO takes them).
pub fn transmit(tx: &mut Can, ticks: u32, last_status: &mut u32) {
    interrupt::free(|cs| {
        let (Ok(mut m), Ok(buffer)) = (SUPERVISOR.borrow(cs).try_borrow_mut(), BUFFER.borrow(cs).try_borrow()) else {
            return;
        };
        if ticks.wrapping_sub(*last_status) >= STATUS_PERIODS {
            let faults = u8::from(FAULT.load(Ordering::Relaxed));
            if tx.send(&m.status(&MODE, faults)) {
                *last_status = ticks;
            }
            return;
        }
        // Take the next frame only when it can be queued (none is lost).
        if tx.has_room()
            && let Some(frame) = m.next_frame(&MODE, &buffer[..])
        {
            tx.send(&frame);
        }
    });
}

/// Control interrupt: one period of the supervisor. `normal` is the torque demand;
/// returns the demand to run, whether the outputs may be on, and the pre-flight check's
/// refusal when it refused the drive this period (the caller trips with its cause).
pub fn control_step<T: Trig>(
    trig: &mut T,
    measured: &Measured,
    guards: &Guards,
    omega_e: f32,
    normal: Demand,
    run: bool,
) -> (Demand, bool, Option<Refusal>) {
    OMEGA_E.store(omega_e.to_bits(), Ordering::Relaxed);
    FAULT.store(guards.fault, Ordering::Relaxed);
    TIMED_OUT.store(guards.setpoint_timeout, Ordering::Relaxed);
    BREAK.store(guards.break_active, Ordering::Relaxed);
    let (control, refused) = interrupt::free(|cs| {
        match (
            SUPERVISOR.borrow(cs).try_borrow_mut(),
            BUFFER.borrow(cs).try_borrow_mut(),
        ) {
            (Ok(mut m), Ok(mut buffer)) => {
                let c = m.step(&MODE, guards, measured, trig, &mut buffer[..]);
                (c, m.take_refusal())
            }
            // Never happens (every borrow is inside a critical section); outputs off.
            _ => (Control::Off, None),
        }
    });
    match control {
        Control::Normal => (normal, run, refused),
        Control::Demand(d) => (d, !guards.fault, refused),
        Control::Off => (Demand::Off, false, refused),
    }
}
