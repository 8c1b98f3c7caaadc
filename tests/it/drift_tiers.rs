//! The drift tiers of a deep study (`[drift.deep]`): `signorini drift` (what `make test` runs)
//! reruns every run to its quick prefix and the runs named in `full` to the end; `drift --deep`
//! (the scheduled job) reruns all of them to the end. A change past the prefix of a deep run is
//! caught by the scheduled tier, a change anywhere in a `full` run by every test run. The last
//! level of a run named in `replay` is rebuilt from its stored refinement history and solved
//! once more by every test run: a change of that level's numbers, or of the history itself, is
//! caught without rerunning the levels before it.

use signorini::manifest::Manifest;
use signorini::records::StudyDir;
use signorini::store;
use signorini::study::drift::{self, DriftOptions};
use signorini::study::{self, RunOptions};
use std::path::{Path, PathBuf};

const DEEP: &str = r#"description = "a deep study in miniature"
[defaults]
problem = "ex71"
mesh = "structured:2"
theta = 0.5
[[run]]
id = "a"
levels = 7
quick_levels = 3
[[run]]
id = "b"
levels = 6
quick_levels = 2
[[run]]
id = "c"
problem = "fb"
levels = 6
quick_levels = 2
[drift.deep]
full = ["b"]
replay = ["c"]
"#;

fn setup(name: &str) -> (PathBuf, Manifest) {
    let root = std::env::temp_dir().join(format!("signorini-tiers-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(root.join("experiments")).unwrap();
    let file = root.join("experiments/deepish.toml");
    std::fs::write(&file, DEEP).unwrap();
    let m = Manifest::load(&file).unwrap();
    let opts = RunOptions {
        quick: false,
        shard: None,
        fresh: true,
        replace: false,
        results: root.join("results"),
        progress: false,
        wait_for_lock: false,
    };
    study::run_study(&m, &opts).unwrap();
    (root, m)
}

/// Change run `id`'s stored record with `edit` and rewrite the summaries to match.
fn edit_run(root: &Path, m: &Manifest, id: &str, edit: impl FnOnce(&mut signorini::records::RunRecord)) {
    let dir = StudyDir::new(&root.join("results"), &m.study);
    let mut runs = dir.read_runs().unwrap();
    let r = runs.iter_mut().find(|r| r.run.id == id).unwrap();
    edit(r);
    signorini::records::write_json(&dir.run_file(id), r).unwrap();
    store::Store::new(&root.join("results"), &m.study).lock(false).unwrap().sync_summaries(m, &runs, false).unwrap();
}

/// Move the estimate of the last level of run `id` by a relative 1e-5, in its record and in the
/// summaries (so that only a rerun can see it).
fn perturb_last_level(root: &Path, m: &Manifest, id: &str) {
    edit_run(root, m, id, |r| {
        let last = r.levels.last_mut().unwrap();
        last.terms.estimate *= 1.0 + 1e-5;
        last.efficiency = last.err_quadrature.map(|e| last.terms.estimate / e);
    });
}

fn drift_rows(root: &Path, m: &Manifest, deep: bool) -> Vec<(String, Option<usize>, String)> {
    let opts = DriftOptions {
        quick: false,
        deep,
        against: None,
        scratch: root.join(if deep { "scratch-deep" } else { "scratch" }),
        results: root.join("results"),
        progress: false,
    };
    let report = drift::check(std::slice::from_ref(m), false, &opts, &|_| Ok(String::new())).unwrap();
    report.rows.iter().map(|r| (r.run.clone(), r.level, r.field.clone())).collect()
}

#[test]
fn an_unchanged_deep_study_passes_both_tiers() {
    let (root, m) = setup("clean");
    assert_eq!(drift_rows(&root, &m, false), vec![]);
    assert_eq!(drift_rows(&root, &m, true), vec![]);
}

#[test]
fn a_change_past_the_prefix_is_caught_by_the_deep_tier_only() {
    let (root, m) = setup("past-prefix");
    perturb_last_level(&root, &m, "a");
    // the test tier reruns a to level 2 only: it cannot see level 6
    assert_eq!(drift_rows(&root, &m, false), vec![]);
    let rows = drift_rows(&root, &m, true);
    assert!(rows.contains(&("a".to_string(), Some(6), "estimate".to_string())), "{rows:?}");
}

#[test]
fn a_change_at_the_last_level_of_a_full_run_is_caught_by_every_test_run() {
    let (root, m) = setup("full-run");
    perturb_last_level(&root, &m, "b");
    let rows = drift_rows(&root, &m, false);
    assert!(rows.contains(&("b".to_string(), Some(5), "estimate".to_string())), "{rows:?}");
}

#[test]
fn a_full_run_the_study_does_not_declare_is_refused() {
    let text = DEEP.replace(r#"full = ["b"]"#, r#"full = ["z"]"#);
    let err = Manifest::parse(Path::new("deepish.toml"), &text).unwrap_err().to_string();
    assert!(err.contains("drift.deep.full[0]") && err.contains("the id of a declared run"), "{err}");
}

#[test]
fn a_change_at_the_last_level_of_a_replayed_run_is_caught_by_both_tiers() {
    let (root, m) = setup("replayed");
    perturb_last_level(&root, &m, "c");
    // the test tier reruns c to level 1 only, and replays level 5 from the stored history
    let rows = drift_rows(&root, &m, false);
    assert_eq!(rows, vec![("c (replayed)".to_string(), Some(5), "estimate".to_string())]);
    let rows = drift_rows(&root, &m, true);
    assert!(rows.contains(&("c".to_string(), Some(5), "estimate".to_string())), "{rows:?}");
}

#[test]
fn a_change_of_the_stored_history_is_caught_by_every_test_run() {
    let (root, m) = setup("history");
    // level 2 (past c's quick prefix) marked everywhere: level 3's mesh is no longer the one stored
    edit_run(&root, &m, "c", |r| {
        let h = &mut r.history.as_mut().unwrap().levels[2];
        h.marks = signorini::level::history::Flags::encode(&vec![true; h.n_elements]);
    });
    let opts = DriftOptions {
        quick: false,
        deep: false,
        against: None,
        scratch: root.join("scratch"),
        results: root.join("results"),
        progress: false,
    };
    let report = drift::check(std::slice::from_ref(&m), false, &opts, &|_| Ok(String::new())).unwrap();
    let rows: Vec<_> = report.rows.iter().map(|r| (r.run.clone(), r.level, r.field.clone())).collect();
    assert_eq!(rows, vec![("c (replayed)".to_string(), Some(5), "history".to_string())]);
    assert!(report.rows[0].fresh.contains("level 3: the replayed mesh"), "{:?}", report.rows[0]);
    // and a change inside the prefix is caught by the rerun itself
    edit_run(&root, &m, "c", |r| {
        let h = &mut r.history.as_mut().unwrap().levels[0];
        h.marks = signorini::level::history::Flags::encode(&vec![false; h.n_elements]);
    });
    let rows = drift_rows(&root, &m, false);
    assert!(rows.contains(&("c".to_string(), Some(0), "history.marks".to_string())), "{rows:?}");
}

#[test]
fn a_replayed_run_the_study_does_not_declare_is_refused() {
    let text = DEEP.replace(r#"replay = ["c"]"#, r#"replay = ["d"]"#);
    let err = Manifest::parse(Path::new("deepish.toml"), &text).unwrap_err().to_string();
    assert!(err.contains("drift.deep.replay[0]") && err.contains("the id of a declared run"), "{err}");
}
