//! The reference P2 (quadratic Lagrange) triangle, quadrature rules and sampling lattices.
//!
//! Reference triangle: vertices (0,0), (1,0), (0,1); barycentric coordinates
//! `L0 = 1 - x - y`, `L1 = x`, `L2 = y`. Local node order (as in VTK's quadratic triangle):
//! `[v0, v1, v2, m01, m12, m20]`, the three vertices then the midpoints of edges v0v1, v1v2, v2v0.
//!
//! Quadrature on triangles is built here, not taken from a crate: no maintained Rust crate offers
//! triangle rules of arbitrary degree with a stable API, and the collapsed (Duffy) Gauss product
//! rule is short, exact to any requested degree and free of hand-typed tables.

/// Number of local nodes of the P2 triangle.
pub const N_NODES: usize = 6;

/// Local vertex pairs of the three edges, in the order of the midpoint nodes 3, 4, 5.
pub const EDGE_VERTICES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];

/// A quadrature rule: points and weights (weights sum to the measure of the domain).
#[derive(Clone, Debug)]
pub struct Rule<const D: usize> {
    pub points: Vec<[f64; D]>,
    pub weights: Vec<f64>,
}

/// Gauss–Legendre rule with `n` points on [0, 1] (exact for degree 2n-1).
/// Nodes by Newton's method on the Legendre polynomial, the textbook way. Rules of up to
/// [`CACHED_GAUSS`] points are computed once per process and copied: the boundary checks ask for
/// one per boundary edge, and the Newton steps cost more than the edge's own work.
pub fn gauss_legendre(n: usize) -> Rule<1> {
    static RULES: [std::sync::OnceLock<Rule<1>>; CACHED_GAUSS + 1] = [const { std::sync::OnceLock::new() }; CACHED_GAUSS + 1];
    match RULES.get(n) {
        Some(rule) => rule.get_or_init(|| newton_gauss(n)).clone(),
        None => newton_gauss(n),
    }
}

/// The largest Gauss rule [`gauss_legendre`] keeps once computed.
pub const CACHED_GAUSS: usize = 32;

/// [`gauss_legendre`]'s computation.
fn newton_gauss(n: usize) -> Rule<1> {
    assert!(n >= 1, "a Gauss rule needs at least one point");
    let mut points = Vec::with_capacity(n);
    let mut weights = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (p, d) = legendre(n, x);
            dp = d;
            let dx = p / d;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre(n, x);
        dp = if d != 0.0 { d } else { dp };
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        // map [-1, 1] to [0, 1]
        points.push([0.5 * (1.0 - x)]);
        weights.push(0.5 * w);
    }
    Rule { points, weights }
}

/// Legendre polynomial P_n and its derivative at x.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
        p0 = p1;
        p1 = p2;
    }
    let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, dp)
}

/// Collapsed Gauss rule on the reference triangle, exact for polynomials of degree `degree`.
/// Uses `n = ceil((degree + 2) / 2)` points per direction (the Duffy map adds one degree).
pub fn triangle_rule(degree: usize) -> Rule<2> {
    let n = (degree + 2).div_ceil(2).max(1);
    let g = gauss_legendre(n);
    let mut points = Vec::with_capacity(n * n);
    let mut weights = Vec::with_capacity(n * n);
    for (a, wa) in g.points.iter().zip(&g.weights) {
        for (b, wb) in g.points.iter().zip(&g.weights) {
            // (a, b) in the unit square -> (x, y) = (a, b (1 - a)), Jacobian (1 - a)
            let (s, t) = (a[0], b[0]);
            points.push([s, t * (1.0 - s)]);
            weights.push(wa * wb * (1.0 - s));
        }
    }
    Rule { points, weights }
}

/// Radon's 7-point rule on the reference triangle, exact for polynomials of degree 5, whose
/// point set every symmetry of the triangle maps onto itself: the centroid and two orbits of
/// three points with barycentric coordinates (a, a, 1 - 2a), a = (6 -+ sqrt 15) / 21. The points
/// over which the "quadrature" L-infinity norms are taken: a maximum over the collapsed rule's
/// points ([`triangle_rule`]), which are symmetric only under the reflection fixing one vertex,
/// would depend on how a triangle's vertices are labelled, so a problem mirrored onto the same
/// mesh would report an error 20-25% smaller.
pub fn symmetric_rule_5() -> Rule<2> {
    let r = 15f64.sqrt();
    let mut points = vec![[1.0 / 3.0, 1.0 / 3.0]];
    let mut weights = vec![9.0 / 80.0];
    for (a, w) in [((6.0 - r) / 21.0, (155.0 - r) / 2400.0), ((6.0 + r) / 21.0, (155.0 + r) / 2400.0)] {
        let b = 1.0 - 2.0 * a;
        // (x, y) = (L1, L2) of the barycentric points (a, a, b) and its rotations
        points.extend([[a, a], [b, a], [a, b]]);
        weights.extend([w; 3]);
    }
    Rule { points, weights }
}

