//! The firmware's control step and the simulated drive, stepped together with the
//! timing of thesis A §4.6: at t_n the ADCs sample currents and DC link, the resolver
//! [`Plant::resolver_lag_s`] later (0 without a board); the
//! step computes duties which the timer loads at the next update, so that they act for
//! the period after it — with the update one period after the sample, one period of
//! computation plus the PWM's half-period averaging, the 1.5·T_s the angle lead (4.23)
//! compensates; a board's update comes a little less than a period after its currents'
//! sample, the loop delay its design is made for ([`Plant::loop_delay_periods`]).

use std::f64::consts::PI;

use motor_control::SoftTrig;
use motor_control::angle;
use motor_control::ato::{AtoState, ResolverSample};
use motor_control::step::{AdcSample, ControllerConfig, ControllerState, Demand, StepOutput};

use crate::plant::{Plant, wrap};

/// 2^31: one Q1.31 unit.
pub const Q31: f64 = 2_147_483_648.0;

/// Controller + plant.
#[derive(Clone, Debug)]
pub struct Bench {
    /// The firmware configuration (from the design).
    pub cfg: ControllerConfig,
    /// The firmware state.
    pub state: ControllerState,
    /// The drive.
    pub plant: Plant,
    /// The DC-link voltage the ADC reports if frozen (a failed sensor), else the actual one.
    pub frozen_dc_link: Option<f64>,
    /// Amplitude of the demodulated resolver SIN/COS the controller sees, as a fraction of
    /// Q1.31 full scale (1 here; a board's front end may give less — the trig-identity
    /// observer's gain scales with it, thesis A (4.10)).
    pub resolver_amplitude: f64,
    /// Each phase sensor's true gain relative to the configuration's (1: as configured;
    /// −1: the sensing inverted; 1.2: 20 % high) — a board whose sensing is not what its
    /// file says.
    pub current_gain: [f64; 3],
}

/// One recorded period.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    /// Time of the sample t_n \[s\].
    pub t: f64,
    /// True i_d, i_q at t_n \[A\].
    pub i: [f64; 2],
    /// The controller's output at t_n.
    pub out: StepOutput,
    /// True resolver angle at its sampling instant (t_n + `Plant::resolver_lag_s`) \[rad\].
    pub theta_r: f64,
    /// True electrical angle θ_e(t_n) = n_p·θ_m \[rad\].
    pub theta_e: f64,
    /// True mechanical speed [rad/s].
    pub omega_m: f64,
}

impl Bench {
    /// A bench whose observer starts locked on the true resolver angle and speed (a board
    /// takes a first atan2 of the resolver signals); state at n = −1.
    pub fn new(cfg: ControllerConfig, plant: Plant) -> Self {
        let mut state = ControllerState::new();
        let w_r = plant.resolver_ratio() * plant.omega_m() * plant.ts; // rad per sample
        state.observer = AtoState::locked(
            angle::from_radians_f64(plant.measure().theta_r - w_r),
            (w_r / PI * Q31).round() as i32,
        );
        Self {
            cfg,
            state,
            plant,
            frozen_dc_link: None,
            resolver_amplitude: 1.0,
            current_gain: [1.0; 3],
        }
    }

    /// The ADC sample the controller sees now.
    pub fn adc(&self) -> AdcSample {
        let m = self.plant.measure();
        let cs = &self.cfg.current_sense;
        let code = |i: f64, k: usize| {
            (f64::from(cs.offset[k]) + (i / f64::from(cs.amps_per_lsb[k])).round()).clamp(0.0, 65535.0) as u16
        };
        let q = |x: f64| (x * Q31).round().clamp(-Q31, Q31 - 1.0) as i32;
        let u_dc = self.frozen_dc_link.unwrap_or(m.dc_link);
        let ds = &self.cfg.dc_link_sense;
        AdcSample {
            phase_currents: [
                code(self.current_gain[0] * m.phase_currents[0], 0),
                code(self.current_gain[1] * m.phase_currents[1], 1),
                code(self.current_gain[2] * m.phase_currents[2], 2),
            ],
            resolver: ResolverSample {
                sin: q(self.resolver_amplitude * m.theta_r.sin()),
                cos: q(self.resolver_amplitude * m.theta_r.cos()),
            },
            dc_link: (f64::from(ds.offset) + u_dc / f64::from(ds.volts_per_lsb))
                .round()
                .clamp(0.0, 65535.0) as u16,
        }
    }

    /// One period: sample, control, then the plant runs with the duties the loop delay
    /// makes act ([`Plant::step_with`]).
    pub fn step(&mut self, demand: Demand) -> Sample {
        let sample = self.adc();
        let before = Sample {
            t: self.plant.t,
            i: self.plant.i,
            out: StepOutput::default(),
            theta_r: self.plant.measure().theta_r,
            theta_e: self.plant.theta_e(),
            omega_m: self.plant.omega_m(),
        };
        let out = self.cfg.process(&mut self.state, &mut SoftTrig, &sample, demand);
        self.plant.step_with(match demand {
            Demand::Off => None,
            _ => Some(out.duties),
        });
        Sample { out, ..before }
    }
}

impl Sample {
    /// The electrical angle the controller transforms with, minus the true one, wrapped
    /// \[rad\]: its field-orientation error.
    pub fn angle_error(&self) -> f64 {
        wrap(angle::to_radians_f64(self.out.theta_e) - self.theta_e)
    }
}
