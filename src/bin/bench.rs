//! `make bench`: phase timings of the contact solve of Example 7.2 on structured meshes,
//! medians over repeats, written to `results/bench/solver.json` and printed as a table.
//!
//! Phases: assembly, symbolic factorisation, numeric factorisation (first in the process, and
//! warm: a refactorisation of the same pattern), Schur complement, sparse solves, each
//! active-set iteration. Then what a user sees: whole contact solves in fresh processes (mesh,
//! assembly, ordering, factorisation, active set, displacement and contact force), interleaved
//! with NGSolve's whole linear solves of the same system in fresh processes, medians of three,
//! and one scale point; the table of the performance targets with met / not met. Then the
//! graded section (bench/graded.rs, alone with `--graded-only`): a factorisation's phases on the
//! deep study's graded levels beside the grid's and METIS's, in `results/bench/graded.json`.
//! Speed lives here, never in timed tests.

use anyhow::Result;
use clap::Parser;
use signorini::assembly::{self, DofMap};
use signorini::contact::ContactSolver;
use signorini::mesh::{MeshSpec, P2Nodes};
use signorini::problems::Ex72;
use signorini::records;
use signorini::settings::pdas::PdasOptions;
use signorini::solve;
use std::time::Instant;

#[derive(Parser)]
#[command(about = "Benchmark the P2 contact solver on Example 7.2")]
struct Args {
    /// Mesh sizes N of structured:N.
    #[arg(long, value_delimiter = ',', default_values_t = [32usize, 64, 128, 256, 512])]
    sizes: Vec<usize>,
    /// Repeats per size (medians are reported).
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// Output file.
    #[arg(long, default_value = "results/bench/solver.json")]
    out: std::path::PathBuf,
    /// NGSolve's timings of the same systems (crosscheck.py bench), printed side by side.
    #[arg(long, default_value = "results/bench/ngsolve_bench.json")]
    ngsolve: std::path::PathBuf,
    /// Sizes of the whole-process comparison with NGSolve (fresh processes, interleaved).
    #[arg(long, value_delimiter = ',', default_values_t = [256usize, 512])]
    cold_sizes: Vec<usize>,
    /// Fresh processes per size and solver in that comparison (medians are reported).
    #[arg(long, default_value_t = 3)]
    cold_repeats: usize,
    /// The scale point: one whole contact solve on structured:SCALE in a fresh process (0: none).
    #[arg(long, default_value_t = 1024)]
    scale: usize,
    /// The Python of the NGSolve cross-check (crosscheck/setup.sh creates it).
    #[arg(long, default_value = "crosscheck/.venv/bin/python")]
    python: std::path::PathBuf,
    /// The Python of the bench environment, whose NGSolve has MKL PARDISO (crosscheck/setup.sh
    /// bench creates it): the second anchor of the whole-solve comparison.
    #[arg(long, default_value = "crosscheck/.venv-bench/bin/python")]
    pardiso_python: std::path::PathBuf,
    /// Sizes of the factorisation-rate measurement (numeric phase against faer's dense LL^T).
    #[arg(long, value_delimiter = ',', default_values_t = [256usize, 512, 1024])]
    rate_sizes: Vec<usize>,
    /// Run the sizes in this process and print one JSON row per size (the parent runs every size
    /// in a child of its own, so that peak memory and first-touch costs are the size's own).
    #[arg(long, hide = true)]
    child: bool,
    /// Run one whole contact solve of the first size in this process and print its JSON row.
    #[arg(long, hide = true)]
    cold_child: bool,
    /// Only the rate of the numeric factorisation on these sizes beside faer's dense LL^T on
    /// every core (each size in a process of its own), printed and not written.
    #[arg(long, value_delimiter = ',')]
    factor_rate: Vec<usize>,
    /// Run the factor-rate measurement of the first size in this process.
    #[arg(long, hide = true)]
    rate_child: bool,
    /// The adaptive point: this run of experiments/deep.toml (Example 7.1 to 1e7 NDF) computed
    /// afresh in a process of its own, into a temporary results directory ("" for none).
    #[arg(long, default_value = "ex71_as_written")]
    adaptive: String,
    /// Run the adaptive point in this process.
    #[arg(long, hide = true)]
    adaptive_child: bool,
    /// The graded section (bench/graded.rs): the level nearest this NDF of each of
    /// `--graded-runs`, rebuilt from its stored history, and structured:N of about the same
    /// NDF, each factorised phase by phase (0: no graded section). Levels near 9e6 NDF need
    /// about 13 GiB.
    #[arg(long, default_value_t = 2e6)]
    graded_ndof: f64,
    /// The runs of experiments/deep.toml the graded section measures.
    #[arg(long, value_delimiter = ',', default_value = graded::RUNS)]
    graded_runs: Vec<String>,
    /// Only the graded section (no structured sizes, NGSolve, scale or adaptive point).
    #[arg(long)]
    graded_only: bool,
    /// The graded section's output file.
    #[arg(long, default_value = "results/bench/graded.json")]
    graded_out: std::path::PathBuf,
    /// Write each graded case's mesh (VTU) and node graph (n, entries, then ptr and adj as int32) into this folder.
    #[arg(long)]
    graded_save: Option<std::path::PathBuf>,
    /// Run one graded case (a run id, or structured:N) in this process.
    #[arg(long, hide = true)]
    graded_child: Option<String>,
}

#[path = "bench/graded.rs"]
mod graded;

/// The manifest of the adaptive point.
const DEEP_MANIFEST: &str = "experiments/deep.toml";

/// One adaptive run of the deep study from the first mesh to its last level, in a fresh process.
#[derive(serde::Serialize, serde::Deserialize, Clone)]
struct AdaptiveRun {
    run: String,
    levels: usize,
    last_ndof: usize,
    /// the whole process's work: every level, its records and their writing
    wall_s: f64,
    /// the levels' own times (t_level summed) and the last level's phases
    levels_s: f64,
    last_level_s: f64,
    last_factorisation_s: f64,
    peak_rss_mb: f64,
}

