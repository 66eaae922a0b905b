//! Inverter boards: one TOML file per board in `boards/`, resolved into SI values and
//! checked against the microcontroller's own pin data ([`chip`]) before anything is
//! built. Every problem is a located [`Diagnostic`](crate::Diagnostic) like a motor spec's: file,
//! line:column, key, what is wrong, what would be accepted.
//!
//! What is checked: the chip is one we carry data for; every pin exists in its package;
//! every digital signal is on a pin that carries its peripheral function (the
//! alternate-function number comes from the chip data); every analog signal is an
//! input of ADC1 or ADC2 (the two converters the firmware triggers from TIM1); no pin
//! carries two signals; PB8 (BOOT0) only with a stated `[boot0] handling`; the sampling
//! time of every analog input against DS12288 Table 67 for its channel class and source
//! resistance ([`sampling`]); trip levels inside the measurable ranges.
//!
//! This layer knows no motor: a board with a motor (its ADC scalings and trips in the
//! firmware's units, and the checks that need both) is a section of the design,
//! [`crate::design::on_board`].

pub mod chip;
pub mod current;
pub mod gates;
pub mod parts;
mod raw;
pub mod sampling;
mod sequence;

use std::ops::Range;

use serde::Serialize;

use crate::diagnostic::{Diagnostics, Source};
use crate::firmware;
use crate::spec::{Param, Provenance, ResolveContext};
use crate::units::Kind;
use chip::Chip;
pub use current::CurrentSensing;
pub use gates::{GateDriver, GateInput};
pub use raw::{
    Boot0Handling, ComparatorOutput, Direction, InputLogic, InputPull, Placement, Polarity, SampleInstant, SensorKind,
};
use raw::{PinName, RawBoard, RawPins};
pub use sequence::{AdcSlot, Converter};

/// The board `motorgen firmware` and the firmware build use when none is named.
pub const DEFAULT_BOARD: &str = "motorgen-reference";

// Here rather than beside `Home` in `firmware`, which the board module uses and which
// must not use it back (tests/it/layers.rs: no module cycles).
impl crate::firmware::Home {
    /// The file (repository-relative) a firmware-limit case's file is checked and built
    /// with: the default board ([`DEFAULT_BOARD`]) for a spec, fischer-ti085 (the README's
    /// default motor) for a board.
    pub fn partner(self) -> String {
        match self {
            crate::firmware::Home::Spec => format!("boards/{DEFAULT_BOARD}.toml"),
            crate::firmware::Home::Board => "motors/fischer-ti085.toml".to_string(),
        }
    }
}

/// Frames the drive sends or receives after the setpoint identifier: status, command,
/// capture header, capture data, capture end (identifiers setpoint_id + 1 … + 5, the
/// `can` constants group); a board's `can.setpoint_id` leaves room for them.
pub const FRAMES_AFTER_SETPOINT: u16 = 5;

/// The ADC kernel clock the firmware runs the converters at \[Hz\]: HCLK/4 = 170 MHz/4
/// (synchronous clock, ADC12_CCR.CKMODE = 0b11, RM0440 §21.4.3), below the 52 MHz of
/// DS12288 Table 66 for several ADCs at V_DDA ≥ 2.7 V. The firmware checks at compile
/// time that its `hw::ADC_CLOCK_HZ` is this value.
pub const ADC_CLOCK_HZ: f64 = 42.5e6;

/// A signal the firmware needs a pin for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Signal {
    /// Phase u high-side gate.
    GateUHigh,
    /// Phase v high-side gate.
    GateVHigh,
    /// Phase w high-side gate.
    GateWHigh,
    /// Phase u low-side gate.
    GateULow,
    /// Phase v low-side gate.
    GateVLow,
    /// Phase w low-side gate.
    GateWLow,
    /// Over-current comparator → TIM1 break.
    BreakInput,
    /// Resolver excitation (square wave into the excitation amplifier).
    ResolverExcitation,
    /// Resolver SIN winding.
    ResolverSin,
    /// Resolver COS winding.
    ResolverCos,
    /// Phase u current.
    CurrentU,
    /// Phase v current.
    CurrentV,
    /// Phase w current (optional: two phases suffice).
    CurrentW,
    /// DC-link voltage.
    DcLink,
    /// CAN receive.
    CanRx,
    /// CAN transmit.
    CanTx,
}

/// What a signal needs from its pin.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Need {
    /// A peripheral signal on an alternate function, e.g. `("TIM1", "CH1N")`.
    Digital(&'static str, &'static str),
    /// An input of ADC1 or ADC2.
    Analog,
}

impl Signal {
    /// Every signal, in the order of `[pins]`.
    pub const ALL: [Signal; 16] = [
        Signal::GateUHigh,
        Signal::GateVHigh,
        Signal::GateWHigh,
        Signal::GateULow,
        Signal::GateVLow,
        Signal::GateWLow,
        Signal::BreakInput,
        Signal::ResolverExcitation,
        Signal::ResolverSin,
        Signal::ResolverCos,
        Signal::CurrentU,
        Signal::CurrentV,
        Signal::CurrentW,
        Signal::DcLink,
        Signal::CanRx,
        Signal::CanTx,
    ];

