// trybuild compiles this file with CARGO_MANIFEST_DIR = target/tests/trybuild/motor-macros.
motor_macros::motor_constants!("../../../../crates/macros/tests/ui/bare-number.toml");
fn main() {}
