//! The drift check: fresh records against stored ones, field by field (in the spirit of numdiff
//! and pytest-regressions' num_regression).
//!
//! Integers and structural fields (NDF, levels, active-set sizes, iteration counts, the run's
//! spec) must match exactly. A float passes when
//!
//! ```text
//! |fresh - stored| <= rel * |stored| + floor * scale,   scale = max over the run's stored levels of |field|
//! ```
//!
//! with `rel` and `floor` from the manifest's `[drift]` table (per field, with a default). `rel`
//! bounds the round-off of a number computed to full relative accuracy; `floor` covers fields
//! that are differences of nearly equal numbers (an error near round-off, eta_6 at 1e-17 on a
//! level where the contact zone happens to be resolved): their round-off is relative to the size
//! the field has elsewhere in the run, not to its own value. Both are measured, not chosen
//! (`results/roundoff/`). Observed rates (least-squares slope of -log(field) in log(NDF) over a
//! run's last levels) are checked against one-sided floors; measurements (timings `t_*`, memory
//! `mem_*`) never. A level, field, run or study missing on either side is drift. In the quick
//! form the fresh runs are prefixes of the stored full runs and are compared level by level.
//! The refinement histories (marks and warm starts per level, mesh fingerprints) must agree
//! exactly as far as the fresh run went; a deep study in its tiers also replays the last level of
//! its `replay` runs from the stored history and compares that level (`replay_tier`).
//!
//! Besides the numbers, the files derived from the records are checked: `levels.csv` and
//! `provenance.json`'s run list must be exactly what the stored records give
//! ([`check_derived`]), so a hand edit or a bad merge of a view is drift too.
//!
//! `--against DIR` compares the records of another results folder (a study rerun into a scratch
//! folder, or all of them with another ordering) with the stored ones instead of rerunning: the
//! studies DIR holds are compared and the others named as not compared ([`select_against`]); a
//! folder holding none is an error. Their provenance must match too ([`compare_provenance`]):
//! records made from an edited manifest, problem file or mesh are reported as such.

use ::store::records::RunRecord;
use ::store::study::manifest::{DERIVED, DriftSpec, Manifest, Tolerance};
use ::store::study::store::Store;
use ::store::study::{manifest, provenance, store};
use model::level::record::LevelRecord;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One thing that moved.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DriftRow {
    pub study: String,
    pub run: String,
    pub level: Option<usize>,
    pub field: String,
    pub stored: String,
    pub fresh: String,
    /// |fresh - stored| / |stored| for numbers.
    pub relative_change: Option<f64>,
    pub tolerance: String,
}

#[allow(clippy::too_many_arguments)] // one argument per column of the table
fn row(
    study: &str,
    run: &str,
    level: Option<usize>,
    field: &str,
    stored: String,
    fresh: String,
    rel: Option<f64>,
    tol: String,
) -> DriftRow {
    DriftRow { study: study.into(), run: run.into(), level, field: field.into(), stored, fresh, relative_change: rel, tolerance: tol }
}

fn show(v: Option<&Value>) -> String {
    match v {
        None => "(missing)".into(),
        Some(Value::Null) => "null".into(),
        Some(v) => v.to_string(),
    }
}

/// The largest change one float field showed across a comparison, whether or not it drifted:
/// what the round-off measurement records and the tolerances are set from.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FieldChange {
    /// max |fresh - stored| / |stored| over the entries with |stored| >= 1e-3 scale: the
    /// relative change of the numbers the floor does not cover. A tolerance with
    /// rel = m max_rel and floor = m max_floor covers every entry with a margin m.
    pub max_rel: f64,
    /// max |fresh - stored| / scale over all entries (scale: the field's largest |value| in its run).
    pub max_floor: f64,
    /// Where `max_rel` was seen: "run level".
    pub at: String,
    /// Entries compared.
    pub entries: usize,
    /// For the [`ORDER_OF_MAGNITUDE`] fields: the largest |log10 fresh - log10 stored|, both
    /// values raised to REL_RANGE x scale first (reports written before it was kept say 0).
    #[serde(default)]
    pub max_decades: f64,
}

/// Fields that measure round-off themselves: `roundoff_floor`, the size of one step of iterative
/// refinement. Another ordering of the same solve moves it by up to 79% (ex72_large with nested
/// dissection forced; `make roundoff`), more than any relative tolerance could accept. What the
/// claims use it for is its order of magnitude (an error counts when it is 10x above it), and
/// that is what the drift check compares: fresh and stored agree within [`DECADES`] after both
/// are raised to REL_RANGE x scale (the floors of the first, tiny meshes are at 1e-16 and
/// differ in every digit). They get no measured tolerance.
pub const ORDER_OF_MAGNITUDE: &[&str] = &["roundoff_floor"];

/// How far an [`ORDER_OF_MAGNITUDE`] field may move, in decades: a factor 10.
pub const DECADES: f64 = 1.0;

/// |log10 a - log10 b| with both raised to `least` first (0 when both are below it).
fn decades_apart(a: f64, b: f64, least: f64) -> f64 {
    let (a, b) = (a.abs().max(least), b.abs().max(least));
    if a == b { 0.0 } else { (a.log10() - b.log10()).abs() }
}

fn is_derived(field: &str) -> bool {
    DERIVED.iter().any(|(f, _)| *f == field)
}

/// Rows for the derived fields of `levels` that are not what their definition gives.
fn check_derived_fields(study: &str, run: &str, side: &str, levels: &[LevelRecord], out: &mut Vec<DriftRow>) {
    for l in levels {
        let v = serde_json::to_value(l).expect("records serialise");
        for (field, definition) in DERIVED {
            let (stored, expected) = (v[field].as_f64(), definition(l));
            if stored != expected {
                let text = |x: Option<f64>| x.map(|x| x.to_string()).unwrap_or("null".into());
                out.push(row(
                    study,
                    run,
                    Some(l.level),
                    field,
                    format!("{side}: {}", text(stored)),
                    format!("by definition: {}", text(expected)),
                    None,
                    "exact (a function of the record's fields)".into(),
                ));
            }
        }
    }
}

/// Entries with |stored| >= REL_RANGE x (the field's largest |value| in its run) count for
/// [`FieldChange::max_rel`]; below, the floor covers them.
pub const REL_RANGE: f64 = 1e-3;

