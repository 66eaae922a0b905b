//! Stage 3 of the current-loop pipeline ([`super`]): the figures of one axis as the
//! firmware samples it — closed-loop poles, gain and phase margin, step overshoot and rise
//! time of the discrete model that [`super::discrete`] documents (ZOH plant, one period of
//! computation delay, forward-difference PI, active damping, prefilter) — and the floors
//! they must meet. [`finish`] turns a stage-2 design into the axis's [`AxisGains`].
//!
//! # The loop
//!
//! With `a = e^(−R·T_s/L)` and the ZOH of 1/(Ls + R) (thesis A (5.5)) whose voltage
//! switches λ·T_s after the sample, `b = (e^(−R·(1−λ)·T_s/L) − a)/R` and
//! `b₀ = (1 − e^(−R·(1−λ)·T_s/L))/R` ([`super::discrete`]; the loop delay is (λ + 1/2)·T_s;
//! λ = 1, b₀ = 0 is the 1.5·T_s of thesis A §4.6: the duties computed from the samples
//! at t_n act during [t_{n+1}, t_{n+2})):
//!
//! ```text
//! P(z) = (b₀·z + b) / (z·(z − a))                          plant seen from the PI output
//! C(z) = k_p + k_i·T_s/(z − 1)                              forward-difference PI (4.17b)
//! u    = C·(r_f − i) − R_a·i                                active damping (thesis B 2.31)
//! L(z) = P(z)·(C(z) + R_a)
//!      = (b₀·z + b)·[(k_p + R_a)(z − 1) + k_i·T_s] / [z·(z − a)·(z − 1)]
//! ```
//!
//! `L` is the loop broken at the plant input (the inverter), where the motor's gain
//! (L, R) and delay uncertainty act; both feedback paths of the current (PI and active
//! damping) pass through it. The closed-loop poles are the roots of `1 + L = 0`:
//!
//! ```text
//! z³ + (b₀·K − 1 − a)·z² + (a + b·K + b₀·M)·z + b·M = 0,   K = k_p + R_a, M = k_i·T_s − K
//! ```
//!
//! found as the eigenvalues of the companion matrix (nalgebra). The reference reaches
//! the current through `T(z) = F(z)·P(z)·C(z)/(1 + L(z))` with the prefilter
//! `F(z) = c·z/(z − (1 − c))` (5.16); the overshoot and rise time are read off its
//! simulated step ([`super::discrete::step_response`]).
//!
//! # Margins
//!
//! `L(e^{jωT_s})` is evaluated on a logarithmic grid from 10⁻⁶/T_s to the Nyquist
//! frequency π/T_s; every crossing of |L| = 1 (gain crossover) and of the unwrapped
//! phase through −180° − k·360° (phase crossover) is refined by bisection. The phase
//! margin is the smallest 180° + arg L over the gain crossovers, the gain margin the
//! smallest −20·log₁₀|L| over the phase crossovers (none: infinite).
//!
//! # Floors
//!
//! A design is accepted when the sampled loop is stable and
//!
//! * phase margin ≥ [`MIN_PHASE_MARGIN_DEG`] = 45° and gain margin ≥
//!   [`MIN_GAIN_MARGIN_DB`] = 6 dB (a factor 2): Åström & Murray, *Feedback Systems*
//!   (2nd ed., 2021), §10.3, give 30°–60° and a factor 2–5 as typical requirements; 45°
//!   is the middle of that range, a gain margin of 2 its robust end for a plant whose L
//!   and R are known to a few ten per cent (saturation, temperature: thesis B §2.1.6);
//! * the step overshoot stays within [`OVERSHOOT_ALLOWANCE_PCT`] = 2 percentage points of
//!   the method's designed overshoot (0 for the first-order methods, thesis A (5.8),
//!   thesis B (2.41); e^(−πζ/√(1−ζ²)) for pole placement, thesis A §5.4.1). A phase margin
//!   of 45° alone admits about 20 % overshoot (ζ ≈ PM/100, Franklin, Powell &
//!   Emami-Naeini, *Feedback Control of Dynamic Systems*, §6.4), which no method here
//!   designs for; the allowance covers the sampled loop's small departures (the third
//!   pole of the delay, the imperfect discrete cancellation of the plant pole);
//! * with `compensate_delay` (the default) the step rises within [`RISE_TOLERANCE`] = 10 %
//!   of the designed rise time (ln 9/α, or the second-order design's with ζ, ω_n): the
//!   sampled loop delivers the α the user asked for, the same tolerance `motorgen verify`
//!   holds the simulated step to.

