//! L-infinity norms of the error u - u_h, evaluated three ways (PAPER-NOTES.md): at the
//! quadrature points of every element (the paper's way), on a dense barycentric lattice of every
//! element, and over the nodal values only (which is not the L-infinity norm).

use crate::element;
use crate::mesh::Mesh;
use crate::solve::DiscreteSolution;
use rayon::prelude::*;

/// Degree of the quadrature rule whose points the "quadrature" norm uses (collapsed Gauss,
/// 3 x 3 = 9 points per element; declared in every record).
pub const QUADRATURE_DEGREE: usize = 5;
/// Order of the barycentric lattice of the "dense" norm (28 points per element).
pub const LATTICE_ORDER: usize = 6;

/// Which points an L-infinity norm is taken over.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    Quadrature,
    Dense,
}

impl Sampling {
    /// Reference points of the sampling on the reference triangle.
    pub fn points(self) -> Vec<[f64; 2]> {
        match self {
            Sampling::Quadrature => element::triangle_rule(QUADRATURE_DEGREE).points,
            Sampling::Dense => element::lattice(LATTICE_ORDER),
        }
    }

    pub fn describe(self) -> String {
        match self {
            Sampling::Quadrature => format!("collapsed Gauss points of the degree-{QUADRATURE_DEGREE} rule per element"),
            Sampling::Dense => format!("barycentric lattice of order {LATTICE_ORDER} per element"),
        }
    }
}

/// ||u - u_h||_Linf three ways (max over both components).
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct LinfError {
    pub linf_quadrature: f64,
    pub linf_dense: f64,
    pub linf_nodal: f64,
}

/// max over the sampling points of |u - u_h| (componentwise maximum).
/// The displacement the error is measured against: an exact solution or a reference solution.
pub type Reference<'a> = &'a (dyn Fn([f64; 2]) -> [f64; 2] + Sync);

pub fn linf_error_on(mesh: &Mesh, sol: &DiscreteSolution, exact: Reference, sampling: Sampling) -> f64 {
    let refs = sampling.points();
    (0..mesh.n_triangles())
        .into_par_iter()
        .map(|t| {
            sol.eval_element(mesh, t, &refs)
                .iter()
                .map(|(x, uh)| {
                    let u = exact(*x);
                    (u[0] - uh[0]).abs().max((u[1] - uh[1]).abs())
                })
                .fold(0.0, f64::max)
        })
        .reduce(|| 0.0, f64::max)
}

pub fn linf_error(mesh: &Mesh, sol: &DiscreteSolution, exact: Reference) -> LinfError {
    let nodal = sol
        .nodes
        .coords
        .iter()
        .zip(&sol.u)
        .map(|(x, uh)| {
            let u = exact(*x);
            (u[0] - uh[0]).abs().max((u[1] - uh[1]).abs())
        })
        .fold(0.0, f64::max);
    LinfError {
        linf_quadrature: linf_error_on(mesh, sol, exact, Sampling::Quadrature),
        linf_dense: linf_error_on(mesh, sol, exact, Sampling::Dense),
        linf_nodal: nodal,
    }
}
