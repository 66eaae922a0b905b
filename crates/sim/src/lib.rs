//! The simulated drive both sides test the firmware's control step against: `motorgen
//! verify` (codegen) runs its scenarios on it, and the control core's own closed-loop
//! tests (`firmware/control/tests`) use it as a dev-dependency. One model, so the two
//! cannot drift apart.
//!
//! * [`plant`]: a PMSM in rotor (dq) coordinates with optional harmonics and L_q
//!   saturation, an ideal inverter, the ADCs and the resolver; the shaft either follows a
//!   speed profile or turns freely with its inertia.
//! * [`mod@bench`]: the firmware's [`ControllerConfig::process`] and the plant, stepped with
//!   the sampling timing of thesis A §4.6.
//! * [`figures`]: step-response figures (rise time, overshoot, settling) of sampled
//!   signals.
//!
//! Host-only (`std`, `f64`); the control core itself stays `no_std`.
//!
//! [`ControllerConfig::process`]: motor_control::step::ControllerConfig::process

pub mod bench;
pub mod figures;
pub mod plant;
