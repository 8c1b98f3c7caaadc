//! Battery 12, what a solve's numbers resolve under far-translated data (`adapt::resolution`,
//! the one decision of `solve`, every level of `adapt` and every study run):
//! * F3: Example 7.2 translated rigidly by 3e11 stopped `adapt` and `run` at level 1 as "exact to
//!   round-off" with a genuine estimate, and the study stored 2 of its 6 levels without a reason.
//!   The estimate's round-off test came first and its bound exceeded every estimate of a u_h
//!   whose round-off reaches 1e-2 of its deformation, so that refusal never fired. The
//!   deformation is now asked first (a u_h without deformation above 30 times its round-off is at
//!   round-off: exact, or translated beyond recognition; one with a deformation and a round-off
//!   above 1e-2 of it is refused); the stop note no longer calls u_h exact; a study run that ends
//!   before its last level says why on its summary line (not in the stored record).
//! * F1: the contact forces' round-off bounds (`lambda_floor`) grow with the translation, and at
//!   1e10 on `structured:16` real forces fell under them: eta_7 5.120e-3 -> 1.9e-6, no word.
//!   A bound above 1e-2 of the largest contact force, or an active force under its own bound
//!   while the bounds are above 1e-6 of it, is refused; a bound above 1e-6 of it is warned
//!   (stderr, and `warnings` in `solve --json`, which now carries `roundoff_floor` too).
//! * F7: a mesh translated far from the origin kept element shapes to 2.5e-2 (1e13: eta_6 35%
//!   off, no word), and at 1e15 was refused as "the body can move rigidly" on a line. The mesh
//!   check (`Mesh::check`, before anything reads the geometry) now refuses element shapes kept to
//!   worse than 1e-3 ("translate the mesh nearer the origin"); beyond 1e-5 `solve` warns.

use super::common::{scratch, signorini_in};
use std::path::Path;

/// Example 7.2's data with a rigid translation `c` added to the Dirichlet data and the gap.
fn translated(c: &str) -> String {
    format!(
        "dirichlet = [\"0.1 + {c}\", 0]\nrequired_vertices = [[1, 0.5]]\n[material]\nE = 500\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = \"x > 1 - 1e-12\"\ndirichlet = \"x < 1e-12\"\n[contact]\nnormal = \"outward\"\nchi = \"{c} + (-0.2 + 0.5*abs(y - 0.5))\"\n"
    )
}

fn solve_translated(dir: &Path, c: &str, mesh: &str, json: bool) -> (i32, String, String) {
    std::fs::write(dir.join("rt.toml"), translated(c)).unwrap();
    let mut args = vec!["solve", "--problem", "rt.toml", "--mesh", mesh];
    if json {
        args.push("--json");
    }
    signorini_in(dir, &args)
}

fn eta7(out: &str) -> f64 {
    let line = out.lines().find(|l| l.starts_with("estimator: eta1..7 = ")).unwrap_or_else(|| panic!("{out}"));
    line["estimator: eta1..7 = ".len()..].split(',').next().unwrap().split_whitespace().nth(6).unwrap().parse().unwrap()
}

#[test]
fn a_u_h_whose_round_off_reaches_its_deformation_is_refused_not_called_exact() {
    let dir = scratch("b12-f3");
    // structured:8 at 3e11: round-off 1.3e-2 of the deformation, estimate 660 times its round-off
    // scale (below the 1e3 that made it "at round-off", exit 0 with a warning)
    let (code, out, err) = solve_translated(&dir, "3e11", "structured:8", false);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("u_h does not resolve the deformation") && !out.contains("estimator:"), "{out}{err}");
    // an exact rigid translation is still at round-off, and the note does not call every such
    // u_h exact
    std::fs::write(
        dir.join("rigid.toml"),
        "dirichlet = [0.1, 0.3]\n[material]\nE = 500\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = \"x > 1 - 1e-12\"\ndirichlet = \"x < 1e-12\"\n[contact]\nnormal = \"outward\"\nchi = \"1e3\"\n",
    )
    .unwrap();
    let (code, out, err) = signorini_in(&dir, &["adapt", "--problem", "rigid.toml", "--mesh", "structured:16", "--levels", "3"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("# stopped: the estimate is zero, or at round-off"), "{out}");
    assert!(out.contains("or a rigid translation in the data left it no digits of the deformation"), "{out}");
    assert!(!out.contains("the discrete solution is exact"), "{out}");
}

