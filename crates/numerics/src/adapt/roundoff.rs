//! What a solve's numbers can resolve ([`resolution`]): the one decision, for `solve`, every
//! level of `adapt` and every study run, of whether a solve's estimate measures the
//! discretisation error, is round-off of an exact discrete solution, or comes from a u_h, a set
//! of contact forces or an element geometry that round-off has eaten into.

use crate::contact::solve::DiscreteSolution;
use crate::estimator::estimate::Estimate;
use model::base::number::shown;
use model::mesh::Mesh;
use model::mesh::precision::ShapeRoundoff;
use model::problems::{Material, Problem};

/// The estimate is at round-off when eta_h is at most this many times what u_h's round-off can do
/// to it ([`Body::estimate_roundoff`]): the smaller of two scales of the stress an error of u_h
/// at its round-off carries (the estimator's terms are stresses times lengths). The first is
/// (2 mu + |zeta|) delta, delta the round-off u_h carries: the larger of its measured round-off
/// floor ([`DiscreteSolution::roundoff`], one step of iterative refinement, `roundoff_floor` in
/// the level records) and f64::EPSILON max |u_h| (the representation of its values). The second
/// is the largest stress the round-off's energy allows: |sigma(e)|^2 <= 2 max(mu, mu + zeta)
/// times e's energy density, so sqrt(2 max(mu, mu + zeta) a(c, c)) for the refinement step c
/// ([`DiscreteSolution::roundoff_energy_at`]), an inverse estimate turning the L2 bound into
/// one on the estimator's h-weighted maxima; it is at least (2 mu + |zeta|) f64::EPSILON max
/// |u_h|, the representation's share, which has no energy measured. The two agree within a
/// factor 2.3 on compressible materials (lambda/mu up to 1.5, the examples and the patch test); on a nearly incompressible one the round-off grows
/// with lambda/mu along displacements of almost no divergence, whose stress is mu's, not
/// lambda's, and only the second sees it (Example 7.2 with mu = 1, lambda = 1e8: delta 3e-8 to
/// 3e-7, `structured:4` to `:64`, and a real estimate of 25 to 33, within 1e3 (2 mu + lambda)
/// delta but 1.6e3 to 6.2e4 times the second scale). Exact discrete solutions give at most 59
/// times the smaller scale (a rigid translation 6 to 24 of the first; the patch test and linear
/// fields with lambda/mu from 1 to 1e8, `structured:4` to `:64`, 0.03 to 59), real estimates
/// 1e15 and more on well-conditioned data; the deepest stored levels, with estimates down to
/// 2.2e-5 of (2 mu + |zeta|) max |u_h| and floors near 1e-12 of it, 1e7 and more. The scale is
/// the round-off, not the displacement: a rigid motion of the body moves max |u_h| but not the
/// deformation the estimate measures (Example 7.2 translated by 5e10 has an accurate estimate of
/// 8e2, 2.3e4 times its round-off scale, which a scale of max |u_h| would stop at level 0 as
/// "exact").
/// Asked only of a u_h that resolves its deformation ([`resolution`]).
pub const ROUNDOFF_ESTIMATE: f64 = 1e3;

/// The largest share of the deformation's size the round-off of u_h may reach
/// ([`resolution`]): beyond it u_h keeps fewer than 2 digits of the deformation, and the contact
/// set and the estimate are the round-off's (Example 7.2 translated rigidly by 1e12 loses an
/// active node and eta_7, by 1e16 every active node, all certified). Not 1e-3:
/// Example 7.2 translated by 5e10 keeps its estimate to 1e-2 with a measured round-off of 2.6e-3
/// to 4.9e-3 of the deformation (`structured:8`, and level 1 from `structured:4`), and
/// `tests/it/resolution.rs` holds it accepted; the stored studies stay below 1e-9 of it.
pub const RESOLVED_DEFORMATION: f64 = 1e-2;

