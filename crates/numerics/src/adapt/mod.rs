//! The adaptive loop of Section 7: SOLVE -> ESTIMATE -> MARK -> REFINE, one level per turn
//! ([`AdaptState::step`]: the loop's state, stepped), with an observer that sees every level
//! (what the study runner records). The loop keeps a
//! refinement [`History`] (marks and warm starts per level) from which [`replay`] rebuilds and
//! solves any level again, and it can start from a later level ([`run_from`], [`Start`]): how an
//! interrupted deep run resumes.
//! The method: `docs/method.md`, sections "MARK: the maximum strategy" and "The loop and its stops".

pub mod replay;
mod roundoff;

pub use roundoff::{
    Cause, Caveat, Conditioned, Drowned, NO_DEFORMATION, RESOLVED_DEFORMATION, RESOLVED_FORCES, ROUNDOFF_ESTIMATE, Resolution, TRANSLATED,
    Unresolved, WARNED_FORCES, WARNED_SHAPE, deformation, force_roundoff, resolution,
};

use crate::contact::consistent::BodyForceFindings;
use crate::contact::norms::{self, Reference};
use crate::contact::solve::{self, DiscreteSolution, SolveError};
use crate::estimator::estimate::{self, Estimate};
use model::level::history::{Flags, History, LevelHistory};
use model::level::record::LevelRecord;
use model::level::terms::NotFinite;
use model::mesh::Mesh;
use model::mesh::refine::{self, Refinement};
use model::problems::Problem;
use model::settings::adapt::{AdaptConfig, Refine};
use model::settings::estimator::ConfigError;
use std::ops::ControlFlow;
use std::time::Instant;

#[derive(Debug, thiserror::Error)]
pub enum AdaptError {
    /// A setting of the loop outside its range ([`ConfigError`], the estimator's error type: one
    /// for all settings).
    #[error("adaptive loop settings: {0}")]
    Config(#[from] ConfigError),
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The solve of level `level` (its mesh with `ndof` unknowns) failed: a refusal of the data
    /// or a solver that did not converge, named with the level it happened at (a refusal at a
    /// later level names that level, not only the data).
    #[error("level {level} ({ndof} unknowns): {error}")]
    SolveAt { level: usize, ndof: usize, error: Box<SolveError> },
    /// The estimate of level `level` is not a finite number (nothing of that level is kept).
    #[error("level {level}: {error}")]
    Estimate { level: usize, error: NotFinite },
    /// The next level would not fit in memory: levels `0..level` were solved (and seen by the
    /// observer), level `level` was not.
    #[error("stopped before level {level} ({}): {error}", if *level == 0 { "no level was solved".to_string() } else { format!("levels 0 to {} were solved", level - 1) })]
    Memory { level: usize, error: model::base::memory::MemoryError },
    /// A start at or beyond the last level: nothing is left to solve.
    #[error("nothing to solve: the loop starts at level {start} and has {levels} levels")]
    NothingToSolve { start: usize, levels: usize },
    /// A start at a later level whose mesh is above `max_ndof`: nothing is left to solve (the
    /// loop never hands out such a start: the level before it does not continue).
    #[error("nothing to solve: the loop starts at level {start}, whose mesh has {ndof} unknowns, above max_ndof {max}")]
    BeyondMaxNdof { start: usize, ndof: usize, max: usize },
    #[error(transparent)]
    Replay(#[from] replay::ReplayError),
    /// Refining level `level` into the next failed (levels `0..=level` were solved and seen by
    /// the observer).
    #[error("refining level {level} (levels 0 to {level} were solved): {error}")]
    Refine { level: usize, error: model::mesh::MeshError },
    /// Level `level`'s u_h does not resolve its deformation, or its contact forces are at their
    /// round-off ([`resolution`]).
    #[error("level {level}: {error}")]
    Unresolved { level: usize, error: Unresolved },
}

/// What the observer sees at each level.
pub struct Level<'a> {
    pub record: &'a LevelRecord,
    pub mesh: &'a Mesh,
    pub solution: &'a DiscreteSolution,
    pub estimate: &'a Estimate,
    /// The level's entry of the refinement history.
    pub history: &'a LevelHistory,
    /// The loop goes on to a next level (false at the last level, which is not refined).
    pub continues: bool,
    /// The active set the next level starts from, if it continues with warm starts.
    pub next_active: Option<&'a [bool]>,
    /// What the level's numbers keep fewer digits of than they should ([`resolution`]).
    pub caveats: &'a [Caveat],
}

/// Mark by the maximum strategy: eta_T >= theta max eta_T.
pub fn mark_maximum(indicators: &[f64], theta: f64) -> Vec<bool> {
    let max = indicators.iter().cloned().fold(0.0, f64::max);
    indicators.iter().map(|&e| max > 0.0 && e >= theta * max).collect()
}

/// Centroid of the first element with the largest indicator.
fn largest_indicator_centroid(mesh: &Mesh, indicators: &[f64]) -> [f64; 2] {
    let centroid = |t: usize| {
        let v = mesh.triangles[t].map(|i| mesh.vertices[i]);
        [(v[0][0] + v[1][0] + v[2][0]) / 3.0, (v[0][1] + v[1][1] + v[2][1]) / 3.0]
    };
    let max = indicators.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    // elements within TIE of the largest count as tied (round-off moves indicators by about
    // 1e-10 relative, results/roundoff/), and the tie goes to the smallest centroid (x, then y):
    // otherwise which of two near-equal corners wins would depend on the summation order
    const TIE: f64 = 1e-8;
    (0..indicators.len())
        .filter(|&t| indicators[t] >= max - TIE * max.abs())
        .map(centroid)
        .min_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])))
        .unwrap_or([f64::NAN; 2])
}

