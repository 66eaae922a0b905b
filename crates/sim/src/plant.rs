//! The simulated drive: a PMSM in rotor (dq) coordinates driven by an ideal
//! three-phase inverter, with the current ADCs, the DC-link ADC and the resolver
//! demodulator the firmware reads.
//!
//! Motor model (thesis B (2.14)–(2.16), θ = electrical angle, ω = electrical speed):
//!
//! ```text
//! L_dq(θ)·di/dt = v − Z_dq(θ, ω)·i − ω·ψ_m,dq(θ)
//! L_dq = [[L_d + L_6/5·cos 6θ, −L_6/5·sin 6θ], [−L_6/5·sin 6θ, L_q − L_6/5·cos 6θ]]   (2.15a)
//! Z_dq = [[R − ωL_6 sin 6θ, −ωL_q − ωL_6 cos 6θ], [ωL_d − ωL_6 cos 6θ, R + ωL_6 sin 6θ]] (2.15b)
//! ψ_m,dq = [ψ_d,6 sin 6θ + ψ_d,12 sin 12θ, ψ_m + ψ_q,6 cos 6θ + ψ_q,12 cos 12θ]        (2.15c)
//! ```
//!
//! Without harmonic data this is thesis A (2.26): `v_d = R·i_d + L_d·di_d/dt − ω·L_q·i_q`,
//! `v_q = R·i_q + L_q·di_q/dt + ω·(L_d·i_d + ψ_M)`. With a saturation curve, L_q is
//! L_q(|i_q|) (thesis B (2.25)), interpolated linearly between the spec's points.
//!
//! The shaft ([`Shaft`]) either follows an imposed speed profile (the current loop is
//! much faster than the mechanics, thesis B §2.2) or turns freely: J·dω_m/dt = T_e − b·ω_m
//! with T_e = 3/2·n_p·i_q·(ψ_M + (L_d − L_q)·i_d) (thesis A (2.33), (2.34); harmonic
//! torque is not modelled). Inverter: the phase voltages are `(duty − 1/2)·U_dc`,
//! constant over a period (volt-second average, thesis A (3.3)); the state is
//! integrated with RK4 on [`SUBSTEPS`] sub-steps while the rotor turns.

use std::f64::consts::PI;

/// RK4 sub-steps per PWM period (ω_e,max·T_s ≤ 2π/12 by thesis A (1.1): ≤ 0.13 rad per sub-step).
pub const SUBSTEPS: usize = 4;

/// Electrical parameters of the simulated machine (SI).
#[derive(Clone, Debug, PartialEq)]
pub struct MotorModel {
    /// n_p.
    pub pole_pairs: u32,
    /// R_s \[Ω\].
    pub resistance: f64,
    /// L_d \[H\].
    pub ld: f64,
    /// L_q \[H\] (unsaturated).
    pub lq: f64,
    /// ψ_M \[Wb\] (0 when the spec does not know it).
    pub psi: f64,
    /// L_6 \[H\] (2.16c).
    pub l6: f64,
    /// ψ_d,6, ψ_d,12 \[Wb\] (2.16e).
    pub psi_d: [f64; 2],
    /// ψ_q,6, ψ_q,12 \[Wb\] (2.16f).
    pub psi_q: [f64; 2],
    /// L_q(|i_q|) points (\[A\], \[H\]), sorted by current; empty = constant L_q.
    pub q_saturation: Vec<(f64, f64)>,
}

impl MotorModel {
    /// L_q at `iq` \[A\]: the saturation curve (2.25), constant beyond its ends.
    pub fn lq_at(&self, iq: f64) -> f64 {
        let pts = &self.q_saturation;
        let x = iq.abs();
        match pts.iter().position(|&(i, _)| i > x) {
            None => pts.last().map_or(self.lq, |&(_, l)| l),
            Some(0) => pts[0].1,
            Some(k) => {
                let ((x0, y0), (x1, y1)) = (pts[k - 1], pts[k]);
                y0 + (y1 - y0) * (x - x0) / (x1 - x0)
            }
        }
    }

    /// Whether any harmonic term (2.15) is non-zero.
    pub fn has_harmonics(&self) -> bool {
        self.l6 != 0.0 || self.psi_d.iter().chain(&self.psi_q).any(|&p| p != 0.0)
    }

