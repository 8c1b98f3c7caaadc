//! `make bench`'s graded section: where the time of a factorisation goes on
//! the deep study's graded meshes, beside the uniform grid of the same size and METIS's ordering.
//!
//! The deep study's level records say that a graded level at 2e6 NDF spends more time in
//! `t_factorisation` than the uniform run at the same NDF, with a fraction of its flops. Here
//! each mesh (the level nearest `--graded-ndof` NDF of a run of experiments/deep.toml, rebuilt
//! from its stored refinement history as the drift check's replay tier does, and
//! `structured:N` of about the same NDF with the same problem) is taken through the solver's
//! factorisation in a process of its own, phase by phase: the solver's symbolic phase as the
//! contact solver runs it (both orderings in parallel, the structure, the schedule), then its
//! pieces one at a time ([`signorini::sparse::anatomy`]: the node graph, each ordering with its
//! time and flop count, METIS's nested dissection as the anchor, the structure for the kept
//! order), the supernodes' sizes, and the numeric phase (first and warm) with its rate.
//! Nothing here changes what the solver computes.

use super::{load, peak_rss_mb, run_child};
use anyhow::{Context, Result};
use signorini::assembly::{self, DofMap};
use signorini::mesh::{Mesh, MeshSpec, P2Nodes};
use signorini::settings::pdas::Strategy;
use signorini::sparse::anatomy::{FillCount, NodeGraph};
use signorini::{cholesky, records, symbolic};
use signorini_store::study::manifest::Manifest;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[path = "metis.rs"]
mod metis;

/// The runs of experiments/deep.toml measured by default: fb and Example 7.1 as written (graded
/// by 512 and 1024) and one without full-contact nodes (graded by 5.7).
pub const RUNS: &str = "fb_as_written,ex71_as_written,fb_without_full_contact";

/// The run whose problem the uniform grid is solved with (and whose stored level of the same
/// NDF is printed beside it).
const GRID_RUN: &str = "fb_uniform";

const DEEP: &str = "experiments/deep.toml";

/// The section's options (see `Args` in bench.rs).
pub struct Options<'a> {
    pub ndof: f64,
    pub runs: &'a [String],
    pub out: &'a Path,
    /// where each case's mesh (VTU) and node graph (ordstat's binary) are written, if given
    pub save: Option<&'a Path>,
}

/// One ordering of the node graph: its time, and what it leaves to factorise.
#[derive(serde::Serialize, serde::Deserialize, Clone)]
struct Ordering {
    name: String,
    order_s: f64,
    /// the column counts of L (elimination tree, row subtrees) that its flops come from
    count_s: f64,
    multiply_adds: f64,
    nnz_l: f64,
    node_nnz_l: f64,
    node_flops: f64,
}

/// The supernodes of the solver's structure: how many, their widths in columns, the entries.
#[derive(serde::Serialize, serde::Deserialize, Clone)]
struct Supernodes {
    count: usize,
    median_cols: usize,
    mean_cols: f64,
    /// shares of the columns of L in supernodes of fewer than 8, 8 to 32, more than 32 columns
    share_cols_below_8: f64,
    share_cols_8_to_32: f64,
    share_cols_above_32: f64,
    /// share of the executed multiply-adds in supernodes of at least 32 columns
    share_work_32: f64,
    /// values of L stored (dense blocks, explicit zeros of the relaxation included)
    values_of_l: usize,
}

/// One mesh through the factorisation, phase by phase (seconds).
#[derive(serde::Serialize, serde::Deserialize, Clone)]
struct Case {
    name: String,
    run: String,
    level: Option<usize>,
    ndof: usize,
    unknowns: usize,
    contact_nodes: usize,
    /// the contact solver's strategy (Refactor: all unknowns ordered, one numeric factorisation
    /// per active-set iteration) and the unknowns it orders
    strategy: String,
    n_order: usize,
    nodes: usize,
    grading: f64,
    mesh_s: f64,
    assembly_s: f64,
    /// the solver's symbolic phase as `ContactSolver` times it: `symbolic::analyse` (node graph,
    /// both orderings in parallel with their flop counts, structure and placement) + `Plan::new`
    solver_symbolic_s: f64,
    analyse_s: f64,
    plan_s: f64,
    /// its pieces one at a time: the node graph (with the reach of its nodes), the orderings,
    /// the structure and placement for the kept order
    graph_s: f64,
    orderings: Vec<Ordering>,
    chosen: String,
    structure_s: f64,
    supernodes: Supernodes,
    /// numeric phase: loading the values, the first factorisation (first touch of L), the
    /// best of two warm ones
    load_s: f64,
    numeric_first_s: f64,
    numeric_warm_s: f64,
    /// the kept ordering's multiply-adds (with m^3/6 of a trailing contact block) and the
    /// executed ones (explicit zeros of relaxed supernodes included); GFlop/s of the warm phase
    /// on both counts (2 flops per multiply-add)
    multiply_adds: f64,
    executed_multiply_adds: f64,
    gflops: f64,
    gflops_executed: f64,
    /// the stored record of this level (of the grid run's level of the nearest NDF for the
    /// grid): its factorisation time and active-set iterations, and the numeric factorisations
    /// that implies (Refactor: one in `new` and one per iteration)
    stored_ndof: Option<usize>,
    stored_t_factorisation: Option<f64>,
    stored_pdas_iterations: Option<usize>,
    numeric_factorisations: usize,
    peak_rss_mb: f64,
}

