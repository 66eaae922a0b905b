//! Literal check: no motor, tuning or board number may be written into the firmware;
//! they all come from the generated constants (`motor::`, its `board` group from the
//! board file).
//!
//! Every numeric literal in `src/**/*.rs` (comments, strings and the trailing
//! `#[cfg(test)]` module excluded) must be one of:
//! * in `src/hw.rs`, the documented hardware facts of the STM32G474 and the board
//!   (clock 170 MHz, PLL factors, CAN bit rate and identifier, …);
//! * a hexadecimal, binary or octal literal (register bit patterns and keys);
//! * a decimal integer ≤ 32 (bit positions, field codes, small counts);
//! * one of the floats 0.0, 0.5, 1.0, 2.0 (rounding, halving, unity);
//! * a power of ten ≥ 1000, integer or float (unit conversions ms/s, µs/s, …);
//! * listed in [`FILE_ALLOWLIST`] with its reason (register-encoding boundaries).
//!
//! In addition no literal anywhere in `src/` (hw.rs included; hexadecimal too) may equal
//! a number of the generated module of the motor and board being built (magnitudes
//! up to 32, powers of ten ≥ 100 and a file's allowlisted register facts excepted): a motor
//! or board number copied into the firmware fails even where literals are otherwise
//! allowed. And no board-layer source may name a pin in a register accessor
//! (`afrh8()`, `moder13()`, `idr6()`, `br13()`, …): which pins carry which signal is the
//! board file's, and the pins are configured from its generated constants.

use std::path::{Path, PathBuf};

/// Numbers allowed in one file beyond the general rules, with the reason.
const FILE_ALLOWLIST: &[(&str, &[f64], &str)] = &[
    (
        "timing.rs",
        &[
            64.0, 127.0, 254.0, 504.0, 1008.0, 49.0, 95.0, 185.0, 495.0, 1281.0, 224.0,
        ],
        "TIMx_BDTR.DTG range boundaries, its DTG[7:5] = 111 prefix 0xE0, and ADC_SMPR half-cycle counts (RM0440)",
    ),
    (
        "can_frame.rs",
        &[128.0, 256.0, 512.0],
        "FDCAN_NBTP field ranges (RM0440 §44.4.7)",
    ),
    ("fmac.rs", &[256.0], "FMAC local memory size in words (RM0440 §18.3.2)"),
    (
        "hw.rs",
        &[170_000_000.0, 32_000.0, 85.0],
        "SYSCLK (DS12288 §3.9) and the LSI (DS12288 Table 56): the clocks codegen's `check` computes with are emitted as board::TIMER_CLOCK_HZ, FDCAN_CLOCK_HZ and LSI_HZ, and config.rs asserts they equal these; PLL_N = 85 (HSI16/4·85/2 = 170 MHz, RM0440 §7.4.4), which equals the reference boards' 500 ns dead time in 170 MHz ticks (board::MIN_PULSE) by coincidence of the same clock",
    ),
];

const FLOAT_ALLOWED: [f64; 4] = [0.0, 0.5, 1.0, 2.0];

/// A numeric literal found in source text.
#[derive(Debug, Clone, PartialEq)]
struct Literal {
    line: usize,
    text: String,
    value: f64,
    float: bool,
    radix: bool,
}

/// Source text with comments, string and char literals blanked (line structure kept).
fn strip(src: &str) -> String {
    let b = src.as_bytes();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if c == b'/' && b.get(i + 1) == Some(&b'*') {
            while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                if b[i] == b'\n' {
                    out.push('\n');
                }
                i += 1;
            }
            i += 2;
        } else if c == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    i += 1;
                }
                if b.get(i) == Some(&b'\n') {
                    out.push('\n');
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if c == b'\'' && b.get(i + 2) == Some(&b'\'') {
            i += 3;
        } else {
            out.push(c as char);
            i += 1;
        }
    }
    out
}

