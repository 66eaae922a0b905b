//! The spec → design path at the library level ([`codegen::design_source`]): every bad
//! spec fails with located diagnostics — file:line:column, the key, what is wrong and
//! what would be accepted — checked twice: against the test's own locator and words,
//! and as the exact rendered text against a reviewed snapshot in `tests/diagnostics/`.
//! (The CLI tests only check exit codes and I/O; they print these same messages.)
//!
//! To accept an intended change of the messages:
//! `UPDATE_SNAPSHOTS=1 cargo test -p codegen --test spec`, then review
//! `git diff codegen/tests/diagnostics/`.

use motor_test_support::repo;

use std::path::Path;

fn fischer() -> String {
    std::fs::read_to_string(repo().join("motors/fischer-ti085.toml")).unwrap()
}

/// 1-based line of the first occurrence of `needle` in `text` (the test's own locator).
fn line_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).unwrap_or_else(|| panic!("{needle:?} not in spec"));
    text[..at].matches('\n').count() + 1
}

/// Designs `text` as `<name>.toml` and asserts a located failure: a problem at
/// `line`, naming `key` (if not empty), saying what is accepted and each of `words`;
/// the whole message equals the snapshot `tests/diagnostics/<name>.txt`.
fn fails(name: &str, text: &str, line: usize, key: &str, words: &[&str]) {
    let file = format!("{name}.toml");
    let rendered = match codegen::design_source(&file, text) {
        Ok(_) => panic!("{name}: designed without error"),
        Err(e) => e.to_string(),
    };
    let loc = format!("error: {file}:{line}:");
    assert!(rendered.contains(&loc), "{name}: expected {loc} in\n{rendered}");
    if !key.is_empty() {
        assert!(
            rendered.contains(&format!("`{key}`")),
            "{name}: expected key `{key}` in\n{rendered}"
        );
    }
    assert!(rendered.contains("accepted: "), "{name}: no 'accepted' in\n{rendered}");
    for w in words {
        assert!(rendered.contains(w), "{name}: expected {w:?} in\n{rendered}");
    }
    let snapshot = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/diagnostics")
        .join(format!("{name}.txt"));
    if std::env::var_os("UPDATE_SNAPSHOTS").is_some() {
        std::fs::create_dir_all(snapshot.parent().unwrap()).unwrap();
        std::fs::write(&snapshot, &rendered).unwrap();
    } else {
        let want = std::fs::read_to_string(&snapshot).unwrap_or_else(|e| {
            panic!(
                "{}: {e}; if new: UPDATE_SNAPSHOTS=1 cargo test -p codegen --test spec",
                snapshot.display()
            )
        });
        assert_eq!(
            rendered, want,
            "{name}: the message differs from its snapshot; if intended: UPDATE_SNAPSHOTS=1 cargo test -p codegen --test spec"
        );
    }
}

/// Replaces `from` (which must occur) by `to` and returns the new text and the line of the change.
fn mutate(from: &str, to: &str) -> (String, usize) {
    let text = fischer();
    assert!(text.contains(from), "{from:?}");
    let new = text.replacen(from, to, 1);
    let line = line_of(&new, to.lines().next().unwrap_or(to));
    (new, line)
}

#[test]
fn empty_file() {
    fails("empty", "", 1, "", &["empty"]);
}

#[test]
fn syntax_error() {
    let (t, line) = mutate("pole_pairs = 4 ", "pole_pairs = = 4 ");
    fails("syntax", &t, line, "", &["TOML syntax error"]);
}

#[test]
fn unknown_key_typo() {
    let (t, line) = mutate("inductance = \"0.393 mH\"", "inductanse = \"0.393 mH\"");
    fails(
        "typo",
        &t,
        line,
        "motor.datasheet.inductanse",
        &["unknown key `inductanse`", "phase_resistance"],
    );
}

