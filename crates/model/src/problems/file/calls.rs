//! Function calls in an expression, checked and the two-argument ones written infix before
//! exmex parses: every expression of a problem file passes through [`infix`].
//!
//! exmex has `min`, `max` and `atan2` as binary operators and reads the call syntax by
//! rewriting `f(a, b)` to `((a)f(b))` as it tokenizes, with one flag for the parenthesis to
//! close: a call inside the second argument of another (`min(1, max(0, s))`) resets it, and
//! exmex refuses the expression as "parentheses mismatch"; it blames a call with three arguments
//! on the parentheses too, and one with one argument on its internals ("1 ops and 1 node").
//! [`infix`] does exmex's rewrite itself, for any nesting, from the matched parentheses: the
//! call's name and `(` become `((`, its comma `)f(`, its `)` `))`, so exmex sees no comma and
//! the expressions exmex's own rewrite parses read into the same operations. A call with
//! another number of arguments, a comma outside a call of these, and parentheses that do not
//! match are named.

/// The functions of two arguments (exmex's binary operators with call syntax).
pub(super) const TWO_ARGUMENTS: [&str; 3] = ["min", "max", "atan2"];

/// The deepest nesting of parentheses an expression may have. exmex's parse of nested calls
/// takes time quadratic in their depth (`abs(abs(...))` 40k deep takes 2 s, 200k deep over
/// 120 s); no expression a problem needs comes near this.
pub(super) const MAX_NESTING: usize = 1000;

/// An open parenthesis: where it is (character index), the function it calls (if a name
/// precedes it) and the character indices of the commas directly inside it.
struct Open {
    at: usize,
    call: Option<(String, usize)>,
    commas: Vec<usize>,
}

/// `text` with every call of a [`TWO_ARGUMENTS`] function written infix (`((a)min(b))`), or
/// why it is refused: a call of such a function with other than two arguments, or of another
/// function with other than one, a two-argument function not called, a comma outside a call of
/// one, parentheses that do not match. Positions are characters from 1.
pub(super) fn infix(text: &str) -> Result<String, String> {
    let c: Vec<(usize, char)> = text.char_indices().collect();
    // what each character becomes
    let mut out: Vec<String> = c.iter().map(|&(_, ch)| ch.to_string()).collect();
    let mut open: Vec<Open> = Vec::new();
    // the last name read and where it starts, while only blanks follow it
    let mut name: Option<(String, usize)> = None;
    let mut i = 0;
    while i < c.len() {
        let ch = c[i].1;
        if ch.is_ascii_digit() || ch == '.' {
            i = super::names::number_end(&c, i).max(i + 1);
            name = None;
            continue;
        }
        if ch.is_alphabetic() || ch == '_' {
            let start = i;
            i = super::names::name_end(&c, i);
            let word: String = c[start..i].iter().map(|&(_, ch)| ch).collect();
            let called = c[i..].iter().find(|(_, c)| !c.is_whitespace()).is_some_and(|&(_, c)| c == '(');
            if TWO_ARGUMENTS.contains(&word.as_str()) && !called {
                return Err(format!("`{word}` at character {} is a function of two arguments: call it as {word}(a, b)", start + 1));
            }
            name = Some((word, start));
            continue;
        }
        match ch {
            '(' if open.len() == MAX_NESTING => {
                return Err(format!(
                    "the `(` at character {} nests parentheses deeper than {MAX_NESTING} (the most an expression may have)",
                    i + 1
                ));
            }
            '(' => open.push(Open { at: i, call: name.take(), commas: Vec::new() }),
            ',' => match open.last_mut() {
                Some(o) => o.commas.push(i),
                None => return Err(format!("the comma at character {} is outside every call ({})", i + 1, SEPARATES)),
            },
            ')' => {
                let o = open.pop().ok_or_else(|| format!("the `)` at character {} closes no `(`", i + 1))?;
                close(&c, &o, i, &mut out)?;
            }
            _ => {}
        }
        if !ch.is_whitespace() {
            name = None;
        }
        i += 1;
    }
    if let Some(o) = open.last() {
        return Err(format!("the `(` at character {} is not closed", o.at + 1));
    }
    Ok(out.concat())
}

