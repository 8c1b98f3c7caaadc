//! A body's thickness along the contact normal at a point of its boundary: the chord, the length
//! of the line p + t n inside the body that holds p, from p into the body (the piece holding p
//! and every piece beyond it on that side; holes between do not count). The gap bound of
//! [`plausible`](super::plausible) takes it (a gap chi(p) below minus the chord pushes the body
//! through itself along n at p). Neither the body's extent along n (by it, an L-shaped body's
//! 0.1-thick flange could be pushed 0.5 through its clamped top, certified, because the column
//! on its end makes the extent 5) nor the whole mesh's (a second body 5 above a thin plate)
//! bounds it.
//!
//! The body is bounded by its boundary edges, straight between the mesh's vertices (a point of a
//! curved edge lies off that chord by less than the edge's length). The line crosses them at
//! parameters that, sorted, enter and leave the body in turn; a vertex on the line counts on one
//! side of it, as for a line moved an infinitesimal step to that side, and both sides are tried
//! (the larger chord counts: a point at a corner takes the more favourable of its two sides, as
//! the normal check does). The sum stops at a piece whose far end lies on Gamma_D where the
//! displacement along n is prescribed: that end is held, so material beyond it is no room for
//! the face (without that stop, a C-shaped body's clamped 0.1 flange could be pushed 0.15
//! through its clamped top, certified, its upper arm across open air adding to the sum; a
//! block's 0.01 floor over a clamped hole likewise). A held end is where its Dirichlet data put it: data
//! that move it towards the face by `toward` leave the face that much less room, and data that
//! move it away leave more ([`Room::left`]: a 0.1 plate whose top is held at u_y = -0.05 has
//! room 0.05, so chi = -0.08, which would end its bottom face above its top, is refused, and one
//! held at +0.05 has room 0.15, so chi = -0.12 is accepted). So a gap that is not negative is checked too where the
//! Dirichlet data move a held end (`[0, -0.2]` on a 0.1 plate's top with chi = 0.01 turned the
//! plate inside out). The boundary edges are in an R*-tree ([`rstar`], as in
//! [`mesh::locate`](model::mesh::locate)), built at the first negative gap, so that a point
//! costs the edges near its line, not all of them: near linear at 1e7 unknowns.

use model::mesh::{Mesh, P2Nodes};
use model::problems::{Part, Problem};
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{AABB, RTree, RTreeObject, SelectionFunction};

type Boxed = GeomWithData<Rectangle<[f64; 2]>, usize>;

/// What the line from a point of the contact part meets going into its body: the body's
/// material along it (the chord) and, where the sum stopped at a held end, that end.
#[derive(Clone, Copy, Debug)]
pub(super) struct Room {
    pub material: f64,
    pub held: Option<HeldEnd>,
}

/// The end of a chord on Gamma_D ([`Room`]): where, and how far the Dirichlet data move it
/// towards the contact face along the line (negative: away from it).
#[derive(Clone, Copy, Debug)]
pub(super) struct HeldEnd {
    pub at: [f64; 2],
    pub toward: f64,
}

impl Room {
    /// The room the face has along the line before the body passes through itself: the
    /// material, less what the Dirichlet data move a held end towards the face.
    pub(super) fn left(&self) -> f64 {
        self.material - self.held.map_or(0.0, |h| h.toward)
    }
}

/// Every body's chords through points of its boundary ([`Chords::overlapped`]).
pub(super) struct Chords<'a> {
    /// Per boundary edge of the mesh, its two vertices.
    ends: Vec<[[f64; 2]; 2]>,
    /// Per boundary edge of the mesh, its body (the split `certify::bodies` makes).
    body_of_edge: Vec<usize>,
    /// Per boundary edge of the mesh, whether it lies on Gamma_D.
    on_dirichlet: Vec<bool>,
    /// The displacement components Gamma_D prescribes (`Problem::dirichlet_components`).
    prescribed: [bool; 2],
    /// The problem, whose Dirichlet data place a held end.
    problem: &'a dyn Problem,
    /// Whether the Dirichlet data are nonzero at some node of Gamma_D (then a gap that is not
    /// negative can be too small as well: a held end moved towards the face).
    moving: bool,
    /// The boundary edges' bounding boxes, built when a gap is first negative (most problems
    /// have none, and a chord is never needed where the gap is not).
    tree: std::cell::OnceCell<RTree<Boxed>>,
}

