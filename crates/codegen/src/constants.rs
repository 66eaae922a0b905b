//! The design as a flat list of documented constants, grouped by concern.
//!
//! This is the single path from a [`Design`] to code: the Rust module, the C
//! header, the Markdown report, the DBC file and the proc-macro all render this list, so a
//! constant cannot differ between them. Every entry carries its physical value
//! with unit, its formula, the source equation and the provenance of its inputs.
//!
//! The constants are data. Each group's module declares its entries once, as a table of
//! declarations (`Decl`: name, value source and unit, formula, equation, inputs, JSON
//! pointer) read against a context — the part of the design the group covers and the input
//! texts its entries cite, computed once —, and `Decl::constant` turns a declaration into
//! a [`Constant`]. The groups, in this order: `current_loop`, `observer`, `scaling`,
//! `filter`, `limits`, `field_weakening`, `sensorless`, and for a design on a board
//! `board`, [`can`] and `commissioning`.

mod board;
pub mod can;
mod current_loop;
mod field_weakening;
mod filter;
mod limits;
mod observer;
mod scaling;
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
    /// JSON pointer of the same value in `motorgen design --format json` (null there reads as 0);
    /// empty for a fixed choice of the firmware, which the design does not compute.
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

impl Group {
    /// The constant called `name` in this group.
    pub fn constant(&self, name: &str) -> Option<&Constant> {
        self.constants.iter().find(|k| k.name == name)
    }

    /// The machine value of the constant called `name` as a number (`None` when the group
    /// has no such constant or its value is not a single number).
    pub fn number(&self, name: &str) -> Option<f64> {
        self.constant(name)?.value.number.as_f64()
    }
}

/// The group called `name` among `groups` (the output of [`constants`]).
pub fn group_named<'a>(groups: &'a [Group], name: &str) -> Option<&'a Group> {
    groups.iter().find(|g| g.name == name)
}

/// All constants of `d`, grouped: current loop, observer, scalings, filter, limits, field
/// weakening, sensorless estimator, and on a board the board, CAN and commissioning groups.
pub fn constants(d: &Design) -> Vec<Group> {
    vec![
        current_loop::group(d),
        observer::group(d),
        scaling::group(d),
        filter::group(d),
        limits::group(d),
        field_weakening::group(d),
        sensorless::group(d),
    ]
    .into_iter()
    .chain(board::group(d))
    .chain(can::group(d))
    .chain(can::commissioning_group(d))
    .collect()
}

