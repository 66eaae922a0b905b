const X: fixed::types::I1F31 = motor_macros::q31!(1.5);
fn main() {
    let _ = X;
}
