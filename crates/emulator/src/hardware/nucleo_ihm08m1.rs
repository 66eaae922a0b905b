//! NUCLEO-G474RE (UM2505) with the X-NUCLEO-IHM08M1 power board (UM1996), as their user
//! manuals and schematics and the parts' datasheets describe them, plus the resolver and
//! CAN add-on on free morpho pins.
//!
//! Pins: the shield's signal → morpho position (UM1996 Tables 3 and 4) → G474RE pin
//! (UM2505 Table 16, "ST morpho connector on NUCLEO-G474RE").

use super::{Analog, AnalogInput, Driver, DriverInput, Hardware, Logic, Pull};

/// The L6398's HIN: in phase, internal pull-down (L6398 datasheet DocID18199, §3 truth
/// table; Table 8: HIN logic "1" input bias current 110–260 µA at 15 V).
const fn hin(pin: &'static str) -> DriverInput {
    DriverInput {
        pin,
        logic: Logic::ActiveHigh,
        pull: Pull::Down,
    }
}

/// The L6398's LIN: active low — the low-side output is on while LIN is low (L6398
/// datasheet §3 truth table; ST community "L6398 (IHM08M1) input logic": HIN = LIN = low
/// turns the low side on) — with an internal pull-up (Table 8: LIN logic "0" input bias
/// current 3–20 µA at 0 V).
const fn lin(pin: &'static str) -> DriverInput {
    DriverInput {
        pin,
        logic: Logic::ActiveLow,
        pull: Pull::Up,
    }
}

/// Current-sense stage (UM1996 schematic, one per phase): the 10 mΩ low-side shunt's
/// top terminal → 680 Ω → TSV994 (+), 6.8 kΩ from (+) to 3.3 V, feedback 4.7 kΩ over
/// 1 kΩ to ground.
const SHUNT_OHM: f64 = 0.010;
const R_IN: f64 = 680.0;
const R_BIAS: f64 = 6_800.0;
const R_F: f64 = 4_700.0;
const R_G: f64 = 1_000.0;
/// The stage's supply and the NUCLEO's V_REF+ = V_DDA (UM2505, power supply).
const V_SUPPLY: f64 = 3.3;

