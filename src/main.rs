//! The `signorini` command line: thin, everything lives in the library.

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use signorini::adapt::Refine;
use signorini::adapt::{self, AdaptConfig};
use signorini::contact::PdasOptions;
use signorini::contact::sampling::Sampling;
use signorini::estimate::{self, ContactTerm, EstimatorConfig, LogFactor};
use signorini::mesh::MeshSpec;
use signorini::{norms, problems, report, solve, study};
use std::process::ExitCode;

/// `eprintln!` that cannot panic: a message whose write to stderr fails (a full device, a
/// file-size limit, a closed stderr) is dropped, and the exit status still says what happened.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// The first error writing standard output, if one happened (a full device, a file-size limit).
static STDOUT_ERROR: std::sync::OnceLock<String> = std::sync::OnceLock::new();

/// Write to standard output without panicking: std's `println!` panics when the write fails
/// (`> /dev/full` ended in exit 101). The first error is kept, later output dropped, and [`main`]
/// exits with the error status naming it. Every `print!`/`println!` of this file comes here (the
/// two macros below shadow std's).
fn stdout_write(args: std::fmt::Arguments, newline: bool) {
    use std::io::Write as _;
    if STDOUT_ERROR.get().is_some() {
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|_| if newline { out.write_all(b"\n") } else { Ok(()) }) {
        let _ = STDOUT_ERROR.set(e.to_string());
    }
}

/// Flush standard output (its last lines are buffered) and report the first write error.
fn stdout_result() -> std::result::Result<(), String> {
    use std::io::Write as _;
    if let Err(e) = std::io::stdout().flush() {
        let _ = STDOUT_ERROR.set(e.to_string());
    }
    STDOUT_ERROR.get().map_or(Ok(()), |e| Err(e.clone()))
}

macro_rules! println {
    () => { stdout_write(format_args!(""), true) };
    ($($arg:tt)*) => { stdout_write(format_args!($($arg)*), true) };
}

macro_rules! print {
    ($($arg:tt)*) => { stdout_write(format_args!($($arg)*), false) };
}

/// The files this command wrote, in order, each complete (written to a temporary name and
/// renamed). A failed standard output then names them: they are kept and valid, and only the
/// printed report was lost (battery 14: `export > /dev/full` said only "No space left on device").
static WRITTEN: std::sync::Mutex<Vec<std::path::PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Print `line` for the file `path` just written, and remember the file ([`WRITTEN`]). Every
/// "wrote" line of this file comes here.
fn wrote(path: &std::path::Path, line: std::fmt::Arguments) {
    let mut written = WRITTEN.lock().unwrap_or_else(|e| e.into_inner());
    if !written.iter().any(|w| w == path) {
        written.push(path.to_path_buf());
    }
    drop(written);
    println!("{line}");
}

/// The error of a failed standard output (`e`): with the files written, which it did not touch.
fn stdout_error(e: &str) -> anyhow::Error {
    let written = WRITTEN.lock().unwrap_or_else(|e| e.into_inner());
    if written.is_empty() {
        return anyhow::anyhow!("writing standard output: {e}");
    }
    let files: Vec<String> = written.iter().map(|f| f.display().to_string()).collect();
    anyhow::anyhow!(
        "writing standard output: {e}. Only the printed report was lost: the files were written before, complete and valid: {}",
        files.join(", ")
    )
}

#[derive(Parser)]
#[command(name = "signorini", version, about = "P2 finite elements for the Signorini problem and its supremum-norm a posteriori estimator")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// One solve on a mesh (structured:N, symmetric:N or a Gmsh file gmsh:PATH.msh), or on a
    /// mesh of the adaptive loop from it (--adapt-levels, --adapt-min-ndof), with its error,
    /// estimator and KKT report.
    Solve {
        #[command(flatten)]
        args: SolveArgs,
        /// Print one JSON object on stdout instead of the summary.
        #[arg(long)]
        json: bool,
    },
    /// The adaptive loop SOLVE -> ESTIMATE -> MARK -> REFINE, one table row per level.
    Adapt(AdaptArgs),
    /// Run a declared study (experiments/STUDY.toml) into results/STUDY/.
    Run {
        /// The study manifest(s).
        #[arg(required = true)]
        manifests: Vec<std::path::PathBuf>,
        /// The short form: the first quick_levels levels of every run (an exact prefix).
        /// Written to target/quick-results/ unless --results is given.
        #[arg(long)]
        quick: bool,
        /// Threads for assembly, estimator and errors (results do not depend on it); more than
        /// the cores available is reduced to them, with a note.
        #[arg(long, allow_negative_numbers = true)]
        jobs: Option<usize>,
        /// Run every N-th run only: K/N, 1 <= K <= N (cluster job arrays); shards merge by run id.
        /// A shard that holds no run of the manifests given is an error.
        #[arg(long)]
        shard: Option<String>,
        /// Start over instead of resuming after the runs already finished.
        #[arg(long)]
        fresh: bool,
        /// Replace stored runs whose spec differs from the manifest's (records and mesh
        /// snapshots; each when its new run has finished) and remove stored runs the manifest
        /// does not declare. Without it such a study is refused, naming the runs and keys.
        #[arg(long, conflicts_with = "fresh")]
        replace: bool,
        /// Results root [default: results, or target/quick-results with --quick].
        #[arg(long)]
        results: Option<std::path::PathBuf>,
        /// If another process is running the same study, wait for it instead of refusing.
        #[arg(long)]
        wait: bool,
        /// Check the manifests (and the shard) and the results folder as a run does, print its
        /// runs, one STUDY/RUN a line (those it would keep, replace or remove say so, and the
        /// leftover files of unfinished runs it would remove first), and run nothing
        /// (scripts/slurm/submit.sh checks --tasks with it).
        #[arg(long)]
        plan: bool,
    },
    /// Rerun every declared study and compare with the stored results at every level, field by
    /// field, within the manifests' tolerances; check levels.csv, provenance.json and CLAIMS.md
    /// against the records; exit non-zero on drift. The report goes to target/drift/ (with
    /// --against DIR: DIR/drift-report.json).
    Drift {
        /// Rerun the quick forms only (prefixes of the stored full runs: the first levels).
        #[arg(long)]
        quick: bool,
        /// Rerun deep studies (a [drift.deep] table in their manifest) to the end; without it
        /// their runs are rerun in their quick forms, the ones the table names in full.
        #[arg(long, conflicts_with_all = ["quick", "against"])]
        deep: bool,
        /// Compare the records in this results folder with the stored ones instead of rerunning
        /// (a study rerun into a scratch folder; or every study rerun with another ordering or
        /// thread count, to measure round-off): the studies DIR holds, their provenance
        /// (manifest, problem files, meshes) included; the others are named as not compared.
        #[arg(long, value_name = "DIR", conflicts_with = "quick")]
        against: Option<std::path::PathBuf>,
        /// Where to write the JSON report (default: target/drift/report[_quick][-STUDY...].json;
        /// with --against DIR: DIR/drift-report.json).
        #[arg(long, value_name = "FILE")]
        report: Option<std::path::PathBuf>,
        /// With --study and --report FILE: merge into FILE, replacing the checked studies'
        /// entries and keeping every other study's (`make roundoff STUDIES=...` measures some
        /// studies into the reports of all).
        #[arg(long, requires_all = ["report", "study"])]
        merge: bool,
        /// Accept a deliberate change: rerun STUDY in full and rewrite its stored results (in
        /// --results); nothing is compared, so --quick, --against, --report and --study do not apply.
        #[arg(long, value_name = "STUDY", conflicts_with_all = ["quick", "against", "report", "study", "merge"])]
        accept: Vec<String>,
        /// Check only these studies (default: every experiments/*.toml).
        #[arg(long, value_name = "STUDY")]
        study: Vec<String>,
        /// Folder of the study manifests.
        #[arg(long, default_value = "experiments")]
        experiments: std::path::PathBuf,
        /// Results root holding the stored results to compare with.
        #[arg(long, default_value = "results")]
        results: std::path::PathBuf,
    },
    /// Redraw every figure under figures/ and results/CLAIMS.md from the stored results alone;
    /// with --results DIR (a study rerun into a scratch folder), the figures of the declared
    /// studies DIR holds into DIR/figures/ and DIR/CLAIMS.md. Refuses if a study's runs do not
    /// match its manifest (interrupted, sharded or partial), naming what is missing.
    Figures {
        /// Results root to read; CLAIMS.md is written there [default: results, where every
        /// declared study must be complete].
        #[arg(long)]
        results: Option<std::path::PathBuf>,
        /// The declared studies the results must match.
        #[arg(long, default_value = "experiments")]
        experiments: std::path::PathBuf,
        /// Folder the figures are written to [default: figures, or DIR/figures with --results DIR].
        #[arg(long, visible_alias = "out")]
        figures: Option<std::path::PathBuf>,
        /// Draw only these studies' figures (repeatable) [default: every study the results hold].
        #[arg(long, value_name = "STUDY")]
        study: Vec<String>,
        /// If another process is writing a study of the results folder, wait for it to finish
        /// instead of refusing (what the Slurm finish job does).
        #[arg(long)]
        wait: bool,
    },
    /// Write one self-contained HTML page per study for a browser (OUT/STUDY.html): its figures
    /// embedded, its CLAIMS rows, the drift status from the last drift report, the run table and
    /// the provenance. Reads only files (records, PNGs, the drift report): run `figures` and
    /// `drift` first for a current page.
    Report {
        /// Results root to read [default: results].
        #[arg(long)]
        results: Option<std::path::PathBuf>,
        /// Folder of the figures' PNGs [default: figures, or DIR/figures with --results DIR].
        #[arg(long)]
        figures: Option<std::path::PathBuf>,
        /// Folder the pages are written to [default: target/report, or DIR/report with --results DIR].
        #[arg(long)]
        out: Option<std::path::PathBuf>,
        /// Only these studies (repeatable) [default: every study the results hold].
        #[arg(long, value_name = "STUDY")]
        study: Vec<String>,
        /// The drift report the pages quote [default: target/drift/report.json, or
        /// DIR/drift-report.json with --results DIR, and every target/drift/report*.json drift
        /// wrote: each page quotes the newest that covers its study].
        #[arg(long, value_name = "FILE")]
        drift_report: Option<std::path::PathBuf>,
        /// Folder of the study manifests, whose run roles the CLAIMS rows read.
        #[arg(long, default_value = "experiments")]
        experiments: std::path::PathBuf,
        /// If another process is writing a study of the results folder, wait for it to finish
        /// instead of refusing (what the Slurm finish job does).
        #[arg(long)]
        wait: bool,
    },
    /// Solve as `solve` does and write the mesh and solution for the NGSolve cross-check
    /// (OUT/mesh.vtu, OUT/case.json: the report `solve --json` prints).
    Export {
        #[command(flatten)]
        args: SolveArgs,
        /// Output directory.
        #[arg(long)]
        out: std::path::PathBuf,
    },
}