/// The grid of about `ndof` NDF: structured:N with N the power of two nearest (2 (2N + 1)^2 NDF).
fn grid_n(ndof: f64) -> usize {
    let n = ((ndof / 2.0).sqrt() - 1.0) / 2.0;
    1usize << n.max(1.0).log2().round() as u32
}

/// The cases: every run's level nearest `ndof`, then the grid.
fn cases(o: &Options) -> Vec<String> {
    let mut v: Vec<String> = o.runs.to_vec();
    v.push(format!("structured:{}", grid_n(o.ndof)));
    v
}

/// Run the section: every case in a process of its own, a table, and `o.out`.
pub fn section(o: &Options) -> Result<()> {
    let exe = std::env::current_exe()?;
    println!(
        "\ngraded meshes: levels nearest {:.2e} NDF of {DEEP}, rebuilt from their stored histories, beside the grid; one process each:",
        o.ndof
    );
    let mut out: Vec<Case> = Vec::new();
    for case in cases(o) {
        println!("  {case}: load {}", load());
        let mut cmd = std::process::Command::new(&exe);
        cmd.args(["--graded-child", &case, "--graded-ndof", &o.ndof.to_string()]);
        if let Some(dir) = o.save {
            cmd.arg("--graded-save").arg(dir);
        }
        out.push(run_child(&mut cmd, &format!("the graded case {case}"))?);
    }
    print_table(&out);
    let doc = serde_json::json!({
        "benchmark": "issue 42 item 1: a factorisation's phases on the deep study's graded levels (rebuilt from their stored histories) and the uniform grid of the same NDF, seconds; orderings on the node graph (one vertex per P2 node of the ordered unknowns), multiply_adds on the unknowns, node_flops = sum of squared column counts on the node graph (CHOLMOD's count); each case in a process of its own",
        "ndof": o.ndof,
        "machine": super::machine(),
        "load_at_end": load(),
        "cases": out,
    });
    records::write_json(o.out, &doc)?;
    println!("wrote {}", o.out.display());
    Ok(())
}

/// One case in this process, its row printed after `ROW ` (run by [`section`]).
pub fn child(case: &str, ndof: f64, save: Option<&Path>) -> Result<()> {
    let row = measure(case, ndof, save)?;
    println!("ROW {}", serde_json::to_string(&row)?);
    Ok(())
}

/// The mesh of a case, with its problem and stored level: a run's level nearest `ndof`
/// rebuilt from its history, or structured:N with the grid run's problem.
struct Built {
    mesh: Mesh,
    problem: Box<dyn signorini::problems::Problem>,
    run: String,
    level: Option<usize>,
    stored: Option<signorini::level::record::LevelRecord>,
}

fn build(case: &str, ndof: f64) -> Result<Built> {
    let manifest = Manifest::load(Path::new(DEEP))?;
    let grid = MeshSpec::parse(case).ok();
    let run = if grid.is_some() { GRID_RUN } else { case };
    let planned = manifest
        .runs
        .iter()
        .find(|p| p.spec.id == run)
        .with_context(|| format!("{DEEP} has no run '{run}' (the graded runs are its run ids)"))?;
    let record = records::StudyDir::new(Path::new("results"), &manifest.study)
        .read_run(run)?
        .with_context(|| format!("results/{}/runs has no record of {run}", manifest.study))?;
    let nearest = record.levels.iter().min_by(|a, b| (a.ndof as f64 - ndof).abs().total_cmp(&(b.ndof as f64 - ndof).abs())).cloned();
    let prepared = signorini::study::prepare(&manifest.study, &planned.spec, &manifest.file, false)?.context("interrupted")?;
    let (mesh, level) = match grid {
        Some(spec) => (spec.build(prepared.problem.as_ref())?, None),
        None => {
            let history = record.history.as_ref().with_context(|| format!("{run} has no stored refinement history"))?;
            let level = nearest.as_ref().context("no level")?.level;
            (signorini::adapt::replay::mesh_at(prepared.initial_mesh()?, history, level)?, Some(level))
        }
    };
    Ok(Built { mesh, problem: prepared.problem, run: run.into(), level, stored: nearest })
}

