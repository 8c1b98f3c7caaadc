//! Expressions in problem files: precedence and functions read as written or refused (a minus
//! before a power, chains of powers, products without a star, `log`), every listed function is
//! accepted, two-argument calls nest, nesting is bounded, whitespace separates.

use crate::common::{estimator_line, fixture, parse_problem, run_edited, scratch, signorini_in};
use signorini::problems::Problem;
use std::collections::BTreeSet;
use std::path::PathBuf;

const SQUARE: &str = "bad_data_square.toml";

const SOLVE_SQ: &[&str] = &["solve", "--problem", "v.toml", "--mesh", "structured:4"];

const CHI: &str = r#"chi = "0.001""#;

#[test]
fn a_minus_before_a_power_is_refused_not_read_as_the_power_of_the_negation() {
    for chi in ["-0.1^2 + 0.011", "0.02 + -x^2", "0.011 + 2*-(x)^2", "0.011 - -sqrt(x)^2", "0.011 + (-x ^ 3)", "0.01 + 2^-x^2"] {
        let (code, _, err) = run_edited("negated-power", SQUARE, &[(CHI, &format!("chi = {chi:?}"))], SOLVE_SQ);
        assert_eq!(code, 1, "{chi}: {err}");
        for says in ["v.toml:", "key `contact.chi`", "negates the base of a power", "write -(s^2) or 0 - s^2"] {
            assert!(err.contains(says), "{chi}: no {says:?} in\n{err}");
        }
    }
    // the unambiguous forms, a minus that is a subtraction, an exponent's sign, a negative power
    for chi in [
        "-(0.1^2) + 0.011",
        "0 - 0.1^2 + 0.011",
        "(-0.1)^2 - 0.009",
        "0.011 - x^2",
        "1e-3 + x*1E-12",
        "0.001*2^-x",
        "-0.2 + 0.5*abs(y - 0.5)",
    ] {
        let (code, out, err) = run_edited("power-ok", SQUARE, &[(CHI, &format!("chi = {chi:?}"))], SOLVE_SQ);
        assert!(code == 0 && out.contains("certified:") || err.contains("overlap the body"), "{chi}: {err}");
        assert!(!err.contains("negates the base"), "{chi}: {err}");
    }
}

/// `2^3^2` is (2^3)^2 = 64 in exmex, 512 as everyone else reads it: a chain of powers without parentheses is refused, naming the `^`; the
/// parenthesised forms and powers apart pass.
#[test]
fn a_chain_of_powers_is_refused_not_read_left_to_right() {
    for chi in ["0.0001*2^3^2", "0.001 + x^2^2", "0.001 + 2^(x)^2", "0.001 + abs(x)^2 ^ 1"] {
        let (code, _, err) = run_edited("chained-power", SQUARE, &[(CHI, &format!("chi = {chi:?}"))], SOLVE_SQ);
        assert_eq!(code, 1, "{chi}: {err}");
        for says in ["v.toml:", "key `contact.chi`", "follows another without parentheses", "(a^b)^c"] {
            assert!(err.contains(says), "{chi}: no {says:?} in\n{err}");
        }
    }
    for chi in ["0.0001*2^(3^2)", "0.0001*(2^3)^2", "0.001 + x^2*y^2", "0.001 + 2^x - y^2", "0.001 + (x^2)^2"] {
        let (code, out, err) = run_edited("chained-power-ok", SQUARE, &[(CHI, &format!("chi = {chi:?}"))], SOLVE_SQ);
        assert!(code == 0 && out.contains("certified:") || err.contains("overlap the body"), "{chi}: {err}");
        assert!(!err.contains("without parentheses"), "{chi}: {err}");
    }
}

#[test]
fn products_without_a_star_and_units_get_a_hint() {
    for chi in ["0.001x", "1 mm"] {
        let (code, _, err) = run_edited("star", SQUARE, &[(CHI, &format!("chi = {chi:?}"))], SOLVE_SQ);
        assert_eq!(code, 1, "{err}");
        assert!(err.contains("a product needs `*`, as in 2*x; numbers carry no units"), "{chi}: {err}");
    }
}

/// Example 7.2's problem file with `chi` nested `depth` calls of `abs` deep.
fn nested(depth: usize) -> String {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/experiments/problems/ex72.toml")).unwrap();
    let chi = format!("chi = \"{}0{}\"", "abs(".repeat(depth), ")".repeat(depth));
    text.lines().map(|l| if l.starts_with("chi = ") { chi.clone() } else { l.to_string() }).collect::<Vec<_>>().join("\n")
}

