//! `report`: one self-contained HTML page per study (figures embedded, CLAIMS rows, drift
//! status, run table, provenance), read from files only.

use super::places::{is_tracked_results, output_folder};
use super::workspace::Workspace;
use anyhow::{Result, bail};
use signorini_store::study::store::Shelf;
use std::path::PathBuf;

/// `report`: the study pages, with the defaults of a scratch folder when --results names one.
/// Write the study pages: the files written.
pub fn write(
    results: Option<&std::path::Path>,
    figures: Option<&std::path::Path>,
    out: Option<&std::path::Path>,
    studies: &[String],
    drift_report: Option<&std::path::Path>,
    workspace: &Workspace,
    wait: bool,
) -> Result<Vec<PathBuf>> {
    let experiments = workspace.experiments.as_path();
    let tracked = results.is_none_or(is_tracked_results);
    let results = results.map_or_else(|| std::path::PathBuf::from("results"), |r| r.to_path_buf());
    if results.exists() && !results.is_dir() {
        bail!("--results {}: this is a file; report reads the study folders of a results folder: give a folder's path", results.display());
    }
    if wait {
        Shelf::wait_for_writers(&results)?;
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
            let others = super::drift::written_drift_reports().into_iter().filter(|f| *f != default);
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
    let drift = crate::page::DriftReports::read(&files, drift_report.is_some(), &advice)?;
    let shelf = Shelf::open_folder(&results, &workspace.manifests)?;
    crate::page::write_pages(&shelf, &figures, &out, studies, &drift, &workspace.roles)
}
