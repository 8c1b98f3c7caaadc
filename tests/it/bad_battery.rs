//! What the third battery of hostile inputs found (issue 38, "Done when"), each refused by the one
//! function every path goes through:
//!
//! * a Gmsh mesh whose file lacks a physical group the problem names (a misspelt name beside the
//!   right one, a surface group as a boundary part) was solved, the name tagging nothing
//!   (`GmshFile::check_named_groups`);
//! * a `[curves]` circle the mesh's boundary does not follow was accepted: refinement pulled new
//!   vertices onto it, ending in "non-positive area" or a distorted mesh
//!   (`GmshFile::check_on_curve`);
//! * `-s^2` is `(-s)^2` in exmex: a value every reader takes for `-(s^2)` silently changed sign
//!   (`negated_power`, in the one expression parser of problem files), and `2^3^2` is
//!   `(2^3)^2` (`chained_power`, beside it);
//! * a pair with a third value (`required_vertices = [[1, 0.5, 0]]`, an exact solution or a
//!   circle centre of three) was read as its first two (`Two`, every pair of a problem file);
//! * a subnormal C_0 was printed with 320 digits and called "not positive"
//!   (`ConfigError::number`);
//! * a run id `.` or `.x` made a hidden record (`runs/..json`), and ids differing only in case
//!   share one record file on macOS (the manifest's id check).
//! * `adapt --save DIR/` computed every level, then failed to write (`check_writable`).
//! * standard output on a full device panicked (exit 101): `stdout_write` in main.rs.
//! * one name given to two physical groups merged them into one part (`physical_names`).
//! * a partitioned mesh was read as if whole, its groups empty (`refuse_partitioned`).

use std::path::PathBuf;
use std::process::Command;

