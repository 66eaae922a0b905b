//! `motorgen`: design motor-controller constants from a motor TOML file.

mod atomic;
mod commission;
mod exit;
mod firmware;
mod folders;
mod identify;
mod output;
mod report;
mod verify;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use codegen::render::{Output, render_with};
use exit::{Exit, Failure};
use motor_commission::Input;
use output::{out, outln};

/// Motor description (TOML) → tuned motor-controller constants.
#[derive(Parser)]
#[command(name = "motorgen", version, about, after_help = exit::HELP)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the design of one motor: its summary (the headline constants and checks),
    /// or with --format the whole design as JSON, or the Rust, C or Markdown output.
    Design {
        /// The motor spec, e.g. motors/fischer-ti085.toml.
        #[arg(value_name = "SPEC")]
        spec: PathBuf,
        /// Output format.
        #[arg(long, value_enum, default_value_t = Format::Summary)]
        format: Format,
        /// Directory with replacement templates (for rust, c, markdown).
        #[arg(long, value_name = "DIR")]
        templates: Option<PathBuf>,
        /// A board file, or the stem of one in boards/ (e.g. motorgen-reference): adds the
        /// `board` constants and the checks of the motor on that board.
        #[arg(long, value_name = "BOARD_FILE")]
        board: Option<PathBuf>,
    },
    /// Write the Rust module, C header and Markdown summary of one motor into a directory,
    /// and with --board the DBC file of its CAN interface (files are only rewritten when
    /// their bytes change).
    Generate {
        /// The motor spec.
        #[arg(value_name = "SPEC")]
        spec: PathBuf,
        /// Output directory (created if missing).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Directory with replacement templates (motor.rs.j2, motor.h.j2, motor.md.j2,
        /// motor.dbc.j2).
        #[arg(long, value_name = "DIR")]
        templates: Option<PathBuf>,
        /// A board file or the stem of one in boards/: adds its `board` and `can` constants
        /// (as `design --board`) and writes STEM.dbc.
        #[arg(long, value_name = "BOARD_FILE")]
        board: Option<PathBuf>,
    },
    /// Validate motor specs and board files (a file with a top-level `chip` is a board);
    /// with --board, each motor spec on that board (what the image of the pair needs: the
    /// board's sensing and ratings, the trips it will use). Warnings go to stderr; exit 1
    /// if any has a problem.
    Check {
        /// One or more motor specs or board files.
        #[arg(required = true, value_name = "FILE")]
        specs: Vec<PathBuf>,
        /// A board file, or the stem of one in boards/ (e.g. motorgen-reference): checks
        /// every motor spec given on it and prints the trip levels its image would use.
        #[arg(long, value_name = "BOARD_FILE")]
        board: Option<PathBuf>,
    },
    /// Write a commented starting spec to DIR/STEM.toml, DIR defaulting to motors/
    /// (never overwrites).
    New {
        /// File stem: lowercase letters, digits and '-'.
        #[arg(value_name = "STEM")]
        stem: String,
        /// Directory of motor specs (default: motors/ in the working directory).
        #[arg(long = "motors-dir", visible_alias = "dir", value_name = "DIR", env = folders::MOTORS_ENV)]
        motors_dir: Option<PathBuf>,
    },
    /// Build the STM32G474 image of one motor (or --all) on a board into
    /// target/firmware/STEM.elf and .bin (target/firmware/BOARD/… for a board other than
    /// the default) and print its flash and RAM use (fails above the 64 KiB flash
    /// budget); cargo's build progress is shown on stderr.
    Firmware {
        /// Motor file stem in the motors folder, e.g. fischer-ti085.
        #[arg(required_unless_present = "all", conflicts_with = "all", value_name = "STEM")]
        stem: Option<String>,
        /// Every motor in the motors folder.
        #[arg(long)]
        all: bool,
        /// Directory of motor specs (default: motors/ in the working directory).
        #[arg(long = "motors-dir", visible_alias = "dir", value_name = "DIR", env = folders::MOTORS_ENV)]
        motors_dir: Option<PathBuf>,
        /// Board file stem in the boards folder (default: motorgen-reference).
        #[arg(long, value_name = "BOARD", default_value = codegen::board::DEFAULT_BOARD)]
        board: String,
        /// Directory of board files (default: boards/ beside the motors folder, else in
        /// the working directory).
        #[arg(long, value_name = "DIR", env = folders::BOARDS_ENV)]
        boards_dir: Option<PathBuf>,
    },
    /// Simulate the firmware's current loop and observer with the motor and print a
    /// pass/fail table of measured vs designed figures (exit 3 on a failure).
    Verify {
        /// The motor spec.
        #[arg(value_name = "SPEC")]
        spec: PathBuf,
        /// A board file or the stem of one in boards/: the motor on that board (refused
        /// where it does not fit), simulated with the board's current and DC-link sensing
        /// as the image would run.
        #[arg(long, value_name = "BOARD_FILE")]
        board: Option<PathBuf>,
        /// Output format: the pass/fail table, or every scenario's criteria and verdict as
        /// JSON (for CI pipelines).
        #[arg(long, value_enum, default_value_t = verify::VerifyFormat::Text)]
        format: verify::VerifyFormat,
    },
    /// Write a self-contained HTML report (verification table, SVG plots, every constant
    /// with formula and provenance) to DIR/STEM.html (exit 3 if a figure fails).
    Report {
        /// The motor spec.
        #[arg(value_name = "SPEC")]
        spec: PathBuf,
        /// Output directory (created if missing).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// A `commission … frequency-response` output directory: its
        /// frequency-response-d.json and -q.json are overlaid on the current-loop Bode plots.
        #[arg(long, value_name = "DIR")]
        measured: Option<PathBuf>,
    },
    /// Identify R, L, ψ_M or the resolver offset from recorded commissioning runs
    /// (thesis A chapter 6) and write them into the spec's [motor.identified].
    Identify {
        #[command(subcommand)]
        what: identify::What,
    },
    /// Write the captures in CAN logs (`candump -l` format) as the CSV recordings
    /// `identify --csv` reads, for inspection: DIR/LOGSTEM-N-ROUTINE.csv (all or nothing;
    /// a corrupted capture is a located error and nothing is written).
    Capture {
        /// The motor spec (its scalings decode the signals).
        #[arg(value_name = "SPEC")]
        spec: PathBuf,
        /// The board file whose CAN identifiers the drive uses.
        #[arg(long, value_name = "BOARD_FILE")]
        board: PathBuf,
        /// One or more logs.
        #[arg(long, required = true, num_args = 1.., value_name = "LOG")]
        candump: Vec<PathBuf>,
        /// Output directory (created if missing).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
    },
    /// Run a commissioning routine on the drive over CAN (SocketCAN, Linux): send the
    /// command, receive the capture, write its CSV recording to DIR and identify from it
    /// as `identify … --candump` does (exit 6 refused/aborted, 69 no CAN interface,
    /// 75 timeout; nothing written then).
    Commission(commission::CommissionArgs),
    /// List the motors in a directory (default: motors/ in the working directory).
    List {
        /// Directory of motor specs.
        #[arg(long = "motors-dir", visible_alias = "dir", value_name = "DIR", env = folders::MOTORS_ENV)]
        motors_dir: Option<PathBuf>,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    /// Human-readable headline constants and checks (the default).
    Summary,
    /// The complete design as JSON (SI units).
    Json,
    /// Rust module of documented `const` items.
    Rust,
    /// C header with the same values.
    C,
    /// Markdown summary of every constant.
    Markdown,
}