/// What a comma separates, for messages.
const SEPARATES: &str = "a comma separates the two arguments of min, max or atan2";

/// Check the group `o` closed at `at` and, for a two-argument call, write it infix in `out`
/// (what each character becomes): the name and the blanks after it dropped, `(` made `((`,
/// the comma `)name(`, `)` made `))`.
fn close(c: &[(usize, char)], o: &Open, at: usize, out: &mut [String]) -> Result<(), String> {
    let bounds: Vec<usize> = std::iter::once(o.at).chain(o.commas.iter().copied()).chain(std::iter::once(at)).collect();
    let blank = |w: &[usize]| c[w[0] + 1..w[1]].iter().all(|(_, c)| c.is_whitespace());
    let arguments = if o.commas.is_empty() && blank(&bounds) { 0 } else { o.commas.len() + 1 };
    match &o.call {
        Some((f, start)) if TWO_ARGUMENTS.contains(&f.as_str()) => {
            if arguments != 2 {
                return Err(format!("{f} takes two arguments, got {arguments} (the call at character {})", start + 1));
            }
            if let Some(k) = bounds.windows(2).position(blank) {
                return Err(format!("argument {} of the {f} at character {} is empty", k + 1, start + 1));
            }
            out[*start..o.at].iter_mut().for_each(String::clear);
            out[o.at] = "((".into();
            out[o.commas[0]] = format!("){f}(");
            out[at] = "))".into();
        }
        Some((f, start)) if super::names::FUNCTIONS.contains(&f.as_str()) && arguments != 1 => {
            return Err(format!("{f} takes one argument, got {arguments} (the call at character {})", start + 1));
        }
        _ if !o.commas.is_empty() => {
            return Err(format!(
                "the comma at character {} is not in a call of min, max or atan2 (nor is a tuple an expression)",
                o.commas[0] + 1
            ));
        }
        _ => {}
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::infix;

    #[test]
    fn calls_are_written_infix_at_any_depth() {
        assert_eq!(infix("min(1, max(0, s))").unwrap(), "((1)min( ((0)max( s))))");
        assert_eq!(infix("atan2 (y, x) + 1e-3").unwrap(), "((y)atan2( x)) + 1e-3");
        assert_eq!(infix("sqrt(x) * 2").unwrap(), "sqrt(x) * 2");
    }

    #[test]
    fn nesting_is_bounded() {
        let deep = |n: usize| format!("{}0{}", "abs(".repeat(n), ")".repeat(n));
        assert!(infix(&deep(super::MAX_NESTING)).is_ok());
        let why = infix(&deep(super::MAX_NESTING + 1)).unwrap_err();
        assert!(why.contains("character 4004 nests parentheses deeper than 1000"), "{why}");
    }

    #[test]
    fn wrong_calls_are_named() {
        for (bad, says) in [
            ("min(0.1, 0.2, 0.3)", "min takes two arguments, got 3"),
            ("min(0.1)", "min takes two arguments, got 1"),
            ("max()", "max takes two arguments, got 0"),
            ("atan2(1, )", "argument 2 of the atan2 at character 1 is empty"),
            ("sqrt(1, 2)", "sqrt takes one argument, got 2"),
            ("(1, 2)", "the comma at character 3 is not in a call"),
            ("1, 2", "the comma at character 2 is outside every call"),
            ("2 min 3", "`min` at character 3 is a function of two arguments"),
            ("min(1, 2))", "the `)` at character 10 closes no `(`"),
            ("min(1, (2)", "the `(` at character 4 is not closed"),
        ] {
            let why = infix(bad).expect_err(bad);
            assert!(why.contains(says), "{bad}: {why}");
        }
    }
}
