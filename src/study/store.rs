//! The study folder `results/STUDY/` kept readable and consistent whatever happens.
//!
//! - A finished run lands in one [`Batch`]: its mesh snapshots (written while it ran), its record
//!   and the summaries listing it (`levels.csv`, `provenance.json`) are all written in full to
//!   temporary files first, then renamed into place ([`commit_run`]). A write that fails (a full
//!   disk) leaves nothing of the run and no temporary file; a run that stops (an interrupt, an
//!   error) leaves nothing either.
//! - What a killed process leaves (temporary files, mesh snapshots of a run without a record) is
//!   an orphan: the next run removes it and says so ([`remove_orphans`]).
//! - The summaries are rewritten only when their content would change ([`sync_summaries`]): a run
//!   that executes nothing leaves every file as it was.
//! - A stored run is never replaced silently: a manifest whose run differs from the stored one, or
//!   a stored run the manifest does not declare, is refused unless told to replace it
//!   ([`stale_runs`], [`refusal`]); the runner repeats the check under the run's lock, and
//!   `--fresh` holds every run lock of the study before it removes anything.
//! - `run`, `drift`, `figures` and `report` check the folder with [`Store::check`] first: each
//!   record's run id is its file name, every snapshot it saves exists and parses, the summaries
//!   match the records; a folder at fault is refused naming the file (`run --replace` replaces
//!   the records at fault).

use super::manifest::Manifest;
use super::provenance::{self, Provenance};
use crate::records::{self, Batch, RunRecord, RunSpec, StudyDir};
use anyhow::{Context, Result};
use serde_json::Value;
use std::path::PathBuf;

/// Every run record of the study; an unreadable one is an error naming it (and is then never
/// overwritten: nothing is written after this fails).
pub fn read_runs(dir: &StudyDir) -> Result<Vec<RunRecord>> {
    dir.read_runs().with_context(|| format!("reading the runs in {}", dir.root.join("runs").display()))
}

/// The leaves of a JSON value by dotted key (`estimator.c0`), in order.
fn flatten(prefix: &str, value: &Value, out: &mut Vec<(String, Value)>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                flatten(&if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") }, v, out);
            }
        }
        leaf => out.push((prefix.to_string(), leaf.clone())),
    }
}

/// The keys in which a stored run's spec differs from the declared one, each with both values:
/// `estimator.c0: 0.45 stored, 1e308 declared`.
pub fn spec_differences(stored: &RunSpec, declared: &RunSpec) -> Vec<String> {
    let leaves = |s: &RunSpec| {
        let mut out = Vec::new();
        flatten("", &serde_json::to_value(s).unwrap_or_default(), &mut out);
        out
    };
    let (a, b) = (leaves(stored), leaves(declared));
    let get = |side: &[(String, Value)], key: &str| side.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone());
    let mut keys: Vec<&String> = a.iter().map(|(k, _)| k).collect();
    keys.extend(b.iter().map(|(k, _)| k).filter(|k| !a.iter().any(|(ka, _)| ka == *k)));
    let show = |v: Option<Value>| v.map_or("(absent)".to_string(), |v| v.to_string());
    let hash = |v: Option<Value>| v.and_then(|v| v.as_str().map(|h| format!("sha256 {}", &h[..h.len().min(12)]))).unwrap_or("none".into());
    keys.into_iter()
        .filter(|k| get(&a, k) != get(&b, k))
        .map(|k| match k.strip_prefix("inputs.") {
            // an input file is named as such: the run read other bytes than the file holds now
            Some(file) => match get(&a, k) {
                None => format!("the input file {file} is not in the stored spec ({} now)", hash(get(&b, k))),
                stored => format!("the input file {file} changed ({} stored, {} now)", hash(stored), hash(get(&b, k))),
            },
            None => format!("{k}: {} stored, {} declared", show(get(&a, k)), show(get(&b, k))),
        })
        .collect()
}

/// A stored run the manifest does not ask for as it is.
#[derive(Clone, Debug, PartialEq)]
pub enum Stale {
    /// Declared with another spec: the differing keys ([`spec_differences`]).
    Differs { id: String, differences: Vec<String> },
    /// Not declared by the manifest at all.
    Undeclared { id: String },
    /// A record file (`runs/FILE.json`) at fault in the store's integrity check ([`Store::check`]):
    /// what is wrong with it and its snapshots.
    Damaged { file: String, what: Vec<String> },
}