    /// di_dq/dt [A/s] at electrical angle `th`, speed `w`, currents `i`, voltage `v` (2.14).
    pub fn current_derivative(&self, th: f64, w: f64, i: [f64; 2], v: [f64; 2]) -> [f64; 2] {
        let lq = self.lq_at(i[1]);
        let [id, iq] = i;
        let (s6, c6) = (6.0 * th).sin_cos();
        let (s12, c12) = (12.0 * th).sin_cos();
        let l6 = self.l6;
        let l = [
            [self.ld + l6 / 5.0 * c6, -l6 / 5.0 * s6],
            [-l6 / 5.0 * s6, lq - l6 / 5.0 * c6],
        ];
        let z = [
            [self.resistance - w * l6 * s6, -w * lq - w * l6 * c6],
            [w * self.ld - w * l6 * c6, self.resistance + w * l6 * s6],
        ];
        let psi = [
            self.psi_d[0] * s6 + self.psi_d[1] * s12,
            self.psi + self.psi_q[0] * c6 + self.psi_q[1] * c12,
        ];
        let rhs = [
            v[0] - z[0][0] * id - z[0][1] * iq - w * psi[0],
            v[1] - z[1][0] * id - z[1][1] * iq - w * psi[1],
        ];
        let det = l[0][0] * l[1][1] - l[0][1] * l[1][0];
        [
            (l[1][1] * rhs[0] - l[0][1] * rhs[1]) / det,
            (l[0][0] * rhs[1] - l[1][0] * rhs[0]) / det,
        ]
    }
}

/// Mechanical speed profile ω_m(t) = clamp(ω_0 + a·(t − t_0), …) [rad/s]: constant
/// (a = 0) or a ramp from `from` to `to` starting at `start`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedProfile {
    /// Speed before the ramp [rad/s].
    pub from: f64,
    /// Speed after the ramp [rad/s].
    pub to: f64,
    /// Ramp start \[s\].
    pub start: f64,
    /// |acceleration| [rad/s²] (ignored when `from == to`).
    pub acceleration: f64,
}

impl SpeedProfile {
    /// Constant speed `w` [rad/s].
    pub fn constant(w: f64) -> Self {
        Self {
            from: w,
            to: w,
            start: 0.0,
            acceleration: 0.0,
        }
    }

    /// The straight line from `from` at `start` to `to` at `start + length` [rad/s, s],
    /// then `to`: one piece of a piecewise-linear profile.
    pub fn segment(start: f64, length: f64, from: f64, to: f64) -> Self {
        Self {
            from,
            to,
            start,
            acceleration: (to - from).abs() / length,
        }
    }

    /// ω_m(t) [rad/s].
    pub fn at(&self, t: f64) -> f64 {
        if self.from == self.to || t <= self.start {
            return self.from;
        }
        let w = self.from + (self.to - self.from).signum() * self.acceleration * (t - self.start);
        if self.to > self.from {
            w.min(self.to)
        } else {
            w.max(self.to)
        }
    }
}

/// What the ADCs and the resolver demodulator deliver (before quantisation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    /// Phase currents u, v, w \[A\].
    pub phase_currents: [f64; 3],
    /// Resolver angle θ_r \[rad\].
    pub theta_r: f64,
    /// DC-link voltage \[V\].
    pub dc_link: f64,
}

/// How the shaft moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shaft {
    /// The shaft follows a speed profile (a dynamometer, or a blocked rotor at 0).
    Imposed(SpeedProfile),
    /// Free rotor: J·dω_m/dt = T_e − b·ω_m (thesis A (2.33)).
    Free {
        /// J [kg·m²].
        inertia: f64,
        /// b [N·m·s/rad].
        damping: f64,
        /// ω_m now [rad/s] (the mechanical state).
        speed: f64,
    },
}

/// The loop delays [`Plant::step_with`] simulates [periods of T_s], both ends excluded:
/// the update from just after the sample to just before two periods after it.
pub const SIMULATED_LOOP_DELAY: (f64, f64) = (0.5, 2.5);

