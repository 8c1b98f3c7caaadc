//! Declared studies: manifests in `experiments/*.toml`, run into `results/STUDY/`.
//!
//! A study is a list of independent runs (problem, initial mesh, refinement, estimator variant).
//! Each finished run is written at once, atomically, as `runs/RUN.json`, so an interrupted study
//! keeps every run it finished and a rerun resumes after them (unless told to start over).
//! `--shard K/N` runs every N-th run; shards merge by run id, since the CSV and the provenance
//! are rebuilt from all run records present. `--quick` runs the first `quick_levels` levels of
//! the same runs: the exact prefix of the full study (same meshes, same numbers).

pub mod drift;
pub mod manifest;
pub mod provenance;
pub mod reference;

use crate::adapt::{self, AdaptConfig, Level};
use crate::mesh::{MeshSpec, io};
use crate::problems;
use crate::records::{self, MeshSnapshot, RunRecord, RunSpec, StudyDir};
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use manifest::Manifest;
use reference::ReferenceField;
use std::collections::HashMap;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// Reference solutions computed in this process, shared by every run and study that declares
/// the same one (they are deterministic, so sharing changes no number).
static REFERENCES: Mutex<Option<HashMap<String, Arc<ReferenceField>>>> = Mutex::new(None);

fn reference_for(key: &str, compute: impl FnOnce() -> Result<ReferenceField>) -> Result<Arc<ReferenceField>> {
    if let Some(r) = REFERENCES.lock().expect("reference cache").get_or_insert_default().get(key) {
        return Ok(r.clone());
    }
    let r = Arc::new(compute()?);
    REFERENCES.lock().expect("reference cache").get_or_insert_default().insert(key.to_string(), r.clone());
    Ok(r)
}

/// How to run a study.
#[derive(Clone, Debug)]
pub struct RunOptions {
    pub quick: bool,
    /// (K, N): run the runs with index i such that i % N == K - 1.
    pub shard: Option<(usize, usize)>,
    /// Delete this study's stored runs first instead of resuming.
    pub fresh: bool,
    /// The results root (`results/`).
    pub results: PathBuf,
    pub progress: bool,
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

/// Run a study; returns the ids of the runs executed (not resumed).
pub fn run_study(manifest: &Manifest, opts: &RunOptions) -> Result<Vec<String>> {
    let dir = StudyDir::new(&opts.results, &manifest.study);
    if opts.fresh {
        for sub in ["runs", "meshes"] {
            let p = dir.root.join(sub);
            if p.exists() {
                std::fs::remove_dir_all(&p).with_context(|| format!("removing {}", p.display()))?;
            }
        }
    }
    let mut executed = Vec::new();
    for (i, planned) in manifest.runs.iter().enumerate() {
        if let Some((k, n)) = opts.shard {
            if i % n != k - 1 {
                continue;
            }
        }
        let spec = effective_spec(planned, opts.quick);
        if let Some(existing) = dir.read_run(&spec.id)? {
            if existing.run == spec {
                if opts.progress {
                    eprintln!("{}/{}: finished earlier, kept (use --fresh to start over)", manifest.study, spec.id);
                }
                continue;
            }
            eprintln!("{}/{}: stored run has another spec, running it again", manifest.study, spec.id);
        }
        let record = run_one(&manifest.study, &spec, &dir, opts.progress)?;
        records::write_json(&dir.run_file(&spec.id), &record).with_context(|| format!("writing {}", dir.run_file(&spec.id).display()))?;
        executed.push(spec.id.clone());
    }
    let runs = dir.read_runs()?;
    dir.write_csv(&runs)?;
    let prov = provenance::collect(&manifest.study, &manifest.file, &manifest.bytes, opts.quick, runs.iter().map(|r| r.run.id.clone()).collect());
    records::write_json(&dir.provenance_file(), &prov)?;
    Ok(executed)
}

fn reference_key(spec: &RunSpec) -> Option<String> {
    spec.reference.as_ref().map(|r| format!("{}|{}|{}|{}|{:?}", spec.problem, spec.mesh, r.theta, r.min_ndof, r.contact_term))
}

/// One run: the adaptive loop with a progress bar, saving the declared levels.
fn run_one(study: &str, spec: &RunSpec, dir: &StudyDir, progress: bool) -> Result<RunRecord> {
    let problem = problems::by_name(&spec.problem)?;
    let mesh_spec = MeshSpec::parse(&spec.mesh)?;
    let reference = match (reference_key(spec), &spec.reference) {
        (Some(key), Some(rs)) => Some(reference_for(&key, || {
            let spinner = bar(progress, 0, &format!("{study}/{}: reference solution (min NDF {})", spec.id, rs.min_ndof));
            let field = reference::compute(problem.as_ref(), &mesh_spec, rs).with_context(|| format!("{study}/{}: computing the reference solution", spec.id));
            spinner.finish_and_clear();
            field
        })?),
        _ => None,
    };
    let exact = problem.exact();
    let exact_fn = exact.map(|e| move |x: [f64; 2]| e.u(x));
    let reference_fn = reference.as_ref().map(|r| move |x: [f64; 2]| r.eval(x));
    let error_against: Option<crate::norms::Reference> = match (&exact_fn, &reference_fn) {
        (Some(f), _) => Some(f),
        (None, Some(f)) => Some(f),
        (None, None) => None,
    };
    if spec.reference.is_some() && exact.is_some() {
        bail!("{study}/{}: problem {} has an exact solution; a reference solution is not needed", spec.id, spec.problem);
    }
    let config = AdaptConfig {
        levels: spec.levels,
        max_ndof: spec.max_ndof,
        refine: spec.refine,
        theta: spec.theta,
        estimator: spec.estimator,
        ..Default::default()
    };
    let pb = bar(progress, spec.levels as u64, &format!("{study}/{}", spec.id));
    let mut save_error: Option<anyhow::Error> = None;
    let mesh = mesh_spec.build(&|x| problem.part_of(x));
    let levels = adapt::run(problem.as_ref(), mesh, &config, error_against, &mut |level: Level| {
        let r = level.record;
        pb.set_message(format!("level {} NDF {} estimate {:.3e}{}", r.level, r.ndof, r.estimate, r.err_quadrature.map(|e| format!(" error {e:.3e}")).unwrap_or_default()));
        pb.inc(1);
        if spec.save_levels.contains(&r.level) {
            if let Err(e) = save_level(study, spec, dir, &level, problem.as_ref()) {
                save_error = Some(e);
                return ControlFlow::Break(());
            }
        }
        ControlFlow::Continue(())
    })
    .with_context(|| format!("{study}/{}", spec.id))?;
    pb.finish_and_clear();
    if let Some(e) = save_error {
        return Err(e);
    }
    if progress {
        let last = levels.last().expect("at least one level");
        eprintln!("{study}/{}: {} levels, final NDF {}, estimate {:.3e}", spec.id, levels.len(), last.ndof, last.estimate);
    }
    Ok(RunRecord { study: study.to_string(), run: spec.clone(), levels, reference_ndof: reference.as_ref().map(|r| r.ndof) })
}

fn bar(progress: bool, len: u64, prefix: &str) -> ProgressBar {
    if !progress {
        return ProgressBar::hidden();
    }
    let pb = if len == 0 { ProgressBar::new_spinner() } else { ProgressBar::new(len) };
    let style = if len == 0 {
        ProgressStyle::with_template("{spinner} {prefix} [{elapsed}]").expect("valid template")
    } else {
        ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} {msg} [{elapsed}]").expect("valid template").progress_chars("=> ")
    };
    pb.set_style(style);
    pb.set_prefix(prefix.to_string());
    pb.enable_steady_tick(std::time::Duration::from_millis(200));
    pb
}