impl Command {
    /// Whether the command writes files (results, figures, pages, a report, a VTU): a closed
    /// standard output must not stop it before they are written ([`main`]).
    fn writes_files(&self) -> bool {
        match self {
            Command::Solve { .. } => false,
            Command::Adapt(args) => args.save.is_some(),
            Command::Run { plan, .. } => !plan,
            Command::Drift { .. } | Command::Figures { .. } | Command::Export { .. } | Command::Report { .. } => true,
        }
    }
}

/// The estimator's flags. Each argument's id is the setting's key (`estimator.c0`, as
/// [`estimate::ConfigError`] names it), its default the library's ([`EstimatorConfig::default`]),
/// its values the library's enums ([`clap::ValueEnum`]).
#[derive(clap::Args)]
struct EstimatorArgs {
    /// Estimator constant C_0 (estimate = C_0 eta_h).
    #[arg(id = "estimator.c0", long = "c0", value_name = "C0", allow_negative_numbers = true, default_value_t = EstimatorConfig::default().c0)]
    c0: f64,
    /// eta_5 over all contact nodes (as-written), without full-contact nodes, or the repaired
    /// contact terms (only the tensile normal stress at full-contact nodes, eta_7 on a narrower set).
    #[arg(long, value_enum, default_value_t = EstimatorConfig::default().contact_term)]
    contact_term: ContactTerm,
    /// The log factor l_h.
    #[arg(long, value_enum, default_value_t = EstimatorConfig::default().log_factor)]
    log_factor: LogFactor,
    /// Points the L-infinity norms are taken over.
    #[arg(long, value_enum, default_value_t = EstimatorConfig::default().sampling)]
    sampling: Sampling,
}

impl EstimatorArgs {
    fn config(&self) -> EstimatorConfig {
        EstimatorConfig {
            c0: self.c0,
            contact_term: self.contact_term,
            log_factor: self.log_factor,
            sampling: self.sampling,
            // the reading of sigma-hat in eta_4, eta_5 is a manifest option (estimator.stress_frame)
            ..EstimatorConfig::default()
        }
    }
}

