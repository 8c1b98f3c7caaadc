//! The exact solution against the boundary and contact conditions (paper eq. 1.1–1.8): on
//! Gamma_D u is the Dirichlet data (the components it prescribes), at a point constraint u is the
//! prescribed value, on Gamma_N sigma(u) n is the traction, in a component Gamma_D leaves free
//! (rollers) the traction is zero, on Gamma_C u . n <= chi, sigma_nn <= 0,
//! (chi - u . n) sigma_nn = 0 and sigma(u) n has no part across the contact normal (frictionless). A mistyped gap or traction otherwise gives an
//! exact solution of another problem, and errors that never converge (chi = -0.05 in Example
//! 7.1 keeps the error at 5e-2 on every mesh, every solve certified).
//!
//! Checked on every boundary edge of the mesh at every point where the discrete problem reads
//! the data there: its end points and midpoint (the P2 nodes, where the Dirichlet data, the gap
//! and the contact normal are taken) and the Gauss points of the traction
//! ([`crate::fem::assembly::edge_points`]). An edge on a curve (`[curves]`) is checked at the
//! curve's points closest to those, with the curve's own normal: its chord is off the curve, and
//! the chord's normal is not the body's (with curved edges left out, tension on a contact arc
//! would be certified). The points depend on the mesh, but every value of the data the
//! discrete problem sees is checked (a bump in the Dirichlet data between sampled midpoints
//! passes on the meshes that put no point in it). On Neumann edges the estimator's edge points (both
//! samplings, [`model::settings::sampling::Sampling::edge_parameters`]) are checked too: it reads
//! the traction there.
//!
//! The contact conditions are not data the discrete problem reads between its nodes, yet an
//! exact solution that goes through the obstacle between them is not one (checked at the nodes
//! only, a dip 0.008 wide would be certified on structured:4 and 8, refused on 16 and at level 4
//! of `adapt`). So every
//! contact edge is also cut into equal pieces no longer than the body's size (the diagonal of the
//! mesh's bounding box) over [`CONTACT_DENSITY`], and all four contact conditions are checked at
//! their ends. The rule: a violation longer than that spacing along Gamma_C is refused on every
//! mesh, at the first level; a narrower one only where some mesh puts a point in it. A value off by more than [`super::CONSISTENT`] times the
//! scale of what it is compared with (the largest |u| over the points, or for a traction
//! [`stress_scale`]: the largest |sigma n|, no less than the stress the size of u and grad u
//! implies) is a contradiction.

use super::{CONSISTENT, ExactError};
use crate::fem::assembly::edge_points;
use model::mesh::{Mesh, P2Nodes};
use model::problems::{Curve, Exact, Part, Problem};

/// A checked point of a boundary edge: where, the body's outward normal there, the part, and
/// which edge (by index into `mesh.boundary`) at which parameter `t` (0 and 1: its vertices).
pub(in crate::contact) struct Point {
    pub at: [f64; 2],
    pub normal: [f64; 2],
    pub part: Part,
    pub edge: usize,
    pub t: f64,
}

/// The point of `curve` closest to `x` and the curve's normal there, turned to agree with the
/// chord's outward normal `chord` (the chord's own where the curve has no normal).
fn on_curve(curve: &Curve, x: [f64; 2], chord: [f64; 2]) -> ([f64; 2], [f64; 2]) {
    let at = curve.project(x);
    (at, curve.outward(at, chord))
}

/// The contact part is checked at points no farther apart than the body's size (the diagonal of
/// the mesh's bounding box) over this number, on every mesh (see the module docs).
pub const CONTACT_DENSITY: usize = 4096;

