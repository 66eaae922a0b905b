//! The identification of `motorgen identify step|flux|resolver` and of `motorgen
//! commission`: a spec's text and the texts of its recordings and CAN logs (or captures
//! received live) → each routine's estimates, their spread, and the spec's new text with
//! the identified values and their provenance in `[motor.identified]`.
//!
//! No file I/O: the front end reads every file into an [`Input`] (its text, or why it
//! could not be read), locks and reads the spec, and writes the [`Update`] or prints its
//! diff. The results table is written to a [`fmt::Write`] as it is found, so a front end
//! that prints it shows the recordings that were good before one that is not.
//!
//! The checks run in the command's order, which decides what is reported when several
//! inputs are wrong: [`Request::check`] (recordings given, `--date`) before the spec is
//! read; then in [`Request::identify`] the spec's design, `--sample-period`, the CSV
//! recordings (all their problems together), the logs' captures, each recording's
//! identification, and last the design of the updated spec (nothing is returned to
//! write unless every recording is good and the new spec designs).

use std::fmt;
use std::path::Path;
use std::sync::Arc;

use codegen::units::{self, Kind};
use codegen::{Design, Diagnostic, Diagnostics, Source};
use motor_control::can_protocol::Layout;
use motor_control::commissioning::Axis;

use super::candump;
use super::error::Error;
use super::recording::{self, Recording, RecordingKind};
use super::resolver::{self, RatioEstimate};
use super::step::{StepEstimate, StepSetup, identify_step};
use super::writeback::{self, Entry, Origin};
use super::{Spread, flux};

/// One line of the results table (a table that cannot be written is the writer's
/// business: `motorgen` ends the program itself when standard output fails).
macro_rules! say {
    ($out:expr, $($t:tt)*) => {
        let _ = writeln!($out, $($t)*);
    };
}

/// A file as the front end read it.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    /// The file's name as the user gave it (in messages; the provenance takes its last
    /// component).
    pub name: String,
    /// Its text, or why it could not be read: [`Error::Unreadable`] for an I/O failure,
    /// [`Error::Input`] for a file that is no text (located).
    pub text: Result<String, Error>,
}

impl Input {
    /// A file read as `text`.
    pub fn new(name: impl Into<String>, text: impl Into<String>) -> Self {
        Input {
            name: name.into(),
            text: Ok(text.into()),
        }
    }

    /// A text file read as `bytes`: its text, or bad input located at the first byte
    /// that is not UTF-8.
    pub fn from_bytes(name: impl Into<String>, bytes: Vec<u8>) -> Self {
        let name = name.into();
        let text = String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            let text = String::from_utf8_lossy(e.as_bytes());
            Source {
                file: &name,
                text: &text,
            }
            .error(
                at..at,
                "",
                format!("the file is not valid UTF-8 (byte {at})"),
                "a UTF-8 text file; save the spec as UTF-8",
            )
            .into()
        });
        Input { name, text }
    }

    /// A file that could not be read: `problem` (e.g. `cannot read the log: <why>`) at
    /// the file, `accepted` what would be.
    pub fn unreadable(name: impl Into<String>, problem: String, accepted: &str) -> Self {
        let name = name.into();
        Input {
            text: Err(Error::Unreadable(plain_error(&name, problem, accepted))),
            name,
        }
    }

    /// The text, or the failure to read it.
    pub fn text(&self) -> Result<&str, Error> {
        self.text.as_deref().map_err(Clone::clone)
    }

    /// The file name without its directory.
    fn short_name(&self) -> String {
        short(&self.name)
    }
}

/// A checked capture from a CAN log (a file, or the frames received live).
#[derive(Debug, Clone, PartialEq)]
pub struct LoggedCapture {
    /// The log's name: a file, or `IFACE (live)`.
    pub file: String,
    /// The log's text, to locate a problem of the recording at the frame that carried it.
    pub log: Arc<String>,
    /// The capture.
    pub capture: candump::Capture,
    /// Its CSV recording.
    pub csv: String,
}

