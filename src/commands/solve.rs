//! `solve` and `export`: one certified solve on a mesh, or on a mesh of the adaptive loop from
//! it, with its error, estimate and KKT report; `export` writes it for the NGSolve cross-check.

use super::places::{check_target, output_folder};
use crate::adapt;
use crate::estimate;
use crate::mesh::MeshSpec;
use crate::settings::adapt::AdaptConfig;
use crate::settings::estimator::{ConfigError, EstimatorConfig};
use crate::settings::pdas::PdasOptions;
use crate::{norms, problems, report, solve};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// How the caller names a setting in its messages, by the setting's key (`theta`,
/// `estimator.c0`, `pdas.max_iterations`): the command line names its flag; a program, the key.
pub type Names<'a> = &'a dyn Fn(&str) -> String;

/// What `solve` and `export` solve: a problem on a mesh, or on an adaptive level from it.
#[derive(Clone, Debug)]
pub struct SolveOptions {
    /// A built-in problem's name or a problem file's path.
    pub problem: String,
    /// `structured:N`, `symmetric:N` or `gmsh:PATH.msh`.
    pub mesh: String,
    /// Points `X,Y` where u_h is evaluated.
    pub probes: Vec<String>,
    pub max_pdas_iterations: usize,
    /// Log every active-set iteration on standard error.
    pub verbose: bool,
    /// Marking parameter of the levels refined before the solve.
    pub theta: f64,
    /// Solve on this adaptive level instead (with `adapt_min_ndof`, the last level tried).
    pub adapt_levels: Option<usize>,
    /// Solve on the first adaptive level with at least this many unknowns instead.
    pub adapt_min_ndof: Option<usize>,
    pub estimator: EstimatorConfig,
}

/// Validate the loop's settings as manifests do (the same functions), naming each setting as
/// `names` does: every setting, and `max_ndof` against the initial mesh `spec`.
pub fn validate(config: &AdaptConfig, spec: &MeshSpec, names: Names) -> Result<()> {
    let flag = |e: ConfigError| anyhow::anyhow!("{}: expected {}, got {}", names(e.key), e.expected, e.got);
    config.validate().map_err(flag)?;
    config.check_initial(spec.ndof()?, &spec.to_string()).map_err(flag)
}

/// A solve's mesh, solution, element indicators and report.
pub type Solved = (crate::mesh::Mesh, solve::DiscreteSolution, Vec<f64>, report::SolveReport);

/// Solve as `signorini solve` does: the data checked, the solution certified by its KKT
/// conditions, the estimate finite, the resolution checked (caveats become the report's warnings).
pub fn solve(args: &SolveOptions, names: Names) -> Result<Solved> {
    let problem = problems::by_name(&args.problem)?;
    let spec = MeshSpec::parse(&args.mesh)?;
    let probes = args.probes.iter().map(|p| report::parse_probe(p)).collect::<Result<Vec<_>, _>>()?;
    let pdas = PdasOptions { max_iterations: args.max_pdas_iterations, ..Default::default() };
    let estimator = args.estimator;
    let adaptive = args.adapt_levels.is_some() || args.adapt_min_ndof.is_some();
    let theta = args.theta;
    let config = AdaptConfig {
        levels: args.adapt_levels.map_or(200, |l| l.saturating_add(1)),
        theta,
        estimator,
        pdas: pdas.clone(),
        ..Default::default()
    };
    validate(&config, &spec, names)?;
    crate::memory::check_memory(&spec.to_string(), spec.ndof()?)?;
    if let Some(n) = args.adapt_min_ndof {
        crate::memory::check_memory(&format!("an adaptive level reaching --adapt-min-ndof {n}"), n as f64)?;
    }
    let mut mesh = spec.build(problem.as_ref())?;
    // probes outside the initial mesh fail before anything is solved
    let locator = crate::mesh::locate::Locator::new(&mesh);
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
    let mut log = |it: &crate::contact::PdasIteration| {
        if verbose {
            note!("pdas {:>3}: active {:>6} (+{} -{}), residual {:.3e}", it.iteration, it.active, it.added, it.removed, it.residual);
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
        note!("warning: {w}");
    }
    let report =
        report::SolveReport { warnings, ..report::SolveReport::new(problem.name(), &mesh_name, &mesh, &sol, error, &est, &probes)? };
    Ok((mesh, sol, est.element, report))
}

/// Solve and write the case files (`OUT/mesh.vtu`, `OUT/case.json`): the files written.
pub fn export(args: &SolveOptions, out: &Path, names: Names) -> Result<Vec<PathBuf>> {
    // before solving
    output_folder("--out", out, "export writes a folder there (mesh.vtu, case.json)")?;
    for file in ["mesh.vtu", "case.json"] {
        check_target("--out", &out.join(file))?;
    }
    let (mesh, sol, indicator, r) = solve(args, names)?;
    // eta_{1,p} .. eta_{5,p} per node, computed again for the file (the solve keeps only eta_T)
    let nodal = estimate::node_terms(&mesh, problems::by_name(&args.problem)?.as_ref(), &sol, &r.estimator_config);
    report::export_case(out, &mesh, &sol, &indicator, &nodal, &r)
}