/// The record files at fault among `faults` ([`Store::check`]), each once with all it has.
pub fn damaged(faults: &[Fault]) -> Vec<Stale> {
    let mut out: Vec<Stale> = Vec::new();
    for f in faults {
        let Some(stem) = &f.record else { continue };
        let text = f.to_string();
        match out.iter_mut().find(|s| matches!(s, Stale::Damaged { file, .. } if file == stem)) {
            Some(Stale::Damaged { what, .. }) => what.push(text),
            _ => out.push(Stale::Damaged { file: stem.clone(), what: vec![text] }),
        }
    }
    out
}

/// The stored runs that are stale: among `planned` (the runs this invocation is responsible
/// for, as they would run), those stored with another spec; among all stored runs, those the
/// manifest does not declare.
pub fn stale_runs(manifest: &Manifest, runs: &[RunRecord], planned: &[RunSpec]) -> Vec<Stale> {
    let mut out: Vec<Stale> = planned
        .iter()
        .filter_map(|spec| runs.iter().find(|r| r.run.id == spec.id && r.run != *spec))
        .map(|r| Stale::Differs { id: r.run.id.clone(), differences: spec_differences(&r.run, planned_spec(planned, &r.run.id)) })
        .collect();
    out.extend(
        runs.iter().filter(|r| !manifest.runs.iter().any(|p| p.spec.id == r.run.id)).map(|r| Stale::Undeclared { id: r.run.id.clone() }),
    );
    out
}

fn planned_spec<'a>(planned: &'a [RunSpec], id: &str) -> &'a RunSpec {
    planned.iter().find(|s| s.id == id).expect("a planned run")
}

/// The error refusing to overwrite stale runs: each run with what differs, and the way out.
pub fn refusal(manifest: &Manifest, dir: &StudyDir, stale: &[Stale]) -> anyhow::Error {
    let what: Vec<String> = stale
        .iter()
        .map(|s| match s {
            Stale::Differs { id, differences } => format!("run {id} is stored with another spec ({})", differences.join("; ")),
            Stale::Undeclared { id } => format!("run {id} is stored but not declared in {}", manifest.file.display()),
            Stale::Damaged { file, what } => format!("the record runs/{file}.json does not hold together ({})", what.join("; ")),
        })
        .collect();
    anyhow::anyhow!(
        "{}: not overwriting the stored results in {}: {}. Nothing was run or changed. Pass --replace to replace these runs \
         (records and mesh snapshots; the other stored runs are kept), or --fresh to start the study over",
        manifest.file.display(),
        dir.root.display(),
        what.join("; ")
    )
}

/// Whether a finished run's record accounts for the snapshot of `run` at `level`.
fn saved(runs: &[RunRecord], run: &str, level: usize) -> bool {
    runs.iter().any(|r| r.run.id == run && r.run.save_levels.contains(&level) && level < r.levels.len())
}

/// The files of `dir` (one level, sorted by name); none if it does not exist.
fn files_in(dir: &std::path::Path) -> Result<Vec<(String, PathBuf)>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e).with_context(|| format!("reading the directory {}", dir.display())),
    };
    let mut out: Vec<(String, PathBuf)> = entries
        .flatten()
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .map(|e| (e.file_name().to_string_lossy().into_owned(), e.path()))
        .collect();
    out.sort();
    Ok(out)
}

