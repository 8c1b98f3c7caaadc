//! `make bench`: phase timings of the contact solve of Example 7.2 on structured meshes,
//! medians over repeats, written to `results/bench/solver.json` and printed as a table.
//!
//! Phases: assembly, symbolic factorisation, numeric factorisation (first in the process, and
//! warm: a refactorisation of the same pattern), Schur complement, sparse solves, each
//! active-set iteration. Speed lives here, never in timed tests.

use anyhow::Result;
use clap::Parser;
use signorini::assembly::{self, DofMap};
use signorini::contact::{ContactSolver, PdasOptions};
use signorini::mesh::{MeshSpec, P2Nodes};
use signorini::problems::Ex72;
use signorini::records;
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
    /// Run the sizes in this process and print one JSON row per size (the parent runs every size
    /// in a child of its own, so that peak memory and first-touch costs are the size's own).
    #[arg(long, hide = true)]
    child: bool,
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
    /// the fill-reducing ordering kept, with the flops of both candidates
    ordering: serde_json::Value,
    pdas_iterations: usize,
    per_iteration_seconds: Vec<f64>,
    median: Phases,
    runs: Vec<Phases>,
    peak_rss_mb: f64,
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
    let doc = serde_json::json!({
        "benchmark": "Example 7.2 contact solve on structured:N (seconds; medians over repeats; numeric_first is the first factorisation in the process; every size in a process of its own, peak_rss_mb its peak resident memory)",
        "repeats": args.repeats,
        "machine": machine(),
        "ngsolve": args.ngsolve,
        "comparison": comparison,
        "sizes": results,
    });
    records::write_json(&args.out, &doc)?;
    println!("wrote {}", args.out.display());
    Ok(())
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
        let mut solver = ContactSolver::new(&sys.matrix, dofs.n_interior, &dofs.unknown_coords(&nodes))?;
        let (symbolic, numeric_first) = (solver.timings.symbolic, solver.timings.numeric);
        solver.refactor(&sys.matrix)?;
        let (numeric_warm, schur) = (solver.timings.numeric, solver.timings.schur);
        let gap: Vec<f64> = dofs.contact.iter().map(|c| c.gap).collect();
        let out = solver.solve_contact(&sys.matrix, &sys.rhs, &gap, &PdasOptions::default(), &mut |_| {})?.converged()?;
        let t = &solver.timings;
        unknowns = sys.matrix.n();
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
        ("symbolic (orderings ND and AMD, elimination tree, supernodes)", m.symbolic),
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

/// Our medians next to NGSolve's for the same meshes (targets of issue 7): assembly, one linear
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
