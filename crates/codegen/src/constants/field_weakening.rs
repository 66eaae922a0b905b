//! The `field_weakening` group: the thesis B §2.3 controller's constants — the voltage
//! fraction and limit V'_max (thesis B (2.51), (2.55)), the bandwidth α_fw, base speed,
//! L̂_d and gain γ (thesis B (2.60), §2.3.3), the current circle and the i_d limits
//! (thesis B (2.50), (2.56), (2.57)) — and the chapter-3 d-current tables: MTPA (thesis B
//! (3.10)) and, with `[losses]`, the loss-minimising table (thesis B (3.3)–(3.9), (3.14),
//! (C.3)). With ψ_M unknown, the entries the firmware reads are declared as 0.

use super::Source::{Custom, F32};
use super::Text::{Lit, Of};
use super::{Decl, Group, Json, declare, f32_array, phys};
use crate::design::Design;
use crate::design::field_weakening::{BandwidthRule, FieldWeakeningOut};
use crate::design::loss_minimisation::LossTable;

// MTPA_TORQUE_MAX_NM points at the last of the 17 grid torques (`…/torque_nm/16`).
const _: () = assert!(crate::design::field_weakening::MTPA_POINTS == 17);

const TITLE: &str = "Field weakening (thesis B §2.3) and MTPA / loss-minimising i_d tables (chapter 3)";

/// Field weakening off (ψ_M unknown): the thesis rules cannot be evaluated.
struct Off;

impl Off {
    /// Every entry 0: α_fw = 0 makes γ = 0, and the one-point MTPA table holds i_d^ref = 0
    /// — like the omitted back-EMF feed-forward term.
    const DECLS: &'static [Decl<Self>] = &[
        Decl {
            name: "VOLTAGE_FRACTION",
            value: F32(|_| 0.0, ""),
            formula: Lit("V'_max/V_max"),
            equation: Lit("thesis B (2.55)"),
            inputs: Lit(Off::WHY),
            json: Json::At("/field_weakening"),
        },
        Decl {
            name: "BANDWIDTH",
            value: F32(|_| 0.0, "rad/s"),
            formula: Lit("α_fw"),
            equation: Lit("thesis B (2.60), §2.3.3"),
            inputs: Lit(Off::WHY),
            json: Json::At("/field_weakening"),
        },
        Decl {
            name: "BASE_SPEED",
            value: F32(|_| 0.0, "rad/s"),
            formula: Lit("ω_base"),
            equation: Lit("thesis B (2.60)"),
            inputs: Lit(Off::WHY),
            json: Json::At("/field_weakening"),
        },
        Decl {
            name: "LD",
            value: F32(|_| 0.0, "H"),
            formula: Lit("L̂_d in γ"),
            equation: Lit("thesis B (2.60)"),
            inputs: Lit(Off::WHY),
            json: Json::At("/field_weakening"),
        },
        Decl {
            name: "CURRENT_MAX_A",
            value: F32(|_| 0.0, "A"),
            formula: Lit("I_max"),
            equation: Lit("thesis B (2.50), (2.56)"),
            inputs: Lit(Off::WHY),
            json: Json::At("/field_weakening"),
        },
        Decl {
            name: "MTPA_IQ_A",
            value: Custom(|_| (f32_array(&[0.0]), "[0 A]".into())),
            formula: Lit("|i_q| grid"),
            equation: Lit("thesis B (3.10)"),
            inputs: Lit(Off::WHY),
            json: Json::At("/field_weakening"),
        },
        Decl {
            name: "MTPA_ID_A",
            value: Custom(|_| (f32_array(&[0.0]), "[0 A]".into())),
            formula: Lit("i_d = 0"),
            equation: Lit("thesis B (3.10)"),
            inputs: Lit(Off::WHY),
            json: Json::At("/field_weakening"),
        },
        Decl {
            name: "MTPA_TORQUE_MAX_NM",
            value: F32(|_| 0.0, "N·m"),
            formula: Lit("T_max of the MTPA table by torque"),
            equation: Lit("thesis A (2.33), thesis B (3.10)"),
            inputs: Lit(Off::WHY),
            json: Json::At("/field_weakening"),
        },
        Decl {
            name: "MTPA_ID_BY_TORQUE_A",
            value: Custom(|_| {
                (
                    f32_array(&[0.0; crate::design::field_weakening::MTPA_POINTS]),
                    "0 A".into(),
                )
            }),
            formula: Lit("i_d = 0"),
            equation: Lit("thesis B (3.10)"),
            inputs: Lit(Off::WHY),
            json: Json::At("/field_weakening"),
        },
    ];

    /// The inputs of every entry.
    const WHY: &'static str = "ψ_M unknown → 0 (field weakening off)";
}

