//! The record of one solve, as `signorini solve --json` prints it ([`SolveReport`]: its fields
//! are the JSON keys; `tests/it/cli_refusals.rs` checks the ones scripts rely on), and the export of a
//! case for the NGSolve cross-check.

use ::store::records;
use anyhow::Result;
use model::level::terms::Terms;
use model::mesh::locate::Locator;
use model::mesh::{Mesh, io};
use model::settings::estimator::EstimatorConfig;
use numerics::contact::PdasIteration;
use numerics::contact::norms::LinfError;
use numerics::contact::solve::{ContactInterval, DiscreteSolution, Kkt, SolveTimings};
use numerics::estimator::estimate::Estimate;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// u_h at a point.
#[derive(Clone, Debug, Serialize)]
pub struct Probe {
    pub x: f64,
    pub y: f64,
    pub u: [f64; 2],
}

/// A point to evaluate u_h at that is not one.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProbeError {
    #[error("malformed --probe '{0}': expected X,Y with two finite numbers, e.g. 0.5,0.25")]
    Malformed(String),
    #[error("--probe {},{}: the point is outside the mesh (no triangle of the mesh contains it; u_h is defined on the triangles only, and where the boundary is curved the straight-sided triangles leave out the thin part between each boundary edge and the curve)", model::base::number::shown(*x), model::base::number::shown(*y))]
    Outside { x: f64, y: f64 },
}

/// Read a point `X,Y` (finite numbers; spaces around them are allowed).
pub fn parse_probe(s: &str) -> Result<[f64; 2], ProbeError> {
    let bad = || ProbeError::Malformed(s.to_string());
    let (x, y) = s.split_once(',').ok_or_else(bad)?;
    let x: f64 = x.trim().parse().map_err(|_| bad())?;
    let y: f64 = y.trim().parse().map_err(|_| bad())?;
    if !(x.is_finite() && y.is_finite()) {
        return Err(bad());
    }
    Ok([x, y])
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
    /// [min, max] of the arc length along Gamma_C over the active contact nodes.
    pub contact_zone: Option<[f64; 2]>,
    /// The contact zone as arc-length intervals along Gamma_C, one per connected active part
    /// ([`DiscreteSolution::contact_zones`]).
    pub contact_zones: Vec<ContactInterval>,
    pub kkt: Kkt,
    /// The KKT conditions relative to their round-off scales, each within `certificate_tolerance`
    /// (a solve that misses one is an error, [`numerics::contact::certify`]).
    pub certificate: numerics::contact::certify::Certificate,
    pub certificate_tolerance: f64,
    /// Largest |F - K u_h| over unknowns other than contact normals, relative to max |F|.
    pub free_residual: f64,
    /// u_h's round-off floor ([`DiscreteSolution::roundoff`]: one step of iterative
    /// refinement), as a level record's `roundoff_floor`: an estimate near it measures round-off
    /// (the warning `solve` prints on stderr then), so a JSON reader can tell too.
    pub roundoff_floor: f64,
    pub error: Option<LinfError>,
    pub error_sampling: NormPoints,
    pub estimator: Terms,
    pub estimator_config: EstimatorConfig,
    pub full_contact_nodes: usize,
    pub probes: Vec<Probe>,
    pub pdas_log: Vec<PdasIteration>,
    pub timings: SolveTimings,
    /// What the solve's numbers keep fewer digits of than they should, or that its estimate is
    /// at round-off (`adapt::resolution`, which the caller asks; the same sentences `solve`
    /// writes to standard error).
    pub warnings: Vec<String>,
}

/// Which points the error norms are taken over.
#[derive(Clone, Debug, Serialize)]
pub struct NormPoints {
    pub quadrature: String,
    pub dense: String,
}

