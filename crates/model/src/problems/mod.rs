//! The contact problems as data: material, loads, boundary parts, obstacle, exact solution.
//!
//! A problem is data, not branches in the solver: every problem implements [`Problem`] and the
//! solver, estimator and studies only ever call the trait. The built-in problems ([`KNOWN`],
//! module [`builtin`]) are written in Rust; a problem file (`experiments/problems/NAME.toml`,
//! module [`file`](mod@file)) states one as data, with its loads, obstacle and exact solution as
//! expressions in x and y. [`by_name`] takes either.

pub mod builtin;
pub mod file;

pub use builtin::{Ex71, Ex72, Fb, Patch, contact_bottom_dirichlet_top};
pub use file::{FileProblem, ProblemFileError};

mod boundary;
pub use boundary::{Curve, Part};
use std::path::Path;

/// Plane elasticity with Lamé constants: sigma(u) = 2 mu eps(u) + zeta tr(eps(u)) I
/// (paper Section 1; the paper writes zeta for Lamé's lambda).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Material {
    pub mu: f64,
    pub zeta: f64,
}

impl Material {
    /// From Young's modulus and Poisson's ratio (plane strain):
    /// zeta = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)).
    pub fn from_young(e: f64, nu: f64) -> Self {
        Material { mu: e / (2.0 * (1.0 + nu)), zeta: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)) }
    }

    /// From Young's modulus and Poisson's ratio in plane stress (a thin plate, sigma_33 = 0):
    /// the same mu, and zeta = E nu / (1 - nu^2) = 2 mu zeta_3d / (zeta_3d + 2 mu).
    pub fn from_young_plane_stress(e: f64, nu: f64) -> Self {
        Material { mu: e / (2.0 * (1.0 + nu)), zeta: e * nu / (1.0 - nu * nu) }
    }

    /// Stress from a displacement gradient `g[i][j] = d u_i / d x_j`, as (s11, s12, s22).
    #[inline]
    pub fn stress(&self, g: [[f64; 2]; 2]) -> [f64; 3] {
        let tr = g[0][0] + g[1][1];
        let s12 = self.mu * (g[0][1] + g[1][0]);
        [2.0 * self.mu * g[0][0] + self.zeta * tr, s12, 2.0 * self.mu * g[1][1] + self.zeta * tr]
    }

    /// Traction sigma(u) n from a displacement gradient and a unit normal.
    #[inline]
    pub fn traction(&self, g: [[f64; 2]; 2], n: [f64; 2]) -> [f64; 2] {
        let s = self.stress(g);
        [s[0] * n[0] + s[1] * n[1], s[1] * n[0] + s[2] * n[1]]
    }
}

/// An exact solution, where one is known.
pub trait Exact: Send + Sync {
    fn u(&self, x: [f64; 2]) -> [f64; 2];
    /// `grad[i][j] = d u_i / d x_j`.
    fn grad(&self, x: [f64; 2]) -> [[f64; 2]; 2];
    /// Whether the gradient is written by hand (code, or `exact.grad` in a problem file) rather
    /// than differentiated from u symbolically: what a contradiction between the two blames.
    fn grad_written(&self) -> bool {
        true
    }
}

