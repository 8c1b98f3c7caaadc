//! Rebuild a level of a stored run from its refinement history, without the levels' solves:
//! the initial mesh refined by the stored marks, level after level (each mesh checked against
//! its stored fingerprint), then that one level solved from its stored warm start. What the
//! drift check's replay tier compares with the stored record of a deep level, and how an
//! interrupted run resumes ([`resume`]).

use super::{AdaptError, Solved, Start};
use crate::contact::norms::Reference;
use model::level::history::{BadFlags, History};
use model::level::record::LevelRecord;
use model::mesh::{Mesh, refine};
use model::problems::Problem;
use model::settings::adapt::AdaptConfig;

/// A history that does not rebuild the run it belongs to.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error("the history holds {held} levels; level {level} was asked for")]
    Short { level: usize, held: usize },
    #[error(
        "level {level}: the replayed mesh ({got_elements} elements, fingerprint {got}) is not the stored one ({want_elements} elements, fingerprint {want})"
    )]
    Mesh { level: usize, got: String, want: String, got_elements: usize, want_elements: usize },
    #[error("level {level}: {source}")]
    Flags { level: usize, source: BadFlags },
    #[error("level {level}: {what} has {got} flags for {want} {of}")]
    Length { level: usize, what: &'static str, got: usize, want: usize, of: &'static str },
    /// Refining level `level` into the next failed ([`refine::refine`]).
    #[error("refining level {level}: {error}")]
    Refine { level: usize, error: model::mesh::MeshError },
}

/// The mesh of level `level`: `mesh0` refined by the marks of levels 0..level, every mesh on the
/// way (and the last) checked against its stored fingerprint.
pub fn mesh_at(mesh0: Mesh, history: &History, level: usize) -> Result<Mesh, ReplayError> {
    if level >= history.levels.len() {
        return Err(ReplayError::Short { level, held: history.levels.len() });
    }
    let mut mesh = mesh0;
    for (l, entry) in history.levels.iter().enumerate().take(level + 1) {
        let got = mesh.fingerprint();
        if got != entry.mesh {
            let (got_elements, want_elements) = (mesh.n_triangles(), entry.n_elements);
            return Err(ReplayError::Mesh { level: l, got, want: entry.mesh.clone(), got_elements, want_elements });
        }
        if l == level {
            break;
        }
        let marks = entry.marks.decode().map_err(|source| ReplayError::Flags { level: l, source })?;
        if marks.len() != mesh.n_triangles() {
            return Err(ReplayError::Length { level: l, what: "the marks", got: marks.len(), want: mesh.n_triangles(), of: "elements" });
        }
        mesh = refine::refine(&mesh, &marks).map_err(|error| ReplayError::Refine { level: l, error })?.mesh;
    }
    Ok(mesh)
}

/// The warm start stored for `level` (None where the level started cold).
fn initial_active(history: &History, level: usize) -> Result<Option<Vec<bool>>, ReplayError> {
    let entry = history.levels.get(level).ok_or(ReplayError::Short { level, held: history.levels.len() })?;
    entry.initial_active.as_ref().map(|f| f.decode().map_err(|source| ReplayError::Flags { level, source })).transpose()
}

/// Rebuild level `level` of a run from its initial mesh and history and solve it again, as the
/// loop did: the same mesh, the same warm start, so the same record (timings aside). `stored`
/// is the level's stored record, if there is one: its measured peak is what the memory check
/// scales from (a 1.2e7-unknown level that peaked at 11.7 GiB is not refused by the 23 GiB of
/// the per-unknown estimate).
pub fn solve_stored_level(
    problem: &dyn Problem,
    mesh0: Mesh,
    config: &AdaptConfig,
    history: &History,
    level: usize,
    stored: Option<&LevelRecord>,
    reference: Option<Reference>,
) -> Result<(Mesh, Solved), AdaptError> {
    let mesh = mesh_at(mesh0, history, level)?;
    let start = initial_active(history, level)?;
    let measured = stored.and_then(LevelRecord::measured_peak);
    let solved =
        super::solve_level(problem, &mesh, level, config, reference, super::LevelStart { active: start, body_force: None }, measured)?;
    Ok((mesh, solved))
}

/// Where a run whose levels `records` (with their `history`) are finished goes on: the mesh of
/// the next level rebuilt from `mesh0`, refined by the last finished level's marks, and the
/// active set the next level starts from (`next_active`, as the loop had transferred it).
pub fn resume(mesh0: Mesh, records: Vec<LevelRecord>, history: History, next_active: Option<Vec<bool>>) -> Result<Start, ReplayError> {
    let last = history.levels.len().checked_sub(1).ok_or(ReplayError::Short { level: 0, held: 0 })?;
    let mesh = mesh_at(mesh0, &history, last)?;
    let entry = &history.levels[last];
    let marks = entry.marks.decode().map_err(|source| ReplayError::Flags { level: last, source })?;
    if marks.len() != mesh.n_triangles() {
        return Err(ReplayError::Length { level: last, what: "the marks", got: marks.len(), want: mesh.n_triangles(), of: "elements" });
    }
    let mesh = refine::refine(&mesh, &marks).map_err(|error| ReplayError::Refine { level: last, error })?.mesh;
    Ok(Start { mesh, level: last + 1, initial_active: next_active, records, history })
}
