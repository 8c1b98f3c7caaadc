//! `adapt`: the adaptive loop SOLVE -> ESTIMATE -> MARK -> REFINE on one problem, each level
//! handed to an observer as it is solved (the command line prints a table row), the last
//! level's mesh and solution optionally saved as VTU.

use super::places::check_writable;
use super::solve::{Names, validate};
use crate::adapt::{self, Caveat};
use crate::level::record::LevelRecord;
use crate::mesh::MeshSpec;
use crate::settings::adapt::{AdaptConfig, Refine};
use crate::settings::estimator::EstimatorConfig;
use crate::{norms, problems, report, study};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// What `adapt` runs: a problem from an initial mesh, the loop's settings, where to save.
#[derive(Clone, Debug)]
pub struct AdaptOptions {
    /// A built-in problem's name or a problem file's path.
    pub problem: String,
    /// The initial mesh: `structured:N`, `symmetric:N` or `gmsh:PATH.msh`.
    pub mesh: String,
    pub levels: usize,
    pub theta: f64,
    /// Refine every element instead of marking.
    pub uniform: bool,
    pub max_ndof: Option<usize>,
    pub stop_ndof: Option<usize>,
    /// Write the last level's mesh and solution to this VTU file.
    pub save: Option<PathBuf>,
    pub estimator: EstimatorConfig,
}

/// What sees the loop's progress ([`run`]), in order: the start, every level, a note on why
/// the loop stopped early, the file saved.
pub trait AdaptObserver {
    /// Before level 0: the problem's name, and whether it has an exact solution (without one
    /// the error and efficiency are not measured).
    fn start(&mut self, problem: &str, exact: bool);
    /// A level solved, with what its numbers keep fewer digits of than they should.
    fn level(&mut self, record: &LevelRecord, caveats: &[Caveat]);
    /// Why the loop stopped before its last level, where that is not an error.
    fn stopped(&mut self, note: &str);
    /// The VTU file written: its path, level and unknowns.
    fn saved(&mut self, path: &Path, level: usize, ndof: usize);
}

/// Run the loop as `signorini adapt` does: settings checked first (named as `names` does), an
/// interrupt (SIGINT) stops after the level just seen ([`AdaptInterrupted`]).
pub fn run(args: &AdaptOptions, names: Names, observer: &mut dyn AdaptObserver) -> Result<()> {
    let problem = problems::by_name(&args.problem)?;
    let spec = MeshSpec::parse(&args.mesh)?;
    let config = AdaptConfig {
        levels: args.levels,
        max_ndof: args.max_ndof,
        stop_ndof: args.stop_ndof,
        refine: if args.uniform { Refine::Uniform } else { Refine::Adaptive },
        theta: args.theta,
        estimator: args.estimator,
        ..Default::default()
    };
    validate(&config, &spec, names)?;
    if let Some(path) = &args.save {
        check_writable(&names("save"), path)?;
    }
    crate::memory::check_memory(&spec.to_string(), spec.ndof()?)?;
    let mesh = spec.build(problem.as_ref())?;
    let exact = problem.exact();
    let reference = exact.map(|e| move |x: [f64; 2]| e.u(x));
    observer.start(problem.name(), exact.is_some());
    let result = adapt::run(problem.as_ref(), mesh, &config, reference.as_ref().map(|r| r as norms::Reference), &mut |l| {
        observer.level(l.record, l.caveats);
        // an interrupt (SIGINT) stops after the level just seen, as `run` does
        if study::interrupted() { std::ops::ControlFlow::Break(()) } else { std::ops::ControlFlow::Continue(()) }
    })?;
    // a stop the user must act on is the error this command ends with (after --save), as the
    // memory stop is
    if let Some(note) = result.termination.note(&config).filter(|_| !result.termination.is_error()) {
        observer.stopped(&note);
    }
    let level = result.records.last().map_or(0, |r| r.level);
    if let Some(path) = &args.save {
        let doc = report::solution_vtu(&result.mesh, &result.solution, &result.estimate.element);
        crate::records::write_atomic(path, doc.as_bytes()).with_context(|| format!("writing {}", path.display()))?;
        observer.saved(path, level, result.mesh.p2_ndof());
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
pub struct AdaptInterrupted {
    pub level: usize,
    pub saved: Option<std::path::PathBuf>,
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
