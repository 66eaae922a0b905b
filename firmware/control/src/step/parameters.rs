//! The one mapping from a motor's design to the step's [`ControllerConfig`]. The
//! firmware (`motor_config::config::CONTROLLER`, from the generated constants) and the
//! code generator's simulation (`codegen::verify::controller`, from a `Design`) each
//! fill a [`ControllerParameters`] of plain values and call
//! [`ControllerConfig::from_parameters`], so every choice the mapping makes — the
//! observer's error form, the measured phases, the pole-pair range, the voltage circle,
//! the ADC layout — is made here once. What the two sides legitimately fill differently
//! is the current sensing: the board's ADC codes in the firmware, the design's Q1.15
//! full scale in the simulation.

use super::ControllerConfig;
use crate::adc::{CurrentSense, DcLinkSense, MeasuredPhases};
use crate::angle::ResolverToElectrical;
use crate::ato::{AtoConfig, ObserverError};
use crate::feedforward::FeedForwardConfig;
use crate::pi::{CurrentPiConfig, PiConfig, VoltageLimit};
use crate::torque::{TorqueConfig, TorqueParameters};
use fixed::types::I1F31;

/// A motor's design on one board, as plain values: the generated constants of the same
/// names (thesis A chapters 4 and 5) and the board's sensing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerParameters {
    /// Sample (= PWM) period T_s = 1/f_s \[s\] (4.17).
    pub sample_period: f32,
    /// Observer speed scaling π·f_s/2^31 \[rad/s per LSB\] (4.20).
    pub speed_per_lsb: f32,
    /// Code of zero current on every current channel \[LSB\].
    pub current_offset_code: i32,
    /// Current per code \[A/LSB\].
    pub current_per_lsb: f32,
    /// Measured phase currents: 3 (u, v, w), else 2 (u, v; w from (2.1)).
    pub current_phases: u8,
    /// DC-link voltage per code from zero \[V/LSB\].
    pub dc_link_per_lsb: f32,
    /// Observer K̃_p, Q1.31 stored integer (4.22).
    pub observer_kp_q31: i32,
    /// Observer K̃_i, Q1.31 stored integer (4.22).
    pub observer_ki_q31: i32,
    /// The error form the observer gains are scaled for, as the generated
    /// `observer::ERROR_FORM`: 0 = trig identity (4.8), otherwise (1) atan2 (4.10).
    pub observer_error_form: u8,
    /// Motor pole pairs n_p (4.5).
    pub motor_pole_pairs: u32,
    /// Resolver pole pairs n_r (4.5).
    pub resolver_pole_pairs: u32,
    /// Resolver offset θ_off, π-scaled Q1.31 (4.5) (0 until identified, (6.9)).
    pub resolver_offset_q31: i32,
    /// Delay k compensated by the angle lead (4.23) \[samples, Q16.16\].
    pub lead_q16: i32,
    /// d-axis current PI: gains, back-calculation, active damping, prefilter.
    pub d: PiConfig,
    /// q-axis current PI.
    pub q: PiConfig,
    /// Feed-forward L_d \[H\] (5.3).
    pub ld: f32,
    /// Feed-forward L_q \[H\] (5.3).
    pub lq: f32,
    /// Feed-forward ψ_M \[Wb\] (5.3), 0 when unknown.
    pub psi_m: f32,
    /// Lowest U_dc of the 1/U_dc feed-forward \[V\] (5.1).
    pub dc_link_min: f32,
    /// TIM1 auto-reload of the centre-aligned carrier
    /// ([`crate::modulation::centre_aligned_period`]) \[ticks\].
    pub pwm_period: u16,
    /// The torque stage's constants (MTPA, field weakening, MTPV; [`crate::torque`]).
    pub torque: TorqueParameters,
    /// Largest duty of a leg, the generated `board::MAX_DUTY` (1 without a limit).
    pub max_duty: f32,
    /// The fraction of U_dc/√3 that keeps the modulator within it, the generated
    /// `board::USABLE_VOLTAGE_FRACTION` (1 without a limit).
    pub usable_voltage_fraction: f32,
}

/// `n` as the `u16` of [`ResolverToElectrical`], saturating (no motor or resolver has
/// 65 535 pole pairs; the design limits both far below).
const fn pole_pairs(n: u32) -> u16 {
    if n > u16::MAX as u32 { u16::MAX } else { n as u16 }
}

