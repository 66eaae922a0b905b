//! `motorgen report <spec> --out DIR`: designs and verifies the motor, then writes the
//! self-contained HTML report `DIR/<stem>.html`.

use std::path::Path;

use crate::exit::{Exit, Failure};
use crate::output::outln;

/// Writes the report; no file on a bad spec or a write error. A failing verification
/// is reported in the page and on stderr, with the verification-failed exit code.
pub fn run(spec: &Path, out: &Path) -> Result<(), Failure> {
    crate::atomic::check_out_dir(out).map_err(|e| Failure::new(Exit::BadInput, e))?;
    let text = crate::read_spec(spec)?;
    let (design, verification) = motor_verify::verify_source(&spec.display().to_string(), &text)?;
    crate::warn_design(&design);
    let page = motor_verify::report::report(&design, &verification)
        .map_err(|e| Failure::new(Exit::Io, format!("error: cannot draw the report: {e}")))?;
    let stem = spec
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "motor".into());
    let path = out.join(format!("{stem}.html"));
    // Written whole into a temporary file, then renamed: never a partial page.
    crate::atomic::write_set(out, &[(path.clone(), page.into_bytes())])?;
    outln!("wrote {}", path.display());
    if verification.passed() {
        Ok(())
    } else {
        Err(Failure::new(
            Exit::VerificationFailed,
            format!(
                "{} (see the report's table)",
                crate::verify::failed_message(&verification)
            ),
        ))
    }
}
