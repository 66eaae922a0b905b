//! The `field_weakening` group: thesis B §2.3 controller constants and the chapter-3
//! d-current tables.

use super::{Group, Value, c, f32v, phys};
use crate::design::Design;

/// An `f32` array constant.
fn f32_array(v: &[f64]) -> Value {
    let items: Vec<Value> = v.iter().map(|&x| f32v(x)).collect();
    let rust = items
        .iter()
        .map(|x| x.rust_expr.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    let cexpr = items.iter().map(|x| x.c_expr.as_str()).collect::<Vec<_>>().join(", ");
    Value {
        rust_type: format!("[f32; {}]", v.len()),
        rust_expr: format!("[{rust}]"),
        c_type: "float".into(),
        c_len: Some(v.len()),
        c_expr: format!("{{{cexpr}}}"),
        number: serde_json::json!(v.iter().map(|&x| x as f32).collect::<Vec<_>>()),
    }
}

/// The group; with ψ_M unknown the thesis rules cannot be evaluated and every entry is
/// 0 (field weakening off: α_fw = 0 makes γ = 0, and the one-point MTPA table holds
/// i_d^ref = 0), like the omitted back-EMF feed-forward term.
pub fn group(d: &Design) -> Group {
    let title = "Field weakening (thesis B §2.3) and MTPA / loss-minimising i_d tables (chapter 3)";
    let Some(fw) = &d.field_weakening else {
        let off = "ψ_M unknown → 0 (field weakening off)".to_string();
        let zero = |name: &str, formula: &str, eq: &str, unit: &str| {
            c(name, f32v(0.0), phys(0.0, unit), formula, eq, off.clone()).at("/field_weakening")
        };
        return Group {
            name: "field_weakening",
            title,
            constants: vec![
                zero("VOLTAGE_FRACTION", "V'_max/V_max", "thesis B (2.55)", ""),
                zero("BANDWIDTH", "α_fw", "thesis B (2.60), §2.3.3", "rad/s"),
                zero("BASE_SPEED", "ω_base", "thesis B (2.60)", "rad/s"),
                zero("LD", "L̂_d in γ", "thesis B (2.60)", "H"),
                zero("CURRENT_MAX_A", "I_max", "thesis B (2.50), (2.56)", "A"),
                c(
                    "MTPA_IQ_A",
                    f32_array(&[0.0]),
                    "[0 A]".into(),
                    "|i_q| grid",
                    "thesis B (3.10)",
                    off.clone(),
                )
                .at("/field_weakening"),
                c(
                    "MTPA_ID_A",
                    f32_array(&[0.0]),
                    "[0 A]".into(),
                    "i_d = 0",
                    "thesis B (3.10)",
                    off,
                )
                .at("/field_weakening"),
            ],
        };
    };
    let m = &d.motor;
    let j = |field: &str| format!("/field_weakening/{field}");
    let frac_in = format!("V'_max/V_max = {}", fw.voltage_fraction);
    let vmax_in = format!(
        "V_max = U_dc/√3 = {} (U_dc = {}, spec)",
        phys(d.current_loop.voltage_limit_v, "V"),
        phys(d.drive.dc_link_voltage_v, "V")
    );
    let rule = match fw.bandwidth_rule {
        crate::design::field_weakening::BandwidthRule::Mechanical => format!(
            "α_fw = 10·b/J, b/J = {} (motor inertia and viscous friction, torque-controlled drive)",
            phys(fw.mechanical_bandwidth_rad_s.unwrap_or(0.0), "1/s")
        ),
        crate::design::field_weakening::BandwidthRule::SpeedLoop => format!(
            "α_fw = 10·α_s, α_s = {} (spec field_weakening.speed_loop_bandwidth)",
            phys(fw.speed_loop_bandwidth_rad_s.unwrap_or(0.0), "rad/s")
        ),
        crate::design::field_weakening::BandwidthRule::DefaultSpeedLoop => format!(
            "α_fw = 10·α_s, α_s = α_c/100 = {} (no speed loop or J, b in the spec: thesis B Fig. 2.15)",
            phys(fw.speed_loop_bandwidth_rad_s.unwrap_or(0.0), "rad/s")
        ),
    };
    let base_in = match d.per_unit.bases.angular_frequency_rad_s {
        Some(_) => "ω_base = 2π·f_n (per-unit base, thesis B App. A)".to_string(),
        None => "no f_n: ω_base = the corner speed where the full-current MTPA point reaches V'_max, R_s included (2.26), (2.27), (2.53)".to_string(),
    };
    let imax_in = format!("I_max = √2·I_peak,rms = √2·{}", phys(m.peak_current_a_rms, "A"));
    let mtpa_in = format!(
        "ψ_M = {}, L_d = {}, L_q = {}; {} points, |i_q| = 0 … {} (the MTPA point on |i| = I_max), linear in between, held beyond; max interpolation error {} at the interval midpoints against (3.10)",
        phys(d.motor.flux_linkage_wb.unwrap_or(0.0), "Wb"),
        phys(m.d_inductance_h, "H"),
        phys(m.q_inductance_h, "H"),
        fw.mtpa.iq_a.len(),
        phys(fw.iq_mode_b_at_mtpa_a, "A"),
        phys(fw.mtpa.max_interpolation_error_a, "A"),
    );
    let mut k =
        vec![
        c(
            "VOLTAGE_FRACTION",
            f32v(fw.voltage_fraction),
            phys(fw.voltage_fraction, ""),
            "V'_max/V_max (spec field_weakening.voltage_fraction, default 0.9 of thesis B Fig. 2.15)",
            "thesis B (2.55), Fig. 2.15",
            frac_in.clone(),
        )
        .at(j("voltage_fraction")),
        c(
            "VOLTAGE_LIMIT_V",
            f32v(fw.voltage_limit_v),
            phys(fw.voltage_limit_v, "V"),
            "V'_max = fraction·U_dc/√3 at the nominal U_dc (the firmware rescales with the measured U_dc)",
            "thesis B (2.51), (2.55)",
            format!("{frac_in}, {vmax_in}"),
        )
        .at(j("voltage_limit_v")),
        c(
            "BANDWIDTH",
            f32v(fw.bandwidth_rad_s),
            phys(fw.bandwidth_rad_s, "rad/s"),
            "α_fw: field-weakening pole at −α_fw (2.61), α_fw ≪ α_c",
            "thesis B (2.60), §2.3.3",
            format!("{rule}, α_c = {}", phys(d.current_loop.bandwidth_rad_s, "rad/s")),
        )
        .at(j("bandwidth_rad_s")),
        c(
            "BASE_SPEED",
            f32v(fw.base_speed_rad_s),
            phys(fw.base_speed_rad_s, "rad/s"),
            "ω_base (electrical): ω_fw = max(ω_base, |ω_r|)",
            "thesis B (2.60)",
            base_in,
        )
        .at(j("base_speed_rad_s")),
        c(
            "LD",
            f32v(fw.d_inductance_h),
            phys(fw.d_inductance_h, "H"),
            "L̂_d in γ = α_fw/(2·ω_fw·L̂_d·V'_max)",
            "thesis B (2.60)",
            format!("L_d = {}", phys(m.d_inductance_h, "H")),
        )
        .at(j("d_inductance_h")),
        c(
            "GAIN_AT_BASE_SPEED",
            f32v(fw.gain_at_base_speed),
            phys(fw.gain_at_base_speed, "A/(V²·s)"),
            "γ = α_fw/(2·ω_base·L̂_d·V'_max) at ω_fw = ω_base and the nominal V'_max",
            "thesis B (2.60)",
            "α_fw, ω_base, L̂_d, V'_max above".into(),
        )
        .at(j("gain_at_base_speed")),
        c(
            "CURRENT_MAX_A",
            f32v(fw.current_max_a),
            phys(fw.current_max_a, "A"),
            "I_max: current circle, −I_max ≤ i_d^ref, i_q^ref = √(I_max² − (i_d^ref)²) in Mode B",
            "thesis B (2.50), (2.56), (2.57)",
            imax_in.clone(),
        )
        .at(j("current_max_a")),
        c(
            "ID_MIN_A",
            f32v(fw.id_min_a),
            phys(fw.id_min_a, "A"),
            "−I_max, lower limit of i_d^ref (demagnetisation)",
            "thesis B (2.56)",
            imax_in.clone(),
        )
        .at(j("id_min_a")),
        c(
            "ID_MTPA_AT_CURRENT_MAX_A",
            f32v(fw.id_mtpa_at_current_max_a),
            phys(fw.id_mtpa_at_current_max_a, "A"),
            "upper limit of i_d^ref at full current: i_d = −2ΔL·I²/(ψ_M + √(ψ_M² + 8ΔL²·I²)), (3.10) on |i| = I_max",
            "thesis B (2.56), (3.10)",
            format!("{imax_in}, ΔL = L_q − L_d"),
        )
        .at(j("id_mtpa_at_current_max_a")),
        c(
            "IQ_MODE_B_START_A",
            f32v(fw.iq_mode_b_at_mtpa_a),
            phys(fw.iq_mode_b_at_mtpa_a, "A"),
            "√(I_max² − i_d²) at the MTPA point on the circle: Mode B limits |i_q^ref| below this",
            "thesis B (2.57)",
            imax_in,
        )
        .at(j("iq_mode_b_at_mtpa_a")),
        c(
            "MTPA_IQ_A",
            f32_array(&fw.mtpa.iq_a),
            format!("{} points, 0 … {}", fw.mtpa.iq_a.len(), phys(fw.iq_mode_b_at_mtpa_a, "A")),
            "uniform |i_q| grid of the MTPA table",
            "thesis B (3.10)",
            mtpa_in.clone(),
        )
        .at(j("mtpa/iq_a")),
        c(
            "MTPA_ID_A",
            f32_array(&fw.mtpa.id_a),
            format!("{} … {}", phys(fw.mtpa.id_a[0], "A"), phys(fw.id_mtpa_at_current_max_a, "A")),
            "i_d,MTPA = ψ_M/(2ΔL) − √((ψ_M/(2ΔL))² + i_q²), ΔL = L_q − L_d",
            "thesis B (3.10), (2.56)",
            mtpa_in.clone(),
        )
        .at(j("mtpa/id_a")),
        c(
            "MTPA_MAX_INTERPOLATION_ERROR_A",
            f32v(fw.mtpa.max_interpolation_error_a),
            phys(fw.mtpa.max_interpolation_error_a, "A"),
            "max |linear interpolation − (3.10)| at the grid midpoints",
            "thesis B (3.10)",
            mtpa_in,
        )
        .at(j("mtpa/max_interpolation_error_a")),
    ];
    if let Some(lm) = &fw.loss_minimisation {
        let t = &lm.table;
        let what = format!(
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
        let lo = t.id_a.iter().copied().fold(f64::INFINITY, f64::min);
        k.push(
            c(
                "LOSS_MIN_SPEED_RAD_S",
                f32_array(&t.speeds_rad_s),
                format!(
                    "{} points, 0 … {}",
                    t.speeds_rad_s.len(),
                    phys(*t.speeds_rad_s.last().unwrap_or(&0.0), "rad/s")
                ),
                "uniform electrical-speed grid (rows of LOSS_MIN_ID_A)",
                "thesis B (3.8), (3.9)",
                what.clone(),
            )
            .at(j("loss_minimisation/table/speeds_rad_s")),
        );
        k.push(
            c(
                "LOSS_MIN_ID_A",
                f32_array(&t.id_a),
                format!("{} … 0 A", phys(lo, "A")),
                "i_d minimising P_res + P_co (+ P_loss,inv) at constant torque and speed, row-major [speed][MTPA_IQ_A]",
                "thesis B (3.3)–(3.9), (3.14), (C.3)",
                what.clone(),
            )
            .at(j("loss_minimisation/table/id_a")),
        );
        k.push(
            c(
                "LOSS_MIN_MAX_INTERPOLATION_ERROR_A",
                f32v(t.max_interpolation_error_a),
                phys(t.max_interpolation_error_a, "A"),
                "max |bilinear interpolation − numeric optimum| at cell centres and edge midpoints",
                "thesis B (3.8), (3.9)",
                what,
            )
            .at(j("loss_minimisation/table/max_interpolation_error_a")),
        );
    }
    Group {
        name: "field_weakening",
        title,
        constants: k,
    }
}
