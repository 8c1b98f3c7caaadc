//! What the eighth battery of hostile inputs found in the file types of a results folder and of
//! output paths, each fixed in the one function its path goes through:
//!
//! * a file of a results folder that is a named pipe (every reader hung) or a symlink to
//!   `/dev/zero` (every reader grew to 24 GB): every reader of a results folder goes through
//!   `records::read_bytes`/`read_text`, the bounded reader of `base::input`, which refuses by
//!   name what is not a regular file, or is larger than `RESULTS_LIMIT`, before opening it;
//! * an atomic write renamed its file over a named pipe or a device (`adapt --save /dev/null`
//!   as root replaced /dev/null): `base::input::check_target`, in `records::Batch` and in the
//!   command line's early checks of `--save` and `--report`, refuses such a target;
//! * a mesh snapshot no record names: named as a leftover by every reader and removed by `run`,
//!   now also when it is a named pipe or a symlink (which the folder walk skipped);
//! * a lock file that is a named pipe or a symlink to a device: refused naming it;
//! * a named pipe among the manifests of `--experiments`: refused by name (the word on a problem
//!   file put beside the manifests read it again, past the reader, and hung).
//!
//! No test here touches a real device: device nodes are made in a scratch folder, and only as root.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

const STUDY: &str = r#"description = "battery 8 file types: two short runs of Example 7.1, the second saving a mesh"

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
    let dir = crate::common::scratch(&format!("battery8-files-{name}"));
    std::fs::write(dir.join("study.toml"), STUDY).unwrap();
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
    let dir = crate::common::scratch("battery8-files-manifests");
    std::fs::create_dir_all(dir.join("e")).unwrap();
    fifo(&dir.join("e/x.toml"));
    let (code, out) = within(&dir, &["figures", "--experiments", "e", "--results", "results"]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("x.toml") && out.contains("not a regular file (a named pipe)"), "{out}");
}
