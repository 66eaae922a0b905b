//! `motorgen identify step|flux|resolver <spec> …`: identified values from recorded
//! commissioning runs (thesis A chapter 6) into the spec's `[motor.identified]`.
//!
//! The spec is locked before it is read (see [`crate::atomic::LockedSpec`]): two
//! identifications of one spec run one after the other, and the second rewrites what the
//! first wrote. Every recording is read and evaluated first; the spec is only rewritten
//! when all of them are good and the updated spec designs without error, through a
//! temporary file renamed over the spec (never a partial spec). `--dry-run` reads without
//! the lock and prints the change instead.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand, ValueEnum};
use codegen::units::{self, Kind};
use codegen::{Design, Diagnostic, Diagnostics, Source};
use motor_commission::candump;
use motor_commission::recording::{self, Recording, RecordingKind};
use motor_commission::resolver::{self, RatioEstimate};
use motor_commission::step::{StepEstimate, StepSetup, identify_step};
use motor_commission::writeback::{self, Entry, Origin};
use motor_commission::{Spread, flux};
use motor_control::can_protocol::Layout;
use motor_control::commissioning::Axis;

use crate::atomic::LockedSpec;
use crate::exit::{Exit, Failure};
use crate::output::{out, outln};

/// What to identify.
#[derive(Subcommand)]
pub enum What {
    /// R and L of one axis and the transport delay from blocked-rotor voltage steps
    /// (thesis A §6.2, (6.3)–(6.8)); writes phase_resistance and d_/q_inductance.
    Step {
        /// The motor spec to update.
        spec: PathBuf,
        /// The axis the recordings excite.
        #[arg(long, value_enum)]
        axis: AxisArg,
        /// One or more `step` recordings (CSV, see `motor_commission::recording`).
        #[arg(long, required_unless_present = "candump", num_args = 1..)]
        csv: Vec<PathBuf>,
        #[command(flatten)]
        common: Common,
    },
    /// ψ_M from zero-current runs at steady speed (thesis A §6.5, (6.10)); writes
    /// flux_linkage.
    Flux {
        /// The motor spec to update.
        spec: PathBuf,
        /// One or more `flux` recordings.
        #[arg(long, required_unless_present = "candump", num_args = 1..)]
        csv: Vec<PathBuf>,
        #[command(flatten)]
        common: Common,
    },
    /// Resolver offset from alignment runs (thesis A §6.3, (6.9)), written as
    /// resolver_offset; pole-pair ratio and direction from rotation runs (§6.4),
    /// checked against the spec's pole pairs.
    Resolver {
        /// The motor spec to update.
        spec: PathBuf,
        /// `resolver_offset` recordings.
        #[arg(long, num_args = 1..)]
        offset: Vec<PathBuf>,
        /// `pole_pair_ratio` recordings.
        #[arg(long, num_args = 1..)]
        ratio: Vec<PathBuf>,
        #[command(flatten)]
        common: Common,
    },
}

/// Options of every identification.
#[derive(Args)]
pub struct Common {
    /// Print the change to the spec instead of writing it.
    #[arg(long)]
    dry_run: bool,
    /// Identification date written to `date` (YYYY-MM-DD; default: today, UTC).
    #[arg(long)]
    date: Option<String>,
    /// T_s of the recordings' `sample` column when they do not state it, e.g. "50 µs"
    /// (default: 1/switching_frequency of the spec).
    #[arg(long)]
    sample_period: Option<String>,
    /// Logs of the CAN bus (`candump -l` format) holding the drive's captures: each
    /// capture is checked and identified as its CSV recording would be.
    #[arg(long, num_args = 1.., value_name = "LOG", requires = "board")]
    pub candump: Vec<PathBuf>,
    /// The board file whose CAN identifiers the drive uses (needed with --candump).
    #[arg(long, value_name = "BOARD_FILE")]
    pub board: Option<PathBuf>,
    /// Captures received from a live bus (`motorgen commission`), checked as a log's.
    #[arg(skip)]
    pub live: Vec<LoggedCapture>,
}

impl Common {
    /// The options of an identification from captures received live on the bus
    /// (`motorgen commission`): identified exactly as those of a `--candump` log.
    pub fn live(dry_run: bool, date: Option<String>, board: PathBuf, captures: Vec<LoggedCapture>) -> Self {
        Common {
            dry_run,
            date,
            sample_period: None,
            candump: Vec::new(),
            board: Some(board),
            live: captures,
        }
    }
}

