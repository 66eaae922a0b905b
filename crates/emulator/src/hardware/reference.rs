//! The motorgen reference inverter: thesis A's controller as this project specifies it
//! (the board the firmware assumed before boards were data). It has no published
//! schematic; this is its design, stated here for the emulator and, separately, in its
//! board file: SiC MOSFETs, each behind an isolated single-channel driver
//! (1EDI20N12AF), Hall-type phase-current sensors, an over-current comparator on the
//! break input, the resolver front end and a CAN transceiver.

use super::{Analog, AnalogInput, Driver, DriverInput, Hardware, Logic, Pull};

/// A 1EDI20N12AF's IN+: non-inverting with an internal pull-down, IN− tied to ground
/// (1EDI20N12AF data sheet Rev. 2.0, pin description).
const fn in_plus(pin: &'static str) -> DriverInput {
    DriverInput {
        pin,
        logic: Logic::ActiveHigh,
        pull: Pull::Down,
    }
}

/// The front ends' output resistance: op-amp output plus the anti-aliasing series
/// resistor of the design.
const FRONT_END_OHM: f64 = 1_100.0;

/// The hardware.
pub fn hardware() -> Hardware {
    // Hall sensors mounted positive for a current out of the leg: 15 mV/A about
    // mid-supply (sized for thesis A's Fischer TI085, ±110 A).
    with_sensing("motorgen-reference", None, 0.015)
}

/// The same controller with its Hall sensors sized for the seed traction motors:
/// 3.75 mV/A about mid-supply, ±440 A (sized for the EMRAX 228 HV's 339 A peak at thesis
/// A's 1.25 headroom, Table 4.1); everything else is the reference board's.
pub fn hardware_400a() -> Hardware {
    with_sensing("motorgen-reference-400a", Some("motorgen-reference"), 3.75e-3)
}

/// The reference controller named `board` (a variant of `variant_of`) with Hall sensors
/// of `sensitivity` \[V/A\].
fn with_sensing(board: &'static str, variant_of: Option<&'static str>, sensitivity: f64) -> Hardware {
    let input = |pin, signal, source| AnalogInput {
        pin,
        signal,
        source_ohm: FRONT_END_OHM,
        source,
    };
    Hardware {
        board,
        variant_of,
        chip: "STM32G474RE",
        legs: [
            [in_plus("PA8"), in_plus("PB13")],
            [in_plus("PA9"), in_plus("PB14")],
            [in_plus("PA10"), in_plus("PB15")],
        ],
        driver: Driver {
            part: "1EDI20N12AF",
            // One single-channel driver per switch: nothing couples a leg's two switches
            // and no driver inserts dead time (1EDI20N12AF data sheet).
            interlock: false,
            dead_time_s: 0.0,
            // The design's switching allowance: the driver's turn-off propagation plus
            // the SiC switch's turn-off; TIM1's dead time must exceed it (thesis A §3.2:
            // switches do not turn off instantly, so a dead time separates them).
            turn_off_s: 200e-9,
        },
        analog: vec![
            input("PA0", Analog::Current(0), "Hall sensor u"),
            input("PA6", Analog::Current(1), "Hall sensor v"),
            input("PA4", Analog::Current(2), "Hall sensor w"),
            input("PA2", Analog::DcLink, "DC-link divider buffer"),
            input("PA1", Analog::Sin, "resolver SIN front end"),
            input("PA7", Analog::Cos, "resolver COS front end"),
        ],
        // Mounted positive for a current out of the leg, about mid-supply.
        current_gain_v_per_a: sensitivity,
        current_offset_v: 1.65,
        // 3.3 V at 750 V (1.25 × thesis A's 600 V accumulator).
        dc_link_ratio: 0.0044,
        vref: 3.3,
        // The front end's figure: thesis A does not publish its controller's resolver
        // interface; 0.66 V is 40 % of the 1.65 V half range (the board file's stated
        // assumption, which this hardware is built to).
        resolver_amplitude_v: 0.66,
        break_pin: "PB12",
        break_active_low: true,
        excitation_pin: "PC6",
        // CAN RX on PB8: the transceiver's RXD idles high.
        boot0_may_be_high: true,
        // No crystal: the reference design clocks the MCU from HSI16 only.
        hse_crystal_hz: None,
        // Hall-type in-line sensors: the current reaches the pin whatever the switches do.
        low_side_settling_s: None,
    }
}
