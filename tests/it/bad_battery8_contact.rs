//! The eighth battery of hostile inputs: contact data and numeric edges.
//!
//! * A contact normal reversed or nearly tangent, or a gap below minus the body's size (or NaN),
//!   on a stretch of Gamma_C between contact nodes was certified on coarse meshes and refused
//!   only at a finer one: `plausible::check_contact_data` now checks the normal and the gap on
//!   the exact-solution contact check's point set (`consistent::boundary::sample`), so such a
//!   file is refused on every mesh, before level 0.
//! * A rigid translation of 5e10 made the adaptive loop stop at level 0 as "exact to round-off"
//!   with an accurate estimate: `adapt::estimate_at_roundoff` scales by u_h's round-off, which a
//!   rigid motion does not inflate as it inflates max |u_h|.
//! * Underflow of the stiffness matrix (E = 1e-315, 5e-324) was named a singular matrix or a
//!   non-positive pivot, an overflowing solution (body force 1e300) a KKT condition violated by
//!   NaN: `solve::check_finite` and `solve::check_solution` name them as the data's scale.

use crate::common::signorini_in;

fn tmp(name: &str) -> std::path::PathBuf {
    crate::common::scratch(&format!("battery8c-{name}"))
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

/// Level rows of `adapt`'s table.
fn rows(out: &str) -> usize {
    out.lines().filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).count()
}

#[test]
fn bad_contact_data_on_a_stretch_between_nodes_is_refused_on_every_mesh_before_level_0() {
    let dir = tmp("bands");
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
        assert_eq!(rows(&out), 0, "{name}: refused before level 0: {out}");
        assert!(err.contains(says), "{name}: {err}");
    }
    // the same file without the band passes (the check refuses the band, not the problem)
    let file = ex72_with(&dir, "plain", "normal", "normal = [\"1 - 0*max(0, 1 - abs(y - 0.53)/0.004)\", \"0\"]");
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", &file, "--mesh", "structured:4"]);
    assert_eq!(code, 0, "{out}{err}");
}

/// A rigid translation moves max |u_h| but not the deformation the estimate measures: the loop
/// refines as without it, and an exact rigid translation still stops at level 0. (Battery 12,
/// F1: a translation by 5e10, as first tested here, puts the contact forces' round-off at 0.1 of
/// the largest force and is refused as such, not stopped; 1e9 is kept, with a warning, up to
/// level 2.)
#[test]
fn a_rigid_translation_does_not_make_an_accurate_estimate_round_off() {
    let dir = tmp("shift");
    let shifted = |c: &str| {
        let file = ex72_with(&dir, "shifted", "dirichlet", &format!("dirichlet = [\"{c} + 0.1\", 0]"));
        let text = std::fs::read_to_string(dir.join(&file)).unwrap().replace("chi = \"-0.2 +", &format!("chi = \"{c} - 0.2 +"));
        assert!(text.contains(&format!("{c} - 0.2")), "{text}");
        std::fs::write(dir.join(&file), text).unwrap();
        signorini_in(&dir, &["adapt", "--problem", &file, "--mesh", "structured:4", "--levels", "3"])
    };
    let (code, out, err) = shifted("5e10");
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("the contact forces are not resolved") && !out.contains("# stopped"), "{out}{err}");
    let (code, out, err) = shifted("1e9");
    assert_eq!(code, 0, "{err}");
    assert_eq!(rows(&out), 3, "{out}");
    assert!(!out.contains("# stopped"), "{out}");
    // the estimate is the untranslated problem's
    let (code, plain, err) = signorini_in(&dir, &["adapt", "--problem", "ex72", "--mesh", "structured:4", "--levels", "1"]);
    assert_eq!(code, 0, "{err}");
    let estimate = |t: &str| -> f64 {
        let row = t.lines().find(|l| l.trim_start().starts_with('0')).unwrap();
        row.split_whitespace().nth(4).unwrap().parse().unwrap()
    };
    let (a, b) = (estimate(&out), estimate(&plain));
    assert!((a - b).abs() < 1e-2 * b, "{a} vs {b}");
}

#[test]
fn underflow_and_overflow_outside_assembly_are_named_as_the_datas_scale() {
    let dir = tmp("range");
    for (name, e) in [("tiny", "1e-315"), ("smallest", "5e-324")] {
        let file = ex72_with(&dir, name, "E", &format!("E = {e}"));
        let (code, out, err) = signorini_in(&dir, &["solve", "--problem", &file, "--mesh", "structured:4"]);
        assert_ne!(code, 0, "{out}");
        assert!(err.contains("below f64's normal range") && err.contains("give them in other units"), "{e}: {err}");
        assert!(!err.contains("pivot") && !err.contains("singular"), "{e}: {err}");
    }
    let file = ex72_with(&dir, "heavy", "dirichlet", "dirichlet = [0.1, 0]\nbody_force = [\"1e300\", \"1e300\"]");
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", &file, "--mesh", "structured:4"]);
    assert_ne!(code, 0, "{out}");
    assert!(err.contains("overflow beyond f64's range") && err.contains("other units"), "{err}");
    assert!(!err.contains("NaN") && !err.contains("violated"), "{err}");
}
