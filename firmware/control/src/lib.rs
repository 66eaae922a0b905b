//! Portable control core of the STM32G474 motor-controller firmware.
//!
//! Field-oriented current control of a PMSM with resolver feedback, after
//! thesis A (STM32G474 Formula Student controller: transforms §2.1, THPWM §3.2,
//! angle tracking observer §4.4, feed-forward and PI design chapter 5, commissioning
//! chapter 6) and thesis B (IMC current control with active damping and
//! back-calculation anti-windup §2.2, Appendix D). Equation numbers in the docs are
//! the theses' own.
//!
//! Layout — one module per computation, configuration separate from state, each step
//! a `process(&self, &mut State, input)`:
//!
//! | module | computes |
//! |---|---|
//! | [`transforms`] | Clarke (2.7), Park (2.8) and their inverses, `f32` |
//! | [`q31`] | Q1.31 products and conversions (saturating) |
//! | [`trig`] | Q1.31 sin/cos/atan2 behind the [`trig::Trig`] trait (CORDIC on target) |
//! | [`angle`] | θ_e = n_p/n_r·(θ_r − θ_off) (4.5), angle lead (4.23), Q1.31 |
//! | [`ato`] | angle tracking observer (4.19), (4.22), two error architectures |
//! | [`adc`] | ADC codes → A, V |
//! | [`pi`] | current PI, active damping, anti-windup (2.47)–(2.49), voltage limit |
//! | [`feedforward`] | decoupling (5.3), DC link (5.1), torque → i_q (2.34) |
//! | [`torque`] | torque → current references: MTPA (3.10), field weakening (2.55)–(2.60), MTPV |
//! | [`modulation`] | THPWM (3.7), (3.8), duties and compare values |
//! | [`fir`] | FMAC-bit-exact FIR for the identification filter (§6.2) |
//! | [`commissioning`] | chapter-6 routines as state machines |
//! | [`preflight`] | the pre-flight check before the loop closes: d pulses, one electrical turn |
//! | [`commissioning_mode`] | CAN-commanded commissioning: guards, capture, streaming |
//! | [`can_protocol`] | status, command and capture frames as bytes, CRC-32 |
//! | [`setpoint`] | received setpoint with timeout and ramp to zero |
//! | [`step`] | the complete control step and its [`step::ControllerConfig`] |
//! | [`timing`] | TIM1 dead-time and IWDG codes from times (shared with the code generator's checks) |
//!
//! Numbers: angles are π-scaled Q1.31 stored integers and wrap; every other integer
//! quantity saturates; currents and voltages are `f32` (the Cortex-M4F has an FPU).
//! No heap, no `unsafe`, no panicking operations.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]
// "No panics reachable", checked mechanically on the library code: no indexing, no
// unwrap/expect/panic, and every integer operation is wrapping (angles only),
// saturating or checked. (Tests are exempt.)
#![cfg_attr(
    not(test),
    deny(
        clippy::arithmetic_side_effects,
        clippy::indexing_slicing,
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::unreachable,
        clippy::todo,
        clippy::unimplemented
    )
)]

pub mod adc;
pub mod angle;
pub mod ato;
pub mod can_protocol;
pub mod commissioning;
pub mod commissioning_mode;
pub mod estimator;
pub mod fast_trig;
pub mod feedforward;
pub mod fir;
pub mod modulation;
pub mod pi;
pub mod preflight;
pub mod q31;
pub mod setpoint;
pub mod step;
pub mod timing;
pub mod torque;
pub mod transforms;
pub mod trig;

pub use fast_trig::FastTrig;
pub use step::{AdcSample, ControllerConfig, ControllerState, Demand, StepOutput};
pub use trig::{SoftTrig, Trig};