#[test]
fn a_study_run_of_translated_data_is_refused_and_an_early_stop_says_why() {
    let dir = scratch("b12-f3-run");
    std::fs::create_dir_all(dir.join("exp/problems")).unwrap();
    std::fs::write(dir.join("exp/problems/t.toml"), translated("3e11")).unwrap();
    let manifest = |name: &str, problem: &str, extra: &str| {
        std::fs::write(
            dir.join(format!("exp/{name}.toml")),
            format!("description = \"F3\"\n[defaults]\nproblem = \"{problem}\"\nmesh = \"structured:4\"\nlevels = 6\n{extra}[[run]]\nid = \"a\"\n"),
        )
        .unwrap();
    };
    manifest("tr", "problems/t.toml", "");
    let (code, _, err) = signorini_in(&dir, &["run", "exp/tr.toml", "--results", "res"]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("tr/a: level 0: the contact forces are not resolved"), "{err}");
    assert!(!dir.join("res/tr/runs/a.json").exists(), "a refused run is not stored");
    // a run that stops before its last level for another reason says which
    manifest("short", "ex72", "max_ndof = 300\n");
    let (code, _, err) = signorini_in(&dir, &["run", "exp/short.toml", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    let line = err.lines().find(|l| l.starts_with("short/a: ")).unwrap_or_else(|| panic!("{err}"));
    assert!(
        line.contains("levels, final NDF") && line.contains("(stopped: the next level would have more than max_ndof = 300 unknowns)"),
        "{line}"
    );
}

#[test]
fn contact_forces_at_their_round_off_are_refused_and_fewer_than_six_digits_warned() {
    let dir = scratch("b12-f1");
    // structured:16 at 1e10: two active forces under their bounds, eta_7 1.9e-6 instead of 5.12e-3
    let (code, out, err) = solve_translated(&dir, "1e10", "structured:16", false);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("the contact forces are not resolved") && err.contains("carry a force under their own bound"), "{err}");
    assert!(!out.contains("estimator:"), "{out}");
    // structured:32 at 1e8: one active force under its bound while the bounds are 1.7e-3 of the
    // largest force (eta_7 is 5% off at 1e9)
    let (code, out, err) = solve_translated(&dir, "1e8", "structured:32", false);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("1 active node carries a force under its own bound"), "{err}");
    // structured:8 at 1e9: bounds 3.6e-3 of the largest force, eta_7 kept, and said
    let (code, plain, err) = solve_translated(&dir, "0", "structured:8", false);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("warning"), "{err}");
    let (code, out, err) = solve_translated(&dir, "1e9", "structured:8", false);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("warning: the contact forces keep fewer than 6 digits"), "{err}");
    assert!((eta7(&out) - eta7(&plain)).abs() <= 1e-3 * eta7(&plain), "{plain}\n{out}");
    // the JSON carries the same warning and u_h's round-off floor
    let (code, json, err) = solve_translated(&dir, "1e9", "structured:8", true);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let warnings = v["warnings"].as_array().unwrap_or_else(|| panic!("{json}"));
    assert!(warnings.len() == 1 && warnings[0].as_str().unwrap().starts_with("the contact forces keep fewer than 6 digits"), "{json}");
    assert!(v["roundoff_floor"].as_f64().is_some_and(|r| r > 1e-6), "{json}");
    let (_, json, _) = solve_translated(&dir, "0", "structured:8", true);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["warnings"].as_array().map(Vec::len), Some(0), "{json}");
}

/// An n x n Gmsh grid of the unit square moved by (t, t) (groups left, contact on the right,
/// free), and Example 7.2's data moved with it.
fn far_square(dir: &Path, n: usize, t: f64) {
    let sides: super::common::msh::Groups = &|side| match side {
        "left" => "left",
        "right" => "contact",
        _ => "free",
    };
    let msh = super::common::msh::msh(&[(super::common::msh::grid(n, n, [t, t], [1.0, 1.0]), sides)]);
    std::fs::write(dir.join("far.msh"), msh).unwrap();
    std::fs::write(
        dir.join("far.toml"),
        format!(
            "dirichlet = [0.1, 0]\nrequired_vertices = [[{:?}, {:?}]]\n[material]\nE = 500\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = [\"contact\"]\ndirichlet = [\"left\"]\nneumann = [\"free\"]\n[contact]\nnormal = \"outward\"\nchi = \"-0.2 + 0.5*abs(y - {t:?} - 0.5)\"\n",
            t + 1.0,
            t + 0.5
        ),
    )
    .unwrap();
}

#[test]
fn a_mesh_far_from_the_origin_is_refused_as_such_and_warned_before() {
    let dir = scratch("b12-f7");
    let solve = |t: f64| {
        far_square(&dir, 8, t);
        signorini_in(&dir, &["solve", "--problem", "far.toml", "--mesh", "gmsh:far.msh"])
    };
    let (code, plain, err) = solve(0.0);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("warning"), "{err}");
    // 1e15: the Dirichlet side x = 1e15, 0 <= y - 1e15 <= 1 was read as a line
    for t in [1e13, 1e15] {
        let (code, out, err) = solve(t);
        assert_eq!(code, 1, "{t}: {out}{err}");
        assert!(
            err.contains("translate the mesh (and the problem's data) nearer the origin") && err.contains("at most 1e-3 is accepted"),
            "{t}: {err}"
        );
        assert!(!err.contains("rigidly"), "{t}: {err}");
    }
    // 1e11: shapes kept to 2.5e-4, eta_6 0.3% off: said, and solved
    let (code, out, err) = solve(1e11);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("warning: the element shapes keep fewer than 5 digits"), "{err}");
    assert!((eta7(&out) - eta7(&plain)).abs() <= 1e-3 * eta7(&plain), "{plain}\n{out}");
}
