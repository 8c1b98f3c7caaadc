//! The read side of the store's door: a [`Shelf`] of checked study folders, what `figures`,
//! `report`, `claims` and drift's CLAIMS rows read. It is made only by [`Shelf::open`], which
//! reads every study through [`Store::read`] (the integrity check: a folder at fault is an error
//! naming the file); then it hands out each study's records as checked, the mesh snapshots a
//! record saves, the provenance text and the problem a run solved. Nothing above the store
//! reads a results file itself.

use super::Store;
use crate::records::{MeshSnapshot, RunRecord, RunSpec};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What the shelf cannot hand out.
#[derive(Debug, thiserror::Error)]
pub enum ShelfError {
    /// A study the shelf was not opened with (its folder was never checked).
    #[error("study {study} was not read through the integrity check of {root} (a reader asked for a study it did not open)")]
    NotOpened { study: String, root: PathBuf },
    /// A run the study does not hold.
    #[error("{study} holds no run {run}")]
    NoRun { study: String, run: String },
    /// A level whose snapshot the run's record does not save.
    #[error("run {study}/{run} saves no mesh snapshot of level {level}")]
    NotSaved { study: String, run: String, level: usize },
    /// A snapshot that went away or changed since the check.
    #[error("reading {}: {source}", file.display())]
    Snapshot { file: PathBuf, source: std::io::Error },
}

/// One checked study: its store, records (in file-name order) and provenance text.
#[derive(Debug)]
struct Shelved {
    store: Store,
    runs: Vec<RunRecord>,
    provenance: Option<String>,
    /// Whether its folder holds a `runs/` folder ([`Shelf::held`]).
    held: bool,
    /// What its manifest declares that the folder does not hold as declared, where the shelf
    /// was opened with its manifest ([`Shelf::not_as_declared`]).
    not_as_declared: Vec<String>,
}

/// A read-only view of the checked study folders of one results folder.
#[derive(Debug)]
pub struct Shelf {
    root: PathBuf,
    studies: BTreeMap<String, Shelved>,
}

impl Shelf {
    /// Read every one of `stores` (study folders under `results`) through [`Store::read`]: the
    /// first folder that does not hold together is an error naming its files. A study whose
    /// folder does not exist is on the shelf with no runs.
    pub fn open(results: &Path, stores: impl IntoIterator<Item = Store>) -> anyhow::Result<Shelf> {
        let mut studies = BTreeMap::new();
        for store in stores {
            let runs = store.read()?;
            let provenance = crate::records::read_text(&store.dir().provenance_file()).ok();
            let held = store.dir().root.join("runs").is_dir();
            studies.insert(store.study().to_string(), Shelved { store, runs, provenance, held, not_as_declared: Vec::new() });
        }
        Ok(Shelf { root: results.to_path_buf(), studies })
    }

    /// The shelf of a whole results folder: every study of `manifests` (a refusal names its
    /// manifest) and every other study the folder holds ([`Shelf::in_folder`]).
    pub fn open_folder(results: &Path, manifests: &[crate::study::manifest::Manifest]) -> anyhow::Result<Shelf> {
        let declared = manifests.iter().map(|m| Store::of(results, m));
        let others = Shelf::in_folder(results)?.into_iter().filter(|s| !manifests.iter().any(|m| &m.study == s));
        let mut shelf = Shelf::open(results, declared.chain(others.map(|s| Store::new(results, &s)).collect::<Vec<_>>()))?;
        for m in manifests {
            if let Some(s) = shelf.studies.get_mut(&m.study) {
                s.not_as_declared = m
                    .runs
                    .iter()
                    .filter_map(|p| match s.runs.iter().find(|r| r.run.id == p.spec.id) {
                        None => Some(format!("{} (missing)", p.spec.id)),
                        Some(r) if r.run != p.spec => Some(format!("{} (computed with another spec)", p.spec.id)),
                        Some(_) => None,
                    })
                    .collect();
            }
        }
        Ok(shelf)
    }

    /// The runs `study`'s manifest declares that its folder does not hold as declared, each
    /// with why ("r2 (missing)"): empty for a complete study, or one the shelf was opened
    /// without the manifest of. What `report` says on the page and on stderr (`figures`
    /// refuses such a folder).
    pub fn not_as_declared(&self, study: &str) -> &[String] {
        self.studies.get(study).map_or(&[], |s| &s.not_as_declared)
    }

    /// The studies under `results` (folders holding a `runs/` folder, or one another process
    /// writes now: `run --fresh` removes `runs/` before it writes it again, and a reader then
    /// names that process, through [`Store::check`], rather than finding no study; so is one
    /// whose lock file is not a file, which the check refuses naming it), by name:
    /// what [`Shelf::open`] is given for a whole folder.
    pub fn in_folder(results: &Path) -> std::io::Result<Vec<String>> {
        let read = std::fs::read_dir(results).map_err(|e| std::io::Error::new(e.kind(), format!("reading {}: {e}", results.display())))?;
        let mut out = Vec::new();
        for e in read {
            let e = e?;
            let d = e.path();
            if d.join("runs").is_dir()
                || !matches!(super::lock::writer_of(&crate::records::StudyDir::new(results, &e.file_name().to_string_lossy())), Ok(None))
            {
                out.push(e.file_name().to_string_lossy().into_owned());
            }
        }
        out.sort();
        Ok(out)
    }

