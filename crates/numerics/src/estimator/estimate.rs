//! The supremum-norm a posteriori error estimator of the paper (Section 6, eq. 6.3; Section 7,
//! eq. 7.1), term by term, with the variants the ablation studies need.
//!
//! For every P2 node p (vertex or edge midpoint) with patch Omega_p (the elements containing p)
//! of diameter h_p:
//!
//! ```text
//! eta_{1,p} = h_p^2 ||f + div sigma(u_h)||_Linf(Omega_p)          (element residual s(u_h))
//! eta_{2,p} = h_p   ||[sigma(u_h)] n||_Linf(Gamma_{p,I})           (interior jumps, eq. 5.5)
//! eta_{3,p} = h_p   ||g - sigma(u_h) n||_Linf(Gamma_{p,N})         (Neumann residual), p on Gamma_N
//! eta_{4,p} = h_p   ||t . sigma(u_h) n||_Linf(Gamma_{p,C})         (tangential contact stress), p on Gamma_C
//! eta_{5,p} = h_p   ||n . sigma(u_h) n||_Linf(Gamma_{p,C})         (normal contact stress), p on Gamma_C
//!   (with `StressFrame::Cartesian`: the second and first Cartesian components of sigma(u_h) n)
//! eta_i = max_p eta_{i,p},
//! eta_6 = ||(u_h.n - chi)^+||_Linf(Gamma_C),   eta_7 = ||(chi - u_h.n)^+||_Linf(Lambda_h^C),
//! eta_h = l_h (eta_1 + ... + eta_5) + eta_6 + eta_7,   l_h = 1 + |log h_min|^2,
//! estimate = C_0 eta_h.
//! ```
//!
//! Gamma_{p,I} is the set of interior edges through p (the edge itself for a midpoint);
//! Gamma_{p,N} and Gamma_{p,C} are the Neumann and contact edges of the patch's elements.
//! Lambda_h^C is the union of Gamma_{p,C} over contact nodes with positive discrete contact force
//! lambda_p = <lambda_h, psi_p n>_h (Theorem 6.1); "positive" means above its own round-off and
//! above 1e-10 times the largest contact force (`DiscreteSolution::positive_forces`), since
//! inactive nodes carry round-off. Vector norms are the largest component.
//! Norms are maxima over a declared sampling: the element quadrature points or a dense lattice
//! (elements), Gauss points or equispaced points with the end points (edges).
//! The method: `docs/method.md`, section "ESTIMATE: eta_1 .. eta_7".

mod local;
pub mod repair;

use crate::contact::solve::DiscreteSolution;
use model::base::element::EDGE_VERTICES;
use model::level::terms::Terms;
use model::mesh::{Mesh, dist};
use model::problems::{Part, Problem};
use model::settings::estimator::{ContactTerm, EstimatorConfig};
use rayon::prelude::*;

/// Gauss points per edge for the "quadrature" sampling of edge terms.
pub const EDGE_GAUSS: usize = model::settings::sampling::EDGE_GAUSS;

/// The estimate and the per-element indicators used for marking.
#[derive(Clone, Debug)]
pub struct Estimate {
    pub terms: Terms,
    pub config: EstimatorConfig,
    /// eta_T = max over the six nodes p of T of l_h (eta_{1,p} + ... + eta_{5,p}), plus the local
    /// eta_6 and eta_7 on T's contact edges.
    pub element: Vec<f64>,
    /// Number of full-contact nodes (N_h^FC).
    pub full_contact_nodes: usize,
    /// The largest eta_{5,p} over full-contact nodes p, as this variant takes it there: |sigma_nn|
    /// (as written), 0 (without full-contact nodes), (sigma_nn)^+ (repaired). A diagnostic: it
    /// shows where the repaired term sees a tensile normal stress that the variant without
    /// full-contact nodes is blind to.
    pub eta5_full_contact: f64,
}

