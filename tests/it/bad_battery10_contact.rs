//! Battery 10, contact data:
//! * F1: `normal = "outward"` with the contact predicate on two sides of the square gave the
//!   corner node one side's normal (a tie of the nearest side): the corner passed the other wall
//!   by 8% of the gap, certified. A contact node whose normal differs between its two contact
//!   edges (a corner of the normal, also a declared normal that jumps there) is refused, naming
//!   the node and both normals (`contact::plausible`, every problem).
//! * F11: `outward` with a `[curves]` circle for one contact group gave a flat contact group the
//!   circle's radial normal (21-40 degrees off): the body passed the wall by 7 times the gap,
//!   certified. Each contact edge now gets its own outward normal, its circle's or the straight
//!   edge's (`Mesh::outward_at`).
//! * F9: `outward` with a predicate found the square's contact sides by sampling the predicate
//!   at k/16: a contact stretch shorter than 1/16 of a side was "on none of the sides", or got
//!   another side's normal and was refused as "nearly tangent". The normal is the contact edge's
//!   own, on any mesh: no sampling.

use super::common::{scratch, signorini_in};

fn repo(path: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// u_h at the probe, from the `solve` output line `u_h(x, y) = (u1, u2)`.
fn probe(out: &str, at: &str) -> [f64; 2] {
    let line = out.lines().find(|l| l.starts_with(&format!("u_h({at})"))).unwrap_or_else(|| panic!("no probe {at}: {out}"));
    let inner = line.split(" = (").nth(1).unwrap().trim_end_matches(')');
    let v: Vec<f64> = inner.split(", ").map(|s| s.parse().unwrap()).collect();
    [v[0], v[1]]
}

const SQUARE: &str = "dirichlet = [0.1, 0]\n[material]\nmu = 1\nlambda = 1\n[parts]\ncontact = \"CONTACT\"\ndirichlet = \"DIRICHLET\"\n[contact]\nnormal = NORMAL\nchi = 0.05\n";

fn square(name: &str, contact: &str, dirichlet: &str, normal: &str, mesh: &str, probes: &[&str]) -> (i32, String, String) {
    let dir = scratch(name);
    let text = SQUARE.replace("CONTACT", contact).replace("DIRICHLET", dirichlet).replace("NORMAL", normal);
    std::fs::write(dir.join("p.toml"), text).unwrap();
    let mut args = vec!["solve", "--problem", "p.toml", "--mesh", mesh];
    for p in probes {
        args.extend(["--probe", p]);
    }
    signorini_in(&dir, &args)
}

#[test]
fn a_corner_between_two_outward_contact_sides_is_refused_naming_the_node_and_both_normals() {
    let (code, out, err) = square("b10-corner", "y < 1e-12 || x > 1 - 1e-12", "x < 1e-12", "\"outward\"", "structured:8", &["1,0"]);
    assert_eq!(code, 1, "{out}{err}");
    for part in [
        "the contact node at (1, 0)",
        "is a corner of the contact normal",
        "(1.000000, 0.000000)",
        "(0.000000, -1.000000)",
        "90.0000 degrees",
        "declare its direction",
    ] {
        assert!(err.contains(part), "{part}: {err}");
    }
    // the advice followed: the bottom's contact ends before the corner; the corner is held at the wall
    let (code, out, err) = square(
        "b10-corner-ended",
        "y < 1e-12 && x < 0.875 || x > 1 - 1e-12",
        "x < 1e-12",
        "\"outward\"",
        "structured:8",
        &["1,0", "1,0.0625"],
    );
    assert_eq!(code, 0, "{err}");
    for at in ["1, 0", "1, 0.0625"] {
        let u = probe(&out, at);
        assert!(u[0] <= 0.05 + 1e-12, "{at}: {u:?} passes the wall x = 1.05");
    }
}

#[test]
fn a_declared_normal_that_jumps_at_a_contact_vertex_is_a_corner_too() {
    // (0, -1) on the bottom, (1, 0) on the right side and at the corner itself
    let jump = "[\"max(0, signum(x - 1 + 1e-12))\", \"max(0, signum(x - 1 + 1e-12)) - 1\"]";
    let (code, out, err) = square("b10-jump", "y < 1e-12 || x > 1 - 1e-12", "x < 1e-12", jump, "structured:8", &[]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("the contact node at (1, 0)") && err.contains("is a corner of the contact normal"), "{err}");
    // a declared constant direction has no corner: the bottom alone with it solves
    let (code, _, err) = square("b10-flat", "y < 1e-12", "x < 1e-12", "[0, -1]", "structured:8", &[]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn outward_gives_a_flat_contact_group_its_own_normal_beside_a_circle_group() {
    let dir = scratch("b10-circle-flat");
    let mesh = format!("gmsh:{}", repo("experiments/meshes/quarter_disc.msh").display());
    // the arc (a circle) and the flat bottom both in contact; the vertex (1, 0) where they meet
    // at a right angle is held by a point constraint, so it carries no contact constraint
    let problem = "dirichlet = [0, 0]\nbody_force = [0, \"-2\"]\n[[point_constraints]]\nat = [1, 0]\nu = [0, 0]\n[material]\nmu = 1\nlambda = 1\n[parts]\ncontact = [\"arc\", \"bottom\"]\ndirichlet = [\"left\"]\n[curves]\narc = { circle = { centre = [0, 0], radius = 1 } }\n[contact]\nnormal = \"outward\"\nchi = 0.02\n";
    std::fs::write(dir.join("p.toml"), problem).unwrap();
    // battery 14 (F3): the point constraint holding the vertex takes a force (a quarter of the
    // nodal forces' scale), so each mesh would solve another problem: it is now refused, and the
    // bottom's normal beside the arc can no longer be checked on this mesh with it
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", &mesh, "--probe", "0.5,0", "--probe", "0.75,0"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("the point constraint at (1, 0) prescribes u_1 = 0") && err.contains("removing a rigid motion"), "{err}");
    // what is left to check positively on this mesh: the flat group in contact beside the (free)
    // arc, held at the floor along its own normal (0, -1). The arc and the bottom both in contact
    // need the meeting vertex out of contact, which only a point constraint taking a force did
    let flat = problem
        .replace("[[point_constraints]]\nat = [1, 0]\nu = [0, 0]\n", "")
        .replace("contact = [\"arc\", \"bottom\"]", "contact = [\"bottom\"]\nneumann = [\"arc\"]")
        .replace("[curves]\narc = { circle = { centre = [0, 0], radius = 1 } }\n", "");
    std::fs::write(dir.join("p.toml"), &flat).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", &mesh, "--probe", "0.5,0", "--probe", "0.75,0"]);
    assert_eq!(code, 0, "{err}");
    for at in ["0.5, 0", "0.75, 0"] {
        let u = probe(&out, at);
        assert!(u[1] >= -0.02 - 1e-12, "{at}: {u:?} passes the floor y = -0.02");
    }
    assert!((probe(&out, "0.75, 0")[1] + 0.02).abs() < 1e-9, "the bottom presses on the floor: {out}");
    // without the point constraint the meeting vertex is a corner: refused, with both normals
    std::fs::write(dir.join("p.toml"), problem.replace("[[point_constraints]]\nat = [1, 0]\nu = [0, 0]\n", "")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", &mesh]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("the contact node at (1, 0)") && err.contains("corner") && err.contains("90.0000 degrees"), "{err}");
}

#[test]
fn outward_finds_a_contact_stretch_shorter_than_a_sixteenth_of_a_side() {
    // the top edge of the right side (1/32 long) alone
    let (code, out, err) =
        square("b10-tip", "x > 1 - 1e-12 && y > 0.96875", "x < 1e-12 && y > 0.5", "\"outward\"", "structured:32", &["1,0.984375"]);
    assert_eq!(code, 0, "{err}");
    assert!(probe(&out, "1, 0.984375")[0] <= 0.05 + 1e-12, "{out}");
    // beside the bottom, with its own normal (1, 0), not the bottom's (0, -1)
    let (code, _, err) =
        square("b10-tip-bottom", "y < 1e-12 || x > 1 - 1e-12 && y > 0.96875", "x < 1e-12 && y > 0.5", "\"outward\"", "structured:32", &[]);
    assert_eq!(code, 0, "{err}");
}

/// F4: a stress-free exact solution (a rigid motion written with identities) was refused as
/// "tangential traction 2e-19": the tractions were judged against the largest |sigma(u) n|, which
/// was that round-off. The stress scale is now no less than the one the size of u and grad u
/// implies; a real traction mismatch is still refused.
#[test]
fn a_stress_free_exact_solution_with_round_off_in_its_gradient_is_accepted() {
    let dir = scratch("b10-rigid");
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

/// An annulus 0.5 < r < 1 of `n` sectors and `layers` rings, the hole (a closed loop, on its
/// circle) contact, the outer circle clamped; the gap closes on x > 0 only, the normal is the
/// body's outward one (toward the centre).
struct Hole;

impl signorini::problems::Problem for Hole {
    fn name(&self) -> &str {
        "hole"
    }
    fn description(&self) -> &str {
        "contact on a closed loop"
    }
    fn material(&self) -> signorini::problems::Material {
        signorini::problems::Material { mu: 1.0, zeta: 1.0 }
    }
    fn part_of(&self, _x: [f64; 2]) -> signorini::problems::Part {
        signorini::problems::Part::Neumann
    }
    fn body_force(&self, _x: [f64; 2]) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn traction(&self, _x: [f64; 2], _n: [f64; 2]) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn dirichlet(&self, _x: [f64; 2]) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn contact_normal(&self, _x: [f64; 2], outward: [f64; 2]) -> [f64; 2] {
        outward
    }
    fn gap(&self, x: [f64; 2]) -> f64 {
        0.002 - 0.01 * x[0].max(0.0) / 0.5
    }
}

/// Rings at the radii `radii` (0.5 first, 1 last), `n` sectors each.
fn annulus(n: usize, radii: &[f64]) -> signorini::mesh::Mesh {
    use signorini::mesh::BoundaryEdge;
    use signorini::problems::{Curve, Part};
    let v = |k: usize, j: usize| k * n + j % n;
    let layers = radii.len() - 1;
    let mut vertices = Vec::new();
    for &r in radii {
        for j in 0..n {
            let t = std::f64::consts::TAU * j as f64 / n as f64;
            vertices.push([r * t.cos(), r * t.sin()]);
        }
    }
    let mut triangles = Vec::new();
    for k in 0..layers {
        for j in 0..n {
            let (a, b, c, d) = (v(k, j), v(k + 1, j), v(k + 1, j + 1), v(k, j + 1));
            triangles.extend([[a, b, c], [a, c, d]]);
        }
    }
    let inner = Curve::Circle { centre: [0.0, 0.0], radius: 0.5 };
    let mut boundary: Vec<BoundaryEdge> =
        (0..n).map(|j| BoundaryEdge { v: [v(0, j + 1), v(0, j)], part: Part::Contact, curve: Some(inner) }).collect();
    boundary.extend((0..n).map(|j| BoundaryEdge { v: [v(layers, j), v(layers, j + 1)], part: Part::Dirichlet, curve: None }));
    let mesh = signorini::mesh::Mesh { vertices, triangles, boundary };
    mesh.check().unwrap();
    mesh
}

/// F7: on a closed contact loop, one active arc through the loop's start was reported as two
/// zones, and zone_min/zone_max as the whole loop. It is one zone [s_first, s_last + L].
#[test]
fn an_active_arc_through_the_start_of_a_closed_contact_loop_is_one_zone() {
    let mesh = annulus(32, &[0.5, 0.625, 0.75, 0.875, 1.0]);
    let sol = super::common::solve_on(&Hole, &mesh);
    let loop_length = 32.0 * 2.0 * 0.5 * (std::f64::consts::PI / 32.0).sin();
    let zones = sol.contact_zones();
    assert_eq!(zones.len(), 1, "{zones:?}");
    let z = zones[0];
    // pressed on x > 0 only: the arc crosses the x axis at (0.5, 0), the loop's start (the hole's
    // boundary runs clockwise, the body on its left: from above the axis to below it)
    assert!(z.s[0] < loop_length && z.s[1] > loop_length && z.s[1] - z.s[0] < 0.5 * loop_length, "{z:?} (L = {loop_length})");
    assert!(z.from[1] > 0.0 && z.to[1] < 0.0 && z.from[0] > 0.0 && z.to[0] > 0.0, "{z:?}");
    // its length is that of the active nodes: (active - 1) half-edges
    let half = 0.5 * loop_length / 32.0;
    assert!(((z.s[1] - z.s[0]) / half - (sol.active_count() - 1) as f64).abs() < 1e-9, "{z:?}: {} active", sol.active_count());
    assert_eq!(sol.contact_zone(), Some(z.s));
}

/// F10: refinement onto a concave curve (a hole's circle) turned a triangle over where the first
/// layer is thinner than the chord's sagitta, and the error blamed the vertex order. It names the
/// curve, the edge, the new vertex and the remedy.
#[test]
fn refinement_that_turns_a_triangle_over_on_a_curve_says_so() {
    let mut mesh = annulus(16, &[0.5, 0.505, 0.6, 0.8, 1.0]);
    let mut error = None;
    for _ in 0..3 {
        match signorini::mesh::refine::refine(&mesh, &vec![true; mesh.n_triangles()]) {
            Ok(r) => mesh = r.mesh,
            Err(e) => {
                error = Some(e.to_string());
                break;
            }
        }
    }
    let error = error.expect("refinement onto the hole turns a triangle over");
    for part in [
        "refinement put the new vertex of the contact boundary edge",
        "the circle of centre (0, 0) and radius 0.5",
        "turned triangle",
        "thinner there than the curve's sagitta",
        "mesh the body finer near the curve",
    ] {
        assert!(error.contains(part), "{part}: {error}");
    }
    assert!(!error.contains("counter-clockwise"), "{error}");
}