/// What a comparison found: the drift rows, and per float field its largest change.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DriftComparison {
    pub rows: Vec<DriftRow>,
    pub changes: BTreeMap<String, FieldChange>,
}

/// The largest |value| of every float field over a run's levels (the `scale` of the floor).
fn field_scales(levels: &[Value]) -> BTreeMap<String, f64> {
    let mut out = BTreeMap::new();
    for l in levels {
        for (k, v) in l.as_object().into_iter().flatten() {
            if let Some(x) = v.as_f64() {
                let e = out.entry(k.clone()).or_insert(0.0f64);
                *e = e.max(x.abs());
            }
        }
    }
    out
}

/// Compare two level records (as JSON objects), appending what moved and recording changes.
#[allow(clippy::too_many_arguments)]
fn compare_level(
    study: &str,
    run: &str,
    level: usize,
    stored: &Value,
    fresh: &Value,
    scales: &BTreeMap<String, f64>,
    spec: &DriftSpec,
    out: &mut Vec<DriftRow>,
    changes: &mut BTreeMap<String, FieldChange>,
) {
    let (Some(s), Some(f)) = (stored.as_object(), fresh.as_object()) else { return };
    let mut keys: Vec<&String> = s.keys().chain(f.keys()).collect();
    keys.sort();
    keys.dedup();
    for key in keys {
        if model::level::record::is_measurement(key) {
            continue; // timings and memory are never compared
        }
        let (sv, fv) = (s.get(key), f.get(key));
        let drift = |rel: Option<f64>, tol: String| row(study, run, Some(level), key, show(sv), show(fv), rel, tol);
        match (sv, fv) {
            (Some(Value::Number(a)), Some(Value::Number(b))) if a.is_f64() || b.is_f64() => {
                let (a, b) = (a.as_f64().unwrap_or(f64::NAN), b.as_f64().unwrap_or(f64::NAN));
                let tol = spec.tolerance(key);
                let scale = scales.get(key.as_str()).copied().unwrap_or(0.0);
                let diff = (a - b).abs();
                let c = changes.entry(key.clone()).or_default();
                c.entries += 1;
                if scale > 0.0 {
                    c.max_floor = c.max_floor.max(diff / scale);
                }
                if a.abs() >= REL_RANGE * scale && diff / a.abs() > c.max_rel {
                    c.max_rel = diff / a.abs();
                    c.at = format!("{run} {level}");
                }
                let rel = if a != 0.0 { Some(diff / a.abs()) } else { None };
                if ORDER_OF_MAGNITUDE.contains(&key.as_str()) {
                    let decades = decades_apart(a, b, REL_RANGE * scale);
                    c.max_decades = c.max_decades.max(decades);
                    if !(decades <= DECADES) {
                        out.push(drift(rel, format!("within {DECADES} decade(s), both raised to {:.3e}", REL_RANGE * scale)));
                    }
                } else if !is_derived(key) && !(diff <= tol.rel * a.abs() + tol.floor * scale) {
                    out.push(drift(rel, format!("rel {:e} + floor {:e} x {scale:.3e}", tol.rel, tol.floor)));
                }
            }
            (Some(a), Some(b)) if a == b => {}
            (Some(Value::Number(a)), Some(Value::Number(b))) => {
                let rel = a.as_f64().zip(b.as_f64()).and_then(|(a, b)| (a != 0.0).then(|| (a - b).abs() / a.abs()));
                out.push(drift(rel, "exact".into()));
            }
            _ => out.push(drift(None, "exact".into())),
        }
    }
}

/// Fields of a reference's last level a one-solve replay cannot give as the loop did: the
/// active-set iteration starts from the set the loop ended with, so it takes fewer iterations.
pub(crate) const NOT_REPLAYED: &[&str] = &["pdas_iterations"];

/// The fields in which level record `fresh` (solved again) is not `stored`, compared as the
/// drift check compares levels ([`compare_level`]: the tolerances of `spec`, measurements never,
/// the scale of each field its stored value), leaving out the fields named in `skip`: what a
/// replay of one stored level checks its record against.
pub fn level_differences(stored: &LevelRecord, fresh: &LevelRecord, spec: &DriftSpec, skip: &[&str]) -> Vec<DriftRow> {
    let as_value = |l: &LevelRecord| {
        let mut v = serde_json::to_value(l).expect("records serialise");
        if let Some(o) = v.as_object_mut() {
            o.retain(|k, _| !skip.contains(&k.as_str()));
        }
        v
    };
    let (s, f) = (as_value(stored), as_value(fresh));
    let scales = field_scales(std::slice::from_ref(&s));
    let (mut rows, mut changes) = (Vec::new(), BTreeMap::new());
    compare_level("", "", stored.level, &s, &f, &scales, spec, &mut rows, &mut changes);
    rows
}

/// Observed rate of `field` in NDF: least-squares slope of -log(field) against log(ndof) over
/// the last `last` levels (None if fewer levels or a non-positive value).
pub fn observed_rate(run: &RunRecord, field: &str, last: usize) -> Option<f64> {
    let levels: Vec<Value> = run.levels.iter().map(|l| serde_json::to_value(l).expect("records serialise")).collect();
    if levels.len() < last.max(2) {
        return None;
    }
    let pts: Vec<(f64, f64)> = levels[levels.len() - last..]
        .iter()
        .map(|l| Some(((l["ndof"].as_f64()?).ln(), l[field].as_f64().filter(|v| *v > 0.0)?.ln())))
        .collect::<Option<_>>()?;
    model::base::stats::fit_line(&pts).map(|f| -f.slope)
}

/// Compare a study's fresh runs with its stored runs. `quick`: fresh runs are the quick forms
/// (prefixes) of the stored full runs.
pub fn compare_study(manifest: &Manifest, stored: &[RunRecord], fresh: &[RunRecord], quick: bool) -> Vec<DriftRow> {
    compare(manifest, stored, fresh, quick).rows
}

