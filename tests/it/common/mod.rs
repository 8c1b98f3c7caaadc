//! Shared helpers for the integration tests.
#![allow(dead_code)]

pub mod browser;
pub mod msh;

use signorini::mesh::{Mesh, MeshSpec};
use signorini::problems::Problem;
use signorini::settings::pdas::PdasOptions;
use signorini::solve::{self, DiscreteSolution};

pub fn mesh(problem: &dyn Problem, spec: &str) -> Mesh {
    MeshSpec::parse(spec).unwrap().build(problem).unwrap()
}

pub fn solve_on(problem: &dyn Problem, mesh: &Mesh) -> DiscreteSolution {
    solve::solve(mesh, problem, &PdasOptions::default(), &mut |_| {}).expect("the solve converges")
}

/// Observed rate log(e1/e2)/log(h1/h2).
pub fn rate(e1: f64, e2: f64, h1: f64, h2: f64) -> f64 {
    (e1 / e2).ln() / (h1 / h2).ln()
}

/// The discrete KKT conditions of the solution on `spec`, to round-off: no penetration,
/// lambda_p >= 0, lambda_p = 0 off the active set, complementarity, the equations at free nodes,
/// active nodes on the obstacle.
pub fn assert_kkt(problem: &dyn Problem, spec: &str) {
    let m = mesh(problem, spec);
    let sol = solve_on(problem, &m);
    let k = sol.kkt();
    let name = format!("{} on {spec}", problem.name());
    // displacement scale 0.1-1: round-off level
    assert!(k.max_penetration <= 1e-12, "{name}: penetration {:e}", k.max_penetration);
    assert!(k.min_lambda >= -1e-10 * k.force_scale, "{name}: min lambda {:e} (scale {:e})", k.min_lambda, k.force_scale);
    assert!(k.max_inactive_lambda <= 1e-10 * k.force_scale, "{name}: lambda off the active set {:e}", k.max_inactive_lambda);
    assert!(k.max_complementarity <= 1e-10 * k.force_scale, "{name}: complementarity {:e}", k.max_complementarity);
    assert!(sol.free_residual < 1e-10, "{name}: equations at free nodes {:e}", sol.free_residual);
    // the round-off bound of a contact force holds where the force is round-off: off the
    // active set (what Lambda_h^C, and so eta_7, counts rests on it)
    assert_inactive_forces_within_roundoff(&sol, &name);
    // active nodes are exactly in contact
    for (i, c) in sol.dofs.contact.iter().enumerate() {
        if sol.active[i] {
            assert!((sol.normal_displacement(i) - c.gap).abs() < 1e-12, "{name}: active node not on the obstacle");
        }
    }
}

/// Off the active set a contact force is round-off: below its bound `lambda_floor`, and so not
/// counted as positive (Lambda_h^C, eta_7 rest on it).
pub fn assert_inactive_forces_within_roundoff(sol: &DiscreteSolution, name: &str) {
    let positive = sol.positive_forces();
    for (i, &active) in sol.active.iter().enumerate() {
        if !active {
            let (l, floor) = (sol.lambda[i], sol.lambda_floor[i]);
            assert!(l.abs() <= floor, "{name}: inactive lambda {l:e} above its round-off bound {floor:e}");
            assert!(!positive[i], "{name}: an inactive node counted as a positive force");
        }
    }
}

/// The error a bad manifest text gives, checked to name the file first.
pub fn parse_err(text: &str) -> String {
    match signorini::manifest::Manifest::parse(std::path::Path::new("experiments/bad_case.toml"), text) {
        Ok(_) => panic!("accepted a bad manifest:\n{text}"),
        Err(e) => {
            let s = e.to_string();
            assert!(s.starts_with("experiments/bad_case.toml"), "error does not name the file: {s}");
            s
        }
    }
}

/// (exit code, stdout, stderr) of the binary run in `dir`; a panic or a signal is never an answer.
pub fn signorini_in(dir: &std::path::Path, args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_signorini")).args(args).current_dir(dir).output().unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned());
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    let code = out.status.code().unwrap_or_else(|| panic!("{args:?}: killed by a signal\n{stderr}"));
    (code, stdout, stderr)
}

