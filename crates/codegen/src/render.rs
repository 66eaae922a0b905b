//! Renders the constants of a design through minijinja templates (strict undefined).
//!
//! The built-in templates are the files in `templates/`, embedded at compile
//! time; `motorgen --templates DIR` supplies the same names from another
//! directory. Rendering does no file I/O: callers pass template sources in.

use minijinja::syntax::SyntaxConfig;
use minijinja::value::{Serde, Value};
use minijinja::{Environment, UndefinedBehavior, context};
use serde::Serialize;

use crate::Design;
use crate::constants::{Constant, Group, constants};
use crate::escape::{Target, escape, markdown_code};

/// Output formats and their template file names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Output {
    /// Rust module of `const` items.
    Rust,
    /// C header.
    C,
    /// Markdown summary.
    Markdown,
    /// DBC description of the CAN interface (only for a design on a board, whose
    /// `can` constants group it renders; not in [`Output::ALL`]).
    Dbc,
}

impl Output {
    /// All outputs.
    pub const ALL: [Output; 3] = [Output::Rust, Output::C, Output::Markdown];

    /// Template file name in `templates/`.
    pub fn template(self) -> &'static str {
        match self {
            Output::Rust => "motor.rs.j2",
            Output::C => "motor.h.j2",
            Output::Markdown => "motor.md.j2",
            Output::Dbc => "motor.dbc.j2",
        }
    }

    /// Generated file name for a motor stem.
    pub fn file_name(self, stem: &str) -> String {
        match self {
            Output::Rust => format!("{}.rs", stem.replace('-', "_")),
            Output::C => format!("{}.h", stem.replace('-', "_")),
            Output::Markdown => format!("{stem}.md"),
            Output::Dbc => format!("{stem}.dbc"),
        }
    }

    /// The built-in template source.
    pub fn builtin(self) -> &'static str {
        match self {
            Output::Rust => include_str!("../../../templates/motor.rs.j2"),
            Output::C => include_str!("../../../templates/motor.h.j2"),
            Output::Markdown => include_str!("../../../templates/motor.md.j2"),
            Output::Dbc => include_str!("../../../templates/motor.dbc.j2"),
        }
    }
}

/// rustfmt's default line width, which the Rust output is laid out for.
pub const RUST_MAX_WIDTH: usize = 100;
/// rustfmt's default `short_array_element_width_threshold`.
const SHORT_ARRAY_ELEMENT_WIDTH: usize = 10;

/// `pub const NAME: TYPE = EXPR;` at `indent`, laid out as rustfmt (default config) does:
/// one line if it fits; a long array broken into rustfmt's mixed layout; otherwise the
/// expression moved to the next line.
pub fn rust_const(k: &Constant, indent: usize) -> String {
    let pad = " ".repeat(indent);
    let head = format!("{pad}pub const {}: {} = ", k.name, k.value.rust_type);
    let expr = &k.value.rust_expr;
    if head.chars().count() + expr.chars().count() < RUST_MAX_WIDTH {
        return format!("{head}{expr};");
    }
    if let Some(inner) = expr.strip_prefix('[').and_then(|e| e.strip_suffix(']')) {
        let items: Vec<&str> = inner.split(", ").collect();
        let inner_pad = " ".repeat(indent + 4);
        // rustfmt lays an array out one item per line when any item is wider than
        // `short_array_element_width_threshold` (10).
        if items.iter().any(|i| i.chars().count() > SHORT_ARRAY_ELEMENT_WIDTH) {
            let body: String = items.iter().map(|i| format!("{inner_pad}{i},\n")).collect();
            return format!("{head}[\n{body}{pad}];");
        }
        let mut out = format!("{head}[\n");
        let mut line = inner_pad.clone();
        for (i, item) in items.iter().enumerate() {
            let piece = format!("{item},");
            let sep = if line.len() > inner_pad.len() { " " } else { "" };
            if line.len() + sep.len() + piece.len() >= RUST_MAX_WIDTH {
                out.push_str(&line);
                out.push('\n');
                line = format!("{inner_pad}{piece}");
            } else {
                line.push_str(sep);
                line.push_str(&piece);
            }
            if i + 1 == items.len() {
                out.push_str(&line);
                out.push('\n');
            }
        }
        out.push_str(&format!("{pad}];"));
        return out;
    }
    format!("{}\n{pad}    {expr};", head.trim_end())
}

/// Why rendering failed.
#[derive(Debug)]
pub struct RenderError {
    /// Template file name.
    pub template: String,
    /// Line in the template, if known.
    pub line: Option<usize>,
    /// The message.
    pub message: String,
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.line {
            Some(l) => write!(f, "error: template {}:{l}: {}", self.template, self.message),
            None => write!(f, "error: template {}: {}", self.template, self.message),
        }
    }
}

