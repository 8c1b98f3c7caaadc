//! `drift --accept STUDY`: the study rerun in full and its stored results replaced by the rerun,
//! without a moment at which a stored run is lost. The rerun goes into a staging folder beside
//! the results (`RESULTS/.accept/STUDY`, a folder no study can be named after); only when every
//! run of it has finished is the study swapped, as one change through the study's journal
//! ([`::store::records::journal`]): every file of the rerun renamed into place and every old file
//! it does not replace removed. Stopped before the swap (an interrupt, a kill, a failed run) the
//! stored study is as it was; stopped during it, the next writer of the study completes it.

use super::{Manifest, RunOptions};
use ::store::records::{StudyDir, journal::Journal};
use ::store::study::store::{Store, owned};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// The folder the reruns of `drift --accept` are staged in, inside the results root.
pub const STAGING: &str = ::store::records::journal::STAGING;

/// `drift --accept` stopped by an interrupt before the swap (exit status 130): the stored study
/// is unchanged.
#[derive(Debug, thiserror::Error)]
#[error(
    "drift --accept {study}: interrupted while rerunning it into {staging}; {stored} is unchanged (every stored run kept). Run `signorini drift --accept {study}` again: it starts the rerun over"
)]
pub struct AcceptInterrupted {
    pub study: String,
    pub staging: PathBuf,
    pub stored: PathBuf,
}

/// Rerun `manifest`'s study in full into the staging folder, then swap it into `results`.
/// Refused before anything is computed if the stored folder holds files the store did not
/// write or another process writes it; refused at the swap (the rerun kept in the staging
/// folder) if the stored runs changed meanwhile.
pub fn accept(manifest: &Manifest, results: &Path, progress: bool) -> Result<()> {
    let live = Store::of(results, manifest);
    let dir = live.dir().clone();
    let foreign = owned::inventory(&dir)?.foreign;
    if !foreign.is_empty() {
        return Err(owned::refusal(&format!("drift --accept {}", manifest.study), &dir, &foreign));
    }
    // refused now, not after the rerun, if another process writes the study; no process
    // computes a run of it until the swap
    let declared: Vec<String> = manifest.runs.iter().map(|p| p.spec.id.clone()).collect();
    let (writer, _held) = live.lock_every_run(None, &declared, false)?;
    let before = fingerprint(&writer.check()?.runs);
    drop(writer);
    let staging = results.join(STAGING);
    let options =
        RunOptions { quick: false, shard: None, fresh: true, replace: false, results: staging.clone(), progress, wait_for_lock: false };
    super::run_study(manifest, &options).map_err(|e| match e.downcast_ref::<super::Interrupted>() {
        Some(_) => {
            AcceptInterrupted { study: manifest.study.clone(), staging: staging.join(&manifest.study), stored: dir.root.clone() }.into()
        }
        None => e.context(format!(
            "drift --accept {}: the rerun into {} failed; {} is unchanged",
            manifest.study,
            staging.display(),
            dir.root.display()
        )),
    })?;
    let writer = live.lock(false)?;
    let now = fingerprint(&writer.check()?.runs);
    if now != before {
        bail!(
            "drift --accept {}: the stored runs in {} changed while the study was rerun (another process stored or removed runs); nothing was swapped, the rerun is in {}. Run `signorini drift --accept {}` again once the other process is done",
            manifest.study,
            dir.root.display(),
            staging.join(&manifest.study).display(),
            manifest.study
        );
    }
    swap(&dir, &StudyDir::new(&staging, &manifest.study))?;
    drop(writer);
    remove_staging(&staging, &manifest.study);
    Ok(())
}

/// The stored runs as (id, SHA-256 of the record file), to tell whether they changed.
fn fingerprint(runs: &[::store::records::RunRecord]) -> Vec<(String, String)> {
    runs.iter().map(|r| (r.run.id.clone(), ::store::records::record_sha256(r))).collect()
}

/// Every data file of `staged` renamed onto its place in `live`, every data file of `live` it
/// does not replace removed: one change, through `live`'s journal.
fn swap(live: &StudyDir, staged: &StudyDir) -> Result<()> {
    let new = owned::inventory(staged)?;
    let old = owned::inventory(live)?;
    let relative =
        |dir: &StudyDir, p: &Path| p.strip_prefix(&dir.root).map(Path::to_path_buf).expect("an inventory lists paths in its folder");
    // the staged folder as the journal reaches it from the live one: `../.accept/STUDY`
    let up = Path::new("..").join(STAGING).join(live.root.file_name().unwrap_or_default());
    let names: Vec<PathBuf> = new
        .data
        .iter()
        .filter(|p| !p.file_name().is_some_and(|n| ::store::records::is_temporary(&n.to_string_lossy())))
        .map(|p| relative(staged, p))
        .collect();
    let journal = Journal {
        renames: names.iter().map(|n| (up.join(n), n.clone())).collect(),
        removals: old.data.iter().map(|p| relative(live, p)).filter(|p| !names.contains(p)).collect(),
    };
    journal.commit(&live.root).with_context(|| format!("swapping the rerun into {}", live.root.display()))
}

/// The staging folder of a study, once swapped (what is left is only its locks).
fn remove_staging(staging: &Path, study: &str) {
    let folder = staging.join(study);
    model::base::failpoint::step("remove folder", &folder);
    let _ = std::fs::remove_dir_all(&folder);
    let _ = std::fs::remove_dir(staging);
}
