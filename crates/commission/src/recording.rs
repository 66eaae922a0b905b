//! Recorded commissioning data as CSV: parsing with located errors, and the writer
//! for the firmware's capture buffer.
//!
//! # Format (one file per run of a routine)
//!
//! ```text
//! # motorgen recording: step            ← kind: step | flux | resolver_offset | pole_pair_ratio
//! # sample_period = 50 µs               ← T_s of the `sample` index (optional, see below)
//! # axis = q                            ← step only, optional (must match --axis)
//! # current_trip = 10 A                 ← step only, optional trip level
//! # tripped = sample 812, |i| = 10.2 A  ← written when the routine tripped
//! sample,voltage_v,current_a
//! 0,0,0.0012
//! 1,0,-0.0049
//! 20,4,0.0018
//! ```
//!
//! Lines starting with `#` are comments; those of the form `# key = value` are header
//! keys (only before the column line). The first other line names the columns; every
//! following line holds one number per column. The first column is either `sample`
//! (a period index counted in T_s, increasing by a constant step: a decimated capture
//! keeps every k-th period) or `time_s` (seconds, uniformly spaced). T_s comes from
//! the `sample_period` header, else from `--sample-period`, else from the spec's
//! switching frequency (the firmware samples once per PWM period).
//!
//! Columns per routine (what the firmware routine sees each period, thesis A ch. 6):
//!
//! | kind | columns after `sample`/`time_s` | routine |
//! |------|------------------------------|---------|
//! | `step` | `voltage_v,current_a` | `VoltageStep` → `Capture { sample, voltage, current }` (§6.2) |
//! | `flux` | `omega_e_rad_s,u_q_v` (optional `i_d_a,i_q_a`) | `FluxLinkage` inputs (§6.5) |
//! | `resolver_offset` | `u_alpha_v,theta_r_rad` | `ResolverOffset` demand and input (§6.3) |
//! | `pole_pair_ratio` | `theta_e_rad,theta_r_rad` | `PolePairRatio` generated and resolver angle (§6.4) |

use std::fmt::Write as _;

use motor_control::commissioning::{Axis, Capture, CommissioningError};

use codegen::diagnostic::{Diagnostics, Source};
use codegen::units::{self, Kind};

/// Which routine a recording comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordingKind {
    /// Blocked-rotor voltage step (§6.2).
    Step,
    /// Zero-current run at steady speed (§6.5).
    Flux,
    /// Alignment with +α (§6.3).
    ResolverOffset,
    /// Open-loop rotation (§6.4).
    PolePairRatio,
    /// The current loop broken at the controller's output: u_PI and v = u_PI + d of the
    /// injected axis over one multisine period (`crate::frequency_response`).
    FrequencyResponse,
}

impl RecordingKind {
    /// The name in the `# motorgen recording:` line.
    pub fn name(self) -> &'static str {
        match self {
            RecordingKind::Step => "step",
            RecordingKind::Flux => "flux",
            RecordingKind::ResolverOffset => "resolver_offset",
            RecordingKind::PolePairRatio => "pole_pair_ratio",
            RecordingKind::FrequencyResponse => "frequency_response",
        }
    }

    /// Required columns after the time column.
    pub fn columns(self) -> &'static [&'static str] {
        match self {
            RecordingKind::Step => &["voltage_v", "current_a"],
            RecordingKind::Flux => &["omega_e_rad_s", "u_q_v"],
            RecordingKind::ResolverOffset => &["u_alpha_v", "theta_r_rad"],
            RecordingKind::PolePairRatio => &["theta_e_rad", "theta_r_rad"],
            RecordingKind::FrequencyResponse => &["u_pi_v", "v_v"],
        }
    }

    /// Optional columns after the required ones.
    pub fn optional_columns(self) -> &'static [&'static str] {
        match self {
            RecordingKind::Flux => &["i_d_a", "i_q_a"],
            _ => &[],
        }
    }

    fn header_line(self) -> String {
        let mut cols = vec!["sample"];
        cols.extend(self.columns());
        cols.join(",")
    }
}

/// One header key (`# key = value`).
#[derive(Debug, Clone, PartialEq)]
pub struct HeaderKey {
    /// Key.
    pub key: String,
    /// Value text (trimmed).
    pub value: String,
    /// Byte offset of the value in the file.
    pub offset: usize,
}

