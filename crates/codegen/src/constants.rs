//! The design as a flat list of documented constants, grouped by concern.
//!
//! This is the single path from a [`Design`] to code: the Rust module, the C
//! header, the Markdown report and the proc-macro all render this list, so a
//! constant cannot differ between them. Every entry carries its physical value
//! with unit, its formula, the source equation and the provenance of its inputs.

mod board;
pub mod can;
mod field_weakening;
mod sensorless;

use serde::{Deserialize, Serialize};

use crate::design::{Design, Origin};
use crate::spec::Provenance;

/// A constant's machine value, with its Rust and C spellings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Value {
    /// Rust type (absolute paths), e.g. `f32`, `::fixed::types::I1F31`, `[i16; 21]`.
    pub rust_type: String,
    /// Rust const expression.
    pub rust_expr: String,
    /// C type, e.g. `float`, `int32_t` (of the elements, for an array).
    pub c_type: String,
    /// Number of elements of an array constant; `None` for a scalar.
    pub c_len: Option<usize>,
    /// C initialiser; for an integer scalar an integer constant expression (`INT32_C(…)`),
    /// which the header `#define`s so that it works in `#if`, `case` labels and array sizes.
    pub c_expr: String,
    /// The value as JSON-able number(s) for tests: integers are exact, floats are the f32 value.
    pub number: serde_json::Value,
}

/// One generated constant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Constant {
    /// Identifier within its group, SCREAMING_SNAKE_CASE.
    pub name: String,
    /// Machine value.
    pub value: Value,
    /// Physical value with unit, e.g. `0.0393 V/A`.
    pub physical: String,
    /// Formula, e.g. `K_p = L_d·α`.
    pub formula: String,
    /// Source equation, e.g. `thesis A (5.9)`.
    pub equation: String,
    /// Inputs with their provenance, e.g. `L_d = 0.393 mH (datasheet)`.
    pub inputs: String,
    /// JSON pointer of the same value in `motorgen design --format json` (null there reads as 0).
    pub json_path: String,
}

/// Constants of one concern (a Rust module, a C prefix, a report section).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Group {
    /// Module name, snake_case.
    pub name: &'static str,
    /// One-line description.
    pub title: &'static str,
    /// The constants, in a stable order.
    pub constants: Vec<Constant>,
}

/// Shortest decimal that round-trips the f32 nearest `x`, always with a `.` or exponent.
pub fn f32_literal(x: f64) -> String {
    let s = format!("{:?}", x as f32);
    if s.contains(['.', 'e', 'E']) || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

/// The `core::f32::consts` item equal to `x as f32`, if any: clippy's `approx_constant`
/// rejects such a value written as a literal, so generated code names the constant.
fn f32_named_constant(x: f64) -> Option<&'static str> {
    use std::f32::consts as c;
    let named = [
        (c::PI, "PI"),
        (c::TAU, "TAU"),
        (c::FRAC_PI_2, "FRAC_PI_2"),
        (c::FRAC_PI_3, "FRAC_PI_3"),
        (c::FRAC_PI_4, "FRAC_PI_4"),
        (c::FRAC_PI_6, "FRAC_PI_6"),
        (c::FRAC_PI_8, "FRAC_PI_8"),
        (c::FRAC_1_PI, "FRAC_1_PI"),
        (c::FRAC_2_PI, "FRAC_2_PI"),
        (c::FRAC_2_SQRT_PI, "FRAC_2_SQRT_PI"),
        (c::SQRT_2, "SQRT_2"),
        (c::FRAC_1_SQRT_2, "FRAC_1_SQRT_2"),
        (c::E, "E"),
        (c::LN_2, "LN_2"),
        (c::LN_10, "LN_10"),
        (c::LOG2_E, "LOG2_E"),
        (c::LOG10_E, "LOG10_E"),
        (c::LOG2_10, "LOG2_10"),
        (c::LOG10_2, "LOG10_2"),
    ];
    named
        .iter()
        .find(|(v, _)| v.to_bits() == (x as f32).to_bits())
        .map(|&(_, name)| name)
}

