//! The firmware's [`ControllerConfig`] built from a [`Design`]: the same numbers the
//! generated constants carry (`f32` and Q1.31 values), so the simulation runs the
//! controller exactly as the firmware image for this motor would.

use std::f64::consts::PI;

use fixed::types::I1F31;
use motor_control::adc::{CurrentSense, DcLinkSense, MeasuredPhases};
use motor_control::angle::ResolverToElectrical;
use motor_control::ato::{AtoConfig, ObserverError as FwObserverError};
use motor_control::feedforward::FeedForwardConfig;
use motor_control::pi::{CurrentPiConfig, PiConfig, VoltageLimit};
use motor_control::step::ControllerConfig;

use crate::design::Design;
use crate::design::current_loop::AxisGains;
use crate::spec::ObserverError;

/// TIM1 kernel clock \[Hz\]: the STM32G474's maximum SYSCLK (170 MHz, STM32G474 datasheet),
/// as the firmware bench assumes; with centre-aligned PWM the auto-reload is
/// `TIMER_CLOCK_HZ/(2·f_s)` (4250 at 20 kHz). Only the telemetry compare values use it;
/// the simulated inverter applies the duties.
pub const TIMER_CLOCK_HZ: f64 = 170e6;

/// Mid-scale code of a bipolar current channel read as a 16-bit (Q1.15 offset-binary) value.
pub const CURRENT_OFFSET: i32 = 1 << 15;

fn axis(g: &AxisGains) -> PiConfig {
    PiConfig {
        kp: g.kp as f32,
        ki: g.ki as f32,
        anti_windup: g.anti_windup_gain as f32,
        active_damping: g.active_damping_ohm as f32,
        reference_filter: g.reference_filter as f32,
    }
}

/// The firmware configuration of `d`:
///
/// * sample period, observer speed scaling f_s·π/2^31 (4.20), angle lead k (4.23);
/// * current ADC: Q1.15 codes around [`CURRENT_OFFSET`] at `CURRENT_PER_LSB`
///   (full scale margin·√2·I_peak, (4.16)); DC link: codes from 0 at `DC_LINK_PER_LSB`;
/// * observer gains K̃_p, K̃_i (4.22) as the Q1.31 integers, error architecture;
/// * n_p, n_r, θ_off (4.5) (θ_off = 0 when the spec gives none);
/// * PI gains, back-calculation, active damping and prefilter per axis;
/// * feed-forward L_d, L_q, ψ_M (5.3) (ψ_M = 0 when unknown);
/// * U_dc,min (5.1), voltage circle U_dc/√3 (2.50) (margin 1), PWM auto-reload.
pub fn controller_config(d: &Design) -> ControllerConfig {
    let cl = &d.current_loop;
    let o = &d.angle_observer;
    let s = &d.scaling;
    let fs = d.drive.switching_frequency_hz;
    ControllerConfig {
        sample_period: d.drive.sample_period_s as f32,
        speed_per_lsb: s.speed.si_per_lsb as f32,
        current_sense: CurrentSense {
            offset: [CURRENT_OFFSET; 3],
            amps_per_lsb: [s.phase_current.si_per_lsb as f32; 3],
            phases: MeasuredPhases::Three,
        },
        dc_link_sense: DcLinkSense {
            offset: 0,
            volts_per_lsb: s.dc_link_voltage.si_per_lsb as f32,
        },
        observer: AtoConfig {
            kp: I1F31::from_bits(o.kp_q31),
            ki: I1F31::from_bits(o.ki_q31),
            error: match o.error {
                ObserverError::TrigIdentity => FwObserverError::TrigIdentity,
                ObserverError::Atan2 => FwObserverError::Atan2,
            },
        },
        angle: ResolverToElectrical {
            motor_pole_pairs: u16::try_from(o.motor_pole_pairs).unwrap_or(u16::MAX),
            resolver_pole_pairs: u16::try_from(o.resolver_pole_pairs).unwrap_or(u16::MAX),
            offset: o.resolver_offset_q31.unwrap_or(0),
        },
        angle_lead: o.lead_q16,
        current_loop: CurrentPiConfig {
            d: axis(&cl.d),
            q: axis(&cl.q),
            limit: VoltageLimit::Proportional,
        },
        feed_forward: FeedForwardConfig {
            ld: cl.feedforward.d_inductance_h as f32,
            lq: cl.feedforward.q_inductance_h as f32,
            psi_m: cl.feedforward.flux_linkage_wb.unwrap_or(0.0) as f32,
        },
        dc_link_min: d.drive.dc_link_voltage_min_v as f32,
        // VOLTAGE_LIMIT_V = U_dc/√3 (2.50): the whole THPWM linear range.
        voltage_margin: (cl.voltage_limit_v * 3f64.sqrt() / d.drive.dc_link_voltage_v) as f32,
        pwm_period: (TIMER_CLOCK_HZ / (2.0 * fs)).round().clamp(1.0, f64::from(u16::MAX)) as u16,
    }
}

/// Resolver offset the plant uses: the design's θ_off, else 0 (matching the config).
pub fn resolver_offset_rad(d: &Design) -> f64 {
    d.angle_observer
        .resolver_offset_q31
        .map_or(0.0, |b| f64::from(b) * PI / 2_147_483_648.0)
}
