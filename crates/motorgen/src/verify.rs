//! `motorgen verify <spec> [--board <file>]`: runs the standard scenarios on the
//! firmware's control step in closed loop with the simulated motor and prints the
//! pass/fail table; on a board, the motor must fit it and the simulation reads currents
//! and DC link through the board's sensing.

use std::path::Path;

use crate::exit::{Exit, Failure};
use crate::output::out;

/// How `verify` prints its verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum VerifyFormat {
    /// The pass/fail table.
    Text,
    /// Every scenario with its criteria (name, measured, designed, limit, unit, pass) and
    /// its verdict, as JSON (`motor_verify::VerificationJson`).
    Json,
}

/// Reads, designs (on `board` if given) and verifies `spec`; prints the design's warnings
/// (stderr) and the table or the JSON verdict. A bad spec or a pair that does not fit is
/// bad input (with the located message), a failing scenario a failed verification.
pub fn run(spec: &Path, board: Option<&Path>, format: VerifyFormat) -> Result<(), Failure> {
    let text = crate::read_spec(spec)?;
    let name = spec.display().to_string();
    let (d, v) = match board {
        Some(b) => {
            let board_text = crate::read_spec(b)?;
            motor_verify::verify_source_on(&name, &text, &b.display().to_string(), &board_text)?
        }
        None => motor_verify::verify_source(&name, &text)?,
    };
    crate::warn_design(&d);
    match format {
        VerifyFormat::Text => out!("{}", v.table()),
        VerifyFormat::Json => {
            let json = serde_json::to_string_pretty(&v.json())
                .map_err(|e| Failure::new(Exit::Io, format!("error: cannot serialise the verdict: {e}")))?;
            out!("{json}");
        }
    }
    if v.passed() {
        Ok(())
    } else {
        Err(Failure::new(Exit::VerificationFailed, failed_message(&v)))
    }
}

/// `verification failed: <scenario ids>`.
pub fn failed_message(v: &motor_verify::Verification) -> String {
    let failed: Vec<&str> = v.scenarios.iter().filter(|s| !s.passed()).map(|s| s.id).collect();
    format!("verification failed: {}", failed.join(", "))
}