#[derive(clap::Args)]
struct AdaptArgs {
    /// A built-in problem (ex71, ex72, fb, patch) or the path of a problem file (NAME.toml; see
    /// experiments/problems/README.md).
    #[arg(long)]
    problem: String,
    /// Initial mesh: structured:N (or symmetric:N, mirrored about y = 0.5), or gmsh:PATH.msh.
    #[arg(long, default_value = MeshSpec::DEFAULT)]
    mesh: String,
    /// Number of levels solved (level 0 is the initial mesh).
    #[arg(long, allow_negative_numbers = true, default_value_t = AdaptConfig::default().levels)]
    levels: usize,
    /// Marking parameter of the maximum strategy: mark T if eta_T >= theta max eta_T, 0 < theta <= 1.
    #[arg(long, allow_negative_numbers = true, default_value_t = AdaptConfig::default().theta, conflicts_with = "uniform")]
    theta: f64,
    /// Refine every element instead of marking.
    #[arg(long)]
    uniform: bool,
    /// Stop before a level with more unknowns than this.
    #[arg(long, allow_negative_numbers = true)]
    max_ndof: Option<usize>,
    /// Stop after the first level with at least this many unknowns.
    #[arg(long, allow_negative_numbers = true)]
    stop_ndof: Option<usize>,
    /// Write the last level's mesh and solution to this VTU file (ParaView, meshio: displacement,
    /// contact force, active set, element indicators).
    #[arg(long, value_name = "PATH.vtu")]
    save: Option<std::path::PathBuf>,
    #[command(flatten)]
    estimator: EstimatorArgs,
}

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("adaptive").args(["adapt_levels", "adapt_min_ndof"]).multiple(true)))]
struct SolveArgs {
    /// A built-in problem (ex71, ex72, fb, patch) or the path of a problem file (NAME.toml; see
    /// experiments/problems/README.md).
    #[arg(long)]
    problem: String,
    /// Mesh: structured:N (or symmetric:N, mirrored about y = 0.5), or gmsh:PATH.msh (a Gmsh file).
    #[arg(long)]
    mesh: String,
    /// Evaluate u_h at X,Y, a point of the mesh (repeatable; negative numbers are read as values).
    #[arg(long = "probe", value_name = "X,Y", allow_hyphen_values = true)]
    probes: Vec<String>,
    /// Maximum number of active-set iterations.
    #[arg(
        id = "pdas.max_iterations",
        long = "max-pdas-iterations",
        value_name = "MAX_PDAS_ITERATIONS",
        allow_negative_numbers = true,
        default_value_t = PdasOptions::default().max_iterations
    )]
    max_pdas_iterations: usize,
    /// Log every active-set iteration on stderr.
    #[arg(long, short)]
    verbose: bool,
    /// Marking parameter of the maximum strategy, 0 < theta <= 1 (only with --adapt-levels /
    /// --adapt-min-ndof).
    #[arg(long, allow_negative_numbers = true, requires = "adaptive", default_value_t = AdaptConfig::default().theta)]
    theta: f64,
    /// Solve on the mesh of this adaptive level instead (refined from --mesh, marked with the
    /// estimator options below); with --adapt-min-ndof, the last level tried.
    #[arg(long, allow_negative_numbers = true)]
    adapt_levels: Option<usize>,
    /// Solve on the first adaptive level with at least this many unknowns (as the studies'
    /// reference solutions do) instead.
    #[arg(long, allow_negative_numbers = true)]
    adapt_min_ndof: Option<usize>,
    #[command(flatten)]
    estimator: EstimatorArgs,
}

/// The flag of the setting `key` (`theta`, `estimator.c0`, `pdas.max_iterations`) in the
/// subcommand `sub`: the argument whose id is the key, so clap's definitions are the only table.
fn flag_of(sub: &str, key: &str) -> String {
    let cmd = <Cli as clap::CommandFactory>::command();
    let arg = cmd.find_subcommand(sub).and_then(|c| c.get_arguments().find(|a| a.get_id() == key));
    arg.and_then(|a| a.get_long()).map_or_else(|| key.to_string(), |long| format!("--{long}"))
}

/// Validate the loop's settings as manifests do (the same functions), naming the flag of the
/// subcommand `sub`: every setting, and `max_ndof` against the initial mesh `spec`.
fn validate(sub: &str, config: &AdaptConfig, spec: &MeshSpec) -> Result<()> {
    let flag = |e: estimate::ConfigError| anyhow::anyhow!("{}: expected {}, got {}", flag_of(sub, e.key), e.expected, e.got);
    config.validate().map_err(flag)?;
    config.check_initial(spec.ndof()?, &spec.to_string()).map_err(flag)
}

/// A solve's mesh, solution, element indicators and report.
type Solved = (signorini::mesh::Mesh, solve::DiscreteSolution, Vec<f64>, report::SolveReport);

fn run_solve(args: &SolveArgs) -> Result<Solved> {
    let problem = problems::by_name(&args.problem)?;
    let spec = MeshSpec::parse(&args.mesh)?;
    let probes = args.probes.iter().map(|p| report::parse_probe(p)).collect::<Result<Vec<_>, _>>()?;
    let pdas = PdasOptions { max_iterations: args.max_pdas_iterations, ..Default::default() };
    let estimator = args.estimator.config();
    let adaptive = args.adapt_levels.is_some() || args.adapt_min_ndof.is_some();
    let theta = args.theta;
    let config = AdaptConfig {
        levels: args.adapt_levels.map_or(200, |l| l.saturating_add(1)),
        theta,
        estimator,
        pdas: pdas.clone(),
        ..Default::default()
    };
    validate("solve", &config, &spec)?;
    signorini::memory::check_memory(&spec.to_string(), spec.ndof()?)?;
    if let Some(n) = args.adapt_min_ndof {
        signorini::memory::check_memory(&format!("an adaptive level reaching --adapt-min-ndof {n}"), n as f64)?;
    }
    let mut mesh = spec.build(problem.as_ref())?;
    // probes outside the initial mesh fail before anything is solved
    let locator = signorini::mesh::locate::Locator::new(&mesh);
    if let Some(&[x, y]) = probes.iter().find(|&&x| locator.locate(&mesh, x).is_none()) {
        bail!(report::ProbeError::Outside { x, y });
    }
    let mut mesh_name = spec.to_string();
    if adaptive {
        let min_ndof = args.adapt_min_ndof.unwrap_or(0);
        let result = adapt::run(problem.as_ref(), mesh, &config, None, &mut |l| {
            if l.record.ndof >= min_ndof && args.adapt_min_ndof.is_some() {
                std::ops::ControlFlow::Break(())
            } else {
                std::ops::ControlFlow::Continue(())
            }
        })?;
        if result.termination.is_error() {
            bail!("{}", result.termination.note(&config).unwrap_or_default());
        }
        let last = result.records.last().context("the adaptive loop solved no level")?;
        if let Some(min) = args.adapt_min_ndof.filter(|&min| last.ndof < min) {
            let why = result.termination.note(&config).unwrap_or_else(|| "the last level --adapt-levels allows".into());
            bail!(
                "the adaptive loop ended at level {} with {} unknowns ({why}), short of --adapt-min-ndof {min}: raise --adapt-levels, or lower --adapt-min-ndof",
                last.level,
                last.ndof
            );
        }
        let level = last.level;
        mesh = result.mesh;
        mesh_name = format!("{spec} refined adaptively to level {level} (theta {theta})");
    }
    let verbose = args.verbose;
    let mut log = |it: &signorini::contact::PdasIteration| {
        if verbose {
            say!("pdas {:>3}: active {:>6} (+{} -{}), residual {:.3e}", it.iteration, it.active, it.added, it.removed, it.residual);
        }
    };
    let sol =
        solve::solve(&mesh, problem.as_ref(), &pdas, &mut log).with_context(|| format!("solving {} on {}", problem.name(), mesh_name))?;
    let error = problem.exact().map(|e| norms::linf_error(&mesh, &sol, &|x| e.u(x)));
    let est = estimate::estimate(&mesh, problem.as_ref(), &sol, &estimator);
    if let Some(bad) = problem.bad_datum() {
        return Err(solve::SolveError::Data(bad)).with_context(|| format!("estimating on {mesh_name}"));
    }
    est.terms.check_finite().with_context(|| format!("estimating on {mesh_name}"))?;
    let warnings = match adapt::resolution(problem.as_ref(), &mesh, &sol, &est) {
        adapt::Resolution::Unresolved(e) => return Err(e).with_context(|| format!("solving {} on {mesh_name}", problem.name())),
        adapt::Resolution::AtRoundoff => vec![adapt::Caveat::AtRoundoff.to_string()],
        adapt::Resolution::Resolved(caveats) => caveats.iter().map(ToString::to_string).collect(),
    };
    for w in &warnings {
        say!("warning: {w}");
    }
    let report =
        report::SolveReport { warnings, ..report::SolveReport::new(problem.name(), &mesh_name, &mesh, &sol, error, &est, &probes)? };
    Ok((mesh, sol, est.element, report))
}