/// u_h has no deformation above its round-off when the deformation's size ([`deformation`]) is
/// at most this many times its round-off: an exact rigid translation (by 0.1 to 1e10,
/// `structured:4` to `structured:128`) measures 0.25 to 5.7 times; Example 7.2 translated by
/// 1e11 (`structured:16`) 33 times, by 3e11 10 times, by 1e13 to 1e17 1.3 to 2.7 times (its
/// deformation then is round-off too). Between this and 1 / [`RESOLVED_DEFORMATION`] u_h has a
/// deformation but too few digits of it: refused.
pub const NO_DEFORMATION: f64 = 30.0;

/// The largest round-off of u_h, relative to its body's size (the spread of its coordinates),
/// at which a body whose u_h is at its round-off (no deformation above [`NO_DEFORMATION`] times
/// it, or an estimate within [`ROUNDOFF_ESTIMATE`] of it) is called exact to round-off; beyond
/// it that body is refused ([`Unresolved::AtRoundoff`]). u_h alone cannot tell an exact rigid
/// translation from a deformation drowned in the round-off of a large one (Example 7.2
/// translated by 1e13 to 1e17 measures as an exact translation does, its
/// deformation 1.5 to 30 times its round-off, its estimate 6 to 50 times (2 mu + |zeta|)
/// delta), and the data cannot either once they are rounded (at 1e16 the gap and the
/// Dirichlet data are all 1e16). What tells them apart is the round-off against the body: a
/// deformation of more than 1e-6 of the body's size keeps its 2 digits until the round-off
/// passes this bound, so from there on every larger translation is refused as this one is
/// (the decision is monotone in a translation for every deformation above 1e-6 of the size;
/// below 3e-7 of it a window of u_h at round-off stays between the refusal of 30 < deformation
/// / delta < 100 and this bound). The exact cases kept: rigid translations by up to 1e3 on a
/// unit square, `structured:4` to `structured:64` (delta 7e-12 to 3e-9 of the size; by 1e5
/// `structured:16` and `:64` are refused, `structured:4` up to 1e6 kept), fields the
/// P2 space reproduces (near 1e-15); the stored studies' levels are resolved, far from it.
pub const EXACT_ROUNDOFF: f64 = 1e-8;

/// u_h's round-off is blamed on a rigid translation in the data (subtract it) when max |u_h|
/// exceeds this many times the deformation: subtracting the translation shrinks u_h, and the
/// round-off with it, by up to that factor. Below it no translation large enough to matter is
/// there to subtract, and the round-off comes from the conditioning of the stiffness matrix
/// ([`Unresolved::Conditioned`]: a nearly incompressible material, lambda/mu = 1e10 in Example
/// 7.2, has max |u_h| 0.2 against a deformation of 0.3).
pub const TRANSLATED: f64 = 10.0;

/// What makes u_h's round-off large, for a message's advice.
#[derive(Clone, Copy, Debug)]
pub enum Cause {
    /// A rigid translation in the data: max |u_h| above [`TRANSLATED`] times the deformation.
    Translation,
    /// The conditioning of the stiffness matrix, which grows with the material's lambda/mu.
    Conditioning { lame_ratio: f64 },
}

impl Cause {
    fn of(u_max: f64, deformation: f64, m: Material) -> Cause {
        if u_max > TRANSLATED * deformation { Cause::Translation } else { Cause::Conditioning { lame_ratio: m.zeta / m.mu } }
    }
}

/// The largest round-off bound of a contact force (`lambda_floor`, over the contact nodes) that
/// is accepted, relative to the largest contact force at an active node ([`force_roundoff`];
/// beyond it [`Unresolved::Forces`]). A rigid translation c of the data makes the bounds grow
/// like c and leaves the forces: on Example 7.2 the share is about 6e-12 c /
/// deformation on `structured:16`, and eta_7 fell from 5.120e-3 to 1.9e-6 at c = 1e10 (a share
/// of 5.8e-2, two active forces under their bounds), was 1.2% off at 3e9 (1.9e-2) and 0.4% at
/// 1e9 (6.4e-3); on `structured:4` and `:8` it held to shares of 0.1 and 0.17. The finer the
/// mesh, the smaller its forces at the edge of the contact zone against the largest, so an
/// active force under its own bound is refused from [`WARNED_FORCES`] on (`structured:32`: one
/// at 1e8, a share of 1.7e-3; eta_7 5% off at 1e9). Every stored level stays below 1.6e-9
/// (hertz; fb's deep uniform levels 1.5e-9), its active forces above 1.5e6 times their bounds.
pub const RESOLVED_FORCES: f64 = 1e-2;