impl Format {
    fn output(self) -> Option<Output> {
        match self {
            Format::Rust => Some(Output::Rust),
            Format::C => Some(Output::C),
            Format::Markdown => Some(Output::Markdown),
            Format::Summary | Format::Json => None,
        }
    }
}

/// Renders `out` with the template from `dir` if given, else the built-in one.
fn render(d: &codegen::Design, out: Output, dir: Option<&Path>) -> Result<String, Failure> {
    let bad_template = |e: codegen::render::RenderError| Failure::new(Exit::BadInput, e.to_string());
    // A template directory made before the DBC output existed: the built-in DBC.
    let dir = dir.filter(|dir| out != Output::Dbc || dir.join(out.template()).exists());
    match dir {
        Some(dir) => {
            let path = dir.join(out.template());
            let source = std::fs::read_to_string(&path)
                .map_err(|e| Failure::new(Exit::Io, format!("error: cannot read template {}: {e}", path.display())))?;
            render_with(d, &path.display().to_string(), &source).map_err(bad_template)
        }
        None => codegen::render::render(d, out).map_err(bad_template),
    }
}

/// What an unreadable motor spec's message says would be accepted.
const READABLE_SPEC: &str = "a readable motor spec, e.g. motors/fischer-ti085.toml (`motorgen list` shows them)";
/// What an unreadable board file's message says would be accepted.
const READABLE_BOARD: &str = "a readable board file, e.g. boards/motorgen-reference.toml";
/// What an unreadable file of `check` (a spec or a board) says would be accepted.
const READABLE_SPEC_OR_BOARD: &str =
    "a readable motor spec or board file, e.g. motors/fischer-ti085.toml or boards/motorgen-reference.toml";

