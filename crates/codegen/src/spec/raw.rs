//! The motor spec exactly as written in TOML, before units and rules are applied.
//!
//! Every table rejects unknown keys (typos are errors, not ignored settings) and
//! every value keeps its byte span so later checks can point at its line.

use serde::Deserialize;
use serde_spanned::Spanned;

/// Any value whose type and unit are checked after parsing (quantities, numbers).
pub type Val = Spanned<toml::Value>;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSpec {
    pub name: Spanned<String>,
    #[serde(default)]
    pub description: Option<String>,
    pub motor: Spanned<RawMotor>,
    pub resolver: Spanned<RawResolver>,
    pub drive: Spanned<RawDrive>,
    pub current_loop: Spanned<RawCurrentLoop>,
    pub angle_observer: Spanned<RawAngleObserver>,
    pub fir: Spanned<RawFir>,
    #[serde(default)]
    pub scaling: Option<Spanned<RawScaling>>,
    #[serde(default)]
    pub adc: Option<Spanned<RawAdc>>,
    #[serde(default)]
    pub thermal: Option<Spanned<RawThermal>>,
    #[serde(default)]
    pub inverter: Option<Spanned<RawInverter>>,
    #[serde(default)]
    pub field_weakening: Option<Spanned<RawFieldWeakening>>,
    #[serde(default)]
    pub losses: Option<Spanned<RawLosses>>,
    #[serde(default)]
    pub sensorless: Option<Spanned<RawSensorless>>,
}

/// `[motor]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawMotor {
    pub pole_pairs: Val,
    #[serde(default)]
    pub connection: Option<Spanned<Connection>>,
    #[serde(default)]
    pub datasheet: Option<Spanned<RawParams>>,
    #[serde(default)]
    pub identified: Option<Spanned<RawParams>>,
    #[serde(default)]
    pub harmonics: Option<Spanned<RawHarmonics>>,
    #[serde(default)]
    pub saturation: Option<Spanned<RawSaturation>>,
}

/// Winding connection. Values written as plain strings are star-equivalent phase values
/// whatever the connection; it matters for values given `measured = "winding"` (one delta
/// winding is not a star-equivalent phase).
#[derive(Debug, Clone, Copy, Deserialize, serde::Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Connection {
    /// Y.
    Star,
    /// Δ.
    Delta,
}

/// `[motor.datasheet]` and `[motor.identified]`: the same keys; identified wins key by key.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawParams {
    pub phase_resistance: Option<Val>,
    pub inductance: Option<Val>,
    pub d_inductance: Option<Val>,
    pub q_inductance: Option<Val>,
    pub flux_linkage: Option<Val>,
    pub torque_constant: Option<Spanned<RawTorqueConstant>>,
    pub back_emf_constant: Option<Spanned<RawBackEmfConstant>>,
    pub speed_constant: Option<Spanned<RawSpeedConstant>>,
    pub nominal_current: Option<Val>,
    pub peak_current: Option<Val>,
    pub nominal_torque: Option<Val>,
    pub peak_torque: Option<Val>,
    pub nominal_speed: Option<Val>,
    pub rated_frequency: Option<Val>,
    pub rated_power: Option<Val>,
    pub max_speed: Option<Val>,
    pub inertia: Option<Val>,
    pub viscous_friction: Option<Val>,
    pub resolver_offset: Option<Val>,
    /// When the values were identified (free text or a TOML date).
    pub date: Option<toml::Value>,
    /// Which recordings they were identified from.
    pub source: Option<toml::Value>,
}

/// `torque_constant = { value = "0.492 N·m/A", current = "rms" }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTorqueConstant {
    pub value: Val,
    pub current: Spanned<Amplitude>,
}

/// `back_emf_constant = { value = "0.296 V·s/rad", voltage = "rms", measured = "line_to_line", speed = "mechanical" }`;
/// `measured` is required for rms and peak voltages and implied for `block_commutation`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBackEmfConstant {
    pub value: Val,
    pub voltage: Spanned<Amplitude>,
    #[serde(default)]
    pub measured: Option<Spanned<Between>>,
    pub speed: Spanned<SpeedAxis>,
}