/// Above this share (and up to [`RESOLVED_FORCES`]) the contact forces keep fewer than 6 digits
/// of the largest: a warning ([`Caveat::Forces`]), and an active force under its own bound is
/// refused. 600 times the stored levels' largest share.
pub const WARNED_FORCES: f64 = 1e-6;

/// Above this relative round-off of the element shapes (and up to
/// [`model::mesh::precision::SHAPE_ROUNDOFF_REFUSED`], which the mesh check refuses) a warning
/// ([`Caveat::Shape`]). Example 7.2 on an 8x8 grid of the unit square translated by t (mesh and
/// data; delta = 2.5e-16 t): eta_6 (the most sensitive term) moved by 1e-4 at 1e9 (2.5e-6), 3e-3
/// at 1e11 (2.5e-4), 1% at 3e11, 4% at 1e12 (2.5e-3), 35% at 1e13; eta_1 to eta_5 by less than
/// 0.3% to 1e13. The stored studies' deepest levels (h_min 2.1e-8, coordinates up to 1) are
/// near 1.5e-8.
pub const WARNED_SHAPE: f64 = 1e-5;

fn u_max(sol: &DiscreteSolution) -> f64 {
    sol.u.iter().fold(0.0f64, |a, v| a.max(v[0].abs()).max(v[1].abs()))
}

/// The largest over the two components of max - min of `points`.
fn spread<'a>(points: impl Iterator<Item = &'a [f64; 2]>) -> f64 {
    let (lo, hi) = points.fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), p| {
        ([lo[0].min(p[0]), lo[1].min(p[1])], [hi[0].max(p[0]), hi[1].max(p[1])])
    });
    (hi[0] - lo[0]).max(hi[1] - lo[1]).max(0.0)
}

/// The deformation's size: the spread of u_h over the P2 nodes, the largest over the two
/// components of max - min. A rigid translation does not move it; it bounds the deformation's
/// part of u_h from above (a rotation adds to it), so a refusal by it is never too eager.
pub fn deformation(sol: &DiscreteSolution) -> f64 {
    spread(sol.u.iter())
}

/// One edge-connected body of the mesh ([`crate::contact::certify::bodies`], the split the
/// rigid-motion check and the gap bound take) and what its u_h resolves: round-off, deformation
/// and estimate are each body's own, so that one body's rigid motion neither sets another's
/// round-off nor hides in its deformation (taken over the whole mesh, a second body translated
/// by 1e11 would make Example 7.2's genuine estimate "at round-off"; by 1e14 its round-off terms
/// would make the estimate 8.5 times larger, and the deformation, spread over both, hide it).
struct Body {
    /// Where it is, for a message: a vertex of its first triangle, and how many bodies there are.
    point: [f64; 2],
    index: usize,
    count: usize,
    /// The round-off of its u_h (see [`ROUNDOFF_ESTIMATE`]): the larger of its nodes' measured
    /// floor ([`DiscreteSolution::roundoff_at`]) and f64::EPSILON max |u_h| over them, invariant
    /// under rigid motions up to the representation of u_h's values.
    roundoff: f64,
    /// Its deformation's size ([`deformation`] over its nodes).
    deformation: f64,
    /// The energy a(c, c) of u_h's refinement step c over its nodes
    /// ([`DiscreteSolution::roundoff_energy_at`]).
    energy: f64,
    /// The spread of its coordinates ([`EXACT_ROUNDOFF`]).
    size: f64,
    u_max: f64,
    /// eta_h scaled by its share of the largest element indicator: eta_h itself for the body
    /// that holds it (the whole mesh when it is one body).
    estimate: f64,
}