/// [`compare_study`] with the largest change of every float field.
pub fn compare(manifest: &Manifest, stored: &[RunRecord], fresh: &[RunRecord], quick: bool) -> DriftComparison {
    let study = &manifest.study;
    let (mut out, mut changes) = (Vec::new(), BTreeMap::new());
    if stored.is_empty() {
        out.push(row(study, "*", None, "study", "(no stored results)".into(), format!("{} runs", fresh.len()), None, "exact".into()));
        return DriftComparison { rows: out, changes };
    }
    for planned in &manifest.runs {
        let id = &planned.spec.id;
        let (s, f) = (stored.iter().find(|r| &r.run.id == id), fresh.iter().find(|r| &r.run.id == id));
        let (s, f) = match (s, f) {
            (Some(s), Some(f)) => (s, f),
            (s, f) => {
                out.push(row(
                    study,
                    id,
                    None,
                    "run",
                    if s.is_some() { "present" } else { "(missing)" }.into(),
                    if f.is_some() { "present" } else { "(missing)" }.into(),
                    None,
                    "exact".into(),
                ));
                continue;
            }
        };
        // the spec: the stored full spec, shortened to the quick form where quick
        let expected_spec = super::effective_spec(&manifest::PlannedRun { spec: s.run.clone(), quick_levels: planned.quick_levels }, quick);
        if expected_spec != f.run {
            out.push(row(
                study,
                id,
                None,
                "run spec",
                serde_json::to_string(&expected_spec).unwrap_or_default(),
                serde_json::to_string(&f.run).unwrap_or_default(),
                None,
                "exact".into(),
            ));
        }
        if s.reference_ndof != f.reference_ndof {
            let text = |n: Option<usize>| n.map(|n| n.to_string()).unwrap_or("none".into());
            out.push(row(study, id, None, "reference_ndof", text(s.reference_ndof), text(f.reference_ndof), None, "exact".into()));
        }
        let n_compare = if quick { f.levels.len() } else { s.levels.len().max(f.levels.len()) };
        let expected_levels = if quick { s.levels.len().min(expected_spec.levels) } else { s.levels.len() };
        if f.levels.len() != expected_levels {
            out.push(row(study, id, None, "levels", expected_levels.to_string(), f.levels.len().to_string(), None, "exact".into()));
        }
        check_derived_fields(study, id, "stored", &s.levels, &mut out);
        check_derived_fields(study, id, "fresh", &f.levels, &mut out);
        compare_histories(study, s, f, &mut out);
        let stored_levels: Vec<Value> = s.levels.iter().map(|l| serde_json::to_value(l).expect("records serialise")).collect();
        let scales = field_scales(&stored_levels);
        for l in 0..n_compare {
            let (sl, fl) = (stored_levels.get(l), f.levels.get(l));
            match (sl, fl) {
                (Some(a), Some(b)) => {
                    let b = serde_json::to_value(b).expect("records serialise");
                    compare_level(study, id, l, a, &b, &scales, &manifest.drift, &mut out, &mut changes);
                }
                (a, b) => out.push(row(
                    study,
                    id,
                    Some(l),
                    "level",
                    if a.is_some() { "present" } else { "(missing)" }.into(),
                    if b.is_some() { "present" } else { "(missing)" }.into(),
                    None,
                    "exact".into(),
                )),
            }
        }
    }
    for r in stored.iter().chain(fresh) {
        if !manifest.runs.iter().any(|p| p.spec.id == r.run.id) && !out.iter().any(|d| d.run == r.run.id) {
            out.push(row(study, &r.run.id, None, "run", "not in the manifest".into(), "-".into(), None, "exact".into()));
        }
    }
    for floor in &manifest.drift.rates {
        if let Some(f) = fresh.iter().find(|r| r.run.id == floor.run) {
            let last = floor.last.min(f.levels.len());
            match observed_rate(f, &floor.field, last) {
                Some(rate) if rate >= floor.min => {}
                rate => out.push(row(
                    study,
                    &floor.run,
                    None,
                    &format!("rate of {} (last {last} levels)", floor.field),
                    format!(">= {}", floor.min),
                    rate.map(|r| format!("{r:.3}")).unwrap_or("(not computable)".into()),
                    None,
                    "one-sided floor".into(),
                )),
            }
        }
    }
    DriftComparison { rows: out, changes }
}

/// The refinement histories of a stored and a fresh run, exactly, as far as the fresh run went
/// (a quick form is a prefix): one row at the first level whose mesh, marks or warm start differ.
fn compare_histories(study: &str, stored: &RunRecord, fresh: &RunRecord, out: &mut Vec<DriftRow>) {
    let id = &stored.run.id;
    let (s, f) = match (&stored.history, &fresh.history) {
        (Some(s), Some(f)) => (s, f),
        (None, None) => return,
        (s, f) => {
            let text =
                |h: Option<&model::level::history::History>| h.map_or("(missing)".to_string(), |h| format!("{} levels", h.levels.len()));
            out.push(row(study, id, None, "history", text(s.as_ref()), text(f.as_ref()), None, "exact".into()));
            return;
        }
    };
    if let Some((level, field, sv, fv)) = first_history_difference(s, f) {
        out.push(row(study, id, Some(level), &format!("history.{field}"), sv, fv, None, "exact".into()));
    }
}

/// The first level at which two refinement histories differ, as far as the shorter goes: the
/// level, what differs (`mesh`, `marks`, `initial_active`) and the two sides, for a row.
fn first_history_difference(
    s: &model::level::history::History,
    f: &model::level::history::History,
) -> Option<(usize, &'static str, String, String)> {
    s.levels.iter().zip(&f.levels).find_map(|(a, b)| {
        if a.mesh != b.mesh || a.n_elements != b.n_elements {
            Some((a.level, "mesh", format!("{} elements, {}", a.n_elements, a.mesh), format!("{} elements, {}", b.n_elements, b.mesh)))
        } else if a.marks != b.marks {
            Some((a.level, "marks", "stored marks".into(), "other marks".into()))
        } else if a.initial_active != b.initial_active {
            Some((a.level, "initial_active", "stored warm start".into(), "another warm start".into()))
        } else {
            None
        }
    })
}