    /// Its key in `[pins]`.
    pub fn key(self) -> &'static str {
        match self {
            Signal::GateUHigh => "gate_u_high",
            Signal::GateVHigh => "gate_v_high",
            Signal::GateWHigh => "gate_w_high",
            Signal::GateULow => "gate_u_low",
            Signal::GateVLow => "gate_v_low",
            Signal::GateWLow => "gate_w_low",
            Signal::BreakInput => "break_input",
            Signal::ResolverExcitation => "resolver_excitation",
            Signal::ResolverSin => "resolver_sin",
            Signal::ResolverCos => "resolver_cos",
            Signal::CurrentU => "current_u",
            Signal::CurrentV => "current_v",
            Signal::CurrentW => "current_w",
            Signal::DcLink => "dc_link",
            Signal::CanRx => "can_rx",
            Signal::CanTx => "can_tx",
        }
    }

    /// The peripheral function the firmware drives it with: TIM1 for the gates and the
    /// break (RM0440 §28), TIM3 CH1 for the excitation (locked to TIM1, see the firmware's
    /// `resolver` module), FDCAN1 for CAN, ADC1/ADC2 for the analog inputs.
    pub fn need(self) -> Need {
        match self {
            Signal::GateUHigh => Need::Digital("TIM1", "CH1"),
            Signal::GateVHigh => Need::Digital("TIM1", "CH2"),
            Signal::GateWHigh => Need::Digital("TIM1", "CH3"),
            Signal::GateULow => Need::Digital("TIM1", "CH1N"),
            Signal::GateVLow => Need::Digital("TIM1", "CH2N"),
            Signal::GateWLow => Need::Digital("TIM1", "CH3N"),
            Signal::BreakInput => Need::Digital("TIM1", "BKIN"),
            Signal::ResolverExcitation => Need::Digital("TIM3", "CH1"),
            Signal::CanRx => Need::Digital("FDCAN1", "RX"),
            Signal::CanTx => Need::Digital("FDCAN1", "TX"),
            Signal::ResolverSin
            | Signal::ResolverCos
            | Signal::CurrentU
            | Signal::CurrentV
            | Signal::CurrentW
            | Signal::DcLink => Need::Analog,
        }
    }

    /// Whether a board may leave it out (the third phase current).
    pub fn optional(self) -> bool {
        self == Signal::CurrentW
    }

    /// Its code in the generated ADC sequences (`board::ADCx_SIGNALS`); `u8::MAX` for a
    /// signal that is not an analog input.
    pub fn adc_code(self) -> u8 {
        match self {
            Signal::CurrentU => 0,
            Signal::CurrentV => 1,
            Signal::CurrentW => 2,
            Signal::DcLink => 3,
            Signal::ResolverSin => 4,
            Signal::ResolverCos => 5,
            _ => u8::MAX,
        }
    }

    fn raw(self, p: &RawPins) -> Option<&PinName> {
        match self {
            Signal::GateUHigh => p.gate_u_high.as_ref(),
            Signal::GateVHigh => p.gate_v_high.as_ref(),
            Signal::GateWHigh => p.gate_w_high.as_ref(),
            Signal::GateULow => p.gate_u_low.as_ref(),
            Signal::GateVLow => p.gate_v_low.as_ref(),
            Signal::GateWLow => p.gate_w_low.as_ref(),
            Signal::BreakInput => p.break_input.as_ref(),
            Signal::ResolverExcitation => p.resolver_excitation.as_ref(),
            Signal::ResolverSin => p.resolver_sin.as_ref(),
            Signal::ResolverCos => p.resolver_cos.as_ref(),
            Signal::CurrentU => p.current_u.as_ref(),
            Signal::CurrentV => p.current_v.as_ref(),
            Signal::CurrentW => p.current_w.as_ref(),
            Signal::DcLink => p.dc_link.as_ref(),
            Signal::CanRx => p.can_rx.as_ref(),
            Signal::CanTx => p.can_tx.as_ref(),
        }
    }
}

/// A signal placed on a pin.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PinUse {
    /// The signal.
    pub signal: Signal,
    /// The pin, e.g. `PA8`.
    pub pin: &'static str,
    /// GPIO port index (A = 0) and pin number.
    pub port: u8,
    /// Pin number within the port.
    pub number: u8,
    /// Alternate function (digital signals).
    pub af: Option<u8>,
    /// Byte span of the value in the file.
    #[serde(skip)]
    pub span: Range<usize>,
}

impl PinUse {
    /// `port·16 + number`, the encoding of the generated constants.
    pub fn code(&self) -> u8 {
        self.port * 16 + self.number
    }
}

/// The resolved, checked board.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Board {
    /// File as the user named it.
    pub file: String,
    /// Board name.
    pub name: String,
    /// Part number, e.g. `STM32G474RE`.
    pub chip: &'static str,
    /// Package, e.g. `LQFP64`.
    pub package: &'static str,
    /// Every signal's pin, in [`Signal::ALL`] order (the optional third current may be absent).
    pub pins: Vec<PinUse>,
    /// How BOOT0 is handled (set when a signal uses PB8).
    pub boot0: Option<Boot0Handling>,
    /// Break-input polarity.
    pub break_polarity: Polarity,
    /// The over-current comparator's output stage, if the board states it.
    pub break_output: Option<ComparatorOutput>,
    /// The gate driver's inputs.
    pub gate_driver: GateDriver,
    /// The phase-current sensing, with its signed gain at the ADC pin.
    pub current: CurrentSensing,
    /// HSE crystal frequency \[Hz\], if the board has one (`[clock] hse`).
    pub hse_hz: Option<f64>,
    /// V_REF+ of the ADC \[V\].
    pub adc_reference_v: f64,
    /// DC-link divider ratio V_pin/U_dc.
    pub dc_link_divider: f64,
    /// The resolver's SIN and COS peak at their ADC pins about mid-scale \[V\], at the
    /// excitation's peak and the winding's full coupling (`sensing.resolver_amplitude`;
    /// V_REF/2, the ADC's whole range, where the board does not state it). The
    /// trig-identity observer's loop gain scales with it (thesis A (4.10)).
    pub resolver_amplitude_v: f64,
    /// When the currents are sampled.
    pub sample_instant: SampleInstant,
    /// The injected conversion sequences of ADC1 and ADC2, with each input's sampling.
    pub adc: [Vec<AdcSlot>; 2],
    /// Inverter dead time \[s\].
    pub dead_time_s: f64,
    /// Over-current trip |i| \[A\].
    pub over_current_a: f64,
    /// Over-voltage trip U_dc \[V\].
    pub over_voltage_v: f64,
    /// Over-speed trip \[rad/s\] (mechanical).
    pub over_speed_rad_s: f64,
    /// CAN nominal bit rate \[bit/s\].
    pub can_bit_rate: f64,
    /// Standard identifier of the torque-setpoint frame.
    pub setpoint_id: u16,
    /// Setpoint frame period \[s\].
    pub setpoint_period_s: f64,
    /// Time without a setpoint after which the torque ramps to zero \[s\].
    pub setpoint_timeout_s: f64,
    /// Time the ramp takes from the peak current to zero \[s\].
    pub setpoint_ramp_s: f64,
    /// Torque per LSB of the setpoint frame \[N·m\].
    pub torque_resolution_nm: f64,
    /// Independent-watchdog timeout \[s\].
    pub watchdog_timeout_s: f64,
    /// What the board states that contradicts its parts' datasheets, located at the key
    /// (also printed by `motorgen check`).
    pub warnings: Vec<String>,
    /// Key → span of every value, for design checks located at the board key.
    #[serde(skip)]
    pub spans: Vec<(String, Range<usize>)>,
}

