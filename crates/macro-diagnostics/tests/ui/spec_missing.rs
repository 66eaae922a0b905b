motor_macros::motor_constants!("tests/ui/no-such-motor.toml");
fn main() {}
