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
    pub sensing: Spanned<RawSensing>,
    pub pwm: Spanned<RawPwm>,
    pub protection: Spanned<RawProtection>,
    pub can: Spanned<RawCan>,
    pub watchdog: Spanned<RawWatchdog>,
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

/// `[break_input]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBreak {
    pub polarity: Spanned<Polarity>,
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
    pub current_gain: Val,
    pub current_offset: Val,
    pub dc_link_divider: Val,
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