/// A parsed recording: uniformly spaced rows of finite numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// File name as the user gave it (for messages).
    pub file: String,
    /// The file's text (for locating errors).
    pub text: String,
    /// Routine.
    pub kind: RecordingKind,
    /// Header keys in file order.
    pub header: Vec<HeaderKey>,
    /// Column names, the time column first.
    pub columns: Vec<String>,
    /// Time of each row in control periods T_s (the `sample` value, or time_s/T_s).
    pub samples: Vec<f64>,
    /// Values of the remaining columns, row by row.
    pub values: Vec<Vec<f64>>,
    /// Byte offset of each row's line start.
    pub row_offsets: Vec<usize>,
    /// T_s \[s\].
    pub sample_period_s: f64,
    /// Row spacing in periods (the decimation, 1 for every period).
    pub spacing: f64,
}

impl Recording {
    /// A diagnostic at byte `offset` of this file.
    pub fn error_at(
        &self,
        offset: usize,
        key: impl Into<String>,
        problem: impl Into<String>,
        accepted: impl Into<String>,
    ) -> Diagnostics {
        Source {
            file: &self.file,
            text: &self.text,
        }
        .error(offset..offset, key, problem, accepted)
        .into()
    }

    /// A diagnostic at data row `row`, column `col` (index into [`Recording::columns`]).
    pub fn error_at_cell(
        &self,
        row: usize,
        col: usize,
        problem: impl Into<String>,
        accepted: impl Into<String>,
    ) -> Diagnostics {
        let start = self.row_offsets.get(row).copied().unwrap_or(0);
        let line_end = self.text[start..].find('\n').map_or(self.text.len(), |i| start + i);
        let mut offset = start;
        for (k, part) in self.text[start..line_end].split(',').enumerate() {
            if k == col {
                offset += part.len() - part.trim_start().len();
                break;
            }
            offset += part.len() + 1;
        }
        let name = self.columns.get(col).cloned().unwrap_or_default();
        self.error_at(offset, name, problem, accepted)
    }

    /// Index of column `name` among the value columns (after the time column).
    pub fn column(&self, name: &str) -> Option<usize> {
        self.columns.iter().skip(1).position(|c| c == name)
    }

    /// The values of column `name`.
    pub fn series(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.column(name)?;
        Some(self.values.iter().map(|r| r[k]).collect())
    }

    /// A header key's entry.
    pub fn header_key(&self, key: &str) -> Option<&HeaderKey> {
        self.header.iter().find(|h| h.key == key)
    }
}

