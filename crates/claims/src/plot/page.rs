//! One page per study for a reviewer's browser: `signorini report` writes `STUDY.html`, a
//! single self-contained file (figures embedded as PNG data, no script, no external resource)
//! with the study's CLAIMS rows, its figures, the run table, the drift status and the provenance.
//!
//! Everything on the page is read from files the other commands wrote: the records and
//! `provenance.json` under the results folder, the PNGs under the figures folder, CLAIMS rows
//! recomputed from the records ([`crate::analysis::claims`]), and the drift reports `signorini
//! drift` wrote ([`DriftReports`]: for each study the newest that covers it), whose date and
//! scope the page states.

use crate::analysis::claims::Claim;
use crate::analysis::studies::{self, Study};
use base64::Engine;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use store::records::RunRecord;
use store::study::store::Shelf;

/// The figures of [`crate::plot::FIGURES`] drawn from `study` ([`crate::plot::study_of`]), in
/// the order drawn.
pub fn figures_of(study: &str) -> Vec<&'static str> {
    crate::plot::FIGURES.into_iter().filter(|f| crate::plot::study_of(f) == Some(study)).collect()
}

/// The studies a CLAIMS row rests on, from its id (a test checks that every row maps to one).
pub fn claim_studies(id: &str) -> &'static [Study] {
    use studies::*;
    match id {
        // every stored run with an error (claims::c0_claim: no page says "No CLAIMS row rests
        // on this study" of a study whose runs it reads)
        _ if id.starts_with("c0") => ALL,
        // every row recomputed: every study a row reads
        "parity" => ALL,
        "sampling" => &[EX71, EX72, CONTACT_TERM_ABLATION],
        _ if id.starts_with("efficiency-up-to-l_h") => {
            &[DEEP, EX71, EX72, EX72_LARGE, EX72_ROLLERS, FB, HERTZ, CONTACT_TERM_ABLATION, ESTIMATOR_REPAIR]
        }
        // the row named after the study it judges
        HERTZ => &[HERTZ],
        "efficiency-size" => &[DEEP, EX72_LARGE, EX72_ROLLERS, HERTZ],
        _ if id.starts_with("theta") => &[THETA_ABLATION],
        _ if id.starts_with("7.1-") => &[DEEP, EX71, CONTACT_TERM_ABLATION, ESTIMATOR_REPAIR],
        _ if id.starts_with("7.2-") => &[EX72, EX72_LARGE, CONTACT_TERM_ABLATION, ESTIMATOR_REPAIR],
        _ if id.starts_with("7.2r-") => &[EX72_ROLLERS],
        _ if id.starts_with("log-factor") => &[LOG_ABLATION],
        _ if id.starts_with("fb-") => &[DEEP, FB, ESTIMATOR_REPAIR],
        _ if id.starts_with("estimator-repair") => &[DEEP, ESTIMATOR_REPAIR, HERTZ],
        _ => &[],
    }
}

/// Whether the CLAIMS row `id` rests on `study`: the c0 row on every study (it reads every
/// stored run with an error, of any study, declared here or not: `claims::c0_claim`), the
/// others on their [`claim_studies`].
pub fn rests_on(id: &str, study: &str) -> bool {
    id.starts_with("c0") || claim_studies(id).contains(&study)
}

/// The drift reports the pages may quote, and the command a page advises where none covers its
/// study. `report --drift-report FILE` quotes that file alone; by default, the default report
/// and every one `drift` writes under `target/drift/` (`report-STUDY.json` for `drift --study
/// STUDY`), so the command a page advises makes the next page "checked" (the advised
/// `signorini drift --study S` writes `target/drift/report-S.json`, which `report` reads, so no
/// page stays "not checked" after it).
pub struct DriftReports {
    /// The reports read, in the order given (the default or named one first).
    reports: Vec<serde_json::Value>,
    /// The command that checks a study, `STUDY` in place of its name.
    advice: String,
}

