//! Problem files (`experiments/problems/*.toml`, `problems::file`): the files stating the
//! built-in problems give the same data, solutions, active sets, estimates and errors as the
//! built-ins; `hertz.toml` maps its physical groups; every kind of bad file is an error naming
//! the file, the key and the position.

use crate::common;
use crate::common::{fixture, parse_problem, scratch, signorini_in};
use common::*;
use signorini::adapt;
use signorini::norms;
use signorini::problems::{self, Curve, FileProblem, Material, Part, Problem};
use signorini::settings::adapt::AdaptConfig;
use std::path::{Path, PathBuf};
use std::process::Command;

fn file(name: &str) -> FileProblem {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/problems").join(format!("{name}.toml"));
    FileProblem::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn max_abs(v: &[[f64; 2]]) -> f64 {
    v.iter().fold(0.0f64, |s, u| s.max(u[0].abs()).max(u[1].abs()))
}

fn close(a: f64, b: f64, rel: f64, scale: f64) -> bool {
    (a - b).abs() <= rel * scale.max(a.abs()).max(b.abs())
}

/// Points inside and on the boundary of the unit square (a fixed pseudo-random set).
fn points() -> Vec<[f64; 2]> {
    let mut s = 0x2545f491u64;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut p: Vec<[f64; 2]> = (0..200).map(|_| [next(), next()]).collect();
    for k in 0..=16 {
        let t = k as f64 / 16.0;
        p.extend([[t, 0.0], [1.0, t], [t, 1.0], [0.0, t]]);
    }
    p
}

/// The unit square's outward normal at the boundary point `x`, of a side holding `x` whose
/// midpoint is in `b`'s contact part: what the mesh gives `normal = "outward"` there.
fn contact_side_outward(b: &dyn Problem, x: [f64; 2]) -> [f64; 2] {
    let sides = [
        ([0.5, 0.0], [0.0, -1.0], x[1] == 0.0),
        ([1.0, 0.5], [1.0, 0.0], x[0] == 1.0),
        ([0.5, 1.0], [0.0, 1.0], x[1] == 1.0),
        ([0.0, 0.5], [-1.0, 0.0], x[0] == 0.0),
    ];
    sides.iter().find(|(m, _, on)| *on && b.part_of(*m) == Part::Contact).map(|s| s.1).expect("a contact side holds x")
}

/// The data of the file and of the built-in agree at every point: loads, Dirichlet data, gap,
/// normal, parts, exact solution and its gradient (ex71's differentiated symbolically by exmex).
#[test]
fn built_ins_as_files_state_the_same_data() {
    for (name, builtin) in [
        ("ex71", problems::by_name("ex71").unwrap()),
        ("ex72", problems::by_name("ex72").unwrap()),
        ("fb", problems::by_name("fb").unwrap()),
    ] {
        let f = file(name);
        let b = builtin.as_ref();
        assert_eq!(f.name(), name);
        assert_eq!(f.material(), b.material(), "{name}: material");
        assert_eq!(f.required_vertices(), b.required_vertices(), "{name}: required vertices");
        assert_eq!(f.load_breaks(), b.load_breaks(), "{name}: load breaks");
        assert_eq!(f.exact().is_some(), b.exact().is_some(), "{name}: exact solution");
        for x in points() {
            let ctx = format!("{name} at {x:?}");
            let on_boundary = x[0] == 0.0 || x[0] == 1.0 || x[1] == 0.0 || x[1] == 1.0;
            if on_boundary {
                assert_eq!(f.part_of(x), b.part_of(x), "{ctx}: part");
            }
            if b.part_of(x) == Part::Contact && on_boundary {
                let o = contact_side_outward(b, x);
                assert_eq!(f.contact_normal(x, o), b.contact_normal(x, o), "{ctx}: normal");
            }
            for (what, u, v) in [("body force", f.body_force(x), b.body_force(x)), ("dirichlet", f.dirichlet(x), b.dirichlet(x))] {
                for i in 0..2 {
                    assert!(close(u[i], v[i], 1e-13, 1.0), "{ctx}: {what}[{i}] {} vs {}", u[i], v[i]);
                }
            }
            for n in [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0], [0.6, 0.8]] {
                let (u, v) = (f.traction(x, n), b.traction(x, n));
                for i in 0..2 {
                    assert!(close(u[i], v[i], 1e-13, 1.0), "{ctx}: traction[{i}] with n = {n:?}: {} vs {}", u[i], v[i]);
                }
            }
            assert!(close(f.gap(x), b.gap(x), 1e-13, 1.0), "{ctx}: gap {} vs {}", f.gap(x), b.gap(x));
            if let (Some(e), Some(g)) = (f.exact(), b.exact()) {
                let (u, v) = (e.u(x), g.u(x));
                let (gu, gv) = (e.grad(x), g.grad(x));
                for i in 0..2 {
                    assert!(close(u[i], v[i], 1e-13, 1.0), "{ctx}: u[{i}] {} vs {}", u[i], v[i]);
                    for j in 0..2 {
                        assert!(close(gu[i][j], gv[i][j], 1e-13, 1.0), "{ctx}: grad[{i}][{j}] {} vs {}", gu[i][j], gv[i][j]);
                    }
                }
            }
        }
    }
}

