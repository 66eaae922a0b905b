//! `motorgen firmware <stem> [--board <board>]` / `motorgen firmware --all`: the
//! STM32G474 image of one motor or of every motor in `motors/`, on a board of `boards/`
//! (default `motorgen-reference`).
//!
//! Per motor: designs the spec on the board first (a bad spec or board file, or a motor
//! the board does not fit, stops here with its located diagnostic; with `--all`, a sound
//! spec the board does not fit is left out with a warning naming the board keys, and it
//! is an error only if no motor fits; the design's warnings are printed once on stderr),
//! runs
//! `cargo build --release --target thumbv7em-none-eabihf -p motor-firmware` in
//! `firmware/` with `MOTOR=<stem>`, `MOTORS_DIR`, `BOARD=<board>` and `BOARDS_DIR` (one
//! shared target directory, so only the app crate rebuilds per motor), copies the ELF to
//! `target/firmware/<stem>.elf` under the repository root (`target/firmware/<board>/`
//! for another board), writes `<stem>.bin` (the
//! ELF's loadable segments placed by load address, gaps filled with the erased-flash
//! byte 0xFF) and prints flash and static RAM use; for one motor it first prints the
//! constants summary of the design the image is built from. An image over the 64 KiB flash
//! budget (the G474RE itself has 512 KiB) is an error and is not written.
//!
//! The repository root is the nearest ancestor of the motors folder that holds
//! `firmware/Cargo.toml`, else the nearest such ancestor of the current directory —
//! never the source tree `motorgen` was built from (an installed binary's build path).

use std::fmt::Write as _;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use object::elf;
use object::read::elf::{ElfFile32, FileHeader, ProgramHeader, SectionHeader};
use object::{Endianness, Object, ObjectSection, ObjectSymbol};

use crate::exit::{Exit, Failure};
use crate::output::{errln, out};

/// The firmware's target triple.
const TARGET: &str = "thumbv7em-none-eabihf";
/// The firmware package (a binary of the same name).
const PACKAGE: &str = "motor-firmware";
/// The project's flash budget for one image \[bytes\] — a budget, not the chip's limit:
/// the STM32G474RE has 512 KiB of flash (DS12288 Table 2).
pub const FLASH_LIMIT: u64 = 64 * 1024;
/// How cargo prints a `cargo::warning` of `motor-config`'s build script (the design's
/// warnings for this motor on the board, which `run` has printed already).
const BUILD_SCRIPT_WARNING: &str = "warning: motor-config@";
/// Erased-flash byte, for gaps between segments in the `.bin`.
const ERASED: u8 = 0xFF;
/// Largest span of load addresses accepted for a `.bin` \[bytes\]: more means a
/// segment is loaded outside flash (the file would be mostly padding).
const MAX_SPAN: u64 = 16 * 1024 * 1024;

/// What to build.
pub enum Which {
    /// One stem.
    One(String),
    /// Every `*.toml` in the motors folder that fits the board (the others are warned about).
    All,
}

/// Flash and RAM use of one image.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Usage {
    /// Bytes in flash: the `.bin` length (vector table, text, rodata, .data load image).
    pub flash: u64,
    /// Flash bytes per allocated section with contents, in address order.
    pub flash_sections: Vec<(String, u64)>,
    /// Static RAM: .data + .bss + .uninit (every allocated writable section) \[bytes\].
    pub ram: u64,
    /// RAM bytes per allocated writable section.
    pub ram_sections: Vec<(String, u64)>,
    /// Stack space: `_stack_start − _stack_end` if the ELF defines both (the image's
    /// memory.x places the stack at the bottom of RAM, below the static data).
    pub stack: Option<u64>,
}

/// The `.bin` image and the usage figures of an ELF.
#[derive(Debug)]
pub struct Image {
    /// Flat binary from the lowest load address.
    pub bin: Vec<u8>,
    /// Load address of `bin[0]`.
    pub base: u64,
    /// Flash and RAM use.
    pub usage: Usage,
}

