//! The writers of a study folder. Every change goes through a guard of the lock that covers it,
//! so none can be made without the lock, by construction:
//! - [`Writer`] holds the study lock (`STUDY/.lock`): the shared files change only under it
//!   (storing a finished run with the summaries listing it, removing a run, the leftovers of an
//!   unfinished one, bringing the summaries in line, `--fresh`);
//! - [`RunWriter`] holds one run's lock (`STUDY/.locks/RUN.lock`) while the run is computed: its
//!   checkpoint and the mesh snapshots it stages are its own, and removing a stored run needs its
//!   lock too ([`Writer::claim_run`]), so no process removes what another computes.

use super::check::{files_in, orphans};
use super::lock::Lock;
use super::{Checked, Store, checkpoint, owned};
use crate::records::{self, Batch, ReferenceRecord, RunRecord, StudyDir};
use crate::study::manifest::Manifest;
use crate::study::provenance::{self, Provenance};
use anyhow::{Context, Result, bail};

/// The study lock, held: the only way to change a study folder's shared files.
pub struct Writer<'a> {
    pub(super) store: &'a Store,
    pub(super) _lock: Lock,
}

/// One run's lock, held: the run is computed (or removed) by this process and no other.
pub struct RunWriter<'a> {
    pub(super) store: &'a Store,
    pub(super) id: String,
    pub(super) _lock: Lock,
}

impl RunWriter<'_> {
    pub fn id(&self) -> &str {
        &self.id
    }

    /// Where the run's snapshot of `level` goes (`meshes/RUN_levelL.EXT`): staged in the run's
    /// batch while it computes, committed with its record ([`Writer::commit_run`]).
    pub fn snapshot_file(&self, level: usize, ext: &str) -> std::path::PathBuf {
        self.store.dir.mesh_file(&self.id, level, ext)
    }

    /// The run's checkpoint, if there is one for exactly `spec` written by `code`, as written
    /// (`checkpoint::read`; any other is discarded, saying why).
    pub fn checkpoint(&self, spec: &records::RunSpec, code: &provenance::CodeVersion) -> Option<checkpoint::Checkpoint> {
        checkpoint::read(&self.store.dir, spec, code)
    }

    /// `STUDY/.partial/RUN.json`, for messages.
    pub fn checkpoint_file(&self) -> std::path::PathBuf {
        checkpoint::file(&self.store.dir, &self.id)
    }

    /// Keep the run's levels so far (atomically), to resume from after a stop.
    pub fn keep(&self, kept: &checkpoint::Checkpoint) -> Result<()> {
        if kept.run.id != self.id {
            bail!("the checkpoint of run {} given to run {}", kept.run.id, self.id);
        }
        checkpoint::write(&self.store.dir, kept)
    }

    /// Add the reference solution the run is measured against to its batch, unless the study
    /// stores it already (the same history to the same NDF): it lands with the run.
    pub fn stage_reference(&self, reference: &ReferenceRecord, batch: &mut Batch) -> Result<()> {
        stage_reference(&self.store.dir, reference, batch)
    }
}

