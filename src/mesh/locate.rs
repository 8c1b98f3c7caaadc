//! Point location on any triangle mesh: an R*-tree ([`rstar`]) of the triangles' bounding boxes
//! narrows a query to the few triangles whose box holds the point; the point's reference
//! coordinates in each decide.

use super::Mesh;
use crate::base::element::Affine;
use rstar::RTree;
use rstar::primitives::{GeomWithData, Rectangle};

type Boxed = GeomWithData<Rectangle<[f64; 2]>, usize>;

/// Points closer than this to a triangle, in its reference coordinates, lie in it (the probes'
/// tolerance: a point on an edge or at a vertex given in decimal is found).
pub const TOLERANCE: f64 = 1e-12;

/// A triangle found for a point: its index, the point's reference coordinates in it and how far
/// outside it the point is, `max(-r_0, -r_1, r_0 + r_1 - 1, 0)` (0 inside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub triangle: usize,
    pub reference: [f64; 2],
    pub outside: f64,
}

/// The R*-tree of a mesh's triangles. Built once per mesh (O(T log T)); a query costs
/// O(log T) plus the few boxes holding the point.
pub struct Locator {
    tree: RTree<Boxed>,
}

/// The smallest and largest coordinates of a triangle's corners `c`.
pub fn bounding_box(c: [[f64; 2]; 3]) -> ([f64; 2], [f64; 2]) {
    let lo = [c[0][0].min(c[1][0]).min(c[2][0]), c[0][1].min(c[1][1]).min(c[2][1])];
    let hi = [c[0][0].max(c[1][0]).max(c[2][0]), c[0][1].max(c[1][1]).max(c[2][1])];
    (lo, hi)
}

impl Locator {
    pub fn new(mesh: &Mesh) -> Self {
        let boxes = (0..mesh.n_triangles())
            .map(|t| {
                let (lo, hi) = bounding_box(mesh.corners(t));
                // a margin (relative to the box) so that a point on an edge is in the boxes of
                // both triangles whatever the rounding
                let pad = 1e-9 * (hi[0] - lo[0]).max(hi[1] - lo[1]) + 1e-300;
                GeomWithData::new(Rectangle::from_corners([lo[0] - pad, lo[1] - pad], [hi[0] + pad, hi[1] + pad]), t)
            })
            .collect();
        Locator { tree: RTree::bulk_load(boxes) }
    }

    /// The triangle containing `x`, or the one `x` is least outside of: among the triangles whose
    /// box holds `x`, the smallest `(outside, index)`; if no box holds `x`, the triangle of the
    /// nearest box. `None` only for a mesh without triangles.
    pub fn nearest(&self, mesh: &Mesh, x: [f64; 2]) -> Option<Hit> {
        let hit = |t: usize| {
            let r = Affine::new(mesh.corners(t)).inverse(x);
            Hit { triangle: t, reference: r, outside: (-r[0]).max(-r[1]).max(r[0] + r[1] - 1.0).max(0.0) }
        };
        let best = self
            .tree
            .locate_all_at_point(x)
            .map(|b| hit(b.data))
            .min_by(|a, b| a.outside.total_cmp(&b.outside).then(a.triangle.cmp(&b.triangle)));
        best.or_else(|| self.tree.nearest_neighbor(x).map(|b| hit(b.data)))
    }

    /// The triangle containing `x` (up to [`TOLERANCE`]), `None` if `x` is outside the mesh.
    pub fn locate(&self, mesh: &Mesh, x: [f64; 2]) -> Option<Hit> {
        self.nearest(mesh, x).filter(|h| h.outside <= TOLERANCE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problems::Curve;

    /// Point location against brute force (every triangle tried) on a mesh graded towards a
    /// corner of a disc: the same triangle (smallest outside, then smallest index) for points
    /// inside, on edges, at vertices and outside.
    #[test]
    fn rtree_agrees_with_brute_force_on_a_graded_disc() {
        let disc = Curve::Circle { centre: [0.0, 0.0], radius: 1.0 };
        let mut mesh = crate::mesh::tests::disc(disc);
        for _ in 0..6 {
            // grade towards (1, 0): mark the triangles near it
            let marked: Vec<bool> = (0..mesh.n_triangles()).map(|t| crate::mesh::dist(mesh.corners(t)[0], [1.0, 0.0]) < 0.4).collect();
            mesh = crate::mesh::refine::refine(&mesh, &marked).unwrap().mesh;
        }
        let locator = Locator::new(&mesh);
        let brute = |x: [f64; 2]| {
            (0..mesh.n_triangles())
                .map(|t| {
                    let r = Affine::new(mesh.corners(t)).inverse(x);
                    Hit { triangle: t, reference: r, outside: (-r[0]).max(-r[1]).max(r[0] + r[1] - 1.0).max(0.0) }
                })
                .min_by(|a, b| a.outside.total_cmp(&b.outside).then(a.triangle.cmp(&b.triangle)))
                .unwrap()
        };
        let mut points: Vec<[f64; 2]> = mesh.vertices.clone();
        let mut s = 12345u64;
        for _ in 0..2000 {
            let mut next = || {
                s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (s >> 11) as f64 / (1u64 << 53) as f64
            };
            points.push([2.2 * next() - 1.1, 2.2 * next() - 1.1]);
        }
        for t in 0..mesh.n_triangles() {
            let c = mesh.corners(t);
            points.push([0.5 * (c[0][0] + c[1][0]), 0.5 * (c[0][1] + c[1][1])]);
        }
        let (mut inside, mut outside) = (0, 0);
        for x in points {
            let b = brute(x);
            match locator.locate(&mesh, x) {
                Some(h) => {
                    inside += 1;
                    assert!(b.outside <= TOLERANCE, "{x:?} located in {} but brute force finds it outside", h.triangle);
                    assert_eq!((h.triangle, h.outside), (b.triangle, b.outside), "at {x:?}");
                }
                None => {
                    outside += 1;
                    assert!(b.outside > TOLERANCE, "{x:?}: brute force finds triangle {} (outside {})", b.triangle, b.outside);
                }
            }
        }
        assert!(inside > 1000 && outside > 200, "{inside} inside, {outside} outside");
    }
}
