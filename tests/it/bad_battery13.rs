//! Battery 13:
//! * F1: the gap bound (a gap below minus the body's thickness along the contact normal is
//!   refused) took the edge-connected body's extent along n, so an L-shaped body whose contact
//!   side is a 0.1-thick flange (top clamped) with a column 5 high on its end let chi = -0.5
//!   push the flange 5 thicknesses through its clamped top, certified. The bound is now the
//!   body's chord through the point along n (`contact::chord::Chords`: the piece of the line
//!   p + t n inside the body that holds p).
//! * F5: a mesh far from the origin refined past the shape-round-off bound failed the next
//!   level's mesh check: `adapt` printed the triangle but not the level, and a study stored
//!   none of the levels solved. The loop now stops before that level
//!   (`adapt::AdaptTermination::FarFromOrigin`), naming it and what to do: `adapt` exits 1 after
//!   the levels it printed, as for the memory stop; a study stores the levels solved and says why
//!   on its summary line.

use super::common::msh::{grid, msh};
use super::common::{scratch, signorini_in};

const FLANGE: &str = "dirichlet = [0, 0]\n[material]\nE = 500\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = [\"contact\"]\ndirichlet = [\"top\"]\nneumann = [\"free\"]\n[contact]\nnormal = \"outward\"\nchi = \"CHI\"\n";

#[test]
fn a_thin_flange_of_a_thick_body_is_not_pushed_through_itself() {
    let dir = scratch("b13-flange");
    let flange_sides = |side: &str| match side {
        "bottom" => "contact",
        "top" => "top",
        _ => "free",
    };
    let column_sides = |_: &str| "free";
    // the flange [0, 10] x [0, 0.1] (its top clamped) and a column [0, 0.5] x [0.1, 5] on its
    // left end: one body, 5 high along n = (0, -1), 0.1 thick through the flange
    let flange = || grid(40, 1, [0.0, 0.0], [10.0, 0.1]);
    let l = msh(&[(flange(), &flange_sides), (grid(2, 10, [0.0, 0.1], [0.5, 4.9]), &column_sides)]);
    std::fs::write(dir.join("L.msh"), l).unwrap();
    std::fs::write(dir.join("plate.msh"), msh(&[(flange(), &flange_sides)])).unwrap();
    std::fs::write(dir.join("deep.toml"), FLANGE.replace("CHI", "-0.5")).unwrap();
    for mesh in ["gmsh:L.msh", "gmsh:plate.msh"] {
        let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "deep.toml", "--mesh", mesh, "--probe", "5,0"]);
        assert_eq!(code, 1, "{mesh}: {out}{err}");
        for part in ["is -0.5", "more than the body's thickness along the contact normal", "inside the body, 0.1)"] {
            assert!(err.contains(part), "{mesh}: {part}: {err}");
        }
        assert!(!out.contains("certified"), "{mesh}: {out}");
    }
    // half the flange's thickness is a displacement it can take
    std::fs::write(dir.join("half.toml"), FLANGE.replace("CHI", "-0.05")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "half.toml", "--mesh", "gmsh:L.msh"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("certified"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Example 7.2 scaled to a 10 x 10 block meshed 8 x 8 at (1e12, 1e12): the shapes of its
/// elements keep 2.5e-4 at level 0, and corner refinement passes the 1e-3 bound within a few levels.
fn far_block(dir: &std::path::Path) {
    let sides = |side: &str| match side {
        "left" => "left",
        "right" => "contact",
        _ => "free",
    };
    std::fs::write(dir.join("far.msh"), msh(&[(grid(8, 8, [1e12, 1e12], [10.0, 10.0]), &sides)])).unwrap();
    let problem = "dirichlet = [1.0, 0.0]\n[material]\nE = 500\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = [\"contact\"]\ndirichlet = [\"left\"]\nneumann = [\"free\"]\n[contact]\nnormal = \"outward\"\nchi = \"10*(-0.2 + 0.5*abs((y - 1e12)/10 - 0.5))\"\n";
    std::fs::write(dir.join("far.toml"), problem).unwrap();
}

/// The level `text` says the loop stopped before.
fn stopped_before(text: &str) -> usize {
    text.split("stopped before level ").nth(1).and_then(|s| s.split(' ').next()).and_then(|s| s.parse().ok()).expect(text)
}

#[test]
fn a_far_mesh_refined_past_its_round_off_stops_before_that_level_and_a_study_keeps_the_levels_solved() {
    let dir = scratch("b13-far");
    far_block(&dir);
    let (code, out, err) = signorini_in(&dir, &["adapt", "--problem", "far.toml", "--mesh", "gmsh:far.msh", "--levels", "12"]);
    assert_eq!(code, 1, "{out}{err}");
    let level = stopped_before(&err);
    assert!((1..12).contains(&level), "{err}");
    for part in [
        format!("levels 0 to {} were solved", level - 1),
        "lies at coordinates up to 1.00000000001e12".into(),
        "translate the mesh (and the problem's data) nearer the origin".into(),
        format!("--levels {level}"),
        "--max-ndof".into(),
    ] {
        assert!(err.contains(&part), "{part}: {err}");
    }
    // the levels solved were printed, the last one being level - 1
    let last_row = out.lines().rev().find(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).expect(&out);
    assert_eq!(last_row.split_whitespace().next(), Some((level - 1).to_string().as_str()), "{out}");
    // what it advises works
    let (code, _, err) = signorini_in(&dir, &["adapt", "--problem", "far.toml", "--mesh", "gmsh:far.msh", "--levels", &level.to_string()]);
    assert_eq!(code, 0, "{err}");
    // a study of more levels keeps those solved, and says why it stopped
    let manifest = "description = \"far\"\n[defaults]\nproblem = \"far.toml\"\nmesh = \"gmsh:far.msh\"\nlevels = 12\n[[run]]\nid = \"a\"\n";
    std::fs::write(dir.join("far_study.toml"), manifest).unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "far_study.toml", "--results", "res"]);
    assert_eq!(code, 0, "{out}{err}");
    let said = format!("{out}{err}");
    assert!(said.contains(&format!("far_study/a: {level} levels")) && stopped_before(&said) == level, "{said}");
    let record: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("res/far_study/runs/a.json")).unwrap()).unwrap();
    assert_eq!(record["levels"].as_array().map(Vec::len), Some(level), "{record}");
    std::fs::remove_dir_all(&dir).ok();
}