impl Writer<'_> {
    /// The folder checked as a whole ([`Store::scan`]) by the process that holds its study lock
    /// (a reader's [`Store::check`] would find this process's own locks and refuse).
    pub fn check(&self) -> Result<Checked> {
        self.store.scan()
    }

    /// The lock of a stored run this process does not compute, to remove it: at once, or
    /// refused naming the process that computes it.
    pub fn claim_run(&self, id: &str) -> Result<RunWriter<'_>> {
        Ok(RunWriter { store: self.store, id: id.to_string(), _lock: Lock::run_now(&self.store.dir, id)? })
    }

    /// Remove a run's record, its mesh snapshots (`meshes/RUN_levelL.*`) and its checkpoint.
    pub fn remove_run(&self, run: &RunWriter) -> Result<()> {
        checkpoint::remove(&self.store.dir, &run.id)?;
        self.remove_stored(run)
    }

    /// Remove a run's record and mesh snapshots (its checkpoint stays), as one change: the run is
    /// there whole or gone.
    fn remove_stored(&self, run: &RunWriter) -> Result<()> {
        self.same_folder(run)?;
        let dir = &self.store.dir;
        let mut removals: Vec<std::path::PathBuf> = snapshots_of(dir, &run.id)?;
        removals.insert(0, dir.run_file(&run.id));
        commit_as_one(dir, Batch::default(), removals)
    }

    /// `--fresh`: remove the runs this process holds (with a shard, only those: the other shards'
    /// are someone else's), or with `whole` every file of the study the store wrote (records,
    /// snapshots, references, checkpoints, summaries; [`owned::inventory`]), every run's lock
    /// being in `held` ([`Store::lock_every_run`]). A folder holding a file the store did not
    /// write is refused, naming it, before anything is removed. The removal is one change: an
    /// interrupt leaves the study whole or empty.
    pub fn start_over(&self, held: &[RunWriter], whole: bool) -> Result<()> {
        if !whole {
            return held.iter().try_for_each(|run| self.remove_run(run));
        }
        let dir = &self.store.dir;
        let found = owned::inventory(dir)?;
        if !found.foreign.is_empty() {
            return Err(owned::refusal("run --fresh", dir, &found.foreign));
        }
        commit_as_one(dir, Batch::default(), found.data)?;
        for sub in ["runs", "meshes", "references", ".partial"] {
            let folder = dir.root.join(sub);
            if folder.is_dir() {
                model::base::failpoint::step("remove folder", &folder);
                std::fs::remove_dir(&folder).with_context(|| format!("removing the emptied folder {}", folder.display()))?;
            }
        }
        Ok(())
    }

    /// Remove the leftovers of unfinished runs (`orphans`; a run another process computes
    /// now has none), saying so in one line that names them.
    pub fn remove_orphans(&self, runs: &[RunRecord]) -> Result<()> {
        let dir = &self.store.dir;
        let found = orphans(dir, runs)?;
        if found.is_empty() {
            return Ok(());
        }
        for f in &found {
            model::base::failpoint::step("remove", f);
            std::fs::remove_file(f).with_context(|| format!("removing {}", f.display()))?;
        }
        model::base::note::line(format_args!(
            "{}: removed {} file(s) of an unfinished run (no finished run accounts for them): {}",
            self.store.study,
            found.len(),
            super::check::names(dir, &found)
        ));
        Ok(())
    }

    /// Make `levels.csv` and `provenance.json` describe exactly `runs` (the runs present), writing
    /// only what would change: the CSV when its bytes differ, the provenance when it is missing,
    /// unreadable, lists other runs or lacks the hash of an input they read. (A provenance records who computed the runs; a process that
    /// computed none of them has nothing to add to it.) Both are written together.
    pub fn sync_summaries(&self, manifest: &Manifest, runs: &[RunRecord], quick: bool) -> Result<()> {
        let dir = &self.store.dir;
        let mut batch = Batch::default();
        let csv = csv_bytes(dir, runs)?;
        if crate::records::read_bytes(&dir.csv_file()).ok().as_deref() != Some(csv.as_slice()) {
            batch.add(&dir.csv_file(), &csv)?;
        }
        let ids: Vec<String> = runs.iter().map(|r| r.run.id.clone()).collect();
        let stale = |p: Provenance| p.runs != ids || super::check::input_not_in(&p, runs).is_some();
        if self.store.provenance().map_or(true, stale) {
            batch.add_json(&dir.provenance_file(), &provenance_of(manifest, runs, quick))?;
        }
        commit_as_one(dir, batch, Vec::new())
    }

    /// Store a finished run, computed under `run`'s lock. `batch` holds its mesh snapshots,
    /// written while it ran; its record and the summaries listing it join them, then the run's
    /// previous record and snapshots (a replaced run) are removed and everything is renamed into
    /// place; then its checkpoint goes. If a write fails, nothing of the run reaches the folder and
    /// no temporary file is left.
    pub fn commit_run(&self, run: &RunWriter, manifest: &Manifest, record: RunRecord, mut batch: Batch, quick: bool) -> Result<()> {
        self.same_folder(run)?;
        if record.run.id != run.id {
            bail!("the record of run {} committed under the lock of run {}", record.run.id, run.id);
        }
        let dir = &self.store.dir;
        let mut runs = self.sound_records(&run.id)?;
        let foreign: Vec<&str> = runs.iter().map(|r| r.run.id.as_str()).filter(|id| !declares(manifest, id)).collect();
        if !foreign.is_empty() {
            bail!(
                "{}: {} holds run(s) {}, which {} does not declare: another manifest of study {} stored them while run {} was computed. \
                 Run {} is not stored beside them (the folder would match neither manifest); rerun it into another --results folder, \
                 or with the manifest that declares every run",
                manifest.file.display(),
                dir.root.display(),
                foreign.join(", "),
                manifest.file.display(),
                manifest.study,
                run.id,
                run.id
            );
        }
        let record = RunRecord { snapshots: staged_snapshots(dir, &record, &batch)?, ..record };
        runs.retain(|r| r.run.id != run.id);
        runs.push(record.clone());
        runs.sort_by_key(|r| dir.run_file(&r.run.id));
        batch.add_json(&dir.run_file(&run.id), &record)?;
        batch.add(&dir.csv_file(), &csv_bytes(dir, &runs)?)?;
        batch.add_json(&dir.provenance_file(), &provenance_of(manifest, &runs, quick))?;
        // a replaced run's record is replaced by the rename; its snapshots of levels the new
        // run does not save go in the same change
        let staged: Vec<std::path::PathBuf> = batch.paths().map(std::path::Path::to_path_buf).collect();
        let removals = snapshots_of(dir, &run.id)?.into_iter().filter(|f| !staged.contains(f)).collect();
        commit_as_one(dir, batch, removals)?;
        checkpoint::remove(dir, &run.id)
    }

    /// Refused if another process computes a run of the study that `manifest` does not declare
    /// (another manifest of the same study, started before this one): run beside it, the
    /// folder would end with runs of both manifests and match neither.
    pub fn refuse_foreign_runs_in_progress(&self, manifest: &Manifest) -> Result<()> {
        let dir = &self.store.dir;
        let foreign: Vec<String> = super::lock::runs_of(dir, std::iter::empty())
            .into_iter()
            .filter(|id| !declares(manifest, id) && super::lock::run_in_progress(dir, id))
            .collect();
        if !foreign.is_empty() {
            bail!(
                "{}: another process computes run(s) {} of {}, which {} does not declare (another manifest of study {}); \
                 nothing was run. Run this manifest into another --results folder, or wait for the other to finish",
                manifest.file.display(),
                foreign.join(", "),
                dir.root.display(),
                manifest.file.display(),
                manifest.study
            );
        }
        Ok(())
    }

    /// Remove a stored reference solution (`references/KEY.json` at fault): the runs measured
    /// against it store it again, computed anew ([`Writer::commit_reference`]).
    pub fn remove_reference(&self, key: &str) -> Result<()> {
        let file = self.store.dir.reference_file(key);
        model::base::failpoint::step("remove", &file);
        match std::fs::remove_file(&file) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e).with_context(|| format!("removing {}", file.display())),
            _ => Ok(()),
        }
    }

    /// Store a reference solution of finished runs that the study does not hold yet.
    pub fn commit_reference(&self, reference: &ReferenceRecord) -> Result<()> {
        let mut batch = Batch::default();
        stage_reference(&self.store.dir, reference, &mut batch)?;
        commit_as_one(&self.store.dir, batch, Vec::new())
    }

    /// After a failure part-way through changing the folder (a removal or a rename that failed):
    /// remove the orphans and bring the summaries in line with the runs present.
    /// A record at fault is left as it is, and so are the summaries (never rendered from it):
    /// `run` refuses the folder naming it.
    pub fn repair(&self, manifest: &Manifest, quick: bool) -> Result<()> {
        let checked = self.check()?;
        self.remove_orphans(&checked.runs)?;
        if checked.faults.iter().any(|f| f.record.is_some()) {
            return Ok(());
        }
        self.sync_summaries(manifest, &checked.runs, quick)
    }

    /// The records, checked under the study lock as `run` checks them at its start
    /// ([`Store::check`]), for a commit to render the summaries from: a record at fault (edited
    /// while run `committing` computed; its own old record, which it replaces, aside) refuses
    /// the commit naming it, so an edit is never rendered into `levels.csv` and then passed as
    /// sound. Faults of the summaries alone are not the records': the commit renders them anew.
    fn sound_records(&self, committing: &str) -> Result<Vec<RunRecord>> {
        let checked = self.check()?;
        let at_fault: Vec<String> =
            checked.faults.iter().filter(|f| f.record.as_deref().is_some_and(|r| r != committing)).map(|f| format!("\n  {f}")).collect();
        if !at_fault.is_empty() {
            bail!(
                "run {committing} is not stored: {} does not hold together (changed while the run computed?):{}\n\
                 The summaries are rendered only from records that pass the check, so nothing was written (its checkpoint, if any, is kept). \
                 Rerun the runs at fault with `{}` (or restore the files)",
                self.store.dir.root.display(),
                at_fault.concat(),
                self.store.replace_command()
            );
        }
        Ok(checked.runs)
    }

    /// A run's lock is of this folder (two stores of one process must not mix their guards).
    fn same_folder(&self, run: &RunWriter) -> Result<()> {
        if run.store.dir.root != self.store.dir.root {
            bail!("run {} of {} changed under the lock of {}", run.id, run.store.dir.root.display(), self.store.dir.root.display());
        }
        Ok(())
    }
}

