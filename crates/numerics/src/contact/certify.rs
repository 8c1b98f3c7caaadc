//! Every answer is certified. Before the SOLVE step factorises, it checks that the Dirichlet
//! part stops the rigid motions of every body ([`check_held`]); before it reports a discrete
//! solution, it checks the solution's KKT conditions (paper eq. 3.4, Lemma 5.2) against
//! tolerances scaled to the problem ([`certify`]). Either failure is a named error, never an
//! answer.
//!
//! # The KKT conditions and their scales
//! With r = F - K u (computed element by element, [`crate::fem::assembly::stiffness_times`]) and
//! lambda_p = r_p at the normal unknown of contact node p, a discrete solution has
//!
//! ```text
//!   r_i = 0 at every other unknown and at inactive contact normals   (the equations)
//!   lambda_p >= 0                                                     (sign of the force)
//!   u_h(p).n <= chi_h(p)                                              (no penetration)
//!   lambda_p (chi_h(p) - u_h(p).n) = 0                                (complementarity)
//! ```
//!
//! In floating point each holds to round-off. The equations and the sign are checked relative
//! to s_i = |F_i| + (sum_T |K_T| |u|)_i + (sum_T |K_T| 1)_i max|u|: the magnitude of the terms
//! r_i sums, plus what an error of round-off size in every unknown moves r_i by (a Cholesky
//! solve is backward stable in norm, not row by row: rows with small |K| |u|, such as those of
//! the graded Hertz mesh, carry the round-off of the whole solve; measured componentwise alone
//! they reached 1.2e-10). max_i |r_i| / s_i is then a backward error of the linear solves,
//! whatever the condition number. Penetration is checked relative to the displacement scale
//! U = max(max_p |u_h(p).n|, max_p |chi_h(p)|), complementarity relative to s_p U. The one
//! tolerance, [`TOLERANCE`], leaves orders of magnitude between the round-off measured on every
//! study and a wrong answer.

use crate::fem::assembly::DofMap;
use model::mesh::{Mesh, P2Nodes};
use model::problems::{Part, Problem};

/// The relative tolerance of every KKT condition ([`certify`]). Measured on all 769 solves of
/// every level of every study (`signorini drift`, 2026-11-24, up to 1.1M unknowns): the
/// largest values were 4.9e-14 for the equations (ex71), 1.5e-16 for complementarity (hertz),
/// exactly 0 for the sign and for penetration. A floating body solved through its singular
/// matrix misses the equations by 8.7e-4 (tests/it/kkt.rs). 1e-9 lies four orders of magnitude
/// above the round-off, room for the growth of the condition number to 1e7 unknowns and more.
pub const TOLERANCE: f64 = 1e-9;

/// The KKT conditions of a discrete solution, each as a relative value (see the module docs);
/// all at most [`TOLERANCE`] for a certified solution.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Certificate {
    /// max |r_i| / s_i over the unknowns other than active contact normals.
    pub equations: f64,
    /// max (-lambda_p)^+ / s_p over active contact nodes.
    pub sign: f64,
    /// max (u_h(p).n - chi_h(p))^+ / U over contact nodes.
    pub penetration: f64,
    /// max |lambda_p (chi_h(p) - u_h(p).n)| / (s_p U) over contact nodes.
    pub complementarity: f64,
}

/// One KKT condition that does not hold: which, by how much, and where.
#[derive(Debug, thiserror::Error)]
#[error(
    "the discrete solution is not certified: {condition} violated at ({x:.6}, {y:.6}) by {value:.3e} relative (tolerance {tolerance:.0e}); {advice}",
    x = at[0], y = at[1],
)]
pub struct KktError {
    pub condition: &'static str,
    pub value: f64,
    pub tolerance: f64,
    pub at: [f64; 2],
    pub certificate: Certificate,
    pub advice: &'static str,
}

/// The worst value of one condition and the node where it occurs.
#[derive(Clone, Copy)]
struct Worst {
    value: f64,
    node: usize,
}

