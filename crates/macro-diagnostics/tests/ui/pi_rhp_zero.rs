fn main() {
    // Fischer at 100 rad/s, ζ = 1/√2: R/(2L) = 160 rad/s, so the loop has a RHP zero.
    let _ = motor_macros::pi_gains!(method = pole_placement, resistance = "0.126 Ω", inductance = "0.393 mH", bandwidth = "100 rad/s", fs = "20 kHz", damping = 0.7071);
}