/// The drive's state: currents, rotor angle, DC link, pending duties.
#[derive(Clone, Debug)]
pub struct Plant {
    /// Machine parameters.
    pub motor: MotorModel,
    /// How the shaft moves.
    pub shaft: Shaft,
    /// Resolver pole pairs n_r (4.4).
    pub resolver_pole_pairs: u32,
    /// Resolver mounted the other way round: θ_r = −n_r·θ_m + θ_off.
    pub resolver_reversed: bool,
    /// Resolver offset θ_off \[rad\] (4.5): θ_r = n_r·θ_m + θ_off.
    pub resolver_offset: f64,
    /// PWM period T_s \[s\].
    pub ts: f64,
    /// Time \[s\].
    pub t: f64,
    /// i_d, i_q \[A\].
    pub i: [f64; 2],
    /// Mechanical angle θ_m \[rad\], unwrapped.
    pub theta_m: f64,
    /// Actual DC-link voltage \[V\] (a scenario may change it between periods).
    pub dc_link: f64,
    /// The duties [`Plant::advance`] switches to after a part of the period (`extra_delay`)
    /// (with [`Plant::step_with`]: computed at this sample when the update falls inside
    /// the period, at the previous one otherwise); `None` = gates off.
    pub pending: Option<[f32; 3]>,
    /// The part of the period in [0, 1) during which the previous period's duties still
    /// act before the pending ones ([`Plant::advance`]; set by [`Plant::step_with`] from
    /// [`Plant::loop_delay_periods`]); 0: the pending duties for the whole period.
    extra_delay: f64,
    /// The loop delay D [periods of T_s] [`Plant::step_with`] simulates: the duties
    /// computed from a sample act from (D − 1/2)·T_s after it for one period, so their
    /// mean is D·T_s after the sample. Default 1.5 (thesis A §4.6: sampled at the update);
    /// `verify` sets the design's (a board samples a little after its trigger), `motorgen
    /// commission --sim-scale delay=…` a perturbed one; within [`SIMULATED_LOOP_DELAY`].
    pub loop_delay_periods: f64,
    /// The resolver is held this long after the currents \[s\] (a board converts it later
    /// in its ADC sequences; `verify` sets the design's, 0 default): [`Plant::measure`]
    /// reports θ_r then, θ_r + dθ_r/dt·lag (exact at a constant speed).
    pub resolver_lag_s: f64,
    /// The duties of the previous period (for [`Plant::extra_delay`]).
    previous: Option<[f32; 3]>,
    /// A winding open (0 = u, 1 = v, 2 = w; a broken lead or connector): its current is
    /// zero and the star point floats, so the αβ current stays on the line
    /// perpendicular to that phase's axis (2π·k/3). Modelled by projecting the current
    /// onto that line after every integration sub-step: exact for a non-salient machine
    /// (L_d = L_q), an approximation of the cross-coupling for a salient one.
    pub open_phase: Option<usize>,
}

impl Plant {
    /// A drive at rest at θ_m = 0, t = 0, without current, gates off, with a one-pole-pair
    /// resolver at zero offset.
    pub fn new(motor: MotorModel, shaft: Shaft, ts: f64, dc_link: f64) -> Self {
        Self {
            motor,
            shaft,
            resolver_pole_pairs: 1,
            resolver_reversed: false,
            resolver_offset: 0.0,
            ts,
            t: 0.0,
            i: [0.0, 0.0],
            theta_m: 0.0,
            dc_link,
            pending: None,
            extra_delay: 0.0,
            loop_delay_periods: 1.5,
            resolver_lag_s: 0.0,
            previous: None,
            open_phase: None,
        }
    }

    /// Electrical angle θ_e = n_p·θ_m (thesis A (2.19)) \[rad\].
    pub fn theta_e(&self) -> f64 {
        f64::from(self.motor.pole_pairs) * self.theta_m
    }

    /// Resolver turns per mechanical turn, signed: ±n_r.
    pub fn resolver_ratio(&self) -> f64 {
        let nr = f64::from(self.resolver_pole_pairs);
        if self.resolver_reversed { -nr } else { nr }
    }

    /// Resolver angle θ_r = ±n_r·θ_m + θ_off \[rad\] (4.4), (4.5).
    pub fn theta_r(&self) -> f64 {
        self.resolver_ratio() * self.theta_m + self.resolver_offset
    }