/// P2 basis values at reference point (x, y), local node order `[v0, v1, v2, m01, m12, m20]`.
#[inline]
pub fn p2_values(x: f64, y: f64) -> [f64; N_NODES] {
    let l = [1.0 - x - y, x, y];
    [
        l[0] * (2.0 * l[0] - 1.0),
        l[1] * (2.0 * l[1] - 1.0),
        l[2] * (2.0 * l[2] - 1.0),
        4.0 * l[0] * l[1],
        4.0 * l[1] * l[2],
        4.0 * l[2] * l[0],
    ]
}

/// Reference gradients of the P2 basis at (x, y): `[d/dx, d/dy]` per local node.
#[inline]
pub fn p2_gradients(x: f64, y: f64) -> [[f64; 2]; N_NODES] {
    let l = [1.0 - x - y, x, y];
    // d(L0, L1, L2)/d(x, y)
    let dl = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
    let mut g = [[0.0; 2]; N_NODES];
    for i in 0..3 {
        for k in 0..2 {
            g[i][k] = (4.0 * l[i] - 1.0) * dl[i][k];
        }
    }
    for (e, [i, j]) in EDGE_VERTICES.iter().enumerate() {
        for k in 0..2 {
            g[3 + e][k] = 4.0 * (dl[*i][k] * l[*j] + l[*i] * dl[*j][k]);
        }
    }
    g
}

/// Barycentric lattice of order `k` on the reference triangle: the points (i/k, j/k), i + j <= k.
/// Order 6 gives 28 points per element (vertices and edge midpoints included).
pub fn lattice(k: usize) -> Vec<[f64; 2]> {
    let mut pts = Vec::with_capacity((k + 1) * (k + 2) / 2);
    for j in 0..=k {
        for i in 0..=(k - j) {
            pts.push([i as f64 / k as f64, j as f64 / k as f64]);
        }
    }
    pts
}

/// The affine map of a physical triangle `[a, b, c]` from the reference triangle.
#[derive(Clone, Copy, Debug)]
pub struct Affine {
    pub origin: [f64; 2],
    /// Columns are b - a and c - a.
    pub jac: [[f64; 2]; 2],
    pub det: f64,
    /// Inverse transpose of the Jacobian: physical gradient = inv_t * reference gradient.
    pub inv_t: [[f64; 2]; 2],
}

impl Affine {
    pub fn new(v: [[f64; 2]; 3]) -> Self {
        let j = [[v[1][0] - v[0][0], v[2][0] - v[0][0]], [v[1][1] - v[0][1], v[2][1] - v[0][1]]];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        // inverse of J is [[j11, -j01], [-j10, j00]] / det; its transpose:
        let inv_t = [[j[1][1] / det, -j[1][0] / det], [-j[0][1] / det, j[0][0] / det]];
        Affine { origin: v[0], jac: j, det, inv_t }
    }

    /// Physical point of reference point (x, y).
    #[inline]
    pub fn map(&self, p: [f64; 2]) -> [f64; 2] {
        [self.origin[0] + self.jac[0][0] * p[0] + self.jac[0][1] * p[1], self.origin[1] + self.jac[1][0] * p[0] + self.jac[1][1] * p[1]]
    }

    /// Physical gradient from a reference gradient.
    #[inline]
    pub fn grad(&self, g: [f64; 2]) -> [f64; 2] {
        [self.inv_t[0][0] * g[0] + self.inv_t[0][1] * g[1], self.inv_t[1][0] * g[0] + self.inv_t[1][1] * g[1]]
    }

    /// Reference coordinates of a physical point (inverse map).
    #[inline]
    pub fn inverse(&self, x: [f64; 2]) -> [f64; 2] {
        let d = [x[0] - self.origin[0], x[1] - self.origin[1]];
        // J^{-1} = inv_t^T
        [self.inv_t[0][0] * d[0] + self.inv_t[1][0] * d[1], self.inv_t[0][1] * d[0] + self.inv_t[1][1] * d[1]]
    }
}

