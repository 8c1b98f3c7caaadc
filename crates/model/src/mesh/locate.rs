//! Point location on any triangle mesh: an R*-tree ([`rstar`]) of the triangles' bounding boxes
//! narrows a query to the few triangles whose box holds the point; the point's reference
//! coordinates in each decide.

use super::Mesh;
use crate::base::element::Affine;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{PointDistance, RTree};

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

/// Where `x` is in triangle `t`: its reference coordinates and how far outside.
fn hit(mesh: &Mesh, x: [f64; 2], t: usize) -> Hit {
    let r = Affine::new(mesh.corners(t)).inverse(x);
    Hit { triangle: t, reference: r, outside: (-r[0]).max(-r[1]).max(r[0] + r[1] - 1.0).max(0.0) }
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
        Self::best(mesh, x, self.tree.locate_all_at_point(x)).or_else(|| self.tree.nearest_neighbor(x).map(|b| hit(mesh, x, b.data)))
    }

    /// [`Locator::nearest`] of every point of `xs`, for points that lie close together (the
    /// sampling points of one triangle of another mesh): the triangles whose box meets the
    /// points' bounding box are found in one query, and each point picks among those whose box
    /// holds it, as `nearest` does among the same triangles, so the hits are `nearest`'s point by
    /// point. A point that no shared box holds (outside the mesh), and every point where the
    /// points' box meets more than [`Locator::SHARED_MAX`] triangles, is located on its own.
    pub fn nearest_each(&self, mesh: &Mesh, xs: &[[f64; 2]]) -> Vec<Hit> {
        let Some(&first) = xs.first() else { return Vec::new() };
        let (lo, hi) =
            xs.iter().fold((first, first), |(lo, hi), x| ([lo[0].min(x[0]), lo[1].min(x[1])], [hi[0].max(x[0]), hi[1].max(x[1])]));
        let mut near: Vec<Boxed> =
            self.tree.locate_in_envelope_intersecting(rstar::AABB::from_corners(lo, hi)).take(Self::SHARED_MAX + 1).cloned().collect();
        if near.len() > Self::SHARED_MAX {
            near.clear();
        }
        let one = |x: [f64; 2]| {
            // a box that holds x meets the points' box, which holds x too: it is among `near`
            let shared = Self::best(mesh, x, near.iter().filter(|b| b.contains_point(&x)));
            shared.or_else(|| self.nearest(mesh, x)).expect("a mesh with triangles")
        };
        xs.iter().map(|&x| one(x)).collect()
    }

    /// Triangles one query of [`Locator::nearest_each`] shares among its points, at most: each
    /// point tests every shared box, so a query that meets many is dearer than locating the
    /// points one by one. Measured with the errors of a study's runs against its reference
    /// (`signorini drift --study ex72_large --study ex72_rollers`, one run each, idle): 64
    /// took ex72_rollers' errors from 12.0 s to 7.0 s against 512 and left ex72_large's as they
    /// were (30.2 s, 29.9 s). The hits are the same either way.
    pub const SHARED_MAX: usize = 64;

    /// Among the triangles of `boxes`, the smallest `(outside, index)` for `x`.
    fn best<'a>(mesh: &Mesh, x: [f64; 2], boxes: impl Iterator<Item = &'a Boxed>) -> Option<Hit> {
        boxes.map(|b| hit(mesh, x, b.data)).min_by(|a, b| a.outside.total_cmp(&b.outside).then(a.triangle.cmp(&b.triangle)))
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

    /// The points of one triangle of a coarser mesh located together are located as one by one,
    /// hit for hit: lattice points, corners, edge midpoints and points just outside, both where
    /// the triangle's box meets few triangles of the fine mesh and where it meets more than
    /// [`Locator::SHARED_MAX`].
    #[test]
    fn points_located_together_are_located_as_one_by_one() {
        let disc = Curve::Circle { centre: [0.0, 0.0], radius: 1.0 };
        let mut meshes = vec![crate::mesh::tests::disc(disc)];
        for level in 0..14 {
            let mesh = meshes.last().unwrap();
            // uniform three times, then graded towards (1, 0)
            let near = |c: [[f64; 2]; 3]| {
                crate::mesh::dist([(c[0][0] + c[1][0] + c[2][0]) / 3.0, (c[0][1] + c[1][1] + c[2][1]) / 3.0], [1.0, 0.0]) < 0.3
            };
            let marked: Vec<bool> = (0..mesh.n_triangles()).map(|t| level < 3 || near(mesh.corners(t))).collect();
            meshes.push(crate::mesh::refine::refine(mesh, &marked).unwrap().mesh);
        }
        let fine = meshes.last().unwrap();
        let locator = Locator::new(fine);
        let (mut shared, mut alone) = (0, 0);
        for coarse in &meshes[..meshes.len() - 1] {
            for t in 0..coarse.n_triangles() {
                let c = coarse.corners(t);
                let at = |l: [f64; 3]| [0, 1].map(|i| l[0] * c[0][i] + l[1] * c[1][i] + l[2] * c[2][i]);
                let mut xs: Vec<[f64; 2]> = Vec::new();
                for i in 0..=6 {
                    for j in 0..=6 - i {
                        xs.push(at([i as f64 / 6.0, j as f64 / 6.0, (6 - i - j) as f64 / 6.0]));
                    }
                }
                xs.push(at([1.0 + 1e-7, -0.5e-7, -0.5e-7]));
                let together = locator.nearest_each(fine, &xs);
                let one_by_one: Vec<Hit> = xs.iter().map(|&x| locator.nearest(fine, x).unwrap()).collect();
                assert_eq!(together, one_by_one, "the points of triangle {t} of a mesh of {}", coarse.n_triangles());
                let (lo, hi) = bounding_box(c);
                let near = locator.tree.locate_in_envelope_intersecting(rstar::AABB::from_corners(lo, hi)).count();
                if near <= Locator::SHARED_MAX { shared += 1 } else { alone += 1 }
            }
        }
        assert!(shared > 100 && alone > 10, "{shared} triangles shared a query, {alone} did not");
    }
}
