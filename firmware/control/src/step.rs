//! One complete current-control step (field-oriented control, thesis A §3.1.3,
//! Fig. 5.7; thesis B Appendix D):
//!
//! 1. ADC codes → phase currents \[A\], DC-link voltage \[V\] ([`crate::adc`]);
//! 2. resolver SIN/COS → angle tracking observer θ̂_r, ω̂_r (4.19), (4.22);
//! 3. θ_e = n_p/n_r·(θ̂_r − θ_off) (4.5), ω_e = n_p/n_r·ω̂_r;
//! 4. Clarke (2.7) and Park (2.8) at θ_e → i_d, i_q;
//! 5. a torque demand → current references (MTPA, field weakening, MTPV:
//!    [`crate::torque`]); PI per axis with active damping, decoupling/back-EMF feed-forward (5.3),
//!    voltage-circle limit V_max = margin·U_dc/√3 (2.51) and back-calculation
//!    anti-windup (2.47)–(2.49);
//! 6. inverse Park at the lead angle θ_e + k·ω_e^i (4.23), k = 1.5 samples;
//! 7. THPWM (3.7), (3.8) and duty = 1/2 + u/U_dc (5.1) → timer compare values.
//!
//! Every number comes from [`ControllerConfig`]; the library holds none.
//! Three sine/cosine evaluations per step go through [`Trig`] (observer, Park,
//! inverse Park), so the board layer can use the CORDIC.

mod parameters;
pub use parameters::ControllerParameters;

use crate::adc::{CurrentSense, DcLinkSense};
use crate::angle::{ResolverToElectrical, ResolverTurns, lead, speed_to_rad_per_s};
use crate::ato::{AtoConfig, AtoState, ResolverSample};
use crate::feedforward::{FeedForwardConfig, dc_link_gain, effective_dc_link};
use crate::modulation::{compare_values, thpwm_limited};
use crate::pi::{CurrentPiConfig, CurrentPiState, VoltageLimit, limit_voltage};
use crate::torque::{TorqueConfig, TorqueState};
use crate::transforms::{AlphaBeta, Dq, INV_SQRT_3, Uvw, inverse_park, park};
use crate::trig::Trig;

/// Everything the current-control step needs; plain data so a code generator can
/// emit it as a `const`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerConfig {
    /// Sample (= PWM) period T_s \[s\] (4.17).
    pub sample_period: f32,
    /// Observer speed scaling `π·f_s/2^31` \[rad/s per LSB of ω^i\] (4.20).
    pub speed_per_lsb: f32,
    /// Phase-current ADC scaling.
    pub current_sense: CurrentSense,
    /// DC-link ADC scaling.
    pub dc_link_sense: DcLinkSense,
    /// Angle tracking observer gains and error architecture (4.22).
    pub observer: AtoConfig,
    /// Resolver → electrical angle: n_p, n_r, θ_off (4.5).
    pub angle: ResolverToElectrical,
    /// Delay k compensated by the inverse-Park angle lead (4.23) \[samples, Q16.16\];
    /// thesis A §4.6: 1.5 samples = `3 << 15`.
    pub angle_lead: i32,
    /// Current PI controllers (thesis A (5.9)/(5.14), thesis B (2.31)–(2.49)).
    pub current_loop: CurrentPiConfig,
    /// Motor model for the decoupling feed-forward (5.3).
    pub feed_forward: FeedForwardConfig,
    /// Lowest DC-link voltage used for the 1/U_dc feed-forward (5.1) \[V\]; below it the
    /// output is reduced instead of the gain growing.
    pub dc_link_min: f32,
    /// Fraction of the THPWM linear limit U_dc/√3 the current loop may use
    /// (≤ 1 keeps the modulator linear) \[-\].
    pub voltage_margin: f32,
    /// PWM timer auto-reload (centre-aligned period) for the compare values \[ticks\].
    pub pwm_period: u16,
    /// Largest duty of a leg (the low-side shunts' sampling window; 1 without a limit):
    /// the modulator scales the phase voltages to stay within it
    /// ([`crate::modulation::thpwm_limited`]).
    pub max_duty: f32,
    /// The torque → current-reference stage of [`Demand::Torque`] (MTPA, field
    /// weakening, MTPV; [`crate::torque`]).
    pub torque: TorqueConfig,
}

