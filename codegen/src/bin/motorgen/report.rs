//! `motorgen report <spec> --out DIR`: designs and verifies the motor, then writes the
//! self-contained HTML report `DIR/<stem>.html`.

use std::path::Path;

use crate::exit::{Exit, Failure};

/// Writes the report; no file on a bad spec or a write error. A failing verification
/// is reported in the page and on stderr, with the verification-failed exit code.
pub fn run(spec: &Path, out: &Path) -> Result<(), Failure> {
    let text = crate::read_spec(spec)?;
    let (design, verification) = codegen::verify::verify_source(&spec.display().to_string(), &text)?;
    let page = codegen::report::report(&design, &verification)
        .map_err(|e| Failure::new(Exit::Io, format!("error: cannot draw the report: {e}")))?;
    let stem = spec
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "motor".into());
    let io = |what: String| Failure::new(Exit::Io, what);
    std::fs::create_dir_all(out).map_err(|e| io(format!("error: cannot create {}: {e}", out.display())))?;
    let path = out.join(format!("{stem}.html"));
    // Written whole into a temporary file, then renamed: never a partial page.
    let tmp = out.join(format!(".{stem}.html.tmp"));
    if let Err(e) = std::fs::write(&tmp, page).and_then(|()| std::fs::rename(&tmp, &path)) {
        let _ = std::fs::remove_file(&tmp);
        return Err(io(format!("error: cannot write {}: {e}", path.display())));
    }
    println!("wrote {}", path.display());
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