/// Per body (`of`: the body of each triangle), the energy a(c, c) of u_h's refinement step c:
/// the sum of [`DiscreteSolution::roundoff_energy_at`] over its nodes, each counted once.
fn energies(sol: &DiscreteSolution, of: &[usize], count: usize) -> Vec<f64> {
    let mut counted = vec![false; sol.u.len()];
    let mut energy = vec![0.0f64; count];
    for (t, &b) in of.iter().enumerate() {
        for &p in &sol.nodes.elements[t] {
            if !std::mem::replace(&mut counted[p], true) {
                energy[b] += sol.roundoff_energy_at[p];
            }
        }
    }
    energy
}

impl Body {
    fn all(sol: &DiscreteSolution, est: &Estimate) -> Vec<Body> {
        let of = crate::contact::certify::bodies(&sol.nodes);
        let count = of.iter().map(|b| b + 1).max().unwrap_or(0);
        let mut nodes: Vec<Vec<usize>> = vec![Vec::new(); count];
        let mut first = vec![usize::MAX; count];
        let mut largest = vec![0.0f64; count];
        for (t, &b) in of.iter().enumerate() {
            nodes[b].extend(sol.nodes.elements[t]);
            first[b] = first[b].min(t);
            largest[b] = largest[b].max(est.element.get(t).copied().unwrap_or(0.0));
        }
        let top = largest.iter().fold(0.0f64, |a, v| a.max(*v));
        let energy = energies(sol, &of, count);
        (0..count)
            .map(|b| {
                let at = &nodes[b];
                let u_max = at.iter().fold(0.0f64, |a, &p| a.max(sol.u[p][0].abs()).max(sol.u[p][1].abs()));
                let floor = at.iter().fold(0.0f64, |a, &p| a.max(sol.roundoff_at[p]));
                Body {
                    point: sol.nodes.coords[sol.nodes.elements[first[b]][0]],
                    index: b,
                    count,
                    roundoff: floor.max(f64::EPSILON * u_max),
                    deformation: spread(at.iter().map(|&p| &sol.u[p])),
                    energy: energy[b],
                    size: spread(at.iter().map(|&p| &sol.nodes.coords[p])),
                    u_max,
                    estimate: if top > 0.0 { est.terms.eta_h * largest[b] / top } else { est.terms.eta_h },
                }
            })
            .collect()
    }

    /// What u_h's round-off can do to the estimate ([`ROUNDOFF_ESTIMATE`]): the smaller of
    /// (2 mu + |zeta|) delta and the largest stress the round-off's energy allows, the latter at
    /// least (2 mu + |zeta|) f64::EPSILON max |u_h| (the representation of u_h's values).
    fn estimate_roundoff(&self, m: Material) -> f64 {
        let modulus = 2.0 * m.mu + m.zeta.abs();
        let by_energy = (2.0 * m.mu.max(m.mu + m.zeta) * self.energy.max(0.0)).sqrt();
        (modulus * self.roundoff).min(by_energy.max(modulus * f64::EPSILON * self.u_max))
    }

    fn cause(&self, m: Material) -> Cause {
        Cause::of(self.u_max, self.deformation, m)
    }

    /// ", of body k of the n separate bodies (one point at (x, y))", or nothing for one body.
    fn named(&self) -> String {
        if self.count <= 1 {
            return String::new();
        }
        format!(
            " of body {} of the {} separate bodies of the mesh (one point at ({:.4}, {:.4}))",
            self.index + 1,
            self.count,
            self.point[0],
            self.point[1]
        )
    }

