//! The study folder `results/STUDY/` kept readable and consistent whatever happens, behind one
//! door: [`Store`]. Every reader and writer of a study folder goes through it; the folder's
//! invariants live in its modules and nowhere else:
//! - [`check`]: the integrity check every reader runs first (`run`, `drift` on both sides of
//!   `--against`, `figures`, `report`): each record's run id is its file name, every snapshot it
//!   saves exists and parses, the summaries and references match the records; a folder at fault
//!   is refused naming the file (`run --replace` replaces the records at fault). What a killed
//!   process leaves (temporary files, snapshots of a run without a record) is a leftover: named
//!   and ignored by readers, removed by the next run.
//! - [`mod@write`]: every change needs the guard of a lock ([`Store::lock`] for the shared files,
//!   [`Store::lock_run`] for a run being computed). A finished run lands in one [`Batch`](crate::records::Batch): its
//!   mesh snapshots (written while it ran), its record and the summaries listing it
//!   (`levels.csv`, `provenance.json`) are written in full to temporary files, then renamed into
//!   place ([`Writer::commit_run`]); a run that stops leaves nothing. The summaries are rewritten
//!   only when their content would change: a run that executes nothing changes no file.
//! - [`stale`]: a stored run is never replaced silently; a manifest whose run differs from the
//!   stored one, or a stored run the manifest does not declare, is refused unless told to
//!   replace it; the runner repeats the check under the run's lock, and `--fresh` holds every run
//!   lock of the study before it removes anything ([`Store::lock_every_run`]).
//! - [`checkpoint`]: a run in progress kept after every level, to resume from.
//! - [`shelf`]: the read side: a [`Shelf`] of study folders, made only after each passed
//!   [`Store::read`], is all that figures, claims and the report pages read.

pub mod check;
pub mod checkpoint;
mod lock;
pub mod owned;
pub use lock::{BeingWritten, Held, scratch_folder};
pub mod shelf;
pub mod stale;
pub mod write;

pub use check::{Checked, Fault, first_difference};
pub use shelf::{Shelf, ShelfError};
pub use stale::Stale;
pub use write::{RunWriter, Writer};

use crate::records::{ReferenceRecord, RunRecord, RunSpec, StudyDir};
use crate::study::provenance::Provenance;
use anyhow::{Context, Result, bail};
use std::path::PathBuf;

/// The study folder that holds `path` (the path itself or a folder above it), if any: a folder
/// holding `runs/`, `.lock` or `.locks` (what a study folder has once a run was stored or
/// locked in it). Symlinks are followed (the deepest existing folder on the way is resolved),
/// so a link into a study folder is found too. An output flag of the command line refuses a
/// target there: every write into a study folder goes through the guard of a lock
/// ([`mod@write`]), and an output written past it replaced run records and snapshots.
pub fn study_folder_above(path: &std::path::Path) -> Option<PathBuf> {
    let absolute = std::path::absolute(path).ok()?;
    // resolve what exists (symlinks), keep the rest as written
    let existing = absolute.ancestors().find(|a| a.exists())?;
    let resolved = existing.canonicalize().ok()?;
    let rest = absolute.strip_prefix(existing).ok()?;
    let full = if rest.as_os_str().is_empty() { resolved } else { resolved.join(rest) };
    let is_study = |d: &std::path::Path| d.join("runs").is_dir() || d.join(".locks").is_dir() || d.join(".lock").is_file();
    full.ancestors().find(|d| is_study(d)).map(|d| d.to_path_buf())
}