    /// Mechanical speed now [rad/s].
    pub fn omega_m(&self) -> f64 {
        match self.shaft {
            Shaft::Imposed(p) => p.at(self.t),
            Shaft::Free { speed, .. } => speed,
        }
    }

    /// Electromagnetic torque T_e = 3/2·n_p·i_q·(ψ_M + (L_d − L_q(i_q))·i_d) [N·m]
    /// (thesis A (2.33)) at the currents `i`.
    pub fn torque(&self, i: [f64; 2]) -> f64 {
        let m = &self.motor;
        1.5 * f64::from(m.pole_pairs) * i[1] * (m.psi + (m.ld - m.lq_at(i[1])) * i[0])
    }

    /// The sampled quantities at the current instant.
    pub fn measure(&self) -> Measured {
        let (s, c) = self.theta_e().sin_cos();
        let [id, iq] = self.i;
        let alpha = c * id - s * iq;
        let beta = s * id + c * iq;
        let k = 3f64.sqrt() / 2.0;
        Measured {
            phase_currents: [alpha, -0.5 * alpha + k * beta, -0.5 * alpha - k * beta],
            theta_r: self.theta_r() + self.resolver_ratio() * self.omega_m() * self.resolver_lag_s,
            dc_link: self.dc_link,
        }
    }

    /// One period from the sample the `computed` duties were computed from (`None`: gates
    /// off), with the loop delay [`Plant::loop_delay_periods`] = D: λ = D − 1/2 after the
    /// sample the update loads them. λ < 1: the previous sample's duties for λ·T_s, then
    /// these; λ ≥ 1: the duties of two samples ago for (λ − 1)·T_s, then the previous
    /// sample's, these pending for the next period. A D outside [`SIMULATED_LOOP_DELAY`]
    /// is taken at its nearest end.
    pub fn step_with(&mut self, computed: Option<[f32; 3]>) {
        let (lo, hi) = SIMULATED_LOOP_DELAY;
        let lag = self.loop_delay_periods.clamp(lo + 1e-9, hi - 1e-9) - 0.5;
        if lag < 1.0 {
            self.pending = computed;
            self.extra_delay = lag;
            self.advance();
        } else {
            self.extra_delay = lag - 1.0;
            self.advance();
            self.pending = computed;
        }
    }

