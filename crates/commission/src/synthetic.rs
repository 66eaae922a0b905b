//! Synthetic recordings for tests and benchmarks of the identification: blocked-rotor
//! voltage steps generated from a motor's R and L (thesis A (6.4) with a transport
//! delay), with noise and ADC quantisation, in the CSV format of [`crate::recording`].

use codegen::Design;

/// SplitMix64 (a seeded, reproducible generator) and Box–Muller normal samples.
pub struct Noise(pub u64);

impl Noise {
    /// A uniform sample in (0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// A standard normal sample (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// Noise σ in ADC LSB (a realistic 12-bit current channel: a few LSB of noise).
pub const NOISE_LSB: f64 = 3.0;
/// Transport delay of the generated recordings \[samples\].
pub const DELAY: f64 = 1.5;

/// A `step` recording of the blocked rotor with resistance `r`, inductance `l`:
/// 40 rows at 0 V, then `u` for 12 τ; each current is the exact first-order response
/// delayed by [`DELAY`] plus N(0, (3 LSB)²), quantised to the 12-bit ADC over ±full scale.
pub fn step_recording(d: &Design, axis: &str, r: f64, l: f64, seed: u64) -> String {
    let ts = d.drive.sample_period_s;
    let fs = d.scaling.phase_current.full_scale;
    let lsb = 2.0 * fs / 4096.0;
    // Half the peak current: well inside the trip and the measurement range.
    let u = 0.5 * d.motor.peak_current_a * r;
    let tau = l / r / ts;
    let pre = 40usize;
    let rows = pre + (12.0 * tau) as usize;
    let mut noise = Noise(seed);
    let mut s = format!(
        "# motorgen recording: step\n# sample_period = {} µs\n# axis = {axis}\nsample,voltage_v,current_a\n",
        ts * 1e6
    );
    for n in 0..rows {
        let t = n as f64 - pre as f64 - DELAY;
        let i = if t > 0.0 { u / r * (1.0 - (-t / tau).exp()) } else { 0.0 };
        let measured = ((i + NOISE_LSB * lsb * noise.normal()) / lsb).round() * lsb;
        let v = if n >= pre { u } else { 0.0 };
        s.push_str(&format!("{n},{v},{}\n", measured as f32));
    }
    s
}
