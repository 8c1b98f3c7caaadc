//! The body force against -div sigma(u) of the exact solution (paper eq. 1.1), at every point
//! where the assembly evaluates f on the mesh ([`crate::fem::assembly::LoadPoints`], about 36 a
//! triangle), each by central differences of sigma(exact.grad) with its triangle's step: four
//! gradients a point, the largest part of the data checks.
//!
//! Each triangle's points are summed up in a [`Finding`]: per component, its share of the scale
//! (the largest finite |f_i| and |-div sigma(u)_i|) and how far its worst point is off
//! (the largest |-div sigma(u)_i - f_i|). The scale over the whole mesh is the largest share,
//! and a point counts ([`super::judge`]) only where it is off by more than [`super::CONSISTENT`]
//! times that scale: the triangles whose finding says none of theirs is are done with, the others
//! are evaluated again and judged point by point, in order. The verdict is the one of every point
//! judged at once.
//!
//! A refinement leaves most triangles of an adaptive level as they were: the same corners in
//! the same order, so the same load points, the same step (a thousandth of the longest edge,
//! no less than 1e-6 of the body's size, which bisection keeps) and the same values. Their
//! findings pass to the next level ([`BodyForceFindings::inherit`]) and only the new triangles
//! are evaluated, with the same verdict as checking every point again (tests/it/consistent_exact.rs
//! compares the two level by level).

use super::{CONSISTENT, Mismatch, Quotient, judge, minus_div};
use crate::fem::assembly::LoadPoints;
use model::mesh::Mesh;
use model::mesh::refine::Refinement;
use model::problems::{Exact, Problem};
use rayon::prelude::*;

/// What the load points of one triangle hold against a scale.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Finding {
    /// Per component, the largest finite |f_i| and |-div sigma(u)_i| over the points.
    scale: [f64; 2],
    /// Per component, the largest |-div sigma(u)_i - f_i| over the points (NaN passed over:
    /// a point that is not a number is never off).
    off: [f64; 2],
    /// The triangle's load points; 0 for a finding not known (a triangle to evaluate).
    points: u32,
}

impl Finding {
    const UNKNOWN: Finding = Finding { scale: [0.0; 2], off: [0.0; 2], points: 0 };

    fn of(values: &[Evaluated]) -> Finding {
        let mut finding = Finding { points: values.len() as u32, ..Finding::UNKNOWN };
        for v in values {
            for i in 0..2 {
                for x in [v.f[i].abs(), v.fine[i].value.abs()] {
                    if x.is_finite() {
                        finding.scale[i] = finding.scale[i].max(x);
                    }
                }
                finding.off[i] = finding.off[i].max((v.fine[i].value - v.f[i]).abs());
            }
        }
        finding
    }
}

/// The findings of the body-force check on every triangle of one mesh, for the next level's
/// check to take where its triangles are the same ([`BodyForceFindings::inherit`]). Two are
/// equal when they hold the same findings, however many were inherited.
#[derive(Clone, Debug)]
pub struct BodyForceFindings {
    /// The body's size the steps were taken with ([`super::diameter`]).
    diameter: f64,
    triangles: Vec<Finding>,
    /// Triangles whose finding came from the level before.
    inherited: usize,
}

impl PartialEq for BodyForceFindings {
    fn eq(&self, other: &Self) -> bool {
        self.diameter.to_bits() == other.diameter.to_bits() && self.triangles == other.triangles
    }
}

impl BodyForceFindings {
    /// The findings for the refined mesh of `refinement` (of `mesh`, the mesh these are of): a
    /// new triangle with its parent's corners in the same order, bit for bit, takes its
    /// parent's finding; every other one is evaluated by the next check.
    pub fn inherit(&self, mesh: &Mesh, refinement: &Refinement) -> BodyForceFindings {
        let new = &refinement.mesh;
        let bits = |c: [[f64; 2]; 3]| c.map(|v| v.map(f64::to_bits));
        let same = self.triangles.len() == mesh.n_triangles();
        let triangles = (0..new.n_triangles())
            .into_par_iter()
            .map(|t| {
                let parent = refinement.parent[t];
                if same && bits(new.corners(t)) == bits(mesh.corners(parent)) { self.triangles[parent] } else { Finding::UNKNOWN }
            })
            .collect();
        BodyForceFindings { diameter: self.diameter, triangles, inherited: 0 }
    }

