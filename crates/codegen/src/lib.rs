//! `codegen`, the design core: a motor description (TOML) in, every tuned controller
//! constant out, rendered as Rust, C, Markdown and DBC.
//!
//! The design path does no file I/O: [`design_source`] takes the file's name and
//! text and returns the [`Design`] or located [`Diagnostics`]. The `motorgen` CLI, the
//! firmware's build script and the proc-macros all call it, so a constant cannot differ
//! between the three paths. ([`files`] holds the one helper the CLI and the build
//! scripts share to write generated files.)
//!
//! Layers inside (each module may use the ones above it, never one below; checked by
//! `tests/it/layers.rs`): [`units`], [`diagnostic`], [`escape`], [`firmware`] (the image's
//! clocks and the limits its build enforces) → [`spec`], [`board`] (parsing) → [`design`]
//! → [`constants`] → [`render`], [`summary`].
//! This crate depends on no simulation, plotting, CLI, CAN or file-editing crate
//! (`ARCHITECTURE.md`): verification is `motor-verify`, identification and the CAN
//! session `motor-commission`, the command line `motorgen`.

pub mod board;
pub mod constants;
pub mod design;
pub mod diagnostic;
pub mod escape;
pub mod files;
pub mod firmware;
pub mod render;
pub mod spec;
pub mod summary;
pub mod units;

pub use design::Design;
pub use diagnostic::{Diagnostic, Diagnostics, Source};

/// Parses and checks one board file. `file` is only used in messages.
pub fn board_source(file: &str, text: &str) -> Result<board::Board, Diagnostics> {
    board::parse(Source { file, text })
}

/// Designs a motor on a board: the motor's design ([`design_source`]) with the board's
/// constants and the checks that need both (warnings at the board key, see
/// [`design::on_board`]).
pub fn design_with_board(file: &str, text: &str, board_file: &str, board_text: &str) -> Result<Design, Diagnostics> {
    let board = board_source(board_file, board_text);
    // The motor is designed for the voltage the board's duty limit leaves it
    // (`design::duty_limit`): its switching frequency and dead time with the board's
    // sampling window.
    let source = Source { file, text };
    let design = spec::parse(source).and_then(|spec| {
        let max_duty = board.as_ref().ok().and_then(|b| {
            let dead = spec
                .drive
                .dead_time
                .as_ref()
                .map_or(b.dead_time_s, |p| p.value.max(b.dead_time_s));
            let l = design::duty_limit::for_board(b, spec.drive.switching_frequency.value, dead)?;
            Some((l, spec.drive.switching_frequency.value))
        });
        // A window that leaves too little voltage is the board's error, before the
        // motor's design fails for lack of voltage at a spec key.
        if let (Some((l, fs)), Ok(b)) = (&max_duty, &board)
            && let Some(e) = design::refuse_duty_limit(
                b,
                Source {
                    file: board_file,
                    text: board_text,
                },
                l,
                *fs,
            )
        {
            return Err(Diagnostics(vec![e]));
        }
        design::design_with_duty_limit(&spec, source, max_duty.map_or(1.0, |(l, _)| l.max_duty))
    });
    let (board, design) = match (board, design) {
        (Ok(b), Ok(d)) => (b, d),
        (Err(mut a), Err(b)) => {
            a.0.extend(b.0);
            return Err(a);
        }
        (Err(e), _) | (_, Err(e)) => return Err(e),
    };
    design::on_board(
        design,
        &board,
        Source {
            file: board_file,
            text: board_text,
        },
    )
}

/// Parses, resolves and designs one spec. `file` is only used in messages.
pub fn design_source(file: &str, text: &str) -> Result<Design, Diagnostics> {
    let source = Source { file, text };
    let spec = spec::parse(source)?;
    design::design(&spec, source)
}