/// Evaluate the estimator on a discrete solution.
///
/// ```rust
/// use signorini_numerics::estimator::estimate;
/// use model::mesh::MeshSpec;
/// use model::problems::{Ex71, Problem};
/// use model::settings::estimator::EstimatorConfig;
/// use model::settings::pdas::PdasOptions;
///
/// let mesh = MeshSpec::parse("structured:4").unwrap().build(&Ex71).unwrap();
/// let sol = signorini_numerics::contact::solve::solve(&mesh, &Ex71, &PdasOptions::default(), &mut |_| {}).unwrap();
/// let est = estimate::estimate(&mesh, &Ex71, &sol, &EstimatorConfig::default());
/// assert_eq!(est.element.len(), mesh.n_triangles());
/// // an upper bound of the error (reliability), here with the exact solution known
/// let u = |x: [f64; 2]| Ex71.exact().unwrap().u(x);
/// assert!(est.terms.estimate >= signorini_numerics::contact::norms::linf_error(&mesh, &sol, &u).linf_quadrature);
/// ```
pub fn estimate(mesh: &Mesh, problem: &dyn Problem, sol: &DiscreteSolution, config: &EstimatorConfig) -> Estimate {
    with_node_terms(mesh, problem, sol, config, |nodal, local, lambda_c, l_h| {
        let (terms, full_contact_nodes, eta5_full_contact) = sum_terms(nodal, l_h, config.c0);
        let element = element_indicators(mesh, sol, nodal, local, lambda_c, l_h);
        Estimate { terms, config: *config, element, full_contact_nodes, eta5_full_contact }
    })
}

/// (eta_{1,p}, ..., eta_{5,p}) of every P2 node p, scaled by h_p^2 and h_p as [`estimate`] takes
/// their maxima (eta_i = max_p eta_{i,p}), with the variant's eta_{5,p} at full-contact nodes.
/// Computed again, not kept by [`estimate`]: `signorini export` writes them for the cross-check.
pub fn node_terms(mesh: &Mesh, problem: &dyn Problem, sol: &DiscreteSolution, config: &EstimatorConfig) -> Vec<[f64; 5]> {
    with_node_terms(mesh, problem, sol, config, |nodal, _, _, _| nodal.iter().map(|n| n.scaled).collect())
}

/// The nodes' terms, the element locals, Lambda_h^C and l_h, handed to `then`.
fn with_node_terms<R>(
    mesh: &Mesh,
    problem: &dyn Problem,
    sol: &DiscreteSolution,
    config: &EstimatorConfig,
    then: impl FnOnce(&[NodeTerms], &[local::ElementLocal], &LambdaC, f64) -> R,
) -> R {
    let edge_s = local::edge_samples(config.sampling);
    let stress = local::vertex_stresses(mesh, problem, sol);
    let local = local::element_locals(mesh, problem, sol, config, &stress, &edge_s);
    let jump = local::interior_jumps(mesh, sol, &stress, &edge_s);
    let patches = Patches::new(mesh, sol);
    let positive_forces = sol.positive_forces();
    let positive = |p: usize| sol.dofs.contact_index[p].is_some_and(|k| positive_forces[k]);
    let lambda_c = LambdaC::new(mesh, sol, config, &positive);
    let (h_min, _) = mesh.h_range();
    let l_h = config.log_factor.value(h_min);
    let nodal: Vec<NodeTerms> =
        (0..sol.nodes.len()).into_par_iter().map(|p| node_terms_at(mesh, sol, config, &patches, &local, &jump, &lambda_c, p)).collect();
    then(&nodal, &local, &lambda_c, l_h)
}

/// Which contact edges eta_7 is taken over (Lambda_h^C): those through a contact node with
/// positive discrete contact force (Theorem 6.1), or the narrower set of the repaired variant.
enum LambdaC<'a> {
    Positive(&'a (dyn Fn(usize) -> bool + Sync)),
    Repaired(Vec<bool>),
}

impl<'a> LambdaC<'a> {
    fn new(mesh: &Mesh, sol: &DiscreteSolution, config: &EstimatorConfig, positive: &'a (dyn Fn(usize) -> bool + Sync)) -> Self {
        if config.contact_term == ContactTerm::TensileOnFullContact {
            LambdaC::Repaired(repair::narrow_lambda(mesh, sol, positive))
        } else {
            LambdaC::Positive(positive)
        }
    }

