//! Contact data that make physical sense on the mesh, checked once per solve before anything is
//! assembled ([`check_contact_data`], called by [`solve`](super::solve::solve), so the command
//! line, the adaptive loop and every study get it).
//!
//! * **The constraint direction points out of the body.** The Signorini condition u . n <= chi
//!   stops the body moving through the obstacle along n; n must leave the body where it is
//!   used. At every contact node the declared normal is compared with the outward unit normal
//!   of the contact edges holding the node (at a vertex between two contact edges, the more
//!   favourable of the two: a corner may take any direction of its normal cone), and so it is
//!   at every point of the contact part's sampling, the point set on which an exact solution's
//!   contact conditions are checked (`consistent::boundary::sample`: the Gauss points and
//!   pieces no longer than the body's size over 4096 along every contact edge, on a curve with
//!   the curve's normal): a stretch of bad data between the nodes is refused on every mesh, not
//!   only where refinement puts a node in it (checked at the nodes only, a reversed normal 0.005
//!   long would be certified on structured:4 and 8). A normal with
//!   n . n_out < 0 is reversed (the constraint would pull the body into the obstacle); one with
//!   n . n_out < cos 80 degrees (within 10 degrees of the boundary) is nearly tangent: the
//!   constraint would act mostly along the surface, limiting sliding, and the normal gap it
//!   measures is inflated by 1 / cos(angle) > 5.8. 80 degrees, not less, because a declared
//!   direction is often a flat foundation's, not the surface's normal (`hertz.toml`: the arc of
//!   a cylinder against the direction (0, -1)), and such a part legitimately reaches well past
//!   45 degrees on a curved body.
//! * **A contact node carries one direction.** The node holds one constraint u . n <= chi; where
//!   the normal differs between its two contact edges (two sides of the square with `normal =
//!   "outward"`, two circles meeting at an angle, a declared normal that jumps there) the node is
//!   held along one of them only and could pass the obstacle along the other (the corner of two
//!   contact sides that takes the bottom's normal can pass the side wall by 8% of the gap,
//!   certified). Refused, naming the node and both normals ([`ContactDataError::Corner`]).
//! * **The obstacle does not overlap the body by more than its thickness.** A gap chi(p) < -D,
//!   D the body's chord through p along the contact normal n (the length of the piece of the
//!   line p + t n inside the edge-connected body holding p, up to a held end of Gamma_D, which
//!   counts where its Dirichlet data put it: [`Chords`]), asks the body to move through its
//!   whole thickness along n at p:
//!   outside linear (small-strain) elasticity everywhere it happens, and in practice a sign or
//!   unit mistake. Checked at the contact nodes and on the same sampling as the normal; a gap
//!   or normal that is not a finite number at a sampled point is named as the data watch names
//!   it ([`ContactDataError::Datum`]).
//! * **Prescribed displacements do not push the body into the obstacle.** A node of the closure
//!   of Gamma_C whose displacement is prescribed (a corner shared with Gamma_D, a point
//!   constraint) is not a contact node, so the constraint is not imposed there; yet a prescribed
//!   u with u . n > chi puts that point of the body inside the obstacle, which no solution of the
//!   contact problem does. Where the prescribed components determine u . n (both prescribed, or
//!   the one along n), u . n - chi must not exceed [`PRESCRIBED_PENETRATION`] times the body's
//!   size. Such data leave the continuous problem without a solution: the trace of u on the
//!   boundary lies in H^{1/2}, which holds no function with a jump, yet u . n would have to jump
//!   from its prescribed value to at most chi at that end of Gamma_C; the discrete problems are
//!   solvable only because the node is not constrained, and their solutions converge to nothing.
//! * **No node of the closure of Gamma_C is left unconstrained along n.** Where one component
//!   is prescribed (rollers meeting the contact part, a symmetry hold on it) and the normal has a
//!   part along the free one, u . n depends on a free unknown that no constraint bounds (the node
//!   is not a contact node): a certified answer could pass the obstacle there (a Hertz symmetry
//!   hold on the contact part can sink by 6.7e-5). Refused, naming the node
//!   ([`ContactDataError::HalfPrescribed`]); imposing the constraint on the free component alone is
//!   not built.
//!
//! Not repeated here: a normal of length 0 or a gap that is not a finite number at a node is
//! refused by the data watch (`problems::BadDatum`, after assembly); a declared normal is normalised where
//! it is evaluated; Young's modulus, Poisson's ratio and the Lamé constants are checked when a
//! problem file is read (`problems::file`).

