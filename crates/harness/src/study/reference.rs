//! Reference solutions for problems without an exact solution (Example 7.2): a discrete
//! solution on a much finer adaptive mesh, evaluated anywhere by point location. Computed by
//! the adaptive loop ([`compute`]) or rebuilt from its stored refinement history in one solve
//! ([`replay`]), to the same numbers.

use ::store::records::{Rebuild, ReferenceSpec};
use model::base::element::{self, N_NODES};
use model::level::history::Flags;
use model::mesh::{
    Mesh, MeshSpec,
    locate::{Hit, Locator},
};
use model::problems::Problem;
use model::settings::adapt::{AdaptConfig, Refine};
use numerics::adapt;
use numerics::contact::norms::Displacement;

/// A P2 field on a mesh with an R*-tree for point location ([`Locator`]).
pub struct ReferenceField {
    mesh: Mesh,
    elements: Vec<[usize; 6]>,
    values: Vec<[f64; 2]>,
    locator: Locator,
    pub ndof: usize,
    /// How it was computed and how to rebuild it: what a study stores (`references/KEY.json`,
    /// `records::ReferenceRecord`).
    pub spec: ReferenceSpec,
    pub rebuild: Rebuild,
}

impl ReferenceField {
    pub fn new(mesh: Mesh, elements: Vec<[usize; 6]>, values: Vec<[f64; 2]>, spec: ReferenceSpec, rebuild: Rebuild) -> Self {
        let locator = Locator::new(&mesh);
        let ndof = 2 * values.len();
        ReferenceField { mesh, elements, values, locator, ndof, spec, rebuild }
    }

    /// The field at x: in the triangle containing x (the one of smallest index where x is on an
    /// edge), or the P2 polynomial of the triangle x is least outside of if x is a hair outside
    /// every triangle (a point of a coarser mesh whose boundary approximates a curve differently).
    pub fn eval(&self, x: [f64; 2]) -> [f64; 2] {
        self.value(&self.locator.nearest(&self.mesh, x).expect("a reference mesh has triangles"))
    }

    /// The field's P2 polynomial on the triangle of `hit`, at its point.
    fn value(&self, hit: &Hit) -> [f64; 2] {
        let phi = element::p2_values(hit.reference[0], hit.reference[1]);
        let el = &self.elements[hit.triangle];
        let mut v = [0.0; 2];
        for a in 0..N_NODES {
            v[0] += phi[a] * self.values[el[a]][0];
            v[1] += phi[a] * self.values[el[a]][1];
        }
        v
    }
}

/// What the errors of a study's runs are measured against; the points of one triangle of a run's
/// mesh are located together ([`Locator::nearest_each`]: the same triangles as one by one).
impl Displacement for ReferenceField {
    fn at(&self, x: [f64; 2]) -> [f64; 2] {
        self.eval(x)
    }

    fn at_each(&self, xs: &[[f64; 2]]) -> Vec<[f64; 2]> {
        self.locator.nearest_each(&self.mesh, xs).iter().map(|hit| self.value(hit)).collect()
    }
}

/// Levels the reference loop may refine through before giving up on `min_ndof`.
pub const REFERENCE_LEVELS: usize = 200;

/// Why a reference solution could not be computed.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    #[error(transparent)]
    Adapt(#[from] adapt::AdaptError),
    /// The loop ended before the reference reached `min_ndof` unknowns.
    #[error("the reference solution reached {ndof} unknowns after {levels} levels, short of reference.min_ndof = {min_ndof}: {why}")]
    Short { ndof: usize, levels: usize, min_ndof: usize, why: String },
    /// A stored reference that does not rebuild to what it records.
    #[error("the stored reference ({stored} unknowns) replays to {replayed} unknowns")]
    Replayed { stored: usize, replayed: usize },
    /// A stored reference whose record of its last level is not what the replay gives (an
    /// edited file: its estimate, its active nodes, its memory measurement...).
    #[error("the stored record of its last level (level {level}) is not what the replay gives: {differences}")]
    Record { level: usize, differences: String },
}

/// The adaptive loop of a reference solution: the maximum strategy with `spec.theta`, the
/// estimator with `spec.contact_term` (otherwise the defaults), as many levels as it takes.
fn config_of(spec: &ReferenceSpec) -> AdaptConfig {
    let estimator = model::settings::estimator::EstimatorConfig { contact_term: spec.contact_term, ..Default::default() };
    AdaptConfig { levels: REFERENCE_LEVELS, refine: Refine::Adaptive, theta: spec.theta, estimator, ..Default::default() }
}

