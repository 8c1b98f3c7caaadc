//! Problem data and meshes that used to give an answer (exit 0) or a crash: each is now a named
//! error before anything is solved, saying which key, node or triangle and the point or value.

use std::path::{Path, PathBuf};
use std::process::Command;

fn fixture(name: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)).unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("signorini-bad-data-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `signorini solve` on the square problem with `from` replaced by `to`; (exit code, stderr).
fn solve_variant(name: &str, base: &str, from: &str, to: &str, mesh: &str) -> (i32, String) {
    let dir = tmp(name);
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
    let dir = tmp("nocontact");
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

/// A Gmsh variant of tests/fixtures/square.msh: (exit code, stderr).
fn gmsh_variant(name: &str, from: &str, to: &str) -> (i32, String) {
    let dir = tmp(name);
    let msh = fixture("square.msh");
    assert!(msh.contains(from), "{from}");
    std::fs::write(dir.join("bad.msh"), msh.replace(from, to)).unwrap();
    std::fs::write(dir.join("v.toml"), fixture("bad_data_gmsh.toml")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["solve", "--problem", "v.toml", "--mesh", "gmsh:bad.msh"])
        .output()
        .unwrap();
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn the_unmodified_gmsh_square_solves() {
    let (code, err) = gmsh_variant("good", "$Nodes", "$Nodes");
    assert_eq!(code, 0, "{err}");
}

#[test]
fn malformed_gmsh_meshes_are_named() {
    let nodes = "$Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n$EndNodes";
    let second_block = |header: &str| nodes.replace("$Nodes\n1 4 1 4\n", header).replace("$EndNodes", "2 1 0 1\n4\n0.5 0.5 0\n$EndNodes");
    for (name, from, to, says) in [
        // triangle 6 laid over triangle 5 (both on the same side of their edge)
        (
            "fold",
            "6 1 4 3".to_string(),
            "6 1 2 4".to_string(),
            "triangles 5 and 6 overlap: their edge (0, 0)-(1, 0) has both on the same side",
        ),
        ("count", "$Nodes\n1 4 1 4\n".into(), "$Nodes\n1 3 1 4\n".into(), "the $Nodes header declares 3 nodes, its blocks hold 4"),
        // a header count or range that is wrong is named as such, not blamed on a tag listed twice
        ("count-over", "$Nodes\n1 4 1 4\n".into(), "$Nodes\n1 5 1 4\n".into(), "the $Nodes header declares 5 nodes, its blocks hold 4"),
        ("min-tag", "$Nodes\n1 4 1 4\n".into(), "$Nodes\n1 4 2 4\n".into(), "node tag 1 is outside the range 2 to 4"),
        ("inf", "0 1 0\n$EndNodes".into(), "1e999 1 0\n$EndNodes".into(), "node 4 has the coordinate inf"),
        ("nan", "0 1 0\n$EndNodes".into(), "nan 1 0\n$EndNodes".into(), "node 4 has the coordinate NaN"),
        // tags 1..4, then 4 again: mshio drops the tags of a section whose tags look contiguous
        ("dup-dense", nodes.into(), second_block("$Nodes\n2 5 1 4\n"), "node tag 4 is listed twice, at (0, 1, 0) and at (0.5, 0.5, 0)"),
        // sparse tags (up to 9), 4 listed again in a second block with other coordinates
        ("dup-sparse", nodes.into(), second_block("$Nodes\n2 5 1 9\n"), "node tag 4 is listed twice, at (0, 1, 0) and at (0.5, 0.5, 0)"),
    ] {
        let (code, err) = gmsh_variant(name, &from, &to);
        assert_eq!(code, 1, "{name}: {err}");
        assert!(err.contains("bad.msh") && err.contains(says), "{name}: {err}");
    }
}

#[test]
fn a_mesh_that_is_not_a_regular_file_is_refused_at_once() {
    let dir = tmp("devzero");
    std::fs::write(dir.join("v.toml"), fixture("bad_data_gmsh.toml")).unwrap();
    let start = std::time::Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["solve", "--problem", "v.toml", "--mesh", "gmsh:/dev/zero"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("/dev/zero: not a regular file"), "{err}");
    assert!(start.elapsed().as_secs() < 5, "it read on: {:?}", start.elapsed());
}
