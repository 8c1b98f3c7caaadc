//! What the eighth battery of hostile inputs found in the parsers, each fixed where every path
//! goes through:
//!
//! * a pair with a third value (`[[point_constraints]]` `u = ["free", 0, 7]`, `at = [0, 0.5,
//!   0]`) was read as its first two: every pair-valued key of a problem file is now read as the
//!   one type that refuses a third value (`Two`), tested here key by key;
//! * a `min`, `max` or `atan2` call inside the second argument of another was refused as
//!   "parentheses mismatch" (exmex's own rewrite of the call syntax): the calls are written
//!   infix before exmex parses, at any nesting, and a wrong number of arguments is named;
//! * a Gmsh file with lines after a section's end that do not start with `$` (gmsh reads it)
//!   was refused, and a byte-order mark was blamed on `$EndMeshFormat`.

use crate::common::{fixture, signorini_in};
use signorini::problems::{FileProblem, Problem};
use std::path::Path;

const SQUARE: &str = "bad_data_square.toml";
const CHI: &str = "chi = \"0.001\"";

fn tmp(name: &str) -> std::path::PathBuf {
    crate::common::scratch(&format!("battery8-parse-{name}"))
}

/// The problem text parsed, or its error's message.
fn parse(text: &str) -> Result<FileProblem, String> {
    FileProblem::parse(Path::new("p.toml"), text).map_err(|e| e.to_string())
}

/// The square problem with a point constraint and an exact solution added, every pair valid.
fn with_every_pair() -> String {
    let base = fixture(SQUARE);
    format!(
        "required_vertices = [[0.5, 0]]\n{base}\n[[point_constraints]]\nat = [0.5, 1]\nu = [\"free\", 0]\n\n[exact]\nu = [\"0\", \"0\"]\ngrad = [[\"0\", \"0\"], [\"0\", \"0\"]]\n"
    )
}

#[test]
fn every_pair_valued_key_refuses_a_third_value() {
    let good = with_every_pair();
    assert!(parse(&good).is_ok(), "{:?}", parse(&good).err());
    let normal = good.replace("normal = \"outward\"", "normal = [0, -1]");
    assert!(parse(&normal).is_ok(), "{:?}", parse(&normal).err());
    for (key, from, to) in [
        ("body_force", "body_force = [\"0\", \"-1\"]", "body_force = [\"0\", \"-1\", \"0\"]"),
        ("traction", "traction = [\"0\", \"0\"]", "traction = [\"0\", \"0\", \"0\"]"),
        ("dirichlet", "dirichlet = [\"0\", \"-0.01\"]", "dirichlet = [\"0\", \"-0.01\", 0]"),
        ("required_vertices", "required_vertices = [[0.5, 0]]", "required_vertices = [[0.5, 0, 0]]"),
        ("at", "at = [0.5, 1]", "at = [0.5, 1, 0]"),
        ("u", "u = [\"free\", 0]", "u = [\"free\", 0, 7]"),
        ("u", "u = [\"0\", \"0\"]", "u = [\"0\", \"0\", \"0\"]"),
        ("grad", "grad = [[\"0\", \"0\"], [\"0\", \"0\"]]", "grad = [[\"0\", \"0\", \"0\"], [\"0\", \"0\"]]"),
        ("grad", "grad = [[\"0\", \"0\"], [\"0\", \"0\"]]", "grad = [[\"0\", \"0\"], [\"0\", \"0\"], [\"0\", \"0\"]]"),
    ] {
        assert!(good.contains(from), "{from}");
        let err = parse(&good.replace(from, to)).map(|_| ()).expect_err(to);
        assert!(err.contains(key) && err.contains("two"), "{to}: {err}");
    }
    let err = parse(&normal.replace("normal = [0, -1]", "normal = [0, -1, 0]")).map(|_| ()).expect_err("normal");
    assert!(err.contains("normal") && err.contains("two"), "{err}");
    // a circle's centre (groups and a curve)
    let circle = fixture("bad_data_gmsh.toml") + "\n[curves.bottom]\ncircle = { centre = [0.5, 2], radius = 2 }\n";
    assert!(parse(&circle).is_ok(), "{:?}", parse(&circle).err());
    let err = parse(&circle.replace("[0.5, 2]", "[0.5, 2, 0]")).map(|_| ()).expect_err("centre");
    assert!(err.contains("centre") && err.contains("two"), "{err}");
}

#[test]
fn a_point_constraint_with_a_third_value_is_refused_by_the_binary() {
    let dir = tmp("pc");
    let text = with_every_pair().replace("u = [\"free\", 0]", "u = [\"free\", 0, 7]");
    std::fs::write(dir.join("p.toml"), text).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("p.toml:") && err.contains("point_constraints") && err.contains("exactly two"), "{err}");
}

/// chi = `expr` of the square problem, evaluated at `x`.
fn chi(expr: &str, x: [f64; 2]) -> f64 {
    let text = fixture(SQUARE).replace(CHI, &format!("chi = \"{expr}\""));
    parse(&text).unwrap_or_else(|e| panic!("{expr}: {e}")).gap(x)
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
    let got = parse(&text).unwrap_or_else(|e| panic!("{e}")).gap([x, y]);
    assert!((got - 0.4 * 0.3).abs() < 1e-16, "{got}");
}

#[test]
fn a_wrong_number_of_arguments_is_named() {
    let dir = tmp("args");
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

/// The estimator line of solving the Gmsh square with `msh` as its mesh, or the error.
fn solve_msh(dir: &Path, msh: &str) -> Result<String, String> {
    std::fs::write(dir.join("v.toml"), fixture("bad_data_gmsh.toml")).unwrap();
    std::fs::write(dir.join("m.msh"), msh).unwrap();
    let (code, out, err) = signorini_in(dir, &["solve", "--problem", "v.toml", "--mesh", "gmsh:m.msh"]);
    match code {
        0 => Ok(out.lines().find(|l| l.starts_with("estimator:")).unwrap_or_default().to_string()),
        _ => Err(err),
    }
}

#[test]
fn lines_between_sections_are_skipped_as_gmsh_skips_them() {
    let dir = tmp("stray");
    let msh = fixture("square.msh");
    let plain = solve_msh(&dir, &msh).unwrap();
    assert!(!plain.is_empty());
    for (at, stray) in [("$EndElements\n", "written by hand\n1 2 3\n"), ("$EndMeshFormat\n", "x\n"), ("$EndNodes\n", "  note\n")] {
        assert!(msh.contains(at));
        let with = msh.replacen(at, &format!("{at}{stray}"), 1);
        assert_eq!(solve_msh(&dir, &with).as_ref(), Ok(&plain), "{stray:?} after {at:?}");
    }
}

#[test]
fn a_byte_order_mark_is_named() {
    let dir = tmp("bom");
    let err = solve_msh(&dir, &format!("\u{feff}{}", fixture("square.msh"))).unwrap_err();
    assert!(err.contains("m.msh") && err.contains("starts with a byte-order mark") && err.contains("save it without one"), "{err}");
    assert!(!err.contains("EndEndMeshFormat"), "{err}");
}
