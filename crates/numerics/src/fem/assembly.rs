//! Assembly of the P2 plane-elasticity system a(u, v) = L(v) (paper Section 1, eq. 1.8 and 3.4).
//!
//! Unknowns are the free nodal values (Dirichlet nodes carry their data and are eliminated).
//! At a contact node the two unknowns are taken in the local frame (u.n, u.t), t = (-n_2, n_1),
//! so the contact constraint u(p).n <= chi_h(p) acts on a single unknown for any normal.
//! The unknowns are numbered so that every contact normal unknown comes last (the block `C`);
//! the contact solver relies on that to work on a small Schur complement.
//! The method: `docs/method.md`, section "The discretisation".

use model::base::element::{self, Affine, EDGE_VERTICES, N_NODES};
use model::mesh::{Mesh, P2Nodes};
use model::problems::{Material, Part, Problem};
use rayon::prelude::*;

use crate::sparse::csc::{SymCsc, offsets, par_fill};

/// Marks a node component that is not an unknown (a Dirichlet value).
pub const FIXED: usize = usize::MAX;

/// Quadrature degree for the body force (smooth data such as Example 7.1's exponentials:
/// the load error is far below the discretisation error and the cross-check's tolerance).
pub const LOAD_DEGREE: usize = 10;
/// Gauss points per edge for Neumann loads.
pub const EDGE_POINTS: usize = 8;

/// A contact node: the P2 node, its constraint direction (`Problem::contact_normal`, a unit
/// vector) and chi_h(p) = chi(p).
#[derive(Clone, Copy, Debug)]
pub struct ContactNode {
    pub node: usize,
    pub normal: [f64; 2],
    pub gap: f64,
}

/// Which unknown belongs to which node component.
#[derive(Clone, Debug)]
pub struct DofMap {
    /// Per node, the unknowns of its two local components (Cartesian, or (normal, tangential) at
    /// contact nodes); `FIXED` for a prescribed component (Dirichlet data or a point constraint).
    pub dof: Vec<[usize; 2]>,
    pub n_free: usize,
    /// Unknowns `0..n_interior` are not contact normals; `n_interior + k` is the normal unknown
    /// of `contact[k]`.
    pub n_interior: usize,
    pub contact: Vec<ContactNode>,
    /// Per node, its index in `contact`.
    pub contact_index: Vec<Option<usize>>,
    /// The nodes of the problem's point constraints with their prescribed components (in the
    /// order of `Problem::point_constraints`; a point that is not a vertex is left out, and
    /// the solve refuses such a mesh before, `Mesh::check_vertices`).
    pub points: Vec<(usize, [Option<f64>; 2])>,
}

/// Within this distance a point constraint is at a vertex (as `Mesh::check_vertices` finds it).
const POINT_TOLERANCE: f64 = 1e-12;

impl DofMap {
    /// Contact nodes are the nodes on Gamma_C with no prescribed component (the Dirichlet part
    /// wins at shared corners, see `P2Nodes::part`), each with the problem's normal at the
    /// body's outward normal there (`P2Nodes::outward`: where two contact edges meet, one of
    /// theirs; `contact::plausible` refuses a node where their normals differ). A node's component is prescribed on
    /// Gamma_D if the problem's Dirichlet data prescribe it (`Problem::dirichlet_components`),
    /// and at a point constraint's vertex if the constraint does.
    pub fn new(nodes: &P2Nodes, problem: &dyn Problem) -> Self {
        let n = nodes.len();
        let on_dirichlet = problem.dirichlet_components();
        let mut fixed: Vec<[bool; 2]> =
            nodes.part.iter().map(|part| if *part == Some(Part::Dirichlet) { on_dirichlet } else { [false, false] }).collect();
        let points: Vec<(usize, [Option<f64>; 2])> = problem
            .point_constraints()
            .iter()
            .filter_map(|c| {
                let p = (0..nodes.n_vertices).find(|&p| model::mesh::dist(nodes.coords[p], c.at) < POINT_TOLERANCE)?;
                Some((p, c.u))
            })
            .collect();
        for (p, u) in &points {
            for i in 0..2 {
                fixed[*p][i] |= u[i].is_some();
            }
        }
        let mut dof = vec![[FIXED; 2]; n];
        let mut contact = Vec::new();
        let mut contact_index = vec![None; n];
        let mut next = 0;
        for p in 0..n {
            if nodes.part[p] == Some(Part::Contact) && fixed[p] == [false, false] {
                let x = nodes.coords[p];
                contact_index[p] = Some(contact.len());
                let outward = nodes.outward[p].expect("a contact node is on a contact edge");
                contact.push(ContactNode { node: p, normal: problem.contact_normal(x, outward), gap: problem.gap(x) });
                dof[p][1] = next; // tangential unknown among the interior ones
                next += 1;
                continue;
            }
            for i in 0..2 {
                if !fixed[p][i] {
                    dof[p][i] = next;
                    next += 1;
                }
            }
        }
        let n_interior = next;
        for (k, c) in contact.iter().enumerate() {
            dof[c.node][0] = n_interior + k;
        }
        DofMap { dof, n_free: n_interior + contact.len(), n_interior, contact, contact_index, points }
    }