/// The numeric literals of (stripped) source text.
fn literals(src: &str) -> Vec<Literal> {
    let text = strip(src);
    let mut found = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let b = line.as_bytes();
        let mut i = 0;
        while i < b.len() {
            let prev = if i == 0 { b' ' } else { b[i - 1] };
            let starts = b[i].is_ascii_digit() && !(prev.is_ascii_alphanumeric() || prev == b'_' || prev == b'.');
            if !starts {
                i += 1;
                continue;
            }
            let start = i;
            while i < b.len() {
                let c = b[i];
                let exp_sign =
                    (c == b'-' || c == b'+') && matches!(b[i - 1], b'e' | b'E') && !line[start..i].starts_with("0x");
                let dot = c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit);
                if c.is_ascii_alphanumeric() || c == b'_' || dot || exp_sign {
                    i += 1;
                } else {
                    break;
                }
            }
            let raw = &line[start..i];
            if let Some(lit) = parse(raw, n + 1) {
                found.push(lit);
            }
        }
    }
    found
}

/// Parses one literal token (suffixes and `_` removed).
fn parse(raw: &str, line: usize) -> Option<Literal> {
    let mut t = raw.replace('_', "");
    for suffix in [
        "usize", "isize", "u128", "i128", "u64", "i64", "u32", "i32", "u16", "i16", "u8", "i8", "f32", "f64",
    ] {
        if let Some(s) = t.strip_suffix(suffix)
            && !s.is_empty()
        {
            t = s.to_string();
            break;
        }
    }
    let lit = |value: f64, float: bool, radix: bool| {
        Some(Literal {
            line,
            text: raw.to_string(),
            value,
            float,
            radix,
        })
    };
    for (prefix, base) in [("0x", 16), ("0b", 2), ("0o", 8)] {
        if let Some(digits) = t.strip_prefix(prefix) {
            return lit(u128::from_str_radix(digits, base).ok()? as f64, false, true);
        }
    }
    let float = t.contains(['.', 'e', 'E']);
    lit(t.parse::<f64>().ok()?, float, false)
}

/// A power of ten ≥ 100: too round to tell a copied motor number from a board choice
/// (100 ms, 100 periods) when comparing against the generated constants (a designed
/// ρ = 10 rad/s gives γ1 = ρ² = 100).
fn is_round(v: f64) -> bool {
    v >= 100.0 && (v.log10() - v.log10().round()).abs() < 1e-12
}

fn is_power_of_ten(v: f64) -> bool {
    v >= 1000.0 && (v.log10() - v.log10().round()).abs() < 1e-12
}

/// Literals of one file that break the rules (`file` is its name, for the
/// allowlist and the hw.rs exemption).
fn violations(file: &str, src: &str) -> Vec<Literal> {
    if file == "hw.rs" {
        return Vec::new();
    }
    let extra: &[f64] = FILE_ALLOWLIST
        .iter()
        .find(|(f, _, _)| *f == file)
        .map_or(&[], |(_, v, _)| v);
    literals(src)
        .into_iter()
        .filter(|l| {
            let allowed = if l.radix {
                true
            } else if l.float {
                FLOAT_ALLOWED.contains(&l.value) || is_power_of_ten(l.value)
            } else {
                l.value <= 32.0 || is_power_of_ten(l.value)
            };
            !(allowed || extra.contains(&l.value))
        })
        .collect()
}

/// The numbers of the generated module (its code, not its doc comments).
fn generated_numbers() -> Vec<f64> {
    let out = Path::new(env!("OUT_DIR"));
    ["motor.rs"]
        .iter()
        .filter_map(|f| std::fs::read_to_string(out.join(f)).ok())
        .flat_map(|src| literals(&src))
        .map(|l| l.value.abs())
        .filter(|v| *v > 32.0 && !is_round(*v))
        .collect()
}

/// The source files of the firmware, with their text up to a trailing test module.
fn sources() -> Vec<(PathBuf, String)> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).expect("src readable").flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let mut files = Vec::new();
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    // This crate's logic and the board layer of the image (`../app`).
    walk(&manifest.join("src"), &mut files);
    walk(&manifest.join("../app/src"), &mut files);
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("source readable");
            let code = text.split("#[cfg(test)]\nmod tests").next().unwrap_or("").to_string();
            (p, code)
        })
        .collect()
}