/// The run roles the repository's manifests (`experiments/`) declare, checked against what the
/// CLAIMS rows and figures need: the roles every test reading results with them uses.
pub fn roles() -> &'static signorini::analysis::roles::Roles {
    static ROLES: std::sync::OnceLock<signorini::analysis::roles::Roles> = std::sync::OnceLock::new();
    ROLES.get_or_init(|| signorini::analysis::roles::read(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments")).unwrap())
}

/// The checked view of a results folder as `figures` and `report` open it: every declared study
/// and every study the folder holds, each through the store's integrity check (a folder that
/// does not exist holds none). A folder at fault panics with the check's message.
pub fn shelf(results: &std::path::Path) -> signorini::store::Shelf {
    use signorini::store::Shelf;
    if !results.exists() {
        return Shelf::open(results, std::iter::empty()).unwrap();
    }
    let experiments = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments");
    let manifests = signorini::manifest::declared(&experiments, &[]).unwrap();
    Shelf::open_folder(results, &manifests).unwrap_or_else(|e| panic!("{e:#}"))
}

/// Make a folder of hand-made records (written straight to `runs/` and `meshes/` by a test) a
/// sound results folder, as the harness would have stored it: each record of its folder's
/// study, saving the levels whose snapshot is there (each snapshot of its run and level, with
/// the level's NDF, beside a VTU), and the summaries `levels.csv` and `provenance.json` rendered
/// from the records (a provenance already there keeps its manifest). Then open it ([`shelf`]).
pub fn sealed(results: &std::path::Path) -> signorini::store::Shelf {
    use signorini::records::{MeshSnapshot, StudyDir, write_atomic, write_json};
    for study in signorini::store::Shelf::in_folder(results).unwrap_or_default() {
        let dir = StudyDir::new(results, &study);
        let mut runs = dir.read_runs().unwrap();
        for r in &mut runs {
            r.study = study.clone();
            let id = r.run.id.clone();
            r.run.save_levels = (0..r.levels.len()).filter(|&l| dir.mesh_file(&id, l, "json").exists()).collect();
            for &l in &r.run.save_levels {
                let mut snap: MeshSnapshot =
                    serde_json::from_str(&std::fs::read_to_string(dir.mesh_file(&id, l, "json")).unwrap()).unwrap();
                (snap.study, snap.run, snap.level, snap.ndof) = (study.clone(), id.clone(), l, r.levels[l].ndof);
                write_json(&dir.mesh_file(&id, l, "json"), &snap).unwrap();
                write_atomic(&dir.mesh_file(&id, l, "vtu"), b"<?xml version=\"1.0\"?>\n<VTKFile></VTKFile>\n").unwrap();
                for ext in ["json", "vtu"] {
                    let file = dir.mesh_file(&id, l, ext);
                    let hash = signorini::base::digest::sha256_hex(&std::fs::read(&file).unwrap());
                    r.snapshots.insert(file.file_name().unwrap().to_string_lossy().into_owned(), hash);
                }
            }
            write_json(&dir.run_file(&id), r).unwrap();
        }
        write_atomic(&dir.csv_file(), &dir.csv_bytes(&runs).unwrap()).unwrap();
        let manifest = std::fs::read_to_string(dir.provenance_file())
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .and_then(|v| v["manifest"].as_str().map(String::from))
            .unwrap_or_else(|| format!("experiments/{study}.toml"));
        let ids = runs.iter().map(|r| r.run.id.clone()).collect();
        let p = signorini::provenance::collect(&study, std::path::Path::new(&manifest), b"", false, ids, &[]);
        write_json(&dir.provenance_file(), &p).unwrap();
    }
    shelf(results)
}

/// The text of `tests/fixtures/NAME`.
pub fn fixture(name: &str) -> String {
    std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)).unwrap()
}