/// Reads a 32-bit ARM ELF: loadable segments by physical (load) address into a flat
/// binary, section sizes into the usage figures.
pub fn image(elf_bytes: &[u8]) -> Result<Image, String> {
    let file = ElfFile32::<Endianness>::parse(elf_bytes).map_err(|e| format!("not a 32-bit ELF: {e}"))?;
    let e = file.endian();
    let machine = file.elf_header().e_machine(e);
    if machine != elf::EM_ARM {
        return Err(format!("not an ARM ELF (e_machine {machine})"));
    }
    let mut loads = Vec::new();
    for ph in file.elf_program_headers() {
        if ph.p_type(e) != elf::PT_LOAD || ph.p_filesz(e) == 0 {
            continue;
        }
        let data = ph
            .data(e, elf_bytes)
            .map_err(|()| "a loadable segment lies outside the file".to_string())?;
        loads.push((u64::from(ph.p_paddr(e)), data));
    }
    loads.sort_by_key(|&(addr, _)| addr);
    let (Some(&(base, _)), Some(end)) = (loads.first(), loads.iter().map(|&(a, d)| a + d.len() as u64).max()) else {
        return Err("the ELF has no loadable contents".into());
    };
    let span = end - base;
    if span > MAX_SPAN {
        return Err(format!(
            "loadable segments span {span} bytes from {base:#010x}: a segment is loaded outside flash"
        ));
    }
    let mut bin = vec![ERASED; span as usize];
    let mut covered_to = base;
    for (addr, data) in &loads {
        if *addr < covered_to {
            return Err(format!("loadable segments overlap at {addr:#010x}"));
        }
        let at = (addr - base) as usize;
        bin[at..at + data.len()].copy_from_slice(data);
        covered_to = addr + data.len() as u64;
    }

    let mut flash_sections = Vec::new();
    let mut ram_sections = Vec::new();
    for s in file.sections() {
        let header = s.elf_section_header();
        let flags = header.sh_flags(e);
        if !flags.contains(elf::SHF_ALLOC) || s.size() == 0 {
            continue;
        }
        let name = s.name().unwrap_or("?").to_string();
        if header.sh_type(e) != elf::SHT_NOBITS {
            flash_sections.push((name.clone(), s.size()));
        }
        if flags.contains(elf::SHF_WRITE) {
            ram_sections.push((name, s.size()));
        }
    }
    let symbol = |name: &str| file.symbols().find(|s| s.name() == Ok(name)).map(|s| s.address());
    let stack = match (symbol("_stack_start"), symbol("_stack_end")) {
        (Some(start), Some(end)) if start >= end => Some(start - end),
        _ => None,
    };
    // Alignment gaps between the segments (filled with 0xFF in the `.bin`).
    let contents: u64 = loads.iter().map(|(_, d)| d.len() as u64).sum();
    if span > contents {
        flash_sections.push(("padding".to_string(), span - contents));
    }
    let usage = Usage {
        flash: span,
        flash_sections,
        ram: ram_sections.iter().map(|(_, n)| n).sum(),
        ram_sections,
        stack,
    };
    Ok(Image { bin, base, usage })
}

/// `n` bytes as KiB with one decimal.
fn kib(n: u64) -> String {
    format!("{:.1} KiB", n as f64 / 1024.0)
}

/// The report lines of one image.
pub fn report(stem: &str, usage: &Usage) -> String {
    let mut out = String::new();
    let parts = |v: &[(String, u64)]| {
        v.iter()
            .map(|(n, b)| format!("{n} {b}"))
            .collect::<Vec<_>>()
            .join(" + ")
    };
    let _ = writeln!(
        out,
        "{stem}: flash {} bytes ({}, {:.1} % of the 64 KiB budget) = {}",
        usage.flash,
        kib(usage.flash),
        usage.flash as f64 / FLASH_LIMIT as f64 * 100.0,
        parts(&usage.flash_sections)
    );
    let _ = write!(
        out,
        "{stem}: static RAM {} bytes ({}) = {}",
        usage.ram,
        kib(usage.ram),
        if usage.ram_sections.is_empty() {
            "no .data/.bss".to_string()
        } else {
            parts(&usage.ram_sections)
        }
    );
    match usage.stack {
        Some(s) => {
            let _ = writeln!(out, "; stack: {s} bytes ({}) below the statics", kib(s));
        }
        None => out.push('\n'),
    }
    out
}

/// Nearest ancestor of `start` (itself included) holding `firmware/Cargo.toml`.
fn root_above(start: &Path) -> Option<PathBuf> {
    let start = start.canonicalize().ok()?;
    start
        .ancestors()
        .find(|d| d.join("firmware").join("Cargo.toml").is_file())
        .map(Path::to_path_buf)
}

/// The repository root (see the module documentation).
fn repo_root(motors: &Path) -> Result<PathBuf, String> {
    root_above(motors)
        .or_else(|| std::env::current_dir().ok().and_then(|d| root_above(&d)))
        .ok_or_else(|| {
            format!(
                "cannot find the repository (a folder holding firmware/Cargo.toml) above {} or the \
                 current directory\n  accepted: run motorgen inside the motor-toolchain repository",
                motors.display()
            )
        })
}

/// The `*.toml` stems (motors or boards) in `dir`, sorted.
fn stems(dir: &Path, what: &str) -> Result<Vec<String>, String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| format!("cannot read the {what} folder {}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    v.sort();
    Ok(v)
}

