//! The results store under hostile conditions (issue battery, store items): a stored run is
//! never replaced silently, a record the tool cannot read back is never written, a failed write
//! (a full disk, simulated with a file-size limit) leaves the folder consistent with no temporary
//! file, what a killed run leaves is cleaned by the next run and ignored by drift, and a run that
//! executes nothing changes no file. After every case the folder lists exactly the runs present.

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::Command;

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("signorini-bad-store-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Run the binary in `dir`; (exit code, stdout + stderr).
fn signorini(dir: &Path, args: &[&str]) -> (i32, String) {
    run_with(dir, args, None)
}

/// As [`signorini`], with a file-size limit (RLIMIT_FSIZE, bytes) on the process.
fn run_with(dir: &Path, args: &[&str], fsize: Option<u64>) -> (i32, String) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_signorini"));
    cmd.current_dir(dir).args(args);
    if let Some(limit) = fsize {
        // SAFETY: setrlimit only, between fork and exec
        unsafe {
            cmd.pre_exec(move || {
                let lim = libc::rlimit { rlim_cur: limit, rlim_max: limit };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &lim) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
    }
    let o = cmd.output().unwrap();
    (o.status.code().unwrap_or(-1), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

const STUDY: &str = r#"description = "store test: two short runs of Example 7.1, the second saving a mesh"

[defaults]
problem = "ex71"
mesh = "structured:2"
quick_levels = 2

[[run]]
id = "a"
levels = 3

[[run]]
id = "b"
levels = 4
theta = 0.5
save_levels = [3]
"#;

/// A study folder `dir/study.toml`; returns the manifest's path relative to `dir`.
fn manifest(dir: &Path, text: &str) -> &'static str {
    std::fs::write(dir.join("study.toml"), text).unwrap();
    "study.toml"
}

/// Every file under `dir`, relative, sorted.
fn files(dir: &Path) -> Vec<String> {
    fn walk(root: &Path, d: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                out.push(p.strip_prefix(root).unwrap().display().to_string());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// The study folder lists exactly the runs whose records are present: the run ids of
/// `runs/*.json`, the rows of `levels.csv` and `provenance.json`'s list agree, every mesh snapshot
/// belongs to a present run, and no temporary file is left. Returns the run ids.
fn consistent(study: &Path) -> Vec<String> {
    let all = files(study);
    assert!(!all.iter().any(|f| f.contains(".tmp")), "temporary files left: {all:?}");
    let mut ids: Vec<String> = all.iter().filter_map(|f| f.strip_prefix("runs/")?.strip_suffix(".json").map(String::from)).collect();
    ids.sort();
    let csv = std::fs::read_to_string(study.join("levels.csv")).unwrap_or_default();
    let mut in_csv: Vec<String> = csv.lines().skip(1).filter_map(|l| l.split(',').next().map(String::from)).collect();
    in_csv.dedup();
    in_csv.sort();
    assert_eq!(in_csv, ids, "levels.csv lists other runs than runs/: {csv}");
    if !ids.is_empty() {
        let prov: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(study.join("provenance.json")).unwrap()).unwrap();
        let mut listed: Vec<String> = prov["runs"].as_array().unwrap().iter().map(|v| v.as_str().unwrap().to_string()).collect();
        listed.sort();
        assert_eq!(listed, ids, "provenance.json lists other runs than runs/");
    }
    for m in all.iter().filter_map(|f| f.strip_prefix("meshes/")) {
        assert!(ids.iter().any(|id| m.starts_with(&format!("{id}_level"))), "mesh snapshot {m} of no present run");
    }
    ids
}

fn results_of(dir: &Path) -> PathBuf {
    dir.join("results/study")
}

#[test]
fn a_differing_spec_is_refused_naming_the_run_and_keys_and_replaced_only_when_asked() {
    let dir = tmp("differs");
    let m = manifest(&dir, STUDY);
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    let before = std::fs::read(results_of(&dir).join("runs/b.json")).unwrap();
    // the same study name with run b edited (theta) and a new run c: refused, nothing changed
    manifest(&dir, &STUDY.replace("theta = 0.5", "theta = 0.7"));
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("run b is stored with another spec") && out.contains("theta: 0.5 stored, 0.7 declared"), "{out}");
    assert!(out.contains("--replace") && out.contains("Nothing was run or changed"), "{out}");
    assert_eq!(std::fs::read(results_of(&dir).join("runs/b.json")).unwrap(), before, "the stored run changed");
    assert_eq!(consistent(&results_of(&dir)), ["a", "b"]);
    // --replace: run b recomputed with theta 0.7; its old snapshot replaced by the new one
    let (code, out) = signorini(&dir, &["run", m, "--results", "results", "--replace"]);
    assert_eq!(code, 0, "{out}");
    let b: serde_json::Value = serde_json::from_slice(&std::fs::read(results_of(&dir).join("runs/b.json")).unwrap()).unwrap();
    assert_eq!(b["run"]["theta"], 0.7);
    assert_eq!(consistent(&results_of(&dir)), ["a", "b"]);
    // a stored run the manifest no longer declares is refused too
    manifest(&dir, &STUDY.replace("theta = 0.5", "theta = 0.7").replace("id = \"a\"", "id = \"a2\""));
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_ne!(code, 0);
    assert!(out.contains("run a is stored but not declared in study.toml"), "{out}");
    assert_eq!(consistent(&results_of(&dir)), ["a", "b"]);
}

#[test]
fn a_value_a_record_cannot_hold_stops_the_run_at_its_level_and_stores_nothing_of_it() {
    let dir = tmp("nonfinite");
    let m = manifest(&dir, &STUDY.replace("levels = 3\n", "levels = 3\nestimator = { c0 = 1e308 }\n"));
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("study/a: level 0:") && out.contains("estimate is inf"), "{out}");
    assert!(!results_of(&dir).join("runs/a.json").exists());
    consistent(&results_of(&dir));
    // what is stored can be read back: resume, drift and figures do not fail on it
    manifest(&dir, STUDY);
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    assert_eq!(consistent(&results_of(&dir)), ["a", "b"]);
}

#[test]
fn a_full_disk_leaves_the_folder_consistent_without_temporary_files() {
    let dir = tmp("full");
    let m = manifest(&dir, STUDY);
    // find how much a full run writes, then give less than that
    let (code, out) = signorini(&dir, &["run", m, "--results", "full"]);
    assert_eq!(code, 0, "{out}");
    let biggest =
        files(&dir.join("full/study")).iter().map(|f| std::fs::metadata(dir.join("full/study").join(f)).unwrap().len()).max().unwrap();
    for limit in [biggest / 4, biggest / 2, biggest - 1] {
        let results = format!("r{limit}");
        let (code, out) = run_with(&dir, &["run", m, "--results", &results], Some(limit));
        assert_ne!(code, 0, "a limit of {limit} bytes must stop the run: {out}");
        assert!(out.contains("File too large") || out.contains("too large"), "the error names the failed write: {out}");
        let present = consistent(&dir.join(&results).join("study"));
        // the limit lifted, the study completes from what is there
        let (code, out) = signorini(&dir, &["run", m, "--results", &results]);
        assert_eq!(code, 0, "{out}");
        assert_eq!(consistent(&dir.join(&results).join("study")), ["a", "b"], "after {present:?}");
    }
}

#[test]
fn what_a_killed_run_leaves_is_removed_by_the_next_run_and_ignored_by_drift() {
    let dir = tmp("orphans");
    let m = manifest(&dir, STUDY);
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    let study = results_of(&dir);
    // leftovers of a killed process: a snapshot of an unfinished run, a temporary file
    std::fs::write(study.join("meshes/c_level7.vtu"), "partial").unwrap();
    std::fs::write(study.join("runs/.c.json.tmp4242.0"), "partial").unwrap();
    let (code, out) = signorini(&dir, &["drift", "--against", "results", "--experiments", ".", "--study", "study"]);
    assert!(out.contains("ignoring 2 file(s) of an unfinished run"), "{code} {out}");
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("removed 2 file(s) of an unfinished run") && out.contains("meshes/c_level7.vtu"), "{out}");
    assert_eq!(consistent(&study), ["a", "b"]);
}

#[test]
fn a_run_that_executes_nothing_changes_no_file() {
    let dir = tmp("noop");
    let m = manifest(&dir, STUDY);
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    let state = |d: &Path| -> Vec<(String, Vec<u8>, std::time::SystemTime)> {
        files(d)
            .into_iter()
            .map(|f| {
                let p = d.join(&f);
                (f, std::fs::read(&p).unwrap(), std::fs::metadata(&p).unwrap().modified().unwrap())
            })
            .filter(|(f, _, _)| f != ".lock")
            .collect()
    };
    let before = state(&results_of(&dir));
    std::thread::sleep(std::time::Duration::from_millis(20));
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("0 run(s) executed"), "{out}");
    assert_eq!(state(&results_of(&dir)), before, "a run that executed nothing rewrote a file");
}
