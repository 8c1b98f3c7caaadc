//! Declared studies: manifests in `experiments/*.toml`, run into `results/STUDY/`.
//!
//! A study is a list of independent runs (problem, initial mesh, refinement, estimator variant).
//! Each finished run is written at once, atomically, as `runs/RUN.json`, so an interrupted study
//! keeps every run it finished and a rerun resumes after them (unless told to start over).
//! `--shard K/N` runs every N-th run; shards merge by run id, since the CSV and the provenance
//! are rebuilt from all run records present. `--quick` runs the first `quick_levels` levels of
//! the same runs: the exact prefix of the full study (same meshes, same numbers).
//!
//! The store stays consistent whatever happens ([`store`]): a finished run, its mesh snapshots
//! and the summaries listing it (`levels.csv`, `provenance.json`) land together or not at all;
//! what a killed process leaves is removed by the next run; a run that executes nothing changes
//! no file; a stored run whose spec differs from the manifest's is replaced only when asked
//! (`replace`). `--fresh` with `--shard K/N` removes only shard K's runs; the study lock
//! ([`store::Store::lock`], held while shared files change) and one lock per run (held while it
//! is computed) let shards of one study compute side by side while no run is computed twice;
//! an interrupt stops after the current level and keeps every finished run ([`Interrupted`]).

pub mod accept;
pub mod drift;
pub mod progress;
pub mod reference;

use ::store::records::{Batch, MeshSnapshot, RunRecord, RunSpec};
use ::store::study::{manifest, provenance, store};
use anyhow::{Context, Result, bail};
use manifest::Manifest;
use model::mesh::MeshSpec;
use model::problems;
use model::settings::adapt::AdaptConfig;
use numerics::adapt::{self, Level};
use progress::Progress;
use reference::ReferenceField;
use std::collections::HashMap;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use store::{RunWriter, Store};

/// Reference solutions computed in this process, shared by every run and study that declares
/// the same one (they are deterministic, so sharing changes no number).
static REFERENCES: Mutex<Option<HashMap<String, Arc<ReferenceField>>>> = Mutex::new(None);

/// Held by the largest solves of a process (a reference solution computed or rebuilt, a deep
/// level replayed: up to 4.5e6 unknowns), so that they run one at a time whatever else runs
/// beside them: the peak memory of one of them, not of two.
static LARGE: Mutex<()> = Mutex::new(());

/// Wait for the other large solves of this process to end, and hold them off ([`LARGE`]).
pub fn one_large_solve() -> std::sync::MutexGuard<'static, ()> {
    LARGE.lock().unwrap_or_else(|e| e.into_inner())
}

fn reference_for(key: &str, compute: impl FnOnce() -> Result<ReferenceField>) -> Result<Arc<ReferenceField>> {
    let cached = || REFERENCES.lock().expect("reference cache").get_or_insert_default().get(key).cloned();
    if let Some(r) = cached() {
        return Ok(r);
    }
    // one at a time; a thread that waited here for the same reference takes it from the cache
    let _large = one_large_solve();
    if let Some(r) = cached() {
        return Ok(r);
    }
    let r = Arc::new(compute()?);
    REFERENCES.lock().expect("reference cache").get_or_insert_default().insert(key.to_string(), r.clone());
    Ok(r)
}

/// Set when the user interrupts (SIGINT): the runner finishes the level it is on, keeps every
/// run it finished and stops. The command line installs the handler; a library user may set it.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Ask a running study to stop after the current level (what the SIGINT handler does).
pub fn interrupt() {
    INTERRUPTED.store(true, Ordering::SeqCst);
}

pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// A study stopped by an interrupt: what it kept and how to go on.
#[derive(Debug, thiserror::Error)]
#[error("{study}: interrupted; kept {} finished run(s){}{}; levels.csv and provenance.json describe exactly these. Resume with `{resume}` (finished runs are kept)", kept.len(), if kept.is_empty() { String::new() } else { format!(" ({})", kept.join(", ")) }, if missing.is_empty() { String::new() } else { format!(", not yet run: {}", missing.join(", ")) })]
pub struct Interrupted {
    pub study: String,
    /// The command that resumes the study.
    pub resume: String,
    pub kept: Vec<String>,
    pub missing: Vec<String>,
}

/// How to run a study.
#[derive(Clone, Debug)]
pub struct RunOptions {
    pub quick: bool,
    /// (K, N): run the runs with index i such that i % N == K - 1.
    pub shard: Option<(usize, usize)>,
    /// Delete the stored runs this invocation is responsible for first (all of the study's, or
    /// only shard K's with `shard`) instead of resuming after them.
    pub fresh: bool,
    /// Replace the stored runs whose spec differs from the manifest's (each when its new run
    /// has finished) and remove stored runs the manifest does not declare, instead of refusing.
    pub replace: bool,
    /// The results root (`results/`).
    pub results: PathBuf,
    pub progress: bool,
    /// When another process holds the study's lock: wait for it (true) or refuse (false).
    pub wait_for_lock: bool,
}