/// The reference solutions of a study's runs, stored against fresh (`references/KEY.json`):
/// each present on both sides with the same refinement history, level for level, and the same
/// NDF. Rows under run `reference KEY`. (Without `--deep` the fresh side is the stored one
/// rebuilt in one solve, its meshes checked by their fingerprints on the way, so only a missing
/// file shows here; `--deep` computes it by the adaptive loop and compares every level.) Against
/// another folder (`against`), whose files no replay checks, the record of the last level is
/// compared too, as levels are (the fields a one-solve replay cannot give left out), and the
/// final active set exactly (a hand-edited `last.eta_h` there is a drift, never "none").
fn compare_references(study: &str, stored: &Store, fresh: &Store, runs: &[RunRecord], spec: &DriftSpec, against: bool) -> Vec<DriftRow> {
    let mut out = Vec::new();
    let keys: std::collections::BTreeSet<String> = runs.iter().filter_map(|r| ::store::records::ReferenceRecord::key_of(&r.run)).collect();
    let describe = |r: &Option<::store::records::ReferenceRecord>| {
        r.as_ref().map_or("(missing)".to_string(), |r| format!("NDF {} after {} levels", r.rebuild.ndof, r.rebuild.history.levels.len()))
    };
    for key in keys {
        let label = format!("reference {key}");
        let (s, f) = (stored.reference(&key).ok().flatten(), fresh.reference(&key).ok().flatten());
        match (&s, &f) {
            (Some(a), Some(b)) => {
                if let Some((level, field, sv, fv)) = first_history_difference(&a.rebuild.history, &b.rebuild.history) {
                    out.push(row(study, &label, Some(level), &format!("history.{field}"), sv, fv, None, "exact".into()));
                } else if a.rebuild.ndof != b.rebuild.ndof || a.rebuild.history.levels.len() != b.rebuild.history.levels.len() {
                    out.push(row(study, &label, None, "history", describe(&s), describe(&f), None, "exact".into()));
                } else if against {
                    for r in level_differences(&a.rebuild.last, &b.rebuild.last, spec, NOT_REPLAYED) {
                        out.push(DriftRow { study: study.to_string(), run: label.clone(), field: format!("last.{}", r.field), ..r });
                    }
                    if a.rebuild.final_active != b.rebuild.final_active {
                        out.push(row(study, &label, None, "final_active", "stored set".into(), "another set".into(), None, "exact".into()));
                    }
                }
            }
            _ => out.push(row(study, &label, None, "history", describe(&s), describe(&f), None, "exact".into())),
        }
    }
    out
}

/// The last level of a run of a deep study's replay tier, solved again from its stored history
/// (by the worker that reruns the study, [`rerun_all`]) for [`replay_tier`] to compare.
struct Replayed {
    id: String,
    level: usize,
    solved: anyhow::Result<LevelRecord>,
}

/// The replay tier's solves of a deep study in its tiers: the last level of every run in
/// `[drift.deep] replay` (the last with at most `replay_max_ndof` unknowns where that is given),
/// rebuilt from its stored history and solved once more ([`super::replay_stored_level`]).
fn replay_solves(manifest: &Manifest, results: &Path, progress: bool) -> anyhow::Result<Vec<Replayed>> {
    let Some(tier) = &manifest.drift.deep else { return Ok(Vec::new()) };
    let stored = Store::of(results, manifest).check()?.runs;
    let mut out = Vec::new();
    for id in &tier.replay {
        let Some(s) = stored.iter().find(|r| &r.run.id == id) else { continue }; // a missing run is a row already
        let Some(level) = s.levels.iter().rposition(|l| tier.replay_max_ndof.is_none_or(|m| l.ndof <= m)) else { continue };
        if progress {
            model::base::note::line(format_args!(
                "{}/{id}: replaying level {level} (NDF {}) from the stored refinement history",
                manifest.study, s.levels[level].ndof
            ));
        }
        let solved = super::replay_stored_level(manifest, s, level, progress).map(|solved| solved.record);
        out.push(Replayed { id: id.clone(), level, solved });
    }
    Ok(out)
}

/// The replay tier of a deep study in its tiers: each level [`replay_solves`] solved again,
/// against its stored record (rows under run `ID (replayed)`). A history that does not rebuild
/// its meshes is a row of field `history`.
fn replay_tier(manifest: &Manifest, stored: &[RunRecord], replayed: Vec<Replayed>, c: &mut DriftComparison) -> anyhow::Result<()> {
    let study = &manifest.study;
    for Replayed { id, level, solved } in replayed {
        let label = format!("{id} (replayed)");
        let Some(s) = stored.iter().find(|r| r.run.id == id) else { continue };
        match solved {
            Ok(record) => {
                let stored_levels: Vec<Value> = s.levels.iter().map(|l| serde_json::to_value(l).expect("records serialise")).collect();
                let scales = field_scales(&stored_levels);
                let fresh = serde_json::to_value(&record).expect("records serialise");
                compare_level(study, &label, level, &stored_levels[level], &fresh, &scales, &manifest.drift, &mut c.rows, &mut c.changes);
            }
            Err(e) => {
                let replay = e.chain().find_map(|c| match c.downcast_ref::<numerics::adapt::AdaptError>() {
                    Some(numerics::adapt::AdaptError::Replay(r)) => Some(r.to_string()),
                    _ => c.downcast_ref::<numerics::adapt::replay::ReplayError>().map(|r| r.to_string()),
                });
                match replay {
                    Some(why) => c.rows.push(row(
                        study,
                        &label,
                        Some(level),
                        "history",
                        "replays the stored meshes".into(),
                        why,
                        None,
                        "exact".into(),
                    )),
                    None => return Err(e),
                }
            }
        }
    }
    Ok(())
}

/// A readable table of what moved.
pub fn table(rows: &[DriftRow]) -> String {
    let mut s = format!(
        "{:<22} {:<34} {:>5} {:<20} {:>24} {:>24} {:>10} {}\n",
        "study", "run", "level", "field", "stored", "fresh", "rel.change", "tolerance"
    );
    for r in rows {
        s += &format!(
            "{:<22} {:<34} {:>5} {:<20} {:>24} {:>24} {:>10} {}\n",
            r.study,
            r.run,
            r.level.map(|l| l.to_string()).unwrap_or("-".into()),
            r.field,
            r.stored,
            r.fresh,
            r.relative_change.map(|v| format!("{v:.2e}")).unwrap_or("-".into()),
            r.tolerance
        );
    }
    s
}

use store::first_difference;