/// Parses `text` (file `file`) as a recording of `kind`. `sample_period_s` is the
/// fallback T_s (CLI option or the spec) used when the file has no `sample_period`
/// header and counts in `sample`.
pub fn parse(file: &str, text: &str, kind: RecordingKind, sample_period_s: f64) -> Result<Recording, Diagnostics> {
    let src = Source { file, text };
    let mut header = Vec::new();
    let mut kind_seen: Option<(String, usize)> = None;
    let mut columns: Option<(Vec<String>, usize)> = None;
    let mut samples = Vec::new();
    let mut values = Vec::new();
    let mut row_offsets = Vec::new();
    let accepted_header = format!("a column line `{}`", kind.header_line());
    let mut offset = 0usize;
    for raw_line in text.split_inclusive('\n') {
        let line_start = offset;
        offset += raw_line.len();
        let line = raw_line.trim_end_matches(['\n', '\r']);
        let trimmed = line.trim();
        if trimmed.is_empty() {
            continue;
        }
        if let Some(comment) = trimmed.strip_prefix('#') {
            if columns.is_some() {
                continue;
            }
            let c = comment.trim();
            if let Some(k) = c.strip_prefix("motorgen recording:") {
                let value_at = line_start + line.find("motorgen recording:").unwrap_or(0) + "motorgen recording:".len();
                kind_seen = Some((k.trim().to_string(), value_at));
            } else if let (Some((k, _)), Some(eq)) = (c.split_once('='), line.find('=')) {
                let after = &line[eq + 1..];
                header.push(HeaderKey {
                    key: k.trim().to_string(),
                    value: after.trim().to_string(),
                    offset: line_start + eq + 1 + (after.len() - after.trim_start().len()),
                });
            }
            continue;
        }
        let Some((cols, _)) = &columns else {
            let names: Vec<String> = line.split(',').map(|s| s.trim().to_string()).collect();
            check_columns(&src, line_start, line, &names, kind)?;
            columns = Some((names, line_start));
            continue;
        };
        let parts: Vec<&str> = line.split(',').collect();
        if parts.len() != cols.len() {
            return Err(src
                .error(
                    line_start..line_start,
                    "",
                    format!(
                        "this row has {} fields, the column line names {}",
                        parts.len(),
                        cols.len()
                    ),
                    format!("{} comma-separated numbers per row ({})", cols.len(), cols.join(",")),
                )
                .into());
        }
        let mut row = Vec::with_capacity(parts.len());
        let mut at = line_start;
        for (k, part) in parts.iter().enumerate() {
            let lead = part.len() - part.trim_start().len();
            let cell = part.trim();
            let v = cell.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                let what = if cell.parse::<f64>().is_ok() {
                    format!("`{cell}` is not a finite number (NaN or infinite)")
                } else {
                    format!("`{cell}` is not a number")
                };
                src.error(
                    at + lead..at + lead,
                    cols[k].clone(),
                    what,
                    "a finite decimal number such as 0.125 or -1.5e-3",
                )
            })?;
            row.push(v);
            at += part.len() + 1;
        }
        samples.push(row[0]);
        values.push(row[1..].to_vec());
        row_offsets.push(line_start);
    }
    let Some((columns, _)) = columns else {
        return Err(src
            .error(
                text.len()..text.len(),
                "",
                "the file has no column line and no data",
                accepted_header,
            )
            .into());
    };
    if let Some((k, at)) = &kind_seen
        && k != kind.name()
    {
        return Err(src
            .error(
                *at..*at,
                "motorgen recording",
                format!(
                    "this is a `{k}` recording, but a `{}` recording is needed here",
                    kind.name()
                ),
                format!("a file starting with `# motorgen recording: {}`", kind.name()),
            )
            .into());
    }
    let mut rec = Recording {
        file: file.to_string(),
        text: text.to_string(),
        kind,
        header,
        columns,
        samples,
        values,
        row_offsets,
        sample_period_s,
        spacing: 1.0,
    };
    if rec.samples.len() < 2 {
        return Err(rec.error_at(
            text.len(),
            "",
            format!("the recording has {} data rows", rec.samples.len()),
            "a recording with many rows (a step needs its baseline, the rise and the settled current)",
        ));
    }
    if let Some(h) = rec.header_key("sample_period") {
        let t = units::parse(Kind::Time, &h.value)
            .ok()
            .filter(|t| sample_period_in_range(*t))
            .ok_or_else(|| {
                src.error(
                    h.offset..h.offset,
                    "sample_period",
                    format!("`{}` is not a sample period: {SAMPLE_PERIOD_REASON}", h.value),
                    format!("a time in {SAMPLE_PERIOD_RANGE}, e.g. \"50 µs\""),
                )
            })?;
        rec.sample_period_s = t;
    }
    check_values(&rec)?;
    timebase(&mut rec)?;
    if !sample_period_in_range(rec.sample_period_s) {
        // T_s from the time_s spacing (no header), or the caller's fallback.
        return Err(rec.error_at_cell(
            1,
            0,
            format!(
                "the sample period T_s = {} s (from {}) is outside {SAMPLE_PERIOD_RANGE}: {SAMPLE_PERIOD_REASON}",
                rec.sample_period_s,
                if rec.columns[0] == "time_s" {
                    "the time_s spacing"
                } else {
                    "--sample-period or the spec"
                }
            ),
            format!("rows one period apart with T_s in {SAMPLE_PERIOD_RANGE}, or a `# sample_period = 50 µs` header"),
        ));
    }
    Ok(rec)
}

/// Accepted sample periods T_s: one PWM period of a drive switching at 100 Hz to 1 MHz,
/// around the spec's `drive.switching_frequency` range (the firmware samples once per period).
pub const SAMPLE_PERIOD_S: (f64, f64) = (1e-6, 1e-2);
const SAMPLE_PERIOD_RANGE: &str = "[1 µs, 10 ms]";
const SAMPLE_PERIOD_REASON: &str = "the firmware samples once per PWM period, and drives switch at 100 Hz to 1 MHz";

/// Whether `t` \[s\] is an accepted sample period.
pub fn sample_period_in_range(t: f64) -> bool {
    t.is_finite() && (SAMPLE_PERIOD_S.0..=SAMPLE_PERIOD_S.1).contains(&t)
}

