//! Closed-loop field weakening: the current references from a torque (i_q) demand,
//! thesis B §2.3.2–2.3.3 and Appendix D.
//!
//! ```text
//! di_d^ref/dt = γ·(V'_max² − v_d² − v_q²)                        (2.55)
//! γ = α_fw/(2·ω_fw·L̂_d·V'_max),  ω_fw = max(ω_base, |ω̂_r|)        (2.60)
//! −I_max ≤ i_d^ref ≤ i_d,MTPA(i_q^0)                                (2.56)
//! i_q^ref = sign(i_q^0)·√(I_max² − (i_d^ref)²)  if the circle is left (2.57), Mode B
//! ```
//!
//! Discretised with the forward difference as in Appendix D:
//! `i_d^ref(n+1) = i_d^ref(n) + T_s·γ·(V'_max² − |v(n)|²)`, then clamped to (2.56).
//! Below base speed the voltage error is positive and the clamp holds i_d^ref on the
//! max-torque-per-ampere curve (3.10); above it the integrator lowers i_d^ref until the
//! voltage magnitude settles at V'_max — with the pole at −α_fw in both modes, (2.61),
//! (2.65). `V'_max = voltage_fraction·V_max` follows the measured DC link (thesis B
//! §2.3: "the dc-link voltage is typically monitored"), so no base speed has to be
//! recomputed when U_dc changes; γ is recomputed every step from the same V'_max.
//!
//! The voltage fed back is the previous step's current-controller output. Appendix D
//! uses the unlimited PI output; the firmware step reports the applied (circle-limited)
//! voltage [`crate::step::StepOutput::u_dq`]. The two are equal while |v| ≤ V_max; when
//! the current loop saturates, |v| = V_max > V'_max still drives i_d^ref down at the
//! bounded rate γ·(V'_max² − V_max²), so `voltage_fraction < 1` is required (the thesis
//! sets V'_max below V_max anyway: 0.9 in Fig. 2.15, 0.85 in Fig. 2.16).
//!
//! This is a stage the board runs before [`crate::step::ControllerConfig::process`]
//! (it turns a torque demand into `Demand::Current`), so the current step stays a pure
//! current controller and the resolver and sensorless drives share it.

use crate::transforms::Dq;

/// The max-torque-per-ampere curve i_d,MTPA(i_q), the upper limit of (2.56).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MtpaCurve {
    /// i_d = 0 (non-salient machine, L_d = L_q).
    Zero,
    /// Thesis B (3.10) with constant inductances, ΔL = L̂_q − L̂_d:
    /// `i_d = ψ_m/(2ΔL) − √((ψ_m/(2ΔL))² + i_q²)`, evaluated in the cancellation-free
    /// form `i_d = −2ΔL·i_q²/(ψ_m + √(ψ_m² + 4ΔL²·i_q²))` (exact, and 0 for ΔL = 0).
    Analytic {
        /// ψ̂_m \[Wb\].
        psi_m: f32,
        /// ΔL = L̂_q − L̂_d \[H\].
        delta_l: f32,
    },
    /// Points `[|i_q|, i_d]` \[A\] sorted by |i_q| (e.g. with the saturated L_q(i_q) of
    /// (2.25)), linear in between, constant beyond the ends; empty = 0.
    Table(&'static [[f32; 2]]),
}

impl MtpaCurve {
    /// i_d,MTPA \[A\] at `iq` \[A\] (even in i_q).
    pub fn id(&self, iq: f32) -> f32 {
        let x = libm::fabsf(iq);
        match *self {
            Self::Zero => 0.0,
            Self::Analytic { psi_m, delta_l } => {
                let den = psi_m + libm::sqrtf(psi_m * psi_m + 4.0 * delta_l * delta_l * x * x);
                if den > 0.0 { -2.0 * delta_l * x * x / den } else { 0.0 }
            }
            Self::Table(points) => table(points, x),
        }
    }
}