fn measure(case: &str, ndof: f64, save: Option<&Path>) -> Result<Case> {
    let t0 = Instant::now();
    let b = build(case, ndof)?;
    let mesh_s = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let nodes = P2Nodes::new(&b.mesh);
    let dofs = DofMap::new(&nodes, b.problem.as_ref());
    let sys = assembly::assemble(&b.mesh, &nodes, &dofs, b.problem.as_ref());
    let assembly_s = t0.elapsed().as_secs_f64();
    let coords = dofs.unknown_coords(&nodes);
    let (matrix, n) = (&sys.matrix, sys.matrix.n());
    let strategy = Strategy::auto(n - dofs.n_interior, n);
    let n_order = if strategy == Strategy::Schur { dofs.n_interior } else { n };
    eprintln!("graded {case}: {} NDF, {n} unknowns, {strategy:?}", 2 * nodes.len());
    let solver = solver_phases(matrix, n_order, &coords)?;
    // the pieces one at a time
    let t0 = Instant::now();
    let graph = NodeGraph::new(matrix, n_order, &coords);
    let graph_s = t0.elapsed().as_secs_f64();
    let chosen = serde_json::to_value(solver.choice.method)?.as_str().unwrap_or("?").to_string();
    let (orderings, kept) = orderings(case, &graph, &chosen);
    let kept = kept.context("the kept ordering was not among the candidates")?;
    let t0 = Instant::now();
    let structure = graph.symbolic(matrix, n_order, &kept);
    let structure_s = t0.elapsed().as_secs_f64();
    drop(structure);
    if let Some(dir) = save {
        save_case(dir, case, &b.mesh, &nodes, &graph)?;
    }
    let stored = b.stored.as_ref();
    let pdas = stored.map(|r| r.pdas_iterations);
    Ok(Case {
        name: match b.level {
            Some(level) => format!("{} level {level}", b.run),
            None => case.to_string(),
        },
        run: b.run.clone(),
        level: b.level,
        ndof: 2 * nodes.len(),
        unknowns: n,
        contact_nodes: dofs.contact.len(),
        strategy: format!("{strategy:?}"),
        n_order,
        nodes: graph.n_nodes(),
        grading: graph.grading(),
        mesh_s,
        assembly_s,
        solver_symbolic_s: solver.analyse_s + solver.plan_s,
        analyse_s: solver.analyse_s,
        plan_s: solver.plan_s,
        graph_s,
        orderings,
        chosen,
        structure_s,
        supernodes: solver.supernodes,
        load_s: solver.load_s,
        numeric_first_s: solver.numeric_first_s,
        numeric_warm_s: solver.numeric_warm_s,
        multiply_adds: solver.multiply_adds,
        executed_multiply_adds: solver.executed,
        gflops: 2.0 * solver.multiply_adds / solver.numeric_warm_s / 1e9,
        gflops_executed: 2.0 * solver.executed / solver.numeric_warm_s / 1e9,
        stored_ndof: stored.map(|r| r.ndof),
        stored_t_factorisation: stored.map(|r| r.t_factorisation),
        stored_pdas_iterations: pdas,
        numeric_factorisations: if strategy == Strategy::Refactor { 1 + pdas.unwrap_or(0) } else { 1 },
        peak_rss_mb: peak_rss_mb(),
    })
}

/// The solver's symbolic phase as `ContactSolver::new` runs it, then its numeric phase.
struct SolverPhases {
    analyse_s: f64,
    plan_s: f64,
    choice: signorini::ordering::OrderingChoice,
    supernodes: Supernodes,
    load_s: f64,
    numeric_first_s: f64,
    numeric_warm_s: f64,
    multiply_adds: f64,
    executed: f64,
}

