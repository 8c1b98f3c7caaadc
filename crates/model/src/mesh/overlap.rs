//! Triangles whose interiors overlap: two bodies meshed in one place, two bodies crossing each
//! other, or one body wrapped onto itself. The topology of such a mesh can be perfect (each body
//! conforming on its own), so the check is geometric: an R*-tree ([`rstar`], as in
//! [`locate`](super::locate)) of the triangles' bounding boxes gives the candidate pairs, whose
//! boxes overlap; the separating axis test on the two triangles' six edge normals decides.
//!
//! Triangles that share an edge or a vertex touch without overlapping: their projections on the
//! separating axis meet in a point, up to round-off. An axis separates two triangles when their
//! projections overlap by at most [`TOLERANCE`] times the larger triangle's diameter, measured
//! from a vertex of one of them (so that a mesh far from the origin is judged by its own size).

use rayon::prelude::*;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{AABB, RTree};

/// How deep, relative to the larger of the two triangles' diameters, projections may overlap on
/// a separating axis and still count as touching (round-off on a shared edge is ~1e-16).
pub const TOLERANCE: f64 = 1e-9;

/// Two triangles (indices, `a < b`) whose interiors overlap, and a point inside both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Overlap {
    pub a: usize,
    pub b: usize,
    pub point: [f64; 2],
}

/// The first pair of overlapping triangles (smallest `a`, then smallest `b`), if any. The
/// triangles are counter-clockwise vertex triples of `vertices` (areas positive: checked before).
pub fn find(vertices: &[[f64; 2]], triangles: &[[usize; 3]]) -> Option<Overlap> {
    let corners = |t: usize| triangles[t].map(|v| vertices[v]);
    let boxes: Vec<GeomWithData<Rectangle<[f64; 2]>, usize>> = (0..triangles.len())
        .map(|t| {
            let (lo, hi) = super::locate::bounding_box(corners(t));
            GeomWithData::new(Rectangle::from_corners(lo, hi), t)
        })
        .collect();
    let tree = RTree::bulk_load(boxes);
    (0..triangles.len()).into_par_iter().find_map_first(|a| {
        let (lo, hi) = super::locate::bounding_box(corners(a));
        tree.locate_in_envelope_intersecting(AABB::from_corners(lo, hi))
            .map(|g| g.data)
            .filter(|&b| b > a)
            .filter_map(|b| overlap(corners(a), corners(b)).map(|point| Overlap { a, b, point }))
            .min_by_key(|o| o.b)
    })
}

/// A point inside both counter-clockwise triangles `p` and `q` if their interiors overlap (no
/// edge normal separates them beyond [`TOLERANCE`]), else `None`.
pub fn overlap(p: [[f64; 2]; 3], q: [[f64; 2]; 3]) -> Option<[f64; 2]> {
    // coordinates relative to a vertex of p: the round-off is that of the triangles' size
    let o = p[0];
    let rel = |t: [[f64; 2]; 3]| t.map(|v| [v[0] - o[0], v[1] - o[1]]);
    let (p, q) = (rel(p), rel(q));
    let diameter = |t: &[[f64; 2]; 3]| (0..3).map(|i| super::dist(t[i], t[(i + 1) % 3])).fold(0.0, f64::max);
    let h = diameter(&p).max(diameter(&q));
    for t in [&p, &q] {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let n = [b[1] - a[1], a[0] - b[0]];
            let project = |s: &[[f64; 2]; 3]| {
                let d = s.map(|v| n[0] * v[0] + n[1] * v[1]);
                (d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2]))
            };
            let ((p0, p1), (q0, q1)) = (project(&p), project(&q));
            if p1.min(q1) - p0.max(q0) <= TOLERANCE * h * n[0].hypot(n[1]) {
                return None;
            }
        }
    }
    let inside = clip(&p, &q);
    if inside.is_empty() {
        return None;
    }
    let k = inside.len() as f64;
    let c = inside.iter().fold([0.0, 0.0], |c, v| [c[0] + v[0] / k, c[1] + v[1] / k]);
    Some([c[0] + o[0], c[1] + o[1]])
}