/// Parse "K/N" with 1 <= K <= N.
pub fn parse_shard(s: &str) -> Result<(usize, usize)> {
    let bad = || anyhow::anyhow!("malformed --shard '{s}': expected K/N with 1 <= K <= N, e.g. 2/4");
    let (k, n) = s.split_once('/').ok_or_else(bad)?;
    let (k, n): (usize, usize) = (k.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
    if k == 0 || n == 0 || k > n {
        return Err(bad());
    }
    Ok((k, n))
}

/// The spec a run actually uses (the quick form shortens it).
pub fn effective_spec(planned: &manifest::PlannedRun, quick: bool) -> RunSpec {
    let mut spec = planned.spec.clone();
    if quick {
        spec.levels = planned.quick_levels;
        spec.save_levels.retain(|l| *l < spec.levels);
    }
    spec
}

/// Run a study; returns the ids of the runs executed (not resumed). Holds the study's lock
/// throughout. First removes what an unfinished run left ([`store::Writer::remove_orphans`]) and
/// refuses stale stored runs unless `replace` ([`store::stale::refusal`]); every finished run is
/// then stored together with the summaries listing it ([`store::Writer::commit_run`]). On an interrupt
/// ([`interrupt`]) the run in progress is dropped and an [`Interrupted`] error says what was kept.
///
/// ```rust
/// use signorini_harness::study::{self, RunOptions};
/// use std::path::Path;
/// use store::study::manifest::Manifest;
///
/// let text = r#"
/// description = "two short runs"
/// [defaults]
/// problem = "ex71"
/// mesh = "structured:2"
/// [[run]]
/// id = "adaptive"
/// levels = 3
/// [[run]]
/// id = "uniform"
/// refine = "uniform"
/// levels = 2
/// "#;
/// let manifest = Manifest::parse(Path::new("doc.toml"), text).unwrap();
/// let results = std::env::temp_dir().join(format!("signorini-doc-{}", std::process::id()));
/// let opts = RunOptions { quick: false, shard: None, fresh: true, replace: false, results: results.clone(), progress: false, wait_for_lock: false };
/// let ran = study::run_study(&manifest, &opts).unwrap();
/// assert_eq!(ran, ["adaptive", "uniform"]);
/// let runs = store::records::StudyDir::new(&results, &manifest.study).read_runs().unwrap();
/// assert_eq!(runs.iter().map(|r| r.levels.len()).collect::<Vec<_>>(), [3, 2]);
/// std::fs::remove_dir_all(&results).unwrap();
/// ```
pub fn run_study(manifest: &Manifest, opts: &RunOptions) -> Result<Vec<String>> {
    let store = Store::of(&opts.results, manifest);
    let in_shard = |i: usize| opts.shard.is_none_or(|(k, n)| i % n == k - 1);
    let planned: Vec<RunSpec> =
        manifest.runs.iter().enumerate().filter(|(i, _)| in_shard(*i)).map(|(_, p)| effective_spec(p, opts.quick)).collect();
    set_up(manifest, &store, &planned, opts)?;
    run_planned(manifest, &store, &planned, opts).map_err(|e| {
        if e.downcast_ref::<Interrupted>().is_some() {
            return e;
        }
        // a removal or rename may have failed part-way: leave the folder consistent
        match store.lock(true).and_then(|w| w.repair(manifest, opts.quick)) {
            Ok(()) => e,
            Err(r) => e.context(format!("and bringing {} in line with its runs failed too: {r:#}", store.dir().root.display())),
        }
    })
}

/// What `run` would do with a planned run ([`plan`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Planned {
    /// Not stored (or `--fresh`): computed.
    Compute,
    /// Stored with its spec: kept, nothing computed.
    Keep,
    /// Stored with another spec: replaced (`--replace`), with what differs.
    Replace(Vec<String>),
    /// Stored but no longer declared: removed with its snapshots (`--replace`), and why.
    Remove(String),
}

/// What `run` would do ([`plan`]): each run, by id, and the leftover files of unfinished runs it
/// removes first (the plan names both these and the runs `--replace` removes).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Plan {
    pub runs: Vec<(String, Planned)>,
    pub leftovers: Vec<PathBuf>,
    /// What `--fresh` removes first: every file of the study the store wrote, or a shard's
    /// runs' records, snapshots and checkpoints.
    pub removals: Vec<PathBuf>,
}

