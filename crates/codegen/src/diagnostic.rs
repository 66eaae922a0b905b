//! Located, user-facing errors: every problem in a motor spec names the file,
//! the line and column, the key, what is wrong and what would be accepted.

use std::fmt;
use std::ops::Range;

/// One problem found in a motor spec.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// The file as the user named it.
    pub file: String,
    /// 1-based line of the offending text.
    pub line: usize,
    /// 1-based column (in characters) of the offending text.
    pub column: usize,
    /// Dotted key path, e.g. `motor.datasheet.inductance` (empty for whole-file problems).
    pub key: String,
    /// What is wrong.
    pub problem: String,
    /// What would be accepted instead.
    pub accepted: String,
    /// The source line, for the excerpt under the message.
    pub excerpt: String,
    /// Further observations that bear on it (e.g. the spec's cross-checks that disagree),
    /// each printed as a `note:` line.
    pub notes: Vec<String>,
}

/// Where a spec came from, and its text, for locating byte spans.
#[derive(Debug, Clone, Copy)]
pub struct Source<'a> {
    /// The file name shown in messages.
    pub file: &'a str,
    /// The file's text.
    pub text: &'a str,
}

impl<'a> Source<'a> {
    /// Builds a diagnostic at byte `span` of the source.
    pub fn error(
        &self,
        span: Range<usize>,
        key: impl Into<String>,
        problem: impl Into<String>,
        accepted: impl Into<String>,
    ) -> Diagnostic {
        let (line, column, excerpt) = locate(self.text, span.start);
        Diagnostic {
            file: self.file.to_string(),
            line,
            column,
            key: key.into(),
            problem: problem.into(),
            accepted: accepted.into(),
            excerpt,
            notes: Vec::new(),
        }
    }
}

impl Source<'_> {
    /// A warning located at byte `span`: `file:line:column: \`key\`: text` (what every
    /// command prints on stderr after `warning: `).
    pub fn warning(&self, span: Range<usize>, key: &str, text: impl std::fmt::Display) -> String {
        let (line, column, _) = locate(self.text, span.start);
        if key.is_empty() {
            format!("{}:{line}:{column}: {text}", self.file)
        } else {
            format!("{}:{line}:{column}: `{key}`: {text}", self.file)
        }
    }

    /// The span of the header `[table]` in the file, for a warning about a key the table
    /// lacks (0..0, the file's start, if the file has no such header).
    pub fn table_span(&self, table: &str) -> Range<usize> {
        let header = format!("[{table}]");
        let mut offset = 0;
        for line in self.text.split_inclusive('\n') {
            let t = line.trim_start();
            if t.starts_with(&header) {
                let at = offset + (line.len() - t.len());
                return at..at + header.len();
            }
            offset += line.len();
        }
        0..0
    }
}

/// 1-based line and column of byte `offset` in `text`, and that line's text.
fn locate(text: &str, offset: usize) -> (usize, usize, String) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = text[line_start..offset].chars().count() + 1;
    let line_end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    let excerpt = text[line_start..line_end].trim_end_matches('\r').to_string();
    (line, column, excerpt)
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "error: {}:{}:{}: ", self.file, self.line, self.column)?;
        if !self.key.is_empty() {
            write!(f, "`{}`: ", self.key)?;
        }
        writeln!(f, "{}", self.problem)?;
        if !self.excerpt.is_empty() {
            let gutter = " ".repeat(self.line.to_string().len());
            let (shown, caret) = excerpt_window(&self.excerpt, self.column);
            writeln!(f, "{gutter} |")?;
            writeln!(f, "{} | {shown}", self.line)?;
            // The caret's indent is written out, not a format width: a width above
            // u16::MAX (a column past 65 535 on one long line) panics in `fmt`.
            writeln!(f, "{gutter} | {}^", " ".repeat(caret - 1))?;
        }
        write!(f, "  accepted: {}", self.accepted)?;
        for n in &self.notes {
            write!(f, "\n  note: {n}")?;
        }
        Ok(())
    }
}

/// Longest excerpt line shown whole \[characters\] (the shipped specs and boards stay below
/// 160); a longer line is shown as a window of
/// [`EXCERPT_WINDOW`] characters around the column.
pub const EXCERPT_MAX: usize = 240;
/// Characters of a long line shown around the column \[characters\].
pub const EXCERPT_WINDOW: usize = 80;
/// Characters of the window before the column \[characters\].
const WINDOW_BEFORE: usize = 30;

