//! An exact solution that is one: its gradient is the derivative of its displacement, and the
//! body force is -div sigma(u) (paper eq. 1.1), checked on the mesh before a solve
//! ([`check_exact`]). A problem file may state `exact.grad` by hand (exmex cannot differentiate
//! `max`), and its body force is always written by hand: a slip in either is otherwise a silent
//! wrong answer. The traction `"exact"` is sigma(grad) n, so a wrong gradient solves another
//! problem than the one whose u the errors are measured against; a wrong body force does the
//! same. Both are certified solutions of the wrong problem, and the error rates only look poor.
//!
//! The derivatives are taken by central differences at the centroids of up to [`SAMPLES`]
//! triangles spread over the mesh; the gradient also at every point where it enters the discrete
//! problem or the estimate, the points of the Neumann edges where the traction `"exact"` =
//! sigma(grad) n is read (`boundary::gradient_points`: the P2 nodes, the traction's Gauss points,
//! the estimator's edge points; a band in a hand-written grad, divergence-free, between the centroids
//! would otherwise be certified on structured:4 to 32); the body force also at every point where the assembly
//! evaluates it on this mesh (module `body_force`: whatever f the discrete problem sees is
//! checked; on a refined mesh the triangles the refinement left as they were keep the verdict
//! of their points from the level before). The steps are `s` and `s / 2`, `s` a thousandth of the
//! triangle's (or boundary edge's) longest edge. A central difference is second-order, so the two steps differ by
//! about 3/4 of the larger one's error; a mismatch is reported only where it exceeds
//! [`CONSISTENT`] times the data's scale and [`BEYOND`] times that difference. Where a kink of
//! the data falls inside the stencil (fb's (x - a)_+^(1/2) in f, at x = a) the two steps
//! disagree by about as much as the mismatch, and the point proves nothing either way: it is
//! passed over, not refused.
//!
//! The boundary and contact conditions are checked too (module `boundary`): an exact solution must
//! satisfy them as well as the equations.

pub(in crate::contact) mod body_force;
pub(in crate::contact) mod boundary;

pub use body_force::BodyForceFindings;

use model::mesh::{Mesh, P2Nodes};
use model::problems::{Exact, Material, Problem};

/// Triangles sampled (spread evenly over the mesh's numbering).
pub const SAMPLES: usize = 97;

/// The smallest mismatch reported, relative to the largest value of the quantity over the samples.
pub const CONSISTENT: f64 = 1e-6;

/// How many times the difference between the two steps a mismatch must exceed to be reported.
pub const BEYOND: f64 = 100.0;

/// An exact solution that contradicts itself or the body force.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ExactError {
    #[error(
        "{problem}: the exact solution's gradient contradicts its displacement: at {x} {what} is {declared:.6e}, while central differences of `exact.u[{i}]` give {differenced:.6e} (steps {step:.1e} and half that agree to {spread:.1e}), at {count} of {sampled} sampled points; {advice}",
        x = model::base::number::point(*.at),
        what = gradient_entry(*.written, *.i, *.j),
        advice = if *.written { "write the derivative of u there, or leave `exact.grad` out and it is differentiated from u" } else { "u is not differentiable there as written (a kink or a jump near the point?); write `exact.grad` by hand where the derivative is known" }
    )]
    Gradient {
        problem: String,
        /// Whether the gradient is written by hand ([`Exact::grad_written`]).
        written: bool,
        at: [f64; 2],
        i: usize,
        j: usize,
        declared: f64,
        differenced: f64,
        step: f64,
        spread: f64,
        count: usize,
        sampled: usize,
    },
    #[error(
        "{problem}: the body force is not -div sigma(u) of the exact solution: at {x} `body_force[{i}]` is {declared:.6e}, while -div sigma(u) is {differenced:.6e} by central differences of sigma(exact.grad) (steps {step:.1e} and half that agree to {spread:.1e}), at {count} of {sampled} sampled points; an exact solution must solve the equations, -div sigma(u) = f (paper eq. 1.1)",
        x = model::base::number::point(*.at)
    )]
    BodyForce {
        problem: String,
        at: [f64; 2],
        i: usize,
        declared: f64,
        differenced: f64,
        step: f64,
        spread: f64,
        count: usize,
        sampled: usize,
    },
    #[error(
        "{problem}: the exact solution does not satisfy {what}: at {x} {detail}, at {count} of {sampled} checked boundary points; an exact solution must satisfy the problem's boundary and contact conditions (paper eq. 1.1-1.8), or the errors are measured against the solution of another problem",
        x = model::base::number::point(*.at)
    )]
    Boundary { problem: String, what: String, at: [f64; 2], detail: String, count: usize, sampled: usize },
}