impl DriftReports {
    /// Read `files` (one that cannot be read or parsed is an error naming it; one that does not
    /// exist is skipped, unless `named`: a file the user named is an error when it is missing,
    /// as a typo would otherwise read as "no drift report"); `advice` is the
    /// command a page advises, `STUDY` in place of the study.
    pub fn read(files: &[PathBuf], named: bool, advice: &str) -> anyhow::Result<DriftReports> {
        use anyhow::Context;
        let mut reports = Vec::new();
        for file in files {
            match store::records::read_text(file) {
                Ok(t) => reports.push(serde_json::from_str(&t).with_context(|| {
                    format!(
                        "reading the drift report {} (drift writes it whole, so it was cut or edited since): run `signorini drift` to write it again, or remove it and the pages say \"not checked\"",
                        file.display()
                    )
                })?),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound && !named => {}
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                    anyhow::bail!("the drift report {} (--drift-report) does not exist: give the file `signorini drift` wrote (by default target/drift/report.json), or leave --drift-report out", file.display())
                }
                Err(e) => return Err(e).with_context(|| format!("reading the drift report {}", file.display())),
            }
        }
        Ok(DriftReports { reports, advice: advice.to_string() })
    }

    /// The report that speaks for `study` with the records `runs`: among those with an entry
    /// for it, one that compared exactly these records before one that did not, then the newest
    /// by its own date (the first given on a tie); where none has an entry, the first report.
    fn for_study(&self, study: &str, runs: &[RunRecord]) -> Option<&serde_json::Value> {
        let entry = |r: &serde_json::Value| r["studies"].as_array().and_then(|s| s.iter().find(|e| e["study"] == study).cloned());
        let rank = |r: &serde_json::Value| {
            entry(r)
                .map(|e| (records_not_compared(&e, runs).is_none(), e["date"].as_str().or(r["date"].as_str()).unwrap_or("").to_string()))
        };
        let mut best: Option<(&serde_json::Value, (bool, String))> = None;
        for r in &self.reports {
            if let Some(k) = rank(r)
                && best.as_ref().is_none_or(|(_, b)| k > *b)
            {
                best = Some((r, k));
            }
        }
        best.map(|(r, _)| r).or(self.reports.first())
    }
}

/// What the page says about drift: the report's date, whether it compared this study and what
/// it found, for the records `runs` the page shows: a report that did not compare exactly these
/// (by their hashes, `records` and `against_records` of its entry) says nothing about them.
fn drift_status(reports: &DriftReports, study: &str, runs: &[RunRecord]) -> String {
    let advice = format!("run <code>{}</code>", escape(&reports.advice.replace("STUDY", study)));
    let Some(r) = reports.for_study(study, runs) else {
        return format!("not checked: no drift report found ({advice})");
    };
    let date = r["date"].as_str().unwrap_or("an unknown date");
    let against = r["against"].as_str().map(|a| format!(" against {}", escape(a))).unwrap_or_default();
    let entry = r["studies"].as_array().and_then(|s| s.iter().find(|e| e["study"] == study));
    // a deep study rerun in its tiers says so in its own entry
    let scope = if r["quick"].as_bool() == Some(true) {
        "quick prefixes"
    } else if entry.is_some_and(|e| e["quick"].as_bool() == Some(true)) {
        "quick prefixes and, for the runs its manifest names, every level (a deep study's test tier)"
    } else {
        "every level"
    };
    let stale = entry.and_then(|e| records_not_compared(e, runs));
    match entry {
        Some(_) if r["self_comparison"].as_bool() == Some(true) => {
            format!("not checked: the drift report of {date}{against} compared this folder with itself (nothing was rerun)")
        }
        Some(e) if store::study::compared_a_copy(e) => format!(
            "not checked: the drift report of {date}{against} compared these records with byte-identical ones, timings included: a copy of this folder, not a rerun"
        ),
        None => format!("not checked in the drift report of {date}{against} (it did not include this study; {advice})"),
        Some(_) if let Some(why) = stale => format!("not checked: the drift report of {date}{against} {why}; {advice}"),
        Some(e) => match e["drift"].as_u64() {
            Some(0) => format!("<b>no drift</b>: rerun and compared at {scope}{against} on {date}, {} run(s)", e["runs"]),
            Some(n) => format!("<b class=\"bad\">drift</b>: {n} field(s) moved ({scope}{against}, {date}); see the drift report"),
            None => format!("unreadable entry in the drift report of {date}"),
        },
    }
}

