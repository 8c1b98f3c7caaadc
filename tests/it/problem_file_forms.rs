//! Property test of the problem-file parser: a valid problem file written in another form (its
//! keys and tables in another order, tables as `[name]` headers or dotted keys, other spacing,
//! numbers as integers, floats or expression strings, expressions in equivalent forms that are
//! exact in floating point: `(e)`, `1*(e)`) is the same problem: the same material, parts,
//! curves, data at every sample point (bit for bit), required vertices and load breaks.

use proptest::prelude::*;
use signorini::problems::{FileProblem, Problem};
use std::path::{Path, PathBuf};
use toml::Value;

/// The random choices a form is written with, consumed in order.
struct Choices {
    v: Vec<u32>,
    i: usize,
}

impl Choices {
    fn pick(&mut self, n: usize) -> usize {
        let c = self.v[self.i % self.v.len()];
        self.i += 1;
        c as usize % n
    }
    fn ws(&mut self) -> &'static str {
        ["", " ", "  ", "\t"][self.pick(4)]
    }
    fn permute<T>(&mut self, mut items: Vec<T>) -> Vec<T> {
        for k in (1..items.len()).rev() {
            let j = self.pick(k + 1);
            items.swap(k, j);
        }
        items
    }
}

/// An expression in an equivalent form, exact in floating point.
fn expression(s: &str, c: &mut Choices) -> String {
    match c.pick(4) {
        0 => s.to_string(),
        1 => format!("({s})"),
        2 => format!("1*({s})"),
        _ => format!(" {s} "),
    }
}

fn string(s: &str) -> String {
    Value::String(s.to_string()).to_string()
}

/// A value written anew; `expr`: its strings are expressions and its numbers may be written as
/// expression strings (a number or expression key), else strings are kept as they are (names,
/// predicates, the words "exact", "outward" and "free").
fn value(v: &Value, expr: bool, c: &mut Choices) -> String {
    match v {
        // "free" (a component left free) is a word, not an expression
        Value::String(s) if expr && s != "free" => string(&expression(s, c)),
        Value::String(s) => string(s),
        Value::Integer(i) => match c.pick(3) {
            0 => i.to_string(),
            1 => format!("{i}.0"),
            _ if expr => string(&i.to_string()),
            _ => i.to_string(),
        },
        Value::Float(f) => match c.pick(3) {
            0 => format!("{f:?}"),
            1 => format!("{f:e}"),
            _ if expr => string(&format!("{f:?}")),
            _ => format!("{f:?}"),
        },
        Value::Array(a) => {
            let items: Vec<String> = a.iter().map(|x| value(x, expr, c)).collect();
            let sep = format!(",{}", c.ws());
            format!("[{}{}{}]", c.ws(), items.join(&sep), c.ws())
        }
        Value::Table(t) => {
            let keys = c.permute(t.keys().cloned().collect());
            let items: Vec<String> = keys.iter().map(|k| format!("{k}{}={}{}", c.ws(), c.ws(), value(&t[k], expr, c))).collect();
            format!("{{ {} }}", items.join(", "))
        }
        other => other.to_string(),
    }
}

/// Whether the value `v` of `table.key` is a number or expression (or an array of them): not a
/// name, a predicate or a word (`"exact"`, `"outward"`).
fn is_expression(table: &str, key: &str, v: &Value) -> bool {
    if v.is_str() && ["traction", "dirichlet", "normal"].contains(&key) {
        return false;
    }
    match table {
        "" => ["body_force", "traction", "dirichlet", "required_vertices", "load_breaks"].contains(&key),
        "constants" | "exact" => true,
        "material" => key != "model",
        "contact" => true,
        _ => false,
    }
}