#[test]
fn deep_nesting_is_refused_at_once_with_its_reason() {
    let dir = scratch("expressions-nesting");
    std::fs::write(dir.join("ok.toml"), nested(1000)).unwrap();
    std::fs::write(dir.join("deep.toml"), nested(200_000)).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "ok.toml", "--mesh", "structured:2"]);
    assert_eq!(code, 0, "{err}");
    let start = std::time::Instant::now();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "deep.toml", "--mesh", "structured:2"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("nests parentheses deeper than 1000") && err.contains("characters cut"), "{}", &err[..err.len().min(3000)]);
    assert!(err.len() < 4000, "{} bytes", err.len());
    // not a timing test: 200k deep took over 120 s; the refusal reads the text once
    assert!(start.elapsed().as_secs() < 60, "{:?}", start.elapsed());
    std::fs::remove_dir_all(&dir).ok();
}

/// chi = `expr` of the square problem, evaluated at `x`.
fn chi(expr: &str, x: [f64; 2]) -> f64 {
    let text = fixture(SQUARE).replace(CHI, &format!("chi = \"{expr}\""));
    parse_problem(&text).unwrap_or_else(|e| panic!("{expr}: {e}")).gap(x)
}

#[test]
fn two_argument_calls_nest_in_either_argument_with_the_right_value() {
    let (x, y) = (0.3_f64, 0.8_f64);
    for (expr, want) in [
        ("min(0.15, max(0.1, 0.2))", 0.15),
        ("min(1, max(0, y))", 0.8),
        ("min(1, 2*max(0, y))", 1.0),
        ("max(0.05, min(0.1, 0.2)*3)", 0.1 * 3.0),
        ("atan2(0.1, max(0.2, 0.3)*2)", 0.1_f64.atan2(0.6)),
        ("min(0.1, (max(0.2, 0.3)))", 0.1),
        ("min(x, max(y, 0.5))", 0.3),
        ("max(min(0.1, 0.2)*3, 0.05)", 0.1 * 3.0),
        ("min(max(0.1, 0.2), 0.15)", 0.15),
        ("max(x, min(y, max(0.9, min(x, y))))", 0.8),
        ("min(max(x, y), max(min(x, y), 0.5))", 0.5),
        ("atan2(y, atan2(x, 1))", y.atan2(x.atan())),
        ("atan2(atan2(y, 1), x)", y.atan().atan2(x)),
        ("2*min(x, y) - max(x, y)/4", 2.0 * 0.3 - 0.8 / 4.0),
        ("min(x, y)^2 + max(x, 1 - y)", 0.3_f64.powf(2.0) + 0.3),
        ("sqrt(max(x, min(y, 0.5)))", 0.5_f64.sqrt()),
        ("-min(x, -max(y, 0.1))", 0.8),
        ("max(-1, min(1, (x - 0.5)*10))", -1.0),
        ("min(max(min(x, 0.2), 0.1), max(y, min(0.7, 0.75)))", 0.2),
        ("abs(min(x - 1, max(y - 1, -0.5)))", 1.0 - 0.3),
        ("max (x , min ( y , 0.5 ) )", 0.5),
        ("min(1e-3, max(1e-4, x*1e-3))", 0.3 * 1e-3),
        ("max(min(x, y), min(y, x)) + min(max(x, y), max(y, x))", 0.3 + 0.8),
    ] {
        let got = chi(expr, [x, y]);
        assert!((got - want).abs() <= 1e-15 * want.abs().max(1.0), "{expr}: {got} against {want}");
    }
    // a constant defined by a nested call of another, declared after it
    let text = fixture(SQUARE).replace(CHI, "chi = \"s*x\"") + "\n[constants]\ns = \"min(1, max(0, a))\"\na = 0.4\n";
    let got = parse_problem(&text).unwrap_or_else(|e| panic!("{e}")).gap([x, y]);
    assert!((got - 0.4 * 0.3).abs() < 1e-16, "{got}");
}

