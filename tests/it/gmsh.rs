//! Gmsh meshes (`gmsh:PATH.msh`): parsing, tagging by physical group, curved boundaries under
//! refinement, errors naming the line; the contact zone as arc-length intervals.

use crate::common;
use crate::common::{fixture, run_edited, scratch, signorini_in, solve_gmsh_square};
use common::*;
use signorini::mesh::{Mesh, MeshError, MeshSpec};
use signorini::problems::{Curve, Material, Part, Problem};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A problem that names physical groups: `groups` maps a name to its part and curve. The body is
/// pushed down (f = (0, -1)) onto a flat foundation under y = 0 (n = (0, -1), chi = 0).
struct Named {
    groups: Vec<(&'static str, Part, Option<Curve>)>,
}

impl Problem for Named {
    fn name(&self) -> &str {
        "named"
    }
    fn description(&self) -> &str {
        "a test problem naming physical groups"
    }
    fn material(&self) -> Material {
        Material::from_young(100.0, 0.3)
    }
    fn part_of(&self, _x: [f64; 2]) -> Part {
        Part::Neumann
    }
    fn part_of_group(&self, group: &str) -> Option<Part> {
        self.groups.iter().find(|g| g.0 == group).map(|g| g.1)
    }
    fn curve_of_group(&self, group: &str) -> Option<Curve> {
        self.groups.iter().find(|g| g.0 == group).and_then(|g| g.2)
    }
    fn body_force(&self, _x: [f64; 2]) -> [f64; 2] {
        [0.0, -1.0]
    }
    fn traction(&self, _x: [f64; 2], _n: [f64; 2]) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn dirichlet(&self, _x: [f64; 2]) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn contact_normal(&self, _x: [f64; 2], _outward: [f64; 2]) -> [f64; 2] {
        [0.0, -1.0]
    }
    fn gap(&self, _x: [f64; 2]) -> f64 {
        0.0
    }
}

const UNIT_CIRCLE: Curve = Curve::Circle { centre: [0.0, 0.0], radius: 1.0 };

fn quarter_disc_problem() -> Named {
    Named { groups: vec![("bottom", Part::Contact, None), ("arc", Part::Neumann, Some(UNIT_CIRCLE)), ("left", Part::Dirichlet, None)] }
}

fn meshes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/meshes")
}

fn area(m: &Mesh) -> f64 {
    (0..m.n_triangles()).map(|t| m.area(t)).sum()
}

/// The unit square as two triangles (the second listed clockwise), "bottom" on y = 0 and
/// "sides" on the other three sides: a hand-written MSH 4.1 ASCII file.
const SQUARE: &str = include_str!("../fixtures/square.msh");

fn square_problem() -> Named {
    Named { groups: vec![("bottom", Part::Contact, None), ("sides", Part::Dirichlet, None)] }
}

