fn main() {
    let _ = motor_macros::ato_gains!(natural_frequency = "70 mA", damping = 1.0, fs = "20 kHz", error = trig_identity);
}
