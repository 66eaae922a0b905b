fn main() {
    let _ = motor_macros::pi_gains!(methd = imc, resistance = "0.126 Ω", inductance = "0.393 mH", bandwidth = "100 rad/s", fs = "20 kHz");
}