    /// The prescribed value of every node's fixed components (0 elsewhere): the problem's
    /// Dirichlet data on Gamma_D, then the point constraints' values at their vertices (on a
    /// component Gamma_D also prescribes, the solve has checked the two are equal:
    /// `contact::point::check_on_dirichlet`).
    pub fn prescribed(&self, nodes: &P2Nodes, problem: &dyn Problem) -> Vec<[f64; 2]> {
        let mut values: Vec<[f64; 2]> = (0..nodes.len())
            .map(|p| {
                let mut v = if nodes.part[p] == Some(Part::Dirichlet) { problem.dirichlet(nodes.coords[p]) } else { [0.0, 0.0] };
                for (i, vi) in v.iter_mut().enumerate() {
                    if self.dof[p][i] != FIXED {
                        *vi = 0.0;
                    }
                }
                v
            })
            .collect();
        for (p, u) in &self.points {
            for i in 0..2 {
                if let Some(ui) = u[i] {
                    values[*p][i] = ui;
                }
            }
        }
        values
    }

    /// The rotation taking Cartesian components to the node's local ones (identity off contact).
    #[inline]
    pub fn frame(&self, p: usize) -> Option<[[f64; 2]; 2]> {
        self.contact_index[p].map(|k| {
            let n = self.contact[k].normal;
            [[n[0], n[1]], [-n[1], n[0]]]
        })
    }

    /// The position of every unknown (its node's), for the fill-reducing ordering.
    pub fn unknown_coords(&self, nodes: &P2Nodes) -> Vec<[f64; 2]> {
        let mut coords = vec![[0.0; 2]; self.n_free];
        for (p, d) in self.dof.iter().enumerate() {
            for &k in d.iter().filter(|&&k| k != FIXED) {
                coords[k] = nodes.coords[p];
            }
        }
        coords
    }

    /// Full Cartesian nodal displacements from the unknowns and the Dirichlet values.
    pub fn displacement(&self, free: &[f64], dirichlet: &[[f64; 2]]) -> Vec<[f64; 2]> {
        (0..self.dof.len())
            .map(|p| {
                let d = self.dof[p];
                // a node with a prescribed component is never rotated (not a contact node)
                let value = |i: usize| if d[i] == FIXED { dirichlet[p][i] } else { free[d[i]] };
                let local = [value(0), value(1)];
                match self.frame(p) {
                    // u = R^T local
                    Some(r) => [r[0][0] * local[0] + r[1][0] * local[1], r[0][1] * local[0] + r[1][1] * local[1]],
                    None => local,
                }
            })
            .collect()
    }
}

/// The assembled system: K u = F on the unknowns, with Dirichlet values eliminated.
#[derive(Clone, Debug)]
pub struct System {
    pub matrix: SymCsc,
    pub rhs: Vec<f64>,
    /// Prescribed values (P2 interpolant of the Dirichlet data, point constraints) of every
    /// node's fixed components; zero elsewhere.
    pub dirichlet: Vec<[f64; 2]>,
}

/// The 12 x 12 element stiffness of P2 plane elasticity on one triangle, local unknown order
/// `2 a + i` (node a, Cartesian component i):
/// K[(a,i),(b,j)] = int mu (delta_ij grad phi_a . grad phi_b + d_j phi_a d_i phi_b) + zeta d_i phi_a d_j phi_b.
pub fn element_stiffness(map: &Affine, material: Material, rule: &element::Rule<2>) -> [[f64; 12]; 12] {
    let mut k = [[0.0; 12]; 12];
    let area = map.det.abs();
    for (q, w) in rule.points.iter().zip(&rule.weights) {
        let rg = element::p2_gradients(q[0], q[1]);
        let g: [[f64; 2]; N_NODES] = std::array::from_fn(|a| map.grad(rg[a]));
        let w = w * area;
        for a in 0..N_NODES {
            for b in 0..N_NODES {
                let dot = g[a][0] * g[b][0] + g[a][1] * g[b][1];
                for i in 0..2 {
                    for j in 0..2 {
                        let mut v = material.mu * g[a][j] * g[b][i] + material.zeta * g[a][i] * g[b][j];
                        if i == j {
                            v += material.mu * dot;
                        }
                        k[2 * a + i][2 * b + j] += w * v;
                    }
                }
            }
        }
    }
    k
}