/// Solved on a few meshes, the file and the built-in give the same active sets, nodal values and
/// contact forces within 1e-9 relative, and the same true errors where there is an exact
/// solution; the adaptive loop takes the same steps (same meshes, estimates, errors).
#[test]
fn built_ins_as_files_give_the_same_solutions() {
    for name in ["ex71", "ex72", "fb"] {
        let (f, b) = (file(name), problems::by_name(name).unwrap());
        for spec in ["structured:6", "symmetric:8", "structured:16"] {
            let ctx = format!("{name} on {spec}");
            let (mf, mb) = (mesh(&f, spec), mesh(b.as_ref(), spec));
            assert_eq!(mf.boundary, mb.boundary, "{ctx}: boundary parts");
            let (sf, sb) = (solve_on(&f, &mf), solve_on(b.as_ref(), &mb));
            assert_eq!(sf.active, sb.active, "{ctx}: active sets");
            assert!(sf.active.iter().any(|&a| a), "{ctx}: some contact is active");
            let scale = max_abs(&sb.u);
            let du = sf.u.iter().zip(&sb.u).fold(0.0f64, |s, (a, c)| s.max((a[0] - c[0]).abs()).max((a[1] - c[1]).abs()));
            assert!(du <= 1e-9 * scale, "{ctx}: nodal values differ by {du:e} (scale {scale:e})");
            let lscale = sb.lambda.iter().fold(0.0f64, |s, l| s.max(l.abs()));
            let dl = sf.lambda.iter().zip(&sb.lambda).fold(0.0f64, |s, (a, c)| s.max((a - c).abs()));
            assert!(dl <= 1e-9 * lscale, "{ctx}: contact forces differ by {dl:e} (scale {lscale:e})");
            if let (Some(ef), Some(eb)) = (f.exact(), b.exact()) {
                let errf = norms::linf_error(&mf, &sf, &|x| ef.u(x));
                let errb = norms::linf_error(&mb, &sb, &|x| eb.u(x));
                assert!(close(errf.linf_quadrature, errb.linf_quadrature, 1e-9, 0.0), "{ctx}: error {errf:?} vs {errb:?}");
                assert!(close(errf.linf_nodal, errb.linf_nodal, 1e-9, 0.0), "{ctx}: nodal error {errf:?} vs {errb:?}");
            }
        }
        let config = AdaptConfig { levels: 5, ..Default::default() };
        let run = |p: &dyn Problem| {
            let exact = p.exact();
            let reference = exact.map(|e| move |x: [f64; 2]| e.u(x));
            adapt::run(p, mesh(p, "structured:4"), &config, reference.as_ref().map(|r| r as norms::Reference), &mut |_| {
                std::ops::ControlFlow::Continue(())
            })
            .unwrap()
            .records
        };
        let (rf, rb) = (run(&f), run(b.as_ref()));
        assert_eq!(rf.len(), rb.len());
        for (a, c) in rf.iter().zip(&rb) {
            let ctx = format!("{name} adaptive level {}", c.level);
            assert_eq!((a.ndof, a.active_nodes, a.n_elements), (c.ndof, c.active_nodes, c.n_elements), "{ctx}: mesh and active set");
            assert!(close(a.terms.estimate, c.terms.estimate, 1e-9, 0.0), "{ctx}: estimate {} vs {}", a.terms.estimate, c.terms.estimate);
            if let (Some(x), Some(y)) = (a.err_quadrature, c.err_quadrature) {
                assert!(close(x, y, 1e-9, 0.0), "{ctx}: error {x} vs {y}");
            }
        }
    }
}