/// The accepted magnitude of a column's values and why, by the column's unit suffix.
fn column_range(name: &str) -> (f64, &'static str) {
    if name == "sample" {
        (
            u32::MAX as f64,
            "|sample| ≤ 4294967295: the firmware counts periods in a u32",
        )
    } else if name == "time_s" {
        (
            1e5,
            "|time_s| ≤ 1e5 s: a commissioning run lasts seconds, and beyond a day f64 times lose the row spacing",
        )
    } else if name.ends_with("_rad_s") {
        (1e6, "|ω| ≤ 1e6 rad/s: beyond any machine's electrical speed")
    } else if name.ends_with("_rad") {
        (
            1e3,
            "|θ| ≤ 1000 rad: angles are recorded wrapped to ±π (or a few turns)",
        )
    } else if name.ends_with("_v") {
        (2000.0, "|u| ≤ 2000 V: the DC-link range of the motor spec")
    } else if name.ends_with("_a") {
        (1e5, "|i| ≤ 100 kA: the current range of the motor spec")
    } else {
        (f64::MAX, "")
    }
}

/// Every value within its column's range ([`column_range`]): a number beyond it is a
/// corrupted or mis-scaled capture, never input to an estimate.
fn check_values(rec: &Recording) -> Result<(), Diagnostics> {
    for (row, (t, values)) in rec.samples.iter().zip(&rec.values).enumerate() {
        for (col, v) in std::iter::once(t).chain(values).enumerate() {
            let (max, why) = column_range(&rec.columns[col]);
            if v.abs() > max {
                return Err(rec.error_at_cell(
                    row,
                    col,
                    format!("{} = {v} is out of range", rec.columns[col]),
                    why.to_string(),
                ));
            }
        }
    }
    Ok(())
}

fn check_columns(
    src: &Source<'_>,
    at: usize,
    line: &str,
    names: &[String],
    kind: RecordingKind,
) -> Result<(), Diagnostics> {
    let accepted = format!(
        "the column line `{}` (the first column may be `time_s` instead of `sample`{})",
        kind.header_line(),
        if kind.optional_columns().is_empty() {
            String::new()
        } else {
            format!(", optional extra columns: {}", kind.optional_columns().join(","))
        }
    );
    let first = names.first().map(String::as_str).unwrap_or("");
    if first != "sample" && first != "time_s" {
        return Err(src
            .error(
                at..at,
                first.to_string(),
                format!("the first column is `{first}`, not a time column"),
                accepted,
            )
            .into());
    }
    let required = kind.columns();
    let optional = kind.optional_columns();
    let rest = &names[1..];
    let ok = rest.len() >= required.len()
        && rest.iter().zip(required).all(|(a, b)| a == b)
        && (rest.len() == required.len() || rest[required.len()..] == *optional);
    if ok {
        Ok(())
    } else {
        let bad = rest
            .iter()
            .zip(required.iter().chain(optional))
            .position(|(a, b)| a != b)
            .unwrap_or(rest.len().min(required.len()));
        // Byte offset of field `bad + 1` in the line (the end of the line if missing).
        let mut col_at = at;
        for (k, part) in line.split(',').enumerate() {
            if k == bad + 1 {
                col_at += part.len() - part.trim_start().len();
                break;
            }
            col_at += part.len() + 1;
        }
        let col_at = col_at.min(at + line.len());
        Err(src
            .error(
                col_at..col_at,
                names.get(bad + 1).cloned().unwrap_or_default(),
                format!(
                    "the columns are `{}`; a {} recording needs `{}`",
                    names.join(","),
                    kind.name(),
                    kind.header_line()
                ),
                accepted,
            )
            .into())
    }
}

/// Converts the time column to periods and checks it increases uniformly.
fn timebase(rec: &mut Recording) -> Result<(), Diagnostics> {
    let in_seconds = rec.columns[0] == "time_s";
    let n = rec.samples.len();
    let first_step = rec.samples[1] - rec.samples[0];
    for k in 1..n {
        let d = rec.samples[k] - rec.samples[k - 1];
        if d <= 0.0 {
            return Err(rec.error_at_cell(
                k,
                0,
                format!(
                    "{} goes from {} to {}: time must increase row by row (non-monotonic time)",
                    rec.columns[0],
                    rec.samples[k - 1],
                    rec.samples[k]
                ),
                "strictly increasing sample indices or times, one row per captured period",
            ));
        }
        // Index columns are exact; times are printed with limited digits.
        let tolerance = if in_seconds { 0.01 * first_step } else { 0.0 };
        if (d - first_step).abs() > tolerance {
            return Err(rec.error_at_cell(
                k,
                0,
                format!(
                    "the spacing changes from {first_step} to {d} here: rows must be uniformly spaced (the FIR runs at the capture rate)"
                ),
                "rows one period (or a constant decimation of periods) apart, without gaps",
            ));
        }
    }
    if in_seconds {
        if rec.header_key("sample_period").is_none() {
            // Without a stated T_s the row spacing is one period.
            rec.sample_period_s = first_step;
        }
        let ts = rec.sample_period_s;
        for s in &mut rec.samples {
            *s /= ts;
        }
        rec.spacing = first_step / ts;
    } else {
        if first_step.fract() != 0.0 || rec.samples[0].fract() != 0.0 {
            return Err(rec.error_at_cell(
                0,
                0,
                "sample indices must be whole numbers",
                "period indices 0, 1, 2, … (or 0, k, 2k, … for a decimated capture)",
            ));
        }
        rec.spacing = first_step;
    }
    Ok(())
}