impl Board {
    /// The pin of `signal`, if the board has it.
    pub fn pin(&self, signal: Signal) -> Option<&PinUse> {
        self.pins.iter().find(|p| p.signal == signal)
    }

    /// Span of the value at `key` (0..0 if unknown).
    pub fn span(&self, key: &str) -> Range<usize> {
        self.spans
            .iter()
            .find(|(k, _)| k == key)
            .map_or(0..0, |(_, s)| s.clone())
    }

    /// Full scale of the current measurement \[A\]: the smaller of the two distances from
    /// the zero-current level to the ADC's rails, divided by the gain.
    pub fn current_full_scale_a(&self) -> f64 {
        self.current.offset_v.min(self.adc_reference_v - self.current.offset_v) / self.current.gain_v_per_a.abs()
    }

    /// Full scale of the DC-link measurement \[V\]: V_REF+/ratio.
    pub fn dc_link_full_scale_v(&self) -> f64 {
        self.adc_reference_v / self.dc_link_divider
    }
}

/// Longest injected trigger latency \[ADC cycles\] (DS12288 Table 66, t_LATRINJ with
/// CKMODE = 0b11).
pub const TRIGGER_LATENCY_CYCLES: f64 = 3.125;
/// Successive-approximation cycles of a 12-bit conversion (RM0440 §21.4.12).
pub const CONVERSION_CYCLES: f64 = 12.5;

/// Worst trigger-to-end time of a converter's sequence: latency 3 ADC cycles (DS12288
/// Table 66, t_LATRINJ ≤ 3.125 cycles with CKMODE = 0b11) plus, per rank, sampling +
/// 12.5 conversion cycles (RM0440 §21.4.12: T_CONV = sampling + 12.5 cycles at 12 bits).
pub fn sequence_time(board: &Board, adc_hz: f64) -> f64 {
    board
        .adc
        .iter()
        .map(|q| {
            (TRIGGER_LATENCY_CYCLES + q.iter().map(|s| s.sampling.cycles + CONVERSION_CYCLES).sum::<f64>()) / adc_hz
        })
        .fold(0.0, f64::max)
}

/// The mean instant after the ADC trigger at which the phase currents the firmware uses
/// (u and v, and w where the board senses it) are sampled \[s\]: a rank's input is held
/// at the end of its sampling phase (RM0440 §21.4.12: t_CONV = t_SMPL + t_SAR, the input
/// is sampled during t_SMPL), i.e. after the trigger latency (DS12288 Table 66,
/// t_LATRINJ ≤ 3.125 cycles with CKMODE = 0b11), the ranks before it (sampling + 12.5
/// cycles each) and its own sampling. The d and q currents mix the phases, so the loop
/// sees their mean (a padding repeat of `sequence::lock_step` is not read).
pub fn current_sample_instant(board: &Board, adc_hz: f64) -> f64 {
    let phases: &[Signal] = if board.pin(Signal::CurrentW).is_some() {
        &[Signal::CurrentU, Signal::CurrentV, Signal::CurrentW]
    } else {
        &[Signal::CurrentU, Signal::CurrentV]
    };
    sample_instant(board, phases, adc_hz)
}

/// The mean instant after the ADC trigger at which the resolver's SIN and COS are held
/// \[s\] ([`current_sample_instant`]'s rule): the angle observer's input, which the
/// angle lead (thesis A (4.23)) carries to the voltage's mean.
pub fn resolver_sample_instant(board: &Board, adc_hz: f64) -> f64 {
    sample_instant(board, &[Signal::ResolverSin, Signal::ResolverCos], adc_hz)
}

/// How long after the resolver's SIN its COS is held \[s\] (negative: before; each
/// signal's first rank, [`current_sample_instant`]'s rule). The observer's input is the
/// angle of (sin(θ_r − ε), cos(θ_r + ε)) with ε = ω_r·Δt/2 about the mean instant
/// ([`resolver_sample_instant`]), which is θ_r − ε·cos 2θ_r to first order in ε: a
/// ripple at twice the resolver angle whose amplitude grows with the speed.
pub fn resolver_skew(board: &Board, adc_hz: f64) -> f64 {
    match (
        hold_instant(&board.adc, Signal::ResolverSin, adc_hz),
        hold_instant(&board.adc, Signal::ResolverCos, adc_hz),
    ) {
        (Some(sin), Some(cos)) => cos - sin,
        _ => 0.0,
    }
}

/// The resolver signals' amplitude at the observer's input as a fraction of full scale
/// (the ADC's half range about mid-scale, to which the firmware normalises SIN and COS):
/// the front end's peak `resolver_amplitude_v` over V_REF/2, times the excitation's
/// envelope where SIN and COS are held — the excitation's fundamental peaks at their mean
/// hold instant (`EXCITATION_SHIFT_TICKS`), so windings held Δt apart ([`resolver_skew`])
/// each read cos(π·f_s·Δt/2) of it at f_s/2 excitation (thesis A §4.3). The
/// trig-identity error is this fraction times sin(θ_r − θ̂) (thesis A (4.10)).
pub fn resolver_signal_gain(board: &Board, fs_hz: f64) -> f64 {
    let envelope = (std::f64::consts::PI * fs_hz * resolver_skew(board, ADC_CLOCK_HZ) / 2.0).cos();
    board.resolver_amplitude_v / (board.adc_reference_v / 2.0) * envelope
}

/// When `signal`'s first rank is held after the trigger \[s\]: the trigger latency, the
/// ranks before it (sampling + 12.5 cycles each) and its own sampling; `None` where no
/// sequence converts it.
pub(crate) fn hold_instant(adc: &[Vec<AdcSlot>; 2], signal: Signal, adc_hz: f64) -> Option<f64> {
    adc.iter().find_map(|q| {
        let rank = q.iter().position(|s| s.signal == signal && !s.padding)?;
        let before: f64 = q[..rank].iter().map(|s| s.sampling.cycles + CONVERSION_CYCLES).sum();
        Some((TRIGGER_LATENCY_CYCLES + before + q[rank].sampling.cycles) / adc_hz)
    })
}