impl SolveReport {
    /// The report of one solve; an error if a probe is outside the mesh.
    pub fn new(
        problem: &str,
        mesh_name: &str,
        mesh: &Mesh,
        sol: &DiscreteSolution,
        error: Option<LinfError>,
        estimate: &Estimate,
        probes: &[[f64; 2]],
    ) -> Result<Self, ProbeError> {
        let (h_min, h_max) = mesh.h_range();
        let locator = Locator::new(mesh);
        let probes = probes
            .iter()
            .map(|&[x, y]| sol.probe(mesh, &locator, [x, y]).map(|u| Probe { x, y, u }).ok_or(ProbeError::Outside { x, y }))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(SolveReport {
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
            contact_zones: sol.contact_zones(),
            kkt: sol.kkt(),
            certificate: sol.certificate,
            certificate_tolerance: numerics::contact::certify::TOLERANCE,
            free_residual: sol.free_residual,
            roundoff_floor: sol.roundoff,
            error,
            error_sampling: NormPoints {
                quadrature: model::settings::sampling::Sampling::Quadrature.describe(),
                dense: model::settings::sampling::Sampling::Dense.describe(),
            },
            estimator: estimate.terms,
            estimator_config: estimate.config,
            full_contact_nodes: estimate.full_contact_nodes,
            probes,
            pdas_log: sol.pdas.clone(),
            timings: sol.timings.clone(),
            warnings: Vec::new(),
        })
    }

    /// A short human-readable summary.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{} on {}: {} elements, ndof {} ({} free), h in [{:.3e}, {:.3e}]",
            self.problem, self.mesh, self.n_elements, self.ndof, self.ndof_free, self.h_min, self.h_max
        );
        let interval = |z: &ContactInterval| {
            let component =
                if self.contact_zones.iter().any(|z| z.component > 0) { format!(" of part {}", z.component + 1) } else { String::new() };
            format!("[{}, {}]{component}", model::base::number::significant(z.s[0]), model::base::number::significant(z.s[1]))
        };
        let zone = match self.contact_zones.as_slice() {
            [] => "no contact zone".to_string(),
            [z] => format!("contact zone {} along Gamma_C (arc length)", interval(z)),
            zs => format!("contact zones {} along Gamma_C (arc length)", zs.iter().map(interval).collect::<Vec<_>>().join(", ")),
        };
        let _ = writeln!(
            s,
            "contact: {} of {} nodes active, {zone}, {} active-set iteration{}",
            self.active_nodes,
            self.contact_nodes,
            self.pdas_iterations,
            if self.pdas_iterations == 1 { "" } else { "s" }
        );
        let _ = writeln!(
            s,
            "KKT: penetration {:.2e}, min lambda {:.2e}, complementarity {:.2e}",
            self.kkt.max_penetration, self.kkt.min_lambda, self.kkt.max_complementarity
        );
        let c = &self.certificate;
        let _ = writeln!(
            s,
            "certified: relative to round-off scales, equations {:.1e}, sign {:.1e}, penetration {:.1e}, complementarity {:.1e} (tolerance {:.0e})",
            c.equations, c.sign, c.penetration, c.complementarity, self.certificate_tolerance
        );
        match &self.error {
            Some(e) => {
                let _ =
                    writeln!(s, "error Linf: quadrature {:.4e}, dense {:.4e}, nodal {:.4e}", e.linf_quadrature, e.linf_dense, e.linf_nodal);
            }
            None => {
                let _ = writeln!(s, "error: not measured ({} has no exact solution)", self.problem);
            }
        }
        let e = &self.estimator;
        let _ = writeln!(
            s,
            "estimator: eta1..7 = {:.3e} {:.3e} {:.3e} {:.3e} {:.3e} {:.3e} {:.3e}, l_h {:.3}, eta_h {:.4e}, estimate (C0 = {}) {:.4e}",
            e.eta1, e.eta2, e.eta3, e.eta4, e.eta5, e.eta6, e.eta7, e.l_h, e.eta_h, e.c0, e.estimate
        );
        for p in &self.probes {
            let _ = writeln!(s, "u_h({}, {}) = ({:.6e}, {:.6e})", p.x, p.y, p.u[0], p.u[1]);
        }
        let t = &self.timings;
        let _ = writeln!(
            s,
            "time: assembly {:.3}s, symbolic {:.3}s, numeric {:.3}s, schur {:.3}s, solves {:.3}s, active set {:.3}s, total {:.3}s",
            t.assembly, t.contact.symbolic, t.contact.numeric, t.contact.schur, t.contact.solves, t.contact.active_set, t.total
        );
        s
    }
}

