//! The design: every constant the controller needs, computed from a resolved [`Spec`].
//!
//! Each submodule computes one thing and cites its equation; this module only
//! assembles them, applies the design-rule checks, and reports violations at
//! the key that caused them.

pub mod adc;
pub mod angle_observer;
pub mod current_loop;
pub mod discrete_loop;

pub mod field_weakening;
pub mod fir;
pub mod flux_linkage;
pub mod loss_minimisation;
pub mod modulation;
pub mod per_unit;
pub mod sampling;
pub mod scaling;
pub mod sensorless;
pub mod thermal;

use std::collections::BTreeMap;
use std::f64::consts::{PI, SQRT_2};

use serde::Serialize;

use crate::diagnostic::{Diagnostic, Diagnostics, Source};
use crate::spec::{FluxCrossCheck, Method, ObserverError, Param, Provenance, Spec};
use current_loop::{AxisGains, CurrentLoopError};
use scaling::{QFormat, Scaling};

/// A value with where it came from, for the JSON provenance table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Origin {
    /// datasheet / identified / derived / default.
    pub source: Provenance,
    /// The key it was read from.
    pub key: String,
    /// Formula and inputs, for derived values.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl From<&Param> for Origin {
    fn from(p: &Param) -> Self {
        Origin {
            source: p.source,
            key: p.key.clone(),
            note: p.note.clone(),
        }
    }
}

/// Motor values the design used (SI).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MotorOut {
    /// n_p.
    pub pole_pairs: u32,
    /// R_s [Ω].
    pub phase_resistance_ohm: f64,
    /// R_s at the maximum winding temperature [Ω] (thesis B 2.24), if `[thermal]` is given.
    pub phase_resistance_hot_ohm: Option<f64>,
    /// L_d [H].
    pub d_inductance_h: f64,
    /// L_q [H].
    pub q_inductance_h: f64,
    /// ψ_M [Wb], null if unknown.
    pub flux_linkage_wb: Option<f64>,
    /// ψ_M from K_t and from K_e, when both are given.
    pub flux_cross_check: Option<FluxCrossCheck>,
    /// τ_d = L_d/R [s].
    pub d_time_constant_s: f64,
    /// τ_q = L_q/R [s].
    pub q_time_constant_s: f64,
    /// Peak phase current, rms [A].
    pub peak_current_a_rms: f64,
    /// Nominal phase current, rms [A].
    pub nominal_current_a_rms: Option<f64>,
    /// Maximum shaft speed [rad/s].
    pub max_speed_rad_s: f64,
    /// Maximum shaft speed [rpm].
    pub max_speed_rpm: f64,
    /// f_e,max = n_p·n_max/60 [Hz] (Table 1.2).
    pub max_electrical_frequency_hz: f64,
    /// ω_e,max = 2π·f_e,max [rad/s] (2.19).
    pub max_electrical_speed_rad_s: f64,
    /// Peak phase-current amplitude √2·I_peak,rms [A] (current-circle radius, thesis B 2.51).
    pub peak_current_a: f64,
    /// Where each value came from.
    pub provenance: BTreeMap<&'static str, Origin>,
}

/// Inverter operating point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriveOut {
    /// f_s [Hz].
    pub switching_frequency_hz: f64,
    /// T_s = 1/f_s [s].
    pub sample_period_s: f64,
    /// 12·f_e,max [Hz] (1.1).
    pub min_switching_frequency_hz: f64,
    /// U_dc [V].
    pub dc_link_voltage_v: f64,
    /// Lowest U_dc [V].
    pub dc_link_voltage_min_v: f64,
    /// Dead time [s].
    pub dead_time_s: Option<f64>,
}

/// Decoupling and back-EMF feed-forward constants (5.3), torque → i_q (2.34).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeedForward {
    /// L_d in u_q,ff = ω_e·(L_d·i_d + ψ_M) [H].
    pub d_inductance_h: f64,
    /// L_q in u_d,ff = −ω_e·L_q·i_q [H].
    pub q_inductance_h: f64,
    /// ψ_M in the back-EMF term [Wb]; null when unknown (term omitted).
    pub flux_linkage_wb: Option<f64>,
    /// K_t = 3/2·n_p·ψ_M per peak ampere [N·m/A] (2.34).
    pub torque_constant_nm_per_a: Option<f64>,
    /// 1/K_t: i_q per N·m [A/(N·m)].
    pub iq_per_nm: Option<f64>,
}

