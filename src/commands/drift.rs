//! `drift`: every declared study rerun (deep ones in their tiers) and compared with the stored
//! results at every level, within the manifests' tolerances; or, with `--accept`, studies rerun
//! in full and swapped in. [`check`] reruns and compares; the command line prints the
//! [`Checked::tables`], writes the report ([`Checked::write_report`]) and ends with the
//! [`Checked::outcome`].

use super::places::{check_target, is_tracked_results};
use super::workspace::Workspace;
use crate::study;
use anyhow::{Context, Result, bail};
use signorini_store::study::{manifest, store};
use std::path::{Path, PathBuf};

/// What `drift` checks, as the command line's flags say it.
#[derive(Clone, Debug, Default)]
pub struct DriftRequest {
    /// Rerun the quick forms only.
    pub quick: bool,
    /// Rerun deep studies to the end.
    pub deep: bool,
    /// Compare the records of this folder instead of rerunning.
    pub against: Option<PathBuf>,
    /// Where the JSON report goes (default: [`default_report`]).
    pub report: Option<PathBuf>,
    /// Merge into the report at `report`, keeping the other studies' entries.
    pub merge: bool,
    /// Rerun these studies in full and rewrite their stored results; nothing is compared.
    pub accept: Vec<String>,
    /// Check only these studies (empty: every declared one).
    pub only: Vec<String>,
    /// The folder of the study manifests.
    pub experiments: PathBuf,
    /// The results root holding the stored results.
    pub results: PathBuf,
}

/// What [`check`] did: accepted studies, or a comparison to report.
pub enum Drift {
    Accepted,
    Checked(Box<Checked>),
}

/// A comparison made: the report, where it goes, and what it was compared with.
pub struct Checked {
    pub report: study::drift::DriftReport,
    /// The report file.
    pub file: PathBuf,
    /// The report already at `file` that this one merges into (`--merge`).
    older: Option<serde_json::Value>,
    against: Option<PathBuf>,
    results: PathBuf,
}