    /// Whether eta_{7,p} at node p takes boundary edge `bi` (a contact edge of p's patch).
    fn at_node(&self, p: usize, bi: usize) -> bool {
        match self {
            LambdaC::Positive(positive) => positive(p),
            LambdaC::Repaired(edges) => edges[bi],
        }
    }

    /// Whether element `el`'s indicator takes its contact edge `bi` (with nodes `bn`).
    fn at_element(&self, el: &[usize], bn: &[usize], bi: usize) -> bool {
        match self {
            LambdaC::Positive(positive) => el.iter().any(|&p| positive(p)) || bn.iter().any(|&p| positive(p)),
            LambdaC::Repaired(edges) => edges[bi],
        }
    }
}

/// Node -> elements of its patch Omega_p, and h_p, the patch's diameter.
struct Patches {
    start: Vec<usize>,
    elements: Vec<usize>,
    h_p: Vec<f64>,
}

impl Patches {
    fn new(mesh: &Mesh, sol: &DiscreteSolution) -> Self {
        let nodes = &sol.nodes;
        let n_nodes = nodes.len();
        let mut start = vec![0usize; n_nodes + 1];
        for el in &nodes.elements {
            for &p in el {
                start[p + 1] += 1;
            }
        }
        for p in 0..n_nodes {
            start[p + 1] += start[p];
        }
        let mut elements = vec![0usize; start[n_nodes]];
        let mut fill = start.clone();
        for (t, el) in nodes.elements.iter().enumerate() {
            for &p in el {
                elements[fill[p]] = t;
                fill[p] += 1;
            }
        }
        let h_p = (0..n_nodes)
            .into_par_iter()
            .map(|p| {
                let mut verts: Vec<usize> = elements[start[p]..start[p + 1]].iter().flat_map(|&t| mesh.triangles[t]).collect();
                verts.sort_unstable();
                verts.dedup();
                let mut d = 0.0f64;
                for (k, &a) in verts.iter().enumerate() {
                    for &b in &verts[k + 1..] {
                        d = d.max(dist(mesh.vertices[a], mesh.vertices[b]));
                    }
                }
                d
            })
            .collect();
        Patches { start, elements, h_p }
    }

    fn of(&self, p: usize) -> &[usize] {
        &self.elements[self.start[p]..self.start[p + 1]]
    }
}

/// One node's terms: (eta_{1,p}, ..., eta_{5,p}) already scaled by h_p^2 or h_p, whether p is
/// a full-contact node, and its eta_6 and eta_7 parts.
struct NodeTerms {
    scaled: [f64; 5],
    full: bool,
    penetration: f64,
    separation: f64,
}

/// Node p's terms, gathered over its patch.
#[allow(clippy::too_many_arguments)]
fn node_terms_at(
    mesh: &Mesh,
    sol: &DiscreteSolution,
    config: &EstimatorConfig,
    patches: &Patches,
    local: &[local::ElementLocal],
    jump: &[f64],
    lambda_c: &LambdaC,
    p: usize,
) -> NodeTerms {
    let nodes = &sol.nodes;
    let nv = nodes.n_vertices;
    let els = patches.of(p);
    let hp = patches.h_p[p];
    let mut e = [0.0f64; 5];
    let part = nodes.part[p];
    let mut full_contact = true;
    let mut has_contact_edge = false;
    let (mut pen, mut sep) = (0.0f64, 0.0f64);
    let mut tensile = 0.0f64;
    for &t in els {
        e[0] = e[0].max(local[t].residual);
        for le in 0..3 {
            let Some(bi) = nodes.element_boundary[t][le] else { continue };
            match mesh.boundary[bi].part {
                Part::Neumann if part == Some(Part::Neumann) => e[2] = e[2].max(local[t].neumann[le]),
                // the residual of the components Gamma_D leaves free (zero where it prescribes both)
                Part::Dirichlet if part == Some(Part::Dirichlet) => e[2] = e[2].max(local[t].neumann[le]),
                Part::Contact if part == Some(Part::Contact) => {
                    has_contact_edge = true;
                    e[3] = e[3].max(local[t].tangential[le]);
                    e[4] = e[4].max(local[t].normal[le]);
                    tensile = tensile.max(local[t].tensile[le]);
                    let bn = nodes.boundary_nodes[bi];
                    full_contact &= bn.iter().all(|&q| sol.dofs.contact_index[q].is_some_and(|k| sol.active[k]));
                    pen = pen.max(local[t].penetration[le]);
                    if lambda_c.at_node(p, bi) {
                        sep = sep.max(local[t].separation[le]);
                    }
                }
                _ => {}
            }
        }
    }
    // interior jumps on the edges through p (a vertex) or on p's own edge (a midpoint)
    if p >= nv {
        e[1] = jump[p - nv];
    } else {
        for &t in els {
            let el = &nodes.elements[t];
            for (le, [i, j]) in EDGE_VERTICES.iter().enumerate() {
                if el[*i] == p || el[*j] == p {
                    e[1] = e[1].max(jump[el[3 + le] - nv]);
                }
            }
        }
    }
    let full = has_contact_edge && full_contact;
    if config.contact_term == ContactTerm::WithoutFullContact && full {
        e[4] = 0.0;
    }
    if config.contact_term == ContactTerm::TensileOnFullContact && full {
        e[4] = tensile;
    }
    let scaled = [hp * hp * e[0], hp * e[1], hp * e[2], hp * e[3], hp * e[4]];
    NodeTerms { scaled, full, penetration: pen, separation: sep }
}