/// Write a level's mesh and fields as VTU (displacement, contact force, active set, element
/// indicators) and the mesh snapshot JSON the mesh figure reads.
fn save_level(study: &str, spec: &RunSpec, dir: &StudyDir, level: &Level, problem: &dyn problems::Problem) -> Result<()> {
    let (mesh, sol) = (level.mesh, level.solution);
    let n = sol.nodes.len();
    let (mut lambda, mut active, mut contact) = (vec![0.0; n], vec![0i32; n], vec![0i32; n]);
    let mut contact_nodes = Vec::new();
    for (k, c) in sol.dofs.contact.iter().enumerate() {
        lambda[c.node] = sol.lambda[k];
        active[c.node] = sol.active[k] as i32;
        contact[c.node] = 1;
        contact_nodes.push((sol.nodes.coords[c.node], sol.active[k]));
    }
    let doc = io::vtu(
        mesh,
        &sol.nodes,
        &[("u", io::Field::Vector(&sol.u)), ("lambda", io::Field::Scalar(&lambda)), ("active", io::Field::Int(&active)), ("contact", io::Field::Int(&contact))],
        &[("indicator", io::Field::Scalar(&level.estimate.element))],
    );
    let l = level.record.level;
    records::write_atomic(&dir.mesh_file(&spec.id, l, "vtu"), doc.as_bytes())?;
    let snapshot = MeshSnapshot {
        study: study.to_string(),
        run: spec.id.clone(),
        level: l,
        ndof: level.record.ndof,
        vertices: mesh.vertices.clone(),
        triangles: mesh.triangles.clone(),
        contact_nodes,
        kinks: problem.required_vertices(),
    };
    records::write_json(&dir.mesh_file(&spec.id, l, "json"), &snapshot)?;
    Ok(())
}