/// A 2D frictionless unilateral contact problem (paper eq. 1.1–1.8).
pub trait Problem: Send + Sync {
    /// Short name used on the command line and in manifests.
    fn name(&self) -> &str;
    fn description(&self) -> &str;
    fn material(&self) -> Material;
    /// The boundary part containing boundary point `x` (an edge midpoint): how the built-in
    /// meshes (`structured:N`, `symmetric:N`) are tagged.
    fn part_of(&self, x: [f64; 2]) -> Part;
    /// lhs - rhs of every comparison in the predicates behind [`Problem::part_of`], at `x`, in a
    /// fixed order: along a line the part can change only where one of them changes sign (how
    /// `Mesh::check_parts_whole` finds a part that ends inside an edge). Empty when the parts are
    /// not written as comparisons (the built-ins).
    fn part_comparisons(&self, _x: [f64; 2]) -> Vec<f64> {
        Vec::new()
    }
    /// The boundary part of the edges in the mesh file's physical group `group` (how Gmsh meshes
    /// are tagged); `None` if the problem does not name that group.
    fn part_of_group(&self, _group: &str) -> Option<Part> {
        None
    }
    /// The physical groups the problem names (in `part_of_group`): a mesh file lacking one of
    /// them is an error.
    fn groups(&self) -> Vec<String> {
        Vec::new()
    }
    /// The curve on which the boundary edges of physical group `group` lie, if they lie on one:
    /// refinement puts new boundary vertices there.
    fn curve_of_group(&self, _group: &str) -> Option<Curve> {
        None
    }
    /// Body force f.
    fn body_force(&self, x: [f64; 2]) -> [f64; 2];
    /// Neumann traction g at `x` on Gamma_N with outward unit normal `n`.
    fn traction(&self, x: [f64; 2], n: [f64; 2]) -> [f64; 2];
    /// Dirichlet value on Gamma_D (of the components [`Problem::dirichlet_components`] names).
    fn dirichlet(&self, x: [f64; 2]) -> [f64; 2];
    /// Which Cartesian components the Dirichlet data prescribe on Gamma_D: both by default. A
    /// component left free carries zero traction there (rollers: `[true, false]` on a side
    /// x = c prescribes u_1 and leaves the shear traction zero).
    fn dirichlet_components(&self) -> [bool; 2] {
        [true, true]
    }
    /// Components prescribed at single mesh vertices (e.g. u_2 = 0 at one point, fixing the
    /// rigid motion that rollers leave free). Each point is also a required vertex; where a
    /// point lies on Gamma_D its prescribed components win over the Dirichlet data.
    fn point_constraints(&self) -> Vec<PointConstraint> {
        Vec::new()
    }
    /// The constraint direction n of u . n <= chi at `x` on Gamma_C, where the body's outward
    /// unit normal is `outward` (on the contact edge in question: its curve's, or the straight
    /// edge's, `Mesh::outward_at`). A declared direction ignores `outward`; `normal =
    /// "outward"` returns it, so every edge gets its own (the nearest circle or square side
    /// could give a flat side another part's normal).
    fn contact_normal(&self, x: [f64; 2], outward: [f64; 2]) -> [f64; 2];
    /// The gap chi: the constraint is u . n <= chi on Gamma_C.
    fn gap(&self, x: [f64; 2]) -> f64;
    /// Points that must be mesh vertices (kinks of chi), so that chi_h interpolates chi well.
    fn required_vertices(&self) -> Vec<[f64; 2]> {
        Vec::new()
    }
    /// Vertical lines x = c across which the body force is not smooth (a root singularity of a
    /// derivative, such as ((x - c)_+)^(1/2)): the load of an element crossing one is integrated
    /// piecewise (`assembly::split_load`), exact to round-off where a Gauss rule on the whole
    /// element would converge only algebraically.
    fn load_breaks(&self) -> Vec<f64> {
        Vec::new()
    }
    /// [`Problem::required_vertices`], each with where the problem declares it, in an error's
    /// words (a problem file's key); by default "a required vertex of problem NAME".
    fn required_vertices_declared(&self) -> Vec<(String, [f64; 2])> {
        self.required_vertices().into_iter().map(|p| (format!("a required vertex of problem {}", self.name()), p)).collect()
    }
    /// [`Problem::load_breaks`], each with where the problem declares it (as
    /// [`Problem::required_vertices_declared`]).
    fn load_breaks_declared(&self) -> Vec<(String, f64)> {
        self.load_breaks().into_iter().map(|c| (format!("a load break of problem {}", self.name()), c)).collect()
    }
    fn exact(&self) -> Option<&dyn Exact> {
        None
    }
    /// The file the problem was read from (for error messages); `None` for a built-in problem.
    fn source(&self) -> Option<&Path> {
        None
    }
    /// How the problem declares its boundary parts, as its source states them (e.g.
    /// `parts.dirichlet = "x < 1e-12"`), for error messages; empty if it states none.
    fn declared_parts(&self) -> Vec<String> {
        Vec::new()
    }
    /// The first datum (in a fixed order: by key, then point) that was not a finite number
    /// where it was evaluated since the problem was made; `None` for problems whose data are
    /// finite by construction (the built-ins). The SOLVE step checks it after assembling and the
    /// estimator after evaluating (`solve::SolveError::Data`).
    fn bad_datum(&self) -> Option<BadDatum> {
        None
    }
}

