//! Declared studies as stored: the manifests that declare them ([`manifest`]), the results
//! folder that holds their runs ([`store`]) and where each run came from ([`provenance`]); what
//! a results folder holds of the declared studies, whether it holds a study complete, and whether
//! a drift report's entry compared its records with a copy of them.

pub mod manifest;
pub mod provenance;
pub mod store;

use crate::records::RunSpec;
use anyhow::{Context, Result, bail};
use manifest::Manifest;
use model::problems;
use std::path::{Path, PathBuf};
use store::Store;

/// Every declared run is stored with exactly its declared (full) spec, and nothing else is:
/// what figures and claims need before they draw from a study. The error names what is missing
/// or different and how to complete the study.
pub fn check_complete(manifest: &Manifest, results: &std::path::Path) -> Result<()> {
    let store = Store::of(results, manifest);
    let runs = store.read()?;
    let dir = store.dir();
    let mut problems = Vec::new();
    for planned in &manifest.runs {
        match runs.iter().find(|r| r.run.id == planned.spec.id) {
            None => problems.push(format!("run {} is missing", planned.spec.id)),
            Some(r) if r.run != planned.spec => problems.push(format!(
                "run {} was computed with another spec ({})",
                planned.spec.id,
                store::stale::spec_differences(&r.run, &planned.spec).join("; ")
            )),
            Some(_) => {}
        }
    }
    for r in &runs {
        if !manifest.runs.iter().any(|p| p.spec.id == r.run.id) {
            problems.push(format!("run {} is not declared in {}", r.run.id, manifest.file.display()));
        }
    }
    if !problems.is_empty() {
        // the advice writes into the folder being checked, never into results/ unless that is it
        let into = if results == std::path::Path::new("results") { String::new() } else { format!(" --results {}", results.display()) };
        // runs stored with another spec or not declared are refused by a plain run: the advice
        // that works replaces them
        let replace = if runs.iter().any(|r| manifest.runs.iter().all(|p| p.spec != r.run)) { " --replace" } else { "" };
        bail!(
            "{} does not match {}: {}. Complete it with `signorini run {}{into}{replace}` (or start over with --fresh) before drawing from it",
            dir.root.display(),
            manifest.file.display(),
            problems.join("; "),
            manifest.file.display()
        );
    }
    Ok(())
}

/// The problem a stored run of `study` solved: its spec's problem resolved against the manifest
/// the provenance names, with the run's constants (for figures and claims that need the problem's
/// data, such as Hertz's radius and material). A problem file not found there (the study was
/// run from another folder) is looked for beside `experiments/STUDY.toml`, so a study rerun
/// into a scratch folder is drawn without copying its manifest and problem files.
pub fn stored_problem(results: &std::path::Path, study: &str, spec: &RunSpec) -> Result<Box<dyn problems::Problem>> {
    let prov = Store::new(results, study).provenance()?;
    let recorded = manifest::resolve_problem(std::path::Path::new(&prov.manifest), &spec.problem);
    let declared = manifest::resolve_problem(&PathBuf::from("experiments").join(format!("{study}.toml")), &spec.problem);
    let found = |p: &String| !problems::is_file(p) || std::path::Path::new(p).exists();
    let path = [recorded.clone(), declared].into_iter().find(found).unwrap_or(recorded);
    problems::load(&path, &spec.constants).with_context(|| format!("the problem of {study}/{}", spec.id))
}

/// The declared studies a results folder holds (a folder `DIR/STUDY`), those it does not, and
/// its other folders (not declared studies).
#[derive(Clone, Debug)]
pub struct Held {
    pub present: Vec<Manifest>,
    pub absent: Vec<String>,
    pub undeclared: Vec<String>,
}

/// Which of `manifests`' studies `dir` holds. A `dir` that is not a readable folder is an error.
pub fn held_by(dir: &Path, manifests: &[Manifest]) -> std::io::Result<Held> {
    let entries =
        std::fs::read_dir(dir).map_err(|e| std::io::Error::new(e.kind(), format!("reading the folder {}: {e}", dir.display())))?;
    let mut folders: Vec<String> =
        entries.flatten().filter(|e| e.path().is_dir()).map(|e| e.file_name().to_string_lossy().into_owned()).collect();
    folders.sort();
    let (present, absent): (Vec<&Manifest>, Vec<&Manifest>) = manifests.iter().partition(|m| folders.contains(&m.study));
    let undeclared = folders.into_iter().filter(|f| !manifests.iter().any(|m| &m.study == f)).collect();
    Ok(Held { present: present.into_iter().cloned().collect(), absent: absent.iter().map(|m| m.study.clone()).collect(), undeclared })
}

/// Whether a drift report's study entry compared the stored records with records byte-identical
/// to them (their hashes, `records` and `against_records`), timings (`t_*`) included: no rerun
/// reproduces a run's timings, so the other folder is a copy of the stored one, or the folder
/// itself. That checks that the copy reads back, not the numbers, and a study page never quotes
/// it as a rerun (`drift --against` a `cp -r` copy is never "rerun and compared"). The folder itself ([`same_folder`]) is the case where every record is its own copy.
pub fn compared_a_copy(entry: &serde_json::Value) -> bool {
    let stored = entry.get("records").and_then(serde_json::Value::as_object);
    stored.is_some_and(|s| !s.is_empty() && entry.get("against_records").and_then(serde_json::Value::as_object) == Some(s))
}
