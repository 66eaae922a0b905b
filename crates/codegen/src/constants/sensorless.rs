//! The `sensorless` group: thesis B chapter 4's estimator constants (Table 4.1) — the
//! bandwidth ρ and the PLL gains γ1, γ2 (thesis B (4.7), (4.74)), the signal injection's
//! frequency, voltage, gain and filters (thesis B (4.19), (4.34), (4.35), §4.3), the
//! transition speeds (thesis B (4.59), (4.69)), the resetting term's band and current
//! limit (thesis B (4.83), (4.92), §4.6), the bifurcation limit (thesis B (4.66)) and R̂_s
//! of the back-EMF error (thesis B (4.51)).
//!
//! With ψ_M (or I_base) unknown the rules cannot be evaluated and every entry is 0
//! (sensorless operation off), as for the field-weakening group; without injection (no
//! saliency, or too little for the carrier rule) the injection entries are 0, with the
//! reason the design gives. Their JSON pointers then point at the null.

use super::Source::F32;
use super::Text::{Lit, Of};
use super::{Decl, Group, Json, declare, phys};
use crate::design::Design;
use crate::design::sensorless::{InjectionOut, RhoRule, SensorlessOut};

/// What the entries read.
struct Estimator<'a> {
    d: &'a Design,
    s: Option<&'a SensorlessOut>,
    inj: Option<&'a InjectionOut>,
    /// Why the estimator is off, when it is.
    off: &'static str,
    /// How ρ was chosen (or why the estimator is off).
    rho: String,
    /// L_d, L_q, ψ_M.
    motor: String,
}

