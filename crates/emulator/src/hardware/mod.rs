//! The boards around the chip, described by this crate from their schematics and their
//! parts' datasheets — never read from `boards/*.toml`. The image is built from a board
//! file; the emulated board is this description, so a wrong fact in the board file
//! meets the hardware it claims to describe and shows as a strict-mode rule or a failed
//! criterion, instead of being confirmed by itself.
//!
//! Each board has its own module (one per file in `boards/`, [`for_board`]); what they
//! describe:
//! * which MCU pin drives which gate-driver input, how that input turns its switch on
//!   (active high or low), what holds it when nothing drives it, whether the driver
//!   interlocks a leg's two switches and inserts dead time of its own, and how long a
//!   switch keeps conducting after its gate is commanded off;
//! * which MCU pin carries which analog signal, the current sensing's signed gain and
//!   zero level, the DC-link divider, and what drives each input (its source resistance,
//!   for the sampling capacitor's settling);
//! * the over-current comparator on the break pin: its pin and its active level;
//! * what PB8 (BOOT0) sees at reset.
//!
//! Chip facts (which alternate function of a pin is which peripheral signal, which ADC
//! channel a pin is) come from the chip's own table (`codegen::board::chip`, generated
//! from ST's pin database), not from a board file.

pub mod nucleo_ihm08m1;
pub mod reference;

use codegen::board::chip::{self, Chip};

/// How a gate-driver input turns its switch on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Logic {
    /// A high input turns it on.
    ActiveHigh,
    /// A low input turns it on.
    ActiveLow,
}

/// What holds a line while nothing drives it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pull {
    /// To ground.
    Down,
    /// To the logic supply.
    Up,
    /// Nothing: it floats.
    None,
}

/// One gate-driver input and the MCU pin wired to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DriverInput {
    /// The MCU pin, e.g. `"PA7"`.
    pub pin: &'static str,
    /// How it turns its switch on.
    pub logic: Logic,
    /// What holds it while the pin does not drive it.
    pub pull: Pull,
}

impl DriverInput {
    /// Whether the input asks for its switch on at pin level `level`.
    pub fn asks_on(&self, level: bool) -> bool {
        match self.logic {
            Logic::ActiveHigh => level,
            Logic::ActiveLow => !level,
        }
    }

    /// The level of an undriven input, `None` when it floats.
    pub fn undriven(&self) -> Option<bool> {
        match self.pull {
            Pull::Down => Some(false),
            Pull::Up => Some(true),
            Pull::None => None,
        }
    }
}

/// The gate driver's behaviour between its inputs and the switches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Driver {
    /// The part, for messages.
    pub part: &'static str,
    /// Both switches of a leg kept off when both inputs ask for on.
    pub interlock: bool,
    /// Time an output waits after the other output of its leg turned off before it may
    /// turn on \[s\] (0: none).
    pub dead_time_s: f64,
    /// Time a switch keeps conducting after its driver output turns off \[s\]: the
    /// driver's turn-off propagation and the switch's own turn-off. The two switches of
    /// a leg conduct together (shoot-through) unless one turns on at least this long
    /// after the other was commanded off.
    pub turn_off_s: f64,
}

/// Which signal an analog input carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Analog {
    /// Phase current u, v or w (0, 1, 2).
    Current(usize),
    /// DC-link voltage.
    DcLink,
    /// Resolver SIN winding.
    Sin,
    /// Resolver COS winding.
    Cos,
}

/// An analog input: the pin, its signal and what drives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnalogInput {
    /// The MCU pin.
    pub pin: &'static str,
    /// The signal.
    pub signal: Analog,
    /// Source resistance the ADC's sampling capacitor charges through \[Ω\].
    pub source_ohm: f64,
    /// What drives the input, for messages.
    pub source: &'static str,
}

/// A board's hardware.
#[derive(Clone, Debug, PartialEq)]
pub struct Hardware {
    /// The board file (`boards/<stem>.toml`) this describes.
    pub board: &'static str,
    /// The board this one is a variant of — the same hardware but for the phase-current
    /// sensing's gain (`motorgen-reference-400a` of `motorgen-reference`): the scenarios
    /// run on it only the motors the other board does not take ([`crate::rig::benches`]).
    pub variant_of: Option<&'static str>,
    /// The chip on it.
    pub chip: &'static str,
    /// Per leg u, v, w: the high-side and low-side driver inputs.
    pub legs: [[DriverInput; 2]; 3],
    /// The gate driver.
    pub driver: Driver,
    /// The analog inputs.
    pub analog: Vec<AnalogInput>,
    /// Phase current → ADC-pin voltage: signed gain \[V/A\] (current out of the leg
    /// positive) and zero level \[V\].
    pub current_gain_v_per_a: f64,
    /// ADC-pin voltage at zero current \[V\].
    pub current_offset_v: f64,
    /// DC-link divider V_pin/U_dc.
    pub dc_link_ratio: f64,
    /// V_REF+ \[V\].
    pub vref: f64,
    /// The resolver front end's SIN/COS peak at their pins about mid-scale \[V\], at the
    /// excitation's peak and the winding's full coupling.
    pub resolver_amplitude_v: f64,
    /// The over-current comparator's output pin (TIM1_BKIN) and whether it pulls low on
    /// over-current.
    pub break_pin: &'static str,
    /// The comparator's active level is low.
    pub break_active_low: bool,
    /// The resolver excitation output pin (TIM3_CH1).
    pub excitation_pin: &'static str,
    /// PB8 (BOOT0) may be high at a reset: it carries a CAN transceiver's RXD, which
    /// idles high (recessive).
    pub boot0_may_be_high: bool,
    /// The HSE crystal on OSC_IN/OSC_OUT \[Hz\], `None` where none is fitted: HSERDY
    /// follows HSEON only with one (RM0440 §7.4.1).
    pub hse_crystal_hz: Option<f64>,
    /// Low-side shunt sensing: a phase current reaches its pin only while the leg's low
    /// side conducts, and this long \[s\] after the low side switched on (the stage's
    /// settling and the edge's ringing); `None` for in-line sensing, which reads the
    /// current whatever the switches do. The strict rule "ADC sampling inside a switching
    /// edge" (`Soc::convert`) holds every current conversion's sampling phase to it.
    pub low_side_settling_s: Option<f64>,
}