/// The sparsity pattern of the lower triangle on the unknowns: (row, col) is present when the
/// two nodes share an element. Built on the nodes: every node's neighbours once, sorted; the
/// column of an unknown holds the unknowns >= it of its node's neighbours.
fn pattern(nodes: &P2Nodes, dofs: &DofMap) -> SymCsc {
    let n_nodes = nodes.len();
    let node_index = |p: usize| u32::try_from(p).expect("more than 2^32 nodes");
    // node adjacency: every node of every element containing the node (u32: half the memory
    // traffic of usize), then sorted, the unique ones moved to the front of each node's slice
    let mut count = vec![0usize; n_nodes];
    for el in &nodes.elements {
        for &p in el {
            count[p] += N_NODES;
        }
    }
    let adj_ptr = offsets(count.into_iter());
    let mut adj = vec![0u32; adj_ptr[n_nodes]];
    let mut fill = adj_ptr.clone();
    for el in &nodes.elements {
        let el32 = el.map(node_index);
        for &p in el {
            adj[fill[p]..fill[p] + N_NODES].copy_from_slice(&el32);
            fill[p] += N_NODES;
        }
    }
    drop(fill);
    let n_unique = par_fill(
        &mut adj,
        &adj_ptr,
        || (),
        |_, _, list| {
            list.sort_unstable();
            let mut k = 0;
            for i in 0..list.len() {
                if i == 0 || list[i] != list[k - 1] {
                    list[k] = list[i];
                    k += 1;
                }
            }
            k
        },
    );
    let neighbours = |p: usize| adj[adj_ptr[p]..adj_ptr[p] + n_unique[p]].iter().map(|&q| q as usize);
    // each unknown's owner node
    let n = dofs.n_free;
    let mut owner = vec![0u32; n];
    for p in 0..n_nodes {
        for &d in &dofs.dof[p] {
            if d != FIXED {
                owner[d] = node_index(p);
            }
        }
    }
    // The unknowns of node p's neighbours, increasing. DofMap numbers the unknowns in node
    // order, the contact normals last (also in node order): the neighbours' other unknowns, then
    // their contact normals, are increasing without a sort (checked; sorted if a numbering ever
    // breaks that).
    let (owner, n_interior) = (&owner, dofs.n_interior);
    let node_rows = |p: usize, list: &mut Vec<usize>| {
        list.clear();
        list.extend(neighbours(p).flat_map(|q| dofs.dof[q]).filter(|&d| d != FIXED && d < n_interior));
        list.extend(neighbours(p).map(|q| dofs.dof[q][0]).filter(|&d| d != FIXED && d >= n_interior));
        if !list.is_sorted() {
            list.sort_unstable();
        }
    };
    // The rows of column j are the suffix >= j of its owner's list: where it starts. The list is
    // kept in `scratch` with its node, so the columns of one node build it once.
    let column = |j: usize, scratch: &mut (usize, Vec<usize>)| {
        let p = owner[j] as usize;
        if scratch.0 != p {
            node_rows(p, &mut scratch.1);
            scratch.0 = p;
        }
        scratch.1.partition_point(|&d| d < j)
    };
    let scratch = || (usize::MAX, Vec::with_capacity(64));
    let counts: Vec<usize> = (0..n)
        .into_par_iter()
        .map_init(scratch, |s, j| {
            let start = column(j, s);
            s.1.len() - start
        })
        .collect();
    let col_ptr = offsets(counts.into_iter());
    let mut row_idx = vec![0usize; col_ptr[n]];
    par_fill(&mut row_idx, &col_ptr, scratch, |j, s, col| {
        let start = column(j, s);
        col.copy_from_slice(&s.1[start..]);
    });
    // the values' pages are written here, in order and on every core: the scatter's first access
    // to a fresh page would be a read (it adds), which maps the zero page, and its write a second
    // fault, in element order all over the array
    let mut values = vec![0.0; row_idx.len()];
    values.par_chunks_mut(1 << 15).for_each(|c| c.fill(0.0));
    SymCsc::new(n, col_ptr, row_idx, values)
        .expect("the stiffness pattern: every column holds its diagonal and sorted, unique rows below it")
}

/// Assemble stiffness and loads: body force f, Neumann traction g, Dirichlet data eliminated.
pub fn assemble(mesh: &Mesh, nodes: &P2Nodes, dofs: &DofMap, problem: &dyn Problem) -> System {
    let material = problem.material();
    let mut matrix = pattern(nodes, dofs);
    let mut rhs = vec![0.0; dofs.n_free];
    let dirichlet = dofs.prescribed(nodes, problem);
    let stiff_rule = element::triangle_rule(2);
    let load_rule = element::triangle_rule(LOAD_DEGREE);
    let load_basis: Vec<[f64; N_NODES]> = load_rule.points.iter().map(|q| element::p2_values(q[0], q[1])).collect();
    let breaks = problem.load_breaks();
    let contribution = |t: usize, e: &mut Contribution| {
        let corners = mesh.corners(t);
        let map = Affine::new(corners);
        e.k = element_stiffness(&map, material, &stiff_rule);
        e.f = element_load(&map, corners, &|x| problem.body_force(x), &breaks, &load_rule, &load_basis);
        let el = &nodes.elements[t];
        rotate(&mut e.k, Some(&mut e.f), el, dofs);
        e.locate(el, dofs, &dirichlet);
    };

    // Element contributions in parallel, a chunk at a time into one buffer, scattered in element
    // order so the sums are the same on any number of threads. A chunk (about 1.4 kB an element)
    // stays in the last-level cache between the two passes: 2048 elements take 8% less time on
    // one thread than 16384 at structured:256.
    const CHUNK: usize = 2048;
    let n_el = mesh.n_triangles();
    let mut local = vec![Contribution::ZERO; CHUNK.min(n_el)];
    for start in (0..n_el).step_by(CHUNK) {
        let chunk = &mut local[..CHUNK.min(n_el - start)];
        chunk.par_iter_mut().enumerate().for_each(|(i, e)| contribution(start + i, e));
        scatter(&mut matrix, &mut rhs, chunk);
    }
    drop(local);
    neumann_load(mesh, nodes, dofs, problem, &mut rhs);
    System { matrix, rhs, dirichlet }
}

/// Where [`assemble`] evaluates the body force, triangle by triangle: the load rule's points, or
/// the piecewise rule's across a load break (the problem's `load_breaks`). Enumerated by
/// [`element_load`] itself, so the exact solution's consistency check
/// (`crate::contact::consistent`) sees every value of f the discrete problem sees. One triangle
/// at a time: a mesh of 1e7 unknowns has about 1e8 load points, too many to hold at once.
pub struct LoadPoints {
    breaks: Vec<f64>,
    rule: element::Rule<2>,
    basis: Vec<[f64; N_NODES]>,
}

