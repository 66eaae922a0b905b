//! The closed loop: `motorgen verify`'s simulated drive ([`motor_sim::plant::Plant`]: the
//! PMSM dq model with the spec's harmonics and L_q saturation, the ideal inverter, the
//! resolver) driven by the switches the board's gate driver turns on from the pins the
//! image drives ([`crate::bridge`]), and read back through the board's own sensing
//! ([`crate::hardware`]: its sign and gain, not the board file's) at each conversion's
//! instant. The real control interrupt then runs the real control step against the
//! simulated motor.
//!
//! Time is the emulator's: at every TIM1 update event (and MOE change) the plant is
//! integrated up to that instant with the duties that were active, then takes the new
//! ones; a conversion at `t` sees the plant integrated on to `t` (a copy, so the
//! period's integration stays one piece).

use motor_sim::plant::{Measured, Plant, SpeedProfile};
use motor_verify::Setup;

use crate::hardware::{Analog as Signal, Hardware};
use crate::soc::Analog;
use crate::wiring::Sensing;

/// The plant's state at one bridge change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Emulator time \[s\].
    pub t: f64,
    /// True i_d, i_q \[A\].
    pub i: [f64; 2],
    /// The duties applied from `t` on (`None`: not switching).
    pub duties: Option<[f64; 3]>,
}

/// The simulated drive behind the board's analog inputs.
#[derive(Clone, Debug)]
pub struct Drive {
    /// The motor, inverter and resolver (time = emulator time since reset).
    pub plant: Plant,
    /// Longest integration step \[s\]: the design's sample period, for which the plant's
    /// RK4 sub-steps are sized ([`motor_sim::plant::SUBSTEPS`]).
    max_step_s: f64,
    /// The board's sensing (with any defect a test injects).
    pub sensing: Sensing,
    /// Which motor winding each of the bridge's legs u, v, w is connected to (a defect
    /// a test injects: `[0, 2, 1]` is leads v and w swapped at the motor; `[0, 1, 2]` as
    /// wired). The winding gets its leg's voltage; the leg's current sensor measures
    /// that winding's current.
    pub leads: [usize; 3],
    /// Every bridge change, in time order.
    pub samples: Vec<Sample>,
}

impl Drive {
    /// The drive of `setup` (the same machine model `motorgen verify` builds from the
    /// spec and design, resolver pole pairs and offset from the design) at rest at
    /// θ_m = 0, the shaft following `speed`, the nominal DC link, gates off; sensed
    /// through the board's hardware `hw`.
    pub fn new(setup: &Setup<'_>, speed: SpeedProfile, hw: &Hardware) -> Self {
        let d = setup.design;
        let mut plant = setup.plant(speed);
        // The emulated ADCs read the plant at each conversion's own hold instant
        // (`measure_at`): the resolver's lag behind the currents, which verify's bench
        // adds to its single sampling instant, is already in the time.
        plant.resolver_lag_s = 0.0;
        Self {
            plant,
            max_step_s: d.drive.sample_period_s,
            sensing: Sensing::new(hw),
            leads: [0, 1, 2],
            samples: Vec::new(),
        }
    }

    /// Integrates `plant` from its time to `t` \[s\] with its pending duties, in steps of
    /// at most one sample period (a remainder below 1 ps, from rounding, is dropped).
    fn integrate(plant: &mut Plant, t: f64, max_step: f64) {
        while t - plant.t > 1e-12 {
            plant.ts = (t - plant.t).min(max_step);
            plant.advance();
        }
    }

    /// What the sensors see at `t` \[s\] (not before the last bridge change).
    fn measure_at(&self, t: f64) -> Measured {
        if t <= self.plant.t {
            return self.plant.measure();
        }
        let mut p = self.plant.clone();
        Self::integrate(&mut p, t, self.max_step_s);
        p.measure()
    }
}

impl Analog for Drive {
    /// The board's [`Sensing`] of the plant at `t`: its phase currents, DC link and
    /// resolver angle θ_r.
    fn volts(&mut self, signal: Signal, t: f64, excitation: f64) -> f64 {
        let m = self.measure_at(t);
        let by_leg = self.leads.map(|w| m.phase_currents[w]);
        self.sensing.volts(signal, by_leg, m.dc_link, m.theta_r, excitation)
    }

    fn bridge(&mut self, t: f64, duties: Option<[f64; 3]>) {
        Self::integrate(&mut self.plant, t, self.max_step_s);
        self.plant.pending = duties.map(|d| {
            let mut winding = [0.0f32; 3];
            for (leg, &w) in self.leads.iter().enumerate() {
                winding[w] = d[leg] as f32;
            }
            winding
        });
        self.samples.push(Sample {
            t,
            i: self.plant.i,
            duties,
        });
    }
}
