//! Identified motor values from recorded commissioning data (thesis A chapter 6), and
//! their write-back into the motor spec's `[motor.identified]` section: the logic of
//! `motorgen identify`, `capture` and `commission`, which only read the files, lock and
//! write the spec, open the bus and print.
//!
//! * [`recording`]: the CSV format of the firmware's captures, parsed with located
//!   errors, and the writer for a `VoltageStep` capture buffer.
//! * [`step`]: R (6.3), τ from the 10–90 % rise time (6.7), L = R·τ (6.8) and the
//!   transport delay (§6.2) from a blocked-rotor voltage step, filtered by the FMAC FIR.
//! * [`flux`]: ψ_M from u_q ≈ ω_e·ψ_M at zero current (6.10).
//! * [`resolver`]: resolver offset θ_off = θ_r after alignment (6.9) and the pole-pair
//!   ratio n_p/n_r with the direction check (§6.4).
//! * [`candump`]: captures sent over CAN (`candump -l` logs or a live socket),
//!   reassembled, checked and turned into recordings.
//! * [`writeback`]: the new values into the spec text with `toml_edit` (comments and
//!   layout kept).
//! * [`identify`]: the whole identification of one routine: a spec's text and its
//!   recordings' and logs' texts ([`Input`]) → the estimates, their spread and the
//!   spec's [`identify::Update`] (`motorgen identify`; `capture`'s CSV files).
//! * [`commission`]: a session on a bus: the options checked into a command
//!   ([`commission::plan`]), the session (command, status, the capture's frames
//!   recorded as a `candump -l` log for [`candump`]), and the captures' CSV files and
//!   identification ([`commission::Plan::run`]) (`motorgen commission`).
//! * [`socket`]: the live bus, a SocketCAN socket (Linux).
//! * [`sim_drive`]: the firmware's commissioning mode on the simulated motor behind the
//!   same bus trait (the simulated bench of the tests).
//! * [`synthetic`]: synthetic recordings of a blocked-rotor step from R and L (thesis A
//!   (6.4) with a transport delay, noise and ADC quantisation), for tests and benchmarks.
//! * [`error`]: why an identification or a session failed ([`Error`]: bad input,
//!   unreadable input, bus unavailable, refused, aborted, timeout), one variant per exit
//!   code of `motorgen`.
//!
//! No file I/O: the front end reads the files into [`Input`]s and writes what comes
//! back; the only I/O here is the CAN socket of [`socket`].
//!
//! May depend on `codegen` (the design core), `motor-control` and `motor-sim`; never on
//! `motor-verify` or `motorgen` (ARCHITECTURE.md).

pub mod candump;
pub mod commission;
pub mod error;
pub mod flux;
pub mod frequency_response;
pub mod identify;
pub mod recording;
pub mod resolver;
pub mod sim_drive;
pub mod socket;
pub mod step;
pub mod synthetic;
pub mod writeback;

pub use error::{Error, Problem};
pub use identify::Input;

/// Mean and spread of one quantity over several recordings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spread {
    /// Arithmetic mean.
    pub mean: f64,
    /// Sample standard deviation (n − 1 in the denominator; 0 for one value).
    pub std_dev: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Number of values.
    pub count: usize,
}

impl Spread {
    /// The spread of `values` (`None` if empty).
    pub fn of(values: &[f64]) -> Option<Spread> {
        let n = values.len();
        if n == 0 {
            return None;
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        let var = if n > 1 {
            values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64
        } else {
            0.0
        };
        Some(Spread {
            mean,
            std_dev: var.sqrt(),
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            count: n,
        })
    }

    /// Standard deviation relative to the mean, in percent.
    pub fn relative_percent(&self) -> f64 {
        100.0 * self.std_dev / self.mean.abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand calculation: mean of 1, 2, 3, 6 is 3; squared deviations 4 + 1 + 0 + 9 = 14,
    /// /3 → s = √(14/3) = 2.1602.
    #[test]
    fn spread_of_four_values() {
        let s = Spread::of(&[1.0, 2.0, 3.0, 6.0]).unwrap();
        assert_eq!((s.mean, s.min, s.max, s.count), (3.0, 1.0, 6.0, 4));
        assert!((s.std_dev - (14.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!(Spread::of(&[2.5]).unwrap().std_dev, 0.0);
        assert!(Spread::of(&[]).is_none());
    }
}