/// An empty scratch folder `signorini-NAME-PID` under the system's temporary folder.
pub fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("signorini-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Limit a resource of the process `cmd` starts (`libc::RLIMIT_AS` as `prlimit --as` sets it,
/// `libc::RLIMIT_FSIZE` as `--fsize`) to `bytes`.
pub fn limit(cmd: &mut std::process::Command, resource: libc::__rlimit_resource_t, bytes: u64) {
    use std::os::unix::process::CommandExt;
    // SAFETY: setrlimit only, between fork and exec
    unsafe {
        cmd.pre_exec(move || {
            let lim = libc::rlimit { rlim_cur: bytes, rlim_max: bytes };
            if libc::setrlimit(resource, &lim) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
}

/// Write the manifest `manifest` (a path relative to `dir`, its folder made) with `text`, and run
/// its study into `results` (relative to `dir`), which must succeed: the stored study a test of
/// the store, drift or the pages starts from.
pub fn stored_study(dir: &std::path::Path, manifest: &str, text: &str, results: &str) {
    let path = dir.join(manifest);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(&path, text).unwrap();
    let (code, out, err) = signorini_in(dir, &["run", manifest, "--results", results]);
    assert_eq!(code, 0, "{out}{err}");
}

/// Copy the folder `from` with everything in it to `to` (made; symlinks copied as links).
pub fn copy_tree(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap().flatten() {
        let (kind, target) = (entry.file_type().unwrap(), to.join(entry.file_name()));
        if kind.is_dir() {
            copy_tree(&entry.path(), &target);
        } else if kind.is_symlink() {
            std::os::unix::fs::symlink(std::fs::read_link(entry.path()).unwrap(), &target).unwrap();
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

/// The text of `tests/fixtures/BASE` with each `from` replaced by its `to` (each must be there).
pub fn edited(base: &str, edits: &[(&str, &str)]) -> String {
    let mut text = fixture(base);
    for (from, to) in edits {
        assert!(text.contains(from), "{from} not in {base}");
        text = text.replace(from, to);
    }
    text
}

/// `signorini ARGS` in a fresh folder holding `v.toml` (fixture `base` with `edits`, see
/// [`edited`]), `qd.msh` (the quarter disc) and `sq.msh` (the Gmsh square), removed afterwards:
/// (exit code, stdout, stderr), never a panic or a signal.
pub fn run_edited(name: &str, base: &str, edits: &[(&str, &str)], args: &[&str]) -> (i32, String, String) {
    let dir = scratch(&format!("edited-{name}"));
    std::fs::write(dir.join("v.toml"), edited(base, edits)).unwrap();
    std::fs::write(dir.join("qd.msh"), fixture("gmsh_renumbered/plain.msh")).unwrap();
    std::fs::write(dir.join("sq.msh"), fixture("square.msh")).unwrap();
    let answer = signorini_in(&dir, args);
    std::fs::remove_dir_all(&dir).ok();
    answer
}

/// `signorini ARGS` in `dir` without progress lines: (exit code, stdout followed by stderr),
/// never a panic.
pub fn output_in(dir: &std::path::Path, args: &[&str]) -> (i32, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(dir)
        .env("SIGNORINI_PROGRESS", "off")
        .args(args)
        .output()
        .unwrap();
    let all = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(!all.contains("panicked"), "{all}");
    (o.status.code().unwrap_or(-1), all)
}

/// `signorini solve` of the Gmsh square's problem (fixture `bad_data_gmsh.toml` with `edits`)
/// on `tests/fixtures/square.msh` with `mesh_edits` (each replaced once): (exit code, stdout and
/// stderr).
pub fn solve_gmsh_square(name: &str, edits: &[(&str, &str)], mesh_edits: &[(&str, &str)]) -> (i32, String) {
    let dir = scratch(&format!("gmsh-square-{name}"));
    for (file, fixture_name, edits) in [("v.toml", "bad_data_gmsh.toml", edits), ("sq.msh", "square.msh", mesh_edits)] {
        let mut text = fixture(fixture_name);
        for (from, to) in edits {
            assert!(text.contains(from), "{from} not in {fixture_name}");
            text = text.replacen(from, to, 1);
        }
        std::fs::write(dir.join(file), text).unwrap();
    }
    let out = output_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "gmsh:sq.msh"]);
    std::fs::remove_dir_all(&dir).ok();
    out
}

/// `signorini ARGS` run in the repository's root: (exit code, stdout, stderr), as [`signorini_in`].
pub fn signorini_in_repo(args: &[&str]) -> (i32, String, String) {
    signorini_in(std::path::Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

/// The path of `tests/fixtures/NAME`, as a string for an argument list.
pub fn fixture_path(name: &str) -> String {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name).display().to_string()
}

/// `signorini ARGS` in `dir` without progress lines, killed after 20 s (a hang is a failure, not
/// a wait): (exit code, stdout, stderr); never a panic or a signal.
pub fn signorini_in_time(dir: &std::path::Path, args: &[&str]) -> (i32, String, String) {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
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

/// Write a study `NAME.toml` in `dir` of ex71 on structured:2 with one run `id` (2 levels, quick
/// form 1) and `extra` appended; its file name.
pub fn one_run_manifest(dir: &std::path::Path, name: &str, id: &str, extra: &str) -> String {
    let file = format!("{name}.toml");
    let text = format!(
        "description = \"t\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\nlevels = 2\nquick_levels = 1\n[[run]]\nid = \"{id}\"\n{extra}"
    );
    std::fs::write(dir.join(&file), text).unwrap();
    file
}

/// Copy the folder `from` to `to` (made), following symlinks.
pub fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let target = to.join(e.file_name());
        if e.path().is_dir() { copy_dir(&e.path(), &target) } else { std::fs::copy(e.path(), target).map(|_| ()).unwrap() }
    }
}

/// The `estimator:` line of a solve's output.
pub fn estimator_line(out: &str) -> String {
    out.lines().find(|l| l.starts_with("estimator:")).unwrap_or_default().to_string()
}

/// Wait for `child` (its output piped): (exit code, stdout followed by stderr).
pub fn finish(child: std::process::Child) -> (i32, String) {
    let o = child.wait_with_output().unwrap();
    (o.status.code().unwrap_or(-1), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

/// The problem text parsed, or its error's message.
pub fn parse_problem(text: &str) -> Result<signorini::problems::FileProblem, String> {
    signorini::problems::FileProblem::parse(std::path::Path::new("p.toml"), text).map_err(|e| e.to_string())
}

/// Level rows of `adapt`'s table.
pub fn level_rows(out: &str) -> usize {
    out.lines().filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).count()
}

/// A scratch folder with the study of two runs ([`TWO_RUNS`]) stored into `res` and `fresh`.
pub fn stored_two_runs(name: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    std::fs::write(dir.join("experiments/s.toml"), TWO_RUNS).unwrap();
    for results in ["res", "fresh"] {
        let (code, out, err) = signorini_in(&dir, &["run", "experiments/s.toml", "--results", results]);
        assert_eq!(code, 0, "{out}{err}");
    }
    dir
}

/// A stored study of two runs, one adaptive, one uniform.
const TWO_RUNS: &str = "description = \"s\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\ntheta = 0.5\nlevels = 4\nquick_levels = 2\n[[run]]\nid = \"a\"\nrefine = \"adaptive\"\n[[run]]\nid = \"c\"\nrefine = \"uniform\"\n";

/// A study of two short runs of Example 7.1 (`a`, and `b` with theta 0.3), three levels each.
pub const TWO_SHORT_RUNS: &str = r#"description = "two short runs"
[defaults]
problem = "ex71"
mesh = "structured:4"
levels = 3
save_levels = [1]
[[run]]
id = "a"
[[run]]
id = "b"
theta = 0.3
"#;

/// A scratch folder named `name` with `exp/st.toml` ([`TWO_SHORT_RUNS`]) run into `res/`.
pub fn stored_two_short_runs(name: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    stored_study(&dir, "exp/st.toml", TWO_SHORT_RUNS, "res");
    dir
}

/// A study of one run of 22 levels: long enough to be stopped part way.
pub const LONG: &str = r#"description = "one run long enough to be stopped"
[defaults]
problem = "ex71"
mesh = "structured:4"
theta = 0.5
[[run]]
id = "long"
levels = 22
"#;

/// The levels a run's checkpoint file holds (0 where there is none yet, or it does not parse).
pub fn checkpoint_levels(file: &std::path::Path) -> usize {
    let Ok(text) = std::fs::read_to_string(file) else { return 0 };
    let Ok(v) = serde_json::from_str::<serde_json::Value>(&text) else { return 0 };
    v["levels"].as_array().map_or(0, |l| l.len())
}

/// A study of one run of a few seconds (16 levels of Example 7.1 from `structured:8`).
pub const SHORT_RUN_STUDY: &str = r#"description = "one run of a few seconds"
[defaults]
problem = "ex71"
mesh = "structured:8"
[[run]]
id = "a"
levels = 16
theta = 0.5
"#;
