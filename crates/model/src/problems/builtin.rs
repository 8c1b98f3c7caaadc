//! The built-in problems: Examples 7.1 and 7.2 of the paper, the free-boundary problem `fb` and
//! the patch test. `experiments/problems/{ex71,ex72,fb}.toml` state the first three as problem
//! files; `tests/it/problem_files.rs` keeps the two equal.

use super::Part;
use super::{Exact, Material, Problem};

const EPS: f64 = 1e-12;

/// The boundary parts of Example 7.2 (and the patch test): contact on x = 1, Dirichlet on x = 0,
/// Neumann top and bottom.
fn contact_right_dirichlet_left(x: [f64; 2]) -> Part {
    if x[0] > 1.0 - EPS {
        Part::Contact
    } else if x[0] < EPS {
        Part::Dirichlet
    } else {
        Part::Neumann
    }
}

/// The boundary parts of Example 7.1 (and `fb`): contact on the bottom y = 0, Dirichlet on the
/// top y = 1, Neumann on the sides. Public for problems of one's own on the unit square.
pub fn contact_bottom_dirichlet_top(x: [f64; 2]) -> Part {
    if x[1] < EPS {
        Part::Contact
    } else if x[1] > 1.0 - EPS {
        Part::Dirichlet
    } else {
        Part::Neumann
    }
}

/// Example 7.1: smooth manufactured solution u = (y^2 (y - 1), e^y (1 - y) y (x - 2)),
/// zeta = mu = 1, Gamma_C the bottom (n = (0, -1), chi = 0), Gamma_D the top, Gamma_N the sides.
/// The exact solution is in contact along the whole of Gamma_C (sigma_nn = 3x - 6 < 0).
pub struct Ex71;

impl Exact for Ex71 {
    fn u(&self, x: [f64; 2]) -> [f64; 2] {
        let (x, y) = (x[0], x[1]);
        [y * y * (y - 1.0), y.exp() * (1.0 - y) * y * (x - 2.0)]
    }
    fn grad(&self, x: [f64; 2]) -> [[f64; 2]; 2] {
        let (x, y) = (x[0], x[1]);
        let e = y.exp();
        [[0.0, 3.0 * y * y - 2.0 * y], [e * (1.0 - y) * y, (x - 2.0) * e * (1.0 - y - y * y)]]
    }
}

impl Problem for Ex71 {
    fn name(&self) -> &str {
        "ex71"
    }
    fn description(&self) -> &str {
        "Example 7.1: smooth manufactured solution, contact along the whole bottom edge"
    }
    fn material(&self) -> Material {
        Material { mu: 1.0, zeta: 1.0 }
    }
    fn part_of(&self, x: [f64; 2]) -> Part {
        contact_bottom_dirichlet_top(x)
    }
    /// f = -div sigma(u) = (2 e^y (y^2 + y - 1) - 6 y + 2, 3 y (x - 2)(y + 3) e^y), derived here
    /// from the exact u of Example 7.1 (the paper prints no f) and checked against finite
    /// differences of the exact stress in tests/it/problems.rs.
    fn body_force(&self, x: [f64; 2]) -> [f64; 2] {
        let (x, y) = (x[0], x[1]);
        let e = y.exp();
        [2.0 * e * (y * y + y - 1.0) - 6.0 * y + 2.0, 3.0 * y * (x - 2.0) * (y + 3.0) * e]
    }
    /// g = sigma(u) n from the exact stress.
    fn traction(&self, x: [f64; 2], n: [f64; 2]) -> [f64; 2] {
        self.material().traction(self.grad(x), n)
    }
    fn dirichlet(&self, x: [f64; 2]) -> [f64; 2] {
        self.u(x)
    }
    fn contact_normal(&self, _x: [f64; 2], _outward: [f64; 2]) -> [f64; 2] {
        [0.0, -1.0]
    }
    fn gap(&self, _x: [f64; 2]) -> f64 {
        0.0
    }
    fn exact(&self) -> Option<&dyn Exact> {
        Some(self)
    }
}

/// Example 7.2: contact with a rigid wedge. E = 500, nu = 0.3, f = g = 0, u = (0.1, 0) on
/// Gamma_D = {x = 0}, Gamma_C = {x = 1} with n = (1, 0) and chi(y) = -0.2 + 0.5 |y - 0.5|,
/// Gamma_N the top and bottom. chi has a kink at y = 0.5, which must be a mesh vertex.
pub struct Ex72;