fn run_adapt(args: &AdaptArgs) -> Result<()> {
    let problem = problems::by_name(&args.problem)?;
    let spec = MeshSpec::parse(&args.mesh)?;
    let config = AdaptConfig {
        levels: args.levels,
        max_ndof: args.max_ndof,
        stop_ndof: args.stop_ndof,
        refine: if args.uniform { Refine::Uniform } else { Refine::Adaptive },
        theta: args.theta,
        estimator: args.estimator.config(),
        ..Default::default()
    };
    validate("adapt", &config, &spec)?;
    if let Some(path) = &args.save {
        check_writable("--save", path)?;
    }
    signorini::memory::check_memory(&spec.to_string(), spec.ndof()?)?;
    let mesh = spec.build(problem.as_ref())?;
    let exact = problem.exact();
    let reference = exact.map(|e| move |x: [f64; 2]| e.u(x));
    if exact.is_none() {
        println!(
            "# {} has no exact solution: the error and eff columns are empty (the studies measure them against a reference solution, see experiments/)",
            problem.name()
        );
    }
    let or_dash =
        |v: Option<f64>, scientific: bool| v.map_or("-".to_string(), |v| if scientific { format!("{v:.3e}") } else { format!("{v:.3}") });
    println!(
        "{:>3} {:>8} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>6} {:>4} {:>7}",
        "lvl", "ndof", "h_min", "error", "estimate", "eff", "eta1", "eta2", "eta3", "eta4", "eta5", "eta6+7", "active", "its", "time"
    );
    let result = adapt::run(problem.as_ref(), mesh, &config, reference.as_ref().map(|r| r as norms::Reference), &mut |l| {
        let r = l.record;
        println!(
            "{:>3} {:>8} {:>9.3e} {:>9} {:>9.3e} {:>9} {:>9.3e} {:>9.3e} {:>9.3e} {:>9.3e} {:>9.3e} {:>9.3e} {:>6} {:>4} {:>7.3}",
            r.level,
            r.ndof,
            r.h_min,
            or_dash(r.err_quadrature, true),
            r.terms.estimate,
            // in exponent form far from 1 (an exact solution's 5.6e14 printed 18 digits)
            or_dash(r.efficiency, r.efficiency.is_some_and(|e| !(1e-3..1e4).contains(&e.abs()))),
            r.terms.eta1,
            r.terms.eta2,
            r.terms.eta3,
            r.terms.eta4,
            r.terms.eta5,
            r.terms.eta6 + r.terms.eta7,
            r.active_nodes,
            r.pdas_iterations,
            r.t_level
        );
        for c in l.caveats {
            say!("warning: level {}: {c}", r.level);
        }
        // an interrupt (SIGINT) stops after the level just printed, as `run` does
        if study::interrupted() { std::ops::ControlFlow::Break(()) } else { std::ops::ControlFlow::Continue(()) }
    })?;
    // a stop the user must act on is the error this command ends with (after --save), as the
    // memory stop is
    if let Some(note) = result.termination.note(&config).filter(|_| !result.termination.is_error()) {
        println!("# {note}");
    }
    let level = result.records.last().map_or(0, |r| r.level);
    if let Some(path) = &args.save {
        let doc = report::solution_vtu(&result.mesh, &result.solution, &result.estimate.element);
        signorini::records::write_atomic(path, doc.as_bytes()).with_context(|| format!("writing {}", path.display()))?;
        wrote(path, format_args!("# wrote {} (level {level}, NDF {})", path.display(), result.mesh.p2_ndof()));
    }
    if study::interrupted() {
        bail!(AdaptInterrupted { level, saved: args.save.clone() });
    }
    if result.termination.is_error() {
        bail!("{}", result.termination.note(&config).unwrap_or_default());
    }
    Ok(())
}

/// `adapt` stopped by an interrupt after level `level` (exit status 130): the rows above are
/// the levels kept.
#[derive(Debug)]
struct AdaptInterrupted {
    level: usize,
    saved: Option<std::path::PathBuf>,
}

impl std::fmt::Display for AdaptInterrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "adapt: interrupted after level {}; the table above holds levels 0 to {}", self.level, self.level)?;
        match &self.saved {
            Some(p) => write!(f, ", and {} the last of them", p.display()),
            None => Ok(()),
        }
    }
}

impl std::error::Error for AdaptInterrupted {}

