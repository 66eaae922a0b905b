//! Motor data as datasheets print it (issue 13): the per-unit bases that do not wait for
//! an unrelated key, inverse saliency, datasheet forms converted with their provenance,
//! and the cross-checks of redundant values. Library-level: spec text → design.

use codegen::constants::{Group, constants};
use codegen::design::Design;

use motor_test_support::read;

fn chalmers() -> String {
    read("motors/chalmers-hev50.toml")
}

/// `text` with the first line starting with `key` removed (which must exist).
fn without(text: &str, key: &str) -> String {
    let at = text
        .lines()
        .position(|l| l.starts_with(key))
        .unwrap_or_else(|| panic!("{key} not in spec"));
    let out: Vec<&str> = text
        .lines()
        .enumerate()
        .filter(|&(i, _)| i != at)
        .map(|(_, l)| l)
        .collect();
    out.join("\n")
}

fn design(name: &str, text: &str) -> Design {
    codegen::design_source(name, text).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn group<'a>(groups: &'a [Group], name: &str) -> &'a Group {
    codegen::constants::group_named(groups, name).unwrap()
}

/// Thesis B's motor with and without `rated_frequency`/`nominal_speed`: f_n enters none of
/// the estimator's formulas, so every generated estimator constant is the same, and ω_min2
/// (4.69) is the 65.86 rad/s of thesis B §4.4.2 (hand calculation in
/// design::sensorless::tests::omega_min2_is_0_05_pu) — not the 92 rad/s the peak current
/// gave when I_base fell back to it. The default ω_hp is 0.015 pu = 3 Hz at f_n = 200 Hz,
/// the same as the 2π·3 Hz used without a per-unit base.
#[test]
fn estimator_constants_do_not_depend_on_rated_frequency() {
    let with = design("with.toml", &chalmers());
    let no_f = without(&without(&chalmers(), "rated_frequency"), "nominal_speed");
    let without_f = design("without.toml", &no_f);
    assert!(without_f.per_unit.bases.angular_frequency_rad_s.is_none());
    assert_eq!(with.per_unit.bases.current_a, without_f.per_unit.bases.current_a);
    let (a, b) = (constants(&with), constants(&without_f));
    let (a, b) = (group(&a, "sensorless"), group(&b, "sensorless"));
    assert_eq!(a.constants.len(), b.constants.len());
    for (x, y) in a.constants.iter().zip(&b.constants) {
        assert_eq!((&x.name, &x.value.number), (&y.name, &y.value.number), "{}", x.name);
    }
    for d in [&with, &without_f] {
        let w2 = d.sensorless.as_ref().unwrap().omega_min2_rad_s;
        assert!((w2 - 65.86).abs() < 0.01, "{w2}");
    }
}

/// No rated current: the estimator's (4.24), (4.35), (4.69) need I_base = √2·I_n, and
/// nothing else stands in. With a `[sensorless]` section that is an error at
/// `motor.datasheet.nominal_current`; without one there is no estimator. The bases that need only the DC link and f_n are still there.
#[test]
fn no_rated_current_no_silent_fallback() {
    let text = without(&chalmers(), "nominal_current");
    let err = codegen::design_source("x.toml", &text).unwrap_err().to_string();
    assert!(
        err.contains("`motor.datasheet.nominal_current`") && err.contains("I_base = √2·I_n"),
        "{err}"
    );
    let at = text.find("[sensorless]").unwrap();
    let d = design("y.toml", &text[..at]);
    // Without the section no estimator is designed (a resolver drive), so nothing needs I_n.
    assert!(d.sensorless.is_none());
    let b = &d.per_unit.bases;
    assert!(b.current_a.is_none() && b.impedance_ohm.is_none() && b.inductance_h.is_none());
    // ψ_m = 0.71 pu (Table B.2) needs only V_base and ω_base.
    assert_eq!((d.per_unit.values["flux_linkage"] * 100.0).round() / 100.0, 0.71);
}