/// The files of the study folder no finished run accounts for: temporary files (of a process
/// killed while writing) anywhere in it, and mesh snapshots of a run without a record or of a
/// level its record does not save (a run killed before it finished, an old binary's leftovers).
/// Files the study never writes are left alone, and so are the temporary files of a run another
/// process computes now (its run lock is held; ask under the study lock).
pub fn orphans(dir: &StudyDir, runs: &[RunRecord]) -> Result<Vec<PathBuf>> {
    let meshes = dir.root.join("meshes");
    let mut out = Vec::new();
    let runs_dir = dir.root.join("runs");
    let references = dir.root.join("references");
    let keys: Vec<String> = runs.iter().filter_map(|r| records::ReferenceRecord::key_of(&r.run)).collect();
    for sub in [dir.root.clone(), runs_dir.clone(), meshes.clone(), references.clone()] {
        for (name, path) in files_in(&sub)? {
            let stray_mesh = sub == meshes && StudyDir::parse_mesh_name(&name).is_some_and(|(run, level)| !saved(runs, run, level));
            // a reference no stored run is measured against (its runs replaced or removed)
            let stray_reference = sub == references && name.strip_suffix(".json").is_some_and(|k| !keys.iter().any(|key| key == k));
            let temporary = records::is_temporary(&name);
            // a temporary file of a run another process computes now is not an orphan
            let of_run = name.strip_prefix('.').and_then(|n| n.rsplit_once(".tmp")).and_then(|(target, _)| {
                if sub == runs_dir {
                    target.strip_suffix(".json").map(str::to_string)
                } else {
                    StudyDir::parse_mesh_name(target).map(|(run, _)| run.to_string()).filter(|_| sub == meshes)
                }
            });
            let in_progress = temporary && of_run.is_some_and(|id| super::lock::run_in_progress(dir, &id));
            if (temporary || stray_mesh || stray_reference) && !in_progress {
                out.push(path);
            }
        }
    }
    Ok(out)
}

/// The orphans' paths relative to the study folder, comma-separated.
pub fn names(dir: &StudyDir, files: &[PathBuf]) -> String {
    files.iter().map(|f| f.strip_prefix(&dir.root).unwrap_or(f).display().to_string()).collect::<Vec<_>>().join(", ")
}

/// Remove the [`orphans`], saying so in one line that names them.
pub fn remove_orphans(study: &str, dir: &StudyDir, runs: &[RunRecord]) -> Result<()> {
    let found = orphans(dir, runs)?;
    if found.is_empty() {
        return Ok(());
    }
    for f in &found {
        std::fs::remove_file(f).with_context(|| format!("removing {}", f.display()))?;
    }
    crate::base::note::line(format_args!(
        "{study}: removed {} file(s) of an unfinished run (no finished run accounts for them): {}",
        found.len(),
        names(dir, &found)
    ));
    Ok(())
}

/// Remove a run's record, its mesh snapshots (`meshes/RUN_levelL.*`) and its checkpoint.
pub fn remove_run(dir: &StudyDir, id: &str) -> Result<()> {
    super::checkpoint::remove(dir, id)?;
    let file = dir.run_file(id);
    match std::fs::remove_file(&file) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(e).with_context(|| format!("removing {}", file.display())),
    }
    for (name, path) in files_in(&dir.root.join("meshes"))? {
        if StudyDir::parse_mesh_name(&name).is_some_and(|(run, _)| run == id) {
            std::fs::remove_file(&path).with_context(|| format!("removing {}", path.display()))?;
        }
    }
    Ok(())
}

/// The provenance of the study as it is now, for these runs.
fn provenance_of(manifest: &Manifest, runs: &[RunRecord], quick: bool) -> Provenance {
    let meshes = manifest.mesh_files();
    let meshes: Vec<&std::path::Path> = meshes.iter().map(|p| p.as_path()).collect();
    let ids = runs.iter().map(|r| r.run.id.clone()).collect();
    let mut prov = provenance::collect(&manifest.study, &manifest.file, &manifest.bytes, quick, ids, &meshes);
    prov.problem_files = manifest.problem_files().iter().map(|f| provenance::ProblemFile::of(f)).collect();
    prov
}

/// The runs `provenance.json` lists, if it can be read.
pub fn listed_runs(dir: &StudyDir) -> Option<Vec<String>> {
    let text = std::fs::read_to_string(dir.provenance_file()).ok()?;
    serde_json::from_str::<Provenance>(&text).ok().map(|p| p.runs)
}

fn csv_bytes(dir: &StudyDir, runs: &[RunRecord]) -> Result<Vec<u8>> {
    dir.csv_bytes(runs).with_context(|| format!("rendering {}", dir.csv_file().display()))
}