/// The current-loop design.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurrentLoopOut {
    /// Tuning method.
    pub method: Method,
    /// Requested closed-loop bandwidth α [rad/s].
    pub bandwidth_rad_s: f64,
    /// ζ (pole placement).
    pub damping: Option<f64>,
    /// ω_n from (5.15) (pole placement).
    pub natural_frequency_rad_s: Option<f64>,
    /// Guideline ceiling for α [rad/s]: 30 % (1st order) or 17 % (2nd order) of f_s.
    pub bandwidth_limit_rad_s: f64,
    /// Designed 10–90 % rise time [s]: ln 9/α for first-order loops.
    pub rise_time_s: Option<f64>,
    /// 10–90 % rise time [s] of the sampled d- and q-axis loops with the 1.5·T_s delay
    /// (`discrete_loop`), first-order methods.
    pub sampled_rise_time_s: Option<[f64; 2]>,
    /// Each axis designed for a lower α so that the sampled loop rises in ln 9/α.
    pub compensate_delay: bool,
    /// Designed step overshoot (with prefilter for pole placement), fraction.
    pub overshoot: f64,
    /// d-axis gains.
    pub d: AxisGains,
    /// q-axis gains.
    pub q: AxisGains,
    /// The same design with R at the maximum winding temperature (thesis B 2.24), if `[thermal]` is given.
    pub hot: Option<HotVariant>,
    /// Voltage limit of the PI output vector, U_dc/√3 [V] (thesis B 2.50).
    pub voltage_limit_v: f64,
    /// Feed-forward constants.
    pub feedforward: FeedForward,
}

/// Gains designed for the hot winding resistance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HotVariant {
    /// Winding temperature [°C].
    pub temperature_c: f64,
    /// R_s(T) [Ω].
    pub phase_resistance_ohm: f64,
    /// d-axis gains.
    pub d: AxisGains,
    /// q-axis gains.
    pub q: AxisGains,
}

/// The angle-tracking-observer design.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObserverOut {
    /// Error architecture.
    pub error: ObserverError,
    /// ω_n [rad/s].
    pub natural_frequency_rad_s: f64,
    /// ζ.
    pub damping: f64,
    /// K_p = 2ζω_n (4.15).
    pub kp: f64,
    /// K_i = ω_n² (4.15).
    pub ki: f64,
    /// K̃_p as a real number (4.22).
    pub kp_scaled: f64,
    /// K̃_i as a real number (4.22).
    pub ki_scaled: f64,
    /// K̃_p stored integer, Q1.31.
    pub kp_q31: i32,
    /// K̃_i stored integer, Q1.31.
    pub ki_q31: i32,
    /// Relative rounding error of K̃_i.
    pub ki_quantisation_error: f64,
    /// n_p (motor).
    pub motor_pole_pairs: u32,
    /// n_r (resolver).
    pub resolver_pole_pairs: u32,
    /// n_p/n_r of (4.5).
    pub electrical_per_resolver: f64,
    /// θ_off [rad] of (4.5), if known.
    pub resolver_offset_rad: Option<f64>,
    /// θ_off as a Q1.31 stored integer (angle/π), if known.
    pub resolver_offset_q31: Option<i32>,
    /// Delay k in samples compensated by the angle lead (4.23).
    pub lead_samples: f64,
    /// k in Q16.16: θ_e,lead^i = θ_e^i + (ω_e^i·LEAD) >> 16, ω_e^i the per-sample electrical angle step (4.19), (4.23).
    pub lead_q16: i32,
    /// Lag k·ω_e,max·T_s at maximum speed [deg] (4.23).
    pub lead_at_max_speed_deg: f64,
    /// The error form as the generated `observer::ERROR_FORM`: 0 = trig identity (4.8),
    /// 1 = atan2 (CORDIC phase, normalised by π).
    pub error_form: u8,
}

/// Fixed-point scalings of every quantity the firmware represents.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScalingsOut {
    /// Headroom factor applied to the ratings.
    pub margin: f64,
    /// Phase current.
    pub phase_current: Scaling,
    /// Phase voltage.
    pub phase_voltage: Scaling,
    /// DC-link voltage.
    pub dc_link_voltage: Scaling,
    /// Angle (fixed by the CORDIC interface, A = π).
    pub angle: Scaling,
    /// Observer speed, A = f_s·π (4.20).
    pub speed: Scaling,
    /// Observer error, A = 1 (4.20).
    pub observer_error: Scaling,
}

/// The ADC settling rule.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AdcOut {
    /// N bits.
    pub resolution_bits: u32,
    /// −ln(2^−N) (7.4).
    pub settling_time_constants: f64,
    /// ⌈N·ln 2⌉ time constants used.
    pub settling_multiple: u32,
    /// The chosen sampling time, if `[adc]` is given.
    pub sample_time: Option<adc::SampleTime>,
}

