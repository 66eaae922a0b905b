//! Max torque per ampere and loss-minimising d-current, thesis B chapter 3.
//!
//! * MTPA (3.10): `i_d = ψ_m/(2ΔL) − √((ψ_m/(2ΔL))² + i_q²)`, ΔL = L_q − L_d.
//!   Written for ΔL > 0; for inverse saliency (ΔL < 0) the torque maximum is the other
//!   root, `ψ_m/(2ΔL) + √(…)` ≥ 0 (see [`mtpa_id`]).
//! * Losses: resistive (3.3), core losses in the parallel resistance R_c of Fig. 2.7
//!   (3.4), and optionally the inverter (3.11)–(3.14). The loss-minimising point at a
//!   given torque and speed is the minimum of these along the constant-torque curve —
//!   the condition (3.8), (3.9) that Appendix C solves in closed form (C.3) for the
//!   motor losses. Here it is found numerically (golden-section search), so the inverter
//!   losses, which (C.3) leaves out, can be included (thesis B §3.3.4: "preferably
//!   accomplished using numerical methods").
//!
//! The motor is modelled as in Fig. 2.7: the magnetising currents i_d0, i_q0 flow
//! through the inductances, the core current through R_c in parallel with the
//! induced voltage, so the terminal currents are
//! `i_d = i_d0 − ω·L_q·i_q0/R_c`, `i_q = i_q0 + ω·(L_d·i_d0 + ψ_m)/R_c` and the torque
//! is `T = 3/2·n_p·(ψ_m·i_q0 − ΔL·i_d0·i_q0)` ((3.5)–(3.7)).

use std::f64::consts::{PI, SQRT_2};

/// i_d,MTPA(i_q) \[A\] of (3.10), in the cancellation-free form
/// `−2ΔL·i_q²/(ψ_m + √(ψ_m² + 4ΔL²·i_q²))` (0 for ΔL = 0).
///
/// Derivation for either sign of ΔL: at |i| = I, T ∝ i_q·(ψ_m − ΔL·i_d) (3.7) with
/// i_q² = I² − i_d²; dT/di_d = 0 gives ΔL·i_d² − ψ_m·i_d − ΔL·i_q² = 0, roots
/// i_d = ψ_m/(2ΔL) ± √((ψ_m/(2ΔL))² + i_q²). The product of the roots is −i_q² < 0: one
/// root on each side of 0. The torque maximum is the root where ψ_m − ΔL·i_d > 0 (the
/// other lies beyond i_d = ψ_m/ΔL, where the torque has turned negative): the `−` root
/// for ΔL > 0 (i_d ≤ 0, thesis B's (3.10)) and the `+` root for ΔL < 0 (i_d ≥ 0). Both are
/// (ψ_m − √(ψ_m² + 4ΔL²·i_q²))/(2ΔL) — multiply by the conjugate for the form used here.
pub fn mtpa_id(psi: f64, delta_l: f64, iq: f64) -> f64 {
    let den = psi + (psi * psi + 4.0 * delta_l * delta_l * iq * iq).sqrt();
    // `+ 0.0` turns −0 into +0 (the generated tables hold no negative zeros).
    if den > 0.0 {
        -2.0 * delta_l * iq * iq / den + 0.0
    } else {
        0.0
    }
}

/// The MTPA point (i_d, i_q) \[A\] on the current circle |i| = `i_max` (the largest torque
/// per (2.50)): (3.10) with i_d² + i_q² = I², i.e. `2i_d² − ψ/ΔL·i_d − I² = 0`, in the
/// cancellation-free form `i_d = −2ΔL·I²/(ψ_m + √(ψ_m² + 8ΔL²·I²))` — the torque-maximising
/// root for either sign of ΔL, as in [`mtpa_id`].
pub fn mtpa_corner(psi: f64, delta_l: f64, i_max: f64) -> (f64, f64) {
    let den = psi + (psi * psi + 8.0 * delta_l * delta_l * i_max * i_max).sqrt();
    let id = if den > 0.0 {
        -2.0 * delta_l * i_max * i_max / den + 0.0
    } else {
        0.0
    };
    (id, (i_max * i_max - id * id).max(0.0).sqrt())
}