/// Make `levels.csv` and `provenance.json` describe exactly `runs` (the runs present), writing
/// only what would change: the CSV when its bytes differ, the provenance when it is missing,
/// unreadable or lists other runs. (A provenance records who computed the runs; a process that
/// computed none of them has nothing to add to it.) Both are written together.
pub fn sync_summaries(manifest: &Manifest, dir: &StudyDir, runs: &[RunRecord], quick: bool) -> Result<()> {
    let mut batch = Batch::default();
    let csv = csv_bytes(dir, runs)?;
    if std::fs::read(dir.csv_file()).ok().as_deref() != Some(csv.as_slice()) {
        batch.add(&dir.csv_file(), &csv)?;
    }
    let ids: Vec<String> = runs.iter().map(|r| r.run.id.clone()).collect();
    if listed_runs(dir).as_ref() != Some(&ids) {
        batch.add_json(&dir.provenance_file(), &provenance_of(manifest, runs, quick))?;
    }
    Ok(batch.commit()?)
}

/// Store a finished run. `batch` holds its mesh snapshots, written while it ran; its record and
/// the summaries listing it join them, then the run's previous record and snapshots (a replaced
/// run) are removed and everything is renamed into place. If a write fails, nothing of the run
/// reaches the folder and no temporary file is left.
pub fn commit_run(manifest: &Manifest, dir: &StudyDir, record: &RunRecord, mut batch: Batch, quick: bool) -> Result<()> {
    let id = &record.run.id;
    let mut runs = read_runs(dir)?;
    runs.retain(|r| &r.run.id != id);
    runs.push(record.clone());
    runs.sort_by_key(|r| dir.run_file(&r.run.id));
    batch.add_json(&dir.run_file(id), record)?;
    batch.add(&dir.csv_file(), &csv_bytes(dir, &runs)?)?;
    batch.add_json(&dir.provenance_file(), &provenance_of(manifest, &runs, quick))?;
    remove_run(dir, id)?;
    Ok(batch.commit()?)
}

/// After a failure part-way through changing the folder (a removal or a rename that failed):
/// remove the orphans and bring the summaries in line with the runs present.
pub fn repair(manifest: &Manifest, dir: &StudyDir, quick: bool) -> Result<()> {
    let runs = read_runs(dir)?;
    remove_orphans(&manifest.study, dir, &runs)?;
    sync_summaries(manifest, dir, &runs, quick)
}

/// The one door to a study's results folder for readers: the folder read and checked as a
/// whole ([`Store::check`]). `run`, `drift` (both sides of `--against`), `figures` and `report`
/// read a study through it, so a folder that does not hold together is named, never drawn or
/// compared as if it did.
#[derive(Clone, Debug)]
pub struct Store {
    pub dir: StudyDir,
    pub study: String,
}

/// Something in a study folder that does not hold together: the file and what is wrong with it.
#[derive(Clone, Debug, PartialEq)]
pub struct Fault {
    pub file: PathBuf,
    pub what: String,
    /// The stem of the record file at fault (`runs/STEM.json`, and its snapshots); `None` for a
    /// summary (`levels.csv`, `provenance.json`), which is rendered from the records.
    pub record: Option<String>,
}

impl std::fmt::Display for Fault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.file.display(), self.what)
    }
}

/// A study folder as read by [`Store::check`].
#[derive(Clone, Debug, Default)]
pub struct Checked {
    /// The records, in file-name order.
    pub runs: Vec<RunRecord>,
    /// What does not hold together (empty for a sound folder).
    pub faults: Vec<Fault>,
    /// Files of an unfinished run no record accounts for ([`orphans`]): `run` removes them,
    /// every reader names and ignores them.
    pub leftovers: Vec<PathBuf>,
}

impl Checked {
    /// The faults, one per line, for an error message.
    pub fn faults_text(&self) -> String {
        self.faults.iter().map(|f| format!("\n  {f}")).collect()
    }
}

impl Store {
    pub fn new(results: &std::path::Path, study: &str) -> Self {
        Store { dir: StudyDir::new(results, study), study: study.to_string() }
    }