/// The mean hold instant of `signals` after the trigger \[s\] (each signal's first rank;
/// 0 for none of them on the board, which its parser refuses for the currents and resolver).
fn sample_instant(board: &Board, signals: &[Signal], adc_hz: f64) -> f64 {
    let held: Vec<f64> = signals
        .iter()
        .filter_map(|&s| hold_instant(&board.adc, s, adc_hz))
        .collect();
    held.iter().sum::<f64>() / held.len().max(1) as f64
}

/// Whether the image must check the BOOT0 option bytes at start-up.
pub fn checks_option_bytes(board: &Board) -> bool {
    board.boot0 == Some(Boot0Handling::OptionBytes)
}

/// The break input's polarity as TIM1_BDTR.BKP (1 = active high, RM0440 §28.6.20).
pub fn break_active_high(board: &Board) -> bool {
    board.break_polarity == Polarity::ActiveHigh
}

/// TIM1_CCER's polarity bits for the board's gate driver ([`gates::ccer_polarity`]).
pub fn tim1_ccer_polarity(board: &Board) -> u32 {
    gates::ccer_polarity(&board.gate_driver)
}

/// TIM1_CR2's idle levels OISx/OISxN for the board's gate driver ([`gates::cr2_idle`]).
pub fn tim1_cr2_idle(board: &Board) -> u32 {
    gates::cr2_idle(&board.gate_driver)
}

/// GPIOx_PUPDR code for the break pin (RM0440 GPIOx_PUPDR: 00 none, 01 pull-up, 10
/// pull-down): with a push-pull comparator none; otherwise (open drain, or an output
/// stage the board does not state) a pull to the inactive level, so that the line is
/// never left floating into TIM1_BKIN — up for an active-low break, down for an
/// active-high one.
pub fn break_pull(board: &Board) -> u8 {
    match (board.break_output, board.break_polarity) {
        (Some(ComparatorOutput::PushPull), _) => 0b00,
        (_, Polarity::ActiveLow) => 0b01,
        (_, Polarity::ActiveHigh) => 0b10,
    }
}

/// Whether the currents are sampled at the carrier maximum (low-side pulse centre).
pub fn samples_at_carrier_maximum(board: &Board) -> bool {
    board.sample_instant == SampleInstant::LowSideCentre
}

/// Example of a complete board file for messages.
const EXAMPLE: &str = "boards/motorgen-reference.toml";

/// Parses, resolves and checks one board file. `source.file` is only used in messages.
pub fn parse(source: Source<'_>) -> Result<Board, Diagnostics> {
    if source.text.trim().is_empty() {
        return Err(source
            .error(
                0..0,
                "",
                "the file is empty",
                format!("a board file with `name`, `chip`, [pins], [break_input], [gate_driver], [current_sensing], [sensing], [pwm], [protection], [can] and [watchdog] (see {EXAMPLE})"),
            )
            .into());
    }
    let raw: RawBoard = crate::spec::deserialize(source, EXAMPLE)?;
    let mut cx = ResolveContext::new(source);
    let board = resolve(&mut cx, &raw);
    match board {
        Some(b) if cx.errors.is_empty() => Ok(b),
        _ => Err(Diagnostics(cx.errors)),
    }
}

/// Whether `text` is a board file rather than a motor spec (it has a top-level `chip`).
pub fn is_board_file(text: &str) -> bool {
    text.parse::<toml::Table>().is_ok_and(|t| t.contains_key("chip"))
}

