//! Conforming local refinement by newest-vertex bisection (NVB), and transfer of P2 fields.
//!
//! # Convention
//!
//! Every triangle `[a, b, c]` (counter-clockwise) carries its *refinement edge* opposite its
//! first vertex: the edge `(b, c)`; `a` is the *newest vertex*. [`Mesh::unit_square`] lists its
//! triangles so that the square's diagonal is the refinement edge. Bisecting `[a, b, c]` at
//! `m = (b + c) / 2` gives the two children
//!
//! ```text
//!   [m, a, b]   and   [m, c, a]
//! ```
//!
//! which are again counter-clockwise (each has half the parent's signed area) and have the new
//! vertex `m` first, so their refinement edges are `(a, b)` and `(c, a)`: the parent's two other
//! edges.
//!
//! # What NVB guarantees
//!
//! * Every triangle created by repeated NVB is similar to one of at most four triangles per
//!   initial triangle (Mitchell; Sewell), so the minimum angle is bounded below by a constant
//!   depending only on the initial mesh. On the structured right-isosceles meshes of
//!   [`Mesh::unit_square`], whose refinement edges are the hypotenuses, every descendant is a
//!   right isosceles triangle again: the minimum angle stays exactly 45 degrees.
//! * [`refine`] returns a conforming mesh (no hanging nodes): it is the smallest conforming NVB
//!   refinement in which every marked triangle is bisected at least once. The closure marks the
//!   refinement edge of every marked triangle, then repeatedly the refinement edge of every
//!   triangle having some marked edge, until nothing changes; each triangle is then bisected
//!   once, twice or three times (2, 3 or 4 children). Binev, Dahmen and DeVore show that the
//!   number of triangles added by the closures over a whole adaptive run is bounded by a
//!   constant times the number of marked triangles.
//! * Vertices are only added, never moved or removed: old vertex `v` keeps index `v` and its
//!   coordinates (so special vertices, such as the kink of an obstacle, survive). New vertices
//!   are the edge midpoints `0.5 * (p + q)`, appended after the old vertices, except on a curved
//!   boundary edge (one with a [`Curve`](super::Curve)): there the new vertex is the point of the
//!   curve closest to the midpoint ([`Curve::project`](super::Curve::project)), so the mesh's
//!   boundary converges to the curve. The children of such a triangle are then not similar to
//!   the four shapes above, but close to them once the edge is short (the displacement is
//!   O(h^2) against the edge's O(h)); `tests` check that no triangle inverts on a disc refined
//!   many times. The P2 edge midpoints stay on the straight edges (no isoparametric elements).
//! * Boundary edges that are bisected are replaced by their two halves, in place and in the same
//!   direction, with the same [`Part`](super::Part) and curve.
//! * The result is deterministic: edges are numbered in triangle order, new vertices in edge
//!   order, and children are listed in the order of their parents. No hash-map iteration order
//!   is involved.
//! * The cost is O(number of triangles) per call: the edges are found through buckets indexed by
//!   the smaller vertex of each edge (compressed rows), and the closure is a work list.
//!
//! # Why by hand
//!
//! No maintained Rust crate provides conforming newest-vertex bisection on a plain triangle list
//! with tagged boundary edges and a parent map for data transfer; mesh crates either generate
//! Delaunay meshes (whose refinement moves or re-connects vertices) or bring their own data
//! structures. The algorithm is short (the closure plus three bisection patterns), so it is
//! written here against [`Mesh`] directly.

use super::{BoundaryEdge, Mesh, MeshError, P2Nodes};
use crate::base::element::{Affine, p2_values};

/// Marker for "no triangle" in the edge owner table.
const NONE: usize = usize::MAX;

/// The result of [`refine`]: the new mesh and, per new triangle, the old triangle containing it.
#[derive(Clone, Debug)]
pub struct Refinement {
    pub mesh: Mesh,
    /// `parent[t_new]` is the triangle of the old mesh that contains new triangle `t_new`.
    pub parent: Vec<usize>,
}

/// The edges of a mesh: per triangle its three edge numbers (local edges `(0,1)`, `(1,2)`,
/// `(2,0)`, as in [`crate::base::element::EDGE_VERTICES`]) and per edge its one or two triangles.
/// Edges are numbered in order of first appearance in the triangle list.
struct Edges {
    tri_edges: Vec<[usize; 3]>,
    owners: Vec<[usize; 2]>,
    /// Bucket of vertex `v`: `slots[start[v]..start[v] + fill[v]]`, pairs `(other vertex, edge)`
    /// for the edges whose smaller vertex is `v`.
    start: Vec<usize>,
    fill: Vec<usize>,
    slots: Vec<(usize, usize)>,
}

