//! Problem files: a contact problem as data (`experiments/problems/NAME.toml`).
//!
//! The material, the loads, the Dirichlet data, the obstacle chi and an exact solution are
//! expressions in `x` and `y`, the boundary parts predicates in `x`, `y` (the built-in meshes) or
//! lists of Gmsh physical groups. Every key is described, with an example, in
//! `experiments/problems/README.md`; `ex71.toml`, `ex72.toml` and `fb.toml` there state the
//! built-in problems (`tests/it/problem_files.rs` solves both and compares).
//!
//! Expressions are parsed once, when the file is read, by the `exmex` crate, chosen because it
//! parses into a flat expression (operands and operators in evaluation order: no tree to walk,
//! no allocation per evaluation), which keeps evaluation at every quadrature point affordable
//! (assembly about 4 times the built-in's, measured in `experiments/problems/README.md`); it
//! differentiates expressions symbolically (an exact solution's gradient need not be written
//! out); it is maintained, small (regex and smallvec) and has `min`, `max`, `abs` and `sqrt`,
//! all that the kinks and roots of the problems here need.
//!
//! Every error names the file, the key, the line and column of its value, and what was
//! expected (for an expression, what exmex said).

use super::{Curve, Part};
use super::{Exact, Material, Problem};
use exmex::prelude::*;
use exmex::{FloatOpsFactory, MatchLiteral, literal_matcher_from_pattern};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

mod calls;
mod names;
mod tables;

pub use names::{CONSTANTS as EXPRESSION_CONSTANTS, FUNCTIONS as EXPRESSION_FUNCTIONS};

/// A problem file as [`crate::base::input::read`] reads it: a regular file of at most
/// [`TEXT_LIMIT`](crate::base::input::TEXT_LIMIT) bytes.
pub const PROBLEM_FILE: crate::base::input::Kind =
    crate::base::input::Kind { what: "the problem file", limit: crate::base::input::Limit::Bytes(crate::base::input::TEXT_LIMIT) };

/// What is wrong with a problem file.
#[derive(Debug, thiserror::Error)]
pub enum ProblemFileError {
    #[error("{file}: {error}")]
    Read { file: PathBuf, error: crate::base::input::InputError },
    /// TOML syntax, an unknown or missing key, a value of the wrong type (toml's message).
    #[error("{file}:{line}:{column}: {}", crate::base::input::excerpt(message))]
    Syntax { file: PathBuf, line: usize, column: usize, message: String },
    #[error("{file}:{line}:{column}: key `{key}`: {}", crate::base::input::excerpt(message))]
    Invalid { file: PathBuf, key: String, line: usize, column: usize, message: String },
}

/// A number or an expression.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged, expecting = "a number or an expression (a string)")]
enum Scalar {
    Number(f64),
    Text(String),
}

/// A vector: two numbers or expressions, or `"exact"` (from the `[exact]` table).
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged, expecting = "an array of two numbers or expressions, or \"exact\"")]
enum VectorToml {
    Pair(Two<Scalar>),
    Word(String),
}

/// The constraint direction: `"outward"` or a fixed direction (two numbers or expressions).
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged, expecting = "\"outward\" or an array of two numbers or expressions")]
enum NormalToml {
    Pair(Two<Scalar>),
    Word(String),
}