impl LoadPoints {
    pub fn new(breaks: Vec<f64>) -> LoadPoints {
        let rule = element::triangle_rule(LOAD_DEGREE);
        let basis = rule.points.iter().map(|q| element::p2_values(q[0], q[1])).collect();
        LoadPoints { breaks, rule, basis }
    }

    /// The points of triangle `t`, in the order [`element_load`] evaluates f at them.
    pub fn of(&self, mesh: &Mesh, t: usize) -> Vec<[f64; 2]> {
        let corners = mesh.corners(t);
        let seen = std::cell::RefCell::new(Vec::with_capacity(self.rule.points.len()));
        let record = |x: [f64; 2]| {
            seen.borrow_mut().push(x);
            [0.0; 2]
        };
        element_load(&Affine::new(corners), corners, &record, &self.breaks, &self.rule, &self.basis);
        seen.into_inner()
    }
}

/// The points where [`assemble`] evaluates the Neumann traction on the boundary edge from `a`
/// to `b`: (parameter s in [0, 1], Gauss weight, point).
pub fn edge_points(a: [f64; 2], b: [f64; 2]) -> Vec<(f64, f64, [f64; 2])> {
    let gauss = element::gauss_legendre(EDGE_POINTS);
    gauss
        .points
        .iter()
        .zip(&gauss.weights)
        .map(|(s, &w)| {
            let s = s[0];
            (s, w, [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])])
        })
        .collect()
}

/// The body-force load int_T f phi_a of one triangle, local order `2 a + i` (Cartesian): the
/// rule `load_rule` (with its P2 values `load_basis`), or piecewise across a load break.
fn element_load(
    map: &Affine,
    corners: [[f64; 2]; 3],
    body_force: &dyn Fn([f64; 2]) -> [f64; 2],
    breaks: &[f64],
    load_rule: &element::Rule<2>,
    load_basis: &[[f64; N_NODES]],
) -> [f64; 12] {
    let crossing = breaks.iter().find(|&&c| corners.iter().any(|v| v[0] < c) && corners.iter().any(|v| v[0] > c));
    if let Some(&c) = crossing {
        return split_load(map, corners, c, body_force);
    }
    let mut f = [0.0; 12];
    let area = map.det.abs();
    for ((q, w), phi) in load_rule.points.iter().zip(&load_rule.weights).zip(load_basis) {
        let fx = body_force(map.map(*q));
        let (f0, f1) = (w * area * fx[0], w * area * fx[1]);
        for (a, &p) in phi.iter().enumerate() {
            f[2 * a] += f0 * p;
            f[2 * a + 1] += f1 * p;
        }
    }
    f
}

/// At every point constraint's node (`DofMap::points`), the Cartesian residual K u - F of its
/// two components, from the elements around it (stiffness times the full displacement `u`,
/// body force and Neumann traction as [`assemble`] integrates them): at a prescribed component
/// the reaction force the constraint exerts (with its sign reversed), at a free one the
/// equilibrium residual (zero to round-off). With `load` false, K u alone (for the step of
/// iterative refinement that measures u_h's round-off, [`crate::contact::point`]).
pub fn point_reactions(mesh: &Mesh, nodes: &P2Nodes, dofs: &DofMap, problem: &dyn Problem, u: &[[f64; 2]], load: bool) -> PointRows {
    let stiff_rule = element::triangle_rule(2);
    let load_rule = element::triangle_rule(LOAD_DEGREE);
    let load_basis: Vec<[f64; N_NODES]> = load_rule.points.iter().map(|q| element::p2_values(q[0], q[1])).collect();
    let breaks = problem.load_breaks();
    let (residual, magnitude) = dofs
        .points
        .iter()
        .map(|&(p, _)| {
            let (mut r, mut m) = ([0.0; 2], [0.0; 2]);
            for (t, el) in nodes.elements.iter().enumerate() {
                let Some(a) = el.iter().position(|&q| q == p) else { continue };
                let corners = mesh.corners(t);
                let map = Affine::new(corners);
                let k = element_stiffness(&map, problem.material(), &stiff_rule);
                let f = if load {
                    element_load(&map, corners, &|x| problem.body_force(x), &breaks, &load_rule, &load_basis)
                } else {
                    [0.0; 12]
                };
                for i in 0..2 {
                    let row = 2 * a + i;
                    let terms = (0..12).map(|l| k[row][l] * u[el[l / 2]][l % 2]);
                    r[i] += terms.clone().sum::<f64>() - f[row];
                    m[i] += terms.map(f64::abs).sum::<f64>() + f[row].abs();
                }
            }
            for (be, bn) in mesh.boundary.iter().zip(&nodes.boundary_nodes) {
                let Some(i) = bn.iter().position(|&q| q == p).filter(|_| load && be.part == Part::Neumann) else { continue };
                let (a, b) = (mesh.vertices[be.v[0]], mesh.vertices[be.v[1]]);
                let (normal, len) = edge_normal(a, b);
                for (s, w, x) in edge_points(a, b) {
                    let g = problem.traction(x, normal);
                    let phi = edge_basis(s)[i];
                    for c in 0..2 {
                        r[c] -= w * len * g[c] * phi;
                        m[c] += (w * len * g[c] * phi).abs();
                    }
                }
            }
            (r, m)
        })
        .unzip();
    PointRows { residual, magnitude }
}