fn solver_phases(matrix: &signorini::sparse::csc::SymCsc, n_order: usize, coords: &[[f64; 2]]) -> Result<SolverPhases> {
    let t0 = Instant::now();
    let (sn, placement, choice) = symbolic::analyse(matrix, n_order, coords);
    let analyse_s = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let plan = cholesky::Plan::new(&sn);
    let plan_s = t0.elapsed().as_secs_f64();
    let mut l = cholesky::zeros(sn.len_val(), "L")?;
    let t0 = Instant::now();
    cholesky::load(&sn, &placement, matrix.values(), None, &mut l, true);
    let load_s = t0.elapsed().as_secs_f64();
    let factor = |l: &mut [f64]| -> Result<f64> {
        let t0 = Instant::now();
        cholesky::factorize(&sn, &plan, l).map_err(|e| anyhow::anyhow!("{e:?}"))?;
        Ok(t0.elapsed().as_secs_f64())
    };
    let numeric_first_s = factor(&mut l)?;
    let mut numeric_warm_s = f64::INFINITY;
    for _ in 0..2 {
        cholesky::load(&sn, &placement, matrix.values(), None, &mut l, false);
        numeric_warm_s = numeric_warm_s.min(factor(&mut l)?);
    }
    // the ordering counts the leading block; a trailing contact block is dense: m^3 / 6 more
    let m = (sn.n() - n_order) as f64;
    Ok(SolverPhases {
        analyse_s,
        plan_s,
        choice,
        supernodes: supernodes(&sn, &plan),
        load_s,
        numeric_first_s,
        numeric_warm_s,
        multiply_adds: choice.multiply_adds() + m * m * m / 6.0,
        executed: plan.multiply_adds(),
    })
}

/// An ordering of the node graph, None if it is not available.
type OrderOf = fn(&NodeGraph) -> Option<Vec<usize>>;

/// Each ordering timed and counted, and the order the solver kept (`chosen`).
fn orderings(case: &str, graph: &NodeGraph, chosen: &str) -> (Vec<Ordering>, Option<Vec<usize>>) {
    let candidates: [(&str, OrderOf); 3] =
        [("nested_dissection", |g| Some(g.nested_dissection())), ("minimum_degree", NodeGraph::minimum_degree), ("metis", metis::node_nd)];
    let (mut out, mut kept) = (Vec::new(), None);
    for (name, order_of) in candidates {
        let t0 = Instant::now();
        let Some(order) = order_of(graph) else { continue };
        let order_s = t0.elapsed().as_secs_f64();
        let t0 = Instant::now();
        let c: FillCount = graph.count(&order);
        let count_s = t0.elapsed().as_secs_f64();
        eprintln!("graded {case}: {name} {order_s:.2} s, {:.3e} multiply-adds", c.multiply_adds);
        let (multiply_adds, nnz_l, node_nnz_l, node_flops) = (c.multiply_adds, c.nnz_l, c.node_nnz_l, c.node_flops);
        out.push(Ordering { name: name.into(), order_s, count_s, multiply_adds, nnz_l, node_nnz_l, node_flops });
        if name == chosen {
            kept = Some(order);
        }
    }
    (out, kept)
}

fn supernodes(sn: &symbolic::Symbolic, plan: &cholesky::Plan) -> Supernodes {
    let begin = sn.supernode_begin();
    let widths: Vec<usize> = begin.windows(2).map(|w| w[1] - w[0]).collect();
    let cols = sn.n() as f64;
    let share = |keep: &dyn Fn(usize) -> bool| widths.iter().filter(|&&w| keep(w)).sum::<usize>() as f64 / cols;
    let mut sorted = widths.clone();
    sorted.sort_unstable();
    Supernodes {
        count: widths.len(),
        median_cols: sorted.get(sorted.len() / 2).copied().unwrap_or(0),
        mean_cols: cols / widths.len().max(1) as f64,
        share_cols_below_8: share(&|w| w < 8),
        share_cols_8_to_32: share(&|w| (8..=32).contains(&w)),
        share_cols_above_32: share(&|w| w > 32),
        share_work_32: plan.shape(sn, 32).1,
        values_of_l: sn.len_val(),
    }
}