/// A boundary part: a predicate in x, y (built-in meshes) or a list of physical groups (Gmsh).
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged, expecting = "a predicate in x, y (a string such as \"y < 1e-12\") or an array of physical-group names")]
enum PartToml {
    Predicate(String),
    Groups(Vec<String>),
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialToml {
    #[serde(rename = "E")]
    e: Option<Spanned<Scalar>>,
    nu: Option<Spanned<Scalar>>,
    model: Option<Spanned<String>>,
    mu: Option<Spanned<Scalar>>,
    lambda: Option<Spanned<Scalar>>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PartsToml {
    contact: Spanned<PartToml>,
    dirichlet: Option<Spanned<PartToml>>,
    neumann: Option<Spanned<PartToml>>,
}

/// Exactly two values: a point, a vector, a row of a gradient. serde reads a longer TOML array
/// into `[T; 2]` by dropping the rest (`[1, 0.5, 0]` would be the point (1, 0.5), an exact
/// solution with three components would use two); this type refuses it, for every pair of a problem file.
#[derive(Clone, Debug)]
struct Two<T>([T; 2]);

impl<T> std::ops::Deref for Two<T> {
    type Target = [T; 2];
    fn deref(&self) -> &[T; 2] {
        &self.0
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Two<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> serde::de::Visitor<'de> for Visit<T> {
            type Value = Two<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an array of exactly two values")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Two<T>, A::Error> {
                use serde::de::Error;
                let a = seq.next_element()?.ok_or_else(|| A::Error::invalid_length(0, &self))?;
                let b = seq.next_element()?.ok_or_else(|| A::Error::invalid_length(1, &self))?;
                let mut n = 2;
                while seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
                    n += 1;
                }
                if n != 2 {
                    return Err(A::Error::invalid_length(n, &self));
                }
                Ok(Two([a, b]))
            }
        }
        d.deserialize_seq(Visit(std::marker::PhantomData))
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CircleToml {
    centre: Two<f64>,
    radius: f64,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CurveToml {
    circle: CircleToml,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ContactToml {
    chi: Spanned<Scalar>,
    normal: Spanned<NormalToml>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ExactToml {
    u: Spanned<Two<Scalar>>,
    grad: Option<Spanned<Two<Two<Scalar>>>>,
}

/// `[[point_constraints]]`: components prescribed at one point.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PointToml {
    at: Spanned<Two<Scalar>>,
    u: Spanned<Two<Scalar>>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileToml {
    description: Option<String>,
    body_force: Option<Spanned<VectorToml>>,
    traction: Option<Spanned<VectorToml>>,
    dirichlet: Option<Spanned<VectorToml>>,
    required_vertices: Option<Spanned<Vec<Two<Scalar>>>>,
    load_breaks: Option<Spanned<Vec<Scalar>>>,
    #[serde(default)]
    point_constraints: Vec<PointToml>,
    #[serde(default)]
    constants: BTreeMap<String, Spanned<Scalar>>,
    material: MaterialToml,
    parts: PartsToml,
    #[serde(default)]
    curves: BTreeMap<String, Spanned<CurveToml>>,
    contact: ContactToml,
    exact: Option<ExactToml>,
}

// Numbers in expressions: exmex's default literals have no exponent ("1e-12" would read as
// 1, Euler's e, -12); these do (and `e` alone is still Euler's number).
literal_matcher_from_pattern!(Number, r"^([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]+)?");

/// The 1-based character position of a unary minus whose operand (a number, a name, a call
/// or a parenthesised group) is the base of `^`, if `text` has one: exmex binds that minus
/// before the power, so `-s^2` is `(-s)^2`, where a reader (and every other calculator) reads
/// `-(s^2)`. Refused rather than read against the reader.
fn negated_power(text: &str) -> Option<usize> {
    let c: Vec<char> = text.chars().collect();
    let skip = |mut j: usize| {
        while j < c.len() && c[j].is_whitespace() {
            j += 1;
        }
        j
    };
    let group = |mut j: usize| {
        // j at '(': past its matching ')'
        let mut depth = 0usize;
        while j < c.len() {
            match c[j] {
                '(' => depth += 1,
                ')' => {
                    depth -= 1;
                    if depth == 0 {
                        return j + 1;
                    }
                }
                _ => {}
            }
            j += 1;
        }
        j
    };
    let mut prev: Option<char> = None;
    for i in 0..c.len() {
        if c[i].is_whitespace() {
            continue;
        }
        if c[i] == '-' && prev.is_none_or(|p| "(,+-*/^".contains(p)) {
            let mut j = skip(i + 1);
            if j < c.len() && (c[j].is_ascii_digit() || c[j] == '.') {
                while j < c.len() && (c[j].is_ascii_digit() || c[j] == '.') {
                    j += 1;
                }
                if j < c.len() && (c[j] == 'e' || c[j] == 'E') {
                    j += 1;
                    if j < c.len() && (c[j] == '+' || c[j] == '-') {
                        j += 1;
                    }
                    while j < c.len() && c[j].is_ascii_digit() {
                        j += 1;
                    }
                }
            } else if j < c.len() && (c[j].is_alphabetic() || c[j] == '_') {
                while j < c.len() && (c[j].is_alphanumeric() || c[j] == '_') {
                    j += 1;
                }
                let k = skip(j);
                if k < c.len() && c[k] == '(' {
                    j = group(k);
                }
            } else if j < c.len() && c[j] == '(' {
                j = group(j);
            } else {
                prev = Some(c[i]);
                continue;
            }
            let k = skip(j);
            if k < c.len() && c[k] == '^' {
                return Some(i + 1);
            }
        }
        prev = Some(c[i]);
    }
    None
}

/// The column (1-based) of the second `^` of a chain `a^b^c` without parentheses, if `text`
/// has one: exmex groups it `(a^b)^c` (2^3^2 is 64), where the usual reading is `a^(b^c)`
/// (512). Refused rather than read either way silently. A chain is two `^` at one depth of
/// parentheses with no other binary operator (`+ - * /`, a comma) between them.
fn chained_power(text: &str) -> Option<usize> {
    // per depth: whether a `^` was seen with no other operator after it
    let mut open_power: Vec<bool> = vec![false];
    for (i, ch) in text.chars().enumerate() {
        match ch {
            '(' => open_power.push(false),
            ')' if open_power.len() > 1 => {
                open_power.pop();
            }
            '^' => {
                let last = open_power.last_mut().expect("depth 0 is never popped");
                if *last {
                    return Some(i + 1);
                }
                *last = true;
            }
            '+' | '-' | '*' | '/' | ',' => *open_power.last_mut().expect("depth 0 is never popped") = false,
            _ => {}
        }
    }
    None
}

/// Why `text` is refused as a power exmex reads against the reader ([`negated_power`],
/// [`chained_power`]), if it is.
fn power_trap(text: &str) -> Option<String> {
    if let Some(column) = negated_power(text) {
        return Some(format!(
            "the `-` at character {column} negates the base of a power, which exmex applies before `^` (-s^2 reads (-s)^2 = s^2, not -(s^2)): write -(s^2) or 0 - s^2 for minus the power, (-s)^2 for the power of the negation"
        ));
    }
    chained_power(text).map(|column| {
        format!(
            "the `^` at character {column} follows another without parentheses; exmex reads a^b^c as (a^b)^c (2^3^2 = 64), the usual reading is a^(b^c) (512): write the parentheses you mean"
        )
    })
}

/// A parsed expression: exmex's default float operators, numbers with exponents.
type Flat = FlatEx<f64, FloatOpsFactory<f64>, Number>;

/// `text` parsed by exmex, its calls checked and the two-argument ones written infix first
/// ([`calls::infix`]): every expression of a problem file is parsed here. `Err`: why not.
fn parse_flat(text: &str) -> Result<Flat, String> {
    let infix = calls::infix(text).map_err(|why| format!("cannot parse {text:?}: {why}"))?;
    Flat::parse(&infix).map_err(|e| {
        // exmex's message for two operands side by side ("x y", "(x)(y)")
        let hint = if e.msg().contains("ops and") { format!(" ({})", names::PRODUCT) } else { String::new() };
        format!("cannot parse {text:?}: {}{hint}", e.msg())
    })
}

/// What an expression's variable stands for.
#[derive(Clone, Copy, Debug)]
enum Slot {
    X,
    Y,
    /// The outward unit normal (traction only).
    Nx,
    Ny,
    Const(f64),
}

/// At most this many distinct variables and constants in one expression.
const MAX_VARS: usize = 16;

/// A scalar expression in x, y (and nx, ny in a traction), parsed once.
#[derive(Clone, Debug)]
enum Expr {
    Const(f64),
    Flat {
        /// Boxed: exmex keeps up to 32 nodes inline (about 20 kB).
        flat: Box<Flat>,
        /// What each of the expression's variables (exmex orders them alphabetically) stands for.
        slots: Vec<Slot>,
    },
}

impl Expr {
    #[inline]
    fn eval(&self, x: [f64; 2], n: [f64; 2]) -> f64 {
        match self {
            Expr::Const(c) => *c,
            Expr::Flat { flat, slots } => {
                let mut v = [0.0; MAX_VARS];
                for (v, s) in v.iter_mut().zip(slots) {
                    *v = match *s {
                        Slot::X => x[0],
                        Slot::Y => x[1],
                        Slot::Nx => n[0],
                        Slot::Ny => n[1],
                        Slot::Const(c) => c,
                    };
                }
                // the number of values is the expression's number of variables (checked when parsed)
                flat.eval(&v[..slots.len()]).unwrap_or(f64::NAN)
            }
        }
    }

    #[inline]
    fn at(&self, x: [f64; 2]) -> f64 {
        self.eval(x, [0.0, 0.0])
    }

    /// The partial derivative in x (`var` = "x") or y, symbolically; `Err` with exmex's message
    /// where an operator has no derivative (`abs`, `min`, `max`, ...).
    fn derivative(&self, var: &str) -> Result<Expr, String> {
        match self {
            Expr::Const(_) => Ok(Expr::Const(0.0)),
            Expr::Flat { flat, slots } => match flat.var_names().iter().position(|v| v == var) {
                None => Ok(Expr::Const(0.0)),
                Some(i) => {
                    let d = flat.clone().partial(i).map_err(|e| e.msg().to_string())?;
                    Ok(Expr::Flat { flat: Box::new(d), slots: slots.clone() })
                }
            },
        }
    }
}

/// A comparison `lhs op rhs`.
#[derive(Clone, Debug)]
struct Inequality {
    lhs: Expr,
    op: Cmp,
    rhs: Expr,
}

#[derive(Clone, Copy, Debug)]
enum Cmp {
    Lt,
    Le,
    Gt,
    Ge,
}

/// A predicate in x, y: comparisons joined by `&&` and `||` (`&&` binding tighter).
#[derive(Clone, Debug)]
struct Predicate {
    /// Disjunction of conjunctions.
    any: Vec<Vec<Inequality>>,
}

impl Predicate {
    fn holds(&self, x: [f64; 2]) -> bool {
        self.any.iter().any(|all| {
            all.iter().all(|c| {
                let (a, b) = (c.lhs.at(x), c.rhs.at(x));
                match c.op {
                    Cmp::Lt => a < b,
                    Cmp::Le => a <= b,
                    Cmp::Gt => a > b,
                    Cmp::Ge => a >= b,
                }
            })
        })
    }
}

/// Dirichlet data or a traction: two expressions, or the exact solution's (u, or sigma(u) n).
#[derive(Clone, Debug)]
enum VectorData {
    Exprs([Expr; 2]),
    FromExact,
}

/// How the constraint direction (`Problem::contact_normal`) is found.
#[derive(Clone, Debug)]
enum Normal {
    /// A declared direction (normalised), possibly varying with x, y.
    Fixed([Expr; 2]),
    /// The body's outward normal on each contact edge: its `[curves]` circle's, or the straight
    /// edge's (`Mesh::outward_at`).
    Outward,
}

/// The exact solution of a problem file: u and its gradient (given or differentiated by exmex).
#[derive(Clone, Debug)]
struct ExactExprs {
    u: [Expr; 2],
    /// `grad[i][j] = d u_i / d x_j`.
    grad: [[Expr; 2]; 2],
    /// Whether the file writes `exact.grad` (otherwise exmex differentiated `exact.u`).
    grad_written: bool,
}

impl Exact for ExactExprs {
    fn grad_written(&self) -> bool {
        self.grad_written
    }
    fn u(&self, x: [f64; 2]) -> [f64; 2] {
        [self.u[0].at(x), self.u[1].at(x)]
    }
    fn grad(&self, x: [f64; 2]) -> [[f64; 2]; 2] {
        let g = &self.grad;
        [[g[0][0].at(x), g[0][1].at(x)], [g[1][0].at(x), g[1][1].at(x)]]
    }
}

/// A contact problem read from a problem file.
#[derive(Clone, Debug)]
pub struct FileProblem {
    name: String,
    /// The file it was read from.
    file: PathBuf,
    description: String,
    material: Material,
    /// Predicates on boundary-edge midpoints (built-in meshes): contact, then Dirichlet; the
    /// rest is Neumann.
    contact_predicate: Option<Predicate>,
    dirichlet_predicate: Option<Predicate>,
    /// Physical group -> part (Gmsh meshes).
    groups: BTreeMap<String, Part>,
    /// The `[parts]` entries as written, for error messages.
    declared_parts: Vec<String>,
    curves: BTreeMap<String, Curve>,
    body_force: [Expr; 2],
    traction: VectorData,
    dirichlet: VectorData,
    /// The components `dirichlet` prescribes (a `"free"` one is not).
    dirichlet_components: [bool; 2],
    point_constraints: Vec<super::PointConstraint>,
    chi: Expr,
    normal: Normal,
    required_vertices: Vec<[f64; 2]>,
    load_breaks: Vec<f64>,
    exact: Option<ExactExprs>,
    /// The first datum evaluated to something other than a finite number.
    watch: super::DatumWatch,
}

/// Line and column (from 1) of byte `offset` in `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// Reads a problem file's values, naming file, key and position in its errors.
struct Reader<'a> {
    file: &'a Path,
    text: &'a str,
    constants: BTreeMap<String, f64>,
}

impl Reader<'_> {
    fn error(&self, key: &str, span: std::ops::Range<usize>, message: impl Into<String>) -> ProblemFileError {
        let (line, column) = line_column(self.text, span.start);
        ProblemFileError::Invalid { file: self.file.to_path_buf(), key: key.to_string(), line, column, message: message.into() }
    }

    /// Parse `text` as an expression whose variables may be `vars` (and the constants).
    fn expr(&self, key: &str, span: std::ops::Range<usize>, value: &Scalar, vars: &[&str]) -> Result<Expr, ProblemFileError> {
        let written = match value {
            Scalar::Number(v) => return Ok(Expr::Const(*v)),
            Scalar::Text(t) => t,
        };
        // a tab or a line break (a `"""` string over several lines) separates as a space does;
        // exmex knows only the space
        let spaced: String = written.chars().map(|c| if c.is_whitespace() { ' ' } else { c }).collect();
        let text = spaced.as_str();
        if let Some(why) = power_trap(text) {
            return Err(self.error(key, span, format!("{text:?}: {why}")));
        }
        let mut known: Vec<&str> = vars.to_vec();
        known.extend(self.constants.keys().map(String::as_str));
        if let Some(why) = names::refused_name(text, &known) {
            return Err(self.error(key, span, why));
        }
        let flat = parse_flat(text).map_err(|why| self.error(key, span.clone(), why))?;
        let names = flat.var_names();
        if names.len() > MAX_VARS {
            return Err(self.error(
                key,
                span,
                format!("{text:?} has {} variables and constants, at most {MAX_VARS} are allowed", names.len()),
            ));
        }
        let mut slots = Vec::with_capacity(names.len());
        for name in names {
            let slot = match name.as_str() {
                "x" if vars.contains(&"x") => Slot::X,
                "y" if vars.contains(&"y") => Slot::Y,
                "nx" if vars.contains(&"nx") => Slot::Nx,
                "ny" if vars.contains(&"ny") => Slot::Ny,
                c => match self.constants.get(c) {
                    Some(&v) => Slot::Const(v),
                    None => {
                        let mut known: Vec<&str> = vars.to_vec();
                        known.extend(self.constants.keys().map(String::as_str));
                        let known = if known.is_empty() { "none here".to_string() } else { known.join(", ") };
                        return Err(self.error(
                            key,
                            span,
                            format!("unknown variable `{c}` in {text:?} (variables and constants here: {known})"),
                        ));
                    }
                },
            };
            slots.push(slot);
        }
        if slots.iter().all(|s| matches!(s, Slot::Const(_))) {
            let e = Expr::Flat { flat: Box::new(flat), slots };
            return Ok(Expr::Const(e.at([0.0, 0.0])));
        }
        Ok(Expr::Flat { flat: Box::new(flat), slots })
    }

    /// A number: a number or an expression of the constants alone.
    fn number(&self, key: &str, value: &Spanned<Scalar>) -> Result<f64, ProblemFileError> {
        match self.expr(key, value.span(), value.get_ref(), &[])? {
            Expr::Const(v) if v.is_finite() => Ok(v),
            Expr::Const(v) => Err(self.error(key, value.span(), format!("a finite number, got {v}"))),
            Expr::Flat { .. } => unreachable!("an expression without variables is a constant"),
        }
    }

    fn pair(&self, key: &str, span: std::ops::Range<usize>, value: &[Scalar; 2], vars: &[&str]) -> Result<[Expr; 2], ProblemFileError> {
        Ok([self.expr(&format!("{key}[0]"), span.clone(), &value[0], vars)?, self.expr(&format!("{key}[1]"), span, &value[1], vars)?])
    }

    fn vector(
        &self,
        key: &str,
        value: Option<&Spanned<VectorToml>>,
        vars: &[&str],
        has_exact: bool,
    ) -> Result<VectorData, ProblemFileError> {
        let Some(value) = value else { return Ok(VectorData::Exprs([Expr::Const(0.0), Expr::Const(0.0)])) };
        match value.get_ref() {
            VectorToml::Pair(p) => Ok(VectorData::Exprs(self.pair(key, value.span(), p, vars)?)),
            VectorToml::Word(w) if w == "exact" && has_exact => Ok(VectorData::FromExact),
            VectorToml::Word(w) if w == "exact" => Err(self.error(key, value.span(), "\"exact\" needs an [exact] table")),
            VectorToml::Word(w) => {
                Err(self.error(key, value.span(), format!("an array of two numbers or expressions, or \"exact\"; got {w:?}")))
            }
        }
    }

    /// `lhs op rhs [&& ...] [|| ...]`.
    fn predicate(&self, key: &str, span: std::ops::Range<usize>, text: &str) -> Result<Predicate, ProblemFileError> {
        let mut any = Vec::new();
        for alternative in text.split("||") {
            let mut all = Vec::new();
            for comparison in alternative.split("&&") {
                let (at, op, len) = ["<=", ">=", "<", ">"]
                    .iter()
                    .filter_map(|o| comparison.find(o).map(|i| (i, *o, o.len())))
                    .min_by_key(|&(i, _, _)| i)
                    .ok_or_else(|| {
                        self.error(
                            key,
                            span.clone(),
                            format!("a comparison (<, <=, >, >=) in {comparison:?} (a predicate is comparisons joined by && and ||)"),
                        )
                    })?;
                let op = match op {
                    "<=" => Cmp::Le,
                    ">=" => Cmp::Ge,
                    "<" => Cmp::Lt,
                    _ => Cmp::Gt,
                };
                let (lhs, rhs) = (&comparison[..at], &comparison[at + len..]);
                if [lhs, rhs].iter().any(|side| side.matches('(').count() != side.matches(')').count()) {
                    return Err(self.error(
                        key,
                        span.clone(),
                        format!(
                            "the parentheses of {:?} enclose a comparison: parentheses group terms of an expression, not comparisons (a predicate is comparisons joined by && and ||, && binding tighter, with no grouping around them): write `x > 1` rather than `(x > 1)`",
                            comparison.trim()
                        ),
                    ));
                }
                if ["<", ">", "="].iter().any(|o| rhs.contains(o)) {
                    return Err(self.error(key, span.clone(), format!("one comparison in {comparison:?} (join several with && or ||)")));
                }
                let side = |s: &str| self.expr(key, span.clone(), &Scalar::Text(s.trim().to_string()), &["x", "y"]);
                all.push(Inequality { lhs: side(lhs)?, op, rhs: side(rhs)? });
            }
            any.push(all);
        }
        Ok(Predicate { any })
    }

    /// Resolve `[constants]`: numbers, or expressions of other constants (in any order).
    fn resolve_constants(&mut self, table: &BTreeMap<String, Spanned<Scalar>>) -> Result<(), ProblemFileError> {
        for name in table.keys() {
            if matches!(name.as_str(), "x" | "y" | "nx" | "ny") {
                return Err(self.error(&format!("constants.{name}"), table[name].span(), "a name other than x, y, nx, ny (the variables)"));
            }
            if parse_flat(name).map(|f| f.var_names().len() != 1).unwrap_or(true) {
                return Err(self.error(
                    &format!("constants.{name}"),
                    table[name].span(),
                    format!("a name usable in an expression (letters, digits, '_'; not an operator or a built-in constant such as e, E, PI); got {name:?}"),
                ));
            }
        }
        let mut pending: Vec<&String> = table.keys().collect();
        while !pending.is_empty() {
            let before = pending.len();
            let mut next = Vec::new();
            for name in pending {
                let value = &table[name];
                let ready = match value.get_ref() {
                    Scalar::Number(_) => true,
                    Scalar::Text(t) => parse_flat(t).map(|f| f.var_names().iter().all(|v| self.constants.contains_key(v))).unwrap_or(true),
                };
                if ready {
                    let v = self.number(&format!("constants.{name}"), value)?;
                    self.constants.insert(name.clone(), v);
                } else {
                    next.push(name);
                }
            }
            if next.len() == before {
                // an unknown name or a cycle: report the first with its unknown variable
                let name = next[0];
                let key = format!("constants.{name}");
                let mut known = self.constants.clone();
                for n in &next {
                    known.insert((*n).clone(), 0.0);
                }
                let Scalar::Text(t) = table[name].get_ref() else { unreachable!("numbers are always ready") };
                let unknown = parse_flat(t).map(|f| f.var_names().iter().find(|v| !known.contains_key(*v)).cloned()).unwrap_or_default();
                let message = match unknown {
                    Some(v) => format!("unknown variable `{v}` in {t:?} (a constant is a number or an expression of other constants)"),
                    None => format!(
                        "{t:?}: the constants {} refer to each other in a cycle",
                        next.iter().map(|n| n.as_str()).collect::<Vec<_>>().join(", ")
                    ),
                };
                return Err(self.error(&key, table[name].span(), message));
            }
            pending = next;
        }
        Ok(())
    }
}

impl FileProblem {
    /// Read and check a problem file. The problem's name is the file stem.
    pub fn load(path: &Path) -> Result<Self, ProblemFileError> {
        Self::load_with(path, &BTreeMap::new())
    }

    /// Read a problem file with some of its `[constants]` given other values (a study's run
    /// `constants` table: the same problem at another load). Constants defined from an
    /// overridden one follow it; naming a constant the file does not declare is an error.
    pub fn load_with(path: &Path, overrides: &BTreeMap<String, f64>) -> Result<Self, ProblemFileError> {
        let text = crate::base::input::read_text(path, PROBLEM_FILE)
            .map_err(|error| ProblemFileError::Read { file: path.to_path_buf(), error })?;
        Self::parse_with(path, &text, overrides)
    }

    /// Parse a problem file's text; `path` names it in errors and gives the problem's name.
    pub fn parse(path: &Path, text: &str) -> Result<Self, ProblemFileError> {
        Self::parse_with(path, text, &BTreeMap::new())
    }

    /// [`FileProblem::parse`] with constants overridden (see [`FileProblem::load_with`]).
    pub fn parse_with(path: &Path, text: &str, overrides: &BTreeMap<String, f64>) -> Result<Self, ProblemFileError> {
        let mut raw: FileToml = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map_or((1, 1), |s| line_column(text, s.start));
            let (file, message) = (path.to_path_buf(), crate::base::toml_text::plain(e.message().trim_end()));
            match crate::base::toml_text::key_of(&e).or_else(|| crate::base::toml_text::duplicate_key(&e, text)) {
                Some(key) => ProblemFileError::Invalid { file, key, line, column, message },
                None => ProblemFileError::Syntax { file, line, column, message },
            }
        })?;
        let mut r = Reader { file: path, text, constants: BTreeMap::new() };
        r.override_constants(&mut raw, overrides)?;
        r.resolve_constants(&raw.constants)?;
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let material = r.material(&raw.material)?;
        let parts = r.parts(&raw.parts)?;
        let curves = r.curves(&raw.curves, &parts)?;

        // data
        let xy = ["x", "y"];
        let has_exact = raw.exact.is_some();
        let body_force = match (r.vector("body_force", raw.body_force.as_ref(), &xy, true)?, &raw.body_force) {
            (VectorData::Exprs(e), _) => e,
            (VectorData::FromExact, value) => {
                return Err(r.error(
                    "body_force",
                    value.as_ref().map_or(0..0, |v| v.span()),
                    "two expressions: f = -div sigma(u) is not derived from [exact], write it out",
                ));
            }
        };
        let traction = r.vector("traction", raw.traction.as_ref(), &["x", "y", "nx", "ny"], has_exact)?;
        let (dirichlet, dirichlet_components) = r.dirichlet(raw.dirichlet.as_ref(), has_exact)?;
        let point_constraints = r.point_constraints(&raw.point_constraints)?;
        let chi = r.expr("contact.chi", raw.contact.chi.span(), raw.contact.chi.get_ref(), &xy)?;
        let normal_value = &raw.contact.normal;
        let normal = r.normal(normal_value)?;
        let (required_vertices, load_breaks) = r.lists(&raw)?;
        let exact = r.exact(&raw.exact)?;
        let tables::Parts { groups, contact_predicate, dirichlet_predicate, declared_parts, .. } = parts;
        Ok(FileProblem {
            name,
            file: path.to_path_buf(),
            description: raw.description.unwrap_or_default(),
            material,
            contact_predicate,
            dirichlet_predicate,
            groups,
            declared_parts,
            curves,
            body_force,
            traction,
            dirichlet,
            dirichlet_components,
            point_constraints,
            chi,
            normal,
            required_vertices,
            load_breaks,
            exact,
            watch: Default::default(),
        })
    }
}

