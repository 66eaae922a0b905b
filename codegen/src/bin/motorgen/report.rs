//! `motorgen report <spec> --out DIR`: designs and verifies the motor, then writes the
//! self-contained HTML report `DIR/<stem>.html`.

use std::path::Path;
use std::process::ExitCode;

/// Writes the report; non-zero exit (and no file) on a bad spec or a write error. A
/// failing verification is reported in the page and on stderr, and the exit is non-zero.
pub fn run(spec: &Path, out: &Path) -> ExitCode {
    let text = match crate::read_spec(spec) {
        Ok(t) => t,
        Err(e) => {
            eprint!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let (design, verification) = match codegen::verify::verify_source(&spec.display().to_string(), &text) {
        Ok(x) => x,
        Err(e) => {
            eprint!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let page = match codegen::report::report(&design, &verification) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let stem = spec
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "motor".into());
    if let Err(e) = std::fs::create_dir_all(out) {
        eprintln!("error: cannot create {}: {e}", out.display());
        return ExitCode::FAILURE;
    }
    let path = out.join(format!("{stem}.html"));
    // Written whole into a temporary file, then renamed: never a partial page.
    let tmp = out.join(format!(".{stem}.html.tmp"));
    if let Err(e) = std::fs::write(&tmp, page).and_then(|()| std::fs::rename(&tmp, &path)) {
        let _ = std::fs::remove_file(&tmp);
        eprintln!("error: cannot write {}: {e}", path.display());
        return ExitCode::FAILURE;
    }
    println!("wrote {}", path.display());
    if verification.passed() {
        ExitCode::SUCCESS
    } else {
        let failed: Vec<&str> = verification
            .scenarios
            .iter()
            .filter(|s| !s.passed())
            .map(|s| s.id)
            .collect();
        eprintln!("verification failed: {} (see the report's table)", failed.join(", "));
        ExitCode::FAILURE
    }
}