/// Inverter loss data reduced to (3.11)–(3.14), one leg's V and r being the mean of the
/// transistor's and the diode's (thesis B takes them as equal, V = V_CE0 ≈ V_T0,
/// r = r_CE ≈ r_T).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InverterLoss {
    /// On-state voltage V \[V\].
    pub threshold_v: f64,
    /// Lead resistance r \[Ω\].
    pub resistance_ohm: f64,
    /// E_on + E_off \[J\].
    pub switching_energy_j: f64,
    /// E_rr \[J\].
    pub recovery_energy_j: f64,
    /// I_c,nom \[A\].
    pub nominal_current_a: f64,
    /// f_sw \[Hz\].
    pub switching_frequency_hz: f64,
}

impl InverterLoss {
    /// P_loss,inv \[W\] (3.14) at the current amplitude `i` \[A\] (I_rms = i/√2).
    pub fn loss(&self, i: f64) -> f64 {
        let irms = i / SQRT_2;
        let cond = 2.0 * SQRT_2 * self.threshold_v * irms / PI + self.resistance_ohm * irms * irms; // (3.11)
        let s_t =
            self.switching_energy_j * 2.0 * SQRT_2 * irms * self.switching_frequency_hz / (PI * self.nominal_current_a); // (3.12)
        let s_d = self.recovery_energy_j * self.switching_frequency_hz; // (3.13)
        3.0 * (cond + s_t + s_d)
    }
}

/// The loss model of one motor (and inverter).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LossModel {
    /// n_p.
    pub pole_pairs: u32,
    /// R_s \[Ω\].
    pub rs: f64,
    /// L_d \[H\].
    pub ld: f64,
    /// L_q \[H\].
    pub lq: f64,
    /// ψ_m \[Wb\].
    pub psi: f64,
    /// R_c \[Ω\]; `None` = no core losses (R_c → ∞).
    pub rc: Option<f64>,
    /// Inverter losses, if included.
    pub inverter: Option<InverterLoss>,
    /// Current-circle radius I_max \[A\]; bounds the search (see [`LossModel::search_range`]).
    pub i_max: f64,
}

/// Golden-section iterations: the bracket shrinks by 0.618^100 ≈ 1e-21 — to f64 resolution.
const GOLDEN_STEPS: usize = 100;
/// Bisection steps on the torque.
const BISECTION_STEPS: usize = 100;

impl LossModel {
    /// Terminal currents (i_d, i_q) \[A\] of the magnetising currents at electrical speed `w` (Fig. 2.7).
    pub fn terminal(&self, w: f64, id0: f64, iq0: f64) -> (f64, f64) {
        match self.rc {
            Some(rc) => (id0 - w * self.lq * iq0 / rc, iq0 + w * (self.ld * id0 + self.psi) / rc),
            None => (id0, iq0),
        }
    }

    /// Torque [N·m] of the magnetising currents, (3.5)–(3.7).
    pub fn torque(&self, id0: f64, iq0: f64) -> f64 {
        1.5 * f64::from(self.pole_pairs) * iq0 * (self.psi - (self.lq - self.ld) * id0)
    }

    /// P_res (3.3) + P_co (3.4) + P_loss,inv (3.14) \[W\].
    pub fn loss(&self, w: f64, id0: f64, iq0: f64) -> f64 {
        let (id, iq) = self.terminal(w, id0, iq0);
        let res = 1.5 * self.rs * (id * id + iq * iq);
        let co = self.rc.map_or(0.0, |rc| {
            let (idc, iqc) = (id - id0, iq - iq0);
            1.5 * rc * (idc * idc + iqc * iqc)
        });
        let inv = self.inverter.map_or(0.0, |x| x.loss(id.hypot(iq)));
        res + co + inv
    }

    /// i_q0 giving torque `t` at i_d0 (explicit: the torque is linear in i_q0).
    fn iq0_for(&self, t: f64, id0: f64) -> f64 {
        let k = 1.5 * f64::from(self.pole_pairs) * (self.psi - (self.lq - self.ld) * id0);
        if k.abs() > 0.0 { t / k } else { 0.0 }
    }