/// The VTU document of a solved mesh, as ParaView and meshio read it: per P2 node the
/// displacement `u`, the contact force `lambda`, `active` and `contact` (1 on contact nodes); per
/// triangle the estimator's element indicator `indicator` (eta_T, what the marking compares).
pub fn solution_vtu(mesh: &Mesh, sol: &DiscreteSolution, indicator: &[f64]) -> String {
    solution_vtu_with(mesh, sol, indicator, None)
}

/// [`solution_vtu`], with `nodal` (the estimator's [`crate::estimate::node_terms`]) also the point
/// data `eta1` .. `eta5` (eta_{i,p}, scaled by h_p^2 or h_p) and `lambda_floor`, the round-off
/// bound of each contact force (`DiscreteSolution::lambda_floor`, 0 off the contact nodes), which
/// decides with `lambda` which forces are positive (`DiscreteSolution::positive_forces`:
/// Lambda_h^C of eta_7). The exported case carries them for the cross-check of the estimator.
fn solution_vtu_with(mesh: &Mesh, sol: &DiscreteSolution, indicator: &[f64], nodal: Option<&[[f64; 5]]>) -> String {
    let n = sol.nodes.len();
    let (mut lambda, mut active, mut contact) = (vec![0.0; n], vec![0i32; n], vec![0i32; n]);
    let mut lambda_floor = vec![0.0; n];
    for (k, c) in sol.dofs.contact.iter().enumerate() {
        lambda[c.node] = sol.lambda[k];
        lambda_floor[c.node] = sol.lambda_floor[k];
        active[c.node] = sol.active[k] as i32;
        contact[c.node] = 1;
    }
    let mut point = vec![
        ("u", io::Field::Vector(&sol.u)),
        ("lambda", io::Field::Scalar(&lambda)),
        ("active", io::Field::Int(&active)),
        ("contact", io::Field::Int(&contact)),
    ];
    let terms: Vec<Vec<f64>> = (0..5).map(|i| nodal.map_or_else(Vec::new, |t| t.iter().map(|e| e[i]).collect())).collect();
    if nodal.is_some() {
        point.push(("lambda_floor", io::Field::Scalar(&lambda_floor)));
        for (name, t) in ["eta1", "eta2", "eta3", "eta4", "eta5"].into_iter().zip(&terms) {
            point.push((name, io::Field::Scalar(t)));
        }
    }
    io::vtu(mesh, &sol.nodes, &point, &[("indicator", io::Field::Scalar(indicator))])
}

/// Write `mesh.vtu` ([`solution_vtu`]: displacement, contact force, active set, element
/// indicators; and per node the estimator's terms `nodal` and the contact forces' round-off
/// bounds) and `case.json` into `dir`; returns the files written.
pub fn export_case(
    dir: &Path,
    mesh: &Mesh,
    sol: &DiscreteSolution,
    indicator: &[f64],
    nodal: &[[f64; 5]],
    report: &SolveReport,
) -> Result<Vec<std::path::PathBuf>> {
    let (vtu, case) = (dir.join("mesh.vtu"), dir.join("case.json"));
    // one batch: both files are checked and written before either lands, so a target that
    // cannot be replaced (a named pipe where case.json goes) leaves no half-written export
    let mut batch = records::Batch::default();
    batch.add(&vtu, solution_vtu_with(mesh, sol, indicator, Some(nodal)).as_bytes())?;
    batch.add_json(&case, report)?;
    batch.commit()?;
    Ok(vec![vtu, case])
}