#[test]
fn missing_key_and_section() {
    let (t, _) = mutate("error = \"trig_identity\"", "");
    let line = line_of(&t, "[angle_observer]");
    fails(
        "missing_key",
        &t,
        line,
        "angle_observer.error",
        &["missing required key"],
    );
    let text = fischer();
    let start = text.find("[fir]").unwrap();
    let t = &text[..start];
    fails("missing_section", t, 1, "fir", &["missing required key `fir`"]);
    let (t, _) = mutate("max_speed = \"20000 rpm\"", "");
    let line = line_of(&t, "[motor]");
    fails(
        "missing_motor_key",
        &t,
        line,
        "motor.datasheet.max_speed",
        &["missing required key `max_speed`"],
    );
}

#[test]
fn wrong_dimension_and_bare_number() {
    let (t, line) = mutate("inductance = \"0.393 mH\"", "inductance = \"0.393 mA\"");
    fails(
        "dimension",
        &t,
        line,
        "motor.datasheet.inductance",
        &["not an inductance", "mH"],
    );
    let (t, line) = mutate("inductance = \"0.393 mH\"", "inductance = 0.000393");
    fails(
        "bare",
        &t,
        line,
        "motor.datasheet.inductance",
        &["bare number", "never taken as SI"],
    );
}

#[test]
fn non_positive_and_non_finite() {
    let (t, line) = mutate("phase_resistance = \"0.126 Ω\"", "phase_resistance = \"-0.126 Ω\"");
    fails(
        "negative_r",
        &t,
        line,
        "motor.datasheet.phase_resistance",
        &["greater than zero"],
    );
    let (t, line) = mutate("inductance = \"0.393 mH\"", "inductance = \"0 mH\"");
    fails("zero_l", &t, line, "motor.datasheet.inductance", &["greater than zero"]);
    let (t, line) = mutate("value = \"0.296 V·s/rad\"", "value = \"-0.296 V·s/rad\"");
    fails(
        "negative_psi",
        &t,
        line,
        "motor.datasheet.back_emf_constant.value",
        &["greater than zero"],
    );
    let (t, line) = mutate("peak_current = \"61 A\"", "peak_current = \"NaN A\"");
    fails(
        "nan",
        &t,
        line,
        "motor.datasheet.peak_current",
        &["not a finite number"],
    );
    let (t, line) = mutate("peak_current = \"61 A\"", "peak_current = \"inf A\"");
    fails(
        "inf",
        &t,
        line,
        "motor.datasheet.peak_current",
        &["not a finite number"],
    );
    let (t, line) = mutate("damping = 1.0", "damping = nan");
    fails("nan_number", &t, line, "angle_observer.damping", &["out of range"]);
}

#[test]
fn pole_pairs_must_be_positive_whole() {
    let (t, line) = mutate("pole_pairs = 4 ", "pole_pairs = 4.5 ");
    fails("fractional_pp", &t, line, "motor.pole_pairs", &["not a whole number"]);
    let (t, line) = mutate("pole_pairs = 4 ", "pole_pairs = 0 ");
    fails("zero_pp", &t, line, "motor.pole_pairs", &["out of range"]);
}

#[test]
fn conflicting_inductance_forms() {
    let (t, line) = mutate(
        "inductance = \"0.393 mH\"",
        "inductance = \"0.393 mH\"\nd_inductance = \"0.4 mH\"\nq_inductance = \"0.4 mH\"",
    );
    fails(
        "conflict",
        &t,
        line + 1,
        "motor.datasheet.d_inductance",
        &["conflicting inductance forms"],
    );
}

#[test]
fn unknown_method_and_observer_error() {
    let (t, line) = mutate("method = \"imc\"", "method = \"pid\"");
    fails(
        "method",
        &t,
        line,
        "current_loop.method",
        &["`pid` is not a known value", "pole_placement"],
    );
    let (t, line) = mutate("error = \"trig_identity\"", "error = \"cordic\"");
    fails(
        "observer_error",
        &t,
        line,
        "angle_observer.error",
        &["`cordic`", "atan2"],
    );
}