    /// Triangles whose finding the check took from the level before instead of evaluating it.
    pub fn inherited(&self) -> usize {
        self.inherited
    }
}

/// The body force `f` at a point and -div sigma(u) there with the finer step (half `step`).
struct Evaluated {
    at: [f64; 2],
    step: f64,
    f: [f64; 2],
    fine: [Quotient; 2],
}

/// The body force against -div sigma(u) (each component, as [`judge`] does for one): at the
/// sampled centroids, and at every load point of the mesh, each with the step of its triangle
/// (`steps`); a triangle's findings are taken from `before` where it has them (the module
/// docs). Whatever value of f the discrete problem sees is checked, so a file is not accepted
/// on one mesh and refused on another for a mismatch between samples. Returns the first
/// mismatch with its component, the number of points compared, and every triangle's findings.
pub(super) fn mismatch(
    problem: &dyn Problem,
    exact: &dyn Exact,
    mesh: &Mesh,
    centroids: &[([f64; 2], f64)],
    steps: &[f64],
    floor: f64,
    before: Option<&BodyForceFindings>,
) -> (Option<(usize, Mismatch)>, usize, BodyForceFindings) {
    let material = problem.material();
    let loads = LoadPoints::new(problem.load_breaks());
    let evaluate =
        |at: [f64; 2], step: f64| Evaluated { at, step, f: problem.body_force(at), fine: minus_div(&material, exact, at, step / 2.0) };
    let of_triangle = |t: usize| -> Vec<Evaluated> { loads.of(mesh, t).into_iter().map(|x| evaluate(x, steps[t])).collect() };
    let diameter = super::diameter(mesh);
    let before = before.filter(|b| b.triangles.len() == mesh.n_triangles() && b.diameter.to_bits() == diameter.to_bits());
    let known = |t: usize| before.map_or(Finding::UNKNOWN, |b| b.triangles[t]);
    let triangles: Vec<Finding> = (0..mesh.n_triangles())
        .into_par_iter()
        .map(|t| match known(t) {
            f if f.points > 0 => f,
            _ => Finding::of(&of_triangle(t)),
        })
        .collect();
    let inherited = before.map_or(0, |b| b.triangles.iter().filter(|f| f.points > 0).count());
    let at_centroids: Vec<Evaluated> = centroids.par_iter().map(|&(at, step)| evaluate(at, step)).collect();
    let centroid_scale = Finding::of(&at_centroids).scale;
    let count = centroids.len() + triangles.iter().map(|f| f.points as usize).sum::<usize>();
    let findings = BodyForceFindings { diameter, triangles, inherited };
    for (i, &at_centroid) in centroid_scale.iter().enumerate() {
        let scale = findings.triangles.iter().map(|f| f.scale[i]).chain([at_centroid]).fold(floor, f64::max);
        let threshold = CONSISTENT * scale;
        let off = |v: &&Evaluated| (v.fine[i].value - v.f[i]).abs() > threshold;
        // the points off, in the order of every point at once: the centroids, then the
        // triangles' (only those whose findings hold one are evaluated again)
        let again: Vec<usize> = (0..mesh.n_triangles()).filter(|&t| findings.triangles[t].off[i] > threshold).collect();
        let evaluated: Vec<Vec<Evaluated>> = again.par_iter().map(|&t| of_triangle(t)).collect();
        let kept: Vec<&Evaluated> = at_centroids.iter().chain(evaluated.iter().flatten()).filter(off).collect();
        let pts: Vec<([f64; 2], f64)> = kept.iter().map(|k| (k.at, k.step)).collect();
        let first: Vec<(f64, Quotient)> = kept.iter().map(|k| (k.f[i], k.fine[i])).collect();
        let differenced = |at, s| minus_div(&material, exact, at, s)[i];
        // the scale over every point, fixed: judge's own fold over the kept ones cannot exceed it
        if let Some(m) = judge(&pts, &first, &differenced, scale) {
            return (Some((i, m)), count, findings);
        }
    }
    (None, count, findings)
}