/// The "accepted:" list of an unknown stem: the stems that exist.
fn accepted(known: &[String]) -> String {
    if known.is_empty() {
        "none: the folder holds no *.toml".to_string()
    } else {
        known.join(", ")
    }
}

/// The motor and board an image is built for, with their folders.
pub struct Target<'a> {
    /// Motor specs folder.
    pub motors: &'a Path,
    /// Board stem.
    pub board: &'a str,
    /// Board files folder.
    pub boards: &'a Path,
}

/// Runs cargo for `stem` on the board, relaying its progress (stderr) line by line as it
/// comes; returns the built ELF's path (from cargo's JSON messages on stdout).
fn cargo_build(root: &Path, t: &Target<'_>, stem: &str) -> Result<PathBuf, Failure> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let command = format!(
        "MOTOR={stem} BOARD={} cargo build --release --target {TARGET} -p {PACKAGE}",
        t.board
    );
    errln!("{stem}: {command} (in firmware/; a first build takes minutes)");
    let child = Command::new(&cargo)
        .args(["build", "--release", "--target", TARGET, "-p", PACKAGE])
        .args(["--message-format=json-render-diagnostics"])
        .current_dir(root.join("firmware"))
        .env("MOTOR", stem)
        .env("MOTORS_DIR", t.motors)
        .env("BOARD", t.board)
        .env("BOARDS_DIR", t.boards)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn();
    let io = |what: String| Failure::new(Exit::Io, what);
    let mut child = match child {
        Ok(c) => c,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(io(format!(
                "error: `{}` was not found: install Rust with rustup (https://rustup.rs), then \
                 `rustup target add {TARGET}`",
                cargo.to_string_lossy()
            )));
        }
        Err(e) => return Err(io(format!("error: cannot run {}: {e}", cargo.to_string_lossy()))),
    };
    let (Some(out), Some(err)) = (child.stdout.take(), child.stderr.take()) else {
        return Err(io(format!(
            "error: cannot read the output of {}",
            cargo.to_string_lossy()
        )));
    };
    // Progress and rendered diagnostics go to our stderr as they come; a copy is kept
    // for the hint below. The JSON messages on stdout are read meanwhile.
    let relay = std::thread::spawn(move || {
        let mut seen = String::new();
        for line in BufReader::new(err).lines().map_while(Result::ok) {
            // The build script's `cargo::warning`s are the design's warnings about the
            // board, which were printed once before cargo ran.
            if line.starts_with(BUILD_SCRIPT_WARNING) {
                continue;
            }
            errln!("{line}");
            seen.push_str(&line);
            seen.push('\n');
        }
        seen
    });
    let mut stdout = String::new();
    let read = BufReader::new(out).read_to_string(&mut stdout);
    let status = child.wait();
    let stderr = relay.join().unwrap_or_default();
    let status = status
        .and_then(|s| read.map(|_| s))
        .map_err(|e| io(format!("error: {command}: {e}")))?;
    if !status.success() {
        let hint = if stderr.contains("target may not be installed") || stderr.contains("can't find crate for `core`") {
            format!("\n  the {TARGET} target is missing: install it with `rustup target add {TARGET}`")
        } else {
            String::new()
        };
        return Err(Failure::new(
            Exit::BuildFailed,
            format!("error: {command} failed ({status}; its messages are above){hint}"),
        ));
    }
    stdout
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|m| {
            m["reason"] == "compiler-artifact" && m["target"]["name"] == PACKAGE && m["target"]["kind"][0] == "bin"
        })
        .find_map(|m| m["executable"].as_str().map(PathBuf::from))
        .ok_or_else(|| {
            Failure::new(
                Exit::BuildFailed,
                format!("error: cargo built no `{PACKAGE}` executable (is firmware/app a binary crate?)"),
            )
        })
}

/// Builds, checks and writes one motor's image (its spec designs); returns its report.
fn build_one(root: &Path, t: &Target<'_>, stem: &str) -> Result<String, Failure> {
    let elf_path = cargo_build(root, t, stem)?;
    let io = |what: String| Failure::new(Exit::Io, what);
    let bytes = std::fs::read(&elf_path).map_err(|e| io(format!("error: cannot read {}: {e}", elf_path.display())))?;
    let image =
        image(&bytes).map_err(|e| Failure::new(Exit::BuildFailed, format!("error: {}: {e}", elf_path.display())))?;
    let mut report = report(stem, &image.usage);
    if image.usage.flash > FLASH_LIMIT {
        return Err(Failure::new(
            Exit::VerificationFailed,
            format!(
                "{report}error: {stem}: the image needs {} bytes of flash, more than the 64 KiB ({FLASH_LIMIT} \
                 bytes) budget; nothing written (the ELF is {})",
                image.usage.flash,
                elf_path.display()
            ),
        ));
    }
    let mut out = root.join("target").join("firmware");
    if t.board != codegen::board::DEFAULT_BOARD {
        out = out.join(t.board);
    }
    let elf_out = out.join(format!("{stem}.elf"));
    let bin_out = out.join(format!("{stem}.bin"));
    // The pair is replaced together or not at all.
    crate::atomic::write_set(&out, &[(elf_out.clone(), bytes), (bin_out.clone(), image.bin.clone())])?;
    let _ = writeln!(
        report,
        "{stem}: wrote {} and {} (load address {:#010x})",
        elf_out.display(),
        bin_out.display(),
        image.base
    );
    Ok(report)
}

