//! The SOLVE step: one discrete Signorini solution (paper eq. 3.4) on a given mesh, with the
//! discrete contact force (eq. 4.5) and its KKT report.
//! The method: `docs/method.md`, sections "The discrete contact force" and "The certificate a solve passes before it reports".

use crate::contact::certify::{self, Certificate, KktError, KktInput, RigidMotionError};
use crate::contact::consistent::BodyForceFindings;
use crate::contact::{ContactError, ContactSolver, PdasIteration, PdasTermination, Timings};
use crate::fem::assembly::{self, DofMap, System};
use model::base::element::{self, Affine};
use model::level::sample::ContactSample;
use model::mesh::locate::Locator;
use model::mesh::{Mesh, MeshError, P2Nodes};
use model::problems::Problem;
use model::settings::pdas::{PdasOptions, Strategy};
use std::time::Instant;

#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error(transparent)]
    Contact(#[from] ContactError),
    #[error(transparent)]
    RigidMotion(#[from] RigidMotionError),
    #[error(transparent)]
    NotCertified(#[from] KktError),
    #[error(transparent)]
    Data(#[from] model::problems::BadDatum),
    #[error(transparent)]
    ContactData(#[from] Box<super::plausible::ContactDataError>),
    #[error(transparent)]
    Exact(#[from] super::consistent::ExactError),
    #[error(transparent)]
    PointReaction(#[from] Box<super::point::PointReactionError>),
    #[error(transparent)]
    PointOnDirichlet(#[from] Box<super::point::PointOnDirichletError>),
    /// No boundary edge of the mesh is in the contact part.
    #[error("the problem's contact part matches no boundary edge of the mesh: there is nothing to be in contact (the problem declares: {})", if .declared.is_empty() { "no parts by name".to_string() } else { .declared.join("; ") })]
    NoContact { declared: Vec<String> },
    /// A non-zero traction where no boundary edge of the mesh is Neumann: it would be ignored.
    #[error("{problem}: the traction (`traction`) is ({tx}, {ty}) at ({x}, {y}), but no boundary edge of the mesh is in the Neumann part (the problem declares: {}): a traction acts only on Gamma_N and would be ignored; remove `traction` or leave part of the boundary to Neumann", if .declared.is_empty() { "no parts by name".to_string() } else { .declared.join("; ") }, tx = model::base::number::shown(.value[0]), ty = model::base::number::shown(.value[1]), x = model::base::number::shown(.at[0]), y = model::base::number::shown(.at[1]))]
    UnusedTraction { problem: String, at: [f64; 2], value: [f64; 2], declared: Vec<String> },
    /// An entry of the assembled stiffness matrix or load vector overflowed f64's range while
    /// the data themselves are finite: the problem's scale, not its data, is at fault.
    #[error("{problem}: the assembled {what} has an entry that is not a finite number (overflow beyond f64's range, about 1.8e308) although every datum is finite: the material (mu = {mu}, zeta = {zeta}) or the loads are too large for this mesh; give them in other units (for example E in GPa instead of Pa) so that the stiffness entries, about mu times a mesh-independent factor, stay well inside the range", mu = model::base::number::shown(*.mu), zeta = model::base::number::shown(*.zeta))]
    Overflow { problem: String, what: &'static str, mu: f64, zeta: f64 },
    /// The assembled stiffness matrix is zero or has entries below f64's normal range
    /// (subnormal: they keep fewer digits, and products of them vanish): the material is too
    /// small in these units.
    #[error("{problem}: the assembled stiffness matrix has entries below f64's normal range (about 2.2e-308: subnormal numbers, which keep fewer digits and whose products vanish; the largest entry is {largest}): the material (mu = {mu}, zeta = {zeta}) is too small in these units for the factorisation to be trusted; give them in other units (for example E in MPa instead of Pa, or lengths in mm instead of m) so that the stiffness entries, about mu times a mesh-independent factor, stay well inside the range", largest = model::base::number::shown(*.largest), mu = model::base::number::shown(*.mu), zeta = model::base::number::shown(*.zeta))]
    Underflow { problem: String, largest: f64, mu: f64, zeta: f64 },
    /// The solve of a finite system gave a displacement, a product K u_h, or a product of forces
    /// and displacements (the scale complementarity is measured on) beyond f64's range: the
    /// loads are too large for the stiffness in these units.
    #[error("{problem}: {what} is not a finite number (overflow beyond f64's range, about 1.8e308) although the assembled system is finite: the loads (largest load-vector entry {load}) and the displacements they cause (largest |u_h| {u}, with the stiffness mu = {mu}) are too large for f64; give the data in other units (for example loads in kN instead of N, or E in Pa instead of GPa) so that the loads, the displacements and their products stay well inside the range", load = model::base::number::shown(*.load), u = model::base::number::shown(*.u), mu = model::base::number::shown(*.mu))]
    SolutionOverflow { problem: String, what: &'static str, load: f64, u: f64, mu: f64 },
}

/// Refuse an assembled system with an entry beyond f64's range ([`SolveError::Overflow`]): the
/// one check between the data (each finite, `Problem::bad_datum`) and the factorisation, which
/// would otherwise read the overflow as a matrix that is not positive definite.
/// It also refuses a stiffness matrix that is zero or holds a subnormal entry
/// ([`SolveError::Underflow`]), which the factorisation would read as a singular matrix or a
/// non-positive pivot. (A subnormal load entry is left alone: a load that decays to nothing far
/// from where it acts is not a scale mistake.)
fn check_finite(system: &assembly::System, problem: &dyn Problem) -> Result<(), SolveError> {
    use rayon::prelude::*;
    let m = problem.material();
    let what = if !system.matrix.values().par_iter().all(|v| v.is_finite()) {
        "stiffness matrix"
    } else if !system.rhs.iter().all(|v| v.is_finite()) {
        "load vector"
    } else {
        let largest = system.matrix.values().par_iter().fold(|| 0.0f64, |a, v| a.max(v.abs())).reduce(|| 0.0, f64::max);
        let subnormal = system.matrix.values().par_iter().any(|v| *v != 0.0 && !v.is_normal());
        if largest < f64::MIN_POSITIVE || subnormal {
            return Err(SolveError::Underflow { problem: super::plausible::problem_name(problem), largest, mu: m.mu, zeta: m.zeta });
        }
        return Ok(());
    };
    Err(SolveError::Overflow { problem: super::plausible::problem_name(problem), what, mu: m.mu, zeta: m.zeta })
}

/// Refuse a solution of the (finite) system whose values, or whose products that the
/// certificate ([`certify::certify`]) computes, are not finite ([`SolveError::SolutionOverflow`]):
/// u_h itself, K u_h, and the scale of complementarity, (max |F| + max |K u_h|) times
/// max(|u_h|, |chi_h|). The one check of the solve's result before it is certified, so that an
/// overflow is named as one and not as a KKT condition violated by NaN.
fn check_solution(u: &[f64], ku: &[f64], rhs: &[f64], gap: &[f64], problem: &dyn Problem) -> Result<(), SolveError> {
    let largest = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let (u_max, ku_max, load) = (largest(u), largest(ku), largest(rhs));
    let what = if !u.iter().all(|v| v.is_finite()) {
        "the discrete solution u_h"
    } else if !ku.iter().all(|v| v.is_finite()) {
        "the product K u_h of the stiffness matrix and the discrete solution"
    } else if !((load + ku_max) * u_max.max(largest(gap))).is_finite() {
        "the product of the forces and the displacements (max |F| times max |u_h|, the scale of complementarity lambda_p (chi_h - u_h.n))"
    } else {
        return Ok(());
    };
    let problem_name = super::plausible::problem_name(problem);
    Err(SolveError::SolutionOverflow { problem: problem_name, what, load, u: u_max, mu: problem.material().mu })
}

/// Refuse a traction that would be ignored: where no boundary edge is Neumann, the traction is
/// evaluated at the three P2 nodes of every boundary edge with the edge's outward normal, and
/// any non-zero value is an error naming `traction` (the default zero traction passes).
fn unused_traction(mesh: &Mesh, nodes: &P2Nodes, problem: &dyn Problem) -> Result<(), SolveError> {
    use model::problems::Part;
    if mesh.boundary.iter().any(|e| e.part == Part::Neumann) {
        return Ok(());
    }
    let outward = model::mesh::outward_normals(mesh, nodes);
    for (three, n) in nodes.boundary_nodes.iter().zip(outward) {
        for &p in three {
            let at = nodes.coords[p];
            let value = problem.traction(at, n);
            if value != [0.0, 0.0] {
                let problem_name = super::plausible::problem_name(problem);
                return Err(SolveError::UnusedTraction { problem: problem_name, at, value, declared: problem.declared_parts() });
            }
        }
    }
    Ok(())
}

/// A discrete solution and everything computed on the way.
pub struct DiscreteSolution {
    pub nodes: P2Nodes,
    pub dofs: DofMap,
    /// Cartesian displacement at every P2 node.
    pub u: Vec<[f64; 2]>,
    /// Nodal contact force lambda_p = L(phi_p n) - a(u_h, phi_p n) per contact node (in the order
    /// of `dofs.contact`), computed from the residual F - K u, element by element (eq. 4.5 /
    /// Lemma 5.2; [`assembly::stiffness_times`]).
    pub lambda: Vec<f64>,
    /// Per contact node, a bound of lambda_p's round-off ([`lambda_roundoff`]): a force below it
    /// is not measurably positive ([`DiscreteSolution::positive_forces`]).
    pub lambda_floor: Vec<f64>,
    /// Per point constraint (`dofs.points`), the Cartesian residual K u - F at its node
    /// ([`assembly::point_reactions`]): minus the reaction force at a prescribed component.
    pub reactions: Vec<[f64; 2]>,
    /// Active contact nodes (u_h(p).n = chi_h(p) enforced).
    pub active: Vec<bool>,
    pub pdas: Vec<PdasIteration>,
    pub termination: PdasTermination,
    /// Complementarity constant used.
    pub c: f64,
    /// Largest |F - K u| over the unknowns other than contact normals, relative to max |F|.
    pub free_residual: f64,
    /// max(|F|, |K u|) over the unknowns: the scale of the nodal vectors (F includes what the
    /// Dirichlet data put on the right-hand side), for relative checks of the KKT conditions.
    pub force_scale: f64,
    /// The round-off u_h carries: the largest Cartesian component, over the P2 nodes, of one
    /// step of iterative refinement in working precision ([`ContactSolver::correction`] for the
    /// residual F - K u_h computed element by element). No error of u_h below it is measurable.
    pub roundoff: f64,
    /// Per P2 node, the larger Cartesian component of the same refinement step: the round-off
    /// of each separate body of the mesh (`adapt::resolution` takes it per body, so that one
    /// body's rigid motion does not set another's round-off).
    pub roundoff_at: Vec<f64>,
    /// Per P2 node, its share c . (K c) of the energy a(c, c) of the same refinement step c
    /// (the Cartesian dot product of c and K c at the node; their sum over a body is that body's
    /// energy of c, at least 0): what u_h's round-off can do to the stresses
    /// (`adapt::resolution`).
    pub roundoff_energy_at: Vec<f64>,
    pub strategy: Strategy,
    /// The KKT conditions' relative values, each within [`certify::TOLERANCE`].
    pub certificate: Certificate,
    pub timings: SolveTimings,
    /// What the body-force check found on each triangle (None without an exact solution), for
    /// the next level's check ([`solve_from`]).
    pub body_force: Option<BodyForceFindings>,
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct SolveTimings {
    pub assembly: f64,
    /// The checks of the data before the assembly (part of `assembly`): the Dirichlet parts,
    /// the contact data, and an exact solution against the equations and boundary conditions.
    pub checks: f64,
    #[serde(flatten)]
    pub contact: Timings,
    /// The refinement step that measures [`DiscreteSolution::roundoff`].
    pub roundoff: f64,
    pub total: f64,
}

/// The KKT conditions at the contact nodes.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Kkt {
    /// max_p (u_h(p).n - chi_h(p))^+
    pub max_penetration: f64,
    /// min_p lambda_p
    pub min_lambda: f64,
    /// max_p |lambda_p (chi_h(p) - u_h(p).n)|
    pub max_complementarity: f64,
    /// max |lambda_p| over inactive nodes
    pub max_inactive_lambda: f64,
    /// Scale of nodal forces max(|F|, |K u_h|), for relative checks.
    pub force_scale: f64,
}

/// Assemble, factorise and solve the contact problem on `mesh`. `observe` sees every
/// active-set iteration. An active-set method that does not converge is an error naming the
/// iterations and the residual. A mesh on which the Dirichlet part does not hold every body is
/// refused before factorising, and the solution is returned only once its KKT conditions hold
/// to [`certify::TOLERANCE`] ([`crate::contact::certify`]).
///
/// ```rust
/// use model::mesh::MeshSpec;
/// use model::problems::{Ex72, Problem};
/// use model::settings::pdas::PdasOptions;
///
/// let mesh = MeshSpec::parse("structured:8").unwrap().build(&Ex72).unwrap();
/// let sol = signorini_numerics::contact::solve::solve(&mesh, &Ex72, &PdasOptions::default(), &mut |_| {}).unwrap();
/// assert_eq!(sol.active.len(), sol.dofs.contact.len());
/// assert!(sol.active_count() > 0 && sol.kkt().max_penetration <= 1e-12);
/// // too few iterations: a clear error
/// let few = PdasOptions { max_iterations: 1, ..Default::default() };
/// let err = signorini_numerics::contact::solve::solve(&mesh, &Ex72, &few, &mut |_| {}).err().unwrap();
/// assert!(err.to_string().contains("did not converge in 1 iterations"));
/// ```
pub fn solve(
    mesh: &Mesh,
    problem: &dyn Problem,
    options: &PdasOptions,
    observe: &mut dyn FnMut(&PdasIteration),
) -> Result<DiscreteSolution, SolveError> {
    solve_from(mesh, problem, options, None, observe)
}

/// [`solve`] on a refined mesh, its exact solution's body-force check taking the findings of the
/// triangles the refinement left as they were (`before`: [`BodyForceFindings::inherit`], released
/// once the check is done); the same verdict as checking every point.
pub fn solve_from(
    mesh: &Mesh,
    problem: &dyn Problem,
    options: &PdasOptions,
    before: Option<BodyForceFindings>,
    observe: &mut dyn FnMut(&PdasIteration),
) -> Result<DiscreteSolution, SolveError> {
    mesh.check()?;
    mesh.check_vertices(&problem.required_vertices())?;
    let t_all = Instant::now();
    let t0 = Instant::now();
    let nodes = P2Nodes::new(mesh);
    let dofs = DofMap::new(&nodes, problem);
    let t_checks = Instant::now();
    super::point::check_on_dirichlet(&nodes, &dofs, problem)?;
    certify::check_held(mesh, &nodes, &dofs, problem)?;
    super::plausible::check_contact_data(mesh, &nodes, &dofs, problem)?;
    let body_force = super::consistent::check_exact(problem, mesh, &nodes, before.as_ref())?;
    drop(before);
    if dofs.contact.is_empty() {
        return Err(SolveError::NoContact { declared: problem.declared_parts() });
    }
    unused_traction(mesh, &nodes, problem)?;
    let checks_time = t_checks.elapsed().as_secs_f64();
    let system = assembly::assemble(mesh, &nodes, &dofs, problem);
    // the data were evaluated where they are used (gap and normal in the DofMap, load and
    // Dirichlet data in the assembly): any that was not a finite number stops here
    if let Some(bad) = problem.bad_datum() {
        return Err(SolveError::Data(bad));
    }
    check_finite(&system, problem)?;
    let System { matrix, rhs, dirichlet } = system;
    let assembly_time = t0.elapsed().as_secs_f64();
    let strategy = options.strategy.unwrap_or(Strategy::auto(dofs.contact.len(), dofs.n_free));
    // the solver takes the matrix (and releases it before factorising, for the Schur strategy)
    let mut solver = ContactSolver::with_strategy(matrix, dofs.n_interior, &dofs.unknown_coords(&nodes), strategy)?;
    let gap: Vec<f64> = dofs.contact.iter().map(|c| c.gap).collect();
    let out = solver.solve_contact(&rhs, &gap, options, observe)?;
    // an overflowing u_h may also stop the active-set method: named before its convergence is
    check_solution(&out.u, &[], &rhs, &gap, problem)?;
    let out = out.converged()?;
    // the residual F - K u, element by element: zero at free unknowns, lambda_p at contact normals
    let assembly::StiffnessProduct { ku, magnitude, row_norm } = assembly::stiffness_times(mesh, &nodes, &dofs, problem.material(), &out.u);
    check_solution(&out.u, &ku, &rhs, &gap, problem)?;
    let normal_displacement = &out.u[dofs.n_interior..];
    let u_max = out.u.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let kkt = KktInput {
        nodes: &nodes,
        dofs: &dofs,
        rhs: &rhs,
        ku: &ku,
        magnitude: &magnitude,
        row_norm: &row_norm,
        u_max,
        normal_displacement,
        active: &out.active,
    };
    let certificate = certify::certify(&kkt, certify::TOLERANCE)?;
    // per contact row: the magnitude of the terms r_i sums
    let contact_terms: Vec<f64> = (dofs.n_interior..dofs.n_free).map(|i| rhs[i].abs() + magnitude[i]).collect();
    // the same over every unknown: a point constraint's reaction balances all the nodal forces
    let all_terms: f64 = rhs.iter().zip(&magnitude).map(|(f, m)| f.abs() + m).sum();
    drop((magnitude, row_norm));
    let r: Vec<f64> = rhs.iter().zip(&ku).map(|(f, k)| f - k).collect();
    let f_scale = rhs.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(f64::MIN_POSITIVE);
    let force_scale = ku.iter().fold(f_scale, |a, v| a.max(v.abs()));
    let free_residual = r[..dofs.n_interior].iter().fold(0.0f64, |a, v| a.max(v.abs())) / f_scale;
    let lambda = r[dofs.n_interior..].to_vec();
    let t_roundoff = Instant::now();
    let correction = solver.correction(&r, &out.active)?;
    let contact_timings = solver.timings.clone();
    drop(solver);
    let zero = vec![[0.0; 2]; dirichlet.len()];
    let correction_at = dofs.displacement(&correction, &zero);
    let roundoff_at: Vec<f64> = correction_at.iter().map(|v| v[0].abs().max(v[1].abs())).collect();
    let roundoff = roundoff_at.iter().fold(0.0f64, |a, v| a.max(*v));
    // how far one refinement step would move each lambda_p: (K c)_p
    let moved = assembly::stiffness_times(mesh, &nodes, &dofs, problem.material(), &correction).ku;
    let roundoff_energy_at =
        correction_at.iter().zip(dofs.displacement(&moved, &zero)).map(|(c, kc)| c[0] * kc[0] + c[1] * kc[1]).collect();
    let lambda_floor = contact_terms.iter().zip(&moved[dofs.n_interior..]).map(|(&terms, &kc)| lambda_roundoff(terms, kc)).collect();
    let u = dofs.displacement(&out.u, &dirichlet);
    let reactions = assembly::point_reactions(mesh, &nodes, &dofs, problem, &u, true);
    let moved_points = assembly::point_reactions(mesh, &nodes, &dofs, problem, &correction_at, false).residual;
    let point_bounds: Vec<[f64; 2]> = reactions
        .magnitude
        .iter()
        .zip(&moved_points)
        .map(|(m, kc)| std::array::from_fn(|i| lambda_roundoff(m[i] + all_terms, kc[i])))
        .collect();
    super::point::check_reactions(&nodes, &dofs, problem, &reactions.residual, &point_bounds, force_scale)?;
    let reactions = reactions.residual;
    let timings = SolveTimings {
        assembly: assembly_time,
        checks: checks_time,
        contact: contact_timings,
        roundoff: t_roundoff.elapsed().as_secs_f64(),
        total: t_all.elapsed().as_secs_f64(),
    };
    Ok(DiscreteSolution {
        nodes,
        dofs,
        u,
        lambda,
        lambda_floor,
        reactions,
        active: out.active,
        pdas: out.iterations,
        termination: out.termination,
        c: out.c,
        free_residual,
        force_scale,
        roundoff,
        roundoff_at,
        roundoff_energy_at,
        strategy,
        certificate,
        timings,
        body_force,
    })
}

/// Threshold, relative to the largest contact force, above which lambda_p counts as positive
/// ([`DiscreteSolution::positive_forces`]).
pub const LAMBDA_POSITIVE: f64 = 1e-10;

/// A bound of the round-off of lambda_p = F_p - (K u_h)_p, four times the sum of its two
/// sources: the sum itself, 32 eps times the magnitude of its terms `terms` = |F_p| +
/// (sum_T |K_T| |u_h|)_p; and u_h's own round-off, measured: one step of iterative refinement
/// c would move lambda_p by (K c)_p (`moved`). A bound sqrt(2) |K|_p max|c| instead, which
/// treats the error of u_h as arbitrary, is 1e4 to 1e6 times the round-off measured at inactive
/// nodes (fb, uniform levels to 8.4e6 unknowns) and hid real forces of 1e-10 near the edge of
/// the contact zone, 100 times their measured (K c)_p. At an inactive node lambda_p is round-off
/// and stays below the bound (tests/it/kkt.rs); the bound grows with a rigid translation of the
/// data as the round-off does.
pub fn lambda_roundoff(terms: f64, moved: f64) -> f64 {
    4.0 * (32.0 * f64::EPSILON * terms + moved.abs())
}

impl DiscreteSolution {
    /// Which contact nodes carry a positive discrete contact force lambda_p (Theorem 6.1's
    /// Lambda_h^C, eta_7): lambda_p above its own round-off (`lambda_floor`) and above
    /// [`LAMBDA_POSITIVE`] times the largest contact force. Both bounds are forces on the body:
    /// adding a rigid translation to the Dirichlet data and the gap moves neither (max(|F|, |K u|)
    /// would grow with the translation and hide every contact force).
    pub fn positive_forces(&self) -> Vec<bool> {
        let largest = self.lambda.iter().fold(0.0f64, |a, l| a.max(*l));
        self.lambda.iter().zip(&self.lambda_floor).map(|(l, floor)| *l > floor.max(LAMBDA_POSITIVE * largest)).collect()
    }

    /// u_h(p).n at contact node k.
    pub fn normal_displacement(&self, k: usize) -> f64 {
        let c = &self.dofs.contact[k];
        let u = self.u[c.node];
        u[0] * c.normal[0] + u[1] * c.normal[1]
    }

    pub fn kkt(&self) -> Kkt {
        let mut k = Kkt {
            max_penetration: 0.0,
            min_lambda: f64::INFINITY,
            max_complementarity: 0.0,
            max_inactive_lambda: 0.0,
            force_scale: self.force_scale,
        };
        for (i, c) in self.dofs.contact.iter().enumerate() {
            let gap = c.gap - self.normal_displacement(i);
            let l = self.lambda[i];
            k.max_penetration = k.max_penetration.max(-gap);
            k.min_lambda = k.min_lambda.min(l);
            k.max_complementarity = k.max_complementarity.max((l * gap).abs());
            if !self.active[i] {
                k.max_inactive_lambda = k.max_inactive_lambda.max(l.abs());
            }
        }
        if self.dofs.contact.is_empty() {
            k.min_lambda = 0.0;
        }
        k
    }

    pub fn active_count(&self) -> usize {
        self.active.iter().filter(|a| **a).count()
    }

    /// The contact zone as arc-length intervals along Gamma_C, one per connected active part.
    ///
    /// Gamma_C is split into its connected components, each walked counter-clockwise along the
    /// boundary (the direction of `Mesh::boundary`) from its start (for a closed component, from
    /// its edge of smallest first vertex); the arc length s of a P2 node is measured along the
    /// straight boundary edges from that start. A run of consecutive active contact nodes (vertices
    /// and edge midpoints, in that order) is one interval `[s_first, s_last]`; a node of Gamma_C
    /// that is no contact node (on the closure of Gamma_D) ends a run. On a closed component of
    /// length L, a run through its start is one interval `[s_first, s_last + L]` (its end past
    /// L: the arc is taken modulo L), listed first for that component. On the unit square s is x
    /// along the bottom from (0, 0) and y along the right side from (1, 0).
    pub fn contact_zones(&self) -> Vec<ContactInterval> {
        // contact edges: boundary edges whose midpoint is a contact node
        let edges: Vec<[usize; 3]> =
            self.nodes.boundary_nodes.iter().copied().filter(|b| self.dofs.contact_index[b[2]].is_some()).collect();
        let mut from: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
        let mut is_end = std::collections::HashSet::new();
        for (i, e) in edges.iter().enumerate() {
            from.insert(e[0], i);
            is_end.insert(e[1]);
        }
        let mut starts: Vec<usize> = (0..edges.len()).filter(|&i| !is_end.contains(&edges[i][0])).collect();
        let mut walked = vec![false; edges.len()];
        let mut zones = Vec::new();
        let mut component = 0;
        loop {
            let start = match starts.first() {
                Some(&i) => {
                    starts.remove(0);
                    i
                }
                // what is left are closed loops: start at the edge of smallest first vertex
                None => match (0..edges.len()).filter(|&i| !walked[i]).min_by_key(|&i| edges[i][0]) {
                    Some(i) => i,
                    None => break,
                },
            };
            let mut run: Option<ContactInterval> = None;
            let mut visit = |p: usize, s: f64, zones: &mut Vec<ContactInterval>| {
                let x = self.nodes.coords[p];
                if self.dofs.contact_index[p].is_some_and(|k| self.active[k]) {
                    match &mut run {
                        Some(z) => {
                            z.s[1] = s;
                            z.to = x;
                        }
                        None => run = Some(ContactInterval { component, s: [s, s], from: x, to: x }),
                    }
                } else if let Some(z) = run.take() {
                    zones.push(z);
                }
            };
            let first_zone = zones.len();
            let (mut e, mut s) = (start, 0.0);
            visit(edges[e][0], s, &mut zones);
            while !walked[e] {
                walked[e] = true;
                let [a, b, m] = edges[e];
                let len = model::mesh::dist(self.nodes.coords[a], self.nodes.coords[b]);
                visit(m, s + 0.5 * len, &mut zones);
                s += len;
                visit(b, s, &mut zones);
                match from.get(&b) {
                    Some(&next) if !walked[next] => e = next,
                    _ => break,
                }
            }
            // a closed loop walked back to its start: a run still open there and a first zone
            // from s = 0 are one arc through the start (not two zones, with zone_min/zone_max the
            // whole loop); it is written [s_first, s_last + L]
            let closed = edges[e][1] == edges[start][0];
            match (run, zones.get(first_zone).copied()) {
                (Some(last), Some(head)) if closed && head.s[0] == 0.0 => {
                    zones[first_zone] = ContactInterval { component, s: [last.s[0], s + head.s[1]], from: last.from, to: head.to };
                }
                (run, _) => zones.extend(run),
            }
            component += 1;
        }
        zones
    }

    /// [min, max] of the arc length over active contact nodes ([`Self::contact_zones`]): on the
    /// unit square, x on the bottom and y on the right side; on a closed loop of length L, max
    /// may exceed L where a zone wraps through the loop's start.
    pub fn contact_zone(&self) -> Option<[f64; 2]> {
        self.contact_zones().iter().fold(None, |z, c| Some(z.map_or(c.s, |[a, b]: [f64; 2]| [a.min(c.s[0]), b.max(c.s[1])])))
    }

    /// Values of u_h at the reference points `refs` of triangle `t`.
    pub fn eval_element(&self, mesh: &Mesh, t: usize, refs: &[[f64; 2]]) -> Vec<([f64; 2], [f64; 2])> {
        let map = Affine::new(mesh.corners(t));
        let el = &self.nodes.elements[t];
        refs.iter()
            .map(|r| {
                let phi = element::p2_values(r[0], r[1]);
                let mut v = [0.0; 2];
                for a in 0..element::N_NODES {
                    v[0] += phi[a] * self.u[el[a]][0];
                    v[1] += phi[a] * self.u[el[a]][1];
                }
                (map.map(*r), v)
            })
            .collect()
    }

    /// u_h at a physical point, or None outside the mesh (found through `locator`, the mesh's
    /// R*-tree).
    pub fn probe(&self, mesh: &Mesh, locator: &Locator, x: [f64; 2]) -> Option<[f64; 2]> {
        locator.locate(mesh, x).map(|h| self.eval_element(mesh, h.triangle, &[h.reference])[0].1)
    }
}

/// One connected active part of the contact zone: arc lengths `s = [start, end]` along
/// component `component` of Gamma_C (numbered in the order they are walked), and its end points.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ContactInterval {
    pub component: usize,
    pub s: [f64; 2],
    pub from: [f64; 2],
    pub to: [f64; 2],
}

/// The discrete contact force density lambda_h(p) = lambda_p / int psi_p ds (eq. 4.5, 4.6):
/// int psi_p ds is a quarter of the adjacent contact edge lengths for a vertex, half of its edge
/// for an edge midpoint.
pub fn contact_density(mesh: &Mesh, sol: &DiscreteSolution) -> Vec<f64> {
    let weight = contact_weights(mesh, sol, |vertex, len| if vertex { 0.25 * len } else { 0.5 * len });
    sol.lambda.iter().zip(&weight).map(|(l, w)| l / w).collect()
}

/// Per contact unknown, the sum over the contact edges at its node of `share(is_vertex, edge
/// length)`: the integral of the node's basis function over Gamma_C, for the basis `share` describes.
fn contact_weights(mesh: &Mesh, sol: &DiscreteSolution, share: impl Fn(bool, f64) -> f64) -> Vec<f64> {
    let mut weight = vec![0.0; sol.dofs.contact.len()];
    for (be, bn) in mesh.boundary.iter().zip(&sol.nodes.boundary_nodes) {
        if be.part != model::problems::Part::Contact {
            continue;
        }
        let len = model::mesh::dist(mesh.vertices[be.v[0]], mesh.vertices[be.v[1]]);
        for (i, &p) in bn.iter().enumerate() {
            if let Some(k) = sol.dofs.contact_index[p] {
                weight[k] += share(i < 2, len);
            }
        }
    }
    weight
}
/// The contact nodes with their nodal forces and the pressure p_h(p) = lambda_p / int psi_p ds, psi_p
/// the node's P2 basis function on Gamma_C (a sixth of each adjacent contact edge's length for a
/// vertex, two thirds of its edge for an edge midpoint): the weights for which a constant or
/// linear pressure p gives nodal forces lambda_p = int p psi_p ds with p_h = p at the nodes. The
/// paper's density (`contact_density`, eq. 4.5) divides by integrals of piecewise-linear hats
/// instead, which for a smooth pressure alternates between 2/3 p at vertices and 4/3 p at
/// midpoints: fine for its sign, not for a pressure profile.
pub fn contact_samples(mesh: &Mesh, sol: &DiscreteSolution) -> Vec<ContactSample> {
    let weight = contact_weights(mesh, sol, |vertex, len| if vertex { len / 6.0 } else { 2.0 * len / 3.0 });
    sol.dofs
        .contact
        .iter()
        .enumerate()
        .map(|(k, c)| ContactSample {
            x: sol.nodes.coords[c.node],
            lambda: sol.lambda[k],
            pressure: sol.lambda[k] / weight[k],
            active: sol.active[k],
        })
        .collect()
}