impl Problem for Ex72 {
    fn name(&self) -> &str {
        "ex72"
    }
    fn description(&self) -> &str {
        "Example 7.2: contact with a rigid wedge (no exact solution)"
    }
    fn material(&self) -> Material {
        Material::from_young(500.0, 0.3)
    }
    fn part_of(&self, x: [f64; 2]) -> Part {
        contact_right_dirichlet_left(x)
    }
    fn body_force(&self, _x: [f64; 2]) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn traction(&self, _x: [f64; 2], _n: [f64; 2]) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn dirichlet(&self, _x: [f64; 2]) -> [f64; 2] {
        [0.1, 0.0]
    }
    fn contact_normal(&self, _x: [f64; 2], _outward: [f64; 2]) -> [f64; 2] {
        [1.0, 0.0]
    }
    fn gap(&self, x: [f64; 2]) -> f64 {
        -0.2 + 0.5 * (x[1] - 0.5).abs()
    }
    fn required_vertices(&self) -> Vec<[f64; 2]> {
        vec![[1.0, 0.5]]
    }
    fn required_vertices_declared(&self) -> Vec<(String, [f64; 2])> {
        vec![("the kink of problem ex72's obstacle".into(), [1.0, 0.5])]
    }
}

/// `fb`: a free boundary with an exact solution (beyond the paper). Example 7.1 is in contact on
/// all of Gamma_C and Example 7.2 has no exact solution; here the contact zone is [a, 1] with an
/// irrational free-boundary point a, and the true error is known.
///
/// Omega = (0,1)^2, zeta = mu = 1; Gamma_C = (0,1) x {0} with n = (0,-1), Gamma_D the top,
/// Gamma_N the sides (as in Example 7.1). With a = sqrt(2) - 1, r(x) = 0.05 sin(2 pi x) and
/// p(x) = -((x - a)_+)^(5/2):
///
/// ```text
/// u(x, y) = ( -y r'(x), y p(x) / (zeta + 2 mu) + r(x) ),
/// f = -div sigma(u),  g = sigma(u) n on Gamma_N,  u = u on Gamma_D,
/// chi(x) = -r(x) + ((a - x)_+)^(3/2)                     (constraint u.n <= chi on Gamma_C).
/// ```
///
/// With zeta = mu = 1 (zeta + 2 mu = 3):
/// sigma_11 = p/3 - 3 y r'',  sigma_12 = y p'/3,  sigma_22 = p - y r'', so on y = 0 the tangential
/// stress vanishes and sigma_nn = sigma_22 = p <= 0, nonzero exactly on (a, 1]; the gap
/// chi - u.n = ((a - x)_+)^(3/2) vanishes exactly on [a, 1]. Hence u.n <= chi, sigma_nn <= 0,
/// sigma_nn (u.n - chi) = 0 and sigma_t = 0: the Signorini conditions (eq. 1.5-1.8) hold and u is
/// the solution, in contact exactly on [a, 1]. f = (3 y r''' - 2 p'/3, r'' - y p''/3) is bounded
/// (p'' = -(15/4) ((x - a)_+)^(1/2)) but not smooth across x = a; u has the usual Signorini
/// regularity there (u_2 ~ (x - a)^(5/2) y), so uniform P2 refinement stays below h^3. Since a is
/// irrational, no mesh vertex (structured or bisected: dyadic coordinates) ever lands on x = a.
pub struct Fb;

impl Fb {
    /// The free-boundary point a = sqrt(2) - 1: contact on [a, 1].
    pub const A: f64 = std::f64::consts::SQRT_2 - 1.0;
    const R_AMPLITUDE: f64 = 0.05;

    /// [r, r', r'', r'''] at x, r(x) = 0.05 sin(2 pi x).
    pub fn r(x: f64) -> [f64; 4] {
        let k = 2.0 * std::f64::consts::PI;
        let (s, c) = (k * x).sin_cos();
        let a = Self::R_AMPLITUDE;
        [a * s, a * k * c, -a * k * k * s, -a * k * k * k * c]
    }

    /// [p, p', p''] at x, p(x) = -((x - a)_+)^(5/2): the normal contact stress sigma_nn on Gamma_C.
    pub fn p(x: f64) -> [f64; 3] {
        let s = (x - Self::A).max(0.0);
        let q = s.sqrt();
        [-s * s * q, -2.5 * s * q, -3.75 * q]
    }

    fn lame(&self) -> f64 {
        let m = self.material();
        m.zeta + 2.0 * m.mu
    }
}

