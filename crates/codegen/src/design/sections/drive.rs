//! The inverter operating point, the sampling rule f_s ≥ 12·f_e,max (thesis A 1.1) and
//! the firmware's limits on the drive's values (`crate::firmware`): TIM1's 16-bit
//! auto-reload for f_s, its dead-time generator for `drive.dead_time`.

use serde::Serialize;

use super::Context;
use crate::design::acceleration::AccelerationRule;
use crate::design::{dead_time, sampling};
use crate::firmware;

/// Inverter operating point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriveOut {
    /// f_s \[Hz\].
    pub switching_frequency_hz: f64,
    /// T_s = 1/f_s \[s\].
    pub sample_period_s: f64,
    /// TIM1 auto-reload of the centre-aligned carrier, f_TIM/(2·f_s) rounded
    /// (`firmware::pwm_period`, the firmware's `config::PWM_PERIOD`).
    pub pwm_period: u16,
    /// 12·f_e,max \[Hz\] (1.1).
    pub min_switching_frequency_hz: f64,
    /// U_dc \[V\].
    pub dc_link_voltage_v: f64,
    /// Lowest U_dc \[V\].
    pub dc_link_voltage_min_v: f64,
    /// Dead time \[s\] (`drive.dead_time`).
    pub dead_time_s: Option<f64>,
    /// Its average voltage error U_dc·t_d·f_s \[V\] (see [`dead_time`]).
    pub dead_time_voltage_error_v: Option<f64>,
    /// Largest shaft acceleration the drive must follow [rad/s², mechanical]
    /// (`design::acceleration`).
    pub max_acceleration_rad_s2: f64,
    /// Where it came from.
    pub max_acceleration_rule: AccelerationRule,
}

/// The drive section; f_s below 12·f_e,max (1.1) is an error at `drive.switching_frequency`.
pub(in crate::design) fn drive(cx: &mut Context<'_>) -> DriveOut {
    let spec = cx.spec;
    let fs = cx.switching_frequency();
    let fe_max = cx.max_electrical_frequency();
    let fs_min = sampling::min_switching_frequency(fe_max);
    if fs < fs_min {
        let p = &spec.drive.switching_frequency;
        cx.errors.push(cx.src.error(
            p.span.clone(),
            &p.key,
            format!("f_s = {fs} Hz is below 12·f_e,max = {fs_min:.0} Hz (thesis A 1.1) for f_e,max = {fe_max:.1} Hz"),
            format!(
                "a switching frequency of at least {:.0} Hz, or a lower motor.max_speed",
                fs_min.ceil()
            ),
        ));
    }
    let pwm_period = match firmware::pwm_period(fs) {
        Ok(arr) => arr,
        Err(r) => {
            let p = &spec.drive.switching_frequency;
            cx.errors
                .push(cx.src.error(p.span.clone(), &p.key, r.problem, r.accepted));
            0
        }
    };
    if let Some(p) = &spec.drive.dead_time
        && let Err(r) = firmware::dead_time(p.value)
    {
        cx.errors
            .push(cx.src.error(p.span.clone(), &p.key, r.problem, r.accepted));
    }
    let (acceleration, rule) = cx.max_acceleration();
    DriveOut {
        switching_frequency_hz: fs,
        sample_period_s: 1.0 / fs,
        pwm_period,
        min_switching_frequency_hz: fs_min,
        dc_link_voltage_v: spec.drive.dc_link_voltage.value,
        dc_link_voltage_min_v: spec.drive.dc_link_voltage_min.value,
        dead_time_s: spec.drive.dead_time.as_ref().map(|p| p.value),
        max_acceleration_rad_s2: acceleration,
        max_acceleration_rule: rule,
        dead_time_voltage_error_v: spec
            .drive
            .dead_time
            .as_ref()
            .map(|p| dead_time::voltage_error(spec.drive.dc_link_voltage.value, p.value, fs)),
    }
}