    /// Advances one PWM period with the pending duties (`None` = gates off: no current,
    /// as long as the back EMF stays below U_dc; the rotor keeps turning).
    pub fn advance(&mut self) {
        let np = f64::from(self.motor.pole_pairs);
        let to_ab = |d: Option<[f32; 3]>| {
            d.map(|d| {
                let ph = d.map(|x| (f64::from(x) - 0.5) * self.dc_link);
                let k = 3f64.sqrt() / 2.0;
                // Amplitude-invariant Clarke (thesis A (2.7)); the common mode drops out.
                [
                    2.0 / 3.0 * (ph[0] - 0.5 * ph[1] - 0.5 * ph[2]),
                    2.0 / 3.0 * k * (ph[1] - ph[2]),
                ]
            })
        };
        let u_ab = to_ab(self.pending);
        let delay = if self.extra_delay > 0.0 && self.extra_delay < 1.0 {
            self.extra_delay
        } else {
            0.0
        };
        let u_before = to_ab(self.previous);
        self.previous = self.pending;
        if u_ab.is_none() && (delay == 0.0 || u_before.is_none()) {
            self.i = [0.0, 0.0];
            if let Shaft::Imposed(p) = self.shaft {
                // θ_m integrates the piecewise-linear speed exactly (Simpson's rule).
                let (t, h) = (self.t, self.ts);
                self.theta_m += h / 6.0 * (p.at(t) + 4.0 * p.at(t + h / 2.0) + p.at(t + h));
                self.t += h;
                return;
            }
        }
        // State [i_d, i_q, θ_m, ω_m]; ω_m is a state only for the free shaft.
        let f = |t: f64, s: [f64; 4], u_ab: Option<[f64; 2]>| -> [f64; 4] {
            let (wm, dw) = match self.shaft {
                Shaft::Imposed(p) => (p.at(t), 0.0),
                Shaft::Free { inertia, damping, .. } => (s[3], (self.torque([s[0], s[1]]) - damping * s[3]) / inertia),
            };
            let di = match u_ab {
                Some(u) => {
                    let th = np * s[2];
                    let (sn, cs) = th.sin_cos();
                    let v = [cs * u[0] + sn * u[1], -sn * u[0] + cs * u[1]];
                    self.motor.current_derivative(th, np * wm, [s[0], s[1]], v)
                }
                None => [0.0, 0.0],
            };
            [di[0], di[1], wm, dw]
        };
        let add =
            |a: [f64; 4], b: [f64; 4], k: f64| [a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2], a[3] + k * b[3]];
        // RK4 on SUBSTEPS sub-steps over `length` from (t, s) with the voltage `u`.
        let segment = |mut t: f64, mut s: [f64; 4], length: f64, u: Option<[f64; 2]>| {
            let h = length / SUBSTEPS as f64;
            for _ in 0..SUBSTEPS {
                let k1 = f(t, s, u);
                let k2 = f(t + h / 2.0, add(s, k1, h / 2.0), u);
                let k3 = f(t + h / 2.0, add(s, k2, h / 2.0), u);
                let k4 = f(t + h, add(s, k3, h), u);
                for j in 0..4 {
                    s[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
                }
                if let Some(k) = self.open_phase {
                    s = open_phase_projection(s, np, k);
                }
                t += h;
            }
            s
        };
        let mut s = [self.i[0], self.i[1], self.theta_m, self.omega_m()];
        if delay > 0.0 {
            s = segment(self.t, s, delay * self.ts, u_before);
            s = segment(self.t + delay * self.ts, s, (1.0 - delay) * self.ts, u_ab);
        } else {
            s = segment(self.t, s, self.ts, u_ab);
        }
        self.i = [s[0], s[1]];
        self.theta_m = s[2];
        if let Shaft::Free { speed, .. } = &mut self.shaft {
            *speed = s[3];
        }
        self.t += self.ts;
    }
}

/// The state `s` = [i_d, i_q, θ_m, ω_m] with the αβ current projected onto the line
/// perpendicular to phase `k`'s axis (phase `k` open, [`Plant::open_phase`]).
fn open_phase_projection(mut s: [f64; 4], np: f64, k: usize) -> [f64; 4] {
    let (sn, cs) = (np * s[2]).sin_cos();
    let (alpha, beta) = (cs * s[0] - sn * s[1], sn * s[0] + cs * s[1]);
    // e ⟂ the phase axis at 2πk/3.
    let (ps, pc) = (2.0 * std::f64::consts::PI * k as f64 / 3.0).sin_cos();
    let (ex, ey) = (-ps, pc);
    let along = alpha * ex + beta * ey;
    let (alpha, beta) = (along * ex, along * ey);
    s[0] = cs * alpha + sn * beta;
    s[1] = -sn * alpha + cs * beta;
    s
}

