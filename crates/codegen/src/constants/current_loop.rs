//! The `current_loop` group. Per axis (`D_…`, `Q_…`, one table for both): the PI gains
//! K_p and K_i of the spec's method — IMC, thesis A (5.9), (5.7); pole placement, thesis A
//! (5.14), (5.15); IMC with active damping, thesis B (2.38), (2.39) —, the
//! forward-difference K_i·T_s (thesis A (4.17b)), the series-form zero K_b (thesis A
//! (5.7)), the active damping R_a (thesis B (2.43)), the anti-windup gain (thesis B (2.49))
//! and the reference prefilter (thesis A (5.16)). Then the decoupling and back-EMF
//! feed-forward L_d, L_q, ψ_M (thesis A (5.3)) and torque → i_q (thesis A (2.34)).

use super::Source::F32;
use super::Text::{Lit, Of};
use super::{Decl, Group, Json, declare, fs_input, phys, provenance};
use crate::design::current_loop::AxisGains;
use crate::design::{Design, FeedForward};
use crate::spec::Method;

/// The formulas of K_p and K_i for the spec's tuning method, and their equations.
#[derive(Clone, Copy)]
struct Tuning {
    kp: &'static str,
    ki: &'static str,
    equation: &'static str,
}

impl Tuning {
    fn of(method: Method) -> Tuning {
        let (kp, ki, equation) = match method {
            Method::Imc => ("K_p = K_a = L·α", "K_i = K_a·K_b = R·α", "thesis A (5.9), (5.7)"),
            Method::PolePlacement => ("K_p = 2ζω_n·L − R", "K_i = L·ω_n²", "thesis A (5.14), (5.15)"),
            Method::ImcActiveDamping => ("k_p = α_c·L", "k_i = α_c·(R + R_a)", "thesis B (2.38), (2.39)"),
        };
        Tuning { kp, ki, equation }
    }
}

/// What one axis's entries read: its gains and the inputs they cite.
struct Axis<'a> {
    /// `d` or `q`, as in the JSON design.
    axis: &'static str,
    g: &'a AxisGains,
    tuning: Tuning,
    /// L, R and α (delay-compensated where it was), ζ for pole placement.
    inputs: String,
    /// f_s.
    fs: String,
}

impl<'a> Axis<'a> {
    /// The entries of each axis.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "KP",
            value: F32(|a| a.g.kp, "V/A"),
            formula: Of(|a| a.tuning.kp.into()),
            equation: Of(|a| a.tuning.equation.into()),
            inputs: Of(|a| format!("{}; {}", a.inputs, a.g.sampled.describe())),
            json: Json::Of(|a| a.json("kp")),
        },
        Decl {
            name: "KI",
            value: F32(|a| a.g.ki, "V/(A·s)"),
            formula: Of(|a| a.tuning.ki.into()),
            equation: Of(|a| a.tuning.equation.into()),
            inputs: Of(|a| a.inputs.clone()),
            json: Json::Of(|a| a.json("ki")),
        },
        Decl {
            name: "KI_TS",
            value: F32(|a| a.g.ki_ts, "V/A"),
            formula: Lit("K_i·T_s (forward-difference integrator)"),
            equation: Lit("thesis A (4.17b)"),
            inputs: Of(|a| format!("{}, {}", a.inputs, a.fs)),
            json: Json::Of(|a| a.json("ki_ts")),
        },
        Decl {
            name: "KB",
            value: F32(|a| a.g.kb, "rad/s"),
            formula: Lit("K_b = K_i/K_p (series-form zero)"),
            equation: Lit("thesis A (5.7)"),
            inputs: Of(|a| a.inputs.clone()),
            json: Json::Of(|a| a.json("kb")),
        },
        Decl {
            name: "ACTIVE_DAMPING",
            value: F32(|a| a.g.active_damping_ohm, "Ω"),
            formula: Lit("R_a = α_c·L − R (0 unless imc_active_damping)"),
            equation: Lit("thesis B (2.43)"),
            inputs: Of(|a| a.inputs.clone()),
            json: Json::Of(|a| a.json("active_damping_ohm")),
        },
        Decl {
            name: "ANTI_WINDUP",
            value: F32(|a| a.g.anti_windup_gain, "A/V"),
            formula: Lit("1/k_p in dI/dt = e + (ū − u)/k_p"),
            equation: Lit("thesis B (2.49)"),
            inputs: Of(|a| a.inputs.clone()),
            json: Json::Of(|a| a.json("anti_windup_gain")),
        },
        Decl {
            name: "PREFILTER",
            value: F32(|a| a.g.reference_filter, ""),
            formula: Of(|a| {
                match a.g.prefilter {
                    Some(_) => "a = 1 − exp(−T_s·K_i/K_p): y += a·(x − y)",
                    None => "y += a·(x − y) with a = 1, no prefilter: this method's closed loop has no zero to cancel",
                }
                .into()
            }),
            equation: Lit("thesis A (5.16)"),
            inputs: Of(|a| format!("{}, {}", a.inputs, a.fs)),
            json: Json::Of(|a| a.json("reference_filter")),
        },
    ];

    /// The JSON pointer of `field` of this axis's gains.
    fn json(&self, field: &str) -> String {
        format!("/current_loop/{}/{field}", self.axis)
    }
}