/// Write `text` to a fresh file under target/ and return its path.
fn write(name: &str, text: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-gmsh");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// 1-based line of the first line of `text` equal to `line`.
fn line_of(text: &str, line: &str) -> usize {
    1 + text.lines().position(|l| l == line).unwrap()
}

fn build_err(path: &Path, problem: &dyn Problem) -> String {
    let err = MeshSpec::Gmsh(path.to_path_buf()).build(problem).expect_err("an error");
    assert!(matches!(err, MeshError::Gmsh { .. }), "{err:?}");
    err.to_string()
}

#[test]
fn hand_written_square_is_read_tagged_and_oriented() {
    let path = write("square.msh", SQUARE);
    let spec = MeshSpec::parse(&format!("gmsh:{}", path.display())).unwrap();
    assert_eq!(spec, MeshSpec::Gmsh(path.clone()));
    assert_eq!(spec.ndof().unwrap(), 2.0 * (4.0 + 5.0));
    let m = spec.build(&square_problem()).unwrap();
    assert_eq!((m.n_vertices(), m.n_triangles(), m.boundary.len()), (4, 2, 4));
    assert_eq!(m.vertices, vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    // both counter-clockwise (the second was listed clockwise), the diagonal opposite the first vertex
    for t in 0..2 {
        assert!((m.area(t) - 0.5).abs() < 1e-15);
        let [a, b, c] = m.triangles[t];
        assert!([b, c] == [0, 2] || [b, c] == [2, 0], "refinement edge of {:?} is not the diagonal", m.triangles[t]);
        assert!(a == 1 || a == 3);
    }
    let bottom: Vec<_> = m.boundary.iter().filter(|e| e.part == Part::Contact).map(|e| e.v).collect();
    assert_eq!(bottom, vec![[0, 1]], "the bottom, counter-clockwise");
    assert_eq!(m.boundary.iter().filter(|e| e.part == Part::Dirichlet).count(), 3);
}

/// MSH separates fields by white space of any length (Gmsh reads aligned columns): runs of
/// spaces, tabs, blanks at the start and end of a line and CRLF line ends read as the same mesh
/// as the plain file; a physical name keeps the spaces inside its quotes; an error in such a
/// file still names its own line.
#[test]
fn white_space_of_any_length_between_fields_reads_as_the_plain_file() {
    let plain = MeshSpec::Gmsh(write("plain.msh", SQUARE)).build(&square_problem()).unwrap();
    let forms: [(&str, String); 4] = [
        ("runs.msh", SQUARE.replace(' ', "   ")),
        ("tabs.msh", SQUARE.replace(' ', " \t ")),
        ("blank-ends.msh", SQUARE.lines().map(|l| format!("  {l}\t ")).collect::<Vec<_>>().join("\n")),
        ("crlf.msh", SQUARE.replace('\n', "\r\n")),
    ];
    for (name, text) in &forms {
        let m = MeshSpec::Gmsh(write(name, text)).build(&square_problem()).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!((&m.vertices, &m.triangles), (&plain.vertices, &plain.triangles), "{name}");
        assert_eq!(
            m.boundary.iter().map(|e| (e.v, e.part)).collect::<Vec<_>>(),
            plain.boundary.iter().map(|e| (e.v, e.part)).collect::<Vec<_>>()
        );
    }
    // inside quotes the spaces are the name's: "bottom  face" is not "bottom face"
    let spaced = SQUARE.replace("\"bottom\"", "\"bottom  face\"");
    let problem = Named { groups: vec![("bottom  face", Part::Contact, None), ("sides", Part::Dirichlet, None)] };
    MeshSpec::Gmsh(write("quoted.msh", &spaced.replace(' ', "  ").replace("bottom    face", "bottom  face"))).build(&problem).unwrap();
    // an error names the same line as in the plain file (a misspelt section end)
    let broken = SQUARE.replacen("$EndNodes", "$EndNodez", 1);
    let plain_err = build_err(&write("plain-broken.msh", &broken), &square_problem());
    let spaced_err = build_err(&write("spaced-broken.msh", &broken.replace(' ', "   ")), &square_problem());
    let line = |e: &str| e.split("line ").nth(1).and_then(|r| r.split(':').next()).map(str::to_string);
    assert!(line(&plain_err).is_some() && line(&plain_err) == line(&spaced_err), "{plain_err}\n{spaced_err}");
}

#[test]
fn truncated_file_is_an_error_naming_file_and_line() {
    let cut = &SQUARE[..SQUARE.find("5 1 2 3").unwrap() + 4];
    let path = write("truncated.msh", cut);
    let err = build_err(&path, &square_problem());
    let last = cut.lines().count();
    assert!(err.contains("truncated.msh") && err.contains(&format!("line {last}")) && err.contains("truncated"), "{err}");
    // another version of the format: the line after $MeshFormat
    let path = write("version.msh", &SQUARE.replace("4.1 0 8", "2.2 0 8"));
    let err = build_err(&path, &square_problem());
    assert!(err.contains("version.msh, line 2") && err.contains("4.1"), "{err}");
    // a missing section
    let path = write("no_elements.msh", &SQUARE[..SQUARE.find("$Elements").unwrap()]);
    let err = build_err(&path, &square_problem());
    assert!(err.contains("no_elements.msh") && err.contains("no $Elements section"), "{err}");
    // a broken $PhysicalNames entry
    let text = SQUARE.replace("1 2 \"sides\"", "1 2 sides");
    let path = write("bad_names.msh", &text);
    let err = build_err(&path, &square_problem());
    assert!(err.contains(&format!("line {}", line_of(&text, "1 2 sides"))) && err.contains("$PhysicalNames"), "{err}");
    // an unreadable file
    let err = build_err(Path::new("no/such/mesh.msh"), &square_problem());
    assert!(err.contains("no/such/mesh.msh") && err.contains("cannot read"), "{err}");
}

/// A binary file cut anywhere inside its `$Nodes` section is named as truncated there, whatever
/// its cut bytes would read as (a node tag of 0, "the internally reserved value").
#[test]
fn binary_file_cut_inside_its_nodes_is_named_truncated() {
    let whole = std::fs::read(meshes_dir().join("quarter_disc_binary.msh")).unwrap();
    let find = |what: &[u8]| whole.windows(what.len()).position(|w| w == what).unwrap();
    let (body, end) = (find(b"$Nodes\n") + 7, find(b"$EndNodes"));
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-gmsh");
    std::fs::create_dir_all(&dir).unwrap();
    for cut in (body..end).step_by(5) {
        let path = dir.join("cut_binary.msh");
        std::fs::write(&path, &whole[..cut]).unwrap();
        let err = build_err(&path, &quarter_disc_problem());
        assert!(err.contains("the file ends inside its $Nodes section (opened at line ") && err.contains("truncated"), "{cut}: {err}");
        assert!(!err.contains("reserved"), "{cut}: {err}");
    }
}

/// An ASCII file whose header declares binary data (file-type 1) is named as such, not as
/// truncated.
#[test]
fn text_under_a_binary_header_is_named_as_such() {
    let path = write("text_as_binary.msh", &SQUARE.replace("4.1 0 8", "4.1 1 8"));
    let err = build_err(&path, &square_problem());
    assert!(err.contains("text_as_binary.msh, line 2: the $MeshFormat header declares a binary file (file-type 1"), "{err}");
    assert!(err.contains("the data reads as text") && err.contains("`4.1 0 8`") && !err.contains("truncated"), "{err}");
}

#[test]
fn group_the_problem_does_not_name_is_an_error_listing_the_groups() {
    let path = write("square_unknown.msh", SQUARE);
    let problem = Named { groups: vec![("bottom", Part::Contact, None), ("walls", Part::Dirichlet, None)] };
    let err = build_err(&path, &problem);
    assert!(err.contains("square_unknown.msh") && err.contains(&format!("line {}", line_of(SQUARE, "1 2 \"sides\""))), "{err}");
    assert!(err.contains("\"sides\" (not named by named)") && err.contains("\"bottom\" (Contact)"), "{err}");
}

#[test]
fn untagged_boundary_edge_and_missing_node_are_errors_naming_the_line() {
    // drop the line element 4 -> 1: the edge x = 0 is then in no group
    let text = SQUARE.replace("1 2 1 3\n", "1 2 1 2\n").replace("4 4 1\n", "").replace("3 6 1 6\n", "3 5 1 6\n");
    let path = write("untagged.msh", &text);
    let err = build_err(&path, &square_problem());
    // the triangle holding that edge is element 6
    assert!(err.contains("untagged.msh") && err.contains(&format!("line {}", line_of(&text, "6 1 4 3"))), "{err}");
    assert!(err.contains("from (0, 1) to (0, 0)") && err.contains("no physical group"), "{err}");
    // a triangle naming a node the file does not have
    let text = SQUARE.replace("6 1 4 3", "6 1 9 3");
    let path = write("missing_node.msh", &text);
    let err = build_err(&path, &square_problem());
    assert!(err.contains(&format!("line {}", line_of(&text, "6 1 9 3"))) && err.contains("node 9"), "{err}");
    // a line element that is no boundary edge (the diagonal)
    let text = SQUARE.replace("1 1 2\n", "1 1 3\n");
    let path = write("interior_line.msh", &text);
    let err = build_err(&path, &square_problem());
    assert!(err.contains(&format!("line {}", line_of(&text, "1 1 3"))) && err.contains("not a boundary edge"), "{err}");
}

#[test]
fn quarter_disc_counts_area_and_tags() {
    let spec = MeshSpec::Gmsh(meshes_dir().join("quarter_disc.msh"));
    let p = quarter_disc_problem();
    let m = spec.build(&p).unwrap();
    m.check().unwrap();
    assert!(m.n_triangles() > 20 && m.n_triangles() < 200, "{} triangles", m.n_triangles());
    assert_eq!(spec.ndof().unwrap(), 2.0 * signorini::mesh::P2Nodes::new(&m).len() as f64);
    // the polygon inscribed in the quarter circle: area below pi/4 and close to it
    let arc: Vec<_> = m.boundary.iter().filter(|e| e.part == Part::Neumann).collect();
    let n = arc.len() as f64;
    let polygon = 0.5 * n * (std::f64::consts::FRAC_PI_2 / n).sin();
    assert!((area(&m) - polygon).abs() < 1e-3 * polygon && area(&m) < std::f64::consts::FRAC_PI_4, "area {} vs {polygon}", area(&m));
    for e in &m.boundary {
        let (a, b) = (m.vertices[e.v[0]], m.vertices[e.v[1]]);
        match e.part {
            Part::Contact => assert!(a[1] == 0.0 && b[1] == 0.0 && e.curve.is_none() && b[0] > a[0]),
            Part::Dirichlet => assert!(a[0] == 0.0 && b[0] == 0.0 && e.curve.is_none() && b[1] < a[1]),
            Part::Neumann => {
                assert_eq!(e.curve, Some(UNIT_CIRCLE));
                for x in [a, b] {
                    assert!((x[0].hypot(x[1]) - 1.0).abs() < 1e-12, "{x:?} off the circle");
                }
            }
        }
    }
    let len = |part| {
        m.boundary.iter().filter(|e| e.part == part).map(|e| signorini::mesh::dist(m.vertices[e.v[0]], m.vertices[e.v[1]])).sum::<f64>()
    };
    assert!((len(Part::Contact) - 1.0).abs() < 1e-14 && (len(Part::Dirichlet) - 1.0).abs() < 1e-14);
}

/// Uniform refinement of the quarter disc: new arc vertices on the circle, no triangle inverted,
/// the area tending to pi/4 like h^2 (the error falls by about 4 per bisection of the arc edges).
#[test]
fn quarter_disc_refined_onto_the_arc() {
    let p = quarter_disc_problem();
    let mut m = MeshSpec::Gmsh(meshes_dir().join("quarter_disc.msh")).build(&p).unwrap();
    let mut errors = Vec::new();
    for _ in 0..8 {
        m = signorini::mesh::refine::refine(&m, &vec![true; m.n_triangles()]).unwrap().mesh;
        m.check().unwrap();
        for e in m.boundary.iter().filter(|e| e.curve.is_some()) {
            for v in e.v {
                let x = m.vertices[v];
                assert!((x[0].hypot(x[1]) - 1.0).abs() <= 1e-14, "{x:?} off the circle");
            }
        }
        let arc_edges = m.boundary.iter().filter(|e| e.curve.is_some()).count() as f64;
        errors.push((arc_edges, std::f64::consts::FRAC_PI_4 - area(&m)));
    }
    let (a, b) = (errors[errors.len() - 3], errors[errors.len() - 1]);
    let slope = (b.1 / a.1).ln() / (b.0 / a.0).ln();
    assert!((slope + 2.0).abs() < 0.1, "area error ~ N^{slope}: {errors:?}");
    // a solve on the refined mesh: the body rests on the foundation
    let sol = solve_on(&p, &m);
    assert!(sol.active_count() > 0 && sol.kkt().max_penetration <= 1e-12);
    // VTU as for the built-in meshes: one quadratic triangle per triangle, one line per boundary edge
    let doc = signorini::mesh::io::vtu(&m, &sol.nodes, &[("u", signorini::mesh::io::Field::Vector(&sol.u))], &[]);
    assert!(doc.contains(&format!("NumberOfPoints=\"{}\" NumberOfCells=\"{}\"", sol.nodes.len(), m.n_triangles() + m.boundary.len())));
    write("quarter_disc_refined.vtu", &doc);
}

#[test]
fn hertz_mesh_is_graded_towards_the_lowest_point() {
    let p = Named {
        groups: vec![
            ("top", Part::Dirichlet, None),
            ("contact", Part::Contact, Some(Curve::Circle { centre: [0.0, 1.0], radius: 1.0 })),
            ("free", Part::Neumann, Some(Curve::Circle { centre: [0.0, 1.0], radius: 1.0 })),
        ],
    };
    let path = meshes_dir().join("hertz.msh");
    assert!(std::fs::metadata(&path).unwrap().len() < 1 << 20, "hertz.msh stays under 1 MB");
    let m = MeshSpec::Gmsh(path).build(&p).unwrap();
    // the half disc less the circular segments cut off by the straight arc edges
    let segments: f64 = m
        .boundary
        .iter()
        .filter(|e| e.curve.is_some())
        .map(|e| {
            let theta = 2.0 * (0.5 * signorini::mesh::dist(m.vertices[e.v[0]], m.vertices[e.v[1]])).asin();
            0.5 * (theta - theta.sin())
        })
        .sum();
    let expected = 0.5 * std::f64::consts::PI - segments;
    assert!((area(&m) - expected).abs() < 1e-12 && segments < 3e-3, "area {} against {expected}", area(&m));
    let near = |t: usize| signorini::mesh::dist(m.corners(t)[0], [0.0, 0.0]);
    let h_near = (0..m.n_triangles()).filter(|&t| near(t) < 0.01).map(|t| m.diameter(t)).fold(0.0, f64::max);
    let h_far = (0..m.n_triangles()).filter(|&t| near(t) > 0.8).map(|t| m.diameter(t)).fold(0.0, f64::max);
    assert!(h_near < 0.01 && h_far > 0.08, "h near (0, 0) {h_near}, far {h_far}");
    let contact = m.boundary.iter().filter(|e| e.part == Part::Contact);
    assert!(contact.clone().all(|e| e.v.iter().all(|&v| m.vertices[v][0].abs() <= 0.3 + 1e-12)));
    assert!(contact.count() > 20);
}

/// A body pushed down onto a foundation with two humps' valleys: contact in two separate parts of
/// the bottom, reported as two arc-length intervals (x on the bottom), each around its valley.
struct TwoValleys;

impl Problem for TwoValleys {
    fn name(&self) -> &str {
        "two_valleys"
    }
    fn description(&self) -> &str {
        "a block pressed onto a foundation touching it near x = 0.25 and x = 0.75"
    }
    fn material(&self) -> Material {
        Material::from_young(100.0, 0.3)
    }
    fn part_of(&self, x: [f64; 2]) -> Part {
        signorini::problems::contact_bottom_dirichlet_top(x)
    }
    fn body_force(&self, _x: [f64; 2]) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn traction(&self, _x: [f64; 2], _n: [f64; 2]) -> [f64; 2] {
        [0.0, 0.0]
    }
    fn dirichlet(&self, _x: [f64; 2]) -> [f64; 2] {
        [0.0, -0.01]
    }
    fn contact_normal(&self, _x: [f64; 2], _outward: [f64; 2]) -> [f64; 2] {
        [0.0, -1.0]
    }
    /// chi = 16 (x - 1/4)^2 (x - 3/4)^2: touching at x = 1/4 and 3/4, 0.0625 apart at x = 1/2.
    fn gap(&self, x: [f64; 2]) -> f64 {
        16.0 * (x[0] - 0.25).powi(2) * (x[0] - 0.75).powi(2)
    }
}

#[test]
fn contact_zone_intervals_on_two_separate_active_parts() {
    let p = TwoValleys;
    let m = mesh(&p, "structured:32");
    let sol = solve_on(&p, &m);
    let zones = sol.contact_zones();
    assert_eq!(zones.len(), 2, "{zones:?}");
    for (z, centre) in zones.iter().zip([0.25, 0.75]) {
        assert_eq!(z.component, 0);
        assert!(z.s[0] < centre && centre < z.s[1] && z.s[1] - z.s[0] < 0.3, "{z:?} around {centre}");
        // arc length along the bottom from (0, 0) is x
        assert_eq!([z.from[0], z.to[0]], z.s);
        assert!(z.from[1] == 0.0 && z.to[1] == 0.0);
    }
    // mirror symmetry of the problem: the intervals mirror each other
    assert!((zones[0].s[0] - (1.0 - zones[1].s[1])).abs() < 1e-12 && (zones[0].s[1] - (1.0 - zones[1].s[0])).abs() < 1e-12, "{zones:?}");
    // every active node is in an interval, every node inside an interval is active
    for (k, c) in sol.dofs.contact.iter().enumerate() {
        let x = sol.nodes.coords[c.node][0];
        let inside = zones.iter().any(|z| z.s[0] <= x && x <= z.s[1]);
        assert_eq!(inside, sol.active[k], "node at x = {x}");
    }
    assert_eq!(sol.contact_zone(), Some([zones[0].s[0], zones[1].s[1]]));
}

/// Arc length along a curved Gamma_C: the quarter disc, clamped on x = 0, its arc squeezed by a
/// rigid ring 0.01 inside it (n the radial direction): one interval along the whole arc,
/// counter-clockwise from (1, 0) to the midpoint of the last arc edge (the corner (0, 1) is on
/// the closure of Gamma_D, so no contact node).
#[test]
fn contact_zone_arc_length_along_a_curve() {
    struct Ring;
    impl Problem for Ring {
        fn name(&self) -> &str {
            "ring"
        }
        fn description(&self) -> &str {
            "a quarter disc squeezed into a ring"
        }
        fn material(&self) -> Material {
            Material::from_young(100.0, 0.3)
        }
        fn part_of(&self, _x: [f64; 2]) -> Part {
            Part::Neumann
        }
        fn part_of_group(&self, g: &str) -> Option<Part> {
            match g {
                "arc" => Some(Part::Contact),
                "bottom" => Some(Part::Neumann),
                "left" => Some(Part::Dirichlet),
                _ => None,
            }
        }
        fn curve_of_group(&self, g: &str) -> Option<Curve> {
            (g == "arc").then_some(UNIT_CIRCLE)
        }
        fn body_force(&self, _x: [f64; 2]) -> [f64; 2] {
            [0.0, 0.0]
        }
        fn traction(&self, _x: [f64; 2], _n: [f64; 2]) -> [f64; 2] {
            [0.0, 0.0]
        }
        fn dirichlet(&self, x: [f64; 2]) -> [f64; 2] {
            // the left side moves with the ring: at (0, 1), where it meets the contact part,
            // u . n = chi (held at 0 there, the body would start inside the ring)
            [0.0, -0.01 * x[1]]
        }
        fn contact_normal(&self, x: [f64; 2], _outward: [f64; 2]) -> [f64; 2] {
            let r = x[0].hypot(x[1]);
            [x[0] / r, x[1] / r]
        }
        fn gap(&self, _x: [f64; 2]) -> f64 {
            -0.01
        }
    }
    let m = MeshSpec::Gmsh(meshes_dir().join("quarter_disc.msh")).build(&Ring).unwrap();
    let sol = solve_on(&Ring, &m);
    let zones = sol.contact_zones();
    let arc: Vec<[f64; 2]> =
        m.boundary.iter().filter(|e| e.part == Part::Contact).flat_map(|e| [m.vertices[e.v[0]], m.vertices[e.v[1]]]).collect();
    let lengths: Vec<f64> = arc.chunks(2).map(|e| signorini::mesh::dist(e[0], e[1])).collect();
    let arc_len: f64 = lengths.iter().sum();
    assert_eq!(zones.len(), 1, "{zones:?}");
    assert_eq!(zones[0].s[0], 0.0);
    let last = lengths.iter().zip(arc.chunks(2)).find(|(_, e)| e[1] == [0.0, 1.0]).map(|(l, _)| *l).unwrap();
    assert!((zones[0].s[1] - (arc_len - 0.5 * last)).abs() < 1e-14, "{zones:?} vs {arc_len} - {last} / 2");
    assert_eq!(zones[0].from, [1.0, 0.0]);
    assert!(
        zones[0].to[0] > 0.0 && (zones[0].to[0].hypot(zones[0].to[1]) - 1.0).abs() < 0.01,
        "counter-clockwise from (1, 0) to near (0, 1): {zones:?}"
    );
}

/// A manifest's relative mesh path is relative to the manifest's folder (the run's spec keeps it as
/// written, like the problem, and `resolve_mesh` resolves it); an absolute one and the built-in
/// meshes stay as they are.
#[test]
fn manifest_mesh_paths_are_relative_to_the_manifest() {
    use signorini::manifest::{Manifest, resolve_mesh};
    let text = |mesh: &str| format!("[defaults]\nproblem = \"ex71\"\nlevels = 2\nmesh = \"{mesh}\"\n[[run]]\nid = \"a\"\n");
    // the manifest reads the mesh (its hash is part of the run's spec): put one where it points
    let root = std::env::temp_dir().join(format!("signorini-mesh-paths-{}", std::process::id()));
    std::fs::create_dir_all(root.join("studies/own/meshes")).unwrap();
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/meshes/hertz.msh"), root.join("studies/own/meshes/hertz.msh"))
        .unwrap();
    let file = root.join("studies/own/hertz.toml");
    let m = Manifest::parse(&file, &text("gmsh:meshes/hertz.msh")).unwrap();
    assert_eq!(m.runs[0].spec.mesh, "gmsh:meshes/hertz.msh");
    assert_eq!(resolve_mesh(&file, &m.runs[0].spec.mesh), format!("gmsh:{}", root.join("studies/own/meshes/hertz.msh").display()));
    assert_eq!(m.mesh_files(), vec![root.join("studies/own/meshes/hertz.msh")]);
    std::fs::remove_dir_all(&root).unwrap();
    assert_eq!(resolve_mesh(Path::new("hertz.toml"), "gmsh:meshes/hertz.msh"), "gmsh:meshes/hertz.msh");
    assert_eq!(resolve_mesh(Path::new("studies/hertz.toml"), "gmsh:/abs/hertz.msh"), "gmsh:/abs/hertz.msh");
    assert_eq!(resolve_mesh(Path::new("studies/hertz.toml"), "structured:4"), "structured:4");
    let e = Manifest::parse(Path::new("studies/hertz.toml"), &text("gmsh:")).unwrap_err().to_string();
    assert!(e.contains("run[0].mesh") && e.contains("gmsh:PATH.msh"), "{e}");
}

/// On the command line: a Gmsh mesh whose groups the problem does not name is a clear error, and
/// a probe outside the mesh too.
#[test]
fn command_line_names_the_mesh_file_and_its_groups() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["solve", "--problem", "ex71", "--mesh", &format!("gmsh:{}", meshes_dir().join("quarter_disc.msh").display())])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("quarter_disc.msh") && !err.contains("panicked"), "{err}");
    assert!(err.contains("problem ex71 declares its boundary parts by its own rule on x and y, which tag the built-in meshes"), "{err}");
}

