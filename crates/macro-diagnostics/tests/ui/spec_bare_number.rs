// trybuild compiles this file with CARGO_MANIFEST_DIR = target/tests/trybuild/motor-macro-diagnostics.
motor_macros::motor_constants!("../../../../crates/macro-diagnostics/tests/ui/bare-number.toml");
fn main() {}