/// Piecewise-linear lookup of `x` in `[x, y]` points sorted by x.
fn table(points: &[[f32; 2]], x: f32) -> f32 {
    let (Some(first), Some(last)) = (points.first(), points.last()) else {
        return 0.0;
    };
    let [x0, y0] = *first;
    if x <= x0 {
        return y0;
    }
    for w in points.windows(2) {
        if let [[xa, ya], [xb, yb]] = *w
            && x <= xb
        {
            let span = xb - xa;
            return if span > 0.0 {
                ya + (yb - ya) * (x - xa) / span
            } else {
                yb
            };
        }
    }
    let [_, y_last] = *last;
    y_last
}

/// Field-weakening controller constants (designed off-line, thesis B §2.3.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldWeakeningConfig {
    /// Sample period T_s \[s\] (forward difference, App. D).
    pub sample_period: f32,
    /// Field-weakening bandwidth α_fw \[rad/s\] (2.60), α_fw ≪ α_c, α_fw ≥ 10·b/J.
    pub bandwidth: f32,
    /// L̂_d \[H\] in γ (2.60).
    pub ld: f32,
    /// Electrical base speed ω_base \[rad/s\]: ω_fw = max(ω_base, |ω̂_r|) (2.60).
    pub base_speed: f32,
    /// V'_max/V_max \[-\], < 1 (thesis B: 0.9 in Fig. 2.15).
    pub voltage_fraction: f32,
    /// Current-circle radius I_max \[A\] (2.50), also the demagnetisation limit of (2.56).
    pub current_max: f32,
    /// i_d,MTPA(i_q) (2.56), (3.10).
    pub mtpa: MtpaCurve,
}

/// State: the integrated d-axis reference.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FieldWeakeningState {
    /// i_d^ref \[A\] (2.55).
    pub id_ref: f32,
}

/// What one step of the field-weakening controller reads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldWeakeningInput {
    /// q-current demand i_q^0 \[A\] (torque demand through (2.34)).
    pub iq_demand: f32,
    /// Electrical speed ω̂_r \[rad/s\] (observed or estimated).
    pub omega: f32,
    /// The current controller's previous output voltage v_dq \[V\].
    pub voltage: Dq,
    /// Radius of the inverter voltage circle V_max \[V\] (2.51) at the measured U_dc.
    pub voltage_max: f32,
    /// Additional bound on |i_q^ref| \[A\], e.g. the estimator's (4.92);
    /// `f32::INFINITY` for none.
    pub iq_limit: f32,
}

impl FieldWeakeningConfig {
    /// γ (2.60) \[A/(V²·s)\] at electrical speed `omega` and limit `v_max_prime`;
    /// 0 when any factor is not positive and finite.
    pub fn gain(&self, omega: f32, v_max_prime: f32) -> f32 {
        let w_fw = libm::fabsf(omega).max(self.base_speed);
        let den = 2.0 * w_fw * self.ld * v_max_prime;
        let g = self.bandwidth / den;
        if den > 0.0 && g.is_finite() && g > 0.0 { g } else { 0.0 }
    }