/// Reads a motor spec as UTF-8 text: an unreadable file is an I/O failure, invalid
/// UTF-8 bad input; both name the file.
fn read_spec(path: &Path) -> Result<String, Failure> {
    Ok(read_input(path).text?)
}

/// Reads a file of `check` (a spec or a board) as [`read_spec`] reads a spec.
fn read_spec_or_board(path: &Path) -> Result<String, Failure> {
    Ok(read_as(path, READABLE_SPEC_OR_BOARD).text?)
}

/// Reads a board file as [`read_spec`] reads a spec.
fn read_board(path: &Path) -> Result<String, Failure> {
    Ok(read_board_input(path).text?)
}

/// A motor spec as the library crates take it: its text, or why it could not be read
/// (an unreadable file, or bad input located at its first invalid UTF-8 byte).
fn read_input(path: &Path) -> Input {
    read_as(path, READABLE_SPEC)
}

/// A board file as the library crates take it (see [`read_input`]).
fn read_board_input(path: &Path) -> Input {
    read_as(path, READABLE_BOARD)
}

/// `path` read as an input whose unreadable message names `accepted`.
fn read_as(path: &Path, accepted: &str) -> Input {
    let name = path.display().to_string();
    match std::fs::read(path) {
        Ok(bytes) => Input::from_bytes(name, bytes),
        Err(e) => Input::unreadable(name, format!("cannot read the file: {e}"), accepted),
    }
}

/// Prints the design's warnings on stderr, once each (each is located at its key:
/// `file:line:column: `key`: …`). Every command that designs calls it once, whatever the
/// output format.
fn warn_design(d: &codegen::Design) {
    for w in &d.warnings {
        output::warn(format_args!("{w}"));
    }
}

fn design(path: &Path) -> Result<codegen::Design, Failure> {
    let text = read_spec(path)?;
    Ok(codegen::design_source(&path.display().to_string(), &text)?)
}

/// The design of a motor, on `board` if given (its constants and checks added).
fn design_on(path: &Path, board: Option<&Path>) -> Result<codegen::Design, Failure> {
    let Some(board) = board else {
        return design(path);
    };
    let text = read_spec(path)?;
    let board_text = read_board(board)?;
    Ok(codegen::design_with_board(
        &path.display().to_string(),
        &text,
        &board.display().to_string(),
        &board_text,
    )?)
}

/// The folder a bare name is looked up in: `MOTORGEN_MOTORS_DIR` / `MOTORGEN_BOARDS_DIR`
/// if set, else `motors/` or `boards/` in the working directory (never the source tree
/// the binary was built from, [`folders`]).
fn shipped_dir(folder: &str) -> PathBuf {
    let var = if folder == "boards" {
        folders::BOARDS_ENV
    } else {
        folders::MOTORS_ENV
    };
    std::env::var_os(var).map_or_else(|| PathBuf::from(folder), PathBuf::from)
}

/// A spec or board argument: the file it names if there is one, else a bare name (no
/// folder) looked up in `folder` (`motors` or `boards`, as [`shipped_dir`] finds it) with or
/// without `.toml`: `--board motorgen-reference` is `boards/motorgen-reference.toml`. A name
/// found nowhere stays as given, and reading it reports the missing file.
fn locate(path: PathBuf, folder: &str) -> PathBuf {
    let bare = path.components().count() == 1 && path.parent().is_none_or(|p| p.as_os_str().is_empty());
    if path.exists() || !bare {
        return path;
    }
    let dir = shipped_dir(folder);
    let mut with_toml = path.clone().into_os_string();
    with_toml.push(".toml");
    [dir.join(&path), dir.join(with_toml)]
        .into_iter()
        .find(|p| p.is_file())
        .unwrap_or(path)
}