/// The parameters s in [0, 1] of `edge` (from `p` to `q`) where it is checked, sorted, each
/// once: every point where the discrete problem or the estimate reads the data on the edge (the
/// P2 nodes, the traction's Gauss points [`edge_points`], and on a Neumann edge the estimator's
/// edge points under both samplings), and on a contact edge also equal pieces no longer than
/// `spacing`.
fn parameters(p: [f64; 2], q: [f64; 2], part: Part, spacing: f64) -> Vec<f64> {
    use model::settings::sampling::Sampling;
    let mut s = vec![0.0, 1.0, 0.5];
    s.extend(edge_points(p, q).into_iter().map(|(t, _, _)| t));
    if part == Part::Neumann {
        s.extend(Sampling::Quadrature.edge_parameters());
        s.extend(Sampling::Dense.edge_parameters());
    }
    if part == Part::Contact {
        let pieces = ((p[0] - q[0]).hypot(p[1] - q[1]) / spacing).ceil();
        let pieces = if pieces.is_finite() { (pieces as usize).clamp(1, 1 << 20) } else { 1 };
        s.extend((1..pieces).map(|k| k as f64 / pieces as f64));
    }
    s.sort_by(f64::total_cmp);
    s.dedup();
    s
}

/// Every checked point (see the module docs), edge by edge, with the length of its edge; with
/// `only`, the edges of that part alone. The one point set of the contact part: the exact
/// solution's contact conditions and the contact data ([`crate::contact::plausible`]) are
/// checked on it.
pub(in crate::contact) fn sample(mesh: &Mesh, nodes: &P2Nodes, only: Option<Part>) -> Vec<(Point, f64)> {
    use rayon::prelude::*;
    let normals = model::mesh::outward_normals(mesh, nodes);
    let spacing = super::diameter(mesh) / CONTACT_DENSITY as f64;
    // in the edges' order, whatever the number of threads
    let edges = mesh.boundary.par_iter().enumerate().filter(|(_, e)| only.is_none_or(|p| e.part == p));
    edges
        .flat_map_iter(|(b, edge)| {
            let [p, q] = edge.v.map(|v| mesh.vertices[v]);
            let len = (p[0] - q[0]).hypot(p[1] - q[1]);
            let chord = normals[b];
            parameters(p, q, edge.part, spacing).into_iter().map(move |t| {
                let x = [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
                let (at, normal) = match &edge.curve {
                    None => (x, chord),
                    Some(curve) => on_curve(curve, x, chord),
                };
                (Point { at, normal, part: edge.part, edge: b, t }, len)
            })
        })
        .collect()
}

/// The boundary points where `exact.grad` is compared with differences of `exact.u`, each with
/// its difference step (a thousandth of its edge, at least 1e-6 of the body's size, as
/// [`super::steps`]): every point of [`sample`] on a Neumann edge, and on a curved one also the
/// chord's points: where the assembly and the estimator read the traction `"exact"` =
/// sigma(grad) n, the only place the gradient enters the discrete problem or the estimate.
pub(super) fn gradient_points(mesh: &Mesh, nodes: &P2Nodes) -> Vec<([f64; 2], f64)> {
    let floor = 1e-3 * super::diameter(mesh);
    let spacing = super::diameter(mesh) / CONTACT_DENSITY as f64;
    let neumann = sample(mesh, nodes, Some(Part::Neumann)).into_iter();
    let mut out: Vec<([f64; 2], f64)> = neumann.map(|(p, len)| (p.at, 1e-3 * len.max(floor))).collect();
    for edge in mesh.boundary.iter().filter(|e| e.curve.is_some() && e.part == Part::Neumann) {
        let [p, q] = edge.v.map(|v| mesh.vertices[v]);
        let step = 1e-3 * (p[0] - q[0]).hypot(p[1] - q[1]).max(floor);
        out.extend(parameters(p, q, edge.part, spacing).into_iter().map(|t| ([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])], step)));
    }
    out
}

/// The scale tractions are judged against: the largest |sigma(u) n| over the points, but no less
/// than the stress the displacement's size implies, (2 mu + |lambda|) times the largest |grad u|
/// over the points and the largest |u| over the body's size (the diagonal of the mesh's bounding
/// box). For a stress-free exact solution (a rigid motion written with identities, sin^2 + cos^2)
/// the largest |sigma(u) n| is the round-off of its gradient, and a tolerance relative to it
/// would refuse that round-off as "tangential traction 2e-19".
fn stress_scale(problem: &dyn Problem, exact: &dyn Exact, mesh: &Mesh, points: &[Point], scale_u: f64) -> f64 {
    let material = problem.material();
    let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
    let stiffness = 2.0 * material.mu + material.zeta.abs();
    use rayon::prelude::*;
    let (traction, gradient) = points
        .par_iter()
        .map(|p| {
            let g = exact.grad(p.at);
            let t = material.traction(g, p.normal);
            (finite(t[0].hypot(t[1])), finite(g[0][0].abs().max(g[0][1].abs()).max(g[1][0].abs()).max(g[1][1].abs())))
        })
        .reduce(|| (0.0f64, 0.0f64), |a, b| (a.0.max(b.0), a.1.max(b.1)));
    traction.max(stiffness * gradient).max(stiffness * scale_u / super::diameter(mesh))
}

