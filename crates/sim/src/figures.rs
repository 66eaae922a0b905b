//! Figures of sampled responses: 10–90 % rise time, overshoot, final error, settling.

/// Step-response figures of a sampled signal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepFigures {
    /// 10–90 % rise time \[s\] (linear interpolation between samples); NaN if never reached.
    pub rise_time: f64,
    /// Peak beyond the target, as a fraction of the step height (≥ 0).
    pub overshoot: f64,
    /// (last sample − target)/height.
    pub final_error: f64,
}

/// Time \[s\] at which `samples` (spaced `dt`) first crosses `initial + level·(target − initial)`.
pub fn crossing(samples: &[f64], dt: f64, initial: f64, target: f64, level: f64) -> f64 {
    let height = target - initial;
    let y = initial + level * height;
    for n in 1..samples.len() {
        let (a, b) = (samples[n - 1] - y, samples[n] - y);
        if a * height.signum() < 0.0 && b * height.signum() >= 0.0 {
            return ((n - 1) as f64 + a.abs() / (a.abs() + b.abs())) * dt;
        }
    }
    f64::NAN
}

/// Rise time, overshoot and final error of a step from `initial` to `target`.
pub fn step_figures(samples: &[f64], dt: f64, initial: f64, target: f64) -> StepFigures {
    let height = target - initial;
    let peak = samples
        .iter()
        .map(|&v| (v - initial) / height)
        .fold(f64::NEG_INFINITY, f64::max);
    StepFigures {
        rise_time: crossing(samples, dt, initial, target, 0.9) - crossing(samples, dt, initial, target, 0.1),
        overshoot: (peak - 1.0).max(0.0),
        final_error: samples.last().map_or(f64::NAN, |&v| (v - target) / height),
    }
}

/// Time \[s\] after which `|x|` stays below `threshold`; `None` if the last sample is not.
pub fn settling_time(x: &[f64], dt: f64, threshold: f64) -> Option<f64> {
    match x.iter().rposition(|v| v.abs() >= threshold) {
        None => Some(0.0),
        Some(k) if k + 1 < x.len() => Some((k + 1) as f64 * dt),
        Some(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sampled first-order step 1 − e^(−t) (dt = 1 ms): rise time ln 9 = 2.197 s, no
    /// overshoot, final error e^(−20) after 20 s.
    #[test]
    fn first_order_step() {
        let dt = 1e-3;
        let y: Vec<f64> = (0..=20_000).map(|k| 1.0 - (-(k as f64) * dt).exp()).collect();
        let f = step_figures(&y, dt, 0.0, 1.0);
        assert!((f.rise_time - 9f64.ln()).abs() < 1e-6, "{}", f.rise_time);
        assert_eq!(f.overshoot, 0.0);
        assert!((f.final_error + (-20f64).exp()).abs() < 1e-15, "{}", f.final_error);
    }

    /// A falling step is measured like a rising one.
    #[test]
    fn falling_step() {
        let f = step_figures(&[4.0, 3.0, 2.0, 1.0, 0.0, -0.5, 0.0], 1.0, 4.0, 0.0);
        // 10 % of the way at 3.6 (0.4 samples), 90 % at 0.4 (3.6 samples).
        assert!((f.rise_time - 3.2).abs() < 1e-12, "{}", f.rise_time);
        assert!((f.overshoot - 0.125).abs() < 1e-12, "{}", f.overshoot);
        assert_eq!(f.final_error, 0.0);
    }

    #[test]
    fn settling() {
        let x = [5.0, 3.0, 0.5, 2.0, 0.1, 0.05];
        assert_eq!(settling_time(&x, 1.0, 1.0), Some(4.0));
        assert_eq!(settling_time(&x, 1.0, 0.01), None);
    }
}
