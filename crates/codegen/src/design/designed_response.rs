//! The designed (continuous) closed-loop step of each current-loop method: the response
//! the user asks for, against which the sampled loop is judged (`discrete_loop`,
//! `sampled_loop`) and the simulation compared (`verify`).

use super::discrete_loop::rise_time;

/// Unit step response of the designed closed loop at `t` \[s\]: first order
/// `1 − e^(−αt)` (thesis A (5.8), thesis B (2.41)) when `zeta` is `None`, else the
/// second-order system of thesis A (4.14) with ω_n, ζ (the prefilter (5.16) having
/// cancelled the zero).
pub fn designed_step(t: f64, alpha: f64, second_order: Option<(f64, f64)>) -> f64 {
    match second_order {
        None => 1.0 - (-alpha * t).exp(),
        Some((wn, zeta)) if zeta < 1.0 => {
            let wd = wn * (1.0 - zeta * zeta).sqrt();
            1.0 - (-zeta * wn * t).exp() * ((wd * t).cos() + zeta / (1.0 - zeta * zeta).sqrt() * (wd * t).sin())
        }
        Some((wn, 1.0)) => 1.0 - (-wn * t).exp() * (1.0 + wn * t),
        Some((wn, zeta)) => {
            let r = (zeta * zeta - 1.0).sqrt();
            let (p1, p2) = (wn * (zeta - r), wn * (zeta + r));
            1.0 - (p2 * (-p1 * t).exp() - p1 * (-p2 * t).exp()) / (p2 - p1)
        }
    }
}

/// 10–90 % rise time of [`designed_step`] \[s\], found on a grid of 1/(2000·α).
pub fn designed_rise_time(alpha: f64, second_order: Option<(f64, f64)>) -> f64 {
    let dt = 1.0 / (2000.0 * alpha);
    let y: Vec<f64> = (0..40_000)
        .map(|k| designed_step(k as f64 * dt, alpha, second_order))
        .collect();
    rise_time(&y, dt).unwrap_or(f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ln 9/α for a first-order loop (thesis A (5.8)): α = 100 rad/s → 21.97 ms.
    #[test]
    fn first_order_rise_time_is_ln9_over_alpha() {
        let t = designed_rise_time(100.0, None);
        assert!((t - 9f64.ln() / 100.0).abs() < 1e-5, "{t}");
    }

    /// ζ = 1/√2: the 10–90 % rise time from the usual empirical fit
    /// ω_n·t_r ≈ 1 − 0.4167·ζ + 2.917·ζ² = 1 − 0.2947 + 1.4585 = 2.164 (good to about
    /// 1 % for 0.3 < ζ < 0.8), and the peak e^(−π) = 4.32 % above 1 (thesis A §5.4.1).
    #[test]
    fn second_order_figures() {
        let z = std::f64::consts::FRAC_1_SQRT_2;
        let t = designed_rise_time(1.0, Some((1.0, z)));
        assert!((t - 2.164).abs() < 0.03, "{t}");
        let dt = 1e-3;
        let y: Vec<f64> = (0..20_000)
            .map(|k| designed_step(k as f64 * dt, 1.0, Some((1.0, z))))
            .collect();
        let peak = y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!((peak - 1.0 - (-std::f64::consts::PI).exp()).abs() < 1e-5, "{peak}");
    }
}
