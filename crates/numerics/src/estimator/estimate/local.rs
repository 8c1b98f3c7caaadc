//! The element-local quantities of the estimator, before they are gathered on patches: the
//! stress of u_h at each element's vertices (sigma(u_h) is linear on a P2 element), the element
//! residual f + div sigma(u_h) (eta_1), the boundary residuals on Neumann and contact edges
//! (eta_3, eta_4, eta_5, eta_6, eta_7) and the interior traction jumps (eta_2).

use crate::contact::solve::DiscreteSolution;
use crate::fem::assembly::edge_basis;
use model::base::element::{self, Affine, EDGE_VERTICES, N_NODES};
use model::mesh::Mesh;
use model::problems::{Material, Part, Problem};
use model::settings::estimator::{EstimatorConfig, StressFrame};
use model::settings::sampling::Sampling;
use rayon::prelude::*;

/// Local (per element) quantities before they are gathered on patches.
#[derive(Clone, Copy, Default)]
pub(super) struct ElementLocal {
    /// max |f + div sigma(u_h)| over the element
    pub(super) residual: f64,
    /// per local edge: max |g - sigma n| (Neumann), or on contact edges the max |sigma_t|, max |sigma_n|
    /// and max (sigma_n)^+ (the tensile part)
    pub(super) neumann: [f64; 3],
    pub(super) tangential: [f64; 3],
    pub(super) normal: [f64; 3],
    pub(super) tensile: [f64; 3],
    /// per local edge on Gamma_C: max (u.n - chi)^+ and max (chi - u.n)^+
    pub(super) penetration: [f64; 3],
    pub(super) separation: [f64; 3],
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

/// Edge sampling parameters in [0, 1] ([`Sampling::edge_parameters`]).
pub(super) fn edge_samples(sampling: Sampling) -> Vec<f64> {
    sampling.edge_parameters()
}

/// Stress (s11, s12, s22) of u_h at the three vertices of every element.
pub(super) fn vertex_stresses(mesh: &Mesh, problem: &dyn Problem, sol: &DiscreteSolution) -> Vec<[[f64; 3]; 3]> {
    let material = problem.material();
    (0..mesh.n_triangles())
        .into_par_iter()
        .map(|t| {
            let el = &sol.nodes.elements[t];
            let u: [[f64; 2]; N_NODES] = std::array::from_fn(|a| sol.u[el[a]]);
            vertex_stress(material, &Affine::new(mesh.corners(t)), &u)
        })
        .collect()
}

/// Every element's [`ElementLocal`]: the residual over the element sampling, and the boundary
/// residuals over the edge sampling `edge_s` of its boundary edges.
pub(super) fn element_locals(
    mesh: &Mesh,
    problem: &dyn Problem,
    sol: &DiscreteSolution,
    config: &EstimatorConfig,
    stress: &[[[f64; 3]; 3]],
    edge_s: &[f64],
) -> Vec<ElementLocal> {
    let material = problem.material();
    let elem_refs = config.sampling.points();
    (0..mesh.n_triangles())
        .into_par_iter()
        .map(|t| {
            let map = Affine::new(mesh.corners(t));
            let el = &sol.nodes.elements[t];
            let u: [[f64; 2]; N_NODES] = std::array::from_fn(|a| sol.u[el[a]]);
            let div = div_stress(material, &map, &u);
            let mut out = ElementLocal::default();
            for r in &elem_refs {
                let f = problem.body_force(map.map(*r));
                out.residual = out.residual.max(inf_norm([f[0] + div[0], f[1] + div[1]]));
            }
            for le in 0..3 {
                boundary_edge(mesh, problem, sol, config, t, le, &stress[t], edge_s, &mut out);
            }
            out
        })
        .collect()
}

/// The residuals on local edge `le` of element `t` if it is a Neumann or contact edge, or a
/// Dirichlet edge with a component left free.
#[allow(clippy::too_many_arguments)]
fn boundary_edge(
    mesh: &Mesh,
    problem: &dyn Problem,
    sol: &DiscreteSolution,
    config: &EstimatorConfig,
    t: usize,
    le: usize,
    stress: &[[f64; 3]; 3],
    edge_s: &[f64],
    out: &mut ElementLocal,
) {
    let nodes = &sol.nodes;
    let [i, j] = EDGE_VERTICES[le];
    let el = &nodes.elements[t];
    let Some(bi) = nodes.element_boundary[t][le] else { return };
    let be = mesh.boundary[bi];
    // the boundary edge runs counter-clockwise from be.v[0] to be.v[1]
    let (a, b) = (mesh.vertices[be.v[0]], mesh.vertices[be.v[1]]);
    let (normal, _) = crate::fem::assembly::edge_normal(a, b);
    // element stress at the boundary edge's start and end
    let (sa, sb) = if el[i] == be.v[0] { (stress[i], stress[j]) } else { (stress[j], stress[i]) };
    let bn = nodes.boundary_nodes[bi];
    for &s in edge_s {
        let x = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
        let tr = traction(lerp3(sa, sb, s), normal);
        match be.part {
            Part::Neumann => {
                let g = problem.traction(x, normal);
                out.neumann[le] = out.neumann[le].max(inf_norm([g[0] - tr[0], g[1] - tr[1]]));
            }
            Part::Contact => {
                let n = problem.contact_normal(x, mesh.outward_at(bi, x));
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
            Part::Dirichlet => {
                // a component the Dirichlet data leave free carries zero traction (rollers):
                // its residual is a Neumann one
                let prescribed = problem.dirichlet_components();
                let free = (0..2).filter(|&i| !prescribed[i]).fold(0.0f64, |a, i| a.max(tr[i].abs()));
                out.neumann[le] = out.neumann[le].max(free);
            }
        }
    }
}

/// The largest traction jump |[sigma(u_h)] n| over the edge sampling of every interior edge,
/// indexed by edge (the edge's midpoint node is `n_vertices + e`), computed by the element of
/// lower index.
pub(super) fn interior_jumps(mesh: &Mesh, sol: &DiscreteSolution, stress: &[[[f64; 3]; 3]], edge_s: &[f64]) -> Vec<f64> {
    let nodes = &sol.nodes;
    let nv = nodes.n_vertices;
    let mut jump = vec![0.0f64; nodes.edges.len()];
    for t in 0..mesh.n_triangles() {
        let el = &nodes.elements[t];
        for (le, [i, j]) in EDGE_VERTICES.iter().enumerate() {
            let Some(t2) = nodes.neighbours[t][le] else { continue };
            if t2 > t {
                continue;
            }
            let (a, b) = (mesh.vertices[el[*i]], mesh.vertices[el[*j]]);
            let (n, _) = crate::fem::assembly::edge_normal(a, b); // outward for t (counter-clockwise)
            let el2 = &nodes.elements[t2];
            let k2 = |v: usize| (0..3).find(|&k| el2[k] == v).expect("neighbour shares the edge");
            let (s1a, s1b) = (stress[t][*i], stress[t][*j]);
            let (s2a, s2b) = (stress[t2][k2(el[*i])], stress[t2][k2(el[*j])]);
            let mut m = 0.0f64;
            for &s in edge_s {
                let d = traction(lerp3(s2a, s2b, s), n);
                let c = traction(lerp3(s1a, s1b, s), n);
                m = m.max(inf_norm([d[0] - c[0], d[1] - c[1]]));
            }
            jump[el[3 + le] - nv] = m;
        }
    }
    jump
}