impl Edges {
    fn new(mesh: &Mesh) -> Self {
        let nv = mesh.n_vertices();
        let nt = mesh.n_triangles();
        // every half-edge reserves a slot in the bucket of its smaller vertex (an upper bound)
        let mut start = vec![0usize; nv + 1];
        for tri in &mesh.triangles {
            for [i, j] in crate::base::element::EDGE_VERTICES {
                start[tri[i].min(tri[j]) + 1] += 1;
            }
        }
        for v in 0..nv {
            start[v + 1] += start[v];
        }
        let mut edges = Edges {
            tri_edges: Vec::with_capacity(nt),
            owners: Vec::with_capacity(3 * nt / 2 + 2),
            start,
            fill: vec![0; nv],
            slots: vec![(0, 0); 3 * nt],
        };
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let mut te = [0; 3];
            for (le, [i, j]) in crate::base::element::EDGE_VERTICES.iter().enumerate() {
                let (lo, hi) = super::key(tri[*i], tri[*j]);
                te[le] = match edges.find(lo, hi) {
                    Some(e) => {
                        let o = &mut edges.owners[e];
                        assert!(o[1] == NONE, "edge ({lo}, {hi}) is shared by more than two triangles: the mesh is not conforming");
                        o[1] = t;
                        e
                    }
                    None => {
                        let e = edges.owners.len();
                        edges.owners.push([t, NONE]);
                        edges.slots[edges.start[lo] + edges.fill[lo]] = (hi, e);
                        edges.fill[lo] += 1;
                        e
                    }
                };
            }
            edges.tri_edges.push(te);
        }
        edges
    }

    /// The edge `(lo, hi)`, `lo < hi`, if it exists.
    #[inline]
    fn find(&self, lo: usize, hi: usize) -> Option<usize> {
        let s = self.start[lo];
        self.slots[s..s + self.fill[lo]].iter().find(|(w, _)| *w == hi).map(|&(_, e)| e)
    }

    fn len(&self) -> usize {
        self.owners.len()
    }
}