/// One whole contact solve in a fresh process: Example 7.2 on structured:N from nothing to the
/// displacement and the contact force (what `signorini solve` does before the estimator).
#[derive(serde::Serialize, serde::Deserialize, Clone)]
struct ColdRun {
    n: usize,
    unknowns: usize,
    whole_s: f64,
    mesh_s: f64,
    assembly_s: f64,
    symbolic_s: f64,
    numeric_s: f64,
    /// Schur complement, sparse solves, active-set iterations and the residual
    rest_s: f64,
    pdas_iterations: usize,
    peak_rss_mb: f64,
}

/// NGSolve's whole linear solve of the same system in a fresh process (`crosscheck.py bench-cold`).
#[derive(serde::Serialize, serde::Deserialize, Clone)]
struct NgRun {
    #[serde(rename = "N")]
    n: usize,
    whole_s: f64,
    mesh_s: f64,
    assembly_s: f64,
    factorisation_s: f64,
    solve_s: f64,
    peak_rss_mb: f64,
}

/// Medians of the fresh-process runs of one size.
#[derive(serde::Serialize, serde::Deserialize, Clone)]
struct ColdSize {
    n: usize,
    ours: Vec<ColdRun>,
    ngsolve: Vec<NgRun>,
    /// why NGSolve has no runs, if it has none
    ngsolve_missing: Option<String>,
    /// NGSolve with MKL PARDISO's LL^T (`inverse="pardisospd"` on the matrix stored as symmetric,
    /// in the bench venv), and why it has no runs
    #[serde(default)]
    pardiso: Vec<NgRun>,
    #[serde(default)]
    pardiso_missing: Option<String>,
}

fn cold_solve(n: usize) -> Result<ColdRun> {
    let t0 = Instant::now();
    let mesh = MeshSpec::Structured(n).build(&Ex72)?;
    let mesh_s = t0.elapsed().as_secs_f64();
    let sol = solve::solve(&mesh, &Ex72, &PdasOptions::default(), &mut |_| {})?;
    let whole_s = t0.elapsed().as_secs_f64();
    let t = &sol.timings;
    let (symbolic_s, numeric_s) = (t.contact.symbolic, t.contact.numeric);
    Ok(ColdRun {
        n,
        unknowns: sol.dofs.n_free,
        whole_s,
        mesh_s,
        assembly_s: t.assembly,
        symbolic_s,
        numeric_s,
        rest_s: whole_s - mesh_s - t.assembly - symbolic_s - numeric_s,
        pdas_iterations: sol.pdas.len(),
        peak_rss_mb: peak_rss_mb(),
    })
}

/// `run` of the deep study computed afresh in this process into a temporary results directory
/// (removed after): wall time, peak memory and the levels' own times from its record.
fn adaptive_run(run: &str) -> Result<AdaptiveRun> {
    use signorini::study;
    use signorini_store::study::manifest::Manifest;
    let manifest = Manifest::load(std::path::Path::new(DEEP_MANIFEST))?;
    let index = manifest.runs.iter().position(|p| p.spec.id == run).ok_or_else(|| {
        let known: Vec<&str> = manifest.runs.iter().map(|p| p.spec.id.as_str()).collect();
        anyhow::anyhow!("{DEEP_MANIFEST} has no run '{run}' (it has: {})", known.join(", "))
    })?;
    let results = std::env::temp_dir().join(format!("signorini-bench-adaptive-{}", std::process::id()));
    let opts = study::RunOptions {
        quick: false,
        shard: Some((index + 1, manifest.runs.len())),
        fresh: true,
        replace: false,
        results: results.clone(),
        progress: false,
        wait_for_lock: false,
    };
    let t0 = Instant::now();
    let outcome = study::run_study(&manifest, &opts);
    let wall_s = t0.elapsed().as_secs_f64();
    let record = outcome.and_then(|_| {
        records::StudyDir::new(&results, &manifest.study).read_run(run)?.ok_or_else(|| anyhow::anyhow!("run {run} left no record"))
    });
    let _ = std::fs::remove_dir_all(&results);
    let record = record?;
    let last = record.levels.last().ok_or_else(|| anyhow::anyhow!("run {run} has no level"))?;
    Ok(AdaptiveRun {
        run: run.into(),
        levels: record.levels.len(),
        last_ndof: last.ndof,
        wall_s,
        levels_s: record.levels.iter().map(|l| l.t_level).sum(),
        last_level_s: last.t_level,
        last_factorisation_s: last.t_factorisation,
        peak_rss_mb: peak_rss_mb(),
    })
}

fn adaptive_point(run: &str) -> Result<AdaptiveRun> {
    println!("\nadaptive point: {run} of {DEEP_MANIFEST}, computed afresh in a process of its own (several minutes):");
    let exe = std::env::current_exe()?;
    let r: AdaptiveRun =
        run_child(std::process::Command::new(exe).args(["--adaptive-child", "--adaptive", run]), &format!("the adaptive run {run}"))?;
    println!(
        "  {} levels to {} NDF: {:.0} s wall ({:.0} s in its levels; the last {:.1} s, of which the factorisation {:.1} s), peak {:.0} MB",
        r.levels, r.last_ndof, r.wall_s, r.levels_s, r.last_level_s, r.last_factorisation_s, r.peak_rss_mb
    );
    Ok(r)
}

/// The performance bounds on the adaptive run to 1e7 NDF.
fn adaptive_targets(r: &AdaptiveRun) -> Vec<Target> {
    let note = format!("{}: {} levels to {} NDF; phase times per level in its record", r.run, r.levels, r.last_ndof);
    let reached = r.last_ndof >= 10_000_000;
    let row = |target: &str, ours: f64, goal: f64, unit: &str| Target {
        target: target.into(),
        n: r.last_ndof,
        ours,
        reference: None,
        value: None,
        goal: format!("<= {goal:.0} {unit}"),
        met: Some(reached && ours <= goal),
        note: note.clone(),
    };
    vec![
        row("adaptive run to 1e7 NDF: wall [s]", r.wall_s, 600.0, "s"),
        row("adaptive run to 1e7 NDF: peak memory [MB]", r.peak_rss_mb, 16.0 * 1024.0, "MB"),
    ]
}

