//! A problem mirrored about y = x reports the same errors, estimates and adaptive meshes as the
//! original: the error maxima are taken over points that a reflection maps onto themselves.

use crate::common::{scratch, signorini_in};

const MIRRORED: &str = r#"description = "Example 7.1 mirrored about y = x"
body_force = ["3*x*(y - 2)*(x + 3)*exp(x)", "2*exp(x)*(x^2 + x - 1) - 6*x + 2"]
traction = "exact"
dirichlet = "exact"
[material]
mu = 1
lambda = 1
[parts]
contact = "x < 1e-12"
dirichlet = "x > 1 - 1e-12"
[contact]
normal = "outward"
chi = 0
[exact]
u = ["exp(x)*(1 - x)*x*(y - 2)", "x^2*(x - 1)"]
"#;

/// The lines of a command's output that carry numbers a mirror must not change (a level row
/// without its last column, the level's time).
fn numbers(out: &str) -> Vec<String> {
    let row = |l: &str| l.trim_start().starts_with(|c: char| c.is_ascii_digit());
    let keep = |l: &&str| l.starts_with("error Linf") || l.starts_with("estimator:") || row(l);
    let strip = |l: &str| {
        let words: Vec<&str> = l.split_whitespace().collect();
        if row(l) { words[..words.len() - 1].join(" ") } else { words.join(" ") }
    };
    out.lines().filter(keep).map(strip).collect()
}

#[test]
fn a_mirrored_problem_reports_the_same_errors_estimates_and_meshes() {
    let dir = scratch("mirror-symmetry-mirrored-problem-reports");
    std::fs::write(dir.join("sw71.toml"), MIRRORED).unwrap();
    let run = |args: &[&str]| {
        let (code, out, err) = signorini_in(&dir, args);
        assert_eq!(code, 0, "{args:?}: {err}");
        numbers(&out)
    };
    for (original, mirrored) in [
        (
            run(&["solve", "--problem", "ex71", "--mesh", "structured:8"]),
            run(&["solve", "--problem", "sw71.toml", "--mesh", "structured:8"]),
        ),
        (
            run(&["adapt", "--problem", "ex71", "--mesh", "structured:4", "--levels", "6"]),
            run(&["adapt", "--problem", "sw71.toml", "--mesh", "structured:4", "--levels", "6"]),
        ),
    ] {
        assert!(original.len() >= 2, "{original:?}");
        assert_eq!(original, mirrored);
    }
}
