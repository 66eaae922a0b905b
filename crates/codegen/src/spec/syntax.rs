//! The first pass's errors: TOML syntax errors and serde shape errors (unknown, missing or
//! mistyped keys), each located and rewritten in the spec's terms.

use crate::diagnostic::{Diagnostics, Source};

pub(super) fn syntax_error(source: Source<'_>, e: &toml::de::Error) -> Diagnostics {
    let span = e.span().unwrap_or(0..0);
    source
        .error(
            span,
            "",
            format!("TOML syntax error: {}", e.message().trim()),
            "valid TOML 1.0 (https://toml.io): `key = value` lines, [section] headers, quoted strings",
        )
        .into()
}

/// A serde error (unknown key, missing key, wrong type, unknown variant) at its key path.
pub(super) fn shape_error(source: Source<'_>, path: &str, e: &toml::de::Error, example: &str) -> Diagnostics {
    let span = e.span().unwrap_or(0..0);
    let message = e.message().trim().to_string();
    // serde_spanned wraps values in a private field; it is not part of the user's key.
    let path = path
        .split('.')
        .filter(|seg| !seg.starts_with("$__serde_spanned") && !seg.is_empty())
        .collect::<Vec<_>>()
        .join(".");
    let (problem, accepted) = if let Some(rest) = message.strip_prefix("unknown field ") {
        let (field, expected) = rest.split_once(", expected ").unwrap_or((rest, "no other keys"));
        let expected = expected.trim_start_matches("one of ");
        match nearest_key(field.trim_matches('`'), expected) {
            Some(near) => (
                format!("unknown key {field}: did you mean `{near}`?"),
                format!("`{near}`, or one of {expected}"),
            ),
            None => (
                format!("unknown key {field} (is it misspelt?)"),
                format!("one of {expected}"),
            ),
        }
    } else if let Some(field) = message.strip_prefix("missing field ") {
        let key = if path.is_empty() {
            field.trim_matches('`').to_string()
        } else {
            format!("{path}.{}", field.trim_matches('`'))
        };
        (
            format!("missing required key `{key}`"),
            format!("the key with a value; see {example} for a complete file"),
        )
    } else if let Some(rest) = message.strip_prefix("unknown variant ") {
        let (value, expected) = rest.split_once(", expected ").unwrap_or((rest, "?"));
        (
            format!("{value} is not a known value"),
            format!("one of {}", expected.trim_start_matches("one of ")),
        )
    } else {
        (message, format!("a value of the type this key takes; see {example}"))
    };
    source.error(span, path, problem, accepted).into()
}

/// The accepted key (from serde's "`a`, `b`, …" list) nearest to `field`, when it is near
/// enough to be a misspelling: at most a third of its characters edited (optimal string
/// alignment distance, so a swapped pair counts once).
fn nearest_key<'a>(field: &str, expected: &'a str) -> Option<&'a str> {
    expected
        .split(", ")
        .map(|k| k.trim_start_matches("or ").trim_matches('`'))
        .filter(|k| !k.is_empty())
        .map(|k| (strsim::osa_distance(field, k), k))
        .min_by_key(|&(d, _)| d)
        .filter(|&(d, _)| d > 0 && 3 * d <= field.chars().count().max(3))
        .map(|(_, k)| k)
}

#[cfg(test)]
mod tests {
    use super::nearest_key;

    /// serde lists the keys as "`a`, `b`, or `c`"; the nearest within a third of the
    /// characters is suggested (hand-counted distances).
    #[test]
    fn suggests_the_nearest_key() {
        let keys = "`phase_resistance`, `inductance`, `d_inductance`, `q_inductance`, or `peak_current`";
        // phase_resistence → phase_resistance: one substitution.
        assert_eq!(nearest_key("phase_resistence", keys), Some("phase_resistance"));
        // inductanse → inductance: one substitution (not d_inductance: three edits).
        assert_eq!(nearest_key("inductanse", keys), Some("inductance"));
        // peak_curent → peak_current: one deletion; the last key is found after "or".
        assert_eq!(nearest_key("peak_curent", keys), Some("peak_current"));
        // Nothing close: no guess.
        assert_eq!(nearest_key("colour", keys), None);
    }
}
