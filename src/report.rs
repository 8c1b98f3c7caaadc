//! The record of one solve, as `signorini solve --json` prints it (CONTRACT.md), and the export of
//! a case for the NGSolve cross-check.

use crate::contact::PdasIteration;
use crate::estimate::{Estimate, EstimatorConfig, Terms};
use crate::mesh::{Mesh, io};
use crate::norms::LinfError;
use crate::records;
use crate::solve::{DiscreteSolution, Kkt, SolveTimings};
use anyhow::{Context, Result};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

#[derive(Clone, Debug, Serialize)]
pub struct Probe {
    pub x: f64,
    pub y: f64,
    /// None outside the domain.
    pub u: Option<[f64; 2]>,
}

#[derive(Clone, Debug, Serialize)]
pub struct SolveReport {
    pub problem: String,
    pub mesh: String,
    /// 2 x number of P2 nodes, Dirichlet nodes included.
    pub ndof: usize,
    pub ndof_free: usize,
    pub n_elements: usize,
    pub h_min: f64,
    pub h_max: f64,
    pub contact_nodes: usize,
    pub pdas_iterations: usize,
    pub active_nodes: usize,
    pub contact_zone: Option<[f64; 2]>,
    pub kkt: Kkt,
    /// Largest |F - K u_h| over unknowns other than contact normals, relative to max |F|.
    pub free_residual: f64,
    pub error: Option<LinfError>,
    pub error_sampling: ErrorSampling,
    pub estimator: Terms,
    pub estimator_config: EstimatorConfig,
    pub full_contact_nodes: usize,
    pub probes: Vec<Probe>,
    pub pdas_log: Vec<PdasIteration>,
    pub timings: SolveTimings,
}

/// Which points the error norms are taken over.
#[derive(Clone, Debug, Serialize)]
pub struct ErrorSampling {
    pub quadrature: String,
    pub dense: String,
}

impl SolveReport {
    pub fn new(problem: &str, mesh_name: &str, mesh: &Mesh, sol: &DiscreteSolution, error: Option<LinfError>, estimate: &Estimate, probes: &[[f64; 2]]) -> Self {
        let (h_min, h_max) = mesh.h_range();
        SolveReport {
            problem: problem.to_string(),
            mesh: mesh_name.to_string(),
            ndof: 2 * sol.nodes.len(),
            ndof_free: sol.dofs.n_free,
            n_elements: mesh.n_triangles(),
            h_min,
            h_max,
            contact_nodes: sol.dofs.contact.len(),
            pdas_iterations: sol.pdas.len(),
            active_nodes: sol.active_count(),
            contact_zone: sol.contact_zone(),
            kkt: sol.kkt(),
            free_residual: sol.free_residual,
            error,
            error_sampling: ErrorSampling {
                quadrature: crate::norms::Sampling::Quadrature.describe(),
                dense: crate::norms::Sampling::Dense.describe(),
            },
            estimator: estimate.terms,
            estimator_config: estimate.config,
            full_contact_nodes: estimate.full_contact_nodes,
            probes: probes.iter().map(|p| Probe { x: p[0], y: p[1], u: sol.probe(mesh, *p) }).collect(),
            pdas_log: sol.pdas.clone(),
            timings: sol.timings.clone(),
        }
    }

    /// A short human-readable summary.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "{} on {}: {} elements, ndof {} ({} free), h in [{:.3e}, {:.3e}]", self.problem, self.mesh, self.n_elements, self.ndof, self.ndof_free, self.h_min, self.h_max);
        let _ = writeln!(s, "contact: {} of {} nodes active, zone {:?}, {} active-set iterations", self.active_nodes, self.contact_nodes, self.contact_zone, self.pdas_iterations);
        let _ = writeln!(s, "KKT: penetration {:.2e}, min lambda {:.2e}, complementarity {:.2e}", self.kkt.max_penetration, self.kkt.min_lambda, self.kkt.max_complementarity);
        if let Some(e) = &self.error {
            let _ = writeln!(s, "error Linf: quadrature {:.4e}, dense {:.4e}, nodal {:.4e}", e.linf_quadrature, e.linf_dense, e.linf_nodal);
        }
        let e = &self.estimator;
        let _ = writeln!(s, "estimator: eta1..7 = {:.3e} {:.3e} {:.3e} {:.3e} {:.3e} {:.3e} {:.3e}, l_h {:.3}, eta_h {:.4e}, estimate (C0 = {}) {:.4e}", e.eta1, e.eta2, e.eta3, e.eta4, e.eta5, e.eta6, e.eta7, e.l_h, e.eta_h, e.c0, e.estimate);
        for p in &self.probes {
            let _ = writeln!(s, "u({}, {}) = {:?}", p.x, p.y, p.u);
        }
        let t = &self.timings;
        let _ = writeln!(s, "time: assembly {:.3}s, symbolic {:.3}s, numeric {:.3}s, schur {:.3}s, solves {:.3}s, active set {:.3}s, total {:.3}s", t.assembly, t.contact.symbolic, t.contact.numeric, t.contact.schur, t.contact.solves, t.contact.active_set, t.total);
        s
    }
}

/// Write `mesh.vtu` (displacement, contact force, active set) and `case.json` into `dir`.
pub fn export_case(dir: &Path, mesh: &Mesh, sol: &DiscreteSolution, report: &SolveReport) -> Result<()> {
    let n = sol.nodes.len();
    let mut lambda = vec![0.0; n];
    let mut active = vec![0i32; n];
    let mut contact = vec![0i32; n];
    for (k, c) in sol.dofs.contact.iter().enumerate() {
        lambda[c.node] = sol.lambda[k];
        active[c.node] = sol.active[k] as i32;
        contact[c.node] = 1;
    }
    let doc = io::vtu(
        mesh,
        &sol.nodes,
        &[("u", io::Field::Vector(&sol.u)), ("lambda", io::Field::Scalar(&lambda)), ("active", io::Field::Int(&active)), ("contact", io::Field::Int(&contact))],
        &[],
    );
    records::write_atomic(&dir.join("mesh.vtu"), doc.as_bytes()).with_context(|| format!("writing {}", dir.display()))?;
    records::write_json(&dir.join("case.json"), report).with_context(|| format!("writing {}", dir.display()))?;
    Ok(())
}