/// Wraps an angle into [−π, π).
pub fn wrap(x: f64) -> f64 {
    x - 2.0 * PI * ((x + PI) / (2.0 * PI)).floor()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn motor() -> MotorModel {
        MotorModel {
            pole_pairs: 2,
            resistance: 0.5,
            ld: 1e-3,
            lq: 2e-3,
            psi: 0.1,
            l6: 0.0,
            psi_d: [0.0; 2],
            psi_q: [0.0; 2],
            q_saturation: vec![],
        }
    }

    /// Without harmonics (2.14) is thesis A (2.26): hand-evaluated at
    /// i = (1, 2) A, v = (3, 4) V, ω = 100 rad/s:
    /// di_d/dt = (3 − 0.5·1 + 100·2e-3·2)/1e-3 = 2900 A/s,
    /// di_q/dt = (4 − 0.5·2 − 100·(1e-3·1 + 0.1))/2e-3 = −3550 A/s.
    #[test]
    fn reduces_to_the_standard_model() {
        let d = motor().current_derivative(0.7, 100.0, [1.0, 2.0], [3.0, 4.0]);
        assert!((d[0] - 2900.0).abs() < 1e-9, "{d:?}");
        assert!((d[1] + 3550.0).abs() < 1e-9, "{d:?}");
    }

    /// (2.15c) at θ = π/12 (6θ = π/2): ψ_d adds ψ_d,6·1 + ψ_d,12·sin π = ψ_d,6, so with
    /// zero current and voltage di_d/dt = −ω·ψ_d,6/L_d = −100·0.01/1e-3 = −1000 A/s.
    #[test]
    fn flux_harmonic_enters_the_d_axis() {
        let m = MotorModel {
            psi_d: [0.01, 0.002],
            ..motor()
        };
        let d = m.current_derivative(PI / 12.0, 100.0, [0.0, 0.0], [0.0, 0.0]);
        assert!((d[0] + 1000.0).abs() < 1e-9, "{d:?}");
    }

    /// Thesis B (2.25)-style curve: flat, then linear, then constant past the last point.
    #[test]
    fn saturation_curve_interpolates() {
        let m = MotorModel {
            q_saturation: vec![(0.0, 0.56e-3), (83.7, 0.56e-3), (226.3, 0.42e-3)],
            ..motor()
        };
        assert_eq!(m.lq_at(-50.0), 0.56e-3);
        // Midway between 83.7 A and 226.3 A: (0.56 + 0.42)/2 mH.
        assert!((m.lq_at(155.0) - 0.49e-3).abs() < 1e-12);
        assert_eq!(m.lq_at(400.0), 0.42e-3);
    }

    /// (2.33) by hand: n_p = 2, ψ = 0.1 Wb, L_d − L_q = −1 mH, i = (−10, 20) A:
    /// T_e = 1.5·2·20·(0.1 + (−1e-3)·(−10)) = 60·0.11 = 6.6 N·m.
    #[test]
    fn torque_by_hand() {
        let p = Plant::new(motor(), Shaft::Imposed(SpeedProfile::constant(0.0)), 50e-6, 100.0);
        assert!((p.torque([-10.0, 20.0]) - 6.6).abs() < 1e-12);
    }

    /// A free shaft with the gates off spins down as J·dω/dt = −b·ω:
    /// ω(t) = ω_0·e^(−bt/J), θ(t) = ω_0·J/b·(1 − e^(−bt/J)). J = 1e-3 kg·m², b = 0.05 N·m·s,
    /// ω_0 = 100 rad/s, t = 200·50 µs = 10 ms: ω = 100·e^(−0.5) = 60.65 rad/s,
    /// θ = 2·(1 − e^(−0.5)) = 0.7869 rad.
    #[test]
    fn free_shaft_spins_down() {
        let shaft = Shaft::Free {
            inertia: 1e-3,
            damping: 0.05,
            speed: 100.0,
        };
        let mut p = Plant::new(motor(), shaft, 50e-6, 100.0);
        for _ in 0..200 {
            p.advance();
        }
        let decay = (-0.5f64).exp();
        assert!((p.omega_m() - 100.0 * decay).abs() < 1e-9, "{}", p.omega_m());
        assert!((p.theta_m - 2.0 * (1.0 - decay)).abs() < 1e-9, "{}", p.theta_m);
        assert_eq!(p.i, [0.0, 0.0]);
    }

    /// A constant voltage step at standstill gives i = V/R·(1 − e^(−tR/L)) exactly.
    #[test]
    fn rl_step_matches_the_exact_solution() {
        let m = motor();
        let mut p = Plant::new(m.clone(), Shaft::Imposed(SpeedProfile::constant(0.0)), 50e-6, 100.0);
        // Phase voltages (d − 1/2)·100 V = (3, −1.5, −1.5) V → u_α = 2/3·(3 + 0.75 + 0.75)
        // = 3 V, u_β = 0; at θ = 0 that is u_d (f32 duties: computed from them below).
        p.pending = Some([0.53, 0.485, 0.485]);
        for _ in 0..40 {
            p.advance();
        }
        let ud = 2.0 / 3.0 * ((0.53f32 as f64 - 0.5) - 0.5 * 2.0 * (0.485f32 as f64 - 0.5)) * 100.0;
        let want = ud / m.resistance * (1.0 - (-p.t * m.resistance / m.ld).exp());
        assert!((p.i[0] - want).abs() < 1e-6 * want, "{} vs {want}", p.i[0]);
        assert!(p.i[1].abs() < 1e-12);
    }
}