#[test]
fn a_wrong_number_of_arguments_is_named() {
    let dir = scratch("expressions-args");
    for (expr, says) in [
        ("min(0.1, 0.2, 0.3)", "min takes two arguments, got 3"),
        ("min(0.1)", "min takes two arguments, got 1"),
        ("max(0.1, min(0.2))", "min takes two arguments, got 1"),
        ("atan2()", "atan2 takes two arguments, got 0"),
        ("sqrt(0.1, 0.2)", "sqrt takes one argument, got 2"),
        ("(0.1, 0.2)", "not in a call of min, max or atan2"),
        ("0.1 max 0.2", "`max` at character 5 is a function of two arguments"),
    ] {
        let text = fixture(SQUARE).replace(CHI, &format!("chi = \"{expr}\""));
        std::fs::write(dir.join("p.toml"), text).unwrap();
        let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", "structured:2"]);
        assert_eq!(code, 1, "{expr}: {err}");
        assert!(err.contains("key `contact.chi`") && err.contains(says), "{expr}: {err}");
        assert!(!err.contains("parentheses mismatch") && !err.contains("ops and"), "{expr}: {err}");
    }
}

mod nestings {
    use proptest::prelude::*;

    /// An expression tree over x, y and constants, with min, max, atan2, + and *.
    #[derive(Clone, Debug)]
    enum T {
        X,
        Y,
        C(f64),
        Call(&'static str, Box<T>, Box<T>),
        Op(char, Box<T>, Box<T>),
    }

    impl T {
        fn text(&self) -> String {
            match self {
                T::X => "x".into(),
                T::Y => "y".into(),
                T::C(c) => format!("{c:?}"),
                T::Call(f, a, b) => format!("{f}({}, {})", a.text(), b.text()),
                T::Op(o, a, b) => format!("({} {o} {})", a.text(), b.text()),
            }
        }
        fn value(&self, x: f64, y: f64) -> f64 {
            match self {
                T::X => x,
                T::Y => y,
                T::C(c) => *c,
                T::Call(f, a, b) => {
                    let (a, b) = (a.value(x, y), b.value(x, y));
                    match *f {
                        "min" => a.min(b),
                        "max" => a.max(b),
                        _ => a.atan2(b),
                    }
                }
                T::Op(o, a, b) => match o {
                    '+' => a.value(x, y) + b.value(x, y),
                    _ => a.value(x, y) * b.value(x, y),
                },
            }
        }
    }

    fn tree() -> impl Strategy<Value = T> {
        let leaf = prop_oneof![Just(T::X), Just(T::Y), (0u32..100).prop_map(|k| T::C(k as f64 / 8.0))];
        leaf.prop_recursive(5, 24, 2, |inner| {
            prop_oneof![
                (prop_oneof![Just("min"), Just("max"), Just("atan2")], inner.clone(), inner.clone()).prop_map(|(f, a, b)| T::Call(
                    f,
                    Box::new(a),
                    Box::new(b)
                )),
                (prop_oneof![Just('+'), Just('*')], inner.clone(), inner).prop_map(|(o, a, b)| T::Op(o, Box::new(a), Box::new(b))),
            ]
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 200, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(8), ..ProptestConfig::default() })]
        /// Every nesting of the two-argument functions reads to the value of the tree written.
        #[test]
        fn every_nesting_reads_to_its_value(t in tree(), x in 0.0..1.0f64, y in 0.0..1.0f64) {
            let text = t.text();
            let got = super::chi(&text, [x, y]);
            let want = t.value(x, y);
            prop_assert!(got == want || (got - want).abs() <= 1e-13 * want.abs().max(1.0), "{}: {} against {}", text, got, want);
        }
    }
}

#[test]
fn whitespace_in_an_expression_separates_and_a_parenthesised_comparison_is_named() {
    let dir = scratch("expressions-spaces");
    let base = fixture("bad_data_square.toml");
    let solve = |text: String| {
        std::fs::write(dir.join("v.toml"), text).unwrap();
        signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "structured:4"])
    };
    let (_, plain, _) = solve(base.clone());
    for chi in ["chi = \"0.001\t+ 0*x\"", "chi = \"\"\"0.001\n  + 0*x\"\"\"", "chi = \"0.001 +\\n0*x\"", "chi = \"0.001\\t+ 0*x\""] {
        let (code, out, err) = solve(base.replace("chi = \"0.001\"", chi));
        assert_eq!(code, 0, "{chi:?}: {err}");
        assert_eq!(estimator_line(&out), estimator_line(&plain), "{chi:?}");
    }
    let (code, _, err) = solve(base.replace("contact = \"y < 1e-12\"", "contact = \"(y < 1e-12)\""));
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("key `parts.contact`") && err.contains("the parentheses of \"(y < 1e-12)\" enclose a comparison"), "{err}");
}

