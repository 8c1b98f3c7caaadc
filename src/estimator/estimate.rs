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
//! lambda_p = <lambda_h, psi_p n>_h (Theorem 6.1); "positive" means above `LAMBDA_POSITIVE` times
//! the scale of nodal forces max(|F|, |K u_h|), since inactive nodes carry round-off. Vector norms are the largest component.
//! Norms are maxima over a declared sampling: the element quadrature points or a dense lattice
//! (elements), Gauss points or equispaced points with the end points (edges).

pub mod repair;

use crate::assembly::edge_basis;
use crate::element::{self, Affine, EDGE_VERTICES, N_NODES};
use crate::mesh::{Mesh, Part, dist};
use crate::norms::Sampling;
use crate::problems::{Material, Problem};
use crate::solve::DiscreteSolution;
use rayon::prelude::*;

/// Threshold, relative to the force scale, above which lambda_p counts as positive (Lambda_h^C).
pub const LAMBDA_POSITIVE: f64 = 1e-10;
/// Gauss points per edge for the "quadrature" sampling of edge terms.
pub const EDGE_GAUSS: usize = 3;

/// Which contact nodes eta_5 is taken over.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactTerm {
    /// All contact nodes, as the paper writes eta_5.
    AsWritten,
    /// Without full-contact nodes N_h^FC (u_h.n = chi_h on all of Gamma_{p,C}), as in
    /// Krause–Veeser–Walloth. At a node in full contact the exact normal stress is a compressive
    /// contact pressure, not an error: taken over all contact nodes, eta_5 measures that pressure
    /// and decays only like h (measured: the `contact_term_ablation` study).
    WithoutFullContact,
    /// The repaired contact terms (beyond the paper): at a full-contact node eta_5 takes only the
    /// tensile part (n . sigma(u_h) n)^+ of the normal stress, at other contact nodes it is as
    /// written; eta_7 is taken over a narrower Lambda_h^C, the full-contact edges (all three
    /// nodes active) and the edges through an active node with positive contact force that lies
    /// on no full-contact edge (an isolated active node). See [`repair`] for why, and for the
    /// step of the proof that is open.
    TensileOnFullContact,
}

/// The log factor l_h multiplying the residual terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LogFactor {
    /// 1 + |log h_min|^2 (eq. 6.3)
    Squared,
    /// 1 + |log h_min|
    Linear,
    /// 1
    One,
}

impl LogFactor {
    pub fn value(self, h_min: f64) -> f64 {
        let l = h_min.ln().abs();
        match self {
            LogFactor::Squared => 1.0 + l * l,
            LogFactor::Linear => 1.0 + l,
            LogFactor::One => 1.0,
        }
    }
}

/// How the paper's sigma-hat_1, sigma-hat_2 (the components of sigma(u_h) n in eta_5 and eta_4)
/// are read. The paper defines sigma-hat_1 as the first component of sigma n "in a frame where
/// e_1 is the normal"; read literally as the first Cartesian component it is -sigma_12 on the
/// bottom edge of Example 7.1 (n = (0, -1)) and the normal stress sigma_11 on Example 7.2's
/// right edge (n = (1, 0)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StressFrame {
    /// sigma-hat_1 = n . sigma n (normal stress, eta_5), sigma-hat_2 = t . sigma n (eta_4).
    #[default]
    Normal,
    /// sigma-hat_1 = (sigma n)_1 (eta_5), sigma-hat_2 = (sigma n)_2 (eta_4): the Cartesian components.
    Cartesian,
}

/// A declared estimator variant.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EstimatorConfig {
    pub contact_term: ContactTerm,
    pub log_factor: LogFactor,
    /// The constant replacing the hidden one of Theorem 6.1 (Section 7: 0.45).
    pub c0: f64,
    pub sampling: Sampling,
    /// Reading of sigma-hat_1, sigma-hat_2 in eta_4, eta_5 (absent in older records: normal).
    #[serde(default)]
    pub stress_frame: StressFrame,
}

impl Default for EstimatorConfig {
    fn default() -> Self {
        EstimatorConfig {
            contact_term: ContactTerm::AsWritten,
            log_factor: LogFactor::Squared,
            c0: 0.45,
            sampling: Sampling::Quadrature,
            stress_frame: StressFrame::Normal,
        }
    }
}

/// The estimator's terms (the `estimator` object of `signorini solve --json`).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Terms {
    pub eta1: f64,
    pub eta2: f64,
    pub eta3: f64,
    pub eta4: f64,
    pub eta5: f64,
    pub eta6: f64,
    pub eta7: f64,
    pub l_h: f64,
    /// Psi = eta_1 + ... + eta_5
    pub psi: f64,
    pub eta_h: f64,
    pub c0: f64,
    /// C_0 eta_h, the quantity compared with the error
    pub estimate: f64,
}

