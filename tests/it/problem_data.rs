//! Problem data and meshes that cannot be solved are named errors before anything is solved:
//! the key, node or triangle and the point or value, each shown in a few characters; a refusal
//! found at a later level names the level.

use crate::common;
use crate::common::{fixture, one_run_manifest, run_edited, scratch, signorini_in, signorini_in_time, solve_gmsh_square};
use std::path::PathBuf;
use std::process::Command;

const SQUARE: &str = "bad_data_square.toml";

#[test]
fn a_subnormal_c0_is_shown_in_a_few_characters() {
    let (code, _, err) = run_edited("c0", SQUARE, &[("", "")], &["adapt", "--problem", "ex71", "--levels", "2", "--c0", "1e-320"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--c0: expected a positive number of at least 2.2250738585072014e-308"), "{err}");
    assert!(err.contains("got 1e-320") && err.len() < 300, "{err}");
    let text = fixture("tiny.toml").replace("[[run]]\nid = \"a\"", "[[run]]\nid = \"a\"\nestimator = { c0 = 1e-320 }");
    assert!(text.contains("1e-320"));
    let err = common::parse_err(&text);
    assert!(err.contains("key `run[0].estimator.c0`") && err.contains("got 1e-320") && err.len() < 300, "{err}");
    let err = common::parse_err(&fixture("tiny.toml").replace("theta = 0.5", "theta = -1e-320"));
    assert!(err.contains("got -1e-320") && err.len() < 300, "{err}");
}

/// Clear messages: a pair of the wrong length names its key, a
/// huge number in a manifest is printed short, `export --out FILE` says what is wrong before
/// solving, and `--adapt-min-ndof` that the loop does not reach is an error, not a silent mesh.
#[test]
fn lengths_huge_numbers_export_files_and_unreached_minimums_are_named() {
    let ex71 = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex71.toml")).unwrap();
    let dir = scratch("problem-data-named");
    let cases = [
        ("body_force", ex71.replacen("body_force = [", "body_force = [\"0\", ", 1)),
        ("exact.u", ex71.replace(r#"u = ["y^2*(y - 1)", "#, "u = [")),
        ("contact.normal", ex71.replace(r#"normal = "outward""#, "normal = [0, -1, 0]")),
    ];
    for (key, text) in cases {
        std::fs::write(dir.join("v.toml"), text).unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
            .current_dir(&dir)
            .args(["solve", "--problem", "v.toml", "--mesh", "structured:4"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{key}: {err}");
        assert!(err.contains("v.toml:") && err.contains(&format!("key `{key}`")), "{key}: {err}");
    }
    let err = common::parse_err(&fixture("tiny.toml").replacen("levels = 5", "levels = 1e300", 1));
    assert!(err.contains("`1e300`") && err.contains("expected a non-negative integer") && err.len() < 600, "{err}");
    std::fs::write(dir.join("taken"), "a file").unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["export", "--problem", "ex71", "--mesh", "structured:4", "--out", "taken"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("--out taken: this is a file; export writes a folder there"), "{err}");
    // figures and report say it the same way (not "File exists (os error 17)")
    let repo = env!("CARGO_MANIFEST_DIR");
    let (experiments, results) = (format!("{repo}/experiments"), format!("{repo}/results"));
    for (args, says) in [
        (vec!["figures", "--results", &results, "--experiments", &experiments, "--figures", "taken"], "--figures taken: this is a file"),
        (vec!["report", "--results", &results, "--experiments", &experiments, "--out", "taken"], "--out taken: this is a file"),
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_signorini")).current_dir(&dir).args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(says) && err.contains("give a folder's path"), "{args:?}: {err}");
    }
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["solve", "--problem", "ex71", "--mesh", "structured:4", "--adapt-levels", "2", "--adapt-min-ndof", "100000"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("the adaptive loop ended at level 2 with") && err.contains("short of --adapt-min-ndof 100000"), "{err}");
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
    let dir = scratch("problem-data-level");
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

/// `signorini solve` on the square problem with `from` replaced by `to`; (exit code, stderr).
fn solve_variant(name: &str, base: &str, from: &str, to: &str, mesh: &str) -> (i32, String) {
    let dir = scratch(&format!("problem-data-{name}"));
    let text = fixture(base);
    assert!(text.contains(from), "{from} not in {base}");
    std::fs::write(dir.join("v.toml"), text.replace(from, to)).unwrap();
    std::fs::write(dir.join("sq.msh"), fixture("square.msh")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["solve", "--problem", "v.toml", "--mesh", mesh])
        .output()
        .unwrap();
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// The error names the key, a point and the value.
fn names_datum(err: &str, key: &str, value: &str) {
    assert!(err.contains(&format!("problem v: `{key}` is {value} at (")), "{err}");
}

#[test]
fn data_that_is_not_a_number_where_it_is_used_is_named_with_its_point() {
    let base = "bad_data_square.toml";
    for (from, to, key, value) in [
        (r#"body_force = ["0", "-1"]"#, r#"body_force = ["sqrt(x - 2)", "-1"]"#, "body_force[0]", "NaN"),
        (r#"dirichlet = ["0", "-0.01"]"#, r#"dirichlet = ["0.1 / x", "-0.01"]"#, "dirichlet[0]", "inf"),
        (r#"traction = ["0", "0"]"#, r#"traction = ["ln(0)", "0"]"#, "traction[0]", "-inf"),
        (r#"chi = "0.001""#, r#"chi = "sqrt(0 - 1)""#, "contact.chi", "NaN"),
        (r#"chi = "0.001""#, r#"chi = "ln(x)""#, "contact.chi", "-inf"),
        (r#"normal = "outward""#, r#"normal = ["x - 0.5", "0"]"#, "contact.normal (its length)", "0"),
    ] {
        let (code, err) = solve_variant(key, base, from, to, "structured:4");
        assert_eq!(code, 1, "{to}: {err}");
        names_datum(&err, key, value);
    }
}

#[test]
fn a_contact_part_that_matches_no_edge_is_named() {
    let text = fixture("bad_data_square.toml").replace(r#"normal = "outward""#, "normal = [0, -1]");
    let dir = scratch("problem-data-nocontact");
    std::fs::write(dir.join("v.toml"), text.replace(r#"contact = "y < 1e-12""#, r#"contact = "y < -1""#)).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["solve", "--problem", "v.toml", "--mesh", "structured:4"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("contact part matches no boundary edge") && err.contains(r#"parts.contact = "y < -1""#), "{err}");
}

const SOLVE: &[&str] = &["solve", "--problem", "v.toml", "--mesh", "structured:4"];

const ADAPT: &[&str] = &["adapt", "--problem", "v.toml", "--mesh", "structured:4", "--levels", "2"];

#[test]
fn a_traction_where_no_edge_is_neumann_is_refused_naming_traction() {
    // the top and both sides Dirichlet, the bottom contact: no Neumann edge is left
    let all_held = (r#"dirichlet = "y > 1 - 1e-12""#, r#"dirichlet = "y > 1e-12""#);
    let held_still = (r#"dirichlet = ["0", "-0.01"]"#, r#"dirichlet = ["0", "0"]"#);
    for (name, args) in [("tr-solve", SOLVE), ("tr-adapt", ADAPT)] {
        let (code, _, err) =
            run_edited(name, SQUARE, &[all_held, held_still, (r#"traction = ["0", "0"]"#, r#"traction = ["5", "x"]"#)], args);
        assert_eq!(code, 1, "{name}: {err}");
        for says in [
            "problem file v.toml: the traction (`traction`) is (5, ",
            "no boundary edge of the mesh is in the Neumann part",
            r#"parts.dirichlet = "y > 1e-12""#,
            "would be ignored",
        ] {
            assert!(err.contains(says), "{name}: no {says:?} in\n{err}");
        }
    }
    // the zero traction (written or by default) passes there, and a traction with Neumann edges
    let (code, out, err) = run_edited("tr-zero", SQUARE, &[all_held, held_still], SOLVE);
    assert!(code == 0 && out.contains("certified:"), "{err}");
    let (code, out, err) = run_edited("tr-neumann", SQUARE, &[(r#"traction = ["0", "0"]"#, r#"traction = ["0.01", "0"]"#)], SOLVE);
    assert!(code == 0 && out.contains("certified:"), "{err}");
}

const SQUARE_NODES: &str = "0 0 0\n1 0 0\n1 1 0\n0 1 0";

#[test]
fn a_mesh_scaled_past_what_f64_squares_is_named_as_a_scale_not_a_zero_area() {
    for (scale, says) in [
        ("1e200", "has an area that is not a finite number at coordinates of size 1e200"),
        ("1e-200", "has an area that underflows to 0 at coordinates of size 1e-200"),
    ] {
        let nodes = format!("0 0 0\n{scale} 0 0\n{scale} {scale} 0\n0 {scale} 0");
        let (code, out) = solve_gmsh_square(scale, &[], &[(SQUARE_NODES, &nodes)]);
        assert_eq!(code, 1, "{out}");
        assert!(out.contains("sq.msh, line 37: triangle 5 ") && out.contains(says) && out.contains("rescale the mesh"), "{out}");
    }
    // a triangle that is flat is still that (node 3 on the line through 1 and 2)
    let (code, out) = solve_gmsh_square("flat", &[], &[(SQUARE_NODES, "0 0 0\n1 0 0\n2 0 0\n0 1 0")]);
    assert!(code == 1 && out.contains("triangle 5 has zero area"), "{out}");
    // CAD round-off in z is read as the plane; a z of the mesh's size is not
    let (code, out) = solve_gmsh_square("z-roundoff", &[], &[(SQUARE_NODES, "0 0 0\n1 0 1e-17\n1 1 0\n0 1 -1e-15")]);
    assert!(code == 0 && out.contains("certified:"), "{out}");
    let (code, out) = solve_gmsh_square("z-off", &[], &[(SQUARE_NODES, "0 0 0\n1 0 1e-9\n1 1 0\n0 1 0")]);
    assert!(code == 1 && out.contains("node 2 has z = 1e-9: a planar mesh in z = 0 is expected"), "{out}");
}

#[test]
fn messages_name_the_groups_the_empty_part_and_the_duplicate_key() {
    // curve 1 (the bottom) in the groups "bottom" and "sides"
    let (code, out) = solve_gmsh_square("two-groups", &[], &[("1 0 0 0 1 0 0 1 1 0", "1 0 0 0 1 0 0 2 1 2 0")]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains(r#"curve 1 is in 2 physical groups ("bottom" (tag 1), "sides" (tag 2))"#), "{out}");
    let (code, out) = solve_gmsh_square("empty-contact", &[(r#"contact = ["bottom"]"#, "contact = []")], &[]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("v.toml:11:11: key `parts.contact`: at least one physical group: parts.contact is empty"), "{out}");
    for (name, edit, says) in [
        (
            "dup-top",
            ("traction = [\"0\", \"0\"]", "traction = [\"0\", \"0\"]\ntraction = [\"1\", \"0\"]"),
            "v.toml:4:1: key `traction`: duplicate key",
        ),
        ("dup-table", ("lambda = 1", "lambda = 1\nmu = 2"), "v.toml:9:1: key `material.mu`: duplicate key"),
    ] {
        let (code, out) = solve_gmsh_square(name, &[edit], &[]);
        assert!(code == 1 && out.contains(says), "{name}: {out}");
    }
}

/// Points in messages go through `base::number::point`: a huge coordinate is `1e308`, not its
/// 309 digits (the probe and contact-zone lines of a solve report are left to `records/`).
#[test]
fn a_huge_point_in_a_message_is_shown_in_a_few_characters() {
    let edit = (r#"traction = ["0", "0"]"#, "traction = [\"0\", \"0\"]\nrequired_vertices = [[1e308, 0.5]]");
    let (code, _, err) = run_edited("huge-point", SQUARE, &[edit], SOLVE);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("key `required_vertices[0]`: (1e308, 0.5) is not a vertex of the mesh"), "{err}");
    assert!(!err.contains("0000000000"), "{err}");
}

/// A probe: a point far outside the domain is named in a few characters.
#[test]
fn a_probe_far_outside_is_shown_in_a_few_characters() {
    let args = [SOLVE, &["--probe", "1e308,0.5"]].concat();
    let (code, _, err) = run_edited("probe-far", SQUARE, &[], &args);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--probe 1e308,0.5: the point is outside the mesh"), "{err}");
    assert!(!err.contains("0000000000"), "{err}");
}

/// A part that ends inside a boundary edge of a built-in mesh is not decided at the edge's
/// midpoint (contact for x < 0.6 read as x < 0.5 on structured:4): refused,
/// naming the edge and the point where the part changes; where the grid meets the end (structured:5,
/// structured:10) it solves.
#[test]
fn a_part_ending_inside_an_edge_is_refused_where_the_grid_misses_it() {
    let edit = (r#"contact = "y < 1e-12""#, r#"contact = "y < 1e-12 && x < 0.6""#);
    for n in ["4", "8"] {
        let args = ["solve", "--problem", "v.toml", "--mesh", &format!("structured:{n}")];
        let (code, _, err) = run_edited(&format!("part-in-edge-{n}"), SQUARE, &[edit], &args);
        assert_eq!(code, 1, "{n}: {err}");
        assert!(err.contains(&format!("the boundary parts change inside an edge of structured:{n}: the edge from (0.5, 0) to")), "{err}");
        assert!(err.contains("a part must end at a vertex of the mesh"), "{err}");
    }
    for n in ["5", "10"] {
        let args = ["solve", "--problem", "v.toml", "--mesh", &format!("structured:{n}")];
        let (code, _, err) = run_edited(&format!("part-at-vertex-{n}"), SQUARE, &[edit], &args);
        assert_eq!(code, 0, "{n}: {err}");
    }
}

/// A body force of 1e308: its products with the displacements it causes overflow before any
/// estimator term is computed, and the solve's one check of its result names that, with the units as the remedy, never a C_0. (An estimator term that overflows
/// on its own is named by loop_settings::an_estimate_that_overflows_is_refused_by_both_paths_at_level_0.)
#[test]
fn an_overflowing_estimator_term_is_named_not_c0() {
    let dir = scratch("problem-data-overflow");
    let text = fixture("bad_data_square.toml").replace(r#"body_force = ["0", "-1"]"#, r#"body_force = ["0", "-1e308"]"#);
    std::fs::write(dir.join("p.toml"), text).unwrap();
    let (code, _, err) = signorini_in_time(&dir, &["solve", "--problem", "p.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("is not a finite number") && err.contains("give the data in other units"), "{err}");
    assert!(!err.contains("C_0") && !err.contains("violated"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn points_and_lines_the_mesh_does_not_hold_name_the_file_and_key() {
    let dir = scratch("problem-data-points");
    let base = fixture("bad_data_square.toml");
    for (case, add, says, outside) in [
        ("vertex", "required_vertices = [[3, 3]]\n", "key `required_vertices[0]`: (3, 3) is not a vertex of the mesh", true),
        ("inside", "required_vertices = [[0.5, 0.3]]\n", "key `required_vertices[0]`: (0.5, 0.3) is not a vertex of the mesh", false),
        ("break", "load_breaks = [\"5\"]\n", "key `load_breaks[0]`: the line x = 5 does not cross the mesh", false),
    ] {
        std::fs::write(dir.join("p.toml"), base.replace("[material]", &format!("{add}\n[material]"))).unwrap();
        for cmd in ["solve", "adapt"] {
            let (code, _, err) = signorini_in_time(&dir, &[cmd, "--problem", "p.toml", "--mesh", "structured:4"]);
            assert_eq!(code, 1, "{case}: {err}");
            assert!(err.contains(&format!("p.toml: {says}")) && !err.contains("kink"), "{case}: {err}");
            assert_eq!(err.contains("it lies outside the mesh, which spans x in [0, 1], y in [0, 1]"), outside, "{case}: {err}");
        }
    }
    let point = "\n[[point_constraints]]\nat = [2, 2]\nu = [\"free\", 0]\n";
    std::fs::write(dir.join("p.toml"), format!("{base}{point}")).unwrap();
    let (code, _, err) = signorini_in_time(&dir, &["solve", "--problem", "p.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("p.toml: key `point_constraints[0].at`: (2, 2) is not a vertex") && !err.contains("kink"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn hints_name_the_option_that_helps() {
    let dir = scratch("problem-data-hints");
    // no ./experiments
    let (code, _, err) = signorini_in_time(&dir, &["figures", "--results", "r", "--study", "s"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("pass --experiments DIR"), "{err}");
    // a drift report that cannot be written where --against puts it
    std::fs::create_dir(dir.join("experiments")).unwrap();
    let file = one_run_manifest(&dir.join("experiments"), "s", "a", "");
    assert_eq!(signorini_in_time(&dir, &["run", &format!("experiments/{file}"), "--results", "r"]).0, 0);
    assert_eq!(signorini_in_time(&dir, &["run", &format!("experiments/{file}"), "--results", "o"]).0, 0);
    std::fs::create_dir(dir.join("o/drift-report.json")).unwrap();
    let (code, out, err) = signorini_in_time(&dir, &["drift", "--study", "s", "--against", "o", "--results", "r"]);
    assert_eq!(code, 1, "{out}{err}");
    // refused before anything is rerun (every output target is checked first)
    assert!(err.contains("the drift report (--report FILE writes it elsewhere) o/drift-report.json: not a regular file"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn long_input_lines_are_quoted_as_excerpts() {
    let dir = scratch("problem-data-excerpt");
    let line = "x".repeat(1 << 20);
    std::fs::write(dir.join("s.toml"), format!("description = \"{line}\n")).unwrap();
    std::fs::write(dir.join("t.toml"), format!("description = \"t\"\n[[run]]\nid = \"a\"\nproblem = \"ex71\"\nmesh = \"{line}\"\n"))
        .unwrap();
    let problem = fixture("bad_data_square.toml").replace(r#"chi = "0.001""#, &format!("chi = \"0.001 + {line}\""));
    std::fs::write(dir.join("p.toml"), problem).unwrap();
    for args in [vec!["run", "s.toml"], vec!["run", "t.toml"], vec!["solve", "--problem", "p.toml", "--mesh", "structured:2"]] {
        let (code, _, err) = signorini_in_time(&dir, &args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(err.len() < 4000 && err.contains("characters cut) ... "), "{args:?}: {} bytes: {}", err.len(), &err[..err.len().min(500)]);
    }
    std::fs::remove_dir_all(&dir).ok();
}
