//! `motorgen verify <spec>`: runs the standard scenarios on the firmware's control step
//! in closed loop with the simulated motor and prints the pass/fail table.

use std::path::Path;

use crate::exit::{Exit, Failure};
use crate::output::out;

/// Reads, designs and verifies `spec`; prints the table. A bad spec is bad input (with
/// the located message), a failing scenario a failed verification.
pub fn run(spec: &Path) -> Result<(), Failure> {
    let text = crate::read_spec(spec)?;
    let (_, v) = motor_verify::verify_source(&spec.display().to_string(), &text)?;
    out!("{}", v.table());
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