use super::chord::Chords;
use crate::fem::assembly::DofMap;
use model::base::number::{point, shown};
use model::mesh::{Mesh, P2Nodes};
use model::problems::{Part, Problem};

/// The largest angle, in degrees, a declared contact normal may make with the outward normal.
pub const MAX_NORMAL_ANGLE_DEGREES: f64 = 80.0;

/// How far (relative to the diameter of the mesh's bounding box) a prescribed displacement at a
/// node of the closure of Gamma_C may pass the obstacle: round-off of data that touch it.
pub const PRESCRIBED_PENETRATION: f64 = 1e-9;

/// Contact data without physical sense on this mesh.
#[derive(Debug, thiserror::Error)]
pub enum ContactDataError {
    #[error(
        "{problem}: the contact normal (`contact.normal`) at {x} on the contact part ({part}), edge {a}-{b}, is ({nx:.6}, {ny:.6}), {how} the edge's outward normal ({ox:.6}, {oy:.6}) (n . n_out = {dot:.6}, an angle of {angle:.1} degrees): a contact normal must point out of the body, within {max} degrees of the outward normal",
        x = point(*.at), a = point(.edge[0]), b = point(.edge[1]),
        nx = .normal[0], ny = .normal[1], ox = .outward[0], oy = .outward[1],
        how = if *.dot < 0.0 { "reversed against" } else { "nearly tangent to the boundary: far from" },
        angle = .dot.clamp(-1.0, 1.0).acos().to_degrees(), max = MAX_NORMAL_ANGLE_DEGREES
    )]
    Normal { problem: String, part: String, at: [f64; 2], edge: [[f64; 2]; 2], normal: [f64; 2], outward: [f64; 2], dot: f64 },
    #[error(
        "{problem}: the contact node at {x} on the contact part ({part}) is a corner of the contact normal: the node carries n = ({nx:.6}, {ny:.6}), but on the contact edge from {a} to {b} the normal next to it is ({sx:.6}, {sy:.6}), {angle:.4} degrees apart. One node carries one constraint u . n <= chi, so it could pass the obstacle along the other direction. Let one of the two contact stretches end before this node (the edge on one side of it not contact), or, where the obstacle is one flat surface, declare its direction (normal = [nx, ny])",
        x = point(*.at), a = point(.edge[0]), b = point(.edge[1]), nx = .node[0], ny = .node[1], sx = .side[0], sy = .side[1],
        angle = .angle.to_degrees()
    )]
    /// `node`: the node's normal; `side`: the normal on `edge` next to the node; `angle` in radians.
    Corner { problem: String, part: String, at: [f64; 2], edge: [[f64; 2]; 2], node: [f64; 2], side: [f64; 2], angle: f64 },
    #[error(
        "{problem}: the gap `contact.chi` at {x} on the contact part ({part}) is {chi}: the obstacle would overlap the body by more than the body's thickness along the contact normal ({nx:.6}, {ny:.6}) there (the length of the line through that point along n inside the body, {d}{held}), pushing the body through itself; a gap below minus the body's thickness is a sign or unit mistake",
        x = point(*.at), chi = shown(*.chi), d = shown(*.chord), nx = .normal[0], ny = .normal[1],
        held = held_text(.held, *.chord)
    )]
    /// `chord`: the body's chord through `at` along the unit `normal` ([`Chords`]); `held`:
    /// the end on Gamma_D it stops at, and how far the Dirichlet data move that end towards the
    /// contact face (negative: away), where they move it.
    Gap { problem: String, part: String, at: [f64; 2], chi: f64, normal: [f64; 2], chord: f64, held: Option<([f64; 2], f64)> },
    #[error(
        "{problem}: the node at {x} on the closure of the contact part ({part}) has u_{fixed} prescribed by {by} and u_{free} free, and the contact normal there ({nx:.6}, {ny:.6}) acts on the free u_{free}: the contact condition u . n <= chi is imposed only at nodes with no prescribed component, so it would not hold there and the body could pass the obstacle at that node. Prescribe both components there, or let the contact part and the part or point that prescribes one component not meet",
        x = point(*.at), nx = .normal[0], ny = .normal[1], fixed = .fixed + 1, free = 2 - .fixed
    )]
    /// `fixed`: the prescribed component (0 or 1).
    HalfPrescribed { problem: String, part: String, by: String, at: [f64; 2], fixed: usize, normal: [f64; 2] },
    #[error(
        "{problem}: the displacement prescribed at {x} on the closure of the contact part ({part}) by {by} is ({ux}, {uy}); along the contact normal ({nx:.6}, {ny:.6}) that is u . n = {un}, past the gap chi = {chi} by {over:.3e}: the body would start inside the obstacle there. Prescribe a displacement with u . n <= chi at the contact part's ends (or end the contact part before them)",
        x = point(*.at), ux = .u[0], uy = .u[1], nx = .normal[0], ny = .normal[1], over = .un - .chi
    )]
    /// `u`: the prescribed components, "free" for one that is not.
    Prescribed { problem: String, part: String, by: String, at: [f64; 2], u: [String; 2], normal: [f64; 2], un: f64, chi: f64 },
    /// The gap or the normal is not a finite number at a sampled point of the contact part.
    #[error(transparent)]
    Datum(model::problems::BadDatum),
}

