//! What the sixth battery of hostile inputs (issue 38) left that was not silent: a refusal of a
//! valid mesh, messages that blamed the wrong thing or gave no way out. Each is fixed in the one
//! function its path goes through:
//!
//! * a valid mesh far from the origin was refused as "a rotation is free": `check_held` judged
//!   "one line" by the largest coordinate, now by the body's size plus coordinate round-off;
//! * an overflow of the stiffness entries (E = 1e307) read as "not positive definite": the
//!   assembled system is checked for finite entries (`solve`'s `check_finite`);
//! * a tab or a line break in an expression gave exmex's "don't know how to parse"; a
//!   parenthesised comparison "parentheses mismatch";
//! * `normal = "outward"` on a circle around a hole was refused without saying why or what to
//!   write (then a note; since battery 10 "outward" is the body's outward normal there, toward
//!   the centre, and solves);
//! * a predicate problem on a Gmsh mesh blamed every group; a problem file beside the manifests
//!   was only an unknown manifest key;
//! * a parametric Gmsh file gave mshio's words only (wrong `$Nodes` header counts, and the same
//!   input under another name: `bad_data` and `bad_store`).

use crate::common::{fixture, signorini_in};

fn tmp(name: &str) -> std::path::PathBuf {
    crate::common::scratch(&format!("leftovers6-{name}"))
}

/// The `estimator:` line of a solve's output.
fn estimator_line(out: &str) -> String {
    out.lines().find(|l| l.starts_with("estimator:")).unwrap_or_default().to_string()
}

#[test]
fn a_mesh_far_from_the_origin_solves_as_the_same_mesh_at_the_origin() {
    let dir = tmp("far");
    std::fs::write(dir.join("v.toml"), fixture("bad_data_gmsh.toml")).unwrap();
    let msh = fixture("square.msh");
    let corners = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n$EndNodes";
    assert!(msh.contains(corners));
    let mut lines = Vec::new();
    for shift in [0.0, 1e6, 1e9] {
        let moved: String = corners
            .lines()
            .map(|l| match l.split(' ').collect::<Vec<_>>()[..] {
                [x, y, z] => format!("{} {y} {z}\n", x.parse::<f64>().unwrap() + shift),
                _ => l.to_string(),
            })
            .collect();
        std::fs::write(dir.join("m.msh"), msh.replace(corners, &moved)).unwrap();
        let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "gmsh:m.msh"]);
        assert_eq!(code, 0, "shift {shift}: {err}");
        assert!(!err.contains("rotation"), "{err}");
        lines.push(estimator_line(&out));
    }
    // the same estimate to the digits shown
    assert!(!lines[0].is_empty() && lines.iter().all(|l| *l == lines[0]), "{lines:#?}");
}

#[test]
fn an_overflow_of_the_stiffness_is_named_as_such() {
    let dir = tmp("overflow");
    let text = fixture("bad_data_square.toml").replace("mu = 1\nlambda = 1", "E = 1e307\nnu = 0.3\nmodel = \"plane_strain\"");
    std::fs::write(dir.join("v.toml"), text).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("the assembled stiffness matrix has an entry that is not a finite number (overflow"), "{err}");
    assert!(!err.contains("not positive definite"), "{err}");
}

#[test]
fn whitespace_in_an_expression_separates_and_a_parenthesised_comparison_is_named() {
    let dir = tmp("spaces");
    let base = fixture("bad_data_square.toml");
    let solve = |text: String| {
        std::fs::write(dir.join("v.toml"), text).unwrap();
        signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "structured:4"])
    };
    let (_, plain, _) = solve(base.clone());
    for chi in ["chi = \"0.001\t+ 0*x\"", "chi = \"\"\"0.001\n  + 0*x\"\"\"", "chi = \"0.001 +\\n0*x\"", "chi = \"0.001\\t+ 0*x\""] {
        let (code, out, err) = solve(base.replace("chi = \"0.001\"", chi));
        assert_eq!(code, 0, "{chi:?}: {err}");
        assert_eq!(estimator_line(&out), estimator_line(&plain), "{chi:?}");
    }
    let (code, _, err) = solve(base.replace("contact = \"y < 1e-12\"", "contact = \"(y < 1e-12)\""));
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("key `parts.contact`") && err.contains("the parentheses of \"(y < 1e-12)\" enclose a comparison"), "{err}");
}

/// Battery 10 changed what this test holds: `normal = "outward"` is each contact edge's own
/// outward normal (its circle's, turned to the body's outside), so around a hole it points to the
/// centre and solves as the declared normal toward the centre does (it was refused as "reversed",
/// with a note saying what to write instead).
#[test]
fn outward_on_a_circle_around_a_hole_points_to_the_centre() {
    let dir = tmp("hole");
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

#[test]
fn a_predicate_problem_on_a_gmsh_mesh_says_predicates_tag_the_built_in_meshes() {
    let dir = tmp("predicate-gmsh");
    std::fs::write(dir.join("sq.msh"), fixture("square.msh")).unwrap();
    std::fs::write(dir.join("v.toml"), fixture("bad_data_square.toml")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "gmsh:sq.msh"]);
    assert_eq!(code, 1, "{err}");
    for part in ["declares its boundary parts by predicates on x and y (parts.contact = \"y < 1e-12\"", "which tag the built-in meshes"] {
        assert!(err.contains(part), "{part}: {err}");
    }
    assert!(!err.contains("not named by"), "{err}");
}

#[test]
fn a_problem_file_beside_the_manifests_is_called_one() {
    let dir = tmp("beside");
    let study =
        "description = \"one short run\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\nlevels = 2\n[[run]]\nid = \"a\"\n";
    std::fs::write(dir.join("study.toml"), study).unwrap();
    std::fs::write(dir.join("square.toml"), fixture("bad_data_square.toml")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["drift", "--experiments", ".", "--results", "none"]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("square.toml looks like a problem file") && err.contains("keep problem files in a subfolder"), "{err}");
}

#[test]
fn a_parametric_gmsh_file_is_refused_with_the_option_that_writes_a_plain_one() {
    let dir = tmp("parametric");
    std::fs::write(dir.join("v.toml"), fixture("bad_data_gmsh.toml")).unwrap();
    let msh = fixture("square.msh");
    assert!(msh.contains("$Nodes\n1 4 1 4\n2 1 0 4\n"));
    std::fs::write(dir.join("m.msh"), msh.replace("$Nodes\n1 4 1 4\n2 1 0 4\n", "$Nodes\n1 4 1 4\n2 1 1 4\n")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "gmsh:m.msh"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("m.msh") && err.contains("Mesh.SaveParametric = 0"), "{err}");
}