/// Refuse an output path whose folder does not exist, or that is not a file a write may replace
/// (a named pipe, a device such as /dev/null: the write renames a new file over it), before
/// hours of work are spent, not after.
fn check_writable(flag: &str, path: &std::path::Path) -> Result<()> {
    let dir = signorini::base::input::folder_of(path);
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
/// flag; the same check every atomic write makes ([`signorini::base::input::check_target`]), made
/// here before any computation.
fn check_target(flag: &str, path: &std::path::Path) -> Result<()> {
    outside_study(flag, path)?;
    signorini::base::input::check_target(path).map_err(|e| anyhow::anyhow!("{flag} {}: {e}", path.display()))
}

/// Refuse an output path inside a results study folder (`STUDY/` holding `runs/`, `.lock` or
/// `.locks`, at any depth: [`study::store::study_folder_above`]): only `run` writes there, under
/// the study's lock, and a report, snapshot or page written past it replaced run records and
/// snapshots (the run lost, or the folder refused). Every output flag comes through here
/// ([`check_target`] for a file, [`output_folder`] for a folder), before any computation; the
/// outputs' defaults (`figures/`, `RESULTS/figures`, `RESULTS/report`, `DIR/drift-report.json`)
/// are beside the study folders, not in them.
fn outside_study(flag: &str, path: &std::path::Path) -> Result<()> {
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
fn results_place(flag: &str, results: Option<&std::path::Path>) -> Result<()> {
    match results.and_then(study::store::results_place_fault) {
        Some(why) => bail!("{flag} {why}; nothing was read or written"),
        None => Ok(()),
    }
}

/// The switches of `signorini run` that shape what a run does with the store.
struct RunFlags {
    quick: bool,
    fresh: bool,
    replace: bool,
    wait: bool,
    /// Check and print the runs, run nothing.
    plan: bool,
}

fn run_studies(manifests: &[std::path::PathBuf], shard: Option<&str>, results: Option<std::path::PathBuf>, flags: RunFlags) -> Result<()> {
    let RunFlags { quick, fresh, replace, wait, plan } = flags;
    let shard = shard.map(study::parse_shard).transpose()?;
    let results = results.unwrap_or_else(|| if quick { "target/quick-results".into() } else { "results".into() });
    // parse and check every run of every manifest first: a mistake in the last one should not
    // cost the first one's run
    let parsed = manifests.iter().map(|m| study::manifest::Manifest::load(m)).collect::<Result<Vec<_>, _>>()?;
    for manifest in &parsed {
        manifest.check_runs()?;
    }
    check_one_declaration(&parsed, quick)?;
    // a run CLAIMS.md or a figure needs that no manifest declares would be found missing only
    // by `figures`, after the study was computed
    signorini::analysis::roles::check(&parsed)?;
    if quick && !replace && !fresh {
        for manifest in &parsed {
            check_quick_beside_full(manifest, &results)?;
        }
    }
    if let Some(shard) = shard {
        check_shard(&parsed, shard)?;
    }
    let options = study::RunOptions { quick, shard, fresh, replace, results: results.clone(), progress: true, wait_for_lock: wait };
    if plan {
        // a study given twice (`run M.toml M.toml`) declares the same runs (checked above) and
        // stores each run once: each listed once
        let mut listed = std::collections::BTreeSet::new();
        for m in &parsed {
            let plan = study::plan(m, &options)?;
            if !plan.leftovers.is_empty() && listed.insert((m.study.clone(), String::new())) {
                let files: Vec<String> = plan.leftovers.iter().map(|f| f.display().to_string()).collect();
                println!("{} (first removes {} leftover file(s) of an unfinished run: {})", m.study, files.len(), files.join(", "));
            }
            if !plan.removals.is_empty() && listed.insert((m.study.clone(), "--fresh".into())) {
                let files: Vec<String> = plan.removals.iter().map(|f| f.display().to_string()).collect();
                println!("{} (--fresh first removes {} file(s): {})", m.study, files.len(), files.join(", "));
            }
            for (id, doing) in plan.runs {
                if listed.insert((m.study.clone(), id.clone())) {
                    match doing {
                        study::Planned::Compute => println!("{}/{id}", m.study),
                        study::Planned::Keep => println!("{}/{id} (kept: stored with this spec, nothing computed)", m.study),
                        study::Planned::Replace(why) => println!("{}/{id} (replaces the stored run: {})", m.study, why.join("; ")),
                        study::Planned::Remove(why) => println!("{}/{id} (removes the stored run and its snapshots: {why})", m.study),
                    }
                }
            }
        }
        return Ok(());
    }
    for manifest in &parsed {
        let executed = study::run_study(manifest, &options)?;
        say!("{}: {} run(s) executed, results in {}", manifest.study, executed.len(), results.join(&manifest.study).display());
    }
    Ok(())
}

/// Manifests given together that declare the same study declare the same runs: otherwise the
/// second would be refused (or with --replace would replace the first's runs) only after the
/// first had computed, so the conflict is refused before anything is, naming both files.
fn check_one_declaration(manifests: &[study::manifest::Manifest], quick: bool) -> Result<()> {
    let runs = |m: &study::manifest::Manifest| {
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
fn check_quick_beside_full(manifest: &study::manifest::Manifest, results: &std::path::Path) -> Result<()> {
    let store = study::store::Store::new(results, &manifest.study);
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

/// How many times the cores available to this process `RAYON_NUM_THREADS` may ask for: more
/// only adds overhead (the results do not depend on the thread count), and thousands of threads
/// make a tiny solve take minutes (battery 12, F6: 20000 threads ran a 162-unknown solve past
/// 100 s, where 2 threads take 3 ms).
const MAX_THREADS_PER_CORE: usize = 8;

/// Build rayon's global pool once, at startup, before anything uses it: `--jobs J` of `run`
/// ([`threads`]), else `RAYON_NUM_THREADS` as rayon reads it (a positive integer; anything else
/// means one thread per core, and a note on standard error says so: [`rayon_threads`]), refused
/// above [`MAX_THREADS_PER_CORE`] times the cores. Built
/// lazily, a pool that cannot start its threads (an address-space limit, a process limit) made
/// the first parallel call panic (battery 12, F6: `RAYON_NUM_THREADS=2000` under `prlimit
/// --as=4e9`, exit 101); here the failure is an error naming where the thread count came from.
fn start_threads(jobs: Option<usize>) -> Result<()> {
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let env = rayon_threads(jobs.is_none(), cores);
    let (builder, from) = match (jobs, env) {
        (Some(j), _) => {
            let n = threads(j)?;
            (rayon::ThreadPoolBuilder::new().num_threads(n), format!("--jobs {j} ({n} threads)"))
        }
        (None, Some(n)) if n > MAX_THREADS_PER_CORE * cores => bail!(
            "RAYON_NUM_THREADS={n} is more than {MAX_THREADS_PER_CORE} times the {cores} core(s) available to this process: the results do not depend on the thread count, and thousands of threads on a few cores only add overhead (a tiny solve can take minutes). Nothing was computed; set it to at most {} or unset it (one thread per core)",
            MAX_THREADS_PER_CORE * cores
        ),
        (None, Some(n)) => (rayon::ThreadPoolBuilder::new().num_threads(n), format!("RAYON_NUM_THREADS={n}")),
        (None, None) => (rayon::ThreadPoolBuilder::new(), format!("one thread per core ({cores})")),
    };
    builder.build_global().map_err(|e| {
        anyhow::anyhow!(
            "starting the solver's threads ({from}) failed: {e}. An address-space limit (ulimit -v) or a limit on processes (ulimit -u) can stop threads from starting; nothing was computed. Ask for fewer threads (RAYON_NUM_THREADS, at least 1) or raise the limit"
        )
    })
}

/// `RAYON_NUM_THREADS` if it is a positive integer. Any other value set means one thread per
/// core, as rayon reads it; where it decides (`noted`: no `--jobs`), a one-line note says what
/// was given and what is used instead of ignoring it without a word.
fn rayon_threads(noted: bool, cores: usize) -> Option<usize> {
    let given = std::env::var_os("RAYON_NUM_THREADS")?;
    let n = given.to_str().and_then(|v| v.trim().parse::<usize>().ok()).filter(|&n| n > 0);
    if n.is_none() && noted {
        say!(
            "note: RAYON_NUM_THREADS={:?} is not a positive integer; using one thread per core ({cores}), as when it is unset",
            given.to_string_lossy()
        );
    }
    n
}

/// The thread count for `--jobs J`: at least 1; more than the cores available to this process
/// is reduced to them with a note (results do not depend on it, and a pool of thousands of
/// threads on a few cores only adds overhead; refusing would break a script that passes the
/// machine's nominal core count where a container allows fewer).
fn threads(jobs: usize) -> Result<usize> {
    if jobs == 0 {
        bail!("--jobs must be at least 1");
    }
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    if jobs > cores {
        say!(
            "note: --jobs {jobs} is more than the {cores} core(s) available to this process; using {cores} (the results do not depend on the thread count; more threads than cores only add overhead)"
        );
    }
    Ok(jobs.min(cores))
}

/// A shard must hold at least one run of the manifests given (each manifest's runs are dealt
/// out to the shards in order); a manifest of which it holds none gets a note.
fn check_shard(manifests: &[study::manifest::Manifest], (k, n): (usize, usize)) -> Result<()> {
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
        say!("note: --shard {k}/{n} holds no run of {s} ({r} run(s)); other shards run them");
    }
    Ok(())
}

/// Whether `dir` is the tracked results folder `results/` of the current directory, the one
/// `CLAIMS.md` names as `results/` and where every declared study must be complete.
fn is_tracked_results(dir: &std::path::Path) -> bool {
    let tracked = std::path::Path::new("results");
    dir == tracked || matches!((dir.canonicalize(), tracked.canonicalize()), (Ok(a), Ok(b)) if a == b)
}

/// `drift --accept`: rerun the studies in full (every run checked first) and rewrite their results.
fn accept_studies(accept: &[String], experiments: &std::path::Path, results: &std::path::Path) -> Result<()> {
    let manifests = study::manifest::declared(experiments, accept)?;
    for m in &manifests {
        m.check_runs()?;
    }
    for m in &manifests {
        study::accept::accept(m, results, true).map_err(|e| accept_advice(e, &m.study))?;
        say!(
            "accepted: {} rewritten from a full rerun of {}; run `signorini figures`, review and commit the change",
            results.join(&m.study).display(),
            m.file.display()
        );
    }
    Ok(())
}

/// `drift --accept STUDY` refused by a lock another process holds: the advice in drift's terms
/// (the lock's own speaks of `--wait`, which drift has not; the run's of `--fresh`).
fn accept_advice(e: anyhow::Error, study: &str) -> anyhow::Error {
    match e.chain().find_map(|c| c.downcast_ref::<study::store::Held>()) {
        Some(held) => anyhow::anyhow!(
            "drift --accept {study}: {} is being written by {} (the lock is {}); --accept reruns the whole study and waits for no process: nothing was changed. Let that process finish (or stop it), then run `signorini drift --accept {study}` again",
            held.what,
            held.holder,
            held.lock.display()
        ),
        None => e,
    }
}

/// `drift` stopped by an interrupt while rerunning the studies into its scratch folder (exit
/// status 130): nothing was compared and no report written; the advice is drift again (the
/// scratch folder's runs are started over by it), not a `run` into the scratch folder.
#[derive(Debug)]
struct DriftInterrupted {
    study: String,
    scratch: std::path::PathBuf,
}

impl std::fmt::Display for DriftInterrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "drift: interrupted while rerunning {} into its scratch folder {}; nothing was compared and no report written, and the stored results are unchanged. Run the same `signorini drift` again to check",
            self.study,
            self.scratch.display()
        )
    }
}

impl std::error::Error for DriftInterrupted {}

/// Where the drift report goes by default: `target/drift/report[_quick][-STUDY...].json`, or
/// `DIR/drift-report.json` for a comparison against DIR (not the report `make test` leaves).
fn default_report(quick: bool, against: Option<&std::path::Path>, only: &[String]) -> std::path::PathBuf {
    match against {
        Some(dir) => dir.join("drift-report.json"),
        None => std::path::Path::new("target/drift").join(format!(
            "report{}{}.json",
            if quick { "_quick" } else { "" },
            only.iter().map(|s| format!("-{s}")).collect::<String>()
        )),
    }
}

/// The reports `drift` wrote under `target/drift/` by default ([`default_report`] without
/// --against: `report[_quick][-STUDY...].json`), sorted by name: what `report` reads besides its
/// default, so that the command a page advises makes it "checked".
fn written_drift_reports() -> Vec<std::path::PathBuf> {
    let Ok(dir) = std::fs::read_dir("target/drift") else { return Vec::new() };
    let mut files: Vec<std::path::PathBuf> = dir
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with("report") && n.ends_with(".json")))
        .collect();
    files.sort();
    files
}