/// How a declaration's machine value, and the physical value printed beside it, come from
/// its context.
enum Source<C> {
    /// An `f32`; its physical value is the same number in the unit (empty for a ratio).
    F32(fn(&C) -> f64, &'static str),
    /// Any other machine value (an integer, a Q1.31 fraction, an array, an `f32` whose unit
    /// the design chooses) with its physical value as text.
    Custom(fn(&C) -> (Value, String)),
}

/// A declaration's text: as written, or made from its context (the formula of the method
/// the spec chose, the inputs' values and provenance).
enum Text<C> {
    /// This text.
    Lit(&'static str),
    /// The text the context gives.
    Of(fn(&C) -> String),
}

/// Where a declared constant's value is in `motorgen design --format json` (null there
/// reads as 0).
enum Json<C> {
    /// At this JSON pointer.
    At(&'static str),
    /// At the pointer the context gives: one per instance of a repeated table, or the null
    /// standing for a result the design does not have.
    Of(fn(&C) -> String),
    /// Nowhere: a choice of the firmware or its CAN protocol, not a result of the design.
    None,
}

/// One constant, declared as data: its name, and how each of its parts comes from the
/// context `C` its table is read against.
///
/// A group's tables are `const`s; where the context borrows the design they are
/// associated consts of the context (`Axis::DECLS`), as a free `const` cannot be generic
/// over that borrow.
struct Decl<C> {
    /// Identifier within its group (after the prefix of a repeated table),
    /// SCREAMING_SNAKE_CASE.
    name: &'static str,
    /// Machine value and physical value.
    value: Source<C>,
    /// Formula.
    formula: Text<C>,
    /// Source equation.
    equation: Text<C>,
    /// Inputs with their provenance.
    inputs: Text<C>,
    /// The same value in the JSON design.
    json: Json<C>,
}

impl<C> Text<C> {
    /// The text for `ctx`.
    fn text(&self, ctx: &C) -> String {
        match self {
            Text::Lit(s) => (*s).to_string(),
            Text::Of(f) => f(ctx),
        }
    }
}

impl<C> Decl<C> {
    /// The constant this declares for `ctx`, its name prefixed with `prefix` (`D_` for the
    /// d axis of the table both axes share; empty for a table read once).
    fn constant(&self, ctx: &C, prefix: &str) -> Constant {
        let (value, physical) = match self.value {
            Source::F32(get, unit) => f32_in(get(ctx), unit),
            Source::Custom(make) => make(ctx),
        };
        Constant {
            name: format!("{prefix}{}", self.name),
            value,
            physical,
            formula: self.formula.text(ctx),
            equation: self.equation.text(ctx),
            inputs: self.inputs.text(ctx),
            json_path: match self.json {
                Json::At(pointer) => pointer.to_string(),
                Json::Of(pointer) => pointer(ctx),
                Json::None => String::new(),
            },
        }
    }
}

/// The constants `decls` declares for `ctx`, in table order, names prefixed with `prefix`.
fn declare<'a, C>(decls: &'a [Decl<C>], ctx: &'a C, prefix: &'a str) -> impl Iterator<Item = Constant> + 'a {
    decls.iter().map(move |k| k.constant(ctx, prefix))
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

/// An `f32` constant and its physical value in `unit`.
fn f32_in(x: f64, unit: &str) -> (Value, String) {
    (f32v(x), phys(x, unit))
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

/// An integer constant (Rust type `rust`, C type `c`) whose physical value is the number
/// itself: a count.
fn count(x: i64, rust: &str, c: &str) -> (Value, String) {
    (intv(x, rust, c), x.to_string())
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

/// The provenance label of the motor value `key`, with the conversion from the datasheet's
/// form where there was one (`datasheet, converted from …`).
fn provenance(d: &Design, key: &str) -> String {
    let o = d.motor.provenance.get(key);
    match o.and_then(|o| o.note.as_deref()).filter(|n| n.starts_with("converted")) {
        Some(n) => format!("{}, {n}", prov(o)),
        None => prov(o).to_string(),
    }
}

/// The sampling frequency as an input: `f_s = 20000 Hz (spec)`.
fn fs_input(d: &Design) -> String {
    format!("f_s = {} (spec)", phys(d.drive.switching_frequency_hz, "Hz"))
}

#[cfg(test)]
mod tests {
    use std::collections::HashSet;

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

    /// The number(s) of a JSON value, null read as 0 (as the constants document).
    fn numbers(v: &serde_json::Value) -> Vec<f64> {
        match v {
            serde_json::Value::Array(a) => a.iter().flat_map(numbers).collect(),
            serde_json::Value::Null => vec![0.0],
            x => vec![x.as_f64().unwrap_or_else(|| panic!("{x} is not a number"))],
        }
    }

    /// Every declared constant of every motor, alone and on every board it fits, has a
    /// SCREAMING_SNAKE_CASE name unique in its group and a JSON pointer to the same value in
    /// the JSON design; only the firmware's fixed choices, which the design does not compute
    /// — the CAN protocol, the commissioning routines' parameters, the ADC, timer, FDCAN and
    /// LSI clocks — have none. (The golden tests check the motors without a board, in the generated code.)
    #[test]
    fn every_constant_is_named_once_and_is_its_json_value() {
        for (stem, rel, text) in motor_test_support::motors() {
            let mut designs = vec![("no board".to_string(), crate::design_source(&rel, &text).unwrap())];
            for board in motor_test_support::board_stems() {
                let file = format!("boards/{board}.toml");
                // A board the motor does not fit is refused at its own keys (issue 27).
                match crate::design_with_board(&rel, &text, &file, &motor_test_support::read(&file)) {
                    Ok(d) => designs.push((board, d)),
                    Err(e) => assert!(e.0.iter().all(|d| d.file == file), "{stem} on {board}: {e}"),
                }
            }
            assert!(designs.len() > 1, "{stem} fits no board");
            for (board, d) in designs {
                let json = serde_json::to_value(&d).unwrap();
                for g in constants(&d) {
                    let mut names = HashSet::new();
                    for k in &g.constants {
                        let at = format!("{stem} ({board}): {}::{}", g.name, k.name);
                        assert!(
                            !k.name.is_empty()
                                && !k.name.starts_with(|c: char| c.is_ascii_digit())
                                && k.name
                                    .chars()
                                    .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_'),
                            "{at}: not SCREAMING_SNAKE_CASE"
                        );
                        assert!(names.insert(k.name.as_str()), "{at} declared twice");
                        if k.json_path.is_empty() {
                            let fixed = matches!(
                                (g.name, k.name.as_str()),
                                ("can" | "commissioning", _)
                                    | ("board", "ADC_CLOCK_HZ" | "TIMER_CLOCK_HZ" | "FDCAN_CLOCK_HZ" | "LSI_HZ")
                            );
                            assert!(fixed, "{at} has no JSON pointer");
                            continue;
                        }
                        let want = json
                            .pointer(&k.json_path)
                            .unwrap_or_else(|| panic!("{at}: no {} in the JSON design", k.json_path));
                        let got = numbers(&k.value.number);
                        // A result the design does not have (null) stands for zeros, as many
                        // as the constant has entries (the 17 MTPA points without ψ_M).
                        let want = match want {
                            serde_json::Value::Null => vec![0.0; got.len().max(1)],
                            w => numbers(w),
                        };
                        assert_eq!(got.len(), want.len(), "{at}: {got:?} but {} is {want:?}", k.json_path);
                        for (g, w) in got.iter().zip(&want) {
                            if k.value.c_type == "float" {
                                // The f32 constant is the JSON f64 rounded to the nearest f32.
                                assert_eq!(g.to_bits(), f64::from(*w as f32).to_bits(), "{at}: {g}, JSON {w}");
                            } else {
                                assert_eq!(g, w, "{at}");
                            }
                        }
                    }
                }
            }
        }
    }
}