#[test]
fn fir_requests_out_of_bounds() {
    let (t, line) = mutate("stop_edge = \"2 kHz\"", "stop_edge = \"50 Hz\"");
    fails("fir_order", &t, line, "fir.stop_edge", &["pass_edge < stop_edge"]);
    let (t, line) = mutate("stop_edge = \"2 kHz\"", "stop_edge = \"12 kHz\"");
    fails("fir_nyquist", &t, line, "fir.stop_edge", &["Nyquist"]);
    let (t, _) = mutate("order = 20", "");
    let line = line_of(&t, "[fir]");
    fails(
        "fir_no_length",
        &t,
        line,
        "fir.order",
        &["neither `order` nor `stop_attenuation`"],
    );
    let (t, line) = mutate("order = 20", "order = 200");
    fails("fir_too_long", &t, line, "fir.order", &["127 taps"]);
}

#[test]
fn observer_gain_overflows_q31() {
    // K̃_p = 2·1·70 000/(20 000·π) = 2.23 ≥ 1.
    let (t, line) = mutate(
        "natural_frequency = \"70 rad/s\"",
        "natural_frequency = \"70000 rad/s\"",
    );
    fails(
        "q31",
        &t,
        line,
        "angle_observer.natural_frequency",
        &["does not fit Q1.31"],
    );
}

#[test]
fn design_rules_are_located_errors() {
    // Pole placement at 100 rad/s: RHP zero for Fischer (R/(2L) = 160 rad/s), smallest α = 226.7 rad/s.
    let (t, line) = mutate("method = \"imc\"", "method = \"pole_placement\"\ndamping = 0.7071");
    let _ = line;
    let line = line_of(&t, "bandwidth = ");
    fails(
        "rhp",
        &t,
        line,
        "current_loop.bandwidth",
        &["right-half-plane zero", "226."],
    );
    // Delay-compensated IMC at α = 40 000 rad/s (α·T_s = 2) breaks the phase-margin floor.
    let (t, line) = mutate("bandwidth = \"100 rad/s\"", "bandwidth = \"40000 rad/s\"");
    fails(
        "bandwidth",
        &t,
        line,
        "current_loop.bandwidth",
        &[
            "phase margin",
            "< 45°",
            "delay-compensated",
            "accepted: a bandwidth up to",
        ],
    );
    // f_s ≥ 12·1333 Hz = 16 kHz.
    let (t, line) = mutate("switching_frequency = \"20 kHz\"", "switching_frequency = \"15 kHz\"");
    fails("fs", &t, line, "drive.switching_frequency", &["12·f_e,max", "16000"]);
    // Sensorless: ρ ≤ α_c/10 = 10 rad/s for Fischer (thesis B Table 4.1).
    let section = |body: &str| mutate("[fir]", &format!("[sensorless]\n{body}\n\n[fir]"));
    let (t, _) = section("bandwidth = \"50 rad/s\"");
    let line = line_of(&t, "bandwidth = \"50");
    fails("rho", &t, line, "sensorless.bandwidth", &["α_c/10", "10.0 rad/s"]);
    // (4.74): ρ = √(n_p·a/sin 10°) ≤ 10 rad/s ⇔ a ≤ 10²·0.17365/4 = 4.34 rad/s² = 41 rpm/s.
    let (t, _) = section("max_acceleration = \"5000 rpm/s\"");
    let line = line_of(&t, "max_acceleration");
    fails(
        "accel",
        &t,
        line,
        "sensorless.max_acceleration",
        &["(4.74)", "4.3 rad/s²", "41 rpm/s"],
    );
    let (t, _) = section("bandwidth = \"5 rad/s\"\nmax_acceleration = \"10 rpm/s\"");
    let line = line_of(&t, "bandwidth = \"5");
    fails("both", &t, line, "sensorless.bandwidth", &["both", "max_acceleration"]);
    let (t, _) = section("max_angle_error = \"95 °\"");
    let line = line_of(&t, "max_angle_error");
    fails("angle", &t, line, "sensorless.max_angle_error", &["90°", "\"10 °\""]);
    let (t, _) = section("max_angle_error = \"10 m\"");
    let line = line_of(&t, "max_angle_error");
    fails(
        "angle_unit",
        &t,
        line,
        "sensorless.max_angle_error",
        &["not an angle", "°, deg, rad"],
    );
}