/// The JSON row a child printed after `ROW `.
fn run_child<T: serde::de::DeserializeOwned>(cmd: &mut std::process::Command, what: &str) -> Result<T> {
    let out = cmd.stderr(std::process::Stdio::inherit()).output()?;
    anyhow::ensure!(out.status.success(), "{what} failed ({})", out.status);
    let text = String::from_utf8_lossy(&out.stdout);
    let row = text.lines().find_map(|l| l.strip_prefix("ROW ")).ok_or_else(|| anyhow::anyhow!("no result from {what}"))?;
    Ok(serde_json::from_str(row)?)
}

fn ours_cold(n: usize) -> Result<ColdRun> {
    let exe = std::env::current_exe()?;
    run_child(std::process::Command::new(exe).args(["--cold-child", "--sizes", &n.to_string()]), &format!("our solve of structured:{n}"))
}

fn ngsolve_cold(python: &std::path::Path, n: usize, inverse: &str) -> Result<NgRun> {
    run_child(
        std::process::Command::new(python).args([
            "crosscheck/crosscheck.py",
            "--out-dir",
            "",
            "bench-cold",
            "--n",
            &n.to_string(),
            "--inverse",
            inverse,
        ]),
        &format!("NGSolve's solve of structured:{n} ({inverse})"),
    )
}

fn load() -> String {
    std::fs::read_to_string("/proc/loadavg").map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" ")).unwrap_or_default()
}

/// Fresh processes, ours and NGSolve's interleaved, `repeats` of each per size.
fn cold_comparison(sizes: &[usize], repeats: usize, python: &std::path::Path, pardiso: &std::path::Path) -> Result<Vec<ColdSize>> {
    let have_ngsolve = python.exists();
    let have_pardiso = pardiso.exists();
    let mut out = Vec::new();
    if !sizes.is_empty() {
        println!("\nwhole solves in fresh processes (ours: contact solve; NGSolve: linear solve), interleaved:");
    }
    for &n in sizes {
        let mut size = ColdSize {
            n,
            ours: Vec::new(),
            ngsolve: Vec::new(),
            ngsolve_missing: (!have_ngsolve).then(|| format!("no NGSolve: {} does not exist (crosscheck/setup.sh)", python.display())),
            pardiso: Vec::new(),
            pardiso_missing: (!have_pardiso)
                .then(|| format!("no PARDISO: {} does not exist (crosscheck/setup.sh bench)", pardiso.display())),
        };
        for r in 0..repeats.max(1) {
            let ours = ours_cold(n)?;
            println!(
                "  structured:{n} run {}: ours {:.3} s (mesh {:.3}, assembly {:.3}, symbolic {:.3}, numeric {:.3}, rest {:.3}), peak {:.0} MB; load {}",
                r + 1,
                ours.whole_s,
                ours.mesh_s,
                ours.assembly_s,
                ours.symbolic_s,
                ours.numeric_s,
                ours.rest_s,
                ours.peak_rss_mb,
                load()
            );
            size.ours.push(ours);
            if have_ngsolve {
                let ng = ngsolve_cold(python, n, "sparsecholesky")?;
                print_ng(n, r, "NGSolve", &ng);
                size.ngsolve.push(ng);
            }
            if have_pardiso {
                let ng = ngsolve_cold(pardiso, n, "pardisospd")?;
                print_ng(n, r, "NGSolve + PARDISO", &ng);
                size.pardiso.push(ng);
            }
        }
        out.push(size);
    }
    Ok(out)
}

fn print_ng(n: usize, r: usize, who: &str, ng: &NgRun) {
    println!(
        "  structured:{n} run {}: {who} {:.3} s (mesh {:.3}, assembly {:.3}, factorisation {:.3}, solve {:.3}), peak {:.0} MB; load {}",
        r + 1,
        ng.whole_s,
        ng.mesh_s,
        ng.assembly_s,
        ng.factorisation_s,
        ng.solve_s,
        ng.peak_rss_mb,
        load()
    );
}

/// The scale point: our whole solve on structured:N once if its memory estimate fits; NGSolve's
/// only if its peak, extrapolated from the largest compared size, fits in 80 % of the available memory.
fn scale_point(n: usize, cold: &[ColdSize], python: &std::path::Path) -> Result<ColdSize> {
    let spec = MeshSpec::Structured(n);
    let ndof = spec.ndof()?;
    signorini::memory::check_memory(&spec.to_string(), ndof)?;
    println!("\nscale point structured:{n} ({ndof:.0} unknowns), load {}:", load());
    let ours = ours_cold(n)?;
    println!("  ours {:.3} s, peak {:.0} MB", ours.whole_s, ours.peak_rss_mb);
    let mut size = ColdSize { n, ours: vec![ours], ngsolve: Vec::new(), ngsolve_missing: None, pardiso: Vec::new(), pardiso_missing: None };
    let largest = cold.iter().filter(|c| !c.ngsolve.is_empty()).max_by_key(|c| c.n);
    let Some(largest) = largest else {
        size.ngsolve_missing = Some("not run: no NGSolve measurement to extrapolate its memory from".into());
        return Ok(size);
    };
    // the factor grows slightly faster than the unknowns: 10 % on top of their ratio
    let factor = 1.1 * (n as f64 / largest.n as f64).powi(2);
    let needed_mb = factor * median(largest.ngsolve.iter().map(|r| r.peak_rss_mb).collect());
    let available_mb = signorini::memory::available_memory().unwrap_or(0.0) / (1024.0 * 1024.0);
    if needed_mb > 0.8 * available_mb {
        size.ngsolve_missing = Some(format!(
            "not run: about {needed_mb:.0} MB needed (its structured:{} peak x {factor:.1}), {available_mb:.0} MB available",
            largest.n
        ));
        println!("  NGSolve {}", size.ngsolve_missing.as_deref().unwrap_or_default());
    } else {
        let ng = ngsolve_cold(python, n, "sparsecholesky")?;
        println!("  NGSolve {:.3} s, peak {:.0} MB", ng.whole_s, ng.peak_rss_mb);
        size.ngsolve.push(ng);
    }
    Ok(size)
}