/// Why a drift report's study entry does not speak for the records `runs`, if it does not: it
/// names no hashes (a report of an older harness), or a run shown is not one it compared (run
/// again since, or a report of another folder), or it compared a run the page does not show.
fn records_not_compared(entry: &serde_json::Value, runs: &[RunRecord]) -> Option<String> {
    let sides: Vec<&serde_json::Map<String, serde_json::Value>> =
        ["records", "against_records"].iter().filter_map(|k| entry[*k].as_object()).collect();
    if sides.is_empty() {
        return Some("records no hashes of the records it compared, so it may predate these records".into());
    }
    // each side of the comparison (the stored folder, and with --against the other one) that
    // holds exactly these records speaks for them
    let differences = |side: &serde_json::Map<String, serde_json::Value>| {
        let changed: Vec<&str> = runs
            .iter()
            .filter(|r| side.get(&r.run.id).and_then(|v| v.as_str()) != Some(store::records::record_sha256(r).as_str()))
            .map(|r| r.run.id.as_str())
            .collect();
        let gone: Vec<String> = side.keys().filter(|id| !runs.iter().any(|r| r.run.id == **id)).cloned().collect();
        (changed, gone)
    };
    let (changed, gone) = sides.into_iter().map(differences).min_by_key(|(c, g)| c.len() + g.len())?;
    if !changed.is_empty() {
        return Some(format!("predates these records or compared others (run(s) {} changed since)", escape(&changed.join(", "))));
    }
    if !gone.is_empty() {
        return Some(format!("compared run(s) {} that these records no longer hold", escape(&gone.join(", "))));
    }
    None
}

/// HTML-escape text.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Text with numbers in it (a CLAIMS row's wording and evidence), HTML-escaped, each number in
/// scientific notation (`4.4e-4`, `-1.2E+3`) in a `<span class="n">` that never wraps, so that no
/// line ends inside one (`4.4e-` above `4`).
fn prose(text: &str) -> String {
    let text = escape(text);
    let b = text.as_bytes();
    let digits = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    let mut out = String::with_capacity(text.len());
    let (mut copied, mut i) = (0, 0);
    while i < b.len() {
        let starts = b[i].is_ascii_digit() && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'.' || b[i - 1] == b'_'));
        if !starts {
            i += 1;
            continue;
        }
        let start = if i > 0 && b[i - 1] == b'-' { i - 1 } else { i };
        let mut end = digits(i);
        if end + 1 < b.len() && b[end] == b'.' && b[end + 1].is_ascii_digit() {
            end = digits(end + 1);
        }
        let mut exponent = end + 1;
        if exponent < b.len() && (b[end] == b'e' || b[end] == b'E') && (b[exponent] == b'-' || b[exponent] == b'+') {
            exponent += 1;
        }
        let after = digits(exponent);
        let scientific = end < b.len() && (b[end] == b'e' || b[end] == b'E') && after > exponent;
        if scientific && (after == b.len() || !b[after].is_ascii_alphanumeric()) {
            out += &text[copied..start];
            let _ = write!(out, "<span class=\"n\">{}</span>", &text[start..after]);
            copied = after;
            i = after;
        } else {
            i = end;
        }
    }
    out + &text[copied..]
}

/// A number of the run table, every one in the same style: scientific with four significant
/// digits (`9.117e6`, `1.945e-7`), "–" for none. The cells that hold them never wrap (`td.num`).
fn num(v: Option<f64>) -> String {
    v.map_or("–".to_string(), |v| format!("{v:.3e}"))
}

fn run_table(runs: &[RunRecord]) -> String {
    let mut s = String::from(
        "<table class=\"runs\"><tr><th>run</th><th>problem</th><th>refinement</th><th>estimator</th><th>levels</th><th>final NDF</th><th>final estimate</th><th>final error</th><th>efficiency</th></tr>\n",
    );
    for r in runs {
        let last = r.levels.last();
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{:?}{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            escape(&r.run.id),
            escape(&r.run.problem),
            r.run.refine,
            if matches!(r.run.refine, model::settings::adapt::Refine::Adaptive) {
                format!(", θ = {}", r.run.theta)
            } else {
                String::new()
            },
            escape(&estimator_settings(&r.run.estimator)),
            r.levels.len(),
            last.map_or("–".into(), |l| l.ndof.to_string()),
            num(last.map(|l| l.terms.estimate)),
            num(last.and_then(|l| l.err_quadrature)),
            num(last.and_then(|l| l.efficiency)),
        );
    }
    s + "</table>\n"
}

