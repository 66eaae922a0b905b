//! `motorgen verify <spec>`: runs the standard scenarios on the firmware's control step
//! in closed loop with the simulated motor and prints the pass/fail table.

use std::path::Path;
use std::process::ExitCode;

use crate::output::{err, out};

/// Reads, designs and verifies `spec`; prints the table; non-zero exit if a scenario fails
/// or the spec is bad (with the located message).
pub fn run(spec: &Path) -> ExitCode {
    let text = match crate::read_spec(spec) {
        Ok(t) => t,
        Err(e) => {
            err!("{e}");
            return ExitCode::FAILURE;
        }
    };
    match codegen::verify::verify_source(&spec.display().to_string(), &text) {
        Ok((_, v)) => {
            out!("{}", v.table());
            if v.passed() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            }
        }
        Err(e) => {
            err!("{e}");
            ExitCode::FAILURE
        }
    }
}
