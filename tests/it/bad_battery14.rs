//! Battery 14, findings F3, F4 and F5:
//! * F3: a point constraint with a non-zero value at an interior point of Example 7.2 (u = (0.3,
//!   0) at (0.5, 0.5)) was certified, exit 0, and the answer depended on the mesh (a point has
//!   zero H^1 capacity: each mesh solved another problem). The solve now refuses a point
//!   constraint whose reaction is above its round-off (`contact::point`), so solve, adapt and
//!   studies all refuse it; the rollers' u_2 = 0, whose reaction is zero, is still accepted.
//! * F4: `adapt --uniform --problem patch` (exact to round-off) printed efficiencies of
//!   round-off over round-off without a word, where `solve` warns and the adaptive loop stops.
//!   Every level at round-off now says so (the text `solve` gives) in `adapt`, uniform too, and
//!   in a study run's warnings and summary line; nothing stored changes.
//! * F5: a run record truncated (or not JSON, or a link to another file) stopped run, run
//!   --plan, drift --against and run --replace alike with the JSON parser's error and no
//!   remedy. It is now a fault of its run (named by the file stem) in the store's check, refused
//!   with the `--replace` advice, and `run --replace` removes the file (a link, never its
//!   target) and computes the run again.

use super::common::{scratch, signorini_in};
use std::path::Path;

/// Example 7.2 with `u = (0.3, 0)` prescribed at its centre (battery 14's repro).
const INTERIOR_POINT: &str = "dirichlet = [0.1, 0]\nrequired_vertices = [[1, 0.5]]\n[material]\nE = 500\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = \"x > 1 - 1e-12\"\ndirichlet = \"x < 1e-12\"\n[contact]\nnormal = \"outward\"\nchi = \"-0.2 + 0.5*abs(y - 0.5)\"\n[[point_constraints]]\nat = [0.5, 0.5]\nu = [0.3, 0]\n";

fn rollers() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/experiments/problems/ex72_rollers.toml")).unwrap()
}

fn solve(dir: &Path, problem: &str, mesh: &str) -> (i32, String, String) {
    std::fs::write(dir.join("p.toml"), problem).unwrap();
    signorini_in(dir, &["solve", "--problem", "p.toml", "--mesh", mesh])
}

