//! The names an expression may use: one allow-list of functions and built-in constants, which
//! the check of every expression ([`refused_name`]), its error messages and the documentation
//! (`experiments/problems/README.md`, kept equal by a test) share.
//!
//! exmex knows more than these: `log` (which it reads as ln, where many engineers read log10),
//! and `log2 cbrt round ceil trunc fract asinh acosh atanh` and the constants `π`, `τ`, which
//! are not documented here. A name exmex does not know (`ab(y)`, `cot(1)`) or a number run into
//! a name (`0x10`) gets exmex's internals ("a number/variable cannot be on the right of a
//! closing parenthesis", "0 ops and 2 node"); each is refused here by name, before exmex parses.

use exmex::{FloatOpsFactory, MakeOperators};

/// The functions an expression may call (`min`, `max` and `atan2` take two arguments).
pub const FUNCTIONS: [&str; 19] = [
    "sqrt", "exp", "ln", "log10", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "abs", "signum", "floor", "min",
    "max", "atan2",
];

/// The named constants exmex provides that an expression may use (besides the file's own).
pub const CONSTANTS: [&str; 4] = ["PI", "E", "e", "TAU"];

/// The hint for two operands side by side ("2x", "500 MPa").
pub(super) const PRODUCT: &str = "a product needs `*`, as in 2*x; numbers carry no units";

/// The functions, as listed in messages.
fn functions() -> String {
    FUNCTIONS.join(", ")
}

/// Why `text` is refused for a name it uses, if it is: `log` (ambiguous), a name exmex knows
/// that is not in [`FUNCTIONS`] or [`CONSTANTS`], a call of anything but a function, a name
/// that is neither a function, a constant nor one of `known` (the variables and the file's
/// constants), or a number run into a name. Messages name the character (from 1).
pub(super) fn refused_name(text: &str, known: &[&str]) -> Option<String> {
    let exmex_ops = FloatOpsFactory::<f64>::make();
    let chars: Vec<(usize, char)> = text.char_indices().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i].1;
        if c.is_ascii_digit() || c == '.' {
            let start = i;
            i = number_end(&chars, i);
            if i < chars.len() && is_name_start(chars[i].1) {
                let end = name_end(&chars, i);
                let run: String = chars[start..end].iter().map(|&(_, c)| c).collect();
                return Some(format!(
                    "`{run}` at character {} of {text:?}: a number run into a name ({PRODUCT}; they are decimal, as 16 or 1.6e1)",
                    start + 1
                ));
            }
            continue;
        }
        if !is_name_start(c) {
            i += 1;
            continue;
        }
        let (start, end) = (i, name_end(&chars, i));
        i = end;
        let name: String = chars[start..end].iter().map(|&(_, c)| c).collect();
        let called = chars[end..].iter().find(|&&(_, c)| !c.is_whitespace()).is_some_and(|&(_, c)| c == '(');
        // made only for a message: formatting `text` for every name would make a long
        // expression's check quadratic (200k nested calls: over 120 s)
        let at = || format!("at character {} of {text:?}", start + 1);
        if name == "log" {
            return Some(format!(
                "`log` {} is ambiguous (exmex reads it as the natural logarithm, many readers as log10): write ln or log10",
                at()
            ));
        }
        if FUNCTIONS.contains(&name.as_str()) || (!called && (CONSTANTS.contains(&name.as_str()) || known.contains(&name.as_str()))) {
            continue;
        }
        let what = if exmex_ops.iter().any(|o| o.repr() == name) {
            format!("`{name}` {} is not one of the functions and constants an expression may use", at())
        } else if called && (known.contains(&name.as_str()) || CONSTANTS.contains(&name.as_str())) {
            format!("`{name}` {} is a variable or constant, not a function (a product needs `*`, as in {name}*(...))", at())
        } else if called {
            format!("unknown function `{name}` {}", at())
        } else {
            let known = if known.is_empty() { "none here".to_string() } else { known.join(", ") };
            let after_number =
                chars[..start].iter().rev().find(|&&(_, c)| !c.is_whitespace()).is_some_and(|&(_, c)| c.is_ascii_digit() || c == '.');
            let hint = if after_number { format!("; {PRODUCT}") } else { String::new() };
            return Some(format!("unknown variable `{name}` {} (variables and constants here: {known}{hint})", at()));
        };
        return Some(format!("{what} (functions: {}; constants: {})", functions(), CONSTANTS.join(", ")));
    }
    None
}

/// A name starts with a letter or `_` (exmex's variables: `[a-zA-Z_]`, and `π`, `τ`).
fn is_name_start(c: char) -> bool {
    c.is_alphabetic() || c == '_'
}

/// The index after the name that starts at `i`.
pub(super) fn name_end(chars: &[(usize, char)], mut i: usize) -> usize {
    while i < chars.len() && (chars[i].1.is_alphanumeric() || chars[i].1 == '_') {
        i += 1;
    }
    i
}

/// The index after the number that starts at `i`, as the expression's literal reads it
/// (`12`, `1.5`, `.5`, `1e-12`; an `e` without exponent digits is not part of it).
pub(super) fn number_end(chars: &[(usize, char)], mut i: usize) -> usize {
    let digits = |mut i: usize| {
        while i < chars.len() && chars[i].1.is_ascii_digit() {
            i += 1;
        }
        i
    };
    i = digits(i);
    if i < chars.len() && chars[i].1 == '.' {
        i = digits(i + 1);
    }
    if i < chars.len() && matches!(chars[i].1, 'e' | 'E') {
        let mut j = i + 1;
        if j < chars.len() && matches!(chars[j].1, '+' | '-') {
            j += 1;
        }
        if j < chars.len() && chars[j].1.is_ascii_digit() {
            i = digits(j);
        }
    }
    i
}

#[cfg(test)]
mod tests {
    use super::refused_name;

    #[test]
    fn documented_names_pass_and_others_are_named() {
        for ok in ["sqrt(x) + ln(y) + log10(2)", "1e-12*x", "2.5E+3", "min(x, y)^2", "PI*e + TAU", "a*(x)", ".5*x"] {
            assert_eq!(refused_name(ok, &["x", "y", "a"]), None, "{ok}");
        }
        for (bad, says) in [
            ("log(10)", "`log` at character 1 of \"log(10)\" is ambiguous"),
            ("1 + log (x)", "`log` at character 5 of \"1 + log (x)\" is ambiguous"),
            ("cbrt(8)", "`cbrt` at character 1 of \"cbrt(8)\" is not one of"),
            ("round(x)", "`round`"),
            ("0.5*ab(y)", "unknown function `ab` at character 5"),
            ("cot(1)", "unknown function `cot`"),
            ("a(x)", "`a` at character 1 of \"a(x)\" is a variable or constant, not a function"),
            ("0x10", "`0x10` at character 1 of \"0x10\": a number run into a name"),
            ("2x", "`2x` at character 1 of \"2x\": a number run into a name (a product needs `*`, as in 2*x; numbers carry no units;"),
            ("1 mm", "unknown variable `mm` at character 3 of \"1 mm\" (variables and constants here: x, y, a; a product needs"),
            ("z + 1", "unknown variable `z`"),
            ("π", "`π`"),
        ] {
            let why = refused_name(bad, &["x", "y", "a"]).unwrap_or_else(|| panic!("{bad} accepted"));
            assert!(why.contains(says), "{bad}: {why}");
        }
    }
}