/// Where a recording came from: a CSV file, or a capture in a CAN log (whose problems
/// are located at the log's frames).
pub struct RecordingOrigin {
    capture: Option<(candump::Capture, String, String)>,
    /// The log's text, for relocating.
    log: std::rc::Rc<String>,
}

impl RecordingOrigin {
    fn csv() -> Self {
        RecordingOrigin {
            capture: None,
            log: std::rc::Rc::new(String::new()),
        }
    }

    /// `e` located in the log for a capture, unchanged for a CSV file.
    fn locate(&self, e: Diagnostics) -> Diagnostics {
        match &self.capture {
            Some((c, csv, file)) => c.relocate(e, csv, file, &self.log),
            None => e,
        }
    }
}

/// A checked capture from a log: (log file, log text, capture, its CSV recording).
pub type LoggedCapture = (String, std::rc::Rc<String>, candump::Capture, String);

/// The CAN interface of the spec on `--board`.
pub fn layout(spec: &Path, board: &Path) -> Result<Layout, Failure> {
    let text = crate::read_spec(spec)?;
    let board_text = crate::read_spec(board)?;
    let d = codegen::design_with_board(
        &spec.display().to_string(),
        &text,
        &board.display().to_string(),
        &board_text,
    )?;
    candump::layout(&d).ok_or_else(|| {
        Failure::from(plain_error(
            &board.display().to_string(),
            "the design has no CAN interface".into(),
            "a board file with a [can] section",
        ))
    })
}