    /// What this body's u_h resolves: `Ok(false)` resolved, `Ok(true)` at round-off, or the
    /// refusal. A u_h at its round-off is exact only while that round-off is below
    /// [`EXACT_ROUNDOFF`] of the body's size; past it the same finding is a refusal, so a
    /// larger translation is never treated more mildly than a smaller one.
    fn verdict(&self, problem: &dyn Problem) -> Result<bool, Unresolved> {
        let (delta, deformation, m) = (self.roundoff, self.deformation, problem.material());
        let none = deformation <= NO_DEFORMATION * delta;
        if !none && delta > RESOLVED_DEFORMATION * deformation {
            return Err(match self.cause(m) {
                Cause::Translation => Unresolved::Displacement { roundoff: delta, deformation, u_max: self.u_max, body: self.named() },
                Cause::Conditioning { lame_ratio } => self.conditioned(lame_ratio, Drowned::Deformation),
            });
        }
        let scale = self.estimate_roundoff(m);
        // the estimate is at round-off: its indicators are noise, the maximum strategy marks nothing
        let at_roundoff = none || self.estimate <= ROUNDOFF_ESTIMATE * scale;
        if at_roundoff && delta > EXACT_ROUNDOFF * self.size {
            return Err(match self.cause(m) {
                Cause::Translation => Unresolved::AtRoundoff { roundoff: delta, size: self.size, u_max: self.u_max, body: self.named() },
                Cause::Conditioning { lame_ratio } if none => self.conditioned(lame_ratio, Drowned::NoDeformation),
                Cause::Conditioning { lame_ratio } => self.conditioned(lame_ratio, Drowned::Estimate { estimate: self.estimate, scale }),
            });
        }
        Ok(at_roundoff)
    }

    /// The refusal of a u_h whose round-off no rigid translation explains ([`TRANSLATED`]).
    fn conditioned(&self, lame_ratio: f64, drowned: Drowned) -> Unresolved {
        Unresolved::Conditioned(Conditioned {
            drowned,
            roundoff: self.roundoff,
            deformation: self.deformation,
            size: self.size,
            u_max: self.u_max,
            lame_ratio,
            body: self.named(),
        })
    }
}

/// How well the contact forces are resolved: the largest round-off bound of a lambda_p
/// (`lambda_floor`, over every contact node) and the largest contact force, or None without a
/// positive force at an active node (nothing presses on the obstacle: no force to resolve).
/// The bound grows with a rigid translation of the data (its terms |F_p| + sum |K_T| |u_h| do),
/// the forces do not.
pub fn force_roundoff(sol: &DiscreteSolution) -> Option<(f64, f64)> {
    let largest = sol.lambda.iter().zip(&sol.active).filter(|(_, a)| **a).fold(0.0f64, |m, (l, _)| m.max(*l));
    let floor = sol.lambda_floor.iter().fold(0.0f64, |m, f| m.max(*f));
    (largest > 0.0).then_some((floor, largest))
}

/// The active contact nodes whose force is not above its own round-off bound (`lambda_floor`):
/// their place in Lambda_h^C is undecidable.
fn sunk(sol: &DiscreteSolution) -> usize {
    sol.lambda.iter().zip(&sol.lambda_floor).zip(&sol.active).filter(|((l, f), a)| **a && **l <= **f).count()
}