    /// One step: returns `(i_d^ref, i_q^ref)` \[A\].
    ///
    /// Non-finite inputs leave the integrator where it was (the references stay within
    /// the limits); a NaN demand gives i_q^ref = 0.
    pub fn process(&self, state: &mut FieldWeakeningState, input: FieldWeakeningInput) -> (f32, f32) {
        let i_max = if self.current_max > 0.0 { self.current_max } else { 0.0 };
        let iq0 = if input.iq_demand.is_nan() { 0.0 } else { input.iq_demand };
        let v_prime = self.voltage_fraction * input.voltage_max;
        let gamma = self.gain(input.omega, v_prime);
        let v = input.voltage;
        let step = self.sample_period * gamma * (v_prime * v_prime - v.d * v.d - v.q * v.q);
        if step.is_finite() && state.id_ref.is_finite() {
            state.id_ref += step;
        } else if !state.id_ref.is_finite() {
            state.id_ref = 0.0;
        }
        // (2.56): upper limit first, the demagnetisation limit wins (App. D order).
        let id_mtpa = self.mtpa.id(iq0);
        if state.id_ref > id_mtpa {
            state.id_ref = id_mtpa;
        }
        if state.id_ref < -i_max {
            state.id_ref = -i_max;
        }
        let id = state.id_ref;
        // (2.57), Mode B: stay on the current circle.
        let iq_circle = libm::sqrtf((i_max * i_max - id * id).max(0.0));
        let limit = if input.iq_limit.is_nan() {
            iq_circle
        } else {
            iq_circle.min(libm::fabsf(input.iq_limit))
        };
        let iq = iq0.max(-limit).min(limit);
        (id, iq)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thesis B motor (Table B.2), SI.
    const RS: f32 = 7.9e-3;
    const LD: f32 = 0.23e-3;
    const LQ: f32 = 0.56e-3;
    const PSI: f32 = 0.104;
    /// I_base = √2·160 A (Table A.1).
    const I_BASE: f32 = 226.27;
    /// ω_base = 2π·200 Hz.
    const W_BASE: f32 = 1256.64;
    /// V_base = 320 V/√3.
    const V_BASE: f32 = 184.75;

    fn config(alpha_fw: f32) -> FieldWeakeningConfig {
        FieldWeakeningConfig {
            sample_period: 1e-4,
            bandwidth: alpha_fw,
            ld: LD,
            base_speed: W_BASE,
            voltage_fraction: 0.9,
            current_max: 1.4 * I_BASE,
            mtpa: MtpaCurve::Analytic {
                psi_m: PSI,
                delta_l: LQ - LD,
            },
        }
    }

    /// Steady-state voltage of the dq model at electrical speed w (thesis B (2.52)).
    fn voltage(w: f32, id: f32, iq: f32) -> Dq {
        Dq {
            d: RS * id - w * LQ * iq,
            q: RS * iq + w * (LD * id + PSI),
        }
    }

    /// Thesis B §2.2.1: "i_q^ref = 0.8 pu and i_d^ref = −0.25 pu, where i_d^ref is set
    /// according to the max torque-per-ampere trajectory", i.e. (3.10) with the saturated
    /// L_q = 0.42 mH (0.65 pu, Table B.2). Hand calculation: ΔL = 0.19 mH, i_q = 181.0 A,
    /// ψ/(2ΔL) = 273.7 A, i_d = 273.7 − √(273.7² + 181.0²) = −54.4 A = −0.240 pu.
    #[test]
    fn mtpa_matches_the_thesis_operating_point() {
        let m = MtpaCurve::Analytic {
            psi_m: PSI,
            delta_l: 0.42e-3 - LD,
        };
        let id = m.id(0.8 * I_BASE) / I_BASE;
        assert!((id + 0.25).abs() < 0.015, "{id} pu");
        assert!((m.id(-0.8 * I_BASE) / I_BASE - id).abs() < 1e-6, "even in i_q");
        // Non-salient: 0.
        let round = MtpaCurve::Analytic {
            psi_m: PSI,
            delta_l: 0.0,
        };
        assert_eq!(round.id(100.0), 0.0);
        assert_eq!(MtpaCurve::Zero.id(100.0), 0.0);
    }

    #[test]
    fn table_interpolates_and_holds_its_ends() {
        static PTS: [[f32; 2]; 3] = [[0.0, 0.0], [100.0, -20.0], [200.0, -60.0]];
        let m = MtpaCurve::Table(&PTS);
        assert_eq!(m.id(0.0), 0.0);
        assert!((m.id(50.0) + 10.0).abs() < 1e-5);
        assert!((m.id(-150.0) + 40.0).abs() < 1e-5);
        assert_eq!(m.id(500.0), -60.0);
        assert_eq!(MtpaCurve::Table(&[]).id(5.0), 0.0);
    }

    /// γ (2.60), hand-evaluated: α_fw = 147 rad/s, L_d = 0.23 mH, V'_max = 0.9·184.75 V
    /// = 166.3 V. Below base speed ω_fw = ω_base: γ = 147/(2·1256.64·0.23e-3·166.3)
    /// = 1.5293 A/(V²·s); at 2ω_base half of it.
    #[test]
    fn gain_follows_2_60() {
        let c = config(147.0);
        let v = 0.9 * V_BASE;
        assert!((c.gain(300.0, v) - 1.5293).abs() < 1e-3);
        assert!((c.gain(-2.0 * W_BASE, v) - 1.5293 / 2.0).abs() < 1e-3);
        assert_eq!(c.gain(300.0, 0.0), 0.0);
        assert_eq!(c.gain(300.0, f32::NAN), 0.0);
    }

    /// Runs the controller against the quasi-static motor (currents follow their
    /// references through a first-order current loop α_c) at speed `w` for `n` steps.
    fn run(
        c: &FieldWeakeningConfig,
        st: &mut FieldWeakeningState,
        w: f32,
        iq0: f32,
        alpha_c: f32,
        n: usize,
    ) -> Vec<(f32, f32, f32)> {
        let ts = c.sample_period;
        let a = 1.0 - libm::expf(-alpha_c * ts);
        let (mut id, mut iq) = (st.id_ref, 0.0f32);
        let mut v = voltage(w, id, iq);
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let (idr, iqr) = c.process(
                st,
                FieldWeakeningInput {
                    iq_demand: iq0,
                    omega: w,
                    voltage: v,
                    voltage_max: V_BASE,
                    iq_limit: f32::INFINITY,
                },
            );
            id += a * (idr - id);
            iq += a * (iqr - iq);
            v = voltage(w, id, iq);
            out.push((idr, iqr, libm::sqrtf(v.d * v.d + v.q * v.q)));
        }
        out
    }