/// Compute the reference solution `spec` declares: adaptive refinement from `mesh_spec`
/// (`config_of`) until the NDF reaches `min_ndof`; the last level's solution, with the
/// history that rebuilds it. `on_level` sees every level (progress) and may stop the loop (an
/// interrupt): then the result is `None`. A loop that ends short of `min_ndof` (after
/// [`REFERENCE_LEVELS`] levels) is an error saying how far it got.
pub fn compute(
    problem: &dyn Problem,
    mesh_spec: &MeshSpec,
    spec: &ReferenceSpec,
    on_level: &mut dyn FnMut(&model::level::record::LevelRecord) -> std::ops::ControlFlow<()>,
) -> Result<Option<ReferenceField>, ReferenceError> {
    let mesh = mesh_spec.build(problem).map_err(|e| adapt::AdaptError::Solve(e.into()))?;
    let config = config_of(spec);
    // the automatic ordering even in a round-off measurement (SIGNORINI_ORDERING): the reference
    // stays the one the stored errors were measured against (numerics::sparse::ordering::automatic)
    let out = numerics::sparse::ordering::automatic(|| {
        adapt::run(problem, mesh, &config, None, &mut |level| {
            if level.record.ndof >= spec.min_ndof { std::ops::ControlFlow::Break(()) } else { on_level(level.record) }
        })
    })?;
    let last = out.records.last().expect("level 0 is always solved");
    if last.ndof >= spec.min_ndof {
        let rebuild =
            Rebuild { ndof: last.ndof, last: last.clone(), history: out.history, final_active: Some(Flags::encode(&out.solution.active)) };
        return Ok(Some(ReferenceField::new(out.mesh, out.solution.nodes.elements, out.solution.u, spec.clone(), rebuild)));
    }
    if out.termination == adapt::AdaptTermination::StoppedByObserver {
        return Ok(None); // on_level stopped it (an interrupt)
    }
    let why = out.termination.note(&config).unwrap_or_else(|| {
        format!(
            "the reference loop stops after {REFERENCE_LEVELS} levels, and marking with theta = {} added about {:.0} unknowns per level \
         (the largest level-to-level growth was {}); lower reference.theta (more elements marked per level) or reference.min_ndof",
            spec.theta,
            last.ndof.saturating_sub(out.records[0].ndof) as f64 / (out.records.len() - 1).max(1) as f64,
            out.records.windows(2).map(|w| w[1].ndof.saturating_sub(w[0].ndof)).max().unwrap_or(0)
        )
    });
    Err(ReferenceError::Short { ndof: last.ndof, levels: out.records.len(), min_ndof: spec.min_ndof, why })
}

/// Rebuild a stored reference solution: the last mesh of its history from `mesh_spec`'s mesh
/// (every level's fingerprint checked), solved once, as the loop solved it (the automatic
/// ordering, as in [`compute`]), from the active set the loop's solve ended with (else from its
/// warm start): the same solution in one solve, and in one numeric factorisation. The replayed
/// level's record is compared with the stored record of the last level as the drift check
/// compares levels (`tolerances`, the study's; `drift::level_differences`): a stored record
/// that is not what its solve gives is an error naming the fields (measurements, `t_*` and
/// `mem_*`, are not compared: no two solves share them).
pub fn replay(
    problem: &dyn Problem,
    mesh_spec: &MeshSpec,
    spec: &ReferenceSpec,
    record: &Rebuild,
    tolerances: &::store::study::manifest::DriftSpec,
) -> Result<ReferenceField, ReferenceError> {
    use adapt::replay::ReplayError;
    let mesh0 = mesh_spec.build(problem).map_err(|e| adapt::AdaptError::Solve(e.into()))?;
    let config = config_of(spec);
    let last = record.history.levels.len().checked_sub(1).ok_or(adapt::AdaptError::from(ReplayError::Short { level: 0, held: 0 }))?;
    let mesh = adapt::replay::mesh_at(mesh0, &record.history, last).map_err(adapt::AdaptError::from)?;
    let start = record.final_active.as_ref().or(record.history.levels[last].initial_active.as_ref());
    let start =
        start.map(|f| f.decode()).transpose().map_err(|source| adapt::AdaptError::from(ReplayError::Flags { level: last, source }))?;
    let measured = record.last.measured_peak();
    let solved = numerics::sparse::ordering::automatic(|| {
        adapt::solve_level(problem, &mesh, last, &config, None, adapt::LevelStart { active: start, body_force: None }, measured)
    })?;
    if solved.record.ndof != record.ndof {
        return Err(ReferenceError::Replayed { stored: record.ndof, replayed: solved.record.ndof });
    }
    let rows = crate::study::drift::level_differences(&record.last, &solved.record, tolerances, crate::study::drift::NOT_REPLAYED);
    if !rows.is_empty() {
        let differences =
            rows.iter().map(|r| format!("{} stored {}, replayed {} ({})", r.field, r.stored, r.fresh, r.tolerance)).collect::<Vec<_>>();
        return Err(ReferenceError::Record { level: last, differences: differences.join("; ") });
    }
    Ok(ReferenceField::new(mesh, solved.solution.nodes.elements, solved.solution.u, spec.clone(), record.clone()))
}