impl Terms {
    pub fn eta(&self) -> [f64; 7] {
        [self.eta1, self.eta2, self.eta3, self.eta4, self.eta5, self.eta6, self.eta7]
    }
}

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

/// Local (per element) quantities before they are gathered on patches.
#[derive(Clone, Copy, Default)]
struct ElementLocal {
    /// max |f + div sigma(u_h)| over the element
    residual: f64,
    /// per local edge: max |g - sigma n| (Neumann), or on contact edges the max |sigma_t|, max |sigma_n|
    /// and max (sigma_n)^+ (the tensile part)
    neumann: [f64; 3],
    tangential: [f64; 3],
    normal: [f64; 3],
    tensile: [f64; 3],
    /// per local edge on Gamma_C: max (u.n - chi)^+ and max (chi - u.n)^+
    penetration: [f64; 3],
    separation: [f64; 3],
}

/// Stress (s11, s12, s22) of u_h at the three vertices of element t.
fn vertex_stress(material: Material, map: &Affine, u: &[[f64; 2]; N_NODES]) -> [[f64; 3]; 3] {
    let refs = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    refs.map(|r| {
        let g = element::p2_gradients(r[0], r[1]);
        let mut grad = [[0.0; 2]; 2];
        for a in 0..N_NODES {
            let ga = map.grad(g[a]);
            for i in 0..2 {
                for j in 0..2 {
                    grad[i][j] += u[a][i] * ga[j];
                }
            }
        }
        material.stress(grad)
    })
}

/// div sigma(u_h) on element t (constant): mu Laplace u + (mu + zeta) grad div u.
fn div_stress(material: Material, map: &Affine, u: &[[f64; 2]; N_NODES]) -> [f64; 2] {
    let h = element::p2_hessians(map);
    let (mut lap, mut graddiv) = ([0.0; 2], [0.0; 2]);
    for a in 0..N_NODES {
        let [xx, xy, yy] = h[a];
        lap[0] += u[a][0] * (xx + yy);
        lap[1] += u[a][1] * (xx + yy);
        graddiv[0] += u[a][0] * xx + u[a][1] * xy;
        graddiv[1] += u[a][0] * xy + u[a][1] * yy;
    }
    let (mu, zeta) = (material.mu, material.zeta);
    [mu * lap[0] + (mu + zeta) * graddiv[0], mu * lap[1] + (mu + zeta) * graddiv[1]]
}

#[inline]
fn lerp3(a: [f64; 3], b: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2])]
}

#[inline]
fn traction(s: [f64; 3], n: [f64; 2]) -> [f64; 2] {
    [s[0] * n[0] + s[1] * n[1], s[1] * n[0] + s[2] * n[1]]
}

#[inline]
fn inf_norm(v: [f64; 2]) -> f64 {
    v[0].abs().max(v[1].abs())
}

/// Edge sampling parameters in [0, 1].
fn edge_samples(sampling: Sampling) -> Vec<f64> {
    match sampling {
        Sampling::Quadrature => element::gauss_legendre(EDGE_GAUSS).points.iter().map(|p| p[0]).collect(),
        Sampling::Dense => (0..=crate::norms::LATTICE_ORDER).map(|k| k as f64 / crate::norms::LATTICE_ORDER as f64).collect(),
    }
}