    /// Mode A, small torque, ω = 1.5·ω_base. With an ideal first-order current loop
    /// α_c the linearised loop is (2.59) without the (p + α_c)³ factor:
    /// p² + α_c·p + 2·α_c·γ·|ω|·L_d·V'_max = p² + α_c·p + α_c·α_fw (γ by (2.60),
    /// ω_fw = |ω|), slow root p = −α_c/2·(1 − √(1 − 4α_fw/α_c)) → −α_fw for α_fw ≪ α_c
    /// (2.61). A small perturbation of i_d^ref (2 A, so the quadratic voltage error stays
    /// linear to 0.3 %) decays to e^(p/α_fw) after 1/α_fw (within 2 %), and the
    /// voltage settles on V'_max (2.55) with i_d on the voltage ellipse (2.52).
    #[test]
    fn mode_a_pole_at_minus_alpha_fw() {
        let alpha_fw = 14.7;
        let alpha_c = 1470.0;
        let c = config(alpha_fw);
        let w = 1.5 * W_BASE;
        let vp = 0.9 * V_BASE;
        // Equilibrium with i_q = 0 from (2.52) (hand-solved quadratic, R·i_d kept):
        // (R·i_d)² + (w·(L_d·i_d + ψ))² = V'² → a·i_d² + b·i_d + c = 0.
        let (qa, qb, qc) = (
            RS * RS + (w * LD) * (w * LD),
            2.0 * w * w * LD * PSI,
            (w * PSI) * (w * PSI) - vp * vp,
        );
        let id_eq = (-qb + libm::sqrtf(qb * qb - 4.0 * qa * qc)) / (2.0 * qa);
        let slow = alpha_c / 2.0 * (1.0 - libm::sqrtf(1.0 - 4.0 * alpha_fw / alpha_c));
        let mut st = FieldWeakeningState { id_ref: id_eq - 2.0 };
        let n = libm::roundf(1.0 / (alpha_fw * c.sample_period)) as usize;
        let out = run(&c, &mut st, w, 0.0, alpha_c, 30 * n);
        let (id_n, _, _) = out[n - 1];
        let ratio = (id_n - id_eq) / -2.0;
        let want = libm::expf(-slow / alpha_fw);
        assert!(
            (ratio / want - 1.0).abs() < 0.02,
            "decay after 1/α_fw: {ratio} vs {want}"
        );
        let (id_end, iq_end, v_end) = *out.last().unwrap();
        assert!((id_end - id_eq).abs() < 0.01, "{id_end} vs {id_eq}");
        assert_eq!(iq_end, 0.0);
        assert!((v_end - vp).abs() < 1e-3 * vp, "{v_end} vs {vp}");
    }