/// The problem file `text` written in another form.
fn reform(text: &str, c: &mut Choices) -> String {
    let doc: toml::Table = text.parse().unwrap();
    let (mut top, mut tables) = (Vec::new(), Vec::new());
    for k in c.permute(doc.keys().cloned().collect()) {
        match &doc[&k] {
            Value::Table(t) => {
                let keys = c.permute(t.keys().cloned().collect::<Vec<_>>());
                let lines: Vec<(String, String)> =
                    keys.iter().map(|key| (key.clone(), value(&t[key], is_expression(&k, key, &t[key]), c))).collect();
                // a table as a [header] or as dotted keys at the top
                if c.pick(3) == 0 {
                    top.extend(lines.into_iter().map(|(key, v)| format!("{k}.{key}{}={}{v}", c.ws(), c.ws())));
                } else {
                    let body: Vec<String> = lines.into_iter().map(|(key, v)| format!("{}{key}{}={}{v}", c.ws(), c.ws(), c.ws())).collect();
                    tables.push(format!("[{k}]\n{}\n", body.join("\n")));
                }
            }
            v => {
                let v = value(v, is_expression("", &k, v), c);
                top.push(format!("{k}{}={}{v}", c.ws(), c.ws()));
            }
        }
    }
    let blank = if c.pick(2) == 0 { "\n" } else { "\n\n" };
    format!("{}\n{blank}{}", top.join("\n"), tables.join(blank))
}

/// Bit for bit, or both NaN.
fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

fn same_vec(a: [f64; 2], b: [f64; 2]) -> bool {
    same(a[0], b[0]) && same(a[1], b[1])
}

/// What differs between the two problems, if anything.
fn difference(a: &dyn Problem, b: &dyn Problem) -> Option<String> {
    if a.material() != b.material() || a.groups() != b.groups() || a.required_vertices() != b.required_vertices() {
        return Some("material, groups or required vertices".into());
    }
    if a.load_breaks() != b.load_breaks() || a.description() != b.description() || a.name() != b.name() {
        return Some("load breaks, description or name".into());
    }
    for g in a.groups() {
        if a.part_of_group(&g) != b.part_of_group(&g) || a.curve_of_group(&g) != b.curve_of_group(&g) {
            return Some(format!("group {g}"));
        }
    }
    for i in 0..9 {
        for j in 0..9 {
            let x = [-1.0 + 0.27 * i as f64, -0.2 + 0.17 * j as f64];
            let n = [0.6, 0.8];
            let checks = [
                ("body_force", same_vec(a.body_force(x), b.body_force(x))),
                ("traction", same_vec(a.traction(x, n), b.traction(x, n))),
                ("dirichlet", same_vec(a.dirichlet(x), b.dirichlet(x))),
                ("normal", same_vec(a.contact_normal(x, n), b.contact_normal(x, n))),
                ("gap", same(a.gap(x), b.gap(x))),
                ("part", a.part_of(x) == b.part_of(x)),
            ];
            if let Some((what, _)) = checks.iter().find(|(_, ok)| !ok) {
                return Some(format!("{what} at {x:?}"));
            }
            match (a.exact(), b.exact()) {
                (None, None) => {}
                (Some(ea), Some(eb)) => {
                    let (ga, gb) = (ea.grad(x), eb.grad(x));
                    if !same_vec(ea.u(x), eb.u(x)) || !same_vec(ga[0], gb[0]) || !same_vec(ga[1], gb[1]) {
                        return Some(format!("exact at {x:?}"));
                    }
                }
                _ => return Some("exact".into()),
            }
        }
    }
    (a.bad_datum() != b.bad_datum()).then(|| "bad datum".into())
}

fn sources() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<PathBuf> = std::fs::read_dir(root.join("experiments/problems"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    files.push(root.join("tests/fixtures/bad_data_square.toml"));
    files.push(root.join("tests/fixtures/gmsh_renumbered/quarter_disc.toml"));
    files
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(38), ..ProptestConfig::default() })]

    #[test]
    fn a_problem_file_in_another_form_is_the_same_problem(file in prop::sample::select(sources()), v in prop::collection::vec(any::<u32>(), 64..256)) {
        let text = std::fs::read_to_string(&file).unwrap();
        let want = FileProblem::parse(&file, &text).unwrap();
        let form = reform(&text, &mut Choices { v, i: 0 });
        let got = FileProblem::parse(&file, &form).map_err(|e| TestCaseError::fail(format!("{e}\n--- the form:\n{form}")))?;
        if let Some(d) = difference(&want, &got) {
            return Err(TestCaseError::fail(format!("{}: {d} differs\n--- the form:\n{form}", file.display())));
        }
    }
}