/// The Hertz problem file: its physical groups, circles, material and data.
#[test]
fn hertz_file_names_its_groups() {
    let p = file("hertz");
    assert_eq!(p.part_of_group("top"), Some(Part::Dirichlet));
    assert_eq!(p.part_of_group("contact"), Some(Part::Contact));
    assert_eq!(p.part_of_group("free"), Some(Part::Neumann));
    assert_eq!(p.part_of_group("arc"), None);
    assert_eq!(p.groups(), ["contact", "free", "top"]);
    let circle = Curve::Circle { centre: [0.0, 1.0], radius: 1.0 };
    assert_eq!(p.curve_of_group("contact"), Some(circle));
    assert_eq!(p.curve_of_group("free"), Some(circle));
    assert_eq!(p.curve_of_group("top"), None);
    assert_eq!(p.material(), Material::from_young(1000.0, 0.3));
    assert_eq!(p.dirichlet([0.3, 1.0]), [0.0, -0.005]);
    assert_eq!(p.body_force([0.1, 0.5]), [0.0, 0.0]);
    assert_eq!(p.traction([0.8, 0.4], [0.8, -0.6]), [0.0, 0.0]);
    let x = [0.2, 1.0 - (1.0f64 - 0.04).sqrt()];
    // declared: the arc's outward normal there does not change it
    assert_eq!(p.contact_normal(x, [0.6, -0.8]), [0.0, -1.0]);
    assert_eq!(p.gap(x), x[1]);
    assert!(p.exact().is_none());
}

const GOOD: &str = r#"
description = "a block on a flat obstacle"
body_force = [0, "-1"]

[material]
E = 10
nu = 0.25
model = "plane_stress"

[parts]
contact = "y < 1e-12"
dirichlet = "y > 1 - 1e-12"

[contact]
normal = "outward"
chi = "0.01*x"
"#;

fn err(text: &str) -> String {
    match FileProblem::parse(Path::new("problems/bad.toml"), text) {
        Ok(_) => panic!("accepted a bad problem file:\n{text}"),
        Err(e) => {
            let s = e.to_string();
            assert!(s.starts_with("problems/bad.toml:"), "the error does not name the file: {s}");
            s
        }
    }
}

/// `GOOD` with `from` replaced by `to` (which must occur).
fn edit(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "{from:?}");
    GOOD.replacen(from, to, 1)
}

