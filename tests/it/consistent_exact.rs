//! The checks that an exact solution a problem file declares is one (crates/numerics/src/contact/consistent/)
//! look at every point where the data enter the discrete problem, on curved parts too: tension on
//! a contact arc is refused, edges on a `[curves]` circle included; a bump in the Dirichlet data
//! or the body force between the sampled points is refused on every mesh and before the first
//! level of an adaptive run. A stress-free exact solution with round-off in its gradient, and one
//! large against its variation, are accepted.

use crate::common::{scratch, signorini_in};
use signorini::contact::consistent::{BodyForceFindings, check_exact};
use signorini::mesh::refine::{Refinement, refine};
use signorini::mesh::{Mesh, P2Nodes};
use signorini::problems::{Ex71, Fb, Problem};
use std::path::PathBuf;
use std::process::Command;

fn repo(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// `signorini ARGS` in a fresh folder holding `v.toml` (`text`): (exit code, stdout, stderr).
fn run(name: &str, text: &str, args: &[&str]) -> (i32, String, String) {
    let dir = std::env::temp_dir().join(format!("signorini-consistent-exact-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("v.toml"), text).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_signorini")).current_dir(&dir).env("SIGNORINI_PROGRESS", "off").args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!err.contains("panicked"), "{name}: {err}");
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stdout).into_owned(), err)
}

/// The quarter disc with contact on its arc (a `[curves]` circle), Dirichlet data "exact" on
/// the straight sides, u = `s` (x, y) and the gap `chi`: sigma = 4 s I, so sigma_nn = 4 s on the
/// arc, where u . n = s.
fn quarter_disc(s: &str, chi: &str) -> String {
    format!(
        r#"description = "radial u = {s} (x, y) on the quarter disc"
dirichlet = "exact"
[material]
mu = 1
lambda = 1
[parts]
contact = ["arc"]
dirichlet = ["bottom", "left"]
[curves]
arc = {{ circle = {{ centre = [0, 0], radius = 1 }} }}
[contact]
normal = "outward"
chi = {chi}
[exact]
u = ["{s}*x", "{s}*y"]
"#
    )
}

