//! Reference solutions for problems without an exact solution (Example 7.2): a discrete
//! solution on a much finer adaptive mesh, evaluated anywhere by point location.

use crate::adapt::{self, AdaptConfig, Refine};
use crate::element::{self, Affine, N_NODES};
use crate::mesh::{Mesh, MeshSpec};
use crate::problems::Problem;
use crate::records::ReferenceSpec;

/// A P2 field on a mesh with a bucket grid for point location. Written by hand: a uniform grid
/// of element bounding boxes is all the unit square needs, and spatial-index crates would add a
/// dependency for twenty lines.
pub struct ReferenceField {
    mesh: Mesh,
    elements: Vec<[usize; 6]>,
    values: Vec<[f64; 2]>,
    grid: usize,
    buckets: Vec<Vec<u32>>,
    pub ndof: usize,
}

impl ReferenceField {
    pub fn new(mesh: Mesh, elements: Vec<[usize; 6]>, values: Vec<[f64; 2]>) -> Self {
        let grid = ((mesh.n_triangles() as f64 / 2.0).sqrt().ceil() as usize).clamp(1, 4096);
        let mut buckets = vec![Vec::new(); grid * grid];
        let cell = |v: f64| ((v * grid as f64).floor() as isize).clamp(0, grid as isize - 1) as usize;
        for t in 0..mesh.n_triangles() {
            let c = mesh.corners(t);
            let (x0, x1) = (c.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min), c.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max));
            let (y0, y1) = (c.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min), c.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max));
            for j in cell(y0 - 1e-12)..=cell(y1 + 1e-12) {
                for i in cell(x0 - 1e-12)..=cell(x1 + 1e-12) {
                    buckets[j * grid + i].push(t as u32);
                }
            }
        }
        let ndof = 2 * values.len();
        ReferenceField { mesh, elements, values, grid, buckets, ndof }
    }

    /// The field at x (the nearest element's extrapolation if x is a hair outside every element).
    pub fn eval(&self, x: [f64; 2]) -> [f64; 2] {
        let g = self.grid;
        let cell = |v: f64| ((v * g as f64).floor() as isize).clamp(0, g as isize - 1) as usize;
        let mut best: Option<(f64, usize, [f64; 2])> = None;
        for &t in &self.buckets[cell(x[1]) * g + cell(x[0])] {
            let t = t as usize;
            let r = Affine::new(self.mesh.corners(t)).inverse(x);
            let outside = (-r[0]).max(-r[1]).max(r[0] + r[1] - 1.0).max(0.0);
            if best.is_none_or(|b| outside < b.0) {
                best = Some((outside, t, r));
            }
            if outside == 0.0 {
                break;
            }
        }
        let (_, t, r) = best.expect("every point of the unit square lies in a bucket with elements");
        let phi = element::p2_values(r[0], r[1]);
        let el = &self.elements[t];
        let mut v = [0.0; 2];
        for a in 0..N_NODES {
            v[0] += phi[a] * self.values[el[a]][0];
            v[1] += phi[a] * self.values[el[a]][1];
        }
        v
    }
}

/// Compute the reference solution: adaptive refinement from `mesh_spec` (estimator with
/// `spec.contact_term`, otherwise the defaults) until the NDF reaches `spec.min_ndof`; the last
/// level's solution. `on_level` sees every level (progress) and may stop the loop (an
/// interrupt): then the result is `None`.
pub fn compute(
    problem: &dyn Problem,
    mesh_spec: &MeshSpec,
    spec: &ReferenceSpec,
    on_level: &mut dyn FnMut(&crate::adapt::LevelRecord) -> std::ops::ControlFlow<()>,
) -> Result<Option<ReferenceField>, crate::adapt::AdaptError> {
    let mesh = mesh_spec.build(&|x| problem.part_of(x));
    let estimator = crate::estimate::EstimatorConfig { contact_term: spec.contact_term, ..Default::default() };
    let config = AdaptConfig { levels: 200, refine: Refine::Adaptive, theta: spec.theta, estimator, ..Default::default() };
    let out = adapt::run(problem, mesh, &config, None, &mut |level| {
        if level.record.ndof >= spec.min_ndof { std::ops::ControlFlow::Break(()) } else { on_level(level.record) }
    })?;
    // the last level solved is the reference if it reached min_ndof (not if on_level stopped the loop)
    let reached = out.termination == adapt::Termination::StoppedByObserver && out.records.last().is_some_and(|r| r.ndof >= spec.min_ndof);
    Ok(reached.then(|| ReferenceField::new(out.mesh, out.solution.nodes.elements, out.solution.u)))
}