/// One line of the targets' table.
#[derive(serde::Serialize)]
struct Target {
    target: String,
    n: usize,
    ours: f64,
    reference: Option<f64>,
    value: Option<f64>,
    goal: String,
    met: Option<bool>,
    note: String,
}

/// The bound a target's value must keep.
enum Bound {
    AtMost(f64),
    AtLeast(f64),
}

impl Target {
    /// A target whose value is held against a bound: the goal's text and whether it is met
    /// follow from the bound (not met is `None` when there is no value).
    fn bounded(target: &str, n: usize, ours: f64, reference: Option<f64>, value: Option<f64>, bound: Bound, note: String) -> Self {
        let (goal, met) = match bound {
            Bound::AtMost(g) => (format!("<= {g:.2}"), value.map(|v| v <= g)),
            Bound::AtLeast(g) => (format!(">= {g:.2}"), value.map(|v| v >= g)),
        };
        Target { target: target.into(), n, ours, reference, value, goal, met, note }
    }

    /// A target whose value is ours / reference.
    fn ratio(target: &str, n: usize, ours: f64, reference: Option<f64>, bound: Bound, note: String) -> Self {
        Self::bounded(target, n, ours, reference, reference.map(|r| ours / r), bound, note)
    }
}

/// The performance targets, each with the measured value and whether it is met.
fn targets(phases: &[SizeResult], rates: &[FactorRate], cold: &[ColdSize], scale: Option<&ColdSize>) -> Vec<Target> {
    let mut t = Vec::new();
    let med = |v: Vec<f64>| if v.is_empty() { None } else { Some(median(v)) };
    for r in rates.iter().filter(|r| r.n >= 512) {
        let dense = format!("dense: the better of n = {:?} right after each factorisation, every core", r.dense_orders);
        let first_gflops = 2.0 * r.multiply_adds / r.numeric_first_s / 1e9;
        for (what, ours, ratio) in [("cold", first_gflops, r.first_ratio), ("warm", r.sparse_gflops, r.ratio)] {
            t.push(Target::bounded(
                &format!("numeric factorisation ({what}) / dense LL^T rate [GFlop/s]"),
                r.n,
                ours,
                Some(r.dense_gflops),
                Some(ratio),
                Bound::AtLeast(0.5),
                format!("{what}; {dense}"),
            ));
        }
    }
    let goal_max = [(256, 0.22), (512, 0.18)];
    for c in cold {
        let ours = median(c.ours.iter().map(|r| r.whole_s).collect());
        let ng = med(c.ngsolve.iter().map(|r| r.whole_s).collect());
        let missing = c.ngsolve_missing.clone().unwrap_or_default();
        if let Some(&(_, g)) = goal_max.iter().find(|(n, _)| *n == c.n) {
            t.push(Target::ratio("cold whole solve / NGSolve's whole linear solve [s]", c.n, ours, ng, Bound::AtMost(g), missing.clone()));
            if let Some(r) = rates.iter().find(|r| r.n == c.n && r.gemm_gflops > 0.0) {
                let best = at_gemm_rate(&c.ours, r);
                t.push(Target::ratio(
                    "bound: the same, numeric phase at faer's GEMM rate",
                    c.n,
                    best,
                    ng,
                    Bound::AtMost(g),
                    format!("{:.2e} multiply-adds at {:.1} GFlop/s, the other phases as measured", r.multiply_adds, r.gemm_gflops),
                ));
            }
        }
        if c.n == 512 {
            let ours = median(c.ours.iter().map(|r| r.peak_rss_mb).collect());
            let ng = med(c.ngsolve.iter().map(|r| r.peak_rss_mb).collect());
            t.push(Target::ratio("peak memory / NGSolve's [MB]", c.n, ours, ng, Bound::AtMost(0.6), missing.clone()));
            let sym = median(c.ours.iter().map(|r| r.symbolic_s / r.whole_s).collect());
            let (symbolic, whole) =
                (median(c.ours.iter().map(|r| r.symbolic_s).collect()), median(c.ours.iter().map(|r| r.whole_s).collect()));
            t.push(Target::bounded(
                "symbolic analysis / cold whole solve",
                c.n,
                symbolic,
                Some(whole),
                Some(sym),
                Bound::AtMost(0.1),
                String::new(),
            ));
        }
        if c.n == 512 {
            let ours = median(c.ours.iter().map(|r| r.whole_s).collect());
            let pardiso = med(c.pardiso.iter().map(|r| r.factorisation_s + r.solve_s).collect());
            t.push(Target::ratio(
                "cold whole solve / PARDISO's factorisation + solve [s]",
                c.n,
                ours,
                pardiso,
                Bound::AtMost(0.5),
                c.pardiso_missing.clone().unwrap_or_else(|| "NGSolve's inverse=\"pardisospd\" (MKL 2026.2)".into()),
            ));
        }
        if c.n >= 256 {
            let ours = median(c.ours.iter().map(|r| r.assembly_s).collect());
            let ng = med(c.ngsolve.iter().map(|r| r.assembly_s).collect());
            let value = ng.map(|ng| ng / ours);
            t.push(Target::bounded("NGSolve's assembly / ours (cold) [s]", c.n, ours, ng, value, Bound::AtLeast(2.0), missing));
        }
    }
    if let Some(p) = phases.iter().find(|p| p.n == 512).or_else(|| phases.iter().max_by_key(|p| p.n)) {
        let (first, warm) = (p.median.numeric_first, p.median.numeric_warm);
        t.push(Target::bounded(
            "first numeric factorisation / refactorisation [s]",
            p.n,
            first,
            Some(warm),
            Some(first / warm),
            Bound::AtMost(1.3),
            "one process".into(),
        ));
    }
    if let Some(s) = scale {
        let ours = &s.ours[0];
        let ng = s.ngsolve.first();
        // ours beside NGSolve's (if it ran), as a ratio
        let row = |target: &str, mine: f64, theirs: Option<f64>, goal: &str, met: bool| Target {
            target: target.into(),
            n: s.n,
            ours: mine,
            reference: theirs,
            value: theirs.map(|r| mine / r),
            goal: goal.into(),
            met: Some(met),
            note: s.ngsolve_missing.clone().unwrap_or_default(),
        };
        // the scale point's bounds at structured:1024; any other scale point only has to run and fit
        let (time_goal, mem_goal) = if s.n == 1024 { (50.0, 10.0 * 1024.0) } else { (f64::INFINITY, 24.0 * 1024.0) };
        let goal = |g: f64, unit: &str| if g.is_finite() { format!("<= {g:.0} {unit}") } else { "runs".into() };
        t.push(row(
            "scale point: whole contact solve [s]",
            ours.whole_s,
            ng.map(|r| r.whole_s),
            &goal(time_goal, "s"),
            ours.whole_s <= time_goal,
        ));
        t.push(row(
            "scale point: peak memory [MB]",
            ours.peak_rss_mb,
            ng.map(|r| r.peak_rss_mb),
            &goal(mem_goal, "MB"),
            ours.peak_rss_mb <= mem_goal,
        ));
        // what no faster factorisation changes: the numeric phase at faer's GEMM rate, and the
        // values of L alone
        if let Some(r) = rates.iter().find(|r| r.n == s.n && r.gemm_gflops > 0.0) {
            let best = at_gemm_rate(&s.ours, r);
            t.push(row(
                "bound: the same solve, numeric phase at faer's GEMM rate [s]",
                best,
                None,
                &goal(time_goal, "s"),
                best <= time_goal,
            ));
            let l_mb = r.values_of_l as f64 * 8.0 / (1024.0 * 1024.0);
            t.push(row("bound: the values of L alone [MB]", l_mb, None, &goal(mem_goal, "MB"), l_mb <= mem_goal));
        }
    }
    t
}

