//! The parts of a problem's boundary and the curves it may follow: what a problem declares and
//! a mesh is tagged with (re-exported by `mesh`).

/// The part of the boundary an edge belongs to (paper Section 1: Gamma_D, Gamma_N, Gamma_C).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Part {
    Dirichlet,
    Neumann,
    Contact,
}

impl Part {
    /// Integer code used in VTU files (0 is reserved for triangles).
    pub fn code(self) -> i32 {
        match self {
            Part::Dirichlet => 1,
            Part::Neumann => 2,
            Part::Contact => 3,
        }
    }
}

/// A curved part of the boundary. A straight-sided mesh only approximates it; refinement puts the
/// new vertex of a bisected boundary edge on the curve ([`Curve::project`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Curve {
    /// The circle of centre `centre` and radius `radius`.
    Circle { centre: [f64; 2], radius: f64 },
}

impl Curve {
    /// The point of the curve closest to `x` (`x` itself if `x` is the circle's centre).
    pub fn project(&self, x: [f64; 2]) -> [f64; 2] {
        match *self {
            Curve::Circle { centre, radius } => {
                let d = [x[0] - centre[0], x[1] - centre[1]];
                let r = d[0].hypot(d[1]);
                if r == 0.0 { x } else { [centre[0] + radius * d[0] / r, centre[1] + radius * d[1] / r] }
            }
        }
    }

    /// The unit normal of the curve at its point closest to `x`, pointing away from the circle's
    /// centre (`None` at the centre, where it has no direction). Which side is the body's outside
    /// the mesh decides: turn it to agree with the boundary edge's outward normal.
    pub fn normal(&self, x: [f64; 2]) -> Option<[f64; 2]> {
        match *self {
            Curve::Circle { centre, .. } => {
                let d = [x[0] - centre[0], x[1] - centre[1]];
                let r = d[0].hypot(d[1]);
                (r > 0.0).then(|| [d[0] / r, d[1] / r])
            }
        }
    }

    /// The body's outward unit normal at the curve's point closest to `x`: the curve's normal
    /// turned to agree with `chord`, the outward normal of the straight boundary edge `x` lies on
    /// (so it points into a hole for a body around one); `chord` itself at the centre.
    pub fn outward(&self, x: [f64; 2], chord: [f64; 2]) -> [f64; 2] {
        match self.normal(x) {
            Some(n) if n[0] * chord[0] + n[1] * chord[1] < 0.0 => [-n[0], -n[1]],
            Some(n) => n,
            None => chord,
        }
    }

    /// The circle's centre.
    pub fn centre(&self) -> [f64; 2] {
        match *self {
            Curve::Circle { centre, .. } => centre,
        }
    }

    /// The circle's radius.
    pub fn radius(&self) -> f64 {
        match *self {
            Curve::Circle { radius, .. } => radius,
        }
    }

    /// The distance from `x` to the curve, relative to its size (the circle's radius).
    pub fn relative_distance(&self, x: [f64; 2]) -> f64 {
        match *self {
            Curve::Circle { centre, radius } => ((x[0] - centre[0]).hypot(x[1] - centre[1]) - radius).abs() / radius,
        }
    }

    /// How far (relative to its size) a mesh vertex may lie from the curve its boundary edge is
    /// declared on: a mesher places them on it to round-off; a curve declared with another
    /// centre or radius than the mesh's misses them by far more, and refinement would then pull
    /// new vertices onto a curve the mesh does not follow.
    pub const VERTEX_TOLERANCE: f64 = 1e-6;
}