/// How a message names entry (i, j) of the exact gradient: as written, or as derived from u.
fn gradient_entry(written: bool, i: usize, j: usize) -> String {
    let derivative = format!("d u_{} / d {}", i + 1, ["x", "y"][j]);
    if written {
        format!("`exact.grad[{i}][{j}]` ({derivative})")
    } else {
        format!("{derivative}, differentiated symbolically from `exact.u[{i}]` (the file writes no `exact.grad`),")
    }
}

/// One comparison at one point: what the problem states, the difference quotient with the
/// steps `step` and `step / 2`.
struct Sample {
    at: [f64; 2],
    declared: f64,
    coarse: Quotient,
    fine: Quotient,
    step: f64,
}

impl Sample {
    /// The mismatch, if it is one: beyond [`CONSISTENT`] times `scale`, and [`BEYOND`] times
    /// what the quotients cannot resolve: the two steps' difference, or their round-off where
    /// that is larger (two quotients of a displacement large against its variation can agree
    /// by chance to far below their round-off, as for u = (0.5 - 1e-9 x, 0)).
    fn contradicts(&self, scale: f64) -> bool {
        let off = (self.fine.value - self.declared).abs();
        let unresolved = (self.coarse.value - self.fine.value).abs().max(self.coarse.roundoff).max(self.fine.roundoff);
        [self.declared, self.coarse.value, self.fine.value].iter().all(|v| v.is_finite())
            && off > CONSISTENT * scale
            && off > BEYOND * unresolved
    }
}

/// A difference quotient and a bound of its round-off.
#[derive(Clone, Copy, Debug)]
struct Quotient {
    value: f64,
    roundoff: f64,
}

impl Quotient {
    /// (f(a) - f(b)) / (2 s) for a = x + s e_j, b = x - s e_j: the values carry a few ulps each
    /// (8 eps |f|), and a and b are rounded (the step off by eps (|x_j| + s)).
    fn central(fa: f64, fb: f64, x_j: f64, s: f64) -> Quotient {
        Quotient::of_magnitude(fa, fb, fa.abs() + fb.abs(), x_j, s)
    }

    /// [`Quotient::central`] of values whose round-off is that of `magnitude` (|f(a)| + |f(b)|
    /// or larger: the components of a vector computed together).
    fn of_magnitude(fa: f64, fb: f64, magnitude: f64, x_j: f64, s: f64) -> Quotient {
        let value = (fa - fb) / (2.0 * s);
        let roundoff = f64::EPSILON * (8.0 * magnitude / (2.0 * s) + value.abs() * (x_j.abs() + s) / s);
        Quotient { value, roundoff }
    }
}

/// The points `x + s e_j` and `x - s e_j`.
fn stencil(x: [f64; 2], j: usize, s: f64) -> ([f64; 2], [f64; 2]) {
    let (mut a, mut b) = (x, x);
    a[j] += s;
    b[j] -= s;
    (a, b)
}

/// Central difference of `f` at `x` along axis `j` with step `s`.
fn central(f: &dyn Fn([f64; 2]) -> f64, x: [f64; 2], j: usize, s: f64) -> Quotient {
    let (a, b) = stencil(x, j, s);
    Quotient::central(f(a), f(b), x[j], s)
}

/// The difference step of every triangle: a thousandth of its longest edge, and at least 1e-6
/// of the body's size (round-off in the differences stays far below the mismatches reported, on
/// the smallest triangles of a graded mesh too).
fn steps(mesh: &Mesh) -> Vec<f64> {
    let diameter = diameter(mesh);
    (0..mesh.n_triangles())
        .map(|k| {
            let t = mesh.triangles[k].map(|v| mesh.vertices[v]);
            let longest = (0..3).map(|e| (t[e][0] - t[(e + 1) % 3][0]).hypot(t[e][1] - t[(e + 1) % 3][1])).fold(0.0, f64::max);
            1e-3 * longest.max(1e-3 * diameter)
        })
        .collect()
}

/// The body's size: the diagonal of the mesh's bounding box.
pub(in crate::contact) fn diameter(mesh: &Mesh) -> f64 {
    let (lo, hi) = mesh.vertices.iter().fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), v| {
        ([lo[0].min(v[0]), lo[1].min(v[1])], [hi[0].max(v[0]), hi[1].max(v[1])])
    });
    (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}