/// [`point_reactions`]' rows, one per point constraint.
pub struct PointRows {
    /// K u - F at the point's node, per Cartesian component.
    pub residual: Vec<[f64; 2]>,
    /// The magnitude of the terms of that sum: sum_T |K_T| |u| term by term, plus |F| and |traction|.
    pub magnitude: Vec<[f64; 2]>,
}

/// K u on the unknowns, element by element: for every triangle its stiffness in the local frames
/// (as [`assemble`] computes it) times u at its unknowns, added into K u in element order (so the
/// same bits on any number of threads). This is a(u_h, phi) for every basis function phi of an
/// unknown without the assembled matrix, which the contact solver releases before factorising
/// (see [`crate::contact`]); it equals `matrix.mul(u)` up to round-off (a test checks it).
///
/// With it, the magnitude sum_T |K_T| |u| of the same terms and the rows' absolute sums
/// sum_T |K_T| 1: the scales against which the round-off of F - K u is judged
/// ([`crate::contact::certify`]).
pub fn stiffness_times(mesh: &Mesh, nodes: &P2Nodes, dofs: &DofMap, material: Material, u: &[f64]) -> StiffnessProduct {
    assert_eq!(u.len(), dofs.n_free);
    let rule = element::triangle_rule(2);
    let product = |t: usize, out: &mut ElementProduct| {
        let el = &nodes.elements[t];
        let mut k = element_stiffness(&Affine::new(mesh.corners(t)), material, &rule);
        rotate(&mut k, None, el, dofs);
        let global: [usize; 12] = std::array::from_fn(|l| dofs.dof[el[l / 2]][l % 2]);
        let free = || (0..12).filter(|&l| global[l] != FIXED);
        let row = |r: usize, term: &dyn Fn(f64, f64) -> f64| {
            if global[r] == FIXED { 0.0 } else { free().map(|l| term(k[r][l], u[global[l]])).sum() }
        };
        out.ku = std::array::from_fn(|r| row(r, &|k, u| k * u));
        out.magnitude = std::array::from_fn(|r| row(r, &|k, u| (k * u).abs()));
        out.row_norm = std::array::from_fn(|r| row(r, &|k, _| k.abs()));
        out.global = global;
    };
    // a chunk of elements in parallel, then its products added in element order
    const CHUNK: usize = 4096;
    let n_el = mesh.n_triangles();
    let zeros = || vec![0.0; dofs.n_free];
    let mut sum = StiffnessProduct { ku: zeros(), magnitude: zeros(), row_norm: zeros() };
    let empty = ElementProduct { ku: [0.0; 12], magnitude: [0.0; 12], row_norm: [0.0; 12], global: [FIXED; 12] };
    let mut local = vec![empty; CHUNK.min(n_el)];
    for start in (0..n_el).step_by(CHUNK) {
        let chunk = &mut local[..CHUNK.min(n_el - start)];
        chunk.par_iter_mut().enumerate().for_each(|(i, out)| product(start + i, out));
        for e in chunk.iter() {
            for (r, &g) in e.global.iter().enumerate() {
                if g != FIXED {
                    sum.ku[g] += e.ku[r];
                    sum.magnitude[g] += e.magnitude[r];
                    sum.row_norm[g] += e.row_norm[r];
                }
            }
        }
    }
    sum
}

/// K u on the unknowns and the magnitude of its terms ([`stiffness_times`]).
pub struct StiffnessProduct {
    pub ku: Vec<f64>,
    /// sum over elements T of |K_T| |u| (every term's magnitude): the round-off scale of `ku`.
    pub magnitude: Vec<f64>,
    /// sum over elements T of |K_T| 1: the row's absolute sum, over the unknowns.
    pub row_norm: Vec<f64>,
}

/// One element's share of [`stiffness_times`].
#[derive(Clone, Copy)]
struct ElementProduct {
    ku: [f64; 12],
    magnitude: [f64; 12],
    row_norm: [f64; 12],
    global: [usize; 12],
}

/// One element's share of the system, ready to scatter: its stiffness and load in the local
/// frames, the Dirichlet values of its fixed unknowns, and where its local unknowns go.
#[derive(Clone, Copy)]
struct Contribution {
    k: [[f64; 12]; 12],
    f: [f64; 12],
    global: [usize; 12],
    /// The Dirichlet value of every fixed local unknown (0 at the free ones).
    g: [f64; 12],
    /// The local unknowns by increasing global index, the `n_free` free ones first.
    order: [u8; 12],
    n_free: u8,
}

impl Contribution {
    const ZERO: Contribution =
        Contribution { k: [[0.0; 12]; 12], f: [0.0; 12], global: [FIXED; 12], g: [0.0; 12], order: [0; 12], n_free: 0 };

    /// With `k` and `f` in the local frames: where the local unknowns go, and the Dirichlet
    /// values of the fixed ones.
    fn locate(&mut self, el: &[usize; 6], dofs: &DofMap, dirichlet: &[[f64; 2]]) {
        self.global = std::array::from_fn(|l| dofs.dof[el[l / 2]][l % 2]);
        // Dirichlet nodes are never rotated: their local components are Cartesian
        self.g = std::array::from_fn(|l| if self.global[l] == FIXED { dirichlet[el[l / 2]][l % 2] } else { 0.0 });
        let global = &self.global;
        self.order = std::array::from_fn(|l| l as u8);
        self.order.sort_unstable_by_key(|&l| global[l as usize]);
        self.n_free = global.iter().filter(|&&g| g != FIXED).count() as u8;
    }

