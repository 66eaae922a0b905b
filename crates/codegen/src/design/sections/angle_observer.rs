//! The angle-tracking-observer section: gains (4.15) scaled to Q1.31 (4.22), the speed
//! full scale f_s·π (4.20) against the top speed, the resolver ratio and offset (4.5) and
//! the angle lead (4.23).

use std::f64::consts::PI;

use serde::Serialize;

use super::Context;
use crate::design::angle_observer::{self, ObserverGains};
use crate::spec::{ObserverError, Provenance};

/// The angle-tracking-observer design.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObserverOut {
    /// Error architecture.
    pub error: ObserverError,
    /// ω_n [rad/s].
    pub natural_frequency_rad_s: f64,
    /// ζ.
    pub damping: f64,
    /// K_p, K_i (4.15) and their Q1.31 forms K̃_p, K̃_i (4.22), with K̃_i's rounding error
    /// (serialised as fields of this section).
    #[serde(flatten)]
    pub gains: ObserverGains,
    /// n_p (motor).
    pub motor_pole_pairs: u32,
    /// n_r (resolver).
    pub resolver_pole_pairs: u32,
    /// n_p/n_r of (4.5).
    pub electrical_per_resolver: f64,
    /// θ_off \[rad\] of (4.5), if known.
    pub resolver_offset_rad: Option<f64>,
    /// θ_off as a Q1.31 stored integer (angle/π), if known.
    pub resolver_offset_q31: Option<i32>,
    /// Delay k in samples compensated by the angle lead (4.23).
    pub lead_samples: f64,
    /// Where k came from: `angle_observer.lead_samples`, or by default the board's timing
    /// (from the resolver's sample to the voltage's mean; 1.5 without a board, thesis A §4.6).
    pub lead_samples_source: Provenance,
    /// k in Q16.16: θ_e,lead^i = θ_e^i + (ω_e^i·LEAD) >> 16, ω_e^i the per-sample electrical angle step (4.19), (4.23).
    pub lead_q16: i32,
    /// Lag k·ω_e,max·T_s at maximum speed \[deg\] (4.23).
    pub lead_at_max_speed_deg: f64,
    /// Steady lag of the observer at the drive's largest acceleration
    /// (`drive.max_acceleration_rad_s2`), in electrical degrees (`angle_observer::ramp_lag`).
    pub lag_at_max_acceleration_deg: f64,
    /// The largest the design accepts [electrical °] (`angle_observer::MAX_TRACKING_ERROR_DEG`).
    pub max_lag_deg: f64,
    /// The error form as the generated `observer::ERROR_FORM`: 0 = trig identity (4.8),
    /// 1 = atan2 (CORDIC phase, normalised by π).
    pub error_form: u8,
}