/// The targets' table, printed.
fn print_targets(t: &[Target]) {
    let opt = |v: Option<f64>, p: usize| v.map_or("-".to_string(), |v| format!("{v:.p$}"));
    println!("\ntargets (our cold contact solve against NGSolve's cold linear solve, fresh processes, medians):");
    println!("{:<60} {:>8} {:>10} {:>10} {:>7}  {:<15} {:<8} note", "target", "N", "ours", "reference", "value", "goal", "met");
    for r in t {
        println!(
            "{:<60} {:>8} {:>10.3} {:>10} {:>7}  {:<15} {:<8} {}",
            r.target,
            r.n,
            r.ours,
            opt(r.reference, 3),
            opt(r.value, 2),
            r.goal,
            r.met.map_or("-", |m| if m { "met" } else { "not met" }),
            r.note
        );
    }
}

#[derive(serde::Serialize, serde::Deserialize, Default, Clone)]
struct Phases {
    assembly: f64,
    symbolic: f64,
    numeric_first: f64,
    numeric_warm: f64,
    schur: f64,
    /// the two sparse triangular solves (y = K^-1 F and the final displacement)
    solves: f64,
    active_set: f64,
    /// one linear solve: numeric (warm) + one sparse solve
    linear_solve: f64,
    /// the contact solve after assembly and symbolic analysis: numeric (warm) + Schur + solves + active set
    contact_solve: f64,
}

#[derive(serde::Serialize, serde::Deserialize)]
struct SizeResult {
    n: usize,
    unknowns: usize,
    contact_unknowns: usize,
    /// the fill-reducing ordering kept, with the flops of the candidates computed (AMD: null on a
    /// large quasi-uniform mesh, where it is not computed) and the mesh grading
    ordering: serde_json::Value,
    pdas_iterations: usize,
    per_iteration_seconds: Vec<f64>,
    median: Phases,
    runs: Vec<Phases>,
    peak_rss_mb: f64,
}

/// The median cold whole solve of `runs` had its numeric phase run at faer's GEMM rate (the
/// ordering's multiply-adds, the same run's rate) and the other phases taken as measured: a
/// bound on what a faster numeric factorisation alone can give.
fn at_gemm_rate(runs: &[ColdRun], rate: &FactorRate) -> f64 {
    let rest = median(runs.iter().map(|r| r.whole_s - r.numeric_s).collect());
    rest + 2.0 * rate.multiply_adds / (rate.gemm_gflops * 1e9)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .map(|l| l.split_whitespace().nth(1).unwrap_or("0").parse::<f64>().unwrap_or(0.0) / 1024.0)
        })
        .unwrap_or(f64::NAN)
}

fn machine() -> serde_json::Value {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("model name")).map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string()))
        .unwrap_or_default();
    let mem = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| s.lines().next().map(|l| l.to_string())).unwrap_or_default();
    serde_json::json!({
        "cpu": cpu,
        "cores": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        "memory": mem,
        "rayon_threads": rayon::current_num_threads(),
    })
}

const HEADER: &str = "    N  unknowns | assembly symbolic num.first  num.warm   schur  solves act.set  its |   linear  contact  peak MB";

