// Issue 31: the plain IMC rule gave gains for α = 37 699 rad/s (30 % of f_s = 20 kHz) that
// `motorgen check` refuses; the macro now refuses it with check's rule and the bandwidth
// that works.
fn main() {
    let _ = motor_macros::pi_gains!(method = imc, resistance = "0.126 Ω", inductance = "0.393 mH", bandwidth = "37699 rad/s", fs = "20 kHz");
}
