//! The results store survives shards, interrupts and concurrent runs: `--fresh --shard K/N`
//! removes only shard K's runs; a second process running the same study is refused (or waits)
//! and deletes nothing, while shards compute side by side and never the same run twice; an interrupted study keeps its finished runs with summaries that
//! describe exactly them, and `figures` refuses it.

use crate::common::{fixture_path, scratch};
use signorini::check_complete;
use signorini::manifest::Manifest;
use signorini::records::StudyDir;
use signorini::store::Store;
use signorini::study::drift;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn signorini(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_signorini")).args(args).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned() + &String::from_utf8_lossy(&out.stdout);
    assert!(!err.contains("panicked"), "{err}");
    (out.status.code(), err)
}

/// `signorini run` of the tiny study with --wait, in the background (stderr captured).
fn run_waiting(res: &str) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["run", &fixture_path("tiny.toml"), "--quick", "--wait", "--results", res])
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap()
}

/// A study of several runs long enough to be interrupted in the middle (about a second each).
fn long_manifest(dir: &Path) -> PathBuf {
    let f = dir.join("long.toml");
    let mut text = String::from(
        "description = \"runs to interrupt\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\nlevels = 18\nsave_levels = [2]\n",
    );
    for i in 0..6 {
        text += &format!("[[run]]\nid = \"r{i}\"\ntheta = 0.{}\n", 3 + i);
    }
    std::fs::write(&f, text).unwrap();
    f
}

#[test]
fn fresh_shard_removes_only_its_own_runs() {
    let d = scratch("store-shard");
    let res = d.to_str().unwrap();
    assert_eq!(signorini(&["run", &fixture_path("tiny.toml"), "--quick", "--shard", "2/2", "--results", res]).0, Some(0));
    let dir = StudyDir::new(&d, "tiny");
    assert!(dir.run_file("b").exists());
    let (code, err) = signorini(&["run", &fixture_path("tiny.toml"), "--quick", "--shard", "1/2", "--fresh", "--results", res]);
    assert_eq!(code, Some(0), "{err}");
    let ids: Vec<String> = dir.read_runs().unwrap().iter().map(|r| r.run.id.clone()).collect();
    assert_eq!(ids, ["a", "b"], "shard 1's --fresh removed shard 2's run");
    // the summaries describe both
    let runs = dir.read_runs().unwrap();
    assert!(drift::check_derived(&Store::new(&d, "tiny"), &runs).is_empty());
}

#[test]
fn a_second_run_of_the_same_study_is_refused_or_waits_and_loses_nothing() {
    let d = scratch("store-lock");
    let res = d.to_str().unwrap();
    assert_eq!(signorini(&["run", &fixture_path("tiny.toml"), "--quick", "--shard", "2/2", "--results", res]).0, Some(0));
    let dir = StudyDir::new(&d, "tiny");
    let before = std::fs::read(dir.run_file("b")).unwrap();
    let store = Store::new(&d, "tiny");
    let lock = store.lock(false).unwrap();
    // refused after the lock's patience (1 s here, 30 by default), naming the holder; with
    // --fresh it must not have deleted anything
    let out = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["run", &fixture_path("tiny.toml"), "--quick", "--fresh", "--results", res])
        .env("SIGNORINI_LOCK_PATIENCE", "1")
        .output()
        .unwrap();
    let (code, err) = (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned());
    assert_ne!(code, Some(0));
    assert!(
        err.contains("is being written by process")
            && err.contains(&std::process::id().to_string())
            && err.contains("--wait")
            && err.contains("held for more than 1 s"),
        "{err}"
    );
    assert_eq!(std::fs::read(dir.run_file("b")).unwrap(), before, "the refused run touched the other's run");
    assert!(!dir.run_file("a").exists());
    // with --wait it waits for the lock, then runs
    let child = run_waiting(res);
    std::thread::sleep(Duration::from_millis(1500));
    assert!(!dir.run_file("a").exists(), "ran while the lock was held");
    drop(lock);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("waiting for it to finish"), "{err}");
    assert!(dir.run_file("a").exists() && dir.run_file("b").exists());
}

