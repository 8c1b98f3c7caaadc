//! TOML errors as the files' readers show them (manifests, problem files): the key the error is
//! about, and toml's message in the words of the file rather than of Rust, with numbers short.

/// The key a TOML error is about (`body_force`, `exact.u`), where toml knows it: its error
/// shows the key path only when displayed without the file's text (`in `a.b``), so that is how
/// it is read. None for syntax errors, which are not about a key.
pub fn key_of(e: &toml::de::Error) -> Option<String> {
    let mut bare = e.clone();
    bare.set_input(None);
    bare.to_string().lines().find_map(|l| l.strip_prefix("in `")?.strip_suffix('`').map(str::to_string))
}

/// The key of a "duplicate key" error, read from `text` at the error's span (toml names it
/// neither in its message nor in its key path): the line's text before `=` (a key, dotted or
/// quoted) after the header of its table, if any (`material.mu`), or the whole line (a table
/// header such as `[material]`).
pub fn duplicate_key(e: &toml::de::Error, text: &str) -> Option<String> {
    if !e.message().starts_with("duplicate key") {
        return None;
    }
    let start = e.span()?.start;
    let line = text.get(start..)?.lines().next()?;
    let key = line.split_once('=').map_or(line, |(k, _)| k).trim();
    if key.is_empty() {
        return None;
    }
    // a key in a table is named with the table's header above it (`material.mu`)
    let table = text[..start].lines().rev().map(str::trim).find(|l| l.starts_with('[')).map(|h| h.trim_matches(['[', ']']).trim());
    Some(match table {
        Some(t) if !key.starts_with('[') && !t.is_empty() => format!("{t}.{key}"),
        _ => key.to_string(),
    })
}

/// toml's (serde's) message with Rust's type names in TOML's words and every number of more
/// than 17 digits (toml prints `levels = 1e300` as 301 digits) in scientific notation.
pub fn plain(message: &str) -> String {
    let worded = [
        ("expected usize", "expected a non-negative integer"),
        ("expected u64", "expected a non-negative integer"),
        ("expected f64", "expected a number"),
        ("expected i64", "expected an integer"),
        ("expected a sequence", "expected an array"),
        ("expected a map", "expected a table"),
        ("expected struct Tolerance", "expected a table { rel = .., floor = .. }"),
    ]
    .iter()
    .fold(message.to_string(), |m, (rust, toml)| m.replace(rust, toml));
    short_numbers(&worded)
}

/// `text` with each run of more than 17 digits (with its fraction, if any) written as `{:e}`.
fn short_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(start) = rest.find(|c: char| c.is_ascii_digit()) {
        out.push_str(&rest[..start]);
        let tail = &rest[start..];
        let end = tail.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(tail.len());
        let number = &tail[..end];
        let digits = number.chars().filter(char::is_ascii_digit).count();
        match number.parse::<f64>() {
            Ok(v) if digits > 17 => out.push_str(&format!("{v:e}")),
            _ => out.push_str(number),
        }
        rest = &tail[end..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_numbers_are_short_and_others_untouched() {
        let long = format!("invalid type: floating point `1{}.0`, expected usize", "0".repeat(300));
        assert_eq!(plain(&long), "invalid type: floating point `1e300`, expected a non-negative integer");
        assert_eq!(plain("line 12, column 3: 0.45 and 12345678901234567"), "line 12, column 3: 0.45 and 12345678901234567");
    }

    #[test]
    fn the_key_of_a_type_error_is_found() {
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct T {
            a: A,
        }
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct A {
            b: [f64; 2],
        }
        let e = toml::from_str::<T>("[a]\nb = \"text\"\n").unwrap_err();
        assert_eq!(key_of(&e).as_deref(), Some("a.b"));
        let e = toml::from_str::<T>("[a\n").unwrap_err();
        assert_eq!(key_of(&e), None);
    }
}