const SOLVE: &[&str] = &["solve", "--problem", "v.toml", "--mesh", "structured:4"];

#[test]
fn log_is_refused_as_ambiguous_and_unlisted_names_are_named_with_the_list() {
    for (name, chi, says) in [
        ("log", "0.001*log(10)", "`log` at character 7 of \"0.001*log(10)\" is ambiguous"),
        ("log-space", "0.001*log (10)", "write ln or log10"),
        ("cbrt", "0.001*cbrt(8)", "`cbrt` at character 7 of \"0.001*cbrt(8)\" is not one of the functions"),
        ("round", "0.001*round(x)", "`round` at character 7"),
        ("ab", "0.001 + 0.5*ab(y - 0.5)", "unknown function `ab` at character 13"),
        ("cot", "0.001*cot(1)", "unknown function `cot`"),
        ("hex", "0x10", "`0x10` at character 1 of \"0x10\": a number run into a name"),
        ("pi", "0.001*π", "`π` at character 7"),
    ] {
        let (code, _, err) = run_edited(name, SQUARE, &[(CHI, &format!("chi = {chi:?}"))], SOLVE);
        assert_eq!(code, 1, "{name}: {err}");
        for part in ["v.toml:16:7: key `contact.chi`: ", says] {
            assert!(err.contains(part), "{name}: no {part:?} in\n{err}");
        }
        if name != "hex" && !name.starts_with("log") {
            assert!(err.contains("(functions: sqrt, exp, ln, log10,") && err.contains("constants: PI, E, e, TAU)"), "{name}: {err}");
        }
        assert!(!err.contains("wlog") && !err.contains("ops and"), "{name}: exmex's internals in\n{err}");
    }
    // in a constant and in a predicate too: every expression goes through the one check
    let (code, _, err) = run_edited("log-const", SQUARE, &[(CHI, "chi = \"a\"\n[constants]\na = \"0.001*log(2)\"")], SOLVE);
    assert!(code == 1 && err.contains("key `constants.a`") && err.contains("`log`"), "{err}");
    let (code, _, err) = run_edited("log-pred", SQUARE, &[(r#"contact = "y < 1e-12""#, r#"contact = "y < log(1.00001)""#)], SOLVE);
    assert!(code == 1 && err.contains("key `parts.contact`") && err.contains("`log`"), "{err}");
}

#[test]
fn every_listed_function_is_accepted_and_the_docs_list_exactly_them() {
    use signorini::problems::file::{EXPRESSION_CONSTANTS, EXPRESSION_FUNCTIONS};
    let text = fixture(SQUARE);
    for f in EXPRESSION_FUNCTIONS {
        let call = if ["min", "max", "atan2"].contains(&f) { format!("{f}(0.5, 1)") } else { format!("{f}(0.5)") };
        let chi = format!("chi = \"0.001 + 1e-9*{call}\"");
        let p = signorini::problems::FileProblem::parse(std::path::Path::new("f.toml"), &text.replace(CHI, &chi));
        assert!(p.is_ok(), "{f}: {:?}", p.err().map(|e| e.to_string()));
    }
    // experiments/problems/README.md, paragraph **Expressions**: the unary functions in one
    // code span, then the binary ones and the constants
    let readme = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/README.md")).unwrap();
    let para = &readme[readme.find("**Expressions**").expect("the Expressions paragraph")..];
    let para = &para[..para.find("\n\n").unwrap()];
    let spans: Vec<&str> = para.split('`').skip(1).step_by(2).collect();
    let unary = spans.iter().find(|s| s.starts_with("sqrt ")).expect("the list of functions");
    let mut documented: BTreeSet<&str> = unary.split_whitespace().collect();
    documented.extend(
        spans
            .iter()
            .filter_map(|s| s.strip_suffix(')').and_then(|s| s.split_once('(')).map(|(f, _)| f))
            .filter(|f| f.starts_with(|c: char| c.is_ascii_alphabetic()) && f.chars().all(|c| c.is_ascii_alphanumeric())),
    );
    let listed: BTreeSet<&str> = EXPRESSION_FUNCTIONS.into_iter().collect();
    assert_eq!(documented, listed, "experiments/problems/README.md against crates/model/src/problems/file/names.rs");
    for c in EXPRESSION_CONSTANTS {
        assert!(spans.contains(&c), "constant {c} not documented");
    }
}
