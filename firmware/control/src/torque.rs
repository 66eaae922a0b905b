//! The torque → current-reference stage: a torque demand \[N·m\] becomes the current
//! references (i_d^ref, i_q^ref) the current loop follows, on the current circle, the
//! voltage limit of the measured DC link and, where the motor has one inside the circle,
//! the maximum-torque-per-volt line. It runs inside the control step
//! ([`crate::step::Demand::Torque`]), so the image's control interrupt and `motorgen
//! verify` run this one function with one configuration.
//!
//! ```text
//! T = 3/2·n_p·i_q·(ψ_M + (L_d − L_q)·i_d)                          thesis A (2.33)
//! i_d,MTPA(T): (3.10) along the torque, a table uniform in T         thesis B (3.10)
//! di_d^ref/dt = γ·(V'_max² − v_d² − v_q²)                            thesis B (2.55)
//! γ = α_fw/(2·ω_fw·L̂_d·V'_max),  ω_fw = max(ω_base, |ω̂_r|)          thesis B (2.60)
//! −I_max ≤ i_d^ref ≤ i_d,MTPA(T)                                      thesis B (2.56)
//! Mode A: i_q^ref = T/(3/2·n_p·(ψ_M + (L_d − L_q)·i_d^ref))          (2.33) solved for i_q
//! Mode B: |i_q^ref| ≤ √(I_max² − (i_d^ref)²)                          thesis B (2.57)
//! Mode C: i_d^ref ≥ i_d,MTPV(i_q^ref); beyond it |v| is held by
//!         lowering i_q^ref along the MTPV line at the gain γ·L̂_d/L̂_q  (MTPV, see below)
//! ```
//!
//! Below base speed the voltage error of (2.55) is positive and the clamp holds i_d^ref on
//! the max-torque-per-ampere curve (3.10) of the demanded torque, and i_q^ref makes that
//! torque exactly (2.33). Above it the integrator lowers i_d^ref until |v| settles at
//! V'_max with the pole at −α_fw (2.61), (2.65); Mode A keeps the torque along the
//! constant-torque curve, Mode B the circle. `V'_max = voltage_fraction·V_max` follows the
//! measured DC link (thesis B §2.3: "the dc-link voltage is typically monitored"), so no
//! base speed is recomputed when U_dc changes; γ is recomputed every step.
//!
//! **Mode C, maximum torque per volt (MTPV).** For a given stator flux |ψ_s| = |v|/ω (R_s
//! neglected) the torque 3/2·n_p·(ψ_d·i_q − ψ_q·i_d) with ψ_d = ψ_M + L_d·i_d,
//! ψ_q = L_q·i_q is largest where (with a = 1/L_d − 1/L_q, c = ψ_M/L_d)
//! `a·ψ_d² − c·ψ_d − a·ψ_q² = 0`, i.e. on the line
//! `ψ_d = −2a·ψ_q²/(c + √(c² + 4a²·ψ_q²))` (the root continuous at a = 0: ψ_d = 0, the
//! non-salient i_d = −ψ_M/L_d) — the voltage-limited operation of Morimoto et al.,
//! "Expansion of operating limits for permanent magnet motor by current vector control
//! considering inverter capacity", IEEE Trans. Ind. Appl. 26(5), 1990, and Sul,
//! *Control of Electric Machine Drive Systems* (2011) §6.4 ("maximum torque per voltage").
//! It lies inside the circle |i| = I_max when ψ_M < L_d·I_max (its end at i_q = 0 is
//! i_d = −ψ_M/L_d). There thesis B's integrator would push i_d^ref past the line, where
//! the torque falls and |v| rises again; so i_d^ref is held on the line, and while |v| is
//! still above V'_max the same voltage error lowers i_q^ref instead (a second integrator,
//! released first when the voltage error turns positive). Moving along the line, |v|
//! answers a change of i_q with ω·L_q (v_d ≈ −ω·L_q·i_q dominates where ψ_d is small),
//! where (2.60) assumes ω·L_d for i_d: the gain γ·L̂_d/L̂_q keeps the pole at −α_fw.
//!
//! The voltage fed back is the previous step's applied (circle-limited) current-controller
//! output (Appendix D uses the unlimited one; they are equal while |v| ≤ V_max); when the
//! current loop saturates, |v| = V_max > V'_max still drives i_d^ref down at the bounded
//! rate γ·(V'_max² − V_max²), so `voltage_fraction < 1` is required (thesis B: 0.9 in
//! Fig. 2.15, 0.85 in Fig. 2.16).
//!
//! Square roots go through [`Trig::sqrt`] (the FPU's VSQRT on the board), divisions are
//! the FPU's VDIV; nothing here loops.

