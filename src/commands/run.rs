//! `run`: declared studies into their results folders, every manifest and run checked before
//! the first run computes; `--plan` lists what a run would do and runs nothing.

use crate::study;
use anyhow::{Result, bail};
use signorini_store::study::manifest::Manifest;
use signorini_store::study::store::Store;

/// The switches of `signorini run` that shape what a run does with the store.
#[derive(Clone, Copy, Debug, Default)]
pub struct RunFlags {
    /// The short form: the first quick_levels levels of every run.
    pub quick: bool,
    /// Start over instead of resuming.
    pub fresh: bool,
    /// Replace stored runs whose spec differs from the manifest's.
    pub replace: bool,
    /// Wait for another process running the same study instead of refusing.
    pub wait: bool,
    /// Check and list the runs, run nothing.
    pub plan: bool,
}

/// Run the studies of `manifests` (or with `flags.plan`, list what would be done: the lines
/// returned, one STUDY/RUN each). `shard` is `K/N`; `results` defaults to `results`, or
/// `target/quick-results` with `flags.quick`.
pub fn run_studies(
    manifests: &[std::path::PathBuf],
    shard: Option<&str>,
    results: Option<std::path::PathBuf>,
    flags: RunFlags,
) -> Result<Vec<String>> {
    let RunFlags { quick, fresh, replace, wait, plan } = flags;
    let shard = shard.map(study::parse_shard).transpose()?;
    let results = results.unwrap_or_else(|| if quick { "target/quick-results".into() } else { "results".into() });
    // parse and check every run of every manifest first: a mistake in the last one should not
    // cost the first one's run
    let parsed = manifests.iter().map(|m| Manifest::load(m)).collect::<Result<Vec<_>, _>>()?;
    for manifest in &parsed {
        manifest.check_runs()?;
    }
    check_one_declaration(&parsed, quick)?;
    // a run CLAIMS.md or a figure needs that no manifest declares would be found missing only
    // by `figures`, after the study was computed
    crate::analysis::roles::check(&parsed)?;
    if quick && !replace && !fresh {
        for manifest in &parsed {
            check_quick_beside_full(manifest, &results)?;
        }
    }
    if let Some(shard) = shard {
        check_shard(&parsed, shard)?;
    }
    let options = study::RunOptions { quick, shard, fresh, replace, results: results.clone(), progress: true, wait_for_lock: wait };
    let mut lines = Vec::new();
    if plan {
        // a study given twice (`run M.toml M.toml`) declares the same runs (checked above) and
        // stores each run once: each listed once
        let mut listed = std::collections::BTreeSet::new();
        for m in &parsed {
            let plan = study::plan(m, &options)?;
            if !plan.leftovers.is_empty() && listed.insert((m.study.clone(), String::new())) {
                let files: Vec<String> = plan.leftovers.iter().map(|f| f.display().to_string()).collect();
                lines.push(format!(
                    "{} (first removes {} leftover file(s) of an unfinished run: {})",
                    m.study,
                    files.len(),
                    files.join(", ")
                ));
            }
            if !plan.removals.is_empty() && listed.insert((m.study.clone(), "--fresh".into())) {
                let files: Vec<String> = plan.removals.iter().map(|f| f.display().to_string()).collect();
                lines.push(format!("{} (--fresh first removes {} file(s): {})", m.study, files.len(), files.join(", ")));
            }
            for (id, doing) in plan.runs {
                if listed.insert((m.study.clone(), id.clone())) {
                    match doing {
                        study::Planned::Compute => lines.push(format!("{}/{id}", m.study)),
                        study::Planned::Keep => lines.push(format!("{}/{id} (kept: stored with this spec, nothing computed)", m.study)),
                        study::Planned::Replace(why) => {
                            lines.push(format!("{}/{id} (replaces the stored run: {})", m.study, why.join("; ")))
                        }
                        study::Planned::Remove(why) => {
                            lines.push(format!("{}/{id} (removes the stored run and its snapshots: {why})", m.study))
                        }
                    }
                }
            }
        }
        return Ok(lines);
    }
    for manifest in &parsed {
        let executed = study::run_study(manifest, &options)?;
        note!("{}: {} run(s) executed, results in {}", manifest.study, executed.len(), results.join(&manifest.study).display());
    }
    Ok(lines)
}

/// Manifests given together that declare the same study declare the same runs: otherwise the
/// second would be refused (or with --replace would replace the first's runs) only after the
/// first had computed, so the conflict is refused before anything is, naming both files.
fn check_one_declaration(manifests: &[Manifest], quick: bool) -> Result<()> {
    let runs = |m: &Manifest| {
        let mut specs: Vec<_> = m.runs.iter().map(|p| study::effective_spec(p, quick)).collect();
        specs.sort_by(|a, b| a.id.cmp(&b.id));
        specs
    };
    for (i, a) in manifests.iter().enumerate() {
        if let Some(b) = manifests[..i].iter().find(|b| b.study == a.study && runs(b) != runs(a)) {
            bail!(
                "{} and {} both declare study {} with different runs: given together, the second would find the first's runs stored with \
                 another spec; nothing was run. Run one of them (or give them different file names: the study is the file's name)",
                b.file.display(),
                a.file.display(),
                a.study
            );
        }
    }
    Ok(())
}

/// `run --quick` into a folder that holds the full form of a run: its quick form (the first
/// `quick_levels` levels) is another spec, and replacing the full run with it would throw the
/// full run away, so the refusal says so and points at another folder rather than at --replace.
fn check_quick_beside_full(manifest: &Manifest, results: &std::path::Path) -> Result<()> {
    let store = Store::new(results, &manifest.study);
    let stored = store.records().unwrap_or_default();
    let full = manifest.runs.iter().find(|p| {
        let (full, quick) = (study::effective_spec(p, false), study::effective_spec(p, true));
        full != quick && stored.iter().any(|r| r.run == full)
    });
    if let Some(p) = full {
        bail!(
            "{}: {} holds the full form of study {} (run {} with its {} levels); --quick computes only the first {} levels of each run, \
             another spec, and storing it there would replace the full runs. Nothing was run or changed. Give the quick runs another \
             folder: --results target/quick-results (the default of --quick) or any other",
            manifest.file.display(),
            store.dir().root.display(),
            manifest.study,
            p.spec.id,
            p.spec.levels,
            p.quick_levels
        );
    }
    Ok(())
}

/// A shard must hold at least one run of the manifests given (each manifest's runs are dealt
/// out to the shards in order); a manifest of which it holds none gets a note.
fn check_shard(manifests: &[Manifest], (k, n): (usize, usize)) -> Result<()> {
    let counts: Vec<(&str, usize, usize)> =
        manifests.iter().map(|m| (m.study.as_str(), m.runs.len(), (0..m.runs.len()).filter(|i| i % n == k - 1).count())).collect();
    if counts.iter().all(|c| c.2 == 0) {
        let sizes: Vec<String> = counts.iter().map(|(s, r, _)| format!("{s} has {r} run(s)")).collect();
        bail!(
            "--shard {k}/{n}: this shard holds no run ({}); shard K of N runs the runs K, K + N, K + 2N, ... of each study, so K must be at most its number of runs",
            sizes.join(", ")
        );
    }
    for (s, r, _) in counts.iter().filter(|c| c.2 == 0) {
        note!("note: --shard {k}/{n} holds no run of {s} ({r} run(s)); other shards run them");
    }
    Ok(())
}