/// `drift --accept`: rerun the studies in full (every run checked first) and rewrite their results.
fn accept_studies(accept: &[String], experiments: &std::path::Path, results: &std::path::Path) -> Result<()> {
    let manifests = manifest::declared(experiments, accept)?;
    for m in &manifests {
        m.check_runs()?;
    }
    for m in &manifests {
        study::accept::accept(m, results, true).map_err(|e| accept_advice(e, &m.study))?;
        note!(
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
    match e.chain().find_map(|c| c.downcast_ref::<store::Held>()) {
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
pub struct DriftInterrupted {
    pub study: String,
    pub scratch: std::path::PathBuf,
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
pub fn default_report(quick: bool, against: Option<&std::path::Path>, only: &[String]) -> std::path::PathBuf {
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
pub fn written_drift_reports() -> Vec<std::path::PathBuf> {
    let Ok(dir) = std::fs::read_dir("target/drift") else { return Vec::new() };
    let mut files: Vec<std::path::PathBuf> = dir
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with("report") && n.ends_with(".json")))
        .collect();
    files.sort();
    files
}

/// The report already at `file` that `--merge` merges into: None without `--merge` or where
/// there is none yet; read before anything is rerun, so that a file that is not a drift report
/// is an error naming it at once (and is never overwritten).
fn report_to_merge_into(path: &Path) -> Result<Option<serde_json::Value>> {
    if !path.exists() {
        return Ok(None);
    }
    let text = crate::records::read_text(path).with_context(|| format!("reading the drift report {} to merge into", path.display()))?;
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

/// Rerun and compare as `signorini drift` does (or accept, with `request.accept`): the report
/// file checked writable, and a report to merge into read, before anything is rerun.
pub fn check(request: &DriftRequest) -> Result<Drift> {
    let DriftRequest { quick, deep, ref against, report: ref report_file, merge, ref accept, ref only, ref experiments, ref results } =
        *request;
    let against = against.as_deref();
    if !accept.is_empty() {
        accept_studies(accept, experiments, results)?;
        return Ok(Drift::Accepted);
    }
    let results = if is_tracked_results(results) { Path::new("results") } else { results.as_path() };
    // every manifest, and what the CLAIMS rows need, checked before any run is rerun
    let workspace = Workspace::load(experiments)?;
    let (manifests, roles) = (workspace.studies(only)?, &workspace.roles);
    // the default too: `--against DIR` writes DIR/drift-report.json
    let file = report_file.clone().unwrap_or_else(|| default_report(quick, against, only));
    let flag = if report_file.is_some() { "--report" } else { "the drift report (--report FILE writes it elsewhere)" };
    check_target(flag, &file)?;
    let older = if merge { report_to_merge_into(&file)? } else { None };
    let scratch = PathBuf::from("target/drift").join(if quick { "quick" } else { "full" });
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
        let Ok(shelf) = store::Shelf::open_folder(r, &manifests) else {
            return Ok(crate::records::read_text(&r.join("CLAIMS.md")).unwrap_or_default());
        };
        crate::claims::claims(&shelf, roles).map(|c| crate::claims::markdown_for(&c, r)).map_err(std::io::Error::other)
    })
    .map_err(|e| match e.downcast_ref::<study::Interrupted>() {
        Some(i) => DriftInterrupted { study: i.study.clone(), scratch: scratch.clone() }.into(),
        None => e,
    })?;
    Ok(Drift::Checked(Box::new(Checked { report, file, older, against: against.map(Path::to_path_buf), results: results.to_path_buf() })))
}

impl Checked {
    /// The table of the fields that moved (if any), then the largest change of each float field.
    pub fn tables(&self) -> String {
        let moved = if self.report.rows.is_empty() { String::new() } else { study::drift::table(&self.report.rows) };
        format!(
            "{moved}\nlargest change of each float field (whether within tolerance or not):\n{}\n",
            study::drift::changes_table(&self.report)
        )
    }

    /// Write the JSON report (merged into the older one with `--merge`): its path.
    pub fn write_report(&self) -> Result<&Path> {
        let written = match &self.older {
            Some(older) => {
                self.report.merged_into(older.clone()).with_context(|| format!("merging into the drift report {}", self.file.display()))?
            }
            None => serde_json::to_value(&self.report)?,
        };
        crate::records::write_json(&self.file, &written).with_context(|| {
            format!("writing the drift report {} (--report FILE writes it elsewhere; the comparison above stands)", self.file.display())
        })?;
        Ok(&self.file)
    }

    /// The verdict line of a drift run: none, or what moved and what to do about it.
    pub fn outcome(&self) -> Result<Vec<String>> {
        let (report, against, results) = (&self.report, self.against.as_deref(), self.results.as_path());
        let mut lines = Vec::new();
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
                lines.push(format!(
                    "drift: none ({studies} checked at every level{}{tiers})",
                    if report.quick { " of the quick forms" } else { "" }
                ));
                Ok(lines)
            }
            (0, Some(dir)) => {
                lines.push(format!(
                    "drift: none ({studies} of {} compared with {} at every level{not_compared})",
                    dir.display(),
                    results.display()
                ));
                if report.self_comparison {
                    lines.push(format!(
                        "note: {} is the stored results folder itself: each record was compared with itself and nothing was rerun; this checks that the folder reads back, not its numbers (a study page does not quote it as a drift check)",
                        dir.display()
                    ));
                } else if !report.copies.is_empty() {
                    note!(
                        "note: the records of {} in {} are byte-identical to the stored ones, timings (t_*) included: no rerun reproduces timings, so {} is a copy of the stored folder, not a rerun; this checks that the copy reads back, not its numbers (a study page does not quote it as a drift check). To check the numbers, rerun into it: `signorini run experiments/STUDY.toml --fresh --results {}`",
                        report.copies.join(", "),
                        dir.display(),
                        dir.display(),
                        dir.display()
                    );
                }
                Ok(lines)
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
}