use crate::transforms::Dq;
use crate::trig::Trig;

/// Points of the MTPA table: i_d,MTPA at the torques `k·T_max/(MTPA_POINTS − 1)`,
/// k = 0 … 16 (the design's `field_weakening::MTPA_ID_BY_TORQUE_A`).
pub const MTPA_POINTS: usize = 17;

/// The generated constants of the stage, as plain values (the `field_weakening` group and
/// the motor data; thesis B §2.3 and chapter 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueParameters {
    /// Sample period T_s \[s\] (the forward difference of App. D).
    pub sample_period: f32,
    /// Motor pole pairs n_p (2.33).
    pub pole_pairs: u32,
    /// ψ̂_M \[Wb\]; 0 (unknown) switches the stage off: every torque gives zero current.
    pub psi_m: f32,
    /// L̂_d \[H\] (2.33), (2.60).
    pub ld: f32,
    /// L̂_q \[H\] (2.33).
    pub lq: f32,
    /// Field-weakening bandwidth α_fw \[rad/s\] (2.60), α_fw ≪ α_c.
    pub bandwidth: f32,
    /// Electrical base speed ω_base \[rad/s\] of (2.60).
    pub base_speed: f32,
    /// V'_max/V_max \[-\], < 1 (thesis B: 0.9 in Fig. 2.15).
    pub voltage_fraction: f32,
    /// Current-circle radius I_max \[A\] (2.50), also the demagnetisation limit of (2.56).
    pub current_max: f32,
    /// The torque of the MTPA point on the current circle, the end of the table's torque
    /// grid \[N·m\] (3.10), (2.50).
    pub mtpa_torque_max: f32,
    /// i_d,MTPA \[A\] at the torques `k·mtpa_torque_max/16` (3.10).
    pub mtpa_id: [f32; MTPA_POINTS],
}

/// The stage's configuration: [`TorqueParameters`] and the quantities derived from them
/// once ([`TorqueConfig::from_parameters`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueConfig {
    /// T_s \[s\].
    pub sample_period: f32,
    /// 3/2·n_p \[-\]: T = 3/2·n_p·i_q·ψ_dq (2.33).
    pub torque_factor: f32,
    /// ψ̂_M \[Wb\].
    pub psi_m: f32,
    /// L̂_d \[H\].
    pub ld: f32,
    /// L̂_q − L̂_d \[H\] (ΔL of (3.10)).
    pub delta_l: f32,
    /// α_fw \[rad/s\].
    pub bandwidth: f32,
    /// ω_base \[rad/s\].
    pub base_speed: f32,
    /// V'_max/V_max.
    pub voltage_fraction: f32,
    /// I_max \[A\].
    pub current_max: f32,
    /// (MTPA_POINTS − 1)/T_max \[1/(N·m)\]: the table index per newton-metre; 0 without a
    /// table.
    pub mtpa_per_torque: f32,
    /// i_d,MTPA at the table's torques \[A\].
    pub mtpa_id: [f32; MTPA_POINTS],
    /// The MTPV line crosses the current circle (ψ̂_M < L̂_d·I_max): Mode C is on.
    pub mtpv: bool,
    /// L̂_q \[H\]: ψ_q = L̂_q·i_q on the MTPV line.
    pub lq: f32,
    /// a = 1/L̂_d − 1/L̂_q \[1/H\] of the MTPV line.
    pub mtpv_a: f32,
    /// c = ψ̂_M/L̂_d \[A\] of the MTPV line.
    pub mtpv_c: f32,
    /// L̂_d/L̂_q \[-\]: the Mode-C gain relative to γ.
    pub cut_gain: f32,
}