use std::f64::consts::PI;

use motor_control::pi::PiConfig;
use nalgebra::{Complex, Matrix3};
use serde::Serialize;

use super::Request;
use super::continuous::{Pi, Prefilter, Promise, rise_time};
use super::discrete::{LoopGains, SampledPlant, step_response};

/// Smallest accepted phase margin [°] (Åström & Murray §10.3: 30°–60° typical).
pub const MIN_PHASE_MARGIN_DEG: f64 = 45.0;
/// Smallest accepted gain margin \[dB\]: a factor 2 (Åström & Murray §10.3: 2–5 typical).
pub const MIN_GAIN_MARGIN_DB: f64 = 6.0;
/// Largest accepted step overshoot above the method's designed one [percentage points].
pub const OVERSHOOT_ALLOWANCE_PCT: f64 = 2.0;
/// Largest accepted relative deviation of the sampled rise time from the designed one
/// (with `compensate_delay`).
pub const RISE_TOLERANCE: f64 = 0.10;

/// The sampled loop's figures for one axis (all with its loop delay).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SampledLoop {
    /// The loop delay D = λ + 1/2 the figures are computed with [periods of T_s].
    pub loop_delay_periods: f64,
    /// Gain margin \[dB\] at the phase crossover; null when the phase never reaches −180°
    /// below the Nyquist frequency (infinite margin).
    pub gain_margin_db: Option<f64>,
    /// Frequency of that phase crossover [rad/s].
    pub phase_crossover_rad_s: Option<f64>,
    /// Phase margin [°] at the gain crossover; null when |L| never falls to 1 below the
    /// Nyquist frequency.
    pub phase_margin_deg: Option<f64>,
    /// Frequency of that gain crossover [rad/s].
    pub gain_crossover_rad_s: Option<f64>,
    /// Step overshoot [%] of the reference step (with prefilter); null when unstable.
    pub overshoot_pct: Option<f64>,
    /// 10–90 % rise time of that step \[s\]; null when unstable or never reaching 90 %.
    pub rise_time_s: Option<f64>,
    /// Closed-loop poles in the z-plane, [re, im] (roots of 1 + L(z) = 0).
    pub poles: Vec<[f64; 2]>,
    /// The same poles as s-plane equivalents s = ln(z)/T_s [rad/s], [re, im]; null for
    /// a pole at z = 0 (a pure delay).
    pub poles_s_rad_s: Vec<Option<[f64; 2]>>,
    /// Largest pole magnitude; the loop is stable when below 1.
    pub spectral_radius: f64,
}

/// Why a sampled loop is refused (the floors of the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub enum FloorBreach {
    /// A closed-loop pole on or outside the unit circle.
    Unstable {
        /// Its magnitude.
        radius: f64,
    },
    /// Phase margin below [`MIN_PHASE_MARGIN_DEG`] (None: no gain crossover).
    PhaseMargin(Option<f64>),
    /// Gain margin below [`MIN_GAIN_MARGIN_DB`].
    GainMargin(f64),
    /// Overshoot more than [`OVERSHOOT_ALLOWANCE_PCT`] above the designed one.
    Overshoot {
        /// Measured on the sampled loop [%].
        sampled_pct: f64,
        /// Designed [%].
        designed_pct: f64,
    },
    /// Rise time more than [`RISE_TOLERANCE`] off the designed one (None: never reaches 90 %).
    Rise {
        /// Of the sampled loop \[s\].
        sampled_s: Option<f64>,
        /// Designed \[s\].
        designed_s: f64,
    },
}

