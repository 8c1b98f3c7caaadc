//! L-infinity norms of the error u - u_h, evaluated three ways (the paper does not say how it
//! evaluates the maximum; the choice moves the observed rates, so all three are kept): at the
//! quadrature points of every element (the paper's way), on a dense barycentric lattice of every
//! element, and over the nodal values only (which is not the L-infinity norm).

use crate::contact::solve::DiscreteSolution;
use model::mesh::Mesh;
use model::settings::sampling::Sampling;
use rayon::prelude::*;

/// ||u - u_h||_Linf three ways (max over both components).
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct LinfError {
    pub linf_quadrature: f64,
    pub linf_dense: f64,
    pub linf_nodal: f64,
}

/// The displacement the error is measured against: an exact solution or a reference solution.
pub type Reference<'a> = &'a dyn Displacement;

/// A displacement field given everywhere: any closure `Fn([f64; 2]) -> [f64; 2]` (an exact
/// solution), or a discrete solution on another mesh (a study's reference solution).
pub trait Displacement: Sync {
    /// The displacement at `x`.
    fn at(&self, x: [f64; 2]) -> [f64; 2];

    /// The displacement at each point of `xs`, points close together (the sampling points of one
    /// triangle): what [`Displacement::at`] gives point by point. A field on another mesh finds
    /// the triangles that hold them together.
    fn at_each(&self, xs: &[[f64; 2]]) -> Vec<[f64; 2]> {
        xs.iter().map(|&x| self.at(x)).collect()
    }
}

impl<F: Fn([f64; 2]) -> [f64; 2] + Sync> Displacement for F {
    fn at(&self, x: [f64; 2]) -> [f64; 2] {
        self(x)
    }
}

/// |u - u_h| (componentwise maximum) at each of the points `at` (with u_h there), u taken from
/// `exact` for all of them at once.
fn errors(exact: Reference, at: &[([f64; 2], [f64; 2])]) -> Vec<f64> {
    let xs: Vec<[f64; 2]> = at.iter().map(|(x, _)| *x).collect();
    let u = exact.at_each(&xs);
    u.iter().zip(at).map(|(u, (_, uh))| (u[0] - uh[0]).abs().max((u[1] - uh[1]).abs())).collect()
}

/// The largest of |u - u_h| at the points `at`; None without points.
fn largest_error(exact: Reference, at: &[([f64; 2], [f64; 2])]) -> Option<f64> {
    errors(exact, at).into_iter().reduce(f64::max)
}

/// The larger of two maxima, either of which may be missing.
fn larger(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
}

pub fn linf_error_on(mesh: &Mesh, sol: &DiscreteSolution, exact: Reference, sampling: Sampling) -> f64 {
    maxima(mesh, sol, exact, sampling, &|_| true).0.unwrap_or(0.0)
}

/// max |u - u_h| over the sampling points x with `keep(x)`; None if no point is kept.
pub fn linf_error_where(
    mesh: &Mesh,
    sol: &DiscreteSolution,
    exact: Reference,
    sampling: Sampling,
    keep: &(dyn Fn([f64; 2]) -> bool + Sync),
) -> Option<f64> {
    maxima(mesh, sol, exact, sampling, keep).1
}

/// max |u - u_h| over every sampling point and over those x with `keep(x)` (None where there
/// are none), from one evaluation of u and u_h per point: the maximum of the same values either
/// way, so the same numbers as [`linf_error_on`] and [`linf_error_where`] one by one.
fn maxima(
    mesh: &Mesh,
    sol: &DiscreteSolution,
    exact: Reference,
    sampling: Sampling,
    keep: &(dyn Fn([f64; 2]) -> bool + Sync),
) -> (Option<f64>, Option<f64>) {
    let refs = sampling.points();
    (0..mesh.n_triangles())
        .into_par_iter()
        .map(|t| {
            let at = sol.eval_element(mesh, t, &refs);
            let e = errors(exact, &at);
            let kept = at.iter().zip(&e).filter(|((x, _), _)| keep(*x)).map(|(_, e)| *e).reduce(f64::max);
            (e.into_iter().reduce(f64::max), kept)
        })
        .reduce(|| (None, None), |a, b| (larger(a.0, b.0), larger(a.1, b.1)))
}

/// Points per edge of the contact-edge sampling (end points included).
pub const EDGE_POINTS: usize = 13;

/// ||u - u_h||_Linf on Gamma_C: max over `EDGE_POINTS` equally spaced points of every contact
/// edge (end points included); None without contact edges.
pub fn linf_error_contact(mesh: &Mesh, sol: &DiscreteSolution, exact: Reference) -> Option<f64> {
    let reference = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    (0..mesh.n_triangles())
        .into_par_iter()
        .filter_map(|t| {
            let tri = mesh.triangles[t];
            let mut refs = Vec::new();
            for b in sol.nodes.element_boundary[t].iter().flatten() {
                let e = &mesh.boundary[*b];
                if e.part != model::problems::Part::Contact {
                    continue;
                }
                let (i, j) = (tri.iter().position(|&v| v == e.v[0])?, tri.iter().position(|&v| v == e.v[1])?);
                for k in 0..EDGE_POINTS {
                    let s = k as f64 / (EDGE_POINTS - 1) as f64;
                    refs.push([(1.0 - s) * reference[i][0] + s * reference[j][0], (1.0 - s) * reference[i][1] + s * reference[j][1]]);
                }
            }
            largest_error(exact, &sol.eval_element(mesh, t, &refs))
        })
        .reduce_with(f64::max)
}

pub fn linf_error(mesh: &Mesh, sol: &DiscreteSolution, exact: Reference) -> LinfError {
    linf_error_with(mesh, sol, exact, &|_| true).0
}

/// [`linf_error`], and the dense lattice's maximum over the points x with `keep(x)` (None if
/// none is kept: [`linf_error_where`] with [`Sampling::Dense`]) from the same evaluations.
pub fn linf_error_with(
    mesh: &Mesh,
    sol: &DiscreteSolution,
    exact: Reference,
    keep: &(dyn Fn([f64; 2]) -> bool + Sync),
) -> (LinfError, Option<f64>) {
    let nodal = sol
        .nodes
        .coords
        .iter()
        .zip(&sol.u)
        .map(|(x, uh)| {
            let u = exact.at(*x);
            (u[0] - uh[0]).abs().max((u[1] - uh[1]).abs())
        })
        .fold(0.0, f64::max);
    let (dense, kept) = maxima(mesh, sol, exact, Sampling::Dense, keep);
    let error = LinfError {
        linf_quadrature: linf_error_on(mesh, sol, exact, Sampling::Quadrature),
        linf_dense: dense.unwrap_or(0.0),
        linf_nodal: nodal,
    };
    (error, kept)
}
