//! The command line's flags (clap), each subcommand's options turned into the library's
//! ([`signorini::commands`]): the defaults are the library's, the estimator's values its enums.

use clap::{Parser, Subcommand};
use signorini::commands::{adapt::AdaptOptions, solve::SolveOptions};
use signorini::mesh::MeshSpec;
use signorini::settings::adapt::AdaptConfig;
use signorini::settings::estimator::{ContactTerm, EstimatorConfig, LogFactor};
use signorini::settings::pdas::PdasOptions;
use signorini::settings::sampling::Sampling;

#[derive(Parser)]
#[command(name = "signorini", version, about = "P2 finite elements for the Signorini problem and its supremum-norm a posteriori estimator")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
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
    Figures(signorini::commands::figures::FiguresArgs),
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
    pub fn writes_files(&self) -> bool {
        match self {
            Command::Solve { .. } => false,
            Command::Adapt(args) => args.save.is_some(),
            Command::Run { plan, .. } => !plan,
            Command::Drift { .. } | Command::Figures(_) | Command::Export { .. } | Command::Report { .. } => true,
        }
    }
}

/// The estimator's flags. Each argument's id is the setting's key (`estimator.c0`, as
/// [`ConfigError`](signorini::settings::estimator::ConfigError) names it), its default the library's ([`EstimatorConfig::default`]),
/// its values the library's enums ([`clap::ValueEnum`]).
#[derive(clap::Args)]
pub struct EstimatorArgs {
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
    pub fn config(&self) -> EstimatorConfig {
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
pub struct AdaptArgs {
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
pub struct SolveArgs {
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
pub fn flag_of(sub: &str, key: &str) -> String {
    let cmd = <Cli as clap::CommandFactory>::command();
    let arg = cmd.find_subcommand(sub).and_then(|c| c.get_arguments().find(|a| a.get_id() == key));
    arg.and_then(|a| a.get_long()).map_or_else(|| key.to_string(), |long| format!("--{long}"))
}

impl AdaptArgs {
    pub fn options(&self) -> AdaptOptions {
        AdaptOptions {
            problem: self.problem.clone(),
            mesh: self.mesh.clone(),
            levels: self.levels,
            theta: self.theta,
            uniform: self.uniform,
            max_ndof: self.max_ndof,
            stop_ndof: self.stop_ndof,
            save: self.save.clone(),
            estimator: self.estimator.config(),
        }
    }
}

impl SolveArgs {
    pub fn options(&self) -> SolveOptions {
        SolveOptions {
            problem: self.problem.clone(),
            mesh: self.mesh.clone(),
            probes: self.probes.clone(),
            max_pdas_iterations: self.max_pdas_iterations,
            verbose: self.verbose,
            theta: self.theta,
            adapt_levels: self.adapt_levels,
            adapt_min_ndof: self.adapt_min_ndof,
            estimator: self.estimator.config(),
        }
    }
}