/// A solution whose round-off reaches what it is meant to resolve.
#[derive(Debug, thiserror::Error)]
pub enum Unresolved {
    #[error(
        "u_h does not resolve the deformation{body}: its round-off {} is {:.1e} of the deformation's size {} (the spread of u_h over the nodes, max - min of a component; at most {RESOLVED_DEFORMATION:e} is kept), with u_h up to {} in size: a displacement that large against its variation (a rigid translation in the data) leaves u_h too few digits of the deformation, so its contact set and estimate would be round-off's. Give the data without the rigid part (subtract the translation from the Dirichlet data and the gap)",
        shown(*.roundoff), .roundoff / .deformation, shown(*.deformation), shown(*.u_max)
    )]
    Displacement { roundoff: f64, deformation: f64, u_max: f64, body: String },
    #[error(
        "u_h does not resolve the deformation{body}: u_h is at its round-off there (no deformation above {NO_DEFORMATION} times it, or an estimate within {ROUNDOFF_ESTIMATE:e} times what it can do to the estimate), and that round-off, {}, is {:.1e} of the body's size {} (u_h is called exact to round-off only up to {EXACT_ROUNDOFF:e} of it), with u_h up to {} in size: an exact rigid motion and a deformation drowned in the round-off of a displacement that large (a rigid translation in the data) cannot be told apart, so its contact set and estimate would be round-off's. Give the data without the rigid part (subtract the translation from the Dirichlet data and the gap)",
        shown(*.roundoff), .roundoff / .size, shown(*.size), shown(*.u_max)
    )]
    AtRoundoff { roundoff: f64, size: f64, u_max: f64, body: String },
    #[error(
        "the contact forces are not resolved: their round-off bound reaches {} against a largest contact force of {} ({:.1e} of it; at most {RESOLVED_FORCES:e} is kept){}, so which nodes carry a positive force (Lambda_h^C) and eta_7 would be round-off's; u_h is up to {} in size{}",
        shown(*.floor), shown(*.largest), .floor / .largest,
        if *.sunk > 0 { format!(", and {} active node{} carr{} a force under {} own bound", .sunk, if *.sunk == 1 { "" } else { "s" }, if *.sunk == 1 { "ies" } else { "y" }, if *.sunk == 1 { "its" } else { "their" }) } else { String::new() },
        shown(*.u_max),
        match .cause {
            Cause::Translation => ": a displacement that large against the deformation (a rigid translation in the data) makes the forces' round-off large. Give the data without the rigid part (subtract the translation from the Dirichlet data and the gap)".to_string(),
            Cause::Conditioning { lame_ratio } => format!(", no rigid translation against its deformation: the forces' round-off comes from {}", conditioning(*lame_ratio)),
        }
    )]
    Forces { floor: f64, largest: f64, sunk: usize, u_max: f64, cause: Cause },
    #[error("{0}")]
    Conditioned(Conditioned),
}

/// A u_h whose round-off reaches what it must resolve while no rigid translation explains that
/// round-off ([`TRANSLATED`]): the stiffness matrix's conditioning does, which subtracting a
/// translation would not change.
#[derive(Debug)]
pub struct Conditioned {
    pub drowned: Drowned,
    pub roundoff: f64,
    pub deformation: f64,
    /// The spread of the body's coordinates ([`EXACT_ROUNDOFF`]).
    pub size: f64,
    pub u_max: f64,
    pub lame_ratio: f64,
    /// ", of body k of the n separate bodies ...", or nothing for one body.
    pub body: String,
}

/// What u_h's round-off reaches ([`Conditioned`]).
#[derive(Debug)]
pub enum Drowned {
    /// More than [`RESOLVED_DEFORMATION`] of the deformation.
    Deformation,
    /// The deformation: none above [`NO_DEFORMATION`] times the round-off.
    NoDeformation,
    /// The estimate: within [`ROUNDOFF_ESTIMATE`] times `scale`, what the round-off can do to it.
    Estimate { estimate: f64, scale: f64 },
}

impl Conditioned {
    /// What the round-off reaches, with the numbers that say so.
    fn found(&self) -> String {
        let Conditioned { roundoff, deformation, size, body, .. } = self;
        let (delta, def) = (shown(*roundoff), shown(*deformation));
        let exact = format!(
            "{:.1e} of the body's size {} (u_h is called exact to round-off only up to {EXACT_ROUNDOFF:e} of it)",
            roundoff / size,
            shown(*size)
        );
        match self.drowned {
            Drowned::Deformation => format!(
                "u_h does not resolve the deformation{body}: its round-off {delta} is {:.1e} of the deformation's size {def} (the spread of u_h over the nodes, max - min of a component; at most {RESOLVED_DEFORMATION:e} is kept), so its contact set and estimate would be round-off's",
                roundoff / deformation
            ),
            Drowned::NoDeformation => {
                format!(
                    "u_h does not resolve the deformation{body}: it has no deformation above {NO_DEFORMATION} times its round-off {delta}, which is {exact}"
                )
            }
            Drowned::Estimate { estimate, scale } => format!(
                "the estimate cannot be told from round-off{body}: it is {}, within {ROUNDOFF_ESTIMATE:e} times {}, what u_h's round-off can do to it (the largest stress the round-off's energy allows), though u_h resolves its deformation {def} to {:.1e} (round-off {delta}); that round-off is {exact}, so an exact discrete solution and a discretisation error below the round-off's reach look alike",
                shown(estimate),
                shown(scale),
                roundoff / deformation
            ),
        }
    }
}