/// What the controller's and the MTPA table's entries read.
struct On<'a> {
    d: &'a Design,
    fw: &'a FieldWeakeningOut,
    /// V'_max/V_max.
    fraction: String,
    /// I_max = √2·I_peak,rms.
    current_max: String,
    /// The motor values and the table's grid and accuracy.
    mtpa: String,
}

impl<'a> On<'a> {
    /// The entries.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "VOLTAGE_FRACTION",
            value: F32(|c| c.fw.voltage_fraction, ""),
            formula: Lit("V'_max/V_max (spec field_weakening.voltage_fraction, default 0.9 of thesis B Fig. 2.15)"),
            equation: Lit("thesis B (2.55), Fig. 2.15"),
            inputs: Of(|c| c.fraction.clone()),
            json: Json::At("/field_weakening/voltage_fraction"),
        },
        Decl {
            name: "VOLTAGE_LIMIT_V",
            value: F32(|c| c.fw.voltage_limit_v, "V"),
            formula: Lit(
                "V'_max = fraction·V_max, V_max = k·U_dc/√3 the usable voltage at the nominal U_dc (k from the board's duty limit, 1 without one; the firmware rescales with the measured U_dc)",
            ),
            equation: Lit("thesis B (2.51), (2.55)"),
            inputs: Of(|c| {
                format!(
                    "{}, V_max = k·U_dc/√3 = {} (U_dc = {}, spec)",
                    c.fraction,
                    phys(c.d.current_loop.voltage_limit_v, "V"),
                    phys(c.d.drive.dc_link_voltage_v, "V")
                )
            }),
            json: Json::At("/field_weakening/voltage_limit_v"),
        },
        Decl {
            name: "BANDWIDTH",
            value: F32(|c| c.fw.bandwidth_rad_s, "rad/s"),
            formula: Lit("α_fw: field-weakening pole at −α_fw (2.61), α_fw ≪ α_c"),
            equation: Lit("thesis B (2.60), §2.3.3"),
            inputs: Of(|c| {
                format!(
                    "{}, α_c = {}",
                    c.bandwidth_rule(),
                    phys(c.d.current_loop.bandwidth_rad_s, "rad/s")
                )
            }),
            json: Json::At("/field_weakening/bandwidth_rad_s"),
        },
        Decl {
            name: "BASE_SPEED",
            value: F32(|c| c.fw.base_speed_rad_s, "rad/s"),
            formula: Lit("ω_base (electrical): ω_fw = max(ω_base, |ω_r|)"),
            equation: Lit("thesis B (2.60)"),
            inputs: Of(|c| {
                match c.d.per_unit.bases.angular_frequency_rad_s {
                    Some(_) => "ω_base = 2π·f_n (per-unit base, thesis B App. A)",
                    None => "no f_n: ω_base = the corner speed where the full-current MTPA point reaches V'_max, R_s included (2.26), (2.27), (2.53)",
                }
                .into()
            }),
            json: Json::At("/field_weakening/base_speed_rad_s"),
        },
        Decl {
            name: "LD",
            value: F32(|c| c.fw.d_inductance_h, "H"),
            formula: Lit("L̂_d in γ = α_fw/(2·ω_fw·L̂_d·V'_max)"),
            equation: Lit("thesis B (2.60)"),
            inputs: Of(|c| format!("L_d = {}", phys(c.d.motor.d_inductance_h, "H"))),
            json: Json::At("/field_weakening/d_inductance_h"),
        },
        Decl {
            name: "GAIN_AT_BASE_SPEED",
            value: F32(|c| c.fw.gain_at_base_speed, "A/(V²·s)"),
            formula: Lit("γ = α_fw/(2·ω_base·L̂_d·V'_max) at ω_fw = ω_base and the nominal V'_max"),
            equation: Lit("thesis B (2.60)"),
            inputs: Lit("α_fw, ω_base, L̂_d, V'_max above"),
            json: Json::At("/field_weakening/gain_at_base_speed"),
        },
        Decl {
            name: "CURRENT_MAX_A",
            value: F32(|c| c.fw.current_max_a, "A"),
            formula: Lit("I_max: current circle, −I_max ≤ i_d^ref, i_q^ref = √(I_max² − (i_d^ref)²) in Mode B"),
            equation: Lit("thesis B (2.50), (2.56), (2.57)"),
            inputs: Of(|c| c.current_max.clone()),
            json: Json::At("/field_weakening/current_max_a"),
        },
        Decl {
            name: "ID_MIN_A",
            value: F32(|c| c.fw.id_min_a, "A"),
            formula: Lit("−I_max, lower limit of i_d^ref (demagnetisation)"),
            equation: Lit("thesis B (2.56)"),
            inputs: Of(|c| c.current_max.clone()),
            json: Json::At("/field_weakening/id_min_a"),
        },
        Decl {
            name: "ID_MTPA_AT_CURRENT_MAX_A",
            value: F32(|c| c.fw.id_mtpa_at_current_max_a, "A"),
            formula: Lit(
                "upper limit of i_d^ref at full current: i_d = −2ΔL·I²/(ψ_M + √(ψ_M² + 8ΔL²·I²)), (3.10) on |i| = I_max",
            ),
            equation: Lit("thesis B (2.56), (3.10)"),
            inputs: Of(|c| format!("{}, ΔL = L_q − L_d", c.current_max)),
            json: Json::At("/field_weakening/id_mtpa_at_current_max_a"),
        },
        Decl {
            name: "IQ_MODE_B_START_A",
            value: F32(|c| c.fw.iq_mode_b_at_mtpa_a, "A"),
            formula: Lit("√(I_max² − i_d²) at the MTPA point on the circle: Mode B limits |i_q^ref| below this"),
            equation: Lit("thesis B (2.57)"),
            inputs: Of(|c| c.current_max.clone()),
            json: Json::At("/field_weakening/iq_mode_b_at_mtpa_a"),
        },
        Decl {
            name: "MTPA_IQ_A",
            value: Custom(|c| {
                let iq = &c.fw.mtpa.iq_a;
                let physical = format!("{} points, 0 … {}", iq.len(), phys(c.fw.iq_mode_b_at_mtpa_a, "A"));
                (f32_array(iq), physical)
            }),
            formula: Lit("uniform |i_q| grid of the MTPA table"),
            equation: Lit("thesis B (3.10)"),
            inputs: Of(|c| c.mtpa.clone()),
            json: Json::At("/field_weakening/mtpa/iq_a"),
        },
        Decl {
            name: "MTPA_ID_A",
            value: Custom(|c| {
                let id = &c.fw.mtpa.id_a;
                let physical = format!("{} … {}", phys(id[0], "A"), phys(c.fw.id_mtpa_at_current_max_a, "A"));
                (f32_array(id), physical)
            }),
            formula: Lit("i_d,MTPA = ψ_M/(2ΔL) − √((ψ_M/(2ΔL))² + i_q²), ΔL = L_q − L_d"),
            equation: Lit("thesis B (3.10), (2.56)"),
            inputs: Of(|c| c.mtpa.clone()),
            json: Json::At("/field_weakening/mtpa/id_a"),
        },
        Decl {
            name: "MTPA_MAX_INTERPOLATION_ERROR_A",
            value: F32(|c| c.fw.mtpa.max_interpolation_error_a, "A"),
            formula: Lit("max |linear interpolation − (3.10)| at the grid midpoints"),
            equation: Lit("thesis B (3.10)"),
            inputs: Of(|c| c.mtpa.clone()),
            json: Json::At("/field_weakening/mtpa/max_interpolation_error_a"),
        },
        Decl {
            name: "MTPA_TORQUE_MAX_NM",
            value: F32(|c| *c.fw.mtpa_by_torque.torque_nm.last().unwrap_or(&0.0), "N·m"),
            formula: Lit(
                "T_max = 3/2·n_p·i_q·(ψ_M − ΔL·i_d) at the MTPA point on |i| = I_max: the end of the torque grid of MTPA_ID_BY_TORQUE_A",
            ),
            equation: Lit("thesis A (2.33), thesis B (3.10), (2.50)"),
            inputs: Of(|c| {
                format!(
                    "n_p = {}, the MTPA point ({}, {})",
                    c.d.motor.pole_pairs,
                    phys(c.fw.id_mtpa_at_current_max_a, "A"),
                    phys(c.fw.iq_mode_b_at_mtpa_a, "A")
                )
            }),
            json: Json::At("/field_weakening/mtpa_by_torque/torque_nm/16"),
        },
        Decl {
            name: "MTPA_ID_BY_TORQUE_A",
            value: Custom(|c| {
                let id = &c.fw.mtpa_by_torque.id_a;
                let physical = format!(
                    "{} points, {} … {} at 0 … {}",
                    id.len(),
                    phys(id[0], "A"),
                    phys(*id.last().unwrap_or(&0.0), "A"),
                    phys(*c.fw.mtpa_by_torque.torque_nm.last().unwrap_or(&0.0), "N·m")
                );
                (f32_array(id), physical)
            }),
            formula: Lit(
                "i_d,MTPA at the torques k·T_max/16 (the point of (3.10) making the torque, by bisection on i_q): the firmware's torque stage interpolates it at the demanded torque and solves (2.33) for i_q",
            ),
            equation: Lit("thesis B (3.10), (2.56); thesis A (2.33)"),
            inputs: Of(|c| {
                format!(
                    "{}; linear interpolation costs at most {:.3} % of current over the MTPA (least) current at the interval midpoints",
                    c.mtpa,
                    100.0 * c.fw.mtpa_by_torque.max_current_excess
                )
            }),
            json: Json::At("/field_weakening/mtpa_by_torque/id_a"),
        },
    ];

    /// How α_fw was chosen, with the value it was chosen from.
    fn bandwidth_rule(&self) -> String {
        let fw = self.fw;
        match fw.bandwidth_rule {
            BandwidthRule::Mechanical => format!(
                "α_fw = 10·b/J, b/J = {} (motor inertia and viscous friction, torque-controlled drive)",
                phys(fw.mechanical_bandwidth_rad_s.unwrap_or(0.0), "1/s")
            ),
            BandwidthRule::SpeedLoop => format!(
                "α_fw = 10·α_s, α_s = {} (spec field_weakening.speed_loop_bandwidth)",
                phys(fw.speed_loop_bandwidth_rad_s.unwrap_or(0.0), "rad/s")
            ),
            BandwidthRule::DefaultSpeedLoop => format!(
                "α_fw = 10·α_s, α_s = α_c/100 = {} (no speed loop or J, b in the spec: thesis B Fig. 2.15)",
                phys(fw.speed_loop_bandwidth_rad_s.unwrap_or(0.0), "rad/s")
            ),
        }
    }
}

