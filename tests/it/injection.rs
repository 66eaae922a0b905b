//! Issue 18: no spec string can add code to the generated Rust, C or Markdown.
//!
//! A corpus of hostile strings (newline, `*/`, `*/ #include`, `//`, backslash, NUL,
//! bidi controls, Markdown structure, C trigraphs, a very long string) is put into
//! every free-text key that reaches a template (`name`, `description`,
//! `[inverter] part`) and into the spec file path. Each rendering must have exactly
//! the structure of the clean one:
//! - Rust: parsed with `syn`, the items with their doc comments removed are token for
//!   token those of the clean rendering (no extra item, no changed value);
//! - C: `cc -std=c11 -pedantic -Werror` accepts the header, and its preprocessed text
//!   (comments removed) is identical to the clean header's: no declaration was added;
//! - Markdown: the same lines, headings and table cells as the clean rendering.

use std::path::Path;
use std::process::Command;

use codegen::render::{Output, render};

const STEM: &str = "chalmers-hev50";

/// The hostile corpus.
fn corpus() -> Vec<String> {
    vec![
        "x\npub const INJECTED: u8 = 1;".into(),
        "x */ int injected; /*".into(),
        "*/ #include <stdio.h>\nint injected;\n/*".into(),
        "// line comment \\".into(),
        "back\\slash\\".into(),
        "nul\0byte".into(),
        "\u{202E}txt.exe\u{2066}x\u{2069} \u{200F}".into(),
        "\r\n# heading\n```\ncode\n```\n".into(),
        "a | b | c <script>alert(1)</script> [x](javascript:y) &amp; *em* _u_".into(),
        "??/\nint injected;".into(),
        "`tick`` ``` ".into(),
        "\u{2028}pub fn injected() {}\u{2029}".into(),
        "*/".repeat(5_000),
    ]
}

/// `s` as a TOML basic string (TOML 1.0 §String: `\\`, `\"` and `\uXXXX` escapes).
fn toml_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '\\' => out.push_str("\\\\"),
            '"' => out.push_str("\\\""),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The seed spec with `hostile` in every free-text key that reaches a template.
fn hostile_spec(clean: &str, hostile: &str) -> String {
    let value = toml_string(hostile);
    let mut seen = [false; 3];
    let text: Vec<String> = clean
        .lines()
        .map(|line| {
            for (i, key) in ["name = ", "description = ", "part = "].iter().enumerate() {
                if line.starts_with(key) {
                    seen[i] = true;
                    return format!("{key}{value}");
                }
            }
            line.to_string()
        })
        .collect();
    assert_eq!(seen, [true; 3], "the seed spec lost one of the keys under test");
    text.join("\n") + "\n"
}