/// The views of a study's stored records, checked against what the records render
/// ([`store::check::summary_faults`]): `levels.csv` byte for byte and `provenance.json`'s
/// list of runs. A hand edit, a bad merge or a study interrupted before its summaries were
/// rewritten is drift.
pub fn check_derived(store: &Store, runs: &[RunRecord]) -> Vec<DriftRow> {
    store::check::summary_faults(store.dir(), store.study(), runs).iter().map(|f| fault_row(store, f)).collect()
}

/// A fault of the stored folder ([`store::Store::check`]) as a row of drift: the file
/// (relative to the study folder) and what is wrong with it.
fn fault_row(store: &Store, f: &store::Fault) -> DriftRow {
    let (study, dir) = (store.study(), store.dir());
    let file = f.file.strip_prefix(&dir.root).unwrap_or(&f.file).display().to_string();
    let field = if f.record.is_some() { "store".to_string() } else { file.clone() };
    row(
        study,
        f.record.as_deref().unwrap_or("*"),
        None,
        &field,
        format!("{file} {}", f.what),
        "a folder that holds together".into(),
        None,
        "exact (the store's integrity check)".into(),
    )
}

/// What a drift run compares the stored results with.
#[derive(Clone, Debug)]
pub struct DriftOptions {
    /// Rerun the quick forms (prefixes of the stored runs) instead of the full studies.
    pub quick: bool,
    /// Rerun deep studies ([`manifest::DeepTier`]) to the end; without it they are rerun
    /// in their tiers.
    pub deep: bool,
    /// Compare with the records already in this results folder instead of rerunning (how
    /// round-off is measured: the studies rerun with another ordering or thread count).
    pub against: Option<PathBuf>,
    /// Where fresh runs are written (emptied first, study by study).
    pub scratch: PathBuf,
    pub results: PathBuf,
    pub progress: bool,
}

/// The outcome of a drift run over some studies.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DriftReport {
    pub date: String,
    pub quick: bool,
    pub against: Option<String>,
    /// Per study: runs compared and rows of drift.
    pub studies: Vec<Value>,
    pub rows: Vec<DriftRow>,
    /// Per study, per float field: the largest change seen (drift or not).
    pub changes: BTreeMap<String, BTreeMap<String, FieldChange>>,
    /// With `against`: the declared studies the folder does not hold, which were not compared.
    #[serde(default)]
    pub not_compared: Vec<String>,
    /// `against` is the stored results folder itself (the same folder by another path, a
    /// symlink): every record was compared with itself. That checks the folder's readers, not
    /// its numbers, and a study page never quotes it as a rerun.
    #[serde(default)]
    pub self_comparison: bool,
    /// With `against`: the studies whose records there are byte-identical to the stored ones,
    /// timings (`t_*`) included ([`compared_a_copy`](::store::study::compared_a_copy)): a copy of the stored folder, not a rerun.
    #[serde(default)]
    pub copies: Vec<String>,
}

/// Whether `against` and `results` are one folder (after resolving symlinks and `.`/`..`).
pub fn same_folder(against: &Path, results: &Path) -> bool {
    matches!((against.canonicalize(), results.canonicalize()), (Ok(a), Ok(r)) if a == r)
}

impl DriftReport {
    /// The studies this report checked (its `studies` entries' names).
    pub fn checked(&self) -> Vec<String> {
        self.studies.iter().filter_map(|s| s.get("study").and_then(Value::as_str).map(str::to_string)).collect()
    }

    /// `older` (a report as JSON, other studies' entries kept byte for byte and in their order)
    /// with this report's studies in place of theirs: their `studies` entries (each with this
    /// report's date), rows and changes replaced, a study it did not hold added at the end
    /// (a round-off measurement of some studies merged into the reports of all of them). The
    /// other top-level fields stay `older`'s.
    pub fn merged_into(&self, mut older: Value) -> serde_json::Result<Value> {
        let mine = self.checked();
        let ours = |v: &Value| v.get("study").and_then(Value::as_str).is_some_and(|s| mine.iter().any(|m| m == s));
        let mut fresh = Vec::new();
        for entry in &self.studies {
            let mut e = entry.clone();
            if let Some(o) = e.as_object_mut() {
                o.insert("date".into(), Value::String(self.date.clone()));
            }
            fresh.push(e);
        }
        let mut studies: Vec<Value> = older.get("studies").and_then(Value::as_array).cloned().unwrap_or_default();
        for e in fresh {
            match studies.iter().position(|o| o.get("study") == e.get("study")) {
                Some(i) => studies[i] = e,
                None => studies.push(e),
            }
        }
        let mut rows: Vec<Value> = older.get("rows").and_then(Value::as_array).cloned().unwrap_or_default();
        rows.retain(|r| !ours(r));
        rows.extend(self.rows.iter().map(serde_json::to_value).collect::<serde_json::Result<Vec<_>>>()?);
        let mut changes = older.get("changes").and_then(Value::as_object).cloned().unwrap_or_default();
        for (study, fields) in &self.changes {
            changes.insert(study.clone(), serde_json::to_value(fields)?);
        }
        if let Some(o) = older.as_object_mut() {
            o.insert("studies".into(), Value::Array(studies));
            o.insert("rows".into(), Value::Array(rows));
            o.insert("changes".into(), Value::Object(changes));
        }
        Ok(older)
    }
}

/// "a, b" or "none".
fn listed(names: &[String]) -> String {
    if names.is_empty() { "none".into() } else { names.join(", ") }
}

/// The studies a comparison `against` a folder covers: those of `manifests` the folder holds
/// (with `named`, the studies were named one by one and each must be there), and the names of
/// those it does not. A folder holding none of them is an error: there is nothing to compare.
pub fn select_against(dir: &Path, manifests: &[Manifest], named: bool) -> anyhow::Result<(Vec<Manifest>, Vec<String>)> {
    let held = ::store::study::held_by(dir, manifests).map_err(|e| anyhow::anyhow!("--against {}: {e}", dir.display()))?;
    if named && !held.absent.is_empty() {
        anyhow::bail!(
            "--against {}: the folder does not hold {} (it holds: {}); nothing of {} to compare",
            dir.display(),
            held.absent.join(", "),
            listed(&held.present.iter().map(|m| m.study.clone()).chain(held.undeclared.clone()).collect::<Vec<_>>()),
            if held.absent.len() == 1 { "it" } else { "theirs" }
        );
    }
    if held.present.is_empty() {
        anyhow::bail!(
            "--against {}: nothing to compare: the folder holds none of the declared studies ({}); its folders: {}. Rerun a study into it with `signorini run experiments/STUDY.toml --results {}`",
            dir.display(),
            manifests.iter().map(|m| m.study.as_str()).collect::<Vec<_>>().join(", "),
            listed(&held.undeclared),
            dir.display()
        );
    }
    Ok((held.present, held.absent))
}

