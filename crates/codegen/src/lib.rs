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
    let board_src = Source {
        file: board_file,
        text: board_text,
    };
    let board = board_source(board_file, board_text);
    let source = Source { file, text };
    let spec = spec::parse(source);
    let (board, spec) = match (board, spec) {
        (Ok(b), Ok(s)) => (b, s),
        (Err(mut a), Err(b)) => {
            a.0.extend(b.0);
            return Err(a);
        }
        (Err(e), _) | (_, Err(e)) => return Err(e),
    };
    // The motor is designed for the voltage the board's duty limit leaves it
    // (`design::duty_limit`): its switching frequency and dead time with the board's
    // sampling window.
    let fs = spec.drive.switching_frequency.value;
    let dead = spec
        .drive
        .dead_time
        .as_ref()
        .map_or(board.dead_time_s, |p| p.value.max(board.dead_time_s));
    let limit = design::duty_limit::for_board(&board, fs, dead);
    // A window that leaves too little voltage is the board's error, before the motor's
    // design fails for lack of voltage at a spec key.
    if let Some(e) = limit
        .as_ref()
        .and_then(|l| design::refuse_duty_limit(&board, board_src, l, fs))
    {
        return Err(Diagnostics(vec![e]));
    }
    let max_duty = limit.as_ref().map_or(1.0, |l| l.max_duty);
    // The current loop is designed for the delay the board's timing makes, the angle
    // lead for its resolver's. Where TIM1 cannot make f_s (the drive section refuses
    // it), or the conversions end after the update (a delay the sampled model does not
    // carry: the board section refuses it at `sensing.source_resistance.current`), the
    // motor is designed with the nominal delay meanwhile.
    let (lo, hi) = design::current_loop::discrete::MODELLED_DELAY_PERIODS;
    let timing = design::timing_of(&board, fs).filter(|t| {
        let d = t.loop_delay_s * fs;
        d > lo && d <= hi && t.angle_lead_periods > lo
    });
    let nominal = design::current_loop::NOMINAL_LOOP_DELAY_PERIODS;
    let terms = design::BoardTerms {
        max_duty,
        loop_delay_periods: timing.map_or(nominal, |t| t.loop_delay_s * fs),
        angle_lead_periods: timing.map_or(nominal, |t| t.angle_lead_periods),
        resolver_signal_gain: board::resolver_signal_gain(&board, fs),
    };
    match design::design_on(&spec, source, terms) {
        Ok(d) => design::on_board(d, &board, board_src),
        Err(e) if max_duty < 1.0 => {
            // The motor fails with the voltage the board leaves it. Designed with the
            // whole linear range: a motor that fails then too gets its own errors; one the
            // board does not fit for other reasons (its sensing, ratings) gets those; one
            // that only lacks the voltage gets the duty limit as the board's error, with
            // the motor's rule as a note.
            let alone = design::design_on(&spec, source, design::BoardTerms { max_duty: 1.0, ..terms })?;
            design::on_board(alone, &board, board_src)?;
            let l = limit.as_ref().expect("a duty limit below 1 comes from one");
            let key = design::duty_limit_key(l);
            let (what, shorter) = if l.bound == design::duty_limit::DutyBound::DeadTime {
                (
                    format!(
                        "TIM1's dead time of {:.0} ns (the longer of the board's and the motor's) keeps every compare value at least {} timer ticks from the carrier's ends and so",
                        l.dead_time_s * 1e9,
                        l.min_pulse
                    ),
                    "dead time (`pwm.dead_time` here, `drive.dead_time` in the motor file)",
                )
            } else {
                (
                    "the low-side shunts' sampling window".to_string(),
                    "settling, dead or sampling time on the board",
                )
            };
            let mut d = board_src.error(
                board.span(key),
                key,
                format!(
                    "{what} limits the duty to {:.4} at f_s = {fs} Hz, which leaves {} ({file}) only {:.1} % of U_dc/√3 ({:.2} V): its design does not hold with that voltage (note)",
                    l.max_duty,
                    spec.name,
                    l.usable_voltage_fraction * 100.0,
                    l.usable_voltage_fraction * spec.drive.dc_link_voltage.value / 3f64.sqrt()
                ),
                format!("a shorter {shorter}, a lower switching frequency, or a motor that fits the usable voltage"),
            );
            d.notes.extend(e.0.iter().map(|x| x.to_string()));
            Err(Diagnostics(vec![d]))
        }
        Err(e) => Err(e),
    }
}

/// Parses, resolves and designs one spec. `file` is only used in messages.
pub fn design_source(file: &str, text: &str) -> Result<Design, Diagnostics> {
    let source = Source { file, text };
    let spec = spec::parse(source)?;
    design::design(&spec, source)
}
