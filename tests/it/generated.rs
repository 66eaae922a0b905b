//! The generated Rust (template and proc-macro) compiles for every motor in
//! `motors/` and holds, constant by constant, the values of the JSON design.
#![deny(warnings)]

/// (item path, JSON pointer, Rust type, value(s) as f64).
pub type Entry = (&'static str, &'static str, &'static str, Vec<f64>);
/// A listing function.
pub type Listing = fn() -> Vec<Entry>;

#[allow(missing_docs, dead_code, clippy::all)]
mod generated {
    use super::{Entry, Listing};
    include!(concat!(env!("OUT_DIR"), "/generated.rs"));
}

/// The JSON value(s) at `pointer`, null read as 0 (documented in the constant) — as many
/// zeros as the constant has entries (`len`: a fixed-length table the firmware reads, e.g.
/// the 17 MTPA points without ψ_M).
fn json_values(v: &serde_json::Value, pointer: &str, len: usize) -> Vec<f64> {
    match v.pointer(pointer) {
        Some(serde_json::Value::Array(a)) => a.iter().map(|x| x.as_f64().unwrap()).collect(),
        Some(serde_json::Value::Null) => vec![0.0; len.max(1)],
        Some(x) => vec![x.as_f64().unwrap_or_else(|| panic!("{pointer}: {x}"))],
        None => panic!("no {pointer} in the JSON design"),
    }
}

#[test]
fn every_constant_equals_the_json_design_and_the_macro_expansion() {
    let motors = motor_test_support::motors();
    assert_eq!(
        generated::MOTORS.len(),
        motors.len(),
        "a motor is missing from the generated set"
    );
    for (stem, template, expanded) in generated::MOTORS {
        let json = crate::design_json(stem);
        let t = template();
        let e = expanded();
        assert_eq!(t.len(), e.len());
        assert!(t.len() > 40, "{stem}: only {} constants", t.len());
        for ((item, pointer, ty, got), (_, _, _, via_macro)) in t.iter().zip(&e) {
            assert!(!pointer.is_empty(), "{stem}: {item} has no JSON path");
            let want = json_values(&json, pointer, got.len());
            assert_eq!(got.len(), want.len(), "{stem}: {item}");
            for (g, w) in got.iter().zip(&want) {
                if *ty == "f32" || ty.starts_with("[f32;") {
                    // The f32 constant (or array element) is the JSON f64 rounded to nearest
                    // f32, bit for bit.
                    assert_eq!(
                        (*g as f32).to_bits(),
                        (*w as f32).to_bits(),
                        "{stem}: {item} = {g}, JSON {w}"
                    );
                } else {
                    assert_eq!(g, w, "{stem}: {item}");
                }
            }
            assert_eq!(got, via_macro, "{stem}: {item} differs between template and proc-macro");
        }
    }
}