/// What to identify, from which recordings.
#[derive(Debug, Clone, PartialEq)]
pub enum What {
    /// R and L of one axis and the transport delay from blocked-rotor voltage steps
    /// (thesis A §6.2, (6.3)–(6.8)); writes `phase_resistance` and `d_`/`q_inductance`.
    Step {
        /// The axis the recordings excite.
        axis: Axis,
        /// `step` recordings (CSV).
        csv: Vec<Input>,
    },
    /// ψ_M from zero-current runs at steady speed (thesis A §6.5, (6.10)); writes
    /// `flux_linkage`.
    Flux {
        /// `flux` recordings (CSV).
        csv: Vec<Input>,
    },
    /// The resolver offset from alignment runs (thesis A §6.3, (6.9)), written as
    /// `resolver_offset`; the pole-pair ratio and direction from rotation runs (§6.4),
    /// checked against the spec's pole pairs.
    Resolver {
        /// `resolver_offset` recordings (CSV).
        offset: Vec<Input>,
        /// `pole_pair_ratio` recordings (CSV).
        ratio: Vec<Input>,
    },
}

/// One identification: the routine, its recordings and options.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// The routine and its CSV recordings.
    pub what: What,
    /// The identification date written to `date` (YYYY-MM-DD), `None`: today.
    pub date: Option<String>,
    /// T_s of CSV recordings that do not state it, e.g. `50 µs` (`None`: the spec's
    /// 1/switching_frequency).
    pub sample_period: Option<String>,
    /// `candump -l` logs holding the drive's captures (each identified as its CSV
    /// recording would be).
    pub logs: Vec<Input>,
    /// The board file whose CAN identifiers the drive uses (needed with logs or live
    /// captures).
    pub board: Option<Input>,
    /// Captures received from a live bus ([`crate::commission::Plan::run`]), checked as
    /// a log's.
    pub live: Vec<LoggedCapture>,
}

/// The spec with the identified values written in.
#[derive(Debug, Clone, PartialEq)]
pub struct Update {
    /// The spec's new text (every line identify did not change keeps its bytes).
    pub text: String,
    /// The keys written into `[motor.identified]`, e.g. `phase_resistance`.
    pub keys: Vec<&'static str>,
    /// The new design's provenance, `key: source` per motor value.
    pub provenance: Vec<String>,
}

impl Update {
    /// The changed lines from `old` to the new text, numbered as in both (Myers' diff).
    pub fn diff(&self, old: &str) -> String {
        writeback::line_diff(old, &self.text)
    }
}

/// Where a recording came from: a CSV file, or a capture in a CAN log (whose problems
/// are located at the log's frames).
struct RecordingOrigin {
    capture: Option<LoggedCapture>,
}

impl RecordingOrigin {
    const CSV: RecordingOrigin = RecordingOrigin { capture: None };

    /// `e` located in the log for a capture, unchanged for a CSV file.
    fn locate(&self, e: Diagnostics) -> Diagnostics {
        match &self.capture {
            Some(c) => c.capture.relocate(e, &c.csv, &c.file, &c.log),
            None => e,
        }
    }
}

/// A problem at the start of `file` (an option, a whole file).
fn plain_error(file: &str, problem: String, accepted: &str) -> Diagnostics {
    Diagnostics(vec![Diagnostic {
        file: file.to_string(),
        line: 1,
        column: 1,
        key: String::new(),
        problem,
        accepted: accepted.to_string(),
        excerpt: String::new(),
        notes: Vec::new(),
    }])
}

/// The CAN interface of the design of `spec` on `board`.
pub fn layout(spec: &Source<'_>, board: &Input) -> Result<Layout, Error> {
    let board_text = board.text()?;
    let d = codegen::design_with_board(spec.file, spec.text, &board.name, board_text)?;
    candump::layout(&d).ok_or_else(|| {
        plain_error(
            &board.name,
            "the design has no CAN interface".into(),
            "a board file with a [can] section",
        )
        .into()
    })
}

/// Every capture in `logs`, checked, with its CSV recording. The problems of all logs are
/// reported together; a log that could not be read ends the reading at once.
pub fn read_logs(logs: &[Input], layout: &Layout) -> Result<Vec<LoggedCapture>, Error> {
    let mut out = Vec::new();
    let mut errors = Vec::new();
    for log in logs {
        let text = log.text()?;
        let frames = match candump::parse_log(&log.name, text) {
            Ok(fr) => fr,
            Err(e) => {
                errors.extend(e.0);
                continue;
            }
        };
        match captures_from_frames(&log.name, text.to_string(), &frames, layout) {
            Ok(v) => out.extend(v),
            Err(e) => errors.extend(e.0),
        }
    }
    if errors.is_empty() {
        Ok(out)
    } else {
        Err(Diagnostics(errors).into())
    }
}

