//! A run in progress, kept after every finished level: `STUDY/.partial/RUN.json` holds the
//! records and refinement history of the levels finished so far and the active set the next
//! level starts from. A run that is stopped (killed, out of time on a cluster) resumes after its
//! last finished level instead of from level 0 ([`crate::study::run_study`]), with the same numbers:
//! the next mesh is rebuilt from the initial one by the stored marks (`adapt::replay`). The
//! checkpoint is not a result: git ignores `.partial/`, and it is removed when the run lands.

use crate::records::{Flags, History, LevelRecord, RunSpec, StudyDir};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    /// The spec of the run in progress: a checkpoint of another spec is not resumed.
    pub run: RunSpec,
    pub levels: Vec<LevelRecord>,
    pub history: History,
    /// The warm start of the next level (None without warm starts).
    pub next_active: Option<Flags>,
}

/// `STUDY/.partial/RUN.json`.
pub(super) fn file(dir: &StudyDir, run: &str) -> PathBuf {
    dir.root.join(".partial").join(format!("{run}.json"))
}

/// The checkpoint of `spec`'s run, if there is one for exactly this spec (one of another spec,
/// or one that does not parse, is ignored: the run starts over and replaces it).
pub(super) fn read(dir: &StudyDir, spec: &RunSpec) -> Option<Checkpoint> {
    let text = crate::records::read_text(&file(dir, &spec.id)).ok()?;
    let c: Checkpoint = serde_json::from_str(&text).ok()?;
    let consistent = c.run == *spec && !c.levels.is_empty() && c.levels.len() == c.history.levels.len();
    consistent.then_some(c)
}

/// Write the checkpoint atomically (a temporary file, then a rename).
pub(super) fn write(dir: &StudyDir, checkpoint: &Checkpoint) -> Result<()> {
    let path = file(dir, &checkpoint.run.id);
    let written = crate::records::write_json(&path, checkpoint);
    // another run's `remove` may take `.partial/` away between its creation and the write: once more
    let written = match written {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => crate::records::write_json(&path, checkpoint),
        other => other,
    };
    written.with_context(|| format!("keeping the run in progress in {}", path.display()))
}

/// Remove the run's checkpoint (and its temporary files), and `.partial/` once it is empty.
pub(super) fn remove(dir: &StudyDir, run: &str) -> Result<()> {
    let path = file(dir, run);
    let partial = dir.root.join(".partial");
    let own_temporary = format!(".{run}.json.tmp");
    if let Ok(entries) = std::fs::read_dir(&partial) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with(&own_temporary) && crate::records::is_temporary(&name) {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
    match std::fs::remove_file(&path) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(e).with_context(|| format!("removing {}", path.display())),
    }
    // fails while another run's checkpoint is there: then it stays
    let _ = std::fs::remove_dir(&partial);
    Ok(())
}