/// Why `results` cannot be a results root, if it cannot: it lies inside a study folder
/// ([`study_folder_above`]: the folder itself, its `runs/`, `meshes/` or any folder below), where
/// studies stored by it would mix with the study's own files, and `--fresh` or `--replace` of
/// either would remove the other's. The one rule every `--results` (and `--against`) is held to.
pub fn results_place_fault(results: &std::path::Path) -> Option<String> {
    // the staging folder of `drift --accept` (RESULTS/.accept) is the store's: an accept of
    // RESULTS reruns into RESULTS/.accept/STUDY and removes it, with what was stored there
    let staging = crate::records::journal::STAGING;
    let absolute = std::path::absolute(results).unwrap_or_else(|_| results.to_path_buf());
    let resolved = absolute.ancestors().find(|a| a.exists()).and_then(|a| a.canonicalize().ok());
    if absolute.components().chain(resolved.iter().flat_map(|r| r.components())).any(|c| c.as_os_str() == staging) {
        return Some(format!(
            "{} is inside a staging folder of drift --accept ({staging}/ of a results root), which the next accept there reruns into and removes. Give a folder outside it",
            results.display()
        ));
    }
    let study = study_folder_above(results)?;
    Some(format!(
        "{} is inside the study folder {} (it holds runs/, .lock or .locks): a results root holds study folders and is never inside one. Give a folder outside it (e.g. beside it)",
        results.display(),
        study.display()
    ))
}

/// The one door to a study's results folder (`results/STUDY/`): readers check it as a whole
/// ([`Store::check`], [`Store::read`]); writers hold its locks ([`Store::lock`],
/// [`Store::lock_run`]) and change it only through the guards they return.
#[derive(Clone, Debug)]
pub struct Store {
    dir: StudyDir,
    study: String,
    /// The manifest the study is declared in, where known: named in the advice of a refusal.
    manifest: Option<PathBuf>,
}

impl Store {
    pub fn new(results: &std::path::Path, study: &str) -> Self {
        Store { dir: StudyDir::new(results, study), study: study.to_string(), manifest: None }
    }

    /// The store of `manifest`'s study in `results`, naming the manifest in its advice.
    pub fn of(results: &std::path::Path, manifest: &crate::study::manifest::Manifest) -> Self {
        Store { manifest: Some(manifest.file.clone()), ..Store::new(results, &manifest.study) }
    }

    /// The command that replaces what is at fault in this folder.
    fn replace_command(&self) -> String {
        let manifest = self.manifest.clone().unwrap_or_else(|| PathBuf::from("experiments").join(format!("{}.toml", self.study)));
        let results = self.dir.root.parent().filter(|r| *r != std::path::Path::new("results"));
        let results = results.map(|r| format!(" --results {}", r.display())).unwrap_or_default();
        format!("signorini run {} --replace{results}", manifest.display())
    }

    /// The folder's layout (paths only; reading and writing go through the store).
    pub fn dir(&self) -> &StudyDir {
        &self.dir
    }

    pub fn study(&self) -> &str {
        &self.study
    }