/// Commit `batch` and remove `removals` in the study folder as one change, through its journal
/// ([`records::journal`]). An error before the journal is on disk changes nothing (the staged
/// temporary files are removed); one after it leaves the journal, which the next writer carries
/// out ([`Store::lock`]).
fn commit_as_one(dir: &StudyDir, batch: Batch, removals: Vec<std::path::PathBuf>) -> Result<()> {
    let journal = batch.into_journal(&dir.root, removals)?;
    let Err(e) = journal.commit(&dir.root) else { return Ok(()) };
    if matches!(records::journal::pending(&dir.root), Ok(None)) {
        for (from, _) in &journal.renames {
            let _ = std::fs::remove_file(dir.root.join(from));
        }
    }
    Err(e).with_context(|| format!("changing {}", dir.root.display()))
}

/// The mesh snapshots of run `id` present in the folder (`meshes/RUN_levelL.*`).
fn snapshots_of(dir: &StudyDir, id: &str) -> Result<Vec<std::path::PathBuf>> {
    Ok(files_in(&dir.root.join("meshes"))?
        .into_iter()
        .filter(|(name, _)| StudyDir::parse_mesh_name(name).is_some_and(|(r, _)| r == id))
        .map(|(_, path)| path)
        .collect())
}

/// The provenance of the study as it is now, for these runs: the hashes of its input files are
/// those the runs read (planned with the manifest and pinned while each run computed), not
/// what the files hold now.
fn provenance_of(manifest: &Manifest, runs: &[RunRecord], quick: bool) -> Provenance {
    let ids = runs.iter().map(|r| r.run.id.clone()).collect();
    let mut prov = provenance::collect(&manifest.study, &manifest.file, &manifest.bytes, quick, ids, &[]);
    let planned = manifest.planned_hashes();
    let hash = |f: &std::path::Path| planned.get(f).cloned();
    prov.mesh_sha256 = manifest
        .mesh_files()
        .iter()
        .map(|m| (m.display().to_string(), hash(m).unwrap_or_else(|| "(not read by any run)".into())))
        .collect();
    prov.problem_files =
        manifest.problem_files().iter().map(|f| provenance::ProblemFile { path: f.display().to_string(), sha256: hash(f) }).collect();
    prov
}