/// State of the stage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorqueState {
    /// The integrated d-axis reference i_d^ref \[A\] (2.55) (`f32::MAX` before the first
    /// step: the clamp (2.56) then starts it on the MTPA curve).
    pub id_ref: f32,
    /// How far Mode C has lowered |i_q^ref| below Modes A/B \[A\] (≥ 0).
    pub iq_cut: f32,
    /// The last step ended on the MTPV line.
    pub on_mtpv: bool,
    /// The current controller's last applied voltage v_dq \[V\] (the feedback of (2.55)).
    pub voltage: Dq,
    /// The references of the last step (i_d^ref, i_q^ref) \[A\] (telemetry).
    pub reference: Dq,
}

impl TorqueState {
    /// Before the first step.
    pub const fn new() -> Self {
        Self {
            id_ref: f32::MAX,
            iq_cut: 0.0,
            on_mtpv: false,
            voltage: Dq { d: 0.0, q: 0.0 },
            reference: Dq { d: 0.0, q: 0.0 },
        }
    }
}

impl Default for TorqueState {
    fn default() -> Self {
        Self::new()
    }
}

/// The smaller of `a` and `b` by one comparison (`f32::min` is a library call on the
/// Cortex-M4F, whose FPv4 has no VMINNM); `a` if either is NaN.
fn lesser(a: f32, b: f32) -> f32 {
    if b < a { b } else { a }
}

/// The larger of `a` and `b` by one comparison (see [`lesser`]); `a` if either is NaN.
fn greater(a: f32, b: f32) -> f32 {
    if b > a { b } else { a }
}

impl TorqueConfig {
    /// The stage off: every torque gives zero current (ψ_M unknown).
    pub const OFF: Self = Self::from_parameters(&TorqueParameters {
        sample_period: 0.0,
        pole_pairs: 0,
        psi_m: 0.0,
        ld: 0.0,
        lq: 0.0,
        bandwidth: 0.0,
        base_speed: 0.0,
        voltage_fraction: 0.0,
        current_max: 0.0,
        mtpa_torque_max: 0.0,
        mtpa_id: [0.0; MTPA_POINTS],
    });

    /// The configuration of `p`: the torque factor 3/2·n_p (2.33), ΔL, the table's index
    /// scale, and whether the MTPV line enters the current circle (ψ̂_M < L̂_d·I_max) with
    /// its coefficients a = 1/L̂_d − 1/L̂_q, c = ψ̂_M/L̂_d and the Mode-C gain ratio
    /// L̂_d/L̂_q. Anything not positive where it must be (ψ̂_M, L̂_d, L̂_q, I_max, T_max)
    /// turns the part that needs it off.
    pub const fn from_parameters(p: &TorqueParameters) -> Self {
        let inductances = p.ld > 0.0 && p.lq > 0.0;
        let on = p.psi_m > 0.0 && p.current_max > 0.0 && inductances;
        let mtpv = on && p.psi_m < p.ld * p.current_max;
        Self {
            sample_period: p.sample_period,
            torque_factor: if on { 1.5 * p.pole_pairs as f32 } else { 0.0 },
            psi_m: p.psi_m,
            ld: p.ld,
            delta_l: p.lq - p.ld,
            bandwidth: p.bandwidth,
            base_speed: p.base_speed,
            voltage_fraction: p.voltage_fraction,
            current_max: if on { p.current_max } else { 0.0 },
            mtpa_per_torque: if on && p.mtpa_torque_max > 0.0 {
                (MTPA_POINTS - 1) as f32 / p.mtpa_torque_max
            } else {
                0.0
            },
            mtpa_id: p.mtpa_id,
            mtpv,
            lq: p.lq,
            mtpv_a: if inductances { 1.0 / p.ld - 1.0 / p.lq } else { 0.0 },
            mtpv_c: if inductances { p.psi_m / p.ld } else { 0.0 },
            cut_gain: if inductances { p.ld / p.lq } else { 0.0 },
        }
    }