/// What `run --plan` prints: each run of `manifest` in `opts`' shard and what `run` would do
/// with it, read from the results folder through the same check and the same refusal as `run`'s
/// set-up (a folder `run` refuses, damaged or with runs stored with another spec, is refused
/// here too, never listed with exit status 0 where `run` refuses). Changes
/// nothing. A folder another process writes now is read as it is, with a note that says so.
pub fn plan(manifest: &Manifest, opts: &RunOptions) -> Result<Plan> {
    let store = Store::of(&opts.results, manifest);
    let in_shard = |i: usize| opts.shard.is_none_or(|(k, n)| i % n == k - 1);
    let planned: Vec<RunSpec> =
        manifest.runs.iter().enumerate().filter(|(i, _)| in_shard(*i)).map(|(_, p)| effective_spec(p, opts.quick)).collect();
    let computed = |planned: Vec<RunSpec>| Plan {
        runs: planned.into_iter().map(|s| (s.id, Planned::Compute)).collect(),
        leftovers: Vec::new(),
        removals: Vec::new(),
    };
    if opts.fresh {
        let found = store::owned::inventory(store.dir())?;
        if !found.foreign.is_empty() && opts.shard.is_none() {
            return Err(store::owned::refusal("run --fresh", store.dir(), &found.foreign));
        }
        let ids: Vec<&str> = planned.iter().map(|s| s.id.as_str()).collect();
        let of_shard = |p: &PathBuf| run_of_file(store.dir(), p).is_some_and(|r| ids.contains(&r.as_str()));
        let removals = found.data.into_iter().filter(|p| opts.shard.is_none() || of_shard(p)).collect();
        return Ok(Plan { removals, ..computed(planned) });
    }
    if !store.dir().root.exists() {
        return Ok(computed(planned));
    }
    let checked = match store.check() {
        Ok(checked) => checked,
        Err(e) => match e.downcast_ref::<store::BeingWritten>() {
            Some(w) => {
                model::base::note::line(format_args!("{}: {w}", manifest.study));
                return Ok(computed(planned));
            }
            None => return Err(e),
        },
    };
    let mut stale = store::stale::damaged(&checked.faults);
    stale.extend(store::stale::stale_runs(manifest, &checked.runs, &planned));
    if !stale.is_empty() && !opts.replace {
        return Err(store::stale::refusal(manifest, store.dir(), &stale));
    }
    let damaged = |id: &str| stale.iter().any(|s| matches!(s, store::Stale::Damaged { file, .. } if file == id));
    let mut runs: Vec<(String, Planned)> = planned
        .into_iter()
        .map(|spec| {
            let doing = match checked.runs.iter().find(|r| r.run.id == spec.id) {
                // a record that cannot be read is not among the runs, and is replaced all the same
                _ if damaged(&spec.id) => Planned::Replace(vec!["its record does not hold together".to_string()]),
                None => Planned::Compute,
                Some(r) if r.run == spec => Planned::Keep,
                Some(r) => Planned::Replace(store::stale::spec_differences(&r.run, &spec)),
            };
            (spec.id, doing)
        })
        .collect();
    // what --replace removes besides: the runs stored but not declared, readable or not
    for s in &stale {
        let (id, why) = match s {
            store::Stale::Undeclared { id } => (id, format!("not declared in {}", manifest.file.display())),
            store::Stale::Damaged { file, .. } if !runs.iter().any(|(id, _)| id == file) => {
                (file, format!("a damaged record, not declared in {}", manifest.file.display()))
            }
            _ => continue,
        };
        runs.push((id.clone(), Planned::Remove(why)));
    }
    Ok(Plan { runs, leftovers: checked.leftovers, removals: Vec::new() })
}

/// The run a file of a study folder belongs to: `runs/RUN.json`, `.partial/RUN.json` (its
/// checkpoint), `meshes/RUN_levelL.*`; `None` for the study's shared files.
fn run_of_file(dir: &::store::records::StudyDir, file: &std::path::Path) -> Option<String> {
    let name = file.file_name()?.to_string_lossy().into_owned();
    let folder = file.parent()?.strip_prefix(&dir.root).ok()?.to_str()?.to_string();
    match folder.as_str() {
        "meshes" => ::store::records::StudyDir::parse_mesh_name(&name).map(|(r, _)| r.to_string()),
        "runs" | ".partial" => name.strip_suffix(".json").map(str::to_string),
        _ => None,
    }
}