/// The observer section, or `None` with the broken rules in `cx.errors`.
pub(in crate::design) fn angle_observer(cx: &mut Context<'_>) -> Option<ObserverOut> {
    let spec = cx.spec;
    let m = &spec.motor;
    let fs = cx.switching_frequency();
    let fe_max = cx.max_electrical_frequency();
    let o = &spec.angle_observer;
    let obs = angle_observer::design(
        o.natural_frequency.value,
        o.damping.value,
        fs,
        o.error,
        cx.resolver_signal_gain,
    )
    .map_err(|e| {
        let (gain, scaled, what) = match e {
            angle_observer::ObserverGainError::Overflow { gain, scaled } => {
                (gain, scaled, "does not fit Q1.31 (|K̃| must be < 1)")
            }
            angle_observer::ObserverGainError::Underflow { gain, scaled } => (gain, scaled, "rounds to zero in Q1.31"),
        };
        cx.errors.push(cx.src.error(
            o.natural_frequency.span.clone(),
            &o.natural_frequency.key,
            format!("observer gain K̃_{} = {scaled:.3e} (4.22) {what}", &gain[1..]),
            if cx.resolver_signal_gain == 1.0 || o.error == ObserverError::Atan2 {
                "a natural frequency that keeps K̃_p = 2ζω_n/(f_s·π) below 1 and K̃_i = ω_n²/(f_s²·π) above 2^−32".to_string()
            } else {
                format!(
                    "a natural frequency that keeps K̃_p = 2ζω_n/(f_s·π·g) below 1 and K̃_i = ω_n²/(f_s²·π·g) above 2^−32, g = {:.4} the board's resolver signal as a fraction of full scale (4.10), or a board whose front end gives more",
                    cx.resolver_signal_gain
                )
            },
        ))
    })
    .ok();
    let np = m.pole_pairs;
    let nr = spec.resolver.pole_pairs;
    // Observer speed full scale f_s·π rad/s of resolver angle (4.20) must hold the top speed.
    let wr_max = f64::from(nr) * m.max_speed.value;
    if wr_max >= fs * PI {
        cx.errors.push(cx.src.error(
            m.max_speed.span.clone(),
            &m.max_speed.key,
            format!("resolver speed n_r·ω_m,max = {wr_max:.0} rad/s exceeds the observer speed full scale f_s·π = {:.0} rad/s (4.20)", fs * PI),
            "a maximum speed below f_s·π/n_r",
        ));
    }
    let obs = obs?;
    // The observer must follow the drive's largest acceleration within the allowed angle.
    let (acc, rule) = cx.max_acceleration();
    let a_r = f64::from(nr) * acc;
    let per_electrical = f64::from(nr) / f64::from(np);
    let limit_r = angle_observer::MAX_TRACKING_ERROR_DEG.to_radians() * per_electrical;
    let lag_r = angle_observer::ramp_lag(a_r, obs.ki, o.error);
    if lag_r.is_none_or(|l| l > limit_r * (1.0 + 1e-12)) {
        let wn_min = angle_observer::min_natural_frequency(a_r, limit_r, o.error);
        cx.errors.push(cx.src.error(
            o.natural_frequency.span.clone(),
            &o.natural_frequency.key,
            format!(
                "at the drive's largest acceleration {acc:.1} rad/s² ({:.0} rpm/s; {}) the observer (K_i = ω_n² = {:.0} rad/s²) {} (type-2 loop: K_i·sin Δ = n_r·ω̇_m, thesis A §4.4); field orientation allows {}° electrical (thesis B §4.4.2)",
                acc * 30.0 / PI,
                rule.describe(),
                obs.ki,
                match lag_r {
                    Some(l) => format!("lags by {:.1}° electrical", l / per_electrical * 180.0 / PI),
                    None => "cannot follow at all (n_r·ω̇_m ≥ K_i: it slips cycles)".to_string(),
                },
                angle_observer::MAX_TRACKING_ERROR_DEG
            ),
            format!(
                "a natural frequency of at least {wn_min:.0} rad/s, or drive.max_acceleration (or drive.application) if the drive accelerates slower than that"
            ),
        ));
    }
    let offset = spec.resolver.offset.as_ref().map(|p| p.value);
    let lead = cx.angle_lead_periods();
    Some(ObserverOut {
        error: o.error,
        natural_frequency_rad_s: o.natural_frequency.value,
        damping: o.damping.value,
        gains: obs,
        motor_pole_pairs: np,
        resolver_pole_pairs: nr,
        electrical_per_resolver: f64::from(np) / f64::from(nr),
        resolver_offset_rad: offset,
        // θ_off wrapped into one turn, π-scaled Q1.31 (4.20): the control core's own conversion.
        resolver_offset_q31: offset.map(motor_control::angle::from_radians_f64),
        lead_samples: lead,
        lead_samples_source: o.lead_samples.source,
        lead_q16: (lead * 65_536.0).round() as i32,
        lead_at_max_speed_deg: angle_observer::lag_angle(lead, 2.0 * PI * fe_max, fs).to_degrees(),
        lag_at_max_acceleration_deg: lag_r.map_or(f64::INFINITY, |l| (l / per_electrical).to_degrees()),
        max_lag_deg: angle_observer::MAX_TRACKING_ERROR_DEG,
        error_form: match o.error {
            ObserverError::TrigIdentity => 0,
            ObserverError::Atan2 => 1,
        },
    })
}