/// eta_1..eta_7 as maxima over the nodes, eta_h and the estimate (eq. 6.3); also the number of
/// full-contact nodes and the largest eta_{5,p} among them.
fn sum_terms(nodal: &[NodeTerms], l_h: f64, c0: f64) -> (Terms, usize, f64) {
    let mut terms = Terms { l_h, c0, ..Default::default() };
    let mut full_contact_nodes = 0;
    let mut eta5_full_contact = 0.0f64;
    for n in nodal {
        let e = &n.scaled;
        terms.eta1 = terms.eta1.max(e[0]);
        terms.eta2 = terms.eta2.max(e[1]);
        terms.eta3 = terms.eta3.max(e[2]);
        terms.eta4 = terms.eta4.max(e[3]);
        terms.eta5 = terms.eta5.max(e[4]);
        terms.eta6 = terms.eta6.max(n.penetration);
        terms.eta7 = terms.eta7.max(n.separation);
        full_contact_nodes += n.full as usize;
        if n.full {
            eta5_full_contact = eta5_full_contact.max(e[4]);
        }
    }
    terms.psi = terms.eta1 + terms.eta2 + terms.eta3 + terms.eta4 + terms.eta5;
    terms.eta_h = l_h * terms.psi + terms.eta6 + terms.eta7;
    terms.estimate = c0 * terms.eta_h;
    (terms, full_contact_nodes, eta5_full_contact)
}

/// The marking indicator of every element: the largest l_h (eta_{1,p} + ... + eta_{5,p}) over its
/// six nodes, plus eta_6 and eta_7 on its own contact edges.
fn element_indicators(
    mesh: &Mesh,
    sol: &DiscreteSolution,
    nodal: &[NodeTerms],
    local: &[local::ElementLocal],
    lambda_c: &LambdaC,
    l_h: f64,
) -> Vec<f64> {
    let nodes = &sol.nodes;
    (0..mesh.n_triangles())
        .into_par_iter()
        .map(|t| {
            let el = &nodes.elements[t];
            let node_part = el.iter().map(|&p| l_h * nodal[p].scaled.iter().sum::<f64>()).fold(0.0, f64::max);
            let mut contact = 0.0f64;
            for le in 0..3 {
                let Some(bi) = nodes.element_boundary[t][le] else { continue };
                if mesh.boundary[bi].part != Part::Contact {
                    continue;
                }
                let bn = nodes.boundary_nodes[bi];
                let sep = if lambda_c.at_element(el, &bn, bi) { local[t].separation[le].max(0.0) } else { 0.0 };
                contact = contact.max(local[t].penetration[le].max(0.0) + sep);
            }
            node_part + contact
        })
        .collect()
}
