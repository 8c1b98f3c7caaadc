//! The `signorini` command line: the flags parsed ([`cli`]), the command run by the library
//! ([`signorini::commands`]), what it returns printed. Nothing else lives here.

mod cli;

use anyhow::Result;
use cli::{Cli, Command, flag_of};
use signorini::adapt::Caveat;
use signorini::commands::adapt::{self, AdaptInterrupted, AdaptObserver};
use signorini::commands::drift::{self, Drift, DriftInterrupted, DriftRequest};
use signorini::commands::output::{self, stdout_write, wrote, wrote_all};
use signorini::commands::places::{again_while_written, results_place};
use signorini::commands::run::{self, RunFlags};
use signorini::commands::threads::start_threads;
use signorini::commands::workspace::Workspace;
use signorini::commands::{figures, report, solve};
use signorini::level::record::LevelRecord;
use signorini::study;
use signorini_claims::say;
use std::path::Path;
use std::process::ExitCode;

macro_rules! println {
    () => { stdout_write(format_args!(""), true) };
    ($($arg:tt)*) => { stdout_write(format_args!($($arg)*), true) };
}

macro_rules! print {
    ($($arg:tt)*) => { stdout_write(format_args!($($arg)*), false) };
}

/// The `adapt` table: a header, one row per level, notes and the saved file.
struct AdaptTable;

impl AdaptObserver for AdaptTable {
    fn start(&mut self, problem: &str, exact: bool) {
        if !exact {
            println!(
                "# {problem} has no exact solution: the error and eff columns are empty (the studies measure them against a reference solution, see experiments/)"
            );
        }
        println!(
            "{:>3} {:>8} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>6} {:>4} {:>7}",
            "lvl", "ndof", "h_min", "error", "estimate", "eff", "eta1", "eta2", "eta3", "eta4", "eta5", "eta6+7", "active", "its", "time"
        );
    }

    fn level(&mut self, r: &LevelRecord, caveats: &[Caveat]) {
        let or_dash = |v: Option<f64>, scientific: bool| {
            v.map_or("-".to_string(), |v| if scientific { format!("{v:.3e}") } else { format!("{v:.3}") })
        };
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
        for c in caveats {
            say!("warning: level {}: {c}", r.level);
        }
    }

    fn stopped(&mut self, note: &str) {
        println!("# {note}");
    }

    fn saved(&mut self, path: &Path, level: usize, ndof: usize) {
        wrote(path, format_args!("# wrote {} (level {level}, NDF {ndof})", path.display()));
    }
}

/// Run the command parsed.
fn dispatch(command: &Command) -> Result<()> {
    match command {
        Command::Solve { args, json } => solve::solve(&args.options(), &|k| flag_of("solve", k)).map(|(_, _, _, r)| {
            if *json {
                println!("{}", serde_json::to_string_pretty(&r).expect("a report serialises"));
            } else {
                print!("{}", r.summary());
            }
        }),
        Command::Adapt(args) => adapt::run(&args.options(), &|k| flag_of("adapt", k), &mut AdaptTable),
        Command::Export { args, out } => solve::export(&args.options(), out, &|k| flag_of("export", k)).map(|f| wrote_all(&f)),
        Command::Run { manifests, quick, jobs: _, shard, fresh, replace, results, wait, plan } => {
            let flags = RunFlags { quick: *quick, fresh: *fresh, replace: *replace, wait: *wait, plan: *plan };
            results_place("--results", results.as_deref())?;
            run::run_studies(manifests, shard.as_deref(), results.clone(), flags).map(|plan| plan.iter().for_each(|l| println!("{l}")))
        }
        Command::Drift { quick, deep, against, report, merge, accept, study, experiments, results } => {
            results_place("--results", Some(results))?;
            results_place("--against", against.as_deref())?;
            let request = DriftRequest {
                quick: *quick,
                deep: *deep,
                against: against.clone(),
                report: report.clone(),
                merge: *merge,
                accept: accept.clone(),
                only: study.clone(),
                experiments: experiments.clone(),
                results: results.clone(),
            };
            let Drift::Checked(checked) = drift::check(&request)? else { return Ok(()) };
            // the table first: a report that cannot be written must not cost it
            print!("{}", checked.tables());
            let file = checked.write_report()?;
            wrote(file, format_args!("report: {}", file.display()));
            checked.outcome().map(|lines| lines.iter().for_each(|l| println!("{l}")))
        }
        Command::Figures(args) => figures::run(args).map(|f| wrote_all(&f)),
        Command::Report { results, figures, out, study, drift_report, experiments, wait } => {
            results_place("--results", results.as_deref())?;
            let workspace = Workspace::load(experiments)?;
            again_while_written(*wait, || {
                report::write(results.as_deref(), figures.as_deref(), out.as_deref(), study, drift_report.as_deref(), &workspace, *wait)
                    .map(|f| wrote_all(&f))
            })
        }
    }
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

fn main() -> ExitCode {
    output::ignore_file_size_signal();
    let cli: Cli = match output::parse() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    if !cli.command.writes_files() {
        // A closed stdout (`signorini solve ... | head -5`) ends a command that only prints
        // quietly, as command-line tools do (Rust ignores SIGPIPE, and the write would fail).
        // A command that writes files goes on: the broken pipe is a failed standard output like
        // `> /dev/full`, the files are written and the error names them (`adapt --save x.vtu |
        // head` keeps the VTU).
        // SAFETY: setting a signal's disposition to the default, before any thread is started.
        unsafe {
            libc::signal(libc::SIGPIPE, libc::SIG_DFL);
        }
    }
    if let Err(e) = signorini::settings::ordering::forced() {
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
    let result = start_threads(jobs).and_then(|()| dispatch(&cli.command));
    output::exit_status(result, |e| {
        e.downcast_ref::<study::Interrupted>().is_some()
            || e.downcast_ref::<AdaptInterrupted>().is_some()
            || e.downcast_ref::<DriftInterrupted>().is_some()
            || e.downcast_ref::<study::accept::AcceptInterrupted>().is_some()
    })
}