impl ControllerConfig {
    /// The step's configuration for `p`:
    ///
    /// * current channels: all three share offset and scale; DC link: codes from 0;
    /// * observer: the Q1.31 gains and the error form they were scaled for;
    /// * angle: n_p, n_r, θ_off (4.5);
    /// * the current loop limits with the proportional voltage circle
    ///   (`VoltageLimit::Proportional`) at the usable fraction k of V_max = U_dc/√3
    ///   (2.50): the whole THPWM linear range (3.8) without a duty limit (k = 1), else
    ///   the part whose duties stay within `max_duty` — the generated `VOLTAGE_LIMIT_V`
    ///   at the nominal U_dc;
    /// * the torque stage of [`TorqueConfig::from_parameters`].
    pub const fn from_parameters(p: &ControllerParameters) -> Self {
        Self {
            sample_period: p.sample_period,
            speed_per_lsb: p.speed_per_lsb,
            current_sense: CurrentSense {
                offset: [p.current_offset_code; 3],
                amps_per_lsb: [p.current_per_lsb; 3],
                phases: if p.current_phases == 3 {
                    MeasuredPhases::Three
                } else {
                    MeasuredPhases::UV
                },
            },
            dc_link_sense: DcLinkSense {
                offset: 0,
                volts_per_lsb: p.dc_link_per_lsb,
            },
            observer: AtoConfig {
                kp: I1F31::from_bits(p.observer_kp_q31),
                ki: I1F31::from_bits(p.observer_ki_q31),
                error: if p.observer_error_form == 0 {
                    ObserverError::TrigIdentity
                } else {
                    ObserverError::Atan2
                },
            },
            angle: ResolverToElectrical {
                motor_pole_pairs: pole_pairs(p.motor_pole_pairs),
                resolver_pole_pairs: pole_pairs(p.resolver_pole_pairs),
                offset: p.resolver_offset_q31,
            },
            angle_lead: p.lead_q16,
            current_loop: CurrentPiConfig {
                d: p.d,
                q: p.q,
                limit: VoltageLimit::Proportional,
            },
            feed_forward: FeedForwardConfig {
                ld: p.ld,
                lq: p.lq,
                psi_m: p.psi_m,
            },
            dc_link_min: p.dc_link_min,
            voltage_margin: p.usable_voltage_fraction,
            pwm_period: p.pwm_period,
            max_duty: p.max_duty,
            torque: TorqueConfig::from_parameters(&p.torque),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modulation::centre_aligned_period;

    /// The Fischer TI085 on the reference board (thesis A Tables 1.1, 1.2, §4.4.2),
    /// by hand: f_s = 20 kHz, T_s = 50 µs; speed π·20 000/2^31 = 2.9258e-5 rad/s per LSB;
    /// current 3.3 V/(15 mV/A·2^16) = 3.3569 mA per code about 32 768; DC link
    /// 750 V/2^15 = 22.888 mV per code; K̃_p = 2·70/(20 000·π)·2^31 = 4 784 957,
    /// K̃_i = 70²/(20 000²·π)·2^31 = 8 374; n_p = 4, n_r = 1; lead 1.5·2^16 = 98 304;
    /// K_p = L·α = 0.0393 V/A, K_i = R·α = 12.6 (5.9), back-calculation 1/K_p;
    /// U_dc,min = 432 V; ARR = 170 MHz/(2·20 kHz) = 4250.
    fn fischer() -> ControllerParameters {
        let pi = PiConfig::new(0.0393, 12.6, 1.0 / 0.0393);
        ControllerParameters {
            sample_period: 50e-6,
            speed_per_lsb: core::f32::consts::PI * 20_000.0 / 2_147_483_648.0,
            current_offset_code: 32_768,
            current_per_lsb: 3.3 / (0.015 * 65_536.0),
            current_phases: 3,
            dc_link_per_lsb: 750.0 / 32_768.0,
            observer_kp_q31: 4_784_957,
            observer_ki_q31: 8_374,
            observer_error_form: 0,
            motor_pole_pairs: 4,
            resolver_pole_pairs: 1,
            resolver_offset_q31: 0,
            lead_q16: 98_304,
            d: pi,
            q: pi,
            ld: 0.393e-3,
            lq: 0.393e-3,
            // ψ_M from K_e = 0.296 V·s/rad: 0.296·√2/(√3·4) = 0.060421 Wb (2.34).
            psi_m: 0.060_421,
            dc_link_min: 432.0,
            pwm_period: 4250,
            torque: crate::torque::TorqueParameters {
                sample_period: 50e-6,
                pole_pairs: 4,
                psi_m: 0.060_421,
                ld: 0.393e-3,
                lq: 0.393e-3,
                bandwidth: 10.0,
                base_speed: 4362.5,
                voltage_fraction: 0.9,
                current_max: 86.27,
                mtpa_torque_max: 31.27,
                mtpa_id: [0.0; crate::torque::MTPA_POINTS],
            },
            max_duty: 1.0,
            usable_voltage_fraction: 1.0,
        }
    }

    /// Every value reaches its field; the three current channels share the sensing; the
    /// DC link counts from 0; the voltage circle is the whole linear range (margin 1).
    #[test]
    fn fischer_by_hand() {
        let p = fischer();
        let c = ControllerConfig::from_parameters(&p);
        assert_eq!(c.sample_period, 50e-6);
        assert_eq!(c.speed_per_lsb, p.speed_per_lsb);
        assert_eq!(c.current_sense.offset, [32_768; 3]);
        assert_eq!(c.current_sense.amps_per_lsb, [p.current_per_lsb; 3]);
        assert_eq!(c.current_sense.phases, MeasuredPhases::Three);
        assert_eq!(
            (c.dc_link_sense.offset, c.dc_link_sense.volts_per_lsb),
            (0, p.dc_link_per_lsb)
        );
        assert_eq!((c.observer.kp.to_bits(), c.observer.ki.to_bits()), (4_784_957, 8_374));
        assert_eq!(c.observer.error, ObserverError::TrigIdentity);
        assert_eq!(
            (c.angle.motor_pole_pairs, c.angle.resolver_pole_pairs, c.angle.offset),
            (4, 1, 0)
        );
        assert_eq!(c.angle_lead, 3 << 15);
        assert_eq!((c.current_loop.d, c.current_loop.q), (p.d, p.q));
        assert_eq!(c.current_loop.limit, VoltageLimit::Proportional);
        assert_eq!((c.feed_forward.ld, c.feed_forward.lq), (0.393e-3, 0.393e-3));
        assert_eq!(c.feed_forward.psi_m, 0.060_421);
        assert_eq!(c.dc_link_min, 432.0);
        assert_eq!(c.voltage_margin, 1.0);
        assert_eq!(Some(c.pwm_period), centre_aligned_period(170_000_000, 20_000.0));
        // Torque stage: 3/2·n_p = 6, non-salient (ΔL = 0), ψ_M = 0.0604 Wb > L_d·I_max
        // = 0.0339 Wb: no MTPV line inside the circle; table index 16/31.27 per N·m.
        assert_eq!(c.torque.torque_factor, 6.0);
        assert_eq!(c.torque.delta_l, 0.0);
        assert!(!c.torque.mtpv);
        assert_eq!(c.torque.mtpa_per_torque, 16.0 / 31.27);
    }

    /// A duty limit reaches the modulator and the voltage circle: d_max = 0.8786 and its
    /// usable fraction 0.7461 (the NUCLEO's with the maxon motor at 40 kHz).
    #[test]
    fn duty_limit_reaches_the_step() {
        let p = ControllerParameters {
            max_duty: 0.8786,
            usable_voltage_fraction: 0.7461,
            ..fischer()
        };
        let c = ControllerConfig::from_parameters(&p);
        assert_eq!(c.max_duty, 0.8786);
        assert_eq!(c.voltage_margin, 0.7461);
    }

    /// The choices: error form 1 is atan2 (4.10); two measured phases are u and v;
    /// pole pairs beyond `u16` saturate instead of wrapping (65 536 would wrap to 0).
    #[test]
    fn choices() {
        let p = ControllerParameters {
            observer_error_form: 1,
            current_phases: 2,
            motor_pole_pairs: 65_536,
            resolver_pole_pairs: 3,
            ..fischer()
        };
        let c = ControllerConfig::from_parameters(&p);
        assert_eq!(c.observer.error, ObserverError::Atan2);
        assert_eq!(c.current_sense.phases, MeasuredPhases::UV);
        assert_eq!((c.angle.motor_pole_pairs, c.angle.resolver_pole_pairs), (u16::MAX, 3));
    }
}
