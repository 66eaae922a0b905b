//! The `observer` group: the angle tracking observer's gains K̃_p, K̃_i pre-scaled for
//! Q1.31 (thesis A (4.15), (4.22)) for the error form the spec chose (thesis A
//! (4.8)–(4.10)), the motor and resolver pole pairs and the resolver offset that turn the
//! resolver angle into the electrical angle (thesis A (4.5), (6.9)), and the lead that
//! compensates the sampling delay (thesis A (4.19), (4.23)).

use super::Source::Custom;
use super::Text::{Lit, Of};
use super::{Decl, Group, Json, count, declare, fs_input, intv, phys, prov, q31v};
use crate::design::{Design, ObserverOut};
use crate::spec::{ObserverError, Provenance};

/// What the observer's entries read.
struct Observer<'a> {
    d: &'a Design,
    o: &'a ObserverOut,
    /// The normalisation of the error in the gains' formulas: π·g (g the resolver
    /// signal's fraction of full scale), or 1 for atan2.
    norm: &'static str,
    /// ω_n, ζ and f_s.
    inputs: String,
}

impl<'a> Observer<'a> {
    /// The entries.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "KP",
            value: Custom(|c| (q31v(c.o.gains.kp_q31), phys(c.o.gains.kp_scaled, ""))),
            formula: Of(|c| format!("K̃_p = 2ζω_n/(f_s·{}), Q1.31", c.norm)),
            equation: Lit("thesis A (4.10), (4.15), (4.22)"),
            inputs: Of(|c| c.inputs.clone()),
            json: Json::At("/angle_observer/kp_q31"),
        },
        Decl {
            name: "KI",
            value: Custom(|c| (q31v(c.o.gains.ki_q31), phys(c.o.gains.ki_scaled, ""))),
            formula: Of(|c| format!("K̃_i = ω_n²/(f_s²·{}), Q1.31", c.norm)),
            equation: Lit("thesis A (4.10), (4.15), (4.22)"),
            inputs: Of(|c| c.inputs.clone()),
            json: Json::At("/angle_observer/ki_q31"),
        },
        Decl {
            name: "MOTOR_POLE_PAIRS",
            value: Custom(|c| count(c.o.motor_pole_pairs.into(), "u32", "uint32_t")),
            formula: Lit("n_p"),
            equation: Lit("thesis A (4.5)"),
            inputs: Lit("n_p (datasheet)"),
            json: Json::At("/angle_observer/motor_pole_pairs"),
        },
        Decl {
            name: "RESOLVER_POLE_PAIRS",
            value: Custom(|c| count(c.o.resolver_pole_pairs.into(), "u32", "uint32_t")),
            formula: Lit("n_r"),
            equation: Lit("thesis A (4.5)"),
            inputs: Lit("n_r (spec [resolver])"),
            json: Json::At("/angle_observer/resolver_pole_pairs"),
        },
        Decl {
            name: "LEAD_Q16",
            value: Custom(|c| {
                (
                    intv(c.o.lead_q16.into(), "i32", "int32_t"),
                    phys(c.o.lead_samples, "samples"),
                )
            }),
            formula: Lit("k in Q16.16: θ_e,lead = θ_e + (ω_e^i·LEAD) >> 16"),
            equation: Lit("thesis A (4.19), (4.23)"),
            inputs: Of(|c| match c.o.lead_samples_source {
                Provenance::Default => {
                    format!(
                        "k = {} samples (default: the delay from the resolver's sample to the voltage's mean — the board's timing, 1.5·T_s without a board, thesis A §4.6)",
                        c.o.lead_samples
                    )
                }
                _ => format!("k = {} samples (spec angle_observer.lead_samples)", c.o.lead_samples),
            }),
            json: Json::At("/angle_observer/lead_q16"),
        },
        Decl {
            name: "RESOLVER_OFFSET",
            value: Custom(|c| {
                let rad = c.o.resolver_offset_rad.unwrap_or(0.0);
                (
                    q31v(c.o.resolver_offset_q31.unwrap_or(0)),
                    format!("{} = {}°", phys(rad, "rad"), phys(rad.to_degrees(), "")),
                )
            }),
            formula: Lit("θ_off/π wrapped into ±π, Q1.31 (0 until identified at commissioning, (6.9))"),
            equation: Lit("thesis A (4.5), (6.9)"),
            inputs: Of(|c| match c.o.resolver_offset_rad {
                Some(_) => format!("θ_off ({})", prov(c.d.motor.provenance.get("resolver_offset"))),
                None => "θ_off not in the spec: 0".into(),
            }),
            json: Json::At("/angle_observer/resolver_offset_q31"),
        },
        Decl {
            name: "ERROR_FORM",
            value: Custom(|c| {
                let form = match c.o.error {
                    ObserverError::TrigIdentity => "0: trig identity",
                    ObserverError::Atan2 => "1: atan2",
                };
                (intv(c.o.error_form.into(), "u8", "uint8_t"), form.into())
            }),
            formula: Lit("error architecture KP/KI are scaled for: 0 = sin θ_r cos θ̂ − cos θ_r sin θ̂, 1 = atan2/π"),
            equation: Lit("thesis A (4.8)–(4.10), (4.22)"),
            inputs: Lit("angle_observer.error (spec)"),
            json: Json::At("/angle_observer/error_form"),
        },
    ];
}

/// The group.
pub fn group(d: &Design) -> Group {
    let o = &d.angle_observer;
    let observer = Observer {
        d,
        o,
        norm: match o.error {
            ObserverError::TrigIdentity => "π·g",
            ObserverError::Atan2 => "1 (atan2 error already normalised by π)",
        },
        inputs: match o.error {
            ObserverError::TrigIdentity => format!(
                "ω_n = {} (spec), ζ = {} (spec), {}, g = {} (the resolver signal's fraction of full scale the error scales with, thesis A (4.10): {})",
                phys(o.natural_frequency_rad_s, "rad/s"),
                o.damping,
                fs_input(d),
                phys(o.gains.signal_gain, ""),
                if d.board.is_some() {
                    "the board's sensing.resolver_amplitude over V_REF/2 times the excitation's envelope where SIN and COS are held"
                } else {
                    "no board: signals at full scale"
                }
            ),
            ObserverError::Atan2 => format!(
                "ω_n = {} (spec), ζ = {} (spec), {}",
                phys(o.natural_frequency_rad_s, "rad/s"),
                o.damping,
                fs_input(d)
            ),
        },
    };
    Group {
        name: "observer",
        title: "Angle tracking observer (Q1.31) and resolver → electrical angle",
        constants: declare(Observer::DECLS, &observer, "").collect(),
    }
}