/// The verdict line of a drift run: none, or what moved and what to do about it.
fn drift_outcome(report: &study::drift::DriftReport, against: Option<&std::path::Path>, results: &std::path::Path) -> Result<()> {
    let n = report.studies.len();
    let studies = format!("{n} {}", if n == 1 { "study" } else { "studies" });
    let not_compared = if report.not_compared.is_empty() {
        String::new()
    } else {
        format!(
            "; not compared (not in {}): {}",
            against.map(|d| d.display().to_string()).unwrap_or_default(),
            report.not_compared.join(", ")
        )
    };
    match (report.rows.len(), against) {
        (0, None) => {
            let tiered: Vec<&str> = report
                .studies
                .iter()
                .filter(|e| e["quick"].as_bool() == Some(true) && !report.quick)
                .filter_map(|e| e["study"].as_str())
                .collect();
            let tiers = if tiered.is_empty() {
                String::new()
            } else {
                format!(
                    "; {} in its tiers: quick prefixes, its `full` runs at every level, the last level of its `replay` runs (all: drift --deep)",
                    tiered.join(", ")
                )
            };
            println!("drift: none ({studies} checked at every level{}{tiers})", if report.quick { " of the quick forms" } else { "" });
            Ok(())
        }
        (0, Some(dir)) => {
            println!("drift: none ({studies} of {} compared with {} at every level{not_compared})", dir.display(), results.display());
            if report.self_comparison {
                println!(
                    "note: {} is the stored results folder itself: each record was compared with itself and nothing was rerun; this checks that the folder reads back, not its numbers (a study page does not quote it as a drift check)",
                    dir.display()
                );
            } else if !report.copies.is_empty() {
                say!(
                    "note: the records of {} in {} are byte-identical to the stored ones, timings (t_*) included: no rerun reproduces timings, so {} is a copy of the stored folder, not a rerun; this checks that the copy reads back, not its numbers (a study page does not quote it as a drift check). To check the numbers, rerun into it: `signorini run experiments/STUDY.toml --fresh --results {}`",
                    report.copies.join(", "),
                    dir.display(),
                    dir.display(),
                    dir.display()
                );
            }
            Ok(())
        }
        (rows, None) => bail!(
            "drift: {rows} field(s) moved; if the change is deliberate, run `signorini drift --accept STUDY`, then `signorini figures`, and commit results/ and figures/"
        ),
        (rows, Some(dir)) => bail!(
            "drift: {rows} field(s) of {dir} differ from the stored results in {} ({studies} compared{not_compared}); the stored results are unchanged. \
             If {dir} was rerun with other settings on purpose, the rows above are what they changed; to recompute {dir}, rerun the study into it with `signorini run experiments/STUDY.toml --fresh --results {dir}`",
            results.display(),
            dir = dir.display()
        ),
    }
}

/// Where `drift --report` writes, and whether it merges into what is there (`--merge`).
#[derive(Clone, Copy)]
struct ReportFile<'a> {
    path: &'a std::path::Path,
    merge: bool,
}

/// The report already at `file` that `--merge` merges into: None without `--merge` or where
/// there is none yet; read before anything is rerun, so that a file that is not a drift report
/// is an error naming it at once (and is never overwritten).
fn report_to_merge_into(file: Option<ReportFile>) -> Result<Option<serde_json::Value>> {
    let Some(ReportFile { path, merge: true }) = file else { return Ok(None) };
    if !path.exists() {
        return Ok(None);
    }
    let text = signorini::records::read_text(path).with_context(|| format!("reading the drift report {} to merge into", path.display()))?;
    let not_one = || {
        format!(
            "{}: not a drift report (expected the JSON `signorini drift --report` writes); nothing was rerun or written",
            path.display()
        )
    };
    // checked as a report, merged as JSON: the other studies' entries are kept as written
    serde_json::from_str::<study::drift::DriftReport>(&text).with_context(not_one)?;
    Ok(Some(serde_json::from_str(&text).with_context(not_one)?))
}