    /// γ (2.60) \[A/(V²·s)\] at electrical speed `omega` and limit `v_max_prime`;
    /// 0 when any factor is not positive and finite.
    pub fn gain(&self, omega: f32, v_max_prime: f32) -> f32 {
        let w_fw = greater(self.base_speed, libm::fabsf(omega));
        let den = 2.0 * w_fw * self.ld * v_max_prime;
        let g = self.bandwidth / den;
        if den > 0.0 && g.is_finite() && g > 0.0 { g } else { 0.0 }
    }

    /// i_d,MTPA \[A\] at the torque magnitude `t` ≥ 0 \[N·m\]: the table, linear in
    /// between, its last value beyond (with (2.57) that is the MTPA point on the circle).
    pub fn mtpa_id(&self, t: f32) -> f32 {
        let last = MTPA_POINTS - 1;
        let x = t * self.mtpa_per_torque;
        let top = self.mtpa_id.get(last).copied().unwrap_or(0.0);
        // Beyond the grid, and NaN (a torque that is no number), the table's end.
        if x >= last as f32 || x.is_nan() {
            return top;
        }
        // 0 ≤ x < 16: the truncation is the interval, k + 1 ≤ 16.
        let k = if x > 0.0 { x as usize } else { 0 };
        match (self.mtpa_id.get(k), self.mtpa_id.get(k.saturating_add(1))) {
            (Some(&a), Some(&b)) => a + (b - a) * (x - k as f32),
            _ => top,
        }
    }

    /// i_d \[A\] of the MTPV line at |i_q| = `iq` \[A\] (module docs):
    /// ψ_d = −2a·ψ_q²/(c + √(c² + 4a²·ψ_q²)), i_d = (ψ_d − ψ̂_M)/L̂_d.
    pub fn mtpv_id<T: Trig + ?Sized>(&self, trig: &mut T, iq: f32) -> f32 {
        let pq = self.lq * iq;
        let (a, c) = (self.mtpv_a, self.mtpv_c);
        let root = trig.sqrt(c * c + 4.0 * a * a * pq * pq);
        let pd = -2.0 * a * pq * pq / (c + root);
        (pd - self.psi_m) / self.ld
    }

