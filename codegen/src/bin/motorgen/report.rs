//! `motorgen report <spec> --out DIR`: designs and verifies the motor, then writes the
//! self-contained HTML report `DIR/<stem>.html`.

use std::path::Path;
use std::process::ExitCode;

use crate::output::{err, errln, outln};

/// Writes the report; non-zero exit (and no file) on a bad spec or a write error. A
/// failing verification is reported in the page and on stderr, and the exit is non-zero.
pub fn run(spec: &Path, out: &Path) -> ExitCode {
    if let Err(e) = crate::atomic::check_out_dir(out) {
        errln!("{e}");
        return ExitCode::FAILURE;
    }
    let text = match crate::read_spec(spec) {
        Ok(t) => t,
        Err(e) => {
            err!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let (design, verification) = match codegen::verify::verify_source(&spec.display().to_string(), &text) {
        Ok(x) => x,
        Err(e) => {
            err!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let page = match codegen::report::report(&design, &verification) {
        Ok(p) => p,
        Err(e) => {
            errln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let stem = spec
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "motor".into());
    let path = out.join(format!("{stem}.html"));
    // Written whole into a temporary file, then renamed: never a partial page.
    if let Err(e) = crate::atomic::write_set(out, &[(path.clone(), page.into_bytes())]) {
        errln!("error: {e}");
        return crate::output::io_failure();
    }
    outln!("wrote {}", path.display());
    if verification.passed() {
        ExitCode::SUCCESS
    } else {
        let failed: Vec<&str> = verification
            .scenarios
            .iter()
            .filter(|s| !s.passed())
            .map(|s| s.id)
            .collect();
        errln!("verification failed: {} (see the report's table)", failed.join(", "));
        ExitCode::FAILURE
    }
}