/// The problem as errors name it: its file, or its built-in name.
pub(super) fn problem_name(problem: &dyn Problem) -> String {
    match problem.source() {
        Some(file) => format!("problem file {}", file.display()),
        None => format!("problem {}", problem.name()),
    }
}

/// How the problem declares its contact part (`parts.contact = ...`), or "Gamma_C".
fn contact_part(problem: &dyn Problem) -> String {
    problem.declared_parts().into_iter().find(|d| d.starts_with("parts.contact")).unwrap_or_else(|| "Gamma_C".into())
}

/// Check the problem's contact data on the contact part and at the prescribed nodes of its
/// closure (see the module docs). Data that are not finite numbers are named by the data watch:
/// when the gap or normal `dofs` holds already tripped it, nothing is checked here (the SOLVE
/// step names it after assembling); one that trips it at a sampled point between the nodes is
/// returned at once ([`ContactDataError::Datum`]).
pub fn check_contact_data(mesh: &Mesh, nodes: &P2Nodes, dofs: &DofMap, problem: &dyn Problem) -> Result<(), Box<ContactDataError>> {
    if problem.bad_datum().is_some() {
        return Ok(());
    }
    let outward: Vec<Option<[f64; 2]>> = model::mesh::outward_normals(mesh, nodes)
        .into_iter()
        .zip(&mesh.boundary)
        .map(|(n, e)| (e.part == Part::Contact).then_some(n))
        .collect();
    let diameter = super::consistent::diameter(mesh);
    let chords = Chords::of(mesh, nodes, problem);
    // the normal at each node and sampled point first: a normal nearly tangent or reversed is
    // named as such, never as a corner where it merely turns fast
    check_nodes(mesh, nodes, dofs, problem, &outward, &chords)?;
    check_sampled(mesh, nodes, problem, &chords)?;
    check_corners(mesh, dofs, problem, diameter)?;
    check_prescribed(mesh, nodes, dofs, problem, diameter)
}

