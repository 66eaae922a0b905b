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
            let gutter = self.line.to_string().len();
            writeln!(f, "{:gutter$} |", "")?;
            writeln!(f, "{} | {}", self.line, self.excerpt)?;
            writeln!(f, "{:gutter$} | {:>col$}", "", "^", col = self.column)?;
        }
        write!(f, "  accepted: {}", self.accepted)?;
        for n in &self.notes {
            write!(f, "\n  note: {n}")?;
        }
        Ok(())
    }
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