/// What the feed-forward entries read: the constants and the motor values they come from.
struct Loop<'a> {
    ff: &'a FeedForward,
    pole_pairs: u32,
    /// L_d with its provenance.
    ld: String,
    /// L_q with its provenance.
    lq: String,
    /// ψ_M with its provenance, or why the term is omitted.
    psi: String,
}

impl<'a> Loop<'a> {
    /// The feed-forward entries, after both axes.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "FF_LD",
            value: F32(|l| l.ff.d_inductance_h, "H"),
            formula: Lit("L_d in u_q,ff = ω_e(L_d·i_d + ψ_M)"),
            equation: Lit("thesis A (5.3)"),
            inputs: Of(|l| l.ld.clone()),
            json: Json::At("/current_loop/feedforward/d_inductance_h"),
        },
        Decl {
            name: "FF_LQ",
            value: F32(|l| l.ff.q_inductance_h, "H"),
            formula: Lit("L_q in u_d,ff = −ω_e·L_q·i_q"),
            equation: Lit("thesis A (5.3)"),
            inputs: Of(|l| l.lq.clone()),
            json: Json::At("/current_loop/feedforward/q_inductance_h"),
        },
        Decl {
            name: "FF_PSI",
            value: F32(|l| l.ff.flux_linkage_wb.unwrap_or(0.0), "Wb"),
            formula: Lit("ψ_M in the back-EMF term ω_e·ψ_M"),
            equation: Lit("thesis A (5.3)"),
            inputs: Of(|l| l.psi.clone()),
            json: Json::At("/current_loop/feedforward/flux_linkage_wb"),
        },
        Decl {
            name: "IQ_PER_NM",
            value: F32(|l| l.ff.iq_per_nm.unwrap_or(0.0), "A/(N·m)"),
            formula: Lit("1/K_t, K_t = 3/2·n_p·ψ_M (0 if ψ_M unknown)"),
            equation: Lit("thesis A (2.34)"),
            inputs: Of(|l| format!("n_p = {} (datasheet), {}", l.pole_pairs, l.psi)),
            json: Json::At("/current_loop/feedforward/iq_per_nm"),
        },
    ];
}

/// The group: the d axis, the q axis, the feed-forward.
pub fn group(d: &Design) -> Group {
    let m = &d.motor;
    let cl = &d.current_loop;
    let ld = format!(
        "L_d = {} ({})",
        phys(m.d_inductance_h, "H"),
        provenance(d, "d_inductance")
    );
    let lq = format!(
        "L_q = {} ({})",
        phys(m.q_inductance_h, "H"),
        provenance(d, "q_inductance")
    );
    let r = format!(
        "R_s = {} ({})",
        phys(m.phase_resistance_ohm, "Ω"),
        provenance(d, "phase_resistance")
    );
    let alpha = format!("α = {} (spec)", phys(cl.bandwidth_rad_s, "rad/s"));
    let zeta = cl.damping.map_or(String::new(), |z| format!(", ζ = {z} (spec)"));
    let axes = [("D_", "d", &cl.d, &ld), ("Q_", "q", &cl.q, &lq)].map(|(prefix, axis, g, l)| {
        let alpha = if cl.compensate_delay {
            format!(
                "α = {} (delay-compensated from {alpha}: the sampled loop with {:.4}·T_s delay rises in ln 9/α_spec)",
                phys(g.bandwidth_rad_s, "rad/s"),
                g.sampled.loop_delay_periods
            )
        } else {
            alpha.clone()
        };
        let axis = Axis {
            axis,
            g,
            tuning: Tuning::of(cl.method),
            inputs: format!("{l}, {r}, {alpha}{zeta}"),
            fs: fs_input(d),
        };
        (prefix, axis)
    });
    let ff = &cl.feedforward;
    let psi = ff
        .flux_linkage_wb
        .map_or("ψ_M unknown → 0 (term omitted)".to_string(), |p| {
            format!("ψ_M = {} ({})", phys(p, "Wb"), provenance(d, "flux_linkage"))
        });
    let feedforward = Loop {
        ff,
        pole_pairs: m.pole_pairs,
        ld,
        lq,
        psi,
    };
    Group {
        name: "current_loop",
        title: "Current loop: PI gains per axis, feed-forward, torque → i_q",
        constants: axes
            .iter()
            .flat_map(|(prefix, a)| declare(Axis::DECLS, a, prefix))
            .chain(declare(Loop::DECLS, &feedforward, ""))
            .collect(),
    }
}