/// Per-unit values of the motor (thesis B App. A).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PerUnitOut {
    /// Bases.
    pub bases: per_unit::Bases,
    /// Motor parameters in pu, by name.
    pub values: BTreeMap<&'static str, f64>,
}

/// Every constant of one motor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Design {
    /// Spec file as given.
    pub spec_file: String,
    /// Motor name.
    pub name: String,
    /// Motor values.
    pub motor: MotorOut,
    /// Drive values.
    pub drive: DriveOut,
    /// Current loop.
    pub current_loop: CurrentLoopOut,
    /// Angle tracking observer.
    pub angle_observer: ObserverOut,
    /// Fixed-point scalings.
    pub scaling: ScalingsOut,
    /// Thesis-B per-unit system, if rated current and frequency are known.
    pub per_unit: Option<PerUnitOut>,
    /// FIR low-pass for identification.
    pub fir: fir::FirDesign,
    /// Modulator.
    pub modulation: modulation::Modulation,
    /// ADC.
    pub adc: AdcOut,
    /// Field weakening and MTPA / loss-minimising tables (thesis B §2.3, ch. 3), if ψ_M is known.
    pub field_weakening: Option<field_weakening::FieldWeakeningOut>,
    /// Sensorless estimator (thesis B chapter 4), when ψ_M is known.
    pub sensorless: Option<sensorless::SensorlessOut>,
    /// The inverter board's values with this motor (`crate::design_with_board`); `None`
    /// for a motor designed on its own.
    pub board: Option<crate::board::design::BoardOut>,
    /// Non-fatal observations.
    pub warnings: Vec<String>,
}

fn loop_error(src: &Source<'_>, spec: &Spec, e: CurrentLoopError) -> Diagnostic {
    let b = &spec.current_loop.bandwidth;
    match e {
        CurrentLoopError::RhpZero { axis, min_bandwidth_rad_s } => src.error(
            b.span.clone(),
            &b.key,
            format!("pole placement at α = {:.4} rad/s puts a right-half-plane zero in the {axis}-axis loop (ω_n·ζ < R/(2L), thesis A §5.4.1)", b.value),
            format!("a bandwidth above {:.1} rad/s, a larger damping, or method = \"imc\"", min_bandwidth_rad_s),
        ),
        CurrentLoopError::NegativeActiveDamping { axis, min_bandwidth_rad_s } => src.error(
            b.span.clone(),
            &b.key,
            format!("α_c·L < R on the {axis} axis: the active damping R_a = α_c·L − R (thesis B 2.43) would be negative"),
            format!("a bandwidth above R/L = {:.1} rad/s, or method = \"imc\"", min_bandwidth_rad_s),
        ),
    }
}

fn axes(spec: &Spec, r: f64, ts: f64) -> Result<(AxisGains, AxisGains), CurrentLoopError> {
    let c = &spec.current_loop;
    let zeta = c.damping.as_ref().map_or(0.0, |d| d.value);
    let axis = |name: char, l: f64| {
        if c.compensate_delay {
            discrete_loop::delay_compensated(c.method, name, r, l, c.bandwidth.value, ts).map(|(g, _)| g)
        } else {
            current_loop::design_axis(c.method, name, r, l, c.bandwidth.value, zeta, ts)
        }
    };
    Ok((
        axis('d', spec.motor.d_inductance.value)?,
        axis('q', spec.motor.q_inductance.value)?,
    ))
}