/// The centroid of every sampled triangle and its step (`steps`, per triangle: [`steps`]).
fn points(mesh: &Mesh, steps: &[f64]) -> Vec<([f64; 2], f64)> {
    let n = mesh.n_triangles();
    let picks = SAMPLES.min(n);
    (0..picks)
        .map(|k| {
            let t = mesh.triangles[k * n / picks].map(|v| mesh.vertices[v]);
            let c = [(t[0][0] + t[1][0] + t[2][0]) / 3.0, (t[0][1] + t[1][1] + t[2][1]) / 3.0];
            (c, steps[k * n / picks])
        })
        .collect()
}

/// What a problem states (`declared`) against a difference quotient (`differenced` at a point
/// with a step) at every sampled point: the first contradiction, if any.
struct Mismatch {
    at: [f64; 2],
    declared: f64,
    differenced: f64,
    step: f64,
    spread: f64,
    count: usize,
}

type Declared<'a> = &'a (dyn Fn([f64; 2]) -> f64 + Sync);
type Differenced<'a> = &'a (dyn Fn([f64; 2], f64) -> Quotient + Sync);

/// The declared value and the finer step's quotient at every point (in parallel: the body force
/// is compared at every quadrature point of the load), then the coarser step only where the
/// finer one is off by more than [`CONSISTENT`] times the scale, the largest value over the
/// points: a contradiction needs both steps, and elsewhere the answer is already no.
fn compare(pts: &[([f64; 2], f64)], declared: Declared, differenced: Differenced) -> Option<Mismatch> {
    use rayon::prelude::*;
    let first: Vec<(f64, Quotient)> = pts.par_iter().map(|&(at, s)| (declared(at), differenced(at, s / 2.0))).collect();
    judge(pts, &first, differenced, 0.0)
}

/// The first contradiction among `pts`, given the declared value and the finer step's quotient
/// at each (`first`): the coarser step is taken only where the finer one is off (see [`compare`]).
/// The scale is the largest value over the points, and no less than `floor`.
fn judge(pts: &[([f64; 2], f64)], first: &[(f64, Quotient)], differenced: Differenced, floor: f64) -> Option<Mismatch> {
    let scale = first.iter().flat_map(|&(d, f)| [d.abs(), f.value.abs()]).filter(|v| v.is_finite()).fold(floor, f64::max);
    let bad: Vec<Sample> = pts
        .iter()
        .zip(first)
        .filter(|(_, (d, f))| (f.value - d).abs() > CONSISTENT * scale)
        .map(|(&(at, s), &(declared, fine))| Sample { at, declared, coarse: differenced(at, s), fine, step: s })
        .filter(|sample| sample.contradicts(scale))
        .collect();
    bad.first().map(|s| Mismatch {
        at: s.at,
        declared: s.declared,
        differenced: s.fine.value,
        step: s.step,
        spread: (s.coarse.value - s.fine.value).abs(),
        count: bad.len(),
    })
}

/// -div sigma(u) at `x` by central differences of sigma(exact.grad) with step `s`, both
/// components from the same four gradients ((sigma e_j)_i = sigma_ij).
fn minus_div(material: &Material, exact: &dyn Exact, x: [f64; 2], s: f64) -> [Quotient; 2] {
    let mut minus = [Quotient { value: 0.0, roundoff: 0.0 }; 2];
    for j in 0..2 {
        let mut e = [0.0; 2];
        e[j] = 1.0;
        let (a, b) = stencil(x, j, s);
        let (ta, tb) = (material.traction(exact.grad(a), e), material.traction(exact.grad(b), e));
        // each component of the traction carries the round-off of the larger one
        let magnitude = ta[0].abs().max(ta[1].abs()) + tb[0].abs().max(tb[1].abs());
        for i in 0..2 {
            let q = Quotient::of_magnitude(ta[i], tb[i], magnitude, x[j], s);
            minus[i] = Quotient { value: minus[i].value - q.value, roundoff: minus[i].roundoff + q.roundoff };
        }
    }
    minus
}