/// The longest contact edge with both active and inactive nodes (`LevelRecord::h_free_boundary`).
pub fn free_boundary_edge(mesh: &Mesh, sol: &DiscreteSolution) -> Option<f64> {
    mesh.boundary
        .iter()
        .zip(&sol.nodes.boundary_nodes)
        .filter(|(e, _)| e.part == model::problems::Part::Contact)
        .filter_map(|(e, nodes)| {
            let active: Vec<bool> = nodes.iter().map(|&n| sol.dofs.contact_index[n].is_some_and(|k| sol.active[k])).collect();
            (active.contains(&true) && active.contains(&false)).then(|| model::mesh::dist(mesh.vertices[e.v[0]], mesh.vertices[e.v[1]]))
        })
        .reduce(f64::max)
}

/// Active set for the refined mesh: a new contact node starts active where the previous level's
/// discrete solution (transferred exactly, P2 in P2) touches the obstacle.
fn transfer_active_set(old_mesh: &Mesh, old: &DiscreteSolution, refinement: &Refinement, problem: &dyn Problem) -> Vec<bool> {
    let new_nodes = model::mesh::P2Nodes::new(&refinement.mesh);
    let u = refine::transfer_p2(old_mesh, &old.nodes, &old.u, refinement, &new_nodes);
    let dofs = crate::fem::assembly::DofMap::new(&new_nodes, problem);
    let scale = u.iter().fold(0.0f64, |a, v| a.max(v[0].abs()).max(v[1].abs())).max(f64::MIN_POSITIVE);
    dofs.contact
        .iter()
        .map(|c| {
            let v = u[c.node];
            v[0] * c.normal[0] + v[1] * c.normal[1] >= c.gap - 1e-10 * scale
        })
        .collect()
}