/// The polygon `p ∩ q` (Sutherland-Hodgman: `p` clipped by each edge of the counter-clockwise
/// `q`), empty if they do not meet; its vertex average lies inside both.
fn clip(p: &[[f64; 2]; 3], q: &[[f64; 2]; 3]) -> Vec<[f64; 2]> {
    let mut poly: Vec<[f64; 2]> = p.to_vec();
    for i in 0..3 {
        let (a, b) = (q[i], q[(i + 1) % 3]);
        // > 0 on the left of a -> b, inside q
        let side = |v: [f64; 2]| (b[0] - a[0]) * (v[1] - a[1]) - (b[1] - a[1]) * (v[0] - a[0]);
        let mut out = Vec::with_capacity(poly.len() + 1);
        for j in 0..poly.len() {
            let (u, v) = (poly[j], poly[(j + 1) % poly.len()]);
            let (su, sv) = (side(u), side(v));
            if su >= 0.0 {
                out.push(u);
            }
            if (su >= 0.0) != (sv >= 0.0) {
                let t = su / (su - sv);
                out.push([u[0] + t * (v[0] - u[0]), u[1] + t * (v[1] - u[1])]);
            }
        }
        poly = out;
        if poly.is_empty() {
            break;
        }
    }
    poly
}

#[cfg(test)]
mod tests {
    use super::*;

    const UNIT: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

    fn shifted(t: [[f64; 2]; 3], d: [f64; 2]) -> [[f64; 2]; 3] {
        t.map(|v| [v[0] + d[0], v[1] + d[1]])
    }

    /// Neighbours touch, copies and crossings overlap with the point in both; far from the
    /// origin too (the tolerance is the triangles' size, not their coordinates').
    #[test]
    fn touching_passes_overlapping_is_found() {
        for origin in [[0.0, 0.0], [1e9, -3e8]] {
            let s = |t| shifted(t, origin);
            let other_side = s([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
            assert_eq!(overlap(s(UNIT), other_side), None, "sharing an edge");
            assert_eq!(overlap(s(UNIT), s([[1.0, 0.0], [2.0, 0.0], [1.0, 1.0]])), None, "sharing a vertex");
            assert_eq!(overlap(s(UNIT), s(shifted(UNIT, [0.5, 0.5]))), None, "a vertex on an edge");
            for d in [[0.0, 0.0], [0.5, 0.0], [0.25, 0.25], [-0.2, 0.1]] {
                let x = overlap(s(UNIT), s(shifted(UNIT, d))).unwrap_or_else(|| panic!("shift {d:?} at {origin:?}"));
                let r = [x[0] - origin[0], x[1] - origin[1]];
                let inside = |t: [[f64; 2]; 3]| {
                    let v = [r[0] - t[0][0], r[1] - t[0][1]];
                    v[0] > 0.0 && v[1] > 0.0 && v[0] + v[1] < 1.0
                };
                assert!(inside(UNIT) && inside(shifted(UNIT, d)), "{x:?} not in both for shift {d:?}");
            }
        }
    }

    /// What the check costs on a large mesh (run with `--ignored --nocapture`): the full
    /// [`Mesh::check`](crate::mesh::Mesh::check) and the overlap search alone.
    #[test]
    #[ignore]
    fn cost_on_structured_512() {
        let m = crate::mesh::Mesh::unit_square(512, false, &|_| crate::problems::Part::Neumann);
        for _ in 0..3 {
            let t = std::time::Instant::now();
            assert_eq!(find(&m.vertices, &m.triangles), None);
            let search = t.elapsed();
            let t = std::time::Instant::now();
            m.check().unwrap();
            println!("{} triangles: overlap search {search:?}, Mesh::check {:?}", m.n_triangles(), t.elapsed());
        }
    }

    /// A refined mesh of the disc has no overlap; the same mesh beside a copy shifted by a
    /// quarter of its size does, named by a triangle of each copy.
    #[test]
    fn a_mesh_and_its_shifted_copy() {
        let disc = crate::problems::Curve::Circle { centre: [0.0, 0.0], radius: 1.0 };
        let mut mesh = crate::mesh::tests::disc(disc);
        for _ in 0..4 {
            mesh = crate::mesh::refine::refine(&mesh, &vec![true; mesh.n_triangles()]).unwrap().mesh;
        }
        assert_eq!(find(&mesh.vertices, &mesh.triangles), None);
        let n = mesh.n_vertices();
        let mut vertices = mesh.vertices.clone();
        vertices.extend(mesh.vertices.iter().map(|v| [v[0] + 0.5, v[1]]));
        let mut triangles = mesh.triangles.clone();
        triangles.extend(mesh.triangles.iter().map(|t| t.map(|v| v + n)));
        let o = find(&vertices, &triangles).expect("two discs crossing");
        assert!(o.a < mesh.n_triangles() && o.b >= mesh.n_triangles(), "{o:?}");
    }
}