#[test]
fn a_good_file_reads_and_plane_stress_is_plane_stress() {
    let p = FileProblem::parse(Path::new("good.toml"), GOOD).unwrap();
    let m = p.material();
    // plane stress: zeta = E nu / (1 - nu^2), mu = E / (2 (1 + nu))
    assert!((m.zeta - 10.0 * 0.25 / (1.0 - 0.0625)).abs() < 1e-14 && (m.mu - 4.0).abs() < 1e-14, "{m:?}");
    assert_eq!(p.part_of([0.5, 0.0]), Part::Contact);
    assert_eq!(p.part_of([0.5, 1.0]), Part::Dirichlet);
    assert_eq!(p.part_of([0.0, 0.5]), Part::Neumann);
    assert_eq!(p.contact_normal([0.25, 0.0], [0.0, -1.0]), [0.0, -1.0]);
    assert_eq!(p.body_force([0.3, 0.3]), [0.0, -1.0]);
    assert_eq!(p.gap([0.5, 0.0]), 0.005);
    // predicates: && binds tighter than ||
    let q =
        FileProblem::parse(Path::new("q.toml"), &edit("contact = \"y < 1e-12\"", "contact = \"y < 1e-12 && x >= 0.5 || x > 1 - 1e-12\""))
            .unwrap();
    assert_eq!(q.part_of([0.25, 0.0]), Part::Neumann);
    assert_eq!(q.part_of([0.75, 0.0]), Part::Contact);
    assert_eq!(q.part_of([1.0, 0.5]), Part::Contact);
    assert_eq!(q.part_of([0.5, 1.0]), Part::Dirichlet);
    // outward on two sides: each edge's own outward normal (the mesh's), whatever side is nearer
    assert_eq!(q.contact_normal([1.0, 0.02], [1.0, 0.0]), [1.0, 0.0]);
    assert_eq!(q.contact_normal([0.98, 0.0], [0.0, -1.0]), [0.0, -1.0]);
}

#[test]
fn toml_syntax_errors_give_line_and_column() {
    let e = err(&edit("chi = \"0.01*x\"", "chi = = 1"));
    assert!(e.starts_with("problems/bad.toml:16:"), "{e}");
}

#[test]
fn unknown_and_missing_keys_are_errors() {
    let e = err(&edit("model = \"plane_stress\"", "model = \"plane_stress\"\npoisson = 0.3"));
    assert!(e.contains("unknown field `poisson`") && e.starts_with("problems/bad.toml:9:"), "{e}");
    let e = err(&edit("chi = \"0.01*x\"", ""));
    assert!(e.contains("missing field `chi`"), "{e}");
    let e = err(&edit("model = \"plane_stress\"", ""));
    assert!(e.contains("key `material.model`") && e.contains("plane_strain"), "{e}");
    let e = err(&edit("model = \"plane_stress\"", "model = \"plane\""));
    assert!(e.contains("key `material.model`") && e.starts_with("problems/bad.toml:8:"), "{e}");
    let e = err(&edit("nu = 0.25", "nu = 0.25\nmu = 3"));
    assert!(e.contains("key `material`") && e.contains("Lamé"), "{e}");
}

#[test]
fn expression_errors_name_the_key_and_what_exmex_said() {
    let e = err(&edit("chi = \"0.01*x\"", "chi = \"0.01*x +* (\""));
    assert!(e.starts_with("problems/bad.toml:16:7: key `contact.chi`: cannot parse"), "{e}");
    let e = err(&edit("chi = \"0.01*x\"", "chi = \"0.01*z\""));
    assert!(e.starts_with("problems/bad.toml:16:7: key `contact.chi`: unknown variable `z`"), "{e}");
    // nx, ny only in a traction
    let e = err(&edit("body_force = [0, \"-1\"]", "body_force = [0, \"nx\"]"));
    assert!(e.contains("key `body_force[1]`") && e.contains("unknown variable `nx`"), "{e}");
    let e = err(&edit("contact = \"y < 1e-12\"", "contact = \"y + 1e-12\""));
    assert!(e.contains("key `parts.contact`") && e.contains("a comparison"), "{e}");
    let e = err(&edit("body_force = [0, \"-1\"]", "body_force = [0, \"-1\", 2]"));
    assert!(e.starts_with("problems/bad.toml:3:"), "{e}");
    let e = err(&edit("body_force = [0, \"-1\"]", "body_force = \"exact\""));
    assert!(e.contains("key `body_force`") && e.contains("write it out"), "{e}");
    let e = err(&edit("body_force = [0, \"-1\"]", "traction = \"exact\""));
    assert!(e.contains("key `traction`") && e.contains("[exact]"), "{e}");
    // an exact solution exmex cannot differentiate, without its gradient
    let e = err(&format!("{GOOD}\n[exact]\nu = [\"abs(x - 0.5)\", \"0\"]\n"));
    assert!(e.contains("key `exact.u[0]`") && e.contains("exact.grad"), "{e}");
}