fn list_pins_with(chip: &Chip, peripheral: &str, signal: &str) -> String {
    let pins = chip.pins_with(peripheral, signal);
    if pins.is_empty() {
        return format!("none: {} has no {peripheral}_{signal}", chip.name);
    }
    pins.iter()
        .map(|(p, af)| match af {
            Some(af) => format!("{p} (AF{af})"),
            None => p.to_string(),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn adc_inputs(chip: &Chip) -> String {
    chip.pin_names()
        .into_iter()
        .filter(|p| chip.adc_channel(p, "ADC1").is_some() || chip.adc_channel(p, "ADC2").is_some())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Port index and pin number of a pin name such as `PB13`.
fn port_and_number(pin: &str) -> Option<(u8, u8)> {
    let rest = pin.strip_prefix('P')?;
    let port = rest.chars().next()?;
    let number: u8 = rest.get(1..)?.parse().ok()?;
    (port.is_ascii_uppercase() && number < 16).then(|| (port as u8 - b'A', number))
}

fn resolve(cx: &mut ResolveContext<'_>, raw: &RawBoard) -> Option<Board> {
    let mut spans = Vec::new();
    let name = raw.name.get_ref().trim().to_string();
    if name.is_empty() {
        cx.err(
            raw.name.span(),
            "name",
            "the board name is empty",
            "a non-empty string such as \"NUCLEO-G474RE + X-NUCLEO-IHM08M1\"",
        );
    }
    let Some(chip) = chip::chip(raw.chip.get_ref().trim()) else {
        cx.err(
            raw.chip.span(),
            "chip",
            format!("\"{}\" is not a chip motorgen has pin data for", raw.chip.get_ref()),
            format!(
                "one of: {} (the firmware targets the STM32G474; other packages need their pin table, see codegen/src/board/chip)",
                chip::CHIPS.iter().map(|c| c.name).collect::<Vec<_>>().join(", ")
            ),
        );
        return None;
    };
    let pins = pins(cx, raw, chip);
    let boot0 = raw.boot0.as_ref().map(|b| *b.get_ref().handling.get_ref());
    if let Some(pins) = &pins {
        boot0_check(cx, raw, pins);
    }

    let q = |cx: &mut ResolveContext<'_>,
             spans: &mut Vec<(String, Range<usize>)>,
             key: &str,
             v: &crate::spec::Val,
             kind: Kind| {
        spans.push((key.to_string(), v.span()));
        cx.quantity(key, v, kind, Provenance::Datasheet, true)
    };
    let s = raw.sensing.get_ref();
    let vref = q(cx, &mut spans, "sensing.adc_reference", &s.adc_reference, Kind::Voltage);
    if let Some(v) = &vref
        && !(2.0..=3.6).contains(&v.value)
    {
        cx.err(
            v.span.clone(),
            "sensing.adc_reference",
            format!("V_REF+ = {} V is outside 2 V … V_DDA ≤ 3.6 V", v.value),
            "the ADC reference the board supplies, 2 V to 3.6 V (DS12288 Table 66), e.g. \"3.3 V\"",
        );
    }
    for (moved, key, to) in [
        (
            &s.current_gain,
            "sensing.current_gain",
            "[current_sensing]: kind, placement, shunt and amplifier_gain (or a Hall sensor's sensitivity and direction), from which the signed gain is derived",
        ),
        (
            &s.current_offset,
            "sensing.current_offset",
            "[current_sensing] offset = \"1.65 V\"",
        ),
    ] {
        if let Some(v) = moved {
            cx.err(
                v.span(),
                key,
                format!("`{key}` is no longer a board fact: the current sensing is described by its parts, whose sign the board's gain alone cannot give (a low-side shunt inverts it)"),
                to,
            );
        }
    }
    let current = current::resolve(cx, &raw.current_sensing, vref.as_ref(), &s.sample_instant, &mut spans);
    let mut part_warnings = Vec::new();
    let gate_driver = gates::resolve(cx, &raw.gate_driver, &mut spans, &mut part_warnings);
    let b = raw.break_input.get_ref();
    let break_polarity = *b.polarity.get_ref();
    spans.push(("break_input.polarity".into(), b.polarity.span()));
    let break_output = b.output.as_ref().map(|o| {
        spans.push(("break_input.output".into(), o.span()));
        if *o.get_ref() == ComparatorOutput::OpenDrain && break_polarity == Polarity::ActiveHigh {
            cx.err(
                o.span(),
                "break_input.output",
                "an open-drain output can only pull the line low, so it cannot signal an active-high break",
                "polarity = \"active_low\" with an open-drain comparator, or output = \"push_pull\"",
            );
        }
        *o.get_ref()
    });
    let hse = raw.clock.as_ref().and_then(|c| c.get_ref().hse.as_ref()).and_then(|v| {
        spans.push(("clock.hse".into(), v.span()));
        let f = cx.quantity("clock.hse", v, Kind::Frequency, Provenance::Datasheet, true)?;
        if !(4e6..=48e6).contains(&f.value) {
            cx.err(
                f.span.clone(),
                "clock.hse",
                format!("{} MHz is outside the HSE oscillator's range", f.value / 1e6),
                "a crystal between 4 MHz and 48 MHz (DS12288 features: 4 to 48 MHz crystal oscillator), e.g. \"24 MHz\"",
            );
            return None;
        }
        Some(f.value)
    });
    spans.push(("sensing.dc_link_divider".into(), s.dc_link_divider.span()));
    let divider = cx.number(
        "sensing.dc_link_divider",
        &s.dc_link_divider,
        0.0,
        1.0,
        "the divider ratio V_pin/U_dc as a plain number between 0 and 1, e.g. 0.0522 for 9.31 kΩ/(169 kΩ + 9.31 kΩ)",
    );
    // The resolver front end's swing: a SIN/COS beyond V_REF/2 about mid-scale clips at
    // the rails, one below a tenth of it leaves the angle fewer than ±205 codes
    // (12 bits, RM0440 §21.4.1): the trig-identity observer's error (4.8) is then
    // coarser than 1/205 rad.
    let amplitude = match (&s.resolver_amplitude, &vref) {
        (Some(v), Some(r)) => {
            spans.push(("sensing.resolver_amplitude".into(), v.span()));
            cx.quantity("sensing.resolver_amplitude", v, Kind::Voltage, Provenance::Datasheet, true)
                .and_then(|a| {
                    let half = r.value / 2.0;
                    if a.value > half || a.value < 0.1 * half {
                        cx.err(
                            a.span.clone(),
                            "sensing.resolver_amplitude",
                            format!(
                                "{} V is outside {:.3} V … {half:.3} V: the SIN/COS peak about mid-scale must fit half the {} V reference and use at least a tenth of it",
                                a.value,
                                0.1 * half,
                                r.value
                            ),
                            format!("the front end's SIN/COS peak at the pin, from its schematic (excitation amplitude × the resolver's transformation ratio × the front end's gain), between {:.3} V and {half:.3} V, e.g. \"1.3 V\"", 0.1 * half),
                        );
                        None
                    } else {
                        Some(a.value)
                    }
                })
        }
        (None, Some(r)) => Some(r.value / 2.0),
        _ => None,
    };
    let sr = s.source_resistance.get_ref();
    let r_current = q(
        cx,
        &mut spans,
        "sensing.source_resistance.current",
        &sr.current,
        Kind::Resistance,
    );
    let r_dc = q(
        cx,
        &mut spans,
        "sensing.source_resistance.dc_link",
        &sr.dc_link,
        Kind::Resistance,
    );
    let r_res = q(
        cx,
        &mut spans,
        "sensing.source_resistance.resolver",
        &sr.resolver,
        Kind::Resistance,
    );
    let cycles = s.sampling_cycles.as_ref().and_then(|v| {
        spans.push(("sensing.sampling_cycles".into(), v.span()));
        cx.number(
            "sensing.sampling_cycles",
            v,
            0.0,
            1e6,
            "one of the ADC_SMPR options 2.5, 6.5, 12.5, 24.5, 47.5, 92.5, 247.5, 640.5 (RM0440 §21.4.12)",
        )
    });
    let fixed_code = match &cycles {
        Some(c) => match sampling::code_of(c.value) {
            Some(code) => Some((code, c.clone())),
            None => {
                cx.err(
                    c.span.clone(),
                    "sensing.sampling_cycles",
                    format!("{} cycles is not an ADC sampling option", c.value),
                    "one of 2.5, 6.5, 12.5, 24.5, 47.5, 92.5, 247.5, 640.5 (RM0440 §21.4.12)",
                );
                None
            }
        },
        None => None,
    };
    let adc = match (&pins, &r_current, &r_dc, &r_res) {
        (Some(pins), Some(rc), Some(rd), Some(rr)) => {
            sequence::plan(cx, raw, chip, pins, [rc, rd, rr], fixed_code.as_ref())
        }
        _ => None,
    };

    let pw = raw.pwm.get_ref();
    let dead = q(cx, &mut spans, "pwm.dead_time", &pw.dead_time, Kind::Time);
    // The firmware's limits (`crate::firmware`): what the image's build could not encode.
    if let Some(d) = &dead
        && let Err(r) = firmware::dead_time(d.value)
    {
        cx.err(d.span.clone(), "pwm.dead_time", r.problem, r.accepted);
    }
    let pr = raw.protection.get_ref();
    let oc = q(
        cx,
        &mut spans,
        "protection.over_current",
        &pr.over_current,
        Kind::Current,
    );
    let ov = q(
        cx,
        &mut spans,
        "protection.over_voltage",
        &pr.over_voltage,
        Kind::Voltage,
    );
    let os = q(cx, &mut spans, "protection.over_speed", &pr.over_speed, Kind::Speed);
    if let (Some(oc), Some(c), Some(v)) = (&oc, &current, &vref) {
        let fs = c.offset_v.min(v.value - c.offset_v) / c.gain_v_per_a.abs();
        if oc.value > fs {
            cx.err(oc.span.clone(), "protection.over_current", format!("{} A is beyond what the board measures, ±{fs:.2} A ({} V reference, {} V at 0 A, {} V/A): the trip could never see it", oc.value, v.value, c.offset_v, c.gain_v_per_a), format!("a trip level up to {fs:.2} A, or a sensor with a lower gain"));
        }
    }
    if let (Some(ov), Some(v), Some(d)) = (&ov, &vref, &divider) {
        let fs = v.value / d.value;
        if ov.value > fs {
            cx.err(
                ov.span.clone(),
                "protection.over_voltage",
                format!(
                    "{} V is beyond what the DC-link divider measures, {fs:.1} V ({} V / {})",
                    ov.value, v.value, d.value
                ),
                format!("a trip level up to {fs:.1} V, or a divider with a smaller ratio"),
            );
        }
    }
    let c = raw.can.get_ref();
    let bit_rate = q(cx, &mut spans, "can.bit_rate", &c.bit_rate, Kind::BitRate);
    if let Some(b) = &bit_rate
        && let Err(r) = firmware::can_bit_rate(firmware::fdcan_kernel_clock_hz(hse), b.value)
    {
        cx.err(b.span.clone(), "can.bit_rate", r.problem, r.accepted);
    }
    spans.push(("can.setpoint_id".into(), c.setpoint_id.span()));
    let id = cx.integer(
        "can.setpoint_id",
        &c.setpoint_id,
        0,
        // The drive's own frames take the identifiers after it (constants group `can`).
        0x7FF - i64::from(FRAMES_AFTER_SETPOINT),
        "a standard (11-bit) identifier 0 … 0x7FA (the drive's status, command and capture frames take the 5 after it), e.g. 0x100",
    );
    if let Some((i, p)) = &id
        && let Err(r) = firmware::setpoint_id(*i as u16, FRAMES_AFTER_SETPOINT)
    {
        cx.err(p.span.clone(), "can.setpoint_id", r.problem, r.accepted);
    }
    let period = q(cx, &mut spans, "can.setpoint_period", &c.setpoint_period, Kind::Time);
    let timeout = q(cx, &mut spans, "can.setpoint_timeout", &c.setpoint_timeout, Kind::Time);
    let ramp = q(cx, &mut spans, "can.setpoint_ramp", &c.setpoint_ramp, Kind::Time);
    let lsb = q(
        cx,
        &mut spans,
        "can.torque_resolution",
        &c.torque_resolution,
        Kind::Torque,
    );
    if let (Some(p), Some(t)) = (&period, &timeout)
        && t.value < p.value
    {
        cx.err(
            t.span.clone(),
            "can.setpoint_timeout",
            format!(
                "a timeout of {} s is shorter than the setpoint period {} s: every frame would time out",
                t.value, p.value
            ),
            "at least one setpoint period, typically three",
        );
    }
    let wd = q(
        cx,
        &mut spans,
        "watchdog.timeout",
        &raw.watchdog.get_ref().timeout,
        Kind::Time,
    );
    if let Some(w) = &wd
        && let Err(r) = firmware::watchdog(w.value)
    {
        cx.err(w.span.clone(), "watchdog.timeout", r.problem, r.accepted);
    }

    Some(Board {
        file: cx.src.file.to_string(),
        name,
        chip: chip.name,
        package: chip.package,
        pins: pins?,
        boot0,
        break_polarity,
        break_output,
        gate_driver: gate_driver?,
        current: current?,
        hse_hz: hse,
        adc_reference_v: vref?.value,
        dc_link_divider: divider?.value,
        resolver_amplitude_v: amplitude?,
        sample_instant: *s.sample_instant.get_ref(),
        adc: adc?,
        dead_time_s: dead?.value,
        over_current_a: oc?.value,
        over_voltage_v: ov?.value,
        over_speed_rad_s: os?.value,
        can_bit_rate: bit_rate?.value,
        setpoint_id: id?.0 as u16,
        setpoint_period_s: period?.value,
        setpoint_timeout_s: timeout?.value,
        setpoint_ramp_s: ramp?.value,
        torque_resolution_nm: lsb?.value,
        watchdog_timeout_s: wd?.value,
        warnings: part_warnings
            .into_iter()
            .map(|(span, key, problem)| located(cx.src, span, &key, &problem))
            .collect(),
        spans,
    })
}

/// `file:line:column: `key`: problem` for a warning at `span`.
fn located(src: Source<'_>, span: Range<usize>, key: &str, problem: &str) -> String {
    let d = src.error(span, key, problem, "");
    format!("{}:{}:{}: `{key}`: {problem}", d.file, d.line, d.column)
}

/// Every signal's pin: exists, carries the function, used once.
fn pins(cx: &mut ResolveContext<'_>, raw: &RawBoard, chip: &'static Chip) -> Option<Vec<PinUse>> {
    let table = raw.pins.get_ref();
    let mut out: Vec<PinUse> = Vec::new();
    let mut seen: Vec<(&'static str, Signal)> = Vec::new();
    let mut ok = true;
    for signal in Signal::ALL {
        let key = format!("pins.{}", signal.key());
        let Some(v) = signal.raw(table) else {
            if !signal.optional() {
                let accepted = match signal.need() {
                    Need::Digital(p, s) => format!("a pin with {p}_{s}: {}", list_pins_with(chip, p, s)),
                    Need::Analog => format!("an ADC1/ADC2 input: {}", adc_inputs(chip)),
                };
                cx.err(
                    raw.pins.span(),
                    &key,
                    format!(
                        "missing required key `{key}`: the firmware needs a pin for {}",
                        signal.key().replace('_', " ")
                    ),
                    accepted,
                );
                ok = false;
            }
            continue;
        };
        let name = v.get_ref().trim();
        let Some(functions) = chip.functions(name) else {
            cx.err(
                v.span(),
                &key,
                format!("\"{name}\" is not a pin of the {} ({})", chip.name, chip.package),
                format!("one of its pins: {}", chip.pin_names().join(", ")),
            );
            ok = false;
            continue;
        };
        let pin = chip.pin_names().into_iter().find(|p| *p == name).unwrap_or("?");
        let _ = functions;
        if let Some(first) = seen.iter().find(|(p, _)| *p == pin) {
            cx.err(
                v.span(),
                &key,
                format!(
                    "two signals on {pin}: `pins.{}` and `pins.{}`",
                    first.1.key(),
                    signal.key()
                ),
                "one pin per signal",
            );
            ok = false;
            continue;
        }
        seen.push((pin, signal));
        let af = match signal.need() {
            Need::Digital(p, s) => match chip.alternate_function(pin, p, s) {
                Some(af) => Some(af),
                None => {
                    cx.err(
                        v.span(),
                        &key,
                        format!(
                            "{pin} has no {p}_{s} function on the {} (alternate functions: {})",
                            chip.name,
                            chip.describe(pin)
                        ),
                        format!("a pin with {p}_{s}: {}", list_pins_with(chip, p, s)),
                    );
                    ok = false;
                    continue;
                }
            },
            Need::Analog => {
                if chip.adc_channel(pin, "ADC1").is_none() && chip.adc_channel(pin, "ADC2").is_none() {
                    cx.err(v.span(), &key, format!("{pin} is not an input of ADC1 or ADC2 ({}); the firmware converts with ADC1 and ADC2 on the PWM trigger", chip.describe(pin)), format!("an ADC1/ADC2 input: {}", adc_inputs(chip)));
                    ok = false;
                    continue;
                }
                None
            }
        };
        let Some((port, number)) = port_and_number(pin) else {
            ok = false;
            continue;
        };
        // The firmware routes alternate functions on GPIOA … GPIOC only.
        if let Need::Digital(p, s) = signal.need()
            && port >= firmware::ROUTED_PORTS
        {
            let on_ports: Vec<String> = chip
                .pins_with(p, s)
                .into_iter()
                .filter(|(q, _)| port_and_number(q).is_some_and(|(k, _)| k < firmware::ROUTED_PORTS))
                .map(|(q, af)| af.map_or(q.to_string(), |af| format!("{q} (AF{af})")))
                .collect();
            cx.err(
                v.span(),
                &key,
                format!(
                    "{pin} is on port {}: the firmware routes its gate, break, excitation and CAN pins on GPIOA … GPIOC only (motor_config::registers::PORTS: clock enables, modes, alternate functions and the fault path's gate writes)",
                    (b'A' + port) as char
                ),
                format!("a pin on port A, B or C with {p}_{s}: {}", on_ports.join(", ")),
            );
            ok = false;
            continue;
        }
        out.push(PinUse {
            signal,
            pin,
            port,
            number,
            af,
            span: v.span(),
        });
    }
    ok.then_some(out)
}

/// PB8 is BOOT0: a signal there needs `[boot0]`, and a CAN receiver cannot hold it low.
fn boot0_check(cx: &mut ResolveContext<'_>, raw: &RawBoard, pins: &[PinUse]) {
    let Some(on_boot0) = pins.iter().find(|p| p.pin == chip::BOOT0_PIN) else {
        return;
    };
    let key = format!("pins.{}", on_boot0.signal.key());
    match raw.boot0.as_ref().map(|b| (b.span(), *b.get_ref().handling.get_ref(), b.get_ref().handling.span())) {
        None => cx.err(
            on_boot0.span.clone(),
            &key,
            "PB8 is BOOT0 on the STM32G474 (DS12288 §3.7, pin PB8-BOOT0): with the factory option bytes (nSWBOOT0 = 1) its level at reset selects the system bootloader instead of the image, and this board does not state how BOOT0 is handled",
            "a [boot0] section: handling = \"option_bytes\" (the image requires nSWBOOT0 = 0, nBOOT0 = 1 and refuses to run otherwise) or \"held_low\" (the board holds PB8 low during reset); or another pin",
        ),
        Some((_, Boot0Handling::HeldLow, span)) if on_boot0.signal == Signal::CanRx => cx.err(
            span,
            "boot0.handling",
            "PB8 carries CAN RX: a CAN transceiver drives RXD high while the bus is idle (recessive), so the board cannot hold BOOT0 low at reset",
            "handling = \"option_bytes\", or CAN RX on another FDCAN1_RX pin",
        ),
        Some(_) => {}
    }
}

/// A located design-time note about a board key (used for motor-vs-board checks).
pub fn warning_at(board: &Board, text: &str, key: &str, problem: &str) -> String {
    let src = Source {
        file: &board.file,
        text,
    };
    located(src, board.span(key), key, problem)
}

/// A resolved value's provenance for the constants (board files are datasheet-like).
pub fn param(value: f64, key: &str) -> Param {
    Param {
        value,
        source: Provenance::Datasheet,
        key: key.into(),
        span: 0..0,
        note: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn board(file: &str, text: &str) -> Result<Board, Diagnostics> {
        parse(Source { file, text })
    }

    /// The reference board (the facts of the old hw.rs): every pin where the README's
    /// table put it, PB8 with its BOOT0 handling, and the slow PA4 (ADC2_IN17) at 24.5
    /// cycles — DS12288 Table 67 for 1.1 kΩ — instead of 2.5 (defect 5).
    #[test]
    fn reference_board() {
        let b = board(
            "boards/motorgen-reference.toml",
            include_str!("../../../../boards/motorgen-reference.toml"),
        )
        .unwrap();
        assert_eq!(b.pin(Signal::GateWLow).map(|p| (p.pin, p.af)), Some(("PB15", Some(4))));
        assert_eq!(
            b.pin(Signal::CanRx).map(|p| (p.pin, p.af, p.code())),
            Some(("PB8", Some(9), 0x18))
        );
        assert_eq!(b.boot0, Some(Boot0Handling::OptionBytes));
        let w = b.adc.iter().flatten().find(|s| s.signal == Signal::CurrentW).unwrap();
        assert_eq!(
            (w.pin, w.channel, w.sampling.fast, w.sampling.cycles),
            ("PA4", 17, false, 24.5)
        );
        // Fast channels at 1.1 kΩ: the 1.5 kΩ row (408.33 ns) → 24.5 cycles too.
        let u = b.adc.iter().flatten().find(|s| s.signal == Signal::CurrentU).unwrap();
        assert_eq!((u.channel, u.sampling.fast, u.sampling.cycles), (1, true, 24.5));
        // SIN and COS on different converters; every current in the first two ranks.
        let conv = |s: Signal| b.adc.iter().position(|q| q.iter().any(|x| x.signal == s));
        assert_ne!(conv(Signal::ResolverSin), conv(Signal::ResolverCos));
        for q in &b.adc {
            for (rank, s) in q.iter().enumerate() {
                if matches!(s.signal, Signal::CurrentU | Signal::CurrentV | Signal::CurrentW) {
                    assert!(rank <= 1, "{:?} at rank {rank}", s.signal);
                }
            }
        }
        // ±1.65 V/15 mV/A = ±110 A; 3.3 V/0.0044 = 750 V.
        assert!((b.current_full_scale_a() - 110.0).abs() < 1e-9);
        assert!((b.dc_link_full_scale_v() - 750.0).abs() < 1e-9);
    }

    /// The NUCLEO-G474RE + X-NUCLEO-IHM08M1: low-side shunts at the low-side centre,
    /// ±min(1.71, 1.59) V/51.8 mV/A = ±30.69 A, 3.3 V/0.05221 = 63.2 V (ST's MC SDK
    /// figure for the board); the divider's 8.82 kΩ on the fast PA1 needs the 12 kΩ row
    /// (4125 ns) → 247.5 cycles at 42.5 MHz (5.82 µs). The parts: L6398 (LIN inverted:
    /// CC1NP..CC3NP, OIS1N..OIS3N, low-side pins high when off), a low-side shunt behind a
    /// non-inverting 5.18 stage (−10 mΩ·5.18 = −51.8 mV/A), the 24 MHz HSE; the currents'
    /// 1 kΩ bound needs DS12288 Table 67's 1.5 kΩ (fast) / 1.2 kΩ (slow) rows, 408.33 ns
    /// → 24.5 cycles at 42.5 MHz (576 ns) on PA0 (fast IN1) and PC1, PC0 (slow IN7, IN6).
    #[test]
    fn nucleo_ihm08m1_board() {
        let b = board(
            "boards/nucleo-g474re-ihm08m1.toml",
            include_str!("../../../../boards/nucleo-g474re-ihm08m1.toml"),
        )
        .unwrap();
        assert_eq!(b.sample_instant, SampleInstant::LowSideCentre);
        assert_eq!(b.pin(Signal::GateULow).map(|p| (p.pin, p.af)), Some(("PA7", Some(6))));
        assert_eq!(b.pin(Signal::BreakInput).map(|p| (p.pin, p.af)), Some(("PA6", Some(6))));
        assert!((b.current.gain_v_per_a + 0.0518).abs() < 1e-12);
        assert!((b.current_full_scale_a() - (3.3 - 1.71) / 0.0518).abs() < 1e-9);
        assert!((b.dc_link_full_scale_v() - 63.206).abs() < 1e-3);
        let dc = b.adc.iter().flatten().find(|s| s.signal == Signal::DcLink).unwrap();
        assert_eq!((dc.pin, dc.sampling.fast, dc.sampling.cycles), ("PA1", true, 247.5));
        for (signal, pin, fast) in [
            (Signal::CurrentU, "PA0", true),
            (Signal::CurrentV, "PC1", false),
            (Signal::CurrentW, "PC0", false),
        ] {
            let s = b.adc.iter().flatten().find(|s| s.signal == signal).unwrap();
            assert_eq!(
                (s.pin, s.sampling.fast, s.sampling.cycles),
                (pin, fast, 24.5),
                "{signal:?}"
            );
        }
        assert_eq!(b.gate_driver.part.as_deref(), Some("L6398"));
        assert_eq!(tim1_ccer_polarity(&b), 0x0888);
        assert_eq!(tim1_cr2_idle(&b), 0x2A00);
        assert_eq!(gates::off_levels(&b.gate_driver), [0, 0, 0, 1, 1, 1]);
        assert_eq!(break_pull(&b), 0b01);
        assert_eq!(b.hse_hz, Some(24e6));
        assert!(b.warnings.is_empty(), "{:?}", b.warnings);
    }

    /// The reference board keeps the facts the firmware assumed: in-phase isolated
    /// drivers (no polarity or idle bit), Hall sensors reading +15 mV/A, no HSE.
    #[test]
    fn reference_board_parts() {
        let b = board(
            "boards/motorgen-reference.toml",
            include_str!("../../../../boards/motorgen-reference.toml"),
        )
        .unwrap();
        assert_eq!((tim1_ccer_polarity(&b), tim1_cr2_idle(&b)), (0, 0));
        assert_eq!(gates::off_levels(&b.gate_driver), [0; 6]);
        assert!((b.current.gain_v_per_a - 0.015).abs() < 1e-12);
        assert_eq!(b.hse_hz, None);
        assert!(!b.gate_driver.interlock && b.gate_driver.dead_time_s.is_none());
    }
}