/// Under the study lock: `--fresh`, the orphans of unfinished runs removed, stored runs whose
/// spec differs refused (or with `--replace` undeclared ones removed), the summaries in line
/// with the runs stored.
fn set_up(manifest: &Manifest, store: &Store, planned: &[RunSpec], opts: &RunOptions) -> Result<()> {
    let declared: Vec<String> = manifest.runs.iter().map(|p| p.spec.id.clone()).collect();
    let (writer, _held) = if opts.fresh {
        let shard: Option<Vec<String>> = opts.shard.map(|_| planned.iter().map(|s| s.id.clone()).collect());
        let (writer, held) = store.lock_every_run(shard.as_deref(), &declared, opts.wait_for_lock)?;
        // with a shard only its runs (the other shards' are someone else's); without, the whole
        // study, also runs no longer declared
        writer.start_over(&held, opts.shard.is_none())?;
        (writer, held)
    } else {
        (store.lock(opts.wait_for_lock)?, Vec::new())
    };
    if !opts.fresh {
        // (--fresh holds every run's lock: none is computed by another process)
        writer.refuse_foreign_runs_in_progress(manifest)?;
    }
    let checked = writer.check()?;
    let mut runs = checked.runs;
    let mut stale = store::stale::damaged(&checked.faults);
    stale.extend(store::stale::stale_runs(manifest, &runs, planned));
    // a refusal changes nothing: it comes before any file is removed (so the snapshots and
    // reference of a run whose record is damaged are not removed as orphans before it)
    if !stale.is_empty() && !opts.replace && !opts.fresh {
        return Err(store::stale::refusal(manifest, store.dir(), &stale));
    }
    writer.remove_orphans(&runs)?;
    for s in &stale {
        let (id, why) = match s {
            store::Stale::Undeclared { id } => (id, format!("not declared in {}", manifest.file.display())),
            store::Stale::Damaged { file, what } => (file, format!("a damaged record: {}", what.join("; "))),
            store::Stale::Summary { file, .. } => {
                // a summary is rendered again below; a reference at fault is computed again
                if file.starts_with(store.dir().root.join("references")) {
                    let key = file.file_stem().map(|k| k.to_string_lossy().into_owned()).unwrap_or_default();
                    model::base::note::line(format_args!("{}: removing {} (at fault; computed again)", manifest.study, file.display()));
                    writer.remove_reference(&key)?;
                }
                continue;
            }
            store::Stale::Differs { .. } => continue,
        };
        model::base::note::line(format_args!("{}/{id}: removing the stored run and its snapshots ({why})", manifest.study));
        writer.remove_run(&writer.claim_run(id)?)?;
        runs = store.records()?;
    }
    runs.retain(|r| declared.contains(&r.run.id));
    writer.sync_summaries(manifest, &runs, opts.quick)
}

/// Run the planned runs not stored with their spec yet, each under its run lock (another process
/// may compute the others side by side: a shard of the same study), storing each as it finishes
/// under the study lock.
fn run_planned(manifest: &Manifest, store: &Store, planned: &[RunSpec], opts: &RunOptions) -> Result<Vec<String>> {
    let mut executed = Vec::new();
    for spec in planned {
        // a finished run no process computes now is kept without taking its lock (a run that
        // executes nothing writes nothing); one being computed (replaced) is waited for or refused
        if store.finished(spec)? {
            keep(manifest, store, spec, opts)?;
            continue;
        }
        let run = store.lock_run(&spec.id, opts.wait_for_lock)?;
        // read again under the run's lock: another process may have stored the run meanwhile
        match store.record(&spec.id)? {
            Some(r) if r.run == *spec => {
                keep(manifest, store, spec, opts)?;
                continue;
            }
            Some(r) if !opts.replace => bail!(
                "{}: another process stored run {} of {} with another spec while this one waited for it ({}); not replacing it. \
                 The runs this process finished before it are kept. Pass --replace to replace it",
                manifest.file.display(),
                spec.id,
                store.dir().root.display(),
                store::stale::spec_differences(&r.run, spec).join("; ")
            ),
            Some(r) => model::base::note::line(format_args!(
                "{}/{}: replacing the stored run when the new one has finished ({})",
                manifest.study,
                spec.id,
                store::stale::spec_differences(&r.run, spec).join("; ")
            )),
            None => {}
        }
        let mut meshes = Batch::default();
        let Some(record) = run_one(&manifest.study, spec, &manifest.file, &run, &mut meshes, opts.progress)? else {
            // interrupted: what the unfinished run wrote goes with `meshes`; the finished ones stay
            drop(meshes);
            return Err(interruption(manifest, store, opts));
        };
        store.lock(true)?.commit_run(&run, manifest, record, meshes, opts.quick)?;
        executed.push(spec.id.clone());
    }
    Ok(executed)
}

/// Run `spec`, stored as declared: said so, and its reference stored if it is missing. With
/// `--fresh` this process removed the run when it started over, so the record it finds now was
/// stored by another process since (one that waited for the run's lock meanwhile): said so, and
/// never the advice to start over, which is what this process did.
fn keep(manifest: &Manifest, store: &Store, spec: &RunSpec, opts: &RunOptions) -> Result<()> {
    if opts.progress {
        let how = if opts.fresh {
            "computed by another process after this one started over (--fresh), kept"
        } else {
            "finished earlier, kept (use --fresh to start over)"
        };
        model::base::note::line(format_args!("{}/{}: {how}", manifest.study, spec.id));
    }
    store_missing_reference(manifest, store, spec, opts)
}