#[test]
fn constants_resolve_in_any_order_and_bad_ones_are_errors() {
    let text = edit("chi = \"0.01*x\"", "chi = \"b*x\"") + "\n[constants]\nb = \"2*a\"\na = \"sqrt(2) - 1\"\n";
    let p = FileProblem::parse(Path::new("c.toml"), &text).unwrap();
    assert_eq!(p.gap([0.5, 0.0]), 2.0 * (std::f64::consts::SQRT_2 - 1.0) * 0.5);
    let e = err(&(GOOD.to_string() + "\n[constants]\na = \"2*b\"\nb = \"a\"\n"));
    assert!(e.contains("key `constants.a`") && e.contains("cycle"), "{e}");
    let e = err(&(GOOD.to_string() + "\n[constants]\na = \"2*q\"\n"));
    assert!(e.contains("key `constants.a`") && e.contains("unknown variable `q`"), "{e}");
    let e = err(&(GOOD.to_string() + "\n[constants]\nx = 2\n"));
    assert!(e.contains("key `constants.x`"), "{e}");
}

/// A study's run can give a constant another value: constants defined from it follow; a constant
/// the file does not declare, or constants for a built-in problem, are errors.
#[test]
fn constants_can_be_overridden_from_a_run() {
    use std::collections::BTreeMap;
    let text = edit("chi = \"0.01*x\"", "chi = \"b*x\"") + "\n[constants]\nb = \"2*a\"\na = 1\n";
    let set = |k: &str, v: f64| BTreeMap::from([(k.to_string(), v)]);
    let p = FileProblem::parse_with(Path::new("c.toml"), &text, &set("a", 3.0)).unwrap();
    assert_eq!(p.gap([0.5, 0.0]), 3.0);
    let e = FileProblem::parse_with(Path::new("c.toml"), &text, &set("q", 3.0)).unwrap_err().to_string();
    assert!(e.starts_with("c.toml") && e.contains("constants.q") && e.contains("declares: a, b"), "{e}");
    let e = FileProblem::parse_with(Path::new("c.toml"), &text, &set("a", f64::NAN)).unwrap_err().to_string();
    assert!(e.contains("finite"), "{e}");
    let e = signorini::problems::load("ex71", &set("a", 1.0)).err().unwrap().to_string();
    assert!(e.contains("built in") && e.contains("ex71"), "{e}");
    let hertz = signorini::problems::load("experiments/problems/hertz.toml", &set("delta", 0.002)).unwrap();
    assert_eq!(hertz.dirichlet([0.3, 1.0]), [0.0, -0.002]);
}

/// A problem whose parts are physical groups only, on a built-in mesh (which has none): a clear
/// error instead of a singular system.
#[test]
fn groups_only_problem_on_a_built_in_mesh_is_an_error() {
    let e = signorini::mesh::MeshSpec::parse("structured:4").unwrap().build(&file("hertz")).unwrap_err().to_string();
    assert!(e.contains("physical group") && e.contains("structured:4") && e.contains("gmsh:"), "{e}");
}