impl std::fmt::Display for Conditioned {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(
            f,
            "{}. No rigid translation explains that round-off: u_h is up to {} in size against a deformation of {} (a translation is blamed from {TRANSLATED} times the deformation on), so subtracting one would not help. The round-off comes from {}",
            self.found(),
            shown(self.u_max),
            shown(self.deformation),
            conditioning(self.lame_ratio)
        )
    }
}

/// From this lambda/mu on a material is called nearly incompressible in a message: Poisson's
/// ratio 0.495 and more in plane strain (lambda/mu = 2 nu / (1 - 2 nu)).
const NEARLY_INCOMPRESSIBLE: f64 = 100.0;

/// Where a round-off that no translation explains comes from, and what to do: "the
/// conditioning of the stiffness matrix, ...".
fn conditioning(lame_ratio: f64) -> String {
    let nearly = if lame_ratio.abs() >= NEARLY_INCOMPRESSIBLE { ", a nearly incompressible material" } else { "" };
    format!(
        "the conditioning of the stiffness matrix (lambda/mu = {lame_ratio:.1e}{nearly}; the conditioning grows with lambda/mu and with refinement): give a material further from incompressibility (a smaller lambda/mu, a Poisson's ratio further from 0.5) or a coarser mesh"
    )
}

/// What a resolved solve keeps fewer digits of than it should, or that its estimate is at
/// round-off: a warning, not a refusal (`solve`, every level of `adapt` and of a study's runs).
#[derive(Clone, Debug)]
pub enum Caveat {
    /// The solve is [`Resolution::AtRoundoff`]: its estimate's terms, and an efficiency index
    /// against an error at round-off too, measure round-off (a uniform loop does not go on
    /// through such levels without a word).
    AtRoundoff,
    /// The contact forces' round-off bound is above [`WARNED_FORCES`] of the largest force.
    Forces { floor: f64, largest: f64, cause: Cause },
    /// The element shapes' relative round-off is above [`WARNED_SHAPE`].
    Shape(ShapeRoundoff),
}

impl std::fmt::Display for Caveat {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            Caveat::AtRoundoff => f.write_str(
                "the estimate is at the round-off of u_h: u_h is exact to round-off (a rigid motion, or a field the P2 space reproduces), or a displacement far larger than its variation (a rigid translation in the data) left it no digits of the deformation; its terms measure round-off, not the discretisation error",
            ),
            Caveat::Forces { floor, largest, cause } => write!(
                f,
                "the contact forces keep fewer than 6 digits: their round-off bound reaches {} against a largest force of {} ({:.1e} of it), so a force near the edge of the contact zone may fall under it and leave Lambda_h^C and eta_7 ({})",
                shown(*floor),
                shown(*largest),
                floor / largest,
                match cause {
                    Cause::Translation => "a rigid translation in the data makes the bound grow; give the data without it".to_string(),
                    Cause::Conditioning { lame_ratio } => format!("no rigid translation in the data makes the bound grow, but {}", conditioning(*lame_ratio)),
                }
            ),
            Caveat::Shape(s) => write!(
                f,
                "the element shapes keep fewer than 5 digits: triangle {} lies at coordinates up to {} but is {} high (round-off {:.1e} of its size), so the estimate's terms may move; translate the mesh nearer the origin",
                s.triangle,
                shown(s.offset),
                shown(s.height),
                s.delta
            ),
        }
    }
}