/// Tension on the contact arc (u = 0.01 (x, y), sigma_nn = +0.04), with the gap closed or
/// open, is refused on `solve` and `adapt`, naming the condition; the same body pressed
/// (u = -0.01 (x, y) against chi = -0.01, sigma_nn = -0.04) is an exact solution and passes.
#[test]
fn an_exact_solution_is_checked_on_a_curved_contact_part() {
    let mesh = format!("gmsh:{}", repo("experiments/meshes/quarter_disc.msh").display());
    for (name, chi) in [("closed", "0.01"), ("open", "0.02")] {
        for command in ["solve", "adapt"] {
            let (code, _, err) =
                run(&format!("{name}-{command}"), &quarter_disc("0.01", chi), &[command, "--problem", "v.toml", "--mesh", &mesh]);
            assert_eq!(code, 1, "{name} {command}: {err}");
            assert!(
                err.contains("the exact solution does not satisfy the contact condition sigma_nn <= 0 on Gamma_C (no tension)")
                    && err.contains("sigma_nn = 4.000000e-2"),
                "{name} {command}: {err}"
            );
        }
    }
    let (code, out, err) =
        run("pressed", &quarter_disc("-0.01", "-0.01"), &["adapt", "--problem", "v.toml", "--mesh", &mesh, "--levels", "3"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.lines().count() > 3, "{out}");
}

/// Example 7.1's file with `from` replaced by `to`.
fn ex71(from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(repo("experiments/problems/ex71.toml")).unwrap();
    assert!(text.contains(from), "{from} not in ex71.toml");
    text.replace(from, to)
}

/// A bump of height 0.01 and width 0.02 in the Dirichlet data u_1 on the top edge (where the
/// exact u_1 is 0) was certified on structured:8 and 32 and refused on 16 and 64: refused on
/// every one of them, and the file as it is passes on them all.
#[test]
fn a_dirichlet_bump_between_sampled_points_is_refused_on_every_mesh() {
    let bumped = ex71(r#"dirichlet = "exact""#, r#"dirichlet = ["0.01*max(0, 1e-4 - (x - 0.53)^2)/1e-4", 0]"#);
    let plain = ex71("chi = 0\n", "chi = 0\n");
    for n in [8, 16, 32, 64] {
        let mesh = format!("structured:{n}");
        let args = ["solve", "--problem", "v.toml", "--mesh", &mesh];
        let (code, _, err) = run(&format!("dbump-{n}"), &bumped, &args);
        assert_eq!(code, 1, "{mesh}: {err}");
        assert!(
            err.contains("the exact solution does not satisfy the Dirichlet data on Gamma_D") && err.contains("`dirichlet[0]` ="),
            "{mesh}: {err}"
        );
        let (code, _, err) = run(&format!("dplain-{n}"), &plain, &args);
        assert_eq!(code, 0, "{mesh}: {err}");
    }
}

/// A bump of peak 1 and radius 0.01 in the body force near (0.37, 0.61) was certified on
/// structured:32 and on 14 levels of `adapt`, then refused at level 15: refused on every mesh,
/// and by `adapt` before its first level.
#[test]
fn a_body_force_bump_between_sampled_points_is_refused_on_every_mesh() {
    let f = r#"2*exp(y)*(y^2 + y - 1) - 6*y + 2""#;
    let bumped = ex71(f, r#"2*exp(y)*(y^2 + y - 1) - 6*y + 2 + 10000.0*max(0, 0.0001 - (x-0.37)^2 - (y-0.61)^2)""#);
    for n in [8, 16, 32] {
        let mesh = format!("structured:{n}");
        let (code, _, err) = run(&format!("fbump-{n}"), &bumped, &["solve", "--problem", "v.toml", "--mesh", &mesh]);
        assert_eq!(code, 1, "{mesh}: {err}");
        assert!(
            err.contains("the body force is not -div sigma(u) of the exact solution") && err.contains("`body_force[0]` is"),
            "{mesh}: {err}"
        );
    }
    let (code, out, err) = run("fbump-adapt", &bumped, &["adapt", "--problem", "v.toml", "--mesh", "structured:8", "--levels", "16"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("the body force is not -div sigma(u)"), "{err}");
    assert!(!out.lines().any(|l| l.trim_start().starts_with("1 ")), "no level is computed before the refusal: {out}");
}

/// `exact.grad` written by hand with an extra 0.5 b(y) in its diagonal, b a band of half-width
/// 0.01 around y = 0.5 whose sigma is divergence-free (the body force check cannot see it),
/// changes the traction `"exact"` on the sides x = 0 and x = 1, between the sampled centroids of
/// structured:4 to 32: the gradient is checked where the traction reads it, and refused on every
/// mesh; the correct gradient written by hand passes.
#[test]
fn a_hand_written_gradient_wrong_where_the_traction_reads_it_is_refused_on_every_mesh() {
    let u = r#"u = ["y^2*(y - 1)", "exp(y)*(1 - y)*y*(x - 2)"]"#;
    let band = "0.5*max(0, 1e-4 - (y - 0.5)^2)/1e-4";
    let grad = |extra: &str, third: &str| {
        format!(
            r#"{u}
grad = [["0{extra}", "3*y^2 - 2*y"], ["exp(y)*(1 - y)*y", "(x - 2)*exp(y)*(1 - y - y^2){third}"]]"#
        )
    };
    let wrong = ex71(u, &grad(&format!(" + {band}"), &format!(" - {band}/3")));
    let right = ex71(u, &grad("", ""));
    for n in [4, 8, 16, 32] {
        let mesh = format!("structured:{n}");
        let args = ["solve", "--problem", "v.toml", "--mesh", &mesh];
        let (code, _, err) = run(&format!("gband-{n}"), &wrong, &args);
        assert_eq!(code, 1, "{mesh}: {err}");
        assert!(err.contains("the exact solution's gradient contradicts its displacement"), "{mesh}: {err}");
        let (code, _, err) = run(&format!("gright-{n}"), &right, &args);
        assert_eq!(code, 0, "{mesh}: {err}");
    }
}

/// Example 7.1 with a dip of depth 0.01 and half-width `w` at x = `x0` on the contact edge
/// y = 0: u_2 -= 0.01 b^3 / w^6, b = (w^2 - (x - x0)^2 - y^2)_+, with the body force and the
/// gradient changed to match, so only the contact condition breaks:
/// u . n = -u_2 = 0.01 > chi = 0 at x0.
fn dip(x0: f64, w: f64) -> String {
    let a = -0.01 / w.powi(6);
    let s = format!("max(0, {:?} - (x - {x0:?})^2 - y^2)", w * w);
    let (bxy, bxx, byy) =
        (format!("24*(x - {x0:?})*y*{s}"), format!("(0 - 6*{s}^2 + 24*(x - {x0:?})^2*{s})"), format!("(0 - 6*{s}^2 + 24*y^2*{s})"));
    format!(
        r#"body_force = ["2*exp(y)*(y^2 + y - 1) - 6*y + 2 - ({a:?})*2*{bxy}", "3*y*(x - 2)*(y + 3)*exp(y) - ({a:?})*({bxx} + 3*{byy})"]
traction = "exact"
dirichlet = "exact"
[material]
mu = 1
lambda = 1
[parts]
contact = "y < 1e-12"
dirichlet = "y > 1 - 1e-12"
[contact]
normal = "outward"
chi = 0
[exact]
u = ["y^2*(y - 1)", "exp(y)*(1 - y)*y*(x - 2) + ({a:?})*{s}^3"]
grad = [["0", "3*y^2 - 2*y"], ["exp(y)*(1 - y)*y + ({a:?})*(0 - 6*(x - {x0:?})*{s}^2)", "(x - 2)*exp(y)*(1 - y - y^2) + ({a:?})*(0 - 6*y*{s}^2)"]]
"#
    )
}

/// A dip 0.008 wide through the obstacle between the contact nodes of structured:4 and 8: the
/// contact conditions are checked at a density tied to the body, not the mesh, so it is refused
/// on every mesh, and by `adapt` before its first level.
#[test]
fn an_exact_solution_through_the_obstacle_between_contact_nodes_is_refused_on_every_mesh() {
    let text = dip(0.547, 0.004);
    for n in [4, 8, 16] {
        let mesh = format!("structured:{n}");
        let (code, _, err) = run(&format!("dip-{n}"), &text, &["solve", "--problem", "v.toml", "--mesh", &mesh]);
        assert_eq!(code, 1, "{mesh}: {err}");
        // the first point found may break u . n <= chi or, on the dip's flank, frictionlessness
        assert!(err.contains("the exact solution does not satisfy") && err.contains("on Gamma_C"), "{mesh}: {err}");
    }
    let (code, out, err) = run("dip-adapt", &text, &["adapt", "--problem", "v.toml", "--mesh", "structured:4", "--levels", "12"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("the exact solution does not satisfy") && err.contains("on Gamma_C"), "{err}");
    assert!(!out.lines().any(|l| l.trim_start().starts_with("1 ")), "no level is computed before the refusal: {out}");
}

/// A stress-free exact solution (a rigid motion written with identities, its tractions
/// round-off such as 2e-19) is accepted: the tractions are judged against a stress scale no less
/// than the one the size of u and grad u implies; a real traction mismatch is still refused.
#[test]
fn a_stress_free_exact_solution_with_round_off_in_its_gradient_is_accepted() {
    let dir = scratch("consistent-exact-rigid");
    let text = "dirichlet = \"exact\"\ntraction = TRACTION\n[material]\nmu = 1\nlambda = 1\n[parts]\ncontact = \"y < 1e-12\"\ndirichlet = \"x < 1e-12\"\n[contact]\nnormal = \"outward\"\nchi = 1\n[exact]\nu = U\n";
    for u in
        ["[\"0.01 - 0.001*y*(sin(x)^2 + cos(x)^2)\", \"0.001*log10(10^x)\"]", "[\"0.01*(cosh(x)^2 - sinh(x)^2) - 0.001*y\", \"0.001*x\"]"]
    {
        std::fs::write(dir.join("p.toml"), text.replace("TRACTION", "\"exact\"").replace("U", u)).unwrap();
        let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", "structured:4"]);
        assert_eq!(code, 0, "{u}: {err}");
    }
    // a traction 1e-7 where sigma(u) n = 0: refused
    let u = "[\"0.01 - 0.001*y\", \"0.001*x\"]";
    std::fs::write(dir.join("p.toml"), text.replace("TRACTION", "[0, \"1e-7\"]").replace("U", u)).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("the traction on Gamma_N"), "{err}");
}

const LARGE_AGAINST_ITS_VARIATION: &str = r#"description = "a displacement large against its variation"
body_force = [0, 0]
traction = "exact"
dirichlet = "exact"
[material]
mu = 1
lambda = 1
[parts]
contact = "y < 1e-12"
dirichlet = "y > 1 - 1e-12"
[contact]
normal = "outward"
chi = 0
[exact]
u = ["0.5 - 1e-9*x", "0"]
"#;

#[test]
fn an_exact_solution_large_against_its_variation_is_accepted_and_a_wrong_gradient_still_refused() {
    let dir = scratch("consistent-exact-exact-solution-large");
    std::fs::write(dir.join("s3.toml"), LARGE_AGAINST_ITS_VARIATION).unwrap();
    for mesh in ["structured:4", "structured:8", "structured:32"] {
        let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "s3.toml", "--mesh", mesh]);
        assert_eq!(code, 0, "{mesh}: {err}");
        assert!(out.contains("error Linf"), "{out}");
    }
    // the same file with a gradient written wrong by a factor of 3 (well above what the
    // differences resolve) is refused, blaming the written entry
    let wrong = LARGE_AGAINST_ITS_VARIATION
        .replace("u = [\"0.5 - 1e-9*x\", \"0\"]", "u = [\"0.5 - 1e-9*x\", \"0\"]\ngrad = [[\"-3e-9\", \"0\"], [\"0\", \"0\"]]");
    std::fs::write(dir.join("wrong.toml"), wrong).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "wrong.toml", "--mesh", "structured:8"]);
    assert_ne!(code, 0);
    assert!(err.contains("gradient contradicts its displacement") && err.contains("`exact.grad[0][0]`"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Refine `mesh` where `near` is, and every seventh triangle elsewhere.
fn refine_near(mesh: &Mesh, near: [f64; 2], radius: f64) -> Refinement {
    let marks: Vec<bool> = (0..mesh.n_triangles())
        .map(|t| {
            let c = mesh.corners(t);
            let centroid = [(c[0][0] + c[1][0] + c[2][0]) / 3.0, (c[0][1] + c[1][1] + c[2][1]) / 3.0];
            signorini::mesh::dist(centroid, near) < radius || t % 7 == 0
        })
        .collect();
    refine(mesh, &marks).unwrap()
}

/// On a refined mesh the body-force check takes the findings of the triangles the refinement
/// left as they were and evaluates only the new ones: level by level, its verdict and findings
/// are those of checking every point again, on Example 7.1, on fb (a kink of f inside some
/// stencils, a load break) and on a file whose body force has a bump of radius 1e-3 that the
/// load points reach only once the triangles around it are refined (refused at the same level,
/// with the same message); every triangle the refinement left as it was is taken from the level
/// before.
#[test]
fn a_refined_mesh_keeps_the_body_force_verdict_of_its_unchanged_triangles() {
    let dir = scratch("consistent-exact-inherited");
    let f = r#"2*exp(y)*(y^2 + y - 1) - 6*y + 2""#;
    std::fs::write(dir.join("bump.toml"), ex71(f, r#"2*exp(y)*(y^2 + y - 1) - 6*y + 2 + 1e6*max(0, 1e-6 - (x-0.37)^2 - (y-0.61)^2)""#))
        .unwrap();
    let bump = signorini::problems::load(dir.join("bump.toml").to_str().unwrap(), &Default::default()).unwrap();
    let problems: [(Box<dyn Problem>, [f64; 2]); 3] = [(Box::new(Ex71), [0.5, 0.0]), (Box::new(Fb), [0.5, 0.0]), (bump, [0.37, 0.61])];
    for (problem, near) in problems {
        let name = problem.name();
        let mut mesh = crate::common::mesh(problem.as_ref(), "structured:8");
        let mut before: Option<BodyForceFindings> = None;
        // the triangles of this level that are their parent unchanged (a parent of one child)
        let mut unchanged = 0;
        let mut refused_at = None;
        for level in 0..9 {
            let nodes = P2Nodes::new(&mesh);
            let every = check_exact(problem.as_ref(), &mesh, &nodes, None);
            let kept = check_exact(problem.as_ref(), &mesh, &nodes, before.as_ref());
            assert_eq!(kept, every, "{name}, level {level}");
            let Ok(Some(findings)) = kept else {
                refused_at = Some(level);
                break;
            };
            assert_eq!(findings.inherited(), unchanged, "{name}, level {level} of {} triangles", mesh.n_triangles());
            let refinement = refine_near(&mesh, near, 0.1);
            let mut children = vec![0; mesh.n_triangles()];
            refinement.parent.iter().for_each(|&p| children[p] += 1);
            unchanged = refinement.parent.iter().filter(|&&p| children[p] == 1).count();
            assert!(unchanged > 0, "{name}, level {level}");
            before = Some(findings.inherit(&mesh, &refinement));
            mesh = refinement.mesh;
        }
        match name {
            "bump.toml" | "bump" => assert!(refused_at.is_some_and(|l| l > 0), "{name}: refused at {refused_at:?}"),
            _ => assert_eq!(refused_at, None, "{name}"),
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The adaptive loop hands each level the findings of the one before.
#[test]
fn the_adaptive_loop_inherits_the_body_force_findings() {
    let mesh = crate::common::mesh(&Ex71, "structured:8");
    let config = signorini::settings::adapt::AdaptConfig { levels: 4, ..Default::default() };
    let out = signorini::adapt::run(&Ex71, mesh, &config, None, &mut |_| std::ops::ControlFlow::Continue(())).unwrap();
    let findings = out.solution.body_force.expect("Example 7.1 has an exact solution");
    assert!(4 * findings.inherited() > out.mesh.n_triangles(), "{} of {}", findings.inherited(), out.mesh.n_triangles());
}