    /// The interval of i_d0 \[A\] the loss minimum lies in. For ΔL ≥ 0: [−I_max, 0] — the
    /// MTPA point (3.10) is ≤ 0, the core losses (3.4) fall with the flux L_d·i_d + ψ_m
    /// and the inverter losses (3.14) pull back towards MTPA, so nothing favours i_d0 > 0.
    /// For inverse saliency (ΔL < 0) the MTPA point is ≥ 0 and the core losses pull it
    /// down: [max(−I_max, ψ_m/ΔL), I_max], stopping where the torque factor ψ_m − ΔL·i_d0
    /// of (3.7) changes sign (beyond it no i_q0 gives the torque with that sign).
    pub fn search_range(&self) -> (f64, f64) {
        let dl = self.lq - self.ld;
        if dl >= 0.0 {
            (-self.i_max, 0.0)
        } else {
            ((self.psi / dl).max(-self.i_max), self.i_max)
        }
    }

    /// The loss-minimising terminal (i_d, i_q) \[A\] at torque `t` and speed `w`:
    /// golden-section search over i_d0 in [`LossModel::search_range`] along the
    /// constant-torque curve.
    pub fn optimum(&self, w: f64, t: f64) -> (f64, f64) {
        let f = |id0: f64| self.loss(w, id0, self.iq0_for(t, id0));
        let g = (5f64.sqrt() - 1.0) / 2.0;
        let (mut a, mut b) = self.search_range();
        let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
        let (mut fc, mut fd) = (f(c), f(d));
        for _ in 0..GOLDEN_STEPS {
            if fc < fd {
                b = d;
                d = c;
                fd = fc;
                c = b - g * (b - a);
                fc = f(c);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + g * (b - a);
                fd = f(d);
            }
        }
        let id0 = 0.5 * (a + b);
        self.terminal(w, id0, self.iq0_for(t, id0))
    }

    /// The loss-minimising i_d \[A\] at terminal `iq` \[A\] ≥ 0 and speed `w` ≥ 0: bisection on
    /// the torque until the optimum's terminal i_q is `iq`, then kept inside the current
    /// circle (2.50) — losses fall monotonically towards the unconstrained optimum along
    /// the constant-torque curve, so the constrained optimum lies on the circle.
    pub fn id_at(&self, w: f64, iq: f64) -> f64 {
        let circle = (self.i_max * self.i_max - iq * iq).max(0.0).sqrt();
        self.unconstrained_id_at(w, iq).clamp(-circle, circle)
    }

    fn unconstrained_id_at(&self, w: f64, iq: f64) -> f64 {
        let t_hi = 2.0
            * 1.5
            * f64::from(self.pole_pairs)
            * (iq + self.i_max)
            * (self.psi + (self.lq - self.ld).abs() * self.i_max);
        let (mut lo, mut hi) = (-t_hi, t_hi);
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (lo + hi);
            if self.optimum(w, mid).1 < iq {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        self.optimum(w, 0.5 * (lo + hi)).0
    }
}

/// Points of a uniform grid from 0 to `end`.
pub fn grid(end: f64, points: usize) -> Vec<f64> {
    let n = points.max(2) - 1;
    (0..=n).map(|k| end * k as f64 / n as f64).collect()
}

/// Largest |linear interpolation − exact| over the interval midpoints of `xs`.
pub fn midpoint_error(xs: &[f64], ys: &[f64], exact: impl Fn(f64) -> f64) -> f64 {
    xs.windows(2)
        .zip(ys.windows(2))
        .map(|(x, y)| (0.5 * (y[0] + y[1]) - exact(0.5 * (x[0] + x[1]))).abs())
        .fold(0.0, f64::max)
}

/// A loss-minimising table: `id[k][j]` at speed `speeds[k]` and |i_q| = `iq[j]`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LossTable {
    /// Electrical speeds ω [rad/s] (rows).
    pub speeds_rad_s: Vec<f64>,
    /// |i_q| grid \[A\] (columns), the MTPA grid.
    pub iq_a: Vec<f64>,
    /// i_d \[A\], row-major: `id_a[k·iq_a.len() + j]` at `speeds_rad_s[k]`, `iq_a[j]`.
    pub id_a: Vec<f64>,
    /// Largest bilinear-interpolation error \[A\] against the numeric optimum at the cell
    /// centres and edge midpoints.
    pub max_interpolation_error_a: f64,
}