/// A finished run whose reference solution the study does not store (a folder written before
/// references were stored, or a deleted file): computed once by the adaptive loop and stored
/// with its history, after checking that it is the reference the run was measured against
/// (the same NDF; the errors the drift check compares tell the rest).
fn store_missing_reference(manifest: &Manifest, store: &Store, spec: &RunSpec, opts: &RunOptions) -> Result<()> {
    let Some(key) = ::store::records::ReferenceRecord::key_of(spec) else { return Ok(()) };
    if matches!(store.reference(&key), Ok(Some(_))) {
        return Ok(());
    }
    model::base::note::line(format_args!(
        "{}/{}: the history of its reference solution is not stored in {}; computing it once",
        manifest.study,
        spec.id,
        store.dir().root.display()
    ));
    let Some(prepared) = prepare(&manifest.study, spec, &manifest.file, opts.progress)? else {
        return Err(interruption(manifest, store, opts));
    };
    let reference = prepared.reference.expect("a run with a reference spec is prepared with its reference");
    let stored = store.record(&spec.id)?.and_then(|r| r.reference_ndof);
    if stored != Some(reference.ndof) {
        bail!(
            "{}/{}: the reference solution computed now has {} unknowns, the stored run was measured against one of {}; rerun it with --replace",
            manifest.study,
            spec.id,
            reference.ndof,
            stored.map_or("none".to_string(), |n| n.to_string())
        );
    }
    store.lock(true)?.commit_reference(&::store::records::ReferenceRecord::new(spec, &reference.spec, reference.rebuild.clone()))
}

/// The error of an interrupted study: the runs kept, those missing, the command that resumes.
fn interruption(manifest: &Manifest, store: &Store, opts: &RunOptions) -> anyhow::Error {
    let kept: Vec<String> = match store.records() {
        Ok(runs) => runs.iter().map(|r| r.run.id.clone()).collect(),
        Err(e) => return e,
    };
    let missing = manifest.runs.iter().map(|p| p.spec.id.clone()).filter(|id| !kept.contains(id)).collect();
    let mut resume = format!("signorini run {}", manifest.file.display());
    if opts.quick {
        resume += " --quick";
    }
    if let Some((k, n)) = opts.shard {
        resume += &format!(" --shard {k}/{n}");
    }
    if opts.results != std::path::Path::new(if opts.quick { "target/quick-results" } else { "results" }) {
        resume += &format!(" --results {}", opts.results.display());
    }
    Interrupted { study: manifest.study.clone(), resume, kept, missing }.into()
}
/// The key of a run's reference solution in the cache: problem and mesh as resolved (two
/// manifests may name different files by the same relative path).
fn reference_key(spec: &RunSpec, problem: &str, mesh: &str) -> Option<String> {
    spec.reference.as_ref().map(|r| format!("{}|{:?}|{}|{}|{}|{:?}", problem, spec.constants, mesh, r.theta, r.min_ndof, r.contact_term))
}

/// What a run solves besides its spec: the problem, the initial mesh and, for a problem without
/// an exact solution, the reference solution errors are measured against.
pub struct Prepared {
    pub problem: Box<dyn problems::Problem>,
    pub mesh_spec: MeshSpec,
    pub reference: Option<Arc<ReferenceField>>,
    /// The run's input files pinned to the bytes its spec holds the hashes of, for as long as
    /// the run computes ([`manifest::pin_inputs`]): every later read (the initial mesh built
    /// again on resuming, a replay) is of those bytes too.
    pub pins: model::base::pin::Pins,
    /// The code that computes the run: its checkpoint holds it, and only its own is resumed.
    pub code: provenance::CodeVersion,
}

impl Prepared {
    /// Call `f` with what errors are measured against: the exact solution, else the reference
    /// solution, else nothing.
    pub fn with_error_against<R>(&self, f: impl FnOnce(Option<numerics::contact::norms::Reference>) -> R) -> R {
        let exact = self.problem.exact();
        let exact_fn = exact.map(|e| move |x: [f64; 2]| e.u(x));
        match (&exact_fn, &self.reference) {
            (Some(e), _) => f(Some(e)),
            (None, Some(r)) => f(Some(r.as_ref())),
            (None, None) => f(None),
        }
    }

    pub fn initial_mesh(&self) -> Result<model::mesh::Mesh> {
        Ok(self.mesh_spec.build(self.problem.as_ref())?)
    }
}