/// The estimator settings of a run that differ from the defaults (`contact_term = as_written;
/// c0 = 1`), as the manifest's `[estimator]` keys; "default" where none do. Runs that differ
/// only there share their refinement cell: this cell tells them apart.
fn estimator_settings(config: &model::settings::estimator::EstimatorConfig) -> String {
    let (Ok(serde_json::Value::Object(set)), Ok(serde_json::Value::Object(default))) =
        (serde_json::to_value(config), serde_json::to_value(model::settings::estimator::EstimatorConfig::default()))
    else {
        return "–".into();
    };
    let differ: Vec<String> = set
        .iter()
        .filter(|(k, v)| default.get(*k) != Some(*v))
        .map(|(k, v)| format!("{k} = {}", v.as_str().map_or_else(|| v.to_string(), str::to_string)))
        .collect();
    if differ.is_empty() { "default".into() } else { differ.join("; ") }
}

/// The HTML id of CLAIMS row `id` on a study page: `claim-` and the row's markdown anchor
/// ([`crate::analysis::claims::anchor`]: lower case, spaces to hyphens, no other punctuation),
/// so that it is a valid id (`claim-estimator-repair-beyond-the-paper`).
pub fn claim_id(id: &str) -> String {
    format!("claim-{}", crate::analysis::claims::anchor(id))
}

fn claims_table(claims: &[&Claim]) -> String {
    if claims.is_empty() {
        return "<p>No CLAIMS row rests on this study.</p>\n".into();
    }
    let mut s = String::from("<table class=\"claims\"><tr><th>claim</th><th>the paper</th><th>measured</th><th>verdict</th></tr>\n");
    for c in claims {
        // the summary line shows; the claim's full wording and its evidence fold behind it
        let _ = writeln!(
            s,
            "<tr class=\"claim\" id=\"{}\"><td><b>{id}</b>: {}<details><summary>the claim in full</summary>{}</details><details><summary>what would fail it</summary>{}</details></td><td>{}</td><td>{}<details><summary>evidence</summary>{}</details></td><td>{}</td></tr>",
            claim_id(&c.id),
            prose(&c.summary.topic),
            prose(&c.claim),
            prose(&crate::analysis::claims::capitalised(&c.criterion.fails_if())),
            prose(c.summary.paper),
            prose(&c.summary.headline),
            prose(&c.measured),
            verdict_html(c),
            id = escape(&c.id)
        );
    }
    s + "</table>\n"
}

/// The verdict as HTML (the markdown bold of failures dropped), with "fragile" where it is.
fn verdict_html(c: &Claim) -> String {
    let fragile = c.fragile.as_ref().map(|f| format!(", <i>fragile</i>: {}", prose(f))).unwrap_or_default();
    format!("{}{fragile}", prose(&c.verdict.text().replace("**", "")))
}

/// The index of the study pages: the summary line of every CLAIMS row, each linked to the pages
/// of the studies it rests on, then the list of studies.
pub fn index_page(results: &Path, studies: &[String], claims: &[Claim]) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>signorini: studies</title><style>{STYLE}</style></head><body>\n<h1>The claims of Section 7, measured</h1>\n<p>From the records in <code>{}</code>. One line per claim; its studies' pages hold the evidence.</p>\n",
        escape(&results.display().to_string())
    );
    s += "<table class=\"claims\"><tr><th>claim</th><th>the paper</th><th>measured</th><th>verdict</th><th>studies</th></tr>\n";
    for c in claims {
        let links: Vec<String> = studies
            .iter()
            .filter(|st| rests_on(&c.id, st))
            .map(|st| format!("<a href=\"{st}.html#{}\">{st}</a>", claim_id(&c.id)))
            .collect();
        let _ = writeln!(
            s,
            "<tr><td><b>{}</b>: {}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&c.id),
            prose(&c.summary.topic),
            prose(c.summary.paper),
            prose(&c.summary.headline),
            verdict_html(c),
            links.join(", ")
        );
    }
    s += "</table>\n<h2>Studies</h2>\n<ul>\n";
    for st in studies {
        let _ = writeln!(s, "<li><a href=\"{0}.html\">{0}</a></li>", escape(st));
    }
    s + "</ul>\n</body></html>\n"
}
/// The eight bytes every PNG file starts with.
const PNG_SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";