impl Worst {
    fn new() -> Self {
        Worst { value: 0.0, node: usize::MAX }
    }
    /// Keep `value` if it is larger, or NaN (a NaN is never certified).
    fn see(&mut self, value: f64, node: usize) {
        if value > self.value || (value.is_nan() && !self.value.is_nan()) {
            *self = Worst { value, node };
        }
    }
}

/// The discrete solution's parts that the KKT conditions speak of, on the unknowns of the
/// assembled system.
pub struct KktInput<'a> {
    pub nodes: &'a P2Nodes,
    pub dofs: &'a DofMap,
    /// The load F.
    pub rhs: &'a [f64],
    /// K u, element by element.
    pub ku: &'a [f64],
    /// sum_T |K_T| |u|, the magnitude of the terms of K u.
    pub magnitude: &'a [f64],
    /// sum_T |K_T| 1, the rows' absolute sums.
    pub row_norm: &'a [f64],
    /// max |u| over the unknowns.
    pub u_max: f64,
    /// u_h(p).n per contact node.
    pub normal_displacement: &'a [f64],
    pub active: &'a [bool],
}

impl KktInput<'_> {
    /// s_i = |F_i| + (sum_T |K_T| |u|)_i + (sum_T |K_T| 1)_i max|u| (module docs): the scale of
    /// r_i's round-off, against which the equations and the sign are judged.
    pub fn scale(&self, i: usize) -> f64 {
        self.rhs[i].abs() + self.magnitude[i] + self.row_norm[i] * self.u_max
    }
}

/// Check the KKT conditions (module docs) and return their relative values, or the error naming
/// the first condition (in the order equations, sign, penetration, complementarity) that exceeds
/// `tolerance`, with the point where it is worst.
pub fn certify(input: &KktInput, tolerance: f64) -> Result<Certificate, KktError> {
    let KktInput { nodes, dofs, rhs, ku, normal_displacement, active, .. } = *input;
    let scale = |i: usize| input.scale(i);
    // |a| / s, with 0 / 0 = 0 (a row without terms) and a / 0 = inf
    let relative = |a: f64, s: f64| if a == 0.0 { 0.0 } else { a / s };
    let mut node_of = vec![usize::MAX; dofs.n_free];
    for (p, d) in dofs.dof.iter().enumerate() {
        for &k in d.iter().filter(|&&k| k != crate::fem::assembly::FIXED) {
            node_of[k] = p;
        }
    }
    let mut equations = Worst::new();
    for i in 0..dofs.n_free {
        let contact = i.checked_sub(dofs.n_interior);
        if contact.is_none_or(|k| !active[k]) {
            equations.see(relative((rhs[i] - ku[i]).abs(), scale(i)), node_of[i]);
        }
    }
    let u_scale = normal_displacement.iter().chain(dofs.contact.iter().map(|c| &c.gap)).fold(0.0f64, |a, v| a.max(v.abs()));
    let (mut sign, mut penetration, mut complementarity) = (Worst::new(), Worst::new(), Worst::new());
    for (k, c) in dofs.contact.iter().enumerate() {
        let i = dofs.n_interior + k;
        let lambda = rhs[i] - ku[i];
        let gap = c.gap - normal_displacement[k];
        if active[k] {
            sign.see(relative((-lambda).max(0.0), scale(i)), c.node);
        }
        penetration.see(relative((-gap).max(0.0), u_scale), c.node);
        complementarity.see(relative((lambda * gap).abs(), scale(i) * u_scale), c.node);
    }
    let certificate = Certificate {
        equations: equations.value,
        sign: sign.value,
        penetration: penetration.value,
        complementarity: complementarity.value,
    };
    let checks = [
        ("the equations (F - K u = 0 off the active contact normals)", equations, ADVICE_EQUATIONS),
        ("the sign of the contact force (lambda_p >= 0 at active nodes)", sign, ADVICE_KKT),
        ("non-penetration (u_h.n <= chi_h at contact nodes)", penetration, ADVICE_KKT),
        ("complementarity (lambda_p (chi_h - u_h.n) = 0)", complementarity, ADVICE_KKT),
    ];
    for (condition, worst, advice) in checks {
        if !(worst.value <= tolerance) {
            let at = nodes.coords.get(worst.node).copied().unwrap_or([f64::NAN; 2]);
            return Err(KktError { condition, value: worst.value, tolerance, at, certificate, advice });
        }
    }
    Ok(certificate)
}