impl std::fmt::Display for FloorBreach {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Unstable { radius } => write!(f, "unstable (a closed-loop pole at |z| = {radius:.3})"),
            Self::PhaseMargin(Some(pm)) => {
                write!(f, "phase margin {pm:.1}° < {MIN_PHASE_MARGIN_DEG}°")
            }
            Self::PhaseMargin(None) => write!(f, "|L| never falls to 1 below the Nyquist frequency"),
            Self::GainMargin(gm) => write!(f, "gain margin {gm:.1} dB < {MIN_GAIN_MARGIN_DB} dB"),
            Self::Overshoot {
                sampled_pct,
                designed_pct,
            } => write!(
                f,
                "step overshoot {sampled_pct:.1} % > {designed_pct:.1} % designed + {OVERSHOOT_ALLOWANCE_PCT} %"
            ),
            Self::Rise {
                sampled_s: Some(t),
                designed_s,
            } => write!(
                f,
                "rising in {:.4} ms, not within {:.0} % of the designed {:.4} ms",
                t * 1e3,
                RISE_TOLERANCE * 100.0,
                designed_s * 1e3
            ),
            Self::Rise { sampled_s: None, .. } => write!(f, "never rising to 90 %"),
        }
    }
}

impl SampledLoop {
    /// One line for the summary, the report and the constants' doc comments: margins,
    /// overshoot and the largest closed-loop pole magnitude.
    pub fn describe(&self) -> String {
        let opt = |x: Option<f64>, unit: &str, none: &str| x.map_or(none.to_string(), |v| format!("{v:.1}{unit}"));
        format!(
            "sampled loop ({:.4}·T_s delay): phase margin {}, gain margin {}, step overshoot {}, poles |z| ≤ {:.3}",
            self.loop_delay_periods,
            opt(self.phase_margin_deg, "°", "∞"),
            opt(self.gain_margin_db, " dB", "∞"),
            opt(self.overshoot_pct, " %", "— (unstable)"),
            self.spectral_radius
        )
    }

    /// The first floor this loop breaks, given what the method designs.
    pub fn breach(&self, promise: &Promise) -> Option<FloorBreach> {
        let designed_overshoot_pct = promise.overshoot_pct;
        if self.spectral_radius >= 1.0 {
            return Some(FloorBreach::Unstable {
                radius: self.spectral_radius,
            });
        }
        match self.phase_margin_deg {
            Some(pm) if pm >= MIN_PHASE_MARGIN_DEG => {}
            pm => return Some(FloorBreach::PhaseMargin(pm)),
        }
        if let Some(gm) = self.gain_margin_db.filter(|gm| *gm < MIN_GAIN_MARGIN_DB) {
            return Some(FloorBreach::GainMargin(gm));
        }
        match self.overshoot_pct {
            Some(os) if os <= designed_overshoot_pct + OVERSHOOT_ALLOWANCE_PCT => {}
            os => {
                return Some(FloorBreach::Overshoot {
                    sampled_pct: os.unwrap_or(f64::INFINITY),
                    designed_pct: designed_overshoot_pct,
                });
            }
        }
        let designed_s = promise.rise_time_s?;
        match self.rise_time_s {
            Some(t) if (t / designed_s - 1.0).abs() <= RISE_TOLERANCE => None,
            t => Some(FloorBreach::Rise {
                sampled_s: t,
                designed_s,
            }),
        }
    }
}

/// L(e^{jωT_s}) of the module documentation.
pub fn open_loop(g: &LoopGains, p: &SampledPlant, omega: f64) -> Complex<f64> {
    let z = Complex::from_polar(1.0, omega * p.ts);
    let one = Complex::new(1.0, 0.0);
    let k = g.kp + g.active_damping;
    p.transfer(z) * (k * (z - one) + g.ki * p.ts) / (z - one)
}

/// Coefficients [c₀, c₁, c₂] of the monic characteristic polynomial
/// z³ + c₂·z² + c₁·z + c₀ of the module documentation.
pub fn characteristic(g: &LoopGains, p: &SampledPlant) -> [f64; 3] {
    let k = g.kp + g.active_damping;
    let m = g.ki * p.ts - k;
    [p.b * m, p.a + p.b * k + p.b0 * m, p.b0 * k - 1.0 - p.a]
}