/// The checked captures of `frames` (from a log `name` with text `text`) and their CSV.
/// A log file and the frames received live share this.
pub fn captures_from_frames(
    name: &str,
    text: String,
    frames: &[candump::LoggedFrame],
    layout: &Layout,
) -> Result<Vec<LoggedCapture>, Diagnostics> {
    let caps = candump::captures(name, &text, frames, layout)?;
    let log = Arc::new(text);
    Ok(caps
        .into_iter()
        .map(|capture| LoggedCapture {
            file: name.to_string(),
            log: log.clone(),
            csv: capture.to_csv(layout),
            capture,
        })
        .collect())
}

/// `motorgen capture`: every capture in `logs` as (file name, CSV recording), the name
/// `LOGSTEM-N-ROUTINE.csv` with N counting the captures of all logs from 1. All or
/// nothing: a corrupted capture is a located error.
pub fn capture_files(spec: &Input, board: &Input, logs: &[Input]) -> Result<Vec<(String, String)>, Error> {
    let spec_text = spec.text()?;
    let source = Source {
        file: &spec.name,
        text: spec_text,
    };
    let layout = layout(&source, board)?;
    Ok(read_logs(logs, &layout)?
        .into_iter()
        .enumerate()
        .map(|(k, c)| {
            let stem = Path::new(&c.file)
                .file_stem()
                .map_or_else(|| "capture".into(), |s| s.to_string_lossy().into_owned());
            let kind = candump::kind_of(c.capture.header.routine).name();
            (format!("{stem}-{}-{kind}.csv", k + 1), c.csv)
        })
        .collect())
}

/// The file name without its directory, for the result tables and the provenance.
fn short(file: &str) -> String {
    Path::new(file)
        .file_name()
        .map_or_else(|| file.to_string(), |n| n.to_string_lossy().into_owned())
}

fn spread_note(label: &str, s: &Spread) -> String {
    if s.count > 1 {
        format!(
            "{label}, mean of {} recordings, ±{:.2} % (1σ)",
            s.count,
            s.relative_percent()
        )
    } else {
        format!("{label}, 1 recording")
    }
}

/// Parses every CSV recording; all problems are reported together, as an unreadable
/// input if any of them could not be read, otherwise as bad input.
fn recordings(files: &[Input], kind: RecordingKind, ts: f64) -> Result<Vec<Recording>, Error> {
    let mut out = Vec::new();
    let mut errors = Vec::new();
    let mut unreadable = false;
    for f in files {
        match &f.text {
            Ok(text) => match recording::parse(&f.name, text, kind, ts) {
                Ok(r) => out.push(r),
                Err(e) => errors.extend(e.0),
            },
            Err(Error::Unreadable(d)) => {
                unreadable = true;
                errors.extend(d.0.iter().cloned());
            }
            Err(Error::Input(d)) => errors.extend(d.0.iter().cloned()),
            Err(e) => return Err(e.clone()),
        }
    }
    if errors.is_empty() {
        Ok(out)
    } else if unreadable {
        Err(Error::Unreadable(Diagnostics(errors)))
    } else {
        Err(Diagnostics(errors).into())
    }
}

/// `e`, a problem of the updated spec `new`, as a problem of the identified values in
/// the spec on disk `old`: a line identify did not change keeps its place in `old`; a
/// line it wrote is shown as it would be written.
fn blame_identified(e: Diagnostic, old: &str, new: &str, keys: &str) -> Diagnostic {
    let problem = format!(
        "with the identified {keys} written, the spec would not design: {}",
        e.problem
    );
    let accepted = format!(
        "{}; nothing was written: check the recordings, or the spec's values that this rule also uses",
        e.accepted
    );
    match writeback::old_line(old, new, e.line) {
        Some(line) => Diagnostic {
            line,
            problem,
            accepted,
            ..e
        },
        None => Diagnostic {
            problem: format!(
                "{problem} (line {} of the updated spec, which identify would write)",
                e.line
            ),
            accepted,
            ..e
        },
    }
}