/// The largest angle (radians, 0.057 degrees) between a contact vertex's normal and the normal
/// on one of its contact edges next to it ([`check_corners`]). A real angle, not round-off: a
/// smooth normal reaches it over [`PART_END`](model::mesh::PART_END) of the body's size only by
/// turning 1e6 radians per body size (a jump for every purpose), and a normal evaluated from
/// expressions at far translated coordinates keeps its direction to about 1e-9
/// (`["x - 0.5", "-1e-3"]` turns by 1e-6 over 1e-9 of the size, which a bound of 1e-6 would call
/// a corner). Below it, the one direction a node holds differs from the other side's by less
/// than 1e-3 of a displacement along it.
pub const CORNER_ANGLE: f64 = 1e-3;

/// Every contact vertex against the normal on each of its contact edges, at the vertex (with
/// that edge's outward normal) and next to it ([`PART_END`](model::mesh::PART_END) of the body's
/// size inside the edge, as the part check takes a vertex): where they differ by more than
/// [`CORNER_ANGLE`] the vertex is a corner of the normal (two contact sides of the square with
/// `normal = "outward"`, two circles meeting at an angle, a declared normal that jumps there),
/// and its one constraint u . n <= chi holds the body along one direction only (a corner of two
/// contact sides that takes the bottom's normal can pass the side wall, certified).
/// Built-in problems and declared constant normals have no corner.
fn check_corners(mesh: &Mesh, dofs: &DofMap, problem: &dyn Problem, diameter: f64) -> Result<(), Box<ContactDataError>> {
    let angle = |a: [f64; 2], b: [f64; 2]| (a[0] * b[1] - a[1] * b[0]).abs().atan2(a[0] * b[0] + a[1] * b[1]);
    for (b, e) in mesh.boundary.iter().enumerate().filter(|(_, e)| e.part == Part::Contact) {
        let [p, q] = e.v.map(|v| mesh.vertices[v]);
        let len = (q[0] - p[0]).hypot(q[1] - p[1]);
        let t = (model::mesh::PART_END * diameter / len).min(0.25);
        for (v, at, far) in [(e.v[0], p, q), (e.v[1], q, p)] {
            let Some(k) = dofs.contact_index[v] else { continue };
            let node = dofs.contact[k].normal;
            let next = [at[0] + t * (far[0] - at[0]), at[1] + t * (far[1] - at[1])];
            for x in [at, next] {
                let side = problem.contact_normal(x, mesh.outward_at(b, x));
                let off = angle(node, side);
                if off > CORNER_ANGLE {
                    let (problem, part) = (problem_name(problem), contact_part(problem));
                    return Err(Box::new(ContactDataError::Corner { problem, part, at, edge: [p, q], node, side, angle: off }));
                }
            }
        }
    }
    Ok(())
}

/// The contact normal and the gap at every contact node, as the discrete problem reads them
/// (on a curved edge the P2 midpoint is the chord's), against the chord's outward normal; at a
/// vertex, the more favourable of its contact edges.
fn check_nodes(
    mesh: &Mesh,
    nodes: &P2Nodes,
    dofs: &DofMap,
    problem: &dyn Problem,
    outward: &[Option<[f64; 2]>],
    chords: &Chords,
) -> Result<(), Box<ContactDataError>> {
    let cos_max = MAX_NORMAL_ANGLE_DEGREES.to_radians().cos();
    // per contact node, the most favourable of its contact edges: (n . n_out, edge)
    let mut best: Vec<Option<(f64, usize)>> = vec![None; dofs.contact.len()];
    for (b, three) in nodes.boundary_nodes.iter().enumerate() {
        let Some(o) = outward[b] else { continue };
        for &p in three {
            let Some(k) = dofs.contact_index[p] else { continue };
            let n = dofs.contact[k].normal;
            let dot = n[0] * o[0] + n[1] * o[1];
            if dot.is_finite() && best[k].is_none_or(|(d, _)| dot > d) {
                best[k] = Some((dot, b));
            }
        }
    }
    // per contact node, its contact edges (a vertex two bodies share has one in each)
    let mut edges: Vec<Vec<usize>> = vec![Vec::new(); dofs.contact.len()];
    for (b, three) in nodes.boundary_nodes.iter().enumerate().filter(|(b, _)| outward[*b].is_some()) {
        for k in three.iter().filter_map(|&p| dofs.contact_index[p]) {
            edges[k].push(b);
        }
    }
    for (k, c) in dofs.contact.iter().enumerate() {
        let at = nodes.coords[c.node];
        if let Some((dot, b)) = best[k]
            && dot < cos_max
        {
            let edge = mesh.boundary[b].v.map(|v| mesh.vertices[v]);
            let outward = outward[b].expect("a contact edge");
            let (problem, part) = (problem_name(problem), contact_part(problem));
            return Err(Box::new(ContactDataError::Normal { problem, part, at, edge, normal: c.normal, outward, dot }));
        }
        if let Some(room) = chords.overlapped(c.gap, at, c.normal, &edges[k]) {
            let (problem, part) = (problem_name(problem), contact_part(problem));
            return Err(Box::new(ContactDataError::gap(problem, part, at, c.gap, c.normal, room)));
        }
    }
    Ok(())
}