impl Exact for Fb {
    fn u(&self, x: [f64; 2]) -> [f64; 2] {
        let (r, p, y) = (Self::r(x[0]), Self::p(x[0]), x[1]);
        [-y * r[1], y * p[0] / self.lame() + r[0]]
    }
    fn grad(&self, x: [f64; 2]) -> [[f64; 2]; 2] {
        let (r, p, y) = (Self::r(x[0]), Self::p(x[0]), x[1]);
        let l = self.lame();
        [[-y * r[2], -r[1]], [y * p[1] / l + r[1], p[0] / l]]
    }
}

impl Problem for Fb {
    fn name(&self) -> &str {
        "fb"
    }
    fn description(&self) -> &str {
        "Free boundary with an exact solution: contact on [a, 1] of the bottom edge, a = sqrt(2) - 1 (beyond the paper)"
    }
    fn material(&self) -> Material {
        Material { mu: 1.0, zeta: 1.0 }
    }
    fn part_of(&self, x: [f64; 2]) -> Part {
        contact_bottom_dirichlet_top(x)
    }
    /// f = -div sigma(u) from the exact second derivatives of u (no finite differences), with
    /// div sigma = mu Laplace u + (mu + zeta) grad div u; for zeta = mu = 1 this is
    /// f = (3 y r''' - 2 p'/3, r'' - y p''/3). Checked against finite differences of the exact
    /// stress in tests/it/fb.rs.
    fn body_force(&self, x: [f64; 2]) -> [f64; 2] {
        let (r, p, y) = (Self::r(x[0]), Self::p(x[0]), x[1]);
        let Material { mu, zeta } = self.material();
        let l = zeta + 2.0 * mu;
        // second derivatives of u: u1_xx = -y r''', u1_xy = -r'', u1_yy = 0,
        // u2_xx = y p''/L + r'', u2_xy = p'/L, u2_yy = 0
        let (u1xx, u1xy, u1yy) = (-y * r[3], -r[2], 0.0);
        let (u2xx, u2xy, u2yy) = (y * p[2] / l + r[2], p[1] / l, 0.0);
        // div sigma = mu Laplace u + (mu + zeta) grad div u
        let div1 = mu * (u1xx + u1yy) + (mu + zeta) * (u1xx + u2xy);
        let div2 = mu * (u2xx + u2yy) + (mu + zeta) * (u1xy + u2yy);
        [-div1, -div2]
    }
    /// g = sigma(u) n from the exact stress.
    fn traction(&self, x: [f64; 2], n: [f64; 2]) -> [f64; 2] {
        self.material().traction(self.grad(x), n)
    }
    fn dirichlet(&self, x: [f64; 2]) -> [f64; 2] {
        self.u(x)
    }
    fn contact_normal(&self, _x: [f64; 2], _outward: [f64; 2]) -> [f64; 2] {
        [0.0, -1.0]
    }
    /// f has ((x - a)_+)^(1/2) and ^(3/2) terms.
    fn load_breaks(&self) -> Vec<f64> {
        vec![Self::A]
    }
    /// chi(x) = -r(x) + ((a - x)_+)^(3/2).
    fn gap(&self, x: [f64; 2]) -> f64 {
        -Self::r(x[0])[0] + (Self::A - x[0]).max(0.0).powf(1.5)
    }
    fn exact(&self) -> Option<&dyn Exact> {
        Some(self)
    }
}

/// A quadratic displacement (in the P2 space) with its own constant f and linear g, and the
/// obstacle far away (no active contact): the discrete solution must equal it to round-off.
/// Boundary parts as in Example 7.2: contact on the right (n = (1, 0)), Dirichlet at the left,
/// Neumann top and bottom.
pub struct Patch {
    pub material: Material,
    /// `u_i = sum_k c[i][k] m_k(x, y)` with monomials m = (1, x, y, x^2, xy, y^2).
    pub c: [[f64; 6]; 2],
    pub gap: f64,
    /// The contact normal used for the constraint (the boundary is x = 1 whatever it says):
    /// tests set an oblique one to exercise the local frames of contact nodes.
    pub normal: [f64; 2],
}

impl Default for Patch {
    fn default() -> Self {
        Patch::traction_free_right(Material::from_young(7.0, 0.27), [0.03, 0.05, 0.02, -0.02, -0.03, 0.04])
    }
}

