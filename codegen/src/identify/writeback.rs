//! Identified values into the spec's `[motor.identified]` section with `toml_edit`:
//! every other line, comment and the layout of the file stay as they were.
//!
//! * A written key gets a trailing comment saying how it was identified (the old value's
//!   comment described the old value and is replaced).
//! * `date` is set to the identification date (a TOML date) and `source` lists the
//!   recordings per routine (`step q: a.csv, b.csv; flux: f.csv`): the entry of the
//!   routine just run is replaced, the others are kept.
//! * `[motor.identified]` wins over `[motor.datasheet]` key by key (see `spec`), so one
//!   identified axis may stand next to a datasheet value for the other. If the
//!   identified section holds a single `inductance` (L_d = L_q) and one axis is
//!   identified, the other axis keeps that value as `d_inductance`/`q_inductance`.

use std::ops::Range;

use toml_edit::{Datetime, DocumentMut, Item, Table, value};

/// One key to write.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// Key in `[motor.identified]`, e.g. `q_inductance`.
    pub key: &'static str,
    /// The value string with its unit, e.g. `"7.612 mH"`.
    pub value: String,
    /// Trailing comment (without `#`).
    pub note: String,
}

/// Where the values came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Origin<'a> {
    /// Date `YYYY-MM-DD`.
    pub date: &'a str,
    /// Routine label, e.g. `step q`, `flux`, `resolver offset`.
    pub label: &'a str,
    /// Recording file names.
    pub files: &'a [String],
}

/// `x` with 4 significant digits.
fn sig4(x: f64) -> String {
    let decimals = (3 - x.abs().log10().floor() as i32).clamp(0, 9) as usize;
    format!("{x:.decimals$}")
}

/// A resistance with a unit the spec accepts.
pub fn ohms(r: f64) -> String {
    if r >= 0.1 {
        format!("{} Ω", sig4(r))
    } else {
        format!("{} mΩ", sig4(r * 1e3))
    }
}

/// An inductance with a unit the spec accepts.
pub fn henries(l: f64) -> String {
    if l >= 1e-5 {
        format!("{} mH", sig4(l * 1e3))
    } else {
        format!("{} µH", sig4(l * 1e6))
    }
}

/// A flux linkage in mWb.
pub fn webers(psi: f64) -> String {
    format!("{} mWb", sig4(psi * 1e3))
}

/// An angle in rad (5 decimals: 10 µrad).
pub fn radians(theta: f64) -> String {
    format!("{theta:.5} rad")
}