/// Second derivatives of the P2 basis in physical coordinates (constant per element):
/// `[d2/dx2, d2/dxdy, d2/dy2]` per local node.
pub fn p2_hessians(map: &Affine) -> [[f64; 3]; N_NODES] {
    // barycentric gradients in physical coordinates
    let dl = [map.grad([-1.0, -1.0]), map.grad([1.0, 0.0]), map.grad([0.0, 1.0])];
    let mut h = [[0.0; 3]; N_NODES];
    let outer = |a: [f64; 2], b: [f64; 2]| [a[0] * b[0], 0.5 * (a[0] * b[1] + a[1] * b[0]), a[1] * b[1]];
    for i in 0..3 {
        // L_i (2 L_i - 1): hessian 4 dL_i dL_i^T
        let o = outer(dl[i], dl[i]);
        h[i] = [4.0 * o[0], 4.0 * o[1], 4.0 * o[2]];
    }
    for (e, [i, j]) in EDGE_VERTICES.iter().enumerate() {
        // 4 L_i L_j: hessian 4 (dL_i dL_j^T + dL_j dL_i^T)
        let o = outer(dl[*i], dl[*j]);
        h[3 + e] = [8.0 * o[0], 8.0 * o[1], 8.0 * o[2]];
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_rule_is_exact_to_its_degree() {
        // int_T x^a y^b = a! b! / (a + b + 2)!
        let fact = |n: usize| (1..=n).product::<usize>() as f64;
        for degree in 1..=12 {
            let r = triangle_rule(degree);
            for a in 0..=degree {
                for b in 0..=(degree - a) {
                    let q: f64 = r.points.iter().zip(&r.weights).map(|(p, w)| w * p[0].powi(a as i32) * p[1].powi(b as i32)).sum();
                    let exact = fact(a) * fact(b) / fact(a + b + 2);
                    assert!((q - exact).abs() < 1e-14, "degree {degree}: x^{a} y^{b}: {q} vs {exact}");
                }
            }
        }
    }

    #[test]
    fn the_symmetric_rule_is_exact_to_degree_5_and_every_symmetry_keeps_its_points() {
        let fact = |n: usize| (1..=n).product::<usize>() as f64;
        let r = symmetric_rule_5();
        for a in 0..=5 {
            for b in 0..=(5 - a) {
                let q: f64 = r.points.iter().zip(&r.weights).map(|(p, w)| w * p[0].powi(a as i32) * p[1].powi(b as i32)).sum();
                let exact = fact(a) * fact(b) / fact(a + b + 2);
                assert!((q - exact).abs() < 1e-15, "x^{a} y^{b}: {q} vs {exact}");
            }
        }
        // the six permutations of the barycentric coordinates (L0, L1, L2)
        let bary = |p: &[f64; 2]| [1.0 - p[0] - p[1], p[0], p[1]];
        for perm in [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]] {
            for (p, w) in r.points.iter().zip(&r.weights) {
                let l = bary(p);
                let image = [l[perm[1]], l[perm[2]]];
                let found = r
                    .points
                    .iter()
                    .zip(&r.weights)
                    .any(|(q, v)| (q[0] - image[0]).abs() < 1e-15 && (q[1] - image[1]).abs() < 1e-15 && v == w);
                assert!(found, "{perm:?} maps {p:?} to {image:?}, not a point of the rule");
            }
        }
    }

    #[test]
    fn p2_basis_is_nodal_and_gradients_match_differences() {
        let nodes = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]];
        for (i, p) in nodes.iter().enumerate() {
            let v = p2_values(p[0], p[1]);
            for (j, vj) in v.iter().enumerate() {
                assert!((vj - if i == j { 1.0 } else { 0.0 }).abs() < 1e-15);
            }
        }
        let (x, y, h) = (0.23, 0.31, 1e-6);
        let g = p2_gradients(x, y);
        let (px, mx) = (p2_values(x + h, y), p2_values(x - h, y));
        let (py, my) = (p2_values(x, y + h), p2_values(x, y - h));
        for i in 0..N_NODES {
            assert!((g[i][0] - (px[i] - mx[i]) / (2.0 * h)).abs() < 1e-8);
            assert!((g[i][1] - (py[i] - my[i]) / (2.0 * h)).abs() < 1e-8);
        }
    }
}