/// `[field_weakening]`, `[losses]` and the α_fw ≪ α_c rule (thesis B §2.3.3): each bad
/// value is reported at its key with what is accepted.
#[test]
fn field_weakening_and_losses_keys() {
    let with = |extra: &str| {
        let text = format!("{}\n{extra}\n", fischer());
        let line = line_of(&text, extra.lines().last().unwrap());
        (text, line)
    };
    let (t, line) = with("[field_weakening]\nvoltage_fraction = 1.2");
    fails(
        "fw_fraction",
        &t,
        line,
        "field_weakening.voltage_fraction",
        &["out of range", "below 1", "Fig. 2.15"],
    );
    let (t, line) = with("[field_weakening]\nvoltage_fraction = \"0.9\"");
    fails(
        "fw_fraction_string",
        &t,
        line,
        "field_weakening.voltage_fraction",
        &["plain number"],
    );
    let (t, line) = with("[field_weakening]\nspeed_loop_bandwidth = 5");
    fails(
        "fw_speed_bare",
        &t,
        line,
        "field_weakening.speed_loop_bandwidth",
        &["bare number", "rad/s"],
    );
    // Fischer α_c = 100 rad/s: α_fw = 10·5 = 50 rad/s > α_c/5 = 20 rad/s; α_s ≤ 2 rad/s.
    let (t, line) = with("[field_weakening]\nspeed_loop_bandwidth = \"5 rad/s\"");
    fails(
        "fw_speed_fast",
        &t,
        line,
        "field_weakening.speed_loop_bandwidth",
        &["α_fw = 10·α_s = 50.0 rad/s", "α_c/5", "at most 2.00 rad/s"],
    );
    let (t, line) = with("[field_weakening]\nvoltage_fractoin = 0.9");
    fails(
        "fw_typo",
        &t,
        line,
        "field_weakening.voltage_fractoin",
        &["unknown key", "`voltage_fraction`"],
    );
    let (t, line) = with("[losses]\ninclude_inverter = true");
    fails(
        "losses_no_inverter",
        &t,
        line,
        "losses.include_inverter",
        &["no [inverter] section", "include_inverter = false"],
    );
    let (t, line) = with("[losses]\ncore_resistance = \"-3 Ω\"");
    fails(
        "losses_negative",
        &t,
        line,
        "losses.core_resistance",
        &["greater than zero"],
    );
    let (t, line) = with("[losses]\ncore_resistance = \"24.5 mH\"");
    fails("losses_unit", &t, line, "losses.core_resistance", &["Ω"]);
    // Torque control with J and b: α_fw = 10·b/J = 10·(0.01/0.001) = 100 rad/s > 20 rad/s.
    let (t, _) = mutate(
        "inductance = \"0.393 mH\"",
        "inductance = \"0.393 mH\"\ninertia = \"0.001 kg·m²\"\nviscous_friction = \"0.01 N·m·s/rad\"",
    );
    let line = line_of(&t, "inertia = ");
    fails(
        "fw_mechanics_fast",
        &t,
        line,
        "motor.datasheet.inertia",
        &["α_fw = 10·b/J", "α_c/5"],
    );
}

