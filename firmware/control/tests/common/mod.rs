//! Test bench: a PMSM in dq coordinates (thesis A (2.26)), an ideal inverter with
//! centre-aligned PWM, ADCs and a resolver, all in f64, driving the control step.
//!
//! Timing (thesis A §4.6): at t_n the ADC samples currents and resolver; the step
//! computes duties which the timer loads at the next period, so they act during
//! [t_{n+1}, t_{n+2}) — one period of computation delay plus the PWM's half-period
//! averaging: the 1.5·T_s the angle lead compensates. Within a period the αβ voltage
//! is constant (volt-second average, (3.3)) while the rotor turns, and (2.26) is
//! integrated with RK4 on `SUBSTEPS` sub-steps.
#![allow(dead_code)]

use core::f64::consts::PI;
use motor_control::SoftTrig;
use motor_control::adc::{CurrentSense, DcLinkSense, MeasuredPhases};
use motor_control::angle::ResolverToElectrical;
use motor_control::ato::{AtoConfig, ObserverError, ResolverSample};
use motor_control::feedforward::FeedForwardConfig;
use motor_control::pi::{CurrentPiConfig, PiConfig, VoltageLimit};
use motor_control::step::{AdcSample, ControllerConfig, ControllerState, Demand, StepOutput};

pub const Q31: f64 = 2_147_483_648.0;
pub const FS: f64 = 20_000.0;
pub const TS: f64 = 1.0 / FS;
pub const SUBSTEPS: usize = 10;
pub const U_DC: f64 = 600.0;
/// ADC: 16-bit (oversampled) bipolar current channels, 5 mA/LSB around 32768.
pub const AMPS_PER_LSB: f64 = 0.005;
pub const CURRENT_OFFSET: i32 = 32768;
pub const VOLTS_PER_LSB: f64 = 0.02;
/// TIM1 at 170 MHz, centre aligned, 20 kHz: ARR = 170e6/(2·20e3) = 4250.
pub const PWM_PERIOD: u16 = 4250;

/// Electrical parameters of a motor.
#[derive(Clone, Copy, Debug)]
pub struct Motor {
    pub r: f64,
    pub ld: f64,
    pub lq: f64,
    pub psi: f64,
    pub np: u16,
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

/// How the shaft moves.
#[derive(Clone, Copy, Debug)]
pub enum Mechanics {
    /// Driven (or blocked, ω = 0) at a constant mechanical speed [rad/s].
    FixedSpeed(f64),
    /// Free rotor: J dω/dt = T_e − b·ω.
    Free { inertia: f64, damping: f64 },
}

/// The simulated drive.
pub struct Plant {
    pub motor: Motor,
    pub mech: Mechanics,
    pub id: f64,
    pub iq: f64,
    /// Mechanical angle [rad] (unwrapped) and speed [rad/s].
    pub theta_m: f64,
    pub omega_m: f64,
    /// Resolver: θ_r = sign·n_r·θ_m + offset.
    pub resolver_pole_pairs: f64,
    pub resolver_sign: f64,
    pub resolver_offset: f64,
    /// Duties waiting for the next period (computed at the previous sample).
    pub pending: Option<[f32; 3]>,
}

impl Plant {
    pub fn new(motor: Motor, mech: Mechanics) -> Self {
        let omega_m = match mech {
            Mechanics::FixedSpeed(w) => w,
            Mechanics::Free { .. } => 0.0,
        };
        Self {
            motor,
            mech,
            id: 0.0,
            iq: 0.0,
            theta_m: 0.0,
            omega_m,
            resolver_pole_pairs: 1.0,
            resolver_sign: 1.0,
            resolver_offset: 0.3,
            pending: None,
        }
    }

    pub fn theta_e(&self) -> f64 {
        f64::from(self.motor.np) * self.theta_m
    }

    pub fn theta_r(&self) -> f64 {
        self.resolver_sign * self.resolver_pole_pairs * self.theta_m + self.resolver_offset
    }

    /// What the ADCs and the resolver demodulator see now.
    pub fn sample(&self) -> AdcSample {
        let th = self.theta_e();
        let (s, c) = th.sin_cos();
        let alpha = c * self.id - s * self.iq;
        let beta = s * self.id + c * self.iq;
        let k = 3f64.sqrt() / 2.0;
        let phases = [alpha, -0.5 * alpha + k * beta, -0.5 * alpha - k * beta];
        let code = |i: f64| (f64::from(CURRENT_OFFSET) + (i / AMPS_PER_LSB).round()).clamp(0.0, 65535.0) as u16;
        let q = |x: f64| (x * Q31).round().clamp(-Q31, Q31 - 1.0) as i32;
        let tr = self.theta_r();
        AdcSample {
            phase_currents: phases.map(code),
            resolver: ResolverSample {
                sin: q(tr.sin()),
                cos: q(tr.cos()),
            },
            dc_link: (U_DC / VOLTS_PER_LSB).round() as u16,
        }
    }