fn f32v(x: f64) -> Value {
    let lit = f32_literal(x);
    let rust_expr = match f32_named_constant(x) {
        Some(name) => format!("::core::f32::consts::{name}"),
        None => lit.clone(),
    };
    let c = if lit.contains(['.', 'e']) {
        format!("{lit}f")
    } else {
        format!("{lit}.0f")
    };
    Value {
        rust_type: "f32".into(),
        rust_expr,
        c_type: "float".into(),
        c_len: None,
        c_expr: c,
        number: serde_json::json!(x as f32),
    }
}

/// `x` as a C integer constant expression of the `<stdint.h>` type `c` (`int32_t`,
/// `uint8_t`, …): the type's constant macro (`INT32_C(5)`, C99 §7.18.4), whose argument
/// must be an unsigned literal, so a negative value is `(-INT32_C(5))` and the type's
/// minimum is its named limit (`INT32_MIN`).
fn c_integer(x: i64, c: &str) -> String {
    let stem = c.strip_suffix("_t").unwrap_or(c).to_uppercase();
    let min = match c {
        "int8_t" => i64::from(i8::MIN),
        "int16_t" => i64::from(i16::MIN),
        "int32_t" => i64::from(i32::MIN),
        _ => i64::MIN,
    };
    if x == min {
        format!("{stem}_MIN")
    } else if x < 0 {
        format!("(-{stem}_C({}))", x.unsigned_abs())
    } else {
        format!("{stem}_C({x})")
    }
}

fn intv(x: i64, rust: &str, c: &str) -> Value {
    Value {
        rust_type: rust.into(),
        rust_expr: x.to_string(),
        c_type: c.into(),
        c_len: None,
        c_expr: c_integer(x, c),
        number: serde_json::json!(x),
    }
}

fn q31v(bits: i32) -> Value {
    Value {
        rust_type: "::fixed::types::I1F31".into(),
        rust_expr: format!("::fixed::types::I1F31::from_bits({bits})"),
        c_type: "int32_t".into(),
        c_len: None,
        c_expr: c_integer(i64::from(bits), "int32_t"),
        number: serde_json::json!(bits),
    }
}

fn u8_array(v: &[u8]) -> Value {
    let list = v.iter().map(u8::to_string).collect::<Vec<_>>().join(", ");
    Value {
        rust_type: format!("[u8; {}]", v.len()),
        rust_expr: format!("[{list}]"),
        c_type: "uint8_t".into(),
        c_len: Some(v.len()),
        c_expr: format!("{{{list}}}"),
        number: serde_json::json!(v),
    }
}

fn i16_array(v: &[i16]) -> Value {
    let list = v.iter().map(i16::to_string).collect::<Vec<_>>().join(", ");
    Value {
        rust_type: format!("[i16; {}]", v.len()),
        rust_expr: format!("[{list}]"),
        c_type: "int16_t".into(),
        c_len: Some(v.len()),
        c_expr: format!("{{{list}}}"),
        number: serde_json::json!(v),
    }
}

/// Physical value with unit and 6 significant digits.
fn phys(x: f64, unit: &str) -> String {
    let s = if x == 0.0 {
        "0".to_string()
    } else if (1e-6..1e7).contains(&x.abs()) {
        let digits = (5 - x.abs().log10().floor() as i32).clamp(0, 12) as usize;
        let t = format!("{x:.digits$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    } else {
        format!("{x:.5e}")
    };
    if unit.is_empty() { s } else { format!("{s} {unit}") }
}

fn prov(o: Option<&Origin>) -> &'static str {
    match o.map(|o| o.source) {
        Some(Provenance::Datasheet) => "datasheet",
        Some(Provenance::Identified) => "identified",
        Some(Provenance::Derived) => "derived",
        Some(Provenance::Default) | None => "default",
    }
}