/// The field-weakening design in the JSON: the defaults of thesis B Fig. 2.15, and the
/// torque-control rule α_fw = 10·b/J when J and b are given (hand values for Fischer:
/// α_c = 100 rad/s → α_s = 1 rad/s, α_fw = 10 rad/s; b/J = 0.0005/0.001 = 0.5 s⁻¹ →
/// α_fw = 5 rad/s).
#[test]
fn field_weakening_rules_in_the_design() {
    let design = |text: &str, name: &str| {
        let d = codegen::design_source(name, text).unwrap_or_else(|e| panic!("{name}: {e}"));
        serde_json::to_value(&d).unwrap()["field_weakening"].clone()
    };
    let fw = design(&fischer(), "fw_default.toml");
    assert_eq!(fw["bandwidth_rule"], "default_speed_loop");
    assert_eq!(fw["bandwidth_rad_s"].as_f64(), Some(10.0));
    assert_eq!(fw["voltage_fraction"].as_f64(), Some(0.9));
    assert!(fw["loss_minimisation"].is_null());
    let (t, _) = mutate(
        "inductance = \"0.393 mH\"",
        "inductance = \"0.393 mH\"\ninertia = \"0.001 kg·m²\"\nviscous_friction = \"0.0005 N·m·s/rad\"",
    );
    // With J given, the drive's acceleration defaults to peak torque / J = 29 100 rad/s²
    // (the unloaded rotor), which no field-weakening loop at α_fw = 5 rad/s follows: set
    // the application's 2000 rpm/s (Fischer's default, 20 000 rpm in 10 s).
    let t = t.replace(
        "dc_link_voltage_min = \"432 V\"",
        "dc_link_voltage_min = \"432 V\"\nmax_acceleration = \"2000 rpm/s\"",
    );
    let fw = design(&t, "fw_mechanics.toml");
    assert_eq!(fw["bandwidth_rule"], "mechanical");
    assert!((fw["bandwidth_rad_s"].as_f64().unwrap() - 5.0).abs() < 1e-9);
    let fw = design(
        &format!("{}\n[field_weakening]\nvoltage_fraction = 0.85\n", fischer()),
        "fw_085.toml",
    );
    assert_eq!(fw["voltage_fraction"].as_f64(), Some(0.85));
}

/// The summary carries the thesis-B rules. Hand check for the Chalmers spec
/// (α_c = 1470 rad/s, thesis B Table B.2): ρ = α_c/10 = 147 rad/s, γ1 = ρ² = 21609,
/// γ2 = 2ρ = 294 (4.7); V'_max = 0.9·V_max.
#[test]
fn summary_shows_field_weakening_and_sensorless() {
    let design = |stem: &str| {
        let file = format!("motors/{stem}.toml");
        let text = std::fs::read_to_string(repo().join(&file)).unwrap();
        codegen::summary::summary(&codegen::design_source(&file, &text).unwrap())
    };
    let s = design("chalmers-hev50");
    for needle in [
        "field weakening: V'_max = 0.9 V_max",
        "ρ = 147.0 rad/s",
        "γ1 = ρ² = 21609.0 1/s², γ2 = 2ρ = 294.0 1/s (4.7)",
        "K_p = 2ζω_n = 140 1/s, K_i = ω_n² = 4900 1/s² (4.15)",
        "ω_min2 = 65.9 (4.69, i_d = -99.56 A at I_base)",
        "17-point MTPA table",
    ] {
        assert!(s.contains(needle), "{needle:?} not in\n{s}");
    }
    // Fischer has no [sensorless] section (a resolver drive): no estimator at all.
    let s = design("fischer-ti085");
    assert!(!s.contains("sensorless:") && !s.contains("injection"), "{s}");
}

/// A misspelt key names the nearest accepted key (strsim), not only the whole list.
#[test]
fn unknown_key_suggests_the_nearest() {
    let (t, line) = mutate("phase_resistance = \"0.126 Ω\"", "phase_resistence = \"0.126 Ω\"");
    fails(
        "typo_nearest",
        &t,
        line,
        "motor.datasheet.phase_resistence",
        &["unknown key `phase_resistence`: did you mean `phase_resistance`?"],
    );
}

/// Datasheet forms that cannot be converted say so at their key: an rms back-EMF constant
/// without `measured` (line to line and phase differ by √3), an unknown `measured`, and
/// a quantity of the wrong dimension inside a compound unit.
#[test]
fn datasheet_forms_are_located_errors() {
    let (t, line) = mutate(
        "back_emf_constant = { value = \"0.296 V·s/rad\", voltage = \"rms\", measured = \"line_to_line\", speed = \"mechanical\" }",
        "back_emf_constant = { value = \"0.296 V·s/rad\", voltage = \"rms\", speed = \"mechanical\" }",
    );
    fails(
        "emf_measured",
        &t,
        line,
        "motor.datasheet.back_emf_constant.measured",
        &["differ by √3", "line_to_line"],
    );
    let (t, line) = mutate(
        "phase_resistance = \"0.126 Ω\"",
        "phase_resistance = { value = \"0.252 Ω\", measured = \"terminal\" }",
    );
    fails(
        "r_measured",
        &t,
        line,
        "motor.datasheet.phase_resistance.measured",
        &["\"line_to_line\", \"phase\" or \"winding\""],
    );
    let (t, line) = mutate("\"0.492 N·m/A\"", "\"492 mN·m/V\"");
    fails(
        "kt_unit",
        &t,
        line,
        "motor.datasheet.torque_constant.value",
        &["is not a torque constant", "mN·m/A"],
    );
}

