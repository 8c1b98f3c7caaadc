//! Where a command may write and read: output files and folders checked before any
//! computation (never inside a study folder, never a pipe, a device or a folder where a file
//! goes), results roots outside study folders, and readers that wait for writers.

use anyhow::{Context, Result, bail};
use store::study;

/// Refuse an output path whose folder does not exist, or that is not a file a write may replace
/// (a named pipe, a device such as /dev/null: the write renames a new file over it), before
/// hours of work are spent, not after.
pub fn check_writable(flag: &str, path: &std::path::Path) -> Result<()> {
    let dir = model::base::input::folder_of(path);
    if let Some(blocking) = dir.ancestors().find(|a| a.exists() && !a.is_dir()) {
        bail!("{flag} {}: {} is a file, not a folder", path.display(), blocking.display());
    }
    if !dir.is_dir() {
        bail!("{flag} {}: the folder {} does not exist", path.display(), dir.display());
    }
    if path.is_dir() {
        bail!("{flag} {}: this is a folder; give the path of a file in it, e.g. {}", path.display(), path.join("solution.vtu").display());
    }
    check_target(flag, path)?;
    // a file can be made there (the write goes through a temporary file in the same folder)
    let probe = dir.join(format!(".signorini-save-probe.{}", std::process::id()));
    std::fs::File::create(&probe).with_context(|| format!("{flag} {}: cannot create a file in {}", path.display(), dir.display()))?;
    std::fs::remove_file(&probe).ok();
    Ok(())
}

/// Refuse an output path a write may not replace (a named pipe, a device, a folder), naming the
/// flag; the same check every atomic write makes ([`model::base::input::check_target`]), made
/// here before any computation.
pub fn check_target(flag: &str, path: &std::path::Path) -> Result<()> {
    outside_study(flag, path)?;
    model::base::input::check_target(path).map_err(|e| anyhow::anyhow!("{flag} {}: {e}", path.display()))
}

/// Refuse an output path inside a results study folder (`STUDY/` holding `runs/`, `.lock` or
/// `.locks`, at any depth: [`study::store::study_folder_above`]): only `run` writes there, under
/// the study's lock, and a report, snapshot or page written past it replaced run records and
/// snapshots (the run lost, or the folder refused). Every output flag comes through here
/// ([`check_target`] for a file, [`output_folder`] for a folder), before any computation; the
/// outputs' defaults (`figures/`, `RESULTS/figures`, `RESULTS/report`, `DIR/drift-report.json`)
/// are beside the study folders, not in them.
pub fn outside_study(flag: &str, path: &std::path::Path) -> Result<()> {
    if let Some(dir) = study::store::study_folder_above(path) {
        // named as the user wrote it where it is on the path given
        let as_given = path.ancestors().find(|a| a.canonicalize().is_ok_and(|c| c == dir));
        let dir = as_given.map_or(dir.clone(), |a| a.to_path_buf());
        bail!(
            "{flag} {}: this is inside the study folder {} (it holds runs/, .lock or .locks), where only `signorini run` writes, under the study's lock; a file written there could replace a run's record or snapshot. Nothing was computed or written; give a path outside the study folder",
            path.display(),
            dir.display()
        );
    }
    Ok(())
}

/// Refuse a results root given by `flag` that lies inside a study folder
/// ([`study::store::results_place_fault`]), before anything is read or computed.
pub fn results_place(flag: &str, results: Option<&std::path::Path>) -> Result<()> {
    match results.and_then(study::store::results_place_fault) {
        Some(why) => bail!("{flag} {why}; nothing was read or written"),
        None => Ok(()),
    }
}

/// Whether `dir` is the tracked results folder `results/` of the current directory, the one
/// `CLAIMS.md` names as `results/` and where every declared study must be complete.
pub fn is_tracked_results(dir: &std::path::Path) -> bool {
    let tracked = std::path::Path::new("results");
    dir == tracked || matches!((dir.canonicalize(), tracked.canonicalize()), (Ok(a), Ok(b)) if a == b)
}

/// A reader given `--wait` (`figures`, `report`): `read` again while it is refused because a
/// process started writing the folder after its wait (each attempt waits for the writers first).
/// A second Slurm array's task may start at any moment: `make cluster-test` failed when one did
/// between the finish job's wait and its read.
pub fn again_while_written(wait: bool, mut read: impl FnMut() -> Result<()>) -> Result<()> {
    loop {
        match read() {
            Err(e) if wait && e.chain().any(|c| c.downcast_ref::<study::store::BeingWritten>().is_some()) => {
                note!("{e:#}; waiting for it (--wait)");
            }
            done => return done,
        }
    }
}

/// A folder a command writes into (`export --out`, `figures --figures`, `report --out`): a file
/// there is an error naming the flag, now, not the operating system's "File exists" later.
pub fn output_folder(flag: &str, path: &std::path::Path, writes: &str) -> Result<()> {
    outside_study(flag, path)?;
    if path.exists() && !path.is_dir() {
        bail!("{flag} {}: this is a file; {writes}: give a folder's path", path.display());
    }
    Ok(())
}