/// The binary encoding of the quarter disc gives the same mesh as the ASCII one (vertices to the
/// ASCII file's 16 digits).
#[test]
fn binary_and_ascii_files_give_the_same_mesh() {
    let p = quarter_disc_problem();
    let ascii = MeshSpec::Gmsh(meshes_dir().join("quarter_disc.msh")).build(&p).unwrap();
    let binary = MeshSpec::Gmsh(meshes_dir().join("quarter_disc_binary.msh")).build(&p).unwrap();
    assert!(std::fs::read(meshes_dir().join("quarter_disc_binary.msh")).unwrap().contains(&0u8), "the file is binary");
    // ASCII files hold 16 significant digits, binary ones the doubles themselves
    assert_eq!(ascii.n_vertices(), binary.n_vertices());
    for (a, b) in ascii.vertices.iter().zip(&binary.vertices) {
        assert!((a[0] - b[0]).abs() <= 1e-15 && (a[1] - b[1]).abs() <= 1e-15, "{a:?} vs {b:?}");
    }
    assert_eq!(ascii.triangles, binary.triangles);
    assert_eq!(ascii.boundary, binary.boundary);
}

/// A cylinder pressed onto a flat foundation on the Hertz mesh: the top moved down by 0.002, the
/// constraint the vertical gap to y = 0 (n = (0, -1), chi = y). One contact interval around the
/// lowest point, inside the contact group, refined adaptively with new arc vertices on the circle.
#[test]
fn hertz_mesh_gives_one_contact_interval_around_the_lowest_point() {
    struct Pressed;
    const ROLLER: Curve = Curve::Circle { centre: [0.0, 1.0], radius: 1.0 };
    impl Problem for Pressed {
        fn name(&self) -> &str {
            "pressed"
        }
        fn description(&self) -> &str {
            "a half cylinder pressed onto a flat foundation"
        }
        fn material(&self) -> Material {
            Material::from_young(1.0, 0.3)
        }
        fn part_of(&self, _x: [f64; 2]) -> Part {
            Part::Neumann
        }
        fn part_of_group(&self, g: &str) -> Option<Part> {
            match g {
                "top" => Some(Part::Dirichlet),
                "contact" => Some(Part::Contact),
                "free" => Some(Part::Neumann),
                _ => None,
            }
        }
        fn curve_of_group(&self, g: &str) -> Option<Curve> {
            (g != "top").then_some(ROLLER)
        }
        fn body_force(&self, _x: [f64; 2]) -> [f64; 2] {
            [0.0, 0.0]
        }
        fn traction(&self, _x: [f64; 2], _n: [f64; 2]) -> [f64; 2] {
            [0.0, 0.0]
        }
        fn dirichlet(&self, _x: [f64; 2]) -> [f64; 2] {
            [0.0, -0.002]
        }
        fn contact_normal(&self, _x: [f64; 2], _outward: [f64; 2]) -> [f64; 2] {
            [0.0, -1.0]
        }
        fn gap(&self, x: [f64; 2]) -> f64 {
            x[1]
        }
    }
    let m = MeshSpec::Gmsh(meshes_dir().join("hertz.msh")).build(&Pressed).unwrap();
    let config = signorini::settings::adapt::AdaptConfig { levels: 4, ..Default::default() };
    let out = signorini::adapt::run(&Pressed, m, &config, None, &mut |_| std::ops::ControlFlow::Continue(())).unwrap();
    let (m, sol) = (&out.mesh, &out.solution);
    for e in m.boundary.iter().filter(|e| e.curve.is_some()) {
        for v in e.v {
            let x = m.vertices[v];
            assert!((x[0].hypot(x[1] - 1.0) - 1.0).abs() <= 1e-14, "{x:?} off the circle");
        }
    }
    let zones = sol.contact_zones();
    assert_eq!(zones.len(), 1, "{zones:?}");
    let z = zones[0];
    // the arc length of (0, 0) from (-0.3, 1 - sqrt(0.91)) along the polygon: about asin(0.3)
    assert!(z.from[0] < 0.0 && z.to[0] > 0.0 && z.s[1] - z.s[0] < 0.3, "{z:?}");
    assert!(z.s[0] < 0.3f64.asin() && 0.3f64.asin() - 1e-3 < z.s[1], "{z:?}");
    assert!(sol.kkt().max_penetration <= 1e-12);
}

