//! A point constraint must take no force. A displacement prescribed at a single point is no
//! constraint of the continuous problem in 2-D (a point has zero H^1 capacity): the force it
//! takes on a mesh tends to zero as h -> 0, so each mesh would solve another problem (u = (0.3,
//! 0) at the centre of Example 7.2 gives a different solution on every mesh and an estimate
//! that grows with refinement). Its one meaningful use is removing a rigid
//! motion (rollers: u_2 = 0 at one point), which the loads leave in equilibrium: the reaction
//! is zero up to round-off. So the solve refuses a point constraint whose reaction is above
//! its round-off, and everything that solves (solve, adapt, studies) gets the refusal.

use crate::fem::assembly::DofMap;
use model::mesh::P2Nodes;
use model::problems::{Part, Problem};

/// A point constraint whose reaction is above its round-off.
#[derive(Debug, thiserror::Error)]
#[error(
    "{problem}: the point constraint at {at} prescribes u_{component} = {value}, and holding it there takes a force of {reaction} ({relative} of the nodal forces' scale {scale}, {ratio} times its round-off {bound}): a point constraint is for removing a rigid motion (rollers: u_2 = 0 at one point), which takes no force; a displacement prescribed at a single point is no constraint of the continuous problem (a point has zero H^1 capacity), so each mesh would solve another problem. Give the prescribed displacement on a part (`[parts] dirichlet` with `dirichlet`) instead",
    at = model::base::number::point(*.at),
    value = model::base::number::shown(*.value),
    reaction = model::base::number::shown(*.reaction),
    relative = model::base::number::shown(.reaction.abs() / .scale),
    scale = model::base::number::shown(*.scale),
    ratio = format!("{:.1e}", .reaction.abs() / .bound),
    bound = model::base::number::shown(*.bound)
)]
pub struct PointReactionError {
    pub problem: String,
    pub at: [f64; 2],
    /// 1 or 2.
    pub component: usize,
    pub value: f64,
    pub reaction: f64,
    pub bound: f64,
    pub scale: f64,
}

/// Refuse the first point-constraint component prescribed by the constraint alone (not also by
/// Gamma_D, whose reaction it then shares) whose reaction (`reactions`, K u - F at its node) is
/// above its round-off bound (`bounds`). The solve bounds it with `lambda_roundoff`, from the
/// same two sources as a contact force's: the sum of the terms, and u_h's round-off (one step
/// of iterative refinement c moves the reaction by (K c)_p). The terms are the point's own plus
/// every unknown's (sum of |F_i| + (sum_T |K_T| |u_h|)_i): a rigid motion's reaction balances
/// all the nodal forces; the point's own terms with (K c)_p alone, 4 times, were exceeded 1.9
/// times on ex72_rollers' uniform level 11 (2.6e5 unknowns). Measured with every unknown's
/// terms (ex72_rollers, adaptive as written to 3.5e5 unknowns and uniform to 2.6e5): the
/// reaction is at most 9e-5 of the bound on every level, a margin of 1e4; u_1 = 0.3 at the
/// centre of Example 7.2 is 3e8 (structured:64) to 1e11 (structured:4) times its
/// bound.
pub fn check_reactions(
    nodes: &P2Nodes,
    dofs: &DofMap,
    problem: &dyn Problem,
    reactions: &[[f64; 2]],
    bounds: &[[f64; 2]],
    force_scale: f64,
) -> Result<(), Box<PointReactionError>> {
    let on_dirichlet = problem.dirichlet_components();
    for (k, &(p, u)) in dofs.points.iter().enumerate() {
        for i in 0..2 {
            let Some(value) = u[i] else { continue };
            if nodes.part[p] == Some(Part::Dirichlet) && on_dirichlet[i] {
                continue;
            }
            let (reaction, bound) = (reactions[k][i], bounds[k][i]);
            if reaction.abs() > bound {
                let problem = super::plausible::problem_name(problem);
                return Err(Box::new(PointReactionError {
                    problem,
                    at: nodes.coords[p],
                    component: i + 1,
                    value,
                    reaction,
                    bound,
                    scale: force_scale,
                }));
            }
        }
    }
    Ok(())
}