#[test]
fn group_errors() {
    let groups =
        edit("contact = \"y < 1e-12\"\ndirichlet = \"y > 1 - 1e-12\"", "contact = [\"arc\"]\ndirichlet = [\"top\"]\nneumann = [\"side\"]")
            .replace("normal = \"outward\"", "normal = [0, -1]");
    FileProblem::parse(Path::new("g.toml"), &groups).unwrap();
    // a curve for a group named nowhere
    let e = err(&(groups.clone() + "\n[curves]\nrim = { circle = { centre = [0, 1], radius = 1 } }\n"));
    assert!(e.contains("key `curves.rim`") && e.contains("referenced nowhere") && e.contains("arc, side, top"), "{e}");
    // a typo in [parts] ("arcc") of the group [curves] names ("arc"): reported at [parts], both named
    let typo =
        groups.replace("contact = [\"arc\"]", "contact = [\"arcc\"]") + "\n[curves]\narc = { circle = { centre = [0, 1], radius = 1 } }\n";
    let e = err(&typo);
    assert!(e.contains("key `parts.contact`") && e.contains("\"arc\"") && e.contains("\"arcc\"") && e.contains("misspelt"), "{e}");
    // a group in two parts
    let e = err(&groups.replace("neumann = [\"side\"]", "neumann = [\"top\"]"));
    assert!(e.contains("key `parts.neumann`") && e.contains("\"top\""), "{e}");
    // outward without a circle: the straight edges' own outward normals
    let p = FileProblem::parse(Path::new("g.toml"), &groups.replace("normal = [0, -1]", "normal = \"outward\"")).unwrap();
    assert_eq!(p.contact_normal([0.6, 0.2], [0.0, -1.0]), [0.0, -1.0]);
    // with a circle, the mesh gives the circle's normal on the group's edges (Curve::outward)
    let with_circle =
        groups.replace("normal = [0, -1]", "normal = \"outward\"") + "\n[curves]\narc = { circle = { centre = [0, 1], radius = 1 } }\n";
    let p = FileProblem::parse(Path::new("g.toml"), &with_circle).unwrap();
    let o = p.curve_of_group("arc").unwrap().outward([0.6, 0.2], [0.0, -1.0]);
    let n = p.contact_normal([0.6, 0.2], o);
    assert!((n[0] - 0.6).abs() < 1e-15 && (n[1] + 0.8).abs() < 1e-15, "{n:?}");
}

#[test]
fn unknown_problem_lists_the_built_ins_and_says_a_file_is_accepted() {
    let e = problems::by_name("ex37").err().unwrap().to_string();
    for k in problems::KNOWN {
        assert!(e.contains(k), "{e}");
    }
    assert!(e.contains(".toml"), "{e}");
    let e = problems::by_name("no/such/problem.toml").err().unwrap().to_string();
    assert!(e.starts_with("no/such/problem.toml: cannot read"), "{e}");
}

/// A manifest names a problem file relative to itself; the record keeps the name as written,
/// the provenance names the file and its SHA-256.
#[test]
fn manifests_resolve_problem_files_relative_to_themselves() {
    use signorini::manifest::Manifest;
    use signorini::study::{self, RunOptions};
    let root = std::env::temp_dir().join(format!("signorini-problem-files-{}", std::process::id()));
    let (experiments, results) = (root.join("experiments"), root.join("results"));
    std::fs::create_dir_all(experiments.join("problems")).unwrap();
    let problem = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex72.toml")).unwrap();
    std::fs::write(experiments.join("problems/wedge.toml"), &problem).unwrap();
    let text = "[defaults]\nproblem = \"problems/wedge.toml\"\nmesh = \"structured:2\"\n[[run]]\nid = \"a\"\nlevels = 2\n";
    let file = experiments.join("wedge.toml");
    std::fs::write(&file, text).unwrap();
    let manifest = Manifest::load(&file).unwrap();
    let opts = RunOptions {
        quick: false,
        shard: None,
        fresh: true,
        replace: false,
        results: results.clone(),
        progress: false,
        wait_for_lock: false,
    };
    study::run_study(&manifest, &opts).unwrap();
    let runs = signorini::records::StudyDir::new(&results, "wedge").read_runs().unwrap();
    assert_eq!(runs[0].run.problem, "problems/wedge.toml");
    let builtin = adapt::run(
        &problems::Ex72,
        mesh(&problems::Ex72, "structured:2"),
        &AdaptConfig { levels: 2, ..Default::default() },
        None,
        &mut |_| std::ops::ControlFlow::Continue(()),
    )
    .unwrap();
    assert_eq!(runs[0].levels.iter().map(|l| l.ndof).collect::<Vec<_>>(), builtin.records.iter().map(|l| l.ndof).collect::<Vec<_>>());
    let prov: serde_json::Value = serde_json::from_slice(&std::fs::read(results.join("wedge/provenance.json")).unwrap()).unwrap();
    let files = prov["problem_files"].as_array().expect("problem_files in the provenance");
    assert_eq!(files.len(), 1);
    assert!(files[0]["path"].as_str().unwrap().ends_with("experiments/problems/wedge.toml"), "{files:?}");
    assert_eq!(files[0]["sha256"].as_str().unwrap(), signorini::base::digest::sha256_hex(&problem));
    // a missing file is an error naming the manifest's key
    let bad = Manifest::parse(&file, &text.replace("wedge.toml\"", "nothing.toml\"")).unwrap_err().to_string();
    assert!(bad.contains("key `run[0].problem`") && bad.contains("cannot read"), "{bad}");
    std::fs::remove_dir_all(&root).unwrap();
}