/// The contact normal and the gap at every point of the contact part's sampling
/// ([`boundary::sample`](super::consistent::boundary::sample), the point set on which the exact
/// solution's contact conditions are checked: the P2 nodes, the Gauss points and pieces no
/// longer than the body's size over [`CONTACT_DENSITY`](super::consistent::boundary::CONTACT_DENSITY)
/// along every contact edge), each against the body's outward normal there: a stretch of bad
/// data longer than that spacing is refused on every mesh, not only on meshes that put a node
/// in it. At a vertex, the more favourable of its contact edges' normals counts.
fn check_sampled(mesh: &Mesh, nodes: &P2Nodes, problem: &dyn Problem, chords: &Chords) -> Result<(), Box<ContactDataError>> {
    use super::consistent::boundary::sample;
    let cos_max = MAX_NORMAL_ANGLE_DEGREES.to_radians().cos();
    let points = sample(mesh, nodes, Some(Part::Contact));
    // per sampled point, n . n_out (NaN where the normal is not a number: the watch names it)
    let mut dots = Vec::with_capacity(points.len());
    let mut at_vertex: std::collections::HashMap<usize, f64> = std::collections::HashMap::new();
    for (p, _) in &points {
        let chi = problem.gap(p.at);
        let n = problem.contact_normal(p.at, p.normal);
        if let Some(room) = chords.overlapped(chi, p.at, n, &[p.edge]) {
            let (problem, part) = (problem_name(problem), contact_part(problem));
            return Err(Box::new(ContactDataError::gap(problem, part, p.at, chi, n, room)));
        }
        let dot = n[0] * p.normal[0] + n[1] * p.normal[1];
        dots.push((n, dot));
        if let Some(v) = vertex(mesh, p.edge, p.t)
            && dot.is_finite()
        {
            let best = at_vertex.entry(v).or_insert(dot);
            *best = best.max(dot);
        }
    }
    if let Some(bad) = problem.bad_datum() {
        return Err(Box::new(ContactDataError::Datum(bad)));
    }
    for ((p, _), &(normal, dot)) in points.iter().zip(&dots) {
        let dot = vertex(mesh, p.edge, p.t).and_then(|v| at_vertex.get(&v).copied()).unwrap_or(dot);
        if dot < cos_max {
            let edge = mesh.boundary[p.edge].v.map(|v| mesh.vertices[v]);
            let (problem, part) = (problem_name(problem), contact_part(problem));
            let outward = p.normal;
            return Err(Box::new(ContactDataError::Normal { problem, part, at: p.at, edge, normal, outward, dot }));
        }
    }
    Ok(())
}