/// Load a run's problem and initial mesh (relative to `manifest_file`) and compute (or take from
/// this process's cache) its reference solution. `None` when interrupted.
pub fn prepare(study: &str, spec: &RunSpec, manifest_file: &std::path::Path, progress: bool) -> Result<Option<Prepared>> {
    let pins = manifest::pin_inputs(manifest_file, spec);
    let problem_path = manifest::resolve_problem(manifest_file, &spec.problem);
    let mesh_path = manifest::resolve_mesh(manifest_file, &spec.mesh);
    let problem = problems::load(&problem_path, &spec.constants)?;
    let mesh_spec = MeshSpec::parse(&mesh_path)?;
    model::base::memory::check_memory(&format!("{study}/{}: the initial mesh {}", spec.id, spec.mesh), mesh_spec.ndof()?)?;
    if spec.reference.is_some() && problem.exact().is_some() {
        bail!("{study}/{}: problem {} has an exact solution; a reference solution is not needed", spec.id, spec.problem);
    }
    let reference = match (reference_key(spec, &problem_path, &mesh_path), &spec.reference) {
        (Some(key), Some(rs)) => {
            let computed = reference_for(&key, || {
                let started = std::time::Instant::now();
                let label = format!("{study}/{}: reference solution (adaptive to NDF >= {})", spec.id, rs.min_ndof);
                let spinner = Progress::new(progress, 0, &label);
                let field = reference::compute(problem.as_ref(), &mesh_spec, rs, &mut |r| {
                    spinner.message(format!("level {}, NDF {} of at least {}", r.level, r.ndof, rs.min_ndof));
                    if interrupted() { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
                })
                .with_context(|| format!("{study}/{}: computing the reference solution", spec.id))?;
                spinner.finish();
                let field = field.ok_or_else(|| anyhow::anyhow!("interrupted"))?;
                if progress {
                    model::base::note::line(format_args!("{label}: NDF {} in {:.1} s", field.ndof, started.elapsed().as_secs_f64()));
                }
                Ok(field)
            });
            match computed {
                Ok(r) => Some(r),
                Err(_) if interrupted() => return Ok(None),
                Err(e) => return Err(e),
            }
        }
        _ => None,
    };
    Ok(Some(Prepared { problem, mesh_spec, reference, pins, code: provenance::code_version(manifest_file) }))
}

/// Take the reference solutions of `manifest`'s runs from the study folder `stored` where it
/// holds them (`references/KEY.json`): each rebuilt from its refinement history in one solve
/// ([`reference::replay`]) into this process's cache, where [`prepare`] finds it instead of
/// computing it by the adaptive loop. What the drift check does, so that a 4.5e6-unknown
/// reference costs one solve, not forty; `drift --deep` computes them anew and compares their
/// histories with the stored ones. A run whose reference is not stored is left to [`prepare`].
pub fn preload_references(manifest: &Manifest, stored: &Store, progress: bool) -> Result<()> {
    for planned in &manifest.runs {
        let spec = &planned.spec;
        let problem_path = manifest::resolve_problem(&manifest.file, &spec.problem);
        let mesh_path = manifest::resolve_mesh(&manifest.file, &spec.mesh);
        let (Some(key), Some(file_key)) = (reference_key(spec, &problem_path, &mesh_path), ::store::records::ReferenceRecord::key_of(spec))
        else {
            continue;
        };
        let Some(record) = stored.reference(&file_key)? else { continue };
        let study = &manifest.study;
        reference_for(&key, || {
            let started = std::time::Instant::now();
            let label = format!(
                "{study}/{}: reference solution from its stored history (level {}, NDF {})",
                spec.id,
                record.rebuild.history.levels.len().saturating_sub(1),
                record.rebuild.ndof
            );
            let spinner = Progress::new(progress, 0, &label);
            let _pins = manifest::pin_inputs(&manifest.file, spec);
            let problem = problems::load(&problem_path, &spec.constants)?;
            let mesh_spec = MeshSpec::parse(&mesh_path)?;
            let field =
                reference::replay(problem.as_ref(), &mesh_spec, &record.spec, &record.rebuild, &manifest.drift).with_context(|| {
                    format!("{study}/{}: replaying the stored reference {}", spec.id, stored.dir().reference_file(&file_key).display())
                })?;
            spinner.finish();
            if progress {
                model::base::note::line(format_args!("{label}: rebuilt in {:.1} s", started.elapsed().as_secs_f64()));
            }
            Ok(field)
        })?;
    }
    Ok(())
}

/// One run of the manifest at `manifest_file` (its problem and mesh files are relative to it): the
/// adaptive loop with a progress bar, adding the declared levels' mesh snapshots to `meshes`, a
/// checkpoint after every level that is not the last ([`store::checkpoint`]), resumed from the
/// checkpoint of an earlier, stopped process if there is one. `None` when interrupted.
fn run_one(
    study: &str,
    spec: &RunSpec,
    manifest_file: &std::path::Path,
    run: &RunWriter,
    meshes: &mut Batch,
    progress: bool,
) -> Result<Option<RunRecord>> {
    let Some(prepared) = prepare(study, spec, manifest_file, progress)? else { return Ok(None) };
    let config = spec.adapt_config();
    let start = start_of(study, spec, run, meshes, &prepared, &config, progress)?;
    let Some((result, at_roundoff)) = loop_of(study, spec, run, meshes, &prepared, &config, start, progress)? else { return Ok(None) };
    // why a run ended before its last level, and which levels measure round-off, are said here,
    // not stored (a record field would change every stored record)
    let mut stopped = result.termination.note(&config).map(|note| format!(" ({note})")).unwrap_or_default();
    if !at_roundoff.is_empty() {
        let list: Vec<String> = at_roundoff.iter().map(ToString::to_string).collect();
        stopped += &format!(
            " (warning: level(s) {} at the round-off of u_h: their estimate and efficiency measure round-off, not the discretisation error)",
            list.join(", ")
        );
    }
    let (levels, history) = (result.records, result.history);
    if progress {
        let last = levels.last().expect("at least one level");
        model::base::note::line(format_args!(
            "{study}/{}: {} levels, final NDF {}, estimate {:.3e}{stopped}",
            spec.id,
            levels.len(),
            last.ndof,
            last.terms.estimate
        ));
    }
    let reference_ndof = prepared.reference.as_ref().map(|r| r.ndof);
    if let Some(r) = &prepared.reference {
        run.stage_reference(&::store::records::ReferenceRecord::new(spec, &r.spec, r.rebuild.clone()), meshes)?;
    }
    Ok(Some(RunRecord {
        study: study.to_string(),
        run: spec.clone(),
        levels,
        reference_ndof,
        history: Some(history),
        snapshots: Default::default(),
    }))
}

/// Where the run starts: level 0, or after the last level of its checkpoint (the mesh snapshots
/// of the levels before it are made again by replaying those levels).
fn start_of(
    study: &str,
    spec: &RunSpec,
    run: &RunWriter,
    meshes: &mut Batch,
    prepared: &Prepared,
    config: &AdaptConfig,
    progress: bool,
) -> Result<adapt::Start> {
    let mesh0 = prepared.initial_mesh()?;
    let Some(c) = run.checkpoint(spec, &prepared.code) else { return Ok(adapt::Start::new(mesh0)) };
    let done = c.levels.len();
    model::base::note::line(format_args!(
        "{study}/{}: resuming after level {} (from {})",
        spec.id,
        done - 1,
        run.checkpoint_file().display()
    ));
    let problem = prepared.problem.as_ref();
    for &l in spec.save_levels.iter().filter(|&&l| l < done) {
        let (mesh, solved) = prepared
            .with_error_against(|r| adapt::replay::solve_stored_level(problem, mesh0.clone(), config, &c.history, l, c.levels.get(l), r))
            .with_context(|| format!("{study}/{}: replaying level {l} for its mesh snapshot", spec.id))?;
        let level = Level {
            record: &c.levels[l],
            mesh: &mesh,
            solution: &solved.solution,
            estimate: &solved.estimate,
            history: &c.history.levels[l],
            continues: true,
            next_active: None,
            caveats: &solved.caveats,
        };
        save_level(study, spec, run, meshes, &level, problem)?;
    }
    let next_active =
        c.next_active.as_ref().map(|f| f.decode()).transpose().with_context(|| format!("{study}/{}: the checkpoint", spec.id))?;
    let start = adapt::replay::resume(mesh0, c.levels, c.history, next_active).with_context(|| format!("{study}/{}: resuming", spec.id))?;
    if progress {
        model::base::note::line(format_args!("{study}/{}: level {} rebuilt from the stored marks", spec.id, start.level));
    }
    Ok(start)
}

/// The adaptive loop of a run from `start`, with its progress bar, snapshots and checkpoints,
/// and the levels it solved at round-off ([`adapt::Caveat::AtRoundoff`], for the run's summary
/// line). `None` when interrupted.
#[allow(clippy::too_many_arguments)]
fn loop_of(
    study: &str,
    spec: &RunSpec,
    run: &RunWriter,
    meshes: &mut Batch,
    prepared: &Prepared,
    config: &AdaptConfig,
    start: adapt::Start,
    progress: bool,
) -> Result<Option<(adapt::AdaptResult, Vec<usize>)>> {
    let problem = prepared.problem.as_ref();
    let mut at_roundoff = Vec::new();
    let pb = Progress::new(progress, spec.levels as u64, &format!("{study}/{}", spec.id));
    pb.inc(start.level as u64);
    let mut level_error: Option<anyhow::Error> = None;
    let mut stopped = false;
    let mut kept = store::checkpoint::Checkpoint {
        run: spec.clone(),
        code: prepared.code.clone(),
        sha256: String::new(),
        levels: start.records.clone(),
        history: start.history.clone(),
        next_active: None,
    };
    let result = prepared.with_error_against(|error_against| {
        adapt::run_from(problem, start, config, error_against, &mut |level: Level| {
            let r = level.record;
            pb.message(format!(
                "level {} NDF {} estimate {:.3e}{}",
                r.level,
                r.ndof,
                r.terms.estimate,
                r.err_quadrature.map(|e| format!(" error {e:.3e}")).unwrap_or_default()
            ));
            pb.inc(1);
            for c in level.caveats {
                model::base::note::line(format_args!("warning: {study}/{}: level {}: {c}", spec.id, r.level));
            }
            if level.caveats.iter().any(|c| matches!(c, adapt::Caveat::AtRoundoff)) {
                at_roundoff.push(r.level);
            }
            let kept_level = keep_level(study, spec, run, meshes, &level, prepared).and_then(|()| {
                kept.levels.push(r.clone());
                kept.history.levels.push(level.history.clone());
                kept.next_active = level.next_active.map(model::level::history::Flags::encode);
                if level.continues { run.keep(&kept) } else { Ok(()) }
            });
            if let Err(e) = kept_level {
                level_error = Some(e);
                return ControlFlow::Break(());
            }
            if interrupted() {
                stopped = true;
                return ControlFlow::Break(());
            }
            ControlFlow::Continue(())
        })
    });
    let result = result.with_context(|| format!("{study}/{}", spec.id))?;
    pb.finish();
    if let Some(e) = level_error {
        return Err(e);
    }
    Ok((!stopped).then_some((result, at_roundoff)))
}

/// Rebuild level `level` of a stored run from its refinement history and solve it again
/// ([`adapt::replay::solve_stored_level`]): the drift check's replay tier. The run's problem,
/// mesh and reference are those of `manifest`.
pub fn replay_stored_level(manifest: &Manifest, stored: &RunRecord, level: usize, progress: bool) -> Result<adapt::Solved> {
    let spec = &stored.run;
    let what = format!("{}/{}: replaying level {level}", manifest.study, spec.id);
    let history = stored.history.as_ref().ok_or_else(|| anyhow::anyhow!("{what}: the stored run has no refinement history"))?;
    let prepared = prepare(&manifest.study, spec, &manifest.file, progress)?.ok_or_else(|| anyhow::anyhow!("{what}: interrupted"))?;
    let mesh0 = prepared.initial_mesh()?;
    let config = spec.adapt_config();
    let problem = prepared.problem.as_ref();
    let spinner = Progress::new(progress, 0, &what);
    let (_, solved) = prepared
        .with_error_against(|r| adapt::replay::solve_stored_level(problem, mesh0, &config, history, level, stored.levels.get(level), r))
        .context(what)?;
    spinner.finish();
    Ok(solved)
}

/// A level just solved: its record must be one a file can hold (every float finite; otherwise
/// the run stops here, naming the level, the field and the value), its errors measured against
/// a reference finer than it by [`manifest::REFERENCE_MARGIN`] (otherwise they measure the
/// reference's error: the run stops here), and its mesh snapshot is added to `meshes` if the
/// run saves it. Every level a run computes comes through here.
fn keep_level(study: &str, spec: &RunSpec, run: &RunWriter, meshes: &mut Batch, level: &Level, prepared: &Prepared) -> Result<()> {
    let r = level.record;
    if let Some(bad) = ::store::records::first_non_finite(r) {
        bail!("{study}/{}: level {}: {bad}; a record cannot hold it, so the run stops here and nothing of it is stored", spec.id, r.level);
    }
    if let (Some(reference), Some(rs)) = (&prepared.reference, &spec.reference)
        && manifest::too_coarse_for(reference.ndof, r.ndof)
    {
        bail!(
            "{study}/{}: level {} has NDF {}, and its errors would be measured against a reference solution of NDF {} (reference.min_ndof = {}), \
             less than {} times finer: they would measure the reference's error, not the level's. Nothing of the run is stored; \
             raise reference.min_ndof to at least {} times the NDF of the run's last level (or give the run fewer levels, max_ndof or stop_ndof)",
            spec.id,
            r.level,
            r.ndof,
            reference.ndof,
            rs.min_ndof,
            manifest::REFERENCE_MARGIN,
            manifest::REFERENCE_MARGIN
        );
    }
    let problem = prepared.problem.as_ref();
    if spec.save_levels.contains(&r.level) {
        save_level(study, spec, run, meshes, level, problem)?;
    }
    Ok(())
}

/// Add a level's mesh and fields as VTU (displacement, contact force, active set, element
/// indicators) and the mesh snapshot JSON the mesh figure reads to `meshes`.
fn save_level(
    study: &str,
    spec: &RunSpec,
    run: &RunWriter,
    meshes: &mut Batch,
    level: &Level,
    problem: &dyn problems::Problem,
) -> Result<()> {
    let (mesh, sol) = (level.mesh, level.solution);
    let doc = crate::report::solution_vtu(mesh, sol, &level.estimate.element);
    let l = level.record.level;
    meshes.add(&run.snapshot_file(l, "vtu"), doc.as_bytes())?;
    let snapshot = MeshSnapshot {
        study: study.to_string(),
        run: spec.id.clone(),
        level: l,
        ndof: level.record.ndof,
        vertices: mesh.vertices.clone(),
        triangles: mesh.triangles.clone(),
        contact_nodes: numerics::contact::solve::contact_samples(mesh, sol),
        kinks: problem.required_vertices(),
    };
    meshes.add_json(&run.snapshot_file(l, "json"), &snapshot)?;
    Ok(())
}