/// Built-in studies keep their provenance as before: no `problem_files` key.
#[test]
fn built_in_problems_add_nothing_to_the_provenance() {
    let m = signorini::manifest::Manifest::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/ex72.toml")).unwrap();
    assert!(m.problem_files().is_empty());
}

mod random_input {
    use super::*;
    use proptest::prelude::*;

    /// Strings of expression characters: operators, parentheses, variables, numbers, names.
    fn expression() -> impl Strategy<Value = String> {
        prop_oneof![
            "[-+*/^(), xyna0-9.eE<>=&|]{0,24}",
            proptest::collection::vec(
                proptest::sample::select(
                    &[
                        "x", "y", "nx", "a", "q", "1e-3", "2", ".5", "+", "-", "*", "/", "^", "(", ")", "sqrt", "max", "abs", ",", "<",
                        "&&", "||", "e", "PI"
                    ][..]
                ),
                0..12
            )
            .prop_map(|v| v.join(" ")),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 1024, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(7), ..ProptestConfig::default() })]

        /// Random expressions in every expression-bearing place: never a panic, and an accepted file
        /// evaluates everywhere without one; a rejection names the file and a key.
        #[test]
        fn random_expressions_never_panic(chi in expression(), f in expression(), c in expression(), pred in expression(), constant in expression()) {
            let text = GOOD
                .replace("chi = \"0.01*x\"", &format!("chi = {chi:?}"))
                .replace("body_force = [0, \"-1\"]", &format!("body_force = [{f:?}, 0]\ntraction = [0, {c:?}]"))
                .replace("contact = \"y < 1e-12\"", &format!("contact = {pred:?}"))
                + &format!("\n[constants]\na = {constant:?}\n");
            match FileProblem::parse(Path::new("problems/random.toml"), &text) {
                Ok(p) => {
                    for x in [[0.5, 0.0], [0.0, 0.0], [1.0, 0.25]] {
                        let _ = (p.gap(x), p.body_force(x), p.traction(x, [0.0, -1.0]), p.part_of(x), p.contact_normal(x, [0.0, -1.0]));
                    }
                }
                Err(e) => {
                    let m = e.to_string();
                    prop_assert!(m.starts_with("problems/random.toml:") && (m.contains("key `") || m.contains("TOML")), "{}", m);
                }
            }
        }

        #[test]
        fn random_text_never_panics(text in "\\PC{0,200}") {
            if let Err(e) = FileProblem::parse(Path::new("problems/random.toml"), &text) {
                prop_assert!(e.to_string().starts_with("problems/random.toml:"), "{}", e);
            }
        }
    }
}

const QD: &str = "gmsh_renumbered/quarter_disc.toml";

const SQUARE: &str = "bad_data_square.toml";