/// The provenance of a study in `fresh` against the stored one: the manifest, problem files and
/// meshes the runs were made with (by hash). Records made from an edited manifest or problem
/// file differ even where every number agrees.
pub fn compare_provenance(study: &str, stored: &Store, fresh: &Store) -> Vec<DriftRow> {
    use provenance::Provenance;
    let read = |d: &Store| d.provenance().ok();
    let tol = "exact (what the runs were made with)";
    let (Some(s), Some(f)) = (read(stored), read(fresh)) else {
        // a stored provenance that cannot be read is drift of the store already (check_derived)
        return match read(fresh) {
            None => vec![row(
                study,
                "*",
                None,
                "provenance.json",
                "present".into(),
                format!("(missing or unreadable: {})", fresh.dir().provenance_file().display()),
                None,
                tol.into(),
            )],
            Some(_) => Vec::new(),
        };
    };
    let mut out = Vec::new();
    if s.manifest_sha256 != f.manifest_sha256 {
        let text = |p: &Provenance| format!("{} (sha256 {})", p.manifest, &p.manifest_sha256[..p.manifest_sha256.len().min(12)]);
        out.push(row(study, "*", None, "manifest_sha256", text(&s), text(&f), None, tol.into()));
    }
    let hashes = |mut v: Vec<String>| {
        v.sort();
        v.join(" ")
    };
    let problems = |p: &Provenance| hashes(p.problem_files.iter().map(|f| f.sha256.clone().unwrap_or("(unreadable)".into())).collect());
    if problems(&s) != problems(&f) {
        out.push(row(study, "*", None, "problem file sha256", problems(&s), problems(&f), None, tol.into()));
    }
    let meshes = |p: &Provenance| hashes(p.mesh_sha256.values().cloned().collect());
    if meshes(&s) != meshes(&f) {
        out.push(row(study, "*", None, "mesh_sha256", meshes(&s), meshes(&f), None, tol.into()));
    }
    out
}

/// Rerun (or read, with `against`) every manifest's study and compare it with the stored
/// results: numbers within the manifests' tolerances and the derived files. `claims` renders
/// `CLAIMS.md` from the results folder; it is compared with the stored file when every
/// declared study is checked (not with `against`, which compares another folder's records).
///
/// With `against`, the studies compared are those the folder holds ([`select_against`]; with
/// `all_studies` false the manifests were named and each must be there), the others are listed
/// in [`DriftReport::not_compared`], and the provenance of each study (manifest, problem files
/// and meshes, by hash) must match the stored one ([`compare_provenance`]). Without it, every
/// run of every manifest is checked ([`Manifest::check_runs`]) before any is rerun.
pub fn check(
    manifests: &[Manifest],
    all_studies: bool,
    opts: &DriftOptions,
    claims: &dyn Fn(&Path) -> std::io::Result<String>,
) -> anyhow::Result<DriftReport> {
    use anyhow::Context;
    stored_root(&opts.results)?;
    let (manifests, not_compared) = match &opts.against {
        Some(dir) => select_against(dir, manifests, !all_studies)?,
        None => {
            for m in manifests {
                m.check_runs()?;
            }
            (manifests.to_vec(), Vec::new())
        }
    };
    let mut report = DriftReport {
        date: provenance::utc_now(),
        quick: opts.quick,
        against: opts.against.as_ref().map(|p| p.display().to_string()),
        studies: Vec::new(),
        rows: Vec::new(),
        changes: BTreeMap::new(),
        not_compared,
        self_comparison: opts.against.as_deref().is_some_and(|a| same_folder(a, &opts.results)),
        copies: Vec::new(),
    };
    // a deep study in its tiers (unless --deep): quick forms, some runs to the end
    let planned: Vec<(Manifest, bool)> = manifests
        .iter()
        .map(|m| if opts.against.is_some() { (m.clone(), opts.quick) } else { m.for_drift(opts.quick, opts.deep) })
        .collect();
    // held until the comparisons end: another drift in this checkout waits rather than
    // starting over the reruns this one compares
    let _scratch = if opts.against.is_none() { Some(store::scratch_folder(&opts.scratch)?) } else { None };
    for (m, _) in &planned {
        let stored = Store::of(&opts.results, m);
        if let Some(why) = stored.provenance().ok().and_then(|p| provenance::history_fault_of(&p, &m.file)) {
            anyhow::bail!(
                "{}: {why}. The drift check compares with results of known code; rerun the study on a commit of this history (`signorini drift --accept {}`) and commit its results",
                stored.dir().root.display(),
                m.study
            );
        }
    }
    let mut replayed = if opts.against.is_none() { rerun_all(&planned, opts)? } else { Vec::new() };
    replayed.resize_with(planned.len(), Vec::new);
    for ((m, quick), replayed) in planned.iter().zip(replayed) {
        let fresh_root = opts.against.clone().unwrap_or_else(|| opts.scratch.clone());
        let stored_store = Store::of(&opts.results, m);
        let fresh_store = Store::of(&fresh_root, m);
        let checked = stored_store.check().with_context(|| format!("reading the stored runs of {}", m.study))?;
        stored_store.note_leftovers(&checked.leftovers);
        let stored = checked.runs;
        let fresh = match &opts.against {
            // another folder's records are read through the same check; a fault there is an error
            Some(_) => fresh_store.read().with_context(|| format!("--against {}: the study {}", fresh_root.display(), m.study))?,
            None => fresh_store.records().with_context(|| format!("reading the fresh runs of {} in {}", m.study, fresh_root.display()))?,
        };
        let mut c = compare(m, &stored, &fresh, *quick);
        replay_tier(m, &stored, replayed, &mut c)?;
        c.rows.extend(checked.faults.iter().map(|f| fault_row(&stored_store, f)));
        c.rows.extend(compare_references(&m.study, &stored_store, &fresh_store, &stored, &m.drift, opts.against.is_some()));
        if opts.against.is_some() {
            c.rows.extend(compare_provenance(&m.study, &stored_store, &fresh_store));
        }
        if opts.progress {
            model::base::note::line(format_args!(
                "{}: {}",
                m.study,
                if c.rows.is_empty() { "no drift".to_string() } else { format!("{} field(s) moved", c.rows.len()) }
            ));
        }
        // the records compared, by hash: a page quoting this report checks that it shows them
        let hashes = |runs: &[RunRecord]| -> BTreeMap<String, String> {
            runs.iter().map(|r| (r.run.id.clone(), ::store::records::record_sha256(r))).collect()
        };
        let mut entry =
            serde_json::json!({ "study": m.study, "runs": fresh.len(), "drift": c.rows.len(), "quick": quick, "records": hashes(&stored) });
        if opts.against.is_some() {
            entry["against_records"] = serde_json::to_value(hashes(&fresh))?;
            if ::store::study::compared_a_copy(&entry) {
                report.copies.push(m.study.clone());
            }
        }
        report.studies.push(entry);
        report.rows.extend(c.rows);
        report.changes.insert(m.study.clone(), c.changes);
    }
    if all_studies && opts.against.is_none() {
        let file = opts.results.join("CLAIMS.md");
        // through the results folder's one reader: a pipe or a device there is named, not read
        let stored = match ::store::records::read_text(&file) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
            Err(e) => format!("(unreadable: {e})"),
        };
        let rendered = claims(&opts.results).with_context(|| format!("rendering {}", file.display()))?;
        if stored != rendered {
            let (a, b) = first_difference(&stored, &rendered);
            report.rows.push(row("*", "*", None, "CLAIMS.md", a, b, None, "exact (rendered from results/)".into()));
        }
    }
    Ok(report)
}