/// [`locate`] for an optional board argument.
fn locate_board(board: Option<PathBuf>) -> Option<PathBuf> {
    board.map(|b| locate(b, "boards"))
}

fn main() -> ExitCode {
    let code = match run(Cli::parse().command) {
        Ok(()) => Exit::Success.into(),
        Err(f) => f.report(),
    };
    output::flush();
    code
}

fn run(command: Command) -> Result<(), Failure> {
    match command {
        Command::Design {
            spec,
            format,
            templates,
            board,
        } => {
            let (spec, board) = (locate(spec, "motors"), locate_board(board));
            let d = design_on(&spec, board.as_deref())?;
            warn_design(&d);
            let out = match format.output() {
                Some(o) => render(&d, o, templates.as_deref())?,
                None if matches!(format, Format::Json) => serde_json::to_string_pretty(&d)
                    .map(|s| s + "\n")
                    .map_err(|e| Failure::new(Exit::Io, format!("error: cannot serialise the design: {e}")))?,
                None => codegen::summary::summary(&d),
            };
            out!("{out}");
            Ok(())
        }
        Command::Generate {
            spec,
            out,
            templates,
            board,
        } => {
            atomic::check_out_dir(&out).map_err(|e| Failure::new(Exit::BadInput, e))?;
            let (spec, board) = (locate(spec, "motors"), locate_board(board));
            let d = design_on(&spec, board.as_deref())?;
            warn_design(&d);
            let stem = spec
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "motor".into());
            // Render everything first: nothing is written unless every output renders.
            let mut files = Vec::new();
            // The DBC of the CAN interface needs the board's identifiers.
            let dbc = d.board.is_some().then_some(Output::Dbc);
            for o in Output::ALL.into_iter().chain(dbc) {
                let text = render(&d, o, templates.as_deref())?;
                files.push((out.join(o.file_name(&stem)), text.into_bytes()));
            }
            // All or nothing, each file rewritten only when its bytes change.
            let written = atomic::write_set(&out, &files)?;
            for ((path, _), w) in files.iter().zip(written) {
                outln!("{} {}", if w { "wrote" } else { "unchanged" }, path.display());
            }
            Ok(())
        }
        Command::Check { specs, board } => {
            // Every file is checked; the exit code is the gravest failure's (I/O over bad input).
            let mut failed = Vec::new();
            let board = locate_board(board);
            let specs: Vec<PathBuf> = specs.into_iter().map(|p| locate(p, "motors")).collect();
            let board_file = match &board {
                Some(b) => match read_spec(b) {
                    Ok(text) => Some((b.display().to_string(), text)),
                    Err(f) => {
                        failed.push(f.exit);
                        f.report();
                        None
                    }
                },
                None => None,
            };
            let (mut motors, mut boards) = (0, 0);
            for path in &specs {
                // Read once; a file with a top-level `chip` is a board, anything else a motor.
                let name = path.display().to_string();
                let checked = read_spec_or_board(path).and_then(|text| {
                    if codegen::board::is_board_file(&text) {
                        boards += 1;
                        let b = codegen::board_source(&name, &text)?;
                        outln!("ok: {name} (board: {}, {} {})", b.name, b.chip, b.package);
                        // Stated facts that contradict the board's parts' datasheets.
                        for w in &b.warnings {
                            output::warn(format_args!("{w}"));
                        }
                        return Ok(());
                    }
                    motors += 1;
                    let d = match (&board, &board_file) {
                        (Some(_), Some((bname, btext))) => codegen::design_with_board(&name, &text, bname, btext)?,
                        // The board could not be read (reported above): the spec alone.
                        (Some(_), None) => codegen::design_source(&name, &text)?,
                        (None, _) => codegen::design_source(&name, &text)?,
                    };
                    warn_design(&d);
                    match &d.board {
                        Some(b) => {
                            outln!("ok: {name} ({}) on {} ({})", d.name, b.board.file, b.board.name);
                            out!("{}", codegen::summary::board(b, &d));
                        }
                        None => outln!("ok: {name} ({})", d.name),
                    }
                    Ok(())
                });
                if let Err(f) = checked {
                    failed.push(f.exit);
                    f.report();
                }
            }
            if board.is_none() && motors > 0 && boards > 0 {
                output::stderr(format_args!(
                    "note: motor specs and board files were checked each on its own; `--board FILE` checks the motors on a board\n"
                ));
            }
            match Exit::gravest(&failed) {
                None => Ok(()),
                Some(exit) => Err(Failure::new(
                    exit,
                    format!("check: {} of {} files failed", failed.len(), specs.len()),
                )),
            }
        }
        Command::New { stem, motors_dir } => {
            if stem.is_empty()
                || !stem
                    .chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
                || stem.starts_with('-')
            {
                return Err(Failure::new(
                    Exit::BadInput,
                    format!(
                        "error: `{stem}` is not a valid motor stem\n  accepted: lowercase letters, digits and '-', e.g. my-motor-80kw"
                    ),
                ));
            }
            let dir = folders::motors(motors_dir)?;
            let path = dir.join(format!("{stem}.toml"));
            if path.exists() {
                return Err(Failure::new(
                    Exit::BadInput,
                    format!(
                        "error: {} already exists\n  accepted: a new stem, or edit the existing file",
                        path.display()
                    ),
                ));
            }
            let text = codegen::render::new_spec(&stem).map_err(|e| Failure::new(Exit::BadInput, e.to_string()))?;
            atomic::create_new(&path, text.as_bytes())?;
            outln!(
                "wrote {}; edit it, then run `motorgen check {}`",
                path.display(),
                path.display()
            );
            Ok(())
        }
        Command::Firmware {
            stem,
            all,
            motors_dir,
            board,
            boards_dir,
        } => {
            let which = match stem {
                Some(stem) if !all => firmware::Which::One(stem),
                _ => firmware::Which::All,
            };
            let motors = folders::motors(motors_dir)?;
            let boards = folders::boards(boards_dir, &motors)?;
            firmware::run(which, &motors, &board, &boards)
        }
        Command::Verify { spec, board, format } => {
            verify::run(&locate(spec, "motors"), locate_board(board).as_deref(), format)
        }
        Command::Report { spec, out, measured } => report::run(&spec, &out, measured.as_deref()),
        Command::Identify { what } => identify::run(what),
        Command::Capture {
            spec,
            board,
            candump,
            out,
        } => {
            atomic::check_out_dir(&out).map_err(|e| Failure::new(Exit::BadInput, e))?;
            let (spec, board) = (read_input(&spec), read_board_input(&board));
            let logs = identify::read_logs(&candump);
            let files: Vec<(PathBuf, Vec<u8>)> = motor_commission::identify::capture_files(&spec, &board, &logs)?
                .into_iter()
                .map(|(name, csv)| (out.join(name), csv.into_bytes()))
                .collect();
            let written = atomic::write_set(&out, &files)?;
            for ((path, _), w) in files.iter().zip(written) {
                outln!("{} {}", if w { "wrote" } else { "unchanged" }, path.display());
            }
            Ok(())
        }
        Command::Commission(args) => commission::run(&args),
        Command::List { motors_dir } => {
            let dir = folders::motors(motors_dir)?;
            let mut entries: Vec<PathBuf> = std::fs::read_dir(&dir)
                .map_err(|e| Failure::new(Exit::Io, format!("error: cannot read {}: {e}", dir.display())))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect();
            entries.sort();
            let stem = |path: &Path| {
                path.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            };
            // One column for every stem, however long (the names start in one column).
            let width = entries
                .iter()
                .map(|p| stem(p).chars().count())
                .max()
                .unwrap_or(0)
                .max(24);
            for path in entries {
                let stem = stem(&path);
                match design(&path) {
                    Ok(d) => outln!("{stem:<width$} {}", d.name),
                    Err(_) => outln!("{stem:<width$} INVALID (`motorgen check {}` says why)", path.display()),
                }
            }
            Ok(())
        }
    }
}
