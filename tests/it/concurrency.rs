//! A writer beside readers: readers of a folder being written name the writer instead of giving a
//! verdict, readers given `--wait` wait for the writer through all its runs, and two drift checks
//! in one checkout take turns.

use crate::common::{SHORT_RUN_STUDY, finish, scratch, signorini_in, stored_study};
use std::process::{Command, Stdio};

/// A study of one run that takes a few seconds (Example 7.1, 19 adaptive levels from
/// structured:8), so that readers reliably start while it is computed again.
const N5_STUDY: &str =
    "description = \"one run of 19 levels\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:8\"\n[[run]]\nid = \"a\"\nlevels = 19\n";

#[test]
fn readers_of_a_folder_being_written_name_the_writer_instead_of_a_verdict() {
    let dir = scratch("concurrency-readers-of-folder");
    stored_study(&dir, "experiments/s.toml", N5_STUDY, "res");
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/s.toml", "--results", "w"]);
    assert_eq!(code, 0, "{out}{err}");
    let writer = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["run", "experiments/s.toml", "--results", "w", "--fresh"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let checkpoint = dir.join("w/s/.partial/a.json");
    let start = std::time::Instant::now();
    while !checkpoint.exists() {
        assert!(start.elapsed().as_secs() < 120, "{} never appeared", checkpoint.display());
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let named = format!("is being written by process {}", writer.id());
    // a reader given --wait waits for the writer, then reads (the Slurm finish job while a
    // second array of the same study holds the folder: refused, it failed `make cluster-test`)
    let waiting = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["figures", "--results", "w", "--wait"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let readers: [&[&str]; 3] = [
        &["drift", "--study", "s", "--results", "res", "--against", "w", "--report", "drift.json"],
        &["report", "--results", "w", "--out", "page"],
        &["figures", "--results", "w"],
    ];
    for args in readers {
        let (code, out, err) = signorini_in(&dir, args);
        assert_ne!(code, 0, "{args:?} read a folder being written: {out}{err}");
        assert!(err.contains(&named) && !err.contains("missing") && !err.contains("holds no study"), "{args:?}: {err}");
    }
    assert!(!dir.join("drift.json").exists() && !dir.join("w/drift-report.json").exists(), "a drift report of a folder being written");
    let status = { writer }.wait().unwrap();
    assert!(status.success());
    let waited = waiting.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&waited.stderr);
    assert!(waited.status.success(), "figures --wait: {err}");
    assert!(err.contains(&named) && err.contains("waiting for it to finish"), "figures --wait did not wait: {err}");
    assert!(dir.join("w/CLAIMS.md").exists(), "figures --wait drew nothing");
    // written, the folder reads: the same run again, no drift
    let (code, out, err) = signorini_in(&dir, &["drift", "--study", "s", "--results", "res", "--against", "w", "--report", "drift.json"]);
    assert_eq!(code, 0, "{out}{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Three runs one `run` process computes one after the other (each long enough that the
/// readers start during the first).
const THREE_RUNS_OF_17_LEVELS: &str = "description = \"three runs of 17 levels\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:8\"\nlevels = 17\n[[run]]\nid = \"a\"\n[[run]]\nid = \"b\"\nestimator = { log_factor = \"one\" }\n[[run]]\nid = \"c\"\nestimator = { log_factor = \"linear\" }\n";

#[test]
fn readers_given_wait_wait_for_the_writer_through_all_its_runs() {
    let dir = scratch("concurrency-wait");
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/w.toml"), THREE_RUNS_OF_17_LEVELS).unwrap();
    let bin = env!("CARGO_BIN_EXE_signorini");
    let spawn = |args: &[&str]| {
        std::process::Command::new(bin)
            .current_dir(&dir)
            .env("SIGNORINI_PROGRESS", "off")
            .args(args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let writer = spawn(&["run", "exp/w.toml", "--results", "res"]);
    // the first run is being computed: its checkpoint is written after its first level
    let checkpoint = dir.join("res/w/.partial/a.json");
    let start = std::time::Instant::now();
    while !checkpoint.exists() {
        assert!(start.elapsed().as_secs() < 120, "{} never appeared", checkpoint.display());
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let readers = [
        spawn(&["figures", "--results", "res", "--experiments", "exp", "--study", "w", "--wait"]),
        spawn(&["report", "--results", "res", "--experiments", "exp", "--study", "w", "--out", "page", "--wait"]),
    ];
    let written = writer.wait_with_output().unwrap();
    assert!(written.status.success(), "{}", String::from_utf8_lossy(&written.stderr));
    for reader in readers {
        let out = reader.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "a reader given --wait was refused: {err}");
        assert!(err.contains("waiting for it to finish") && !err.contains("missing") && !err.contains("incomplete"), "{err}");
    }
    let page = std::fs::read_to_string(dir.join("page/w.html")).unwrap();
    assert!(!page.contains("(missing)"), "the page was drawn from a study still being computed");
    std::fs::remove_dir_all(&dir).ok();
}

fn drift(dir: &std::path::Path) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(dir)
        .args(["drift", "--experiments", "exp", "--results", "results", "--study", "s", "--report", "r.json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

#[test]
fn two_drifts_in_one_checkout_take_turns_and_neither_reports_a_false_drift() {
    let dir = scratch("concurrency-two-drifts");
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/s.toml"), SHORT_RUN_STUDY).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["run", "exp/s.toml", "--results", "results"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let first = drift(&dir);
    // the first reruns the study now: its scratch copy of the run is being computed
    let start = std::time::Instant::now();
    while !dir.join("target/drift/full/s/.partial").exists() && !dir.join("target/drift/full/s/runs/a.json").exists() {
        assert!(start.elapsed().as_secs() < 120, "the first drift never started its rerun");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let second = drift(&dir);
    let ((c1, o1), (c2, o2)) = (finish(first), finish(second));
    assert_eq!(c1, 0, "first: {o1}");
    assert_eq!(c2, 0, "second: {o2}");
    for o in [&o1, &o2] {
        assert!(o.contains("drift: none"), "{o}");
        assert!(!o.contains("(missing)"), "{o}");
    }
    assert!(
        o2.contains("the scratch folder target/drift/full is being written by process") && o2.contains("waiting for it to finish"),
        "{o2}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
