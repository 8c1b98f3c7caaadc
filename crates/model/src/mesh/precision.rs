//! What the vertices' coordinates can resolve of the elements they describe. A coordinate x
//! carries a round-off of eps |x| (f64's unit round-off eps = 2.2e-16), so a triangle of height
//! h placed at distance |x| from the origin has its shape known only to about eps |x| / h: a
//! mesh translated far from the origin loses digits of every element (an 8x8 grid of the unit
//! square moved to (1e13, 1e13) changes eta_6 by 35%, and at 1e15 its Dirichlet side reads as a
//! line, "the body can move rigidly").

use super::{Mesh, MeshError};

/// The largest relative round-off of an element's shape [`Mesh::check`] accepts: beyond it the
/// element geometry keeps fewer than 3 digits. Example 7.2 on the 8x8 grid translated by t:
/// eta_6 moved by 1% at 3e11 (7.5e-4), 4% at 1e12 (2.5e-3), 35% at 1e13 (2.5e-2); the stored
/// studies' deepest levels (h_min 2.1e-8 near coordinates of size 1) are near 1.5e-8. Between
/// 1e-5 and this, `adapt::resolution` warns.
pub const SHAPE_ROUNDOFF_REFUSED: f64 = 1e-3;

/// The worst element of a mesh for [`Mesh::shape_roundoff`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeRoundoff {
    /// eps times the largest coordinate magnitude of the element's vertices, over its smallest
    /// height: the relative round-off of the element's shape.
    pub delta: f64,
    /// The element.
    pub triangle: usize,
    /// The largest coordinate magnitude of its vertices (max of |x| and |y|).
    pub offset: f64,
    /// Its smallest height (twice its area over its longest edge).
    pub height: f64,
}

impl Mesh {
    /// The largest relative round-off of an element's shape over the mesh ([`ShapeRoundoff`]);
    /// `delta` 0 for a mesh without triangles. Invariant under scaling the mesh, not under
    /// translating it: a translation by t adds eps t / h to every element.
    pub fn shape_roundoff(&self) -> ShapeRoundoff {
        let mut worst = ShapeRoundoff { delta: 0.0, triangle: 0, offset: 0.0, height: f64::INFINITY };
        for t in 0..self.n_triangles() {
            let offset = self.corners(t).iter().fold(0.0f64, |a, p| a.max(p[0].abs()).max(p[1].abs()));
            let height = 2.0 * self.area(t).abs() / self.diameter(t);
            let delta = f64::EPSILON * offset / height;
            // a NaN (a degenerate element) is left to the area check
            if delta > worst.delta {
                worst = ShapeRoundoff { delta, triangle: t, offset, height };
            }
        }
        worst
    }

    /// The worst element where the mesh's element shapes keep fewer than 3 digits
    /// ([`SHAPE_ROUNDOFF_REFUSED`]), None where every element keeps them: what [`Mesh::check`]
    /// refuses and what ends the adaptive loop before a refined mesh's level.
    pub fn shape_roundoff_refused(&self) -> Option<ShapeRoundoff> {
        Some(self.shape_roundoff()).filter(|worst| worst.delta > SHAPE_ROUNDOFF_REFUSED)
    }

    /// Refuse a mesh whose element shapes keep fewer than 3 digits
    /// ([`SHAPE_ROUNDOFF_REFUSED`]): part of [`Mesh::check`], before anything reads the geometry
    /// (the rigid-motion check would misread a segment as a line).
    pub(super) fn check_shape_roundoff(&self) -> Result<(), MeshError> {
        match self.shape_roundoff_refused() {
            Some(worst) => Err(worst.into()),
            None => Ok(()),
        }
    }
}

impl From<ShapeRoundoff> for MeshError {
    fn from(ShapeRoundoff { delta, triangle, offset, height }: ShapeRoundoff) -> MeshError {
        MeshError::FarFromOrigin { t: triangle, delta, offset, height }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshSpec;

    #[test]
    fn a_translation_far_from_the_origin_is_refused_and_a_scaling_is_not() {
        let mut m = MeshSpec::parse("structured:8").unwrap().build(&crate::problems::Ex72).unwrap();
        let near = m.shape_roundoff();
        assert!(near.delta < 1e-14, "{near:?}");
        let scaled = Mesh { vertices: m.vertices.iter().map(|p| [1e-9 * p[0], 1e-9 * p[1]]).collect(), ..m.clone() };
        assert!((scaled.shape_roundoff().delta / near.delta - 1.0).abs() < 1e-9);
        for p in &mut m.vertices {
            *p = [p[0] + 1e13, p[1] + 1e13];
        }
        let far = m.shape_roundoff();
        assert!(far.delta > 1e-2 && far.delta < 3e-2, "{far:?}");
        assert!(matches!(m.check(), Err(MeshError::FarFromOrigin { .. })));
    }
}