    /// Adds the load of local unknown r with the Dirichlet values eliminated,
    /// f_r - sum_fixed K_rl g_l, term by term into `rhs`.
    #[inline]
    fn load(&self, rhs: &mut f64, r: usize) {
        *rhs += self.f[r];
        for l in (0..12).filter(|&l| self.global[l] == FIXED) {
            *rhs -= self.k[r][l] * self.g[l];
        }
    }
}

/// Gauss points per direction of [`split_load`].
pub const SPLIT_POINTS: usize = 12;

/// The load int_T f phi_a (a = 0..5, both components) of a triangle crossed by the vertical line
/// x = c across which f is not smooth (a root singularity such as ((x - c)_+)^(1/2), see
/// `Problem::load_breaks`). An iterated integral: the triangle's x-range is cut at its vertices'
/// x and at c, so that the section [y_lo(x), y_hi(x)] is linear in x on each interval; Gauss in y;
/// in x Gauss after the substitution x = c +- (x_r - x_l) s^2 on the two intervals next to c
/// (which makes ((x - c)_+)^(k/2) smooth in s), plain Gauss elsewhere. Exact to round-off for
/// such f where a Gauss rule on the whole triangle converges only algebraically.
pub fn split_load(map: &Affine, corners: [[f64; 2]; 3], c: f64, f: &dyn Fn([f64; 2]) -> [f64; 2]) -> [f64; 12] {
    let gauss = element::gauss_legendre(SPLIT_POINTS);
    let mut xs: Vec<f64> = corners.iter().map(|v| v[0]).chain([c]).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    // the y-range of the triangle at x strictly between vertex abscissae
    let section = |x: f64| {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for [i, j] in EDGE_VERTICES {
            let (p, q) = (corners[i], corners[j]);
            if (p[0] - x) * (q[0] - x) < 0.0 {
                let y = p[1] + (x - p[0]) / (q[0] - p[0]) * (q[1] - p[1]);
                lo = lo.min(y);
                hi = hi.max(y);
            }
        }
        (lo, hi)
    };
    let mut load = [0.0; 12];
    for w in xs.windows(2) {
        let (xl, xr) = (w[0], w[1]);
        for (s, ws) in gauss.points.iter().zip(&gauss.weights) {
            let s = s[0];
            let (x, jac) = if xl == c {
                (xl + (xr - xl) * s * s, 2.0 * (xr - xl) * s)
            } else if xr == c {
                (xr - (xr - xl) * s * s, 2.0 * (xr - xl) * s)
            } else {
                (xl + (xr - xl) * s, xr - xl)
            };
            let (lo, hi) = section(x);
            if !(hi > lo) {
                continue;
            }
            for (t, wt) in gauss.points.iter().zip(&gauss.weights) {
                let y = lo + (hi - lo) * t[0];
                let r = map.inverse([x, y]);
                let phi = element::p2_values(r[0], r[1]);
                let fx = f([x, y]);
                let weight = ws * jac * wt * (hi - lo);
                for a in 0..N_NODES {
                    load[2 * a] += weight * fx[0] * phi[a];
                    load[2 * a + 1] += weight * fx[1] * phi[a];
                }
            }
        }
    }
    load
}

/// Take the element matrix (and load, if given) to the local frames of its contact nodes:
/// K' = T K T^T, f' = T f with T block diagonal (rotation at contact nodes, identity elsewhere).
#[allow(clippy::needless_range_loop)] // two rows (columns) of k change together
fn rotate(k: &mut [[f64; 12]; 12], mut f: Option<&mut [f64; 12]>, el: &[usize; 6], dofs: &DofMap) {
    for (a, &p) in el.iter().enumerate() {
        let Some(r) = dofs.frame(p) else { continue };
        let (i0, i1) = (2 * a, 2 * a + 1);
        // rows
        for c in 0..12 {
            let (x, y) = (k[i0][c], k[i1][c]);
            k[i0][c] = r[0][0] * x + r[0][1] * y;
            k[i1][c] = r[1][0] * x + r[1][1] * y;
        }
        // columns
        for row in k.iter_mut() {
            let (x, y) = (row[i0], row[i1]);
            row[i0] = r[0][0] * x + r[0][1] * y;
            row[i1] = r[1][0] * x + r[1][1] * y;
        }
        if let Some(f) = f.as_deref_mut() {
            let (x, y) = (f[i0], f[i1]);
            f[i0] = r[0][0] * x + r[0][1] * y;
            f[i1] = r[1][0] * x + r[1][1] * y;
        }
    }
}

