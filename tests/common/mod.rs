//! Shared helpers for the integration tests.
#![allow(dead_code)]

use signorini::contact::PdasOptions;
use signorini::mesh::{Mesh, MeshSpec};
use signorini::problems::Problem;
use signorini::solve::{self, DiscreteSolution};

pub fn mesh(problem: &dyn Problem, spec: &str) -> Mesh {
    MeshSpec::parse(spec).unwrap().build(&|x| problem.part_of(x))
}

pub fn solve_on(problem: &dyn Problem, mesh: &Mesh) -> DiscreteSolution {
    solve::solve(mesh, problem, &PdasOptions::default(), &mut |_| {}).expect("the solve converges")
}

/// Observed rate log(e1/e2)/log(h1/h2).
pub fn rate(e1: f64, e2: f64, h1: f64, h2: f64) -> f64 {
    (e1 / e2).ln() / (h1 / h2).ln()
}
