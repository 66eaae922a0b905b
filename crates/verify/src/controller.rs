//! The firmware's [`ControllerConfig`] built from a [`Design`] through the control core's
//! own mapping ([`ControllerConfig::from_parameters`], which the firmware's
//! `motor_config::config::CONTROLLER` uses too): the same numbers the generated constants
//! carry (`f32` and Q1.31 values), so the simulation runs the controller exactly as the
//! firmware image for this motor would. Only the current sensing differs: the design's
//! Q1.15 full scale instead of a board's ADC codes.

use motor_control::angle::to_radians_f64;
use motor_control::step::{ControllerConfig, ControllerParameters};
use motor_control::torque::{MTPA_POINTS, TorqueParameters};

use codegen::design::Design;

/// Mid-scale code of a bipolar current channel read as a 16-bit (Q1.15 offset-binary) value.
pub const CURRENT_OFFSET: i32 = 1 << 15;

/// The parameters of `d` for [`ControllerConfig::from_parameters`]:
///
/// * sample period, observer speed scaling f_s·π/2^31 (4.20), angle lead k (4.23);
/// * current ADC: Q1.15 codes around [`CURRENT_OFFSET`] at `CURRENT_PER_LSB`
///   (full scale margin·√2·I_peak, (4.16)), three phases; DC link at `DC_LINK_PER_LSB`;
///   for a design on a board, the board's offset code, amperes per code, phases and DC-link
///   scale, as the image's `config::PARAMETERS` takes them;
/// * observer gains K̃_p, K̃_i (4.22) as the Q1.31 integers, error form;
/// * n_p, n_r, θ_off (4.5) (θ_off = 0 when the spec gives none);
/// * PI gains, back-calculation, active damping and prefilter per axis;
/// * feed-forward L_d, L_q, ψ_M (5.3) (ψ_M = 0 when unknown);
/// * U_dc,min (5.1), the design's PWM auto-reload (`drive.pwm_period`: TIM1's clock
///   `codegen::firmware::TIMER_CLOCK_HZ`/(2·f_s); a design never has an f_s the 16-bit
///   register cannot hold, `check` refuses it). Only the telemetry compare values use
///   it; the simulated inverter applies the duties.
pub fn controller_parameters(d: &Design) -> ControllerParameters {
    let cl = &d.current_loop;
    let o = &d.angle_observer;
    let s = &d.scaling;
    // On a board, its sensing (the firmware's `config::PARAMETERS`); else the design's
    // full scales.
    let (current_offset_code, current_per_lsb, current_phases, dc_link_per_lsb) = match &d.board {
        Some(b) => (
            b.current_offset_code,
            b.amps_per_lsb as f32,
            b.current_phases,
            b.dc_link_volts_per_lsb as f32,
        ),
        None => (
            CURRENT_OFFSET,
            s.phase_current.si_per_lsb as f32,
            3,
            s.dc_link_voltage.si_per_lsb as f32,
        ),
    };
    ControllerParameters {
        sample_period: d.drive.sample_period_s as f32,
        speed_per_lsb: s.speed.si_per_lsb as f32,
        current_offset_code,
        current_per_lsb,
        current_phases,
        dc_link_per_lsb,
        observer_kp_q31: o.gains.kp_q31,
        observer_ki_q31: o.gains.ki_q31,
        observer_error_form: o.error_form,
        motor_pole_pairs: o.motor_pole_pairs,
        resolver_pole_pairs: o.resolver_pole_pairs,
        resolver_offset_q31: o.resolver_offset_q31.unwrap_or(0),
        lead_q16: o.lead_q16,
        d: cl.d.pi_config(),
        q: cl.q.pi_config(),
        ld: cl.feedforward.d_inductance_h as f32,
        lq: cl.feedforward.q_inductance_h as f32,
        psi_m: cl.feedforward.flux_linkage_wb.unwrap_or(0.0) as f32,
        dc_link_min: d.drive.dc_link_voltage_min_v as f32,
        pwm_period: d.drive.pwm_period,
        torque: torque_parameters(d),
        // On a board its duty limit (the firmware's `board::MAX_DUTY`), else none; the
        // usable fraction as the design has it (1 without a limit).
        max_duty: d.board.as_ref().map_or(1.0, |b| b.duty_limit.max_duty) as f32,
        usable_voltage_fraction: d.modulation.usable_voltage_fraction as f32,
    }
}

/// The torque stage's parameters of `d` (`motor_control::torque`), the values the
/// generated constants carry and the firmware's `motor_config::config::TORQUE` reads:
/// n_p, ψ_M and L_q as the feed-forward has them (`current_loop::FF_PSI`, `FF_LQ`),
/// and the field-weakening design's L̂_d, α_fw, ω_base, V'_max/V_max, I_max and MTPA
/// table by torque (thesis B §2.3, (3.10)); all zero without ψ_M (the stage is off).
pub fn torque_parameters(d: &Design) -> TorqueParameters {
    let ff = &d.current_loop.feedforward;
    let sample_period = d.drive.sample_period_s as f32;
    let pole_pairs = d.angle_observer.motor_pole_pairs;
    match &d.field_weakening {
        Some(fw) => {
            let mut mtpa_id = [0.0f32; MTPA_POINTS];
            for (x, &id) in mtpa_id.iter_mut().zip(&fw.mtpa_by_torque.id_a) {
                *x = id as f32;
            }
            TorqueParameters {
                sample_period,
                pole_pairs,
                psi_m: ff.flux_linkage_wb.unwrap_or(0.0) as f32,
                ld: fw.d_inductance_h as f32,
                lq: ff.q_inductance_h as f32,
                bandwidth: fw.bandwidth_rad_s as f32,
                base_speed: fw.base_speed_rad_s as f32,
                voltage_fraction: fw.voltage_fraction as f32,
                current_max: fw.current_max_a as f32,
                mtpa_torque_max: fw.mtpa_by_torque.torque_nm.last().copied().unwrap_or(0.0) as f32,
                mtpa_id,
            }
        }
        None => TorqueParameters {
            sample_period,
            pole_pairs,
            psi_m: 0.0,
            ld: 0.0,
            lq: ff.q_inductance_h as f32,
            bandwidth: 0.0,
            base_speed: 0.0,
            voltage_fraction: 0.0,
            current_max: 0.0,
            mtpa_torque_max: 0.0,
            mtpa_id: [0.0; MTPA_POINTS],
        },
    }
}

/// The firmware configuration of `d` ([`controller_parameters`] through the control
/// core's mapping).
pub fn controller_config(d: &Design) -> ControllerConfig {
    ControllerConfig::from_parameters(&controller_parameters(d))
}

/// Resolver offset the plant uses: the controller's θ_off (the design's, wrapped into
/// one turn and rounded to Q1.31, else 0), so plant and controller agree exactly.
pub fn resolver_offset_rad(d: &Design) -> f64 {
    to_radians_f64(d.angle_observer.resolver_offset_q31.unwrap_or(0))
}
