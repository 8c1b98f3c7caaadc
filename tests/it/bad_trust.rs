//! What the battery after issue 38 found at the edges of the inputs (findings 4 to 20 of its
//! report), each refused or worded by the one function every path goes through:
//!
//! * a run id too long for the file names the store makes from it failed at the lock, without
//!   the key (the manifest's id check bounds it: `RUN_ID_MAX`);
//! * a named pipe as a manifest, problem or mesh hung, `/dev/zero` grew a buffer (the one input
//!   reader, `base::input::read`, takes regular files of bounded size only);
//! * `run --quick` into a folder of full runs advised `--replace`, which throws the full runs
//!   away;
//! * `mesh = "symmetric:3"` in a manifest lost the parser's reason (`MeshError::expected`);
//! * an estimator term that overflowed (a body force of 1e308) was blamed on C_0 (`NotFinite`);
//! * a point constraint or required vertex outside the mesh was called a kink of the obstacle,
//!   naming neither file nor key, and a load break outside the domain was silently ignored
//!   (`MeshSpec::build` checks what the problem declares of its mesh);
//! * `figures` without ./experiments and `drift --against` a folder it cannot write to gave no
//!   way out (`--experiments`, `--report`);
//! * an error quoted a 1 MB line of the input in full (`base::input::excerpt`);
//! * two manifests of one study with different runs, given together: the first computed, then
//!   the second was refused.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("signorini-bad-trust-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn fixture(rel: &str) -> String {
    std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(rel)).unwrap()
}