const ADVICE_EQUATIONS: &str = "the linear solves did not solve the system (a singular or nearly singular stiffness matrix: check that the Dirichlet part holds the body, the material constants and the mesh)";
const ADVICE_KKT: &str =
    "the active-set method stopped on a wrong answer (check the problem's data: the gap chi, the contact normal, the loads)";

/// The Dirichlet part does not stop the rigid motions of a body: its stiffness matrix is
/// singular and the contact problem has no unique solution (the solver does not treat the
/// semi-coercive case).
#[derive(Debug, thiserror::Error)]
#[error(
    "the body can move rigidly: {body} {held}, so the stiffness matrix is singular (a body needs Dirichlet data at two points at least, e.g. one Dirichlet edge, or components prescribed that stop both translations and the rotation). The mesh's boundary edges: {edges}{declared}"
)]
pub struct RigidMotionError {
    /// Which body (of how many), with its size and a point of it.
    pub body: String,
    /// "has no Dirichlet node", "is held at one point only, (x, y)", or which rigid motion
    /// its prescribed components leave free.
    pub held: String,
    /// Number of boundary edges per part.
    pub edges: String,
    /// The problem's declaration of its parts, if it states one.
    pub declared: String,
}

/// The prescribed components of one body, as far as they stop its rigid motions
/// a + theta (-y, x): a prescribed u_1 at (x, y) asks a_1 = theta y, a prescribed u_2 asks
/// a_2 = -theta x. The motions are stopped unless u_1 or u_2 is prescribed nowhere, or every
/// prescribed u_1 is on one line y = y0 and every prescribed u_2 on one line x = x0 (a rotation
/// about (x0, y0) is left; two distinct fully prescribed nodes always stop it).
#[derive(Clone, Debug, Default)]
struct Held {
    triangles: usize,
    /// The first node with a prescribed component, and whether another one exists.
    first: Option<usize>,
    second: bool,
    /// Per component, the range of the other coordinate over its prescribed nodes (y for u_1,
    /// x for u_2), `None` if it is prescribed nowhere.
    range: [Option<[f64; 2]>; 2],
}

/// How wide a range of coordinates may be and still be one line: 1e-9 of the body's size (the
/// diagonal of the nodes' bounding box, so a mesh far from the origin is judged by its own size,
/// not by its distance from the origin), plus the round-off of coordinates of that magnitude.
#[derive(Clone, Copy, Debug)]
struct LineTolerance(f64);

impl LineTolerance {
    fn of(coords: &[[f64; 2]]) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for x in coords {
            for d in 0..2 {
                (lo[d], hi[d]) = (lo[d].min(x[d]), hi[d].max(x[d]));
            }
        }
        let size = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        let magnitude = coords.iter().fold(0.0f64, |a, x| a.max(x[0].abs()).max(x[1].abs()));
        LineTolerance((1e-9 * size + 8.0 * f64::EPSILON * magnitude).max(f64::MIN_POSITIVE))
    }
}

impl Held {
    fn see(&mut self, p: usize, x: [f64; 2], fixed: [bool; 2]) {
        match self.first {
            None => self.first = Some(p),
            Some(q) if q != p => self.second = true,
            _ => {}
        }
        for (i, r) in self.range.iter_mut().enumerate().filter(|&(i, _)| fixed[i]) {
            let c = x[1 - i];
            *r = Some(r.map_or([c, c], |[a, b]| [a.min(c), b.max(c)]));
        }
    }