fn main() -> Result<()> {
    let args = Args::parse();
    if args.cold_child {
        let n = *args.sizes.first().ok_or_else(|| anyhow::anyhow!("--cold-child needs a size"))?;
        println!("ROW {}", serde_json::to_string(&cold_solve(n)?)?);
        return Ok(());
    }
    if args.rate_child {
        let n = *args.sizes.first().ok_or_else(|| anyhow::anyhow!("--rate-child needs a size"))?;
        println!("ROW {}", serde_json::to_string(&factor_rate(n, args.repeats)?)?);
        return Ok(());
    }
    if args.adaptive_child {
        println!("ROW {}", serde_json::to_string(&adaptive_run(&args.adaptive)?)?);
        return Ok(());
    }
    if let Some(case) = &args.graded_child {
        return graded::child(case, args.graded_ndof, args.graded_save.as_deref());
    }
    let graded =
        graded::Options { ndof: args.graded_ndof, runs: &args.graded_runs, out: &args.graded_out, save: args.graded_save.as_deref() };
    if args.graded_only {
        return graded::section(&graded);
    }
    if !args.factor_rate.is_empty() {
        factor_rates(&args.factor_rate, args.repeats)?;
        return Ok(());
    }
    if args.child {
        for &n in &args.sizes {
            println!("ROW {}", serde_json::to_string(&bench_size(n, args.repeats)?)?);
        }
        return Ok(());
    }
    let exe = std::env::current_exe()?;
    println!("{HEADER}");
    let mut results = Vec::new();
    for &n in &args.sizes {
        let out = std::process::Command::new(&exe)
            .args(["--child", "--sizes", &n.to_string(), "--repeats", &args.repeats.to_string()])
            .stderr(std::process::Stdio::inherit())
            .output()?;
        anyhow::ensure!(out.status.success(), "the benchmark of structured:{n} failed ({})", out.status);
        let text = String::from_utf8_lossy(&out.stdout);
        let row = text.lines().find_map(|l| l.strip_prefix("ROW ")).ok_or_else(|| anyhow::anyhow!("no result for structured:{n}"))?;
        let r: SizeResult = serde_json::from_str(row)?;
        let m = &r.median;
        println!(
            "{:>5} {:>9} | {:>8.3} {:>8.3} {:>9.3} {:>9.3} {:>7.3} {:>7.3} {:>7.4} {:>4} | {:>8.3} {:>8.3} {:>8.0}",
            n,
            r.unknowns,
            m.assembly,
            m.symbolic,
            m.numeric_first,
            m.numeric_warm,
            m.schur,
            m.solves,
            m.active_set,
            r.pdas_iterations,
            m.linear_solve,
            m.contact_solve,
            r.peak_rss_mb
        );
        results.push(r);
    }
    if let Some(last) = results.last() {
        breakdown(last);
    }
    let comparison = side_by_side(&results, &args.ngsolve);
    let rates = factor_rates(&args.rate_sizes, args.repeats)?;
    let cold = cold_comparison(&args.cold_sizes, args.cold_repeats, &args.python, &args.pardiso_python)?;
    let scale = if args.scale > 0 { Some(scale_point(args.scale, &cold, &args.python)?) } else { None };
    let adaptive = if args.adaptive.is_empty() { None } else { Some(adaptive_point(&args.adaptive)?) };
    let mut targets = targets(&results, &rates, &cold, scale.as_ref());
    targets.extend(adaptive.iter().flat_map(adaptive_targets));
    print_targets(&targets);
    let doc = serde_json::json!({
        "benchmark": "Example 7.2 contact solve on structured:N (seconds; medians over repeats; numeric_first is the first factorisation in the process; every size in a process of its own, peak_rss_mb its peak resident memory)",
        "repeats": args.repeats,
        "machine": machine(),
        "ngsolve": args.ngsolve,
        "comparison": comparison,
        "sizes": results,
        "factor_rate": rates,
        "cold": cold,
        "scale": scale,
        "adaptive": adaptive,
        "targets": targets,
    });
    records::write_json(&args.out, &doc)?;
    println!("wrote {}", args.out.display());
    if args.graded_ndof > 0.0 {
        graded::section(&graded)?;
    }
    Ok(())
}

/// The numeric factorisation of one size against the machine's dense rate, in one process.
/// Rates count two flops per multiply-add of the ordering's count (the fill of L, without the
/// explicit zeros that relaxed supernodes add), and n^3 / 3 flops for a dense LL^T of order n.
#[derive(serde::Serialize, serde::Deserialize, Clone)]
struct FactorRate {
    n: usize,
    unknowns: usize,
    supernodes: usize,
    /// share of the executed multiply-adds in supernodes of at least 64 columns
    wide_share: f64,
    /// multiply-adds of the fill (the ordering's count) and executed (explicit zeros included)
    multiply_adds: f64,
    executed_multiply_adds: f64,
    /// the first factorisation in the process (first touch of L), and the median of the others
    numeric_first_s: f64,
    numeric_warm_s: f64,
    /// one solve with L and L^T (median of three), and the number of values of L it reads twice
    solve_warm_s: f64,
    values_of_l: usize,
    /// GFlop/s of the warm factorisation ...
    sparse_gflops: f64,
    /// ... and the machine's dense rate: faer's dense LL^T on every core, the better of the orders
    /// `dense_orders`, measured right after each warm factorisation (median)
    dense_gflops: f64,
    #[serde(default = "dense_orders_before")]
    dense_orders: Vec<usize>,
    /// the median over the warm factorisations of each one's rate over the dense rate measured
    /// right after it, and the same of the first (cold) factorisation
    ratio: f64,
    #[serde(default)]
    first_ratio: f64,
    /// faer's square product on every core, measured as the dense rate: the fastest dense kernel
    /// the factorisation is built from, so no phase of it runs faster
    #[serde(default)]
    gemm_gflops: f64,
}

/// The one order the dense rates were measured at before they were measured at DENSE_ORDERS.
fn dense_orders_before() -> Vec<usize> {
    vec![2048]
}

const RATE_HEADER: &str = "    N   unknowns supernodes wide64 |  madds  executed   first    warm  GFlop/s | dense GFlop/s  ratio cold  warm | GEMM GFlop/s | values of L  solve";

impl FactorRate {
    fn row(&self) -> String {
        format!(
            "{:>5} {:>10} {:>10} {:>6.2} | {:>8.2e} {:>8.2e} {:>7.3} {:>7.3} {:>8.1} | {:>13.1} {:>10.2} {:>5.2} | {:>12.1} | {:>11.3e} {:>6.3}",
            self.n,
            self.unknowns,
            self.supernodes,
            self.wide_share,
            self.multiply_adds,
            self.executed_multiply_adds,
            self.numeric_first_s,
            self.numeric_warm_s,
            self.sparse_gflops,
            self.dense_gflops,
            self.first_ratio,
            self.ratio,
            self.gemm_gflops,
            self.values_of_l as f64,
            self.solve_warm_s
        )
    }
}

/// The factorisation rates of `sizes`, each in a process of its own, printed as they come.
fn factor_rates(sizes: &[usize], repeats: usize) -> Result<Vec<FactorRate>> {
    let exe = std::env::current_exe()?;
    println!("\nnumeric factorisation against faer's dense LL^T (the best of n = {DENSE_ORDERS:?}, every core), one process per size:");
    println!("{RATE_HEADER}");
    let mut out = Vec::new();
    for &n in sizes {
        let mut cmd = std::process::Command::new(&exe);
        cmd.args(["--rate-child", "--sizes", &n.to_string(), "--repeats", &repeats.to_string()]);
        let r: FactorRate = run_child(&mut cmd, &format!("the factor rate of structured:{n}"))?;
        println!("{}", r.row());
        out.push(r);
    }
    Ok(out)
}

