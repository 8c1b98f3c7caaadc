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

use crate::base::element::EDGE_VERTICES;
use crate::contact::sampling::Sampling;
use crate::contact::solve::DiscreteSolution;
use crate::mesh::{Mesh, dist};
use crate::problems::{Part, Problem};
use rayon::prelude::*;

/// Gauss points per edge for the "quadrature" sampling of edge terms.
pub const EDGE_GAUSS: usize = crate::contact::sampling::EDGE_GAUSS;

/// Which contact nodes eta_5 is taken over. Manifests spell the values in snake_case
/// (`as_written`), the command line in kebab-case (`--contact-term as-written`). The variants'
/// docs are for readers of the code (`help = None`): the flag's help describes the values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum ContactTerm {
    /// All contact nodes, as the paper writes eta_5.
    #[value(help = None::<&str>)]
    AsWritten,
    /// Without full-contact nodes N_h^FC (u_h.n = chi_h on all of Gamma_{p,C}), as in
    /// Krause–Veeser–Walloth. At a node in full contact the exact normal stress is a compressive
    /// contact pressure, not an error: taken over all contact nodes, eta_5 measures that pressure
    /// and decays only like h (measured: the `contact_term_ablation` study).
    #[value(help = None::<&str>)]
    WithoutFullContact,
    /// The repaired contact terms (beyond the paper): at a full-contact node eta_5 takes only the
    /// tensile part (n . sigma(u_h) n)^+ of the normal stress, at other contact nodes it is as
    /// written; eta_7 is taken over a narrower Lambda_h^C, the full-contact edges (all three
    /// nodes active) and the edges through an active node with positive contact force that lies
    /// on no full-contact edge (an isolated active node). See [`repair`] for why, and for the
    /// step of the proof that is open.
    #[value(help = None::<&str>)]
    TensileOnFullContact,
}

/// The log factor l_h multiplying the residual terms (`--log-factor`, `estimator.log_factor`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum LogFactor {
    /// 1 + |log h_min|^2 (eq. 6.3)
    #[value(help = None::<&str>)]
    Squared,
    /// 1 + |log h_min|
    #[value(help = None::<&str>)]
    Linear,
    /// 1
    #[value(help = None::<&str>)]
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
    /// The constant replacing the hidden one of Theorem 6.1 (Section 7: [`C0_PAPER`]).
    pub c0: f64,
    pub sampling: Sampling,
    /// Reading of sigma-hat_1, sigma-hat_2 in eta_4, eta_5 (absent in older records: normal).
    #[serde(default)]
    pub stress_frame: StressFrame,
}

/// The constant C_0 of Section 7 as a literal, for text that quotes it (`concat!`): its one
/// definition, which [`C0_PAPER`] reads.
#[macro_export]
macro_rules! c0_paper {
    () => {
        0.45
    };
}
pub use crate::c0_paper;

/// The constant C_0 of Section 7, the estimator's default.
pub const C0_PAPER: f64 = c0_paper!();

impl Default for EstimatorConfig {
    fn default() -> Self {
        EstimatorConfig {
            contact_term: ContactTerm::AsWritten,
            log_factor: LogFactor::Squared,
            c0: C0_PAPER,
            sampling: Sampling::Quadrature,
            stress_frame: StressFrame::Normal,
        }
    }
}

/// A setting outside its range: `key` is the field (as manifests spell it: `estimator.c0`,
/// `theta`), `expected` the admissible values, `got` the value given. The one error of the
/// settings' validation, whether they come from a manifest or the command line (which names
/// the flag of `key` instead).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{key}: expected {expected}, got {got}")]
pub struct ConfigError {
    pub key: &'static str,
    pub expected: String,
    pub got: String,
}

impl ConfigError {
    /// A number as an error shows it: as Rust prints it while that is short (0.5, -1, NaN),
    /// else in exponent form (1e-320 and 1e308, not hundreds of digits).
    pub fn number(x: f64) -> String {
        let plain = x.to_string();
        if plain.len() <= 24 { plain } else { format!("{x:e}") }
    }
}

impl EstimatorConfig {
    /// Check the settings: C_0 must be a positive normal number (not zero, NaN, infinite or
    /// subnormal, where C_0 eta_h loses its digits). Whether C_0 eta_h is finite depends on
    /// eta_h too: [`Terms::check_finite`] checks that once the estimate is computed.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !(self.c0 > 0.0 && self.c0.is_normal()) {
            let expected = if self.c0 > 0.0 && self.c0.is_finite() {
                format!("a positive number of at least {:e} (a subnormal C_0 leaves C_0 eta_h few digits)", f64::MIN_POSITIVE)
            } else {
                "a positive number".into()
            };
            return Err(ConfigError { key: "estimator.c0", expected, got: ConfigError::number(self.c0) });
        }
        Ok(())
    }
}

/// An estimate that is not a finite number: C_0 eta_h overflowed (a C_0 too large for this
/// eta_h) or eta_h itself is not finite (`overflowed` names the term: the problem's data are
/// beyond double precision, which no C_0 mends). Nothing can be compared with it or stored.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("the estimate C_0 eta_h = {c0:e} x {eta_h:e} is {estimate}, not a finite number ({})", blame(overflowed))]
pub struct NotFinite {
    pub c0: f64,
    pub eta_h: f64,
    pub estimate: f64,
    /// The first of eta_1 .. eta_7, l_h and their sum eta_h that is not finite, in words, with
    /// its value; None when eta_h is finite (then C_0 is too large for it).
    pub overflowed: Option<(&'static str, f64)>,
}

/// Whom a [`NotFinite`] estimate is due to: C_0, or the term that overflowed.
fn blame(overflowed: &Option<(&'static str, f64)>) -> String {
    match overflowed {
        None => "estimator.c0, --c0: a C_0 for which it is finite".into(),
        Some((term, value)) => format!(
            "{term} is {value}, so no C_0 makes it finite: the problem's data are too large for double precision; \
             rescale its units (body force, loads, Dirichlet data, obstacle)"
        ),
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

    /// The estimate is a finite number: what every path that reports or stores one checks
    /// (the adaptive loop at every level, `signorini solve`).
    pub fn check_finite(&self) -> Result<(), NotFinite> {
        if self.estimate.is_finite() {
            return Ok(());
        }
        let named = [
            ("eta_1, the element residual h^2 |f + div sigma(u_h)| (the body force)", self.eta1),
            ("eta_2, the stress jumps across edges", self.eta2),
            ("eta_3, the Neumann residual (the surface load)", self.eta3),
            ("eta_4, the tangential contact stress", self.eta4),
            ("eta_5, the normal contact stress", self.eta5),
            ("eta_6, the penetration (u_h.n - chi)^+", self.eta6),
            ("eta_7, the gap (chi - u_h.n)^+ where the contact force is positive", self.eta7),
            ("the log factor l_h", self.l_h),
            ("eta_h = l_h (eta_1 + ... + eta_5) + eta_6 + eta_7", self.eta_h),
        ];
        let overflowed = named.into_iter().find(|(_, v)| !v.is_finite());
        Err(NotFinite { c0: self.c0, eta_h: self.eta_h, estimate: self.estimate, overflowed })
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

/// Evaluate the estimator on a discrete solution.
///
/// ```rust
/// use signorini_numerics::contact::PdasOptions;
/// use signorini_numerics::estimator::estimate::{self, EstimatorConfig};
/// use signorini_numerics::mesh::MeshSpec;
/// use signorini_numerics::problems::{Ex71, Problem};
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
