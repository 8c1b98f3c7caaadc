//! Battery 14, findings F3, F4 and F5:
//! * F3: a point constraint with a non-zero value at an interior point of Example 7.2 (u = (0.3,
//!   0) at (0.5, 0.5)) was certified, exit 0, and the answer depended on the mesh (a point has
//!   zero H^1 capacity: each mesh solved another problem). The solve now refuses a point
//!   constraint whose reaction is above its round-off (`contact::point`), so solve, adapt and
//!   studies all refuse it; the rollers' u_2 = 0, whose reaction is zero, is still accepted.

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