/// The orders of the dense LL^T (and product) the sparse rate is held against: the machine's dense
/// rate is the better of the two (on this project's Xeon faer's LL^T of order 4096 ran 1.2-1.5x
/// faster than of order 2048 on both cores, so one order alone would understate the machine).
const DENSE_ORDERS: [usize; 2] = [2048, 4096];

/// One factorisation and the dense rates measured right after it (GFlop/s, every core).
struct RatePair {
    seconds: f64,
    sparse_gflops: f64,
    dense: f64,
    gemm: f64,
}

fn factor_rate(n: usize, repeats: usize) -> Result<FactorRate> {
    use signorini::{cholesky, symbolic};
    let problem = Ex72;
    let mesh = MeshSpec::Structured(n).build(&problem)?;
    let nodes = P2Nodes::new(&mesh);
    let dofs = DofMap::new(&nodes, &problem);
    let sys = assembly::assemble(&mesh, &nodes, &dofs, &problem);
    let (sn, placement, ordering) = symbolic::analyse(&sys.matrix, dofs.n_interior, &dofs.unknown_coords(&nodes));
    let plan = cholesky::Plan::new(&sn);
    // the ordering counts the leading block (all but the contact unknowns, whose trailing
    // dense block is factorised too: m^3 / 6 more)
    let m = (sn.n() - dofs.n_interior) as f64;
    let multiply_adds = ordering.multiply_adds() + m * m * m / 6.0;
    // The sparse factorisation and the dense kernels side by side: every factorisation is
    // followed by one dense LL^T and one product at each of DENSE_ORDERS, so that each pair sees
    // the machine in one state (this VM's speed wanders by up to 2x within minutes); a pair's
    // dense rate is its better order's, and the ratios are the pairs' own. The dense kernels are
    // warmed up first; the first factorisation still touches L's pages first (the dense
    // matrices are released to the system before it).
    let best = |rate: fn(usize) -> f64| DENSE_ORDERS.iter().map(|&order| rate(order)).fold(0.0, f64::max);
    best(dense_rate);
    best(gemm_rate);
    let mut l = vec![0.0; sn.len_val()];
    let mut pairs = Vec::new();
    for r in 0..=repeats.max(1) {
        cholesky::load(&sn, &placement, sys.matrix.values(), None, &mut l, r == 0);
        let t0 = Instant::now();
        cholesky::factorize(&sn, &plan, &mut l)?;
        let seconds = t0.elapsed().as_secs_f64();
        pairs.push(RatePair {
            seconds,
            sparse_gflops: 2.0 * multiply_adds / seconds / 1e9,
            dense: best(dense_rate),
            gemm: best(gemm_rate),
        });
    }
    let mut x = vec![1.0; sn.n()];
    let solve_warm_s = median(
        (0..3)
            .map(|_| {
                let t0 = Instant::now();
                cholesky::solve_in_place(&sn, &plan, &l, &mut x);
                t0.elapsed().as_secs_f64()
            })
            .collect(),
    );
    let (first, warm) = (&pairs[0], &pairs[1..]);
    let warm_median = |f: fn(&RatePair) -> f64| median(warm.iter().map(f).collect());
    let (supernodes, wide_share) = plan.shape(&sn, 64);
    let numeric_warm_s = warm_median(|p| p.seconds);
    Ok(FactorRate {
        n,
        unknowns: sn.n(),
        supernodes,
        wide_share,
        multiply_adds,
        executed_multiply_adds: plan.multiply_adds(),
        numeric_first_s: first.seconds,
        numeric_warm_s,
        solve_warm_s,
        values_of_l: sn.len_val(),
        sparse_gflops: 2.0 * multiply_adds / numeric_warm_s / 1e9,
        dense_gflops: warm_median(|p| p.dense),
        dense_orders: DENSE_ORDERS.to_vec(),
        ratio: warm_median(|p| p.sparse_gflops / p.dense),
        first_ratio: first.sparse_gflops / first.dense,
        gemm_gflops: warm_median(|p| p.gemm),
    })
}

/// GFlop/s of faer's product of two n x n matrices on every core (2 n^3 flops).
fn gemm_rate(n: usize) -> f64 {
    let a = faer::Mat::<f64>::from_fn(n, n, |i, j| 1.0 / (1.0 + i.abs_diff(j) as f64));
    let mut c = faer::Mat::<f64>::zeros(n, n);
    let t0 = Instant::now();
    faer::linalg::matmul::matmul(c.as_mut(), faer::Accum::Replace, a.as_ref(), a.as_ref(), 1.0, faer::Par::rayon(0));
    let t = t0.elapsed().as_secs_f64();
    std::hint::black_box(&c);
    2.0 * (n as f64).powi(3) / t / 1e9
}

/// GFlop/s of faer's dense LL^T of an n x n SPD matrix on every core.
fn dense_rate(n: usize) -> f64 {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::cholesky::llt::factor::{LltParams, LltRegularization, cholesky_in_place, cholesky_in_place_scratch};
    let mut a = faer::Mat::<f64>::from_fn(n, n, |i, j| if i == j { n as f64 } else { 1.0 / (1.0 + i.abs_diff(j) as f64) });
    let par = faer::Par::rayon(0);
    let mut stack = MemBuffer::new(cholesky_in_place_scratch::<f64>(n, par, faer::Spec::<LltParams, f64>::default()));
    let t0 = Instant::now();
    cholesky_in_place(a.as_mut(), LltRegularization::default(), par, MemStack::new(&mut stack), faer::Spec::<LltParams, f64>::default())
        .expect("the test matrix is diagonally dominant");
    let t = t0.elapsed().as_secs_f64();
    (n as f64).powi(3) / 3.0 / t / 1e9
}