/// `signorini ARGS` in `dir`, killed after 20 s (a hang is a failure, not a wait): (exit code,
/// stdout, stderr); never a panic or a signal.
fn signorini(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(dir)
        .args(args)
        .env("SIGNORINI_PROGRESS", "off")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(20) {
            child.kill().unwrap();
            panic!("signorini {args:?} hung (killed after 20 s)");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let o = child.wait_with_output().unwrap();
    let (out, err) = (String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned());
    assert!(!err.contains("panicked"), "{err}");
    (o.status.code().unwrap_or_else(|| panic!("killed by a signal: {err}")), out, err)
}

/// A study `NAME.toml` of ex71 on structured:2 with one run `id` (2 levels, quick form 1).
fn manifest(dir: &Path, name: &str, id: &str, extra: &str) -> String {
    let file = format!("{name}.toml");
    let text = format!(
        "description = \"t\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\nlevels = 2\nquick_levels = 1\n[[run]]\nid = \"{id}\"\n{extra}"
    );
    std::fs::write(dir.join(&file), text).unwrap();
    file
}

fn mkfifo(path: &Path) {
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo reads the NUL-terminated path it is given
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo {}", path.display());
}

#[test]
fn bad_run_id_longer_than_the_store_s_file_names_allow_is_refused_by_key() {
    let dir = tmp("long-id");
    let long = "x".repeat(300);
    let file = manifest(&dir, "s", &long, "");
    let (code, _, err) = signorini(&dir, &["run", &file, "--results", "r"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("key `run[0].id`") && err.contains("at most 128 characters") && err.contains("300 characters"), "{err}");
    assert!(!dir.join("r").exists(), "something was written before the refusal");
    // the longest accepted id makes every file of a run, snapshots included
    let longest = "y".repeat(128);
    let file = manifest(&dir, "t", &longest, "save_levels = [1]\n");
    let (code, _, err) = signorini(&dir, &["run", &file, "--results", "r"]);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("r/t/runs").join(format!("{longest}.json")).is_file());
    assert!(dir.join("r/t/meshes").join(format!("{longest}_level1.vtu")).is_file());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_input_files_that_are_not_regular_files_are_refused_at_once() {
    let dir = tmp("fifo");
    mkfifo(&dir.join("pipe.toml"));
    mkfifo(&dir.join("pipe.msh"));
    std::fs::create_dir(dir.join("folder.toml")).unwrap();
    let problem = fixture("bad_data_square.toml");
    std::fs::write(dir.join("p.toml"), &problem).unwrap();
    let uses_pipe_mesh = manifest(&dir, "m", "a", "mesh = \"gmsh:pipe.msh\"\n");
    let uses_pipe_problem = manifest(&dir, "q", "a", "problem = \"pipe.toml\"\n");
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
        let (code, _, err) = signorini(&dir, &args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(err.contains(file) && err.contains(&format!("not a regular file ({found})")), "{args:?}: {err}");
    }
    // a problem file beyond the stated limit is refused before it is read
    std::fs::write(dir.join("big.toml"), format!("{problem}\n# {}\n", "x".repeat(17 << 20))).unwrap();
    let (code, _, err) = signorini(&dir, &["solve", "--problem", "big.toml", "--mesh", "structured:2"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("big.toml: the problem file has 17.0 MiB, more than the 16.0 MiB"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_quick_run_into_a_folder_of_full_runs_does_not_advise_replace() {
    let dir = tmp("quick-full");
    let file = manifest(&dir, "s", "a", "");
    assert_eq!(signorini(&dir, &["run", &file, "--results", "r"]).0, 0);
    let before = std::fs::read(dir.join("r/s/runs/a.json")).unwrap();
    let (code, _, err) = signorini(&dir, &["run", &file, "--quick", "--results", "r"]);
    assert_eq!(code, 1, "{err}");
    for says in ["holds the full form of study s", "the first 1 levels", "--results target/quick-results"] {
        assert!(err.contains(says), "no {says:?} in {err}");
    }
    assert!(!err.contains("--replace"), "{err}");
    assert_eq!(std::fs::read(dir.join("r/s/runs/a.json")).unwrap(), before);
    // the quick form in its own folder is fine
    assert_eq!(signorini(&dir, &["run", &file, "--quick", "--results", "q"]).0, 0);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_odd_symmetric_mesh_in_a_manifest_keeps_the_parser_s_reason() {
    let dir = tmp("symmetric");
    let file = manifest(&dir, "s", "a", "mesh = \"symmetric:3\"\n");
    let (code, _, err) = signorini(&dir, &["run", &file, "--results", "r"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("key `run[0].mesh`") && err.contains("N even") && err.contains("use symmetric:2 or symmetric:4"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A body force of 1e308: its products with the displacements it causes overflow before any
/// estimator term is computed, and the solve's one check of its result names that (battery 8,
/// finding 7), with the units as the remedy, never a C_0. (An estimator term that overflows
/// on its own is named by bad_settings::bad_estimate_that_overflows_is_refused_by_both_paths_at_level_0.)
#[test]
fn bad_overflowing_estimator_term_is_named_not_c0() {
    let dir = tmp("overflow");
    let text = fixture("bad_data_square.toml").replace(r#"body_force = ["0", "-1"]"#, r#"body_force = ["0", "-1e308"]"#);
    std::fs::write(dir.join("p.toml"), text).unwrap();
    let (code, _, err) = signorini(&dir, &["solve", "--problem", "p.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("is not a finite number") && err.contains("give the data in other units"), "{err}");
    assert!(!err.contains("C_0") && !err.contains("violated"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_points_and_lines_the_mesh_does_not_hold_name_the_file_and_key() {
    let dir = tmp("points");
    let base = fixture("bad_data_square.toml");
    for (case, add, says, outside) in [
        ("vertex", "required_vertices = [[3, 3]]\n", "key `required_vertices[0]`: (3, 3) is not a vertex of the mesh", true),
        ("inside", "required_vertices = [[0.5, 0.3]]\n", "key `required_vertices[0]`: (0.5, 0.3) is not a vertex of the mesh", false),
        ("break", "load_breaks = [\"5\"]\n", "key `load_breaks[0]`: the line x = 5 does not cross the mesh", false),
    ] {
        std::fs::write(dir.join("p.toml"), base.replace("[material]", &format!("{add}\n[material]"))).unwrap();
        for cmd in ["solve", "adapt"] {
            let (code, _, err) = signorini(&dir, &[cmd, "--problem", "p.toml", "--mesh", "structured:4"]);
            assert_eq!(code, 1, "{case}: {err}");
            assert!(err.contains(&format!("p.toml: {says}")) && !err.contains("kink"), "{case}: {err}");
            assert_eq!(err.contains("it lies outside the mesh, which spans x in [0, 1], y in [0, 1]"), outside, "{case}: {err}");
        }
    }
    let point = "\n[[point_constraints]]\nat = [2, 2]\nu = [\"free\", 0]\n";
    std::fs::write(dir.join("p.toml"), format!("{base}{point}")).unwrap();
    let (code, _, err) = signorini(&dir, &["solve", "--problem", "p.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("p.toml: key `point_constraints[0].at`: (2, 2) is not a vertex") && !err.contains("kink"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_hints_name_the_option_that_helps() {
    let dir = tmp("hints");
    // no ./experiments
    let (code, _, err) = signorini(&dir, &["figures", "--results", "r", "--study", "s"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("pass --experiments DIR"), "{err}");
    // a drift report that cannot be written where --against puts it
    std::fs::create_dir(dir.join("experiments")).unwrap();
    let file = manifest(&dir.join("experiments"), "s", "a", "");
    assert_eq!(signorini(&dir, &["run", &format!("experiments/{file}"), "--results", "r"]).0, 0);
    assert_eq!(signorini(&dir, &["run", &format!("experiments/{file}"), "--results", "o"]).0, 0);
    std::fs::create_dir(dir.join("o/drift-report.json")).unwrap();
    let (code, out, err) = signorini(&dir, &["drift", "--study", "s", "--against", "o", "--results", "r"]);
    assert_eq!(code, 1, "{out}{err}");
    // refused before anything is rerun (battery 10: every output target is checked first)
    assert!(err.contains("the drift report (--report FILE writes it elsewhere) o/drift-report.json: not a regular file"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_long_input_lines_are_quoted_as_excerpts() {
    let dir = tmp("excerpt");
    let line = "x".repeat(1 << 20);
    std::fs::write(dir.join("s.toml"), format!("description = \"{line}\n")).unwrap();
    std::fs::write(dir.join("t.toml"), format!("description = \"t\"\n[[run]]\nid = \"a\"\nproblem = \"ex71\"\nmesh = \"{line}\"\n"))
        .unwrap();
    let problem = fixture("bad_data_square.toml").replace(r#"chi = "0.001""#, &format!("chi = \"0.001 + {line}\""));
    std::fs::write(dir.join("p.toml"), problem).unwrap();
    for args in [vec!["run", "s.toml"], vec!["run", "t.toml"], vec!["solve", "--problem", "p.toml", "--mesh", "structured:2"]] {
        let (code, _, err) = signorini(&dir, &args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(err.len() < 4000 && err.contains("characters cut) ... "), "{args:?}: {} bytes: {}", err.len(), &err[..err.len().min(500)]);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_two_manifests_of_one_study_with_different_runs_are_refused_before_any_run() {
    let dir = tmp("two");
    for sub in ["one", "two"] {
        std::fs::create_dir(dir.join(sub)).unwrap();
    }
    manifest(&dir.join("one"), "s", "a", "");
    manifest(&dir.join("two"), "s", "a", "theta = 0.3\n");
    let (code, _, err) = signorini(&dir, &["run", "one/s.toml", "two/s.toml", "--results", "r"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("one/s.toml and two/s.toml both declare study s with different runs"), "{err}");
    assert!(!dir.join("r").exists(), "a run was computed before the refusal");
    // the same declaration twice is no conflict
    std::fs::copy(dir.join("one/s.toml"), dir.join("two/s.toml")).unwrap();
    let (code, _, err) = signorini(&dir, &["run", "one/s.toml", "two/s.toml", "--results", "r"]);
    assert_eq!(code, 0, "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