/// Every capture in `logs`, checked and turned into its CSV text: (log file, log text,
/// capture, CSV). The reading of frames from a live socket shares everything after the
/// frames ([`captures_from_frames`]).
pub fn read_logs(logs: &[PathBuf], layout: &Layout) -> Result<Vec<LoggedCapture>, Failure> {
    let mut out = Vec::new();
    let mut errors = Vec::new();
    for f in logs {
        let name = f.display().to_string();
        let text = match std::fs::read_to_string(f) {
            Ok(t) => t,
            Err(e) => {
                return Err(Failure::new(
                    Exit::Io,
                    plain_error(
                        &name,
                        format!("cannot read the log: {e}"),
                        "a readable `candump -l` log",
                    )
                    .to_string(),
                ));
            }
        };
        let frames = match candump::parse_log(&name, &text) {
            Ok(fr) => fr,
            Err(e) => {
                errors.extend(e.0);
                continue;
            }
        };
        match captures_from_frames(&name, text, &frames, layout) {
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
pub fn captures_from_frames(
    name: &str,
    text: String,
    frames: &[candump::LoggedFrame],
    layout: &Layout,
) -> Result<Vec<LoggedCapture>, Diagnostics> {
    let caps = candump::captures(name, &text, frames, layout)?;
    let text = std::rc::Rc::new(text);
    Ok(caps
        .into_iter()
        .map(|c| {
            let csv = c.to_csv(layout);
            (name.to_string(), text.clone(), c, csv)
        })
        .collect())
}

/// The recordings of `--candump` whose kind is one of `kinds`; a capture of another
/// routine is a located error at its header frame.
fn can_recordings(
    common: &Common,
    spec: &Path,
    kinds: &[RecordingKind],
) -> Result<Vec<(Recording, RecordingOrigin)>, Failure> {
    if common.candump.is_empty() && common.live.is_empty() {
        return Ok(Vec::new());
    }
    let Some(board) = &common.board else {
        return Err(plain_error(
            "--candump",
            "no --board given".into(),
            "--board BOARD_FILE with --candump",
        )
        .into());
    };
    let layout = layout(spec, board)?;
    let mut captures = common.live.clone();
    if !common.candump.is_empty() {
        captures.extend(read_logs(&common.candump, &layout)?);
    }
    let mut out = Vec::new();
    let mut errors = Vec::new();
    for (k, (file, log, cap, csv)) in captures.into_iter().enumerate() {
        let kind = candump::kind_of(cap.header.routine);
        let origin = RecordingOrigin {
            capture: Some((cap, csv.clone(), file.clone())),
            log,
        };
        if !kinds.contains(&kind) {
            let names: Vec<&str> = kinds.iter().map(|k| k.name()).collect();
            errors.extend(
                origin
                    .locate(
                        codegen::Diagnostic {
                            file: file.clone(),
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
                        }
                        .into(),
                    )
                    .0,
            );
            continue;
        }
        let name = format!("{file} (capture {})", k + 1);
        match recording::parse(&name, &csv, kind, cap_ts(&origin)) {
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

fn cap_ts(o: &RecordingOrigin) -> f64 {
    o.capture.as_ref().map_or(0.0, |(c, _, _)| c.sample_period_s())
}

/// The recordings of `--csv` files and `--candump` logs together.
fn all_recordings(
    csv: &[PathBuf],
    common: &Common,
    spec: &Path,
    kind: RecordingKind,
    ts: f64,
) -> Result<Vec<(Recording, RecordingOrigin)>, Failure> {
    let mut out: Vec<(Recording, RecordingOrigin)> = recordings(csv, kind, ts)?
        .into_iter()
        .map(|r| (r, RecordingOrigin::csv()))
        .collect();
    out.extend(can_recordings(common, spec, &[kind])?);
    Ok(out)
}

/// `--axis`.
#[derive(Clone, Copy, ValueEnum)]
pub enum AxisArg {
    /// Direct axis.
    D,
    /// Quadrature axis.
    Q,
}

fn plain_error(file: &str, problem: String, accepted: &str) -> Diagnostics {
    Diagnostics(vec![Diagnostic {
        file: file.to_string(),
        line: 1,
        column: 1,
        key: String::new(),
        problem,
        accepted: accepted.to_string(),
        excerpt: String::new(),
    }])
}

/// The spec to update: its text and design, and (unless `--dry-run`) its lock, taken
/// before the text is read.
struct Loaded {
    lock: Option<LockedSpec>,
    text: String,
    design: Design,
    /// `--date` or today.
    date: String,
}

/// Checks `--date`, then locks (unless `--dry-run`), reads and designs the spec.
fn load(spec: &Path, common: &Common) -> Result<Loaded, Failure> {
    let date = match &common.date {
        Some(d) => {
            writeback::parse_date(d)
                .map_err(|e| plain_error("--date", e, "a date YYYY-MM-DD, e.g. --date 2025-03-14"))?;
            d.clone()
        }
        None => today(),
    };
    let (lock, text) = if common.dry_run {
        (None, crate::read_spec(spec)?)
    } else {
        if std::fs::metadata(spec).is_err() {
            // A missing spec is reported as every command reports it.
            crate::read_spec(spec)?;
        }
        let mut lock = LockedSpec::open(spec)?;
        let text = crate::spec_text(spec, std::mem::take(&mut lock.bytes))?;
        (Some(lock), text)
    };
    let design = codegen::design_source(&spec.display().to_string(), &text)?;
    Ok(Loaded {
        lock,
        text,
        design,
        date,
    })
}

/// Reads and parses every recording; all problems are reported together.
/// An unreadable recording makes it an I/O failure, otherwise bad input.
fn recordings(files: &[PathBuf], kind: RecordingKind, ts: f64) -> Result<Vec<Recording>, Failure> {
    let mut out = Vec::new();
    let mut errors = Vec::new();
    let mut unreadable = false;
    for f in files {
        let name = f.display().to_string();
        match std::fs::read_to_string(f) {
            Ok(text) => match recording::parse(&name, &text, kind, ts) {
                Ok(r) => out.push(r),
                Err(e) => errors.extend(e.0),
            },
            Err(e) => {
                unreadable = true;
                errors.extend(
                    plain_error(
                        &name,
                        format!("cannot read the recording: {e}"),
                        "a readable UTF-8 CSV recording",
                    )
                    .0,
                )
            }
        }
    }
    if errors.is_empty() {
        Ok(out)
    } else {
        let exit = if unreadable { Exit::Io } else { Exit::BadInput };
        Err(Failure::new(exit, Diagnostics(errors).to_string()))
    }
}

fn sample_period(common: &Common, design: &Design) -> Result<f64, Failure> {
    match &common.sample_period {
        None => Ok(design.drive.sample_period_s),
        Some(s) => units::parse(Kind::Time, s)
            .ok()
            .filter(|t| recording::sample_period_in_range(*t))
            .ok_or_else(|| {
                Failure::from(plain_error(
                    "--sample-period",
                    format!("`{s}` is not a sample period (one PWM period)"),
                    "a time in [1 µs, 10 ms], e.g. \"50 µs\"",
                ))
            }),
    }
}

/// Today (UTC) as YYYY-MM-DD.
fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    writeback::date_from_unix_days((secs / 86_400) as i64)
}

/// The names of the recordings for the provenance: file names of the CSV files and
/// logs, then the interface of each live capture (`can0 (live)`, once).
fn names(files: &[PathBuf], common: &Common) -> Vec<String> {
    let mut out: Vec<String> = files
        .iter()
        .chain(&common.candump)
        .map(|f| {
            f.file_name()
                .map_or_else(|| f.display().to_string(), |n| n.to_string_lossy().into_owned())
        })
        .collect();
    for (name, ..) in &common.live {
        if !out.contains(name) {
            out.push(name.clone());
        }
    }
    out
}

/// The file name without its directory, for the result tables.
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

/// Writes `entries` into the spec (or prints the change), after checking the new spec.
fn write_back(spec: &Path, loaded: Loaded, entries: &[Entry], origin: &Origin<'_>) -> Result<(), Failure> {
    let file = spec.display().to_string();
    let text = &loaded.text;
    let src = Source { file: &file, text };
    let new = writeback::apply(text, entries, origin).map_err(|r| {
        let at = writeback::value_span(text, &r.path).unwrap_or(0..0);
        Diagnostics::from(src.error(at, r.key(), r.problem.clone(), r.accepted.clone()))
    })?;
    let keys: Vec<&str> = entries.iter().map(|e| e.key).collect();
    let keys = keys.join(", ");
    // The updated spec must still design; otherwise nothing is written.
    let design = codegen::design_source(&file, &new).map_err(|d| {
        Diagnostics(
            d.0.into_iter()
                .map(|e| blame_identified(e, text, &new, &keys))
                .collect(),
        )
    })?;
    let Some(lock) = loaded.lock else {
        outln!("--dry-run: {file} would change as follows (nothing written):");
        out!("{}", writeback::line_diff(text, &new));
        return Ok(());
    };
    if lock.links() > 1 {
        crate::output::warn(format_args!(
            "{file} has {} hard links: it is replaced by a new file, the other links keep the old text",
            lock.links()
        ));
    }
    lock.replace(new.as_bytes())?;
    outln!("wrote [motor.identified] {keys} to {file}");
    let prov: Vec<String> = design
        .motor
        .provenance
        .iter()
        .map(|(k, o)| format!("{k}: {}", format!("{:?}", o.source).to_lowercase()))
        .collect();
    outln!("design provenance now: {}", prov.join(", "));
    Ok(())
}

/// Runs one identification; prints results, or fails with located errors (bad input) or
/// an I/O failure.
pub fn run(what: What) -> Result<(), Failure> {
    match what {
        What::Step {
            spec,
            axis,
            csv,
            common,
        } => step(&spec, axis, &csv, &common),
        What::Flux { spec, csv, common } => flux_cmd(&spec, &csv, &common),
        What::Resolver {
            spec,
            offset,
            ratio,
            common,
        } => resolver_cmd(&spec, &offset, &ratio, &common),
    }
}

fn step(spec: &Path, axis: AxisArg, csv: &[PathBuf], common: &Common) -> Result<(), Failure> {
    let loaded = load(spec, common)?;
    let design = &loaded.design;
    let ts = sample_period(common, design)?;
    let (recs, origins): (Vec<Recording>, Vec<RecordingOrigin>) =
        all_recordings(csv, common, spec, RecordingKind::Step, ts)?
            .into_iter()
            .unzip();
    let (axis, name) = match axis {
        AxisArg::D => (Axis::D, "d"),
        AxisArg::Q => (Axis::Q, "q"),
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
    outln!(
        "{name} axis, {} recording(s), FIR order {} (group delay {} samples), T_s = {:.1} µs",
        recs.len(),
        design.fir.order,
        design.fir.group_delay_samples,
        recs[0].sample_period_s * 1e6
    );
    outln!(
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
        outln!(
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
        return Err(plain_error(&spec.display().to_string(), "no recordings".into(), "--csv FILE…").into());
    };
    outln!(
        "  mean: R = {:.5} Ω ± {:.2} %, L_{name} = {:.5} mH ± {:.2} %, transport delay {:.2} ± {:.2} samples (1σ)",
        r.mean,
        r.relative_percent(),
        l.mean * 1e3,
        l.relative_percent(),
        d.mean,
        d.std_dev
    );
    outln!(
        "  (the angle lead assumes {} samples of delay, angle_observer.lead_samples)",
        design.angle_observer.lead_samples
    );
    let label = format!("step {name}");
    let files = names(csv, common);
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
    let date = loaded.date.clone();
    let origin = Origin {
        date: &date,
        label: &label,
        files: &files,
    };
    write_back(spec, loaded, &entries, &origin)
}

fn flux_cmd(spec: &Path, csv: &[PathBuf], common: &Common) -> Result<(), Failure> {
    let loaded = load(spec, common)?;
    let design = &loaded.design;
    let ts = sample_period(common, design)?;
    let (recs, origins): (Vec<Recording>, Vec<RecordingOrigin>) =
        all_recordings(csv, common, spec, RecordingKind::Flux, ts)?
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
                outln!(
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
        return Err(plain_error(&spec.display().to_string(), "no recordings".into(), "--csv FILE…").into());
    };
    outln!("  mean: ψ_M = {:.5} Wb ± {:.2} % (1σ)", s.mean, s.relative_percent());
    let files = names(csv, common);
    let entries = [Entry {
        key: "flux_linkage",
        value: writeback::webers(s.mean),
        note: spread_note("ψ_M = Σu_q/Σω_e at i = 0 (6.10), flux", &s),
    }];
    let date = loaded.date.clone();
    let origin = Origin {
        date: &date,
        label: "flux",
        files: &files,
    };
    write_back(spec, loaded, &entries, &origin)
}

fn resolver_cmd(spec: &Path, offset: &[PathBuf], ratio: &[PathBuf], common: &Common) -> Result<(), Failure> {
    let file = spec.display().to_string();
    if offset.is_empty() && ratio.is_empty() && common.candump.is_empty() && common.live.is_empty() {
        return Err(plain_error(
            "motorgen identify resolver",
            "no recordings given".into(),
            "--offset FILE… (resolver_offset runs) and/or --ratio FILE… (pole_pair_ratio runs)",
        )
        .into());
    }
    let loaded = load(spec, common)?;
    let (text, design) = (&loaded.text, &loaded.design);
    let ts = sample_period(common, design)?;
    let (np, nr) = (
        design.angle_observer.motor_pole_pairs,
        design.angle_observer.resolver_pole_pairs,
    );
    let mut errors = Vec::new();
    // Ratio and direction first: an offset is meaningless with the wrong ratio.
    let can = can_recordings(
        common,
        spec,
        &[RecordingKind::PolePairRatio, RecordingKind::ResolverOffset],
    )?;
    let (can_ratio, can_offset): (Vec<_>, Vec<_>) = can
        .into_iter()
        .partition(|(r, _)| r.kind == RecordingKind::PolePairRatio);
    let mut ratio_recs: Vec<(Recording, RecordingOrigin)> = recordings(ratio, RecordingKind::PolePairRatio, ts)?
        .into_iter()
        .map(|r| (r, RecordingOrigin::csv()))
        .collect();
    ratio_recs.extend(can_ratio);
    let mut ratios: Vec<RatioEstimate> = Vec::new();
    for (r, o) in &ratio_recs {
        match resolver::identify_ratio(r).map_err(|e| o.locate(e)) {
            Ok(e) => {
                outln!(
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
    let src = Source { file: &file, text };
    let at = writeback::value_span(text, &["motor", "pole_pairs"]).unwrap_or(0..0);
    for ((r, _), e) in ratio_recs.iter().zip(&ratios) {
        if !e.directions_agree {
            errors.push(src.error(
                at.clone(),
                "motor.pole_pairs",
                format!(
                    "{}: the resolver turns against the stator field (§6.4 direction check)",
                    r.file
                ),
                "swap two motor phases or the resolver's sine and cosine, then record again",
            ));
        } else if (e.ratio / expected - 1.0).abs() > 0.05 {
            errors.push(src.error(
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
        outln!("  pole-pair ratio agrees with the spec ({np}/{nr}); directions agree");
    }
    if offset.is_empty() && can_offset.is_empty() {
        return Ok(());
    }
    let mut recs: Vec<(Recording, RecordingOrigin)> = recordings(offset, RecordingKind::ResolverOffset, ts)?
        .into_iter()
        .map(|r| (r, RecordingOrigin::csv()))
        .collect();
    recs.extend(can_offset);
    let mut offsets = Vec::new();
    for (r, o) in &recs {
        match resolver::identify_offset(r, np, nr).map_err(|e| o.locate(e)) {
            Ok(e) => {
                outln!(
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
        return Err(plain_error(&file, "no recordings".into(), "--offset FILE…").into());
    };
    outln!(
        "  mean: θ_off = {mean:.5} rad (mod 2π·n_r/n_p), runs within ±{:.3}° electrical",
        (dev * f64::from(np) / f64::from(nr)).to_degrees()
    );
    let files = names(offset, common);
    let entries = [Entry {
        key: "resolver_offset",
        value: writeback::radians(mean),
        note: format!("θ_off = θ_r aligned to phase U (6.9), {} run(s)", offsets.len()),
    }];
    let date = loaded.date.clone();
    let origin = Origin {
        date: &date,
        label: "resolver offset",
        files: &files,
    };
    write_back(spec, loaded, &entries, &origin)
}
