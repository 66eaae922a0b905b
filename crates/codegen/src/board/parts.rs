//! The parts table: gate drivers described once, by their datasheets, so that a board
//! file can name its part (`[gate_driver] part = "L6398"`) instead of restating the facts
//! the firmware's polarities and idle levels are derived from. Every fact carries the
//! datasheet passage it comes from; a board that states a fact itself is warned when it
//! contradicts its part's (`crate::board`, `motorgen check`).
//!
//! "In phase" means a high input turns the switch on; "inverted" that a low input does.
//! The pull is what holds an input that nothing drives — at reset, before the MCU routes
//! its pin (RM0440 GPIO: pins reset to analog mode, no pull), or while TIM1 leaves it in
//! Hi-Z (MOE = 0 with OSSI = 0, RM0440 Table "Output control bits for complementary
//! tim_ocx and tim_ocxn channels with break feature").

use super::raw::{InputLogic, InputPull};

/// One input of a driver, with the datasheet passages that state it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputFact {
    /// How the input turns its switch on.
    pub logic: InputLogic,
    /// Where the datasheet states it.
    pub logic_source: &'static str,
    /// What holds it when undriven.
    pub pull: InputPull,
    /// Where the datasheet states it.
    pub pull_source: &'static str,
}

/// A gate driver as its datasheet describes the inputs a board connects to TIM1's
/// CHx (high side) and CHxN (low side).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GateDriverPart {
    /// Part number as a board file names it.
    pub part: &'static str,
    /// What it is.
    pub description: &'static str,
    /// The datasheet (document and revision).
    pub datasheet: &'static str,
    /// The input the board drives from TIM1_CHx.
    pub high_side: InputFact,
    /// The input the board drives from TIM1_CHxN.
    pub low_side: InputFact,
    /// Whether the driver keeps both switches of a leg off when both inputs ask for on.
    pub interlock: bool,
    /// Where the datasheet states it.
    pub interlock_source: &'static str,
    /// Dead time the driver itself inserts between one output turning off and the other
    /// turning on \[s\], if the datasheet guarantees one.
    pub dead_time_s: Option<f64>,
    /// Where the datasheet states it.
    pub dead_time_source: &'static str,
}

/// The gate drivers a board file may name.
pub const GATE_DRIVERS: &[GateDriverPart] = &[
    GateDriverPart {
        part: "L6398",
        description: "ST high-voltage high- and low-side driver (X-NUCLEO-IHM08M1, three per board)",
        datasheet: "ST L6398 datasheet, DocID18199 Rev 4",
        high_side: InputFact {
            logic: InputLogic::InPhase,
            logic_source: "L6398 datasheet §3 truth table: HIN high turns HVG on",
            pull: InputPull::Down,
            pull_source: "L6398 datasheet Table 8: HIN logic \"1\" input bias current 110–260 µA at HIN = 15 V, 1 µA at 0 V (internal pull-down)",
        },
        low_side: InputFact {
            logic: InputLogic::Inverted,
            logic_source: "L6398 datasheet §3 truth table: LVG is on while LIN is low (LIN is active low; NuttX stm32_ihm08m1.c requires TIM1's complementary outputs inverted for it)",
            pull: InputPull::Up,
            pull_source: "L6398 datasheet Table 8: LIN logic \"0\" input bias current 3–20 µA at LIN = 0 V, 1 µA at 15 V (internal pull-up)",
        },
        interlock: true,
        interlock_source: "L6398 datasheet, features and §3 truth table: interlocking function, both outputs off when both inputs ask for on",
        dead_time_s: Some(320e-9),
        dead_time_source: "L6398 datasheet, features: fixed 320 ns dead time",
    },
    GateDriverPart {
        part: "DRV8323",
        description: "TI three-phase smart gate driver, 6x PWM mode",
        datasheet: "TI DRV832x datasheet, SLVSDJ3",
        high_side: InputFact {
            logic: InputLogic::InPhase,
            logic_source: "DRV832x datasheet, 6x PWM mode truth table: INHx high turns GHx on",
            pull: InputPull::Down,
            pull_source: "DRV832x datasheet, electrical characteristics: INHx/INLx internal pull-down resistance",
        },
        low_side: InputFact {
            logic: InputLogic::InPhase,
            logic_source: "DRV832x datasheet, 6x PWM mode truth table: INLx high turns GLx on",
            pull: InputPull::Down,
            pull_source: "DRV832x datasheet, electrical characteristics: INHx/INLx internal pull-down resistance",
        },
        interlock: true,
        interlock_source: "DRV832x datasheet, 6x PWM mode truth table: INHx = INLx = 1 turns both GHx and GLx off",
        dead_time_s: None,
        dead_time_source: "DRV832x datasheet: the inserted dead time is a register/pin setting of the board, not a fixed fact of the part",
    },
    GateDriverPart {
        part: "IR2110",
        description: "Infineon (IR) high- and low-side driver, independent inputs",
        datasheet: "IR2110(S) datasheet, PD60147",
        high_side: InputFact {
            logic: InputLogic::InPhase,
            logic_source: "IR2110 datasheet, lead definitions: HIN logic input for the high-side gate driver output HO, in phase",
            pull: InputPull::Down,
            pull_source: "IR2110 datasheet, functional block diagram: pull-down on HIN",
        },
        low_side: InputFact {
            logic: InputLogic::InPhase,
            logic_source: "IR2110 datasheet, lead definitions: LIN logic input for the low-side gate driver output LO, in phase",
            pull: InputPull::Down,
            pull_source: "IR2110 datasheet, functional block diagram: pull-down on LIN",
        },
        interlock: false,
        interlock_source: "IR2110 datasheet: independent high- and low-side channels, no cross-conduction prevention logic",
        dead_time_s: None,
        dead_time_source: "IR2110 datasheet: no dead time inserted (matched propagation delays only)",
    },
    GateDriverPart {
        part: "1EDI20N12AF",
        description: "Infineon EiceDRIVER Compact single-channel isolated driver (one per switch; IN− tied to ground)",
        datasheet: "Infineon 1EDI20N12AF data sheet Rev. 2.0, 2015-06-01",
        high_side: InputFact {
            logic: InputLogic::InPhase,
            logic_source: "1EDI20N12AF data sheet, pin description: IN+ non-inverting driver input",
            pull: InputPull::Down,
            pull_source: "1EDI20N12AF data sheet, pin description: IN+ internal pull-down",
        },
        low_side: InputFact {
            logic: InputLogic::InPhase,
            logic_source: "1EDI20N12AF data sheet, pin description: IN+ non-inverting driver input",
            pull: InputPull::Down,
            pull_source: "1EDI20N12AF data sheet, pin description: IN+ internal pull-down",
        },
        interlock: false,
        interlock_source: "1EDI20N12AF data sheet: a single channel per switch, so nothing couples the two switches of a leg",
        dead_time_s: None,
        dead_time_source: "1EDI20N12AF data sheet: a single channel inserts no dead time",
    },
];