fn fixture(rel: &str) -> String {
    std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(rel)).unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("signorini-bad-battery-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `signorini ARGS` in a folder holding `v.toml` (fixture `base` with `from` replaced by `to`),
/// `qd.msh` (the quarter disc) and `sq.msh` (the square): (exit code, stdout, stderr), never a
/// panic or a signal.
fn run(name: &str, base: &str, from: &str, to: &str, args: &[&str]) -> (i32, String, String) {
    let dir = tmp(name);
    let text = fixture(base);
    assert!(text.contains(from), "{from} not in {base}");
    std::fs::write(dir.join("v.toml"), text.replace(from, to)).unwrap();
    std::fs::write(dir.join("qd.msh"), fixture("gmsh_renumbered/plain.msh")).unwrap();
    std::fs::write(dir.join("sq.msh"), fixture("square.msh")).unwrap();
    let answer = crate::common::signorini_in(&dir, args);
    std::fs::remove_dir_all(&dir).ok();
    answer
}

const QD: &str = "gmsh_renumbered/quarter_disc.toml";
const SOLVE_QD: &[&str] = &["solve", "--problem", "v.toml", "--mesh", "gmsh:qd.msh"];
const ADAPT_QD: &[&str] = &["adapt", "--problem", "v.toml", "--mesh", "gmsh:qd.msh", "--levels", "4"];

#[test]
fn bad_physical_group_the_mesh_file_lacks_is_named() {
    // the unchanged problem solves: the refusals below are the names' doing
    let (code, out, err) = run("groups-ok", QD, "", "", SOLVE_QD);
    assert!(code == 0 && out.contains("certified:"), "{err}");
    for (case, from, to, group) in [
        ("misspelt", r#"contact = ["bottom"]"#, r#"contact = ["bottom", "botom"]"#, "botom"),
        ("misspelt-dirichlet", r#"dirichlet = ["left"]"#, r#"dirichlet = ["left", "lef"]"#, "lef"),
        ("surface", r#"neumann = ["arc"]"#, r#"neumann = ["arc", "body"]"#, "body"),
    ] {
        for args in [SOLVE_QD, ADAPT_QD] {
            let (code, _, err) = run(case, QD, from, to, args);
            assert_eq!(code, 1, "{case}: {err}");
            for says in [
                "qd.msh".to_string(),
                format!(r#"names the physical group "{group}", which is not a group of boundary lines of this file"#),
                r#"its groups of lines: "bottom", "arc", "left""#.to_string(),
            ] {
                assert!(err.contains(&says), "{case}: no {says:?} in\n{err}");
            }
        }
    }
}

#[test]
fn bad_curve_the_boundary_does_not_follow_is_refused_before_refining() {
    let arc = "arc = { circle = { centre = [0, 0], radius = 1 } }";
    for (case, to) in [
        ("centre", "arc = { circle = { centre = [0, 1], radius = 1 } }"),
        ("radius", "arc = { circle = { centre = [0, 0], radius = 1.01 } }"),
    ] {
        for args in [SOLVE_QD, ADAPT_QD] {
            let (code, _, err) = run(case, QD, arc, to, args);
            assert_eq!(code, 1, "{case}: {err}");
            for says in ["qd.msh, line ", r#"of this line element of group "arc" is off the curve"#, "[curves]", "of its size"] {
                assert!(err.contains(says), "{case}: no {says:?} in\n{err}");
            }
            assert!(!err.contains("non-positive area"), "{case}: {err}");
        }
    }
    let (code, out, err) = run("curve-ok", QD, "", "", ADAPT_QD);
    assert!(code == 0 && out.lines().filter(|l| l.trim_start().starts_with(char::is_numeric)).count() == 4, "{err}\n{out}");
}

const SQUARE: &str = "bad_data_square.toml";
const SOLVE_SQ: &[&str] = &["solve", "--problem", "v.toml", "--mesh", "structured:4"];
const CHI: &str = r#"chi = "0.001""#;

#[test]
fn bad_minus_before_a_power_is_refused_not_read_as_the_power_of_the_negation() {
    for chi in ["-0.1^2 + 0.011", "0.02 + -x^2", "0.011 + 2*-(x)^2", "0.011 - -sqrt(x)^2", "0.011 + (-x ^ 3)", "0.01 + 2^-x^2"] {
        let (code, _, err) = run("negated-power", SQUARE, CHI, &format!("chi = {chi:?}"), SOLVE_SQ);
        assert_eq!(code, 1, "{chi}: {err}");
        for says in ["v.toml:", "key `contact.chi`", "negates the base of a power", "write -(s^2) or 0 - s^2"] {
            assert!(err.contains(says), "{chi}: no {says:?} in\n{err}");
        }
    }
    // the unambiguous forms, a minus that is a subtraction, an exponent's sign, a negative power
    for chi in [
        "-(0.1^2) + 0.011",
        "0 - 0.1^2 + 0.011",
        "(-0.1)^2 - 0.009",
        "0.011 - x^2",
        "1e-3 + x*1E-12",
        "0.001*2^-x",
        "-0.2 + 0.5*abs(y - 0.5)",
    ] {
        let (code, out, err) = run("power-ok", SQUARE, CHI, &format!("chi = {chi:?}"), SOLVE_SQ);
        assert!(code == 0 && out.contains("certified:") || err.contains("overlap the body"), "{chi}: {err}");
        assert!(!err.contains("negates the base"), "{chi}: {err}");
    }
}

/// `2^3^2` is (2^3)^2 = 64 in exmex, 512 as everyone else reads it (battery 5, finding 4: a
/// silent answer): a chain of powers without parentheses is refused, naming the `^`; the
/// parenthesised forms and powers apart pass.
#[test]
fn bad_chain_of_powers_is_refused_not_read_left_to_right() {
    for chi in ["0.0001*2^3^2", "0.001 + x^2^2", "0.001 + 2^(x)^2", "0.001 + abs(x)^2 ^ 1"] {
        let (code, _, err) = run("chained-power", SQUARE, CHI, &format!("chi = {chi:?}"), SOLVE_SQ);
        assert_eq!(code, 1, "{chi}: {err}");
        for says in ["v.toml:", "key `contact.chi`", "follows another without parentheses", "(a^b)^c"] {
            assert!(err.contains(says), "{chi}: no {says:?} in\n{err}");
        }
    }
    for chi in ["0.0001*2^(3^2)", "0.0001*(2^3)^2", "0.001 + x^2*y^2", "0.001 + 2^x - y^2", "0.001 + (x^2)^2"] {
        let (code, out, err) = run("power-ok", SQUARE, CHI, &format!("chi = {chi:?}"), SOLVE_SQ);
        assert!(code == 0 && out.contains("certified:") || err.contains("overlap the body"), "{chi}: {err}");
        assert!(!err.contains("without parentheses"), "{chi}: {err}");
    }
}

#[test]
fn bad_products_without_a_star_and_units_get_a_hint() {
    for chi in ["0.001x", "1 mm"] {
        let (code, _, err) = run("star", SQUARE, CHI, &format!("chi = {chi:?}"), SOLVE_SQ);
        assert_eq!(code, 1, "{err}");
        assert!(err.contains("a product needs `*`, as in 2*x; numbers carry no units"), "{chi}: {err}");
    }
}

#[test]
fn bad_pair_with_a_third_value_is_refused_where_it_was_cut_to_two() {
    let ex71 = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex71.toml")).unwrap();
    let dir = tmp("pairs");
    let cases = [
        ("exact", ex71.replace(r#"u = ["y^2*(y - 1)","#, r#"u = ["y^2*(y - 1)", "x","#), "structured:4"),
        ("vertex", fixture(SQUARE).replace("[material]", "required_vertices = [[1, 0.5, 0]]\n\n[material]"), "structured:4"),
        ("centre", fixture(QD).replace("centre = [0, 0]", "centre = [0, 0, 0]"), "gmsh:qd.msh"),
    ];
    std::fs::write(dir.join("qd.msh"), fixture("gmsh_renumbered/plain.msh")).unwrap();
    for (case, text, mesh) in cases {
        assert!(text.contains(", \"x\",") || text.contains("0.5, 0]") || text.contains("[0, 0, 0]"), "{case}: not changed");
        std::fs::write(dir.join("v.toml"), text).unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
            .current_dir(&dir)
            .args(["solve", "--problem", "v.toml", "--mesh", mesh])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{case}: {err}");
        assert!(err.contains("v.toml:") && err.contains("invalid length 3, expected an array of exactly two values"), "{case}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_subnormal_c0_is_shown_in_a_few_characters() {
    let (code, _, err) = run("c0", SQUARE, "", "", &["adapt", "--problem", "ex71", "--levels", "2", "--c0", "1e-320"]);
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

use crate::common;

#[test]
fn bad_run_id_that_hides_its_record_or_clashes_by_case_is_refused() {
    for (id, says) in [
        (".", "starts with a letter or digit"),
        (".hidden", "starts with a letter or digit"),
        ("-a", "starts with a letter or digit"),
        ("A", r#""A" and "a", the same name but for case"#),
        ("a", r#""a" twice"#),
    ] {
        let text = fixture("tiny.toml").replace(r#"id = "b""#, &format!("id = {id:?}"));
        let err = common::parse_err(&text);
        assert!(err.contains("key `run[1].id`") && err.contains(says), "{id}: {err}");
    }
    // what the id check still accepts
    for id in ["b.2", "B_2-x", "0"] {
        let text = fixture("tiny.toml").replace(r#"id = "b""#, &format!("id = {id:?}"));
        signorini::study::manifest::Manifest::parse(std::path::Path::new("experiments/tiny.toml"), &text).unwrap();
    }
}

/// `adapt --save` to a folder, or into a folder where no file can be made: refused before level
/// 0 is solved, naming the path. Before, every level was computed and the write failed at the
/// end with "renaming the temporary file to DIR/: Not a directory".
#[test]
fn bad_save_path_that_is_a_folder_is_refused_before_solving() {
    let dir = tmp("save");
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["adapt", "--problem", "ex71", "--levels", "2", "--save", "."])
        .output()
        .unwrap();
    let (out, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("--save .: this is a folder; give the path of a file in it, e.g. ./solution.vtu"), "{err}");
    assert!(!out.contains("lvl"), "solved before refusing: {out}");
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["adapt", "--problem", "ex71", "--levels", "2", "--save", "s.vtu"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.join("s.vtu").is_file());
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "the probe file is removed");
    std::fs::remove_dir_all(&dir).ok();
}

/// Standard output on a full device: the error's exit status (1) naming it, not a panic (101,
/// as std's `println!` ended before), for `solve`, `solve --json` and `adapt`.
#[test]
fn bad_full_stdout_exits_with_the_error_status_not_a_panic() {
    for args in [
        &["solve", "--problem", "ex71", "--mesh", "structured:4"][..],
        &["solve", "--problem", "ex71", "--mesh", "structured:4", "--json"],
        &["adapt", "--problem", "ex71", "--levels", "3"],
    ] {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_signorini")).args(args).stdout(full).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("error: writing standard output: No space left on device") && !err.contains("panicked"), "{args:?}: {err}");
    }
}

/// Two physical groups of lines under one name in `$PhysicalNames`: refused naming both tags and
/// lines (a problem names groups by name, so the two would silently be one part).
#[test]
fn bad_physical_name_given_to_two_groups_is_refused() {
    let dir = tmp("dupname");
    std::fs::write(dir.join("sq.msh"), fixture("square.msh").replace(r#"1 2 "sides""#, r#"1 2 "bottom""#)).unwrap();
    std::fs::write(dir.join("v.toml"), fixture("bad_data_gmsh.toml")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["solve", "--problem", "v.toml", "--mesh", "gmsh:sq.msh"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains(r#"sq.msh, line 7: $PhysicalNames: the name "bottom" is given to groups 1 (line 6) and 2 of dimension 1"#),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The unclear messages the third battery left: a pair of the wrong length names its key, a
/// huge number in a manifest is printed short, `export --out FILE` says what is wrong before
/// solving, and `--adapt-min-ndof` that the loop does not reach is an error, not a silent mesh.
#[test]
fn bad_lengths_huge_numbers_export_files_and_unreached_minimums_are_named() {
    let ex71 = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex71.toml")).unwrap();
    let dir = tmp("named");
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
    // figures and report say it the same way (battery 5, finding 11: "File exists (os error 17)")
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

/// A partitioned MSH 4.1 file (battery 4, finding 6) puts its elements on partition entities:
/// read as if it were whole, its lines came out in no group and the problem was blamed ("its
/// groups of lines: " with none). Refused naming the section, its line and how to write it whole.
#[test]
fn a_partitioned_mesh_is_refused_by_name() {
    let dir = tmp("partitioned");
    std::fs::write(dir.join("v.toml"), fixture(QD)).unwrap();
    std::fs::write(dir.join("p.msh"), fixture("gmsh_renumbered/partitioned.msh")).unwrap();
    for args in [["solve", "--problem", "v.toml", "--mesh", "gmsh:p.msh"], ["adapt", "--problem", "v.toml", "--mesh", "gmsh:p.msh"]] {
        let o = Command::new(env!("CARGO_BIN_EXE_signorini")).current_dir(&dir).args(args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(
            err.contains("p.msh, line 21") && err.contains("a partitioned mesh ($PartitionedEntities)") && err.contains("unpartition"),
            "{err}"
        );
        assert!(!err.contains("names the physical group"), "{err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