/// A point constraint's value on a component that Gamma_D also prescribes at that point, and
/// differs from Gamma_D's value there.
#[derive(Debug, thiserror::Error)]
#[error(
    "{problem}: the point constraint at {at} prescribes u_{component} = {value}, but the point is on the Dirichlet part ({part}), which already sets u_{component} = {dirichlet} there: one node cannot take both values. The point value is redundant there: drop it, or write \"free\" for u_{component} in `u` (a point constraint on Gamma_D can only prescribe a component `dirichlet` leaves \"free\")",
    at = model::base::number::point(*.at),
    value = model::base::number::shown(*.value),
    dirichlet = model::base::number::shown(*.dirichlet)
)]
pub struct PointOnDirichletError {
    pub problem: String,
    pub at: [f64; 2],
    /// 1 or 2.
    pub component: usize,
    pub value: f64,
    pub dirichlet: f64,
    /// How the problem declares Gamma_D (`parts.dirichlet = ...`), or "Gamma_D".
    pub part: String,
}

/// Refuse a point constraint's value on a component Gamma_D also prescribes at its vertex
/// unless it equals Gamma_D's value there (`u = [0.25, 0]` at a rollers' point with
/// `dirichlet = [0.1, "free"]` would keep one of the two values and silently drop the other). Equal
/// values are redundant but harmless and stay accepted. Equal is to 1e-12 of the prescribed
/// displacements' scale (the largest |value| of the Dirichlet data at Gamma_D's nodes and of the
/// point values): the same value written two ways (`0.1` at the point, an expression of the
/// constants in `dirichlet`) differs by a few ulps of that scale, 1e-16; a difference above
/// 1e-12 of it is one the user wrote, not round-off. The solve calls this once per mesh, after
/// numbering the unknowns ([`DofMap::new`]), before anything is assembled; a value on a
/// component of a *contact* node is no equality Gamma_C sets (the point's node leaves the
/// contact nodes, and `contact::plausible` and [`check_reactions`] judge it).
pub fn check_on_dirichlet(nodes: &P2Nodes, dofs: &DofMap, problem: &dyn Problem) -> Result<(), Box<PointOnDirichletError>> {
    let on_dirichlet = problem.dirichlet_components();
    let on_gamma_d = |p: usize| nodes.part[p] == Some(Part::Dirichlet);
    let shared: Vec<(usize, usize, f64)> = dofs
        .points
        .iter()
        .filter(|(p, _)| on_gamma_d(*p))
        .flat_map(|&(p, u)| (0..2).filter_map(move |i| u[i].filter(|_| on_dirichlet[i]).map(|v| (p, i, v))))
        .collect();
    if shared.is_empty() {
        return Ok(());
    }
    let data = (0..nodes.len()).filter(|&p| on_gamma_d(p)).flat_map(|p| {
        let g = problem.dirichlet(nodes.coords[p]);
        (0..2).filter(|&i| on_dirichlet[i]).map(move |i| g[i].abs())
    });
    let points = dofs.points.iter().flat_map(|(_, u)| u.iter().flatten().map(|v| v.abs()));
    let scale = data.chain(points).fold(0.0f64, f64::max);
    for (p, i, value) in shared {
        let dirichlet = problem.dirichlet(nodes.coords[p])[i];
        // a datum that is not a finite number is named by the data watch after assembly
        if !(value.is_finite() && dirichlet.is_finite()) || (value - dirichlet).abs() <= 1e-12 * scale {
            continue;
        }
        let part = problem.declared_parts().into_iter().find(|d| d.starts_with("parts.dirichlet")).unwrap_or_else(|| "Gamma_D".into());
        let problem = super::plausible::problem_name(problem);
        return Err(Box::new(PointOnDirichletError { problem, at: nodes.coords[p], component: i + 1, value, dirichlet, part }));
    }
    Ok(())
}
