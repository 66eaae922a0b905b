//! Identified values into the spec's `[motor.identified]` section with `toml_edit`:
//! every other line, comment and the layout of the file stay as they were.
//!
//! * Only changed lines are touched ([`apply`]): the others keep their bytes and line
//!   endings, a byte-order mark stays, new lines take the file's line ending.
//! * A written key gets a trailing comment `# identified: …` saying how it was
//!   identified. The next identification replaces such a comment; any other trailing
//!   comment on a replaced value (the user's) is kept on a line above the key, as
//!   `# was <old value>: <comment>`.
//! * `date` is set to the identification date (a TOML date) and `source` lists the
//!   recordings per routine (`step q: a.csv, b.csv; flux: f.csv`): the entry of the
//!   routine just run is replaced, the others are kept; their comments stay.
//! * `[motor.identified]` wins over `[motor.datasheet]` key by key (see `spec`), so one
//!   identified axis may stand next to a datasheet value for the other. If the
//!   identified section holds a single `inductance` (L_d = L_q) and one axis is
//!   identified, the other axis keeps that value as `d_inductance`/`q_inductance` in
//!   its place, with its comments.
//! * An inline `identified = {…}` or `motor = {…}` is refused ([`Refusal`]): it cannot
//!   hold the comments.

use std::ops::Range;

use similar::{Algorithm, DiffTag, capture_diff_slices};
use toml_edit::{Datetime, DocumentMut, Item, Key, Table, Value};

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

/// Why the spec cannot take the identified values; the CLI turns it into a located error.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// Key path of the offending item (e.g. `["motor", "identified"]`), located in the
    /// original text with [`value_span`]; empty for the whole file.
    pub path: Vec<&'static str>,
    /// What is wrong.
    pub problem: String,
    /// What would be accepted.
    pub accepted: String,
}