impl<'a> Estimator<'a> {
    /// The entries.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "RHO",
            value: F32(|c| c.get(|s| s.rho_rad_s), "rad/s"),
            formula: Lit("ρ: estimator bandwidth, ρ ≤ α_c/10"),
            equation: Lit("thesis B (4.74), Table 4.1"),
            inputs: Of(|c| c.rho.clone()),
            json: Json::Of(|c| c.json("rho_rad_s")),
        },
        Decl {
            name: "GAMMA1",
            value: F32(|c| c.get(|s| s.gamma1), "1/s²"),
            formula: Lit("γ1 = ρ²"),
            equation: Lit("thesis B (4.7)"),
            inputs: Of(|c| c.rho.clone()),
            json: Json::Of(|c| c.json("gamma1")),
        },
        Decl {
            name: "GAMMA2",
            value: F32(|c| c.get(|s| s.gamma2), "1/s"),
            formula: Lit("γ2 = 2ρ"),
            equation: Lit("thesis B (4.7)"),
            inputs: Of(|c| c.rho.clone()),
            json: Json::Of(|c| c.json("gamma2")),
        },
        Decl {
            name: "INJECTION_FREQUENCY",
            value: F32(|c| c.injected(|i| i.frequency_rad_s), "rad/s"),
            formula: Lit("ω_e, 5α_c ≤ ω_e ≤ ω_sw/10 (spec sensorless.injection_frequency, default ω_sw/10)"),
            equation: Lit("thesis B (4.34)"),
            inputs: Of(|c| {
                c.injection(|_, i| {
                    format!(
                        "5α_c = {}, ω_sw/10 = {}",
                        phys(i.frequency_min_rad_s, "rad/s"),
                        phys(i.frequency_max_rad_s, "rad/s")
                    )
                })
            }),
            json: Json::Of(|c| c.json("injection/frequency_rad_s")),
        },
        Decl {
            name: "INJECTION_VOLTAGE",
            value: F32(|c| c.injected(|i| i.voltage_v), "V"),
            formula: Lit("V_e ≥ I_base·ω_e·L_d·L_q/(10·|ΔL|) (spec sensorless.injection_voltage, default the minimum)"),
            equation: Lit("thesis B (4.35)"),
            inputs: Of(|c| c.injection(|c, i| format!("{}, minimum {}", c.motor, phys(i.voltage_min_v, "V")))),
            json: Json::Of(|c| c.json("injection/voltage_v")),
        },
        Decl {
            name: "INJECTION_GAIN",
            value: F32(|c| c.injected(|i| i.gain_ke_a), "A"),
            formula: Lit(
                "K_e = V_e·ΔL/(4·ω_e·L_d·L_q), ΔL = L_q − L_d signed (negative for inverse saliency; e = e_si/(2K̂_e) (4.20) either way)",
            ),
            equation: Lit("thesis B (4.19)"),
            inputs: Of(|c| c.injection(|c, _| c.motor.clone())),
            json: Json::Of(|c| c.json("injection/gain_ke_a")),
        },
        Decl {
            name: "HIGHPASS",
            value: F32(|c| c.injected(|i| i.highpass_rad_s), "rad/s"),
            formula: Lit("ω_hp: a few hertz (default 0.015 pu, §4.5.1; 2π·3 Hz without a per-unit base)"),
            equation: Lit("thesis B §4.3, Table 4.1"),
            inputs: Of(|c| c.injection(|_, _| "spec sensorless.highpass or the default".into())),
            json: Json::Of(|c| c.json("injection/highpass_rad_s")),
        },
        Decl {
            name: "LOWPASS",
            value: F32(|c| c.injected(|i| i.lowpass_rad_s), "rad/s"),
            formula: Lit("ω_lp, 5ρ ≤ ω_lp ≤ 10ρ (default 5ρ)"),
            equation: Lit("thesis B Table 4.1"),
            inputs: Of(|c| c.injection(|c, _| c.rho.clone())),
            json: Json::Of(|c| c.json("injection/lowpass_rad_s")),
        },
        Decl {
            name: "LOW_SPEED",
            value: F32(|c| c.get(|s| s.omega_ls_rad_s), "rad/s"),
            formula: Lit(
                "ω_ls = max(ω_min1, ω_min2), ω_min1 = 5ρ·|ΔL|·I_max/(3ψ_m), ω_min2 = |R̃·i_d/(θ̃·(ψ_m − ΔL·i_d))| at the MTPA i_d (3.10) of I_base",
            ),
            equation: Lit("thesis B (4.59), (4.69), Table 4.1"),
            inputs: Of(|c| match c.s {
                None => c.off.into(),
                Some(s) => format!(
                    "ω_min1 = {}, ω_min2 = {} (θ̃ = {:.1}°, i_d = {}), I_max = {}, I_base = {}",
                    phys(s.omega_min1_rad_s, "rad/s"),
                    phys(s.omega_min2_rad_s, "rad/s"),
                    s.angle_error_rad.to_degrees(),
                    phys(s.id_at_base_current_a, "A"),
                    phys(c.d.motor.peak_current_a, "A"),
                    phys(c.d.per_unit.bases.current_a.unwrap_or(0.0), "A")
                ),
            }),
            json: Json::Of(|c| c.json("omega_ls_rad_s")),
        },
        Decl {
            name: "HIGH_SPEED",
            value: F32(|c| c.get(|s| s.omega_hs_rad_s), "rad/s"),
            formula: Lit("ω_hs = 2·ω_ls"),
            equation: Lit("thesis B Table 4.1"),
            inputs: Of(|c| c.rho.clone()),
            json: Json::Of(|c| c.json("omega_hs_rad_s")),
        },
        Decl {
            name: "RESET_LOWER",
            value: F32(|c| c.get(|s| s.resetting_lower_rad_s), "rad/s"),
            formula: Lit("Δω1 = ρ: γ0 = 0 below"),
            equation: Lit("thesis B (4.83), §4.6"),
            inputs: Of(|c| c.rho.clone()),
            json: Json::Of(|c| c.json("resetting_lower_rad_s")),
        },
        Decl {
            name: "RESET_UPPER",
            value: F32(|c| c.get(|s| s.resetting_upper_rad_s), "rad/s"),
            formula: Lit("Δω2 = 2ρ: γ0 = ρ above"),
            equation: Lit("thesis B (4.83), §4.6"),
            inputs: Of(|c| c.rho.clone()),
            json: Json::Of(|c| c.json("resetting_upper_rad_s")),
        },
        Decl {
            name: "IQ_LIMIT_RESETTING_A",
            value: F32(|c| c.s.and_then(|s| s.iq_limit_resetting_a).unwrap_or(0.0), "A"),
            formula: Lit(
                "|i_q^ref| < ρ²·ψ_m/(γ0·ω_max·|ΔL|) with γ0 = ρ, while the resetting term acts (0: no limit needed)",
            ),
            equation: Lit("thesis B (4.92)"),
            inputs: Of(|c| {
                format!(
                    "{}, ω_max = {}",
                    c.motor,
                    phys(c.d.motor.max_electrical_speed_rad_s, "rad/s")
                )
            }),
            json: Json::Of(|c| c.json("iq_limit_resetting_a")),
        },
        Decl {
            name: "IQ_LIMIT_BIFURCATION_A",
            value: F32(|c| c.s.and_then(|s| s.iq_limit_bifurcation_a).unwrap_or(0.0), "A"),
            formula: Lit("|i_q| ≤ ψ_m/|ΔL|: no unwanted equilibria of the back-EMF estimator (0: no saliency)"),
            equation: Lit("thesis B (4.66)"),
            inputs: Of(|c| c.motor.clone()),
            json: Json::Of(|c| c.json("iq_limit_bifurcation_a")),
        },
        Decl {
            name: "RS",
            value: F32(|c| c.d.motor.phase_resistance_ohm, "Ω"),
            formula: Lit("R̂_s in the back-EMF error e_d (L̂_d, L̂_q, ψ̂_m: current_loop::FF_LD, FF_LQ, FF_PSI)"),
            equation: Lit("thesis B (4.51)"),
            inputs: Lit("phase resistance (spec)"),
            json: Json::At("/motor/phase_resistance_ohm"),
        },
    ];

    /// An estimator result, 0 when the estimator is off.
    fn get(&self, f: fn(&SensorlessOut) -> f64) -> f64 {
        self.s.map_or(0.0, f)
    }

    /// An injection result, 0 without injection.
    fn injected(&self, f: fn(&InjectionOut) -> f64) -> f64 {
        self.inj.map_or(0.0, f)
    }

    /// The inputs of an injection entry: `detail`, or why there is no injection.
    fn injection(&self, detail: fn(&Self, &InjectionOut) -> String) -> String {
        match (self.s, self.inj) {
            (None, _) => self.off.to_string(),
            (Some(s), None) => format!(
                "no signal injection → 0: {}",
                s.no_injection.as_ref().map_or_else(String::new, ToString::to_string)
            ),
            (Some(_), Some(i)) => detail(self, i),
        }
    }

    /// The JSON pointer of `field` below `/sensorless`, or of the null standing for it
    /// (the estimator off, no injection).
    fn json(&self, field: &str) -> String {
        match (self.s, self.inj) {
            (None, _) => "/sensorless".into(),
            (Some(_), None) if field.starts_with("injection/") => "/sensorless/injection".into(),
            _ => format!("/sensorless/{field}"),
        }
    }
}

