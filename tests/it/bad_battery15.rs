//! Battery 15, finding F1 [silent]: the gap bound (the body's chord through the contact point
//! along n, battery 13 F1 and battery 14 F1) summed all the body's material along the line, also
//! beyond a piece whose far end is clamped. A C-shaped body whose 0.1 flange has its top clamped
//! was pushed 0.15 up, through that top, certified, because the upper arm across open air added
//! 0.1 to the sum (the same body as an L was refused). The sum now ends with the first piece
//! whose far end lies on Gamma_D holding the displacement along n (`contact::chord`; a block's
//! ligament over a clamped hole is in its unit tests).

use super::common::msh::{grid, msh};
use super::common::{scratch, signorini_in};

const FLANGE: &str = "dirichlet = [0, 0]\n[material]\nE = 500\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = [\"contact\"]\ndirichlet = [\"top\"]\nneumann = [\"free\"]\n[contact]\nnormal = \"outward\"\nchi = \"CHI\"\n";

#[test]
fn a_clamped_flange_is_not_pushed_through_its_top_by_an_arm_across_open_air() {
    let dir = scratch("b15-c");
    let flange_sides = |side: &str| match side {
        "bottom" => "contact",
        "top" => "top",
        _ => "free",
    };
    let free = |_: &str| "free";
    // the flange [0, 10] x [0, 0.1] (its top clamped), a column [0, 0.5] x [0.1, 1.1] on its left
    // end and an arm [0, 10] x [1.1, 1.2] back over it: along n = (0, -1) the line from the
    // flange's bottom meets 0.1 of flange, 1.0 of air and 0.1 of arm
    let c = msh(&[
        (grid(40, 1, [0.0, 0.0], [10.0, 0.1]), &flange_sides),
        (grid(2, 4, [0.0, 0.1], [0.5, 1.0]), &free),
        (grid(40, 1, [0.0, 0.1 + 1.0], [10.0, 0.1]), &free),
    ]);
    std::fs::write(dir.join("C.msh"), c).unwrap();
    std::fs::write(dir.join("deep.toml"), FLANGE.replace("CHI", "-0.15")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "deep.toml", "--mesh", "gmsh:C.msh"]);
    assert_eq!(code, 1, "{out}{err}");
    for part in ["is -0.15", "more than the body's thickness along the contact normal", "inside the body, 0.1)"] {
        assert!(err.contains(part), "{part}: {err}");
    }
    assert!(!out.contains("certified"), "{out}");
    // half the flange's thickness is a displacement it can take
    std::fs::write(dir.join("half.toml"), FLANGE.replace("CHI", "-0.05")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "half.toml", "--mesh", "gmsh:C.msh"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("certified"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}