#[allow(clippy::too_many_arguments)]
fn run_drift(
    quick: bool,
    deep: bool,
    against: Option<&std::path::Path>,
    report_file: Option<ReportFile>,
    accept: &[String],
    only: &[String],
    experiments: &std::path::Path,
    results: &std::path::Path,
) -> Result<()> {
    if !accept.is_empty() {
        return accept_studies(accept, experiments, results);
    }
    let results = if is_tracked_results(results) { std::path::Path::new("results") } else { results };
    let manifests = study::manifest::declared(experiments, only)?;
    // what the CLAIMS rows need, checked before any run is rerun
    let roles = signorini::analysis::roles::read(experiments)?;
    // the default too: `--against DIR` writes DIR/drift-report.json
    let file = report_file.map(|r| r.path.to_path_buf()).unwrap_or_else(|| default_report(quick, against, only));
    let flag = if report_file.is_some() { "--report" } else { "the drift report (--report FILE writes it elsewhere)" };
    check_target(flag, &file)?;
    let older = report_to_merge_into(report_file)?;
    let scratch = std::path::PathBuf::from("target/drift").join(if quick { "quick" } else { "full" });
    let options = study::drift::DriftOptions {
        quick,
        deep,
        against: against.map(|p| p.to_path_buf()),
        scratch,
        results: results.to_path_buf(),
        progress: true,
    };
    let scratch = options.scratch.clone();
    let report = study::drift::check(&manifests, only.is_empty(), &options, &|r| {
        // drift's interface takes an io::Result: the typed error's message travels in it
        // CLAIMS.md is compared only when every study is, so a folder at fault has each fault in
        // a row of the report already; rows drawn from records no one can trust are not compared
        let Ok(shelf) = study::store::Shelf::open_folder(r, &manifests) else {
            return Ok(signorini::records::read_text(&r.join("CLAIMS.md")).unwrap_or_default());
        };
        signorini::claims::claims(&shelf, &roles).map(|c| signorini::claims::markdown_for(&c, r)).map_err(std::io::Error::other)
    })
    .map_err(|e| match e.downcast_ref::<study::Interrupted>() {
        Some(i) => DriftInterrupted { study: i.study.clone(), scratch: scratch.clone() }.into(),
        None => e,
    })?;
    // the table first: a report that cannot be written must not cost it
    if !report.rows.is_empty() {
        print!("{}", study::drift::table(&report.rows));
    }
    println!("\nlargest change of each float field (whether within tolerance or not):\n{}", study::drift::changes_table(&report));
    let written = match older {
        Some(older) => report.merged_into(older).with_context(|| format!("merging into the drift report {}", file.display()))?,
        None => serde_json::to_value(&report)?,
    };
    signorini::records::write_json(&file, &written).with_context(|| {
        format!("writing the drift report {} (--report FILE writes it elsewhere; the comparison above stands)", file.display())
    })?;
    wrote(&file, format_args!("report: {}", file.display()));
    drift_outcome(&report, against, results)
}

/// The declared studies `figures` checks complete in `results` and those whose figures it draws
/// (`None`: every figure): in the tracked `results/`, every declared study is checked; in
/// another folder, those it holds. `--study` names the drawn ones, each of which the folder must hold.
fn figure_studies(
    results: &std::path::Path,
    tracked: bool,
    experiments: &std::path::Path,
    only: &[String],
) -> Result<(Vec<study::manifest::Manifest>, Option<Vec<String>>)> {
    let all = study::manifest::declared(experiments, &[])?;
    let named = if only.is_empty() {
        None
    } else {
        Some(study::manifest::declared(experiments, only)?.into_iter().map(|m| m.study).collect::<Vec<_>>())
    };
    if tracked {
        return Ok((all, named));
    }
    let held = study::drift::held_by(results, &all).with_context(|| format!("--results {}", results.display()))?;
    let present: Vec<String> = held.present.iter().map(|m| m.study.clone()).collect();
    let (dir, holds) = (results.display(), if present.is_empty() { "no declared study".to_string() } else { present.join(", ") });
    if let Some(s) = named.iter().flatten().find(|s| !present.contains(s)) {
        bail!(
            "--study {s}: {dir} does not hold it (it holds: {holds}); rerun it there with `signorini run experiments/{s}.toml --results {dir}`"
        );
    }
    if present.is_empty() {
        let declared: Vec<&str> = all.iter().map(|m| m.study.as_str()).collect();
        bail!(
            "nothing to draw: {dir} holds none of the declared studies ({}); rerun one there with `signorini run experiments/STUDY.toml --results {dir}`",
            declared.join(", ")
        );
    }
    if !held.absent.is_empty() {
        say!("figures: {dir} does not hold {}: their figures and claims are not drawn", held.absent.join(", "));
    }
    Ok((held.present, Some(named.unwrap_or(present))))
}

fn run_figures(
    results: Option<&std::path::Path>,
    figures: Option<&std::path::Path>,
    experiments: &std::path::Path,
    only: &[String],
    wait: bool,
) -> Result<()> {
    let tracked = results.is_none_or(is_tracked_results);
    let results = match results {
        Some(r) if !tracked => r.to_path_buf(),
        _ => std::path::PathBuf::from("results"),
    };
    if wait {
        study::store::Shelf::wait_for_writers(&results)?;
    }
    let flag = if figures.is_some() { "--figures" } else { "the default output folder (--figures)" };
    let figures = figures.map(|f| f.to_path_buf()).unwrap_or_else(|| if tracked { "figures".into() } else { results.join("figures") });
    output_folder(flag, &figures, "figures writes its PNG and SVG files into a folder there")?;
    // what the figures and CLAIMS rows need, checked when the manifests are read
    let roles = signorini::analysis::roles::read(experiments)?;
    let (checked, drawn) = figure_studies(&results, tracked, experiments, only)?;
    for m in &checked {
        study::check_complete(m, &results)?;
    }
    // what the figures and CLAIMS rows read: every study, through the integrity check
    let shelf = study::store::Shelf::open_folder(&results, &study::manifest::declared(experiments, &[])?)?;
    for f in signorini::plot::draw_studies(&shelf, &figures, &roles, drawn.as_deref())? {
        wrote(&f, format_args!("wrote {}", f.display()));
    }
    signorini::claims::write(&shelf, &roles).with_context(|| format!("writing {}", results.join("CLAIMS.md").display()))?;
    let claims = results.join("CLAIMS.md");
    wrote(&claims, format_args!("wrote {}", claims.display()));
    Ok(())
}

/// A reader given `--wait` (`figures`, `report`): `read` again while it is refused because a
/// process started writing the folder after its wait (each attempt waits for the writers first).
/// A second Slurm array's task may start at any moment: `make cluster-test` failed when one did
/// between the finish job's wait and its read.
fn again_while_written(wait: bool, mut read: impl FnMut() -> Result<()>) -> Result<()> {
    loop {
        match read() {
            Err(e) if wait && e.chain().any(|c| c.downcast_ref::<study::store::BeingWritten>().is_some()) => {
                say!("{e:#}; waiting for it (--wait)");
            }
            done => return done,
        }
    }
}