/// Inverse saliency (labelled variant: thesis B's motor with L_d = 0.70 mH > L_q = 0.56 mH,
/// the example). The MTPA and loss tables take the positive branch of (3.10)
/// (up to +105.26 A at I_max; hand value in design::field_weakening::tests); the
/// estimator's (4.66) and (4.92) limits exist; the thesis's 500 Hz carrier would need
/// V_e = I_base·ω_e·L_d·L_q/(10·|ΔL|) = 226.27·3141.6·0.70e-3·0.56e-3/1.4e-3 = 199.0 V,
/// above V_max = 184.75 V — an error at the key that set the carrier; at 100 Hz K_e (4.19)
/// is −I_base/40 = −5.657 A. Above 4245 rpm the largest torque lies inside the current
/// circle (ψ_m < L_d·I_max): the design adds maximum torque per volt (the firmware's Mode C)
/// instead of refusing the seed's 12000 rpm — the line ends at −ψ_m/L_d = −0.104/0.70e-3 =
/// −148.57 A and the optimum leaves the circle at 889.0 rad/s. At 4200 rpm verify's field
/// weakening passes; its
/// estimator_recovery slips one cycle with the resetting term, as it does for the same
/// inductances the other way round (L_d = 0.56, L_q = 0.70 mH): a matter of the larger
/// inductances at the lower test speed, not of the sign of ΔL.
#[test]
fn inverse_saliency_variant() {
    let inv = chalmers().replace("d_inductance = \"0.23 mH\"", "d_inductance = \"0.70 mH\"");
    let slow = inv.replace("max_speed = \"12000 rpm\"", "max_speed = \"4200 rpm\"");
    let err = codegen::design_source("inv.toml", &slow).unwrap_err().to_string();
    assert!(
        err.contains("`sensorless.injection_frequency`") && err.contains("199.0 V"),
        "{err}"
    );
    // ψ_m = 0.104 Wb < L_d·I_max = 0.2217 Wb: above 889.0 rad/s = 4244.7 rpm the torque
    // optimum leaves the current circle (checked by brute force in
    // design::field_weakening::tests::max_torque_per_volt_limit_by_brute_force).
    let carrier = |t: &str| t.replace("injection_frequency = \"500 Hz\"", "injection_frequency = \"100 Hz\"");
    let full = design("inv.toml", &carrier(&inv));
    let mtpv = full.field_weakening.as_ref().unwrap().mtpv.as_ref().unwrap();
    assert!((mtpv.line_end_id_a + 148.571).abs() < 1e-3, "{mtpv:?}");
    assert!((mtpv.entry_speed_rad_s.unwrap() - 889.0).abs() < 0.5, "{mtpv:?}");
    assert!((mtpv.gain_ratio - 0.70 / 0.56).abs() < 1e-12);
    assert_eq!(full.field_weakening.as_ref().unwrap().torque_speed_limit_rad_s, None);
    let text = carrier(&slow);
    let d = design("inv.toml", &text);
    let fw = d.field_weakening.as_ref().unwrap();
    assert!((fw.id_mtpa_at_current_max_a - 105.26).abs() < 0.01);
    assert!(fw.mtpa.id_a.iter().all(|&i| i >= 0.0));
    let lt = &fw.loss_minimisation.as_ref().unwrap().table;
    assert_eq!(
        lt.id_a[..lt.iq_a.len()].iter().filter(|&&i| i > 0.0).count(),
        lt.iq_a.len() - 1
    );
    let s = d.sensorless.as_ref().unwrap();
    assert!((s.injection.as_ref().unwrap().gain_ke_a + 226.274_17 / 40.0).abs() < 1e-3);
    assert!((s.iq_limit_bifurcation_a.unwrap() - 742.857).abs() < 1e-3);
    assert!(s.iq_limit_resetting_a.unwrap() > 0.0);
}

