//! Point constraints (`[[point_constraints]]`): a point value that takes a force, or that Gamma_D
//! sets otherwise, is refused; the rollers' point with zero reaction and an equal value on Gamma_D
//! are accepted; a point off the vertices names the mesh that lacks it.

use crate::common::{scratch, signorini_in};
use std::path::Path;

/// Example 7.2 with `u = (0.3, 0)` prescribed at its centre.
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
    let dir = scratch("point-constraints-point-constraint-that");
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
    let dir = scratch("point-constraints-rollers");
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

/// ex72_rollers without its required vertex (the wedge's tip) and with its point constraint at
/// (0, 0.4) (on structured:5, as (0.2, 0.6) is).
fn ex72_rollers_without_tip() -> String {
    rollers().replace("required_vertices = [[1, 0.5]]", "").replace("at = [0, 0.5]", "at = [0, 0.4]")
}

/// ex72_rollers with its point constraint's `u` replaced by `u`.
fn rollers_with(u: &str) -> String {
    let text = rollers();
    assert!(text.contains("u = [\"free\", 0]"), "the rollers' point constraint changed");
    text.replace("u = [\"free\", 0]", u)
}

/// The summary's lines that describe the solution (not the timings).
fn solution_lines(out: &str) -> Vec<&str> {
    out.lines().filter(|l| l.starts_with("contact:") || l.contains("estimate")).collect()
}

#[test]
fn a_point_value_that_gamma_d_sets_otherwise_is_refused() {
    let dir = scratch("point-constraints-dirichlet");
    for mesh in ["structured:4", "structured:16"] {
        let (code, out, err) = solve(&dir, &rollers_with("u = [0.25, 0]"), mesh);
        assert_eq!(code, 1, "{mesh}: {out}{err}");
        assert!(!out.contains("contact:"), "{mesh}: solved: {out}");
        for part in [
            "the point constraint at (0, 0.5) prescribes u_1 = 0.25",
            "on the Dirichlet part (parts.dirichlet",
            "already sets u_1 = 0.1 there",
            "drop it, or write \"free\" for u_1",
        ] {
            assert!(err.contains(part), "{mesh}: {part:?} not in {err}");
        }
    }
    // the adaptive loop gets the same refusal from its first solve
    let (code, _, err) = signorini_in(&dir, &["adapt", "--problem", "p.toml", "--levels", "3"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("already sets u_1 = 0.1 there"), "{err}");
}

#[test]
fn an_equal_point_value_on_gamma_d_is_accepted_and_changes_nothing() {
    let dir = scratch("point-constraints-dirichlet-equal");
    let (code, plain, err) = solve(&dir, &rollers(), "structured:8");
    assert_eq!(code, 0, "{err}");
    // 0.3 - 0.2 is 0.1 less 2.8e-17: the same value to round-off
    for u in ["u = [0.1, 0]", "u = [\"0.3 - 0.2\", 0]"] {
        let (code, out, err) = solve(&dir, &rollers_with(u), "structured:8");
        assert_eq!(code, 0, "{u}: {err}");
        assert!(!solution_lines(&plain).is_empty(), "{plain}");
        assert_eq!(solution_lines(&out), solution_lines(&plain), "{u}");
    }
    // 1e-9 off is no round-off
    let (code, _, err) = solve(&dir, &rollers_with("u = [0.100000001, 0]"), "structured:8");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("prescribes u_1 = 0.100000001") && err.contains("already sets u_1 = 0.1 there"), "{err}");
}

#[test]
fn a_point_constraint_off_the_vertices_says_which_mesh_has_one() {
    let dir = scratch("point-constraints-vertex");
    let text = format!("{}\n[[point_constraints]]\nat = [1, 0.3]\nu = [\"free\", 0]\n", rollers());
    let (code, _, err) = solve(&dir, &text, "structured:4");
    assert_eq!(code, 1, "{err}");
    for part in [
        "point_constraints[1].at`: (1, 0.3) is not a vertex of the mesh",
        "must be a vertex of the mesh given; none is inserted",
        "structured:10 (or symmetric:10)",
        "a Gmsh mesh needs a point there",
    ] {
        assert!(err.contains(part), "{part:?} not in {err}");
    }
    // the mesh it names has the vertex (whatever else it then says of the point)
    let (_, _, err) = solve(&dir, &text, "structured:10");
    assert!(!err.contains("is not a vertex"), "{err}");
    // the N named has every required vertex: (0.2, 0.6) alone is on structured:5, and the
    // wedge's tip (1, 0.5) needs N even
    let text = rollers().replace("required_vertices = [[1, 0.5]]", "required_vertices = [[1, 0.5], [0.2, 0.6]]");
    let (code, _, err) = solve(&dir, &text, "structured:4");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("structured:10 (or symmetric:10) and its multiples have one there and at every other required vertex"), "{err}");
    // an odd N is doubled for symmetric:N
    let text = format!("{}\n[[point_constraints]]\nat = [0.2, 0.6]\nu = [\"free\", 0]\n", ex72_rollers_without_tip());
    let (code, _, err) = solve(&dir, &text, "structured:4");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("structured:5 (or symmetric:10)"), "{err}");
}