/// What a solve's estimate measures ([`resolution`]).
#[derive(Debug)]
pub enum Resolution {
    /// The estimate measures the discretisation error, with what it keeps fewer digits of.
    Resolved(Vec<Caveat>),
    /// On every body u_h has no deformation above its round-off ([`NO_DEFORMATION`]: an exact
    /// rigid motion), or eta_h is at u_h's round-off ([`ROUNDOFF_ESTIMATE`]: an exact discrete
    /// solution), with that round-off below [`EXACT_ROUNDOFF`] of the body's size; the maximum
    /// strategy marks nothing.
    AtRoundoff,
    /// On some body u_h's round-off exceeds [`RESOLVED_DEFORMATION`] of its deformation, or u_h
    /// is at a round-off above [`EXACT_ROUNDOFF`] of the body's size, or the contact forces'
    /// round-off exceeds [`RESOLVED_FORCES`] of the largest force: nothing of the solve is to be
    /// reported or kept.
    Unresolved(Unresolved),
}

/// The one decision, for `solve`, every level of `adapt` and every study, of what a solve's
/// numbers resolve, taken body by body ([`Body`]). For each body the deformation comes first:
/// one whose round-off reaches 1e-2 of a deformation it does have is unresolved, whatever its
/// estimate; then whether it is at round-off (no deformation above 30 times its
/// round-off, or an estimate at it: an exact discrete solution), which is granted only while the
/// round-off is below [`EXACT_ROUNDOFF`] of the body's size and refused past it (asked before
/// the refusal, "no deformation" would take in every translation past the refused window: 1e11
/// refused, 2e11 to 1e17 answered with eta_7 = 0). The first body refused refuses
/// the solve, named when the mesh has several: its u_h or estimate would be round-off's, in the
/// estimate's maxima too. The solve is at round-off when every body is; a body at round-off
/// next to resolved ones adds indicators of at most its round-off, below 1e-8 of its size, and
/// the rest is measured (a second body translated rigidly by 0.1 leaves Example 7.2's verdict
/// alone; by 1e11 its round-off passes that bound and it is refused, named, as it would be
/// alone). Then, for a resolved solve, the contact forces ([`RESOLVED_FORCES`],
/// [`WARNED_FORCES`]) and the element shapes ([`WARNED_SHAPE`]; beyond
/// [`model::mesh::precision::SHAPE_ROUNDOFF_REFUSED`] the mesh check has refused the mesh). The
/// forces are not asked of a solve at round-off: an exact solution that touches the obstacle
/// without pressing on it has forces at their own round-off (u = 0.5 - 1e-9 x on
/// `structured:32`: 2e-11 against bounds of 1e-2 of it), and its eta_7 is declared round-off
/// with the rest; a translated u_h is refused by [`EXACT_ROUNDOFF`] before it could be called
/// at round-off, so its eta_7 is never a silent 0.
pub fn resolution(problem: &dyn Problem, mesh: &Mesh, sol: &DiscreteSolution, est: &Estimate) -> Resolution {
    let mut at_roundoff = true;
    for body in Body::all(sol, est) {
        match body.verdict(problem) {
            Err(error) => return Resolution::Unresolved(error),
            Ok(at) => at_roundoff &= at,
        }
    }
    if at_roundoff {
        return Resolution::AtRoundoff;
    }
    let mut caveats = Vec::new();
    if let Some((floor, largest)) = force_roundoff(sol)
        && floor > WARNED_FORCES * largest
    {
        let (sunk, u_max) = (sunk(sol), u_max(sol));
        let cause = Cause::of(u_max, deformation(sol), problem.material());
        if floor > RESOLVED_FORCES * largest || sunk > 0 {
            return Resolution::Unresolved(Unresolved::Forces { floor, largest, sunk, u_max, cause });
        }
        caveats.push(Caveat::Forces { floor, largest, cause });
    }
    let shape = mesh.shape_roundoff();
    if shape.delta > WARNED_SHAPE {
        caveats.push(Caveat::Shape(shape));
    }
    Resolution::Resolved(caveats)
}
