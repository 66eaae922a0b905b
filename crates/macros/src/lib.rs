//! Proc-macros over `codegen`: firmware code states the physical intent and the
//! compiler produces the constant, through the same functions as `motorgen`.
//!
//! * [`motor_constants!`] — the generated module of a motor spec.
//! * [`q31!`], [`q15!`] — fixed-point literals (`fixed::types::I1F31` / `I1F15`).
//! * [`ato_gains!`] — angle-tracking-observer gains in Q1.31 (thesis A 4.15, 4.22).
//! * [`pi_gains!`] — current-loop PI gains (thesis A 5.9, 5.14; thesis B 2.38) through
//!   the design core's current-loop pipeline and its rules, as `motorgen check` applies them.
//!
//! Errors are `compile_error!`s spanned at the offending argument.

mod expand;

use proc_macro::TokenStream;

/// Expands to the constant modules of a motor spec (path relative to `CARGO_MANIFEST_DIR`),
/// identical to `motorgen design <spec> --format rust`; editing the spec recompiles.
/// With `board = "<board file>"` the `board` module is added, as `motorgen design
/// <spec> --board <board file> --format rust`.
///
/// ```ignore
/// motor_macros::motor_constants!("../motors/fischer-ti085.toml");
/// let kp: f32 = current_loop::D_KP;
/// motor_macros::motor_constants!("../motors/fischer-ti085.toml", board = "../boards/motorgen-reference.toml");
/// let dead_ns: u32 = board::DEAD_TIME_NS;
/// ```
#[proc_macro]
pub fn motor_constants(input: TokenStream) -> TokenStream {
    expand::motor_constants(input.into())
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

/// A Q1.31 literal: `q31!(0.25)` → `::fixed::types::I1F31::from_bits(536870912)`; the value must be in [−1, 1).
#[proc_macro]
pub fn q31(input: TokenStream) -> TokenStream {
    expand::q_literal(input.into(), 31)
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

/// A Q1.15 literal: `q15!(-0.5)` → `::fixed::types::I1F15::from_bits(-16384)`; the value must be in [−1, 1).
#[proc_macro]
pub fn q15(input: TokenStream) -> TokenStream {
    expand::q_literal(input.into(), 15)
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

/// Observer gains `(K̃_p, K̃_i)` as `I1F31` (thesis A 4.15, 4.22):
/// `ato_gains!(natural_frequency = "70 rad/s", damping = 1.0, fs = "20 kHz", error = trig_identity)`.
#[proc_macro]
pub fn ato_gains(input: TokenStream) -> TokenStream {
    expand::ato_gains(input.into())
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

/// Current-loop PI gains `(K_p, K_i)` (parallel form, thesis A (5.6a)) as `f32` for one
/// axis, designed as `motorgen` designs a spec's `[current_loop]`:
/// `pi_gains!(method = imc, resistance = "0.126 Ω", inductance = "0.393 mH", bandwidth = "100 rad/s", fs = "20 kHz")`
/// (`damping = 0.7071` for `pole_placement`; `compensate_delay = false` to opt out of
/// the delay compensation, as in a spec). The gains are the design core's current-loop
/// pipeline (thesis A 5.9, 5.14; thesis B 2.38, with thesis A §4.6's 1.5·T_s delay: a macro has no board), and
/// a bandwidth `motorgen check` refuses — a sampled loop below the phase/gain-margin,
/// overshoot or rise-time floors, a right-half-plane zero, negative active damping — is a
/// compile error at `bandwidth` naming the rule, the figure and the bandwidth that works.
/// What `check` refuses beyond these rules needs the motor, not only R and L: the
/// at-speed figures `motorgen verify` judges (the axes kept apart by the decoupling
/// feed-forward, a DC-link step ridden; they need ψ_M, the top speed and the DC link) —
/// a motor's whole design, with them, is `motor_constants!`. The thesis-A guideline (α
/// below 30 % / 17 % of f_s) is a warning in `check` and not reported here (a proc-macro
/// cannot warn on stable Rust). With `imc_active_damping`
/// the firmware also needs R_a, and with `pole_placement` the prefilter: those come
/// from `motor_constants!`.
#[proc_macro]
pub fn pi_gains(input: TokenStream) -> TokenStream {
    expand::pi_gains(input.into())
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}
