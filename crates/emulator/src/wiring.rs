//! The board around the chip, from the board file through codegen (the same data the
//! image is generated from): pins, ADC inputs, sensing gains; and a drive at standstill
//! as the default analog source.

use codegen::board::Signal;
use codegen::design::Design;
use codegen::spec::Spec;

use crate::soc::{Analog, Pin, Wiring};

/// The default board's design for `motor` (`motors/<motor>.toml` on
/// `boards/<default>.toml`).
pub fn design(motor: &str) -> Result<Design, String> {
    let (spec_file, spec) = read(&format!("motors/{motor}.toml"))?;
    let (board_file, board_text) = read(&format!("boards/{}.toml", crate::image::board_for(motor)?))?;
    codegen::design_with_board(&spec_file, &spec, &board_file, &board_text).map_err(|e| e.to_string())
}

/// `motors/<motor>.toml` parsed: the machine data `motorgen verify`'s plant takes beyond
/// the design (harmonics, L_q saturation).
pub fn spec(motor: &str) -> Result<Spec, String> {
    let (file, text) = read(&format!("motors/{motor}.toml"))?;
    codegen::spec::parse(codegen::Source {
        file: &file,
        text: &text,
    })
    .map_err(|e| e.to_string())
}

/// A repository file's name and text.
fn read(file: &str) -> Result<(String, String), String> {
    let text = std::fs::read_to_string(crate::image::repo().join(file)).map_err(|e| format!("{file}: {e}"))?;
    Ok((file.to_string(), text))
}

/// Amplitude of the resolver SIN/COS inputs at the excitation's extremum, as a fraction
/// of half the ADC range around mid-scale. The board file does not state the front end's
/// swing, so this is the test's choice, inside the rails; the image's angle observer
/// scales its trig-identity error with it (thesis A (4.10)), an atan2 error does not.
pub const RESOLVER_AMPLITUDE: f64 = 0.4;

/// The chip's connections on the design's board.
pub fn wiring(d: &Design) -> Result<Wiring, String> {
    let out = d.board.as_ref().ok_or("the design has no board")?;
    let b = &out.board;
    let pin = |s: Signal| -> Result<Pin, String> {
        let p = b.pin(s).ok_or_else(|| format!("the board has no {}", s.key()))?;
        Ok(Pin {
            port: p.port,
            number: p.number,
            af: p.af.unwrap_or(u8::MAX),
        })
    };
    let gates = [
        pin(Signal::GateUHigh)?,
        pin(Signal::GateVHigh)?,
        pin(Signal::GateWHigh)?,
        pin(Signal::GateULow)?,
        pin(Signal::GateVLow)?,
        pin(Signal::GateWLow)?,
    ];
    let adc_inputs = b.adc.clone().map(|q| q.iter().map(|s| (s.channel, s.signal)).collect());
    Ok(Wiring {
        gates,
        break_pin: pin(Signal::BreakInput)?,
        excitation: pin(Signal::ResolverExcitation)?,
        adc_inputs,
        vref: b.adc_reference_v,
        break_idle_high: !codegen::board::break_active_high(b),
    })
}

/// The board's analog front end: what the pins of the sensed signals carry for a given
/// drive state — phase current i → offset + gain·i, the DC link through its divider, the
/// resolver SIN/COS at mid-scale ± [`RESOLVER_AMPLITUDE`] of half the range times
/// sin/cos θ_r and the excitation's sign (synchronous demodulation, thesis A §4.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensing {
    gain_v_per_a: f64,
    offset_v: f64,
    divider: f64,
    vref: f64,
}

impl Sensing {
    /// The sensing of `d`'s board (board file: `current_gain`, `current_offset`,
    /// `dc_link_divider`, `adc_reference`).
    pub fn new(d: &Design) -> Result<Self, String> {
        let b = &d.board.as_ref().ok_or("the design has no board")?.board;
        Ok(Self {
            gain_v_per_a: b.current_gain_v_per_a,
            offset_v: b.current_offset_v,
            divider: b.dc_link_divider,
            vref: b.adc_reference_v,
        })
    }

    /// Voltage at the pin of `signal` with phase currents `currents` \[A\], DC link
    /// `dc_link_v` \[V\], resolver angle `theta_r` \[rad\] and the excitation's level.
    pub fn volts(
        &self,
        signal: Signal,
        currents: [f64; 3],
        dc_link_v: f64,
        theta_r: f64,
        excitation_high: bool,
    ) -> f64 {
        let half = self.vref / 2.0;
        let sign = if excitation_high { 1.0 } else { -1.0 };
        let current = |k: usize| self.offset_v + self.gain_v_per_a * currents[k];
        match signal {
            Signal::CurrentU => current(0),
            Signal::CurrentV => current(1),
            Signal::CurrentW => current(2),
            Signal::DcLink => dc_link_v * self.divider,
            Signal::ResolverSin => half + RESOLVER_AMPLITUDE * half * sign * theta_r.sin(),
            Signal::ResolverCos => half + RESOLVER_AMPLITUDE * half * sign * theta_r.cos(),
            _ => 0.0,
        }
    }
}

/// The inverter at standstill: phase currents `currents` \[A\] and the DC link at
/// `dc_link_v` through the board's [`Sensing`], the resolver at rotor angle 0 (SIN at
/// mid-scale, COS at [`RESOLVER_AMPLITUDE`] of half the range times the excitation's
/// sign).
#[derive(Clone, Debug)]
pub struct Standstill {
    /// Phase currents u, v, w \[A\].
    pub currents: [f64; 3],
    /// DC-link voltage \[V\].
    pub dc_link_v: f64,
    sensing: Sensing,
}

impl Standstill {
    /// Zero current at the motor's nominal DC-link voltage.
    pub fn new(d: &Design) -> Result<Self, String> {
        Ok(Self {
            currents: [0.0; 3],
            dc_link_v: d.drive.dc_link_voltage_v,
            sensing: Sensing::new(d)?,
        })
    }
}

impl Analog for Standstill {
    fn volts(&mut self, signal: Signal, _t: f64, excitation_high: bool) -> f64 {
        self.sensing
            .volts(signal, self.currents, self.dc_link_v, 0.0, excitation_high)
    }
}
