//! Reference solutions for problems without an exact solution (Example 7.2): a discrete
//! solution on a much finer adaptive mesh, evaluated anywhere by point location.

use crate::adapt::{self, AdaptConfig, Refine};
use crate::element::{self, N_NODES};
use crate::mesh::locate::Locator;
use crate::mesh::{Mesh, MeshSpec};
use crate::problems::Problem;
use crate::records::ReferenceSpec;

/// A P2 field on a mesh with an R*-tree for point location ([`Locator`]).
pub struct ReferenceField {
    mesh: Mesh,
    elements: Vec<[usize; 6]>,
    values: Vec<[f64; 2]>,
    locator: Locator,
    pub ndof: usize,
}

impl ReferenceField {
    pub fn new(mesh: Mesh, elements: Vec<[usize; 6]>, values: Vec<[f64; 2]>) -> Self {
        let locator = Locator::new(&mesh);
        let ndof = 2 * values.len();
        ReferenceField { mesh, elements, values, locator, ndof }
    }

    /// The field at x: in the triangle containing x (the one of smallest index where x is on an
    /// edge), or the P2 polynomial of the triangle x is least outside of if x is a hair outside
    /// every triangle (a point of a coarser mesh whose boundary approximates a curve differently).
    pub fn eval(&self, x: [f64; 2]) -> [f64; 2] {
        let hit = self.locator.nearest(&self.mesh, x).expect("a reference mesh has triangles");
        let phi = element::p2_values(hit.reference[0], hit.reference[1]);
        let el = &self.elements[hit.triangle];
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
    let mesh = mesh_spec.build(problem).map_err(|e| adapt::AdaptError::Solve(e.into()))?;
    let estimator = crate::estimate::EstimatorConfig { contact_term: spec.contact_term, ..Default::default() };
    let config = AdaptConfig { levels: 200, refine: Refine::Adaptive, theta: spec.theta, estimator, ..Default::default() };
    let out = adapt::run(problem, mesh, &config, None, &mut |level| {
        if level.record.ndof >= spec.min_ndof { std::ops::ControlFlow::Break(()) } else { on_level(level.record) }
    })?;
    // the last level solved is the reference if it reached min_ndof (not if on_level stopped the loop)
    let reached = out.termination == adapt::Termination::StoppedByObserver && out.records.last().is_some_and(|r| r.ndof >= spec.min_ndof);
    Ok(reached.then(|| ReferenceField::new(out.mesh, out.solution.nodes.elements, out.solution.u)))
}