/// The date `YYYY-MM-DD` of day `days` since 1970-01-01 in the proleptic Gregorian
/// calendar (civil-from-days: 400-year eras of 146 097 days, years starting in March).
pub fn date_from_unix_days(days: i64) -> String {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

/// The spec text with `entries` written into `[motor.identified]` and the origin noted.
/// Errors (as text) if the file is not TOML or `[motor]` is not a table.
pub fn apply(text: &str, entries: &[Entry], origin: &Origin<'_>) -> Result<String, String> {
    let mut doc: DocumentMut = text.parse().map_err(|e| format!("the spec is not valid TOML: {e}"))?;
    let motor = doc
        .get_mut("motor")
        .and_then(Item::as_table_mut)
        .ok_or("the spec has no [motor] table")?;
    let motor_position = motor.position();
    if motor.get("identified").is_none() {
        let mut t = Table::new();
        // Right after [motor] (and its other sub-tables written in the same place).
        t.set_position(motor_position);
        motor.insert("identified", Item::Table(t));
    }
    let ident = motor
        .get_mut("identified")
        .and_then(Item::as_table_mut)
        .ok_or("[motor.identified] is not a table")?;
    // A single `inductance` becomes d/q when only one axis is identified now.
    let writes_axis = entries
        .iter()
        .any(|e| e.key == "d_inductance" || e.key == "q_inductance");
    if writes_axis && let Some(old) = ident.remove("inductance") {
        for axis in ["d_inductance", "q_inductance"] {
            if !entries.iter().any(|e| e.key == axis) {
                ident.insert(axis, old.clone());
            }
        }
    }
    for e in entries {
        let mut v = value(e.value.as_str());
        if let Some(val) = v.as_value_mut() {
            val.decor_mut().set_suffix(format!("  # {}", e.note));
        }
        match ident.get_mut(e.key) {
            Some(item) => {
                let prefix = item.as_value().and_then(|x| x.decor().prefix().cloned());
                *item = v;
                if let (Some(p), Some(val)) = (prefix, item.as_value_mut()) {
                    val.decor_mut().set_prefix(p);
                }
            }
            None => {
                ident.insert(e.key, v);
            }
        }
    }
    let date: Datetime = origin
        .date
        .parse()
        .map_err(|e| format!("`{}` is not a date: {e}", origin.date))?;
    ident.insert("date", value(date));
    let entry = format!("{}: {}", origin.label, origin.files.join(", "));
    let old_source = ident.get("source").and_then(Item::as_str).unwrap_or("");
    let mut parts: Vec<String> = old_source
        .split("; ")
        .filter(|p| !p.is_empty() && !p.starts_with(&format!("{}:", origin.label)))
        .map(str::to_string)
        .collect();
    parts.push(entry);
    ident.insert("source", value(parts.join("; ")));
    Ok(doc.to_string())
}

/// Byte span of the value at `path` (e.g. `["motor", "pole_pairs"]`) in `text`.
pub fn value_span(text: &str, path: &[&str]) -> Option<Range<usize>> {
    let doc = toml_edit::Document::parse(text).ok()?;
    let mut item = doc.as_item();
    for key in path {
        item = item.get(key)?;
    }
    item.span()
}

/// The lines that differ between `old` and `new` (`- old`, `+ new`, with line numbers
/// of `old`/`new`), by a longest-common-subsequence line diff.
pub fn line_diff(old: &str, new: &str) -> String {
    let a: Vec<&str> = old.lines().collect();
    let b: Vec<&str> = new.lines().collect();
    let (n, m) = (a.len(), b.len());
    // lcs[i][j]: LCS length of a[i..], b[j..].
    let mut lcs = vec![vec![0u32; m + 1]; n + 1];
    for i in (0..n).rev() {
        for j in (0..m).rev() {
            lcs[i][j] = if a[i] == b[j] {
                lcs[i + 1][j + 1] + 1
            } else {
                lcs[i + 1][j].max(lcs[i][j + 1])
            };
        }
    }
    let (mut i, mut j, mut out) = (0, 0, String::new());
    while i < n || j < m {
        if i < n && j < m && a[i] == b[j] {
            i += 1;
            j += 1;
        } else if i < n && (j == m || lcs[i + 1][j] >= lcs[i][j + 1]) {
            out.push_str(&format!("-{:>4} | {}\n", i + 1, a[i]));
            i += 1;
        } else {
            out.push_str(&format!("+{:>4} | {}\n", j + 1, b[j]));
            j += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &str = "# a motor\nname = \"m\"\n\n[motor]\npole_pairs = 4   # datasheet\n\n[motor.datasheet]\nphase_resistance = \"0.126 Ω\"  # Table 1.2\ninductance = \"0.393 mH\"\n\n[resolver]\npole_pairs = 1\n";

    fn origin<'a>(files: &'a [String], label: &'a str) -> Origin<'a> {
        Origin {
            date: "2025-03-14",
            label,
            files,
        }
    }

    #[test]
    fn units_and_digits() {
        assert_eq!(ohms(0.65123), "0.6512 Ω");
        assert_eq!(ohms(7.9e-3), "7.900 mΩ");
        assert_eq!(henries(7.6123e-3), "7.612 mH");
        assert_eq!(henries(0.393e-3), "0.3930 mH");
        assert_eq!(webers(0.05812), "58.12 mWb");
        assert_eq!(radians(1.234567), "1.23457 rad");
    }

    /// A new section lands after [motor]; comments and the other sections are unchanged.
    #[test]
    fn creates_the_section_and_keeps_everything_else() {
        let files = vec!["a.csv".to_string(), "b.csv".to_string()];
        let out = apply(
            SPEC,
            &[Entry {
                key: "phase_resistance",
                value: "0.1301 Ω".into(),
                note: "step q, 2 recordings".into(),
            }],
            &origin(&files, "step q"),
        )
        .unwrap();
        let expected_tail = "[motor.datasheet]\nphase_resistance = \"0.126 Ω\"  # Table 1.2\ninductance = \"0.393 mH\"\n\n[resolver]\npole_pairs = 1\n";
        assert!(
            out.starts_with("# a motor\nname = \"m\"\n\n[motor]\npole_pairs = 4   # datasheet\n"),
            "{out}"
        );
        assert!(out.ends_with(expected_tail), "{out}");
        assert!(out.contains("[motor.identified]\nphase_resistance = \"0.1301 Ω\"  # step q, 2 recordings\ndate = 2025-03-14\nsource = \"step q: a.csv, b.csv\"\n"), "{out}");
        let pos_ident = out.find("[motor.identified]").unwrap();
        assert!(pos_ident < out.find("[motor.datasheet]").unwrap(), "{out}");
    }

    /// An existing key is replaced in place (its comment too); `source` keeps the other
    /// routines' entries; a lone `inductance` is split into d/q.
    #[test]
    fn updates_in_place() {
        let spec = "[motor]\npole_pairs = 4\n\n[motor.identified]   # lab\nphase_resistance = \"0.65 Ω\"   # old\ninductance = \"5 mH\"\nsource = \"flux: f.csv; step q: old.csv\"\n\n[resolver]\npole_pairs = 1\n";
        let files = vec!["new.csv".to_string()];
        let out = apply(
            spec,
            &[
                Entry {
                    key: "phase_resistance",
                    value: "0.6512 Ω".into(),
                    note: "n".into(),
                },
                Entry {
                    key: "q_inductance",
                    value: "7.612 mH".into(),
                    note: "n".into(),
                },
            ],
            &origin(&files, "step q"),
        )
        .unwrap();
        assert!(
            out.contains("[motor.identified]   # lab\nphase_resistance = \"0.6512 Ω\"  # n\n"),
            "{out}"
        );
        assert!(out.contains("d_inductance = \"5 mH\"\n"), "{out}");
        assert!(out.contains("q_inductance = \"7.612 mH\"  # n\n"), "{out}");
        assert!(!out.contains("\ninductance ="), "{out}");
        assert!(out.contains("source = \"flux: f.csv; step q: new.csv\""), "{out}");
        assert!(out.ends_with("\n[resolver]\npole_pairs = 1\n"), "{out}");
    }

    /// Day counts from Python's `date.fromisoformat(s) - date(1970, 1, 1)`.
    #[test]
    fn dates_from_day_counts() {
        assert_eq!(date_from_unix_days(0), "1970-01-01");
        assert_eq!(date_from_unix_days(10_956), "1999-12-31");
        assert_eq!(date_from_unix_days(11_017), "2000-03-01");
        assert_eq!(date_from_unix_days(19_782), "2024-02-29");
    }

    #[test]
    fn diff_shows_only_changed_lines() {
        let d = line_diff("a\nb\nc\n", "a\nB\nc\nd\n");
        assert_eq!(d, "-   2 | b\n+   2 | B\n+   4 | d\n");
    }

    #[test]
    fn spans_of_values() {
        let r = value_span(SPEC, &["motor", "pole_pairs"]).unwrap();
        assert_eq!(&SPEC[r], "4");
    }
}
