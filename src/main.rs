//! The `signorini` command line: thin, everything lives in the library.

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use signorini::contact::PdasOptions;
use signorini::mesh::MeshSpec;
use signorini::{norms, problems, report, solve};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "signorini", version, about = "P2 finite elements for the Signorini problem and its supremum-norm a posteriori estimator")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// One solve (no adaptivity) on a structured mesh.
    Solve(SolveArgs),
    /// Solve and write the mesh and solution for the NGSolve cross-check (mesh.vtu, case.json).
    Export {
        #[command(flatten)]
        args: SolveArgs,
        /// Output directory.
        #[arg(long)]
        out: std::path::PathBuf,
    },
}

#[derive(clap::Args)]
struct SolveArgs {
    /// Problem name (ex71, ex72, patch).
    #[arg(long)]
    problem: String,
    /// Mesh: structured:N (or symmetric:N, mirrored about y = 0.5).
    #[arg(long)]
    mesh: String,
    /// Evaluate u_h at X,Y (repeatable).
    #[arg(long = "probe", value_name = "X,Y")]
    probes: Vec<String>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Maximum number of active-set iterations.
    #[arg(long, default_value_t = PdasOptions::default().max_iterations)]
    max_pdas_iterations: usize,
    /// Log every active-set iteration on stderr.
    #[arg(long, short)]
    verbose: bool,
}

fn parse_probe(s: &str) -> Result<[f64; 2]> {
    let (x, y) = s.split_once(',').with_context(|| format!("malformed --probe '{s}': expected X,Y"))?;
    let x: f64 = x.trim().parse().with_context(|| format!("malformed --probe '{s}': X is not a number"))?;
    let y: f64 = y.trim().parse().with_context(|| format!("malformed --probe '{s}': Y is not a number"))?;
    Ok([x, y])
}

fn run_solve(args: &SolveArgs) -> Result<(signorini::mesh::Mesh, solve::DiscreteSolution, report::SolveReport)> {
    let problem = problems::by_name(&args.problem)?;
    let spec = MeshSpec::parse(&args.mesh)?;
    let probes = args.probes.iter().map(|p| parse_probe(p)).collect::<Result<Vec<_>>>()?;
    if args.max_pdas_iterations == 0 {
        bail!("--max-pdas-iterations must be at least 1");
    }
    let mesh = spec.build(&|x| problem.part_of(x));
    let options = PdasOptions { max_iterations: args.max_pdas_iterations, ..Default::default() };
    let verbose = args.verbose;
    let mut log = |it: &signorini::contact::PdasIteration| {
        if verbose {
            eprintln!(
                "pdas {:>3}: active {:>6} (+{} -{}), residual {:.3e}",
                it.iteration, it.active, it.added, it.removed, it.residual
            );
        }
    };
    let sol = solve::solve(&mesh, problem.as_ref(), &options, &mut log)
        .with_context(|| format!("solving {} on {}", problem.name(), spec))?;
    let error = problem.exact().map(|e| norms::linf_error(&mesh, &sol, e));
    let report = report::SolveReport::new(problem.name(), &spec.to_string(), &mesh, &sol, error, &probes);
    Ok((mesh, sol, report))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Solve(args) => run_solve(args).map(|(_, _, r)| {
            if args.json {
                println!("{}", serde_json::to_string_pretty(&r).expect("a report serialises"));
            } else {
                print!("{}", r.summary());
            }
        }),
        Command::Export { args, out } => run_solve(args).and_then(|(mesh, sol, r)| report::export_case(out, &mesh, &sol, &r)),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