    /// Wait until no other process writes any study folder under `results` (`figures --wait`,
    /// `report --wait`): what a reader does, before it opens the shelf, where another process
    /// may still be writing (a Slurm array's finish job, while a second array of the same study
    /// holds the folder). A writer that starts after the wait is refused by the read as usual.
    pub fn wait_for_writers(results: &Path) -> anyhow::Result<()> {
        if !results.is_dir() {
            return Ok(());
        }
        for study in Shelf::in_folder(results)? {
            super::lock::wait_for_writers(&crate::records::StudyDir::new(results, &study))?;
        }
        Ok(())
    }

    /// The results folder the studies are in (for messages).
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The studies on the shelf, by name.
    pub fn studies(&self) -> impl Iterator<Item = &str> {
        self.studies.keys().map(String::as_str)
    }

    /// The studies on the shelf whose folder holds a `runs/` folder, by name.
    pub fn held(&self) -> Vec<String> {
        self.studies.iter().filter(|(_, s)| s.held).map(|(name, _)| name.clone()).collect()
    }

    /// The study as checked; `None` for one the shelf was not opened with whose folder does not
    /// exist (nothing to check: no runs). A folder that exists but was not checked is an error.
    fn shelved(&self, study: &str) -> Result<Option<&Shelved>, ShelfError> {
        match self.studies.get(study) {
            Some(s) => Ok(Some(s)),
            None if !self.folder(study).exists() => Ok(None),
            None => Err(ShelfError::NotOpened { study: study.to_string(), root: self.root.clone() }),
        }
    }

    fn folder(&self, study: &str) -> PathBuf {
        crate::records::StudyDir::new(&self.root, study).root
    }

    /// The records of `study` as checked, in file-name order.
    pub fn runs(&self, study: &str) -> Result<Vec<RunRecord>, ShelfError> {
        Ok(self.shelved(study)?.map(|s| s.runs.clone()).unwrap_or_default())
    }

    /// The shelf with every record altered by `f` in memory (nothing on disk changes): what a
    /// test of the verdicts uses to show that each kind of row can fail.
    pub fn alter(mut self, mut f: impl FnMut(&mut RunRecord)) -> Shelf {
        for s in self.studies.values_mut() {
            s.runs.iter_mut().for_each(&mut f);
        }
        self
    }

    /// The folder of `study`'s records (for messages).
    pub fn runs_folder(&self, study: &str) -> Result<PathBuf, ShelfError> {
        self.shelved(study)?;
        Ok(self.folder(study).join("runs"))
    }

    /// The folder of `study`'s mesh snapshots (for messages).
    pub fn meshes_folder(&self, study: &str) -> Result<PathBuf, ShelfError> {
        self.shelved(study)?;
        Ok(self.folder(study).join("meshes"))
    }

    /// The levels whose mesh snapshot run `run` of `study` saves (the check found each one
    /// present and parsing), ascending; none for a run the study does not hold.
    pub fn saved_levels(&self, study: &str, run: &str) -> Result<Vec<usize>, ShelfError> {
        Ok(self.shelved(study)?.and_then(|s| s.runs.iter().find(|r| r.run.id == run)).map(RunRecord::saved_levels).unwrap_or_default())
    }

    /// The mesh snapshot of run `run` of `study` at `level`, one its record saves.
    pub fn mesh(&self, study: &str, run: &str, level: usize) -> Result<MeshSnapshot, ShelfError> {
        let Some((shelved, record)) = self.shelved(study)?.and_then(|s| s.runs.iter().find(|r| r.run.id == run).map(|r| (s, r))) else {
            return Err(ShelfError::NoRun { study: study.to_string(), run: run.to_string() });
        };
        if !record.saved_levels().contains(&level) {
            return Err(ShelfError::NotSaved { study: study.to_string(), run: run.to_string(), level });
        }
        let dir = shelved.store.dir();
        dir.read_mesh(record, level).map_err(|source| ShelfError::Snapshot { file: dir.mesh_file(run, level, "json"), source })
    }

    /// The snapshot of the largest level run `run` of `study` saves, if any.
    pub fn latest_mesh(&self, study: &str, run: &str) -> Result<Option<MeshSnapshot>, ShelfError> {
        match self.saved_levels(study, run)?.last() {
            Some(&level) => self.mesh(study, run, level).map(Some),
            None => Ok(None),
        }
    }

    /// The path the snapshot of `run` at `level` of `study` has (or would have): for messages.
    pub fn mesh_path(&self, study: &str, run: &str, level: usize) -> Result<PathBuf, ShelfError> {
        self.shelved(study)?;
        Ok(crate::records::StudyDir::new(&self.root, study).mesh_file(run, level, "json"))
    }

    /// The text of `study`'s `provenance.json` as read when the shelf was opened, if it had one.
    pub fn provenance_text(&self, study: &str) -> Result<Option<&str>, ShelfError> {
        Ok(self.shelved(study)?.and_then(|s| s.provenance.as_deref()))
    }

    /// The problem a stored run of `study` solved ([`crate::study::stored_problem`]).
    pub fn problem(&self, study: &str, spec: &RunSpec) -> anyhow::Result<Box<dyn model::problems::Problem>> {
        if self.shelved(study)?.is_none() {
            return Err(ShelfError::NoRun { study: study.to_string(), run: spec.id.clone() }.into());
        }
        crate::study::stored_problem(&self.root, study, spec)
    }
}

/// For the readers whose errors travel as I/O errors (the CLAIMS rows): the message kept.
impl From<ShelfError> for std::io::Error {
    fn from(e: ShelfError) -> Self {
        match e {
            ShelfError::Snapshot { ref source, .. } => std::io::Error::new(source.kind(), e.to_string()),
            other => std::io::Error::other(other.to_string()),
        }
    }
}