fn csv_bytes(dir: &StudyDir, runs: &[RunRecord]) -> Result<Vec<u8>> {
    dir.csv_bytes(runs).with_context(|| format!("rendering {}", dir.csv_file().display()))
}

/// Add `reference` to `batch` unless the study stores it already (the same history to the
/// same NDF).
fn stage_reference(dir: &StudyDir, reference: &ReferenceRecord, batch: &mut Batch) -> Result<()> {
    let file = dir.reference_file(&reference.key());
    let same = |s: &ReferenceRecord| {
        s.rebuild.history == reference.rebuild.history && s.rebuild.ndof == reference.rebuild.ndof && s.key() == reference.key()
    };
    if !matches!(dir.read_reference(&reference.key()), Ok(Some(s)) if same(&s)) {
        batch.add_json(&file, reference)?;
    }
    Ok(())
}

/// The SHA-256 of each mesh snapshot `record` saves (JSON and VTU of every saved level), from
/// the bytes `batch` stages for it: the record stores exactly what is committed beside it. A
/// saved level the batch does not hold is an error (nothing is stored).
fn staged_snapshots(dir: &StudyDir, record: &RunRecord, batch: &Batch) -> Result<std::collections::BTreeMap<String, String>> {
    let mut out = std::collections::BTreeMap::new();
    for level in record.saved_levels() {
        for ext in ["json", "vtu"] {
            let file = dir.mesh_file(&record.run.id, level, ext);
            let Some(hash) = batch.sha256_of(&file) else {
                bail!("run {} saves level {level}, but its snapshot {} was not written", record.run.id, file.display());
            };
            let name = file.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            out.insert(name, hash.to_string());
        }
    }
    Ok(out)
}

/// Whether `manifest` declares run `id`.
fn declares(manifest: &Manifest, id: &str) -> bool {
    manifest.runs.iter().any(|p| p.spec.id == id)
}