fn c(
    name: impl Into<String>,
    value: Value,
    physical: String,
    formula: &str,
    equation: &str,
    inputs: String,
) -> Constant {
    Constant {
        name: name.into(),
        value,
        physical,
        formula: formula.into(),
        equation: equation.into(),
        inputs,
        json_path: String::new(),
    }
}

impl Constant {
    fn at(mut self, json_path: impl Into<String>) -> Constant {
        self.json_path = json_path.into();
        self
    }
}

/// All constants of `d`, grouped: current loop, observer, scalings, filter, limits.
pub fn constants(d: &Design) -> Vec<Group> {
    let m = &d.motor;
    // The provenance label, with the conversion from the datasheet's form where there was one.
    let pv = |k: &str| {
        let o = m.provenance.get(k);
        match o.and_then(|o| o.note.as_deref()).filter(|n| n.starts_with("converted")) {
            Some(n) => format!("{}, {n}", prov(o)),
            None => prov(o).to_string(),
        }
    };
    let r_in = format!(
        "R_s = {} ({})",
        phys(m.phase_resistance_ohm, "Ω"),
        pv("phase_resistance")
    );
    let ld_in = format!("L_d = {} ({})", phys(m.d_inductance_h, "H"), pv("d_inductance"));
    let lq_in = format!("L_q = {} ({})", phys(m.q_inductance_h, "H"), pv("q_inductance"));
    let cl = &d.current_loop;
    let alpha_in = format!("α = {} (spec)", phys(cl.bandwidth_rad_s, "rad/s"));
    let fs = d.drive.switching_frequency_hz;
    let fs_in = format!("f_s = {} (spec)", phys(fs, "Hz"));

    let mut current = Vec::new();
    for (axis, g, l_in) in [("D", &cl.d, &ld_in), ("Q", &cl.q, &lq_in)] {
        let j = |field: &str| format!("/current_loop/{}/{field}", axis.to_lowercase());
        let (kp_f, ki_f, eq) = match cl.method {
            crate::spec::Method::Imc => ("K_p = K_a = L·α", "K_i = K_a·K_b = R·α", "thesis A (5.9), (5.7)"),
            crate::spec::Method::PolePlacement => ("K_p = 2ζω_n·L − R", "K_i = L·ω_n²", "thesis A (5.14), (5.15)"),
            crate::spec::Method::ImcActiveDamping => ("k_p = α_c·L", "k_i = α_c·(R + R_a)", "thesis B (2.38), (2.39)"),
        };
        let alpha_axis = if cl.compensate_delay {
            format!(
                "α = {} (delay-compensated from {alpha_in}: the sampled loop with 1.5·T_s delay rises in ln 9/α_spec)",
                phys(g.bandwidth_rad_s, "rad/s")
            )
        } else {
            alpha_in.clone()
        };
        let ins = format!(
            "{l_in}, {r_in}, {alpha_axis}{}",
            cl.damping.map_or(String::new(), |z| format!(", ζ = {z} (spec)"))
        );
        current.push(
            c(
                format!("{axis}_KP"),
                f32v(g.kp),
                phys(g.kp, "V/A"),
                kp_f,
                eq,
                format!("{ins}; {}", g.sampled.describe()),
            )
            .at(j("kp")),
        );
        current.push(
            c(
                format!("{axis}_KI"),
                f32v(g.ki),
                phys(g.ki, "V/(A·s)"),
                ki_f,
                eq,
                ins.clone(),
            )
            .at(j("ki")),
        );
        current.push(
            c(
                format!("{axis}_KI_TS"),
                f32v(g.ki_ts),
                phys(g.ki_ts, "V/A"),
                "K_i·T_s (forward-difference integrator)",
                "thesis A (4.17b)",
                format!("{ins}, {fs_in}"),
            )
            .at(j("ki_ts")),
        );
        current.push(
            c(
                format!("{axis}_KB"),
                f32v(g.kb),
                phys(g.kb, "rad/s"),
                "K_b = K_i/K_p (series-form zero)",
                "thesis A (5.7)",
                ins.clone(),
            )
            .at(j("kb")),
        );
        current.push(
            c(
                format!("{axis}_ACTIVE_DAMPING"),
                f32v(g.active_damping_ohm),
                phys(g.active_damping_ohm, "Ω"),
                "R_a = α_c·L − R (0 unless imc_active_damping)",
                "thesis B (2.43)",
                ins.clone(),
            )
            .at(j("active_damping_ohm")),
        );
        current.push(
            c(
                format!("{axis}_ANTI_WINDUP"),
                f32v(g.anti_windup_gain),
                phys(g.anti_windup_gain, "A/V"),
                "1/k_p in dI/dt = e + (ū − u)/k_p",
                "thesis B (2.49)",
                ins.clone(),
            )
            .at(j("anti_windup_gain")),
        );
        current.push(
            c(
                format!("{axis}_PREFILTER"),
                f32v(g.reference_filter),
                phys(g.reference_filter, ""),
                match g.prefilter {
                    Some(_) => "a = 1 − exp(−T_s·K_i/K_p): y += a·(x − y)",
                    None => "y += a·(x − y) with a = 1, no prefilter: this method's closed loop has no zero to cancel",
                },
                "thesis A (5.16)",
                format!("{ins}, {fs_in}"),
            )
            .at(j("reference_filter")),
        );
    }
    let ff = &cl.feedforward;
    current.push(
        c(
            "FF_LD",
            f32v(ff.d_inductance_h),
            phys(ff.d_inductance_h, "H"),
            "L_d in u_q,ff = ω_e(L_d·i_d + ψ_M)",
            "thesis A (5.3)",
            ld_in.clone(),
        )
        .at("/current_loop/feedforward/d_inductance_h"),
    );
    current.push(
        c(
            "FF_LQ",
            f32v(ff.q_inductance_h),
            phys(ff.q_inductance_h, "H"),
            "L_q in u_d,ff = −ω_e·L_q·i_q",
            "thesis A (5.3)",
            lq_in.clone(),
        )
        .at("/current_loop/feedforward/q_inductance_h"),
    );
    let psi = ff.flux_linkage_wb.unwrap_or(0.0);
    let psi_in = ff
        .flux_linkage_wb
        .map_or("ψ_M unknown → 0 (term omitted)".to_string(), |p| {
            format!("ψ_M = {} ({})", phys(p, "Wb"), pv("flux_linkage"))
        });
    current.push(
        c(
            "FF_PSI",
            f32v(psi),
            phys(psi, "Wb"),
            "ψ_M in the back-EMF term ω_e·ψ_M",
            "thesis A (5.3)",
            psi_in.clone(),
        )
        .at("/current_loop/feedforward/flux_linkage_wb"),
    );
    let iq_per_nm = ff.iq_per_nm.unwrap_or(0.0);
    current.push(
        c(
            "IQ_PER_NM",
            f32v(iq_per_nm),
            phys(iq_per_nm, "A/(N·m)"),
            "1/K_t, K_t = 3/2·n_p·ψ_M (0 if ψ_M unknown)",
            "thesis A (2.34)",
            format!("n_p = {} (datasheet), {psi_in}", m.pole_pairs),
        )
        .at("/current_loop/feedforward/iq_per_nm"),
    );

    let o = &d.angle_observer;
    let obs_in = format!(
        "ω_n = {} (spec), ζ = {} (spec)",
        phys(o.natural_frequency_rad_s, "rad/s"),
        o.damping
    );
    let norm = match o.error {
        crate::spec::ObserverError::TrigIdentity => "π",
        crate::spec::ObserverError::Atan2 => "1 (atan2 error already normalised by π)",
    };
    let mut observer = vec![
        c(
            "KP",
            q31v(o.gains.kp_q31),
            phys(o.gains.kp_scaled, ""),
            &format!("K̃_p = 2ζω_n/(f_s·{norm}), Q1.31"),
            "thesis A (4.15), (4.22)",
            format!("{obs_in}, {fs_in}"),
        )
        .at("/angle_observer/kp_q31"),
        c(
            "KI",
            q31v(o.gains.ki_q31),
            phys(o.gains.ki_scaled, ""),
            &format!("K̃_i = ω_n²/(f_s²·{norm}), Q1.31"),
            "thesis A (4.15), (4.22)",
            format!("{obs_in}, {fs_in}"),
        )
        .at("/angle_observer/ki_q31"),
        c(
            "MOTOR_POLE_PAIRS",
            intv(i64::from(o.motor_pole_pairs), "u32", "uint32_t"),
            o.motor_pole_pairs.to_string(),
            "n_p",
            "thesis A (4.5)",
            "n_p (datasheet)".into(),
        )
        .at("/angle_observer/motor_pole_pairs"),
        c(
            "RESOLVER_POLE_PAIRS",
            intv(i64::from(o.resolver_pole_pairs), "u32", "uint32_t"),
            o.resolver_pole_pairs.to_string(),
            "n_r",
            "thesis A (4.5)",
            "n_r (spec [resolver])".into(),
        )
        .at("/angle_observer/resolver_pole_pairs"),
        c(
            "LEAD_Q16",
            intv(i64::from(o.lead_q16), "i32", "int32_t"),
            phys(o.lead_samples, "samples"),
            "k in Q16.16: θ_e,lead = θ_e + (ω_e^i·LEAD) >> 16",
            "thesis A (4.19), (4.23)",
            match o.lead_samples_source {
                Provenance::Default => {
                    format!("k = {} samples (default: 1.5·T_s delay, thesis A §4.6)", o.lead_samples)
                }
                _ => format!("k = {} samples (spec angle_observer.lead_samples)", o.lead_samples),
            },
        )
        .at("/angle_observer/lead_q16"),
    ];
    let offset_rad = o.resolver_offset_rad.unwrap_or(0.0);
    observer.push(
        c(
            "RESOLVER_OFFSET",
            q31v(o.resolver_offset_q31.unwrap_or(0)),
            format!("{} = {}°", phys(offset_rad, "rad"), phys(offset_rad.to_degrees(), "")),
            "θ_off/π wrapped into ±π, Q1.31 (0 until identified at commissioning, (6.9))",
            "thesis A (4.5), (6.9)",
            match o.resolver_offset_rad {
                Some(_) => format!("θ_off ({})", prov(m.provenance.get("resolver_offset"))),
                None => "θ_off not in the spec: 0".into(),
            },
        )
        .at("/angle_observer/resolver_offset_q31"),
    );
    observer.push(
        c(
            "ERROR_FORM",
            intv(i64::from(o.error_form), "u8", "uint8_t"),
            match o.error {
                crate::spec::ObserverError::TrigIdentity => "0: trig identity".into(),
                crate::spec::ObserverError::Atan2 => "1: atan2".into(),
            },
            "error architecture KP/KI are scaled for: 0 = sin θ_r cos θ̂ − cos θ_r sin θ̂, 1 = atan2/π",
            "thesis A (4.8)–(4.10), (4.22)",
            "angle_observer.error (spec)".into(),
        )
        .at("/angle_observer/error_form"),
    );

    let s = &d.scaling;
    let mut scalings = Vec::new();
    for (prefix, key, sc, what) in [
        ("CURRENT", "phase_current", &s.phase_current, "phase current"),
        ("VOLTAGE", "phase_voltage", &s.phase_voltage, "phase voltage"),
        ("DC_LINK", "dc_link_voltage", &s.dc_link_voltage, "DC-link voltage"),
        ("ANGLE", "angle", &s.angle, "angle"),
        ("SPEED", "speed", &s.speed, "observer speed"),
        ("OBSERVER_ERROR", "observer_error", &s.observer_error, "observer error"),
    ] {
        scalings.push(
            c(
                format!("{prefix}_FULL_SCALE"),
                f32v(sc.full_scale),
                phys(sc.full_scale, sc.unit),
                &format!("A of {what}: {}", sc.rule),
                "thesis A (4.16), (4.20), Table 4.1",
                format!("{} (spec)", sc.q_format),
            )
            .at(format!("/scaling/{key}/full_scale")),
        );
        scalings.push(
            c(
                format!("{prefix}_PER_LSB"),
                f32v(sc.si_per_lsb),
                phys(sc.si_per_lsb, sc.unit),
                &format!("A/2^{} ({})", sc.fractional_bits, sc.q_format),
                "thesis A (4.16)",
                format!("A = {}", phys(sc.full_scale, sc.unit)),
            )
            .at(format!("/scaling/{key}/si_per_lsb")),
        );
    }

    let f = &d.fir;
    let fir_in = format!(
        "order {}, pass band 0–{} with ripple ≤ {}, stop band {}–f_s/2, {fs_in}; achieved (Q1.15): ripple {:.2e}, attenuation {:.1} dB",
        f.order,
        phys(f.pass_edge_hz, "Hz"),
        f.pass_ripple,
        phys(f.stop_edge_hz, "Hz"),
        f.pass_ripple_quantised,
        f.stop_attenuation_db_quantised
    );
    let filter = vec![
        c(
            "TAPS_Q15",
            i16_array(&f.taps_q15),
            format!("{} taps, Σ = 32768 (DC gain 1)", f.taps_q15.len()),
            "equiripple low-pass (Parks–McClellan), Q1.15, symmetric",
            "thesis A §6.2",
            fir_in.clone(),
        )
        .at("/fir/taps_q15"),
        c(
            "ORDER",
            intv(f.order as i64, "usize", "uint32_t"),
            f.order.to_string(),
            "N − 1",
            "thesis A §6.2",
            fir_in.clone(),
        )
        .at("/fir/order"),
        c(
            "GROUP_DELAY_SAMPLES",
            f32v(f.group_delay_samples),
            phys(f.group_delay_samples, "samples"),
            "order/2 (linear phase)",
            "thesis A §6.2",
            fir_in.clone(),
        )
        .at("/fir/group_delay_samples"),
    ];

    let md = &d.modulation;
    let mut limits = vec![
        c(
            "SWITCHING_FREQUENCY_HZ",
            f32v(fs),
            phys(fs, "Hz"),
            "f_s = sampling frequency",
            "thesis A (1.1)",
            fs_in.clone(),
        )
        .at("/drive/switching_frequency_hz"),
        c(
            "SAMPLE_PERIOD_S",
            f32v(d.drive.sample_period_s),
            phys(d.drive.sample_period_s, "s"),
            "T_s = 1/f_s",
            "thesis A (4.17)",
            fs_in.clone(),
        )
        .at("/drive/sample_period_s"),
        c(
            "VOLTAGE_LIMIT_V",
            f32v(cl.voltage_limit_v),
            phys(cl.voltage_limit_v, "V"),
            "U_dc/√3 (voltage circle)",
            "thesis B (2.50)",
            format!("U_dc = {} (spec)", phys(d.drive.dc_link_voltage_v, "V")),
        )
        .at("/current_loop/voltage_limit_v"),
        c(
            "DC_LINK_MIN_V",
            f32v(d.drive.dc_link_voltage_min_v),
            phys(d.drive.dc_link_voltage_min_v, "V"),
            "lowest U_dc for the 1/U_dc feed-forward (5.1)",
            "thesis A (5.1)",
            "spec".into(),
        )
        .at("/drive/dc_link_voltage_min_v"),
        c(
            "THPWM_COMMON_MODE",
            f32v(md.thpwm_common_mode_ratio),
            phys(md.thpwm_common_mode_ratio, ""),
            "u_NM/U_dc amplitude 1/(6√3)",
            "thesis A (3.7)",
            "—".into(),
        )
        .at("/modulation/thpwm_common_mode_ratio"),
        c(
            "PEAK_CURRENT_A",
            f32v(m.peak_current_a),
            phys(m.peak_current_a, "A"),
            "√2·I_peak,rms (current-circle radius)",
            "thesis B (2.51)",
            format!(
                "I_peak = {} rms ({})",
                phys(m.peak_current_a_rms, "A"),
                pv("peak_current")
            ),
        )
        .at("/motor/peak_current_a"),
        c(
            "MAX_ELECTRICAL_SPEED",
            f32v(m.max_electrical_speed_rad_s),
            phys(m.max_electrical_speed_rad_s, "rad/s"),
            "ω_e,max = n_p·ω_m,max",
            "thesis A (2.19)",
            format!("n_max ({})", pv("max_speed")),
        )
        .at("/motor/max_electrical_speed_rad_s"),
        c(
            "ADC_SETTLING_TIME_CONSTANTS",
            intv(i64::from(d.adc.settling_multiple), "u32", "uint32_t"),
            d.adc.settling_multiple.to_string(),
            "⌈−ln 2^−N⌉",
            "thesis A (7.4)",
            format!("N = {} bits", d.adc.resolution_bits),
        )
        .at("/adc/settling_multiple"),
    ];
    if let Some(t) = &d.adc.sample_time {
        limits.push(
            c(
                "ADC_SMP_CODE",
                intv(i64::from(t.smp_code), "u8", "uint8_t"),
                format!("{} cycles = {}", t.cycles, phys(t.sample_time_s, "s")),
                "smallest STM32G4 SMP ≥ multiple·(R_ADC + R_EXT)·C_ADC",
                "thesis A (7.2), (7.4)",
                "adc section (spec)".into(),
            )
            .at("/adc/sample_time/smp_code"),
        );
    }

    vec![
        Group {
            name: "current_loop",
            title: "Current loop: PI gains per axis, feed-forward, torque → i_q",
            constants: current,
        },
        Group {
            name: "observer",
            title: "Angle tracking observer (Q1.31) and resolver → electrical angle",
            constants: observer,
        },
        Group {
            name: "scaling",
            title: "Per-unit fixed-point scalings (full scale A and SI per LSB)",
            constants: scalings,
        },
        Group {
            name: "filter",
            title: "Identification FIR low-pass for the FMAC",
            constants: filter,
        },
        Group {
            name: "limits",
            title: "Sampling, voltage and current limits, modulator and ADC",
            constants: limits,
        },
        field_weakening::group(d),
        sensorless::group(d),
    ]
    .into_iter()
    .chain(board::group(d))
    .chain(can::group(d))
    .chain(can::commissioning_group(d))
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn well_known_floats_are_named_not_written_out() {
        assert_eq!(f32v(std::f64::consts::PI).rust_expr, "::core::f32::consts::PI");
        assert_eq!(
            f32v(std::f64::consts::FRAC_1_SQRT_2).rust_expr,
            "::core::f32::consts::FRAC_1_SQRT_2"
        );
        // The C header keeps the literal; π as f32 is 3.1415927 (0x40490FDB).
        assert_eq!(f32v(std::f64::consts::PI).c_expr, "3.1415927f");
        // A value one f32 ulp off π is an ordinary literal.
        assert_eq!(f32v(f64::from(f32::from_bits(0x4049_0FDC))).rust_expr, "3.141593");
        assert_eq!(f32v(3.0).rust_expr, "3.0");
    }

    /// Integer scalars are C integer constant expressions (C99 §7.18.4.1): the stdint
    /// macro takes an unsigned literal, the minimum is the named limit.
    #[test]
    fn c_integers_are_constant_expressions() {
        assert_eq!(intv(5, "u32", "uint32_t").c_expr, "UINT32_C(5)");
        assert_eq!(intv(-7, "i32", "int32_t").c_expr, "(-INT32_C(7))");
        assert_eq!(intv(i64::from(i32::MIN), "i32", "int32_t").c_expr, "INT32_MIN");
        assert_eq!(q31v(i32::MIN).c_expr, "INT32_MIN");
        assert_eq!(q31v(1 << 30).c_expr, "INT32_C(1073741824)");
        assert_eq!(intv(12, "u8", "uint8_t").c_expr, "UINT8_C(12)");
        assert_eq!(i16_array(&[1, -2]).c_len, Some(2));
    }
}