#[test]
fn a_pair_with_a_third_value_is_refused_not_cut_to_two() {
    let ex71 = std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex71.toml")).unwrap();
    let dir = scratch("problem-files-pairs");
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

/// The square problem with a point constraint and an exact solution added, every pair valid.
fn with_every_pair() -> String {
    let base = fixture(SQUARE);
    format!(
        "required_vertices = [[0.5, 0]]\n{base}\n[[point_constraints]]\nat = [0.5, 1]\nu = [\"free\", 0]\n\n[exact]\nu = [\"0\", \"0\"]\ngrad = [[\"0\", \"0\"], [\"0\", \"0\"]]\n"
    )
}

#[test]
fn every_pair_valued_key_refuses_a_third_value() {
    let good = with_every_pair();
    assert!(parse_problem(&good).is_ok(), "{:?}", parse_problem(&good).err());
    let normal = good.replace("normal = \"outward\"", "normal = [0, -1]");
    assert!(parse_problem(&normal).is_ok(), "{:?}", parse_problem(&normal).err());
    for (key, from, to) in [
        ("body_force", "body_force = [\"0\", \"-1\"]", "body_force = [\"0\", \"-1\", \"0\"]"),
        ("traction", "traction = [\"0\", \"0\"]", "traction = [\"0\", \"0\", \"0\"]"),
        ("dirichlet", "dirichlet = [\"0\", \"-0.01\"]", "dirichlet = [\"0\", \"-0.01\", 0]"),
        ("required_vertices", "required_vertices = [[0.5, 0]]", "required_vertices = [[0.5, 0, 0]]"),
        ("at", "at = [0.5, 1]", "at = [0.5, 1, 0]"),
        ("u", "u = [\"free\", 0]", "u = [\"free\", 0, 7]"),
        ("u", "u = [\"0\", \"0\"]", "u = [\"0\", \"0\", \"0\"]"),
        ("grad", "grad = [[\"0\", \"0\"], [\"0\", \"0\"]]", "grad = [[\"0\", \"0\", \"0\"], [\"0\", \"0\"]]"),
        ("grad", "grad = [[\"0\", \"0\"], [\"0\", \"0\"]]", "grad = [[\"0\", \"0\"], [\"0\", \"0\"], [\"0\", \"0\"]]"),
    ] {
        assert!(good.contains(from), "{from}");
        let err = parse_problem(&good.replace(from, to)).map(|_| ()).expect_err(to);
        assert!(err.contains(key) && err.contains("two"), "{to}: {err}");
    }
    let err = parse_problem(&normal.replace("normal = [0, -1]", "normal = [0, -1, 0]")).map(|_| ()).expect_err("normal");
    assert!(err.contains("normal") && err.contains("two"), "{err}");
    // a circle's centre (groups and a curve)
    let circle = fixture("bad_data_gmsh.toml") + "\n[curves.bottom]\ncircle = { centre = [0.5, 2], radius = 2 }\n";
    assert!(parse_problem(&circle).is_ok(), "{:?}", parse_problem(&circle).err());
    let err = parse_problem(&circle.replace("[0.5, 2]", "[0.5, 2, 0]")).map(|_| ()).expect_err("centre");
    assert!(err.contains("centre") && err.contains("two"), "{err}");
}

#[test]
fn a_point_constraint_with_a_third_value_is_refused_by_the_binary() {
    let dir = scratch("problem-files-pc");
    let text = with_every_pair().replace("u = [\"free\", 0]", "u = [\"free\", 0, 7]");
    std::fs::write(dir.join("p.toml"), text).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("p.toml:") && err.contains("point_constraints") && err.contains("exactly two"), "{err}");
}

#[test]
fn a_problem_file_beside_the_manifests_is_called_one() {
    let dir = scratch("problem-files-beside");
    let study =
        "description = \"one short run\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\nlevels = 2\n[[run]]\nid = \"a\"\n";
    std::fs::write(dir.join("study.toml"), study).unwrap();
    std::fs::write(dir.join("square.toml"), fixture("bad_data_square.toml")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["drift", "--experiments", ".", "--results", "none"]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("square.toml looks like a problem file") && err.contains("keep problem files in a subfolder"), "{err}");
}