/// Why [`run`] stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AdaptTermination {
    /// All `AdaptConfig::levels` levels were solved.
    LevelsReached,
    /// The next level would have had more unknowns than `AdaptConfig::max_ndof` (it was not solved).
    MaxNdofReached,
    /// The last level solved has at least `AdaptConfig::stop_ndof` unknowns.
    StopNdofReached,
    /// The observer returned `ControlFlow::Break` (checked before the other two: an observer that
    /// stops at the last level is reported here).
    StoppedByObserver,
    /// The estimate of the last level solved is zero on every element, or at round-off
    /// ([`Resolution::AtRoundoff`]): the maximum strategy marks nothing, so the next level would
    /// be the same mesh again (not solved).
    NothingMarked,
    /// The refined mesh of level `level` (of `ndof` unknowns) has an element whose shape f64 no
    /// longer resolves at its coordinates (`worst`, [`Mesh::shape_roundoff_refused`]: a mesh far
    /// from the origin refined deep); levels `0..level` were solved and seen by
    /// the observer, that one was not. A stop, not an error of the loop, so that a study keeps
    /// the levels solved; the command line exits 1 as for the memory stop ([`Self::is_error`]).
    FarFromOrigin { level: usize, ndof: usize, worst: model::mesh::precision::ShapeRoundoff },
}

impl AdaptTermination {
    /// Why the loop stopped before its last level, in a sentence (None: all levels were solved,
    /// or the caller stopped it and knows why).
    pub fn note(self, config: &AdaptConfig) -> Option<String> {
        match self {
            AdaptTermination::LevelsReached | AdaptTermination::StoppedByObserver => None,
            AdaptTermination::MaxNdofReached => {
                Some(format!("stopped: the next level would have more than max_ndof = {} unknowns", config.max_ndof.unwrap_or(0)))
            }
            AdaptTermination::StopNdofReached => {
                Some(format!("stopped: the last level has at least stop_ndof = {} unknowns", config.stop_ndof.unwrap_or(0)))
            }
            AdaptTermination::NothingMarked => Some(format!(
                "stopped: the estimate is zero, or at round-off (u_h has no deformation above {NO_DEFORMATION} delta, or eta_h is at most {ROUNDOFF_ESTIMATE:e} times what u_h's round-off can do to it: the smaller of (2 mu + lambda) delta, delta the round-off of u_h (the larger of its round-off floor and 2.2e-16 max |u_h|), and the largest stress the round-off's energy allows: u_h is a rigid motion or a field the P2 space reproduces, to round-off, or a rigid translation in the data left it no digits of the deformation), so nothing is marked and the next level would be the same mesh"
            )),
            AdaptTermination::FarFromOrigin { level, ndof, worst } => Some(format!(
                "stopped before level {level} (levels 0 to {} were solved): its refined mesh ({ndof} unknowns) is too fine for its coordinates: {}; or stop the loop before this level: at most {level} levels (levels = {level}, --levels {level}) or at most {} unknowns (max_ndof, --max-ndof)",
                level - 1,
                model::mesh::MeshError::from(worst),
                ndof - 1
            )),
        }
    }

    /// Whether the command line ends with an error (exit 1) after the levels it printed, as for
    /// the memory stop: the loop could not reach the levels asked for, for a reason the user
    /// acts on (a study keeps the levels solved, with the note on its summary line).
    pub fn is_error(self) -> bool {
        matches!(self, AdaptTermination::FarFromOrigin { .. })
    }
}

/// What [`run`] returns: the state of the last level solved and why the loop stopped (in the
/// shape of argmin's `OptimizationResult`).
pub struct AdaptResult {
    /// The mesh of the last level solved (not refined further).
    pub mesh: Mesh,
    /// The discrete solution on `mesh`.
    pub solution: DiscreteSolution,
    /// The estimate of that solution.
    pub estimate: Estimate,
    /// One record per level solved, in order; the last one describes `mesh`.
    pub records: Vec<LevelRecord>,
    /// The refinement history of every level in `records`.
    pub history: History,
    pub termination: AdaptTermination,
}

