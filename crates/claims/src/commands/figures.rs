//! `figures`: every figure and CLAIMS.md redrawn from the stored results alone, after every
//! declared study is checked complete (in the tracked `results/`) or those a scratch folder holds.

use super::places::{again_while_written, is_tracked_results, output_folder, results_place};
use super::workspace::Workspace;
use anyhow::{Context, Result, bail};
use std::path::PathBuf;
use store::study;

/// The declared studies `figures` checks complete in `results` and those whose figures it draws
/// (`None`: every figure): in the tracked `results/`, every declared study is checked; in
/// another folder, those it holds. `--study` names the drawn ones, each of which the folder must hold.
fn figure_studies(
    results: &std::path::Path,
    tracked: bool,
    workspace: &Workspace,
    only: &[String],
) -> Result<(Vec<study::manifest::Manifest>, Option<Vec<String>>)> {
    let all = workspace.manifests.clone();
    let named = if only.is_empty() { None } else { Some(workspace.studies(only)?.into_iter().map(|m| m.study).collect::<Vec<_>>()) };
    if tracked {
        return Ok((all, named));
    }
    let held = study::held_by(results, &all).with_context(|| format!("--results {}", results.display()))?;
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
        note!("figures: {dir} does not hold {}: their figures and claims are not drawn", held.absent.join(", "));
    }
    Ok((held.present, Some(named.unwrap_or(present))))
}

/// Draw the figures into `figures` (default: `figures/`, or `DIR/figures` for `--results DIR`)
/// and write CLAIMS.md beside the results: the files written, CLAIMS.md last.
pub fn draw(
    results: Option<&std::path::Path>,
    figures: Option<&std::path::Path>,
    workspace: &Workspace,
    only: &[String],
    wait: bool,
) -> Result<Vec<PathBuf>> {
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
    let (checked, drawn) = figure_studies(&results, tracked, workspace, only)?;
    for m in &checked {
        study::check_complete(m, &results)?;
    }
    // what the figures and CLAIMS rows read: every study, through the integrity check
    let shelf = study::store::Shelf::open_folder(&results, &workspace.manifests)?;
    let mut written = crate::plot::draw_studies(&shelf, &figures, &workspace.roles, drawn.as_deref())?;
    crate::analysis::claims::write(&shelf, &workspace.roles).with_context(|| format!("writing {}", results.join("CLAIMS.md").display()))?;
    written.push(results.join("CLAIMS.md"));
    Ok(written)
}

/// The flags of `figures` (`signorini figures`, and `signorini-figures`, the same command
/// built without the solver for `make figures`).
#[derive(Clone, Debug, clap::Args)]
pub struct FiguresArgs {
    /// Results root to read; CLAIMS.md is written there [default: results, where every
    /// declared study must be complete].
    #[arg(long)]
    pub results: Option<PathBuf>,
    /// The declared studies the results must match.
    #[arg(long, default_value = "experiments")]
    pub experiments: PathBuf,
    /// Folder the figures are written to [default: figures, or DIR/figures with --results DIR].
    #[arg(long, visible_alias = "out")]
    pub figures: Option<PathBuf>,
    /// Draw only these studies' figures (repeatable) [default: every study the results hold].
    #[arg(long, value_name = "STUDY")]
    pub study: Vec<String>,
    /// If another process is writing a study of the results folder, wait for it to finish
    /// instead of refusing (what the Slurm finish job does).
    #[arg(long)]
    pub wait: bool,
}

/// The `figures` command: the results root checked, the manifests read once, the figures and
/// CLAIMS.md drawn ([`draw`]; again while a writer started after the wait, with `--wait`); the
/// files written, CLAIMS.md last.
pub fn run(args: &FiguresArgs) -> Result<Vec<PathBuf>> {
    results_place("--results", args.results.as_deref())?;
    let workspace = Workspace::load(&args.experiments)?;
    let mut written = Vec::new();
    again_while_written(args.wait, || {
        written = draw(args.results.as_deref(), args.figures.as_deref(), &workspace, &args.study, args.wait)?;
        Ok(())
    })?;
    Ok(written)
}