#[test]
fn an_interrupted_study_keeps_consistent_summaries_and_figures_refuse_it() {
    let d = scratch("store-interrupt");
    let exp = d.join("experiments");
    std::fs::create_dir_all(&exp).unwrap();
    let manifest = long_manifest(&exp);
    let res = d.join("results");
    let dir = StudyDir::new(&res, "long");
    let mut child = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["run", manifest.to_str().unwrap(), "--fresh", "--results", res.to_str().unwrap()])
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !dir.run_file("r0").exists() {
        assert!(t0.elapsed() < Duration::from_secs(120), "the first run did not finish");
        std::thread::sleep(Duration::from_millis(10));
    }
    std::thread::sleep(Duration::from_millis(100)); // inside the second run
    assert!(Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success());
    let status = child.wait().unwrap();
    let mut err = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("interrupted; kept") && err.contains("Resume with `signorini run"), "{err}");
    let runs = dir.read_runs().unwrap();
    assert!(!runs.is_empty() && runs.len() < 6, "{} runs kept", runs.len());
    // the summaries describe exactly the runs kept; no mesh of an unfinished run is left
    assert!(
        drift::check_derived(&Store::new(&res, "long"), &runs).is_empty(),
        "{:?}",
        drift::check_derived(&Store::new(&res, "long"), &runs)
    );
    let csv = std::fs::read_to_string(dir.csv_file()).unwrap();
    assert_eq!(csv.lines().count(), 1 + runs.iter().map(|r| r.levels.len()).sum::<usize>());
    for e in std::fs::read_dir(dir.root.join("meshes")).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        assert!(runs.iter().any(|r| name.starts_with(&format!("{}_level", r.run.id))), "mesh of an unfinished run left: {name}");
    }
    // figures refuse the partial study, naming what is missing, and write nothing
    let m = Manifest::load(&manifest).unwrap();
    let missing = m.runs.iter().map(|p| p.spec.id.clone()).find(|id| !runs.iter().any(|r| &r.run.id == id)).unwrap();
    assert!(check_complete(&m, &res).is_err());
    let figs = d.join("figures");
    let (code, err) = signorini(&[
        "figures",
        "--experiments",
        exp.to_str().unwrap(),
        "--results",
        res.to_str().unwrap(),
        "--figures",
        figs.to_str().unwrap(),
    ]);
    assert_ne!(code, Some(0));
    assert!(err.contains(&format!("run {missing} is missing")) && err.contains("signorini run"), "{err}");
    assert!(!figs.exists(), "figures were drawn from a partial study");
    // resuming completes it
    let (code, err) = signorini(&["run", manifest.to_str().unwrap(), "--results", res.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert!(check_complete(&m, &res).is_ok());
}

#[test]
fn shards_compute_side_by_side_and_a_run_is_computed_once() {
    let d = scratch("store-runlock");
    let res = d.to_str().unwrap();
    let dir = StudyDir::new(&d, "tiny");
    // another process computes run a now: it holds a's lock and has a temporary file staged
    let store = Store::new(&d, "tiny");
    let a = store.lock_run("a", false).unwrap();
    let staged = dir.root.join("meshes").join(format!(".a_level0.json.tmp{}.0", std::process::id()));
    std::fs::create_dir_all(staged.parent().unwrap()).unwrap();
    std::fs::write(&staged, "half written").unwrap();
    // shard 2/2 (run b) neither waits for a nor removes a's file in progress
    let (code, err) = signorini(&["run", &fixture_path("tiny.toml"), "--quick", "--shard", "2/2", "--results", res]);
    assert_eq!(code, Some(0), "{err}");
    assert!(dir.run_file("b").exists() && !dir.run_file("a").exists());
    assert!(staged.exists(), "removed a file of a run in progress: {err}");
    // the whole study without --wait: refused at run a, naming the holder
    let (code, err) = signorini(&["run", &fixture_path("tiny.toml"), "--quick", "--results", res]);
    assert_ne!(code, Some(0));
    assert!(
        err.contains("run a of") && err.contains("is being written by process") && err.contains(&std::process::id().to_string()),
        "{err}"
    );
    // with --wait: waits for a, then computes it once (b is kept)
    let b_before = std::fs::read(dir.run_file("b")).unwrap();
    let child = run_waiting(res);
    std::thread::sleep(Duration::from_millis(1500));
    assert!(!dir.run_file("a").exists(), "computed a while its lock was held");
    std::fs::remove_file(&staged).unwrap(); // the holder's staged file goes with it
    drop(a);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("waiting for it to finish") && err.contains("1 run(s) executed"), "{err}");
    assert_eq!(std::fs::read(dir.run_file("b")).unwrap(), b_before, "b was computed again");
    let runs = dir.read_runs().unwrap();
    assert_eq!(runs.iter().map(|r| r.run.id.as_str()).collect::<Vec<_>>(), ["a", "b"]);
    assert!(drift::check_derived(&Store::new(&d, "tiny"), &runs).is_empty());
}