impl Patch {
    /// The quadratic displacement with free coefficients `(a2, a3, a5, b2, b3, b5)` and the other
    /// six chosen so that sigma(u) n = 0 on x = 1: with the contact inactive, Gamma_C is then
    /// traction free for the exact solution too, so it solves the discrete problem exactly.
    pub fn traction_free_right(material: Material, free: [f64; 6]) -> Self {
        let (mu, zeta) = (material.mu, material.zeta);
        let [a2, a3, a5, b2, b3, b5] = free;
        // sigma_12(1, y) = 0:  a2 + a4 + b1 + 2 b3 = 0 and 2 a5 + b4 = 0
        // sigma_11(1, y) = 0:  (2mu+zeta)(a1 + 2 a3) + zeta (b2 + b4) = 0 and (2mu+zeta) a4 + 2 zeta b5 = 0
        let b4 = -2.0 * a5;
        let a4 = -2.0 * zeta * b5 / (2.0 * mu + zeta);
        let a1 = -2.0 * a3 - zeta * (b2 + b4) / (2.0 * mu + zeta);
        let b1 = -a2 - a4 - 2.0 * b3;
        Patch { material, c: [[0.01, a1, a2, a3, a4, a5], [-0.02, b1, b2, b3, b4, b5]], gap: 10.0, normal: [1.0, 0.0] }
    }
}

impl Exact for Patch {
    fn u(&self, x: [f64; 2]) -> [f64; 2] {
        let m = [1.0, x[0], x[1], x[0] * x[0], x[0] * x[1], x[1] * x[1]];
        let dot = |c: &[f64; 6]| c.iter().zip(&m).map(|(a, b)| a * b).sum();
        [dot(&self.c[0]), dot(&self.c[1])]
    }
    fn grad(&self, x: [f64; 2]) -> [[f64; 2]; 2] {
        let g = |c: &[f64; 6]| [c[1] + 2.0 * c[3] * x[0] + c[4] * x[1], c[2] + c[4] * x[0] + 2.0 * c[5] * x[1]];
        [g(&self.c[0]), g(&self.c[1])]
    }
}

impl Problem for Patch {
    fn name(&self) -> &str {
        "patch"
    }
    fn description(&self) -> &str {
        "Patch test: a quadratic displacement with its own f and g, obstacle far away"
    }
    fn material(&self) -> Material {
        self.material
    }
    fn part_of(&self, x: [f64; 2]) -> Part {
        contact_right_dirichlet_left(x)
    }
    /// f = -div sigma(u), constant for quadratic u.
    fn body_force(&self, _x: [f64; 2]) -> [f64; 2] {
        let (mu, zeta) = (self.material.mu, self.material.zeta);
        let [a, b] = self.c;
        // second derivatives: u_i,xx = 2 c[i][3], u_i,xy = c[i][4], u_i,yy = 2 c[i][5]
        let (u1xx, u1xy, u1yy) = (2.0 * a[3], a[4], 2.0 * a[5]);
        let (u2xx, u2xy, u2yy) = (2.0 * b[3], b[4], 2.0 * b[5]);
        // div sigma = mu Laplace u + (mu + zeta) grad div u
        let div1 = mu * (u1xx + u1yy) + (mu + zeta) * (u1xx + u2xy);
        let div2 = mu * (u2xx + u2yy) + (mu + zeta) * (u1xy + u2yy);
        [-div1, -div2]
    }
    fn traction(&self, x: [f64; 2], n: [f64; 2]) -> [f64; 2] {
        self.material.traction(self.grad(x), n)
    }
    fn dirichlet(&self, x: [f64; 2]) -> [f64; 2] {
        self.u(x)
    }
    fn contact_normal(&self, _x: [f64; 2], _outward: [f64; 2]) -> [f64; 2] {
        self.normal
    }
    fn gap(&self, _x: [f64; 2]) -> f64 {
        self.gap
    }
    /// The polynomial is the solution while it stays clear of the obstacle on x = 1 (the
    /// default gap 10); an obstacle it would pass makes the constraint bind, and then no exact
    /// solution is known (the exact solution check, `contact::consistent`, would refuse it).
    fn exact(&self) -> Option<&dyn Exact> {
        let n = self.normal;
        let len = n[0].hypot(n[1]);
        let clear = (0..=100).all(|k| {
            let u = Exact::u(self, [1.0, k as f64 / 100.0]);
            (u[0] * n[0] + u[1] * n[1]) / len <= self.gap
        });
        clear.then_some(self as &dyn Exact)
    }
}