/// Conforming newest-vertex bisection: every triangle `t` with `marked[t]` is bisected at least
/// once, and further triangles are bisected (recursively across refinement edges) until the mesh
/// has no hanging nodes. See the [module documentation](self) for the convention and the
/// guarantees. With no marks the mesh is returned unchanged (and `parent[t] == t`).
///
/// A new vertex put on a curve (the closest point to a curved boundary edge's midpoint) can
/// turn a child triangle over where the mesh is thinner there than the curve's sagitta over the
/// edge (a concave curve, a hole): that is refused by name ([`MeshError::TurnedByCurve`]), as the
/// projection's doing, not the mesh's vertex order.
///
/// # Panics
/// If `marked.len()` differs from the number of triangles, or the mesh is not conforming (an edge
/// in three triangles, or a boundary edge that is no edge of a triangle).
pub fn refine(mesh: &Mesh, marked: &[bool]) -> Result<Refinement, MeshError> {
    let nt = mesh.n_triangles();
    assert_eq!(marked.len(), nt, "one mark per triangle is needed");
    let edges = Edges::new(mesh);

    // Closure: the set of bisected edges is the smallest set containing the refinement edge of
    // every marked triangle and the refinement edge of every triangle with a bisected edge.
    let mut split = vec![false; edges.len()];
    let mut work: Vec<usize> = Vec::new();
    let mark_edge = |e: usize, split: &mut [bool], work: &mut Vec<usize>| {
        if !split[e] {
            split[e] = true;
            work.extend(edges.owners[e].into_iter().filter(|&t| t != NONE));
        }
    };
    for (t, &m) in marked.iter().enumerate() {
        if m {
            mark_edge(edges.tri_edges[t][1], &mut split, &mut work);
        }
    }
    while let Some(t) = work.pop() {
        let [e0, e1, e2] = edges.tri_edges[t];
        if split[e0] || split[e2] {
            mark_edge(e1, &mut split, &mut work);
        }
    }

    // New vertices: the midpoints of the bisected edges, in edge order.
    let mut vertices = mesh.vertices.clone();
    let mut midpoint = vec![NONE; edges.len()];
    // every curved boundary edge, by edge number
    let mut curved: Vec<Option<BoundaryEdge>> = vec![None; edges.len()];
    for be in mesh.boundary.iter().filter(|be| be.curve.is_some()) {
        let (lo, hi) = super::key(be.v[0], be.v[1]);
        if let Some(e) = edges.find(lo, hi) {
            curved[e] = Some(*be);
        }
    }
    let n_split = split.iter().filter(|&&s| s).count();
    vertices.reserve(n_split);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        // visiting the edges through the triangles gives them in edge order (first appearance)
        for (le, [i, j]) in crate::base::element::EDGE_VERTICES.iter().enumerate() {
            let e = edges.tri_edges[t][le];
            if split[e] && midpoint[e] == NONE {
                let (p, q) = (mesh.vertices[tri[*i]], mesh.vertices[tri[*j]]);
                midpoint[e] = vertices.len();
                let m = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
                vertices.push(curved[e].and_then(|be| be.curve).map_or(m, |c: super::Curve| c.project(m)));
            }
        }
    }

    // Bisection: 1, 2, 3 or 4 children per triangle, in parent order.
    let mut triangles = Vec::with_capacity(nt + 3 * n_split);
    let mut parent = Vec::with_capacity(nt + 3 * n_split);
    for (t, &[a, b, c]) in mesh.triangles.iter().enumerate() {
        let [e0, e1, e2] = edges.tri_edges[t];
        if !split[e1] {
            debug_assert!(!split[e0] && !split[e2], "closure left a hanging node in triangle {t}");
            triangles.push([a, b, c]);
            parent.push(t);
            continue;
        }
        let m = midpoint[e1];
        // left child [m, a, b], refinement edge (a, b) = local edge 0 of the parent
        if split[e0] {
            let p = midpoint[e0];
            triangles.push([p, m, a]);
            triangles.push([p, b, m]);
            parent.extend([t, t]);
        } else {
            triangles.push([m, a, b]);
            parent.push(t);
        }
        // right child [m, c, a], refinement edge (c, a) = local edge 2 of the parent
        if split[e2] {
            let q = midpoint[e2];
            triangles.push([q, m, c]);
            triangles.push([q, a, m]);
            parent.extend([t, t]);
        } else {
            triangles.push([m, c, a]);
            parent.push(t);
        }
    }

    // Boundary: bisected edges become their two halves, same direction and part.
    let mut boundary = Vec::with_capacity(mesh.boundary.len() + n_split.min(mesh.boundary.len()));
    for be in &mesh.boundary {
        let [u, v] = be.v;
        let (lo, hi) = super::key(u, v);
        let e = edges.find(lo, hi).unwrap_or_else(|| panic!("boundary edge ({u}, {v}) is not an edge of any triangle"));
        if split[e] {
            let m = midpoint[e];
            boundary.push(BoundaryEdge { v: [u, m], ..*be });
            boundary.push(BoundaryEdge { v: [m, v], ..*be });
        } else {
            boundary.push(*be);
        }
    }

    let mesh = Mesh { vertices, triangles, boundary };
    check_projected(&mesh, &curved, &midpoint)?;
    Ok(Refinement { mesh, parent })
}

/// Every triangle of the refined `mesh` with a vertex put on a curve has positive area (see
/// [`refine`]); `curved` (the curved boundary edges) and `midpoint` are by edge of the parent
/// mesh, whose vertices keep their numbers.
fn check_projected(mesh: &Mesh, curved: &[Option<BoundaryEdge>], midpoint: &[usize]) -> Result<(), MeshError> {
    let mut on_curve = std::collections::HashMap::new();
    for (e, be) in curved.iter().enumerate() {
        if let (Some(be), true) = (be, midpoint[e] != NONE) {
            on_curve.insert(midpoint[e], (*be, e));
        }
    }
    if on_curve.is_empty() {
        return Ok(());
    }
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let Some(&(be, e)) = tri.iter().find_map(|v| on_curve.get(v)) else { continue };
        let area = mesh.area(t);
        if !(area > 0.0) {
            let edge = be.v.map(|v| mesh.vertices[v]);
            let curve = be.curve.expect("a curved edge");
            return Err(MeshError::TurnedByCurve { t, area, edge, at: mesh.vertices[midpoint[e]], curve, part: be.part });
        }
    }
    Ok(())
}