/// What the loss-minimising table's entries read (a spec with `[losses]`).
struct Losses<'a> {
    t: &'a LossTable,
    /// The loss model and the table's grid and accuracy.
    inputs: String,
}

impl<'a> Losses<'a> {
    /// The entries, after the MTPA table.
    const DECLS: &'a [Decl<Self>] = &[
        Decl {
            name: "LOSS_MIN_SPEED_RAD_S",
            value: Custom(|c| {
                let speeds = &c.t.speeds_rad_s;
                let physical = format!(
                    "{} points, 0 … {}",
                    speeds.len(),
                    phys(*speeds.last().unwrap_or(&0.0), "rad/s")
                );
                (f32_array(speeds), physical)
            }),
            formula: Lit("uniform electrical-speed grid (rows of LOSS_MIN_ID_A)"),
            equation: Lit("thesis B (3.8), (3.9)"),
            inputs: Of(|c| c.inputs.clone()),
            json: Json::At("/field_weakening/loss_minimisation/table/speeds_rad_s"),
        },
        Decl {
            name: "LOSS_MIN_ID_A",
            value: Custom(|c| {
                let lowest = c.t.id_a.iter().copied().fold(f64::INFINITY, f64::min);
                (f32_array(&c.t.id_a), format!("{} … 0 A", phys(lowest, "A")))
            }),
            formula: Lit(
                "i_d minimising P_res + P_co (+ P_loss,inv) at constant torque and speed, row-major [speed][MTPA_IQ_A]",
            ),
            equation: Lit("thesis B (3.3)–(3.9), (3.14), (C.3)"),
            inputs: Of(|c| c.inputs.clone()),
            json: Json::At("/field_weakening/loss_minimisation/table/id_a"),
        },
        Decl {
            name: "LOSS_MIN_MAX_INTERPOLATION_ERROR_A",
            value: F32(|c| c.t.max_interpolation_error_a, "A"),
            formula: Lit("max |bilinear interpolation − numeric optimum| at cell centres and edge midpoints"),
            equation: Lit("thesis B (3.8), (3.9)"),
            inputs: Of(|c| c.inputs.clone()),
            json: Json::At("/field_weakening/loss_minimisation/table/max_interpolation_error_a"),
        },
    ];
}