    fn derivatives(&self, s: [f64; 4], u_ab: (f64, f64)) -> [f64; 4] {
        let [id, iq, th_m, w_m] = s;
        let m = self.motor;
        let np = f64::from(m.np);
        let th = np * th_m;
        let we = np * w_m;
        let (sn, cs) = th.sin_cos();
        let ud = cs * u_ab.0 + sn * u_ab.1;
        let uq = -sn * u_ab.0 + cs * u_ab.1;
        // (2.26)
        let did = (-m.r * id + ud + we * m.lq * iq) / m.ld;
        let diq = (-m.r * iq + uq - we * (m.ld * id + m.psi)) / m.lq;
        let dw = match self.mech {
            Mechanics::FixedSpeed(_) => 0.0,
            Mechanics::Free { inertia, damping } => {
                // (2.33)
                let te = 1.5 * np * iq * (m.psi + id * (m.ld - m.lq));
                (te - damping * w_m) / inertia
            }
        };
        [did, diq, w_m, dw]
    }

    /// Advances one period with the pending duties (`None` = gates off: the
    /// currents are zero as long as the back EMF stays below U_dc).
    pub fn advance(&mut self) {
        let u_ab = match self.pending {
            Some(d) => {
                let ph = d.map(|x| (f64::from(x) - 0.5) * U_DC);
                let k = 3f64.sqrt() / 2.0;
                (
                    2.0 / 3.0 * (ph[0] - 0.5 * ph[1] - 0.5 * ph[2]),
                    2.0 / 3.0 * k * (ph[1] - ph[2]),
                )
            }
            None => {
                self.id = 0.0;
                self.iq = 0.0;
                (0.0, 0.0)
            }
        };
        let h = TS / SUBSTEPS as f64;
        let mut s = [self.id, self.iq, self.theta_m, self.omega_m];
        let gates_on = self.pending.is_some();
        for _ in 0..SUBSTEPS {
            let add =
                |a: [f64; 4], b: [f64; 4], k: f64| [a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2], a[3] + k * b[3]];
            let k1 = self.derivatives(s, u_ab);
            let k2 = self.derivatives(add(s, k1, h / 2.0), u_ab);
            let k3 = self.derivatives(add(s, k2, h / 2.0), u_ab);
            let k4 = self.derivatives(add(s, k3, h), u_ab);
            for j in 0..4 {
                s[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
            }
            if !gates_on {
                s[0] = 0.0;
                s[1] = 0.0;
            }
        }
        [self.id, self.iq, self.theta_m, self.omega_m] = s;
    }
}

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
            offset: (0.3 / PI * Q31).round() as i32,
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

/// Controller + plant, stepped together.
pub struct Bench {
    pub cfg: ControllerConfig,
    pub state: ControllerState,
    pub plant: Plant,
    pub trig: SoftTrig,
    pub last: StepOutput,
}

impl Bench {
    pub fn new(cfg: ControllerConfig, plant: Plant) -> Self {
        let mut state = ControllerState::new();
        // Observer started on the true resolver angle and speed (a board would take a
        // first atan2 of the resolver signals); state at n = −1.
        let w_i = plant.resolver_sign * plant.resolver_pole_pairs * plant.omega_m / (PI * FS) * Q31;
        let th = plant.theta_r() - plant.resolver_sign * plant.resolver_pole_pairs * plant.omega_m * TS;
        let th = th - 2.0 * PI * ((th + PI) / (2.0 * PI)).floor();
        state.observer = motor_control::ato::AtoState::locked((th / PI * Q31) as i64 as i32, w_i.round() as i32);
        Self {
            cfg,
            state,
            plant,
            trig: SoftTrig,
            last: StepOutput::default(),
        }
    }

    /// One period: sample, control, then the plant runs with the previous duties.
    pub fn step(&mut self, demand: Demand) -> StepOutput {
        let sample = self.plant.sample();
        let out = self.cfg.process(&mut self.state, &mut self.trig, &sample, demand);
        self.plant.advance();
        self.plant.pending = match demand {
            Demand::Off => None,
            _ => Some(out.duties),
        };
        self.last = out;
        out
    }
}

/// Step-response figures of a sampled signal: 10–90 % rise time [s] (linear
/// interpolation between samples) and overshoot relative to the step height.
pub struct StepFigures {
    pub rise_time: f64,
    pub overshoot: f64,
    pub final_error: f64,
}

pub fn step_figures(samples: &[f64], initial: f64, target: f64) -> StepFigures {
    let height = target - initial;
    let crossing = |level: f64| -> f64 {
        let y = initial + level * height;
        for n in 1..samples.len() {
            let (a, b) = (samples[n - 1] - y, samples[n] - y);
            if a * height.signum() < 0.0 && b * height.signum() >= 0.0 {
                return (n - 1) as f64 + a.abs() / (a.abs() + b.abs());
            }
        }
        f64::NAN
    };
    let peak = samples
        .iter()
        .map(|&v| (v - initial) / height)
        .fold(f64::NEG_INFINITY, f64::max);
    StepFigures {
        rise_time: (crossing(0.9) - crossing(0.1)) * TS,
        overshoot: (peak - 1.0).max(0.0),
        final_error: (samples[samples.len() - 1] - target) / height,
    }
}
