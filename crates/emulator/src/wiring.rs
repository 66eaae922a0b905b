//! The image's design (motor and board file, the data the image is generated from) for
//! the tests' setpoints and criteria, and the board's analog front end as the emulated
//! hardware has it ([`crate::hardware`], not the board file): a drive at standstill as
//! the default analog source.

use std::sync::{Mutex, PoisonError};

use codegen::design::Design;
use codegen::spec::Spec;

use crate::hardware::{Analog as Signal, Hardware};
use crate::soc::Analog;

/// The design of `motors/<motor>.toml` on the board file `board_file` with text
/// `board_text` (what the image is built from), computed once per process for each
/// pair and board text (`DESIGNS`).
pub fn design(motor: &str, board_file: &str, board_text: &str) -> Result<Design, String> {
    let key = (motor.to_string(), board_file.to_string(), board_text.to_string());
    let known = |designs: &DesignCache| designs.iter().find(|(k, _)| *k == key).map(|(_, d)| d.clone());
    if let Some(d) = known(&DESIGNS.lock().unwrap_or_else(PoisonError::into_inner)) {
        return d;
    }
    // Designed outside the lock: the other test thread may design another pair meanwhile.
    let (spec_file, spec) = read(&format!("motors/{motor}.toml"))?;
    let d = codegen::design_with_board(&spec_file, &spec, board_file, board_text).map_err(|e| e.to_string());
    DESIGNS
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .push((key, d.clone()));
    d
}

/// (motor, board file, board text) and the design of the pair.
type DesignCache = Vec<((String, String, String), Result<Design, String>)>;

/// The designs [`design`] has computed in this process. The test binary builds well over
/// a hundred rigs of about twenty pairs, and designing a pair (the FIR's Remez searches,
/// the loss-minimisation table) took two thirds of a closed-loop scenario's CPU time
/// (`perf`, issue 29); a pair's design cannot change while the process runs (its inputs
/// are the repository's files and the variant's text in the key).
static DESIGNS: Mutex<DesignCache> = Mutex::new(Vec::new());

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
pub fn read(file: &str) -> Result<(String, String), String> {
    let text = std::fs::read_to_string(crate::image::repo().join(file)).map_err(|e| format!("{file}: {e}"))?;
    Ok((file.to_string(), text))
}

/// The board's analog front end as the hardware has it: what the pins of the sensed
/// signals carry for a given drive state — phase current i → the board's zero level +
/// its signed gain·i, the DC link through its divider, the resolver SIN/COS at mid-scale
/// ± the front end's amplitude (`Hardware::resolver_amplitude_v`) times sin/cos θ_r and the excitation at the
/// instant the ADC holds them (the envelope the synchronous demodulation samples, thesis A
/// §4.3).
#[derive(Clone, Debug, PartialEq)]
pub struct Sensing {
    hw: Hardware,
    /// An error of each phase's zero-current level against the hardware description's
    /// \[V\] (a defect a test injects: an offset resistor off its value, an amplifier's
    /// input offset; zero for the board as described).
    pub zero_error_v: [f64; 3],
    /// Each phase's gain against the hardware description's (a defect a test injects:
    /// −1 for a sensor mounted or wired the other way round; 1 for the board as
    /// described).
    pub gain_error: [f64; 3],
}

impl Sensing {
    /// The sensing of `hw`.
    pub fn new(hw: &Hardware) -> Self {
        Self {
            hw: hw.clone(),
            zero_error_v: [0.0; 3],
            gain_error: [1.0; 3],
        }
    }

    /// Voltage at the pin of `signal` with phase currents `currents` \[A\], DC link
    /// `dc_link_v` \[V\], resolver angle `theta_r` \[rad\] and the excitation (±1 at its
    /// peaks).
    pub fn volts(&self, signal: Signal, currents: [f64; 3], dc_link_v: f64, theta_r: f64, excitation: f64) -> f64 {
        let half = self.hw.vref / 2.0;
        match signal {
            Signal::Current(k) => self.hw.current_volts(self.gain_error[k] * currents[k]) + self.zero_error_v[k],
            Signal::DcLink => dc_link_v * self.hw.dc_link_ratio,
            Signal::Sin => half + self.hw.resolver_amplitude_v * excitation * theta_r.sin(),
            Signal::Cos => half + self.hw.resolver_amplitude_v * excitation * theta_r.cos(),
        }
    }
}

/// The inverter at standstill: phase currents `currents` \[A\] and the DC link at
/// `dc_link_v` through the board's [`Sensing`], the resolver at rotor angle 0 (SIN at
/// mid-scale, COS at the front end's amplitude times the excitation).
#[derive(Clone, Debug)]
pub struct Standstill {
    /// Phase currents u, v, w \[A\].
    pub currents: [f64; 3],
    /// DC-link voltage \[V\].
    pub dc_link_v: f64,
    /// The board's sensing (its zero-level errors may be set).
    pub sensing: Sensing,
}

impl Standstill {
    /// Zero current at the motor's nominal DC-link voltage, on `hw`.
    pub fn new(d: &Design, hw: &Hardware) -> Self {
        Self {
            currents: [0.0; 3],
            dc_link_v: d.drive.dc_link_voltage_v,
            sensing: Sensing::new(hw),
        }
    }
}

impl Analog for Standstill {
    fn volts(&mut self, signal: Signal, _t: f64, excitation: f64) -> f64 {
        self.sensing
            .volts(signal, self.currents, self.dc_link_v, 0.0, excitation)
    }
}