/// Where the loop starts: the mesh of level `level`, the active set its solve starts from, and
/// the records and history of the levels before it (empty from level 0).
pub struct Start {
    pub mesh: Mesh,
    pub level: usize,
    pub initial_active: Option<Vec<bool>>,
    pub records: Vec<LevelRecord>,
    pub history: History,
}

impl Start {
    /// Level 0 on `mesh`.
    pub fn new(mesh: Mesh) -> Self {
        Start { mesh, level: 0, initial_active: None, records: Vec::new(), history: History::default() }
    }
}

/// One level solved, estimated and marked (not yet refined).
pub struct Solved {
    pub record: LevelRecord,
    pub solution: DiscreteSolution,
    pub estimate: Estimate,
    pub marks: Vec<bool>,
    /// What its numbers keep fewer digits of than they should ([`resolution`]).
    pub caveats: Vec<Caveat>,
}

/// What the solve of a level starts from besides its mesh: what the level before leaves it.
#[derive(Clone, Debug, Default)]
pub struct LevelStart {
    /// The contact solve's active set (taken if `config.warm_start`).
    pub active: Option<Vec<bool>>,
    /// The body-force findings of the triangles the refinement left as they were
    /// ([`BodyForceFindings::inherit`]): the data checks evaluate only the new ones, to the
    /// same verdict.
    pub body_force: Option<BodyForceFindings>,
}

/// SOLVE, ESTIMATE and MARK on the mesh of level `level`, the contact solve started from
/// `start` (its active set if `config.warm_start`): everything of a level but the refinement.
/// Its record's `t_refine` and `t_level` are zero (the loop sets them).
pub fn solve_level(
    problem: &dyn Problem,
    mesh: &Mesh,
    level: usize,
    config: &AdaptConfig,
    reference: Option<Reference>,
    start: LevelStart,
    measured: Option<(f64, f64)>,
) -> Result<Solved, AdaptError> {
    let ndof = mesh.p2_ndof();
    // before every level, not only the first: an adaptive loop grows until it does not fit;
    // `measured`: unknowns and peak resident bytes of a measured solve, if known (the previous
    // level's in the loop, the level's own stored one in a replay)
    model::base::memory::check_memory_measured(&format!("level {level} of the adaptive loop"), ndof as f64, measured)
        .map_err(|error| AdaptError::Memory { level, error })?;
    let mut options = config.pdas.clone();
    if config.warm_start {
        options.initial_active = start.active;
    }
    let t0 = Instant::now();
    let sol = solve::solve_from(mesh, problem, &options, start.body_force, &mut |_| {}).map_err(|error| AdaptError::SolveAt {
        level,
        ndof,
        error: Box::new(error),
    })?;
    let t_solve = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let est = estimate::estimate(mesh, problem, &sol, &config.estimator);
    // the estimator samples the data at points of its own (a dense lattice, edge points)
    if let Some(bad) = problem.bad_datum() {
        return Err(SolveError::Data(bad).into());
    }
    est.terms.check_finite().map_err(|error| AdaptError::Estimate { level, error })?;
    let t_estimate = t0.elapsed().as_secs_f64();
    let (at_roundoff, caveats) = match resolution(problem, mesh, &sol, &est) {
        Resolution::Unresolved(error) => return Err(AdaptError::Unresolved { level, error }),
        Resolution::AtRoundoff => (true, vec![Caveat::AtRoundoff]),
        Resolution::Resolved(caveats) => (false, caveats),
    };
    // err_right_half from the same evaluations as the dense norm (the record says why x >= 1/2)
    let (error, right_half) = reference.map(|r| norms::linf_error_with(mesh, &sol, r, &|x| x[0] >= 0.5)).unzip();
    let marks = match config.refine {
        Refine::Adaptive if at_roundoff => vec![false; mesh.n_triangles()],
        Refine::Adaptive => mark_maximum(&est.element, config.theta),
        Refine::Uniform => vec![true; mesh.n_triangles()],
    };
    let (h_min, h_max) = mesh.h_range();
    let peak = largest_indicator_centroid(mesh, &est.element);
    let zone = sol.contact_zone();
    let t = &est.terms;
    let ct = &sol.timings.contact;
    let record = LevelRecord {
        level,
        ndof: 2 * sol.nodes.len(),
        ndof_free: sol.dofs.n_free,
        n_elements: mesh.n_triangles(),
        h_min,
        h_max,
        min_angle: mesh.min_angle_degrees(),
        contact_nodes: sol.dofs.contact.len(),
        active_nodes: sol.active_count(),
        full_contact_nodes: est.full_contact_nodes,
        pdas_iterations: sol.pdas.len(),
        zone_min: zone.map(|z| z[0]),
        zone_max: zone.map(|z| z[1]),
        terms: *t,
        err_quadrature: error.map(|e| e.linf_quadrature),
        err_dense: error.map(|e| e.linf_dense),
        err_nodal: error.map(|e| e.linf_nodal),
        efficiency: error.map(|e| t.estimate / e.linf_quadrature),
        err_contact: reference.and_then(|r| norms::linf_error_contact(mesh, &sol, r)),
        err_right_half: right_half.flatten(),
        roundoff_floor: sol.roundoff,
        h_free_boundary: free_boundary_edge(mesh, &sol),
        max_indicator_x: peak[0],
        max_indicator_y: peak[1],
        // counted on the last level too, so a shorter run is an exact prefix of a longer one
        marked: marks.iter().filter(|m| **m).count(),
        t_assembly: sol.timings.assembly,
        t_factorisation: ct.symbolic + ct.numeric + ct.schur,
        t_active_set: ct.active_set,
        t_solve,
        t_estimate,
        t_refine: 0.0,
        t_level: 0.0,
        t_roundoff: sol.timings.roundoff,
        mem_peak_mib: None,
    };
    Ok(Solved { record, solution: sol, estimate: est, marks, caveats })
}

