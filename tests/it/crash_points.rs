//! Every writing command stopped at each change it makes to the filesystem, the way a kill
//! stops it (`SIGNORINI_FAILPOINT=K`: before its K-th change, no cleanup), for every K until the
//! command finishes; after each stop, what is left must hold together:
//! - every run stored before the command is there whole, as it was or as the command makes it
//!   (a reader either reads the folder or refuses it naming the change left part-way, and the
//!   next writer completes that change first);
//! - nothing half-written is read as data (files outside the store: each is as it was before
//!   the command or as a finished command writes it; the rest are temporary files);
//! - the command run again completes, and its results are the uninterrupted command's (the
//!   drift check's comparison finds no difference).

use crate::common::{copy_tree, scratch, signorini_in};
use signorini::manifest::Manifest;
use signorini::store::Store;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The study every case writes: one adaptive run saving a snapshot, one uniform run.
const TINY: &str = "description = \"two short runs\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\n\
[[run]]\nid = \"adaptive\"\nlevels = 2\nsave_levels = [1]\n[[run]]\nid = \"uniform\"\nrefine = \"uniform\"\nlevels = 2\n";

/// The same study with the adaptive run one level longer (a run `--replace` replaces).
fn longer() -> String {
    TINY.replacen("levels = 2\nsave_levels", "levels = 3\nsave_levels", 1)
}

/// A writing command and the folder it starts from.
struct Case {
    name: &'static str,
    /// Whether the study is stored before the command.
    stored: bool,
    args: &'static [&'static str],
    /// The command that completes what a stopped one left (`None`: the command itself).
    completes: Option<&'static [&'static str]>,
    /// Whether the command removes stored runs on purpose (`--fresh`): then a stored run may be gone.
    removes: bool,
}

const CASES: &[Case] = &[
    Case { name: "run", stored: false, args: &["run", "experiments/tiny.toml", "--results", "R"], completes: None, removes: false },
    Case {
        name: "run-replace",
        stored: true,
        args: &["run", "next/tiny.toml", "--replace", "--results", "R"],
        completes: None,
        removes: false,
    },
    Case {
        name: "run-fresh",
        stored: true,
        args: &["run", "experiments/tiny.toml", "--fresh", "--results", "R"],
        completes: Some(&["run", "experiments/tiny.toml", "--results", "R"]),
        removes: true,
    },
    Case {
        name: "drift-accept",
        stored: true,
        args: &["drift", "--accept", "tiny", "--experiments", "experiments", "--results", "R"],
        completes: None,
        removes: false,
    },
    Case {
        name: "figures",
        stored: true,
        args: &["figures", "--results", "R", "--experiments", "experiments"],
        completes: None,
        removes: false,
    },
    Case {
        name: "report",
        stored: true,
        args: &["report", "--results", "R", "--experiments", "experiments"],
        completes: None,
        removes: false,
    },
    Case {
        name: "export",
        stored: false,
        args: &["export", "--problem", "ex71", "--mesh", "structured:2", "--out", "out"],
        completes: None,
        removes: false,
    },
    Case {
        name: "adapt-save",
        stored: false,
        args: &["adapt", "--problem", "ex71", "--mesh", "structured:2", "--levels", "2", "--save", "out/last.vtu"],
        completes: None,
        removes: false,
    },
];

/// The starting folder of a case: the manifests, the study stored if the case wants it.
fn start(case: &Case) -> PathBuf {
    let dir = scratch(&format!("crash-{}", case.name));
    for (file, text) in [("experiments/tiny.toml", TINY.to_string()), ("next/tiny.toml", longer())] {
        std::fs::create_dir_all(dir.join(file).parent().unwrap()).unwrap();
        std::fs::write(dir.join(file), text).unwrap();
    }
    std::fs::create_dir_all(dir.join("out")).unwrap();
    if case.stored {
        let (code, out, err) = signorini_in(&dir, &["run", "experiments/tiny.toml", "--results", "R"]);
        assert_eq!(code, 0, "{out}{err}");
    }
    dir
}

/// The command run in `dir` with its failpoint at `k` (0: none): (exit code, stderr).
fn run_stopped(dir: &Path, args: &[&str], k: usize) -> (i32, String) {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"));
    cmd.args(args).current_dir(dir);
    if k > 0 {
        cmd.env(signorini::base::failpoint::ENV, k.to_string());
    }
    let out = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "{args:?} stopped at {k}: {err}");
    (out.status.code().unwrap_or_else(|| panic!("{args:?}: killed by a signal\n{err}")), err)
}

