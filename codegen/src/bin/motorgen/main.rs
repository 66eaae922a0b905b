//! `motorgen`: design motor-controller constants from a motor TOML file.

mod atomic;
mod firmware;
mod identify;
mod output;
mod report;
mod verify;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use codegen::render::{Output, render_with};
use codegen::{Diagnostic, Diagnostics};
use output::{err, errln, out, outln};

/// Motor description (TOML) → tuned motor-controller constants.
#[derive(Parser)]
#[command(name = "motorgen", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the whole design of one motor.
    Design {
        /// The motor spec, e.g. motors/fischer-ti085.toml.
        spec: PathBuf,
        /// Output format.
        #[arg(long, value_enum, default_value_t = Format::Summary)]
        format: Format,
        /// Directory with replacement templates (for rust, c, markdown).
        #[arg(long)]
        templates: Option<PathBuf>,
        /// A board file (boards/<name>.toml): adds the `board` constants and the checks
        /// of the motor on that board.
        #[arg(long, value_name = "BOARD_FILE")]
        board: Option<PathBuf>,
    },
    /// Write the Rust module, C header and Markdown summary of one motor into a directory
    /// (files are only rewritten when their bytes change).
    Generate {
        /// The motor spec.
        spec: PathBuf,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Directory with replacement templates (motor.rs.j2, motor.h.j2, motor.md.j2).
        #[arg(long)]
        templates: Option<PathBuf>,
        /// A board file: adds its `board` constants (as `design --board`).
        #[arg(long, value_name = "BOARD_FILE")]
        board: Option<PathBuf>,
    },
    /// Validate motor specs and board files (a file with a top-level `chip` is a board);
    /// exit non-zero if any has a problem.
    Check {
        /// One or more motor specs or board files.
        #[arg(required = true)]
        specs: Vec<PathBuf>,
    },
    /// Write a commented starting spec to motors/<stem>.toml (never overwrites).
    New {
        /// File stem: lowercase letters, digits and '-'.
        stem: String,
        /// Directory of motor specs.
        #[arg(long)]
        dir: Option<PathBuf>,
    },
    /// Build the STM32G474 image of one motor (or --all) on a board into
    /// target/firmware/<stem>.elf and .bin (target/firmware/<board>/… for a board other
    /// than the default) and print its flash and RAM use (fails above 64 KiB of flash).
    Firmware {
        /// Motor file stem in the motors folder, e.g. fischer-ti085.
        #[arg(required_unless_present = "all", conflicts_with = "all")]
        stem: Option<String>,
        /// Every motor in the motors folder.
        #[arg(long)]
        all: bool,
        /// Directory of motor specs (default: motors/).
        #[arg(long)]
        dir: Option<PathBuf>,
        /// Board file stem in the boards folder (default: motorgen-reference).
        #[arg(long, default_value = codegen::board::DEFAULT_BOARD)]
        board: String,
        /// Directory of board files (default: boards/ beside the motors folder).
        #[arg(long)]
        boards_dir: Option<PathBuf>,
    },
    /// Simulate the firmware's current loop and observer with the motor and print a
    /// pass/fail table of measured vs designed figures (non-zero exit on a failure).
    Verify {
        /// The motor spec.
        spec: PathBuf,
    },
    /// Write a self-contained HTML report (verification table, SVG plots, every constant
    /// with formula and provenance) to DIR/<stem>.html.
    Report {
        /// The motor spec.
        spec: PathBuf,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// Identify R, L, ψ_M or the resolver offset from recorded commissioning runs
    /// (thesis A chapter 6) and write them into the spec's [motor.identified].
    Identify {
        #[command(subcommand)]
        what: identify::What,
    },
    /// List the motors in a directory (default: motors/).
    List {
        /// Directory of motor specs.
        #[arg(long)]
        dir: Option<PathBuf>,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    /// Human-readable headline constants.
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
fn render(d: &codegen::Design, out: Output, dir: Option<&Path>) -> Result<String, String> {
    match dir {
        Some(dir) => {
            let path = dir.join(out.template());
            let source = std::fs::read_to_string(&path)
                .map_err(|e| format!("error: cannot read template {}: {e}", path.display()))?;
            render_with(d, &path.display().to_string(), &source).map_err(|e| e.to_string())
        }
        None => codegen::render::render(d, out).map_err(|e| e.to_string()),
    }
}

/// Reads a spec as UTF-8 text, or a diagnostic naming the file.
fn read_spec(path: &Path) -> Result<String, Diagnostics> {
    let bytes = std::fs::read(path).map_err(|e| {
        Diagnostics(vec![Diagnostic {
            file: path.display().to_string(),
            line: 1,
            column: 1,
            key: String::new(),
            problem: format!("cannot read the file: {e}"),
            accepted: "a readable motor spec, e.g. motors/fischer-ti085.toml (`motorgen list` shows them)".into(),
            excerpt: String::new(),
        }])
    })?;
    spec_text(path, bytes)
}

/// A spec's bytes as UTF-8 text, or a diagnostic at the first invalid byte.
fn spec_text(path: &Path, bytes: Vec<u8>) -> Result<String, Diagnostics> {
    let file = path.display().to_string();
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let text = String::from_utf8_lossy(e.as_bytes());
        codegen::Source {
            file: &file,
            text: &text,
        }
        .error(
            at..at,
            "",
            format!("the file is not valid UTF-8 (byte {at})"),
            "a UTF-8 text file; save the spec as UTF-8",
        )
        .into()
    })
}