impl Refusal {
    fn at(path: &[&'static str], problem: impl Into<String>, accepted: impl Into<String>) -> Refusal {
        Refusal {
            path: path.to_vec(),
            problem: problem.into(),
            accepted: accepted.into(),
        }
    }

    /// The dotted key of [`Refusal::path`].
    pub fn key(&self) -> String {
        self.path.join(".")
    }
}

/// What marks a trailing comment as written by `motorgen identify` (replaced on the next
/// identification; any other trailing comment is kept).
pub const NOTE_MARK: &str = "identified:";

/// A `--date`: a TOML local date `YYYY-MM-DD` (no time, no offset).
pub fn parse_date(s: &str) -> Result<Datetime, String> {
    match s.parse::<Datetime>() {
        Ok(d) if d.date.is_some() && d.time.is_none() && d.offset.is_none() => Ok(d),
        Ok(_) => Err(format!("`{s}` is not a plain date")),
        Err(e) => Err(format!("`{s}` is not a date: {e}")),
    }
}

/// The spec text with `entries` written into `[motor.identified]` and the origin noted.
///
/// Only the lines that change are touched: every other line is kept byte for byte (its
/// line ending and comments included), a UTF-8 byte-order mark stays, and new lines take
/// the file's line ending (CRLF when most lines end so). `toml_edit` edits an LF copy of
/// the text; `splice` puts its changed lines into the original.
pub fn apply(text: &str, entries: &[Entry], origin: &Origin<'_>) -> Result<String, Refusal> {
    let (bom, body) = match text.strip_prefix('\u{feff}') {
        Some(rest) => ("\u{feff}", rest),
        None => ("", text),
    };
    let lf = body.replace("\r\n", "\n");
    let edited = edit(&lf, entries, origin)?;
    Ok(format!("{bom}{}", splice(body, &lf, &edited)))
}

/// The value of `key` in `table` set to `v`, keeping the old value's spacing before it and
/// (unless `note` replaces it) its trailing comment.
fn set_keeping_decor(table: &mut Table, key: &str, mut v: Value, note: Option<String>) {
    let old = table.get(key).and_then(Item::as_value).map(|x| x.decor().clone());
    if let Some(old) = old {
        if let Some(p) = old.prefix() {
            v.decor_mut().set_prefix(p.clone());
        }
        if let Some(s) = old.suffix() {
            v.decor_mut().set_suffix(s.clone());
        }
    }
    if let Some(note) = note {
        v.decor_mut().set_suffix(note);
    }
    match table.get_mut(key) {
        Some(item) => *item = Item::Value(v),
        None => {
            table.insert(key, Item::Value(v));
        }
    }
}

/// The trailing comment of a value (without `#`), unless it is one identify wrote.
fn user_comment(item: &Item) -> Option<String> {
    let suffix = item.as_value()?.decor().suffix()?.as_str()?;
    let comment = suffix.trim().strip_prefix('#')?.trim();
    (!comment.is_empty() && !comment.starts_with(NOTE_MARK)).then(|| comment.to_string())
}

/// `decor`'s prefix with `line` added as a comment line just above the key.
fn add_comment_line(decor: &mut toml_edit::Decor, line: &str) {
    let old = decor.prefix().and_then(|p| p.as_str()).unwrap_or("").to_string();
    // The key's indentation is what follows the last newline of its prefix.
    let indent = old.rsplit('\n').next().unwrap_or("").to_string();
    decor.set_prefix(format!("{old}# {line}\n{indent}"));
}

/// The `toml_edit` part of [`apply`] on LF text.
fn edit(text: &str, entries: &[Entry], origin: &Origin<'_>) -> Result<String, Refusal> {
    let mut doc: DocumentMut = text.parse().map_err(|e| {
        Refusal::at(
            &[],
            format!("the spec is not valid TOML: {e}"),
            "a spec that `motorgen check` accepts",
        )
    })?;
    let motor = match doc.get_mut("motor") {
        Some(Item::Table(t)) => t,
        Some(_) => {
            return Err(Refusal::at(
                &["motor"],
                "`motor` is an inline table; identify writes a `[motor.identified]` section with a comment on each value, which an inline table cannot hold",
                "`[motor]` as a section (a `[motor]` header with one `key = value` per line)",
            ));
        }
        None => {
            return Err(Refusal::at(
                &[],
                "the spec has no [motor] table",
                "a spec that `motorgen check` accepts",
            ));
        }
    };
    let motor_position = motor.position();
    match motor.get("identified") {
        None => {
            let mut t = Table::new();
            // Right after [motor] (and its other sub-tables written in the same place).
            t.set_position(motor_position);
            motor.insert("identified", Item::Table(t));
        }
        Some(Item::Table(_)) => {}
        Some(_) => {
            return Err(Refusal::at(
                &["motor", "identified"],
                "`identified` is an inline table; identify adds a comment to each value it writes, which an inline table cannot hold",
                "a `[motor.identified]` section: move the inline table's keys under a `[motor.identified]` header, one `key = value` per line",
            ));
        }
    }
    let Some(Item::Table(ident)) = motor.get_mut("identified") else {
        return Err(Refusal::at(
            &["motor", "identified"],
            "[motor.identified] is not a table",
            "a `[motor.identified]` section",
        ));
    };
    let written = |k: &str| entries.iter().any(|e| e.key == k);
    // A single `inductance` becomes d/q when only one axis is identified now: the axis
    // not identified takes its place, its comments and its value.
    if (written("d_inductance") || written("q_inductance")) && ident.contains_key("inductance") {
        let keys: Vec<String> = ident.iter().map(|(k, _)| k.to_string()).collect();
        let pairs: Vec<(Key, Item)> = keys.iter().filter_map(|k| ident.remove_entry(k)).collect();
        for (key, item) in pairs {
            if key.get() != "inductance" {
                ident.insert_formatted(&key, item);
                continue;
            }
            // The axis kept first, with the old line's comments; the identified one after.
            let mut axes = ["d_inductance", "q_inductance"];
            axes.sort_by_key(|a| written(a));
            let mut decor = Some(key.leaf_decor().clone());
            for axis in axes {
                let mut item = item.clone();
                if written(axis)
                    && let Some(v) = item.as_value_mut()
                {
                    v.decor_mut().set_suffix("");
                }
                let key = Key::new(axis).with_leaf_decor(decor.take().unwrap_or_default());
                ident.insert_formatted(&key, item);
            }
        }
    }
    for e in entries {
        let old = ident.get(e.key).and_then(|item| {
            let shown = item
                .as_value()
                .map(|v| {
                    let mut v = v.clone();
                    v.decor_mut().clear();
                    v.to_string()
                })
                .unwrap_or_default();
            user_comment(item).map(|c| (shown, c))
        });
        if let (Some((shown, comment)), Some(mut key)) = (old, ident.key_mut(e.key)) {
            // The user's own comment on the old value stays, on its own line above.
            let line = if shown.is_empty() || shown == "\"\"" {
                comment
            } else {
                format!("was {shown}: {comment}")
            };
            add_comment_line(key.leaf_decor_mut(), &line);
        }
        set_keeping_decor(
            ident,
            e.key,
            Value::from(e.value.as_str()),
            Some(format!("  # {NOTE_MARK} {}", e.note)),
        );
    }
    let date = parse_date(origin.date).map_err(|e| Refusal::at(&[], e, "a date YYYY-MM-DD"))?;
    set_keeping_decor(ident, "date", Value::from(date), None);
    let entry = format!("{}: {}", origin.label, origin.files.join(", "));
    let old_source = ident.get("source").and_then(Item::as_str).unwrap_or("");
    let mut parts: Vec<String> = old_source
        .split("; ")
        .filter(|p| !p.is_empty() && !p.starts_with(&format!("{}:", origin.label)))
        .map(str::to_string)
        .collect();
    parts.push(entry);
    set_keeping_decor(ident, "source", Value::from(parts.join("; ")), None);
    Ok(doc.to_string())
}

/// The lines of `text`, each with its line ending.
fn lines(text: &str) -> Vec<&str> {
    text.split_inclusive('\n').collect()
}

/// `original` with the lines that differ between `old_lf` (its LF copy: the same lines)
/// and `new_lf` replaced; lines taken from `new_lf` get `original`'s line ending.
fn splice(original: &str, old_lf: &str, new_lf: &str) -> String {
    let (orig, old, new) = (lines(original), lines(old_lf), lines(new_lf));
    debug_assert_eq!(orig.len(), old.len());
    let crlf = original.matches("\r\n").count();
    let eol = if 2 * crlf > original.matches('\n').count() {
        "\r\n"
    } else {
        "\n"
    };
    let mut out = String::with_capacity(new_lf.len() + new_lf.len() / 8);
    for op in capture_diff_slices(Algorithm::Myers, &old, &new) {
        let (tag, o, n) = op.as_tag_tuple();
        match tag {
            DiffTag::Equal => orig[o].iter().for_each(|l| out.push_str(l)),
            DiffTag::Delete => {}
            DiffTag::Insert | DiffTag::Replace => {
                for l in &new[n] {
                    match l.strip_suffix('\n') {
                        Some(body) => {
                            out.push_str(body);
                            out.push_str(eol);
                        }
                        None => out.push_str(l),
                    }
                }
            }
        }
    }
    out
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
/// of `old`/`new`), by Myers' diff (`similar`: O((N+M)·D) time, O(N+M) memory, so a
/// spec of any length with a few changed lines diffs in linear time).
pub fn line_diff(old: &str, new: &str) -> String {
    let (a, b) = (lines(old), lines(new));
    let show = |l: &str| l.trim_end_matches('\n').trim_end_matches('\r').to_string();
    let mut out = String::new();
    for op in capture_diff_slices(Algorithm::Myers, &a, &b) {
        let (tag, o, n) = op.as_tag_tuple();
        if tag == DiffTag::Equal {
            continue;
        }
        for i in o {
            out.push_str(&format!("-{:>4} | {}\n", i + 1, show(a[i])));
        }
        for j in n {
            out.push_str(&format!("+{:>4} | {}\n", j + 1, show(b[j])));
        }
    }
    out
}

/// The line of `old` (1-based) that holds what `new`'s line `line` holds, or `None` when
/// that line is one [`apply`] wrote (changed or added).
pub fn old_line(old: &str, new: &str, line: usize) -> Option<usize> {
    let (a, b) = (lines(old), lines(new));
    capture_diff_slices(Algorithm::Myers, &a, &b).iter().find_map(|op| {
        let (tag, o, n) = op.as_tag_tuple();
        (tag == DiffTag::Equal && n.contains(&(line - 1))).then(|| o.start + (line - 1 - n.start) + 1)
    })
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
        assert!(out.contains("[motor.identified]\nphase_resistance = \"0.1301 Ω\"  # identified: step q, 2 recordings\ndate = 2025-03-14\nsource = \"step q: a.csv, b.csv\"\n"), "{out}");
        let pos_ident = out.find("[motor.identified]").unwrap();
        assert!(pos_ident < out.find("[motor.datasheet]").unwrap(), "{out}");
    }

    /// An existing key is replaced in place (its comment too); `source` keeps the other
    /// routines' entries; a lone `inductance` is split into d/q.
    #[test]
    fn updates_in_place() {
        let spec = "[motor]\npole_pairs = 4\n\n[motor.identified]   # lab\nphase_resistance = \"0.65 Ω\"   # old\ninductance = \"5 mH\"\nsource = \"flux: f.csv; step q: old.csv\"\n\n[resolver]\npole_pairs = 1\n";
        let files = vec!["new.csv".to_string()];
        let out = apply(spec, &q_entries(), &origin(&files, "step q")).unwrap();
        // The user's comment on the replaced value stays, above it, with the old value.
        assert!(
            out.contains(
                "[motor.identified]   # lab\n# was \"0.65 Ω\": old\nphase_resistance = \"0.6512 Ω\"  # identified: n\n"
            ),
            "{out}"
        );
        assert!(out.contains("d_inductance = \"5 mH\"\n"), "{out}");
        assert!(out.contains("q_inductance = \"7.612 mH\"  # identified: n\n"), "{out}");
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

    fn q_entries() -> Vec<Entry> {
        vec![
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
        ]
    }

    /// A CRLF file with a byte-order mark: every untouched line keeps its bytes (the
    /// one LF-only line too), new lines end in CRLF, the BOM stays.
    #[test]
    fn line_endings_and_bom_are_kept() {
        let spec = "\u{feff}# lab copy\r\nname = \"m\"\r\n\r\n[motor]\r\npole_pairs = 4\n\r\n[motor.identified]\r\nphase_resistance = \"0.65 Ω\"  # identified: old\r\ninductance = \"5 mH\"\r\n\r\n[resolver]\r\npole_pairs = 1\r\n";
        let files = vec!["q.csv".to_string()];
        let out = apply(spec, &q_entries(), &origin(&files, "step q")).unwrap();
        let expected = "\u{feff}# lab copy\r\nname = \"m\"\r\n\r\n[motor]\r\npole_pairs = 4\n\r\n[motor.identified]\r\nphase_resistance = \"0.6512 Ω\"  # identified: n\r\nd_inductance = \"5 mH\"\r\nq_inductance = \"7.612 mH\"  # identified: n\r\ndate = 2025-03-14\r\nsource = \"step q: q.csv\"\r\n\r\n[resolver]\r\npole_pairs = 1\r\n";
        assert_eq!(out, expected);
        // An LF file stays LF.
        let lf = apply(SPEC, &q_entries(), &origin(&files, "step q")).unwrap();
        assert!(!lf.contains('\r') && !lf.starts_with('\u{feff}'), "{lf}");
    }

    /// The comment lines above a lone `inductance` stay above the axis it still gives
    /// (the one not identified), with its trailing comment; `date` and `source` keep
    /// their trailing comments; a comment between other keys is untouched.
    #[test]
    fn comments_survive_the_split_and_the_rewrite() {
        let spec = "[motor]\npole_pairs = 4\n\n[motor.identified]\n# LCR meter, 1 kHz\ninductance = \"5 mH\"  # both axes\n# bench 2\ndate = 2024-01-02  # first run\nsource = \"flux: f.csv\"  # see log\n";
        let files = vec!["q.csv".to_string()];
        let out = apply(spec, &q_entries(), &origin(&files, "step q")).unwrap();
        assert_eq!(
            out,
            "[motor]\npole_pairs = 4\n\n[motor.identified]\n# LCR meter, 1 kHz\nd_inductance = \"5 mH\"  # both axes\nq_inductance = \"7.612 mH\"  # identified: n\n# bench 2\ndate = 2025-03-14  # first run\nsource = \"flux: f.csv; step q: q.csv\"  # see log\nphase_resistance = \"0.6512 Ω\"  # identified: n\n"
        );
        // Identifying d next keeps q and the comments; nothing is duplicated.
        let d = [Entry {
            key: "d_inductance",
            value: "5.1 mH".into(),
            note: "m".into(),
        }];
        let again = apply(&out, &d, &origin(&files, "step d")).unwrap();
        assert!(
            again.contains(
                "# LCR meter, 1 kHz\n# was \"5 mH\": both axes\nd_inductance = \"5.1 mH\"  # identified: m\n"
            ),
            "{again}"
        );
        assert_eq!(again.matches("both axes").count(), 1, "{again}");
        let third = apply(&again, &d, &origin(&files, "step d")).unwrap();
        assert_eq!(third.matches('#').count(), again.matches('#').count(), "{third}");
    }

    /// An inline `identified = {…}` (or `motor = {…}`) is refused with the key to locate.
    #[test]
    fn inline_tables_are_refused_at_their_key() {
        let files = vec!["q.csv".to_string()];
        let spec = "[motor]\npole_pairs = 4\nidentified = { inductance = \"5 mH\" }\n";
        let e = apply(spec, &q_entries(), &origin(&files, "step q")).unwrap_err();
        assert_eq!(e.key(), "motor.identified");
        assert!(e.problem.contains("inline table"), "{e:?}");
        let span = value_span(spec, &e.path).unwrap();
        assert_eq!(&spec[span.start..span.start + 1], "{");
        let e = apply("motor = { pole_pairs = 4 }\n", &q_entries(), &origin(&files, "step q")).unwrap_err();
        assert_eq!(e.key(), "motor");
    }

    #[test]
    fn dates_must_be_plain_dates() {
        assert!(parse_date("2025-03-14").is_ok());
        assert!(parse_date("2025-13-01").is_err());
        assert!(parse_date("2025-03-14T10:00:00").is_err());
        assert!(parse_date("yesterday").is_err());
    }

    /// Lines of the new text map back to the old one; written lines map to nothing.
    #[test]
    fn new_lines_map_to_old_ones() {
        let (old, new) = ("a\nb\nc\n", "a\nB\nx\nc\n");
        assert_eq!(old_line(old, new, 1), Some(1));
        assert_eq!(old_line(old, new, 2), None);
        assert_eq!(old_line(old, new, 3), None);
        assert_eq!(old_line(old, new, 4), Some(3));
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