/// `entries` written into `spec`, after checking that the new spec designs (identify's
/// write-back, and `motorgen commission … frequency-response --write`).
pub fn update(spec: &Source<'_>, entries: &[Entry], origin: &Origin<'_>) -> Result<Update, Error> {
    let text = spec.text;
    let new = writeback::apply(text, entries, origin).map_err(|r| {
        let at = writeback::value_span(text, &r.path).unwrap_or(0..0);
        Diagnostics::from(spec.error(at, r.key(), r.problem.clone(), r.accepted.clone()))
    })?;
    let keys: Vec<&'static str> = entries.iter().map(|e| e.key).collect();
    let joined = keys.join(", ");
    // The updated spec must still design; otherwise nothing is written.
    let design = codegen::design_source(spec.file, &new).map_err(|d| {
        Diagnostics(
            d.0.into_iter()
                .map(|e| blame_identified(e, text, &new, &joined))
                .collect(),
        )
    })?;
    let provenance = design
        .motor
        .provenance
        .iter()
        .map(|(k, o)| format!("{k}: {}", format!("{:?}", o.source).to_lowercase()))
        .collect();
    Ok(Update {
        text: new,
        keys,
        provenance,
    })
}

impl Request {
    /// The checks that need no spec: that the resolver identification has recordings,
    /// and `--date`. Returns the date to write (`today`, YYYY-MM-DD, when none is given).
    pub fn check(&self, today: &str) -> Result<String, Error> {
        if let What::Resolver { offset, ratio } = &self.what
            && offset.is_empty()
            && ratio.is_empty()
            && self.logs.is_empty()
            && self.live.is_empty()
        {
            return Err(plain_error(
                "motorgen identify resolver",
                "no recordings given".into(),
                "--offset FILE… (resolver_offset runs) and/or --ratio FILE… (pole_pair_ratio runs)",
            )
            .into());
        }
        match &self.date {
            Some(d) => {
                writeback::parse_date(d)
                    .map_err(|e| plain_error("--date", e, "a date YYYY-MM-DD, e.g. --date 2025-03-14"))?;
                Ok(d.clone())
            }
            None => Ok(today.to_string()),
        }
    }

    /// Identifies from the recordings against `spec` (the spec's text as it will be
    /// replaced) and writes the results table to `out`. The spec's update with `date`
    /// (from [`Request::check`]), or `None` when there is nothing to write (a resolver
    /// run with ratio recordings only).
    pub fn identify(&self, spec: &Source<'_>, date: &str, out: &mut dyn fmt::Write) -> Result<Option<Update>, Error> {
        let design = codegen::design_source(spec.file, spec.text)?;
        let ts = self.sample_period(&design)?;
        match &self.what {
            What::Step { axis, csv } => self.step(spec, &design, ts, *axis, csv, date, out).map(Some),
            What::Flux { csv } => self.flux(spec, &design, ts, csv, date, out).map(Some),
            What::Resolver { offset, ratio } => self.resolver(spec, &design, ts, offset, ratio, date, out),
        }
    }

    fn sample_period(&self, design: &Design) -> Result<f64, Error> {
        match &self.sample_period {
            None => Ok(design.drive.sample_period_s),
            Some(s) => units::parse(Kind::Time, s)
                .ok()
                .filter(|t| recording::sample_period_in_range(*t))
                .ok_or_else(|| {
                    plain_error(
                        "--sample-period",
                        format!("`{s}` is not a sample period (one PWM period)"),
                        "a time in [1 µs, 10 ms], e.g. \"50 µs\"",
                    )
                    .into()
                }),
        }
    }

    /// The recordings of the logs and live captures whose kind is one of `kinds`; a
    /// capture of another routine is a located error at its header frame.
    fn can_recordings(
        &self,
        spec: &Source<'_>,
        kinds: &[RecordingKind],
    ) -> Result<Vec<(Recording, RecordingOrigin)>, Error> {
        if self.logs.is_empty() && self.live.is_empty() {
            return Ok(Vec::new());
        }
        let Some(board) = &self.board else {
            return Err(plain_error(
                "--candump",
                "no --board given".into(),
                "--board BOARD_FILE with --candump",
            )
            .into());
        };
        let layout = layout(spec, board)?;
        let mut captures = self.live.clone();
        if !self.logs.is_empty() {
            captures.extend(read_logs(&self.logs, &layout)?);
        }
        let mut out = Vec::new();
        let mut errors = Vec::new();
        for (k, c) in captures.into_iter().enumerate() {
            let kind = candump::kind_of(c.capture.header.routine);
            let ts = c.capture.sample_period_s();
            let name = format!("{} (capture {})", c.file, k + 1);
            let file = c.file.clone();
            let csv = c.csv.clone();
            let origin = RecordingOrigin { capture: Some(c) };
            if !kinds.contains(&kind) {
                let names: Vec<&str> = kinds.iter().map(|k| k.name()).collect();
                let wrong = Diagnostic {
                    file,
                    line: 1,
                    column: 1,
                    key: "ROUTINE".into(),
                    problem: format!(
                        "this is a `{}` capture; this identification reads {}",
                        kind.name(),
                        names.join(" and ")
                    ),
                    accepted: format!("captures of the routine {}", names.join(" or ")),
                    excerpt: String::new(),
                    notes: Vec::new(),
                };
                errors.extend(origin.locate(wrong.into()).0);
                continue;
            }
            match recording::parse(&name, &csv, kind, ts) {
                Ok(r) => out.push((r, origin)),
                Err(e) => errors.extend(origin.locate(e).0),
            }
        }
        if errors.is_empty() {
            Ok(out)
        } else {
            Err(Diagnostics(errors).into())
        }
    }