/// Run the loop from `mesh`. `reference` gives the displacement errors are measured against
/// (an exact solution or a reference solution), if any. The observer sees every level and may
/// stop the loop.
///
/// `config` must be valid ([`AdaptConfig::validate`]); at least level 0 is always solved.
///
/// ```rust
/// use signorini_numerics::adapt::{self, AdaptTermination};
/// use model::mesh::MeshSpec;
/// use model::problems::{self, Problem};
/// use model::settings::adapt::AdaptConfig;
/// use std::ops::ControlFlow;
///
/// let problem = problems::by_name("ex71").unwrap();
/// let mesh = MeshSpec::parse("structured:2").unwrap().build(problem.as_ref()).unwrap();
/// let config = AdaptConfig { levels: 3, ..Default::default() };
/// config.validate().unwrap();
/// let exact = problem.exact().unwrap();
/// let u = |x: [f64; 2]| exact.u(x);
/// let result = adapt::run(problem.as_ref(), mesh, &config, Some(&u), &mut |_| ControlFlow::Continue(())).unwrap();
/// assert_eq!(result.termination, AdaptTermination::LevelsReached);
/// assert_eq!(result.records.len(), 3);
/// assert_eq!(result.history.levels.len(), 3);
/// assert_eq!(result.records[2].ndof, 2 * result.solution.nodes.len());
/// assert!(result.records[2].err_quadrature.unwrap() < result.records[0].err_quadrature.unwrap());
/// ```
pub fn run(
    problem: &dyn Problem,
    mesh: Mesh,
    config: &AdaptConfig,
    reference: Option<Reference>,
    observer: &mut dyn FnMut(Level) -> ControlFlow<()>,
) -> Result<AdaptResult, AdaptError> {
    run_from(problem, Start::new(mesh), config, reference, observer)
}

