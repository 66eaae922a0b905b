//! The `scaling` group: for each per-unit signal of the firmware — phase current
//! (`CURRENT_…`), phase voltage (`VOLTAGE_…`), DC-link voltage (`DC_LINK_…`), angle
//! (`ANGLE_…`), observer speed (`SPEED_…`) and observer error (`OBSERVER_ERROR_…`), one
//! table for all — its full scale A and its SI value per LSB (thesis A (4.16), (4.20),
//! Table 4.1).

use super::Source::Custom;
use super::Text::{Lit, Of};
use super::{Decl, Group, Json, declare, f32_in, phys};
use crate::design::Design;
use crate::design::scaling::Scaling;

/// What one signal's entries read.
struct Signal<'a> {
    /// Its key below `/scaling` in the JSON design.
    key: &'static str,
    /// What it is, in words.
    what: &'static str,
    sc: &'a Scaling,
}

impl<'a> Signal<'a> {
    /// The entries of each signal.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "FULL_SCALE",
            value: Custom(|s| f32_in(s.sc.full_scale, s.sc.unit)),
            formula: Of(|s| format!("A of {}: {}", s.what, s.sc.rule)),
            equation: Lit("thesis A (4.16), (4.20), Table 4.1"),
            inputs: Of(|s| format!("{} (spec)", s.sc.q_format)),
            json: Json::Of(|s| format!("/scaling/{}/full_scale", s.key)),
        },
        Decl {
            name: "PER_LSB",
            value: Custom(|s| f32_in(s.sc.si_per_lsb, s.sc.unit)),
            formula: Of(|s| format!("A/2^{} ({})", s.sc.fractional_bits, s.sc.q_format)),
            equation: Lit("thesis A (4.16)"),
            inputs: Of(|s| format!("A = {}", phys(s.sc.full_scale, s.sc.unit))),
            json: Json::Of(|s| format!("/scaling/{}/si_per_lsb", s.key)),
        },
    ];
}

/// The group.
pub fn group(d: &Design) -> Group {
    let s = &d.scaling;
    let signal = |key, what, sc| Signal { key, what, sc };
    let signals = [
        ("CURRENT_", signal("phase_current", "phase current", &s.phase_current)),
        ("VOLTAGE_", signal("phase_voltage", "phase voltage", &s.phase_voltage)),
        (
            "DC_LINK_",
            signal("dc_link_voltage", "DC-link voltage", &s.dc_link_voltage),
        ),
        ("ANGLE_", signal("angle", "angle", &s.angle)),
        ("SPEED_", signal("speed", "observer speed", &s.speed)),
        (
            "OBSERVER_ERROR_",
            signal("observer_error", "observer error", &s.observer_error),
        ),
    ];
    Group {
        name: "scaling",
        title: "Per-unit fixed-point scalings (full scale A and SI per LSB)",
        constants: signals
            .iter()
            .flat_map(|(prefix, s)| declare(Signal::DECLS, s, prefix))
            .collect(),
    }
}