    /// The CSV recordings and those of the logs together.
    fn all_recordings(
        &self,
        csv: &[Input],
        spec: &Source<'_>,
        kind: RecordingKind,
        ts: f64,
    ) -> Result<Vec<(Recording, RecordingOrigin)>, Error> {
        let mut out: Vec<(Recording, RecordingOrigin)> = recordings(csv, kind, ts)?
            .into_iter()
            .map(|r| (r, RecordingOrigin::CSV))
            .collect();
        out.extend(self.can_recordings(spec, &[kind])?);
        Ok(out)
    }

    /// The names of the recordings for the provenance: file names of the CSV files and
    /// logs, then the log of each live capture (`can0 (live)`, once).
    fn names(&self, files: &[Input]) -> Vec<String> {
        let mut out: Vec<String> = files.iter().chain(&self.logs).map(Input::short_name).collect();
        for c in &self.live {
            if !out.contains(&c.file) {
                out.push(c.file.clone());
            }
        }
        out
    }

    #[allow(clippy::too_many_arguments)]
    fn step(
        &self,
        spec: &Source<'_>,
        design: &Design,
        ts: f64,
        axis: Axis,
        csv: &[Input],
        date: &str,
        out: &mut dyn fmt::Write,
    ) -> Result<Update, Error> {
        let (recs, origins): (Vec<Recording>, Vec<RecordingOrigin>) = self
            .all_recordings(csv, spec, RecordingKind::Step, ts)?
            .into_iter()
            .unzip();
        let name = match axis {
            Axis::D => "d",
            Axis::Q => "q",
        };
        let setup = StepSetup {
            axis,
            taps_q15: design.fir.taps_q15.clone(),
            current_full_scale_a: design.scaling.phase_current.full_scale,
            current_limit_a: design.motor.peak_current_a,
            voltage_limit_v: design.current_loop.voltage_limit_v,
        };
        let mut estimates: Vec<StepEstimate> = Vec::new();
        let mut errors = Vec::new();
        for (r, o) in recs.iter().zip(&origins) {
            match identify_step(r, &setup) {
                Ok(e) => estimates.push(e),
                Err(e) => errors.extend(o.locate(e).0),
            }
        }
        if !errors.is_empty() {
            return Err(Diagnostics(errors).into());
        }
        let Some(first) = recs.first() else {
            return Err(plain_error(spec.file, "no recordings".into(), "--csv FILE…").into());
        };
        say!(
            out,
            "{name} axis, {} recording(s), FIR order {} (group delay {} samples), T_s = {:.1} µs",
            recs.len(),
            design.fir.order,
            design.fir.group_delay_samples,
            first.sample_period_s * 1e6
        );
        say!(
            out,
            "  {:<20} {:>8} {:>10} {:>10} {:>10} {:>12} {:>12}",
            "recording",
            "U [V]",
            "R [Ω]",
            "τ [ms]",
            "L [mH]",
            "t_5% [T_s]",
            "T_d [T_s]"
        );
        for (r, e) in recs.iter().zip(&estimates) {
            say!(
                out,
                "  {:<20} {:>8.3} {:>10.5} {:>10.4} {:>10.5} {:>12.2} {:>12.2}",
                short(&r.file),
                e.voltage_v,
                e.resistance_ohm,
                e.time_constant_s * 1e3,
                e.inductance_h * 1e3,
                e.crossing_5_samples,
                e.delay_samples
            );
        }
        let collect = |f: fn(&StepEstimate) -> f64| Spread::of(&estimates.iter().map(f).collect::<Vec<_>>());
        let (Some(r), Some(l), Some(d)) = (
            collect(|e| e.resistance_ohm),
            collect(|e| e.inductance_h),
            collect(|e| e.delay_samples),
        ) else {
            return Err(plain_error(spec.file, "no recordings".into(), "--csv FILE…").into());
        };
        say!(
            out,
            "  mean: R = {:.5} Ω ± {:.2} %, L_{name} = {:.5} mH ± {:.2} %, transport delay {:.2} ± {:.2} samples (1σ)",
            r.mean,
            r.relative_percent(),
            l.mean * 1e3,
            l.relative_percent(),
            d.mean,
            d.std_dev
        );
        say!(
            out,
            "  (the angle lead assumes {} samples of delay, angle_observer.lead_samples)",
            design.angle_observer.lead_samples
        );
        let label = format!("step {name}");
        let files = self.names(csv);
        let entries = [
            Entry {
                key: "phase_resistance",
                value: writeback::ohms(r.mean),
                note: spread_note(&format!("R_{name} (6.3), {label}"), &r),
            },
            Entry {
                key: if name == "d" { "d_inductance" } else { "q_inductance" },
                value: writeback::henries(l.mean),
                note: spread_note(&format!("L = R·T_r/ln 9 (6.8), {label}"), &l),
            },
        ];
        let origin = Origin {
            date,
            label: &label,
            files: &files,
        };
        update(spec, &entries, &origin)
    }

