//! Shared helpers for the integration tests.
#![allow(dead_code)]

pub mod browser;
pub mod msh;

use signorini::contact::PdasOptions;
use signorini::mesh::{Mesh, MeshSpec};
use signorini::problems::Problem;
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
    match signorini::study::manifest::Manifest::parse(std::path::Path::new("experiments/bad_case.toml"), text) {
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
pub fn shelf(results: &std::path::Path) -> signorini::study::store::Shelf {
    use signorini::study::store::Shelf;
    if !results.exists() {
        return Shelf::open(results, std::iter::empty()).unwrap();
    }
    let experiments = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments");
    let manifests = signorini::study::manifest::declared(&experiments, &[]).unwrap();
    Shelf::open_folder(results, &manifests).unwrap_or_else(|e| panic!("{e:#}"))
}

/// Make a folder of hand-made records (written straight to `runs/` and `meshes/` by a test) a
/// sound results folder, as the harness would have stored it: each record of its folder's
/// study, saving the levels whose snapshot is there (each snapshot of its run and level, with
/// the level's NDF, beside a VTU), and the summaries `levels.csv` and `provenance.json` rendered
/// from the records (a provenance already there keeps its manifest). Then open it ([`shelf`]).
pub fn sealed(results: &std::path::Path) -> signorini::study::store::Shelf {
    use signorini::records::{MeshSnapshot, StudyDir, write_atomic, write_json};
    for study in signorini::study::store::Shelf::in_folder(results).unwrap_or_default() {
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
        let p = signorini::study::provenance::collect(&study, std::path::Path::new(&manifest), b"", false, ids, &[]);
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