/// All repeats of one size, in this process.
fn bench_size(n: usize, repeats: usize) -> Result<SizeResult> {
    let problem = Ex72;
    let spec = MeshSpec::Structured(n);
    let mut runs = Vec::new();
    let mut per_iteration = Vec::new();
    let (mut unknowns, mut m, mut its, mut ordering) = (0, 0, 0, serde_json::Value::Null);
    for _ in 0..repeats.max(1) {
        let mesh = spec.build(&problem)?;
        let t0 = Instant::now();
        let nodes = P2Nodes::new(&mesh);
        let dofs = DofMap::new(&nodes, &problem);
        let sys = assembly::assemble(&mesh, &nodes, &dofs, &problem);
        let assembly_time = t0.elapsed().as_secs_f64();
        unknowns = sys.matrix.n();
        // a copy for the first factorisation (the Schur strategy releases it before filling L)
        let mut solver = ContactSolver::new(sys.matrix.clone(), dofs.n_interior, &dofs.unknown_coords(&nodes))?;
        let (symbolic, numeric_first) = (solver.timings.symbolic, solver.timings.numeric);
        // the same values again: the warm refactorisation (the placement of the entries, which
        // the Schur strategy released, is computed again first and counted as symbolic time)
        solver.refactor(sys.matrix)?;
        let (numeric_warm, schur) = (solver.timings.numeric, solver.timings.schur);
        let gap: Vec<f64> = dofs.contact.iter().map(|c| c.gap).collect();
        let out = solver.solve_contact(&sys.rhs, &gap, &PdasOptions::default(), &mut |_| {})?.converged()?;
        let t = &solver.timings;
        m = dofs.contact.len();
        its = out.iterations.len();
        ordering = serde_json::to_value(solver.ordering)?;
        per_iteration = out.iterations.iter().map(|i| i.seconds).collect();
        runs.push(Phases {
            assembly: assembly_time,
            symbolic,
            numeric_first,
            numeric_warm,
            schur,
            solves: t.solves,
            active_set: t.active_set,
            linear_solve: numeric_warm + t.solves / 2.0,
            contact_solve: numeric_warm + schur + t.solves + t.active_set,
        });
    }
    let med = |f: fn(&Phases) -> f64| median(runs.iter().map(f).collect());
    let median = Phases {
        assembly: med(|p| p.assembly),
        symbolic: med(|p| p.symbolic),
        numeric_first: runs[0].numeric_first,
        numeric_warm: med(|p| p.numeric_warm),
        schur: med(|p| p.schur),
        solves: med(|p| p.solves),
        active_set: med(|p| p.active_set),
        linear_solve: med(|p| p.linear_solve),
        contact_solve: med(|p| p.contact_solve),
    };
    Ok(SizeResult {
        n,
        unknowns,
        contact_unknowns: m,
        ordering,
        pdas_iterations: its,
        per_iteration_seconds: per_iteration,
        median,
        runs,
        peak_rss_mb: peak_rss_mb(),
    })
}

/// Where the time of the largest size goes: assembly, then the contact solve phase by phase.
fn breakdown(r: &SizeResult) {
    let m = &r.median;
    let phases = [
        ("assembly (nodes, numbering, pattern, element matrices)", m.assembly),
        ("symbolic (ordering, elimination tree, supernodes)", m.symbolic),
        ("numeric factorisation (warm)", m.numeric_warm),
        ("Schur complement L_CC L_CC^T", m.schur),
        ("two sparse solves", m.solves),
        ("active-set iterations (dense, on S)", m.active_set),
    ];
    let total: f64 = phases.iter().map(|p| p.1).sum();
    println!(
        "\nphase breakdown, structured:{} ({} unknowns, {} contact unknowns, ordering {}):",
        r.n,
        r.unknowns,
        r.contact_unknowns,
        r.ordering["method"].as_str().unwrap_or("?")
    );
    for (name, t) in phases {
        println!("  {:<62} {:>8.3} s {:>5.1}%", name, t, 100.0 * t / total);
    }
    println!("  {:<62} {:>8.3} s", "total", total);
}

/// Our medians next to NGSolve's for the same meshes: assembly, one linear
/// solve (symbolic + numeric factorisation + solve), our contact solve against our own linear
/// solve and against NGSolve's, and peak memory. Printed and returned for the JSON record.
fn side_by_side(ours: &[SizeResult], ngsolve: &std::path::Path) -> Vec<serde_json::Value> {
    let Ok(text) = std::fs::read_to_string(ngsolve) else {
        println!("(no NGSolve timings at {}: run `make bench` or crosscheck.py bench)", ngsolve.display());
        return Vec::new();
    };
    let Ok(doc) = serde_json::from_str::<serde_json::Value>(&text) else { return Vec::new() };
    let rows = doc["rows"].as_array().cloned().unwrap_or_default();
    let mut table = Vec::new();
    println!("\n{:<40} {:>5} {:>10} {:>10} {:>7}  target", "phase", "N", "ours", "reference", "ratio");
    for r in ours {
        let Some(ng) = rows.iter().find(|x| x["N"].as_u64() == Some(r.n as u64)) else { continue };
        let f = |k: &str| ng[k].as_f64().unwrap_or(f64::NAN);
        let ng_linear = f("factorisation_s") + f("solve_s");
        let m = &r.median;
        let our_linear = m.symbolic + m.linear_solve;
        let our_contact = m.symbolic + m.contact_solve;
        let lines = [
            ("assembly [s] vs NGSolve", m.assembly, f("assembly_s"), "<= 0.5"),
            ("linear solve [s] vs NGSolve", our_linear, ng_linear, "-"),
            ("contact solve [s] vs our linear solve", our_contact, our_linear, "<= 1.3"),
            ("contact solve [s] vs NGSolve linear solve", our_contact, ng_linear, "<= 0.8"),
            ("peak memory [MB] vs NGSolve", r.peak_rss_mb, f("peak_rss_mb"), "<= 1.0"),
        ];
        for (name, a, b, target) in lines {
            println!("{:<40} {:>5} {:>10.3} {:>10.3} {:>7.2}  {}", name, r.n, a, b, a / b, target);
            table.push(serde_json::json!({"phase": name, "N": r.n, "ours": a, "reference": b, "ratio": a / b, "target": target}));
        }
    }
    table
}
