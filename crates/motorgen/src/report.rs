//! `motorgen report <spec> --out DIR`: designs and verifies the motor, then writes the
//! self-contained HTML report `DIR/<stem>.html`.

use std::path::Path;

use crate::exit::{Exit, Failure};
use crate::output::outln;
use motor_verify::report::MeasuredLoop;

/// Writes the report; no file on a bad spec or a write error. A failing verification
/// is reported in the page and on stderr, with the verification-failed exit code.
pub fn run(spec: &Path, out: &Path, measured: Option<&Path>) -> Result<(), Failure> {
    crate::atomic::check_out_dir(out).map_err(|e| Failure::new(Exit::BadInput, e))?;
    let measured = match measured {
        Some(dir) => read_measured(dir)?,
        None => Vec::new(),
    };
    let text = crate::read_spec(spec)?;
    let (design, verification) = motor_verify::verify_source(&spec.display().to_string(), &text)?;
    crate::warn_design(&design);
    let page = motor_verify::report::report_with_measured(&design, &verification, &measured)
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

/// The `frequency-response-<axis>.json` files of `dir` (`commission … frequency-response`)
/// as the report overlays them; at least one, each complete, else bad input naming the
/// file and key.
fn read_measured(dir: &Path) -> Result<Vec<MeasuredLoop>, Failure> {
    let mut out = Vec::new();
    for axis in ["d", "q"] {
        let path = dir.join(format!("frequency-response-{axis}.json"));
        let Ok(text) = std::fs::read_to_string(&path) else {
            continue;
        };
        let bad = |key: &str, problem: &str| {
            Failure::new(
                Exit::BadInput,
                format!(
                    "error: {}: `{key}`: {problem}\n  accepted: the JSON `motorgen commission … frequency-response` writes",
                    path.display()
                ),
            )
        };
        let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| bad("", &format!("not JSON: {e}")))?;
        if v.get("axis").and_then(|a| a.as_str()) != Some(axis) {
            return Err(bad("axis", &format!("is not \"{axis}\"")));
        }
        let points = v
            .get("points")
            .and_then(|p| p.as_array())
            .filter(|p| !p.is_empty())
            .ok_or_else(|| bad("points", "missing or empty"))?;
        let mut m = MeasuredLoop {
            axis: axis.to_string(),
            omega: Vec::new(),
            magnitude_db: Vec::new(),
            phase_deg: Vec::new(),
            summary: String::new(),
        };
        for p in points {
            let num = |k: &str| p.get(k).and_then(|x| x.as_f64()).filter(|x| x.is_finite());
            let (Some(f), Some(db), Some(deg)) = (num("frequency_hz"), num("magnitude_db"), num("phase_deg")) else {
                return Err(bad("points", "a point lacks frequency_hz, magnitude_db or phase_deg"));
            };
            m.omega.push(2.0 * std::f64::consts::PI * f);
            m.magnitude_db.push(db);
            m.phase_deg.push(deg);
        }
        let fig = |block: &str, key: &str, unit: &str| {
            v.get(block)
                .and_then(|b| b.get(key))
                .and_then(|x| x.as_f64())
                .map_or_else(|| "—".to_string(), |x| format!("{x:.2}{unit}"))
        };
        let plant = |block: &str| {
            let g = |k: &str, scale: f64, unit: &str| {
                v.get(block)
                    .and_then(|b| b.get(k))
                    .and_then(|x| x.as_f64())
                    .map_or_else(|| "—".to_string(), |x| format!("{:.4}{unit}", x * scale))
            };
            format!(
                "R {}, L {}, delay {}",
                g("resistance_ohm", 1.0, " Ω"),
                g("inductance_h", 1e3, " mH"),
                g("delay_periods", 1.0, " T_s")
            )
        };
        m.summary = format!(
            "gain margin {} (designed {}), phase margin {} (designed {}), crossover {} (designed {}); fitted plant {} beside the spec's {}",
            fig("measured", "gain_margin_db", " dB"),
            fig("designed", "gain_margin_db", " dB"),
            fig("measured", "phase_margin_deg", "°"),
            fig("designed", "phase_margin_deg", "°"),
            fig("measured", "crossover_rad_s", " rad/s"),
            fig("designed", "crossover_rad_s", " rad/s"),
            plant("fitted_plant"),
            plant("designed_plant"),
        );
        out.push(m);
    }
    if out.is_empty() {
        return Err(Failure::new(
            Exit::BadInput,
            format!(
                "error: {}: no frequency-response-d.json or frequency-response-q.json\n  accepted: the --out directory of `motorgen commission … frequency-response`",
                dir.display()
            ),
        ));
    }
    Ok(out)
}