/// Evaluate the P2 field with nodal values `values` (numbered by `old_nodes`) at every node of
/// the refined mesh (numbered by `new_nodes`). The refined P2 space contains the old one, so the
/// field is reproduced exactly (up to rounding): each new node is located in its parent triangle
/// through `refinement.parent` and the parent's affine map, and the parent's six basis functions
/// are evaluated there. Old vertices keep their index, so their values are copied unchanged.
///
/// Works for any number of components `D` (a scalar field is `[f64; 1]`, a displacement
/// `[f64; 2]`).
pub fn transfer_p2<const D: usize>(
    old: &Mesh,
    old_nodes: &P2Nodes,
    values: &[[f64; D]],
    refinement: &Refinement,
    new_nodes: &P2Nodes,
) -> Vec<[f64; D]> {
    assert_eq!(values.len(), old_nodes.len(), "one value per old P2 node is needed");
    assert_eq!(old_nodes.elements.len(), old.n_triangles(), "old_nodes does not belong to the old mesh");
    assert_eq!(new_nodes.elements.len(), refinement.mesh.n_triangles(), "new_nodes does not belong to the refined mesh");
    assert_eq!(refinement.parent.len(), refinement.mesh.n_triangles());
    let nv_old = old.n_vertices();
    assert!(new_nodes.n_vertices >= nv_old);
    let mut out = vec![[0.0; D]; new_nodes.len()];
    let mut done = vec![false; new_nodes.len()];
    // old vertices are new vertices with the same index
    out[..nv_old].copy_from_slice(&values[..nv_old]);
    done[..nv_old].fill(true);
    let mut current = NONE;
    let mut map = Affine::new([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    for (t, nodes) in new_nodes.elements.iter().enumerate() {
        let p = refinement.parent[t];
        for &n in nodes {
            if done[n] {
                continue;
            }
            if p != current {
                map = Affine::new(old.corners(p));
                current = p;
            }
            let r = map.inverse(new_nodes.coords[n]);
            let phi = p2_values(r[0], r[1]);
            let mut v = [0.0; D];
            for (k, &on) in old_nodes.elements[p].iter().enumerate() {
                for d in 0..D {
                    v[d] += phi[k] * values[on][d];
                }
            }
            out[n] = v;
            done[n] = true;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::{Part, dist};
    use super::*;
    use std::collections::{HashMap, HashSet};

    fn tag(x: [f64; 2]) -> Part {
        if x[1] < 1e-12 {
            Part::Contact
        } else if x[1] > 1.0 - 1e-12 {
            Part::Dirichlet
        } else {
            Part::Neumann
        }
    }

    /// Knuth's MMIX linear congruential generator: deterministic pseudo-random numbers.
    struct Lcg(u64);

    impl Lcg {
        fn next_f64(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn total_area(m: &Mesh) -> f64 {
        (0..m.n_triangles()).map(|t| m.area(t)).sum()
    }

    fn length_by_part(m: &Mesh) -> HashMap<&'static str, f64> {
        let mut len = HashMap::new();
        for e in &m.boundary {
            let name = match e.part {
                Part::Dirichlet => "D",
                Part::Neumann => "N",
                Part::Contact => "C",
            };
            *len.entry(name).or_insert(0.0) += dist(m.vertices[e.v[0]], m.vertices[e.v[1]]);
        }
        len
    }

    /// Barycentric coordinates of `x` in triangle `t`.
    fn barycentric(m: &Mesh, t: usize, x: [f64; 2]) -> [f64; 3] {
        let r = Affine::new(m.corners(t)).inverse(x);
        [1.0 - r[0] - r[1], r[0], r[1]]
    }

    fn sorted(tri: [usize; 3]) -> [usize; 3] {
        let mut s = tri;
        s.sort_unstable();
        s
    }

    /// Every property one refinement step must have.
    fn check_step(old: &Mesh, marked: &[bool], r: &Refinement) {
        let new = &r.mesh;
        new.check().unwrap();
        assert!((total_area(new) - 1.0).abs() < 1e-12, "area {}", total_area(new));
        let angle = new.min_angle_degrees();
        assert!(angle >= 45.0 - 1e-9, "min angle {angle}");
        // old vertices unchanged, new ones appended
        assert!(new.n_vertices() >= old.n_vertices());
        assert_eq!(&new.vertices[..old.n_vertices()], &old.vertices[..]);
        // every marked triangle was refined
        let new_tris: HashSet<[usize; 3]> = new.triangles.iter().map(|&t| sorted(t)).collect();
        for (t, &m) in marked.iter().enumerate() {
            if m {
                assert!(!new_tris.contains(&sorted(old.triangles[t])), "marked triangle {t} was not refined");
            }
        }
        // parents: children lie inside their parent and tile it
        assert_eq!(r.parent.len(), new.n_triangles());
        let mut child_area = vec![0.0; old.n_triangles()];
        for (t, &p) in r.parent.iter().enumerate() {
            child_area[p] += new.area(t);
            for x in new.corners(t) {
                assert!(barycentric(old, p, x).iter().all(|&l| l > -1e-12), "child {t} leaves parent {p}");
            }
        }
        for (p, a) in child_area.iter().enumerate() {
            assert!((a - old.area(p)).abs() < 1e-14, "children of {p} do not tile it");
        }
        // new vertices are midpoints of old or new edges: no vertex repeats
        let mut seen: Vec<[u64; 2]> = new.vertices.iter().map(|v| [v[0].to_bits(), v[1].to_bits()]).collect();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), new.n_vertices(), "duplicate vertex");
        // boundary: same length per part, on the same sides, counter-clockwise
        let (lo, ln) = (length_by_part(old), length_by_part(new));
        assert_eq!(lo.len(), ln.len());
        for (k, l) in &lo {
            assert!((l - ln[k]).abs() < 1e-12, "length of part {k} changed: {l} -> {}", ln[k]);
        }
        let directed: HashSet<(usize, usize)> = new.triangles.iter().flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)]).collect();
        for e in &new.boundary {
            let (p, q) = (new.vertices[e.v[0]], new.vertices[e.v[1]]);
            assert!(directed.contains(&(e.v[0], e.v[1])), "boundary edge {:?} is not counter-clockwise", e.v);
            match e.part {
                Part::Contact => assert!(p[1] == 0.0 && q[1] == 0.0),
                Part::Dirichlet => assert!(p[1] == 1.0 && q[1] == 1.0),
                Part::Neumann => assert!((p[0] == 0.0 && q[0] == 0.0) || (p[0] == 1.0 && q[0] == 1.0)),
            }
        }
    }

    /// 30 levels of refinement with random marks, and local marks near (1, 0.5).
    fn refine_many(mirror: bool) -> Mesh {
        let mut mesh = Mesh::unit_square(4, mirror, &tag);
        let mut rng = Lcg(if mirror { 7 } else { 42 });
        let focus = [1.0, 0.5];
        for level in 0..30 {
            let nt = mesh.n_triangles();
            // about 10% on small meshes, then a handful, so the test stays fast in debug builds
            let p = if nt < 1500 { 0.1 } else { 8.0 / nt as f64 };
            let mut marked: Vec<bool> = (0..nt).map(|_| rng.next_f64() < p).collect();
            if level % 2 == 1 {
                for (t, m) in marked.iter_mut().enumerate() {
                    if barycentric(&mesh, t, focus).iter().all(|&l| l > -1e-12) {
                        *m = true;
                    }
                }
            }
            let r = refine(&mesh, &marked).unwrap();
            check_step(&mesh, &marked, &r);
            mesh = r.mesh;
        }
        mesh
    }

    #[test]
    fn thirty_levels_structured() {
        let m = refine_many(false);
        // the local refinement at (1, 0.5) went deep: 15 marked levels around the point
        let (hmin, hmax) = m.h_range();
        assert!(hmin < 2.0f64.powf(-6.0) && hmax <= 0.25 * 2f64.sqrt() + 1e-12, "h range ({hmin}, {hmax})");
    }

    #[test]
    fn thirty_levels_mirrored() {
        let m = refine_many(true);
        assert!(m.h_range().0 < 2.0f64.powf(-6.0));
    }

    #[test]
    fn single_bisection_of_the_diagonal() {
        // unit_square(1): vertices 0 (0,0), 1 (1,0), 2 (0,1), 3 (1,1); triangles [1,3,0], [2,0,3]
        let mesh = Mesh::unit_square(1, false, &tag);
        let r = refine(&mesh, &[true, false]).unwrap();
        assert_eq!(r.mesh.vertices[4], [0.5, 0.5]);
        assert_eq!(r.mesh.triangles, vec![[4, 1, 3], [4, 0, 1], [4, 2, 0], [4, 3, 2]]);
        assert_eq!(r.parent, vec![0, 0, 1, 1]);
        assert_eq!(r.mesh.boundary, mesh.boundary);
        // second step: bisecting [4, 1, 3] splits the right side (1, 3), so its neighbour
        // across that boundary edge is alone; the closure also bisects nothing else
        let r2 = refine(&r.mesh, &[true, false, false, false]).unwrap();
        r2.mesh.check().unwrap();
        assert_eq!(r2.mesh.vertices[5], [1.0, 0.5]);
        assert_eq!(&r2.mesh.triangles[..2], &[[5, 4, 1], [5, 3, 4]]);
        assert_eq!(r2.mesh.n_triangles(), 5);
        let right: Vec<_> = r2.mesh.boundary.iter().filter(|e| e.v.contains(&5)).map(|e| e.v).collect();
        assert_eq!(right, vec![[1, 5], [5, 3]]);
    }

    #[test]
    fn closure_propagates_across_refinement_edges() {
        // unit_square(4): triangle 0 is [b, c, a] in the square [0, 0.25]^2 (a lower left, b lower
        // right, c upper right). Bisecting it (and its diagonal partner, triangle 1) gives first
        // the child [m, b, c] with refinement edge (b, c), the square's right side x = 0.25.
        let mesh = Mesh::unit_square(4, false, &tag);
        let mut marked = vec![false; mesh.n_triangles()];
        marked[0] = true;
        let r1 = refine(&mesh, &marked).unwrap();
        check_step(&mesh, &marked, &r1);
        assert_eq!(r1.mesh.n_triangles(), 34);
        let once = r1.mesh;
        let [m, b, c] = once.triangles[0];
        assert_eq!((once.vertices[m], once.vertices[b], once.vertices[c]), ([0.125, 0.125], [0.25, 0.0], [0.25, 0.25]));
        // Marking it: the neighbour across x = 0.25 has its diagonal as refinement edge, so the
        // closure bisects that neighbour twice (3 children) and its diagonal partner once.
        let mut marked = vec![false; once.n_triangles()];
        marked[0] = true;
        let r = refine(&once, &marked).unwrap();
        check_step(&once, &marked, &r);
        assert_eq!(r.mesh.n_triangles(), 34 + 1 + 2 + 1);
        assert_eq!(r.mesh.n_vertices(), once.n_vertices() + 2);
    }

    #[test]
    fn no_marks_returns_the_same_mesh() {
        for mirror in [false, true] {
            let mesh = Mesh::unit_square(4, mirror, &tag);
            let r = refine(&mesh, &vec![false; mesh.n_triangles()]).unwrap();
            assert_eq!(r.mesh.vertices, mesh.vertices);
            assert_eq!(r.mesh.triangles, mesh.triangles);
            assert_eq!(r.mesh.boundary, mesh.boundary);
            assert_eq!(r.parent, (0..mesh.n_triangles()).collect::<Vec<_>>());
        }
    }

    #[test]
    fn refinement_is_deterministic() {
        let mesh = Mesh::unit_square(6, true, &tag);
        let mut rng = Lcg(3);
        let marked: Vec<bool> = (0..mesh.n_triangles()).map(|_| rng.next_f64() < 0.3).collect();
        let (a, b) = (refine(&mesh, &marked).unwrap(), refine(&mesh, &marked).unwrap());
        assert_eq!(a.mesh.vertices, b.mesh.vertices);
        assert_eq!(a.mesh.triangles, b.mesh.triangles);
        assert_eq!(a.mesh.boundary, b.mesh.boundary);
        assert_eq!(a.parent, b.parent);
    }

    /// Refinement of a disc with its boundary on the circle: new boundary vertices lie on the
    /// circle, no triangle inverts, and under uniform refinement the mesh is the regular polygon
    /// inscribed in the circle, whose area N/2 r^2 sin(2 pi / N) tends to pi r^2 like N^-2.
    #[test]
    fn curved_boundary_refinement_stays_on_the_circle() {
        let (centre, radius) = ([0.3, -0.2], 1.7);
        let circle = super::super::Curve::Circle { centre, radius };
        let on_circle = |m: &Mesh| {
            for e in &m.boundary {
                assert_eq!(e.curve, Some(circle));
                for v in e.v {
                    let p = m.vertices[v];
                    let r = (p[0] - centre[0]).hypot(p[1] - centre[1]);
                    assert!((r - radius).abs() <= 1e-14 * radius, "boundary vertex {p:?} at distance {r} from the centre");
                }
            }
        };
        // uniform: every triangle marked
        let mut mesh = super::super::tests::disc(circle);
        let mut rows = Vec::new();
        for _ in 0..14 {
            mesh = refine(&mesh, &vec![true; mesh.n_triangles()]).unwrap().mesh;
            mesh.check().unwrap();
            on_circle(&mesh);
            let n = mesh.boundary.len() as f64;
            let polygon = 0.5 * n * radius * radius * (2.0 * std::f64::consts::PI / n).sin();
            // to the round-off of summing up to 2^15 triangle areas
            assert!(
                (total_area(&mesh) - polygon).abs() < 1e-12 * polygon,
                "area {} against the inscribed {n}-gon's {polygon}",
                total_area(&mesh)
            );
            rows.push((n, std::f64::consts::PI * radius * radius - total_area(&mesh)));
        }
        // the last levels: the error falls like N^-2 (the slope of log error in log N)
        let (a, b) = (rows[rows.len() - 3], rows[rows.len() - 1]);
        let slope = (b.1 / a.1).ln() / (b.0 / a.0).ln();
        assert!((slope + 2.0).abs() < 0.01, "area error falls like N^{slope}: {rows:?}");
        assert!(rows.last().unwrap().1 > 0.0 && rows.last().unwrap().1 < 1e-4, "{rows:?}");
        // local: random marks and marks near a boundary point, 30 levels
        let mut mesh = super::super::tests::disc(circle);
        let mut rng = Lcg(5);
        let focus = [centre[0] + radius * 0.6, centre[1] - radius * 0.8];
        for level in 0..30 {
            let nt = mesh.n_triangles();
            let p = if nt < 1500 { 0.1 } else { 8.0 / nt as f64 };
            let marked: Vec<bool> = (0..nt)
                .map(|t| rng.next_f64() < p || (level % 2 == 1 && mesh.corners(t).iter().any(|&c| dist(c, focus) < 1.5 * mesh.diameter(t))))
                .collect();
            let r = refine(&mesh, &marked).unwrap();
            r.mesh.check().unwrap(); // positive areas, conforming, boundary tagged
            on_circle(&r.mesh);
            assert!(r.mesh.min_angle_degrees() > 10.0, "min angle {}", r.mesh.min_angle_degrees());
            // the inscribed polygon only grows (up to the round-off of the sum), inside the disc
            let (before, after) = (total_area(&mesh), total_area(&r.mesh));
            assert!(after >= before * (1.0 - 1e-13) && after < std::f64::consts::PI * radius * radius, "area {before} -> {after}");
            mesh = r.mesh;
        }
        assert!(mesh.h_range().0 < 1e-2, "the refinement went deep: {:?}", mesh.h_range());
    }

    #[test]
    fn transfer_reproduces_quadratics() {
        let u = |x: [f64; 2]| [x[0] * x[0] + 3.0 * x[0] * x[1] - x[1], x[1] * x[1] - x[0]];
        for mirror in [false, true] {
            let mut mesh = Mesh::unit_square(4, mirror, &tag);
            let mut rng = Lcg(11);
            for _ in 0..6 {
                let nodes = P2Nodes::new(&mesh);
                let values: Vec<[f64; 2]> = nodes.coords.iter().map(|&x| u(x)).collect();
                let marked: Vec<bool> = (0..mesh.n_triangles()).map(|_| rng.next_f64() < 0.25).collect();
                let r = refine(&mesh, &marked).unwrap();
                let new_nodes = P2Nodes::new(&r.mesh);
                let moved = transfer_p2(&mesh, &nodes, &values, &r, &new_nodes);
                assert_eq!(moved.len(), new_nodes.len());
                for (x, v) in new_nodes.coords.iter().zip(&moved) {
                    let e = u(*x);
                    assert!((v[0] - e[0]).abs() < 1e-13 && (v[1] - e[1]).abs() < 1e-13, "at {x:?}: {v:?} vs {e:?}");
                }
                // a scalar field through the same function
                let s: Vec<[f64; 1]> = values.iter().map(|v| [v[0]]).collect();
                let moved_s = transfer_p2(&mesh, &nodes, &s, &r, &new_nodes);
                for (a, b) in moved_s.iter().zip(&moved) {
                    assert_eq!(a[0], b[0]);
                }
                mesh = r.mesh;
            }
        }
    }
}