#[test]
fn no_motor_or_tuning_literals_in_the_firmware() {
    let generated = generated_numbers();
    assert!(!generated.is_empty(), "the generated module has numbers");
    let mut problems = Vec::new();
    let files = sources();
    assert!(files.len() >= 10, "found the firmware sources");
    for (path, code) in &files {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        for l in violations(name, code) {
            problems.push(format!(
                "{}:{}: literal {} is not a hardware fact",
                path.display(),
                l.line,
                l.text
            ));
        }
        let allowed: &[f64] = FILE_ALLOWLIST
            .iter()
            .find(|(f, _, _)| *f == name)
            .map_or(&[], |(_, v, _)| v);
        for l in literals(code) {
            let v = l.value.abs();
            if generated.iter().any(|g| (g - v).abs() <= 1e-6 * g.max(1.0))
                && v > 32.0
                && !is_round(v)
                && !allowed.contains(&v)
            {
                problems.push(format!(
                    "{}:{}: literal {} equals a generated motor constant",
                    path.display(),
                    l.line,
                    l.text
                ));
            }
        }
    }
    for (path, code) in &files {
        for (line, accessor) in pin_accessors(code) {
            problems.push(format!(
                "{}:{line}: `{accessor}` names a pin in the firmware; pins come from the board file (motor::board)",
                path.display()
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// GPIO register accessors of the PAC that carry a pin number in their name.
const PIN_FIELDS: [&str; 10] = [
    "moder", "afrl", "afrh", "ospeedr", "otyper", "pupdr", "idr", "odr", "bs", "br",
];

/// Calls such as `.afrh8(` or `.br13(` in (stripped) source: (line, accessor).
fn pin_accessors(src: &str) -> Vec<(usize, String)> {
    let text = strip(src);
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        for (i, _) in line.match_indices('.') {
            let rest = &line[i + 1..];
            let ident: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            let digits = ident.trim_start_matches(|c: char| c.is_ascii_alphabetic());
            let name = &ident[..ident.len() - digits.len()];
            if !digits.is_empty()
                && digits.chars().all(|c| c.is_ascii_digit())
                && PIN_FIELDS.contains(&name)
                && rest[ident.len()..].starts_with('(')
            {
                out.push((n + 1, ident));
            }
        }
    }
    out
}

/// The scanner itself: a copied inductance, observer gain or switching frequency
/// is caught; register patterns, small codes and unit conversions are not.
#[test]
fn scanner_catches_motor_numbers() {
    let bad =
        "const L: f32 = 0.393e-3; // L_d\nlet kp = I1F31::from_bits(4_784_957);\nlet fs = 20_000.0f32;\nlet r = 0.126;";
    let v = violations("config.rs", bad);
    let texts: Vec<&str> = v.iter().map(|l| l.text.as_str()).collect();
    assert_eq!(texts, ["0.393e-3", "4_784_957", "20_000.0f32", "0.126"]);
    assert_eq!(v[1].line, 2);
    let ok = "w.mms().bits(0b010); x.0; for k in 0..8 { k << 29 }; let s = \"12.6\"; // 0.0393\nlet us = f / 1_000_000; let h = 0.5 * a; key(0xCCCC);";
    assert!(violations("pwm.rs", ok).is_empty(), "{:?}", violations("pwm.rs", ok));
    // hw.rs may hold hardware numbers, but the generated-value check covers it too.
    assert!(violations("hw.rs", bad).is_empty());
    // Pin-numbered register accessors are board facts; the generic ones are not.
    let pins = "gpioa.afrh().modify(|_, w| w.afrh8().set(6));\nw.br13().set_bit(); r.bits(); w.oc4m().set(7);";
    assert_eq!(pin_accessors(pins), [(1, "afrh8".to_string()), (2, "br13".to_string())]);
    assert_eq!(
        literals("let a = 5e-5; let b = 1.5e3;")
            .iter()
            .map(|l| l.value)
            .collect::<Vec<_>>(),
        [5e-5, 1500.0]
    );
}
