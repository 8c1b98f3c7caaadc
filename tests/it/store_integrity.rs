//! The store's writers and the command line under hostile conditions: a journal crafted or
//! damaged by hand, files planted where the store writes, symlinks, odd places for the results.
//! Each test names the behaviour the store promises (docs/command-line.md, "What the store
//! owns, and what an interrupt leaves") in a case built to break it.

use crate::common::{finish, scratch, signorini_in, stored_study, stored_two_runs};
use std::path::{Path, PathBuf};
use std::process::Command;

const STUDY: &str = "description = \"two runs\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\n\
[[run]]\nid = \"a\"\nlevels = 2\nsave_levels = [1]\n[[run]]\nid = \"b\"\nlevels = 2\n";

/// Every file under `dir` with its bytes, locks left out (they are created by any writer).
fn files(dir: &Path) -> std::collections::BTreeMap<std::path::PathBuf, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if e.file_type().unwrap().is_dir() {
                stack.push(p);
            } else if !p.to_string_lossy().ends_with(".lock") {
                out.insert(p.strip_prefix(dir).unwrap().to_path_buf(), std::fs::read(&p).unwrap_or_default());
            }
        }
    }
    out
}

#[test]
fn a_journal_naming_a_file_outside_the_study_is_refused_and_nothing_is_moved() {
    let dir = scratch("integrity-journal-outside");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    let outside = dir.join("outside");
    std::fs::create_dir_all(&outside).unwrap();
    let victim = outside.join("notes.txt");
    let stolen = outside.join("stolen.json");
    let victim_abs = victim.display().to_string();
    let stolen_abs = stolen.display().to_string();
    // a journal is only ever written by the store, naming files of its folder (and the staging
    // folder ../.accept/STUDY of drift --accept): each of these names another place
    let crafted = [
        serde_json::json!({ "renames": [], "removals": [victim_abs] }),
        serde_json::json!({ "renames": [], "removals": ["../../outside/notes.txt"] }),
        serde_json::json!({ "renames": [["runs/a.json", stolen_abs]], "removals": [] }),
        serde_json::json!({ "renames": [["runs/a.json", "../../outside/stolen.json"]], "removals": [] }),
        serde_json::json!({ "renames": [[victim_abs, "runs/c.json"]], "removals": [] }),
        serde_json::json!({ "renames": [["../../outside/notes.txt", "runs/c.json"]], "removals": [] }),
        serde_json::json!({ "renames": [["../.accept/s/../../../outside/notes.txt", "runs/c.json"]], "removals": [] }),
    ];
    let stored = files(&dir.join("res/s"));
    for journal in crafted {
        std::fs::write(&victim, "mine").unwrap();
        let text = journal.to_string();
        std::fs::write(dir.join("res/s/.journal.json"), &text).unwrap();
        for args in [
            &["run", "exp/s.toml", "--results", "res"][..],
            &["drift", "--accept", "s", "--experiments", "exp", "--results", "res"],
            &["run", "exp/s.toml", "--plan", "--results", "res"],
        ] {
            let (code, out, err) = signorini_in(&dir, args);
            assert_ne!(code, 0, "{text}, then {args:?} succeeded: {out}{err}");
            assert!(err.contains(".journal.json") && err.contains("outside"), "{text}, then {args:?}: the refusal does not say why: {err}");
            assert_eq!(std::fs::read_to_string(&victim).unwrap(), "mine", "{text}, then {args:?}: a file outside the study was moved");
            assert!(!stolen.exists(), "{text}, then {args:?}: a record was moved out of the study");
            let mut now = files(&dir.join("res/s"));
            assert_eq!(now.remove(Path::new(".journal.json")).as_deref(), Some(text.as_bytes()), "{args:?}: the journal changed");
            assert_eq!(now, stored, "{text}, then {args:?}: the study folder changed");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_damaged_journal_is_named_as_one_no_writer_can_carry_out_not_as_a_change_the_next_writer_completes() {
    let dir = scratch("integrity-journal-damaged");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    for text in ["", "{\"renames\": [[\"runs/.a", "null", "{}"] {
        std::fs::write(dir.join("res/s/.journal.json"), text).unwrap();
        for args in [
            &["run", "exp/s.toml", "--results", "res"][..],
            &["figures", "--results", "res", "--experiments", "exp", "--figures", "figs"],
            &["report", "--results", "res", "--experiments", "exp", "--out", "pages"],
        ] {
            let (code, out, err) = signorini_in(&dir, args);
            assert_eq!(code, 1, "{text:?}, then {args:?}: {out}{err}");
            // the reader's advice (run the next writer, which "completes it") led to a writer
            // that failed on the same file with a parse error and no way out
            assert!(!err.contains("completes it"), "{text:?}, then {args:?}: advises a writer that cannot complete it: {err}");
            assert!(err.contains("not a journal the store writes"), "{text:?}, then {args:?}: {err}");
            assert!(err.contains("remove it"), "{text:?}, then {args:?}: names no way out: {err}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_study_named_runs_is_refused_before_it_makes_the_results_root_look_like_a_study_folder() {
    let dir = scratch("integrity-name-runs");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    std::fs::write(dir.join("exp/runs.toml"), STUDY).unwrap();
    // stored, res/runs/ made res look like a study folder (a folder holding runs/): every
    // command on res was refused from then on, the study s with it
    let (code, out, err) = signorini_in(&dir, &["run", "exp/runs.toml", "--results", "res"]);
    assert_eq!(code, 1, "a study named runs was stored: {out}{err}");
    assert!(err.contains("runs") && err.contains("study"), "{err}");
    assert!(!dir.join("res/runs").exists(), "res/runs was made");
    let (code, out, err) = signorini_in(&dir, &["run", "exp/s.toml", "--results", "res"]);
    assert_eq!(code, 0, "the results root is still usable: {out}{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_results_root_in_the_staging_folder_of_drift_accept_is_refused_so_an_accept_cannot_remove_what_it_stored() {
    let dir = scratch("integrity-staging-root");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    // stored into res/.accept, the study was removed without a word by the next
    // `drift --accept s --results res`, which reruns into res/.accept/s and removes it
    for place in ["res/.accept", "res/.accept/", "res/.accept/inner"] {
        for args in
            [&["run", "exp/s.toml", "--results", place][..], &["drift", "--accept", "s", "--experiments", "exp", "--results", place]]
        {
            let (code, out, err) = signorini_in(&dir, args);
            assert_eq!(code, 1, "{args:?}: {out}{err}");
            assert!(err.contains(".accept"), "{args:?}: {err}");
        }
    }
    assert!(!dir.join("res/.accept").exists(), "the staging folder was made");
    let (code, out, err) = signorini_in(&dir, &["drift", "--accept", "s", "--experiments", "exp", "--results", "res"]);
    assert_eq!(code, 0, "{out}{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_study_name_starting_with_a_dash_is_refused_since_no_flag_could_name_it() {
    let dir = scratch("integrity-name-dash");
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/-s.toml"), STUDY).unwrap();
    // stored, it could be named only as `--accept=-s`: `drift --accept -s` said
    // "unexpected argument '-s' found", and so did `--study -s`
    let (code, out, err) = signorini_in(&dir, &["run", "exp/-s.toml", "--results", "res"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("`-s` cannot name one"), "{err}");
    assert!(!dir.join("res/-s").exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn report_given_a_file_for_its_results_folder_says_so_rather_than_naming_a_drift_report() {
    let dir = scratch("integrity-report-file");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    std::fs::write(dir.join("afile"), "x").unwrap();
    // said "reading the drift report afile/drift-report.json: Not a directory"
    let (code, out, err) = signorini_in(&dir, &["report", "--results", "afile", "--experiments", "exp", "--out", "pages"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("--results afile") && err.contains("file") && !err.contains("drift report"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `chown -R uid:gid` of `dir`.
fn chown_tree(dir: &Path, id: u32) {
    std::os::unix::fs::lchown(dir, Some(id), Some(id)).unwrap();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        if e.file_type().unwrap().is_dir() {
            chown_tree(&e.path(), id);
        } else {
            std::os::unix::fs::lchown(e.path(), Some(id), Some(id)).unwrap();
        }
    }
}

#[test]
fn a_change_that_fails_after_its_journal_is_written_says_the_journal_is_pending_and_what_completes_it() {
    // permissions bind only for another user: as root, the command runs as nobody (setpriv)
    // SAFETY: geteuid has no preconditions
    let root = unsafe { libc::geteuid() } == 0;
    if !root || std::process::Command::new("setpriv").arg("--version").output().is_err() {
        eprintln!("skipped: needs root and setpriv to run a command as another user");
        return;
    }
    let dir = scratch("integrity-journal-pending");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    const NOBODY: u32 = 65534;
    chown_tree(&dir, NOBODY);
    use std::os::unix::fs::PermissionsExt;
    let runs = dir.join("res/s/runs");
    for (args, what) in [
        (&["run", "exp/s.toml", "--fresh", "--results", "res"][..], "run --fresh"),
        (&["drift", "--accept", "s", "--experiments", "exp", "--results", "res"], "drift --accept"),
    ] {
        std::fs::set_permissions(&runs, std::fs::Permissions::from_mode(0o555)).unwrap();
        let out = std::process::Command::new("setpriv")
            .args([&format!("--reuid={NOBODY}"), &format!("--regid={NOBODY}"), "--clear-groups", env!("CARGO_BIN_EXE_signorini")])
            .args(args)
            .current_dir(&dir)
            .output()
            .unwrap();
        std::fs::set_permissions(&runs, std::fs::Permissions::from_mode(0o755)).unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{what}: {err}");
        // the journal is on disk and the change part made: the message said only
        // "removing R/s/runs/a.json: Permission denied", while every reader now refuses the folder
        assert!(dir.join("res/s/.journal.json").exists(), "{what}: no journal pending: {err}");
        assert!(
            err.contains(".journal.json") && err.contains("completes"),
            "{what}: the message does not say the change is pending: {err}"
        );
        let (code, out, err) = signorini_in(&dir, &["run", "exp/s.toml", "--results", "res"]);
        assert_eq!(code, 0, "{what}: {out}{err}");
        assert!(err.contains("completed a change"), "{what}: {err}");
        chown_tree(&dir, NOBODY);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_hidden_json_file_in_runs_is_no_record_and_fresh_accept_and_replace_leave_it() {
    let dir = scratch("integrity-hidden-json");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    // a run id starts with a letter or digit, so the store never writes runs/.NAME.json: the
    // file is the user's, yet each of these removed it and exited 0
    for args in [
        &["run", "exp/s.toml", "--fresh", "--results", "res"][..],
        &["drift", "--accept", "s", "--experiments", "exp", "--results", "res"],
        &["run", "exp/s.toml", "--replace", "--results", "res"],
    ] {
        std::fs::write(dir.join("res/s/runs/.notes.json"), "{}").unwrap();
        let (code, out, err) = signorini_in(&dir, args);
        assert!(dir.join("res/s/runs/.notes.json").exists(), "{args:?} removed the user's file (exit {code}): {out}{err}");
        if code != 0 {
            assert!(err.contains(".notes.json"), "{args:?}: {err}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn figures_wait_ends_when_the_writer_it_waits_for_has_exited_even_before_its_parent_reaps_it() {
    let dir = scratch("integrity-wait-zombie");
    let longer = STUDY.replace("levels = 2", "levels = 7").replace("structured:2", "structured:4");
    stored_study(&dir, "exp/s.toml", &longer, "res");
    // a driver that starts `run --fresh` and, before it waits for that child, calls
    // `figures --wait`: the child, ended but not yet reaped, is a zombie that holds no lock, yet
    // kill(pid, 0) found it "running" and figures --wait waited for it forever
    let mut writer = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["run", "exp/s.toml", "--fresh", "--results", "res"])
        .current_dir(&dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(150));
    let mut reader = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["report", "--wait", "--results", "res", "--experiments", "exp", "--out", "pages"])
        .current_dir(&dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    let ended = loop {
        if let Some(status) = reader.try_wait().unwrap() {
            break Some(status);
        }
        if start.elapsed() > std::time::Duration::from_secs(60) {
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    };
    if ended.is_none() {
        reader.kill().ok();
    }
    let out = reader.wait_with_output().unwrap();
    assert!(writer.wait().unwrap().success());
    assert!(ended.is_some(), "report --wait still waited 60 s after its writer ended: {}", String::from_utf8_lossy(&out.stderr));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_truncated_record_is_a_fault_of_its_run_that_replace_recomputes() {
    let dir = stored_two_runs("store-integrity-truncated-record-is");
    let record = dir.join("res/s/runs/c.json");
    let text = std::fs::read(&record).unwrap();
    std::fs::write(&record, &text[..100]).unwrap();
    for args in [&["run", "experiments/s.toml", "--results", "res"][..], &["run", "experiments/s.toml", "--results", "res", "--plan"]] {
        let (code, out, err) = signorini_in(&dir, args);
        assert_eq!(code, 1, "{args:?}: {out}{err}");
        assert!(err.contains("runs/c.json") && err.contains("is not a run record (truncated, or not JSON)"), "{args:?}: {err}");
        assert!(err.contains("--replace"), "{args:?}: {err}");
    }
    let (code, out, err) = signorini_in(&dir, &["drift", "--experiments", "experiments", "--results", "res", "--against", "fresh"]);
    assert_ne!(code, 0, "{out}{err}");
    assert!(format!("{out}{err}").contains("runs/c.json"), "{out}{err}");
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/s.toml", "--results", "res", "--replace"]);
    assert_eq!(code, 0, "{out}{err}");
    let both = format!("{out}{err}");
    assert!(both.contains("s/c: removing the stored run") && both.contains("1 run(s) executed"), "{both}");
    assert!(std::fs::read(&record).unwrap().len() > 100, "run c stored again");
    let (code, out, err) = signorini_in(&dir, &["drift", "--experiments", "experiments", "--results", "res", "--against", "fresh"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("drift: none"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

const EX72_WITH_REFERENCE: &str = "description = \"Example 7.2 with a reference\"\n[defaults]\nproblem = \"ex72\"\nmesh = \"structured:4\"\ntheta = 0.5\nquick_levels = 2\nsave_levels = [2]\n[defaults.reference]\ntheta = 0.5\nmin_ndof = 3000\n[[run]]\nid = \"adaptive\"\nrefine = \"adaptive\"\nlevels = 4\n";

/// Every file under `dir` with its bytes, sorted by path (lock files aside: each process that
/// takes a lock writes its own pid into it).
fn files_with_bytes(dir: &std::path::Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        if e.file_name().to_string_lossy().contains(".lock") {
            continue;
        } else if e.path().is_dir() {
            out.extend(files_with_bytes(&e.path()));
        } else {
            out.push((e.path(), std::fs::read(e.path()).unwrap()));
        }
    }
    out.sort();
    out
}

#[test]
fn a_run_refused_for_a_damaged_record_removes_nothing() {
    let dir = scratch("store-integrity-damaged");
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    std::fs::write(dir.join("experiments/r.toml"), EX72_WITH_REFERENCE).unwrap();
    let run = ["run", "--results", "res", "experiments/r.toml"];
    let (code, out, err) = signorini_in(&dir, &run);
    assert_eq!(code, 0, "{out}{err}");
    let record = dir.join("res/r/runs/adaptive.json");
    let good = std::fs::read(&record).unwrap();
    std::fs::write(&record, &good[..good.len() - 20]).unwrap();
    let before = files_with_bytes(&dir.join("res"));
    assert!(before.iter().any(|(p, _)| p.to_string_lossy().contains("meshes/adaptive_level2")), "a snapshot");
    assert!(before.iter().any(|(p, _)| p.to_string_lossy().contains("references/")), "a reference");
    let (code, out, err) = signorini_in(&dir, &run);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("runs/adaptive.json") && !err.contains("removed"), "{err}");
    assert_eq!(files_with_bytes(&dir.join("res")), before, "the refusal changed the folder");
    // the record restored, the folder is whole again
    std::fs::write(&record, &good).unwrap();
    let (code, out, err) = signorini_in(&dir, &run);
    assert_eq!(code, 0, "{out}{err}");
    let said = format!("{out}{err}");
    assert!(said.contains("finished earlier") && !said.contains("removing"), "{said}");
    std::fs::remove_dir_all(&dir).ok();
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
        super::common::limit(&mut cmd, libc::RLIMIT_FSIZE, limit);
    }
    let o = cmd.output().unwrap();
    (o.status.code().unwrap_or(-1), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

const TWO_RUNS_ONE_SAVING: &str = r#"description = "store test: two short runs of Example 7.1, the second saving a mesh"

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
fn relative_files(dir: &Path) -> Vec<String> {
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
    let all = relative_files(study);
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
    let dir = scratch("store-integrity-differs");
    let m = manifest(&dir, TWO_RUNS_ONE_SAVING);
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    let before = std::fs::read(results_of(&dir).join("runs/b.json")).unwrap();
    // the same study name with run b edited (theta) and a new run c: refused, nothing changed
    manifest(&dir, &TWO_RUNS_ONE_SAVING.replace("theta = 0.5", "theta = 0.7"));
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
    manifest(&dir, &TWO_RUNS_ONE_SAVING.replace("theta = 0.5", "theta = 0.7").replace("id = \"a\"", "id = \"a2\""));
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_ne!(code, 0);
    assert!(out.contains("run a is stored but not declared in study.toml"), "{out}");
    assert_eq!(consistent(&results_of(&dir)), ["a", "b"]);
}

#[test]
fn a_value_a_record_cannot_hold_stops_the_run_at_its_level_and_stores_nothing_of_it() {
    let dir = scratch("store-integrity-nonfinite");
    let m = manifest(&dir, &TWO_RUNS_ONE_SAVING.replace("levels = 3\n", "levels = 3\nestimator = { c0 = 1e308 }\n"));
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("study/a: level 0:") && out.contains("C_0 eta_h = 1e308") && out.contains("is inf, not a finite number"), "{out}");
    assert!(!results_of(&dir).join("runs/a.json").exists());
    consistent(&results_of(&dir));
    // what is stored can be read back: resume, drift and figures do not fail on it
    manifest(&dir, TWO_RUNS_ONE_SAVING);
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    assert_eq!(consistent(&results_of(&dir)), ["a", "b"]);
}

#[test]
fn a_full_disk_leaves_the_folder_consistent_without_temporary_files() {
    let dir = scratch("store-integrity-full");
    let m = manifest(&dir, TWO_RUNS_ONE_SAVING);
    // find how much a full run writes, then give less than that
    let (code, out) = signorini(&dir, &["run", m, "--results", "full"]);
    assert_eq!(code, 0, "{out}");
    let biggest = relative_files(&dir.join("full/study"))
        .iter()
        .map(|f| std::fs::metadata(dir.join("full/study").join(f)).unwrap().len())
        .max()
        .unwrap();
    for limit in [biggest / 4, biggest / 2, biggest - 1] {
        let results = format!("r{limit}");
        let (code, out) = run_with(&dir, &["run", m, "--results", &results], Some(limit));
        assert_ne!(code, 0, "a limit of {limit} bytes must stop the run: {out}");
        assert!(out.contains("File too large") || out.contains("too large"), "the error names the failed write: {out}");
        // named by the file meant, not only by its temporary name
        assert!(out.contains("(through the temporary file ."), "the error names the file meant: {out}");
        let present = consistent(&dir.join(&results).join("study"));
        // the limit lifted, the study completes from what is there
        let (code, out) = signorini(&dir, &["run", m, "--results", &results]);
        assert_eq!(code, 0, "{out}");
        assert_eq!(consistent(&dir.join(&results).join("study")), ["a", "b"], "after {present:?}");
    }
}

#[test]
fn what_a_killed_run_leaves_is_removed_by_the_next_run_and_ignored_by_drift() {
    let dir = scratch("store-integrity-orphans");
    let m = manifest(&dir, TWO_RUNS_ONE_SAVING);
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
    let dir = scratch("store-integrity-noop");
    let m = manifest(&dir, TWO_RUNS_ONE_SAVING);
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    let state = |d: &Path| -> Vec<(String, Vec<u8>, std::time::SystemTime)> {
        relative_files(d)
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

// ---- a results folder that checks itself (Store::check, used by run, drift,
// figures and report)

/// A study stored in `dir/results/study` from [`TWO_RUNS_ONE_SAVING`].
fn stored(name: &str) -> (PathBuf, &'static str) {
    let dir = scratch(&format!("store-integrity-{name}"));
    let m = manifest(&dir, TWO_RUNS_ONE_SAVING);
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    (dir, m)
}

/// `drift --against results` (the folder against itself: every number agrees) and `figures`.
fn drift_and_figures(dir: &Path) -> [(i32, String); 2] {
    [
        signorini(dir, &["drift", "--against", "results", "--experiments", ".", "--study", "study"]),
        signorini(dir, &["figures", "--results", "results", "--experiments", ".", "--figures", "figs"]),
    ]
}

#[test]
fn a_copied_record_fails_drift_figures_and_run_naming_it_and_replace_removes_it() {
    let (dir, m) = stored("copy");
    let study = results_of(&dir);
    std::fs::copy(study.join("runs/a.json"), study.join("runs/copy.json")).unwrap();
    for (code, out) in drift_and_figures(&dir) {
        assert_ne!(code, 0, "{out}");
        assert!(out.contains("runs/copy.json") && out.contains("holds run a, not copy"), "{out}");
    }
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("runs/copy.json") && out.contains("Nothing was run or changed"), "{out}");
    let (code, out) = signorini(&dir, &["run", m, "--results", "results", "--replace"]);
    assert_eq!(code, 0, "{out}");
    assert_eq!(consistent(&study), ["a", "b"]);
    for (code, out) in drift_and_figures(&dir) {
        assert_eq!(code, 0, "{out}");
    }
}

#[test]
fn a_missing_or_truncated_mesh_snapshot_fails_drift_and_figures_naming_it() {
    let (dir, m) = stored("snapshot");
    let study = results_of(&dir);
    let (json, vtu) = (study.join("meshes/b_level3.json"), study.join("meshes/b_level3.vtu"));
    let (json_bytes, vtu_bytes) = (std::fs::read(&json).unwrap(), std::fs::read(&vtu).unwrap());
    std::fs::remove_file(&json).unwrap();
    for (code, out) in drift_and_figures(&dir) {
        assert_ne!(code, 0, "{out}");
        assert!(out.contains("meshes/b_level3.json") && out.contains("missing: run b saves level 3"), "{out}");
    }
    std::fs::write(&json, &json_bytes).unwrap();
    std::fs::write(&vtu, &vtu_bytes[..vtu_bytes.len() / 2]).unwrap();
    for (code, out) in drift_and_figures(&dir) {
        assert_ne!(code, 0, "{out}");
        assert!(out.contains("meshes/b_level3.vtu") && out.contains("is not the") && out.contains("record of run b holds"), "{out}");
    }
    // run refuses too, and --replace computes run b again
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert!(code != 0 && out.contains("b_level3.vtu"), "{out}");
    let (code, out) = signorini(&dir, &["run", m, "--results", "results", "--replace"]);
    assert!(code == 0 && out.contains("1 run(s) executed"), "{out}");
    assert_eq!(std::fs::read(&vtu).unwrap(), vtu_bytes, "run b computed again gives the same snapshot");
}

/// A mesh snapshot is bound to its record by the SHA-256 the record holds of it (the bytes
/// committed with it), so a snapshot swapped with another run's, edited by hand, or held by a
/// record without the hashes is a fault of its run for `run`, `drift` and `figures` (the Hertz
/// row of CLAIMS never reads edited contact forces).
#[test]
fn a_swapped_or_edited_mesh_snapshot_is_a_fault_of_its_run() {
    let dir = scratch("store-integrity-snapshot-hash");
    let text = TWO_RUNS_ONE_SAVING
        .replace("id = \"a\"\nlevels = 3\n", "id = \"a\"\nlevels = 3\ntheta = 0.7\nsave_levels = [2]\n")
        .replace("save_levels = [3]", "save_levels = [2, 3]");
    let m = manifest(&dir, &text);
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    let study = results_of(&dir);
    let record = |id: &str| -> signorini::records::RunRecord {
        serde_json::from_slice(&std::fs::read(study.join(format!("runs/{id}.json"))).unwrap()).unwrap()
    };
    let held: Vec<String> = record("b").snapshots.into_keys().collect();
    assert_eq!(held, ["b_level2.json", "b_level2.vtu", "b_level3.json", "b_level3.vtu"]);
    for (name, hash) in &record("a").snapshots {
        assert_eq!(*hash, signorini::base::digest::sha256_hex(&std::fs::read(study.join("meshes").join(name)).unwrap()), "{name}");
    }
    let pristine = contents(&study);
    let restore = || pristine.iter().for_each(|(f, b)| std::fs::write(study.join(f), b).unwrap());
    let refused = |what: &str, file: &str, why: &str| {
        for (code, out) in drift_and_figures(&dir) {
            assert!(code != 0 && out.contains(file) && out.contains(why), "{what}: {out}");
        }
        let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
        assert!(code != 0 && out.contains(file) && out.contains("Nothing was run or changed"), "{what}: {out}");
    };
    // the VTUs of runs a and b at level 2 swapped (both whole VTK files)
    let (va, vb) = (study.join("meshes/a_level2.vtu"), study.join("meshes/b_level2.vtu"));
    let (a_bytes, b_bytes) = (std::fs::read(&va).unwrap(), std::fs::read(&vb).unwrap());
    assert_ne!(a_bytes, b_bytes);
    std::fs::write(&va, &b_bytes).unwrap();
    std::fs::write(&vb, &a_bytes).unwrap();
    refused("swapped", "meshes/a_level2.vtu", "the snapshot was edited or is another run's");
    restore();
    // a contact force edited in the JSON the mesh figures (and the Hertz row) read
    let json = study.join("meshes/b_level3.json");
    let mut snap: signorini::records::MeshSnapshot = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    snap.contact_nodes[0].lambda += 1.0;
    signorini::records::write_json(&json, &snap).unwrap();
    refused("edited", "meshes/b_level3.json", "record of run b holds");
    restore();
    // a record whose hashes were taken out (as records were written before they were held)
    let mut bare = record("a");
    bare.snapshots.clear();
    signorini::records::write_json(&study.join("runs/a.json"), &bare).unwrap();
    refused("no hashes", "meshes/a_level2.json", "holds no sha256 for it");
    // --replace computes run a again, with its hashes and the same snapshots
    let (code, out) = signorini(&dir, &["run", m, "--results", "results", "--replace"]);
    assert!(code == 0 && out.contains("1 run(s) executed"), "{out}");
    assert_eq!(std::fs::read(&va).unwrap(), a_bytes);
    let stored = &pristine.iter().find(|(f, _)| f == "runs/a.json").unwrap().1;
    assert_eq!(record("a").snapshots, serde_json::from_slice::<signorini::records::RunRecord>(stored).unwrap().snapshots);
    for (code, out) in drift_and_figures(&dir) {
        assert_eq!(code, 0, "{out}");
    }
}

#[test]
fn a_truncated_levels_csv_in_the_folder_compared_is_an_error_not_no_drift() {
    let (dir, m) = stored("against");
    let (code, out) = signorini(&dir, &["run", m, "--results", "other"]);
    assert_eq!(code, 0, "{out}");
    let csv = dir.join("other/study/levels.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    std::fs::write(&csv, &text[..text.len() / 2]).unwrap();
    let (code, out) = signorini(&dir, &["drift", "--against", "other", "--experiments", ".", "--study", "study"]);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("--against other") && out.contains("levels.csv") && out.contains("not what runs/*.json render"), "{out}");
    assert!(!out.contains("no drift"), "{out}");
    // a provenance listing other runs is named the same way
    std::fs::write(&csv, &text).unwrap();
    let prov = dir.join("other/study/provenance.json");
    let p = std::fs::read_to_string(&prov).unwrap().replace("\"b\"", "\"c\"");
    std::fs::write(&prov, p).unwrap();
    let (code, out) = signorini(&dir, &["drift", "--against", "other", "--experiments", ".", "--study", "study"]);
    assert!(code != 0 && out.contains("provenance.json") && out.contains("lists the runs a c"), "{out}");
}

#[test]
fn report_refuses_an_image_that_is_not_a_png() {
    let figs = scratch("store-integrity-png");
    let study = "c0_sweep";
    let name = signorini::page::figures_of(study)[0];
    std::fs::write(figs.join(format!("{name}.png")), "<html>not an image</html>").unwrap();
    let out = figs.join("out");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let e = signorini::page::write_pages(
        &crate::common::shelf(&root.join("results")),
        &figs,
        &out,
        &[study.into()],
        &signorini::page::DriftReports::read(&[figs.join("none.json")], false, "signorini drift --study TWO_RUNS_ONE_SAVING").unwrap(),
        crate::common::roles(),
    )
    .unwrap_err();
    assert!(format!("{e:#}").contains(&format!("{name}.png is not a PNG image")), "{e:#}");
}

// ---- the inputs a run reads are part of its spec

#[test]
fn a_run_whose_problem_file_changed_is_a_changed_spec_naming_the_file() {
    let dir = scratch("store-integrity-inputs");
    let problems = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex71.toml");
    let text = std::fs::read_to_string(&problems).unwrap();
    std::fs::create_dir_all(dir.join("problems")).unwrap();
    std::fs::write(dir.join("problems/p.toml"), &text).unwrap();
    let m = manifest(&dir, &TWO_RUNS_ONE_SAVING.replace("problem = \"ex71\"", "problem = \"problems/p.toml\""));
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    let a: serde_json::Value = serde_json::from_slice(&std::fs::read(results_of(&dir).join("runs/a.json")).unwrap()).unwrap();
    assert_eq!(a["run"]["inputs"]["problems/p.toml"].as_str().map(str::len), Some(64), "{}", a["run"]);
    // the same file, one byte more: refused naming it, nothing changed, never "finished earlier, kept"
    std::fs::write(dir.join("problems/p.toml"), format!("{text}\n")).unwrap();
    let before = std::fs::read(results_of(&dir).join("runs/a.json")).unwrap();
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("the input file problems/p.toml changed") && !out.contains("finished earlier, kept"), "{out}");
    assert_eq!(std::fs::read(results_of(&dir).join("runs/a.json")).unwrap(), before);
    // figures refuse the study as computed with another spec
    let (code, out) = signorini(&dir, &["figures", "--results", "results", "--experiments", ".", "--figures", "figs"]);
    assert!(code != 0 && out.contains("the input file problems/p.toml changed"), "{out}");
    let (code, out) = signorini(&dir, &["run", m, "--results", "results", "--replace"]);
    assert!(code == 0 && out.contains("2 run(s) executed"), "{out}");
    // the same bytes under another name: said so, in one line, not "changed (none now)"
    std::fs::copy(dir.join("problems/p.toml"), dir.join("problems/q.toml")).unwrap();
    let m = manifest(&dir, &TWO_RUNS_ONE_SAVING.replace("problem = \"ex71\"", "problem = \"problems/q.toml\""));
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("the input file problems/p.toml is declared under another name now, problems/q.toml (the same content"), "{out}");
    assert!(!out.contains("none now") && !out.contains("problems/q.toml is not in the stored spec"), "{out}");
}

// ---- no concurrent process undoes a run (real processes, both orders)

/// A study of one small run (Example 7.1, 8 adaptive levels from structured:8): started with
/// [`spawn`], every change to its files waits 50 ms, so it is in progress for seconds (a second
/// process reliably starts while it runs) at the cost in computing of a fraction of a second.
const LONG: &str = r#"description = "store test: one run of a few seconds"
[defaults]
problem = "ex71"
mesh = "structured:8"
[[run]]
id = "a"
levels = 8
theta = 0.5
"#;

/// `signorini args` in `dir`, in the background, every change to its files paused 50 ms
/// ([`signorini::base::failpoint`]).
fn spawn(dir: &Path, args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(dir)
        .args(args)
        .env(signorini::base::failpoint::PAUSE_ENV, "50")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// Wait until run a's checkpoint exists: its process holds the run's lock and computes it.
fn computing(study: &Path) {
    let file = study.join(".partial/a.json");
    let start = std::time::Instant::now();
    while !file.exists() {
        assert!(start.elapsed().as_secs() < 120, "{} never appeared", file.display());
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

fn theta_of(study: &Path) -> f64 {
    let a: serde_json::Value = serde_json::from_slice(&std::fs::read(study.join("runs/a.json")).unwrap()).unwrap();
    a["run"]["theta"].as_f64().unwrap()
}

#[test]
fn a_second_manifest_waiting_for_a_run_never_replaces_it_without_replace_in_either_order() {
    let dir = scratch("store-integrity-two-manifests");
    long_manifests(&dir, "theta = 0.5", [("one", "theta = 0.5"), ("two", "theta = 0.6")]);
    for (first, second, theta) in [("one", "two", 0.5), ("two", "one", 0.6)] {
        let results = format!("results-{first}");
        let study = dir.join(&results).join("s");
        let p1 = spawn(&dir, &["run", &format!("{first}/s.toml"), "--results", &results]);
        computing(&study);
        let p2 = spawn(&dir, &["run", &format!("{second}/s.toml"), "--results", &results, "--wait"]);
        let ((c1, o1), (c2, o2)) = (finish(p1), finish(p2));
        assert_eq!(c1, 0, "{o1}");
        assert!(o2.contains("waiting for it to finish"), "the second process did not wait for the first: {o2}");
        assert_ne!(c2, 0, "{o2}");
        assert!(o2.contains("another process stored run a") && o2.contains("theta") && o2.contains("--replace"), "{o2}");
        assert_eq!(theta_of(&study), theta, "the first process's run was replaced");
        assert_eq!(consistent(&study), ["a"]);
    }
}

#[test]
fn fresh_never_removes_a_run_in_progress_in_either_order() {
    let dir = scratch("store-integrity-fresh");
    let m = manifest(&dir, LONG);
    let study = results_of(&dir).with_file_name("study");
    // a run computes; --fresh without --wait is refused naming it, and the run lands
    let p1 = spawn(&dir, &["run", m, "--results", "results"]);
    computing(&study);
    let (c2, o2) = signorini(&dir, &["run", m, "--results", "results", "--fresh"]);
    assert_ne!(c2, 0, "{o2}");
    assert!(o2.contains(&format!("is being written by process {}", p1.id())) && o2.contains("--wait"), "{o2}");
    let (c1, o1) = finish(p1);
    assert!(c1 == 0 && o1.contains("1 run(s) executed"), "{o1}");
    assert_eq!(consistent(&study), ["a"]);
    let stored = std::fs::read(study.join("runs/a.json")).unwrap();
    // a run computes; --fresh --wait waits for it, then starts over: the first run is not lost
    std::fs::remove_dir_all(&study).unwrap();
    let p1 = spawn(&dir, &["run", m, "--results", "results"]);
    computing(&study);
    let p2 = spawn(&dir, &["run", m, "--results", "results", "--fresh", "--wait"]);
    let ((c1, o1), (c2, o2)) = (finish(p1), finish(p2));
    assert!(c1 == 0 && o1.contains("1 run(s) executed"), "the run computing when --fresh started was lost: {o1}");
    assert!(c2 == 0 && o2.contains("waiting for it to finish") && o2.contains("1 run(s) executed"), "{o2}");
    assert_eq!(consistent(&study), ["a"]);
    // the other order: --fresh computes, a plain run waits and keeps what --fresh stored
    let p1 = spawn(&dir, &["run", m, "--results", "results", "--fresh"]);
    std::thread::sleep(std::time::Duration::from_millis(200)); // past --fresh's removal of the old checkpoint
    computing(&study);
    let p2 = spawn(&dir, &["run", m, "--results", "results", "--wait"]);
    let ((c1, o1), (c2, o2)) = (finish(p1), finish(p2));
    assert!(c1 == 0 && o1.contains("1 run(s) executed"), "{o1}");
    assert!(c2 == 0 && o2.contains("waiting for it to finish") && o2.contains("finished earlier, kept"), "{o2}");
    assert_eq!(consistent(&study), ["a"]);
    // every number the same however the processes met (timings aside)
    let numbers = |b: &[u8]| {
        let mut v: serde_json::Value = serde_json::from_slice(b).unwrap();
        for l in v["levels"].as_array_mut().unwrap() {
            l.as_object_mut().unwrap().retain(|k, _| !k.starts_with("t_") && !k.starts_with("mem_"));
        }
        v
    };
    assert_eq!(numbers(&std::fs::read(study.join("runs/a.json")).unwrap()), numbers(&stored));
}

/// The bytes of every file of a study folder, by relative path (the lock files, which name
/// their last holder, aside).
fn contents(study: &Path) -> Vec<(String, Vec<u8>)> {
    let locks = |f: &String| f == ".lock" || f.starts_with(".locks/");
    relative_files(study).into_iter().filter(|f| !locks(f)).map(|f| (f.clone(), std::fs::read(study.join(&f)).unwrap())).collect()
}

#[test]
fn a_hand_edited_record_or_summary_is_refused_by_run_and_replace_computes_it_again() {
    let (dir, m) = stored("edited");
    let study = results_of(&dir);
    let original: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(study.join("runs/a.json")).unwrap()).unwrap();
    let mut edited = original.clone();
    let estimate = edited["levels"][1]["estimate"].as_f64().unwrap();
    edited["levels"][1]["estimate"] = serde_json::json!(estimate * 1.01);
    std::fs::write(study.join("runs/a.json"), serde_json::to_string_pretty(&edited).unwrap()).unwrap();
    // a plain run refuses, naming the run whose record and rows disagree, and changes no file
    // (it rendered levels.csv from the edited record, and figures then drew the edited number)
    let before = contents(&study);
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("levels.csv") && out.contains("run a level 1") && out.contains("Nothing was run or changed"), "{out}");
    assert!(contents(&study) == before, "a refused run changed the folder");
    let (code, out) = signorini(&dir, &["figures", "--results", "results", "--experiments", ".", "--figures", "figs"]);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("study.toml --replace`"), "the advice names the study's manifest: {out}");
    // --replace computes run a again: the original number is back, not the edited one
    let (code, out) = signorini(&dir, &["run", m, "--results", "results", "--replace"]);
    assert_eq!(code, 0, "{out}");
    let again: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(study.join("runs/a.json")).unwrap()).unwrap();
    assert_eq!(again["levels"][1]["estimate"], original["levels"][1]["estimate"], "{out}");
    assert_eq!(consistent(&study), ["a", "b"]);
    // a summary alone at fault (a row deleted, provenance.json removed): refused, then rendered
    // again from the records with --replace (run b's rows are missing: b is computed again)
    let csv = std::fs::read_to_string(study.join("levels.csv")).unwrap();
    let cut: Vec<&str> = csv.lines().filter(|l| !l.starts_with("b,")).collect();
    std::fs::write(study.join("levels.csv"), cut.join("\n") + "\n").unwrap();
    std::fs::remove_file(study.join("provenance.json")).unwrap();
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("has no row of run b") && out.contains("provenance.json"), "{out}");
    let (code, out) = signorini(&dir, &["run", m, "--results", "results", "--replace"]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("1 run(s) executed"), "only b is computed again: {out}");
    assert_eq!(consistent(&study), ["a", "b"]);
    for (code, out) in drift_and_figures(&dir) {
        assert_eq!(code, 0, "{out}");
    }
}

/// A record is what the harness writes for the run it holds, byte for byte (`"bogus": 1`
/// in a level does not pass, though serde drops an unknown field): an unknown field or a record another program reformatted is a fault of its run,
/// refused by every reader and computed again by `run --replace`.
#[test]
fn a_record_with_an_unknown_field_or_another_format_is_a_fault_of_its_run() {
    let (dir, m) = stored("unknown-field");
    let study = results_of(&dir);
    let file = study.join("runs/a.json");
    let original = std::fs::read_to_string(&file).unwrap();
    let mut bogus: serde_json::Value = serde_json::from_str(&original).unwrap();
    bogus["levels"][1]["bogus"] = serde_json::json!(1);
    let compact = serde_json::to_string(&serde_json::from_str::<serde_json::Value>(&original).unwrap()).unwrap();
    for (case, text) in [("unknown field", serde_json::to_string_pretty(&bogus).unwrap() + "\n"), ("compact", compact + "\n")] {
        std::fs::write(&file, &text).unwrap();
        for (code, out) in drift_and_figures(&dir) {
            assert_ne!(code, 0, "{case}: {out}");
            assert!(out.contains("runs/a.json: is not what the harness writes"), "{case}: {out}");
        }
        let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
        assert_ne!(code, 0, "{case}: {out}");
        assert!(out.contains("is not what the harness writes") && out.contains("Nothing was run or changed"), "{case}: {out}");
        let (code, out) = signorini(&dir, &["run", m, "--results", "results", "--replace"]);
        assert_eq!(code, 0, "{case}: {out}");
        assert!(out.contains("1 run(s) executed"), "{case}: only a is computed again: {out}");
        for (code, out) in drift_and_figures(&dir) {
            assert_eq!(code, 0, "{case}: {out}");
        }
    }
}

/// A stored run that another process is replacing (`--replace`, another theta) is not "finished
/// earlier, kept" for its old manifest (saying so and exiting 0 while the
/// folder ends with the other's run): with --wait that run waits, then is refused naming the
/// other spec; without it, it is refused naming the process.
#[test]
fn a_run_being_replaced_is_not_kept_for_its_old_manifest() {
    let dir = scratch("store-integrity-being-replaced");
    long_manifests(&dir, "theta = 0.5", [("one", "theta = 0.5"), ("two", "theta = 0.6")]);
    let study = dir.join("results/s");
    let (code, out) = signorini(&dir, &["run", "one/s.toml", "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    for wait in [false, true] {
        let p1 = spawn(&dir, &["run", "two/s.toml", "--results", "results", "--replace"]);
        computing(&study);
        let mut args = vec!["run", "one/s.toml", "--results", "results"];
        if wait {
            args.push("--wait");
        }
        let (c2, o2) = signorini(&dir, &args);
        let (c1, o1) = finish(p1);
        assert_eq!(c1, 0, "{o1}");
        assert_ne!(c2, 0, "wait {wait}: {o2}");
        assert!(!o2.contains("finished earlier, kept"), "wait {wait}: {o2}");
        let says = if wait { "another process stored run a" } else { "is being written by process" };
        assert!(o2.contains(says), "wait {wait}: {o2}");
        assert_eq!(theta_of(&study), 0.6);
        assert_eq!(consistent(&study), ["a"]);
        // back to theta 0.5 for the next round
        let (code, out) = signorini(&dir, &["run", "one/s.toml", "--results", "results", "--replace"]);
        assert_eq!(code, 0, "{out}");
    }
}

/// Two manifests of one study that declare different runs, the second started while the first
/// computes: the second is refused before it computes anything, naming the run in progress; the first
/// lands and the folder holds its runs only (never both committed, matching neither manifest).
#[test]
fn a_second_manifest_with_other_runs_is_refused_while_the_first_computes() {
    let dir = scratch("store-integrity-other-runs");
    long_manifests(&dir, "id = \"a\"", [("one", "id = \"a\""), ("two", "id = \"b\"")]);
    let study = dir.join("results/s");
    let p1 = spawn(&dir, &["run", "one/s.toml", "--results", "results"]);
    computing(&study);
    let (c2, o2) = signorini(&dir, &["run", "two/s.toml", "--results", "results"]);
    let (c1, o1) = finish(p1);
    assert_eq!(c1, 0, "{o1}");
    assert_ne!(c2, 0, "{o2}");
    assert!(o2.contains("another process computes run(s) a") && o2.contains("does not declare") && o2.contains("nothing was run"), "{o2}");
    assert_eq!(consistent(&study), ["a"]);
}

/// The provenance lists the hash of every input a stored run read (its
/// meshes' and problem files'); one zeroed by hand is a fault of `provenance.json` for `run`,
/// `drift` and `figures`, not "kept".
#[test]
fn a_provenance_without_the_hash_of_an_input_a_run_read_is_refused() {
    let dir = scratch("store-integrity-provenance-inputs");
    let problems = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex71.toml");
    std::fs::create_dir_all(dir.join("problems")).unwrap();
    std::fs::copy(problems, dir.join("problems/p.toml")).unwrap();
    let m = manifest(&dir, &TWO_RUNS_ONE_SAVING.replace("problem = \"ex71\"", "problem = \"problems/p.toml\""));
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    let prov = results_of(&dir).join("provenance.json");
    let text = std::fs::read_to_string(&prov).unwrap();
    let mut p: serde_json::Value = serde_json::from_str(&text).unwrap();
    let hash = p["problem_files"][0]["sha256"].as_str().unwrap().to_string();
    p["problem_files"][0]["sha256"] = serde_json::json!("0".repeat(64));
    std::fs::write(&prov, serde_json::to_string_pretty(&p).unwrap() + "\n").unwrap();
    let says = format!("does not hold the sha256 {} of the input problems/p.toml that run a read", &hash[..12]);
    for (code, out) in drift_and_figures(&dir) {
        assert!(code != 0 && out.contains("provenance.json") && out.contains(&says), "{out}");
    }
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert!(code != 0 && out.contains("provenance.json") && out.contains(&says) && !out.contains("finished earlier, kept"), "{out}");
    // --replace writes the provenance again from the manifest
    let (code, out) = signorini(&dir, &["run", m, "--results", "results", "--replace"]);
    assert_eq!(code, 0, "{out}");
    assert!(std::fs::read_to_string(&prov).unwrap().contains(&hash));
}

/// Where a stored run has another spec than the manifest declares, the
/// advice `figures` gives is a command that completes the study when followed (a plain `run`
/// refuses such a run: the advice carries --replace).
#[test]
fn the_advice_to_complete_a_study_works_when_followed() {
    let (dir, _) = stored("advice");
    manifest(&dir, &TWO_RUNS_ONE_SAVING.replace("theta = 0.5", "theta = 0.7"));
    let (code, out) = signorini(&dir, &["figures", "--results", "results", "--experiments", ".", "--figures", "figs"]);
    assert_ne!(code, 0, "{out}");
    let advice = out.split("Complete it with `").nth(1).and_then(|t| t.split('`').next()).unwrap_or_else(|| panic!("no advice: {out}"));
    assert!(advice.ends_with("--replace"), "{advice}");
    let args: Vec<&str> = advice.split_whitespace().skip(1).collect();
    let (code, out) = signorini(&dir, &args);
    assert_eq!(code, 0, "following `{advice}`: {out}");
    let (code, out) = signorini(&dir, &["figures", "--results", "results", "--experiments", ".", "--figures", "figs"]);
    assert_eq!(code, 0, "{out}");
}

// ---- the read side of the door: what figures, report and the CLAIMS rows read is checked

/// Copy `from` into `to`, folders too.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let target = to.join(e.file_name());
        if e.path().is_dir() {
            copy_tree(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), &target).unwrap();
        }
    }
}

/// A page of one study still rests on CLAIMS rows read from every study: `report --study
/// c0_sweep` used to check c0_sweep alone, and the Hertz row then read a folder whose mesh
/// snapshot was deleted as "no data", exit 0. Every study is read through the integrity check
/// now: refused, naming the file.
#[test]
fn report_of_one_study_refuses_another_at_fault_that_its_claims_read() {
    let d = scratch("store-integrity-shelf-report");
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::os::unix::fs::symlink(repo.join("experiments"), d.join("experiments")).unwrap();
    for study in ["c0_sweep", "hertz"] {
        copy_tree(&repo.join("results").join(study), &d.join("results").join(study));
    }
    let report = ["report", "--results", "results", "--study", "c0_sweep", "--figures", "figs"];
    let (code, out) = signorini(&d, &report);
    assert_eq!(code, 0, "the sound copy is reported: {out}");
    std::fs::remove_file(d.join("results/hertz/meshes/adaptive_level19.json")).unwrap();
    let (code, out) = signorini(&d, &report);
    assert!(code != 0 && out.contains("adaptive_level19.json") && out.contains("missing"), "{out}");
    assert!(!out.contains("panicked"), "{out}");
}

/// The shelf hands out only what was checked: a study whose folder exists but was not opened
/// is an error naming it, one without a folder has no runs, and a snapshot the record does not
/// save is refused even when a file of that name is there.
#[test]
fn the_shelf_hands_out_only_what_the_check_read() {
    use signorini::store::{Shelf, ShelfError, Store};
    let d = scratch("store-integrity-shelf-lib");
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let results = d.join("results");
    for study in ["c0_sweep", "hertz"] {
        copy_tree(&repo.join("results").join(study), &results.join(study));
    }
    let shelf = Shelf::open(&results, [Store::new(&results, "hertz")]).unwrap();
    assert!(matches!(shelf.runs("c0_sweep"), Err(ShelfError::NotOpened { .. })), "an unchecked folder is not read");
    assert!(shelf.runs("fb").unwrap().is_empty(), "a study without a folder has no runs");
    assert_eq!(shelf.saved_levels("hertz", "adaptive").unwrap(), vec![19]);
    assert_eq!(shelf.mesh("hertz", "adaptive", 19).unwrap().level, 19);
    let stray = results.join("hertz/meshes/adaptive_level3.json");
    std::fs::copy(results.join("hertz/meshes/adaptive_level19.json"), &stray).unwrap();
    assert!(matches!(shelf.mesh("hertz", "adaptive", 3), Err(ShelfError::NotSaved { level: 3, .. })));
    assert!(matches!(shelf.mesh("hertz", "nope", 19), Err(ShelfError::NoRun { .. })));
    // a snapshot edited after the check is refused when it is read, not drawn
    let json = results.join("hertz/meshes/adaptive_level19.json");
    let bytes = std::fs::read(&json).unwrap();
    std::fs::write(&json, [&bytes[..], b" "].concat()).unwrap();
    let e = shelf.mesh("hertz", "adaptive", 19).unwrap_err();
    assert!(matches!(e, ShelfError::Snapshot { .. }) && format!("{e}").contains("is not the"), "{e}");
    std::fs::write(&json, &bytes).unwrap();
    // and the check itself stands in front: a folder at fault is no shelf
    std::fs::remove_file(results.join("hertz/meshes/adaptive_level19.json")).unwrap();
    let e = Shelf::open(&results, [Store::new(&results, "hertz")]).unwrap_err();
    assert!(format!("{e:#}").contains("adaptive_level19.json"), "{e:#}");
}

/// `one/s.toml` and `two/s.toml` in `dir`: the manifest LONG with `from` replaced by each text.
fn long_manifests(dir: &Path, from: &str, variants: [(&str, &str); 2]) {
    for (sub, to) in variants {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
        std::fs::write(dir.join(sub).join("s.toml"), LONG.replace(from, to)).unwrap();
    }
}

// ---- what a record stores is what its run read, and what the summaries render is sound

/// Wait until `file` exists (a run's checkpoint: its process computes it).
fn appears(file: &Path) {
    let start = std::time::Instant::now();
    while !file.exists() {
        assert!(start.elapsed().as_secs() < 120, "{} never appeared", file.display());
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// `text` with the number after its first `"estimate": ` replaced by `value`, the rest of the
/// bytes as they are (an edit the record's format check cannot see).
fn first_estimate_set(text: &str, value: &str) -> String {
    let at = text.find("\"estimate\": ").unwrap() + "\"estimate\": ".len();
    let end = at + text[at..].find([',', '\n']).unwrap();
    format!("{}{value}{}", &text[..at], &text[end..])
}

/// A problem file edited while an earlier run of the study computes (after the study was planned)
/// is refused by name when the later run reads it, never computed and stored under the planned
/// hash; the earlier run is kept, and with the file as planned the later run is computed with
/// its hash (a record never holds the planned hash of bytes it never read).
#[test]
fn an_input_file_edited_while_the_study_runs_is_refused_by_name_not_stored_under_the_old_hash() {
    let dir = scratch("store-integrity-input-edited");
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex71.toml")).unwrap();
    std::fs::write(dir.join("p.toml"), &text).unwrap();
    let m = manifest(&dir, &format!("{LONG}[[run]]\nid = \"b\"\nproblem = \"p.toml\"\nmesh = \"structured:2\"\nlevels = 3\n"));
    let study = results_of(&dir);
    let child = spawn(&dir, &["run", m, "--results", "results", "--jobs", "1"]);
    appears(&study.join(".partial/a.json"));
    std::fs::write(dir.join("p.toml"), format!("{text}\n# edited while run a computes\n")).unwrap();
    let (code, out) = finish(child);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("the input file") && out.contains("p.toml changed while the study ran: planned sha256"), "{out}");
    assert!(study.join("runs/a.json").exists() && !study.join("runs/b.json").exists(), "{:?}", relative_files(&study));
    assert_eq!(consistent(&study), ["a"]);
    // the file as planned again: b is computed from it and holds its hash
    std::fs::write(dir.join("p.toml"), &text).unwrap();
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert!(code == 0 && out.contains("1 run(s) executed"), "{out}");
    let b: serde_json::Value = serde_json::from_slice(&std::fs::read(study.join("runs/b.json")).unwrap()).unwrap();
    assert_eq!(b["run"]["inputs"]["p.toml"].as_str(), Some(signorini::base::digest::sha256_hex(text.as_bytes()).as_str()));
}

/// A record edited while another process commits a run is not rendered into levels.csv: the
/// commit checks the folder as `run` does at its start, refuses naming the record, and the next
/// `run` refuses it too (the edit is never laundered into a folder that run, figures and
/// report pass).
#[test]
fn a_record_edited_while_another_run_commits_is_refused_not_rendered_into_levels_csv() {
    let (dir, _) = stored("laundered");
    let study = results_of(&dir);
    let m = manifest(&dir, &format!("{TWO_RUNS_ONE_SAVING}\n[[run]]\nid = \"c\"\nmesh = \"structured:8\"\nlevels = 8\ntheta = 0.5\n"));
    let child = spawn(&dir, &["run", m, "--results", "results", "--jobs", "1"]);
    appears(&study.join(".partial/c.json"));
    let a = std::fs::read_to_string(study.join("runs/a.json")).unwrap();
    std::fs::write(study.join("runs/a.json"), first_estimate_set(&a, "123.5")).unwrap();
    let (code, out) = finish(child);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("run c is not stored") && out.contains("runs/a.json"), "{out}");
    let csv = std::fs::read_to_string(study.join("levels.csv")).unwrap();
    assert!(!csv.contains(",123.5,"), "the edited record was rendered into levels.csv:\n{csv}");
    assert!(!study.join("runs/c.json").exists());
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert!(code != 0 && out.contains("run a level 0"), "{out}");
    let (code, out) = signorini(&dir, &["figures", "--results", "results", "--experiments", ".", "--figures", "figs"]);
    assert_ne!(code, 0, "{out}");
    // --replace computes a again and stores c: the folder is sound, and the edit is gone
    let (code, out) = signorini(&dir, &["run", m, "--results", "results", "--replace"]);
    assert_eq!(code, 0, "{out}");
    assert_eq!(consistent(&study), ["a", "b", "c"]);
    assert!(!std::fs::read_to_string(study.join("levels.csv")).unwrap().contains(",123.5,"));
}

/// The stored record of a reference solution's last level is checked against its replay, as the
/// drift check compares levels: an edited estimate or active-node count fails `drift` naming the
/// field; the unedited reference replays to no drift.
#[test]
fn an_edited_last_level_of_a_stored_reference_fails_drift_naming_the_field() {
    let dir = scratch("store-integrity-reference-last");
    let m = manifest(
        &dir,
        "description = \"ex72 with a small reference\"\n[defaults]\nproblem = \"ex72\"\nmesh = \"structured:4\"\nquick_levels = 2\n\
         [defaults.reference]\ntheta = 0.5\nmin_ndof = 3000\n[[run]]\nid = \"a\"\nlevels = 3\n",
    );
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    let drift = |dir: &Path| signorini(dir, &["drift", "--study", "study", "--results", "results", "--experiments", "."]);
    let (code, out) = drift(&dir);
    assert!(code == 0 && out.contains("drift: none"), "{out}");
    let refs = results_of(&dir).join("references");
    let file = std::fs::read_dir(&refs).unwrap().flatten().map(|e| e.path()).find(|p| p.extension().is_some_and(|x| x == "json")).unwrap();
    let text = std::fs::read_to_string(&file).unwrap();
    std::fs::write(&file, first_estimate_set(&text, "1000000000.0")).unwrap();
    let (code, out) = drift(&dir);
    assert_ne!(code, 0, "{out}");
    assert!(out.contains("is not what the replay gives") && out.contains("estimate stored 1000000000.0"), "{out}");
    assert!(!out.contains("drift: none"), "{out}");
}

/// Two concurrent `run --fresh --wait` and a `run --wait` on a stored study ): every process ends well, the folder holds both runs, and a `--fresh`
/// process that finds a run another process stored after it started over says so; it never
/// says "finished earlier, kept (use --fresh to start over)", advice it has followed. (Which
/// process computes what depends on the timing; the messages must be true in every order.)
#[test]
fn a_fresh_process_that_keeps_a_run_another_stored_says_so_in_every_order() {
    let dir = scratch("store-integrity-fresh-twice");
    let m = manifest(&dir, &format!("{LONG}[[run]]\nid = \"b\"\nmesh = \"structured:2\"\nlevels = 3\n"));
    let study = results_of(&dir);
    let (code, out) = signorini(&dir, &["run", m, "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    let fresh = ["run", m, "--results", "results", "--jobs", "1", "--fresh", "--wait"];
    let p1 = spawn(&dir, &fresh);
    std::thread::sleep(std::time::Duration::from_millis(300));
    let p2 = spawn(&dir, &fresh);
    std::thread::sleep(std::time::Duration::from_millis(300));
    let p3 = spawn(&dir, &["run", m, "--results", "results", "--jobs", "1", "--wait"]);
    for (name, child) in [("P1 --fresh", p1), ("P2 --fresh", p2), ("P3", p3)] {
        let (code, out) = finish(child);
        assert_eq!(code, 0, "{name}: {out}");
        if name.contains("fresh") {
            assert!(!out.contains("use --fresh to start over"), "{name}: {out}");
        }
    }
    assert_eq!(consistent(&study), ["a", "b"]);
}