/// Check `problem`'s exact solution, if it has one, on `mesh` (see the module docs).
///
/// The body force is compared at every load point (module `body_force`), taking the findings of
/// the triangles `before` holds (the level before's, [`BodyForceFindings::inherit`]); the
/// findings of this mesh are returned for the next level (None without an exact solution).
pub fn check_exact(
    problem: &dyn Problem,
    mesh: &Mesh,
    nodes: &P2Nodes,
    before: Option<&BodyForceFindings>,
) -> Result<Option<BodyForceFindings>, ExactError> {
    let Some(exact) = problem.exact() else { return Ok(None) };
    let problem_name = || match problem.source() {
        Some(file) => format!("problem file {}", file.display()),
        None => format!("problem {}", problem.name()),
    };
    let steps = steps(mesh);
    let pts = points(mesh, &steps);
    // the gradient also where it enters: the traction "exact" = sigma(grad) n
    let mut grad_pts = pts.clone();
    grad_pts.extend(boundary::gradient_points(mesh, nodes));
    let sampled = grad_pts.len();
    for i in 0..2 {
        for j in 0..2 {
            let u = |x: [f64; 2]| exact.u(x)[i];
            if let Some(m) = compare(&grad_pts, &|at| exact.grad(at)[i][j], &|at, s| central(&u, at, j, s)) {
                let Mismatch { at, declared, differenced, step, spread, count } = m;
                return Err(ExactError::Gradient {
                    problem: problem_name(),
                    written: exact.grad_written(),
                    at,
                    i,
                    j,
                    declared,
                    differenced,
                    step,
                    spread,
                    count,
                    sampled,
                });
            }
        }
    }
    let material = problem.material();
    // a body force's scale is no less than the stress the gradient implies over the body's size:
    // for a stress-free exact solution (a rigid motion written as cosh(3 x)^2 - sinh(3 x)^2 - 0.001 y)
    // the largest |f| and |div sigma| are the round-off of the symbolic gradient
    let gradient = grad_pts
        .iter()
        .flat_map(|&(at, _)| exact.grad(at).into_iter().flatten())
        .filter(|v| v.is_finite())
        .fold(0.0f64, |a, v| a.max(v.abs()));
    let floor = (2.0 * material.mu + material.zeta.abs()) * gradient / diameter(mesh);
    let (mismatch, sampled, findings) = body_force::mismatch(problem, exact, mesh, &pts, &steps, floor, before);
    if let Some((i, m)) = mismatch {
        let Mismatch { at, declared, differenced, step, spread, count } = m;
        return Err(ExactError::BodyForce { problem: problem_name(), at, i, declared, differenced, step, spread, count, sampled });
    }
    boundary::check_boundary(problem, exact, mesh, nodes, &problem_name())?;
    Ok(Some(findings))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(declared: f64, coarse: f64, fine: f64) -> Sample {
        let q = |value| Quotient { value, roundoff: 0.0 };
        Sample { at: [0.0, 0.0], declared, coarse: q(coarse), fine: q(fine), step: 1e-3 }
    }

    #[test]
    fn a_mismatch_counts_only_beyond_the_steps_own_disagreement() {
        // converged differences far from the declared value: a contradiction
        assert!(sample(1.0, 2.0 + 1e-9, 2.0).contradicts(2.0));
        // a kink inside the stencil: the two steps disagree as much as the mismatch
        assert!(!sample(1.0, 3.0, 2.0).contradicts(2.0));
        // round-off sized mismatches, and values that are not numbers, prove nothing
        assert!(!sample(1.0, 1.0 + 1e-9, 1.0 + 1e-9).contradicts(1.0));
        assert!(!sample(f64::NAN, 2.0, 2.0).contradicts(2.0));
    }

    #[test]
    fn a_derived_gradient_is_named_as_derived() {
        let error = |written| {
            ExactError::Gradient {
                problem: "problem file p.toml".into(),
                written,
                at: [0.5, 0.25],
                i: 0,
                j: 1,
                declared: 1.0,
                differenced: 2.0,
                step: 1e-4,
                spread: 0.0,
                count: 1,
                sampled: 9,
            }
            .to_string()
        };
        let (written, derived) = (error(true), error(false));
        assert!(written.contains("`exact.grad[0][1]` (d u_1 / d y) is"), "{written}");
        assert!(derived.contains("d u_1 / d y, differentiated symbolically from `exact.u[0]`"), "{derived}");
        assert!(!derived.contains("`exact.grad[") && derived.contains("write `exact.grad` by hand"), "{derived}");
    }

    #[test]
    fn the_built_in_exact_solutions_are_consistent() {
        for problem in model::problems::KNOWN {
            let p = model::problems::by_name(problem).unwrap();
            for n in [4, 16] {
                let mesh = model::mesh::MeshSpec::parse(&format!("structured:{n}")).unwrap().build(p.as_ref()).unwrap();
                assert!(check_exact(p.as_ref(), &mesh, &P2Nodes::new(&mesh), None).is_ok(), "{problem} on structured:{n}");
            }
        }
    }
}
