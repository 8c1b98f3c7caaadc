//! The store's writers and the command line under hostile conditions: a journal crafted or
//! damaged by hand, files planted where the store writes, symlinks, odd places for the results.
//! Each test names the behaviour the store promises (docs/command-line.md, "What the store
//! owns, and what an interrupt leaves") in a case built to break it.

use crate::common::{scratch, signorini_in, stored_study};
use std::path::Path;

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