#[test]
fn a_point_constraint_that_takes_a_force_is_refused() {
    let dir = scratch("b14-f3");
    for mesh in ["structured:4", "structured:16"] {
        let (code, out, err) = solve(&dir, INTERIOR_POINT, mesh);
        assert_eq!(code, 1, "{mesh}: {out}{err}");
        assert!(!out.contains("estimator:"), "{mesh}: {out}");
        for part in [
            "the point constraint at (0.5, 0.5) prescribes u_1 = 0.3",
            "takes a force of",
            "removing a rigid motion",
            "zero H^1 capacity",
            "on a part",
        ] {
            assert!(err.contains(part), "{mesh}: {part:?} not in {err}");
        }
    }
    // the adaptive loop gets the same refusal from its first solve
    let (code, _, err) = signorini_in(&dir, &["adapt", "--problem", "p.toml", "--levels", "3"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("removing a rigid motion"), "{err}");
}

#[test]
fn the_rollers_point_with_zero_reaction_is_accepted() {
    let dir = scratch("b14-f3-rollers");
    for mesh in ["structured:4", "structured:16", "symmetric:24"] {
        let (code, out, err) = solve(&dir, &rollers(), mesh);
        assert_eq!(code, 0, "{mesh}: {err}");
        assert!(out.contains("estimator:"), "{mesh}: {out}");
        assert!(!err.contains("point constraint"), "{mesh}: {err}");
    }
    // u_2 = 0.05 at the point still only fixes the vertical rigid motion (here, a translation
    // by 0.05), which takes no force: accepted too; it is the force, not the value, that counts
    let moved = rollers().replace("u = [\"free\", 0] ", "u = [\"free\", 0.05] ");
    assert_ne!(moved, rollers());
    let (code, _, err) = solve(&dir, &moved, "structured:8");
    assert_eq!(code, 0, "{err}");
}

/// Battery 14's two-run study (repro truncated_record_replace.sh).
const TWO_RUNS: &str = "description = \"s\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\ntheta = 0.5\nlevels = 4\nquick_levels = 2\n[[run]]\nid = \"a\"\nrefine = \"adaptive\"\n[[run]]\nid = \"c\"\nrefine = \"uniform\"\n";

fn stored_two_runs(name: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    std::fs::write(dir.join("experiments/s.toml"), TWO_RUNS).unwrap();
    for results in ["res", "fresh"] {
        let (code, out, err) = signorini_in(&dir, &["run", "experiments/s.toml", "--results", results]);
        assert_eq!(code, 0, "{out}{err}");
    }
    dir
}

#[test]
fn a_truncated_record_is_a_fault_of_its_run_that_replace_recomputes() {
    let dir = stored_two_runs("b14-f5");
    let record = dir.join("res/s/runs/c.json");
    let text = std::fs::read(&record).unwrap();
    std::fs::write(&record, &text[..100]).unwrap();
    for args in [&["run", "experiments/s.toml", "--results", "res"][..], &["run", "experiments/s.toml", "--results", "res", "--plan"]] {
        let (code, out, err) = signorini_in(&dir, args);
        assert_eq!(code, 1, "{args:?}: {out}{err}");
        assert!(err.contains("runs/c.json") && err.contains("is not a run record (truncated, or not JSON)"), "{args:?}: {err}");
        assert!(err.contains("--replace"), "{args:?}: {err}");
    }
    let (code, out, err) = signorini_in(&dir, &["drift", "--experiments", "experiments", "--results", "res", "--against", "fresh"]);
    assert_ne!(code, 0, "{out}{err}");
    assert!(format!("{out}{err}").contains("runs/c.json"), "{out}{err}");
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/s.toml", "--results", "res", "--replace"]);
    assert_eq!(code, 0, "{out}{err}");
    let both = format!("{out}{err}");
    assert!(both.contains("s/c: removing the stored run") && both.contains("1 run(s) executed"), "{both}");
    assert!(std::fs::read(&record).unwrap().len() > 100, "run c stored again");
    let (code, out, err) = signorini_in(&dir, &["drift", "--experiments", "experiments", "--results", "res", "--against", "fresh"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("drift: none"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_record_that_links_to_another_file_is_removed_and_its_target_kept() {
    let dir = stored_two_runs("b14-f5-link");
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

const AT_ROUNDOFF: &str = "the estimate is at the round-off of u_h";

#[test]
fn every_uniform_level_at_round_off_says_so() {
    let dir = scratch("b14-f4");
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "patch", "--mesh", "structured:4"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(format!("{out}{err}").contains(AT_ROUNDOFF), "solve: {out}{err}");
    let (code, out, err) = signorini_in(&dir, &["adapt", "--uniform", "--problem", "patch", "--levels", "3"]);
    assert_eq!(code, 0, "{out}{err}");
    for level in 0..3 {
        assert!(err.contains(&format!("warning: level {level}: {AT_ROUNDOFF}")), "level {level}: {err}");
    }
    // Example 7.1 is not at round-off: no such warning
    let (code, out, err) = signorini_in(&dir, &["adapt", "--uniform", "--problem", "ex71", "--levels", "3"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(!err.contains(AT_ROUNDOFF), "{err}");
    // a study: a warning per level and the run's summary line
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    std::fs::write(
        dir.join("experiments/p.toml"),
        "description = \"p\"\n[defaults]\nproblem = \"patch\"\nmesh = \"structured:4\"\nlevels = 3\n[[run]]\nid = \"u\"\nrefine = \"uniform\"\n",
    )
    .unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/p.toml", "--results", "res"]);
    assert_eq!(code, 0, "{out}{err}");
    let both = format!("{out}{err}");
    assert!(both.contains(&format!("warning: p/u: level 2: {AT_ROUNDOFF}")), "{both}");
    let summary = both.lines().find(|l| l.starts_with("p/u: 3 levels")).unwrap_or_else(|| panic!("{both}"));
    assert!(summary.contains("level(s) 0, 1, 2 at the round-off of u_h"), "{summary}");
    std::fs::remove_dir_all(&dir).ok();
}
