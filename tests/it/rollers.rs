//! Example 7.2 on rollers (`experiments/problems/ex72_rollers.toml`): component-wise Dirichlet
//! data (`dirichlet = [0.1, "free"]`) and a point constraint (`[[point_constraints]]`, u_2 = 0
//! at (0, 1/2)). The constraint's reaction is zero to round-off, the solution is symmetric about
//! y = 1/2, uniform refinement converges much faster than Example 7.2's h^0.71 (the clamped
//! corners are gone), and the new keys' mistakes are clear errors.

use crate::common;
use common::*;
use signorini::adapt;
use signorini::problems::{FileProblem, Problem};
use signorini::settings::adapt::{AdaptConfig, Refine};
use signorini::study::reference;
use std::path::Path;

fn rollers() -> FileProblem {
    FileProblem::load(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/experiments/problems/ex72_rollers.toml"))).unwrap()
}

#[test]
fn rollers_prescribe_u1_only_and_the_point_u2() {
    let p = rollers();
    let sol = solve_on(&p, &mesh(&p, "structured:16"));
    let mut on_left = 0;
    for (x, u) in sol.nodes.coords.iter().zip(&sol.u) {
        if x[0] == 0.0 {
            on_left += 1;
            assert_eq!(u[0], 0.1, "u_1 prescribed at {x:?}");
            if x[1] == 0.5 {
                assert_eq!(u[1], 0.0, "u_2 prescribed at the point");
            }
        }
    }
    assert_eq!(on_left, 33);
    // u_2 moves along the rollers side (it is not clamped): pushed in x, the side widens in y
    let u2 = |y: f64| sol.nodes.coords.iter().zip(&sol.u).find(|(x, _)| x[0] == 0.0 && x[1] == y).unwrap().1[1];
    assert!(u2(0.0) < -1e-3 && u2(1.0) > 1e-3, "u_2 at the corners {} and {}", u2(0.0), u2(1.0));
}

#[test]
fn the_point_constraint_has_zero_reaction_and_the_solution_is_symmetric() {
    let p = rollers();
    for spec in ["structured:16", "symmetric:24", "structured:64"] {
        let sol = solve_on(&p, &mesh(&p, spec));
        assert_eq!(sol.reactions.len(), 1);
        let [r1, r2] = sol.reactions[0];
        // u_2 is prescribed: its reaction is zero to round-off against the nodal forces' scale;
        // u_1 (prescribed on Gamma_D) carries the rollers' push
        assert!(r2.abs() <= 1e-12 * sol.force_scale, "{spec}: reaction {r2:e} against force scale {:e}", sol.force_scale);
        assert!(r1.abs() > 1e-3 * sol.force_scale, "{spec}: the rollers push, reaction {r1:e}");
    }
    // on a mesh symmetric about y = 1/2: u_1 even, u_2 odd (so u_2(0, 1/2) = 0 unconstrained)
    let sol = solve_on(&p, &mesh(&p, "symmetric:24"));
    let scale = sol.u.iter().fold(0.0f64, |a, u| a.max(u[0].abs()).max(u[1].abs()));
    for (i, x) in sol.nodes.coords.iter().enumerate() {
        let j = sol.nodes.coords.iter().position(|y| signorini::mesh::dist(*y, [x[0], 1.0 - x[1]]) < 1e-12).unwrap();
        assert!((sol.u[i][0] - sol.u[j][0]).abs() < 1e-11 * scale && (sol.u[i][1] + sol.u[j][1]).abs() < 1e-11 * scale, "at {x:?}");
    }
}

/// Slope of the least-squares line of log e against log h.
fn slope(h: &[f64], e: &[f64]) -> f64 {
    let n = h.len() as f64;
    let (x, y): (Vec<f64>, Vec<f64>) = (h.iter().map(|v| v.ln()).collect(), e.iter().map(|v| v.ln()).collect());
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum::<f64>() / x.iter().map(|a| (a - mx).powi(2)).sum::<f64>()
}

/// The rate in h of the L-infinity error (quadrature points) of uniform refinement from
/// structured:4, as a study refines (the adaptive loop, `refine = "uniform"`), at levels 2, 4, 6
/// and 8 (h = 1/8 to 1/64; the odd levels' meshes are rotated and sit off the line), against an
/// adaptive reference of at least 2e5 unknowns.
fn uniform_rate(p: &dyn Problem) -> f64 {
    let spec = signorini::records::ReferenceSpec {
        theta: 0.5,
        min_ndof: 200_000,
        contact_term: signorini::settings::estimator::ContactTerm::WithoutFullContact,
    };
    let mesh_spec = signorini::mesh::MeshSpec::parse("structured:4").unwrap();
    let field = reference::compute(p, &mesh_spec, &spec, &mut |_| std::ops::ControlFlow::Continue(())).unwrap().unwrap();
    let config = AdaptConfig { levels: 9, refine: Refine::Uniform, ..Default::default() };
    let out = adapt::run(p, mesh(p, "structured:4"), &config, Some(&field), &mut |_| std::ops::ControlFlow::Continue(())).unwrap();
    let (mut h, mut e) = (Vec::new(), Vec::new());
    for r in out.records.iter().filter(|r| r.level >= 2 && r.level % 2 == 0) {
        h.push(r.h_max);
        e.push(r.err_quadrature.unwrap());
    }
    assert_eq!(h.len(), 4);
    slope(&h, &e)
}

#[test]
fn uniform_refinement_on_rollers_converges_much_faster_than_clamped() {
    // the same measurement on Example 7.2 clamped finds its corners' rate (the paper's h^0.71)
    let clamped = uniform_rate(&signorini::problems::Ex72);
    assert!((0.62..0.82).contains(&clamped), "clamped: uniform rate {clamped:.3}");
    // on rollers about h^1.0: the corners at x = 0 are gone, what limits it lies on x >= 1/2
    let rate = uniform_rate(&rollers());
    assert!(rate > 0.92 && rate > clamped + 0.2, "rollers: uniform rate {rate:.3} (clamped {clamped:.3})");
}

/// The error of `signorini solve` on the problem file `text`, checked to name the file.
fn solve_err(text: &str) -> String {
    let dir =
        std::env::temp_dir().join(format!("signorini-rollers-{}-{:x}", std::process::id(), text.len() * 31 + text.matches('[').count()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("p.toml"), text).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", "structured:4"]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_ne!(code, 0, "accepted:\n{text}");
    err
}

fn with(dirichlet: &str, points: &str) -> String {
    let base = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/experiments/problems/ex72_rollers.toml")).unwrap();
    let start = base.find("[[point_constraints]]").unwrap();
    let end = base.find("[material]").unwrap();
    format!("{}{points}\n{}", &base[..start], &base[end..]).replace("dirichlet = [0.1, \"free\"]", &format!("dirichlet = {dirichlet}"))
}

#[test]
fn malformed_rollers_and_point_constraints_are_clear_errors() {
    let e = solve_err(&with("[\"free\", \"free\"]", ""));
    assert!(e.contains("p.toml:") && e.contains("key `dirichlet`") && e.contains("at least one component prescribed"), "{e}");
    let e = solve_err(&with("[0.1, \"free\"]", "[[point_constraints]]\nat = [0, 0.5]\nu = [\"free\", \"free\"]\n"));
    assert!(e.contains("key `point_constraints[0].u`") && e.contains("at least one component prescribed"), "{e}");
    let twice = "[[point_constraints]]\nat = [0, 0.5]\nu = [\"free\", 0]\n[[point_constraints]]\nat = [0, 0.5]\nu = [0.1, \"free\"]\n";
    let e = solve_err(&with("[0.1, \"free\"]", twice));
    assert!(e.contains("key `point_constraints[1].at`") && e.contains("is point_constraints[0] too"), "{e}");
    let e = solve_err(&with("[0.1, \"free\"]", "[[point_constraints]]\nat = [0, 0.5]\nu = [\"free\", \"z\"]\n"));
    assert!(e.contains("key `point_constraints[0].u[1]`") && e.contains("unknown variable `z`"), "{e}");
    let e = solve_err(&with("[0.1, \"free\"]", "[[point_constraints]]\nat = [0, 0.5]\nv = [0, 0]\n"));
    assert!(e.contains("p.toml:") && e.contains("unknown field `v`"), "{e}");
    // rollers alone leave the vertical translation free
    let e = solve_err(&with("[0.1, \"free\"]", ""));
    assert!(e.contains("the body can move rigidly") && e.contains("u_2 prescribed nowhere"), "{e}");
    // no Dirichlet side and one point: held at that point only
    let e = solve_err(
        &with("[0.1, \"free\"]", "[[point_constraints]]\nat = [0.5, 0.5]\nu = [\"free\", 0]\n")
            .replace("dirichlet = \"x < 1e-12\"", "dirichlet = \"x < 0 - 1\""),
    );
    assert!(e.contains("the body can move rigidly") && e.contains("held at one point only, (0.500000, 0.500000)"), "{e}");
    // u_1 on the rollers side and u_2 at a second point of it: held (the line of u_1's
    // points is vertical, so no rotation is left); u_2 only, at two points: u_1 nowhere
    let e = solve_err(&with("[\"free\", 0]", ""));
    assert!(e.contains("the body can move rigidly") && e.contains("u_1 prescribed nowhere"), "{e}");
    // a point that is no vertex of the mesh
    let e = solve_err(&with("[0.1, \"free\"]", "[[point_constraints]]\nat = [0, 0.4]\nu = [\"free\", 0]\n"));
    assert!(e.contains("0.4"), "{e}");
}
