//! Frequency responses of the discrete designs, as the firmware realises them (for the
//! report's Bode plots), and of the continuous designs they approximate.
//!
//! Current loop per axis, sample period T_s, the design's loop delay D = λ + ½
//! (`codegen::design::current_loop::discrete`; λ = 1 is thesis A §4.6's 1.5·T_s):
//!
//! ```text
//! C(z) = k_p + k_i·T_s·z⁻¹/(1 − z⁻¹)          forward-difference PI (4.17b), (2.49) linear
//! P(z) = (b₀·z + b)/(z·(z − a)),  a = e^(−R·T_s/L), b, b₀ of the voltage switching λ·T_s
//!        after the sample: ZOH of 1/(Ls + R) (thesis A (5.5)) and the computation delay
//! P_a = P/(1 + R_a·P)                            active damping (thesis B (2.31))
//! F(z) = c/(1 − (1 − c)·z⁻¹)                      prefilter (5.16), c = 1 − e^(−T_s·k_i/k_p)
//! L = C·P_a,   T = F·L/(1 + L)
//! ```
//!
//! Angle tracking observer (4.19), (4.22) with the Q1.31 gains, linearised (sin Δ ≈ Δ):
//! `L(z) = z⁻¹/(1 − z⁻¹)·(K̃_p·g + K̃_i·g·z⁻¹/(1 − z⁻¹))`, g = π (trig identity) or 1
//! (atan2), `T = L/(1 + L)`.
//!
//! FIR: `H(e^{jωT}) = Σ h_k·e^{−jωkT}`, h_k = taps/32768 (Q1.15).

use std::f64::consts::PI;

use nalgebra::Complex;

use codegen::design::Design;
use codegen::design::angle_observer::Q31_ONE;
use codegen::design::current_loop::AxisGains;
use codegen::design::current_loop::discrete::SampledPlant;
use codegen::spec::{Method, ObserverError};

/// A frequency response on a grid.
#[derive(Clone, Debug, PartialEq)]
pub struct Response {
    /// Angular frequencies [rad/s].
    pub omega: Vec<f64>,
    /// Complex values.
    pub values: Vec<Complex<f64>>,
}

impl Response {
    /// |H| in dB.
    pub fn magnitude_db(&self) -> Vec<f64> {
        self.values.iter().map(|h| 20.0 * h.norm().log10()).collect()
    }

    /// arg H in degrees, unwrapped along the grid.
    pub fn phase_deg(&self) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.values.len());
        let mut prev: Option<f64> = None;
        for h in &self.values {
            let mut p = h.arg().to_degrees();
            if let Some(q) = prev {
                p -= 360.0 * ((p - q) / 360.0).round();
            }
            out.push(p);
            prev = Some(p);
        }
        out
    }
}

/// `n` logarithmically spaced frequencies from `from` to `to` [rad/s].
pub fn log_grid(from: f64, to: f64, n: usize) -> Vec<f64> {
    let (a, b) = (from.ln(), to.ln());
    (0..n)
        .map(|k| (a + (b - a) * k as f64 / (n - 1).max(1) as f64).exp())
        .collect()
}

/// z⁻¹ = e^(−jωT_s).
fn z_inv(omega: f64, ts: f64) -> Complex<f64> {
    Complex::from_polar(1.0, -omega * ts)
}

/// Open-loop L and closed-loop T of one current-loop axis with gains `g` on the sampled
/// `plant` (its R, L, T_s and loop delay: `discrete::plant` of the design's request), at
/// each frequency of `omega`.
pub fn current_loop(g: &AxisGains, plant: &SampledPlant, omega: &[f64]) -> (Response, Response) {
    let ts = plant.ts;
    let c = g.prefilter.as_ref().map_or(1.0, |p| p.discrete_coefficient);
    let one = Complex::new(1.0, 0.0);
    let (mut open, mut closed) = (Vec::new(), Vec::new());
    for &w in omega {
        let zi = z_inv(w, ts);
        let ctrl = g.kp + g.ki * ts * zi / (one - zi);
        let p = plant.transfer(one / zi);
        let pa = p / (one + g.active_damping_ohm * p);
        let lo = ctrl * pa;
        let f = c / (one - (1.0 - c) * zi);
        open.push(lo);
        closed.push(f * lo / (one + lo));
    }
    open_and_closed(omega, open, closed)
}

/// The open- and closed-loop responses over the same frequencies.
fn open_and_closed(omega: &[f64], open: Vec<Complex<f64>>, closed: Vec<Complex<f64>>) -> (Response, Response) {
    let response = |values| Response {
        omega: omega.to_vec(),
        values,
    };
    (response(open), response(closed))
}

/// The designed continuous closed loop of the current controller: α/(s + α) (IMC,
/// thesis A (5.8), thesis B (2.41)) or ω_n²/(s² + 2ζω_n·s + ω_n²) (pole placement with
/// prefilter, (4.14), (5.16)).
pub fn current_loop_designed(d: &Design, omega: &[f64]) -> Response {
    let cl = &d.current_loop;
    let values = omega
        .iter()
        .map(|&w| {
            let s = Complex::new(0.0, w);
            match (cl.method, cl.natural_frequency_rad_s, cl.damping) {
                (Method::PolePlacement, Some(wn), Some(z)) => wn * wn / (s * s + 2.0 * z * wn * s + wn * wn),
                _ => cl.bandwidth_rad_s / (s + cl.bandwidth_rad_s),
            }
        })
        .collect();
    Response {
        omega: omega.to_vec(),
        values,
    }
}

