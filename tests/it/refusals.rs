//! Refusals that say what is wrong: a round-off that no rigid translation explains is not
//! blamed on one.

use super::common::{scratch, signorini_in};
use std::path::Path;

/// Example 7.2 with the `[material]` table replaced by `material`.
fn ex72_with(material: &str) -> String {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex72.toml");
    let text = std::fs::read_to_string(file).unwrap();
    text.replace("E = 500\nnu = 0.3\nmodel = \"plane_strain\"\n", material)
}

fn eta_h(out: &str) -> f64 {
    let line = out.lines().find(|l| l.starts_with("estimator: ")).unwrap_or_else(|| panic!("no estimate: {out}"));
    line.split("eta_h ").nth(1).and_then(|r| r.split(',').next()).unwrap().parse().unwrap()
}

const TRANSLATION_ADVICE: &str = "subtract the translation";

/// mu = 1, lambda = 1e8: u_h resolves its deformation (0.3) to 5e-8, the solve is certified, and
/// its estimate is lambda = 1e7's to 1e-4: within 1e3 (2 mu + lambda) delta, but far above the
/// largest stress u_h's round-off can carry, so it is solved. A ratio past what the round-off
/// resolves (E = 500, nu = 0.4999999999: lambda/mu = 5e9) is refused as nearly incompressible,
/// with its numbers, not as a rigid translation.
#[test]
fn a_nearly_incompressible_material_is_solved_or_refused_as_such_not_as_a_translation() {
    let dir = scratch("refusals-incompressible");
    let solve = |name: &str, material: &str| {
        std::fs::write(dir.join(name), ex72_with(material)).unwrap();
        signorini_in(&dir, &["solve", "--problem", name, "--mesh", "structured:8"])
    };
    let (code, moderate, err) = solve("l7.toml", "mu = 1\nlambda = 1e7\n");
    assert_eq!(code, 0, "{moderate}{err}");
    let (code, out, err) = solve("l8.toml", "mu = 1\nlambda = 1e8\n");
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("certified: ") && !err.contains("at the round-off"), "{out}{err}");
    assert!((eta_h(&out) - eta_h(&moderate)).abs() <= 1e-4 * eta_h(&moderate), "{moderate}\n{out}");
    assert!(!err.contains(TRANSLATION_ADVICE) && !err.contains("a rigid translation in the data makes"), "{err}");
    let (code, out, err) = solve("nu.toml", "E = 500\nnu = 0.4999999999\nmodel = \"plane_strain\"\n");
    assert_eq!(code, 1, "{out}{err}");
    assert!(!out.contains("estimator:") && !err.contains(TRANSLATION_ADVICE), "{out}{err}");
    for part in [
        "the estimate cannot be told from round-off: it is ",
        "No rigid translation explains that round-off: u_h is up to 0.2 in size",
        "conditioning of the stiffness matrix (lambda/mu = 5.0e9, a nearly incompressible material",
        "a Poisson's ratio further from 0.5",
    ] {
        assert!(err.contains(part), "{part}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