/// Roots of z³ + c₂z² + c₁z + c₀ (eigenvalues of the companion matrix), sorted by
/// decreasing magnitude, then by imaginary part.
pub fn cubic_roots(c: [f64; 3]) -> Vec<Complex<f64>> {
    let m = Matrix3::new(-c[2], -c[1], -c[0], 1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    let mut r: Vec<Complex<f64>> = m.complex_eigenvalues().iter().copied().collect();
    r.sort_by(|x, y| y.norm().total_cmp(&x.norm()).then(y.im.total_cmp(&x.im)));
    r
}

/// Frequencies [rad/s] of the margin search grid: 4000 points, logarithmic, from 10⁻⁶/T_s
/// to π/T_s.
fn grid(ts: f64) -> Vec<f64> {
    let n = 4000;
    let (lo, hi) = ((1e-6 / ts).ln(), (PI / ts).ln());
    (0..n)
        .map(|k| (lo + (hi - lo) * k as f64 / (n - 1) as f64).exp())
        .collect()
}

/// Wraps an angle difference into (−π, π].
fn wrap(x: f64) -> f64 {
    let y = x.rem_euclid(2.0 * PI);
    if y > PI { y - 2.0 * PI } else { y }
}

/// Bisection for the root of `f` between `lo` (f < 0 side given by `f_lo`) and `hi`.
fn bisect(mut lo: f64, mut hi: f64, f: impl Fn(f64) -> f64) -> f64 {
    let f_lo = f(lo);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if (f(mid) < 0.0) == (f_lo < 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// A margin and the frequency it is read at: (margin, ω [rad/s]).
pub type Margin = Option<(f64, f64)>;

/// The margins of the module documentation: (gain margin \[dB\], phase-crossover ω),
/// (phase margin [°], gain-crossover ω).
pub fn margins(g: &LoopGains, p: &SampledPlant) -> (Margin, Margin) {
    let w = grid(p.ts);
    let l: Vec<Complex<f64>> = w.iter().map(|&w| open_loop(g, p, w)).collect();
    // Unwrapped phase along the grid.
    let mut phase = Vec::with_capacity(w.len());
    for (k, v) in l.iter().enumerate() {
        let arg = v.arg();
        phase.push(if k == 0 {
            arg
        } else {
            phase[k - 1] + wrap(arg - l[k - 1].arg())
        });
    }
    let mut gm: Option<(f64, f64)> = None;
    let mut pm: Option<(f64, f64)> = None;
    for k in 0..w.len() - 1 {
        let (m0, m1) = (l[k].norm().ln(), l[k + 1].norm().ln());
        if m0.signum() != m1.signum() || m1 == 0.0 {
            let wc = bisect(w[k], w[k + 1], |x| open_loop(g, p, x).norm().ln());
            let ph = phase[k] + wrap(open_loop(g, p, wc).arg() - l[k].arg());
            let margin = wrap(ph + PI).to_degrees();
            if pm.is_none_or(|(m, _)| margin < m) {
                pm = Some((margin, wc));
            }
        }
        // Phase crossovers: the unwrapped phase passes −π − 2πj.
        let (j0, j1) = (
            ((phase[k] + PI) / (2.0 * PI)).floor(),
            ((phase[k + 1] + PI) / (2.0 * PI)).floor(),
        );
        if j0 != j1 {
            let target = -PI + 2.0 * PI * j0.max(j1);
            let unwrapped = |x: f64| phase[k] + wrap(open_loop(g, p, x).arg() - l[k].arg()) - target;
            let wp = bisect(w[k], w[k + 1], unwrapped);
            let margin = -20.0 * open_loop(g, p, wp).norm().log10();
            if gm.is_none_or(|(m, _)| margin < m) {
                gm = Some((margin, wp));
            }
        }
    }
    (gm, pm)
}

/// Samples [`analyse`] simulates the step for: until the slowest pole has decayed to
/// 10⁻⁴ (at least 200, at most 400 000).
fn step_length(radius: f64) -> usize {
    if radius <= 0.0 {
        return 200;
    }
    ((1e-4f64).ln() / radius.ln()).ceil().clamp(200.0, 400_000.0) as usize
}

/// The figures of one axis with gains `g` on plant `p`.
pub fn analyse(g: &LoopGains, p: &SampledPlant) -> SampledLoop {
    let ts = p.ts;
    let poles = cubic_roots(characteristic(g, p));
    let radius = poles.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let (gm, pm) = margins(g, p);
    let (overshoot, rise) = if radius < 1.0 {
        let y = step_response(g, p, step_length(radius));
        let peak = y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (Some(100.0 * (peak - 1.0).max(0.0)), rise_time(&y, ts))
    } else {
        (None, None)
    };
    SampledLoop {
        loop_delay_periods: p.lag + 0.5,
        gain_margin_db: gm.map(|x| x.0),
        phase_crossover_rad_s: gm.map(|x| x.1),
        phase_margin_deg: pm.map(|x| x.0),
        gain_crossover_rad_s: pm.map(|x| x.1),
        overshoot_pct: overshoot,
        rise_time_s: rise,
        poles: poles.iter().map(|z| [z.re, z.im]).collect(),
        poles_s_rad_s: poles
            .iter()
            .map(|z| (z.norm() > 0.0).then(|| [z.norm().ln() / ts, z.arg() / ts]))
            .collect(),
        spectral_radius: radius,
    }
}

/// PI gains for one axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisGains {
    /// Parallel proportional gain K_p [V/A] (5.6a).
    pub kp: f64,
    /// Parallel integral gain K_i [V/(A·s)] (5.6a).
    pub ki: f64,
    /// Series gain K_a = K_p [V/A] (5.7).
    pub ka: f64,
    /// Series zero K_b = K_i/K_p [rad/s] (5.7).
    pub kb: f64,
    /// Active damping (virtual resistance) R_a \[Ω\], thesis B (2.43); 0 for the other methods.
    pub active_damping_ohm: f64,
    /// Back-calculation anti-windup gain 1/k_p [A/(V·s)·s] of thesis B (2.49).
    pub anti_windup_gain: f64,
    /// Discrete integral gain K_i·T_s [V/A] for the forward-difference integrator (4.17b).
    pub ki_ts: f64,
    /// Reference prefilter (pole placement only).
    pub prefilter: Option<Prefilter>,
    /// Coefficient a of the reference filter y += a·(x − y) the controller runs: the
    /// prefilter's (5.16), or 1 (the reference passes unfiltered) without one.
    pub reference_filter: f64,
    /// Designed closed-loop poles, real and imaginary parts [rad/s].
    pub designed_poles: Vec<[f64; 2]>,
    /// The bandwidth α these gains were designed for [rad/s]: the spec's, or the lower
    /// delay-compensated one of the first-order methods ([`super::discrete`]).
    pub bandwidth_rad_s: f64,
    /// The sampled loop with these gains: poles, margins, overshoot ([`analyse`], the request's
    /// delay).
    #[serde(flatten)]
    pub sampled: SampledLoop,
}

impl AxisGains {
    /// The gains as the sampled loop sees them.
    pub fn loop_gains(&self) -> LoopGains {
        LoopGains {
            kp: self.kp,
            ki: self.ki,
            active_damping: self.active_damping_ohm,
            prefilter: self.prefilter.as_ref().map_or(1.0, |p| p.discrete_coefficient),
        }
    }

    /// The firmware's PI configuration of these gains, as the generated constants carry
    /// them (`f32`): the one mapping the at-speed scenarios and `motor-verify`'s
    /// controller both run.
    pub fn pi_config(&self) -> PiConfig {
        PiConfig {
            kp: self.kp as f32,
            ki: self.ki as f32,
            anti_windup: self.anti_windup_gain as f32,
            active_damping: self.active_damping_ohm as f32,
            reference_filter: self.reference_filter as f32,
        }
    }
}

/// `req`'s axis with the stage-2 gains `pi`: the series form (5.7), the anti-windup gain
/// (thesis B (2.49)), K_i·T_s (4.17b) and the sampled loop's figures ([`analyse`]).
pub fn finish(pi: Pi, req: &Request) -> AxisGains {
    let ts = req.sample_period_s;
    let sampled = analyse(&LoopGains::of(&pi), &super::discrete::plant(req));
    AxisGains {
        kp: pi.kp,
        ki: pi.ki,
        ka: pi.kp,
        kb: pi.ki / pi.kp,
        active_damping_ohm: pi.active_damping_ohm,
        anti_windup_gain: 1.0 / pi.kp,
        ki_ts: pi.ki * ts,
        reference_filter: pi.prefilter.as_ref().map_or(1.0, |p| p.discrete_coefficient),
        prefilter: pi.prefilter,
        designed_poles: pi.designed_poles,
        bandwidth_rad_s: pi.bandwidth_rad_s,
        sampled,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A first-order method without delay compensation: no overshoot, no rise promise.
    const FIRST_ORDER: Promise = Promise {
        overshoot_pct: 0.0,
        rise_time_s: None,
    };

    /// Gains whose PI zero 1 − k_i·T_s/k_p sits exactly on the plant pole a: then
    /// L(z) = K/(z(z − 1)) with K = b·k_p (the IMC loop of `discrete` with perfect
    /// cancellation).
    fn cancelling(r: f64, l: f64, ts: f64, k: f64) -> LoopGains {
        let p = SampledPlant::new(r, l, ts);
        let kp = k / p.b;
        LoopGains {
            kp,
            ki: kp * (1.0 - p.a) / ts,
            active_damping: 0.0,
            prefilter: 1.0,
        }
    }

    /// Hand calculation for L(e^{jθ}) = K/(e^{jθ}(e^{jθ} − 1)), θ = ωT_s:
    /// e^{jθ} − 1 = 2j·sin(θ/2)·e^{jθ/2}, so |L| = K/(2 sin(θ/2)) and
    /// arg L = −θ − (π/2 + θ/2) = −π/2 − 3θ/2.
    /// Phase crossover at θ = π/3 where |L| = K/(2 sin(π/6)) = K: GM = 1/K, i.e.
    /// −20·log₁₀K dB, so the loop is unstable from K = 1 on.
    /// Gain crossover at sin(θ_c/2) = K/2: PM = π/2 − 3·asin(K/2).
    /// Poles: (z − a)(z² − z + K) = 0.
    /// K = 0.2: GM = 13.979 dB at θ = π/3, PM = 90° − 3·5.7392° = 72.782°,
    /// poles a and (1 ± √(1 − 0.8))/2 = 0.72361, 0.27639.
    #[test]
    fn perfect_cancellation_margins_by_hand() {
        let (r, l, ts) = (0.126, 0.393e-3, 5e-5); // Fischer, 20 kHz
        for k in [0.05, 0.2, 0.35, 0.5, 0.9] {
            let g = cancelling(r, l, ts, k);
            let s = analyse(&g, &SampledPlant::new(r, l, ts));
            let gm = -20.0 * f64::log10(k);
            let pm = 90.0 - 3.0 * (k / 2.0).asin().to_degrees();
            assert!(
                (s.gain_margin_db.unwrap() - gm).abs() < 1e-6,
                "K = {k}: {:?} vs {gm}",
                s.gain_margin_db
            );
            assert!(
                (s.phase_margin_deg.unwrap() - pm).abs() < 1e-6,
                "K = {k}: {:?} vs {pm}",
                s.phase_margin_deg
            );
            let wp = PI / 3.0 / ts;
            assert!((s.phase_crossover_rad_s.unwrap() / wp - 1.0).abs() < 1e-9);
            let wc = 2.0 * (k / 2.0).asin() / ts;
            assert!((s.gain_crossover_rad_s.unwrap() / wc - 1.0).abs() < 1e-9);
        }
        let g = cancelling(r, l, ts, 0.2);
        let s = analyse(&g, &SampledPlant::new(r, l, ts));
        let a = (-r * ts / l).exp();
        let want = [0.5 + 0.2f64.sqrt() / 2.0 * 1.0, a, 0.5 - 0.2f64.sqrt() / 2.0];
        let mut got: Vec<f64> = s.poles.iter().map(|p| p[0]).collect();
        got.sort_by(|x, y| y.total_cmp(x));
        let mut want = want.to_vec();
        want.sort_by(|x, y| y.total_cmp(x));
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() < 1e-9, "{got:?} vs {want:?}");
        }
        assert!(s.poles.iter().all(|p| p[1].abs() < 1e-9));
    }

    /// K = 1 puts the pair of z² − z + K on the unit circle ((1 ± j√3)/2) with GM = 0 dB;
    /// K > 1 is unstable, and the analysis reports no overshoot for it.
    #[test]
    fn stability_boundary_at_k_equal_one() {
        let (r, l, ts) = (0.126, 0.393e-3, 5e-5);
        let s = analyse(&cancelling(r, l, ts, 0.999), &SampledPlant::new(r, l, ts));
        assert!(
            s.spectral_radius < 1.0 && s.spectral_radius > 0.999,
            "{}",
            s.spectral_radius
        );
        assert!(s.gain_margin_db.unwrap() > 0.0);
        let s = analyse(&cancelling(r, l, ts, 1.05), &SampledPlant::new(r, l, ts));
        assert!(s.spectral_radius > 1.0);
        assert!(s.gain_margin_db.unwrap() < 0.0);
        assert_eq!(s.overshoot_pct, None);
        assert!(matches!(s.breach(&FIRST_ORDER), Some(FloorBreach::Unstable { .. })));
    }

    /// With the plant pole cancelled, T(z) = K/(z² − z + K); for K = 0.5 the roots are
    /// (1 ± j)/2, ρ = 0.7071, φ = π/4, and the step of y(n+2) = y(n+1) − K·y(n) + K,
    /// y(0) = y(1) = 0, is 0, 0, 0.5, 1, 1.25, 1.25, 1.125, 1, … : overshoot 25 %.
    #[test]
    fn overshoot_of_the_cancelled_loop_by_hand() {
        let (r, l, ts) = (0.126, 0.393e-3, 5e-5);
        let s = analyse(&cancelling(r, l, ts, 0.5), &SampledPlant::new(r, l, ts));
        // The plant pole is cancelled to rounding only; the residue is below 1e-6.
        assert!((s.overshoot_pct.unwrap() - 25.0).abs() < 1e-3, "{:?}", s.overshoot_pct);
        assert!(matches!(s.breach(&FIRST_ORDER), Some(FloorBreach::Overshoot { .. })));
        // K = 0.25: double root 1/2, monotonic step.
        let s = analyse(&cancelling(r, l, ts, 0.25), &SampledPlant::new(r, l, ts));
        assert!(s.overshoot_pct.unwrap() < 1e-6, "{:?}", s.overshoot_pct);
        assert_eq!(s.breach(&FIRST_ORDER), None);
    }

    /// s-plane equivalents: a real pole z = e^{−αT_s} maps back to −α.
    #[test]
    fn s_plane_equivalents_invert_the_z_map() {
        let (r, l, ts) = (0.126, 0.393e-3, 5e-5);
        let s = analyse(&cancelling(r, l, ts, 0.2), &SampledPlant::new(r, l, ts));
        for (z, sp) in s.poles.iter().zip(&s.poles_s_rad_s) {
            let sp = sp.unwrap();
            let back = Complex::new(sp[0] * ts, sp[1] * ts).exp();
            assert!((back - Complex::new(z[0], z[1])).norm() < 1e-12);
        }
        // The plant pole a = e^{−R·T_s/L} ↔ −R/L = −320.6 rad/s.
        assert!(
            s.poles_s_rad_s
                .iter()
                .any(|p| (p.unwrap()[0] + r / l).abs() < 1e-6 * r / l)
        );
    }
}