/// Open-loop and closed-loop response of the discrete ATO with the design's Q1.31 gains.
pub fn observer(d: &Design, omega: &[f64]) -> (Response, Response) {
    let o = &d.angle_observer;
    let ts = d.drive.sample_period_s;
    let g = match o.error {
        ObserverError::TrigIdentity => PI,
        ObserverError::Atan2 => 1.0,
    };
    let kp = f64::from(o.gains.kp_q31) / Q31_ONE * g;
    let ki = f64::from(o.gains.ki_q31) / Q31_ONE * g;
    let one = Complex::new(1.0, 0.0);
    let (mut open, mut closed) = (Vec::new(), Vec::new());
    for &w in omega {
        let zi = z_inv(w, ts);
        let integ = zi / (one - zi);
        let lo = integ * (kp + ki * integ);
        open.push(lo);
        closed.push(lo / (one + lo));
    }
    open_and_closed(omega, open, closed)
}

/// The continuous ATO design (K_p·s + K_i)/(s² + K_p·s + K_i) (thesis A (4.14)).
pub fn observer_designed(d: &Design, omega: &[f64]) -> Response {
    let o = &d.angle_observer;
    let values = omega
        .iter()
        .map(|&w| {
            let s = Complex::new(0.0, w);
            (o.gains.kp * s + o.gains.ki) / (s * s + o.gains.kp * s + o.gains.ki)
        })
        .collect();
    Response {
        omega: omega.to_vec(),
        values,
    }
}

/// Frequency response of the quantised FIR at `n` frequencies from 0 to f_s/2; the grid is
/// in Hz here (`omega` holds f \[Hz\]).
pub fn fir(d: &Design, n: usize) -> Response {
    let fs = d.drive.switching_frequency_hz;
    let f: Vec<f64> = (0..n).map(|k| 0.5 * fs * k as f64 / (n - 1).max(1) as f64).collect();
    let values = f
        .iter()
        .map(|&f| {
            d.fir
                .taps_q15
                .iter()
                .enumerate()
                .map(|(k, &h)| Complex::from_polar(f64::from(h) / 32768.0, -2.0 * PI * f * k as f64 / fs))
                .sum()
        })
        .collect();
    Response { omega: f, values }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q_plant(d: &Design) -> SampledPlant {
        codegen::design::current_loop::discrete::plant(&d.current_loop_request(codegen::design::current_loop::Axis::Q))
    }

    fn fischer() -> Design {
        let text =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/fischer-ti085.toml")).unwrap();
        codegen::design_source("fischer-ti085.toml", &text).unwrap()
    }

    /// Integral action: every closed loop has DC gain exactly 1 (to rounding), and the FIR's
    /// Σ taps = 32768 gives H(0) = 1.
    #[test]
    fn closed_loops_have_unit_dc_gain() {
        let d = fischer();
        let w = [1e-6];
        let (_, t) = current_loop(&d.current_loop.q, &q_plant(&d), &w);
        assert!(
            (t.values[0] - Complex::new(1.0, 0.0)).norm() < 1e-6,
            "{:?}",
            t.values[0]
        );
        let (_, t) = observer(&d, &w);
        assert!(
            (t.values[0] - Complex::new(1.0, 0.0)).norm() < 1e-6,
            "{:?}",
            t.values[0]
        );
        let h = fir(&d, 3);
        assert!((h.values[0] - Complex::new(1.0, 0.0)).norm() < 1e-12);
    }

    /// IMC (5.8): the closed loop is α/(s + α), so |T(jα)| = 1/√2 (−3.01 dB). At
    /// α·T_s = 100/20000 the discrete loop's delay changes this by far less than 0.1 dB.
    #[test]
    fn imc_closed_loop_is_3_db_down_at_alpha() {
        let d = fischer();
        let alpha = d.current_loop.bandwidth_rad_s;
        let (_, t) = current_loop(&d.current_loop.q, &q_plant(&d), &[alpha]);
        let db = t.magnitude_db()[0];
        assert!((db + 3.0103).abs() < 0.1, "{db}");
    }

    /// The step response's final value is the closed loop's DC gain 1, and its first two
    /// samples are 0 (one period of computation delay, then the PWM period itself).
    #[test]
    fn discrete_step_settles_at_one_after_the_delay() {
        let d = fischer();
        use codegen::design::current_loop::discrete::{SampledPlant, step_response};
        let plant = SampledPlant::new(
            d.motor.phase_resistance_ohm,
            d.motor.q_inductance_h,
            d.drive.sample_period_s,
        );
        let y = step_response(&d.current_loop.q.loop_gains(), &plant, 20_000);
        assert_eq!((y[0], y[1]), (0.0, 0.0));
        assert!(y[2] > 0.0);
        assert!((y[19_999] - 1.0).abs() < 1e-6, "{}", y[19_999]);
    }

    /// Phase unwrapping keeps a linear-phase FIR's phase monotonic: −ω·N/2·T_s.
    #[test]
    fn unwrapped_phase_is_continuous() {
        let r = Response {
            omega: vec![0.0; 4],
            values: [170.0f64, 179.0, -178.0, -170.0]
                .iter()
                .map(|p| Complex::from_polar(1.0, p.to_radians()))
                .collect(),
        };
        let p = r.phase_deg();
        assert!((p[2] - 182.0).abs() < 1e-9 && (p[3] - 190.0).abs() < 1e-9, "{p:?}");
    }
}