/// [`run`] from a later level: `start` holds the mesh of level `start.level`, the active set its
/// solve starts from and the records and history of the levels before (a resumed run:
/// [`replay::resume`]). The same numbers as the uninterrupted loop, level for level.
pub fn run_from(
    problem: &dyn Problem,
    start: Start,
    config: &AdaptConfig,
    reference: Option<Reference>,
    observer: &mut dyn FnMut(Level) -> ControlFlow<()>,
) -> Result<AdaptResult, AdaptError> {
    let mut state = AdaptState::new(start, config)?;
    loop {
        if let Some(termination) = state.step(problem, config, reference, observer)? {
            return state.finish(termination, config);
        }
    }
}

/// The loop between two levels (the state of [`run_from`]): the mesh of the next level and the
/// active set its solve starts from, the records and history of the levels solved, and the last
/// level's mesh, solution and estimate. [`AdaptState::step`] solves one level; a caller that
/// steps the loop itself sees each level as [`run`]'s observer does.
pub struct AdaptState {
    /// The level the next step solves.
    level: usize,
    /// The level the loop started at.
    first: usize,
    /// The mesh of level `level` (None once a step has ended the loop).
    mesh: Option<Mesh>,
    initial_active: Option<Vec<bool>>,
    /// The body-force findings the next level inherits ([`LevelStart::body_force`]).
    body_force: Option<BodyForceFindings>,
    /// The record of every level solved, from level 0.
    pub records: Vec<LevelRecord>,
    /// The refinement history of every level in `records`.
    pub history: History,
    /// The last level solved: its mesh, u_h and estimate.
    last: Option<(Mesh, DiscreteSolution, Estimate)>,
}

impl AdaptState {
    /// The loop at `start`, its settings checked (`config` must hold for every step).
    pub fn new(start: Start, config: &AdaptConfig) -> Result<Self, AdaptError> {
        config.validate()?;
        if start.level >= config.levels {
            return Err(AdaptError::NothingToSolve { start: start.level, levels: config.levels });
        }
        if start.level == 0 {
            config.check_initial(start.mesh.p2_ndof() as f64, "of level 0")?;
        }
        let Start { mesh, level, initial_active, records, history } = start;
        Ok(AdaptState { level, first: level, mesh: Some(mesh), initial_active, body_force: None, records, history, last: None })
    }