    /// Read the folder and check that it holds together: every record's run id is its file
    /// name (so each run is stored once) and its study is this one; every mesh snapshot a record
    /// saves exists and parses, as the level it names; `levels.csv` and `provenance.json` are
    /// what the records render ([`summary_faults`]). A record that does not parse is an error
    /// naming it.
    pub fn check(&self) -> Result<Checked> {
        let files = self.dir.read_run_files().with_context(|| format!("reading the runs in {}", self.dir.root.join("runs").display()))?;
        let mut faults = Vec::new();
        for (file, record) in &files {
            let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            let mut fault =
                |file: &std::path::Path, what: String| faults.push(Fault { file: file.to_path_buf(), what, record: Some(stem.clone()) });
            if record.run.id != stem {
                fault(
                    file,
                    format!("holds run {}, not {stem} (a record's run id is its file name: a copy or a renamed file?)", record.run.id),
                );
                continue;
            }
            if record.study != self.study {
                fault(file, format!("is a record of study {}, not {}", record.study, self.study));
            }
            for (path, what) in snapshot_faults(&self.dir, record) {
                fault(&path, what);
            }
        }
        let runs: Vec<RunRecord> = files.into_iter().map(|(_, r)| r).collect();
        faults.extend(summary_faults(&self.dir, &self.study, &runs));
        faults.extend(reference_faults(&self.dir, &runs));
        let leftovers = orphans(&self.dir, &runs)?;
        Ok(Checked { runs, faults, leftovers })
    }

    /// [`Store::check`] for a reader: the records of a sound folder (its leftovers named on
    /// stderr and ignored); a fault is an error naming every one.
    pub fn read(&self) -> Result<Vec<RunRecord>> {
        let checked = self.check()?;
        if !checked.faults.is_empty() {
            anyhow::bail!(
                "{} does not hold together:{}\nRerun the runs at fault with `signorini run experiments/{}.toml --replace` (or restore the files)",
                self.dir.root.display(),
                checked.faults_text(),
                self.study
            );
        }
        self.note_leftovers(&checked.leftovers);
        Ok(checked.runs)
    }

    /// Name the leftovers of an unfinished run a reader ignores, in one line.
    pub fn note_leftovers(&self, leftovers: &[PathBuf]) {
        if !leftovers.is_empty() {
            crate::base::note::line(format_args!(
                "{}: ignoring {} file(s) of an unfinished run in {} (`signorini run` removes them): {}",
                self.study,
                leftovers.len(),
                self.dir.root.display(),
                names(&self.dir, leftovers)
            ));
        }
    }
}

/// The mesh snapshots `record` saves that are missing or do not parse as its level, each with
/// what is wrong: the JSON (what the mesh figures read) must be the run's level with the level's
/// NDF, the VTU a whole VTK file.
fn snapshot_faults(dir: &StudyDir, record: &RunRecord) -> Vec<(PathBuf, String)> {
    let id = &record.run.id;
    let mut out = Vec::new();
    for &l in record.run.save_levels.iter().filter(|&&l| l < record.levels.len()) {
        let json = dir.mesh_file(id, l, "json");
        match dir.read_mesh(id, l) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => out.push((json, format!("missing: run {id} saves level {l}"))),
            Err(e) => out.push((json, format!("does not parse as a mesh snapshot ({e})"))),
            Ok(s) if s.run != *id || s.level != l || s.ndof != record.levels[l].ndof => out.push((
                json,
                format!(
                    "is run {} level {} with {} unknowns, not run {id} level {l} with {}",
                    s.run, s.level, s.ndof, record.levels[l].ndof
                ),
            )),
            Ok(_) => {}
        }
        let vtu = dir.mesh_file(id, l, "vtu");
        match std::fs::read(&vtu) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => out.push((vtu, format!("missing: run {id} saves level {l}"))),
            Err(e) => out.push((vtu, format!("cannot be read ({e})"))),
            Ok(b) if !(b.starts_with(b"<?xml") && b.trim_ascii_end().ends_with(b"</VTKFile>")) => {
                out.push((vtu, "is not a whole VTK file (no XML header or no closing </VTKFile>)".into()))
            }
            Ok(_) => {}
        }
    }
    out
}

/// The first line where two texts differ, shortened, as it reads in each.
pub fn first_difference(a: &str, b: &str) -> (String, String) {
    let (al, bl): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    let i = (0..al.len().max(bl.len())).find(|&i| al.get(i) != bl.get(i)).unwrap_or(al.len().min(bl.len()));
    let cut =
        |s: Option<&&str>| format!("line {}: {}", i + 1, s.map(|s| s.chars().take(60).collect::<String>()).unwrap_or("(none)".into()));
    (cut(al.get(i)), cut(bl.get(i)))
}