/// The table of [`LossModel::id_at`] on `speeds` × `iq`, with its midpoint error.
pub fn loss_table(model: &LossModel, speeds: &[f64], iq: &[f64]) -> LossTable {
    let id: Vec<Vec<f64>> = speeds
        .iter()
        .map(|&w| iq.iter().map(|&i| model.id_at(w, i)).collect())
        .collect();
    let mut err = 0.0f64;
    for (k, &w) in speeds.iter().enumerate() {
        // Along i_q on every grid speed, …
        err = err.max(midpoint_error(iq, &id[k], |i| model.id_at(w, i)));
        if k + 1 < speeds.len() {
            let wm = 0.5 * (w + speeds[k + 1]);
            for j in 0..iq.len() {
                // … along ω on every grid current, …
                let lin = 0.5 * (id[k][j] + id[k + 1][j]);
                err = err.max((lin - model.id_at(wm, iq[j])).abs());
                // … and at the cell centres.
                if j + 1 < iq.len() {
                    let lin = 0.25 * (id[k][j] + id[k][j + 1] + id[k + 1][j] + id[k + 1][j + 1]);
                    err = err.max((lin - model.id_at(wm, 0.5 * (iq[j] + iq[j + 1]))).abs());
                }
            }
        }
    }
    LossTable {
        speeds_rad_s: speeds.to_vec(),
        iq_a: iq.to_vec(),
        // Rounded to 1 µA (far below the interpolation error): the numeric optimum's
        // round-off (~1e-14 A at ω = 0) is not carried into the generated tables.
        id_a: id.concat().iter().map(|x| (x * 1e6).round() / 1e6 + 0.0).collect(),
        max_interpolation_error_a: err,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thesis B motor, Table B.2 (SI), I_base = √2·160 A (Table A.1).
    fn chalmers(rc: Option<f64>, inverter: bool) -> LossModel {
        LossModel {
            pole_pairs: 2,
            rs: 7.9e-3,
            ld: 0.23e-3,
            lq: 0.56e-3,
            psi: 0.104,
            rc,
            inverter: inverter.then_some(InverterLoss {
                threshold_v: 0.87,
                resistance_ohm: 2.6e-3,
                switching_energy_j: 0.306,
                recovery_energy_j: 0.015,
                nominal_current_a: 600.0,
                switching_frequency_hz: 10e3,
            }),
            i_max: 316.8,
        }
    }

    /// (3.10) by hand at i_q = 1 pu = 226.27 A for the thesis B motor: ΔL = 0.33 mH,
    /// ψ/(2ΔL) = 0.104/0.00066 = 157.576 A, √(157.576² + 226.27²) = √(24830.2 + 51198.1)
    /// = 275.733 A, i_d = 157.576 − 275.733 = −118.157 A (−0.5222 pu).
    #[test]
    fn mtpa_at_one_pu_by_hand() {
        let id = mtpa_id(0.104, 0.33e-3, 226.27);
        assert!((id + 118.157).abs() < 0.01, "{id}");
        assert_eq!(mtpa_id(0.104, 0.0, 100.0), 0.0);
        assert_eq!(mtpa_id(0.104, 0.33e-3, 0.0), 0.0);
    }

    /// Thesis B §2.2.1: "i_q^ref = 0.8 pu and i_d^ref = −0.25 pu … set according to the max
    /// torque-per-ampere trajectory", with the saturated L_q = 0.42 mH (0.65 pu, Table B.2):
    /// ΔL = 0.19 mH, i_q = 181.0 A, ψ/(2ΔL) = 273.7 A, i_d = 273.7 − √(273.7² + 181.0²)
    /// = −54.4 A = −0.240 pu (the thesis rounds to −0.25).
    #[test]
    fn mtpa_matches_the_thesis_operating_point() {
        let id = mtpa_id(0.104, 0.19e-3, 0.8 * 226.27) / 226.27;
        assert!((id + 0.240).abs() < 0.002, "{id} pu");
    }

    /// Without core losses (R_c → ∞) and at ω → 0 the loss minimum is the MTPA point
    /// (3.10), (C.4) — with and without inverter losses, which depend on |i| only.
    #[test]
    fn loss_minimum_reduces_to_mtpa() {
        for m in [chalmers(None, false), chalmers(None, true), chalmers(Some(24.5), true)] {
            for iq in [0.0, 50.0, 150.0, 270.0] {
                let w = if m.rc.is_some() { 0.0 } else { 1256.6 };
                let id = m.id_at(w, iq);
                let want = mtpa_id(m.psi, m.lq - m.ld, iq);
                assert!((id - want).abs() < 1e-6 * m.i_max, "{iq} A: {id} vs {want}");
            }
        }
    }

    /// Fig. 3.1: with core losses (R_c = 30 pu = 24.5 Ω) "when the rotor speed is increased,
    /// more negative i_d should be added, as compared to the results given by (3.10)".
    /// And each table point is a true minimum: no i_d0 on a 4001-point scan of the same
    /// constant-torque curve has lower losses (an independent brute-force check).
    #[test]
    fn core_losses_add_negative_id_and_the_point_is_a_minimum() {
        let m = chalmers(Some(24.5), false);
        let iq = 0.25 * 226.27;
        let ids: Vec<f64> = [0.0, 628.3, 1256.6].iter().map(|&w| m.id_at(w, iq)).collect();
        assert!(ids[0] > ids[1] && ids[1] > ids[2], "{ids:?}");
        for (w, id) in [(628.3, ids[1]), (1256.6, ids[2])] {
            // Back to the magnetising currents of this terminal point (Fig. 2.7 inverted).
            let rc = 24.5;
            let (a11, a12, a21, a22) = (1.0, -w * m.lq / rc, w * m.ld / rc, 1.0);
            let (b1, b2) = (id, iq - w * m.psi / rc);
            let det = a11 * a22 - a12 * a21;
            let id0 = (b1 * a22 - a12 * b2) / det;
            let iq0 = (a11 * b2 - a21 * b1) / det;
            let t = m.torque(id0, iq0);
            let best = m.loss(w, id0, iq0);
            for k in 0..=4000 {
                let x = -m.i_max * f64::from(k) / 4000.0;
                let y = t / (1.5 * 2.0 * (m.psi - (m.lq - m.ld) * x));
                assert!(
                    m.loss(w, x, y) >= best - 1e-9 * best,
                    "ω = {w}: i_d0 = {x} beats the optimum"
                );
            }
        }
    }

    /// Inverter losses grow with |i| only, so they pull the optimum back towards MTPA
    /// (thesis B §3.3.4, Fig. 3.5: "the advantage of adding negative i_d … is reduced").
    #[test]
    fn inverter_losses_pull_towards_mtpa() {
        let (w, iq) = (1256.6, 0.25 * 226.27);
        let motor = chalmers(Some(24.5), false).id_at(w, iq);
        let both = chalmers(Some(24.5), true).id_at(w, iq);
        let mtpa = mtpa_id(0.104, 0.33e-3, iq);
        assert!(motor < both && both < mtpa, "{motor} {both} {mtpa}");
    }

    /// (3.11)–(3.14) by hand at i = 300 A (I_rms = 212.13 A), V = 0.87 V, r = 2.6 mΩ,
    /// f_sw = 10 kHz: P_cond = 2√2·0.87·212.13/π + 2.6e-3·212.13² = 166.16 + 117.00 = 283.16 W,
    /// P_s,T = 0.306·2√2·212.13·1e4/(π·600) = 974.03 W, P_s,D = 150 W; ×3 = 4221.56 W.
    #[test]
    fn inverter_loss_by_hand() {
        let p = chalmers(None, true).inverter.unwrap().loss(300.0);
        assert!((p - 4221.56).abs() < 0.05, "{p}");
    }

    /// An inverse-saliency variant of the thesis B motor (L_d = 0.70 mH > L_q = 0.56 mH,
    /// ΔL = −0.14 mH; ψ, R_s, n_p of Table B.2) — a labelled variant, no public data.
    fn inverse(rc: Option<f64>) -> LossModel {
        LossModel {
            ld: 0.70e-3,
            lq: 0.56e-3,
            ..chalmers(rc, false)
        }
    }

    /// (3.10) for inverse saliency, by hand: a = ψ/(2ΔL) = 0.104/(−0.28e-3) = −371.429 A;
    /// at i_q = 226.27 A the roots a ± √(a² + i_q²) = −371.429 ± 434.923 are +63.494 A and
    /// −806.351 A. The torque maximum is the + root (ψ − ΔL·i_d = 0.104 + 0.14e-3·63.49 > 0;
    /// the other root lies beyond i_d = ψ/ΔL = −742.9 A where the torque is negative).
    /// On the circle I = 316.8 A: i_d = (ψ − √(ψ² + 8ΔL²I²))/(4ΔL)
    /// = (0.104 − 0.162950)/(−0.56e-3) = +105.268 A, i_q = 298.799 A, T = 106.44 N·m
    /// (98.84 N·m at i_d = 0).
    #[test]
    fn mtpa_inverse_saliency_by_hand() {
        let id = mtpa_id(0.104, -0.14e-3, 226.27);
        assert!((id - 63.494).abs() < 1e-3, "{id}");
        let (id, iq) = mtpa_corner(0.104, -0.14e-3, 316.8);
        assert!((id - 105.268).abs() < 1e-3 && (iq - 298.799).abs() < 1e-3, "{id} {iq}");
        let m = inverse(None);
        assert!((m.torque(id, iq) - 106.436).abs() < 1e-3);
        // Independent check: a scan of the circle finds no larger torque.
        let best = (0..=20_000)
            .map(|k| {
                let x = -316.8 + 633.6 * f64::from(k) / 20_000.0;
                m.torque(x, (316.8f64 * 316.8 - x * x).max(0.0).sqrt())
            })
            .fold(f64::MIN, f64::max);
        assert!(
            best <= m.torque(id, iq) + 1e-9 && best > m.torque(id, iq) - 1e-3,
            "{best}"
        );
    }

    /// The loss-minimising search for inverse saliency: at ω = 0 (and without R_c) it
    /// returns the positive MTPA i_d, not the i_d ≤ 0 bound; with R_c = 24.5 Ω more speed
    /// asks for less i_d (Fig. 3.1's trend, the core losses fall with L_d·i_d + ψ_m); every
    /// point beats a 4001-point brute-force scan of its constant-torque curve over
    /// [−I_max, I_max].
    #[test]
    fn loss_minimum_for_inverse_saliency() {
        for iq in [0.0, 50.0, 150.0, 270.0] {
            let want = mtpa_id(0.104, -0.14e-3, iq);
            for (m, w) in [(inverse(None), 1256.6), (inverse(Some(24.5)), 0.0)] {
                let id = m.id_at(w, iq);
                assert!((id - want).abs() < 1e-6 * m.i_max, "{iq} A: {id} vs {want}");
            }
        }
        let m = inverse(Some(24.5));
        let iq = 0.5 * 226.27;
        let ids: Vec<f64> = [0.0, 628.3, 1256.6].iter().map(|&w| m.id_at(w, iq)).collect();
        assert!(ids[0] > 0.0 && ids[0] > ids[1] && ids[1] > ids[2], "{ids:?}");
        for (w, id) in [(628.3, ids[1]), (1256.6, ids[2])] {
            let rc = 24.5;
            let (a12, a21) = (-w * m.lq / rc, w * m.ld / rc);
            let b2 = iq - w * m.psi / rc;
            let det = 1.0 - a12 * a21;
            let id0 = (id - a12 * b2) / det;
            let iq0 = (b2 - a21 * id) / det;
            let t = m.torque(id0, iq0);
            let best = m.loss(w, id0, iq0);
            for k in 0..=4000 {
                let x = -m.i_max + 2.0 * m.i_max * f64::from(k) / 4000.0;
                let y = t / (1.5 * 2.0 * (m.psi - (m.lq - m.ld) * x));
                assert!(
                    m.loss(w, x, y) >= best - 1e-9 * best,
                    "ω = {w}: i_d0 = {x} beats the optimum"
                );
            }
        }
    }

    #[test]
    fn midpoint_error_of_a_parabola() {
        // y = x² on {0, 1, 2}: the chord misses the midpoints by h²/4 = 0.25.
        let e = midpoint_error(&[0.0, 1.0, 2.0], &[0.0, 1.0, 4.0], |x| x * x);
        assert!((e - 0.25).abs() < 1e-12);
        assert_eq!(grid(2.0, 3), vec![0.0, 1.0, 2.0]);
    }
}