/// State of the step: observer, resolver turn counter, current controllers, torque stage.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ControllerState {
    /// Angle tracking observer.
    pub observer: AtoState,
    /// Resolver cycle counter (only relevant for n_r > 1).
    pub turns: ResolverTurns,
    /// Current PI integrators and reference filters.
    pub current: CurrentPiState,
    /// The torque stage's integrators and voltage feedback (reset by any other demand).
    pub torque: TorqueState,
}

impl ControllerState {
    /// Observer at rest at θ̂ = 0, integrators empty.
    pub const fn new() -> Self {
        Self {
            observer: AtoState::new(),
            turns: ResolverTurns::new(),
            current: CurrentPiState {
                d: crate::pi::PiState {
                    integral: 0.0,
                    reference: 0.0,
                },
                q: crate::pi::PiState {
                    integral: 0.0,
                    reference: 0.0,
                },
            },
            torque: TorqueState::new(),
        }
    }
}

/// The samples taken at the start of a control period.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AdcSample {
    /// Phase-current codes u, v, w.
    pub phase_currents: [u16; 3],
    /// Demodulated resolver SIN/COS envelopes, Q1.31.
    pub resolver: ResolverSample,
    /// DC-link voltage code.
    pub dc_link: u16,
}

/// What the step should do with the machine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Demand {
    /// Zero voltage (duties 1/2), integrators cleared; the board disables the gates.
    Off,
    /// Closed-loop currents i_d, i_q \[A\]; `feed_forward` enables (5.3).
    Current {
        /// d-axis current reference \[A\].
        id: f32,
        /// q-axis current reference \[A\].
        iq: f32,
        /// Add the decoupling/back-EMF feed-forward (5.3).
        feed_forward: bool,
    },
    /// A torque \[N·m\]: the torque stage ([`crate::torque`]: MTPA, field weakening at the
    /// measured DC link, MTPV, current circle) sets the current references, then as
    /// `Current` with the feed-forward (5.3).
    Torque(f32),
    /// Open-loop voltage in the rotor frame \[V\] (blocked-rotor step, 6.2).
    VoltageDq(Dq),
    /// Closed-loop currents without the feed-forward, with `injection` \[V\] added to the
    /// controller's limited output (the loop broken at the controller's output for the
    /// frequency response, [`crate::commissioning::FrequencyResponse`]): v = u_PI + d,
    /// where `StepOutput::u_dq` is u_PI.
    Injected {
        /// d-axis current reference \[A\].
        id: f32,
        /// q-axis current reference \[A\].
        iq: f32,
        /// The voltage added after the controller \[V\].
        injection: Dq,
    },
    /// Open-loop voltage in the stator frame \[V\] (alignment 6.3, rotation 6.4).
    VoltageAlphaBeta(AlphaBeta),
}

/// Result of one step (actuation plus telemetry).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepOutput {
    /// Duty cycles of phases u, v, w in \[0, 1\].
    pub duties: [f32; 3],
    /// Timer compare values `round(duty·pwm_period)`.
    pub compare: [u16; 3],
    /// Observed resolver angle θ̂_r^i (π-scaled Q1.31).
    pub theta_r: i32,
    /// Observed resolver speed ω̂_r^i (per-sample increment).
    pub omega_r: i32,
    /// Electrical angle θ_e^i (π-scaled Q1.31).
    pub theta_e: i32,
    /// Electrical speed ω_e \[rad/s\].
    pub omega_e: f32,
    /// Measured currents in dq at θ_e \[A\].
    pub i_dq: Dq,
    /// Measured phase currents \[A\] (w from (2.1) with two measured phases).
    pub i_uvw: Uvw,
    /// Applied (limited) voltage in dq \[V\], in the frame of the lead angle.
    pub u_dq: Dq,
    /// Applied voltage in αβ \[V\].
    pub u_alpha_beta: AlphaBeta,
    /// Measured DC-link voltage \[V\].
    pub u_dc: f32,
    /// U_dc was below `dc_link_min` (or not a number): voltages are reduced.
    pub dc_link_low: bool,
}