/// Rerun every planned study (each with its quick flag) into the scratch folder, [`RERUN_AT_ONCE`]
/// studies at a time, and solve the replay tiers' levels again (returned per study, for
/// [`replay_tier`]). The large solves, the stored reference solutions replayed (`--deep`
/// computes them anew in their runs instead) and the replay tiers' levels, are the first
/// worker's tasks before it takes studies, one at a time ([`super::one_large_solve`]: each
/// alone among the large ones in memory), while the other worker reruns the studies that need
/// no reference. Each study has its own folder and locks, and a run's numbers do not depend on
/// the threads that compute it (the round-off measurement of one thread against all finds no
/// change), so the records are the same as one study at a time; the comparisons follow, one
/// study at a time, in the manifests' order. The first error in that order is returned, after
/// the tasks under way have ended.
fn rerun_all(planned: &[(Manifest, bool)], opts: &DriftOptions) -> anyhow::Result<Vec<Vec<Replayed>>> {
    use std::sync::Mutex;
    let workers = if rayon::current_num_threads() >= 2 { RERUN_AT_ONCE } else { 1 };
    let failed = std::sync::atomic::AtomicBool::new(false);
    let with_reference = |i: &usize| planned[*i].0.runs.iter().any(|r| r.spec.reference.is_some());
    // the large solves, one at a time (the lock in `super::one_large_solve`), by the first worker
    // before it takes studies: the stored references, then the replay tiers' levels
    let mut large: Vec<Task> = (0..planned.len()).filter(|i| !opts.deep && with_reference(i)).map(Task::References).collect();
    large.extend((0..planned.len()).filter(|&i| planned[i].1 && !opts.quick && planned[i].0.drift.deep.is_some()).map(Task::Replay));
    // the studies whose runs need no reference first, while the references are rebuilt
    let (mut studies, needing): (Vec<usize>, Vec<usize>) = (0..planned.len()).partition(|i| !with_reference(i));
    studies.extend(needing);
    let studies = Mutex::new(studies.into_iter().map(Task::Study).collect::<std::collections::VecDeque<Task>>());
    let large = Mutex::new(std::collections::VecDeque::from(large));
    type Outcome = Mutex<Option<anyhow::Result<Vec<Replayed>>>>;
    let outcomes: Vec<Outcome> = planned.iter().map(|_| Mutex::new(Some(Ok(Vec::new())))).collect();
    let run = |task: Task| -> anyhow::Result<()> {
        match task {
            Task::References(i) => super::preload_references(&planned[i].0, &Store::new(&opts.results, &planned[i].0.study), opts.progress),
            Task::Study(i) => {
                let m = &planned[i].0;
                if !opts.deep {
                    super::preload_references(m, &Store::new(&opts.results, &m.study), opts.progress)?;
                }
                rerun(m, planned[i].1, opts)
            }
            Task::Replay(i) => {
                let m = &planned[i].0;
                // its references first (from the cache), so the replay does not wait for itself
                super::preload_references(m, &Store::new(&opts.results, &m.study), opts.progress)?;
                let replayed = {
                    let _large = super::one_large_solve();
                    replay_solves(m, &opts.results, opts.progress)?
                };
                let mut slot = outcomes[i].lock().unwrap_or_else(|e| e.into_inner());
                if let Some(Ok(r)) = slot.as_mut() {
                    r.extend(replayed);
                }
                Ok(())
            }
        }
    };
    std::thread::scope(|scope| {
        for worker in 0..workers {
            let (run, failed, large, studies, outcomes) = (&run, &failed, &large, &studies, &outcomes);
            scope.spawn(move || {
                use std::sync::atomic::Ordering::SeqCst;
                let next = || {
                    let from_large = if worker == 0 { large.lock().unwrap_or_else(|e| e.into_inner()).pop_front() } else { None };
                    from_large.or_else(|| studies.lock().unwrap_or_else(|e| e.into_inner()).pop_front())
                };
                while let Some(task) = next() {
                    if failed.load(SeqCst) {
                        return;
                    }
                    let i = task.study();
                    if let Err(e) = run(task) {
                        failed.store(true, SeqCst);
                        *outcomes[i].lock().unwrap_or_else(|e| e.into_inner()) = Some(Err(e));
                    }
                }
            });
        }
    });
    let mut replayed = Vec::new();
    for o in outcomes {
        match o.into_inner().unwrap_or_else(|e| e.into_inner()) {
            Some(Err(e)) => return Err(e),
            Some(Ok(r)) => replayed.push(r),
            None => replayed.push(Vec::new()),
        }
    }
    Ok(replayed)
}