    /// One step: the current references (i_d^ref, i_q^ref) \[A\] for the torque demand
    /// `torque` \[N·m\] at the electrical speed `omega` \[rad/s\] and the voltage circle
    /// `v_max` \[V\] of the measured DC link (2.51), with the previous step's applied
    /// voltage in `state.voltage` (the caller stores it after the current loop).
    ///
    /// A non-finite torque counts as zero (the field weakening keeps holding |v|); a
    /// non-finite voltage or speed leaves the integrators where they were. With the stage
    /// off (ψ̂_M unknown) the result is zero current.
    pub fn process<T: Trig + ?Sized>(
        &self,
        state: &mut TorqueState,
        trig: &mut T,
        torque: f32,
        omega: f32,
        v_max: f32,
    ) -> Dq {
        if self.torque_factor <= 0.0 {
            return Dq::default();
        }
        let torque = if torque.is_finite() { torque } else { 0.0 };
        let t = libm::fabsf(torque);
        let i_max = self.current_max;
        // (2.55), (2.60) at the measured V'_max, forward difference (App. D).
        let v_prime = self.voltage_fraction * v_max;
        let v = state.voltage;
        let error = v_prime * v_prime - v.d * v.d - v.q * v.q;
        let mut step = self.sample_period * self.gain(omega, v_prime) * error;
        if !step.is_finite() {
            step = 0.0;
        }
        if self.mtpv && (state.iq_cut > 0.0 || (state.on_mtpv && step < 0.0)) {
            // Mode C: the voltage error moves i_q^ref along the MTPV line.
            state.iq_cut = lesser(greater(state.iq_cut - step * self.cut_gain, 0.0), i_max);
        } else {
            state.id_ref += step;
        }
        // (2.56): the MTPA curve of the demanded torque above, −I_max below.
        state.id_ref = greater(lesser(state.id_ref, self.mtpa_id(t)), -i_max);
        let mut id = state.id_ref;
        // Mode A: the demanded torque on the constant-torque curve (2.33).
        let flux = self.psi_m - self.delta_l * id;
        let iq_torque = if flux > 0.0 {
            t / (self.torque_factor * flux)
        } else {
            f32::INFINITY
        };
        // Mode B (2.57): inside the current circle.
        let rest = i_max * i_max - id * id;
        let iq_circle = if rest > 0.0 { trig.sqrt(rest) } else { 0.0 };
        let mut iq = lesser(iq_torque, iq_circle);
        if self.mtpv {
            iq = greater(iq - state.iq_cut, 0.0);
            let line = self.mtpv_id(trig, iq);
            // In Mode C (i_q lowered) the current moves along the line; otherwise the line is
            // the lower limit of i_d^ref.
            state.on_mtpv = id <= line;
            if state.on_mtpv || state.iq_cut > 0.0 {
                id = line;
                state.id_ref = line;
            }
        }
        let reference = Dq {
            d: id,
            q: if torque < 0.0 { -iq } else { iq },
        };
        state.reference = reference;
        reference
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trig::SoftTrig;

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
    /// 3/2·n_p, n_p = 2.
    const K: f32 = 3.0;

    /// i_d of (3.10) at i_q, cancellation-free (hand formula of the thesis):
    /// i_d = −2ΔL·i_q²/(ψ + √(ψ² + 4ΔL²·i_q²)).
    fn mtpa_of_iq(dl: f32, iq: f32) -> f32 {
        -2.0 * dl * iq * iq / (PSI + libm::sqrtf(PSI * PSI + 4.0 * dl * dl * iq * iq))
    }

    /// Torque (2.33) of (i_d, i_q) with ΔL.
    fn torque(dl: f32, id: f32, iq: f32) -> f32 {
        K * iq * (PSI - dl * id)
    }

    /// The MTPA point at torque `t` by bisection on i_q along (3.10) (independent of the
    /// stage's table): torque grows with i_q along the curve.
    fn mtpa_at_torque(dl: f32, t: f32) -> (f32, f32) {
        let (mut lo, mut hi) = (0.0f32, 2000.0f32);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if torque(dl, mtpa_of_iq(dl, mid), mid) < t {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (mtpa_of_iq(dl, lo), lo)
    }

    /// The chalmers configuration with the table of (3.10) built here by bisection, at
    /// I_max = 1.4·I_base.
    fn params(alpha_fw: f32, ld: f32) -> TorqueParameters {
        let dl = LQ - ld;
        let i_max = 1.4 * I_BASE;
        // MTPA corner on the circle, by bisection on i_q along (3.10) (for ΔL > 0 the hand
        // form is i_d = (a − √(a² + 2I²))/2 with a = ψ/(2ΔL)).
        let (mut lo, mut hi) = (0.0f32, i_max);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if mid * mid + mtpa_of_iq(dl, mid).powi(2) < i_max * i_max {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let (id_c, iq_c) = (mtpa_of_iq(dl, lo), lo);
        let t_max = K * iq_c * (PSI - dl * id_c);
        let mut table = [0.0f32; MTPA_POINTS];
        for (k, x) in table.iter_mut().enumerate() {
            *x = mtpa_at_torque(dl, t_max * k as f32 / (MTPA_POINTS - 1) as f32).0;
        }
        TorqueParameters {
            sample_period: 1e-4,
            pole_pairs: 2,
            psi_m: PSI,
            ld,
            lq: LQ,
            bandwidth: alpha_fw,
            base_speed: W_BASE,
            voltage_fraction: 0.9,
            current_max: i_max,
            mtpa_torque_max: t_max,
            mtpa_id: table,
        }
    }

    fn config(alpha_fw: f32) -> TorqueConfig {
        TorqueConfig::from_parameters(&params(alpha_fw, LD))
    }

    /// Steady-state voltage of the dq model at electrical speed w (thesis B (2.52)).
    fn voltage(ld: f32, w: f32, id: f32, iq: f32) -> Dq {
        Dq {
            d: RS * id - w * LQ * iq,
            q: RS * iq + w * (ld * id + PSI),
        }
    }

    /// Thesis B §2.2.1: "i_q^ref = 0.8 pu and i_d^ref = −0.25 pu, where i_d^ref is set
    /// according to the max torque-per-ampere trajectory", i.e. (3.10) with the saturated
    /// L_q = 0.42 mH (0.65 pu, Table B.2). Hand calculation: ΔL = 0.19 mH, i_q = 181.0 A,
    /// ψ/(2ΔL) = 273.7 A, i_d = 273.7 − √(273.7² + 181.0²) = −54.4 A = −0.240 pu.
    #[test]
    fn mtpa_matches_the_thesis_operating_point() {
        let id = mtpa_of_iq(0.42e-3 - LD, 0.8 * I_BASE) / I_BASE;
        assert!((id + 0.25).abs() < 0.015, "{id} pu");
    }

    /// At standstill (below base speed) the stage puts any torque up to the table's end on
    /// the MTPA curve and makes it exactly (2.33): the (i_d, i_q) it returns give the
    /// demanded torque within f32 rounding, with a current magnitude at most 0.2 % above
    /// the bisected MTPA point's (the least current for that torque: the table's linear
    /// interpolation of i_d moves the point along the constant-torque curve, where |i| is
    /// stationary at the MTPA point, so an i_d error δ costs about δ²/(2|i|); the worst is
    /// the first interval, where i_d ∝ T² and δ reaches 0.5 A at 10 A: 0.12 %), and the
    /// sign follows the torque. Above the table's end the current sits on the circle at
    /// the MTPA corner.
    #[test]
    fn standstill_torque_is_exact_on_the_mtpa_curve() {
        let c = config(147.0);
        let p = params(147.0, LD);
        for k in 0..=40 {
            let t = p.mtpa_torque_max * k as f32 / 40.0;
            for sign in [1.0f32, -1.0] {
                let mut st = TorqueState::new();
                let r = c.process(&mut st, &mut SoftTrig, sign * t, 0.0, V_BASE);
                let got = torque(LQ - LD, r.d, r.q);
                assert!((got - sign * t).abs() <= 1e-4 * t.max(1.0), "{t}: {got}");
                let (id, iq) = mtpa_at_torque(LQ - LD, t);
                let (least, got) = (libm::hypotf(id, iq), libm::hypotf(r.d, r.q));
                assert!(got <= least * 1.002, "{t}: |i| {got} vs {least}");
                assert!(r.q * sign >= 0.0);
            }
        }
        let mut st = TorqueState::new();
        let r = c.process(&mut st, &mut SoftTrig, 2.0 * p.mtpa_torque_max, 0.0, V_BASE);
        let mag = libm::sqrtf(r.d * r.d + r.q * r.q);
        assert!((mag - p.current_max).abs() < 1e-3 * p.current_max, "{mag}");
        assert_eq!(r.d, p.mtpa_id[MTPA_POINTS - 1]);
    }

    /// The table: exact at its torques, linear in between, its end held beyond.
    #[test]
    fn table_lookup() {
        let mut p = params(147.0, LD);
        for (k, x) in p.mtpa_id.iter_mut().enumerate() {
            *x = -(k as f32);
        }
        p.mtpa_torque_max = 16.0;
        let c = TorqueConfig::from_parameters(&p);
        assert_eq!(c.mtpa_id(0.0), 0.0);
        assert_eq!(c.mtpa_id(5.0), -5.0);
        assert!((c.mtpa_id(5.25) + 5.25).abs() < 1e-6);
        assert_eq!(c.mtpa_id(16.0), -16.0);
        assert_eq!(c.mtpa_id(1e30), -16.0);
        assert_eq!(c.mtpa_id(f32::NAN), -16.0);
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

    /// Runs the stage against the quasi-static motor (currents follow their references
    /// through a first-order current loop α_c) at speed `w` for `n` steps; returns
    /// (i_d^ref, i_q^ref, |v|) per step.
    fn run(c: &TorqueConfig, st: &mut TorqueState, w: f32, t: f32, alpha_c: f32, n: usize) -> Vec<(f32, f32, f32)> {
        let a = 1.0 - libm::expf(-alpha_c * c.sample_period);
        let (mut id, mut iq) = (0.0f32, 0.0f32);
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let r = c.process(st, &mut SoftTrig, t, w, V_BASE);
            id += a * (r.d - id);
            iq += a * (r.q - iq);
            st.voltage = voltage(c.ld, w, id, iq);
            let v = st.voltage;
            out.push((r.d, r.q, libm::sqrtf(v.d * v.d + v.q * v.q)));
        }
        out
    }

    /// Mode A, zero torque, ω = 1.5·ω_base. With an ideal first-order current loop
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
        let mut st = TorqueState {
            id_ref: id_eq - 2.0,
            voltage: voltage(LD, w, id_eq - 2.0, 0.0),
            ..TorqueState::new()
        };
        let n = libm::roundf(1.0 / (alpha_fw * c.sample_period)) as usize;
        // The quasi-static current starts at the perturbed reference.
        let a = 1.0 - libm::expf(-alpha_c * c.sample_period);
        let (mut id, mut out) = (id_eq - 2.0, Vec::new());
        for _ in 0..30 * n {
            let r = c.process(&mut st, &mut SoftTrig, 0.0, w, V_BASE);
            id += a * (r.d - id);
            st.voltage = voltage(LD, w, id, 0.0);
            out.push((r.d, r.q, libm::sqrtf(st.voltage.d.powi(2) + st.voltage.q.powi(2))));
        }
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

    /// Below base speed the voltage error is positive: i_d^ref stays on the MTPA curve of
    /// the torque, which is made exactly.
    #[test]
    fn below_base_speed_holds_mtpa() {
        let c = config(147.0);
        let mut st = TorqueState::new();
        let t = 100.0;
        let out = run(&c, &mut st, 0.5 * W_BASE, t, 1470.0, 2000);
        let (id, iq, v) = *out.last().unwrap();
        assert_eq!(id, c.mtpa_id(t));
        assert!((torque(LQ - LD, id, iq) - t).abs() < 1e-4 * t);
        assert!(v < 0.9 * V_BASE);
    }

    /// Mode A at 1.5·ω_base with a torque below the most the voltage allows there: i_d^ref
    /// goes below the MTPA curve, the torque stays exact (the constant-torque curve), and
    /// |v| settles on V'_max.
    #[test]
    fn mode_a_keeps_the_torque() {
        let c = config(147.0);
        let mut st = TorqueState::new();
        let t = 60.0;
        let out = run(&c, &mut st, 1.5 * W_BASE, t, 1470.0, 20_000);
        let (id, iq, v) = *out.last().unwrap();
        assert!(id < c.mtpa_id(t) - 1.0, "{id}");
        assert!((torque(LQ - LD, id, iq) - t).abs() < 1e-4 * t);
        assert!(libm::sqrtf(id * id + iq * iq) < c.current_max);
        assert!((v - 0.9 * V_BASE).abs() < 2e-3 * V_BASE, "{v}");
    }

    /// Mode B at 3·ω_base with full demand: i_d^ref goes deep, the current stays on the
    /// circle (2.57) and |v| settles on V'_max.
    #[test]
    fn mode_b_stays_on_the_circle() {
        let c = config(147.0);
        let mut st = TorqueState::new();
        let out = run(&c, &mut st, 3.0 * W_BASE, 1e4, 1470.0, 20_000);
        let (id, iq, v) = *out.last().unwrap();
        let mag = libm::sqrtf(id * id + iq * iq);
        assert!((mag - c.current_max).abs() < 1e-3 * c.current_max, "{mag}");
        assert!(iq > 0.0 && id < c.mtpa_id(1e4));
        assert!((v - 0.9 * V_BASE).abs() < 2e-3 * V_BASE, "{v}");
        for (id, iq, _) in out {
            assert!(id >= -c.current_max && libm::sqrtf(id * id + iq * iq) <= 1.0001 * c.current_max);
        }
    }

    /// Mode C on the thesis B motor with a larger L_d, so that ψ_M = 0.104 Wb < L_d·I_max
    /// and the MTPV line enters the circle: L_d = 0.40 mH (salient, L_q > L_d) and
    /// 0.70 mH (inverse saliency, L_d > L_q). At 3·ω_base under full torque demand the
    /// stage settles with |v| on V'_max, inside the circle, on the MTPV line, and its torque
    /// is within 1 % of the largest torque the quasi-static machine gives within
    /// |i| ≤ I_max and |v| ≤ V'_max — found here by brute force over the disk (4001 i_d,
    /// bisection on i_q), independent of the line's formula. Holding the current on the
    /// circle instead (thesis B's Mode B) gives less.
    #[test]
    fn mode_c_reaches_the_most_torque_per_volt() {
        for ld in [0.40e-3f32, 0.70e-3] {
            let p = params(147.0, ld);
            let c = TorqueConfig::from_parameters(&p);
            assert!(c.mtpv);
            let w = 3.0 * W_BASE;
            let mut st = TorqueState::new();
            let out = run(&c, &mut st, w, 1e4, 1470.0, 40_000);
            let (id, iq, v) = *out.last().unwrap();
            let vp = 0.9 * V_BASE;
            assert!((v - vp).abs() < 2e-3 * vp, "L_d {ld}: {v}");
            assert!(
                libm::sqrtf(id * id + iq * iq) < 0.99 * c.current_max,
                "L_d {ld}: ({id}, {iq})"
            );
            assert!(
                (id - c.mtpv_id(&mut SoftTrig, iq)).abs() < 1e-3,
                "L_d {ld}: ({id}, {iq})"
            );
            let dl = LQ - ld;
            let volts = |id: f32, iq: f32| {
                let v = voltage(ld, w, id, iq);
                libm::sqrtf(v.d * v.d + v.q * v.q)
            };
            let mut best = 0.0f32;
            for k in 0..=4000 {
                let d = -c.current_max + 2.0 * c.current_max * k as f32 / 4000.0;
                if volts(d, 0.0) > vp {
                    continue;
                }
                let (mut lo, mut hi) = (0.0f32, libm::sqrtf((c.current_max.powi(2) - d * d).max(0.0)));
                if volts(d, hi) <= vp {
                    lo = hi;
                }
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if volts(d, mid) <= vp { lo = mid } else { hi = mid }
                }
                best = best.max(torque(dl, d, lo));
            }
            let got = torque(dl, id, iq);
            // Thesis B's Mode B on the circle at this speed.
            let mut circle = 0.0f32;
            for k in 0..=20_000 {
                let a = core::f32::consts::PI * k as f32 / 20_000.0;
                let (d, q) = (c.current_max * libm::cosf(a), c.current_max * libm::sinf(a));
                if volts(d, q) <= vp {
                    circle = circle.max(torque(dl, d, q));
                }
            }
            println!("L_d = {ld}: MTPV torque {got} N·m, most possible {best} N·m, on the circle {circle} N·m");
            assert!(got >= 0.99 * best && got <= 1.001 * best, "L_d {ld}: {got} vs {best}");
            assert!(got > circle, "L_d {ld}: {got} vs circle {circle}");
        }
    }

    /// Beyond the reachable speed i_d^ref stops at −I_max (demagnetisation limit, 2.56)
    /// and i_q^ref at 0; non-finite inputs do not stick; the stage off gives zero.
    #[test]
    fn limits_and_bad_inputs() {
        let c = config(147.0);
        let mut st = TorqueState {
            voltage: Dq {
                d: 0.0,
                q: 2.0 * V_BASE,
            },
            ..TorqueState::new()
        };
        let mut r = Dq::default();
        for _ in 0..100_000 {
            r = c.process(&mut st, &mut SoftTrig, 200.0, 10.0 * W_BASE, V_BASE);
        }
        assert_eq!((r.d, r.q), (-c.current_max, 0.0));
        let r = c.process(&mut st, &mut SoftTrig, f32::NAN, f32::NAN, f32::NAN);
        assert!(r.d.is_finite() && r.q == 0.0);
        assert_eq!(st.id_ref, r.d);
        let mut fresh = TorqueState::new();
        assert_eq!(
            TorqueConfig::OFF.process(&mut fresh, &mut SoftTrig, 10.0, 0.0, V_BASE),
            Dq::default()
        );
    }
}
