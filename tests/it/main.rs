//! End-to-end tests over every motor in `motors/`, one test binary: the design of each
//! spec, the generated Rust (template and proc-macro) against the JSON design, the
//! golden files, hostile text in the outputs, and the firmware built for each motor.

mod firmware;
mod firmware_limits;
mod generated;
mod golden;
mod injection;
mod layers;
mod motors;

/// The design of `motors/<stem>.toml` as JSON.
pub fn design_json(stem: &str) -> serde_json::Value {
    let rel = format!("motors/{stem}.toml");
    let text = motor_test_support::read(&rel);
    let d = codegen::design_source(&rel, &text).unwrap_or_else(|e| panic!("{e}"));
    serde_json::to_value(&d).unwrap()
}