/// The part of `line` shown under a message and the 1-based character column of the
/// caret in it: the whole line up to [`EXCERPT_MAX`] characters, else
/// [`EXCERPT_WINDOW`] characters around `column` with `…` where the line goes on (a
/// spec may hold one line of megabytes; the excerpt stays one screen line).
fn excerpt_window(line: &str, column: usize) -> (String, usize) {
    let len = line.chars().count();
    let column = column.clamp(1, len + 1);
    if len <= EXCERPT_MAX {
        return (line.to_string(), column);
    }
    let start = (column - 1)
        .saturating_sub(WINDOW_BEFORE)
        .min(len.saturating_sub(EXCERPT_WINDOW));
    let end = (start + EXCERPT_WINDOW).min(len);
    let mut shown = String::new();
    if start > 0 {
        shown.push('…');
    }
    shown.extend(line.chars().skip(start).take(end - start));
    if end < len {
        shown.push('…');
    }
    (shown, column - start + usize::from(start > 0))
}

/// All problems found in one spec (never empty when returned as an error).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostics(pub Vec<Diagnostic>);

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            writeln!(f, "{d}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostics {}

impl From<Diagnostic> for Diagnostics {
    fn from(d: Diagnostic) -> Self {
        Diagnostics(vec![d])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locates_line_and_column_in_characters() {
        let text = "a = 1\nµ = \"x\"\n";
        // byte offset of `=` on line 2: "a = 1\n" is 6 bytes, "µ" is 2 bytes, then a space.
        let (line, column, excerpt) = locate(text, 6 + 2 + 1);
        assert_eq!((line, column), (2, 3));
        assert_eq!(excerpt, "µ = \"x\"");
    }

    /// Issue 31: an error past column 65 535 panicked in `Display` ("Formatting argument
    /// out of range", the caret's width). Now the line is shown as a window around the
    /// column with the caret under the offending character.
    #[test]
    fn an_error_far_along_one_long_line_displays_a_window() {
        let pad = "#".repeat(70_000);
        let text = format!("x = \"{pad}\" y = \"{}\"\n", "b".repeat(1000));
        let at = text.find(" y").unwrap() + 1;
        let d = Source {
            file: "m.toml",
            text: &text,
        }
        .error(at..at + 1, "y", "bad", "good");
        assert_eq!(d.column, 4 + 1 + 70_000 + 1 + 1 + 1);
        let s = d.to_string();
        let lines: Vec<&str> = s.lines().collect();
        assert!(lines[0].starts_with("error: m.toml:1:70008: `y`: bad"), "{s}");
        let excerpt = lines[2].strip_prefix("1 | ").unwrap();
        let caret = lines[3].strip_prefix("  | ").unwrap();
        // The window: 30 characters before the column, "…" on both sides where the line
        // is cut, and the caret under `y`.
        assert!(excerpt.starts_with('…') && excerpt.ends_with('…'), "{excerpt}");
        assert_eq!(excerpt.chars().count(), EXCERPT_WINDOW + 2, "{excerpt}");
        let caret_col = caret.chars().count();
        assert_eq!(caret.trim_start(), "^");
        assert_eq!(excerpt.chars().nth(caret_col - 1), Some('y'), "{excerpt}\n{caret}");
        assert_eq!(caret_col, 1 + WINDOW_BEFORE + 1);
    }

    /// A short line is shown whole, as before: the caret's indent is the column − 1.
    #[test]
    fn a_short_line_is_shown_whole() {
        let text = "inductance = 0.393\n";
        let d = Source { file: "m.toml", text }.error(13..18, "inductance", "bare", "unit");
        let s = d.to_string();
        assert!(s.contains("1 | inductance = 0.393\n  |              ^\n"), "{s}");
    }

    /// The end of a long line: the window ends at the line's end, no trailing `…`.
    #[test]
    fn an_error_at_the_end_of_a_long_line() {
        let text = format!("x = \"{}\"", "a".repeat(500));
        let at = text.len() - 1;
        let d = Source {
            file: "m.toml",
            text: &text,
        }
        .error(at..at + 1, "x", "bad", "good");
        let s = d.to_string();
        let lines: Vec<&str> = s.lines().collect();
        let excerpt = lines[2].strip_prefix("1 | ").unwrap();
        assert!(excerpt.starts_with('…') && excerpt.ends_with("a\""), "{excerpt}");
        assert_eq!(excerpt.chars().count(), EXCERPT_WINDOW + 1);
        let caret = lines[3].strip_prefix("  | ").unwrap();
        assert_eq!(excerpt.chars().nth(caret.chars().count() - 1), Some('"'));
    }

    #[test]
    fn display_names_file_position_key_and_acceptance() {
        let src = Source {
            file: "m.toml",
            text: "x = 1\n",
        };
        let d = src.error(4..5, "x", "bare number", "a quantity such as \"1 mH\"");
        let s = d.to_string();
        assert!(s.starts_with("error: m.toml:1:5: `x`: bare number"), "{s}");
        assert!(s.contains("accepted: a quantity such as \"1 mH\""), "{s}");
    }
}
