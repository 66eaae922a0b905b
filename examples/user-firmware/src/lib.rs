//! What a user's firmware crate looks like when its constants come from the proc-macros
//! (README, "Constants as code"): the motor's whole generated module from its spec, and
//! the few gains a developer states by hand as physical intent — a current loop at a
//! bandwidth, an observer at a natural frequency, a Q1.31 literal — computed at compile
//! time by the same design functions and rules as `motorgen check` and `design`.
//!
//! `no_std`, no heap: it builds for `thumbv7em-none-eabihf` as it does for the host. The
//! paths are relative to this crate's `Cargo.toml`.

#![no_std]

use fixed::types::I1F31;
use motor_control::ato::{AtoConfig, ObserverError};
use motor_control::pi::{CurrentPiConfig, PiConfig, VoltageLimit};

/// The Fischer TI085's generated module, as `motorgen design motors/fischer-ti085.toml
/// --format rust` prints it (`current_loop::D_KP`, `observer::KP`, …); editing the
/// spec recompiles this crate.
pub mod fischer {
    motor_macros::motor_constants!("../../motors/fischer-ti085.toml");
}

/// The current loop of thesis A's Fischer motor stated as intent: IMC at α = 100 rad/s
/// with its R = 0.126 Ω and L = 0.393 mH (Table 1.2) at f_s = 20 kHz, delay-compensated
/// as a spec is by default. `(K_p [V/A], K_i [V/(A·s)])`; a bandwidth `motorgen check`
/// refuses (e.g. 37 699 rad/s here) does not compile.
pub const CURRENT_PI: (f32, f32) = motor_macros::pi_gains!(
    method = imc,
    resistance = "0.126 Ω",
    inductance = "0.393 mH",
    bandwidth = "100 rad/s",
    fs = "20 kHz"
);

/// The angle observer of thesis A §4.4.2: ω_n = 70 rad/s, ζ = 1, trig-identity error at
/// f_s = 20 kHz; `(K̃_p, K̃_i)` pre-scaled for Q1.31 (4.22).
pub const OBSERVER_GAINS: (I1F31, I1F31) = motor_macros::ato_gains!(
    natural_frequency = "70 rad/s",
    damping = 1.0,
    fs = "20 kHz",
    error = trig_identity
);

/// Half of full scale in Q1.31, written as the number it is.
pub const HALF: I1F31 = motor_macros::q31!(0.5);

/// Both current controllers from [`CURRENT_PI`] (L_d = L_q on this motor), with the
/// back-calculation anti-windup gain 1/K_p (thesis B (2.49)).
pub const CURRENT_LOOP: CurrentPiConfig = CurrentPiConfig {
    d: PiConfig::new(CURRENT_PI.0, CURRENT_PI.1, 1.0 / CURRENT_PI.0),
    q: PiConfig::new(CURRENT_PI.0, CURRENT_PI.1, 1.0 / CURRENT_PI.0),
    limit: VoltageLimit::Proportional,
};

/// The observer configuration from [`OBSERVER_GAINS`].
pub const OBSERVER: AtoConfig = AtoConfig {
    kp: OBSERVER_GAINS.0,
    ki: OBSERVER_GAINS.1,
    error: ObserverError::TrigIdentity,
};
