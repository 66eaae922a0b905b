//! Instruction budgets (issue 31): the measured instruction counts of the firmware's hot
//! paths, per figure, motor and board, recorded in one file,
//! [`FILE`] (`firmware/instruction-budgets.txt`), and checked in CI within
//! [`BAND`] of the recorded figure — a regression past it fails, and so does an
//! improvement past it, so that the better figure is recorded and the next regression
//! is measured from there.
//!
//! A deliberate change (a new stage in the interrupt, another motor or board) is
//! recorded by running the measuring test with [`RECORD_VAR`]`=1`: it rewrites its
//! figure's lines with what it measured (the other lines are kept) and passes; review
//! the file's diff and commit it.
//!
//! The file is plain text, one figure a line, `#` comments:
//!
//! ```text
//! # figure           motor            board               instructions
//! control_interrupt  fischer-ti085    motorgen-reference  1234
//! ```

use std::fmt::Write as _;
use std::path::PathBuf;

/// The recorded figures, relative to the repository root.
pub const FILE: &str = "firmware/instruction-budgets.txt";
/// Set to `1` to record the measured figures instead of checking them.
pub const RECORD_VAR: &str = "MOTORGEN_RECORD_BUDGETS";
/// The accepted relative deviation from a recorded figure, either way.
pub const BAND: f64 = 0.10;

/// One recorded or measured figure.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Figure {
    /// What is counted, e.g. `control_interrupt` (a word without spaces).
    pub figure: String,
    /// The motor's stem.
    pub motor: String,
    /// The board's stem.
    pub board: String,
    /// Instructions.
    pub instructions: u64,
}

fn path() -> PathBuf {
    crate::repo().join(FILE)
}

/// The figures in `text` (the file's format); a malformed line is an error naming it.
pub fn parse(text: &str) -> Result<Vec<Figure>, String> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        let [figure, motor, board, n] = words[..] else {
            return Err(format!(
                "{FILE}:{}: expected `figure motor board instructions`, found `{line}`",
                i + 1
            ));
        };
        let instructions = n
            .parse::<u64>()
            .map_err(|e| format!("{FILE}:{}: `{n}` is not an instruction count: {e}", i + 1))?;
        out.push(Figure {
            figure: figure.to_string(),
            motor: motor.to_string(),
            board: board.to_string(),
            instructions,
        });
    }
    Ok(out)
}

/// Whether `measured` is within [`BAND`] of `recorded`.
pub fn within_band(measured: u64, recorded: u64) -> bool {
    (measured as f64 - recorded as f64).abs() <= BAND * recorded as f64
}

/// `measured` (every one of the same figure) against the recorded file: `Err` lists
/// each figure with no record or outside the band; with [`RECORD_VAR`]`=1` the figure's
/// lines are rewritten with `measured` instead and the result is `Ok`.
pub fn check(measured: &[Figure]) -> Result<(), String> {
    assert!(!measured.is_empty(), "no figure measured: nothing to check");
    let text = std::fs::read_to_string(path()).unwrap_or_default();
    if std::env::var(RECORD_VAR).is_ok_and(|v| v == "1") {
        let text = record(&text, measured);
        std::fs::write(path(), text).map_err(|e| format!("cannot write {FILE}: {e}"))?;
        println!("recorded {} figure(s) in {FILE}", measured.len());
        return Ok(());
    }
    let recorded = parse(&text)?;
    let mut problems = String::new();
    for m in measured {
        let r = recorded
            .iter()
            .find(|r| r.figure == m.figure && r.motor == m.motor && r.board == m.board);
        match r {
            None => writeln!(
                problems,
                "{} {} {}: measured {} instructions, no figure recorded",
                m.figure, m.motor, m.board, m.instructions
            ),
            Some(r) if !within_band(m.instructions, r.instructions) => writeln!(
                problems,
                "{} {} {}: measured {} instructions, recorded {} ({:+.1} %, outside ±{:.0} %{})",
                m.figure,
                m.motor,
                m.board,
                m.instructions,
                r.instructions,
                (m.instructions as f64 / r.instructions as f64 - 1.0) * 100.0,
                BAND * 100.0,
                if m.instructions < r.instructions {
                    ": an improvement"
                } else {
                    ": a regression"
                },
            ),
            Some(r) => {
                println!(
                    "{} {} {}: {} instructions, recorded {} ({:+.1} %)",
                    m.figure,
                    m.motor,
                    m.board,
                    m.instructions,
                    r.instructions,
                    (m.instructions as f64 / r.instructions as f64 - 1.0) * 100.0
                );
                Ok(())
            }
        }
        .expect("writing to a String");
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{problems}if the change is deliberate, record it with {RECORD_VAR}=1 and commit {FILE}"
        ))
    }
}

/// `text` with the lines of `measured`'s figure/motor/board replaced (or appended) by
/// the measured counts; comments and other lines kept.
pub fn record(text: &str, measured: &[Figure]) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    if lines.is_empty() {
        lines.push(format!(
            "# Instruction budgets: measured figures, checked within ±{:.0} % (crates/test-support/src/budget.rs).",
            BAND * 100.0
        ));
        lines.push(format!("# Rewritten by the measuring tests with {RECORD_VAR}=1."));
        lines.push(format!(
            "# {:<22} {:<22} {:<24} instructions",
            "figure", "motor", "board"
        ));
    }
    for m in measured {
        let new = format!("{:<24} {:<22} {:<24} {}", m.figure, m.motor, m.board, m.instructions);
        let same = |l: &String| {
            parse(l)
                .ok()
                .and_then(|f| f.into_iter().next())
                .is_some_and(|f| f.figure == m.figure && f.motor == m.motor && f.board == m.board)
        };
        match lines.iter().position(same) {
            Some(i) => lines[i] = new,
            None => lines.push(new),
        }
    }
    lines.join("\n") + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fig(figure: &str, motor: &str, n: u64) -> Figure {
        Figure {
            figure: figure.into(),
            motor: motor.into(),
            board: "b".into(),
            instructions: n,
        }
    }

    /// ±10 % of 1000 is 900 ..= 1100: a 9× regression and a halving both fail.
    #[test]
    fn band_is_ten_percent_either_way() {
        assert!(within_band(1100, 1000) && within_band(900, 1000) && within_band(1000, 1000));
        assert!(!within_band(1101, 1000) && !within_band(899, 1000));
        assert!(!within_band(9000, 1000) && !within_band(500, 1000));
    }

    /// Recording replaces the figure's own line, keeps comments and other figures, and
    /// the result parses back to the union.
    #[test]
    fn record_replaces_and_appends() {
        let text = "# c\nx m1 b 10\ny m1 b 20 # note\n";
        let out = record(text, &[fig("x", "m1", 11), fig("x", "m2", 12)]);
        assert!(out.starts_with("# c\n"), "{out}");
        assert_eq!(
            parse(&out).unwrap(),
            vec![fig("x", "m1", 11), fig("y", "m1", 20), fig("x", "m2", 12)]
        );
    }

    #[test]
    fn malformed_lines_are_located() {
        let e = parse("# c\nx m1 b\n").unwrap_err();
        assert!(e.contains(":2:"), "{e}");
        let e = parse("x m1 b ten\n").unwrap_err();
        assert!(e.contains(":1:") && e.contains("ten"), "{e}");
    }
}