/// A piece of a drift run's reruns, of the study at an index of the planned ones.
#[derive(Clone, Copy)]
enum Task {
    /// Its stored reference solutions rebuilt into the process's cache.
    References(usize),
    /// Its runs rerun into the scratch folder (its references taken from the cache, or rebuilt).
    Study(usize),
    /// The levels of its replay tier solved again.
    Replay(usize),
}

impl Task {
    fn study(self) -> usize {
        match self {
            Task::References(i) | Task::Study(i) | Task::Replay(i) => i,
        }
    }
}

/// How many studies a drift run reruns at once on a machine with two threads or more. On the
/// 2-core machine the gain is small (a fresh clone's drift: 409 s against 417 s one at a time;
/// a single small run already keeps the cores about 150% busy): two at once fill the rest;
/// more would add memory without adding cores.
pub const RERUN_AT_ONCE: usize = 2;

/// One study's runs rerun into the scratch folder (started over), in its tiers.
fn rerun(m: &Manifest, quick: bool, opts: &DriftOptions) -> anyhow::Result<()> {
    if opts.progress && quick && !opts.quick {
        let (full, replay) = m.drift.deep.as_ref().map(|t| (t.full.join(", "), t.replay.join(", "))).unwrap_or_default();
        let mut tiers = vec!["every run rerun in its quick form".to_string()];
        if !full.is_empty() {
            tiers.push(format!("{full} to the end"));
        }
        if !replay.is_empty() {
            tiers.push(format!("the last level of {replay} replayed from its history"));
        }
        model::base::note::line(format_args!("{}: a deep study: {} (all to the end: drift --deep)", m.study, tiers.join(", ")));
    }
    let options = super::RunOptions {
        quick,
        shard: None,
        fresh: true,
        replace: false,
        results: opts.scratch.clone(),
        progress: opts.progress,
        wait_for_lock: true,
    };
    super::run_study(m, &options)?;
    Ok(())
}

/// The stored results folder a drift run compares with must be a folder, checked before any
/// study is compared or rerun: one that does not exist (drift run from another folder than the
/// repository's) made every run "no stored results", a drift, with advice to rerun into the
/// folder compared.
fn stored_root(results: &Path) -> anyhow::Result<()> {
    if results.is_dir() {
        return Ok(());
    }
    let relative = if results.is_relative() { " (relative to the current folder)" } else { "" };
    let what = if results.exists() { "is not a folder" } else { "does not exist" };
    anyhow::bail!("no stored results folder `{}`{relative}: it {what}; pass --results DIR", results.display())
}

/// The largest change of every float field over the studies of a report, as a table.
pub fn changes_table(report: &DriftReport) -> String {
    let mut by_field: BTreeMap<&str, (f64, f64, String)> = BTreeMap::new();
    for (study, fields) in &report.changes {
        for (field, c) in fields {
            let e = by_field.entry(field).or_insert((0.0, 0.0, String::new()));
            if c.max_rel >= e.0 {
                e.2 = format!("{study} {}", c.at);
            }
            e.0 = e.0.max(c.max_rel);
            e.1 = e.1.max(c.max_floor);
        }
    }
    let mut s = format!("{:<16} {:>12} {:>12}  {}\n", "field", "max rel", "max/scale", "where (max rel)");
    for (field, (rel, floor, at)) in by_field {
        let at = if rel > 0.0 { at.as_str() } else { "-" };
        s += &format!("{field:<16} {rel:>12.2e} {floor:>12.2e}  {at}\n");
    }
    s
}

/// The factor between the largest change round-off was measured to make and the tolerance.
pub const MARGIN: f64 = 10.0;
/// The least relative tolerance of any float field, also of those that never moved in the
/// measurement (h_min, l_h, ...): a few units in the last place, for a libm that rounds
/// `log` or `sqrt` differently on another machine.
pub const MIN_REL: f64 = 1e-12;

/// Round up to one significant digit (2.3e-7 -> 3e-7), as the decimal the manifest will hold.
fn round_up(x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let p = 10f64.powf(x.log10().floor());
    let digit = (x / p).ceil();
    // through the decimal text, so the value is the double a manifest saying it parses to
    format!("{digit}e{}", x.log10().floor()).parse().expect("a decimal number")
}

/// The tolerances round-off asks for, per study and float field, from the reports of
/// `make roundoff` (each a comparison of the stored results with one rerun that changes only
/// the order of operations): rel = MARGIN x the largest `max_rel`, floor = MARGIN x the largest
/// `max_floor` over the reports, rounded up to one significant digit; rel at least MIN_REL.
/// Derived fields and the [`ORDER_OF_MAGNITUDE`] ones are left out.
pub fn measured_tolerances(reports: &[DriftReport]) -> BTreeMap<String, BTreeMap<String, Tolerance>> {
    let mut out: BTreeMap<String, BTreeMap<String, Tolerance>> = BTreeMap::new();
    for r in reports {
        for (study, fields) in &r.changes {
            for (field, c) in fields.iter().filter(|(f, _)| !is_derived(f) && !ORDER_OF_MAGNITUDE.contains(&f.as_str())) {
                let t = out.entry(study.clone()).or_default().entry(field.clone()).or_insert(Tolerance { rel: 0.0, floor: 0.0 });
                t.rel = t.rel.max(c.max_rel);
                t.floor = t.floor.max(c.max_floor);
            }
        }
    }
    for fields in out.values_mut() {
        for t in fields.values_mut() {
            *t = Tolerance { rel: round_up(MARGIN * t.rel).max(MIN_REL), floor: round_up(MARGIN * t.floor) };
        }
    }
    out
}

/// A study's measured tolerances as the manifest's `[drift]` table.
pub fn tolerances_toml(fields: &BTreeMap<String, Tolerance>) -> String {
    let mut s = String::from("[drift]\ndefault = { rel = 1e-12, floor = 0.0 }   # fields not listed: they did not move\n[drift.fields]\n");
    for (f, t) in fields.iter().filter(|(_, t)| **t != Tolerance { rel: MIN_REL, floor: 0.0 }) {
        let num = |v: f64| if v == 0.0 { "0.0".to_string() } else { format!("{v:e}") };
        s += &format!("{f} = {{ rel = {}, floor = {} }}\n", num(t.rel), num(t.floor));
    }
    s
}