    /// `None` if the rigid motions are stopped, else what is left free (for the error).
    fn free_motion(&self, nodes: &P2Nodes, scale: LineTolerance) -> Option<String> {
        let at = |p: usize| format!("({:.6}, {:.6})", nodes.coords[p][0], nodes.coords[p][1]);
        let p = match self.first {
            None => return Some("has no Dirichlet node".to_string()),
            Some(p) if !self.second => return Some(format!("is held at one point only, {}", at(p))),
            Some(p) => p,
        };
        let on_one_line = |r: [f64; 2]| r[1] - r[0] <= scale.0;
        match self.range {
            [None, _] => Some(format!("has u_1 prescribed nowhere (a horizontal translation is free; first prescribed node {})", at(p))),
            [_, None] => Some(format!("has u_2 prescribed nowhere (a vertical translation is free; first prescribed node {})", at(p))),
            [Some(r0), Some(r1)] if on_one_line(r0) && on_one_line(r1) => Some(format!(
                "has u_1 prescribed only on the line y = {:.6} and u_2 only on the line x = {:.6} (a rotation about their crossing is free)",
                r0[0], r1[0]
            )),
            _ => None,
        }
    }
}

/// Check that the prescribed components (Dirichlet data and point constraints) stop the rigid
/// motions of every body of the mesh (an edge-connected set of triangles: two triangles sharing
/// only a vertex can turn about it), as `Held` decides: with both components prescribed, two
/// distinct nodes suffice; rollers on a side need a prescribed u_2 somewhere else.
pub fn check_held(mesh: &Mesh, nodes: &P2Nodes, dofs: &DofMap, problem: &dyn Problem) -> Result<(), RigidMotionError> {
    let bodies = bodies(nodes);
    let n_bodies = bodies.iter().copied().max().map_or(0, |b| b + 1);
    let mut held = vec![Held::default(); n_bodies];
    for (t, el) in nodes.elements.iter().enumerate() {
        let h = &mut held[bodies[t]];
        h.triangles += 1;
        for &p in el {
            let fixed = dofs.dof[p].map(|d| d == crate::fem::assembly::FIXED);
            if fixed != [false, false] {
                h.see(p, nodes.coords[p], fixed);
            }
        }
    }
    let scale = LineTolerance::of(&nodes.coords);
    let Some((b, triangles, held)) =
        held.iter().enumerate().find_map(|(b, h)| h.free_motion(nodes, scale).map(|why| (b, h.triangles, why)))
    else {
        return Ok(());
    };
    let t = bodies.iter().position(|&x| x == b).expect("every body has a triangle");
    let c = nodes.coords[nodes.elements[t][0]];
    let body = if n_bodies == 1 {
        format!("the mesh ({triangles} triangles)")
    } else {
        format!("body {} of the {n_bodies} separate bodies of the mesh ({triangles} triangles, one at ({:.4}, {:.4}))", b + 1, c[0], c[1])
    };
    let count = |part| mesh.boundary.iter().filter(|e| e.part == part).count();
    let edges = format!("{} Dirichlet, {} contact, {} Neumann", count(Part::Dirichlet), count(Part::Contact), count(Part::Neumann));
    let declared = match problem.declared_parts() {
        d if d.is_empty() => String::new(),
        d => format!("; problem {} declares {}", problem.name(), d.join(", ")),
    };
    Err(RigidMotionError { body, held, edges, declared })
}

/// The body of every triangle: the edge-connected components of the mesh, numbered in the
/// order of their first triangle. The one split of the mesh into bodies: the rigid-motion check,
/// the gap bound (`chord::Chords`) and what a solve resolves (`adapt::resolution`, per body)
/// take it.
pub fn bodies(nodes: &P2Nodes) -> Vec<usize> {
    let n = nodes.elements.len();
    let mut body = vec![usize::MAX; n];
    let mut stack = Vec::new();
    let mut next = 0;
    for start in 0..n {
        if body[start] != usize::MAX {
            continue;
        }
        body[start] = next;
        stack.push(start);
        while let Some(t) = stack.pop() {
            for s in nodes.neighbours[t].iter().flatten() {
                if body[*s] == usize::MAX {
                    body[*s] = next;
                    stack.push(*s);
                }
            }
        }
        next += 1;
    }
    body
}