    /// Below base speed the voltage error is positive: i_d^ref stays on the MTPA curve.
    #[test]
    fn below_base_speed_holds_mtpa() {
        let c = config(147.0);
        let mut st = FieldWeakeningState::default();
        let iq = 0.8 * I_BASE;
        let out = run(&c, &mut st, 0.5 * W_BASE, iq, 1470.0, 2000);
        let (id, iqr, v) = *out.last().unwrap();
        assert_eq!(id, c.mtpa.id(iq));
        assert_eq!(iqr, iq);
        assert!(v < 0.9 * V_BASE);
    }

    /// Mode B at 3·ω_base with full demand: i_d^ref goes deep, the current stays on the
    /// circle (2.57) and |v| settles on V'_max.
    #[test]
    fn mode_b_stays_on_the_circle() {
        let c = config(147.0);
        let mut st = FieldWeakeningState {
            id_ref: c.mtpa.id(c.current_max),
        };
        let out = run(&c, &mut st, 3.0 * W_BASE, c.current_max, 1470.0, 20_000);
        let (id, iq, v) = *out.last().unwrap();
        let mag = libm::sqrtf(id * id + iq * iq);
        assert!((mag - c.current_max).abs() < 1e-3 * c.current_max, "{mag}");
        assert!(iq > 0.0 && id < c.mtpa.id(c.current_max));
        assert!((v - 0.9 * V_BASE).abs() < 2e-3 * V_BASE, "{v}");
        for (id, iq, _) in out {
            assert!(id >= -c.current_max && libm::sqrtf(id * id + iq * iq) <= 1.0001 * c.current_max);
        }
    }

    /// Beyond the reachable speed i_d^ref stops at −I_max (demagnetisation limit, 2.56)
    /// and i_q^ref at 0; an estimator bound (4.92) caps i_q; NaN inputs do not stick.
    #[test]
    fn limits_and_bad_inputs() {
        let c = config(147.0);
        let mut st = FieldWeakeningState::default();
        let input = FieldWeakeningInput {
            iq_demand: 100.0,
            omega: 10.0 * W_BASE,
            voltage: Dq {
                d: 0.0,
                q: 2.0 * V_BASE,
            },
            voltage_max: V_BASE,
            iq_limit: 30.0,
        };
        let mut r = (0.0, 0.0);
        for _ in 0..100_000 {
            r = c.process(&mut st, input);
        }
        assert_eq!(r, (-c.current_max, 0.0));
        st.id_ref = -10.0;
        let (_, iq) = c.process(&mut st, FieldWeakeningInput { omega: 0.0, ..input });
        assert_eq!(iq, 30.0);
        let (id, iq) = c.process(
            &mut st,
            FieldWeakeningInput {
                iq_demand: f32::NAN,
                voltage: Dq { d: f32::NAN, q: 0.0 },
                ..input
            },
        );
        assert!(id.is_finite() && iq == 0.0);
        assert_eq!(st.id_ref, id);
    }
}
