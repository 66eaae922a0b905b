//! Test fixtures: the thesis motors, gains and controller configuration at f_s = 20 kHz,
//! U_dc = 600 V, on the simulated drive of `motor-sim` (the same PMSM model, inverter,
//! ADCs and resolver `motorgen verify` uses; thesis A (2.26), timing of §4.6).
#![allow(dead_code)]

use core::f64::consts::PI;
use motor_control::adc::{CurrentSense, DcLinkSense, MeasuredPhases};
use motor_control::angle::ResolverToElectrical;
use motor_control::ato::{AtoConfig, ObserverError};
use motor_control::feedforward::FeedForwardConfig;
use motor_control::pi::{CurrentPiConfig, PiConfig, VoltageLimit};
use motor_control::step::{ControllerConfig, Demand, StepOutput};
pub use motor_sim::bench::Q31;
pub use motor_sim::figures::StepFigures;
pub use motor_sim::plant::{MotorModel, Plant, Shaft, SpeedProfile};

pub const FS: f64 = 20_000.0;
pub const TS: f64 = 1.0 / FS;
pub const U_DC: f64 = 600.0;
/// ADC: 16-bit (oversampled) bipolar current channels, 5 mA/LSB around 32768.
pub const AMPS_PER_LSB: f64 = 0.005;
pub const CURRENT_OFFSET: i32 = 32768;
pub const VOLTS_PER_LSB: f64 = 0.02;
/// TIM1 at 170 MHz, centre aligned, 20 kHz: ARR = 170e6/(2·20e3) = 4250.
pub const PWM_PERIOD: u16 = 4250;
/// The plant's resolver offset θ_off [rad] (also in [`config`]).
pub const RESOLVER_OFFSET: f64 = 0.3;

/// Electrical parameters of a motor.
#[derive(Clone, Copy, Debug)]
pub struct Motor {
    pub r: f64,
    pub ld: f64,
    pub lq: f64,
    pub psi: f64,
    pub np: u16,
}

impl Motor {
    /// The simulated machine (no harmonics, no saturation).
    pub fn model(self) -> MotorModel {
        MotorModel {
            pole_pairs: u32::from(self.np),
            resistance: self.r,
            ld: self.ld,
            lq: self.lq,
            psi: self.psi,
            l6: 0.0,
            psi_d: [0.0; 2],
            psi_q: [0.0; 2],
            q_saturation: Vec::new(),
        }
    }
}

/// Fischer TI085 (thesis A Table 1.2): R = 0.126 Ω, L = 0.393 mH, n_p = 4;
/// ψ_M ≈ 0.058 Wb.
pub const FISCHER: Motor = Motor {
    r: 0.126,
    ld: 0.393e-3,
    lq: 0.393e-3,
    psi: 0.058,
    np: 4,
};

/// Unimotor 142UMD300 (thesis A Table 6.1): R = 0.65 Ω, L_d = 5.4 mH, L_q = 7.6 mH.
/// n_p = 5 and ψ_M = 0.1 Wb are assumptions (only used at standstill).
pub const UNIMOTOR: Motor = Motor {
    r: 0.65,
    ld: 5.4e-3,
    lq: 7.6e-3,
    psi: 0.1,
    np: 5,
};

/// Observer gains of thesis A §4.4.2 (ω_n = 70 rad/s, ζ = 1), trig identity:
/// K̃_p = 2·1·70/(2e4·π), K̃_i = 70²/(2e4²·π), in Q1.31.
pub fn observer() -> AtoConfig {
    let (wn, zeta) = (70.0f64, 1.0f64);
    let kp = 2.0 * zeta * wn / (FS * PI);
    let ki = wn * wn / (FS * FS * PI);
    AtoConfig {
        kp: fixed::types::I1F31::from_bits((kp * Q31).round() as i32),
        ki: fixed::types::I1F31::from_bits((ki * Q31).round() as i32),
        error: ObserverError::TrigIdentity,
    }
}

/// The controller configuration for `motor` with the given current-loop gains.
pub fn config(motor: Motor, current_loop: CurrentPiConfig) -> ControllerConfig {
    ControllerConfig {
        sample_period: TS as f32,
        speed_per_lsb: (PI * FS / Q31) as f32,
        current_sense: CurrentSense {
            offset: [CURRENT_OFFSET; 3],
            amps_per_lsb: [AMPS_PER_LSB as f32; 3],
            phases: MeasuredPhases::Three,
        },
        dc_link_sense: DcLinkSense {
            offset: 0,
            volts_per_lsb: VOLTS_PER_LSB as f32,
        },
        observer: observer(),
        angle: ResolverToElectrical {
            motor_pole_pairs: motor.np,
            resolver_pole_pairs: 1,
            // θ_off = 0.3 rad (the plant's resolver offset) in π-scaled Q1.31.
            offset: (RESOLVER_OFFSET / PI * Q31).round() as i32,
        },
        angle_lead: 3 << 15, // 1.5 samples, Q16.16
        current_loop,
        feed_forward: FeedForwardConfig {
            ld: motor.ld as f32,
            lq: motor.lq as f32,
            psi_m: motor.psi as f32,
        },
        dc_link_min: 50.0,
        voltage_margin: 1.0,
        pwm_period: PWM_PERIOD,
        max_duty: 1.0,
        torque: motor_control::torque::TorqueConfig::OFF,
    }
}

/// Parallel PI from (k_p, k_i) with back-calculation 1/k_p (2.49).
pub fn pi(kp: f64, ki: f64) -> PiConfig {
    PiConfig::new(kp as f32, ki as f32, (1.0 / kp) as f32)
}

pub fn current_loop(d: PiConfig, q: PiConfig) -> CurrentPiConfig {
    CurrentPiConfig {
        d,
        q,
        limit: VoltageLimit::Proportional,
    }
}

/// A shaft held at `w` [rad/s] (0: blocked rotor).
pub fn fixed_speed(w: f64) -> Shaft {
    Shaft::Imposed(SpeedProfile::constant(w))
}

/// A free shaft at rest with inertia J [kg·m²] and viscous damping b [N·m·s/rad].
pub fn free(inertia: f64, damping: f64) -> Shaft {
    Shaft::Free {
        inertia,
        damping,
        speed: 0.0,
    }
}

/// The drive at rest with `motor`, a one-pole-pair resolver at θ_off = 0.3 rad, the
/// 600 V DC link.
pub fn plant(motor: Motor, shaft: Shaft) -> Plant {
    let mut p = Plant::new(motor.model(), shaft, TS, U_DC);
    p.resolver_offset = RESOLVER_OFFSET;
    p
}

/// The shared bench, plus the last controller output (what the commissioning routines
/// read before their next call).
pub struct Bench {
    pub sim: motor_sim::bench::Bench,
    pub last: StepOutput,
}

impl Bench {
    pub fn new(cfg: ControllerConfig, plant: Plant) -> Self {
        Self {
            sim: motor_sim::bench::Bench::new(cfg, plant),
            last: StepOutput::default(),
        }
    }

    /// One period: sample, control, then the plant runs with the previous duties.
    pub fn step(&mut self, demand: Demand) -> StepOutput {
        self.last = self.sim.step(demand).out;
        self.last
    }
}

impl core::ops::Deref for Bench {
    type Target = motor_sim::bench::Bench;
    fn deref(&self) -> &Self::Target {
        &self.sim
    }
}

impl core::ops::DerefMut for Bench {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.sim
    }
}

/// Step-response figures of currents sampled at T_s.
pub fn step_figures(samples: &[f64], initial: f64, target: f64) -> StepFigures {
    motor_sim::figures::step_figures(samples, TS, initial, target)
}
