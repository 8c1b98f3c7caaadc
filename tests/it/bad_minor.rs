//! The minor findings of the fifth battery of hostile inputs (issue 38), each refused or named by
//! the one function its path goes through:
//!
//! * `log(x)` was silently ln, and exmex's undocumented functions (`cbrt`, `round`, ...) were
//!   accepted; an unknown function (`ab(y)`) or a literal such as `0x10` gave exmex's internals:
//!   one allow-list of names (`problems::file::names`), which the check, its message and the
//!   documentation share;
//! * a non-zero traction on a mesh without a Neumann edge was ignored (`solve`'s
//!   `unused_traction`);
//! * plane stress accepted 0.5 <= nu < 1 (`bad_physics` holds that test: one Poisson-ratio check
//!   for both models).

use std::collections::BTreeSet;
use std::path::PathBuf;
use std::process::Command;

fn fixture(rel: &str) -> String {
    std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(rel)).unwrap()
}

/// `signorini ARGS` in a folder holding `v.toml` (fixture `base` with each `from` replaced by
/// its `to`): (exit code, stdout, stderr), never a panic or a signal.
fn run(name: &str, base: &str, edits: &[(&str, &str)], args: &[&str]) -> (i32, String, String) {
    let dir = std::env::temp_dir().join(format!("signorini-bad-minor-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    let mut text = fixture(base);
    for (from, to) in edits {
        assert!(text.contains(from), "{from} not in {base}");
        text = text.replace(from, to);
    }
    std::fs::write(dir.join("v.toml"), text).unwrap();
    let answer = crate::common::signorini_in(&dir, args);
    std::fs::remove_dir_all(&dir).ok();
    answer
}

const SQUARE: &str = "bad_data_square.toml";
const SOLVE: &[&str] = &["solve", "--problem", "v.toml", "--mesh", "structured:4"];
const ADAPT: &[&str] = &["adapt", "--problem", "v.toml", "--mesh", "structured:4", "--levels", "2"];
const CHI: &str = r#"chi = "0.001""#;

#[test]
fn bad_log_is_refused_as_ambiguous_and_unlisted_names_are_named_with_the_list() {
    for (name, chi, says) in [
        ("log", "0.001*log(10)", "`log` at character 7 of \"0.001*log(10)\" is ambiguous"),
        ("log-space", "0.001*log (10)", "write ln or log10"),
        ("cbrt", "0.001*cbrt(8)", "`cbrt` at character 7 of \"0.001*cbrt(8)\" is not one of the functions"),
        ("round", "0.001*round(x)", "`round` at character 7"),
        ("ab", "0.001 + 0.5*ab(y - 0.5)", "unknown function `ab` at character 13"),
        ("cot", "0.001*cot(1)", "unknown function `cot`"),
        ("hex", "0x10", "`0x10` at character 1 of \"0x10\": a number run into a name"),
        ("pi", "0.001*π", "`π` at character 7"),
    ] {
        let (code, _, err) = run(name, SQUARE, &[(CHI, &format!("chi = {chi:?}"))], SOLVE);
        assert_eq!(code, 1, "{name}: {err}");
        for part in ["v.toml:16:7: key `contact.chi`: ", says] {
            assert!(err.contains(part), "{name}: no {part:?} in\n{err}");
        }
        if name != "hex" && !name.starts_with("log") {
            assert!(err.contains("(functions: sqrt, exp, ln, log10,") && err.contains("constants: PI, E, e, TAU)"), "{name}: {err}");
        }
        assert!(!err.contains("wlog") && !err.contains("ops and"), "{name}: exmex's internals in\n{err}");
    }
    // in a constant and in a predicate too: every expression goes through the one check
    let (code, _, err) = run("log-const", SQUARE, &[(CHI, "chi = \"a\"\n[constants]\na = \"0.001*log(2)\"")], SOLVE);
    assert!(code == 1 && err.contains("key `constants.a`") && err.contains("`log`"), "{err}");
    let (code, _, err) = run("log-pred", SQUARE, &[(r#"contact = "y < 1e-12""#, r#"contact = "y < log(1.00001)""#)], SOLVE);
    assert!(code == 1 && err.contains("key `parts.contact`") && err.contains("`log`"), "{err}");
}

#[test]
fn every_listed_function_is_accepted_and_the_docs_list_exactly_them() {
    use signorini::problems::file::{EXPRESSION_CONSTANTS, EXPRESSION_FUNCTIONS};
    let text = fixture(SQUARE);
    for f in EXPRESSION_FUNCTIONS {
        let call = if ["min", "max", "atan2"].contains(&f) { format!("{f}(0.5, 1)") } else { format!("{f}(0.5)") };
        let chi = format!("chi = \"0.001 + 1e-9*{call}\"");
        let p = signorini::problems::FileProblem::parse(std::path::Path::new("f.toml"), &text.replace(CHI, &chi));
        assert!(p.is_ok(), "{f}: {:?}", p.err().map(|e| e.to_string()));
    }
    // experiments/problems/README.md, paragraph **Expressions**: the unary functions in one
    // code span, then the binary ones and the constants
    let readme = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/README.md")).unwrap();
    let para = &readme[readme.find("**Expressions**").expect("the Expressions paragraph")..];
    let para = &para[..para.find("\n\n").unwrap()];
    let spans: Vec<&str> = para.split('`').skip(1).step_by(2).collect();
    let unary = spans.iter().find(|s| s.starts_with("sqrt ")).expect("the list of functions");
    let mut documented: BTreeSet<&str> = unary.split_whitespace().collect();
    documented.extend(
        spans
            .iter()
            .filter_map(|s| s.strip_suffix(')').and_then(|s| s.split_once('(')).map(|(f, _)| f))
            .filter(|f| f.starts_with(|c: char| c.is_ascii_alphabetic()) && f.chars().all(|c| c.is_ascii_alphanumeric())),
    );
    let listed: BTreeSet<&str> = EXPRESSION_FUNCTIONS.into_iter().collect();
    assert_eq!(documented, listed, "experiments/problems/README.md against crates/numerics/src/problems/file/names.rs");
    for c in EXPRESSION_CONSTANTS {
        assert!(spans.contains(&c), "constant {c} not documented");
    }
}

#[test]
fn bad_traction_where_no_edge_is_neumann_is_refused_naming_traction() {
    // the top and both sides Dirichlet, the bottom contact: no Neumann edge is left
    let all_held = (r#"dirichlet = "y > 1 - 1e-12""#, r#"dirichlet = "y > 1e-12""#);
    let held_still = (r#"dirichlet = ["0", "-0.01"]"#, r#"dirichlet = ["0", "0"]"#);
    for (name, args) in [("tr-solve", SOLVE), ("tr-adapt", ADAPT)] {
        let (code, _, err) = run(name, SQUARE, &[all_held, held_still, (r#"traction = ["0", "0"]"#, r#"traction = ["5", "x"]"#)], args);
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
    let (code, out, err) = run("tr-zero", SQUARE, &[all_held, held_still], SOLVE);
    assert!(code == 0 && out.contains("certified:"), "{err}");
    let (code, out, err) = run("tr-neumann", SQUARE, &[(r#"traction = ["0", "0"]"#, r#"traction = ["0.01", "0"]"#)], SOLVE);
    assert!(code == 0 && out.contains("certified:"), "{err}");
}

/// `signorini ARGS` in `dir`: (exit code, stdout and stderr), never a panic.
fn signorini_in(dir: &std::path::Path, args: &[&str]) -> (i32, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_signorini")).current_dir(dir).env("SIGNORINI_PROGRESS", "off").args(args).output().unwrap();
    let all = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(!all.contains("panicked"), "{all}");
    (o.status.code().unwrap_or(-1), all)
}

#[test]
fn bad_drift_against_a_folder_from_where_there_is_no_stored_results_folder_is_named() {
    let dir = std::env::temp_dir().join(format!("signorini-bad-minor-noresults-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::create_dir_all(dir.join("empty")).unwrap();
    let text =
        "description = \"t\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\nlevels = 2\nquick_levels = 1\n[[run]]\nid = \"a\"\n";
    std::fs::write(dir.join("exp/s.toml"), text).unwrap();
    let (code, out) = signorini_in(&dir, &["run", "exp/s.toml", "--results", "s7"]);
    assert_eq!(code, 0, "{out}");
    // from a folder without ./results: an error naming it, not a drift with advice to rerun
    let empty = dir.join("empty");
    let (code, out) = signorini_in(&empty, &["drift", "--against", "../s7", "--experiments", "../exp"]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains("no stored results folder `results` (relative to the current folder): it does not exist; pass --results DIR"),
        "{out}"
    );
    assert!(!out.contains("field(s)") && !out.contains("rerun the study"), "{out}");
    // a file where the folder should be, and without --against (nothing is rerun first)
    std::fs::write(empty.join("results"), "").unwrap();
    let (code, out) = signorini_in(&empty, &["drift", "--quick", "--experiments", "../exp"]);
    assert!(code == 1 && out.contains("no stored results folder `results`") && out.contains("is not a folder"), "{out}");
    assert!(!empty.join("target").exists(), "drift reran a study before refusing");
    // named with --results, the same comparison is no drift
    let (code, out) = signorini_in(&empty, &["drift", "--against", "../s7", "--experiments", "../exp", "--results", "../s7"]);
    assert_eq!(code, 0, "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `signorini solve` of the Gmsh square's problem (fixture `bad_data_gmsh.toml` with `edits`)
/// on `tests/fixtures/square.msh` with `mesh_edits`: (exit code, stdout and stderr).
fn solve_square(name: &str, edits: &[(&str, &str)], mesh_edits: &[(&str, &str)]) -> (i32, String) {
    let dir = std::env::temp_dir().join(format!("signorini-bad-minor-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    for (file, fixture_name, edits) in [("v.toml", "bad_data_gmsh.toml", edits), ("sq.msh", "square.msh", mesh_edits)] {
        let mut text = fixture(fixture_name);
        for (from, to) in edits {
            assert!(text.contains(from), "{from} not in {fixture_name}");
            text = text.replacen(from, to, 1);
        }
        std::fs::write(dir.join(file), text).unwrap();
    }
    let out = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "gmsh:sq.msh"]);
    std::fs::remove_dir_all(&dir).ok();
    out
}

const SQUARE_NODES: &str = "0 0 0\n1 0 0\n1 1 0\n0 1 0";

#[test]
fn bad_mesh_scaled_past_what_f64_squares_is_named_as_a_scale_not_a_zero_area() {
    for (scale, says) in [
        ("1e200", "has an area that is not a finite number at coordinates of size 1e200"),
        ("1e-200", "has an area that underflows to 0 at coordinates of size 1e-200"),
    ] {
        let nodes = format!("0 0 0\n{scale} 0 0\n{scale} {scale} 0\n0 {scale} 0");
        let (code, out) = solve_square(scale, &[], &[(SQUARE_NODES, &nodes)]);
        assert_eq!(code, 1, "{out}");
        assert!(out.contains("sq.msh, line 37: triangle 5 ") && out.contains(says) && out.contains("rescale the mesh"), "{out}");
    }
    // a triangle that is flat is still that (node 3 on the line through 1 and 2)
    let (code, out) = solve_square("flat", &[], &[(SQUARE_NODES, "0 0 0\n1 0 0\n2 0 0\n0 1 0")]);
    assert!(code == 1 && out.contains("triangle 5 has zero area"), "{out}");
    // CAD round-off in z is read as the plane; a z of the mesh's size is not
    let (code, out) = solve_square("z-roundoff", &[], &[(SQUARE_NODES, "0 0 0\n1 0 1e-17\n1 1 0\n0 1 -1e-15")]);
    assert!(code == 0 && out.contains("certified:"), "{out}");
    let (code, out) = solve_square("z-off", &[], &[(SQUARE_NODES, "0 0 0\n1 0 1e-9\n1 1 0\n0 1 0")]);
    assert!(code == 1 && out.contains("node 2 has z = 1e-9: a planar mesh in z = 0 is expected"), "{out}");
}

#[test]
fn bad_smaller_gaps_name_the_groups_the_empty_part_and_the_duplicate_key() {
    // curve 1 (the bottom) in the groups "bottom" and "sides"
    let (code, out) = solve_square("two-groups", &[], &[("1 0 0 0 1 0 0 1 1 0", "1 0 0 0 1 0 0 2 1 2 0")]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains(r#"curve 1 is in 2 physical groups ("bottom" (tag 1), "sides" (tag 2))"#), "{out}");
    let (code, out) = solve_square("empty-contact", &[(r#"contact = ["bottom"]"#, "contact = []")], &[]);
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
        let (code, out) = solve_square(name, &[edit], &[]);
        assert!(code == 1 && out.contains(says), "{name}: {out}");
    }
}

/// Points in messages go through `base::number::point`: a huge coordinate is `1e308`, not its
/// 309 digits (the probe and contact-zone lines of a solve report are left to `records/`).
#[test]
fn bad_huge_point_in_a_message_is_shown_in_a_few_characters() {
    let edit = (r#"traction = ["0", "0"]"#, "traction = [\"0\", \"0\"]\nrequired_vertices = [[1e308, 0.5]]");
    let (code, _, err) = run("huge-point", SQUARE, &[edit], SOLVE);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("key `required_vertices[0]`: (1e308, 0.5) is not a vertex of the mesh"), "{err}");
    assert!(!err.contains("0000000000"), "{err}");
}

/// Finding 12's probe: a point far outside the domain is named in a few characters.
#[test]
fn bad_probe_far_outside_is_shown_in_a_few_characters() {
    let args = [SOLVE, &["--probe", "1e308,0.5"]].concat();
    let (code, _, err) = run("probe-far", SQUARE, &[], &args);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--probe 1e308,0.5: the point is outside the mesh"), "{err}");
    assert!(!err.contains("0000000000"), "{err}");
}

/// Battery 6, finding 4: a physical group named as the tag of another, unnamed group ("1" beside
/// the unnamed group 1) read as one boundary part, so a problem naming "1" held both sides:
/// refused when the mesh is read, naming both groups.
#[test]
fn bad_group_named_as_another_groups_tag_is_refused() {
    let (code, out) = solve_square("name-is-a-tag", &[], &[("3\n1 1 \"bottom\"\n1 2 \"sides\"", "2\n1 2 \"1\"")]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("the physical group 2 is named \"1\", the tag of the unnamed group 1"), "{out}");
}

/// Battery 6, finding 2: a part that ends inside a boundary edge of a built-in mesh was decided at
/// the edge's midpoint (contact for x < 0.6 read as x < 0.5 on structured:4, certified): refused,
/// naming the edge and the point where the part changes; where the grid meets the end (structured:5,
/// structured:10) it solves.
#[test]
fn bad_part_ending_inside_an_edge_is_refused_where_the_grid_misses_it() {
    let edit = (r#"contact = "y < 1e-12""#, r#"contact = "y < 1e-12 && x < 0.6""#);
    for n in ["4", "8"] {
        let args = ["solve", "--problem", "v.toml", "--mesh", &format!("structured:{n}")];
        let (code, _, err) = run(&format!("part-in-edge-{n}"), SQUARE, &[edit], &args);
        assert_eq!(code, 1, "{n}: {err}");
        assert!(err.contains(&format!("the boundary parts change inside an edge of structured:{n}: the edge from (0.5, 0) to")), "{err}");
        assert!(err.contains("a part must end at a vertex of the mesh"), "{err}");
    }
    for n in ["5", "10"] {
        let args = ["solve", "--problem", "v.toml", "--mesh", &format!("structured:{n}")];
        let (code, _, err) = run(&format!("part-at-vertex-{n}"), SQUARE, &[edit], &args);
        assert_eq!(code, 0, "{n}: {err}");
    }
}

/// Battery 6, finding 9: `--adapt-levels` at the largest integer wrapped to 0 levels ("expected a
/// number of levels >= 1, got 0"); it is as many levels as --adapt-min-ndof needs.
#[test]
fn bad_adapt_levels_at_the_largest_integer_does_not_wrap() {
    let args =
        ["solve", "--problem", "ex71", "--mesh", "structured:2", "--adapt-levels", "18446744073709551615", "--adapt-min-ndof", "200"];
    let (code, out, err) = run("levels-max", SQUARE, &[], &args);
    assert_eq!(code, 0, "{out}{err}");
    assert!(!err.contains("got 0"), "{err}");
}
