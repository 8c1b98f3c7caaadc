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
    let msh = fixture("square.msh");
    assert!(msh.contains(from), "{from}");
    let (code, _, err) = solve_gmsh(name, &msh.replace(from, to));
    (code, err)
}

/// `signorini solve` of bad_data_gmsh.toml on the mesh file `msh` (written as bad.msh), probed at
/// (0.25, 0.5): (exit code, stdout without its timings, stderr).
fn solve_gmsh(name: &str, msh: &str) -> (i32, String, String) {
    let dir = tmp(name);
    std::fs::write(dir.join("bad.msh"), msh).unwrap();
    std::fs::write(dir.join("v.toml"), fixture("bad_data_gmsh.toml")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["solve", "--problem", "v.toml", "--mesh", "gmsh:bad.msh", "--probe", "0.25,0.5"])
        .output()
        .unwrap();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    let out: Vec<&str> = std::str::from_utf8(&o.stdout).unwrap().lines().filter(|l| !l.starts_with("time:")).collect();
    (o.status.code().unwrap_or(-1), out.join("\n"), text(&o.stderr))
}

/// tests/fixtures/square.msh with a second square, its own nodes 5-8 shifted by `d`, its own
/// boundary lines in the same groups and its triangles 11 and 12: two bodies, each a valid mesh.
fn two_squares(d: [f64; 2]) -> String {
    let msh = fixture("square.msh");
    let copy: Vec<String> = ["0 0 0", "1 0 0", "1 1 0", "0 1 0"]
        .iter()
        .map(|p| {
            let c: Vec<f64> = p.split(' ').map(|x| x.parse().unwrap()).collect();
            format!("{} {} 0", c[0] + d[0], c[1] + d[1])
        })
        .collect();
    let nodes = format!("0 1 0\n2 1 0 4\n5\n6\n7\n8\n{}\n$EndNodes", copy.join("\n"));
    let elements = "6 1 4 3\n1 1 1 1\n7 5 6\n1 2 1 3\n8 6 7\n9 7 8\n10 8 5\n2 1 2 2\n11 5 6 7\n12 5 8 7\n$EndElements";
    let out = msh
        .replace("$Nodes\n1 4 1 4\n", "$Nodes\n2 8 1 8\n")
        .replace("0 1 0\n$EndNodes", &nodes)
        .replace("$Elements\n3 6 1 6\n", "$Elements\n6 12 1 12\n")
        .replace("6 1 4 3\n$EndElements", elements);
    assert_ne!(out, msh);
    out
}

/// Battery 7, finding 6: two bodies in one place, or crossing each other, each a valid mesh of
/// its own, were solved and certified (a probe gave one body's value). They are refused, naming
/// a triangle of each (tag and line) and a point inside both; squares that only touch along an
/// edge (each its own nodes) still solve.
#[test]
fn overlapping_bodies_in_a_gmsh_file_are_refused_naming_two_triangles_and_a_point() {
    let (code, _, err) = solve_gmsh("touching", &two_squares([1.0, 0.0]));
    assert_eq!(code, 0, "squares side by side: {err}");
    for d in [[0.0, 0.0], [0.5, 0.0], [0.5, 0.25], [-0.3, 0.6]] {
        let msh = two_squares(d);
        let (code, out, err) = solve_gmsh(&format!("overlap{}-{}", d[0], d[1]), &msh);
        assert_eq!(code, 1, "shift {d:?}: {out}{err}");
        // the first triangle of the first square overlaps the first of the second in each shift
        let line = |tag: u32| 1 + msh.lines().position(|l| l.starts_with(&format!("{tag} "))).unwrap();
        let said = format!("bad.msh, line {}: triangles 5 (line {}) and 11 overlap: both hold the point (", line(11), line(5));
        assert!(err.contains(&said), "shift {d:?}: {err}");
        // the point named lies inside both squares
        let at = err.split("both hold the point (").nth(1).and_then(|r| r.split(')').next()).unwrap();
        let p: Vec<f64> = at.split(", ").map(|x| x.parse().unwrap()).collect();
        let inside = |o: [f64; 2]| p[0] > o[0] && p[0] < o[0] + 1.0 && p[1] > o[1] && p[1] < o[1] + 1.0;
        assert!(inside([0.0, 0.0]) && inside(d), "shift {d:?}: ({at}) is not in both");
    }
}

/// Battery 7, finding 10: gmsh skips the sections it does not read (`$Comments`, any unknown
/// one) wherever they are, before `$MeshFormat` too; a file opening with `$Comments` was
/// refused as a bad header. Every placement now solves to the plain file's output, also when a
/// comment holds a line a reader looks for (`$PhysicalNames`, `$MeshFormat`, `$Nodes`); a
/// comment never closed is named at its line.
#[test]
fn sections_gmsh_skips_are_skipped_wherever_they_are() {
    let plain = fixture("square.msh");
    let (code, want, err) = solve_gmsh("plain", &plain);
    assert_eq!(code, 0, "{err}");
    let comment =
        "$Comments\nwritten by hand\n$PhysicalNames\n1\n1 1 \"bottom\"\n$EndPhysicalNames\n$MeshFormat\n4.1 1 8\n$Nodes\n$EndComments";
    for (name, from, to) in [
        ("top", "$MeshFormat\n", format!("{comment}\n$MeshFormat\n")),
        ("top-two", "$MeshFormat\n", format!("$Foo\n1 2 3\n$EndFoo\n\n{comment}\n$MeshFormat\n")),
        ("between", "$Entities\n", format!("{comment}\n$Entities\n")),
        ("before-nodes", "$Nodes\n", format!("{comment}\n$Nodes\n")),
        ("end", "$EndElements\n", format!("$EndElements\n{comment}\n")),
    ] {
        assert!(plain.contains(from), "{from}");
        let (code, out, err) = solve_gmsh(name, &plain.replacen(from, &to, 1));
        assert_eq!((code, &out), (0, &want), "{name}: {err}");
    }
    let (code, _, err) = solve_gmsh("open", &plain.replace("$Entities\n", "$Comments\nno end\n$Entities\n"));
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("bad.msh, line 10: the section $Comments has no line $EndComments"), "{err}");
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
