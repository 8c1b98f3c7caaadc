//! A run in progress, kept after every finished level: `STUDY/.partial/RUN.json` holds the
//! records and refinement history of the levels finished so far and the active set the next
//! level starts from. A run that is stopped (killed, out of time on a cluster) resumes after its
//! last finished level instead of from level 0 ([`crate::study::run_study`]), with the same numbers:
//! the next mesh is rebuilt from the initial one by the stored marks (`adapt::replay`). The
//! checkpoint is not a result: git ignores `.partial/`, and it is removed when the run lands.

use crate::records::{RunSpec, StudyDir};
use crate::study::provenance::CodeVersion;
use anyhow::{Context, Result};
use model::level::history::{Flags, History};
use model::level::record::LevelRecord;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    /// The spec of the run in progress: a checkpoint of another spec is not resumed.
    pub run: RunSpec,
    /// The code that computed the levels ([`crate::study::provenance::code_version`]): another
    /// build's levels are not resumed.
    pub code: CodeVersion,
    /// The SHA-256 of what a resume takes over (`levels`, `history`, `next_active`) as
    /// written ([`Checkpoint::content_sha256`]), set by [`write`]: an edited or damaged
    /// checkpoint is not resumed.
    #[serde(default)]
    pub sha256: String,
    pub levels: Vec<LevelRecord>,
    pub history: History,
    /// The warm start of the next level (None without warm starts).
    pub next_active: Option<Flags>,
}

impl Checkpoint {
    /// The SHA-256 of the JSON of what a resume takes over (the float fields are written and
    /// read back exactly: serde_json's `float_roundtrip`).
    pub fn content_sha256(&self) -> String {
        let json = serde_json::to_vec(&(&self.levels, &self.history, &self.next_active)).expect("a checkpoint serialises");
        model::base::digest::sha256_hex(&json)
    }

    /// Why this checkpoint, read back for `spec`'s run by `code`, is not resumed, if it is not.
    fn unusable(&self, spec: &RunSpec, code: &CodeVersion) -> Option<String> {
        if self.run != *spec {
            return Some(format!("it holds run {} with another spec (the manifest changed since it was written)", self.run.id));
        }
        if self.code != *code {
            return Some(format!(
                "it was written by other code ({}) than this ({}): the levels of two builds are not one run",
                self.code, code
            ));
        }
        let found = self.content_sha256();
        if found != self.sha256 {
            return Some(format!(
                "its levels are not what was written (sha256 {}, written with {}): edited or damaged",
                &found[..12],
                if self.sha256.is_empty() { "none".to_string() } else { self.sha256[..self.sha256.len().min(12)].to_string() }
            ));
        }
        if self.levels.is_empty() || self.levels.len() != self.history.levels.len() {
            return Some(format!("it holds {} level record(s) and {} level(s) of history", self.levels.len(), self.history.levels.len()));
        }
        None
    }
}

/// `STUDY/.partial/RUN.json`.
pub(super) fn file(dir: &StudyDir, run: &str) -> PathBuf {
    dir.root.join(".partial").join(format!("{run}.json"))
}

/// The checkpoint of `spec`'s run, if there is one it may resume from: of exactly this spec,
/// written by this `code`, its content the hash it was written with. Any other is discarded
/// with a line on stderr naming the file and why (one that does not parse, of another spec,
/// build or content): the run starts over and replaces it. None there: None, silently.
pub(super) fn read(dir: &StudyDir, spec: &RunSpec, code: &CodeVersion) -> Option<Checkpoint> {
    let path = file(dir, &spec.id);
    if std::fs::symlink_metadata(&path).is_err() {
        return None;
    }
    let parsed = crate::records::read_text(&path)
        .map_err(|e| format!("it cannot be read ({e})"))
        .and_then(|text| serde_json::from_str::<Checkpoint>(&text).map_err(|e| format!("it does not parse as a checkpoint ({e})")));
    let why = match &parsed {
        Ok(c) => c.unusable(spec, code),
        Err(e) => Some(e.clone()),
    };
    match why {
        None => parsed.ok(),
        Some(why) => {
            model::base::note::line(format_args!("{}: not resumed from: {why}; the run starts over", path.display()));
            None
        }
    }
}

/// Write the checkpoint atomically (a temporary file, then a rename), with the hash of its
/// content ([`Checkpoint::content_sha256`]) that [`read`] checks.
pub(super) fn write(dir: &StudyDir, checkpoint: &Checkpoint) -> Result<()> {
    let path = file(dir, &checkpoint.run.id);
    let sealed = Checkpoint { sha256: checkpoint.content_sha256(), ..checkpoint.clone() };
    let written = crate::records::write_json(&path, &sealed);
    // another run's `remove` may take `.partial/` away between its creation and the write: once more
    let written = match written {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => crate::records::write_json(&path, &sealed),
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
                model::base::failpoint::step("remove", &e.path());
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
    if path.exists() {
        model::base::failpoint::step("remove", &path);
    }
    match std::fs::remove_file(&path) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(e).with_context(|| format!("removing {}", path.display())),
    }
    // fails while another run's checkpoint is there: then it stays
    if partial.is_dir() {
        model::base::failpoint::step("remove folder", &partial);
        let _ = std::fs::remove_dir(&partial);
    }
    Ok(())
}