/// Add element contributions, in element order, into the matrix and the right-hand side.
/// The unknowns are split into ranges of about equal nonzeros, one per thread: a range takes the
/// matrix entries of its columns and the loads of its rows. Every entry still receives its
/// contributions in element order, so the sums are the same on any number of threads.
fn scatter(matrix: &mut SymCsc, rhs: &mut [f64], local: &[Contribution]) {
    let n = matrix.n();
    let parts = rayon::current_num_threads().max(1);
    let nnz = matrix.values().len();
    let mut bounds = vec![0usize];
    for k in 1..parts {
        bounds.push(matrix.col_ptr().partition_point(|&c| c < k * nnz / parts).min(n).max(*bounds.last().unwrap()));
    }
    bounds.push(n);
    let (col_ptr, row_idx, values) = matrix.structure_and_values_mut();
    let mut jobs = Vec::with_capacity(parts);
    let (mut values, mut rhs_rest) = (values, rhs);
    for w in bounds.windows(2) {
        let (v, vt) = std::mem::take(&mut values).split_at_mut(col_ptr[w[1]] - col_ptr[w[0]]);
        let (r, rt) = std::mem::take(&mut rhs_rest).split_at_mut(w[1] - w[0]);
        jobs.push((w[0], w[1], v, r));
        values = vt;
        rhs_rest = rt;
    }
    jobs.into_par_iter().for_each(|(c0, c1, values, rhs)| {
        let base = col_ptr[c0];
        for e in local {
            let free = &e.order[..e.n_free as usize];
            // the free unknowns are by increasing global index: those of this range are a run
            let first = free.partition_point(|&l| e.global[l as usize] < c0);
            let mut i = first;
            while i < free.len() {
                let c = free[i] as usize;
                let gc = e.global[c];
                if gc >= c1 {
                    break;
                }
                // A node's two unknowns gc, gc + 1 (both in this range): column gc + 1 holds the
                // rows of column gc but gc itself, in the same order (both are the suffixes of
                // the node's sorted list), so one scan of column gc places both columns' entries.
                let pair = free.get(i + 1).map(|&l| l as usize).filter(|&c2| c2 / 2 == c / 2 && e.global[c2] == gc + 1 && gc + 1 < c1);
                e.load(&mut rhs[gc - c0], c);
                if let Some(c2) = pair {
                    e.load(&mut rhs[gc + 1 - c0], c2);
                }
                // the rows below: one forward scan of the column's sorted row indices
                let (lo, hi) = (col_ptr[gc], col_ptr[gc + 1]);
                let mut pos = lo;
                for &r in &free[i..] {
                    let gr = e.global[r as usize];
                    while row_idx[pos] != gr {
                        pos += 1;
                        assert!(pos < hi, "entry outside the sparsity pattern");
                    }
                    values[pos - base] += e.k[r as usize][c];
                    if let Some(c2) = pair.filter(|_| gr != gc) {
                        values[hi + (pos - lo - 1) - base] += e.k[r as usize][c2];
                    }
                }
                i += if pair.is_some() { 2 } else { 1 };
            }
        }
    });
}

/// The P2 basis on an edge, parameter s in [0, 1] from a to b, nodes [a, b, midpoint].
#[inline]
pub fn edge_basis(s: f64) -> [f64; 3] {
    [(1.0 - s) * (1.0 - 2.0 * s), s * (2.0 * s - 1.0), 4.0 * s * (1.0 - s)]
}

/// Outward unit normal and length of a counter-clockwise boundary edge from a to b.
#[inline]
pub fn edge_normal(a: [f64; 2], b: [f64; 2]) -> ([f64; 2], f64) {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
    ([d[1] / len, -d[0] / len], len)
}

