//! Battery 19's findings:
//! - F1 [lost]: a record made unreadable (truncated) made `run` (no --replace) remove the run's
//!   mesh snapshots and the study's reference solution as "files of an unfinished run", then
//!   refuse with "Nothing was run or changed". A refusal now comes before any file is removed,
//!   and the files of a run whose record is there but cannot be read are no orphans.
//! - F2 [message]: a refusal of the data found at a later level of the adaptive loop (`adapt`,
//!   `solve --adapt-levels`) named no level; it names the level and its unknowns now.

use super::common::{scratch, signorini_in};

const STUDY: &str = "description = \"repro\"\n[defaults]\nproblem = \"ex72\"\nmesh = \"structured:4\"\ntheta = 0.5\nquick_levels = 2\nsave_levels = [2]\n[defaults.reference]\ntheta = 0.5\nmin_ndof = 3000\n[[run]]\nid = \"adaptive\"\nrefine = \"adaptive\"\nlevels = 4\n";

/// Every file under `dir` with its bytes, sorted by path (lock files aside: each process that
/// takes a lock writes its own pid into it).
fn files(dir: &std::path::Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        if e.file_name().to_string_lossy().contains(".lock") {
            continue;
        } else if e.path().is_dir() {
            out.extend(files(&e.path()));
        } else {
            out.push((e.path(), std::fs::read(e.path()).unwrap()));
        }
    }
    out.sort();
    out
}

#[test]
fn a_run_refused_for_a_damaged_record_removes_nothing() {
    let dir = scratch("b19-damaged");
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    std::fs::write(dir.join("experiments/r.toml"), STUDY).unwrap();
    let run = ["run", "--results", "res", "experiments/r.toml"];
    let (code, out, err) = signorini_in(&dir, &run);
    assert_eq!(code, 0, "{out}{err}");
    let record = dir.join("res/r/runs/adaptive.json");
    let good = std::fs::read(&record).unwrap();
    std::fs::write(&record, &good[..good.len() - 20]).unwrap();
    let before = files(&dir.join("res"));
    assert!(before.iter().any(|(p, _)| p.to_string_lossy().contains("meshes/adaptive_level2")), "a snapshot");
    assert!(before.iter().any(|(p, _)| p.to_string_lossy().contains("references/")), "a reference");
    let (code, out, err) = signorini_in(&dir, &run);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("runs/adaptive.json") && !err.contains("removed"), "{err}");
    assert_eq!(files(&dir.join("res")), before, "the refusal changed the folder");
    // the record restored, the folder is whole again
    std::fs::write(&record, &good).unwrap();
    let (code, out, err) = signorini_in(&dir, &run);
    assert_eq!(code, 0, "{out}{err}");
    let said = format!("{out}{err}");
    assert!(said.contains("finished earlier") && !said.contains("removing"), "{said}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Example 7.1's problem file with f_1 off by 1e-3 in a disc of radius 0.002 at (0.503, 0.013):
/// no load point of structured:4 is in it, one of adaptive level 1 is.
fn bf_low() -> String {
    let ex71 = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/experiments/problems/ex71.toml")).unwrap();
    let f = r#"body_force = ["2*exp(y)*(y^2 + y - 1) - 6*y + 2", "3*y*(x - 2)*(y + 3)*exp(y)"]"#;
    assert!(ex71.contains(f), "experiments/problems/ex71.toml writes its body force as {f}");
    let off = r#"body_force = ["(2*exp(y)*(y^2 + y - 1) - 6*y + 2)*(1 + 1e-3*(1+signum(0.000004-(x-0.503)^2-(y-0.013)^2))/2)", "3*y*(x - 2)*(y + 3)*exp(y)"]"#;
    ex71.replace(f, off)
}

#[test]
fn a_refusal_at_a_later_level_names_the_level() {
    let dir = scratch("b19-level");
    std::fs::write(dir.join("bf_low.toml"), bf_low()).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "bf_low.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 0, "no load point of structured:4 is in the disc: {out}{err}");
    for args in [
        &["adapt", "--problem", "bf_low.toml", "--levels", "4"][..],
        &["solve", "--problem", "bf_low.toml", "--mesh", "structured:4", "--adapt-levels", "3"],
    ] {
        let (code, out, err) = signorini_in(&dir, args);
        assert_eq!(code, 1, "{args:?}: {out}{err}");
        assert!(err.contains("level 1 (282 unknowns): problem file bf_low.toml: the body force is not -div sigma(u)"), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Battery 20, F1 [message]: `run --plan --replace` did not say which stored runs `run --replace`
/// removes (a run no longer declared was left out of the plan, a run whose record cannot be read
/// was listed as a new run) nor the leftover files `run` removes first.
#[test]
fn the_plan_names_every_removal() {
    let dir = scratch("b20-plan");
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    let two = "description = \"plan\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\nlevels = 3\nsave_levels = [1]\n[[run]]\nid = \"adaptive\"\n[[run]]\nid = \"uniform\"\nrefine = \"uniform\"\n";
    std::fs::write(dir.join("experiments/s.toml"), two).unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/s.toml", "--results", "res"]);
    assert_eq!(code, 0, "{out}{err}");
    let plan = ["run", "experiments/s.toml", "--results", "res", "--plan", "--replace"];
    // a leftover of a killed process: named as what run removes first
    std::fs::write(dir.join("res/s/meshes/gone_level1.json"), "{}").unwrap();
    let (code, out, err) = signorini_in(&dir, &plan);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("s (first removes 1 leftover file(s) of an unfinished run:") && out.contains("gone_level1.json"), "{out}");
    std::fs::remove_file(dir.join("res/s/meshes/gone_level1.json")).unwrap();
    // a record that cannot be read: replaced
    let record = dir.join("res/s/runs/uniform.json");
    let good = std::fs::read(&record).unwrap();
    std::fs::write(&record, &good[..500]).unwrap();
    let (code, out, err) = signorini_in(&dir, &plan);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("s/uniform (replaces the stored run: its record does not hold together)"), "{out}");
    // a run no longer declared: removed
    std::fs::write(&record, &good).unwrap();
    std::fs::write(dir.join("experiments/s.toml"), &two[..two.find("[[run]]\nid = \"uniform\"").unwrap()]).unwrap();
    let (code, out, err) = signorini_in(&dir, &plan);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("s/uniform (removes the stored run and its snapshots: not declared in experiments/s.toml)"), "{out}");
    assert!(out.contains("s/adaptive (kept"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}