/// The field-weakening rules (thesis B §2.3) when ψ_M is known; α_fw ≪ α_c is enforced
/// at the key that set α_fw.
/// The sensorless estimator rules (thesis B chapter 4) for a motor with known ψ_M; a ρ
/// above α_c/10 (Table 4.1) is an error at the `[sensorless]` key that set it.
fn sensorless_design(
    spec: &Spec,
    src: &Source<'_>,
    per_unit: Option<&PerUnitOut>,
    speed_max: f64,
) -> Result<Option<(sensorless::SensorlessOut, Vec<String>)>, Box<Diagnostic>> {
    let m = &spec.motor;
    let Some(psi) = m.flux_linkage.as_ref().map(|p| p.value) else {
        return Ok(None);
    };
    let s = &spec.sensorless;
    let i_max = std::f64::consts::SQRT_2 * m.peak_current.value;
    let value = |p: &Option<crate::spec::Param>| p.as_ref().map(|p| p.value);
    let inp = sensorless::Inputs {
        resistance: m.phase_resistance.value,
        ld: m.d_inductance.value,
        lq: m.q_inductance.value,
        psi,
        current_max: i_max,
        current_base: per_unit.map_or(i_max, |p| p.bases.current_a),
        speed_max,
        current_bandwidth: spec.current_loop.bandwidth.value,
        switching: 2.0 * PI * spec.drive.switching_frequency.value,
        voltage_max: spec.drive.dc_link_voltage.value / 3f64.sqrt(),
        speed_base: per_unit.map(|p| p.bases.angular_frequency_rad_s),
        pole_pairs: f64::from(m.pole_pairs),
        choices: sensorless::Choices {
            bandwidth: value(&s.bandwidth),
            max_acceleration: value(&s.max_acceleration),
            angle_error: crate::spec::angle_error_rad(s).0,
            injection_frequency: value(&s.injection_frequency),
            injection_voltage: value(&s.injection_voltage),
            highpass: value(&s.highpass),
            lowpass: value(&s.lowpass),
            resistance_error: value(&s.resistance_error).unwrap_or(crate::spec::DEFAULT_RESISTANCE_ERROR),
            speed_noise: value(&s.speed_noise),
        },
    };
    let (out, notes) = sensorless::design(&inp);
    if out.rho_rad_s > out.rho_max_rad_s * (1.0 + 1e-9)
        && let Some(p) = s.bandwidth.as_ref().or(s.max_acceleration.as_ref())
    {
        let accepted = if s.bandwidth.is_some() {
            format!(
                "a bandwidth up to α_c/10 = {:.1} rad/s, or a faster current loop",
                out.rho_max_rad_s
            )
        } else {
            format!(
                "a shaft acceleration up to (α_c/10)²·sin θ̃max/n_p = {:.1} rad/s² ({:.0} rpm/s), a larger sensorless.max_angle_error, or a faster current loop",
                out.rho_max_rad_s.powi(2) * out.angle_error_rad.sin() / inp.pole_pairs,
                out.rho_max_rad_s.powi(2) * out.angle_error_rad.sin() / inp.pole_pairs * 30.0 / PI
            )
        };
        return Err(Box::new(src.error(
            p.span.clone(),
            &p.key,
            format!(
                "the estimator bandwidth ρ = {:.1} rad/s{} exceeds α_c/10 = {:.1} rad/s (thesis B Table 4.1): the current loop would not follow the estimated frame",
                out.rho_rad_s,
                if s.bandwidth.is_some() { "" } else { " = √(n_p·|ω̇_m|max/sin θ̃max) (thesis B (4.74))" },
                out.rho_max_rad_s
            ),
            accepted,
        )));
    }
    Ok(Some((out, notes)))
}

fn field_weakening_design(
    spec: &Spec,
    src: &Source<'_>,
    errors: &mut Vec<Diagnostic>,
) -> Option<field_weakening::FieldWeakeningOut> {
    let m = &spec.motor;
    let psi = m.flux_linkage.as_ref().map(|p| p.value).filter(|p| *p > 0.0)?;
    let f = &spec.field_weakening;
    let fs = spec.drive.switching_frequency.value;
    let mech = match (&m.inertia, &m.viscous_friction) {
        (Some(j), Some(b)) => Some((b.value / j.value, j)),
        _ => None,
    };
    let inp = field_weakening::Inputs {
        model: loss_minimisation::LossModel {
            pole_pairs: m.pole_pairs,
            rs: m.phase_resistance.value,
            ld: m.d_inductance.value,
            lq: m.q_inductance.value,
            psi,
            rc: f.core_resistance.as_ref().map(|p| p.value),
            inverter: spec
                .inverter
                .as_ref()
                .filter(|_| f.include_inverter)
                .map(|i| field_weakening::inverter_loss(i, fs)),
            i_max: SQRT_2 * m.peak_current.value,
        },
        voltage_max: spec.drive.dc_link_voltage.value / 3f64.sqrt(),
        voltage_fraction: f.voltage_fraction.value,
        current_bandwidth: spec.current_loop.bandwidth.value,
        rated_speed: m.rated_frequency.as_ref().map(|f| 2.0 * PI * f.value),
        speed_loop_bandwidth: f.speed_loop_bandwidth.as_ref().map(|p| p.value),
        mechanical_bandwidth: mech.map(|(bj, _)| bj),
        max_speed: 2.0 * PI * sampling::max_electrical_frequency(m.pole_pairs, m.max_speed.value),
    };
    let (alpha_fw, rule, _) = field_weakening::bandwidth(&inp);
    let ceiling = field_weakening::MAX_BANDWIDTH_FRACTION * inp.current_bandwidth;
    if alpha_fw > ceiling {
        let (span, key, what, fix) = match (rule, &f.speed_loop_bandwidth, mech) {
            (field_weakening::BandwidthRule::SpeedLoop, Some(p), _) => (
                p.span.clone(),
                p.key.clone(),
                format!("α_fw = 10·α_s = {alpha_fw:.1} rad/s"),
                format!("a speed-loop bandwidth of at most {:.2} rad/s", ceiling / 10.0),
            ),
            (_, _, Some((bj, j))) => (
                j.span.clone(),
                j.key.clone(),
                format!("α_fw = 10·b/J = 10·{bj:.3} s⁻¹ = {alpha_fw:.1} rad/s"),
                format!(
                    "an inertia and friction with b/J ≤ {:.3} s⁻¹, or a faster current loop",
                    ceiling / 10.0
                ),
            ),
            _ => (
                spec.current_loop.bandwidth.span.clone(),
                spec.current_loop.bandwidth.key.clone(),
                format!("α_fw = {alpha_fw:.1} rad/s"),
                "a faster current loop".to_string(),
            ),
        };
        errors.push(src.error(
            span,
            key,
            format!(
                "{what} is not ≪ α_c = {:.1} rad/s: the field-weakening pole at −α_fw (2.61) needs α_fw ≤ α_c/5 (thesis B §2.3.3)",
                inp.current_bandwidth
            ),
            fix,
        ));
        return None;
    }
    Some(field_weakening::design(&inp))
}

