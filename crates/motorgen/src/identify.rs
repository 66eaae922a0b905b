//! `motorgen identify step|flux|resolver <spec> …`: identified values from recorded
//! commissioning runs (thesis A chapter 6) into the spec's `[motor.identified]`.
//!
//! The identification is `motor_commission::identify`'s; here the files are read, the
//! spec is locked before it is read (see [`crate::atomic::LockedSpec`]: two
//! identifications of one spec run one after the other, and the second rewrites what the
//! first wrote), the results are printed and the updated spec is written through a
//! temporary file renamed over the spec (never a partial spec). `--dry-run` reads without
//! the lock and prints the change instead.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand, ValueEnum};
use codegen::Source;
use motor_commission::Input;
use motor_commission::identify::{Request, What as Identify};
use motor_commission::writeback;
use motor_control::commissioning::Axis;

use crate::atomic::LockedSpec;
use crate::exit::Failure;
use crate::output::{Stdout, out, outln};

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
    candump: Vec<PathBuf>,
    /// The board file whose CAN identifiers the drive uses (needed with --candump).
    #[arg(long, value_name = "BOARD_FILE")]
    board: Option<PathBuf>,
}

/// `--axis`.
#[derive(Clone, Copy, ValueEnum)]
pub enum AxisArg {
    /// Direct axis.
    D,
    /// Quadrature axis.
    Q,
}

impl From<AxisArg> for Axis {
    fn from(a: AxisArg) -> Axis {
        match a {
            AxisArg::D => Axis::D,
            AxisArg::Q => Axis::Q,
        }
    }
}

/// Reads each CSV recording (an unreadable one is reported with the others' problems).
fn read_recordings(files: &[PathBuf]) -> Vec<Input> {
    files
        .iter()
        .map(|f| {
            let name = f.display().to_string();
            match std::fs::read_to_string(f) {
                Ok(text) => Input::new(name, text),
                Err(e) => Input::unreadable(
                    name,
                    format!("cannot read the recording: {e}"),
                    "a readable UTF-8 CSV recording",
                ),
            }
        })
        .collect()
}

/// Reads each `candump -l` log.
pub fn read_logs(files: &[PathBuf]) -> Vec<Input> {
    files
        .iter()
        .map(|f| {
            let name = f.display().to_string();
            match std::fs::read_to_string(f) {
                Ok(text) => Input::new(name, text),
                Err(e) => Input::unreadable(name, format!("cannot read the log: {e}"), "a readable `candump -l` log"),
            }
        })
        .collect()
}

/// Runs one identification; prints results, or fails with located errors (bad input) or
/// an I/O failure.
pub fn run(what: What) -> Result<(), Failure> {
    let (spec, what, common) = match what {
        What::Step {
            spec,
            axis,
            csv,
            common,
        } => (
            spec,
            Identify::Step {
                axis: axis.into(),
                csv: read_recordings(&csv),
            },
            common,
        ),
        What::Flux { spec, csv, common } => (
            spec,
            Identify::Flux {
                csv: read_recordings(&csv),
            },
            common,
        ),
        What::Resolver {
            spec,
            offset,
            ratio,
            common,
        } => (
            spec,
            Identify::Resolver {
                offset: read_recordings(&offset),
                ratio: read_recordings(&ratio),
            },
            common,
        ),
    };
    // The board is needed only with logs (then clap requires it).
    let board = common
        .board
        .as_deref()
        .filter(|_| !common.candump.is_empty())
        .map(crate::read_board_input);
    let request = Request {
        what,
        date: common.date,
        sample_period: common.sample_period,
        logs: read_logs(&common.candump),
        board,
        live: Vec::new(),
    };
    identify(&spec, common.dry_run, &request)
}

/// Today (UTC) as YYYY-MM-DD.
pub(crate) fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    writeback::date_from_unix_days((secs / 86_400) as i64)
}

/// Runs `request` on the spec at `spec` (for `identify` and `commission`): checks it,
/// then (unless `dry_run`) locks the spec and reads it under the lock, identifies
/// (printing the results), and writes the update into the spec or, with `dry_run`,
/// prints the change.
pub fn identify(spec: &Path, dry_run: bool, request: &Request) -> Result<(), Failure> {
    let date = request.check(&today())?;
    let (lock, text) = if dry_run {
        (None, crate::read_spec(spec)?)
    } else {
        if std::fs::metadata(spec).is_err() {
            // A missing spec is reported as every command reports it.
            crate::read_spec(spec)?;
        }
        let mut lock = LockedSpec::open(spec)?;
        let text = Input::from_bytes(spec.display().to_string(), std::mem::take(&mut lock.bytes)).text?;
        (Some(lock), text)
    };
    let file = spec.display().to_string();
    let source = Source {
        file: &file,
        text: &text,
    };
    let Some(update) = request.identify(&source, &date, &mut Stdout)? else {
        return Ok(());
    };
    let Some(lock) = lock else {
        outln!("--dry-run: {file} would change as follows (nothing written):");
        out!("{}", update.diff(&text));
        return Ok(());
    };
    if lock.links() > 1 {
        crate::output::warn(format_args!(
            "{file} has {} hard links: it is replaced by a new file, the other links keep the old text",
            lock.links()
        ));
    }
    lock.replace(update.text.as_bytes())?;
    outln!("wrote [motor.identified] {} to {file}", update.keys.join(", "));
    outln!("design provenance now: {}", update.provenance.join(", "));
    Ok(())
}
