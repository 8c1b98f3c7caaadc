//! Which points an L-infinity norm and the estimator's edge terms are taken over
//! ([`Sampling`]), on their own below the norms and the solve: the check of an exact solution
//! on the contact part (`consistent::boundary`), which the solve runs, reads the same edge
//! points as the estimator.

use crate::base::element;

/// Degree of the quadrature rule whose points the "quadrature" norm uses (Radon's symmetric
/// 7-point rule, [`element::symmetric_rule_5`]: a maximum over its points does not depend on
/// how an element's vertices are labelled; declared in every record).
pub const QUADRATURE_DEGREE: usize = 5;
/// Order of the barycentric lattice of the "dense" norm (28 points per element).
pub const LATTICE_ORDER: usize = 6;

/// Gauss points per edge for the "quadrature" sampling of the estimator's edge terms.
pub const EDGE_GAUSS: usize = 3;

/// Which points an L-infinity norm is taken over (`--sampling`, `estimator.sampling`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    Quadrature,
    Dense,
}

impl Sampling {
    /// Reference points of the sampling on the reference triangle.
    pub fn points(self) -> Vec<[f64; 2]> {
        match self {
            Sampling::Quadrature => element::symmetric_rule_5().points,
            Sampling::Dense => element::lattice(LATTICE_ORDER),
        }
    }

    /// The parameters s in [0, 1] along a boundary edge where the estimator reads the edge
    /// terms (the Neumann traction among them) with this sampling: [`EDGE_GAUSS`] Gauss points,
    /// or the lattice's points on an edge. Defined here, below the estimator, so that the check
    /// of an exact solution (`contact::consistent`) looks at the same points.
    pub fn edge_parameters(self) -> Vec<f64> {
        match self {
            Sampling::Quadrature => element::gauss_legendre(EDGE_GAUSS).points.iter().map(|p| p[0]).collect(),
            Sampling::Dense => (0..=LATTICE_ORDER).map(|k| k as f64 / LATTICE_ORDER as f64).collect(),
        }
    }

    pub fn describe(self) -> String {
        match self {
            Sampling::Quadrature => {
                format!("the 7 points of Radon's symmetric degree-{QUADRATURE_DEGREE} rule per element (centroid and two orbits of 3)")
            }
            Sampling::Dense => format!("barycentric lattice of order {LATTICE_ORDER} per element"),
        }
    }
}