impl std::error::Error for RenderError {}

fn render_error(e: &minijinja::Error, fallback: &str) -> RenderError {
    let mut message = e.kind().to_string();
    if let Some(d) = e.detail() {
        message = format!("{message}: {d}");
    }
    RenderError {
        template: e.name().unwrap_or(fallback).to_string(),
        line: e.line(),
        message,
    }
}

/// The C identifier prefix of a motor: its spec file's stem in upper case with every
/// character other than a letter or digit replaced by `_` (`motors/fischer-ti085.toml`
/// → `FISCHER_TI085`), `MOTOR_` in front if it would start with a digit. The C header
/// prefixes its include guard and every name with it, so the headers of two motors can
/// be included in one translation unit.
pub fn c_prefix(spec_file: &str) -> String {
    let stem = std::path::Path::new(spec_file)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let id: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect();
    match id.chars().next() {
        None => "MOTOR".into(),
        Some(c) if c.is_ascii_digit() => format!("MOTOR_{id}"),
        Some(_) => id,
    }
}

/// `s` as the text of a DBC string literal: printable ASCII only (DBC files are read
/// as single-byte text), `"` and `\\` replaced by `'` and `/`, anything else by `?`.
pub fn dbc_string(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '"' => '\'',
            '\\' => '/',
            ' '..='~' => c,
            _ => '?',
        })
        .collect()
}

/// Renders `source` (named `name` for messages) for the design `d`.
pub fn render_with(d: &Design, name: &str, source: &str) -> Result<String, RenderError> {
    let mut env = Environment::new();
    env.set_undefined_behavior(UndefinedBehavior::Strict);
    let syntax = SyntaxConfig::builder()
        .keep_trailing_newline(true)
        .build()
        .map_err(|e| render_error(&e, name))?;
    env.set_syntax(syntax);
    // Generated code is marked safe; every other interpolated value is spec-derived text
    // and goes through `escape` for the template's target (issue 18).
    env.add_filter("rust_const", |k: Serde<Constant>, indent: usize| {
        Value::from_safe_string(rust_const(&k, indent))
    });
    env.add_filter("md_code", |s: String| Value::from_safe_string(markdown_code(&s)));
    env.add_filter("dbc_string", |s: String| Value::from_safe_string(dbc_string(&s)));
    let target = Target::of_template(name);
    env.set_formatter(move |out, _state, value| {
        let text = value.to_string();
        let shown = if value.is_safe() { text } else { escape(&text, target) };
        out.write_str(&shown).map_err(minijinja::Error::from)
    });
    env.add_template(name, source).map_err(|e| render_error(&e, name))?;
    let groups: Vec<Group> = constants(d);
    let tmpl = env.get_template(name).map_err(|e| render_error(&e, name))?;
    tmpl.render(context! {
        spec_file => d.spec_file.clone(),
        name => d.name.clone(),
        c_prefix => c_prefix(&d.spec_file),
        can => Value::from(Serde(crate::constants::can::dbc_values(&groups))),
        groups => Value::from(Serde(&groups)),
        design => Value::from(Serde(d)),
    })
    .map_err(|e| render_error(&e, name))
}

/// The commented starting spec written by `motorgen new <stem>`.
pub fn new_spec(stem: &str) -> Result<String, RenderError> {
    let name = "new-motor.toml.j2";
    let mut env = Environment::new();
    env.set_undefined_behavior(UndefinedBehavior::Strict);
    env.add_template(name, include_str!("../../../templates/new-motor.toml.j2"))
        .map_err(|e| render_error(&e, name))?;
    let tmpl = env.get_template(name).map_err(|e| render_error(&e, name))?;
    tmpl.render(context! { stem => stem })
        .map(|s| s + "\n")
        .map_err(|e| render_error(&e, name))
}

/// Renders one output with the built-in template.
pub fn render(d: &Design, out: Output) -> Result<String, RenderError> {
    render_with(d, out.template(), out.builtin())
}

#[cfg(test)]
mod tests {
    use super::c_prefix;

    #[test]
    fn c_prefixes_are_identifiers() {
        assert_eq!(c_prefix("motors/fischer-ti085.toml"), "FISCHER_TI085");
        assert_eq!(c_prefix("chalmers-hev50.toml"), "CHALMERS_HEV50");
        assert_eq!(c_prefix("/x/142umd.toml"), "MOTOR_142UMD");
        assert_eq!(c_prefix("my motor (v2).toml"), "MY_MOTOR__V2_");
        assert_eq!(c_prefix(""), "MOTOR");
    }
}