/// The numbers a violated condition is reported with ([`Detail::text`]): written out only for
/// the conditions that fail, as a mesh of 1e7 unknowns has 1e5 checked boundary points.
enum Detail {
    Dirichlet { i: usize, u: f64, g: f64 },
    Free { i: usize, s: f64, n: [f64; 2] },
    Traction { i: usize, s: f64, g: f64, n: [f64; 2] },
    Contact { un: f64, chi: f64, snn: f64 },
    Tangential { s: [f64; 2], cn: [f64; 2], tangential: f64 },
    Point { i: usize, u: f64, v: f64 },
}

impl Detail {
    fn text(&self) -> String {
        match *self {
            Detail::Dirichlet { i, u, g } => format!("u_{} = {u:.6e}, `dirichlet[{i}]` = {g:.6e}", i + 1),
            Detail::Free { i, s, n } => {
                format!("(sigma(u) n)_{} = {s:.6e} where `dirichlet[{i}]` is \"free\" (n = ({:.4}, {:.4}))", i + 1, n[0], n[1])
            }
            Detail::Traction { i, s, g, n } => {
                format!("(sigma(u) n)_{} = {s:.6e}, the traction `traction[{i}]` = {g:.6e} (n = ({:.4}, {:.4}))", i + 1, n[0], n[1])
            }
            Detail::Contact { un, chi, snn } => format!("u . n = {un:.6e}, the gap chi = {chi:.6e}, sigma_nn = {snn:.6e}"),
            Detail::Tangential { s, cn, tangential } => format!(
                "sigma(u) n = ({:.6e}, {:.6e}), its part across the contact normal ({:.4}, {:.4}) is {tangential:.6e}",
                s[0], s[1], cn[0], cn[1]
            ),
            Detail::Point { i, u, v } => format!("u_{} = {u:.6e}, prescribed {v:.6e}", i + 1),
        }
    }
}

/// One condition at one point: how far it is violated (0 when it holds), the scale that is
/// measured against, and what the error says.
struct Violation {
    at: [f64; 2],
    off: f64,
    scale: f64,
    what: &'static str,
    detail: Detail,
}

impl Violation {
    /// A contradiction: off by more than [`CONSISTENT`] times its scale.
    fn holds(&self) -> bool {
        !(self.off.is_finite() && self.off > CONSISTENT * self.scale)
    }
}

/// Scales the conditions are measured against: |u| ([`check_boundary`]'s `scale_u`) and a
/// traction's ([`stress_scale`]).
struct Scales {
    u: f64,
    stress: f64,
}