/// Thesis B's motor without its rated current: the estimator needs I_base = √2·I_n and
/// says so at the key that gives it (issue 13: no silent fallback to the peak current).
#[test]
fn estimator_without_rated_current_names_the_key() {
    let text = std::fs::read_to_string(repo().join("motors/chalmers-hev50.toml")).unwrap();
    let text = text.replacen("nominal_current = \"160 A\"", "", 1);
    let line = line_of(&text, "[motor]");
    fails(
        "no_nominal_current",
        &text,
        line,
        "motor.datasheet.nominal_current",
        &["I_base = √2·I_n", "(4.35)"],
    );
}

/// Issue 18 at the library level: values that overflow or underflow the design are refused
/// at their key with the accepted range and why (the CLI test checks exit code and files).
#[test]
fn values_beyond_physical_ranges_name_the_range_at_their_key() {
    let more: &[(&str, &str, &str, &str)] = &[
        (
            "switching_frequency = \"20 kHz\"",
            "switching_frequency = \"1e300 Hz\"",
            "drive.switching_frequency",
            "[1 kHz, 200 kHz]",
        ),
        (
            "inductance = \"0.393 mH\"",
            "inductance = \"1e-300 H\"",
            "motor.datasheet.inductance",
            "[1 nH, 10 H]",
        ),
        (
            "phase_resistance = \"0.126 Ω\"",
            "phase_resistance = \"1e300 Ω\"",
            "motor.datasheet.phase_resistance",
            "[1 µΩ, 1 MΩ]",
        ),
        (
            "max_speed = \"20000 rpm\"",
            "max_speed = \"1e300 rpm\"",
            "motor.datasheet.max_speed",
            "1e5 rad/s",
        ),
    ];
    for &(from, to, key, range) in motor_test_support::ISSUE_18_RANGE_EXAMPLES.iter().chain(more) {
        let text = fischer().replacen(from, to, 1);
        assert_ne!(text, fischer(), "{from} not in the Fischer spec");
        let e = codegen::design_source("m.toml", &text).unwrap_err();
        let d = &e.0[0];
        assert_eq!((d.line, d.key.as_str()), (line_of(&text, to), key), "{e}");
        assert!(d.problem.contains(range) && d.accepted.contains(range), "{e}");
        let field = key.rsplit('.').next().unwrap();
        assert!(d.problem.starts_with(&format!("{field} must be in ")), "{e}");
    }
}

/// The last gate: a design with a non-finite number (here planted in a real design) is an
/// error naming the JSON path and the keys that decide it, located at the first of them.
#[test]
fn a_non_finite_design_value_is_an_error_with_its_path() {
    let text = fischer();
    let src = codegen::Source {
        file: "f.toml",
        text: &text,
    };
    let spec = codegen::spec::parse(src).unwrap();
    let mut d = codegen::design::design(&spec, src).unwrap();
    assert!(codegen::design::finite::check(&d, &spec, src).is_ok());
    d.current_loop.q.ki = f64::NAN;
    let e = codegen::design::finite::check(&d, &spec, src).unwrap_err();
    assert!(e.problem.contains("`current_loop.q.ki` comes out as NaN"), "{e}");
    assert!(e.problem.contains("drive.switching_frequency"), "{e}");
    assert_eq!(
        (e.line, e.key.as_str()),
        (line_of(&text, "bandwidth = "), "current_loop.bandwidth"),
        "{e}"
    );
}