/// `speed_constant = { value = "259 rpm/V", voltage = "block_commutation" }`: the speed per
/// volt of induced voltage, the reciprocal of a back-EMF constant (maxon's k_n). `speed`
/// defaults to mechanical (a shaft speed, as rpm is).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSpeedConstant {
    pub value: Val,
    pub voltage: Spanned<Amplitude>,
    #[serde(default)]
    pub measured: Option<Spanned<Between>>,
    #[serde(default)]
    pub speed: Option<Spanned<SpeedAxis>>,
}

/// Which current or voltage a datasheet motor constant refers to.
#[derive(Debug, Clone, Copy, Deserialize, serde::Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Amplitude {
    /// Root mean square of the sinusoidal phase quantity.
    Rms,
    /// Peak (amplitude) of the sinusoidal phase quantity.
    Peak,
    /// The DC supply current / induced DC voltage of 120° block commutation (maxon's k_M,
    /// k_n): two phases conduct, the supply sees the line-to-line back EMF.
    BlockCommutation,
}

/// Between which terminals a value is measured.
#[derive(Debug, Clone, Copy, Deserialize, serde::Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Between {
    /// Line to line (terminal to terminal).
    LineToLine,
    /// Phase: line to neutral, the star-equivalent phase.
    Phase,
    /// Across one winding: the phase in star, line to line in delta (needs `[motor]
    /// connection`).
    Winding,
}

/// Whether a per-speed constant refers to mechanical or electrical rad/s.
#[derive(Debug, Clone, Copy, Deserialize, serde::Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SpeedAxis {
    /// Per mechanical rad/s (shaft).
    Mechanical,
    /// Per electrical rad/s.
    Electrical,
}

/// `[motor.harmonics]`: flux-linkage and inductance harmonics (thesis B 2.14–2.16).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawHarmonics {
    pub d_flux_6: Option<Val>,
    pub d_flux_12: Option<Val>,
    pub q_flux_6: Option<Val>,
    pub q_flux_12: Option<Val>,
    pub inductance_6: Option<Val>,
}

/// `[motor.saturation]`: L_q as a function of |i_q| (thesis B 2.25), piecewise linear.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSaturation {
    pub q_inductance: Vec<Spanned<RawCurvePoint>>,
}

/// One point of the L_q(|i_q|) curve.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCurvePoint {
    pub current: Val,
    pub inductance: Val,
}

/// `[resolver]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawResolver {
    pub pole_pairs: Val,
    #[serde(default)]
    pub offset: Option<Val>,
}

/// `[drive]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDrive {
    pub switching_frequency: Val,
    pub dc_link_voltage: Val,
    #[serde(default)]
    pub dc_link_voltage_min: Option<Val>,
    #[serde(default)]
    pub dead_time: Option<Val>,
    /// Largest shaft acceleration the drive must follow (mechanical).
    #[serde(default)]
    pub max_acceleration: Option<Val>,
    /// What the drive moves, for the default of `max_acceleration`.
    #[serde(default)]
    pub application: Option<Spanned<Application>>,
}

/// What the drive moves: chooses the default largest acceleration
/// (`design::acceleration`).
#[derive(Debug, Clone, Copy, Deserialize, serde::Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Application {
    /// A vehicle (both theses): the top speed in 10 s.
    Traction,
    /// A servo axis: peak torque into the rotor and a load of ten times its inertia.
    Servo,
    /// A robot joint actuator: the top speed in 0.1 s.
    Robot,
}

/// Current-loop tuning method.
#[derive(Debug, Clone, Copy, Deserialize, serde::Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// First-order internal model control, thesis A (5.9).
    Imc,
    /// Second-order pole placement, thesis A (5.14), (5.15).
    PolePlacement,
    /// IMC with decoupling and active damping, thesis B (2.38), (2.39), (2.43).
    ImcActiveDamping,
}

/// `[current_loop]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCurrentLoop {
    pub method: Spanned<Method>,
    pub bandwidth: Val,
    #[serde(default)]
    pub damping: Option<Val>,
    /// Lower α per axis so the sampled loop with its loop delay (1.5·T_s, or the board's) rises in ln 9/α.
    #[serde(default)]
    pub compensate_delay: Option<Spanned<bool>>,
}