/// The group.
pub fn group(d: &Design) -> Group {
    let s = d.sensorless.as_ref();
    let off = if d.motor.flux_linkage_wb.is_none() {
        "ψ_M unknown → 0 (sensorless off)"
    } else if d.per_unit.bases.current_a.is_none() {
        "I_n unknown: no I_base = √2·I_n for (4.24), (4.35), (4.69) → 0 (sensorless off)"
    } else {
        "sensorless off → 0"
    };
    let rho = s.map_or_else(
        || off.to_string(),
        |s| match s.rho_rule {
            RhoRule::Given => "ρ = sensorless.bandwidth (spec)".into(),
            RhoRule::Acceleration => format!(
                "ρ = √(n_p·|ω̇_m|max / sin θ̃max) (spec sensorless.max_acceleration), θ̃max = {:.1}°",
                s.angle_error_rad.to_degrees()
            ),
            RhoRule::CurrentLoopBound => format!(
                "ρ = α_c/10, α_c = {} (Table 4.1 bound, as in Figs. 4.17, 4.18)",
                phys(d.current_loop.bandwidth_rad_s, "rad/s")
            ),
        },
    );
    let m = &d.motor;
    let estimator = Estimator {
        d,
        s,
        inj: s.and_then(|s| s.injection.as_ref()),
        off,
        rho,
        motor: format!(
            "L_d = {}, L_q = {}, ψ_M = {}",
            phys(m.d_inductance_h, "H"),
            phys(m.q_inductance_h, "H"),
            phys(m.flux_linkage_wb.unwrap_or(0.0), "Wb")
        ),
    };
    Group {
        name: "sensorless",
        title: "Sensorless estimator: PLL gains, signal injection, transition, resetting term (thesis B ch. 4)",
        constants: declare(Estimator::DECLS, &estimator, "").collect(),
    }
}
