//! Stored runs the manifest does not ask for as they are: declared with another spec, not
//! declared at all, or damaged (a record at fault in the store's check). `run` refuses them
//! unless told to replace them ([`refusal`]).

use super::check::Fault;
use crate::records::{RunRecord, RunSpec, StudyDir};
use crate::study::manifest::Manifest;
use serde_json::Value;

/// The leaves of a JSON value by dotted key (`estimator.c0`), in order.
fn flatten(prefix: &str, value: &Value, out: &mut Vec<(String, Value)>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                flatten(&if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") }, v, out);
            }
        }
        leaf => out.push((prefix.to_string(), leaf.clone())),
    }
}

/// The keys in which a stored run's spec differs from the declared one, each with both values:
/// `estimator.c0: 0.45 stored, 1e308 declared`.
pub fn spec_differences(stored: &RunSpec, declared: &RunSpec) -> Vec<String> {
    let leaves = |s: &RunSpec| {
        let mut out = Vec::new();
        flatten("", &serde_json::to_value(s).unwrap_or_default(), &mut out);
        out
    };
    let (a, b) = (leaves(stored), leaves(declared));
    let get = |side: &[(String, Value)], key: &str| side.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone());
    let mut keys: Vec<&String> = a.iter().map(|(k, _)| k).collect();
    keys.extend(b.iter().map(|(k, _)| k).filter(|k| !a.iter().any(|(ka, _)| ka == *k)));
    let show = |v: Option<Value>| v.map_or("(absent)".to_string(), |v| v.to_string());
    let hash = |v: Option<Value>| v.and_then(|v| v.as_str().map(|h| format!("sha256 {}", &h[..h.len().min(12)]))).unwrap_or("none".into());
    let differing: Vec<&String> = keys.into_iter().filter(|k| get(&a, k) != get(&b, k)).collect();
    // an input read under one name and declared under another with the same bytes: one line
    let renamed = |k: &str| {
        let h = get(&a, k).filter(|_| get(&b, k).is_none())?;
        differing.iter().find(|o| o.starts_with("inputs.") && get(&a, o).is_none() && get(&b, o).as_ref() == Some(&h)).map(|o| (*o, h))
    };
    let renamed_to: Vec<&String> =
        differing.iter().filter(|k| k.starts_with("inputs.")).filter_map(|k| renamed(k)).map(|(o, _)| o).collect();
    differing
        .iter()
        .filter(|k| !renamed_to.contains(k))
        .map(|k| match k.strip_prefix("inputs.") {
            // an input file is named as such: the run read other bytes than the file holds now
            Some(file) => match (renamed(k), get(&a, k)) {
                (Some((other, h)), _) => format!(
                    "the input file {file} is declared under another name now, {} (the same content, {}): the stored spec names the file the run read",
                    other.trim_start_matches("inputs."),
                    hash(Some(h))
                ),
                (None, None) => format!("the input file {file} is not in the stored spec ({} now)", hash(get(&b, k))),
                (None, stored) => format!("the input file {file} changed ({} stored, {} now)", hash(stored), hash(get(&b, k))),
            },
            None => format!("{k}: {} stored, {} declared", show(get(&a, k)), show(get(&b, k))),
        })
        .collect()
}

/// A stored run the manifest does not ask for as it is.
#[derive(Clone, Debug, PartialEq)]
pub enum Stale {
    /// Declared with another spec: the differing keys ([`spec_differences`]).
    Differs { id: String, differences: Vec<String> },
    /// Not declared by the manifest at all.
    Undeclared { id: String },
    /// A record file (`runs/FILE.json`) at fault in the store's integrity check ([`super::Store::check`]):
    /// what is wrong with it and its snapshots.
    Damaged { file: String, what: Vec<String> },
    /// A summary (`levels.csv`, `provenance.json`) or a stored reference that is not what the
    /// records render or name: `run --replace` renders it again once the runs at fault are
    /// computed again (the summaries hold no number a record does not).
    Summary { file: std::path::PathBuf, what: String },
}

/// Every fault of the folder ([`super::Store::check`]) as a stale entry: a record file at fault
/// once with all it has, a summary or reference as itself. Nothing at fault is kept silently: `run`
/// refuses all of them unless told to replace.
pub fn damaged(faults: &[Fault]) -> Vec<Stale> {
    let mut out: Vec<Stale> = Vec::new();
    for f in faults {
        let Some(stem) = &f.record else {
            out.push(Stale::Summary { file: f.file.clone(), what: f.what.clone() });
            continue;
        };
        let text = f.to_string();
        match out.iter_mut().find(|s| matches!(s, Stale::Damaged { file, .. } if file == stem)) {
            Some(Stale::Damaged { what, .. }) => what.push(text),
            _ => out.push(Stale::Damaged { file: stem.clone(), what: vec![text] }),
        }
    }
    out
}

/// The stored runs that are stale: among `planned` (the runs this invocation is responsible
/// for, as they would run), those stored with another spec; among all stored runs, those the
/// manifest does not declare.
pub fn stale_runs(manifest: &Manifest, runs: &[RunRecord], planned: &[RunSpec]) -> Vec<Stale> {
    let mut out: Vec<Stale> = planned
        .iter()
        .filter_map(|spec| runs.iter().find(|r| r.run.id == spec.id && r.run != *spec))
        .map(|r| Stale::Differs { id: r.run.id.clone(), differences: spec_differences(&r.run, planned_spec(planned, &r.run.id)) })
        .collect();
    out.extend(
        runs.iter().filter(|r| !manifest.runs.iter().any(|p| p.spec.id == r.run.id)).map(|r| Stale::Undeclared { id: r.run.id.clone() }),
    );
    out
}

fn planned_spec<'a>(planned: &'a [RunSpec], id: &str) -> &'a RunSpec {
    planned.iter().find(|s| s.id == id).expect("a planned run")
}

/// The error refusing to overwrite stale runs: each run with what differs, and the way out.
pub fn refusal(manifest: &Manifest, dir: &StudyDir, stale: &[Stale]) -> anyhow::Error {
    let what: Vec<String> = stale
        .iter()
        .map(|s| match s {
            Stale::Differs { id, differences } => format!("run {id} is stored with another spec ({})", differences.join("; ")),
            Stale::Undeclared { id } => format!("run {id} is stored but not declared in {}", manifest.file.display()),
            Stale::Damaged { file, what } => format!("the record runs/{file}.json does not hold together ({})", what.join("; ")),
            Stale::Summary { file, what } => format!("{} {what}", file.strip_prefix(&dir.root).unwrap_or(file).display()),
        })
        .collect();
    anyhow::anyhow!(
        "{}: not overwriting the stored results in {}: {}. Nothing was run or changed. Pass --replace to replace these runs \
         (records and mesh snapshots; the other stored runs are kept){}, or --fresh to start the study over",
        manifest.file.display(),
        dir.root.display(),
        what.join("; "),
        if stale.iter().any(|s| matches!(s, Stale::Summary { .. })) {
            "; with --replace the summaries and references at fault are made again from the records and runs"
        } else {
            ""
        }
    )
}