/// The group; with ψ_M unknown, `Off`'s entries.
pub fn group(d: &Design) -> Group {
    let Some(fw) = &d.field_weakening else {
        return Group {
            name: "field_weakening",
            title: TITLE,
            constants: declare(Off::DECLS, &Off, "").collect(),
        };
    };
    let m = &d.motor;
    let on = On {
        d,
        fw,
        fraction: format!("V'_max/V_max = {}", fw.voltage_fraction),
        current_max: format!("I_max = √2·I_peak,rms = √2·{}", phys(m.peak_current_a_rms, "A")),
        mtpa: format!(
            "ψ_M = {}, L_d = {}, L_q = {}; {} points, |i_q| = 0 … {} (the MTPA point on |i| = I_max), linear in between, held beyond; max interpolation error {} at the interval midpoints against (3.10)",
            phys(m.flux_linkage_wb.unwrap_or(0.0), "Wb"),
            phys(m.d_inductance_h, "H"),
            phys(m.q_inductance_h, "H"),
            fw.mtpa.iq_a.len(),
            phys(fw.iq_mode_b_at_mtpa_a, "A"),
            phys(fw.mtpa.max_interpolation_error_a, "A"),
        ),
    };
    let losses = fw.loss_minimisation.as_ref().map(|lm| {
        let t = &lm.table;
        let inputs = format!(
            "{}{}; R_s = {}, ψ_M, L_d, L_q as above; {} speeds 0 … {} (electrical) × the {} MTPA |i_q| points, bilinear in between; max interpolation error {} at the cell centres and edge midpoints against the numeric optimum",
            lm.core_resistance_ohm.map_or("no core losses".to_string(), |r| format!(
                "core losses R_c = {} (spec losses.core_resistance)",
                phys(r, "Ω")
            )),
            if lm.inverter_losses {
                ", inverter losses (3.11)–(3.14) of [inverter]"
            } else {
                ""
            },
            phys(m.phase_resistance_ohm, "Ω"),
            t.speeds_rad_s.len(),
            phys(*t.speeds_rad_s.last().unwrap_or(&0.0), "rad/s"),
            t.iq_a.len(),
            phys(t.max_interpolation_error_a, "A"),
        );
        Losses { t, inputs }
    });
    Group {
        name: "field_weakening",
        title: TITLE,
        constants: declare(On::DECLS, &on, "")
            .chain(losses.iter().flat_map(|l| declare(Losses::DECLS, l, "")))
            .collect(),
    }
}