impl<'a> Chords<'a> {
    pub(super) fn of(mesh: &Mesh, nodes: &P2Nodes, problem: &'a dyn Problem) -> Chords<'a> {
        let prescribed = problem.dirichlet_components();
        let body = super::certify::bodies(nodes);
        let mut body_of_edge = vec![0; mesh.boundary.len()];
        for (t, local) in nodes.element_boundary.iter().enumerate() {
            for &b in local.iter().flatten() {
                body_of_edge[b] = body[t];
            }
        }
        let ends = mesh.boundary.iter().map(|e| e.v.map(|v| mesh.vertices[v])).collect();
        let on_dirichlet = mesh.boundary.iter().map(|e| e.part == Part::Dirichlet).collect();
        let moving = (0..nodes.coords.len()).filter(|&p| nodes.part[p] == Some(Part::Dirichlet)).any(|p| {
            let u = problem.dirichlet(nodes.coords[p]);
            (0..2).any(|i| prescribed[i] && u[i] != 0.0)
        });
        Chords { ends, body_of_edge, on_dirichlet, prescribed, problem, moving, tree: std::cell::OnceCell::new() }
    }

    /// The room where the gap `chi` at `p` is below minus what it leaves ([`Room::left`]), for a
    /// point on the boundary `edges` (at a vertex two bodies share, the larger room counts);
    /// None otherwise, where `chi` is not a number, where it is not negative and the Dirichlet
    /// data move nothing, and where `n` is zero or not a number (the data watch names those).
    pub(super) fn overlapped(&self, chi: f64, p: [f64; 2], n: [f64; 2], edges: &[usize]) -> Option<Room> {
        if !(chi < 0.0 || (chi.is_finite() && self.moving)) {
            return None;
        }
        let room = edges.iter().filter_map(|&e| self.through(p, n, e)).max_by(|a, b| a.left().total_cmp(&b.left()))?;
        (room.left().is_finite() && chi < -room.left()).then_some(room)
    }

    /// The chord through `p` along `n` (normalised here) of the body holding boundary edge
    /// `edge`, `p` on that edge (or on the curve it is the chord of). None where the line does
    /// not cross the body's boundary within the edge's length of `p`: `n` along the edge, whose
    /// normal check refuses it.
    fn through(&self, p: [f64; 2], n: [f64; 2], edge: usize) -> Option<Room> {
        let len = n[0].hypot(n[1]);
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        let line = Line { p, d: [n[0] / len, n[1] / len] };
        let tree = self.tree.get_or_init(|| self.boxes());
        let body = self.body_of_edge[edge];
        let held = self.holds_along(line.d);
        let near: Vec<Edge> = tree
            .locate_with_selection_function(line)
            .map(|g| g.data)
            .filter(|&e| self.body_of_edge[e] == body)
            .map(|e| Edge { ends: self.ends[e], held: held && self.on_dirichlet[e] })
            .collect();
        let [a, b] = self.ends[edge];
        let reach = (b[0] - a[0]).hypot(b[1] - a[1]);
        let room = |(material, end): Sum| Room {
            material,
            held: end.map(|(at, inward)| {
                // the data's displacement of the end along the line, towards the face: -u . m,
                // m the direction into the body (the components held along the line only)
                let u = self.problem.dirichlet(at);
                let along: f64 = (0..2).filter(|&i| self.prescribed[i]).map(|i| u[i] * inward[i]).sum();
                HeldEnd { at, toward: -along }
            }),
        };
        [false, true]
            .into_iter()
            .filter_map(|strict| line.chord(&near, strict, reach).map(room))
            .max_by(|a, b| a.left().total_cmp(&b.left()))
    }

    /// Whether Gamma_D holds the displacement along the unit vector `d` ([`holds_along`]).
    fn holds_along(&self, d: [f64; 2]) -> bool {
        holds_along(self.prescribed, d)
    }

    fn boxes(&self) -> RTree<Boxed> {
        let boxes = self.ends.iter().enumerate().map(|(e, &[a, b])| {
            let lo = [a[0].min(b[0]), a[1].min(b[1])];
            let hi = [a[0].max(b[0]), a[1].max(b[1])];
            GeomWithData::new(Rectangle::from_corners(lo, hi), e)
        });
        RTree::bulk_load(boxes.collect())
    }
}

/// Whether prescribing the components `fixed` holds the displacement along the unit vector
/// `d`: both components prescribed, or the one prescribed component along `d` (a roller whose
/// free direction has a part along `d` lets the point move that way). The one rule for a
/// chord's held end and for a prescribed node of the contact part's closure.
pub(super) fn holds_along(fixed: [bool; 2], d: [f64; 2]) -> bool {
    match fixed {
        [true, true] => true,
        [true, false] => d[1].abs() < 1e-12,
        [false, true] => d[0].abs() < 1e-12,
        [false, false] => false,
    }
}

/// A boundary edge as the chord sees it: its two vertices, and whether it lies on Gamma_D holding
/// the displacement along the line ([`Chords::holds_along`]).
#[derive(Clone, Copy)]
struct Edge {
    ends: [[f64; 2]; 2],
    held: bool,
}

/// A chord's material and, where it stopped at a held end, that end's point and the direction
/// into the body ([`Line::chord`]).
type Sum = (f64, Option<([f64; 2], [f64; 2])>);

/// The line through `p` along the unit vector `d`.
#[derive(Clone, Copy)]
struct Line {
    p: [f64; 2],
    d: [f64; 2],
}

impl Line {
    /// The signed distance of `v` from the line.
    fn across(&self, v: [f64; 2]) -> f64 {
        self.d[0] * (v[1] - self.p[1]) - self.d[1] * (v[0] - self.p[0])
    }

