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
use signorini::problems::{Ex72, Problem};
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
}

#[derive(serde::Serialize, Default, Clone)]
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

#[derive(serde::Serialize)]
struct SizeResult {
    n: usize,
    unknowns: usize,
    contact_unknowns: usize,
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
        .and_then(|s| s.lines().find(|l| l.starts_with("VmHWM:")).map(|l| l.split_whitespace().nth(1).unwrap_or("0").parse::<f64>().unwrap_or(0.0) / 1024.0))
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

fn main() -> Result<()> {
    let args = Args::parse();
    let problem = Ex72;
    let mut results = Vec::new();
    println!("{:>5} {:>9} | {:>8} {:>8} {:>9} {:>9} {:>7} {:>7} {:>7} {:>4} | {:>8} {:>8}", "N", "unknowns", "assembly", "symbolic", "num.first", "num.warm", "schur", "solves", "act.set", "its", "linear", "contact");
    for &n in &args.sizes {
        let spec = MeshSpec::Structured(n);
        let mut runs = Vec::new();
        let mut per_iteration = Vec::new();
        let (mut unknowns, mut m, mut its) = (0, 0, 0);
        for _ in 0..args.repeats.max(1) {
            let mesh = spec.build(&|x| problem.part_of(x));
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
            let out = solver.solve_contact(&sys.matrix, &sys.rhs, &gap, &PdasOptions::default(), &mut |_| {})?;
            let t = &solver.timings;
            unknowns = sys.matrix.n;
            m = dofs.contact.len();
            its = out.iterations.len();
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
        println!(
            "{:>5} {:>9} | {:>8.3} {:>8.3} {:>9.3} {:>9.3} {:>7.3} {:>7.3} {:>7.4} {:>4} | {:>8.3} {:>8.3}",
            n, unknowns, median.assembly, median.symbolic, median.numeric_first, median.numeric_warm, median.schur, median.solves, median.active_set, its, median.linear_solve, median.contact_solve
        );
        results.push(SizeResult { n, unknowns, contact_unknowns: m, pdas_iterations: its, per_iteration_seconds: per_iteration, median, runs, peak_rss_mb: peak_rss_mb() });
    }
    let doc = serde_json::json!({
        "benchmark": "Example 7.2 contact solve on structured:N (seconds; medians over repeats; numeric_first is the first factorisation in the process)",
        "repeats": args.repeats,
        "machine": machine(),
        "sizes": results,
    });
    records::write_json(&args.out, &doc)?;
    println!("wrote {}", args.out.display());
    side_by_side(&results, &args.ngsolve);
    Ok(())
}

/// Our medians next to NGSolve's for the same meshes: assembly, one linear solve (factorisation
/// and solve), and our whole contact solve against NGSolve's linear solve.
fn side_by_side(ours: &[SizeResult], ngsolve: &std::path::Path) {
    let Ok(text) = std::fs::read_to_string(ngsolve) else {
        println!("(no NGSolve timings at {}: run `make bench` or crosscheck.py bench)", ngsolve.display());
        return;
    };
    let Ok(doc) = serde_json::from_str::<serde_json::Value>(&text) else { return };
    let rows = doc["rows"].as_array().cloned().unwrap_or_default();
    println!("\n{:<34} {:>5} {:>10} {:>10} {:>7}", "phase", "N", "ours [s]", "NGSolve", "ratio");
    for r in ours {
        let Some(ng) = rows.iter().find(|x| x["N"].as_u64() == Some(r.n as u64)) else { continue };
        let f = |k: &str| ng[k].as_f64().unwrap_or(f64::NAN);
        let ng_linear = f("factorisation_s") + f("solve_s");
        let lines = [
            ("assembly", r.median.assembly, f("assembly_s")),
            ("linear solve (factor + solve)", r.median.symbolic + r.median.linear_solve, ng_linear),
            ("contact solve vs their linear", r.median.symbolic + r.median.contact_solve, ng_linear),
        ];
        for (name, a, b) in lines {
            println!("{:<34} {:>5} {:>10.3} {:>10.3} {:>7.2}", name, r.n, a, b, a / b);
        }
    }
}