fn figures_html(figures: &Path, study: &str) -> std::io::Result<String> {
    let mut s = format!(
        "<p>In every figure, a series with the same values as another at every level (or within {} %, so that one curve covers the other) is drawn with large hollow markers around the other, whose legend says \"(same values as …)\", with the largest relative difference where they differ.</p>\n",
        100.0 * crate::plot::DRAWS_OVER_REL
    );
    for name in figures_of(study) {
        let png = figures.join(format!("{name}.png"));
        match store::records::read_bytes(&png) {
            Ok(bytes) if !bytes.starts_with(PNG_SIGNATURE) => {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    format!(
                        "{} is not a PNG image (it does not start with the PNG signature); redraw it with `signorini figures`",
                        png.display()
                    ),
                ));
            }
            Ok(bytes) => {
                let data = base64::engine::general_purpose::STANDARD.encode(bytes);
                let _ = writeln!(
                    s,
                    "<figure id=\"figure-{name}\"><img alt=\"{name}\" src=\"data:image/png;base64,{data}\"><figcaption>{} <span class=\"file\">({name}.png)</span></figcaption></figure>",
                    escape(crate::plot::caption(name).unwrap_or(name))
                );
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                let _ = writeln!(
                    s,
                    "<p>Figure {name}: not drawn (no {}; run <code>signorini figures</code>).</p>",
                    escape(&png.display().to_string())
                );
            }
            Err(e) => return Err(e),
        }
    }
    Ok(s)
}

fn provenance_html(text: Option<&str>) -> String {
    let Some(text) = text else { return "<p>No provenance.json.</p>\n".into() };
    let Ok(serde_json::Value::Object(map)) = serde_json::from_str::<serde_json::Value>(text) else {
        return "<p>provenance.json is not a JSON object.</p>\n".into();
    };
    // what a reader can trust of it: the store checks three fields against the
    // records; the others are a note that nothing can check
    let mut s = String::from(
        "<p>As recorded when the study was written. <code>study</code>, <code>runs</code> and the input files' hashes are checked against the records by every command that reads the folder; the other fields (the commit, <code>quick</code>, the machine, the date, ...) are a note of how the study was made, and nothing checks them: a hand edit of them goes unnoticed.</p>\n<table class=\"provenance\">\n",
    );
    for (k, v) in map {
        let v = match v {
            serde_json::Value::String(t) => t,
            other => other.to_string(),
        };
        let _ = writeln!(s, "<tr><th>{}</th><td><code>{}</code></td></tr>", escape(&k), escape(&v));
    }
    s + "</table>\n"
}

const STYLE: &str = "body{font-family:'DejaVu Sans',sans-serif;max-width:1100px;margin:2em auto;color:#222}\
table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:4px 8px;text-align:left;vertical-align:top}\
th{background:#f4f4f4}figure{margin:1em 0}img{max-width:100%}.bad{color:#b00}code{font-size:90%}\
details{margin-top:4px;color:#444}summary{cursor:pointer;color:#06c}\
td.num{white-space:nowrap;text-align:right}.n{white-space:nowrap}figcaption{color:#333}figcaption .file{color:#777;font-size:85%}";

/// The page of `study`: `shelf` holds its records, `figures` its PNGs, `claims` every CLAIMS
/// row (those of the study are shown), `drift` the drift report if one was found.
pub fn study_page(shelf: &Shelf, figures: &Path, study: &str, claims: &[Claim], drift: &DriftReports) -> std::io::Result<String> {
    let runs = shelf.runs(study)?;
    let rows: Vec<&Claim> = claims.iter().filter(|c| rests_on(&c.id, study)).collect();
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>signorini: {0}</title><style>{STYLE}</style></head><body>\n<h1>Study {0}</h1>\n",
        escape(study)
    );
    let _ = writeln!(
        s,
        "<p>Results from <code>{}</code>, figures from <code>{}</code>.</p>",
        escape(&shelf.root().display().to_string()),
        escape(&figures.display().to_string())
    );
    let incomplete = shelf.not_as_declared(study);
    if !incomplete.is_empty() {
        let _ = writeln!(
            s,
            "<p class=\"bad\"><b>Incomplete</b>: the study's manifest declares runs this folder does not hold as declared: {}. The tables and figures below show only the runs it holds; complete it with <code>signorini run</code>.</p>",
            escape(&incomplete.join(", "))
        );
    }
    let _ = writeln!(s, "<h2>Drift</h2><p>{}</p>", drift_status(drift, study, &runs));
    let _ = writeln!(s, "<h2>Claims</h2>\n{}", claims_table(&rows));
    let _ = writeln!(s, "<h2>Figures</h2>\n{}", figures_html(figures, study)?);
    let _ = writeln!(s, "<h2>Runs</h2>\n{}", run_table(&runs));
    let _ = writeln!(s, "<h2>Provenance</h2>\n{}", provenance_html(shelf.provenance_text(study)?));
    s += "</body></html>\n";
    Ok(s)
}