/// The maxon EC 45 flat written as the catalogue prints it (line-to-line R and L,
/// mN·m/A and rpm/V of block commutation, g·cm²) designs to the same constants as the
/// same motor converted by hand (tests/fixtures; every number's source is in the files),
/// and the provenance says what was converted.
#[test]
fn maxon_as_printed_equals_hand_converted() {
    let printed = design(
        "printed.toml",
        &read("crates/codegen/tests/fixtures/maxon-ec45-flat-70w-24v.toml"),
    );
    let converted = design(
        "converted.toml",
        &read("crates/codegen/tests/fixtures/maxon-ec45-flat-70w-24v-converted.toml"),
    );
    let (a, b) = (constants(&printed), constants(&converted));
    assert_eq!(a.len(), b.len());
    for (ga, gb) in a.iter().zip(&b) {
        assert_eq!(ga.constants.len(), gb.constants.len(), "{}", ga.name);
        for (x, y) in ga.constants.iter().zip(&gb.constants) {
            assert_eq!(x.name, y.name);
            assert!(
                same_numbers(&x.value.number, &y.value.number),
                "{}::{}: {} vs {}",
                ga.name,
                x.name,
                x.value.number,
                y.value.number
            );
        }
    }
    let p = &printed.motor.provenance;
    assert!(
        p["phase_resistance"]
            .note
            .as_deref()
            .unwrap()
            .contains("line-to-line \"0.573 Ω\"")
    );
    assert!(p["inertia"].note.as_deref().unwrap().contains("181 g·cm²"));
    assert!(p["flux_linkage"].note.as_deref().unwrap().contains("236 rpm/V"));
    // k_M and k_n of block commutation agree (0.16 %), within the 5 % tolerance.
    let c = &printed.motor.cross_checks[0];
    assert!(
        c.quantity.starts_with("ψ_M") && (c.disagreement_percent - 0.156).abs() < 0.01,
        "{c}"
    );
    assert!((printed.drive.dead_time_voltage_error_v.unwrap() - 0.24).abs() < 1e-12);
}

/// Equal to f32 rounding: the hand-converted ψ_M is written to 8 digits.
fn same_numbers(a: &serde_json::Value, b: &serde_json::Value) -> bool {
    match (a, b) {
        (serde_json::Value::Array(x), serde_json::Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(a, b)| same_numbers(a, b))
        }
        (serde_json::Value::Number(x), serde_json::Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            (x - y).abs() <= 1e-6 * x.abs().max(y.abs())
        }
        _ => a == b,
    }
}

/// A torque constant 40 % off the given flux linkage no longer passes silently: the
/// design warns with both values (Fischer: ψ_M given as 60.42 mWb, K_t = 0.689 N·m/A
/// rms → 0.0812 Wb).
#[test]
fn disagreeing_constants_are_warned_with_both_values() {
    let text = read("motors/fischer-ti085.toml")
        .replace("\"0.492 N·m/A\"", "\"0.689 N·m/A\"")
        .replace(
            "inductance = \"0.393 mH\"",
            "inductance = \"0.393 mH\"\nflux_linkage = \"60.42 mWb\"",
        );
    let d = design("f.toml", &text);
    let w: Vec<&String> = d.warnings.iter().filter(|w| w.contains("ψ_M [Wb]")).collect();
    assert!(
        w.iter().any(|w| w.contains("0.06042") && w.contains("0.08120")),
        "{w:?}"
    );
}

/// Terminal values in a delta winding and a winding value: R_LL = 2R_Δ/3 is 2 star
/// phases; one delta winding is 3 star phases. `measured = "winding"` without a stated
/// connection is an error at its key.
#[test]
fn star_delta_and_winding_forms() {
    let fischer = read("motors/fischer-ti085.toml");
    for (form, conn) in [
        ("{ value = \"0.252 Ω\", measured = \"line_to_line\" }", "star"),
        ("{ value = \"0.252 Ω\", measured = \"line_to_line\" }", "delta"),
        ("{ value = \"0.378 Ω\", measured = \"winding\" }", "delta"),
        ("{ value = \"0.126 Ω\", measured = \"winding\" }", "star"),
        ("{ value = \"0.126 Ω\", measured = \"phase\" }", "delta"),
    ] {
        let text = fischer
            .replace("phase_resistance = \"0.126 Ω\"", &format!("phase_resistance = {form}"))
            .replace("connection = \"star\"", &format!("connection = \"{conn}\""));
        let r = design("r.toml", &text).motor.phase_resistance_ohm;
        assert!((r - 0.126).abs() < 1e-12, "{form} {conn}: {r}");
    }
    let text = fischer
        .replace(
            "phase_resistance = \"0.126 Ω\"",
            "phase_resistance = { value = \"0.378 Ω\", measured = \"winding\" }",
        )
        .replace("connection = \"star\"     # Table 1.2\n", "");
    let err = codegen::design_source("w.toml", &text).unwrap_err().to_string();
    assert!(
        err.contains("`motor.datasheet.phase_resistance.measured`") && err.contains("connection"),
        "{err}"
    );
}