    /// SOLVE, ESTIMATE and MARK the next level, show it to `observer`, REFINE its mesh into the
    /// next one: why the loop ends after this level, or None when it goes on.
    pub fn step(
        &mut self,
        problem: &dyn Problem,
        config: &AdaptConfig,
        reference: Option<Reference>,
        observer: &mut dyn FnMut(Level) -> ControlFlow<()>,
    ) -> Result<Option<AdaptTermination>, AdaptError> {
        let level = self.level;
        let Some(mesh) = self.mesh.take() else { return Err(AdaptError::NothingToSolve { start: level, levels: config.levels }) };
        if let Some(max) = config.max_ndof
            && level > 0
            && mesh.p2_ndof() > max
        {
            if self.last.is_none() {
                return Err(AdaptError::BeyondMaxNdof { start: level, ndof: mesh.p2_ndof(), max });
            }
            return Ok(Some(AdaptTermination::MaxNdofReached));
        }
        // the level before is not needed while this one solves (the loop returns it only when
        // this level is not solved): its mesh, u_h and estimate added to the peak memory (fb
        // adaptive to 2.6e6 unknowns: peak resident 4.09 -> 3.91 GB without them)
        drop(self.last.take());
        let t_level = Instant::now();
        let previous = self.records.last().and_then(LevelRecord::measured_peak);
        let measured = model::base::memory::reset_peak_resident();
        let started_from = self.initial_active.take().filter(|_| config.warm_start);
        let Solved { mut record, solution: sol, estimate: est, marks, caveats } = solve_level(
            problem,
            &mesh,
            level,
            config,
            reference,
            LevelStart { active: started_from.clone(), body_force: self.body_force.take() },
            previous,
        )?;
        let entry = LevelHistory {
            level,
            n_elements: mesh.n_triangles(),
            mesh: mesh.fingerprint(),
            initial_active: started_from.as_deref().map(Flags::encode),
            marks: Flags::encode(&marks),
        };
        let reached = config.stop_ndof.is_some_and(|s| mesh.p2_ndof() >= s);
        let unmarked = config.refine == Refine::Adaptive && !marks.contains(&true);
        let next = if level + 1 == config.levels || reached || unmarked {
            None
        } else {
            let t0 = Instant::now();
            let refined = refine::refine(&mesh, &marks).map(|refinement| {
                let active = config.warm_start.then(|| transfer_active_set(&mesh, &sol, &refinement, problem));
                let body_force = sol.body_force.as_ref().map(|findings| findings.inherit(&mesh, &refinement));
                (refinement.mesh, active, body_force)
            });
            record.t_refine = t0.elapsed().as_secs_f64();
            Some(refined)
        };
        // a refined mesh whose element shapes f64 does not resolve ends the loop before its
        // level, as the memory check does, not as an error of its solve (Mesh::check)
        let far = match &next {
            Some(Ok((m, ..))) => {
                m.shape_roundoff_refused().map(|worst| AdaptTermination::FarFromOrigin { level: level + 1, ndof: m.p2_ndof(), worst })
            }
            _ => None,
        };
        // a refined mesh above max_ndof is not solved: the loop ends here, and this level says
        // it does not continue, so a run interrupted now keeps no checkpoint of a level it
        // would never solve (resuming from one would solve nothing)
        let over = match (&next, config.max_ndof) {
            (Some(Ok((m, ..))), Some(max)) => m.p2_ndof() > max,
            _ => false,
        };
        let next = if far.is_some() || over { None } else { next };
        record.t_level = t_level.elapsed().as_secs_f64();
        record.mem_peak_mib = model::base::memory::peak_resident().filter(|_| measured).map(|b| b / (1024.0 * 1024.0));
        let flow = observer(Level {
            record: &record,
            mesh: &mesh,
            solution: &sol,
            estimate: &est,
            history: &entry,
            continues: next.is_some(),
            next_active: next.as_ref().and_then(|n| n.as_ref().ok()).and_then(|(_, a, _)| a.as_deref()),
            caveats: &caveats,
        });
        self.records.push(record);
        self.history.levels.push(entry);
        self.last = Some((mesh, sol, est));
        if flow.is_break() {
            return Ok(Some(AdaptTermination::StoppedByObserver));
        }
        let termination = if reached {
            AdaptTermination::StopNdofReached
        } else if next.is_none() && unmarked && level + 1 < config.levels {
            AdaptTermination::NothingMarked
        } else if let Some(far) = far {
            far
        } else if over {
            AdaptTermination::MaxNdofReached
        } else {
            AdaptTermination::LevelsReached
        };
        match next {
            Some(Ok((m, active, body_force))) => {
                self.mesh = Some(m);
                self.initial_active = active;
                self.body_force = body_force;
                self.level += 1;
                Ok(None)
            }
            Some(Err(error)) => Err(AdaptError::Refine { level, error }),
            None => Ok(Some(termination)),
        }
    }

    /// The loop's result once a step has ended it with `termination`.
    pub fn finish(self, termination: AdaptTermination, config: &AdaptConfig) -> Result<AdaptResult, AdaptError> {
        // every way out of the loop solved a level first (first < levels), or returned an error
        let Some((mesh, solution, estimate)) = self.last else {
            return Err(AdaptError::NothingToSolve { start: self.first, levels: config.levels });
        };
        Ok(AdaptResult { mesh, solution, estimate, records: self.records, history: self.history, termination })
    }
}