/// Items of a Rust file with their doc attributes removed, as tokens.
fn items_without_docs(source: &str) -> String {
    fn strip(items: &mut [syn::Item]) {
        for item in items {
            match item {
                syn::Item::Mod(m) => {
                    m.attrs.retain(|a| !a.path().is_ident("doc"));
                    if let Some((_, inner)) = &mut m.content {
                        strip(inner);
                    }
                }
                syn::Item::Const(c) => c.attrs.retain(|a| !a.path().is_ident("doc")),
                _ => {}
            }
        }
    }
    let mut file = syn::parse_file(source).expect("generated Rust parses");
    file.attrs.retain(|a| !a.path().is_ident("doc"));
    strip(&mut file.items);
    quote::quote!(#file).to_string()
}

/// The header compiled strictly, then preprocessed without comments.
fn c_tokens(dir: &Path, name: &str, header: &str) -> String {
    let path = dir.join(format!("{name}.h"));
    std::fs::write(&path, header).unwrap();
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let check = Command::new(&cc)
        .args(["-std=c11", "-pedantic", "-Wall", "-Werror", "-fsyntax-only", "-x", "c"])
        .arg(&path)
        .output()
        .expect("a C compiler (cc) must be installed");
    assert!(
        check.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&check.stderr)
    );
    let pre = Command::new(&cc)
        .args(["-std=c11", "-E", "-P", "-x", "c"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(pre.status.success());
    String::from_utf8(pre.stdout).unwrap()
}

/// The preprocessed header with each declared name's prefix `from` replaced by `to`
/// (declarations are `static const <type> <name>…`; a name without the prefix is kept,
/// so the comparison then fails).
fn with_prefix(tokens: &str, from: &str, to: &str) -> String {
    let mut out = String::new();
    for line in tokens.lines() {
        let mut words: Vec<&str> = line.splitn(4, ' ').collect();
        let renamed;
        if line.starts_with("static const ")
            && words.len() == 4
            && let Some(rest) = words[3].strip_prefix(from)
        {
            renamed = format!("{to}{rest}");
            words[3] = &renamed;
        }
        out.push_str(&words.join(" "));
        out.push('\n');
    }
    out
}

/// Per line: whether it is a heading, a fence, a list item, a table row, and its
/// unescaped `|` count outside code spans.
fn markdown_structure(md: &str) -> Vec<(bool, bool, bool, usize)> {
    md.lines()
        .map(|line| {
            let mut pipes = 0;
            let mut escaped = false;
            let mut fence = 0usize;
            let chars: Vec<char> = line.chars().collect();
            let mut i = 0;
            while i < chars.len() {
                let c = chars[i];
                if escaped {
                    escaped = false;
                } else if c == '\\' && fence == 0 {
                    // A backslash escapes only outside a code span (CommonMark §6.1).
                    escaped = true;
                } else if c == '`' {
                    let run = chars[i..].iter().take_while(|&&x| x == '`').count();
                    if fence == 0 {
                        fence = run;
                    } else if fence == run {
                        fence = 0;
                    }
                    i += run;
                    continue;
                } else if c == '|' && fence == 0 {
                    pipes += 1;
                }
                i += 1;
            }
            assert_eq!(fence, 0, "unclosed code span in {line:?}");
            (
                line.starts_with('#'),
                line.trim_start().starts_with("```"),
                line.starts_with("- "),
                pipes,
            )
        })
        .collect()
}

#[test]
fn hostile_spec_strings_add_nothing_to_the_generated_code() {
    let rel = format!("motors/{STEM}.toml");
    let clean_text = std::fs::read_to_string(motor_test_support::repo().join(&rel)).unwrap();
    let clean = codegen::design_source(&rel, &clean_text).unwrap();
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("injection");
    std::fs::create_dir_all(&dir).unwrap();
    let rust = items_without_docs(&render(&clean, Output::Rust).unwrap());
    let c = c_tokens(&dir, "clean", &render(&clean, Output::C).unwrap());
    let md = markdown_structure(&render(&clean, Output::Markdown).unwrap());
    for (i, hostile) in corpus().iter().enumerate() {
        let d = codegen::design_source(hostile, &hostile_spec(&clean_text, hostile))
            .unwrap_or_else(|e| panic!("corpus {i}: refused: {e:?}"));
        let r = render(&d, Output::Rust).unwrap();
        assert_eq!(items_without_docs(&r), rust, "corpus {i}: Rust items changed");
        let h = render(&d, Output::C).unwrap();
        // The C names carry the spec file's stem as an identifier prefix
        // (`codegen::render::c_prefix`): here the hostile path's, mapped back to compare.
        let tokens = with_prefix(
            &c_tokens(&dir, &format!("hostile{i}"), &h),
            &codegen::render::c_prefix(hostile),
            &codegen::render::c_prefix(&rel),
        );
        assert_eq!(tokens, c, "corpus {i}: C declarations changed");
        let m = render(&d, Output::Markdown).unwrap();
        assert_eq!(markdown_structure(&m), md, "corpus {i}: Markdown structure changed");
        // The text is shown, escaped, not dropped: its first visible word appears.
        if let Some(word) = hostile.split(|c: char| !c.is_alphanumeric()).find(|w| w.len() > 2) {
            assert!(
                r.contains(word) && h.contains(word) && m.contains(word),
                "corpus {i}: {word:?} dropped"
            );
        }
    }
}
