//! Files that are not what they should be: a named pipe, a device or a link where a regular file is
//! expected (a manifest, problem, mesh, record, snapshot, summary or lock), or a file where a folder
//! must be, is refused naming it, at once and without reading it; no write replaces one.

use crate::common::{SHORT_RUN_STUDY, fixture, one_run_manifest, scratch, signorini_in, signorini_in_time, stored_study, stored_two_runs};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// A named pipe as a lock file (`.lock` or `.locks/RUN.lock`) does not block `report`, `figures`
/// and `drift` looking at the locks: a lock file that is not a regular file is refused by its
/// metadata, naming it, as writers refuse it.
#[test]
fn a_reader_refuses_a_lock_file_that_is_a_pipe_without_hanging() {
    let dir = scratch("special-files-fifo-reader-refuses-lock");
    stored_study(
        &dir,
        "experiments/s.toml",
        "description = \"fifo\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\n[[run]]\nid = \"a\"\nlevels = 3\n",
        "res",
    );
    for lock in ["res/s/.lock", "res/s/.locks/a.lock"] {
        let path = dir.join(lock);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::remove_file(&path).ok();
        let made = std::process::Command::new("mkfifo").arg(&path).status().unwrap();
        assert!(made.success());
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
            .current_dir(&dir)
            .args(["report", "--results", "res", "--out", "page"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let start = std::time::Instant::now();
        while child.try_wait().unwrap().is_none() {
            if start.elapsed().as_secs() > 60 {
                child.kill().ok();
                panic!("report hung on the named pipe {lock}");
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let o = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{lock}: {err}");
        assert!(err.contains(&format!("the lock file res/s/{}", lock.trim_start_matches("res/s/"))) && err.contains("named pipe"), "{err}");
        std::fs::remove_file(&path).unwrap();
    }
    std::fs::remove_dir_all(&dir).ok();
}

const TWO_RUNS_OF_TWO_AND_THREE_LEVELS: &str = "description = \"two runs\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\n[[run]]\nid = \"a\"\nlevels = 2\n[[run]]\nid = \"b\"\nlevels = 3\n";

#[test]
fn a_lock_folder_that_is_a_file_is_named_also_when_every_run_is_finished() {
    let dir = scratch("special-files-locks");
    stored_study(&dir, "exp/s.toml", TWO_RUNS_OF_TWO_AND_THREE_LEVELS, "res");
    let locks = dir.join("res/s/.locks");
    std::fs::remove_dir_all(&locks).unwrap();
    std::fs::write(&locks, "").unwrap();
    for args in [&["run", "exp/s.toml", "--results", "res"][..], &["figures", "--results", "res", "--experiments", "exp"]] {
        let (code, _, err) = signorini_in(&dir, args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(err.contains(".locks is a regular file, not a folder: move it away"), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_record_that_links_to_another_file_is_removed_and_its_target_kept() {
    let dir = stored_two_runs("special-files-link");
    let target = dir.join("elsewhere.txt");
    std::fs::write(&target, "root:x:0:0:root:/root:/bin/bash\n").unwrap();
    let record = dir.join("res/s/runs/c.json");
    std::fs::remove_file(&record).unwrap();
    std::os::unix::fs::symlink(&target, &record).unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/s.toml", "--results", "res"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("runs/c.json") && err.contains("is not a run record") && err.contains("--replace"), "{err}");
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/s.toml", "--results", "res", "--replace"]);
    assert_eq!(code, 0, "{out}{err}");
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "root:x:0:0:root:/root:/bin/bash\n", "the link's target untouched");
    assert!(!std::fs::symlink_metadata(&record).unwrap().file_type().is_symlink(), "the link replaced by the record");
    let (code, out, err) = signorini_in(&dir, &["drift", "--experiments", "experiments", "--results", "res", "--against", "fresh"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("drift: none"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

const TWO_RUNS_ONE_SAVING: &str = r#"description = "two short runs of Example 7.1, the second saving a mesh"

[defaults]
problem = "ex71"
mesh = "structured:2"

[[run]]
id = "a"
levels = 3

[[run]]
id = "b"
levels = 4
theta = 0.5
save_levels = [3]
"#;

/// How long a command may take before it counts as hung (a refusal takes well under a second).
const PATIENCE: Duration = Duration::from_secs(60);

/// (exit code, stdout + stderr) of the binary run in `dir`, killed and failed if it does not
/// end within [`PATIENCE`]: a regression that blocks on a named pipe fails instead of hanging.
fn within(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = |name: &str| std::fs::File::create(dir.join(name)).unwrap();
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(args)
        .current_dir(dir)
        .env("SIGNORINI_PROGRESS", "off")
        .stdin(std::process::Stdio::null())
        .stdout(out(".stdout"))
        .stderr(out(".stderr"))
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > PATIENCE {
            child.kill().ok();
            child.wait().ok();
            panic!("{args:?} did not end within {PATIENCE:?} (blocked on a file?)");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let text =
        format!("{}{}", std::fs::read_to_string(dir.join(".stdout")).unwrap(), std::fs::read_to_string(dir.join(".stderr")).unwrap());
    assert!(!text.contains("panicked"), "{args:?}: {text}");
    (status.code().unwrap_or_else(|| panic!("{args:?}: killed by a signal\n{text}")), text)
}

/// A scratch folder holding the study's manifest and its results (`results/study`), computed.
fn stored(name: &str) -> PathBuf {
    let dir = crate::common::scratch(&format!("special-files-{name}"));
    std::fs::write(dir.join("study.toml"), TWO_RUNS_ONE_SAVING).unwrap();
    let (code, out) = within(&dir, &["run", "study.toml", "--results", "results"]);
    assert_eq!(code, 0, "{out}");
    dir
}

/// A named pipe at `path` (made with mkfifo, no writer ever opens it).
fn fifo(path: &Path) {
    std::fs::remove_file(path).ok();
    let status = std::process::Command::new("mkfifo").arg(path).status().unwrap();
    assert!(status.success(), "mkfifo {}", path.display());
}

/// The four readers of a results folder.
const READERS: [&[&str]; 4] = [
    &["run", "study.toml", "--results", "results"],
    &["drift", "--against", "results", "--results", "results", "--experiments", ".", "--study", "study"],
    &["figures", "--results", "results", "--experiments", ".", "--study", "study", "--figures", "figs"],
    &["report", "--results", "results", "--experiments", ".", "--study", "study", "--out", "pages"],
];

/// Every reader refuses the folder within seconds, naming `file` and its type.
fn every_reader_refuses(dir: &Path, file: &str, found: &str) {
    for args in READERS {
        let (code, out) = within(dir, args);
        assert_ne!(code, 0, "{args:?}: {out}");
        assert!(out.contains(file) && out.contains(&format!("not a regular file ({found})")), "{args:?}: {out}");
    }
}

#[test]
fn a_named_pipe_as_a_mesh_snapshot_is_refused_by_every_reader_and_replace_computes_it_again() {
    let dir = stored("pipe-snapshot");
    fifo(&dir.join("results/study/meshes/b_level3.vtu"));
    every_reader_refuses(&dir, "meshes/b_level3.vtu", "a named pipe");
    // the pipe is a fault of run b: --replace removes it and computes the run again
    let (code, out) = within(&dir, &["run", "study.toml", "--results", "results", "--replace"]);
    assert_eq!(code, 0, "{out}");
    assert!(std::fs::symlink_metadata(dir.join("results/study/meshes/b_level3.vtu")).unwrap().is_file());
    let (code, out) = within(&dir, READERS[1]);
    assert_eq!(code, 0, "{out}");
}

#[test]
fn a_named_pipe_as_levels_csv_is_refused_by_every_reader() {
    let dir = stored("pipe-csv");
    fifo(&dir.join("results/study/levels.csv"));
    every_reader_refuses(&dir, "levels.csv", "a named pipe");
    // and it is still the pipe: nothing was renamed over it
    assert!(!std::fs::symlink_metadata(dir.join("results/study/levels.csv")).unwrap().is_file());
}

#[test]
fn a_record_or_provenance_linked_to_dev_zero_is_refused_by_every_reader_without_reading_it() {
    for file in ["runs/a.json", "provenance.json"] {
        let dir = stored(&format!("zero-{}", file.replace('/', "-")));
        let path = dir.join("results/study").join(file);
        std::fs::remove_file(&path).unwrap();
        std::os::unix::fs::symlink("/dev/zero", &path).unwrap();
        every_reader_refuses(&dir, file, "a character device");
    }
}

#[test]
fn a_write_never_replaces_a_named_pipe_or_a_device() {
    let dir = stored("targets");
    let pipe = dir.join("pipe.vtu");
    fifo(&pipe);
    let is_pipe = |p: &Path| {
        use std::os::unix::fs::FileTypeExt;
        std::fs::symlink_metadata(p).unwrap().file_type().is_fifo()
    };
    // refused before any computation, naming the flag, the path and what it is
    let (code, out) = within(&dir, &["adapt", "--problem", "ex71", "--mesh", "structured:2", "--levels", "2", "--save", "pipe.vtu"]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("--save pipe.vtu: not a regular file (a named pipe): give a file path"), "{out}");
    assert!(!out.contains("level"), "computed before refusing: {out}");
    let mut drift = READERS[1].to_vec();
    drift.extend(["--report", "pipe.vtu"]);
    let (code, out) = within(&dir, &drift);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("--report pipe.vtu: not a regular file (a named pipe)"), "{out}");
    assert!(is_pipe(&pipe));
    // the one place every atomic write goes through refuses it too, whoever calls it
    let e = signorini::records::write_atomic(&pipe, b"x").unwrap_err().to_string();
    assert!(e.contains("pipe.vtu: not a regular file (a named pipe)"), "{e}");
    assert!(is_pipe(&pipe));
    let left: Vec<String> = std::fs::read_dir(&dir).unwrap().flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect();
    assert!(!left.iter().any(|n| n.contains(".tmp")), "temporary file left: {left:?}");
    // a character device (a scratch copy of /dev/null, made only as root; never the real one)
    // SAFETY: geteuid has no preconditions
    if unsafe { libc::geteuid() } == 0 {
        let null = dir.join("null");
        assert!(std::process::Command::new("mknod").arg(&null).args(["c", "1", "3"]).status().unwrap().success());
        let (code, out) = within(&dir, &["adapt", "--problem", "ex71", "--mesh", "structured:2", "--levels", "2", "--save", "null"]);
        assert_eq!(code, 1, "{out}");
        assert!(out.contains("--save null: not a regular file (a character device)"), "{out}");
        use std::os::unix::fs::FileTypeExt;
        assert!(std::fs::symlink_metadata(&null).unwrap().file_type().is_char_device());
        std::fs::remove_file(&null).unwrap();
    }
}

#[test]
fn a_mesh_snapshot_no_record_names_is_named_by_every_reader_and_removed_by_run() {
    let dir = stored("unnamed");
    let meshes = dir.join("results/study/meshes");
    // level 3's pair copied as level 2 (run b has a level 2 and saves only level 3), and a pipe
    // and a symlink to /dev/zero under snapshot names
    for ext in ["vtu", "json"] {
        std::fs::copy(meshes.join(format!("b_level3.{ext}")), meshes.join(format!("b_level2.{ext}"))).unwrap();
    }
    fifo(&meshes.join("b_level1.vtu"));
    std::os::unix::fs::symlink("/dev/zero", meshes.join("a_level0.vtu")).unwrap();
    let named = ["meshes/a_level0.vtu", "meshes/b_level1.vtu", "meshes/b_level2.json", "meshes/b_level2.vtu"];
    for args in &READERS[1..] {
        let (code, out) = within(&dir, args);
        assert_eq!(code, 0, "{args:?}: {out}");
        assert!(out.contains("ignoring 4 file(s) of an unfinished run in"), "{args:?}: {out}");
        assert!(out.contains(&named.join(", ")), "{args:?}: {out}");
    }
    let (code, out) = within(&dir, READERS[0]);
    assert_eq!(code, 0, "{out}");
    assert!(
        out.contains(&format!("removed 4 file(s) of an unfinished run (no finished run accounts for them): {}", named.join(", "))),
        "{out}"
    );
    let mut left: Vec<String> =
        std::fs::read_dir(&meshes).unwrap().flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect();
    left.sort();
    assert_eq!(left, ["b_level3.json", "b_level3.vtu"]);
}

#[test]
fn a_lock_file_that_is_a_pipe_or_a_link_to_a_device_is_refused_naming_it() {
    let dir = stored("locks");
    let study = dir.join("results/study");
    fifo(&study.join(".lock"));
    let (code, out) = within(&dir, READERS[0]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("study/.lock is a named pipe, not a file: remove it"), "{out}");
    std::fs::remove_file(study.join(".lock")).unwrap();
    let run_lock = study.join(".locks/a.lock");
    std::fs::remove_file(&run_lock).unwrap();
    std::os::unix::fs::symlink("/dev/zero", &run_lock).unwrap();
    let (code, out) = within(&dir, &["run", "study.toml", "--results", "results", "--fresh"]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains(".locks/a.lock is a character device, not a file: remove it"), "{out}");
    // nothing was removed: the runs are still there
    assert!(study.join("runs/a.json").is_file() && study.join("runs/b.json").is_file());
}

#[test]
fn a_named_pipe_among_the_manifests_is_refused_naming_it() {
    let dir = crate::common::scratch("special-files-files-manifests");
    std::fs::create_dir_all(dir.join("e")).unwrap();
    fifo(&dir.join("e/x.toml"));
    let (code, out) = within(&dir, &["figures", "--experiments", "e", "--results", "results"]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("x.toml") && out.contains("not a regular file (a named pipe)"), "{out}");
}

#[test]
fn a_file_where_a_folder_must_be_is_named() {
    let dir = scratch("special-files-file-where-folder");
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/s.toml"), SHORT_RUN_STUDY.replace("levels = 16", "levels = 2")).unwrap();
    // the study's folder is a file
    std::fs::create_dir_all(dir.join("results")).unwrap();
    std::fs::write(dir.join("results/s"), "not a folder").unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "exp/s.toml", "--results", "results"]);
    assert_ne!(code, 0, "{out}");
    assert!(err.contains("results/s is a regular file, not a folder"), "{err}");
    assert!(!err.contains("os error 17"), "{err}");
    // the study's .locks is a file
    std::fs::remove_file(dir.join("results/s")).unwrap();
    std::fs::create_dir_all(dir.join("results/s")).unwrap();
    std::fs::write(dir.join("results/s/.locks"), "not a folder").unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "exp/s.toml", "--results", "results"]);
    assert_ne!(code, 0, "{out}");
    assert!(err.contains("results/s/.locks is a regular file, not a folder"), "{err}");
    // --save under a file
    std::fs::write(dir.join("plain"), "a file").unwrap();
    let (code, out, err) =
        signorini_in(&dir, &["adapt", "--problem", "ex72", "--mesh", "structured:4", "--levels", "1", "--save", "plain/u.vtu"]);
    assert_ne!(code, 0, "{out}");
    assert!(err.contains("plain is a file, not a folder"), "{err}");
    assert!(!err.contains("does not exist"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_mesh_that_is_not_a_regular_file_is_refused_at_once() {
    let dir = scratch("special-files-devzero");
    std::fs::write(dir.join("v.toml"), fixture("bad_data_gmsh.toml")).unwrap();
    let start = std::time::Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["solve", "--problem", "v.toml", "--mesh", "gmsh:/dev/zero"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("/dev/zero: not a regular file"), "{err}");
    assert!(start.elapsed().as_secs() < 5, "it read on: {:?}", start.elapsed());
}

fn mkfifo(path: &Path) {
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo reads the NUL-terminated path it is given
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo {}", path.display());
}

#[test]
fn input_files_that_are_not_regular_files_are_refused_at_once() {
    let dir = scratch("special-files-fifo");
    mkfifo(&dir.join("pipe.toml"));
    mkfifo(&dir.join("pipe.msh"));
    std::fs::create_dir(dir.join("folder.toml")).unwrap();
    let problem = fixture("bad_data_square.toml");
    std::fs::write(dir.join("p.toml"), &problem).unwrap();
    let uses_pipe_mesh = one_run_manifest(&dir, "m", "a", "mesh = \"gmsh:pipe.msh\"\n");
    let uses_pipe_problem = one_run_manifest(&dir, "q", "a", "problem = \"pipe.toml\"\n");
    for (args, file, found) in [
        (vec!["run", "pipe.toml"], "pipe.toml", "a named pipe"),
        (vec!["run", "folder.toml"], "folder.toml", "a directory"),
        (vec!["run", &uses_pipe_mesh], "pipe.msh", "a named pipe"),
        (vec!["run", &uses_pipe_problem], "pipe.toml", "a named pipe"),
        (vec!["solve", "--problem", "pipe.toml", "--mesh", "structured:2"], "pipe.toml", "a named pipe"),
        (vec!["solve", "--problem", "folder.toml", "--mesh", "structured:2"], "folder.toml", "a directory"),
        (vec!["solve", "--problem", "p.toml", "--mesh", "gmsh:pipe.msh"], "pipe.msh", "a named pipe"),
        (vec!["solve", "--problem", "p.toml", "--mesh", "gmsh:/dev/zero"], "/dev/zero", "a character device"),
    ] {
        let (code, _, err) = signorini_in_time(&dir, &args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(err.contains(file) && err.contains(&format!("not a regular file ({found})")), "{args:?}: {err}");
    }
    // a problem file beyond the stated limit is refused before it is read
    std::fs::write(dir.join("big.toml"), format!("{problem}\n# {}\n", "x".repeat(17 << 20))).unwrap();
    let (code, _, err) = signorini_in_time(&dir, &["solve", "--problem", "big.toml", "--mesh", "structured:2"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("big.toml: the problem file has 17.0 MiB, more than the 16.0 MiB"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
