//! Escapes spec-supplied text for the generated file it lands in, so that no motor
//! name, description, provenance text or path can add code to the generated Rust,
//! C or Markdown (issue 18).
//!
//! One rule for every target: a control character (C0, DEL, C1, U+2028/U+2029) or a
//! bidirectional formatting character (U+061C, U+200E/F, U+202A–U+202E,
//! U+2066–U+2069, the "Trojan Source" class) is written as the visible text
//! `\u{XXXX}`, so a comment always stays on its line and reads in source order.
//! Then, per target:
//! - Rust (`//` and `///` comments): nothing more; a line comment ends only at a newline.
//! - C (`/* */` comments): `*/` → `*\/` (would close the comment), `/*` → `/\*`
//!   (`-Wcomment`), `??` → `?\?` (C11 trigraphs: `??/` is a backslash).
//! - Markdown: `\`, `` ` ``, `|`, `<`, `>`, `[`, `]`, `&` are backslash-escaped (CommonMark
//!   §2.4), so text cannot open a code span, a link, raw HTML, an entity or a table cell.
//!   Generated code shown as code goes through [`markdown_code`].

/// The file a template renders.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// Rust source: text lands in line and doc comments.
    Rust,
    /// C source: text lands in block comments.
    C,
    /// Markdown.
    Markdown,
}

impl Target {
    /// The target for a template name: `*.h[.j2]`/`*.c[.j2]` → C, `*.md[.j2]` → Markdown,
    /// anything else (`*.rs.j2`, user templates) → Rust's rule, which every other
    /// target also applies.
    pub fn of_template(name: &str) -> Target {
        let stem = name.strip_suffix(".j2").unwrap_or(name);
        if stem.ends_with(".h") || stem.ends_with(".c") {
            Target::C
        } else if stem.ends_with(".md") {
            Target::Markdown
        } else {
            Target::Rust
        }
    }
}

/// Whether `c` is shown as `\u{XXXX}` in every target: control and bidi formatting characters.
pub fn is_hidden(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{061C}'
                | '\u{200E}'
                | '\u{200F}'
                | '\u{202A}'..='\u{202E}'
                | '\u{2066}'..='\u{2069}'
                | '\u{2028}'
                | '\u{2029}'
        )
}

/// `text` escaped for `target` (see the module documentation).
pub fn escape(text: &str, target: Target) -> String {
    let mut out = String::with_capacity(text.len());
    let mut prev: Option<char> = None;
    for c in text.chars() {
        if is_hidden(c) {
            out.push_str(&format!("\\u{{{:04X}}}", c as u32));
            prev = None;
            continue;
        }
        match target {
            Target::Rust => out.push(c),
            Target::C => match (prev, c) {
                (Some('*'), '/') => out.push_str("\\/"),
                (Some('/'), '*') => out.push_str("\\*"),
                (Some('?'), '?') => out.push_str("\\?"),
                _ => out.push(c),
            },
            Target::Markdown => {
                if matches!(c, '\\' | '`' | '|' | '<' | '>' | '[' | ']' | '&') {
                    out.push('\\');
                }
                out.push(c);
            }
        }
        prev = Some(c);
    }
    out
}

/// `text` as one Markdown code span: fenced by one backtick more than its longest
/// backtick run (CommonMark §6.1), padded when it starts or ends with a backtick,
/// hidden characters shown as `\u{XXXX}`.
pub fn markdown_code(text: &str) -> String {
    let shown: String = text
        .chars()
        .map(|c| {
            if is_hidden(c) {
                format!("\\u{{{:04X}}}", c as u32)
            } else {
                c.to_string()
            }
        })
        .collect();
    let mut longest = 0;
    let mut run = 0;
    for c in shown.chars() {
        run = if c == '`' { run + 1 } else { 0 };
        longest = longest.max(run);
    }
    let fence = "`".repeat(longest + 1);
    let pad = if shown.starts_with('`') || shown.ends_with('`') {
        " "
    } else {
        ""
    };
    format!("{fence}{pad}{shown}{pad}{fence}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hidden_characters_become_visible_escapes_in_every_target() {
        for t in [Target::Rust, Target::C, Target::Markdown] {
            assert_eq!(escape("a\nb", t), "a\\u{000A}b");
            assert_eq!(escape("a\0b", t), "a\\u{0000}b");
            assert_eq!(escape("\u{202E}x\u{2066}", t), "\\u{202E}x\\u{2066}");
            assert_eq!(escape("a\rb\u{2028}", t), "a\\u{000D}b\\u{2028}");
        }
    }

    #[test]
    fn c_comment_delimiters_and_trigraphs_are_broken() {
        assert_eq!(escape("x */ int y; /*", Target::C), "x *\\/ int y; /\\*");
        assert_eq!(escape("a ??/", Target::C), "a ?\\?/");
        // Rust line comments end only at a newline: `*/` is plain text there.
        assert_eq!(escape("x */ y", Target::Rust), "x */ y");
    }

    #[test]
    fn markdown_structure_characters_are_backslash_escaped() {
        assert_eq!(
            escape("a|b `c` <d> [e](f) &g", Target::Markdown),
            "a\\|b \\`c\\` \\<d\\> \\[e\\](f) \\&g"
        );
        assert_eq!(escape("K_p * 2", Target::Markdown), "K_p * 2");
    }

    #[test]
    fn markdown_code_spans_outlast_their_content() {
        assert_eq!(markdown_code("motors/a.toml"), "`motors/a.toml`");
        assert_eq!(markdown_code("a``b"), "```a``b```");
        assert_eq!(markdown_code("`x"), "`` `x ``");
        assert_eq!(markdown_code("[1, 2]"), "`[1, 2]`");
    }

    #[test]
    fn templates_map_to_their_targets() {
        assert_eq!(Target::of_template("motor.h.j2"), Target::C);
        assert_eq!(Target::of_template("motor.md.j2"), Target::Markdown);
        assert_eq!(Target::of_template("motor.rs.j2"), Target::Rust);
    }
}