impl FileProblem {
    /// The two components of a vector datum, each checked under the key `key[i]`.
    #[inline]
    fn checked(&self, key: &str, x: [f64; 2], v: [f64; 2]) -> [f64; 2] {
        if !(v[0].is_finite() && v[1].is_finite()) {
            for (i, c) in v.iter().enumerate() {
                self.watch.check(&self.name, &format!("{key}[{i}]"), x, *c);
            }
        }
        v
    }
}

impl Problem for FileProblem {
    fn name(&self) -> &str {
        &self.name
    }
    fn description(&self) -> &str {
        &self.description
    }
    fn source(&self) -> Option<&Path> {
        Some(&self.file)
    }
    fn material(&self) -> Material {
        self.material
    }
    /// Contact where the contact predicate holds, else Dirichlet where the Dirichlet predicate
    /// holds, else Neumann.
    fn part_of(&self, x: [f64; 2]) -> Part {
        if self.contact_predicate.as_ref().is_some_and(|p| p.holds(x)) {
            Part::Contact
        } else if self.dirichlet_predicate.as_ref().is_some_and(|p| p.holds(x)) {
            Part::Dirichlet
        } else {
            Part::Neumann
        }
    }
    fn part_comparisons(&self, x: [f64; 2]) -> Vec<f64> {
        let predicates = [&self.contact_predicate, &self.dirichlet_predicate];
        predicates.into_iter().flatten().flat_map(|p| p.any.iter().flatten()).map(|c| c.lhs.at(x) - c.rhs.at(x)).collect()
    }
    fn part_of_group(&self, group: &str) -> Option<Part> {
        self.groups.get(group).copied()
    }
    fn groups(&self) -> Vec<String> {
        self.groups.keys().cloned().collect()
    }
    fn declared_parts(&self) -> Vec<String> {
        self.declared_parts.clone()
    }
    fn curve_of_group(&self, group: &str) -> Option<Curve> {
        self.curves.get(group).copied()
    }
    fn body_force(&self, x: [f64; 2]) -> [f64; 2] {
        self.checked("body_force", x, [self.body_force[0].at(x), self.body_force[1].at(x)])
    }
    fn traction(&self, x: [f64; 2], n: [f64; 2]) -> [f64; 2] {
        let t = match (&self.traction, &self.exact) {
            (VectorData::Exprs(t), _) => [t[0].eval(x, n), t[1].eval(x, n)],
            (VectorData::FromExact, Some(e)) => self.material.traction(e.grad(x), n),
            (VectorData::FromExact, None) => unreachable!("\"exact\" is refused without [exact]"),
        };
        self.checked("traction", x, t)
    }
    fn dirichlet(&self, x: [f64; 2]) -> [f64; 2] {
        let u = match (&self.dirichlet, &self.exact) {
            (VectorData::Exprs(u), _) => [u[0].at(x), u[1].at(x)],
            (VectorData::FromExact, Some(e)) => e.u(x),
            (VectorData::FromExact, None) => unreachable!("\"exact\" is refused without [exact]"),
        };
        self.checked("dirichlet", x, u)
    }
    fn dirichlet_components(&self) -> [bool; 2] {
        self.dirichlet_components
    }
    fn point_constraints(&self) -> Vec<super::PointConstraint> {
        self.point_constraints.clone()
    }
    fn bad_datum(&self) -> Option<super::BadDatum> {
        self.watch.first()
    }
    fn contact_normal(&self, x: [f64; 2], outward: [f64; 2]) -> [f64; 2] {
        match &self.normal {
            Normal::Fixed(n) => {
                let (a, b) = (n[0].at(x), n[1].at(x));
                let l = a.hypot(b);
                // a normal of length 0 (or not a number) has no direction: name its length
                if !(l > 0.0 && l.is_finite()) {
                    self.watch.note(super::BadDatum { problem: self.name.clone(), key: "contact.normal (its length)".into(), x, value: l });
                }
                [a / l, b / l]
            }
            Normal::Outward => outward,
        }
    }
    fn gap(&self, x: [f64; 2]) -> f64 {
        self.watch.check(&self.name, "contact.chi", x, self.chi.at(x))
    }
    /// The declared ones, then the point constraints' points.
    fn required_vertices(&self) -> Vec<[f64; 2]> {
        self.required_vertices.iter().copied().chain(self.point_constraints.iter().map(|c| c.at)).collect()
    }
    fn load_breaks(&self) -> Vec<f64> {
        self.load_breaks.clone()
    }
    fn required_vertices_declared(&self) -> Vec<(String, [f64; 2])> {
        let key = |k: String| format!("{}: key `{k}`", self.file.display());
        let declared = self.required_vertices.iter().enumerate().map(|(i, &p)| (key(format!("required_vertices[{i}]")), p));
        let points = self.point_constraints.iter().enumerate().map(|(i, c)| (key(format!("point_constraints[{i}].at")), c.at));
        declared.chain(points).collect()
    }
    fn load_breaks_declared(&self) -> Vec<(String, f64)> {
        self.load_breaks.iter().enumerate().map(|(i, &c)| (format!("{}: key `load_breaks[{i}]`", self.file.display()), c)).collect()
    }
    fn exact(&self) -> Option<&dyn Exact> {
        self.exact.as_ref().map(|e| e as &dyn Exact)
    }
}