impl ContactDataError {
    /// [`ContactDataError::Gap`] of the `room` a chord left (its held end kept where the
    /// Dirichlet data move it).
    fn gap(problem: String, part: String, at: [f64; 2], chi: f64, normal: [f64; 2], room: super::chord::Room) -> ContactDataError {
        let held = room.held.filter(|h| h.toward != 0.0).map(|h| (h.at, h.toward));
        ContactDataError::Gap { problem, part, at, chi, normal, chord: room.material, held }
    }
}

/// The part of the Gap message on a held end the Dirichlet data move (empty where none).
fn held_text(held: &Option<([f64; 2], f64)>, chord: f64) -> String {
    let Some((at, toward)) = *held else { return String::new() };
    let way = if toward > 0.0 { "towards" } else { "away from" };
    format!(
        ", up to its end at {} on the Dirichlet part, which the Dirichlet data move {} {way} the contact face: {} of room",
        point(at),
        shown(toward.abs()),
        shown(chord - toward)
    )
}

/// The mesh vertex at parameter `t` of boundary edge `edge`, if `t` is one of its ends.
fn vertex(mesh: &Mesh, edge: usize, t: f64) -> Option<usize> {
    let v = mesh.boundary[edge].v;
    if t == 0.0 {
        Some(v[0])
    } else if t == 1.0 {
        Some(v[1])
    } else {
        None
    }
}

/// The prescribed nodes of the closure of Gamma_C against the obstacle (see the module docs).
fn check_prescribed(
    mesh: &Mesh,
    nodes: &P2Nodes,
    dofs: &DofMap,
    problem: &dyn Problem,
    diameter: f64,
) -> Result<(), Box<ContactDataError>> {
    // (node, contact edge holding it): the normal is the problem's on that edge
    let on_closure: std::collections::BTreeSet<(usize, usize)> = nodes
        .boundary_nodes
        .iter()
        .enumerate()
        .filter(|(b, _)| mesh.boundary[*b].part == Part::Contact)
        .flat_map(|(b, three)| three.iter().map(move |&p| (p, b)))
        .filter(|&(p, _)| dofs.contact_index[p].is_none())
        .collect();
    if on_closure.is_empty() {
        return Ok(());
    }
    let values = dofs.prescribed(nodes, problem);
    let fixed = |p: usize, i: usize| dofs.dof[p][i] == crate::fem::assembly::FIXED;
    for (p, b) in on_closure {
        let x = nodes.coords[p];
        let n = problem.contact_normal(x, mesh.outward_at(b, x));
        let len = n[0].hypot(n[1]);
        let (chi, u) = (problem.gap(x), values[p]);
        if !(len > 0.0) || !chi.is_finite() {
            continue; // the data watch names it
        }
        let n = [n[0] / len, n[1] / len];
        let by = if nodes.part[p] == Some(Part::Dirichlet) {
            "the Dirichlet data (`dirichlet`)"
        } else {
            "a point constraint (`point_constraints`)"
        };
        // u . n is known where both components are prescribed, or the one n lies along; where n
        // has a part along a free component, u . n would be constrained by nothing (such a node
        // is not a contact node): refused
        let held = [fixed(p, 0), fixed(p, 1)];
        if held == [false, false] {
            continue;
        }
        if !super::chord::holds_along(held, n) {
            let fixed = if held[0] { 0 } else { 1 };
            let (problem, part) = (problem_name(problem), contact_part(problem));
            return Err(Box::new(ContactDataError::HalfPrescribed { problem, part, by: by.into(), at: x, fixed, normal: n }));
        }
        let un: f64 = (0..2).filter(|&i| held[i]).map(|i| u[i] * n[i]).sum();
        if un - chi > PRESCRIBED_PENETRATION * diameter {
            let (problem, part) = (problem_name(problem), contact_part(problem));
            let u = [0, 1].map(|i| if fixed(p, i) { u[i].to_string() } else { "free".to_string() });
            return Err(Box::new(ContactDataError::Prescribed { problem, part, by: by.into(), at: x, u, normal: n, un, chi }));
        }
    }
    Ok(())
}
