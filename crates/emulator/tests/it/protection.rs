//! Protection on the real image, every board with every motor that fits it: the break
//! input, a phase current at the ADC rail, a HardFault, a stalled control interrupt.
//! "Off" means no switch is commanded on: the gate pins, through their GPIO mode and
//! alternate function and the board's gate driver, turn no switch of the bridge on.

use crate::BOOT_LIMIT_S;
use motor_emulator::periph::gpio::Mode;
use motor_emulator::rig::{Bench, Rig, benches};
use motor_emulator::{HARD_FAULT, Machine, Stop};

fn booted(motor: &str, board: &str) -> Rig {
    let mut rig = Rig::new(Bench::new(motor, board).unwrap()).unwrap_or_else(|e| panic!("{motor}: {e}"));
    rig.boot(BOOT_LIMIT_S).unwrap_or_else(|e| panic!("{motor}: {e}"));
    // A few enabled periods.
    let t = rig.machine.soc().time_s() + 5.0 * rig.pwm_period_s();
    rig.run(t, |_| Some(0.0), |_| false)
        .unwrap_or_else(|e| panic!("{motor}: {e}"));
    assert!(rig.machine.soc().tim1.moe(), "{motor}: outputs not on before the test");
    rig
}

/// Runs `periods` carrier periods with zero-torque setpoints, checking after every event
/// from `off_after_s` on that the gates are off; returns the first time they were seen
/// off.
fn stays_off(rig: &mut Rig, motor: &str, periods: f64, off_after_s: f64) -> Option<f64> {
    let end = rig.machine.soc().time_s() + periods * rig.pwm_period_s();
    let mut first_off = None;
    let mut bad = None;
    rig.run(
        end,
        |_| Some(0.0),
        |m: &Machine| {
            let soc = m.soc();
            let off = !soc.gates_can_switch();
            if off && first_off.is_none() {
                first_off = Some(soc.time_s());
            }
            if soc.time_s() >= off_after_s && !off {
                bad = Some(soc.time_s());
            }
            bad.is_some()
        },
    )
    .unwrap_or_else(|e| panic!("{motor}: {e}"));
    assert!(bad.is_none(), "{motor}: a gate could switch on at {:?} s", bad);
    first_off
}

/// Break input asserted mid-run: MOE cleared by the hardware at once, the outputs off
/// within one PWM period and staying off, also after the comparator releases (the
/// image latches the trip from BIF; setting MOE with BIF latched would be a strict-mode
/// violation).
#[test]
fn break_input_switches_the_outputs_off_for_good() {
    for (motor, board) in benches() {
        let mut rig = booted(&motor, &board);
        let motor = rig.bench.name();
        let t0 = rig.machine.soc().time_s();
        let period = rig.pwm_period_s();
        {
            let soc = rig.machine.soc_mut();
            soc.break_asserted = true;
            soc.update_break();
        }
        let off = stays_off(&mut rig, &motor, 10.0, t0 + period).expect("off");
        assert!(off - t0 <= period, "{motor}: off after {} s", off - t0);
        {
            let soc = rig.machine.soc_mut();
            soc.break_asserted = false;
            soc.update_break();
        }
        stays_off(&mut rig, &motor, 20.0, 0.0);
        println!("{motor}: break → outputs off after {:.2} µs", (off - t0) * 1e6);
    }
}

/// A phase current at the converter's rail trips the drive within one period (the
/// image's TRIPS check), and it stays off with the current back at zero.
#[test]
fn phase_current_at_the_rail_trips() {
    for (motor, board) in benches() {
        let mut rig = booted(&motor, &board);
        let motor = rig.bench.name();
        let t0 = rig.machine.soc().time_s();
        let period = rig.pwm_period_s();
        // Far beyond the sensor's range: the ADC input above V_REF+ reads 4095.
        let rail_a = rig.design.board.as_ref().unwrap().current_full_scale_a * 2.0;
        rig.analog().currents[0] = rail_a;
        let off = stays_off(&mut rig, &motor, 10.0, t0 + 2.0 * period).expect("off");
        rig.analog().currents[0] = 0.0;
        stays_off(&mut rig, &motor, 20.0, 0.0);
        assert!(off - t0 <= 2.0 * period, "{motor}: tripped after {} s", off - t0);
        println!("{motor}: rail current → outputs off after {:.2} µs", (off - t0) * 1e6);
    }
}

/// A HardFault mid-run: MOE cleared and the six gate pins driven to their off levels as
/// GPIO outputs (fault.rs: high for the L6398's active-low LIN), then the watchdog
/// resets the chip.
#[test]
fn hard_fault_switches_the_gates_off_and_the_watchdog_resets() {
    for (motor, board) in benches() {
        let mut rig = booted(&motor, &board);
        let motor = rig.bench.name();
        let t0 = rig.machine.soc().time_s();
        rig.machine.inject(HARD_FAULT);
        let end = t0 + 2.0 * rig.pwm_period_s();
        rig.machine.run_until(end).unwrap_or_else(|e| panic!("{motor}: {e}"));
        let soc = rig.machine.soc();
        assert!(!soc.tim1.moe(), "{motor}: MOE still set after the HardFault");
        let off = rig.hardware.off_levels();
        for (k, (p, n)) in soc.wiring.gates.into_iter().enumerate() {
            let port = &soc.gpio[usize::from(p)];
            assert_eq!(port.mode(n), Mode::Output, "{motor}: gate pin {k} not a GPIO output");
            assert_eq!(port.odr(n), off[k], "{motor}: gate pin {k} not at its off level");
        }
        assert!(!soc.gates_can_switch(), "{motor}: a switch still on");
        // The handler started the watchdog with its reset timeout (≈ 0.5 s) or kept
        // the configured one running: the chip resets.
        let err = rig.machine.run_until(t0 + 1.0).unwrap_err();
        assert!(matches!(err, Stop::WatchdogReset(_)), "{motor}: {err}");
        println!("{motor}: HardFault → gates at their off levels; {err}");
    }
}

/// The control interrupt stops (its trigger no longer reaches the ADCs): the main loop
/// stops refreshing the watchdog, which resets the chip within its timeout (board
/// `[watchdog].timeout`, rounded up by the image's PR/RLR).
#[test]
fn stalled_control_interrupt_ends_in_a_watchdog_reset() {
    for (motor, board) in benches() {
        let mut rig = booted(&motor, &board);
        let motor = rig.bench.name();
        let t0 = rig.machine.soc().time_s();
        let timeout = rig.design.board.as_ref().unwrap().board.watchdog_timeout_s;
        let period = rig.pwm_period_s();
        rig.machine.soc_mut().patches.drop_triggers = true;
        let err = rig.run(t0 + 10.0 * timeout, |_| Some(0.0), |_| false).unwrap_err();
        let Stop::WatchdogReset(t) = err else {
            panic!("{motor}: expected a watchdog reset, got {err}");
        };
        // One IWDG count at the largest prescaler the image could choose is 4·2^6/32 kHz = 8 ms.
        let dt = t - t0;
        assert!(dt >= timeout - 2.0 * period, "{motor}: reset {dt} s after the stall");
        assert!(
            dt <= timeout * 1.25 + period,
            "{motor}: reset {dt} s after the stall (timeout {timeout} s)"
        );
        println!(
            "{motor}: stall → watchdog reset after {:.3} ms (timeout {:.3} ms)",
            dt * 1e3,
            timeout * 1e3
        );
    }
}