/// The boards this crate has a hardware description of, by board-file stem.
pub fn all() -> Vec<Hardware> {
    vec![
        reference::hardware(),
        reference::hardware_400a(),
        nucleo_ihm08m1::hardware(),
    ]
}

/// The hardware of `boards/<stem>.toml`, if described.
pub fn for_board(stem: &str) -> Option<Hardware> {
    all().into_iter().find(|h| h.board == stem)
}

/// A pin's port index (A = 0) and number, e.g. `PB13` → (1, 13).
pub fn port_pin(pin: &str) -> (u8, u8) {
    let rest = pin.strip_prefix('P').unwrap_or(pin);
    let port = rest.as_bytes().first().copied().unwrap_or(b'A') - b'A';
    let number = rest.get(1..).and_then(|n| n.parse().ok()).unwrap_or(0);
    (port, number)
}

/// The pin name of port index `port`, number `number`.
pub fn pin_name(port: u8, number: u8) -> String {
    format!("P{}{number}", char::from(b'A' + port))
}

impl Hardware {
    /// The chip's pin table.
    pub fn chip_data(&self) -> &'static Chip {
        chip::chip(self.chip).expect("a chip the pin table carries")
    }

    /// The pin ADC `adc` (1 or 2) converts on `channel`, from the chip's table.
    pub fn adc_pin(&self, adc: usize, channel: u8) -> Option<&'static str> {
        let name = format!("ADC{adc}");
        let c = self.chip_data();
        c.pin_names()
            .into_iter()
            .find(|p| c.adc_channel(p, &name) == Some(channel))
    }

    /// The analog input wired to `pin`, if any.
    pub fn analog_at(&self, pin: &str) -> Option<&AnalogInput> {
        self.analog.iter().find(|a| a.pin == pin)
    }

    /// The peripheral signal (e.g. `("TIM1", "CH1N")`) alternate function `af` routes to
    /// `pin`, from the chip's table.
    pub fn af_signal(&self, pin: &str, af: u8) -> Option<(&'static str, &'static str)> {
        self.chip_data()
            .functions(pin)?
            .iter()
            .find(|(_, _, a)| *a == Some(af))
            .map(|(p, s, _)| (*p, *s))
    }

    /// The six gate-driver inputs in the order u/v/w high, u/v/w low.
    pub fn gate_inputs(&self) -> [DriverInput; 6] {
        let l = &self.legs;
        [l[0][0], l[1][0], l[2][0], l[0][1], l[1][1], l[2][1]]
    }

    /// The level that turns each of the six inputs' switches off.
    pub fn off_levels(&self) -> [bool; 6] {
        self.gate_inputs().map(|i| i.logic == Logic::ActiveLow)
    }

    /// Voltage at the ADC pin of phase current `i` \[A\].
    pub fn current_volts(&self, i: f64) -> f64 {
        self.current_offset_v + self.current_gain_v_per_a * i
    }

    /// The measurable phase current, ± \[A\].
    pub fn current_full_scale_a(&self) -> f64 {
        self.current_offset_v.min(self.vref - self.current_offset_v) / self.current_gain_v_per_a.abs()
    }

    /// The measurable DC link \[V\].
    pub fn dc_link_full_scale_v(&self) -> f64 {
        self.vref / self.dc_link_ratio
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every board file in `boards/` has a hardware description, on a chip the pin table
    /// carries, with every pin existing there; every described board has a file.
    #[test]
    fn every_board_has_hardware() {
        let stems = motor_test_support::board_stems();
        for s in &stems {
            let hw = for_board(s).unwrap_or_else(|| panic!("boards/{s}.toml has no hardware description"));
            let c = hw.chip_data();
            let pins = hw
                .gate_inputs()
                .map(|i| i.pin)
                .into_iter()
                .chain(hw.analog.iter().map(|a| a.pin))
                .chain([hw.break_pin, hw.excitation_pin]);
            for p in pins {
                assert!(c.functions(p).is_some(), "{s}: {p} is not a pin of {}", c.name);
            }
        }
        for hw in all() {
            assert!(stems.iter().any(|s| s == hw.board), "{} has no board file", hw.board);
        }
        assert_eq!(port_pin("PB13"), (1, 13));
        assert_eq!(pin_name(2, 6), "PC6");
    }
}