/// Every file under `dir` but the locks, by path relative to it, with its bytes.
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(read) = std::fs::read_dir(&d) else { continue };
        for e in read.flatten() {
            let p = e.path();
            if e.file_type().unwrap().is_dir() {
                stack.push(p);
            } else if !p.to_string_lossy().ends_with(".lock") {
                out.insert(p.strip_prefix(dir).unwrap().to_path_buf(), std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// A record's levels as JSON with the measurements (t_*, mem_*) left out: what a rerun reproduces.
fn reproducible(record: &signorini::records::RunRecord) -> serde_json::Value {
    let mut v = serde_json::to_value(&record.levels).unwrap();
    for level in v.as_array_mut().unwrap() {
        level.as_object_mut().unwrap().retain(|k, _| !signorini::level::record::is_measurement(k));
    }
    serde_json::json!({ "run": record.run, "levels": v })
}

/// The stored study in `results` after a stop, as the next writer finds it (a change left
/// part-way completed first), checked whole: its records by run id.
fn recovered(results: &Path, what: &str) -> BTreeMap<String, serde_json::Value> {
    let store = Store::new(results, "tiny");
    if !store.dir().root.exists() {
        return BTreeMap::new();
    }
    if let Err(e) = store.check() {
        assert!(format!("{e:#}").contains("stopped part-way"), "{what}: a reader refused the folder for another reason: {e:#}");
    }
    let writer = store.lock(false).unwrap_or_else(|e| panic!("{what}: {e:#}"));
    let checked = writer.check().unwrap();
    let at_fault: Vec<String> = checked.faults.iter().filter(|f| f.record.is_some()).map(|f| f.to_string()).collect();
    assert!(at_fault.is_empty(), "{what}: runs not whole: {at_fault:?}");
    checked.runs.iter().map(|r| (r.run.id.clone(), reproducible(r))).collect()
}

fn check_case(case: &Case) {
    let origin = start(case);
    let before = recovered(&origin.join("R"), "before");
    let clean = origin.with_extension("clean");
    let _ = std::fs::remove_dir_all(&clean);
    copy_tree(&origin, &clean);
    let (code, err) = run_stopped(&clean, case.args, 0);
    assert_eq!(code, 0, "{}: {err}", case.name);
    let after = recovered(&clean.join("R"), "after");
    let (files_before, files_after) = (files(&origin), files(&clean));
    let completes = case.completes.unwrap_or(case.args);
    let mut k = 1;
    loop {
        let work = origin.with_extension(format!("stop{k}"));
        let _ = std::fs::remove_dir_all(&work);
        copy_tree(&origin, &work);
        let (code, err) = run_stopped(&work, case.args, k);
        if code == 0 {
            std::fs::remove_dir_all(&work).unwrap();
            break;
        }
        let what = format!("{} stopped before change {k}", case.name);
        assert_eq!(code, signorini::base::failpoint::EXIT, "{what}: {err}");
        // files outside the store: as before, as after, or a temporary file
        for (path, bytes) in files(&work) {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let known = files_before.get(&path) == Some(&bytes) || files_after.get(&path) == Some(&bytes);
            let temporary = signorini::records::is_temporary(&name) || name.contains(".tmp");
            let store = path.starts_with("R/tiny") || path.starts_with("R/.accept");
            assert!(known || temporary || store, "{what}: {} is neither the file before nor after", path.display());
        }
        let runs = recovered(&work.join("R"), &what);
        for (id, record) in &before {
            match runs.get(id) {
                Some(r) => assert!(r == record || after.get(id) == Some(r), "{what}: run {id} is neither the stored one nor the new one"),
                None => assert!(case.removes, "{what}: run {id} was lost"),
            }
        }
        let (code, err) = run_stopped(&work, completes, 0);
        assert_eq!(code, 0, "{what}, then run again: {err}");
        assert_eq!(recovered(&work.join("R"), &what), after, "{what}, then run again: the results differ from the uninterrupted command's");
        std::fs::remove_dir_all(&work).unwrap();
        k += 1;
    }
    assert!(k > 2, "{}: stopped at only {} change(s): the failpoint does not reach its writes", case.name, k - 1);
    for d in [origin, clean] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

#[test]
fn every_writer_stopped_at_every_change_leaves_each_run_whole_and_completes() {
    std::thread::scope(|s| {
        let handles: Vec<_> = CASES.iter().map(|case| s.spawn(move || check_case(case))).collect();
        for h in handles {
            h.join().unwrap();
        }
    });
}

#[test]
fn the_manifest_and_the_results_the_crash_cases_read_are_the_declared_ones() {
    let m = Manifest::parse(Path::new("experiments/tiny.toml"), TINY).unwrap();
    assert_eq!(m.runs.len(), 2);
    assert_eq!(Manifest::parse(Path::new("next/tiny.toml"), &longer()).unwrap().runs[0].spec.levels, 3);
}

/// A study whose second run is long enough to be interrupted while it computes.
const LONG: &str = "description = \"a short run, then a long one\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\n\
[[run]]\nid = \"short\"\nlevels = 2\nsave_levels = [1]\n[[run]]\nid = \"long\"\nlevels = 16\n";

#[test]
fn an_interrupted_drift_accept_leaves_every_stored_run_as_it_was() {
    let dir = scratch("accept-interrupted");
    crate::common::stored_study(&dir, "exp/s.toml", LONG, "res");
    let before = files(&dir.join("res/s"));
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["drift", "--accept", "s", "--experiments", "exp", "--results", "res"])
        .stderr(std::process::Stdio::piped())
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // interrupted once the staged rerun has finished a run and is inside the next one
    let staged = dir.join("res/.accept/s/.partial/long.json");
    let started = std::time::Instant::now();
    while !staged.exists() {
        assert!(started.elapsed().as_secs() < 120, "the rerun never reached the long run");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) }, 0);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(err.contains("is unchanged (every stored run kept)") && err.contains("signorini drift --accept s"), "{err}");
    assert_eq!(files(&dir.join("res/s")), before, "the stored study changed");
    // accepted again, uninterrupted: the staging folder is started over and then gone
    let (code, _, err) = signorini_in(&dir, &["drift", "--accept", "s", "--experiments", "exp", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    assert!(!dir.join("res/.accept").exists(), "the staging folder stayed");
    std::fs::remove_dir_all(&dir).ok();
}