const QD: &str = "gmsh_renumbered/quarter_disc.toml";

const SOLVE_QD: &[&str] = &["solve", "--problem", "v.toml", "--mesh", "gmsh:qd.msh"];

const ADAPT_QD: &[&str] = &["adapt", "--problem", "v.toml", "--mesh", "gmsh:qd.msh", "--levels", "4"];

#[test]
fn a_physical_group_the_mesh_file_lacks_is_named() {
    // the unchanged problem solves: the refusals below are the names' doing
    let (code, out, err) = run_edited("groups-ok", QD, &[("", "")], SOLVE_QD);
    assert!(code == 0 && out.contains("certified:"), "{err}");
    for (case, from, to, group) in [
        ("misspelt", r#"contact = ["bottom"]"#, r#"contact = ["bottom", "botom"]"#, "botom"),
        ("misspelt-dirichlet", r#"dirichlet = ["left"]"#, r#"dirichlet = ["left", "lef"]"#, "lef"),
        ("surface", r#"neumann = ["arc"]"#, r#"neumann = ["arc", "body"]"#, "body"),
    ] {
        for args in [SOLVE_QD, ADAPT_QD] {
            let (code, _, err) = run_edited(case, QD, &[(from, to)], args);
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
fn a_curve_the_boundary_does_not_follow_is_refused_before_refining() {
    let arc = "arc = { circle = { centre = [0, 0], radius = 1 } }";
    for (case, to) in [
        ("centre", "arc = { circle = { centre = [0, 1], radius = 1 } }"),
        ("radius", "arc = { circle = { centre = [0, 0], radius = 1.01 } }"),
    ] {
        for args in [SOLVE_QD, ADAPT_QD] {
            let (code, _, err) = run_edited(case, QD, &[(arc, to)], args);
            assert_eq!(code, 1, "{case}: {err}");
            for says in ["qd.msh, line ", r#"of this line element of group "arc" is off the curve"#, "[curves]", "of its size"] {
                assert!(err.contains(says), "{case}: no {says:?} in\n{err}");
            }
            assert!(!err.contains("non-positive area"), "{case}: {err}");
        }
    }
    let (code, out, err) = run_edited("curve-ok", QD, &[("", "")], ADAPT_QD);
    assert!(code == 0 && out.lines().filter(|l| l.trim_start().starts_with(char::is_numeric)).count() == 4, "{err}\n{out}");
}

/// Two physical groups of lines under one name in `$PhysicalNames`: refused naming both tags and
/// lines (a problem names groups by name, so the two would silently be one part).
#[test]
fn a_physical_name_given_to_two_groups_is_refused() {
    let dir = scratch("gmsh-dupname");
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

/// A partitioned MSH 4.1 file puts its elements on partition entities: read as if it were whole,
/// its lines would come out in no group and the problem be blamed. Refused naming the section,
/// its line and how to write it whole.
#[test]
fn a_partitioned_mesh_is_refused_by_name() {
    let dir = scratch("gmsh-partitioned");
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

/// On a closed contact loop, one active arc through the loop's start is one zone
/// [s_first, s_last + L], not two zones with zone_min/zone_max the whole loop.
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

/// Refinement onto a concave curve (a hole's circle) turns a triangle over where the first layer
/// is thinner than the chord's sagitta: the error names the curve, the edge, the new vertex and
/// the remedy, not the vertex order.
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

/// The estimator line of solving the Gmsh square with `msh` as its mesh, or the error.
fn solve_msh(dir: &Path, msh: &str) -> Result<String, String> {
    std::fs::write(dir.join("v.toml"), fixture("bad_data_gmsh.toml")).unwrap();
    std::fs::write(dir.join("m.msh"), msh).unwrap();
    let (code, out, err) = signorini_in(dir, &["solve", "--problem", "v.toml", "--mesh", "gmsh:m.msh"]);
    match code {
        0 => Ok(out.lines().find(|l| l.starts_with("estimator:")).unwrap_or_default().to_string()),
        _ => Err(err),
    }
}

#[test]
fn lines_between_sections_are_skipped_as_gmsh_skips_them() {
    let dir = scratch("gmsh-stray");
    let msh = fixture("square.msh");
    let plain = solve_msh(&dir, &msh).unwrap();
    assert!(!plain.is_empty());
    for (at, stray) in [("$EndElements\n", "written by hand\n1 2 3\n"), ("$EndMeshFormat\n", "x\n"), ("$EndNodes\n", "  note\n")] {
        assert!(msh.contains(at));
        let with = msh.replacen(at, &format!("{at}{stray}"), 1);
        assert_eq!(solve_msh(&dir, &with).as_ref(), Ok(&plain), "{stray:?} after {at:?}");
    }
}

#[test]
fn a_byte_order_mark_is_named() {
    let dir = scratch("gmsh-bom");
    let err = solve_msh(&dir, &format!("\u{feff}{}", fixture("square.msh"))).unwrap_err();
    assert!(err.contains("m.msh") && err.contains("starts with a byte-order mark") && err.contains("save it without one"), "{err}");
    assert!(!err.contains("EndEndMeshFormat"), "{err}");
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
    let dir = scratch(&format!("gmsh-{name}"));
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

/// Two bodies in one place, or crossing each other, each a valid mesh of its own, are refused
/// rather than solved (a probe would give one body's value), naming
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

/// Gmsh skips the sections it does not read (`$Comments`, any unknown one) wherever they are,
/// before `$MeshFormat` too, and so do we: a file opening with `$Comments` is no bad header.
/// Every placement solves to the plain file's output, also when a
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
fn a_predicate_problem_on_a_gmsh_mesh_says_predicates_tag_the_built_in_meshes() {
    let dir = scratch("gmsh-predicate-gmsh");
    std::fs::write(dir.join("sq.msh"), fixture("square.msh")).unwrap();
    std::fs::write(dir.join("v.toml"), fixture("bad_data_square.toml")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "gmsh:sq.msh"]);
    assert_eq!(code, 1, "{err}");
    for part in ["declares its boundary parts by predicates on x and y (parts.contact = \"y < 1e-12\"", "which tag the built-in meshes"] {
        assert!(err.contains(part), "{part}: {err}");
    }
    assert!(!err.contains("not named by"), "{err}");
}

#[test]
fn a_parametric_gmsh_file_is_refused_with_the_option_that_writes_a_plain_one() {
    let dir = scratch("gmsh-parametric");
    std::fs::write(dir.join("v.toml"), fixture("bad_data_gmsh.toml")).unwrap();
    let msh = fixture("square.msh");
    assert!(msh.contains("$Nodes\n1 4 1 4\n2 1 0 4\n"));
    std::fs::write(dir.join("m.msh"), msh.replace("$Nodes\n1 4 1 4\n2 1 0 4\n", "$Nodes\n1 4 1 4\n2 1 1 4\n")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "v.toml", "--mesh", "gmsh:m.msh"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("m.msh") && err.contains("Mesh.SaveParametric = 0"), "{err}");
}

/// A physical group named as the tag of another, unnamed group ("1" beside the unnamed group 1)
/// would read as one boundary part, a problem naming "1" holding both sides: refused when the
/// mesh is read, naming both groups.
#[test]
fn a_group_named_as_another_groups_tag_is_refused() {
    let (code, out) = solve_gmsh_square("name-is-a-tag", &[], &[("3\n1 1 \"bottom\"\n1 2 \"sides\"", "2\n1 2 \"1\"")]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("the physical group 2 is named \"1\", the tag of the unnamed group 1"), "{out}");
}