    fn flux(
        &self,
        spec: &Source<'_>,
        design: &Design,
        ts: f64,
        csv: &[Input],
        date: &str,
        out: &mut dyn fmt::Write,
    ) -> Result<Update, Error> {
        let (recs, origins): (Vec<Recording>, Vec<RecordingOrigin>) = self
            .all_recordings(csv, spec, RecordingKind::Flux, ts)?
            .into_iter()
            .unzip();
        let setup = flux::FluxSetup {
            resistance_ohm: design.motor.phase_resistance_ohm,
            d_inductance_h: design.motor.d_inductance_h,
            max_current_a: 0.1 * design.motor.peak_current_a,
            min_speed_rad_s: 0.05 * design.motor.max_electrical_speed_rad_s,
            voltage_limit_v: design.current_loop.voltage_limit_v,
        };
        let mut values = Vec::new();
        let mut errors = Vec::new();
        for (r, o) in recs.iter().zip(&origins) {
            match flux::identify_flux(r, &setup).map_err(|e| o.locate(e)) {
                Ok(e) => {
                    say!(
                        out,
                        "  {:<20} ω_e = {:>9.1} rad/s  ψ_M = {:.5} Wb (current correction {:+.2e} Wb)",
                        short(&r.file),
                        e.mean_speed_rad_s,
                        e.flux_linkage_wb,
                        -e.correction_wb
                    );
                    values.push(e.flux_linkage_wb);
                }
                Err(e) => errors.extend(e.0),
            }
        }
        if !errors.is_empty() {
            return Err(Diagnostics(errors).into());
        }
        let Some(s) = Spread::of(&values) else {
            return Err(plain_error(spec.file, "no recordings".into(), "--csv FILE…").into());
        };
        say!(
            out,
            "  mean: ψ_M = {:.5} Wb ± {:.2} % (1σ)",
            s.mean,
            s.relative_percent()
        );
        let files = self.names(csv);
        let entries = [Entry {
            key: "flux_linkage",
            value: writeback::webers(s.mean),
            note: spread_note("ψ_M = Σu_q/Σω_e at i = 0 (6.10), flux", &s),
        }];
        let origin = Origin {
            date,
            label: "flux",
            files: &files,
        };
        update(spec, &entries, &origin)
    }