/// The case's mesh as VTU and its node graph in
/// a binary format (n, entries, then ptr and adj as int32), for a check against CHOLMOD's counts.
fn save_case(dir: &Path, case: &str, mesh: &Mesh, nodes: &P2Nodes, graph: &NodeGraph) -> Result<()> {
    std::fs::create_dir_all(dir)?;
    let stem: String = case.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }).collect();
    let vtu: PathBuf = dir.join(format!("{stem}.vtu"));
    std::fs::write(&vtu, signorini::mesh::io::vtu(mesh, nodes, &[], &[]))?;
    let (ptr, adj) = graph.csr();
    let mut bytes = Vec::with_capacity(4 * (2 + ptr.len() + adj.len()));
    for v in [graph.n_nodes() as u32, adj.len() as u32].iter().chain(ptr).chain(adj) {
        bytes.extend_from_slice(&(*v as i32).to_le_bytes());
    }
    std::fs::write(dir.join(format!("{stem}.bin")), bytes)?;
    eprintln!("graded {case}: wrote {} and {stem}.bin", vtu.display());
    Ok(())
}

fn ordering<'a>(c: &'a Case, name: &str) -> Option<&'a Ordering> {
    c.orderings.iter().find(|o| o.name == name)
}

/// The table: phases per case, then the orderings, then the numeric rate against the grid's.
fn print_table(cases: &[Case]) {
    println!(
        "\n{:<33} {:>8} {:>6} {:>8} | {:>6} {:>6} {:>6} {:>6} | {:>6} {:>6} {:>6} | {:>7} {:>8} {:>6} {:>6} {:>6}",
        "case",
        "NDF",
        "grade",
        "strategy",
        "solver",
        "graph",
        "struct",
        "plan",
        "load",
        "first",
        "warm",
        "snodes",
        "med.cols",
        "<8",
        "8-32",
        ">32"
    );
    for c in cases {
        let s = &c.supernodes;
        println!(
            "{:<33} {:>8} {:>6.0} {:>8} | {:>6.2} {:>6.2} {:>6.2} {:>6.2} | {:>6.2} {:>6.2} {:>6.2} | {:>7} {:>8} {:>6.2} {:>6.2} {:>6.2}",
            c.name,
            c.ndof,
            c.grading,
            c.strategy,
            c.solver_symbolic_s,
            c.graph_s,
            c.structure_s,
            c.plan_s,
            c.load_s,
            c.numeric_first_s,
            c.numeric_warm_s,
            s.count,
            s.median_cols,
            s.share_cols_below_8,
            s.share_cols_8_to_32,
            s.share_cols_above_32
        );
    }
    println!(
        "\n{:<33} {:<18} {:>8} {:>8} {:>10} {:>10} {:>10}  kept",
        "case", "ordering", "order s", "count s", "madds", "nnz(L)", "node flops"
    );
    for c in cases {
        for o in &c.orderings {
            println!(
                "{:<33} {:<18} {:>8.2} {:>8.2} {:>10.3e} {:>10.3e} {:>10.3e}  {}",
                c.name,
                o.name,
                o.order_s,
                o.count_s,
                o.multiply_adds,
                o.nnz_l,
                o.node_flops,
                if o.name == c.chosen { "*" } else { "" }
            );
        }
    }
    let grid = cases.iter().find(|c| c.level.is_none());
    println!(
        "\n{:<33} {:>10} {:>10} {:>8} {:>8} {:>9} {:>9} | {:>9} {:>6} {:>10}",
        "case", "madds", "executed", "GFlop/s", "vs grid", "flops/grid", "AMD/METIS", "stored tf", "numer.", "model tf"
    );
    for c in cases {
        let vs = |f: fn(&Case) -> f64| grid.map_or(f64::NAN, |g| f(c) / f(g));
        let amd_metis = match (ordering(c, "minimum_degree"), ordering(c, "metis")) {
            (Some(a), Some(m)) => a.node_flops / m.node_flops,
            _ => f64::NAN,
        };
        // what this run of the bench says the level's t_factorisation is: the solver's symbolic
        // phase and as many warm numeric phases (with their loads) as the level factorised
        let model = c.solver_symbolic_s + c.numeric_factorisations as f64 * (c.numeric_warm_s + c.load_s);
        println!(
            "{:<33} {:>10.3e} {:>10.3e} {:>8.1} {:>8.2} {:>9.3} {:>9.2} | {:>9} {:>6} {:>10.2}",
            c.name,
            c.multiply_adds,
            c.executed_multiply_adds,
            c.gflops,
            vs(|c| c.gflops),
            vs(|c| c.multiply_adds),
            amd_metis,
            c.stored_t_factorisation.map_or("-".into(), |t| format!("{t:.2}")),
            c.numeric_factorisations,
            model
        );
    }
}