fn neumann_load(mesh: &Mesh, nodes: &P2Nodes, dofs: &DofMap, problem: &dyn Problem, rhs: &mut [f64]) {
    for (be, bn) in mesh.boundary.iter().zip(&nodes.boundary_nodes) {
        if be.part != Part::Neumann {
            continue;
        }
        let (a, b) = (mesh.vertices[be.v[0]], mesh.vertices[be.v[1]]);
        let (normal, len) = edge_normal(a, b);
        let mut load = [[0.0; 2]; 3];
        for (s, w, x) in edge_points(a, b) {
            let g = problem.traction(x, normal);
            let phi = edge_basis(s);
            for i in 0..3 {
                load[i][0] += w * len * g[0] * phi[i];
                load[i][1] += w * len * g[1] * phi[i];
            }
        }
        for (i, &p) in bn.iter().enumerate() {
            let l = match dofs.frame(p) {
                Some(r) => [r[0][0] * load[i][0] + r[0][1] * load[i][1], r[1][0] * load[i][0] + r[1][1] * load[i][1]],
                None => load[i],
            };
            for (&d, &lc) in dofs.dof[p].iter().zip(&l) {
                if d != FIXED {
                    rhs[d] += lc;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sym_csc_checks_its_invariant() {
        let ok = |p: Vec<usize>, r: Vec<usize>| SymCsc::new(3, p, r, vec![1.0; 5]);
        assert!(ok(vec![0, 2, 4, 5], vec![0, 2, 1, 2, 2]).is_ok());
        let err = |p: Vec<usize>, r: Vec<usize>| ok(p, r).unwrap_err().0;
        assert!(err(vec![0, 2, 4], vec![0, 2, 1, 2, 2]).contains("column pointers"));
        assert!(err(vec![1, 2, 4, 5], vec![0, 2, 1, 2, 2]).contains("first column pointer"));
        assert!(err(vec![0, 2, 4, 4], vec![0, 2, 1, 2, 2]).contains("last column pointer"));
        assert!(err(vec![0, 4, 2, 5], vec![0, 2, 1, 2, 2]).contains("decrease"));
        assert!(err(vec![0, 9, 2, 5], vec![0, 2, 1, 2, 2]).contains("decrease"));
        assert!(err(vec![0, 2, 4, 5], vec![0, 2, 0, 2, 2]).contains("diagonal"));
        assert!(err(vec![0, 2, 4, 5], vec![0, 0, 1, 2, 2]).contains("strictly increasing"));
        assert!(err(vec![0, 2, 4, 5], vec![0, 3, 1, 2, 2]).contains("out of range"));
    }

    /// The matrix summed the plain way: every element's rotated stiffness added entry by entry,
    /// in element order, into a map keyed by (row, col).
    fn plain_assembly(
        mesh: &Mesh,
        nodes: &P2Nodes,
        dofs: &DofMap,
        problem: &dyn Problem,
    ) -> std::collections::BTreeMap<(usize, usize), f64> {
        let rule = element::triangle_rule(2);
        let mut entries = std::collections::BTreeMap::new();
        for (t, el) in nodes.elements.iter().enumerate() {
            let mut k = element_stiffness(&Affine::new(mesh.corners(t)), problem.material(), &rule);
            rotate(&mut k, None, el, dofs);
            let global: [usize; 12] = std::array::from_fn(|l| dofs.dof[el[l / 2]][l % 2]);
            for (r, &gr) in global.iter().enumerate() {
                for (c, &gc) in global.iter().enumerate() {
                    if gr != FIXED && gc != FIXED && gr >= gc {
                        *entries.entry((gr, gc)).or_insert(0.0) += k[r][c];
                    }
                }
            }
        }
        entries
    }

    /// The pattern holds exactly the couplings of the elements, and every entry is the plain sum
    /// in element order, to the bit, on one thread and on two.
    /// A patch test on structured:100 with oblique contact normals (the local frames are
    /// exercised; 20000 triangles: several element chunks).
    fn oblique_patch() -> (model::problems::Patch, Mesh, P2Nodes, DofMap) {
        let problem = model::problems::Patch { normal: [0.8, -0.6], ..Default::default() };
        let mesh = model::mesh::MeshSpec::parse("structured:100").unwrap().build(&problem).unwrap();
        let nodes = P2Nodes::new(&mesh);
        let dofs = DofMap::new(&nodes, &problem);
        (problem, mesh, nodes, dofs)
    }

    /// `f` on a pool of `threads` threads.
    fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
    }

    #[test]
    fn assembled_matrix_is_the_plain_sum_in_element_order_on_any_thread_count() {
        let (problem, mesh, nodes, dofs) = oblique_patch();
        assert!(!dofs.contact.is_empty() && dofs.n_interior < dofs.n_free && mesh.n_triangles() > 16384);
        let on = |threads: usize| on_threads(threads, || assemble(&mesh, &nodes, &dofs, &problem));
        let (one, two) = (on(1), on(2));
        let plain = plain_assembly(&mesh, &nodes, &dofs, &problem);
        let m = &one.matrix;
        assert_eq!(m.values().len(), plain.len(), "the pattern has exactly the elements' couplings");
        for j in 0..m.n() {
            for k in m.col_ptr()[j]..m.col_ptr()[j + 1] {
                let i = m.row_idx()[k];
                assert_eq!(m.values()[k].to_bits(), plain[&(i, j)].to_bits(), "entry ({i}, {j})");
            }
        }
        assert_eq!((m.col_ptr(), m.row_idx()), (two.matrix.col_ptr(), two.matrix.row_idx()));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(m.values()), bits(two.matrix.values()), "matrix on 1 and 2 threads");
        assert_eq!(bits(&one.rhs), bits(&two.rhs), "load on 1 and 2 threads");
    }

    /// K u element by element is the assembled matrix times u up to round-off (relative to the
    /// sum of the magnitudes of the terms), and the same bits on one thread and on two.
    #[test]
    fn stiffness_times_is_the_matrix_product_on_any_thread_count() {
        let (problem, mesh, nodes, dofs) = oblique_patch();
        assert!(mesh.n_triangles() > 4096, "several chunks of elements");
        let m = assemble(&mesh, &nodes, &dofs, &problem).matrix;
        let u: Vec<f64> = (0..m.n()).map(|i| ((i * 37 % 101) as f64 - 50.0) / 7.0).collect();
        let on = |threads: usize| on_threads(threads, || stiffness_times(&mesh, &nodes, &dofs, problem.material(), &u).ku);
        let (one, two) = (on(1), on(2));
        assert!(one.iter().zip(&two).all(|(a, b)| a.to_bits() == b.to_bits()), "1 and 2 threads differ");
        let assembled = m.mul(&u);
        let abs = SymCsc::new(m.n(), m.col_ptr().to_vec(), m.row_idx().to_vec(), m.values().iter().map(|v| v.abs()).collect()).unwrap();
        let magnitude = abs.mul(&u.iter().map(|v| v.abs()).collect::<Vec<_>>());
        for i in 0..m.n() {
            let diff = (one[i] - assembled[i]).abs();
            assert!(diff <= 64.0 * f64::EPSILON * magnitude[i], "unknown {i}: {} against {} ({diff:.2e})", one[i], assembled[i]);
        }
        // the element-wise magnitude bounds the assembled one (|sum| <= sum ||), up to round-off
        let element_magnitude = stiffness_times(&mesh, &nodes, &dofs, problem.material(), &u).magnitude;
        for i in 0..m.n() {
            assert!(
                element_magnitude[i] >= magnitude[i] * (1.0 - 1e-12),
                "unknown {i}: magnitude {} < {}",
                element_magnitude[i],
                magnitude[i]
            );
        }
    }
}
