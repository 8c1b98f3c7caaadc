//! The drift check: fresh records against stored ones, field by field (in the spirit of numdiff
//! and pytest-regressions' num_regression).
//!
//! Integers and structural fields (NDF, levels, active-set sizes, iteration counts, the run's
//! spec) must match exactly; floats within the manifest's per-field tolerance
//! |fresh - stored| <= abs + rel |stored|; observed rates (least-squares slope of -log(field) in
//! log(NDF) over a run's last levels) against one-sided floors; timings (fields `t_*`) never.
//! A level, field, run or study missing on either side is drift too. In the quick form the fresh
//! runs are prefixes of the stored full runs and are compared level by level.

use super::manifest::{DriftSpec, Manifest};
use crate::records::RunRecord;
use serde::Serialize;
use serde_json::Value;

/// One thing that moved.
#[derive(Clone, Debug, PartialEq, Serialize)]
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

fn row(study: &str, run: &str, level: Option<usize>, field: &str, stored: String, fresh: String, rel: Option<f64>, tol: String) -> DriftRow {
    DriftRow { study: study.into(), run: run.into(), level, field: field.into(), stored, fresh, relative_change: rel, tolerance: tol }
}

fn show(v: Option<&Value>) -> String {
    match v {
        None => "(missing)".into(),
        Some(Value::Null) => "null".into(),
        Some(v) => v.to_string(),
    }
}

/// Compare two level records (as JSON objects), appending what moved.
fn compare_level(study: &str, run: &str, level: usize, stored: &Value, fresh: &Value, spec: &DriftSpec, out: &mut Vec<DriftRow>) {
    let (Some(s), Some(f)) = (stored.as_object(), fresh.as_object()) else { return };
    let mut keys: Vec<&String> = s.keys().chain(f.keys()).collect();
    keys.sort();
    keys.dedup();
    for key in keys {
        if key.starts_with("t_") {
            continue; // timings are never compared
        }
        let (sv, fv) = (s.get(key), f.get(key));
        let drift = |rel: Option<f64>, tol: String| row(study, run, Some(level), key, show(sv), show(fv), rel, tol);
        match (sv, fv) {
            (Some(Value::Number(a)), Some(Value::Number(b))) if a.is_f64() || b.is_f64() => {
                let (a, b) = (a.as_f64().unwrap_or(f64::NAN), b.as_f64().unwrap_or(f64::NAN));
                let tol = spec.tolerance(key);
                let diff = (a - b).abs();
                if !(diff <= tol.abs + tol.rel * a.abs()) {
                    let rel = if a != 0.0 { Some(diff / a.abs()) } else { None };
                    out.push(drift(rel, format!("rel {:e}, abs {:e}", tol.rel, tol.abs)));
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
    let n = pts.len() as f64;
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    Some(-sxy / sxx)
}

/// Compare a study's fresh runs with its stored runs. `quick`: fresh runs are the quick forms
/// (prefixes) of the stored full runs.
pub fn compare_study(manifest: &Manifest, stored: &[RunRecord], fresh: &[RunRecord], quick: bool) -> Vec<DriftRow> {
    let study = &manifest.study;
    let mut out = Vec::new();
    if stored.is_empty() {
        out.push(row(study, "*", None, "study", "(no stored results)".into(), format!("{} runs", fresh.len()), None, "exact".into()));
        return out;
    }
    for planned in &manifest.runs {
        let id = &planned.spec.id;
        let (s, f) = (stored.iter().find(|r| &r.run.id == id), fresh.iter().find(|r| &r.run.id == id));
        let (s, f) = match (s, f) {
            (Some(s), Some(f)) => (s, f),
            (s, f) => {
                out.push(row(study, id, None, "run", if s.is_some() { "present" } else { "(missing)" }.into(), if f.is_some() { "present" } else { "(missing)" }.into(), None, "exact".into()));
                continue;
            }
        };
        // the spec: the stored full spec, shortened to the quick form where quick
        let expected_spec = super::effective_spec(&super::manifest::PlannedRun { spec: s.run.clone(), quick_levels: planned.quick_levels }, quick);
        if expected_spec != f.run {
            out.push(row(study, id, None, "run spec", serde_json::to_string(&expected_spec).unwrap_or_default(), serde_json::to_string(&f.run).unwrap_or_default(), None, "exact".into()));
        }
        if s.reference_ndof != f.reference_ndof {
            out.push(row(study, id, None, "reference_ndof", format!("{:?}", s.reference_ndof), format!("{:?}", f.reference_ndof), None, "exact".into()));
        }
        let n_compare = if quick { f.levels.len() } else { s.levels.len().max(f.levels.len()) };
        let expected_levels = if quick { s.levels.len().min(expected_spec.levels) } else { s.levels.len() };
        if f.levels.len() != expected_levels {
            out.push(row(study, id, None, "levels", expected_levels.to_string(), f.levels.len().to_string(), None, "exact".into()));
        }
        for l in 0..n_compare {
            let (sl, fl) = (s.levels.get(l), f.levels.get(l));
            match (sl, fl) {
                (Some(a), Some(b)) => {
                    let (a, b) = (serde_json::to_value(a).expect("serialises"), serde_json::to_value(b).expect("serialises"));
                    compare_level(study, id, l, &a, &b, &manifest.drift, &mut out);
                }
                (a, b) => out.push(row(study, id, Some(l), "level", if a.is_some() { "present" } else { "(missing)" }.into(), if b.is_some() { "present" } else { "(missing)" }.into(), None, "exact".into())),
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
    out
}

/// A readable table of what moved.
pub fn table(rows: &[DriftRow]) -> String {
    let mut s = format!("{:<22} {:<34} {:>5} {:<20} {:>24} {:>24} {:>10} {}\n", "study", "run", "level", "field", "stored", "fresh", "rel.change", "tolerance");
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