    /// The parameter of `v`'s projection on the line (0 at `p`).
    fn along(&self, v: [f64; 2]) -> f64 {
        self.d[0] * (v[0] - self.p[0]) + self.d[1] * (v[1] - self.p[1])
    }

    /// The chord through `p`: the parameters where the line crosses the `edges` (a closed
    /// boundary), sorted, enter and leave the body in turn; the crossing nearest `p` (within
    /// `reach`) ends the piece holding `p`, and the chord is that piece and every piece beyond
    /// it on the same side of `p`: all the body's material the line meets going into the body
    /// from `p`. Only the material counts, not the holes between: a hole behind the contact face
    /// is room the face may move into (a 0.01 ligament under a 0.85 tall hole is not refused at
    /// a gap of -0.02, as the first piece alone would have it), and the body is pushed through
    /// itself only where the gap exceeds all of it. A vertex on the line counts on the side
    /// `strict` says (false: with the vertices at positive distance), so each vertex is on one
    /// side and the crossings come in pairs. The sum ends with the first piece whose far end
    /// is on a held edge: material beyond a held end is no room for the face. Returns the sum
    /// and, where it stopped at a held end, that end and the direction into the body (the
    /// larger sum of the two crossings at a vertex on the line).
    fn chord(&self, edges: &[Edge], strict: bool, reach: f64) -> Option<Sum> {
        let side = |c: f64| if strict { c > 0.0 } else { c >= 0.0 };
        // (parameter, held) of each crossing
        let mut s: Vec<(f64, bool)> = edges
            .iter()
            .filter_map(|&Edge { ends: [a, b], held }| {
                let (ca, cb) = (self.across(a), self.across(b));
                (side(ca) != side(cb)).then(|| {
                    let (sa, sb) = (self.along(a), self.along(b));
                    (sa + (sb - sa) * ca / (ca - cb), held)
                })
            })
            .collect();
        s.sort_by(|x, y| x.0.total_cmp(&y.0));
        let nearest = s.iter().map(|x| x.0.abs()).fold(f64::INFINITY, f64::min);
        if !s.len().is_multiple_of(2) || nearest > reach {
            return None;
        }
        // from each crossing at p (two at a vertex the line touches), the pieces inside the body
        // on its side, nearest first, up to the first whose far end is held: [s[j], s[j + 1]]
        // for even j from an entry (far end s[j + 1]), [s[j - 1], s[j]] for odd j down from an
        // exit (far end s[j - 1])
        // (length, far end's parameter, far end held) of each piece, nearest first
        let upto_held = |pieces: &mut dyn Iterator<Item = (f64, f64, bool)>, inward: [f64; 2]| {
            let mut sum = 0.0;
            for (length, far, far_held) in pieces {
                sum += length;
                if far_held {
                    return (sum, Some(([self.p[0] + far * self.d[0], self.p[1] + far * self.d[1]], inward)));
                }
            }
            (sum, None)
        };
        let inside = |i: usize| {
            if i.is_multiple_of(2) {
                upto_held(&mut s[i..].chunks_exact(2).map(|w| (w[1].0 - w[0].0, w[1].0, w[1].1)), self.d)
            } else {
                upto_held(&mut s[..=i].chunks_exact(2).rev().map(|w| (w[1].0 - w[0].0, w[0].0, w[0].1)), [-self.d[0], -self.d[1]])
            }
        };
        let at_p = s.iter().enumerate().filter(|(_, x)| x.0.abs() == nearest);
        at_p.map(|(i, _)| inside(i)).max_by(|a, b| a.0.total_cmp(&b.0))
    }
}

/// The boxes the line meets: a box with its four corners strictly on one side (beyond a
/// round-off margin of the coordinates) holds no edge that crosses it.
impl SelectionFunction<Boxed> for Line {
    fn should_unpack_parent(&self, envelope: &AABB<[f64; 2]>) -> bool {
        let (lo, hi) = (envelope.lower(), envelope.upper());
        let corners = [lo, hi, [lo[0], hi[1]], [hi[0], lo[1]]];
        let scale = corners.iter().chain([&self.p]).fold(0.0f64, |m, c| m.max(c[0].abs()).max(c[1].abs()));
        let margin = 1e-12 * scale;
        let c = corners.map(|v| self.across(v));
        !(c.iter().all(|&c| c > margin) || c.iter().all(|&c| c < -margin))
    }

