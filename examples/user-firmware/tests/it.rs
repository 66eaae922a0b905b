//! The example's stated gains are the design's, value for value: each macro expansion
//! against `motors/fischer-ti085.toml`'s JSON design (what `motorgen design --format json`
//! prints) and against the generated module in the same crate; the Q1.31 literal against
//! its hand value.

use user_firmware::{CURRENT_LOOP, CURRENT_PI, HALF, OBSERVER, OBSERVER_GAINS, fischer};

fn design() -> serde_json::Value {
    let rel = "motors/fischer-ti085.toml";
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors/fischer-ti085.toml")).unwrap();
    serde_json::to_value(codegen::design_source(rel, &text).unwrap()).unwrap()
}

fn f32_at(json: &serde_json::Value, pointer: &str) -> f32 {
    json.pointer(pointer)
        .and_then(serde_json::Value::as_f64)
        .unwrap_or_else(|| panic!("no number at {pointer}")) as f32
}

/// The spec states the same request (IMC, 100 rad/s, 0.126 Ω, 0.393 mH, 20 kHz, delay
/// compensation on): `pi_gains!` gives the JSON design's d- and q-axis gains bit for bit
/// (the f32 the JSON's f64 rounds to), and the generated module's constants.
#[test]
fn pi_gains_equals_the_json_design() {
    let json = design();
    for axis in ["d", "q"] {
        assert_eq!(
            CURRENT_PI.0.to_bits(),
            f32_at(&json, &format!("/current_loop/{axis}/kp")).to_bits(),
            "{axis}"
        );
        assert_eq!(
            CURRENT_PI.1.to_bits(),
            f32_at(&json, &format!("/current_loop/{axis}/ki")).to_bits(),
            "{axis}"
        );
    }
    assert_eq!(CURRENT_PI, (fischer::current_loop::D_KP, fischer::current_loop::D_KI));
    assert_eq!(CURRENT_LOOP.d.anti_windup, 1.0 / CURRENT_PI.0);
}

/// `ato_gains!` at the spec's ω_n, ζ, error and f_s gives the JSON design's Q1.31 gains
/// (thesis A §4.4.2 by hand: 4 784 957 and 8 374).
#[test]
fn ato_gains_equals_the_json_design() {
    let json = design();
    let kp = json
        .pointer("/angle_observer/kp_q31")
        .and_then(serde_json::Value::as_i64)
        .unwrap();
    let ki = json
        .pointer("/angle_observer/ki_q31")
        .and_then(serde_json::Value::as_i64)
        .unwrap();
    assert_eq!(
        (
            i64::from(OBSERVER_GAINS.0.to_bits()),
            i64::from(OBSERVER_GAINS.1.to_bits())
        ),
        (kp, ki)
    );
    assert_eq!((kp, ki), (4_784_957, 8_374));
    assert_eq!(OBSERVER.kp, fischer::observer::KP);
    assert_eq!(OBSERVER.ki, fischer::observer::KI);
}

/// 0.5 in Q1.31 is 2^30.
#[test]
fn q31_literal() {
    assert_eq!(HALF.to_bits(), 1 << 30);
}