/// The `firmware` subcommand. Every selected spec must design on the board before cargo
/// runs; every motor is built even if one fails, and the exit code is the gravest failure's.
pub fn run(which: Which, motors: &Path, board: &str, boards: &Path) -> Result<(), Failure> {
    let known = stems(motors, "motors").map_err(|e| Failure::new(Exit::Io, format!("error: {e}")))?;
    let every = matches!(which, Which::All);
    let selected = match which {
        Which::All if known.is_empty() => {
            return Err(Failure::new(
                Exit::BadInput,
                format!(
                    "error: no motor specs (*.toml) in {}\n  accepted: a folder of motor specs (`motorgen new <stem>` writes one)",
                    motors.display()
                ),
            ));
        }
        Which::All => known,
        Which::One(stem) if known.contains(&stem) => vec![stem],
        Which::One(stem) => {
            return Err(Failure::new(
                Exit::BadInput,
                format!(
                    "error: no motor `{stem}` in {} (no {stem}.toml)\n  accepted: {}",
                    motors.display(),
                    accepted(&known)
                ),
            ));
        }
    };
    let root = repo_root(motors).map_err(|e| Failure::new(Exit::Io, format!("error: {e}")))?;
    let motors = motors.canonicalize().unwrap_or_else(|_| motors.to_path_buf());
    let boards = boards.canonicalize().unwrap_or_else(|_| boards.to_path_buf());
    let board_file = boards.join(format!("{board}.toml"));
    if !board_file.is_file() {
        return Err(Failure::new(
            Exit::BadInput,
            format!(
                "error: no board `{board}` in {} (no {board}.toml)\n  accepted: {}",
                boards.display(),
                accepted(&stems(&boards, "boards").unwrap_or_default())
            ),
        ));
    }
    // Every selected spec must design on the board before cargo runs (located
    // diagnostics, a motor the board does not fit among them). With --all, a motor whose
    // spec is sound but which does not fit the board is left out with a warning that
    // names the board keys; a named motor that does not fit is an error.
    let mut designs = Vec::new();
    let mut built = Vec::new();
    let mut failed = Vec::new();
    for stem in &selected {
        let spec = motors.join(format!("{stem}.toml"));
        match super::design_on(&spec, Some(&board_file)) {
            Ok(d) => {
                crate::warn_design(&d);
                designs.push(d);
                built.push(stem.clone());
            }
            Err(f) if every && f.exit == Exit::BadInput && super::design(&spec).is_ok() => {
                let reasons: Vec<String> = f
                    .message
                    .lines()
                    .filter_map(|l| l.strip_prefix("error: "))
                    .map(|l| format!("\n  {l}"))
                    .collect();
                crate::output::warn(format_args!(
                    "{stem} is not built for {board}: it does not fit the board{}",
                    reasons.concat()
                ));
            }
            Err(f) => {
                failed.push(f.exit);
                f.report();
            }
        }
    }
    if let Some(exit) = Exit::gravest(&failed) {
        return Err(Failure::new(exit, "firmware: nothing built (a spec has problems)"));
    }
    if built.is_empty() {
        return Err(Failure::new(
            Exit::BadInput,
            format!(
                "error: no motor in {} fits board `{board}` (see the warnings above)\n  accepted: a board whose sensing and ratings cover a motor's peak current, DC link and speed",
                motors.display()
            ),
        ));
    }
    let target = Target {
        motors: &motors,
        board,
        boards: &boards,
    };
    // One motor: the constants the image is built from, as `motorgen design` prints them.
    if let (false, [d]) = (every, designs.as_slice()) {
        out!("{}", codegen::summary::summary(d));
    }
    for stem in &built {
        match build_one(&root, &target, stem) {
            Ok(report) => out!("{report}"),
            Err(f) => {
                failed.push(f.exit);
                f.report();
            }
        }
    }
    match Exit::gravest(&failed) {
        None => Ok(()),
        Some(exit) => Err(Failure::new(
            exit,
            format!("firmware: {} of {} images not built", failed.len(), selected.len()),
        )),
    }
}
