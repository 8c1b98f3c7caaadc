//! Battery 9:
//! * S2: two `signorini drift` in one checkout share the scratch folder they rerun into
//!   (`target/drift/full`); each started its studies over while the other compared, and one
//!   reported stored runs as missing (a false drift, exit 1). The scratch folder is locked for
//!   the whole command: the second waits, saying who holds it, and both find no drift.
//! * S1: a rigid translation of the Dirichlet data and the gap by 3e7 times the deformation
//!   hid every contact force from eta_7 (positive meant 1e-10 of max(|F|, |K u|), which grows
//!   with the translation); positive now means above the force's own round-off bound and 1e-10
//!   of the largest contact force.
//! * S3: an exact solution large against its variation (u = (0.5 - 1e-9 x, 0)) was refused as
//!   a gradient contradiction, blaming an `exact.grad` the file does not write: two difference
//!   quotients agreed by chance far below their round-off. A mismatch must now exceed the
//!   quotients' round-off bound too, and a derived gradient is named as derived.
//! * S4: a regular file where a folder must be (the study's folder, `.locks`, the folder of
//!   `--save`) gave "File exists (os error 17)" or "does not exist"; the error names the file.

use super::common::{scratch, signorini_in};
use std::process::{Command, Stdio};

const STUDY: &str = r#"description = "battery 9: one run of a few seconds"
[defaults]
problem = "ex71"
mesh = "structured:8"
[[run]]
id = "a"
levels = 16
theta = 0.5
"#;

fn drift(dir: &std::path::Path) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(dir)
        .args(["drift", "--experiments", "exp", "--results", "results", "--study", "s", "--report", "r.json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn finish(child: std::process::Child) -> (i32, String) {
    let o = child.wait_with_output().unwrap();
    (o.status.code().unwrap_or(-1), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

#[test]
fn two_drifts_in_one_checkout_take_turns_and_neither_reports_a_false_drift() {
    let dir = scratch("battery9-two-drifts");
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/s.toml"), STUDY).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["run", "exp/s.toml", "--results", "results"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let first = drift(&dir);
    // the first reruns the study now: its scratch copy of the run is being computed
    let start = std::time::Instant::now();
    while !dir.join("target/drift/full/s/.partial").exists() && !dir.join("target/drift/full/s/runs/a.json").exists() {
        assert!(start.elapsed().as_secs() < 120, "the first drift never started its rerun");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let second = drift(&dir);
    let ((c1, o1), (c2, o2)) = (finish(first), finish(second));
    assert_eq!(c1, 0, "first: {o1}");
    assert_eq!(c2, 0, "second: {o2}");
    for o in [&o1, &o2] {
        assert!(o.contains("drift: none"), "{o}");
        assert!(!o.contains("(missing)"), "{o}");
    }
    assert!(
        o2.contains("the scratch folder target/drift/full is being written by process") && o2.contains("waiting for it to finish"),
        "{o2}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The estimator's seven terms from `solve`'s output.
fn etas(out: &str) -> Vec<f64> {
    let line = out.lines().find(|l| l.starts_with("estimator: eta1..7 = ")).unwrap_or_else(|| panic!("{out}"));
    line["estimator: eta1..7 = ".len()..].split(',').next().unwrap().split_whitespace().map(|v| v.parse().unwrap()).collect()
}

#[test]
fn a_rigid_translation_of_the_data_keeps_the_contact_forces_of_eta_7() {
    let dir = scratch("battery9-s1");
    let plain = std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex72.toml")).unwrap();
    let mut seen = Vec::new();
    for t in ["0", "3e6", "1e9"] {
        let text = plain
            .replace("dirichlet = [0.1, 0]", &format!("dirichlet = [\"{t} + 0.1\", \"0\"]"))
            .replace("chi = \"-0.2", &format!("chi = \"{t} - 0.2"));
        assert!(text.contains(&format!("chi = \"{t} - 0.2")), "{text}");
        std::fs::write(dir.join("shifted.toml"), text).unwrap();
        let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "shifted.toml", "--mesh", "structured:8"]);
        assert_eq!(code, 0, "{t}: {err}");
        seen.push(etas(&out));
    }
    let eta7 = |e: &Vec<f64>| e[6];
    assert!(eta7(&seen[0]) > 1e-3, "{seen:?}");
    for e in &seen[1..] {
        // a translation by 1e9 leaves u_h about 7 significant digits of the deformation
        assert!((eta7(e) - eta7(&seen[0])).abs() <= 1e-3 * eta7(&seen[0]), "eta_7 moved by the translation: {seen:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

const LARGE_AGAINST_ITS_VARIATION: &str = r#"description = "battery 9 S3: a displacement large against its variation"
body_force = [0, 0]
traction = "exact"
dirichlet = "exact"
[material]
mu = 1
lambda = 1
[parts]
contact = "y < 1e-12"
dirichlet = "y > 1 - 1e-12"
[contact]
normal = "outward"
chi = 0
[exact]
u = ["0.5 - 1e-9*x", "0"]
"#;

#[test]
fn an_exact_solution_large_against_its_variation_is_accepted_and_a_wrong_gradient_still_refused() {
    let dir = scratch("battery9-s3");
    std::fs::write(dir.join("s3.toml"), LARGE_AGAINST_ITS_VARIATION).unwrap();
    for mesh in ["structured:4", "structured:8", "structured:32"] {
        let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "s3.toml", "--mesh", mesh]);
        assert_eq!(code, 0, "{mesh}: {err}");
        assert!(out.contains("error Linf"), "{out}");
    }
    // the same file with a gradient written wrong by a factor of 3 (well above what the
    // differences resolve) is refused, blaming the written entry
    let wrong = LARGE_AGAINST_ITS_VARIATION
        .replace("u = [\"0.5 - 1e-9*x\", \"0\"]", "u = [\"0.5 - 1e-9*x\", \"0\"]\ngrad = [[\"-3e-9\", \"0\"], [\"0\", \"0\"]]");
    std::fs::write(dir.join("wrong.toml"), wrong).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "wrong.toml", "--mesh", "structured:8"]);
    assert_ne!(code, 0);
    assert!(err.contains("gradient contradicts its displacement") && err.contains("`exact.grad[0][0]`"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_file_where_a_folder_must_be_is_named() {
    let dir = scratch("battery9-s4");
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/s.toml"), STUDY.replace("levels = 16", "levels = 2")).unwrap();
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