/// Observer error architecture.
#[derive(Debug, Clone, Copy, Deserialize, serde::Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ObserverError {
    /// TRIGIDEN: sin θ_r cos θ̂ − cos θ_r sin θ̂ (4.8).
    TrigIdentity,
    /// CORDIC atan2, error normalised by π.
    Atan2,
}

/// `[angle_observer]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAngleObserver {
    pub natural_frequency: Val,
    pub damping: Val,
    pub error: Spanned<ObserverError>,
    #[serde(default)]
    pub lead_samples: Option<Val>,
}

/// `[fir]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFir {
    pub pass_edge: Val,
    pub stop_edge: Val,
    pub pass_ripple: Val,
    #[serde(default)]
    pub order: Option<Val>,
    #[serde(default)]
    pub stop_attenuation: Option<Val>,
}

/// `[scaling]`: headroom of the fixed-point full scales over the ratings.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScaling {
    #[serde(default)]
    pub margin: Option<Val>,
}

/// `[adc]`: sample-and-hold circuit for the settling-time rule (7.2), (7.4).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAdc {
    #[serde(default)]
    pub resolution_bits: Option<Val>,
    pub clock: Val,
    pub sample_capacitance: Val,
    pub switch_resistance: Val,
    pub source_resistance: Val,
}

/// `[thermal]`: winding temperatures for the hot-resistance variant (thesis B 2.24).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawThermal {
    #[serde(default)]
    pub reference_temperature: Option<Val>,
    pub max_winding_temperature: Val,
}

/// `[inverter]`: switch data for the loss model (thesis B 3.11–3.14, Table B.3).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawInverter {
    #[serde(default)]
    pub part: Option<String>,
    pub nominal_current: Val,
    pub transistor_resistance: Val,
    pub transistor_threshold: Val,
    pub switching_energy: Val,
    pub diode_resistance: Val,
    pub diode_threshold: Val,
    pub recovery_energy: Val,
}

/// `[field_weakening]`: the field-weakening loop's inputs (thesis B §2.3.3).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFieldWeakening {
    /// V'_max/V_max, 0 < x < 1.
    #[serde(default)]
    pub voltage_fraction: Option<Val>,
    /// α_s of a closed speed loop, if the drive has one.
    #[serde(default)]
    pub speed_loop_bandwidth: Option<Val>,
}

/// `[losses]`: the loss model's inputs (thesis B chapter 3).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLosses {
    /// R_c of Fig. 2.7.
    #[serde(default)]
    pub core_resistance: Option<Val>,
    /// Include the inverter losses (3.11)–(3.14) of `[inverter]`.
    #[serde(default)]
    pub include_inverter: Option<Spanned<bool>>,
}

/// `[sensorless]`: the sensorless estimator's inputs (thesis B chapter 4).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSensorless {
    /// ρ, explicit (exclusive with `max_acceleration`).
    #[serde(default)]
    pub bandwidth: Option<Val>,
    /// Largest shaft acceleration |dω_m/dt| the estimator must track (4.74).
    #[serde(default)]
    pub max_acceleration: Option<Val>,
    /// Allowed transient angle error θ̃_max (4.74), (4.69).
    #[serde(default)]
    pub max_angle_error: Option<Val>,
    /// Carrier ω_e of the signal injection (4.34).
    #[serde(default)]
    pub injection_frequency: Option<Val>,
    /// Carrier amplitude V_e (4.35).
    #[serde(default)]
    pub injection_voltage: Option<Val>,
    /// High-pass ω_hp of the demodulation (Table 4.1).
    #[serde(default)]
    pub highpass: Option<Val>,
    /// Low-pass ω_lp of the demodulation (Table 4.1).
    #[serde(default)]
    pub lowpass: Option<Val>,
    /// R̃_s/R_s assumed for ω_min2 (4.69).
    #[serde(default)]
    pub resistance_error: Option<Val>,
    /// Allowed speed-estimate noise ω_ν at base current for (4.24).
    #[serde(default)]
    pub speed_noise: Option<Val>,
}