/// The part named `name` (case-insensitive), if the table has it.
pub fn gate_driver(name: &str) -> Option<&'static GateDriverPart> {
    GATE_DRIVERS.iter().find(|p| p.part.eq_ignore_ascii_case(name.trim()))
}

/// The names of the table's gate drivers, for "accepted:" lines.
pub fn gate_driver_names() -> String {
    GATE_DRIVERS.iter().map(|p| p.part).collect::<Vec<_>>().join(", ")
}

/// The off level of an input with `logic`: low for an in-phase input, high for an
/// inverted one.
pub fn off_level(logic: InputLogic) -> bool {
    logic == InputLogic::Inverted
}

/// The pull that holds an input with `logic` off while undriven.
pub fn safe_pull(logic: InputLogic) -> InputPull {
    match logic {
        InputLogic::InPhase => InputPull::Down,
        InputLogic::Inverted => InputPull::Up,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every part names its datasheet and a passage for each fact, and its pulls hold
    /// its inputs off (a part whose own pull turned a switch on at reset would need a
    /// board resistor, which the table cannot know).
    #[test]
    fn every_fact_is_cited_and_every_pull_holds_off() {
        assert!(GATE_DRIVERS.len() >= 4);
        for p in GATE_DRIVERS {
            for s in [
                p.datasheet,
                p.high_side.logic_source,
                p.high_side.pull_source,
                p.low_side.logic_source,
                p.low_side.pull_source,
                p.interlock_source,
                p.dead_time_source,
            ] {
                assert!(s.len() > 20, "{}: {s:?}", p.part);
            }
            assert_eq!(p.high_side.pull, safe_pull(p.high_side.logic), "{}", p.part);
            assert_eq!(p.low_side.pull, safe_pull(p.low_side.logic), "{}", p.part);
        }
    }

    /// The L6398's LIN is active low with a pull-up (the issue-25 review's fact), its
    /// HIN in phase with a pull-down; names are matched without regard to case.
    #[test]
    fn l6398_low_side_is_inverted() {
        let p = gate_driver("l6398").unwrap();
        assert_eq!(
            (p.high_side.logic, p.high_side.pull, p.low_side.logic, p.low_side.pull),
            (
                InputLogic::InPhase,
                InputPull::Down,
                InputLogic::Inverted,
                InputPull::Up
            )
        );
        assert!(p.interlock);
        assert_eq!(p.dead_time_s, Some(320e-9));
        assert!(!off_level(InputLogic::InPhase) && off_level(InputLogic::Inverted));
        assert!(gate_driver("L6399").is_none());
    }
}