/// The summaries of a study against what its records render: `levels.csv` byte for byte,
/// `provenance.json` readable, of this study and listing exactly these runs. A folder with no
/// record and no summary has nothing to disagree.
pub fn summary_faults(dir: &StudyDir, study: &str, runs: &[RunRecord]) -> Vec<Fault> {
    let (csv, prov) = (dir.csv_file(), dir.provenance_file());
    if runs.is_empty() && !csv.exists() && !prov.exists() {
        return Vec::new();
    }
    let mut out = Vec::new();
    let mut fault = |file: &std::path::Path, what: String| out.push(Fault { file: file.to_path_buf(), what, record: None });
    match (std::fs::read(&csv), dir.csv_bytes(runs)) {
        (Ok(on_disk), Ok(rendered)) if on_disk == rendered => {}
        (Ok(on_disk), Ok(rendered)) => {
            let (a, b) = first_difference(&String::from_utf8_lossy(&on_disk), &String::from_utf8_lossy(&rendered));
            fault(&csv, format!("is not what runs/*.json render: {a}, rendered {b}"));
        }
        (Err(e), _) => fault(&csv, format!("cannot be read ({e})")),
        (_, Err(e)) => fault(&csv, format!("cannot be rendered from the records ({e})")),
    }
    let ids: Vec<String> = runs.iter().map(|r| r.run.id.clone()).collect();
    match std::fs::read_to_string(&prov)
        .map_err(|e| e.to_string())
        .and_then(|t| serde_json::from_str::<Provenance>(&t).map_err(|e| e.to_string()))
    {
        Err(e) => fault(&prov, format!("cannot be read ({e})")),
        Ok(p) if p.runs != ids => fault(&prov, format!("lists the runs {}, the records are {}", p.runs.join(" "), ids.join(" "))),
        Ok(p) if p.study != study => fault(&prov, format!("is the provenance of study {}, not {study}", p.study)),
        Ok(_) => {}
    }
    out
}

/// The stored reference solutions against the runs measured against them: each one present
/// parses, is the reference of the runs naming it (its key) and has the NDF they record. A
/// reference not stored is no fault here (a folder written before references were stored; the
/// drift check computes it and names it missing); `run` stores it ([`stage_reference`]).
pub fn reference_faults(dir: &StudyDir, runs: &[RunRecord]) -> Vec<Fault> {
    let mut out = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for r in runs {
        let Some(key) = records::ReferenceRecord::key_of(&r.run) else { continue };
        let file = dir.reference_file(&key);
        let what = match dir.read_reference(&key) {
            Ok(None) => continue,
            Err(e) => format!("cannot be read ({e})"),
            Ok(Some(stored)) if stored.key() != key => {
                format!("is the reference of {} on {}, not of run {}", stored.problem, stored.mesh, r.run.id)
            }
            Ok(Some(stored)) if Some(stored.rebuild.ndof) != r.reference_ndof => format!(
                "has {} unknowns; run {} was measured against a reference of {}",
                stored.rebuild.ndof,
                r.run.id,
                r.reference_ndof.map_or("none".to_string(), |n| n.to_string())
            ),
            Ok(Some(_)) => continue,
        };
        if seen.insert(file.clone()) {
            out.push(Fault { file, what, record: None });
        }
    }
    out
}

/// Add `reference` to `batch` unless the study stores it already (the same history to the
/// same NDF): a run stores the reference it was measured against, with the run.
pub fn stage_reference(dir: &StudyDir, reference: &records::ReferenceRecord, batch: &mut Batch) -> Result<()> {
    let file = dir.reference_file(&reference.key());
    let same = |s: &records::ReferenceRecord| {
        s.rebuild.history == reference.rebuild.history && s.rebuild.ndof == reference.rebuild.ndof && s.key() == reference.key()
    };
    if !matches!(dir.read_reference(&reference.key()), Ok(Some(s)) if same(&s)) {
        batch.add_json(&file, reference)?;
    }
    Ok(())
}