    /// The study lock: refused naming the holder if another process holds it, unless `wait`.
    /// Its guard is the only way to change the folder's shared files.
    /// Before its guard is handed out, a change another process left part-way is carried out
    /// ([`records::journal::roll_forward`]), so every writer starts from a whole folder.
    pub fn lock(&self, wait: bool) -> Result<Writer<'_>> {
        let writer = Writer { store: self, _lock: lock::Lock::study(&self.dir, wait)? };
        let rolled = crate::records::journal::roll_forward(&self.dir.root)
            .with_context(|| format!("completing the change a stopped process left in {}", self.dir.root.display()))?;
        if let Some(journal) = rolled {
            model::base::note::line(format_args!(
                "{}: completed a change a stopped process left part-way ({} file(s) put into place, {} removed)",
                self.study,
                journal.renames.len(),
                journal.removals.len()
            ));
        }
        Ok(writer)
    }

    /// The lock of run `id`, held while this process computes it: refused naming the process
    /// that computes it, unless `wait`. (Taken briefly under the study lock: do not hold a
    /// [`Writer`] while asking.)
    pub fn lock_run(&self, id: &str, wait: bool) -> Result<RunWriter<'_>> {
        Ok(RunWriter { store: self, id: id.to_string(), _lock: lock::Lock::run(&self.dir, id, wait)? })
    }

    /// `--fresh`: the lock of every run this process would remove (`only`, a shard's runs; or
    /// every run of the study: `declared`, and any run stored, locked or checkpointed), then the
    /// study lock, so that no file of a run another process computes is removed. The run locks
    /// are taken one by one without the study lock (the owner of one takes the study lock to
    /// store its run); a run that started meanwhile is found under the study lock, and then
    /// everything is let go and taken again. Held by another process: refused naming it, or
    /// with `wait` waited for.
    pub fn lock_every_run(&self, only: Option<&[String]>, declared: &[String], wait: bool) -> Result<(Writer<'_>, Vec<RunWriter<'_>>)> {
        if !wait {
            // refused at once if another process sets up or stores (taking the run locks below
            // waits for the study lock briefly, as every run does)
            drop(self.lock(false)?);
        }
        loop {
            let ids = match only {
                Some(ids) => ids.to_vec(),
                None => lock::runs_of(&self.dir, declared.iter().cloned()),
            };
            let mut held = Vec::new();
            for id in &ids {
                // the advice is for a lock another process holds, not for a failure to lock
                let lock = self.lock_run(id, wait).map_err(|e| match e.downcast_ref::<Held>() {
                    Some(_) => e.context("--fresh removes every run of the study; it waits for none without --wait"),
                    None => e,
                })?;
                held.push(lock);
            }
            let writer = self.lock(wait)?;
            if only.is_some() {
                return Ok((writer, held));
            }
            let started: Vec<String> = lock::runs_of(&self.dir, std::iter::empty())
                .into_iter()
                .filter(|id| !ids.contains(id) && lock::run_in_progress(&self.dir, id))
                .collect();
            if started.is_empty() {
                return Ok((writer, held));
            }
            if !wait {
                bail!(
                    "--fresh: run(s) {} of {} started meanwhile; pass --wait to wait for them",
                    started.join(", "),
                    self.dir.root.display()
                );
            }
        }
    }

    /// Every run record as it is, unchecked (an unreadable one is an error naming it): what the
    /// writers re-read under the lock. Readers use [`Store::read`].
    pub fn records(&self) -> Result<Vec<RunRecord>> {
        self.dir.read_runs().with_context(|| format!("reading the runs in {}", self.dir.root.join("runs").display()))
    }

    /// Whether run `spec.id` is stored with exactly `spec` and no process computes it now: a
    /// run another process replaces is not finished, its record is about to change (a run
    /// that called it "kept" then exited 0 while the folder ended with the other's run).
    /// Asked under the study lock, as every look at another process's run lock is.
    pub fn finished(&self, spec: &RunSpec) -> Result<bool> {
        let _study = lock::Lock::study(&self.dir, true)?;
        Ok(!lock::run_in_progress(&self.dir, &spec.id) && self.record(&spec.id)?.is_some_and(|r| r.run == *spec))
    }

    /// The stored record of run `id`, if any.
    pub fn record(&self, id: &str) -> Result<Option<RunRecord>> {
        self.dir.read_run(id).with_context(|| format!("reading the stored run {id}"))
    }

    /// The stored reference solution of `key` (`references/KEY.json`), if any.
    pub fn reference(&self, key: &str) -> Result<Option<ReferenceRecord>> {
        let file = self.dir.reference_file(key);
        self.dir.read_reference(key).with_context(|| format!("reading {}", file.display()))
    }

    /// `provenance.json`.
    pub fn provenance(&self) -> Result<Provenance> {
        let file = self.dir.provenance_file();
        let text = crate::records::read_text(&file)?;
        serde_json::from_str(&text).with_context(|| format!("reading {}", file.display()))
    }

    /// [`Store::scan`] for a reader: refused first, naming the process, if another process
    /// writes the folder now ([`BeingWritten`]); then the folder's records and faults as they are.
    /// A process holding a lock of the folder checks through its guard ([`Writer::check`]).
    pub fn check(&self) -> Result<Checked> {
        if let Some(written) = lock::writer_of(&self.dir)? {
            return Err(written.into());
        }
        self.scan()
    }

    /// Read the folder and check that it holds together: every record's run id is its file
    /// name (so each run is stored once) and its study is this one; every mesh snapshot a record
    /// saves exists and parses, as the level it names; `levels.csv` and `provenance.json` are
    /// what the records render ([`check::summary_faults`]). A record file that does not parse is
    /// a fault of the run its file stem names.
    fn scan(&self) -> Result<Checked> {
        let pending = crate::records::journal::pending(&self.dir.root);
        if let Err(e) = &pending
            && e.kind() == std::io::ErrorKind::InvalidData
        {
            bail!("{e}; nothing was read");
        }
        if pending.map_or(true, |j| j.is_some()) {
            bail!(
                "{}: a change to this folder was stopped part-way ({} lists it); nothing was read. The next command that writes the study completes it: `{}` (it computes nothing that is stored already)",
                self.dir.root.display(),
                self.dir.root.join(crate::records::journal::FILE).display(),
                self.replace_command().replace(" --replace", "")
            );
        }
        let files = self.dir.read_run_files().with_context(|| format!("reading the runs in {}", self.dir.root.join("runs").display()))?;
        let mut faults = Vec::new();
        let mut runs = Vec::new();
        for (file, text, record) in files {
            let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            let mut fault =
                |file: &std::path::Path, what: String| faults.push(Fault { file: file.to_path_buf(), what, record: Some(stem.clone()) });
            // a file that is no record (truncated, not JSON, a link to another file) is a fault
            // of the run its name says, which `run --replace` removes and computes again
            let record = match record {
                Ok(record) => record,
                Err(e) => {
                    fault(&file, format!("is not a run record (truncated, or not JSON): {e}"));
                    continue;
                }
            };
            if record.run.id != stem {
                fault(
                    &file,
                    format!("holds run {}, not {stem} (a record's run id is its file name: a copy or a renamed file?)", record.run.id),
                );
                runs.push(record);
                continue;
            }
            // what the harness writes for this record, byte for byte: an unknown field (which
            // serde would drop silently), a hand edit that reformats, or a record of another
            // version of the format is a fault of its run
            if let Ok(written) = crate::records::json_bytes(&file, &record)
                && written != text.as_bytes()
            {
                let (stored, expected) = check::first_difference(&text, &String::from_utf8_lossy(&written));
                fault(
                    &file,
                    format!(
                        "is not what the harness writes for the run it holds: {stored}, written {expected} (an unknown field or a hand edit?)"
                    ),
                );
            }
            if record.study != self.study {
                fault(&file, format!("is a record of study {}, not {}", record.study, self.study));
            }
            for (path, what) in check::snapshot_faults(&self.dir, &record) {
                fault(&path, what);
            }
            runs.push(record);
        }
        faults.extend(check::summary_faults(&self.dir, &self.study, &runs));
        faults.extend(check::reference_faults(&self.dir, &runs));
        let leftovers = check::orphans(&self.dir, &runs)?;
        Ok(Checked { runs, faults, leftovers })
    }

    /// [`Store::check`] for a reader: the records of a sound folder (its leftovers named on
    /// stderr and ignored); a fault is an error naming every one.
    pub fn read(&self) -> Result<Vec<RunRecord>> {
        let checked = self.check()?;
        if !checked.faults.is_empty() {
            anyhow::bail!(
                "{} does not hold together:{}\nRerun the runs at fault with `{}` (or restore the files)",
                self.dir.root.display(),
                checked.faults_text(),
                self.replace_command()
            );
        }
        self.note_leftovers(&checked.leftovers);
        Ok(checked.runs)
    }

    /// Name the leftovers of an unfinished run a reader ignores, in one line.
    pub fn note_leftovers(&self, leftovers: &[PathBuf]) {
        if !leftovers.is_empty() {
            model::base::note::line(format_args!(
                "{}: ignoring {} file(s) of an unfinished run in {} (`signorini run` removes them): {}",
                self.study,
                leftovers.len(),
                self.dir.root.display(),
                check::names(&self.dir, leftovers)
            ));
        }
    }
}
