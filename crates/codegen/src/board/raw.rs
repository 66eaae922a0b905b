//! A board file exactly as written, before units and chip checks (unknown keys are
//! errors; every value keeps its span for located messages).

use serde::Deserialize;
use serde_spanned::Spanned;

use crate::spec::Val;

/// A pin name as written, e.g. `"PA8"`.
pub type PinName = Spanned<String>;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBoard {
    pub name: Spanned<String>,
    #[serde(default)]
    #[allow(dead_code)]
    pub description: Option<String>,
    pub chip: Spanned<String>,
    pub pins: Spanned<RawPins>,
    #[serde(default)]
    pub boot0: Option<Spanned<RawBoot0>>,
    pub break_input: Spanned<RawBreak>,
    pub gate_driver: Spanned<RawGateDriver>,
    pub current_sensing: Spanned<RawCurrentSensing>,
    pub sensing: Spanned<RawSensing>,
    pub pwm: Spanned<RawPwm>,
    pub protection: Spanned<RawProtection>,
    pub can: Spanned<RawCan>,
    pub watchdog: Spanned<RawWatchdog>,
    #[serde(default)]
    pub clock: Option<Spanned<RawClock>>,
}

/// `[pins]`: one pin per signal (optional here so that a missing one is reported with
/// the pins that could carry it).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPins {
    pub gate_u_high: Option<PinName>,
    pub gate_v_high: Option<PinName>,
    pub gate_w_high: Option<PinName>,
    pub gate_u_low: Option<PinName>,
    pub gate_v_low: Option<PinName>,
    pub gate_w_low: Option<PinName>,
    pub break_input: Option<PinName>,
    pub resolver_excitation: Option<PinName>,
    pub resolver_sin: Option<PinName>,
    pub resolver_cos: Option<PinName>,
    pub current_u: Option<PinName>,
    pub current_v: Option<PinName>,
    pub current_w: Option<PinName>,
    pub dc_link: Option<PinName>,
    pub can_rx: Option<PinName>,
    pub can_tx: Option<PinName>,
}

/// How BOOT0 (PB8) is kept from selecting the bootloader.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Boot0Handling {
    /// The image needs FLASH_OPTR.nSWBOOT0 = 0 and nBOOT0 = 1 (boot from flash whatever
    /// the pin) and checks them at start-up.
    OptionBytes,
    /// The board holds PB8 low while the MCU is in reset.
    HeldLow,
}

/// `[boot0]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBoot0 {
    pub handling: Spanned<Boot0Handling>,
}

/// Polarity of the over-current comparator on the break input.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Polarity {
    /// The comparator pulls the pin low on a fault.
    ActiveLow,
    /// The comparator drives the pin high on a fault.
    ActiveHigh,
}

/// The over-current comparator's output stage.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ComparatorOutput {
    /// Drives both levels (e.g. an op-amp section used as a comparator).
    PushPull,
    /// Only pulls low; the line needs a pull-up to its inactive level.
    OpenDrain,
}

/// `[break_input]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBreak {
    pub polarity: Spanned<Polarity>,
    #[serde(default)]
    pub output: Option<Spanned<ComparatorOutput>>,
}

/// How a gate-driver input turns its switch on.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InputLogic {
    /// A high input turns the switch on (active high).
    InPhase,
    /// A low input turns the switch on (active low).
    Inverted,
}

/// What holds a gate-driver input while nothing drives it (the driver's internal bias or
/// the board's resistor).
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InputPull {
    /// Pulled to ground.
    Down,
    /// Pulled to the logic supply.
    Up,
    /// Nothing: the input floats.
    None,
}

/// `[gate_driver]`: a part of the parts table, or its facts stated one by one (a
/// stated fact wins over the part's and is warned about when it contradicts it).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawGateDriver {
    #[serde(default)]
    pub part: Option<Spanned<String>>,
    #[serde(default)]
    pub high_side_input: Option<Spanned<InputLogic>>,
    #[serde(default)]
    pub low_side_input: Option<Spanned<InputLogic>>,
    #[serde(default)]
    pub high_side_pull: Option<Spanned<InputPull>>,
    #[serde(default)]
    pub low_side_pull: Option<Spanned<InputPull>>,
    #[serde(default)]
    pub interlock: Option<Spanned<bool>>,
    #[serde(default)]
    pub dead_time: Option<Val>,
}

/// What measures the phase currents.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SensorKind {
    /// A shunt resistor and an amplifier.
    Shunt,
    /// A Hall-effect current sensor (or any sensor with a voltage output per ampere).
    Hall,
}

/// Where a shunt sits.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Placement {
    /// Between each leg's low-side switch and ground: carries the phase current only while
    /// the low side conducts.
    LowSide,
    /// In series with the phase, between the leg and the motor terminal.
    Inline,
    /// One shunt in the DC link's return (single-shunt reconstruction).
    DcLink,
}

/// How a Hall sensor's positive current direction is mounted.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// Positive for a current out of the inverter leg into the motor terminal.
    LegToMotor,
    /// Positive for a current from the motor terminal into the leg.
    MotorToLeg,
}

/// `[current_sensing]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCurrentSensing {
    pub kind: Spanned<SensorKind>,
    #[serde(default)]
    pub placement: Option<Spanned<Placement>>,
    #[serde(default)]
    pub shunt: Option<Val>,
    #[serde(default)]
    pub amplifier_gain: Option<Val>,
    #[serde(default)]
    pub sensitivity: Option<Val>,
    #[serde(default)]
    pub direction: Option<Spanned<Direction>>,
    pub offset: Val,
    /// Time the sensed signal needs after a switching edge of its leg before it reads the
    /// phase current (required for low-side shunts: the duty limit).
    #[serde(default)]
    pub settling_time: Option<Val>,
}

/// `[clock]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawClock {
    #[serde(default)]
    pub hse: Option<Val>,
}

/// Where in the PWM period the phase currents are sampled.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SampleInstant {
    /// At the carrier maximum, the centre of the low-side pulse: what low-side shunts need.
    LowSideCentre,
    /// At the carrier minimum, the centre of the high-side pulse (in-line sensors that
    /// prefer to sample away from the low-side switching).
    HighSideCentre,
}

/// `[sensing]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSensing {
    pub adc_reference: Val,
    /// Moved to `[current_sensing]` (refused with a message saying so).
    #[serde(default)]
    pub current_gain: Option<Val>,
    /// Moved to `[current_sensing] offset` (refused with a message saying so).
    #[serde(default)]
    pub current_offset: Option<Val>,
    pub dc_link_divider: Val,
    /// The resolver SIN/COS peak at their pins about mid-scale (optional: V_REF/2).
    #[serde(default)]
    pub resolver_amplitude: Option<Val>,
    pub sample_instant: Spanned<SampleInstant>,
    #[serde(default)]
    pub sampling_cycles: Option<Val>,
    pub source_resistance: Spanned<RawSourceResistance>,
}

/// `[sensing.source_resistance]`: what drives each kind of analog input.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSourceResistance {
    pub current: Val,
    pub dc_link: Val,
    pub resolver: Val,
}

/// `[pwm]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPwm {
    pub dead_time: Val,
}

/// `[protection]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawProtection {
    pub over_current: Val,
    pub over_voltage: Val,
    pub over_speed: Val,
}

/// `[can]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCan {
    pub bit_rate: Val,
    pub setpoint_id: Val,
    pub setpoint_period: Val,
    pub setpoint_timeout: Val,
    pub setpoint_ramp: Val,
    pub torque_resolution: Val,
}

/// `[watchdog]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawWatchdog {
    pub timeout: Val,
}