/// The conditions at one boundary point (see the module docs), each with how far it is off.
fn conditions(problem: &dyn Problem, exact: &dyn Exact, p: &Point, scales: &Scales) -> Vec<Violation> {
    let material = problem.material();
    let sigma_n = |x: [f64; 2], n: [f64; 2]| material.traction(exact.grad(x), n);
    let norm = |v: [f64; 2]| v[0].hypot(v[1]);
    let (u, n, at) = (exact.u(p.at), p.normal, p.at);
    let mut out = Vec::new();
    match p.part {
        Part::Dirichlet => {
            let g = problem.dirichlet(at);
            let prescribed = problem.dirichlet_components();
            for i in (0..2).filter(|&i| prescribed[i]) {
                let detail = Detail::Dirichlet { i, u: u[i], g: g[i] };
                out.push(Violation { at, off: (u[i] - g[i]).abs(), scale: scales.u, what: "the Dirichlet data on Gamma_D", detail });
            }
            // a component the data leave free ("free": rollers) carries zero traction
            let s = sigma_n(at, n);
            for i in (0..2).filter(|&i| !prescribed[i]) {
                let what = "zero traction in a free component on Gamma_D (rollers)";
                out.push(Violation { at, off: s[i].abs(), scale: scales.stress, what, detail: Detail::Free { i, s: s[i], n } });
            }
        }
        Part::Neumann => {
            let (g, s) = (problem.traction(at, n), sigma_n(at, n));
            for i in 0..2 {
                let detail = Detail::Traction { i, s: s[i], g: g[i], n };
                out.push(Violation { at, off: (s[i] - g[i]).abs(), scale: scales.stress, what: "the traction on Gamma_N", detail });
            }
        }
        Part::Contact => {
            let cn = problem.contact_normal(at, n);
            let len = norm(cn);
            let cn = [cn[0] / len, cn[1] / len];
            let (un, chi) = (u[0] * cn[0] + u[1] * cn[1], problem.gap(at));
            let s = sigma_n(at, n);
            let snn = s[0] * cn[0] + s[1] * cn[1];
            let contact =
                |what: &'static str, off: f64, scale: f64| Violation { at, off, scale, what, detail: Detail::Contact { un, chi, snn } };
            out.push(contact("the contact condition u . n <= chi on Gamma_C", (un - chi).max(0.0), scales.u));
            out.push(contact("the contact condition sigma_nn <= 0 on Gamma_C (no tension)", snn.max(0.0), scales.stress));
            // frictionless: the traction acts along the contact normal only
            let tangential = norm([s[0] - snn * cn[0], s[1] - snn * cn[1]]);
            let what = "no tangential traction on Gamma_C (frictionless contact)";
            out.push(Violation { at, off: tangential, scale: scales.stress, what, detail: Detail::Tangential { s, cn, tangential } });
            // open (chi - u . n > 0) and pressed (sigma_nn < 0) at once: the smaller of the two
            // relative violations
            let open = ((chi - un).max(0.0) / scales.u.max(f64::MIN_POSITIVE)).min((-snn).max(0.0) / scales.stress.max(f64::MIN_POSITIVE));
            out.push(contact("complementarity on Gamma_C ((chi - u . n) sigma_nn = 0: pressed where the gap is open)", open, 1.0));
        }
    }
    out
}

/// Check the exact solution against the boundary and contact conditions on `mesh`.
pub fn check_boundary(problem: &dyn Problem, exact: &dyn Exact, mesh: &Mesh, nodes: &P2Nodes, name: &str) -> Result<(), ExactError> {
    use rayon::prelude::*;
    let points: Vec<Point> = sample(mesh, nodes, None).into_iter().map(|(p, _)| p).collect();
    let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
    let scale_u = points
        .par_iter()
        .map(|p| {
            let u = exact.u(p.at);
            finite(u[0].hypot(u[1]))
        })
        .reduce(|| 0.0, f64::max);
    let scales = Scales { u: scale_u, stress: stress_scale(problem, exact, mesh, &points, scale_u) };
    // in the points' order, whatever the number of threads
    let mut bad: Vec<Violation> =
        points.par_iter().flat_map_iter(|p| conditions(problem, exact, p, &scales).into_iter().filter(|v| !v.holds())).collect();
    for c in problem.point_constraints() {
        let u = exact.u(c.at);
        for (i, v) in c.u.iter().enumerate() {
            if let Some(v) = *v {
                let detail = Detail::Point { i, u: u[i], v };
                let what = "a point constraint (`point_constraints`)";
                let violation = Violation { at: c.at, off: (u[i] - v).abs(), scale: scale_u, what, detail };
                if !violation.holds() {
                    bad.push(violation);
                }
            }
        }
    }
    match bad.first() {
        None => Ok(()),
        Some(v) => Err(ExactError::Boundary {
            problem: name.to_string(),
            what: v.what.to_string(),
            at: v.at,
            detail: v.detail.text(),
            count: bad.iter().filter(|b| b.what == v.what).count(),
            sampled: points.len(),
        }),
    }
}