/// `report`: the study pages, with the defaults of a scratch folder when --results names one.
fn run_report(
    results: Option<&std::path::Path>,
    figures: Option<&std::path::Path>,
    out: Option<&std::path::Path>,
    studies: &[String],
    drift_report: Option<&std::path::Path>,
    experiments: &std::path::Path,
    wait: bool,
) -> Result<()> {
    let roles = signorini::analysis::roles::read(experiments)?;
    let tracked = results.is_none_or(is_tracked_results);
    let results = results.map_or_else(|| std::path::PathBuf::from("results"), |r| r.to_path_buf());
    if results.exists() && !results.is_dir() {
        bail!("--results {}: this is a file; report reads the study folders of a results folder: give a folder's path", results.display());
    }
    if wait {
        study::store::Shelf::wait_for_writers(&results)?;
    }
    let under = |tracked_default: &str, scratch: &str| if tracked { tracked_default.into() } else { results.join(scratch) };
    let figures = figures.map_or_else(|| under("figures", "figures"), |f| f.to_path_buf());
    let flag = if out.is_some() { "--out" } else { "the default output folder (--out)" };
    let out = out.map_or_else(|| under("target/report", "report"), |o| o.to_path_buf());
    output_folder(flag, &out, "report writes its pages into a folder there")?;
    // --drift-report FILE alone; by default the default report and every one drift writes under
    // target/drift/, each page quoting the newest that covers its study
    let files = match drift_report {
        Some(d) => vec![d.to_path_buf()],
        None => {
            let default = under("target/drift/report.json", "drift-report.json");
            let others = written_drift_reports().into_iter().filter(|f| *f != default);
            std::iter::once(default.clone()).chain(others).collect()
        }
    };
    // the command after which the page says "checked": drift of the folder the page shows
    let mut advice = "signorini drift --study STUDY".to_string();
    if !tracked {
        advice += &format!(" --results {}", results.display());
    }
    if experiments != std::path::Path::new("experiments") {
        advice += &format!(" --experiments {}", experiments.display());
    }
    let drift = signorini::page::DriftReports::read(&files, drift_report.is_some(), &advice)?;
    let shelf = study::store::Shelf::open_folder(&results, &study::manifest::declared(experiments, &[])?)?;
    for page in signorini::page::write_pages(&shelf, &figures, &out, studies, &drift, &roles)? {
        wrote(&page, format_args!("wrote {}", page.display()));
    }
    Ok(())
}

/// A folder a command writes into (`export --out`, `figures --figures`, `report --out`): a file
/// there is an error naming the flag, now, not the operating system's "File exists" later.
fn output_folder(flag: &str, path: &std::path::Path, writes: &str) -> Result<()> {
    outside_study(flag, path)?;
    if path.exists() && !path.is_dir() {
        bail!("{flag} {}: this is a file; {writes}: give a folder's path", path.display());
    }
    Ok(())
}

/// `export`: solve, write the case files, say where.
fn run_export(args: &SolveArgs, out: &std::path::Path) -> Result<()> {
    // before solving
    output_folder("--out", out, "export writes a folder there (mesh.vtu, case.json)")?;
    for file in ["mesh.vtu", "case.json"] {
        check_target("--out", &out.join(file))?;
    }
    let (mesh, sol, indicator, r) = run_solve(args)?;
    // eta_{1,p} .. eta_{5,p} per node, computed again for the file (the solve keeps only eta_T)
    let nodal = estimate::node_terms(&mesh, problems::by_name(&args.problem)?.as_ref(), &sol, &r.estimator_config);
    for f in report::export_case(out, &mesh, &sol, &indicator, &nodal, &r)? {
        wrote(&f, format_args!("wrote {}", f.display()));
    }
    Ok(())
}

/// SIGINT: the first stops a study (or `adapt`) after its current level (keeping every
/// finished run, or the levels printed), a second one stops at once.
fn install_interrupt_handler() {
    let result = ctrlc::set_handler(|| {
        if study::interrupted() {
            say!("\ninterrupted again: stopping now (finished runs are on disk)");
            std::process::exit(130);
        }
        say!("\ninterrupt: finishing the current level, then stopping (Ctrl-C again stops at once)");
        study::interrupt();
    });
    if let Err(e) = result {
        say!("warning: cannot install the interrupt handler: {e}");
    }
}

/// The command line, or the exit status of what parsing printed instead: help and version go
/// through [`stdout_write`], so that a standard output that fails is an error there too (clap's
/// own printing ignores the failure: `--help > /dev/full` exited 0, battery 18, F3); a usage
/// error goes to standard error with clap's status.
fn parse() -> std::result::Result<Cli, ExitCode> {
    let e = match Cli::try_parse() {
        Ok(cli) => return Ok(cli),
        Err(e) => e,
    };
    if e.use_stderr() {
        let _ = e.print();
        return Err(ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2)));
    }
    print!("{}", e.render());
    match stdout_result() {
        Ok(()) => Err(ExitCode::SUCCESS),
        Err(msg) => {
            say!("error: writing standard output: {msg}");
            Err(ExitCode::FAILURE)
        }
    }
}

fn main() -> ExitCode {
    // A file-size limit (`ulimit -f`, a quota) makes a write fail with EFBIG instead of killing
    // the process, so the store can clean up and say which file it was writing.
    // SAFETY: setting a signal's disposition, before any thread is started.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    let cli = match parse() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    if !cli.command.writes_files() {
        // A closed stdout (`signorini solve ... | head -5`) ends a command that only prints
        // quietly, as command-line tools do (Rust ignores SIGPIPE, and the write would fail).
        // A command that writes files goes on: the broken pipe is a failed standard output like
        // `> /dev/full`, the files are written and the error names them (`adapt --save x.vtu |
        // head` lost the VTU).
        // SAFETY: setting a signal's disposition to the default, before any thread is started.
        unsafe {
            libc::signal(libc::SIGPIPE, libc::SIG_DFL);
        }
    }
    if let Err(e) = signorini::ordering::forced() {
        say!("error: {e}");
        return ExitCode::from(2);
    }
    if matches!(cli.command, Command::Run { .. } | Command::Drift { .. } | Command::Adapt(_)) {
        install_interrupt_handler();
    }
    let jobs = match &cli.command {
        Command::Run { jobs, .. } => *jobs,
        _ => None,
    };
    let result = start_threads(jobs).and_then(|()| match &cli.command {
        Command::Solve { args, json } => run_solve(args).map(|(_, _, _, r)| {
            if *json {
                println!("{}", serde_json::to_string_pretty(&r).expect("a report serialises"));
            } else {
                print!("{}", r.summary());
            }
        }),
        Command::Adapt(args) => run_adapt(args),
        Command::Figures { results, figures, experiments, study, wait } => results_place("--results", results.as_deref())
            .and_then(|()| again_while_written(*wait, || run_figures(results.as_deref(), figures.as_deref(), experiments, study, *wait))),
        Command::Drift { quick, deep, against, report, merge, accept, study, experiments, results } => {
            let report = report.as_deref().map(|f| ReportFile { path: f, merge: *merge });
            results_place("--results", Some(results))?;
            results_place("--against", against.as_deref())?;
            run_drift(*quick, *deep, against.as_deref(), report, accept, study, experiments, results)
        }
        Command::Run { manifests, quick, jobs: _, shard, fresh, replace, results, wait, plan } => {
            let flags = RunFlags { quick: *quick, fresh: *fresh, replace: *replace, wait: *wait, plan: *plan };
            results_place("--results", results.as_deref())?;
            run_studies(manifests, shard.as_deref(), results.clone(), flags)
        }
        Command::Export { args, out } => run_export(args, out),
        Command::Report { results, figures, out, study, drift_report, experiments, wait } => {
            results_place("--results", results.as_deref())?;
            again_while_written(*wait, || {
                run_report(results.as_deref(), figures.as_deref(), out.as_deref(), study, drift_report.as_deref(), experiments, *wait)
            })
        }
    });
    // what was computed and kept stays; output that could not be written is an error
    let result = result.and_then(|()| stdout_result().map_err(|e| stdout_error(&e)));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e)
            if e.downcast_ref::<study::Interrupted>().is_some()
                || e.downcast_ref::<AdaptInterrupted>().is_some()
                || e.downcast_ref::<DriftInterrupted>().is_some()
                || e.downcast_ref::<study::accept::AcceptInterrupted>().is_some() =>
        {
            say!("{e:#}");
            ExitCode::from(130)
        }
        Err(e) => {
            say!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