    #[allow(clippy::too_many_arguments)]
    fn resolver(
        &self,
        spec: &Source<'_>,
        design: &Design,
        ts: f64,
        offset: &[Input],
        ratio: &[Input],
        date: &str,
        out: &mut dyn fmt::Write,
    ) -> Result<Option<Update>, Error> {
        let (np, nr) = (
            design.angle_observer.motor_pole_pairs,
            design.angle_observer.resolver_pole_pairs,
        );
        let mut errors = Vec::new();
        // Ratio and direction first: an offset is meaningless with the wrong ratio.
        let can = self.can_recordings(spec, &[RecordingKind::PolePairRatio, RecordingKind::ResolverOffset])?;
        let (can_ratio, can_offset): (Vec<_>, Vec<_>) = can
            .into_iter()
            .partition(|(r, _)| r.kind == RecordingKind::PolePairRatio);
        let mut ratio_recs: Vec<(Recording, RecordingOrigin)> = recordings(ratio, RecordingKind::PolePairRatio, ts)?
            .into_iter()
            .map(|r| (r, RecordingOrigin::CSV))
            .collect();
        ratio_recs.extend(can_ratio);
        let mut ratios: Vec<RatioEstimate> = Vec::new();
        for (r, o) in &ratio_recs {
            match resolver::identify_ratio(r).map_err(|e| o.locate(e)) {
                Ok(e) => {
                    say!(
                        out,
                        "  {:<20} n_p/n_r = {:.4}, directions {}",
                        short(&r.file),
                        e.ratio,
                        if e.directions_agree { "agree" } else { "DISAGREE" }
                    );
                    ratios.push(e);
                }
                Err(e) => errors.extend(e.0),
            }
        }
        if !errors.is_empty() {
            return Err(Diagnostics(errors).into());
        }
        let expected = f64::from(np) / f64::from(nr);
        let at = writeback::value_span(spec.text, &["motor", "pole_pairs"]).unwrap_or(0..0);
        for ((r, _), e) in ratio_recs.iter().zip(&ratios) {
            if !e.directions_agree {
                errors.push(spec.error(
                    at.clone(),
                    "motor.pole_pairs",
                    format!(
                        "{}: the resolver turns against the stator field (§6.4 direction check)",
                        r.file
                    ),
                    "swap two motor phases or the resolver's sine and cosine, then record again",
                ));
            } else if (e.ratio / expected - 1.0).abs() > 0.05 {
                errors.push(spec.error(
                    at.clone(),
                    "motor.pole_pairs",
                    format!(
                        "{}: the measured n_p/n_r = {:.3} disagrees with the spec's {np}/{nr} = {expected:.3}",
                        r.file, e.ratio
                    ),
                    format!(
                        "motor.pole_pairs and resolver.pole_pairs whose ratio is {:.0} (e.g. pole_pairs = {:.0} for a 1-pole-pair resolver)",
                        e.ratio.round(),
                        e.ratio.round()
                    ),
                ));
            }
        }
        if !errors.is_empty() {
            return Err(Diagnostics(errors).into());
        }
        if !ratios.is_empty() {
            say!(
                out,
                "  pole-pair ratio agrees with the spec ({np}/{nr}); directions agree"
            );
        }
        if offset.is_empty() && can_offset.is_empty() {
            return Ok(None);
        }
        let mut recs: Vec<(Recording, RecordingOrigin)> = recordings(offset, RecordingKind::ResolverOffset, ts)?
            .into_iter()
            .map(|r| (r, RecordingOrigin::CSV))
            .collect();
        recs.extend(can_offset);
        let mut offsets = Vec::new();
        for (r, o) in &recs {
            match resolver::identify_offset(r, np, nr).map_err(|e| o.locate(e)) {
                Ok(e) => {
                    say!(
                        out,
                        "  {:<20} θ_off = {:.5} rad (θ_r within ±{:.5} rad over {} rows)",
                        short(&r.file),
                        e.offset_rad,
                        e.deviation_rad,
                        e.rows
                    );
                    offsets.push(e.offset_rad);
                }
                Err(e) => errors.extend(e.0),
            }
        }
        if !errors.is_empty() {
            return Err(Diagnostics(errors).into());
        }
        let Some((mean, dev)) = resolver::combine_offsets(&offsets, np, nr) else {
            return Err(plain_error(spec.file, "no recordings".into(), "--offset FILE…").into());
        };
        say!(
            out,
            "  mean: θ_off = {mean:.5} rad (mod 2π·n_r/n_p), runs within ±{:.3}° electrical",
            (dev * f64::from(np) / f64::from(nr)).to_degrees()
        );
        let files = self.names(offset);
        let entries = [Entry {
            key: "resolver_offset",
            value: writeback::radians(mean),
            note: format!("θ_off = θ_r aligned to phase U (6.9), {} run(s)", offsets.len()),
        }];
        let origin = Origin {
            date,
            label: "resolver offset",
            files: &files,
        };
        update(spec, &entries, &origin).map(Some)
    }
}
