//! The `filter` group: the identification FIR low-pass the FMAC runs (thesis A §6.2) —
//! its equiripple (Parks–McClellan) taps in Q1.15, its order and its group delay.

use super::Source::{Custom, F32};
use super::Text::{Lit, Of};
use super::{Decl, Group, Json, count, declare, fs_input, i16_array, phys};
use crate::design::Design;

/// What the filter's entries read.
struct Fir<'a> {
    d: &'a Design,
    /// The specification and what the quantised filter achieves.
    inputs: String,
}

impl<'a> Fir<'a> {
    /// The entries.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "TAPS_Q15",
            value: Custom(|c| {
                let taps = &c.d.fir.taps_q15;
                (i16_array(taps), format!("{} taps, Σ = 32768 (DC gain 1)", taps.len()))
            }),
            formula: Lit("equiripple low-pass (Parks–McClellan), Q1.15, symmetric"),
            equation: Lit("thesis A §6.2"),
            inputs: Of(|c| c.inputs.clone()),
            json: Json::At("/fir/taps_q15"),
        },
        Decl {
            name: "ORDER",
            value: Custom(|c| count(c.d.fir.order as i64, "usize", "uint32_t")),
            formula: Lit("N − 1"),
            equation: Lit("thesis A §6.2"),
            inputs: Of(|c| c.inputs.clone()),
            json: Json::At("/fir/order"),
        },
        Decl {
            name: "GROUP_DELAY_SAMPLES",
            value: F32(|c| c.d.fir.group_delay_samples, "samples"),
            formula: Lit("order/2 (linear phase)"),
            equation: Lit("thesis A §6.2"),
            inputs: Of(|c| c.inputs.clone()),
            json: Json::At("/fir/group_delay_samples"),
        },
    ];
}

/// The group.
pub fn group(d: &Design) -> Group {
    let f = &d.fir;
    let fir = Fir {
        d,
        inputs: format!(
            "order {}, pass band 0–{} with ripple ≤ {}, stop band {}–f_s/2, {}; achieved (Q1.15): ripple {:.2e}, attenuation {:.1} dB",
            f.order,
            phys(f.pass_edge_hz, "Hz"),
            f.pass_ripple,
            phys(f.stop_edge_hz, "Hz"),
            fs_input(d),
            f.pass_ripple_quantised,
            f.stop_attenuation_db_quantised
        ),
    };
    Group {
        name: "filter",
        title: "Identification FIR low-pass for the FMAC",
        constants: declare(Fir::DECLS, &fir, "").collect(),
    }
}
