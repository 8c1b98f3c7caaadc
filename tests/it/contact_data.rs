//! Contact data the solve cannot honour are refused, naming the node, the normals or the gap:
//! corners of the contact normal, nodes with one prescribed component, data on a stretch between
//! nodes; the gap bound is the body's own thickness along the normal through the contact point
//! (thin plates, flanges, clamped ends), and `normal = "outward"` is the body's outward normal on
//! every group.

use crate::common::msh::{grid, msh};
use crate::common::{fixture, level_rows, scratch, signorini_in};

fn repo(path: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// u_h at the probe, from the `solve` output line `u_h(x, y) = (u1, u2)`.
fn probe(out: &str, at: &str) -> [f64; 2] {
    let line = out.lines().find(|l| l.starts_with(&format!("u_h({at})"))).unwrap_or_else(|| panic!("no probe {at}: {out}"));
    let inner = line.split(" = (").nth(1).unwrap().trim_end_matches(')');
    let v: Vec<f64> = inner.split(", ").map(|s| s.parse().unwrap()).collect();
    [v[0], v[1]]
}

const SQUARE: &str = "dirichlet = [0.1, 0]\n[material]\nmu = 1\nlambda = 1\n[parts]\ncontact = \"CONTACT\"\ndirichlet = \"DIRICHLET\"\n[contact]\nnormal = NORMAL\nchi = 0.05\n";

fn square(name: &str, contact: &str, dirichlet: &str, normal: &str, mesh: &str, probes: &[&str]) -> (i32, String, String) {
    let dir = scratch(name);
    let text = SQUARE.replace("CONTACT", contact).replace("DIRICHLET", dirichlet).replace("NORMAL", normal);
    std::fs::write(dir.join("p.toml"), text).unwrap();
    let mut args = vec!["solve", "--problem", "p.toml", "--mesh", mesh];
    for p in probes {
        args.extend(["--probe", p]);
    }
    signorini_in(&dir, &args)
}

#[test]
fn a_corner_between_two_outward_contact_sides_is_refused_naming_the_node_and_both_normals() {
    let (code, out, err) = square("b10-corner", "y < 1e-12 || x > 1 - 1e-12", "x < 1e-12", "\"outward\"", "structured:8", &["1,0"]);
    assert_eq!(code, 1, "{out}{err}");
    for part in [
        "the contact node at (1, 0)",
        "is a corner of the contact normal",
        "(1.000000, 0.000000)",
        "(0.000000, -1.000000)",
        "90.0000 degrees",
        "declare its direction",
    ] {
        assert!(err.contains(part), "{part}: {err}");
    }
    // the advice followed: the bottom's contact ends before the corner; the corner is held at the wall
    let (code, out, err) = square(
        "b10-corner-ended",
        "y < 1e-12 && x < 0.875 || x > 1 - 1e-12",
        "x < 1e-12",
        "\"outward\"",
        "structured:8",
        &["1,0", "1,0.0625"],
    );
    assert_eq!(code, 0, "{err}");
    for at in ["1, 0", "1, 0.0625"] {
        let u = probe(&out, at);
        assert!(u[0] <= 0.05 + 1e-12, "{at}: {u:?} passes the wall x = 1.05");
    }
}

#[test]
fn a_declared_normal_that_jumps_at_a_contact_vertex_is_a_corner_too() {
    // (0, -1) on the bottom, (1, 0) on the right side and at the corner itself
    let jump = "[\"max(0, signum(x - 1 + 1e-12))\", \"max(0, signum(x - 1 + 1e-12)) - 1\"]";
    let (code, out, err) = square("b10-jump", "y < 1e-12 || x > 1 - 1e-12", "x < 1e-12", jump, "structured:8", &[]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("the contact node at (1, 0)") && err.contains("is a corner of the contact normal"), "{err}");
    // a declared constant direction has no corner: the bottom alone with it solves
    let (code, _, err) = square("b10-flat", "y < 1e-12", "x < 1e-12", "[0, -1]", "structured:8", &[]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn outward_gives_a_flat_contact_group_its_own_normal_beside_a_circle_group() {
    let dir = scratch("contact-data-circle-flat");
    let mesh = format!("gmsh:{}", repo("experiments/meshes/quarter_disc.msh").display());
    // the arc (a circle) and the flat bottom both in contact; the vertex (1, 0) where they meet
    // at a right angle is held by a point constraint, so it carries no contact constraint
    let problem = "dirichlet = [0, 0]\nbody_force = [0, \"-2\"]\n[[point_constraints]]\nat = [1, 0]\nu = [0, 0]\n[material]\nmu = 1\nlambda = 1\n[parts]\ncontact = [\"arc\", \"bottom\"]\ndirichlet = [\"left\"]\n[curves]\narc = { circle = { centre = [0, 0], radius = 1 } }\n[contact]\nnormal = \"outward\"\nchi = 0.02\n";
    std::fs::write(dir.join("p.toml"), problem).unwrap();
    // the point constraint holding the vertex takes a force (a quarter of the nodal forces'
    // scale), so each mesh would solve another problem: it is refused, and the bottom's normal
    // beside the arc cannot be checked on this mesh with it
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", &mesh, "--probe", "0.5,0", "--probe", "0.75,0"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("the point constraint at (1, 0) prescribes u_1 = 0") && err.contains("removing a rigid motion"), "{err}");
    // what is left to check positively on this mesh: the flat group in contact beside the (free)
    // arc, held at the floor along its own normal (0, -1). The arc and the bottom both in contact
    // need the meeting vertex out of contact, which only a point constraint taking a force did
    let flat = problem
        .replace("[[point_constraints]]\nat = [1, 0]\nu = [0, 0]\n", "")
        .replace("contact = [\"arc\", \"bottom\"]", "contact = [\"bottom\"]\nneumann = [\"arc\"]")
        .replace("[curves]\narc = { circle = { centre = [0, 0], radius = 1 } }\n", "");
    std::fs::write(dir.join("p.toml"), &flat).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", &mesh, "--probe", "0.5,0", "--probe", "0.75,0"]);
    assert_eq!(code, 0, "{err}");
    for at in ["0.5, 0", "0.75, 0"] {
        let u = probe(&out, at);
        assert!(u[1] >= -0.02 - 1e-12, "{at}: {u:?} passes the floor y = -0.02");
    }
    assert!((probe(&out, "0.75, 0")[1] + 0.02).abs() < 1e-9, "the bottom presses on the floor: {out}");
    // without the point constraint the meeting vertex is a corner: refused, with both normals
    std::fs::write(dir.join("p.toml"), problem.replace("[[point_constraints]]\nat = [1, 0]\nu = [0, 0]\n", "")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", &mesh]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("the contact node at (1, 0)") && err.contains("corner") && err.contains("90.0000 degrees"), "{err}");
}

#[test]
fn outward_finds_a_contact_stretch_shorter_than_a_sixteenth_of_a_side() {
    // the top edge of the right side (1/32 long) alone
    let (code, out, err) =
        square("b10-tip", "x > 1 - 1e-12 && y > 0.96875", "x < 1e-12 && y > 0.5", "\"outward\"", "structured:32", &["1,0.984375"]);
    assert_eq!(code, 0, "{err}");
    assert!(probe(&out, "1, 0.984375")[0] <= 0.05 + 1e-12, "{out}");
    // beside the bottom, with its own normal (1, 0), not the bottom's (0, -1)
    let (code, _, err) =
        square("b10-tip-bottom", "y < 1e-12 || x > 1 - 1e-12 && y > 0.96875", "x < 1e-12 && y > 0.5", "\"outward\"", "structured:32", &[]);
    assert_eq!(code, 0, "{err}");
}

const TANGENT: &str = "dirichlet = [0, -0.01]\n[material]\nE = 100\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = \"y < 1e-12\"\ndirichlet = \"y > 1 - 1e-12\"\n[contact]\nnormal = [\"x - 0.5\", \"-1e-3\"]\nchi = 0\n";

#[test]
fn a_nearly_tangent_declared_normal_is_named_as_such_not_as_a_corner() {
    let dir = scratch("contact-data-tangent");
    std::fs::write(dir.join("t.toml"), TANGENT).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "t.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("nearly tangent to the boundary"), "{err}");
    assert!(!err.contains("corner"), "{err}");
    // a normal that turns fast but stays well away from the surface is no corner either
    let steep = TANGENT.replace("\"-1e-3\"", "\"-1\"").replace("\"x - 0.5\"", "\"1e-3*(x - 0.5)\"");
    std::fs::write(dir.join("s.toml"), steep).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "s.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 0, "{err}");
}

const SQUARE_GAP: &str = "dirichlet = [0, 0]\n[material]\nE = 100\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = \"y < 1e-12\"\ndirichlet = \"y > 1 - 1e-12\"\n[contact]\nnormal = [0, -1]\nchi = CHI\n";

#[test]
fn a_gap_below_minus_the_bodys_extent_along_the_normal_is_refused() {
    let dir = scratch("contact-data-gap");
    // the unit square is 1 thick along (0, -1): -1.2 pushes its bottom through the clamped top
    // (the bounding box's diagonal, the former bound, is 1.414)
    std::fs::write(dir.join("deep.toml"), SQUARE_GAP.replace("CHI", "-1.2")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "deep.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{out}{err}");
    for part in ["is -1.2", "more than the body's thickness along the contact normal (0.000000, -1.000000)", "inside the body, 1)"] {
        assert!(err.contains(part), "{part}: {err}");
    }
    // half the thickness is a (large) displacement the body can take
    std::fs::write(dir.join("half.toml"), SQUARE_GAP.replace("CHI", "-0.5")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "half.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 0, "{out}{err}");
}

const PLATE: &str = "dirichlet = [0, 0]\n[material]\nE = 1000\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = [\"contact\"]\ndirichlet = [\"top\"]\nneumann = [\"free\"]\n[contact]\nnormal = [0, -1]\nchi = \"CHI\"\n";

#[test]
fn a_second_body_does_not_widen_the_gap_bound_of_a_thin_plate() {
    let dir = scratch("contact-data-gap-second-body-does");
    let plate = |side: &str| match side {
        "bottom" => "contact",
        "top" => "top",
        _ => "free",
    };
    let held = |side: &str| if side == "top" { "top" } else { "free" };
    let two = msh(&[(grid(40, 2, [0.0, 0.0], [10.0, 0.1]), &plate), (grid(4, 4, [0.0, 5.0], [1.0, 1.0]), &held)]);
    std::fs::write(dir.join("two.msh"), two).unwrap();
    // chi = -0.5 pushes the plate (0.1 thick) 5 thicknesses through its clamped top; the square
    // 5 above it made the whole mesh 6 high along n, and the solve was certified
    std::fs::write(dir.join("thin.toml"), PLATE.replace("CHI", "-0.5")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "thin.toml", "--mesh", "gmsh:two.msh"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("is -0.5") && err.contains("inside the body, 0.1)"), "{err}");
    // each body in contact, each within its own thickness (the plate 0.05 of its 0.1, the
    // square 0.5 of its 1, more than the plate's extent): solved
    let both = |side: &str| match side {
        "bottom" => "contact",
        "top" => "top",
        _ => "free",
    };
    let pair = msh(&[(grid(40, 2, [0.0, 0.0], [10.0, 0.1]), &plate), (grid(4, 4, [0.0, 5.0], [1.0, 1.0]), &both)]);
    std::fs::write(dir.join("pair.msh"), pair).unwrap();
    std::fs::write(dir.join("each.toml"), PLATE.replace("CHI", "-0.05 - 0.45*min(1, max(0, y - 1))")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "each.toml", "--mesh", "gmsh:pair.msh", "--probe", "0.5,5"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("certified"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

const FLANGE: &str = "dirichlet = [0, 0]\n[material]\nE = 500\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = [\"contact\"]\ndirichlet = [\"top\"]\nneumann = [\"free\"]\n[contact]\nnormal = \"outward\"\nchi = \"CHI\"\n";

#[test]
fn a_thin_flange_of_a_thick_body_is_not_pushed_through_itself() {
    let dir = scratch("contact-data-flange");
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

#[test]
fn a_clamped_flange_is_not_pushed_through_its_top_by_an_arm_across_open_air() {
    let dir = scratch("contact-data-c");
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

/// A plate [0, 1] x [0, 0.1], its top held at `top` = u, contact on its bottom at gap `chi`.
fn plate(top: &str, chi: &str) -> String {
    format!(
        "dirichlet = {top}\n[material]\nE = 1000\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = [\"contact\"]\ndirichlet = [\"top\"]\nneumann = [\"free\"]\n[contact]\nnormal = \"outward\"\nchi = \"{chi}\"\n"
    )
}

#[test]
fn a_held_end_counts_where_its_dirichlet_data_put_it() {
    let dir = scratch("contact-data-held");
    let sides = |side: &str| match side {
        "bottom" => "contact",
        "top" => "top",
        _ => "free",
    };
    std::fs::write(dir.join("plate.msh"), msh(&[(grid(10, 2, [0.0, 0.0], [1.0, 0.1]), &sides)])).unwrap();
    let solve = |top: &str, chi: &str| {
        std::fs::write(dir.join("p.toml"), plate(top, chi)).unwrap();
        signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", "gmsh:plate.msh"])
    };
    // the top moved 0.05 towards the face leaves 0.05: -0.08 refused, -0.03 solved
    for (top, chi, room) in [("[0, -0.05]", "-0.08", "0.05"), ("[0, -0.2]", "0.01", "-0.1")] {
        let (code, out, err) = solve(top, chi);
        assert_eq!(code, 1, "{top} {chi}: {out}{err}");
        let part = format!(
            "which the Dirichlet data move {} towards the contact face: {room} of room",
            &top[4..top.len() - 1].trim_start_matches('-')
        );
        assert!(err.contains(&part), "{top} {chi}: {part}: {err}");
        assert!(!out.contains("certified"), "{out}");
    }
    for (top, chi) in [("[0, -0.05]", "-0.03"), ("[0, 0.05]", "-0.12"), ("[0, 0]", "-0.09")] {
        let (code, out, err) = solve(top, chi);
        assert_eq!(code, 0, "{top} {chi}: {out}{err}");
        assert!(out.contains("certified"), "{top} {chi}: {out}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

const BLOCK: &str = "dirichlet = DIRICHLET\nPOINT\n[material]\nmu = 1\nlambda = 1\n[parts]\ncontact = \"y < 1e-12\"\ndirichlet = DPART\n[contact]\nnormal = \"outward\"\nchi = 0\n";

#[test]
fn a_contact_node_with_one_prescribed_component_is_refused_by_name() {
    let dir = scratch("contact-data-half");
    // (name, dirichlet, point constraint, Dirichlet part, the node, what prescribes it)
    let cases = [
        (
            "point",
            "[\"0\", \"-0.1\"]",
            "[[point_constraints]]\nat = [0.5, 0]\nu = [0, \"free\"]",
            "\"y > 1 - 1e-12\"",
            "(0.5, 0)",
            "a point constraint",
        ),
        (
            "rollers",
            "[0, \"free\"]",
            "traction = [\"0\", \"-max(0, ny)\"]\n[[point_constraints]]\nat = [0, 1]\nu = [\"free\", -0.05]",
            "\"x < 1e-12\"",
            "(0, 0)",
            "the Dirichlet data",
        ),
    ];
    for (name, dirichlet, point, dpart, node, by) in cases {
        let text = BLOCK.replace("DIRICHLET", dirichlet).replace("POINT", point).replace("DPART", dpart);
        // `traction` must come before the first table
        let text = match text.find("traction") {
            Some(_) => {
                let line = text.lines().find(|l| l.starts_with("traction")).unwrap().to_string();
                format!("{line}\n{}", text.replace(&format!("{line}\n"), ""))
            }
            None => text,
        };
        std::fs::write(dir.join("v.toml"), text).unwrap();
        let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "structured:4"]);
        assert_eq!(code, 1, "{name}: {out}{err}");
        for part in [
            format!("the node at {node} on the closure of the contact part"),
            format!("u_1 prescribed by {by}"),
            "acts on the free u_2".into(),
        ] {
            assert!(err.contains(&part), "{name}: no {part:?} in {err}");
        }
    }
    // the same block with both components prescribed on the contact side's end: solved
    let text = BLOCK.replace("DIRICHLET", "[0, 0]").replace("POINT", "").replace("DPART", "\"x < 1e-12\"");
    std::fs::write(dir.join("v.toml"), format!("body_force = [\"0\", \"-1\"]\n{text}")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 0, "{err}");
}

/// Example 7.2's problem file with the first line starting with `key =` replaced by `line`.
fn ex72_with(dir: &std::path::Path, name: &str, key: &str, line: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex72.toml");
    let mut text: Vec<String> = std::fs::read_to_string(path).unwrap().lines().map(String::from).collect();
    let at = text.iter().position(|l| l.starts_with(&format!("{key} ="))).unwrap_or_else(|| panic!("{key}"));
    text[at] = line.to_string();
    let file = format!("{name}.toml");
    std::fs::write(dir.join(&file), text.join("\n") + "\n").unwrap();
    file
}

#[test]
fn contact_data_on_a_stretch_between_nodes_is_refused_on_every_mesh_before_level_0() {
    let dir = scratch("contact-data-bands");
    let band = "max(0, 1 - abs(y - 0.53)/0.004)";
    // (name, key, line, what the error says)
    let cases = [
        ("reversed", "normal", format!("normal = [\"1 - 3*{band}\", \"0\"]"), "reversed against"),
        ("tangent", "normal", format!("normal = [\"1 - 0.99*{band}\", \"{band}\"]"), "nearly tangent"),
        ("deep", "chi", format!("chi = \"-0.2 + 0.5*abs(y - 0.5) - 10*{band}\""), "more than the body's thickness"),
        ("nan", "chi", "chi = \"-0.2 + 0.5*abs(y - 0.5) + 0*sqrt(abs(y - 0.53) - 0.002)\"".to_string(), "`contact.chi` is NaN"),
    ];
    for (name, key, line, says) in &cases {
        let file = ex72_with(&dir, name, key, line);
        for mesh in ["structured:4", "structured:8", "structured:16", "symmetric:6"] {
            let (code, out, err) = signorini_in(&dir, &["solve", "--problem", &file, "--mesh", mesh]);
            assert_ne!(code, 0, "{name} on {mesh}: {out}");
            assert!(err.contains(says), "{name} on {mesh}: {err}");
            assert!(!out.contains("certified"), "{name} on {mesh}: {out}");
        }
        let (code, out, err) = signorini_in(&dir, &["adapt", "--problem", &file, "--mesh", "structured:4", "--levels", "6"]);
        assert_ne!(code, 0, "{name}: {out}");
        assert_eq!(level_rows(&out), 0, "{name}: refused before level 0: {out}");
        assert!(err.contains(says), "{name}: {err}");
    }
    // the same file without the band passes (the check refuses the band, not the problem)
    let file = ex72_with(&dir, "plain", "normal", "normal = [\"1 - 0*max(0, 1 - abs(y - 0.53)/0.004)\", \"0\"]");
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", &file, "--mesh", "structured:4"]);
    assert_eq!(code, 0, "{out}{err}");
}

/// `normal = "outward"` is each contact edge's own outward normal (its circle's, turned to the
/// body's outside), so around a hole it points to the centre and solves as the declared normal
/// toward the centre does, not refused as "reversed".
#[test]
fn outward_on_a_circle_around_a_hole_points_to_the_centre() {
    let dir = scratch("contact-data-hole");
    std::fs::write(dir.join("hole.msh"), fixture("hole.msh")).unwrap();
    let problem = "dirichlet = [0, 0]\n[material]\nmu = 1\nlambda = 1\n[parts]\ncontact = [\"arc\"]\ndirichlet = [\"outer\"]\nneumann = [\"sym\"]\n[curves]\narc = { circle = { centre = [0, 0], radius = 1 } }\n[contact]\nnormal = NORMAL\nchi = \"0.01\"\n";
    let mut outputs = Vec::new();
    for normal in ["\"outward\"", "[\"-(x - 0)\", \"-(y - 0)\"]"] {
        std::fs::write(dir.join("v.toml"), problem.replace("NORMAL", normal)).unwrap();
        let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "gmsh:hole.msh"]);
        assert_eq!(code, 0, "{normal}: {err}");
        outputs.push(out.lines().filter(|l| l.starts_with("estimator:") || l.starts_with("contact:")).collect::<Vec<_>>().join("\n"));
    }
    assert!(outputs[0].contains("estimator:"), "{}", outputs[0]);
    assert_eq!(outputs[0], outputs[1]);
}