/// Computes the design, or every rule it breaks, each at its key.
pub fn design(spec: &Spec, src: Source<'_>) -> Result<Design, Diagnostics> {
    let mut errors = Vec::new();
    let mut warnings = Vec::new();
    let m = &spec.motor;
    let fs = spec.drive.switching_frequency.value;
    let ts = 1.0 / fs;
    let np = m.pole_pairs;

    // (1.1) f_s ≥ 12·f_e,max.
    let fe_max = sampling::max_electrical_frequency(np, m.max_speed.value);
    let fs_min = sampling::min_switching_frequency(fe_max);
    if fs < fs_min {
        let p = &spec.drive.switching_frequency;
        errors.push(src.error(
            p.span.clone(),
            &p.key,
            format!("f_s = {fs} Hz is below 12·f_e,max = {fs_min:.0} Hz (thesis A 1.1) for f_e,max = {fe_max:.1} Hz"),
            format!(
                "a switching frequency of at least {:.0} Hz, or a lower motor.max_speed",
                fs_min.ceil()
            ),
        ));
    }

    // Current loop.
    let c = &spec.current_loop;
    let limit = current_loop::bandwidth_limit(c.method, fs);
    if c.bandwidth.value >= limit {
        let pct = if c.method == Method::PolePlacement { 17 } else { 30 };
        errors.push(src.error(
            c.bandwidth.span.clone(),
            &c.bandwidth.key,
            format!(
                "bandwidth α = {:.1} rad/s ({:.0} Hz) is not below {pct} % of f_s = {fs} Hz (thesis A §5.4.1)",
                c.bandwidth.value,
                c.bandwidth.value / (2.0 * PI)
            ),
            format!("a bandwidth below {:.0} rad/s", limit),
        ));
    }
    let r = m.phase_resistance.value;
    let gains = axes(spec, r, ts)
        .map_err(|e| errors.push(loop_error(&src, spec, e)))
        .ok();
    let sampled_rise = gains.as_ref().and_then(|(gd, gq)| {
        if c.method == Method::PolePlacement {
            return None;
        }
        let rise = |g: &AxisGains, l: f64| discrete_loop::predicted_rise_time(g, r, l, ts, g.bandwidth_rad_s);
        Some([rise(gd, m.d_inductance.value)?, rise(gq, m.q_inductance.value)?])
    });
    if let Some(t) = sampled_rise {
        let want = 9f64.ln() / c.bandwidth.value;
        let worst = t[0].min(t[1]);
        if (worst / want - 1.0).abs() > 0.10 {
            warnings.push(format!(
                "current loop: sampled at f_s = {fs} Hz with the 1.5·T_s delay the step rises in {:.3} ms, not ln 9/α = {:.3} ms; {}",
                worst * 1e3,
                want * 1e3,
                if worst < want {
                    "set current_loop.compensate_delay = true or raise f_s"
                } else {
                    "raise f_s or lower the bandwidth"
                }
            ));
        }
    }
    let hot = spec.thermal.as_ref().and_then(|t| {
        let r_hot = thermal::resistance_at(r, t.reference_temperature.value, t.max_winding_temperature.value);
        match axes(spec, r_hot, ts) {
            Ok((d, q)) => Some(HotVariant {
                temperature_c: t.max_winding_temperature.value,
                phase_resistance_ohm: r_hot,
                d,
                q,
            }),
            Err(_) => {
                warnings.push(format!(
                    "no hot-resistance variant: the design is infeasible with R_s({} °C) = {r_hot:.4} Ω",
                    t.max_winding_temperature.value
                ));
                None
            }
        }
    });

    // Angle observer.
    let o = &spec.angle_observer;
    let obs = angle_observer::design(o.natural_frequency.value, o.damping.value, fs, o.error)
        .map_err(|e| {
            let (gain, scaled, what) = match e {
                angle_observer::ObserverGainError::Overflow { gain, scaled } => {
                    (gain, scaled, "does not fit Q1.31 (|K̃| must be < 1)")
                }
                angle_observer::ObserverGainError::Underflow { gain, scaled } => {
                    (gain, scaled, "rounds to zero in Q1.31")
                }
            };
            errors.push(src.error(
                o.natural_frequency.span.clone(),
                &o.natural_frequency.key,
                format!("observer gain K̃_{} = {scaled:.3e} (4.22) {what}", &gain[1..]),
                "a natural frequency that keeps K̃_p = 2ζω_n/(f_s·π) below 1 and K̃_i = ω_n²/(f_s²·π) above 2^−32",
            ))
        })
        .ok();
    let nr = spec.resolver.pole_pairs;
    let ratio = f64::from(np) / f64::from(nr);
    // Observer speed full scale f_s·π rad/s of resolver angle (4.20) must hold the top speed.
    let wr_max = f64::from(nr) * m.max_speed.value;
    if wr_max >= fs * PI {
        errors.push(src.error(
            m.max_speed.span.clone(),
            &m.max_speed.key,
            format!("resolver speed n_r·ω_m,max = {wr_max:.0} rad/s exceeds the observer speed full scale f_s·π = {:.0} rad/s (4.20)", fs * PI),
            "a maximum speed below f_s·π/n_r",
        ));
    }

    // FIR.
    let f = &spec.fir;
    let request = fir::FirRequest {
        sample_rate_hz: fs,
        pass_edge_hz: f.pass_edge.value,
        stop_edge_hz: f.stop_edge.value,
        pass_ripple: f.pass_ripple.value,
        length: match (&f.order, &f.stop_attenuation) {
            (Some((n, _)), _) => fir::FirLength::Order(*n),
            (None, Some(a)) => fir::FirLength::StopAttenuationDb(a.value),
            (None, None) => fir::FirLength::Order(0),
        },
    };
    let fir_design = fir::design_fir(&request)
        .map_err(|e| {
            let (span, key) = match e.key() {
                "pass_edge" => (f.pass_edge.span.clone(), f.pass_edge.key.clone()),
                "stop_edge" | "sample_rate" => (f.stop_edge.span.clone(), f.stop_edge.key.clone()),
                "pass_ripple" => (f.pass_ripple.span.clone(), f.pass_ripple.key.clone()),
                "stop_attenuation" => f
                    .stop_attenuation
                    .as_ref()
                    .map_or((f.span.clone(), "fir.stop_attenuation".into()), |a| {
                        (a.span.clone(), a.key.clone())
                    }),
                _ => f.order.as_ref().map_or((f.span.clone(), "fir.order".into()), |(_, p)| {
                    (p.span.clone(), p.key.clone())
                }),
            };
            let text = e.to_string();
            let (problem, accepted) = text
                .split_once("; accepted: ")
                .map_or((text.clone(), "see the message".to_string()), |(a, b)| {
                    (a.to_string(), b.to_string())
                });
            errors.push(src.error(span, key, problem, accepted));
        })
        .ok();

    // ADC.
    let (bits, sample_time) = match &spec.adc {
        Some(a) => {
            let st = adc::choose_sample_time(
                a.resolution_bits,
                a.clock.value,
                a.sample_capacitance.value,
                a.switch_resistance.value,
                a.source_resistance.value,
            );
            if st.is_none() {
                errors.push(src.error(
                    a.source_resistance.span.clone(),
                    &a.source_resistance.key,
                    format!(
                        "even 640.5 ADC cycles at {} Hz cannot settle the sample-and-hold to 1 LSB (7.4)",
                        a.clock.value
                    ),
                    "a lower source resistance or a slower ADC clock",
                ));
            }
            (a.resolution_bits, st)
        }
        None => (12, None),
    };

    let fw = field_weakening_design(spec, &src, &mut errors);

    if !errors.is_empty() {
        return Err(Diagnostics(errors));
    }
    let (Some((d, q)), Some(obs), Some(fir_design)) = (gains, obs, fir_design) else {
        return Err(Diagnostics(errors));
    };

    if let Some(check) = &m.flux_cross_check
        && check.disagreement_percent > 10.0
    {
        warnings.push(format!(
            "ψ_M from K_t ({:.4} Wb) and from K_e ({:.4} Wb) disagree by {:.1} %",
            check.from_torque_constant_wb, check.from_back_emf_constant_wb, check.disagreement_percent
        ));
    }
    if m.flux_linkage.is_none() {
        warnings.push("ψ_M is unknown: the back-EMF feed-forward term and torque → i_q conversion are omitted".into());
    }

    let psi = m.flux_linkage.as_ref().map(|p| p.value);
    let kt = psi.map(|p| 1.5 * f64::from(np) * p);
    let udc = spec.drive.dc_link_voltage.value;
    let margin = spec.scaling_margin.value;
    let i_peak = SQRT_2 * m.peak_current.value;

    let mut provenance = BTreeMap::new();
    provenance.insert("phase_resistance", Origin::from(&m.phase_resistance));
    provenance.insert("d_inductance", Origin::from(&m.d_inductance));
    provenance.insert("q_inductance", Origin::from(&m.q_inductance));
    provenance.insert("peak_current", Origin::from(&m.peak_current));
    provenance.insert("max_speed", Origin::from(&m.max_speed));
    if let Some(p) = &m.flux_linkage {
        provenance.insert("flux_linkage", Origin::from(p));
    }
    if let Some(p) = &spec.resolver.offset {
        provenance.insert("resolver_offset", Origin::from(p));
    }
    if let Some(note) = &m.identification {
        for o in provenance.values_mut().filter(|o| o.source == Provenance::Identified) {
            o.note = Some(note.clone());
        }
    }

    let per_unit = match (&m.nominal_current, &m.rated_frequency) {
        (Some(i_n), Some(f_n)) => {
            let b = per_unit::bases(
                udc,
                i_n.value,
                f_n.value,
                m.rated_power.as_ref().map(|p| p.value),
                m.nominal_torque.as_ref().map(|p| p.value),
            );
            let mut values = BTreeMap::new();
            values.insert("phase_resistance", r / b.impedance_ohm);
            values.insert("d_inductance", m.d_inductance.value / b.inductance_h);
            values.insert("q_inductance", m.q_inductance.value / b.inductance_h);
            if let Some(p) = psi {
                values.insert("flux_linkage", p / b.flux_wb);
            }
            for (name, h) in [
                ("d_flux_6", &m.harmonics.d_flux_6),
                ("d_flux_12", &m.harmonics.d_flux_12),
                ("q_flux_6", &m.harmonics.q_flux_6),
                ("q_flux_12", &m.harmonics.q_flux_12),
            ] {
                if let Some(h) = h {
                    values.insert(name, h.value / b.flux_wb);
                }
            }
            if let Some(&(_, l_last)) = m.q_saturation.last() {
                values.insert("q_inductance_saturated", l_last / b.inductance_h);
            }
            values.insert("current_loop_bandwidth", c.bandwidth.value / b.angular_frequency_rad_s);
            Some(PerUnitOut { bases: b, values })
        }
        _ => None,
    };

    let sensorless = match sensorless_design(spec, &src, per_unit.as_ref(), 2.0 * PI * fe_max) {
        Ok(Some((out, notes))) => {
            warnings.extend(notes);
            Some(out)
        }
        Ok(None) => None,
        Err(e) => return Err(Diagnostics(vec![*e])),
    };

    let offset = spec.resolver.offset.as_ref().map(|p| p.value);
    let lead = o.lead_samples.value;
    let design = Design {
        spec_file: src.file.to_string(),
        name: spec.name.clone(),
        motor: MotorOut {
            pole_pairs: np,
            phase_resistance_ohm: r,
            phase_resistance_hot_ohm: hot.as_ref().map(|h| h.phase_resistance_ohm),
            d_inductance_h: m.d_inductance.value,
            q_inductance_h: m.q_inductance.value,
            flux_linkage_wb: psi,
            flux_cross_check: m.flux_cross_check.clone(),
            d_time_constant_s: m.d_inductance.value / r,
            q_time_constant_s: m.q_inductance.value / r,
            peak_current_a_rms: m.peak_current.value,
            nominal_current_a_rms: m.nominal_current.as_ref().map(|p| p.value),
            max_speed_rad_s: m.max_speed.value,
            max_speed_rpm: m.max_speed.value * 30.0 / PI,
            max_electrical_frequency_hz: fe_max,
            max_electrical_speed_rad_s: 2.0 * PI * fe_max,
            peak_current_a: i_peak,
            provenance,
        },
        drive: DriveOut {
            switching_frequency_hz: fs,
            sample_period_s: ts,
            min_switching_frequency_hz: fs_min,
            dc_link_voltage_v: udc,
            dc_link_voltage_min_v: spec.drive.dc_link_voltage_min.value,
            dead_time_s: spec.drive.dead_time.as_ref().map(|p| p.value),
        },
        current_loop: CurrentLoopOut {
            method: c.method,
            bandwidth_rad_s: c.bandwidth.value,
            damping: c.damping.as_ref().map(|p| p.value),
            natural_frequency_rad_s: c
                .damping
                .as_ref()
                .map(|z| current_loop::natural_frequency(c.bandwidth.value, z.value)),
            bandwidth_limit_rad_s: limit,
            rise_time_s: (c.method != Method::PolePlacement).then(|| 9f64.ln() / c.bandwidth.value),
            sampled_rise_time_s: sampled_rise,
            compensate_delay: c.compensate_delay,
            overshoot: c.damping.as_ref().map_or(0.0, |z| current_loop::overshoot(z.value)),
            d,
            q,
            hot,
            voltage_limit_v: udc / 3f64.sqrt(),
            feedforward: FeedForward {
                d_inductance_h: m.d_inductance.value,
                q_inductance_h: m.q_inductance.value,
                flux_linkage_wb: psi,
                torque_constant_nm_per_a: kt,
                iq_per_nm: kt.map(|k| 1.0 / k),
            },
        },
        angle_observer: ObserverOut {
            error: o.error,
            natural_frequency_rad_s: o.natural_frequency.value,
            damping: o.damping.value,
            kp: obs.kp,
            ki: obs.ki,
            kp_scaled: obs.kp_scaled,
            ki_scaled: obs.ki_scaled,
            kp_q31: obs.kp_q31,
            ki_q31: obs.ki_q31,
            ki_quantisation_error: obs.ki_quantisation_error,
            motor_pole_pairs: np,
            resolver_pole_pairs: nr,
            electrical_per_resolver: ratio,
            resolver_offset_rad: offset,
            resolver_offset_q31: offset.map(|a| {
                let wrapped = (a / PI + 1.0).rem_euclid(2.0) - 1.0; // [−1, 1)
                ((wrapped * angle_observer::Q31_ONE).round() as i64).clamp(i64::from(i32::MIN), i64::from(i32::MAX))
                    as i32
            }),
            lead_samples: lead,
            lead_q16: (lead * 65_536.0).round() as i32,
            lead_at_max_speed_deg: angle_observer::lag_angle(lead, 2.0 * PI * fe_max, fs).to_degrees(),
            error_form: match o.error {
                ObserverError::TrigIdentity => 0,
                ObserverError::Atan2 => 1,
            },
        },
        scaling: ScalingsOut {
            margin,
            phase_current: scaling::scaling(
                margin * i_peak,
                "A",
                QFormat::Q15,
                format!("margin·√2·I_peak,rms = {margin}·√2·{} A", m.peak_current.value),
            ),
            phase_voltage: scaling::scaling(
                margin * udc / 3f64.sqrt(),
                "V",
                QFormat::Q15,
                format!("margin·U_dc/√3 = {margin}·{udc} V/√3 (THPWM phase amplitude limit)"),
            ),
            dc_link_voltage: scaling::scaling(
                margin * udc,
                "V",
                QFormat::Q15,
                format!("margin·U_dc = {margin}·{udc} V"),
            ),
            angle: scaling::scaling(
                PI,
                "rad",
                QFormat::Q31,
                "A = π, dictated by the CORDIC interface (4.20)",
            ),
            speed: scaling::scaling(
                fs * PI,
                "rad/s",
                QFormat::Q31,
                "A = f_s·π so that θ^i(n) = θ^i(n−1) + ω^i(n−1) (4.19), (4.20)",
            ),
            observer_error: scaling::scaling(1.0, "1", QFormat::Q31, "A = 1 (4.20); atan2 error normalised by π"),
        },
        per_unit,
        fir: fir_design,
        modulation: modulation::modulation(udc, spec.drive.dc_link_voltage_min.value),
        adc: AdcOut {
            resolution_bits: bits,
            settling_time_constants: adc::settling_time_constants(bits),
            settling_multiple: adc::settling_multiple(bits),
            sample_time,
        },
        field_weakening: fw,
        sensorless,
        board: None,
        warnings,
    };
    Ok(design)
}