/// Write `out/STUDY.html` for each of `studies` (every study the shelf's folder holds if empty), and with
/// every study also `out/index.html` ([`index_page`]), atomically; returns the pages written,
/// the index last. A named study without records is an error.
pub fn write_pages(
    shelf: &Shelf,
    figures: &Path,
    out: &Path,
    studies: &[String],
    drift: &DriftReports,
    roles: &crate::analysis::roles::Roles,
) -> anyhow::Result<Vec<PathBuf>> {
    use anyhow::Context;
    let results = shelf.root();
    let present = shelf.held();
    let chosen: Vec<String> = if studies.is_empty() { present.clone() } else { studies.to_vec() };
    if chosen.is_empty() {
        anyhow::bail!("{} holds no study (no STUDY/runs/ folder): nothing to report", results.display());
    }
    if let Some(missing) = chosen.iter().find(|s| !present.contains(s)) {
        anyhow::bail!("study {missing} has no records in {} (studies there: {})", results.display(), present.join(", "));
    }
    // every study shown (and every one a CLAIMS row reads) was read through the store's
    // integrity check when the shelf was opened
    let claims =
        crate::analysis::claims::claims(shelf, roles).with_context(|| format!("computing the CLAIMS rows from {}", results.display()))?;
    model::base::input::create_folder(out)?;
    let mut written = Vec::new();
    for study in &chosen {
        let incomplete = shelf.not_as_declared(study);
        if !incomplete.is_empty() {
            model::base::note::line(format_args!(
                "report: {study} is incomplete in {} (its page says so): {}",
                results.display(),
                incomplete.join(", ")
            ));
        }
        let page = study_page(shelf, figures, study, &claims, drift)?;
        let path = out.join(format!("{study}.html"));
        store::records::write_atomic(&path, page.as_bytes()).with_context(|| format!("writing {}", path.display()))?;
        written.push(path);
    }
    if studies.is_empty() {
        let path = out.join("index.html");
        store::records::write_atomic(&path, index_page(results, &chosen, &claims).as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_the_run_table_print_in_one_style() {
        assert_eq!(num(Some(9117456.44)), "9.117e6");
        assert_eq!(num(Some(1.9451e-7)), "1.945e-7");
        assert_eq!(num(Some(0.45)), "4.500e-1");
        assert_eq!(num(None), "–");
    }

    #[test]
    fn numbers_in_claims_text_never_break() {
        assert_eq!(
            prose("C_0 4.4e-4 over 54 runs, NDF 9.5e3–1.1e6, -2.5E+3 < eta2"),
            "C_0 <span class=\"n\">4.4e-4</span> over 54 runs, NDF <span class=\"n\">9.5e3</span>–<span class=\"n\">1.1e6</span>, <span class=\"n\">-2.5E+3</span> &lt; eta2"
        );
        assert_eq!(prose("eta1 1.14, 1e6x, v1.2e3"), "eta1 1.14, 1e6x, v1.2e3");
    }

    #[test]
    fn claim_ids_have_no_spaces() {
        assert_eq!(claim_id("estimator-repair (beyond the paper)"), "claim-estimator-repair-beyond-the-paper");
        assert_eq!(claim_id("c0"), "claim-c0");
    }

    #[test]
    fn escaping() {
        assert_eq!(escape("a < b & \"c\" > d"), "a &lt; b &amp; &quot;c&quot; &gt; d");
    }
}