/// The hardware.
pub fn hardware() -> Hardware {
    // Non-inverting gain (1 + R_F/R_G) on the divided input: V_out = (1 + R_F/R_G)·
    // (V_shunt·R_BIAS + V_SUPPLY·R_IN)/(R_IN + R_BIAS). A current out of the leg flows up
    // through the low-side shunt while the low side conducts: V_shunt = −R·i.
    let noise_gain = 1.0 + R_F / R_G;
    let gain = -SHUNT_OHM * noise_gain * R_BIAS / (R_IN + R_BIAS);
    let offset = noise_gain * V_SUPPLY * R_IN / (R_IN + R_BIAS);
    // VBUS divider 169 kΩ over 9.31 kΩ (UM1996 schematic); the ADC sees its Thevenin
    // resistance.
    let (r_top, r_bottom) = (169e3, 9.31e3);
    // The TSV994's output impedance during a sampling transient: no series resistor in
    // UM1996, no closed-loop output impedance in its datasheet (DS4975); faster than
    // the stage's loop (20 MHz GBP / noise gain 5.7 = 3.5 MHz), the capacitor sees the
    // open-loop output of a CMOS op-amp, bounded here by 1 kΩ.
    let amp = 1_000.0;
    let current = |pin, k| AnalogInput {
        pin,
        signal: Analog::Current(k),
        source_ohm: amp,
        source: "TSV994 current-sense stage (UM1996)",
    };
    Hardware {
        variant_of: None,
        board: "nucleo-g474re-ihm08m1",
        chip: "STM32G474RE",
        legs: [
            // UH CN10-23 → PA8, UL CN10-15 → PA7; VH CN10-21 → PA9, VL CN7-34 → PB0;
            // WH CN10-33 → PA10, WL CN10-24 → PB1 (UM1996 Table 4, UM2505 Table 16).
            [hin("PA8"), lin("PA7")],
            [hin("PA9"), lin("PB0")],
            [hin("PA10"), lin("PB1")],
        ],
        driver: Driver {
            part: "L6398",
            // L6398 datasheet, features and §3: interlocking function, fixed 320 ns dead time.
            interlock: true,
            dead_time_s: 320e-9,
            // Not a datasheet figure: the L6398's output fall (35 ns into 1 nF, datasheet
            // features) plus the STL220N6F7's turn-off, which ST pairs with the 320 ns on
            // this board; modelled as 150 ns, so the driver's own dead time covers it.
            turn_off_s: 150e-9,
        },
        analog: vec![
            // Curr_fdbk_PhA CN7-28 → PA0, PhB CN7-36 → PC1, PhC CN7-38 → PC0 (UM1996 Table 3).
            current("PA0", 0),
            current("PC1", 1),
            current("PC0", 2),
            AnalogInput {
                pin: "PA1", // VBUS_sensing CN7-30 → PA1
                signal: Analog::DcLink,
                source_ohm: r_top * r_bottom / (r_top + r_bottom),
                source: "VBUS divider 169 kΩ / 9.31 kΩ (UM1996)",
            },
            // The resolver add-on's SIN/COS front end on CN10-16 → PB12 and CN7-32 → PA4
            // (R181, the shield's potentiometer, removed): 1.1 kΩ output + series resistor.
            AnalogInput {
                pin: "PB12",
                signal: Analog::Sin,
                source_ohm: 1_100.0,
                source: "resolver add-on front end",
            },
            AnalogInput {
                pin: "PA4",
                signal: Analog::Cos,
                source_ohm: 1_100.0,
                source: "resolver add-on front end",
            },
        ],
        current_gain_v_per_a: gain,
        current_offset_v: offset,
        dc_link_ratio: r_bottom / (r_top + r_bottom),
        vref: V_SUPPLY,
        // The resolver add-on (on neither ST board) with the reference board's front end.
        resolver_amplitude_v: 0.66,
        // The shield's over-current comparator, CN10-13 → PA6, pulls low on over-current
        // (UM1996 §2.3).
        break_pin: "PA6",
        break_active_low: true,
        excitation_pin: "PC6", // add-on excitation amplifier on CN10-4
        // The add-on's CAN transceiver RXD on CN10-3 → PB8 idles high.
        boot0_may_be_high: true,
        // NUCLEO-G474RE: X3, a 24 MHz crystal on PF0/PF1 (UM2505 §6.7.1 "HSE clock
        // (high-speed external clock)": the 24 MHz crystal is fitted by default).
        hse_crystal_hz: Some(24e6),
        // The TSV994 stage behind each low-side shunt: 20 MHz GBP (DS4975) over its noise
        // gain 5.7 is τ = 45 ns, 12 bits in 8.32·τ = 0.38 µs (thesis A (7.4)); the
        // switching edge's ringing is not stated in UM1996. ST's motor-control SDK waits
        // T_noise = T_rise = 1 µs after an edge on its 10 mΩ three-shunt stages (STMCWB 4.3
        // power-stage parameters): 1 µs, as the board file states.
        low_side_settling_s: Some(1e-6),
    }
}

#[cfg(test)]
mod tests {
    /// The stage by hand: 5.7·6.8/7.48 = 5.1818 on the shunt's −10 mΩ → −51.818 mV/A,
    /// 5.7·3.3·0.68/7.48 = 1.7100 V; divider 9.31/178.31 = 0.052212 (63.2 V full scale).
    #[test]
    fn sensing_by_hand() {
        let h = super::hardware();
        assert!(
            (h.current_gain_v_per_a + 0.051_818).abs() < 1e-6,
            "{}",
            h.current_gain_v_per_a
        );
        assert!((h.current_offset_v - 1.710_0).abs() < 1e-4, "{}", h.current_offset_v);
        assert!((h.dc_link_ratio - 0.052_212).abs() < 1e-6);
    }
}