    fn should_unpack_leaf(&self, leaf: &Boxed) -> bool {
        self.should_unpack_parent(&leaf.envelope())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An L: a flange [0, 10] x [0, 0.1] and a column [0, 0.5] x [0.1, 5], as one closed
    /// boundary of straight edges (the flange's bottom split at x = 5).
    fn l_shape() -> Vec<Edge> {
        let v = [[0.0, 0.0], [5.0, 0.0], [10.0, 0.0], [10.0, 0.1], [0.5, 0.1], [0.5, 5.0], [0.0, 5.0]];
        (0..v.len()).map(|i| Edge { ends: [v[i], v[(i + 1) % v.len()]], held: false }).collect()
    }

    #[test]
    fn the_chord_is_the_piece_of_the_line_holding_the_point() {
        let l = l_shape();
        let down = |p| Line { p, d: [0.0, -1.0] };
        let chord = |p, strict| down(p).chord(&l, strict, 1.0).map(|c| c.0);
        // the flange: 0.1 thick, whatever the column
        assert_eq!(chord([3.0, 0.0], false), Some(0.1));
        assert_eq!(chord([3.0, 0.0], true), Some(0.1));
        // through the column: 5
        assert_eq!(chord([0.25, 0.0], false), Some(5.0));
        // at the vertex (5, 0) between two bottom edges, and at the corner (10, 0) whose line
        // runs along the flange's end: the side that keeps the body gives 0.1
        assert_eq!(chord([5.0, 0.0], false).into_iter().chain(chord([5.0, 0.0], true)).reduce(f64::max), Some(0.1));
        assert_eq!(chord([10.0, 0.0], false).into_iter().chain(chord([10.0, 0.0], true)).reduce(f64::max), Some(0.1));
        // a point off the boundary by more than the reach has no chord
        assert_eq!(down([3.0, -2.0]).chord(&l, false, 1.0), None);
    }

    /// A unit block with a hole [3/8, 5/8] x [0.01, 0.86] behind its bottom face: the line up
    /// from the face meets 0.01 of material, the hole, then 0.14: the chord is 0.15, while the
    /// line from a point beside the hole meets the whole height.
    #[test]
    fn the_chord_counts_the_material_beyond_a_hole_and_not_the_hole() {
        let block = |hole_held: bool| -> Vec<Edge> {
            let square = |lo: [f64; 2], hi: [f64; 2], held: bool| {
                let v = [lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]];
                (0..4).map(move |i| Edge { ends: [v[i], v[(i + 1) % 4]], held })
            };
            square([0.0, 0.0], [1.0, 1.0], false).chain(square([0.375, 0.01], [0.625, 0.86], hole_held)).collect()
        };
        let free = block(false);
        let up = |x: f64| Line { p: [x, 0.0], d: [0.0, -1.0] }.chord(&free, false, 1.0).unwrap().0;
        assert!((up(0.5) - 0.15).abs() < 1e-12, "{}", up(0.5));
        assert!((up(0.2) - 1.0).abs() < 1e-12, "{}", up(0.2));
        // from the top, going down the same way
        let down = Line { p: [0.5, 1.0], d: [0.0, 1.0] }.chord(&free, false, 1.0).unwrap().0;
        assert!((down - 0.15).abs() < 1e-12, "{down}");
        // a clamped hole holds the ligament's far end: the chord is the ligament, going up and
        // going down
        let clamped = block(true);
        // and the held end is named, with the direction into the body
        let (up, end) = Line { p: [0.5, 0.0], d: [0.0, -1.0] }.chord(&clamped, false, 1.0).unwrap();
        assert!((up - 0.01).abs() < 1e-12, "{up}");
        let (at, inward) = end.expect("a held end");
        assert!((at[0] - 0.5).abs() < 1e-12 && (at[1] - 0.01).abs() < 1e-12 && inward == [0.0, 1.0], "{at:?} {inward:?}");
        let (down, end) = Line { p: [0.5, 1.0], d: [0.0, 1.0] }.chord(&clamped, false, 1.0).unwrap();
        assert!((down - 0.14).abs() < 1e-12, "{down}");
        assert_eq!(end.map(|e| e.1), Some([-0.0, -1.0]));
    }
}