/// Evaluate the estimator on a discrete solution.
///
/// ```rust
/// use signorini::contact::PdasOptions;
/// use signorini::estimate::{self, EstimatorConfig};
/// use signorini::mesh::MeshSpec;
/// use signorini::problems::{Ex71, Problem};
///
/// let mesh = MeshSpec::parse("structured:4").unwrap().build(&Ex71).unwrap();
/// let sol = signorini::solve::solve(&mesh, &Ex71, &PdasOptions::default(), &mut |_| {}).unwrap();
/// let est = estimate::estimate(&mesh, &Ex71, &sol, &EstimatorConfig::default());
/// assert_eq!(est.element.len(), mesh.n_triangles());
/// // an upper bound of the error (reliability), here with the exact solution known
/// let u = |x: [f64; 2]| Ex71.exact().unwrap().u(x);
/// assert!(est.terms.estimate >= signorini::norms::linf_error(&mesh, &sol, &u).linf_quadrature);
/// ```
pub fn estimate(mesh: &Mesh, problem: &dyn Problem, sol: &DiscreteSolution, config: &EstimatorConfig) -> Estimate {
    let material = problem.material();
    let nodes = &sol.nodes;
    let n_el = mesh.n_triangles();
    let nv = nodes.n_vertices;
    let elem_refs = config.sampling.points();
    let edge_s = edge_samples(config.sampling);

    // Stress at the vertices of every element (sigma(u_h) is linear on each element).
    let stress: Vec<[[f64; 3]; 3]> = (0..n_el)
        .into_par_iter()
        .map(|t| {
            let el = &nodes.elements[t];
            let u: [[f64; 2]; N_NODES] = std::array::from_fn(|a| sol.u[el[a]]);
            vertex_stress(material, &Affine::new(mesh.corners(t)), &u)
        })
        .collect();

    // positive discrete contact force, per node
    let positive = |p: usize| sol.dofs.contact_index[p].is_some_and(|k| sol.lambda[k] > LAMBDA_POSITIVE * sol.force_scale);

    // Element-local quantities.
    let local: Vec<ElementLocal> = (0..n_el)
        .into_par_iter()
        .map(|t| {
            let map = Affine::new(mesh.corners(t));
            let el = &nodes.elements[t];
            let u: [[f64; 2]; N_NODES] = std::array::from_fn(|a| sol.u[el[a]]);
            let div = div_stress(material, &map, &u);
            let mut out = ElementLocal::default();
            for r in &elem_refs {
                let f = problem.body_force(map.map(*r));
                out.residual = out.residual.max(inf_norm([f[0] + div[0], f[1] + div[1]]));
            }
            for (le, [i, j]) in EDGE_VERTICES.iter().enumerate() {
                let Some(bi) = nodes.element_boundary[t][le] else { continue };
                let be = mesh.boundary[bi];
                // the boundary edge runs counter-clockwise from be.v[0] to be.v[1]
                let (a, b) = (mesh.vertices[be.v[0]], mesh.vertices[be.v[1]]);
                let (normal, _) = crate::assembly::edge_normal(a, b);
                // element stress at the boundary edge's start and end
                let (sa, sb) = if el[*i] == be.v[0] { (stress[t][*i], stress[t][*j]) } else { (stress[t][*j], stress[t][*i]) };
                let bn = nodes.boundary_nodes[bi];
                for &s in &edge_s {
                    let x = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
                    let tr = traction(lerp3(sa, sb, s), normal);
                    match be.part {
                        Part::Neumann => {
                            let g = problem.traction(x, normal);
                            out.neumann[le] = out.neumann[le].max(inf_norm([g[0] - tr[0], g[1] - tr[1]]));
                        }
                        Part::Contact => {
                            let n = problem.contact_normal(x);
                            let tng = [-n[1], n[0]];
                            // (sigma-hat_1, sigma-hat_2): eta_5 takes the first, eta_4 the second
                            let (s1, s2) = match config.stress_frame {
                                StressFrame::Normal => (tr[0] * n[0] + tr[1] * n[1], tr[0] * tng[0] + tr[1] * tng[1]),
                                StressFrame::Cartesian => (tr[0], tr[1]),
                            };
                            out.normal[le] = out.normal[le].max(s1.abs());
                            out.tensile[le] = out.tensile[le].max(s1.max(0.0));
                            out.tangential[le] = out.tangential[le].max(s2.abs());
                            let phi = edge_basis(s);
                            let mut un = 0.0;
                            for k in 0..3 {
                                let uk = sol.u[bn[k]];
                                un += phi[k] * (uk[0] * n[0] + uk[1] * n[1]);
                            }
                            let gap = problem.gap(x);
                            out.penetration[le] = out.penetration[le].max(un - gap);
                            out.separation[le] = out.separation[le].max(gap - un);
                        }
                        Part::Dirichlet => {}
                    }
                }
            }
            out
        })
        .collect();

    // Interior jumps per edge (node index nv + e), computed by the element of lower index.
    let mut jump = vec![0.0f64; nodes.edges.len()];
    for t in 0..n_el {
        let el = &nodes.elements[t];
        for (le, [i, j]) in EDGE_VERTICES.iter().enumerate() {
            let Some(t2) = nodes.neighbours[t][le] else { continue };
            if t2 > t {
                continue;
            }
            let (a, b) = (mesh.vertices[el[*i]], mesh.vertices[el[*j]]);
            let (n, _) = crate::assembly::edge_normal(a, b); // outward for t (counter-clockwise)
            let el2 = &nodes.elements[t2];
            let k2 = |v: usize| (0..3).find(|&k| el2[k] == v).expect("neighbour shares the edge");
            let (s1a, s1b) = (stress[t][*i], stress[t][*j]);
            let (s2a, s2b) = (stress[t2][k2(el[*i])], stress[t2][k2(el[*j])]);
            let mut m = 0.0f64;
            for &s in &edge_s {
                let d = traction(lerp3(s2a, s2b, s), n);
                let c = traction(lerp3(s1a, s1b, s), n);
                m = m.max(inf_norm([d[0] - c[0], d[1] - c[1]]));
            }
            jump[el[3 + le] - nv] = m;
        }
    }

    // Patches: node -> elements, and h_p = diameter of the patch.
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
    let mut patch = vec![0usize; start[n_nodes]];
    let mut fill = start.clone();
    for (t, el) in nodes.elements.iter().enumerate() {
        for &p in el {
            patch[fill[p]] = t;
            fill[p] += 1;
        }
    }
    let h_p: Vec<f64> = (0..n_nodes)
        .into_par_iter()
        .map(|p| {
            let mut verts: Vec<usize> = patch[start[p]..start[p + 1]].iter().flat_map(|&t| mesh.triangles[t]).collect();
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

    let repaired = config.contact_term == ContactTerm::TensileOnFullContact;
    let in_lambda_repaired = repair::narrow_lambda(mesh, sol, &positive);

    // Gather per node.
    let (h_min, _) = mesh.h_range();
    let l_h = config.log_factor.value(h_min);
    let node_terms: Vec<([f64; 5], bool, f64, f64)> = (0..n_nodes)
        .into_par_iter()
        .map(|p| {
            let els = &patch[start[p]..start[p + 1]];
            let hp = h_p[p];
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
                        Part::Contact if part == Some(Part::Contact) => {
                            has_contact_edge = true;
                            e[3] = e[3].max(local[t].tangential[le]);
                            e[4] = e[4].max(local[t].normal[le]);
                            tensile = tensile.max(local[t].tensile[le]);
                            let bn = nodes.boundary_nodes[bi];
                            full_contact &= bn.iter().all(|&q| sol.dofs.contact_index[q].is_some_and(|k| sol.active[k]));
                            pen = pen.max(local[t].penetration[le]);
                            if if repaired { in_lambda_repaired[bi] } else { positive(p) } {
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
            if repaired && full {
                e[4] = tensile;
            }
            let scaled = [hp * hp * e[0], hp * e[1], hp * e[2], hp * e[3], hp * e[4]];
            (scaled, full, pen, sep)
        })
        .collect();

    let mut terms = Terms { l_h, c0: config.c0, ..Default::default() };
    let mut full_contact_nodes = 0;
    let mut eta5_full_contact = 0.0f64;
    for (e, full, pen, sep) in &node_terms {
        terms.eta1 = terms.eta1.max(e[0]);
        terms.eta2 = terms.eta2.max(e[1]);
        terms.eta3 = terms.eta3.max(e[2]);
        terms.eta4 = terms.eta4.max(e[3]);
        terms.eta5 = terms.eta5.max(e[4]);
        terms.eta6 = terms.eta6.max(*pen);
        terms.eta7 = terms.eta7.max(*sep);
        full_contact_nodes += *full as usize;
        if *full {
            eta5_full_contact = eta5_full_contact.max(e[4]);
        }
    }
    terms.psi = terms.eta1 + terms.eta2 + terms.eta3 + terms.eta4 + terms.eta5;
    terms.eta_h = l_h * terms.psi + terms.eta6 + terms.eta7;
    terms.estimate = config.c0 * terms.eta_h;

    // Element indicators for marking.
    let element: Vec<f64> = (0..n_el)
        .into_par_iter()
        .map(|t| {
            let el = &nodes.elements[t];
            let nodal = el.iter().map(|&p| l_h * node_terms[p].0.iter().sum::<f64>()).fold(0.0, f64::max);
            let mut contact = 0.0f64;
            for le in 0..3 {
                let Some(bi) = nodes.element_boundary[t][le] else { continue };
                if mesh.boundary[bi].part != Part::Contact {
                    continue;
                }
                let bn = nodes.boundary_nodes[bi];
                let in_lambda =
                    if repaired { in_lambda_repaired[bi] } else { el.iter().any(|&p| positive(p)) || bn.iter().any(|&p| positive(p)) };
                let sep = if in_lambda { local[t].separation[le].max(0.0) } else { 0.0 };
                contact = contact.max(local[t].penetration[le].max(0.0) + sep);
            }
            nodal + contact
        })
        .collect();

    Estimate { terms, config: *config, element, full_contact_nodes, eta5_full_contact }
}
