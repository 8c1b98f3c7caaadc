//! The drift check reports what moved, with the right row, and passes an unperturbed copy.

use signorini::records::{RunRecord, StudyDir};
use signorini::study::drift::{compare_study, observed_rate};
use signorini::study::manifest::Manifest;
use signorini::study::{self, RunOptions};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn manifest() -> Manifest {
    Manifest::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tiny.toml")).unwrap()
}

/// Full and quick runs of the tiny study, computed once.
fn stored_and_quick() -> &'static (Vec<RunRecord>, Vec<RunRecord>, Vec<RunRecord>) {
    static RUNS: OnceLock<(Vec<RunRecord>, Vec<RunRecord>, Vec<RunRecord>)> = OnceLock::new();
    RUNS.get_or_init(|| {
        let root: PathBuf = std::env::temp_dir().join(format!("signorini-drift-{}", std::process::id()));
        let m = manifest();
        let run = |quick: bool, sub: &str| {
            let results = root.join(sub);
            study::run_study(&m, &RunOptions { quick, shard: None, fresh: true, results: results.clone(), progress: false }).unwrap();
            StudyDir::new(&results, &m.study).read_runs().unwrap()
        };
        (run(false, "full"), run(true, "quick"), run(false, "full2"))
    })
}

#[test]
fn unperturbed_copies_pass_quick_and_full() {
    let (stored, quick, full2) = stored_and_quick();
    let m = manifest();
    assert_eq!(compare_study(&m, stored, quick, true), vec![]);
    assert_eq!(compare_study(&m, stored, full2, false), vec![]);
}

#[test]
fn perturbed_float_beyond_tolerance_is_reported_with_its_row() {
    let (stored, quick, _) = stored_and_quick();
    let mut s = stored.clone();
    s[0].levels[2].eta1 *= 1.0 + 1e-6; // tolerance is rel 1e-9 by default
    let rows = compare_study(&manifest(), &s, quick, true);
    assert_eq!(rows.len(), 1, "{rows:?}");
    let r = &rows[0];
    assert_eq!((r.run.as_str(), r.level, r.field.as_str()), ("a", Some(2), "eta1"));
    assert!((r.relative_change.unwrap() - 1e-6).abs() < 1e-9);
    // within tolerance: no drift
    let mut s = stored.clone();
    s[0].levels[2].eta1 *= 1.0 + 1e-12;
    assert!(compare_study(&manifest(), &s, quick, true).is_empty());
}

#[test]
fn changed_integer_is_reported_exactly() {
    let (stored, quick, _) = stored_and_quick();
    let mut s = stored.clone();
    s[1].levels[1].active_nodes += 1;
    let rows = compare_study(&manifest(), &s, quick, true);
    assert_eq!(rows.len(), 1, "{rows:?}");
    assert_eq!((rows[0].run.as_str(), rows[0].level, rows[0].field.as_str(), rows[0].tolerance.as_str()), ("b", Some(1), "active_nodes", "exact"));
}

#[test]
fn dropped_level_missing_run_and_timings() {
    let (stored, quick, full2) = stored_and_quick();
    let m = manifest();
    let mut s = stored.clone();
    s[0].levels.pop();
    let rows = compare_study(&m, &s, full2, false);
    assert!(rows.iter().any(|r| r.run == "a" && r.field == "levels"), "{rows:?}");
    assert!(rows.iter().any(|r| r.run == "a" && r.level == Some(4) && r.stored == "(missing)"), "{rows:?}");
    // in the quick form, a stored run shorter than the quick prefix is drift too
    let mut s = stored.clone();
    s[1].levels.truncate(1);
    let rows = compare_study(&m, &s, quick, true);
    assert!(rows.iter().any(|r| r.run == "b" && r.level == Some(1) && r.stored == "(missing)"), "{rows:?}");
    // a missing run
    let rows = compare_study(&m, &stored[..1], quick, true);
    assert!(rows.iter().any(|r| r.run == "b" && r.field == "run"), "{rows:?}");
    // a missing study
    let rows = compare_study(&m, &[], quick, true);
    assert!(rows.iter().any(|r| r.field == "study"), "{rows:?}");
    // timings are never compared
    let mut s = stored.clone();
    s[0].levels[0].t_solve += 100.0;
    assert!(compare_study(&m, &s, quick, true).is_empty());
}

#[test]
fn rate_floors_are_one_sided() {
    let (stored, _, full2) = stored_and_quick();
    let rate = observed_rate(&full2[1], "err_quadrature", 3).unwrap();
    assert!(rate > 1.2 && rate < 1.7, "ex71 uniform error rate in NDF {rate}");
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tiny.toml")).unwrap();
    for (min, drift) in [(1.2, false), (2.0, true)] {
        let t = format!("{text}\n[drift]\ndefault = {{ rel = 1e-9, abs = 1e-14 }}\n[[drift.rates]]\nrun = \"b\"\nfield = \"err_quadrature\"\nmin = {min}\nlast = 3\n");
        let m = Manifest::parse(Path::new("tiny.toml"), &t).unwrap();
        let rows = compare_study(&m, stored, full2, false);
        assert_eq!(!rows.is_empty(), drift, "floor {min}: {rows:?}");
    }
}