#[test]
fn a_stored_run_another_process_computes_is_not_removed_by_replace() {
    let d = scratch("store-claim");
    let res = d.to_str().unwrap();
    assert_eq!(signorini(&["run", &fixture_path("tiny.toml"), "--quick", "--results", res]).0, Some(0));
    let dir = StudyDir::new(&d, "tiny");
    // the stored run b is no longer declared, and another process holds b's lock (computes it
    // under an older manifest): --replace must not remove what that process is writing
    let exp = d.join("exp");
    std::fs::create_dir_all(&exp).unwrap();
    let text = std::fs::read_to_string(fixture_path("tiny.toml")).unwrap();
    let cut = text.find("[[run]]\nid = \"b\"").expect("the fixture declares run b");
    let only_a = exp.join("tiny.toml");
    std::fs::write(&only_a, &text[..cut]).unwrap();
    let store = Store::new(&d, "tiny");
    let b = store.lock_run("b", false).unwrap();
    let before = std::fs::read(dir.run_file("b")).unwrap();
    let (code, err) = signorini(&["run", only_a.to_str().unwrap(), "--quick", "--replace", "--results", res]);
    assert_ne!(code, Some(0), "{err}");
    // refused at set-up, naming the run another manifest's process computes (before the claim
    // of run b under the study lock would refuse its removal)
    assert!(err.contains("another process computes run(s) b of") && err.contains("nothing was run"), "{err}");
    assert_eq!(std::fs::read(dir.run_file("b")).unwrap(), before, "the record of a run in progress was removed");
    drop(b);
    let (code, err) = signorini(&["run", only_a.to_str().unwrap(), "--quick", "--replace", "--results", res]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!dir.run_file("b").exists() && dir.run_file("a").exists(), "{err}");
}

#[test]
fn a_temporary_file_of_a_running_writer_is_not_a_leftover() {
    let d = scratch("store-writer");
    let res = d.to_str().unwrap();
    assert_eq!(signorini(&["run", &fixture_path("tiny.toml"), "--quick", "--shard", "2/2", "--results", res]).0, Some(0));
    let dir = StudyDir::new(&d, "tiny");
    // another process commits levels.csv now (its name is in the temporary's), and one that has
    // ended left its own
    let mut writer = Command::new("sleep").arg("30").spawn().unwrap();
    let live = dir.root.join(format!(".levels.csv.tmp{}.0", writer.id()));
    let dead = dir.root.join(format!(".provenance.json.tmp{}.0", 1 << 23));
    std::fs::write(&live, "being written").unwrap();
    std::fs::write(&dead, "left").unwrap();
    let checked = Store::new(&d, "tiny").check().unwrap();
    writer.kill().unwrap();
    writer.wait().unwrap();
    assert_eq!(checked.leftovers, [dead], "{:?}", checked.leftovers);
}

/// The study lock is held only to set up and to commit: a run that finds it taken waits for it
/// (up to 30 s) without --wait, so two shards started at the same moment both run (the second is not
/// refused).
#[test]
fn a_study_lock_held_briefly_is_waited_for_without_wait() {
    let d = scratch("store-brief-lock");
    let res = d.to_str().unwrap();
    let store = Store::new(&d, "tiny");
    let lock = store.lock(false).unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["run", &fixture_path("tiny.toml"), "--quick", "--shard", "1/2", "--results", res])
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1000));
    drop(lock);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(StudyDir::new(&d, "tiny").run_file("a").exists(), "{err}");
}