/// How a [`VoltageStep`](motor_control::commissioning::VoltageStep) run ended, for the
/// header of [`write_step_csv`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepRun {
    /// Excited axis.
    pub axis: Axis,
    /// Trip level \[A\].
    pub current_trip: f32,
    /// `Err(Tripped)` if the routine tripped.
    pub outcome: Result<(), CommissioningError>,
}

/// The CSV of a captured step (see the module documentation for the format):
/// `sample_period_s` is T_s \[s\]; the rows are the captures unchanged (f32 printed
/// exactly by its shortest round-trip representation).
pub fn write_step_csv(captures: &[Capture], sample_period_s: f64, run: &StepRun) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# motorgen recording: step");
    let _ = writeln!(s, "# sample_period = {} µs", sample_period_s * 1e6);
    let _ = writeln!(
        s,
        "# axis = {}",
        match run.axis {
            Axis::D => "d",
            Axis::Q => "q",
        }
    );
    let _ = writeln!(s, "# current_trip = {} A", run.current_trip);
    if let Err(e) = run.outcome {
        match e {
            CommissioningError::Tripped { sample, current } => {
                let _ = writeln!(s, "# tripped = sample {sample}, |i| = {current} A");
            }
            other => {
                let _ = writeln!(s, "# tripped = {other:?}");
            }
        }
    }
    let _ = writeln!(s, "{}", RecordingKind::Step.header_line());
    for c in captures {
        let _ = writeln!(s, "{},{},{}", c.sample, c.voltage, c.current);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use codegen::diagnostic::Diagnostic;

    #[allow(clippy::result_large_err)]
    fn parse_step(text: &str) -> Result<Recording, Diagnostic> {
        parse("rec.csv", text, RecordingKind::Step, 50e-6).map_err(|e| e.0[0].clone())
    }

    #[test]
    fn reads_header_columns_and_decimated_samples() {
        let r = parse_step(
            "# motorgen recording: step\n# sample_period = 100 µs\n# axis = d\nsample,voltage_v,current_a\n0,0,0.5\n2,4,1\n4,4,1.5\n",
        )
        .expect("valid");
        assert!((r.sample_period_s - 100e-6).abs() < 1e-18);
        assert_eq!(r.spacing, 2.0);
        assert_eq!(r.samples, [0.0, 2.0, 4.0]);
        assert_eq!(r.series("current_a").unwrap(), [0.5, 1.0, 1.5]);
        assert_eq!(r.header_key("axis").unwrap().value, "d");
    }

    #[test]
    fn time_column_sets_the_period() {
        let r = parse_step("time_s,voltage_v,current_a\n0,0,0\n0.0001,1,0\n0.0002,1,0.1\n").expect("valid");
        assert!((r.sample_period_s - 1e-4).abs() < 1e-15);
        assert_eq!(r.spacing, 1.0);
    }

    #[test]
    fn nan_is_located_by_line_column_and_name() {
        let e = parse_step("sample,voltage_v,current_a\n0,0,0\n1,4,NaN\n").unwrap_err();
        assert_eq!((e.line, e.column), (3, 5));
        assert_eq!(e.key, "current_a");
        assert!(e.problem.contains("not a finite number"), "{}", e.problem);
    }

    /// Issue 18: sample periods like 1e300 s or 0 s are located errors naming the range.
    #[test]
    fn sample_periods_outside_one_pwm_period_are_refused() {
        for t in ["1e300 s", "0 s", "1e-300 s", "-1 µs", "20 ms"] {
            let e = parse_step(&format!(
                "# sample_period = {t}\nsample,voltage_v,current_a\n0,0,0\n1,4,1\n"
            ))
            .unwrap_err();
            assert_eq!((e.line, e.column, e.key.as_str()), (1, 19, "sample_period"), "{t}: {e}");
            assert!(e.accepted.contains("[1 µs, 10 ms]"), "{e}");
        }
        // From the time_s spacing without a header: 1000 s per row.
        let e = parse_step("time_s,voltage_v,current_a\n0,0,0\n1000,4,1\n").unwrap_err();
        assert_eq!((e.line, e.key.as_str()), (3, "time_s"), "{e}");
        assert!(e.problem.contains("outside [1 µs, 10 ms]"), "{e}");
        // The fallback (CLI or spec) is judged too.
        let e = parse(
            "rec.csv",
            "sample,voltage_v,current_a\n0,0,0\n1,4,1\n",
            RecordingKind::Step,
            1e300,
        )
        .unwrap_err();
        assert!(e.0[0].problem.contains("--sample-period or the spec"), "{}", e.0[0]);
    }

    /// Huge offsets and values beyond any drive are located at their cell with the range.
    #[test]
    fn values_beyond_their_column_range_are_located() {
        let e = parse_step("sample,voltage_v,current_a\n1e300,0,0\n1e300,4,1\n").unwrap_err();
        assert_eq!((e.line, e.column, e.key.as_str()), (2, 1, "sample"), "{e}");
        assert!(e.accepted.contains("4294967295"), "{e}");
        let e = parse_step("sample,voltage_v,current_a\n0,0,0\n1,4,6.1e201\n").unwrap_err();
        assert_eq!((e.line, e.column, e.key.as_str()), (3, 5, "current_a"), "{e}");
        assert!(e.accepted.contains("100 kA"), "{e}");
        let e = parse(
            "r.csv",
            "sample,theta_e_rad,theta_r_rad\n0,0,0\n1,0.1,1e200\n",
            RecordingKind::PolePairRatio,
            50e-6,
        )
        .unwrap_err();
        assert_eq!((e.0[0].line, e.0[0].key.as_str()), (3, "theta_r_rad"), "{}", e.0[0]);
        // Empty and one-row recordings.
        for text in ["sample,voltage_v,current_a\n", "sample,voltage_v,current_a\n0,0,0\n"] {
            let e = parse_step(text).unwrap_err();
            assert!(e.problem.contains("data rows") && e.line >= 1, "{e}");
        }
    }

    #[test]
    fn non_monotonic_time_is_an_error() {
        let e = parse_step("sample,voltage_v,current_a\n0,0,0\n1,4,0.1\n1,4,0.2\n").unwrap_err();
        assert_eq!((e.line, e.column, e.key.as_str()), (4, 1, "sample"));
        assert!(e.problem.contains("non-monotonic"), "{}", e.problem);
    }

    #[test]
    fn wrong_columns_and_kind_are_named() {
        let e = parse_step("sample,voltage_v,amps\n0,0,0\n").unwrap_err();
        assert_eq!(e.key, "amps");
        assert_eq!((e.line, e.column), (1, 18));
        assert!(e.accepted.contains("sample,voltage_v,current_a"), "{}", e.accepted);
        let e = parse_step("# motorgen recording: flux\nsample,voltage_v,current_a\n0,0,0\n1,1,1\n").unwrap_err();
        assert!(e.problem.contains("`flux` recording"), "{}", e.problem);
        let e = parse_step("sample,voltage_v,current_a\n0,0\n").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.problem.contains("2 fields"), "{}", e.problem);
    }

    /// The writer's output parses back to the same numbers.
    #[test]
    fn writer_round_trips() {
        let caps = [
            Capture {
                sample: 0,
                voltage: 0.0,
                current: 0.001,
            },
            Capture {
                sample: 1,
                voltage: 4.0,
                current: -0.1234567,
            },
        ];
        let run = StepRun {
            axis: Axis::Q,
            current_trip: 10.0,
            outcome: Ok(()),
        };
        let text = write_step_csv(&caps, 50e-6, &run);
        let r = parse_step(&text).expect("parses");
        assert!((r.sample_period_s - 50e-6).abs() < 1e-18);
        // Printed as the shortest decimal that reads back as the same f32.
        let back: Vec<f32> = r.series("current_a").unwrap().iter().map(|&v| v as f32).collect();
        assert_eq!(back, [0.001f32, -0.1234567f32]);
        assert_eq!(r.header_key("axis").unwrap().value, "q");
    }
}