/// Components of the displacement prescribed at one point (a mesh vertex).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct PointConstraint {
    pub at: [f64; 2],
    /// The prescribed value of each Cartesian component; `None` leaves it free.
    pub u: [Option<f64>; 2],
}

/// A datum of a problem that is not a finite number at a point where it is used (a body force
/// `sqrt(x - 2)`, Dirichlet data `0.1 / x` at x = 0, a gap `ln(0)`, a contact normal of length 0).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("problem {problem}: `{key}` is {value} at {}: every datum must be a finite number (a normal, of positive length) at the quadrature and boundary points where it is used", crate::base::number::point(*.x))]
pub struct BadDatum {
    pub problem: String,
    /// The key as the problem file spells it (`body_force[0]`, `contact.chi`, ...).
    pub key: String,
    pub x: [f64; 2],
    pub value: f64,
}

/// Keeps the first [`BadDatum`] seen, in a fixed order (key, then x, then y), so that the error
/// does not depend on which thread evaluated which point. Cloning starts a fresh watch.
#[derive(Debug, Default)]
pub struct DatumWatch(std::sync::Mutex<Option<BadDatum>>);

impl Clone for DatumWatch {
    fn clone(&self) -> Self {
        DatumWatch::default()
    }
}

impl DatumWatch {
    /// `value`, noting it if it is not finite.
    #[inline]
    pub fn check(&self, problem: &str, key: &str, x: [f64; 2], value: f64) -> f64 {
        if !value.is_finite() {
            self.note(BadDatum { problem: problem.to_string(), key: key.to_string(), x, value });
        }
        value
    }

    /// Note `bad` (kept if it comes first in the fixed order).
    #[cold]
    pub fn note(&self, bad: BadDatum) {
        let mut first = self.0.lock().unwrap_or_else(|p| p.into_inner());
        let earlier =
            |a: &BadDatum, b: &BadDatum| (&a.key, a.x[0], a.x[1]).partial_cmp(&(&b.key, b.x[0], b.x[1])) == Some(std::cmp::Ordering::Less);
        if first.as_ref().is_none_or(|f| earlier(&bad, f)) {
            *first = Some(bad);
        }
    }

    pub fn first(&self) -> Option<BadDatum> {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }
}

/// The built-in problems' names.
pub const KNOWN: [&str; 4] = ["ex71", "ex72", "fb", "patch"];

/// Why `--problem` (or a manifest's `problem`) names no problem.
#[derive(Debug, thiserror::Error)]
pub enum ProblemError {
    #[error(
        "unknown problem '{0}': expected a built-in problem ({known}) or the path of a problem file (NAME.toml, e.g. experiments/problems/ex72.toml)",
        known = KNOWN.join(", ")
    )]
    Unknown(String),
    #[error("problem '{0}' is built in and has no constants to set; constants apply to problem files (NAME.toml)")]
    Constants(String),
    #[error(transparent)]
    File(#[from] ProblemFileError),
}

/// Whether `s` names a problem file rather than a built-in problem: it ends in `.toml`.
pub fn is_file(s: &str) -> bool {
    s.ends_with(".toml")
}

/// The problem `s` names: a built-in name ([`KNOWN`]) or the path of a problem file (ending in
/// `.toml`, read and checked here; see [`file`](mod@file) for the format).
pub fn by_name(s: &str) -> Result<Box<dyn Problem>, ProblemError> {
    load(s, &std::collections::BTreeMap::new())
}

/// [`by_name`] with some of a problem file's `[constants]` given other values (see
/// [`FileProblem::load_with`]); a built-in problem has no constants to set.
pub fn load(s: &str, constants: &std::collections::BTreeMap<String, f64>) -> Result<Box<dyn Problem>, ProblemError> {
    if !constants.is_empty() && !is_file(s) {
        return Err(ProblemError::Constants(s.to_string()));
    }
    match s {
        "ex71" => Ok(Box::new(Ex71)),
        "ex72" => Ok(Box::new(Ex72)),
        "fb" => Ok(Box::new(Fb)),
        "patch" => Ok(Box::new(Patch::default())),
        _ if is_file(s) => Ok(Box::new(FileProblem::load_with(Path::new(s), constants)?)),
        _ => Err(ProblemError::Unknown(s.to_string())),
    }
}