impl ControllerConfig {
    /// One control period. `trig` supplies sin/cos (CORDIC or [`crate::trig::SoftTrig`]).
    pub fn process<T: Trig>(
        &self,
        state: &mut ControllerState,
        trig: &mut T,
        sample: &AdcSample,
        demand: Demand,
    ) -> StepOutput {
        // 2.–3. Angle.
        let theta_r = self.observer.process(&mut state.observer, trig, sample.resolver);
        let omega_r = state.observer.omega;
        let theta_e = self.angle.process(&mut state.turns, theta_r);
        let omega_e_i = self.angle.electrical_speed(omega_r);
        let out = self.process_at_angle(state, trig, sample, demand, theta_e, omega_e_i, Dq::default());
        StepOutput {
            theta_r,
            omega_r,
            ..out
        }
    }

    /// Steps 1 and 4–7 at a given electrical angle θ_e^i and speed ω_e^i (per-sample
    /// increment, Q1.31) instead of the resolver's — the sensorless drive passes the
    /// estimate of [`crate::estimator`]. `added` is a voltage \[V\] added to the limited
    /// dq output before the inverse Park transform, outside the PI (the injected carrier
    /// of thesis B Appendix D, `ud = ud + udhf`); `StepOutput::u_dq` excludes it, as the
    /// estimator's back-EMF error (4.38), (4.39) wants; it applies to `Demand::Current`
    /// and `Demand::Torque` only (and adds to a `Demand::Injected`'s injection). `theta_r`/`omega_r` of the output are 0 and the observer state is untouched.
    #[allow(clippy::too_many_arguments)]
    pub fn process_at_angle<T: Trig>(
        &self,
        state: &mut ControllerState,
        trig: &mut T,
        sample: &AdcSample,
        demand: Demand,
        theta_e: i32,
        omega_e_i: i32,
        added: Dq,
    ) -> StepOutput {
        // 1. Measurements.
        let u_dc = self.dc_link_sense.volts(sample.dc_link);
        let dc_link_low = u_dc.is_nan() || u_dc < self.dc_link_min;
        let u_dc_eff = effective_dc_link(u_dc, self.dc_link_min);
        let inv_u_dc = dc_link_gain(u_dc, self.dc_link_min);
        let v_max = self.voltage_margin * u_dc_eff * INV_SQRT_3;
        let i_uvw = self.current_sense.currents(sample.phase_currents);
        let i_ab = self.current_sense.alpha_beta_of(i_uvw);

        let omega_e = speed_to_rad_per_s(omega_e_i, self.speed_per_lsb);

        // 4. Currents in the rotor frame.
        let sc = trig.sin_cos(theta_e).to_f32();
        let i_dq = park(i_ab, sc);

        // 6. (angle for the output) lead by k samples of rotation.
        let theta_lead = lead(theta_e, omega_e_i, self.angle_lead);

        // 5. Voltage demand; a torque first becomes current references (the torque stage).
        let demand = if let Demand::Torque(torque) = demand {
            let i = self.torque.process(&mut state.torque, trig, torque, omega_e, v_max);
            Demand::Current {
                id: i.d,
                iq: i.q,
                feed_forward: true,
            }
        } else {
            state.torque = TorqueState::new();
            demand
        };
        let (u_dq, u_ab) = match demand {
            Demand::Off | Demand::Torque(_) => {
                state.current = CurrentPiState::default();
                (Dq::default(), AlphaBeta::default())
            }
            Demand::Current { .. } | Demand::Injected { .. } => {
                let (id, iq, feed_forward, added) = match demand {
                    Demand::Current { id, iq, feed_forward } => (id, iq, feed_forward, added),
                    Demand::Injected { id, iq, injection } => (
                        id,
                        iq,
                        false,
                        Dq {
                            d: added.d + injection.d,
                            q: added.q + injection.q,
                        },
                    ),
                    _ => (0.0, 0.0, false, added),
                };
                let ff = if feed_forward {
                    self.feed_forward.decoupling(omega_e, i_dq)
                } else {
                    Dq::default()
                };
                let u = self.current_loop.process(
                    &mut state.current,
                    Dq { d: id, q: iq },
                    i_dq,
                    ff,
                    v_max,
                    self.sample_period,
                    trig,
                );
                // The torque stage's voltage feedback (2.55): the applied PI output.
                state.torque.voltage = u;
                let applied = Dq {
                    d: u.d + added.d,
                    q: u.q + added.q,
                };
                (u, inverse_park(applied, trig.sin_cos(theta_lead).to_f32()))
            }
            Demand::VoltageDq(v) => {
                state.current = CurrentPiState::default();
                let u = limit_voltage(v, v_max, VoltageLimit::Proportional, trig);
                (u, inverse_park(u, trig.sin_cos(theta_lead).to_f32()))
            }
            Demand::VoltageAlphaBeta(v) => {
                state.current = CurrentPiState::default();
                let lim = limit_voltage(Dq { d: v.alpha, q: v.beta }, v_max, VoltageLimit::Proportional, trig);
                let u_ab = AlphaBeta {
                    alpha: lim.d,
                    beta: lim.q,
                };
                (park(u_ab, trig.sin_cos(theta_lead).to_f32()), u_ab)
            }
        };

        // 7. Modulation.
        let duties = thpwm_limited(u_ab, u_dc_eff, inv_u_dc, self.max_duty, trig);
        StepOutput {
            duties,
            compare: compare_values(duties, self.pwm_period),
            theta_r: 0,
            omega_r: 0,
            theta_e,
            omega_e,
            i_dq,
            i_uvw,
            u_dq,
            u_alpha_beta: u_ab,
            u_dc,
            dc_link_low,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::adc::MeasuredPhases;
    use crate::ato::ObserverError;
    use crate::pi::PiConfig;
    use crate::trig::SoftTrig;
    use fixed::types::I1F31;
    use proptest::prelude::*;

    /// The configuration is plain data: a generator can emit it as a `const`.
    const CONFIG: ControllerConfig = ControllerConfig {
        sample_period: 5e-5,
        speed_per_lsb: 2.925_836_2e-5,
        current_sense: CurrentSense {
            offset: [2048; 3],
            amps_per_lsb: [0.05; 3],
            phases: MeasuredPhases::UV,
        },
        dc_link_sense: DcLinkSense {
            offset: 0,
            volts_per_lsb: 0.2,
        },
        observer: AtoConfig {
            kp: I1F31::from_bits(4_784_957),
            ki: I1F31::from_bits(8_374),
            error: ObserverError::TrigIdentity,
        },
        angle: ResolverToElectrical {
            motor_pole_pairs: 4,
            resolver_pole_pairs: 1,
            offset: 0,
        },
        angle_lead: 3 << 15,
        current_loop: CurrentPiConfig {
            d: PiConfig::new(0.393, 126.0, 2.544_529_3),
            q: PiConfig::new(0.393, 126.0, 2.544_529_3),
            limit: VoltageLimit::Proportional,
        },
        feed_forward: FeedForwardConfig {
            ld: 0.393e-3,
            lq: 0.393e-3,
            psi_m: 0.058,
        },
        dc_link_min: 432.0,
        voltage_margin: 1.0,
        pwm_period: 4250,
        max_duty: 1.0,
        torque: TorqueConfig::OFF,
    };

    proptest! {
        /// Whatever the ADCs deliver and whatever is demanded (including NaN), the
        /// step does not panic (overflow checks are on in tests) and the duties stay
        /// in \[0, 1\], the compare values in 0..=period.
        #[test]
        fn any_input_gives_valid_duties(
            codes in any::<[u16; 3]>(), sin in any::<i32>(), cos in any::<i32>(), dc in any::<u16>(),
            id in proptest::num::f32::ANY, iq in proptest::num::f32::ANY, ff in any::<bool>(), n in 1usize..20,
        ) {
            let mut st = ControllerState::new();
            let sample = AdcSample { phase_currents: codes, resolver: ResolverSample { sin, cos }, dc_link: dc };
            for _ in 0..n {
                let out = CONFIG.process(&mut st, &mut SoftTrig, &sample, Demand::Current { id, iq, feed_forward: ff });
                for d in out.duties {
                    prop_assert!((0.0..=1.0).contains(&d));
                }
                for c in out.compare {
                    prop_assert!(c <= CONFIG.pwm_period);
                }
                prop_assert_eq!(out.dc_link_low, out.u_dc.is_nan() || out.u_dc < CONFIG.dc_link_min);
            }
        }
    }

    /// The step with [`crate::FastTrig`] (2^-23) follows the step with [`SoftTrig`]
    /// (2 LSB of Q1.31): over 2000 periods of a resolver turning at 100 rad/s with a
    /// current demand, the duties never differ by more than 10⁻⁴ (0.01 % of the DC
    /// link): the trig error (≤ 10⁻⁷) stays at the f32 rounding level through the loop.
    #[test]
    fn fast_trig_step_follows_soft_trig_step() {
        let (mut soft, mut fast) = (ControllerState::new(), ControllerState::new());
        let demand = Demand::Current {
            id: -2.0,
            iq: 10.0,
            feed_forward: true,
        };
        let mut worst: f32 = 0.0;
        for n in 0..2000u32 {
            let theta = 100.0 * f64::from(n) * 5e-5;
            let sample = AdcSample {
                phase_currents: [2048 + (n % 7) as u16, 2050 - (n % 5) as u16, 2048],
                resolver: ResolverSample {
                    sin: (theta.sin() * 2.0e9) as i32,
                    cos: (theta.cos() * 2.0e9) as i32,
                },
                dc_link: 3000,
            };
            let a = CONFIG.process(&mut soft, &mut SoftTrig, &sample, demand);
            let b = CONFIG.process(&mut fast, &mut crate::FastTrig, &sample, demand);
            for (x, y) in a.duties.iter().zip(b.duties) {
                worst = worst.max((x - y).abs());
            }
        }
        println!("FastTrig vs SoftTrig step: worst duty difference {worst:e}");
        assert!(worst < 1e-4, "{worst}");
    }

    /// Open-loop α voltage reaches the phases: u_u − u_v = 1.5·u_α, duties from
    /// 1/2 ± u/U_dc; an undervoltage DC link is flagged and the minimum used.
    #[test]
    fn open_loop_alpha_voltage() {
        let mut st = ControllerState::new();
        let sample = AdcSample {
            phase_currents: [2048; 3],
            resolver: ResolverSample { sin: 0, cos: i32::MAX },
            dc_link: 3000, // 600 V
        };
        let out = CONFIG.process(
            &mut st,
            &mut SoftTrig,
            &sample,
            Demand::VoltageAlphaBeta(AlphaBeta { alpha: 60.0, beta: 0.0 }),
        );
        assert!(!out.dc_link_low);
        let [du, dv, _] = out.duties;
        // (DC_u − DC_v)·U_dc = u_u − u_v = 1.5·u_α = 90 V (f32: ≤ 1e-3 V).
        assert!(((du - dv) * 600.0 - 90.0).abs() < 1e-3);
        let low = AdcSample {
            dc_link: 1000, // 200 V < 432 V
            ..sample
        };
        let out = CONFIG.process(
            &mut st,
            &mut SoftTrig,
            &low,
            Demand::VoltageAlphaBeta(AlphaBeta { alpha: 60.0, beta: 0.0 }),
        );
        assert!(out.dc_link_low);
        // Modulated against the 432 V minimum: the phase difference is 90/432.
        let [du, dv, _] = out.duties;
        assert!(((du - dv) * 432.0 - 90.0).abs() < 1e-3);
        // The voltage circle follows the 432 V minimum: 432/√3 = 249.4 V.
        let out = CONFIG.process(
            &mut st,
            &mut SoftTrig,
            &low,
            Demand::VoltageDq(Dq { d: 0.0, q: 1000.0 }),
        );
        assert!((out.u_dq.q - 432.0 * INV_SQRT_3).abs() < 1e-2);
    }
}
