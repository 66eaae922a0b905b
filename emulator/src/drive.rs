//! The closed loop: `motorgen verify`'s simulated drive ([`motor_sim::plant::Plant`]: the
//! PMSM dq model with the spec's harmonics and L_q saturation, the ideal inverter, the
//! resolver) driven by the bridge duties the image programs into TIM1, and read back
//! through the board's sensing gains at each conversion's instant. The real control
//! interrupt then runs the real control step against the simulated motor.
//!
//! Time is the emulator's: at every TIM1 update event (and MOE change) the plant is
//! integrated up to that instant with the duties that were active, then takes the new
//! ones; a conversion at `t` sees the plant integrated on to `t` (a copy, so the
//! period's integration stays one piece).

use codegen::board::Signal;
use codegen::verify::Setup;
use motor_sim::plant::{Measured, Plant, SpeedProfile};

use crate::soc::Analog;
use crate::wiring::RESOLVER_AMPLITUDE;

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
    gain_v_per_a: f64,
    offset_v: f64,
    divider: f64,
    vref: f64,
    /// Every bridge change, in time order.
    pub samples: Vec<Sample>,
}

impl Drive {
    /// The drive of `setup` (the same machine model `motorgen verify` builds from the
    /// spec and design, resolver pole pairs and offset from the design) at rest at
    /// θ_m = 0, the shaft following `speed`, the nominal DC link, gates off; sensed
    /// through the design's board.
    pub fn new(setup: &Setup<'_>, speed: SpeedProfile) -> Result<Self, String> {
        let d = setup.design;
        let b = &d.board.as_ref().ok_or("the design has no board")?.board;
        Ok(Self {
            plant: setup.plant(speed),
            max_step_s: d.drive.sample_period_s,
            gain_v_per_a: b.current_gain_v_per_a,
            offset_v: b.current_offset_v,
            divider: b.dc_link_divider,
            vref: b.adc_reference_v,
            samples: Vec::new(),
        })
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
    /// The board's sensing: phase current i → offset + gain·i, DC link through its
    /// divider, resolver SIN/COS at mid-scale ± [`RESOLVER_AMPLITUDE`] of half the range
    /// times sin/cos θ_r and the excitation's sign (synchronous demodulation, thesis A
    /// §4.3), as [`crate::wiring::Standstill`] does at θ_r = 0.
    fn volts(&mut self, signal: Signal, t: f64, excitation_high: bool) -> f64 {
        let m = self.measure_at(t);
        let half = self.vref / 2.0;
        let sign = if excitation_high { 1.0 } else { -1.0 };
        let current = |k: usize| self.offset_v + self.gain_v_per_a * m.phase_currents[k];
        match signal {
            Signal::CurrentU => current(0),
            Signal::CurrentV => current(1),
            Signal::CurrentW => current(2),
            Signal::DcLink => m.dc_link * self.divider,
            Signal::ResolverSin => half + RESOLVER_AMPLITUDE * half * sign * m.theta_r.sin(),
            Signal::ResolverCos => half + RESOLVER_AMPLITUDE * half * sign * m.theta_r.cos(),
            _ => 0.0,
        }
    }

    fn bridge(&mut self, t: f64, duties: Option<[f64; 3]>) {
        Self::integrate(&mut self.plant, t, self.max_step_s);
        self.plant.pending = duties.map(|d| d.map(|x| x as f32));
        self.samples.push(Sample {
            t,
            i: self.plant.i,
            duties,
        });
    }
}
