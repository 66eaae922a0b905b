//! `motorgen verify <spec>`: runs the standard scenarios on the firmware's control step
//! in closed loop with the simulated motor and prints the pass/fail table.

use std::path::Path;
use std::process::ExitCode;

/// Reads, designs and verifies `spec`; prints the table; non-zero exit if a scenario fails
/// or the spec is bad (with the located message).
pub fn run(spec: &Path) -> ExitCode {
    let text = match crate::read_spec(spec) {
        Ok(t) => t,
        Err(e) => {
            eprint!("{e}");
            return ExitCode::FAILURE;
        }
    };
    match codegen::verify::verify_source(&spec.display().to_string(), &text) {
        Ok((_, v)) => {
            print!("{}", v.table());
            if v.passed() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            }
        }
        Err(e) => {
            eprint!("{e}");
            ExitCode::FAILURE
        }
    }
}