fn design(path: &Path) -> Result<codegen::Design, Diagnostics> {
    let text = read_spec(path)?;
    codegen::design_source(&path.display().to_string(), &text)
}

/// The design of a motor, on `board` if given (its constants and checks added).
fn design_on(path: &Path, board: Option<&Path>) -> Result<codegen::Design, Diagnostics> {
    let Some(board) = board else {
        return design(path);
    };
    let text = read_spec(path)?;
    let board_text = read_spec(board)?;
    codegen::design_with_board(
        &path.display().to_string(),
        &text,
        &board.display().to_string(),
        &board_text,
    )
}

/// `motors/` in the working directory, else the one in this repository.
fn motors_dir(dir: Option<PathBuf>) -> PathBuf {
    dir.unwrap_or_else(|| {
        let here = PathBuf::from("motors");
        if here.is_dir() {
            here
        } else {
            Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("motors")
        }
    })
}

fn main() -> ExitCode {
    let code = run(Cli::parse());
    output::flush();
    code
}

fn run(cli: Cli) -> ExitCode {
    match cli.command {
        Command::Design {
            spec,
            format,
            templates,
            board,
        } => match design_on(&spec, board.as_deref()) {
            Ok(d) => {
                let out = match format {
                    Format::Rust | Format::C | Format::Markdown => {
                        let Some(o) = format.output() else {
                            return ExitCode::FAILURE;
                        };
                        match render(&d, o, templates.as_deref()) {
                            Ok(s) => s,
                            Err(e) => {
                                errln!("{e}");
                                return ExitCode::FAILURE;
                            }
                        }
                    }
                    Format::Summary => codegen::summary::summary(&d),
                    Format::Json => match serde_json::to_string_pretty(&d) {
                        Ok(s) => s + "\n",
                        Err(e) => {
                            errln!("error: cannot serialise the design: {e}");
                            return ExitCode::FAILURE;
                        }
                    },
                };
                out!("{out}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                err!("{e}");
                ExitCode::FAILURE
            }
        },
        Command::Generate {
            spec,
            out,
            templates,
            board,
        } => {
            if let Err(e) = atomic::check_out_dir(&out) {
                errln!("{e}");
                return ExitCode::FAILURE;
            }
            let d = match design_on(&spec, board.as_deref()) {
                Ok(d) => d,
                Err(e) => {
                    err!("{e}");
                    return ExitCode::FAILURE;
                }
            };
            let stem = spec
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "motor".into());
            // Render everything first: nothing is written unless every output renders.
            let mut files = Vec::new();
            for o in Output::ALL {
                match render(&d, o, templates.as_deref()) {
                    Ok(text) => files.push((out.join(o.file_name(&stem)), text.into_bytes())),
                    Err(e) => {
                        errln!("{e}");
                        return ExitCode::FAILURE;
                    }
                }
            }
            match atomic::write_set(&out, &files) {
                Ok(written) => {
                    for ((path, _), w) in files.iter().zip(written) {
                        outln!("{} {}", if w { "wrote" } else { "unchanged" }, path.display());
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    errln!("error: {e}");
                    output::io_failure()
                }
            }
        }
        Command::Check { specs } => {
            let mut ok = true;
            for path in &specs {
                let is_board = std::fs::read_to_string(path).is_ok_and(|t| codegen::board::is_board_file(&t));
                if is_board {
                    match read_spec(path).and_then(|t| codegen::board_source(&path.display().to_string(), &t)) {
                        Ok(b) => outln!("ok: {} (board: {}, {} {})", path.display(), b.name, b.chip, b.package),
                        Err(e) => {
                            ok = false;
                            err!("{e}");
                        }
                    }
                    continue;
                }
                match design(path) {
                    Ok(d) => {
                        outln!("ok: {} ({})", path.display(), d.name);
                        for w in &d.warnings {
                            outln!("  warning: {w}");
                        }
                    }
                    Err(e) => {
                        ok = false;
                        err!("{e}");
                    }
                }
            }
            if ok { ExitCode::SUCCESS } else { ExitCode::FAILURE }
        }
        Command::New { stem, dir } => {
            if stem.is_empty()
                || !stem
                    .chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
                || stem.starts_with('-')
            {
                errln!(
                    "error: `{stem}` is not a valid motor stem\n  accepted: lowercase letters, digits and '-', e.g. my-motor-80kw"
                );
                return ExitCode::FAILURE;
            }
            let dir = motors_dir(dir);
            let path = dir.join(format!("{stem}.toml"));
            if path.exists() {
                errln!(
                    "error: {} already exists\n  accepted: a new stem, or edit the existing file",
                    path.display()
                );
                return ExitCode::FAILURE;
            }
            let text = match codegen::render::new_spec(&stem) {
                Ok(t) => t,
                Err(e) => {
                    errln!("{e}");
                    return ExitCode::FAILURE;
                }
            };
            match atomic::create_new(&path, text.as_bytes()) {
                Ok(()) => {
                    outln!(
                        "wrote {}; edit it, then run `motorgen check {}`",
                        path.display(),
                        path.display()
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    errln!("error: {e}");
                    output::io_failure()
                }
            }
        }
        Command::Firmware {
            stem,
            all,
            dir,
            board,
            boards_dir,
        } => {
            let which = match stem {
                Some(stem) if !all => firmware::Which::One(stem),
                _ => firmware::Which::All,
            };
            let motors = motors_dir(dir);
            let boards = boards_dir.unwrap_or_else(|| {
                let beside = motors.join("..").join("boards");
                if beside.is_dir() {
                    beside
                } else {
                    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("boards")
                }
            });
            firmware::run(which, &motors, &board, &boards)
        }
        Command::Verify { spec } => verify::run(&spec),
        Command::Report { spec, out } => report::run(&spec, &out),
        Command::Identify { what } => identify::run(what),
        Command::List { dir } => {
            let dir = motors_dir(dir);
            let mut entries: Vec<PathBuf> = match std::fs::read_dir(&dir) {
                Ok(rd) => rd
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                    .collect(),
                Err(e) => {
                    errln!("error: cannot read {}: {e}", dir.display());
                    return ExitCode::FAILURE;
                }
            };
            entries.sort();
            for path in entries {
                let stem = path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                match design(&path) {
                    Ok(d) => outln!("{stem:<24} {}", d.name),
                    Err(e) => outln!(
                        "{stem:<24} INVALID ({} problem{})",
                        e.0.len(),
                        if e.0.len() == 1 { "" } else { "s" }
                    ),
                }
            }
            ExitCode::SUCCESS
        }
    }
}
