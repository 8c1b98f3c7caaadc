//! Triangle meshes with tagged boundary edges and the P2 node numbering.
//!
//! A [`Mesh`] holds vertices, counter-clockwise triangles and every boundary edge with the part of
//! the boundary it belongs to (Dirichlet, Neumann or contact) and, on a curved part, the curve
//! it approximates. [`P2Nodes`] numbers the P2 nodes: the mesh vertices first (node `v` is vertex
//! `v`), then one midpoint per edge (on the straight edge: the elements are not isoparametric).
//! [`MeshSpec`] describes a mesh: the unit square (`structured:N`, `symmetric:N`) or a Gmsh file
//! (`gmsh:PATH.msh`, [`gmsh`]). [`locate`] finds the triangle holding a point, [`overlap`] two
//! triangles whose interiors overlap.

pub mod gmsh;
pub mod io;
pub mod locate;
mod msh_nodes;
mod msh_sections;
pub mod overlap;
pub mod precision;
pub mod refine;

use crate::problems::{Curve, Part, Problem};
use rayon::slice::ParallelSliceMut;
use std::fmt;
use std::path::PathBuf;

/// A boundary edge `v[0] -> v[1]` (counter-clockwise along the boundary), its part and, on a
/// curved part of the boundary, the curve it approximates (refinement puts the vertex it adds on
/// that curve; the edge itself, and so the P2 element and its edge midpoint, stay straight).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundaryEdge {
    pub v: [usize; 2],
    pub part: Part,
    pub curve: Option<Curve>,
}

/// A conforming triangulation with tagged boundary.
#[derive(Clone, Debug)]
pub struct Mesh {
    pub vertices: Vec<[f64; 2]>,
    /// Counter-clockwise vertex triples.
    pub triangles: Vec<[usize; 3]>,
    pub boundary: Vec<BoundaryEdge>,
}

/// Points inside each boundary edge of a built-in mesh, at which the parts are checked
/// ([`Mesh::check_parts_whole`]): the edge is cut into this many equal pieces.
pub const PART_SAMPLES: usize = 16;

/// How close to an end of a boundary edge, relative to the body's size (the diagonal of the
/// mesh's bounding box), a change of part is taken for the vertex itself
/// ([`Mesh::check_parts_whole`]).
pub const PART_END: f64 = 1e-9;

/// Both sides of every sign change (-, 0, +) of every component of `g` on [0, 1]: `g` at the
/// [`PART_SAMPLES`] + 1 equally spaced points, and each change between two neighbours located
/// by bisection to adjacent floating-point parameters, both returned.
fn switches(g: &dyn Fn(f64) -> Vec<f64>) -> Vec<f64> {
    let sign = |v: f64| if v.is_nan() { 2 } else { (v > 0.0) as i8 - (v < 0.0) as i8 };
    let ts: Vec<f64> = (0..=PART_SAMPLES).map(|k| k as f64 / PART_SAMPLES as f64).collect();
    let values: Vec<Vec<f64>> = ts.iter().map(|&t| g(t)).collect();
    let mut out = Vec::new();
    for (v, t) in values.windows(2).zip(ts.windows(2)) {
        for (c, (&v0, &v1)) in v[0].iter().zip(&v[1]).enumerate() {
            let (s0, s1) = (sign(v0), sign(v1));
            if s0 == s1 {
                continue;
            }
            let (mut lo, mut hi) = (t[0], t[1]);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if sign(g(mid)[c]) == s0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            out.extend([lo, hi]);
        }
    }
    out
}

/// What is wrong with a mesh.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("malformed mesh description '{}': expected {SPEC_FORMS}", crate::base::input::excerpt(.0))]
    BadSpec(String),
    /// `symmetric:N` with N odd (or 0): the mirror line y = 0.5 must be a grid line.
    #[error("malformed mesh description '{spec}': symmetric:N needs {}", even_symmetric(suggest))]
    OddSymmetric { spec: String, suggest: String },
    #[error("triangle {t} has non-positive area {area:e} (vertices must be counter-clockwise and distinct)")]
    NonPositiveArea { t: usize, area: f64 },
    /// Refinement put the new vertex of a curved boundary edge on its curve and turned a triangle
    /// over ([`refine::refine`]).
    #[error(
        "refinement put the new vertex of the {part} boundary edge from {} to {} on its curve (the circle of centre {} and radius {radius}), at {}, and that turned triangle {t} over (area {area:.3e}): the mesh is thinner there than the curve's sagitta over the edge ({sagitta:.3e}); mesh the body finer near the curve (triangles along it deeper than the sagitta r - sqrt(r^2 - (h/2)^2) of their boundary edges h)",
        crate::base::number::point(.edge[0]), crate::base::number::point(.edge[1]), crate::base::number::point(.curve.centre()), crate::base::number::point(*.at),
        radius = .curve.radius(), part = format!("{:?}", .part).to_lowercase(),
        sagitta = { let (r, h) = (.curve.radius(), dist(.edge[0], .edge[1])); r - (r * r - 0.25 * h * h).max(0.0).sqrt() }
    )]
    TurnedByCurve { t: usize, area: f64, edge: [[f64; 2]; 2], at: [f64; 2], curve: Curve, part: Part },
    #[error("mesh is not conforming: edge ({a}, {b}) is shared by {count} triangles")]
    NonConforming { a: usize, b: usize, count: usize },
    #[error("boundary edge ({a}, {b}) has no tag (every boundary edge must be Dirichlet, Neumann or contact)")]
    UntaggedBoundary { a: usize, b: usize },
    #[error("tagged edge ({a}, {b}) is not a boundary edge of the mesh")]
    TagNotOnBoundary { a: usize, b: usize },
    /// Two triangles whose interiors overlap ([`overlap`]): two bodies in one place or crossing,
    /// or a body folded onto itself; (x, y) is a point inside both.
    #[error(
        "triangles {a} and {b} overlap: both hold the point {} (two bodies meshed in one place or crossing each other, or a body folded onto itself: the triangles of a mesh must meet only at shared edges and vertices)",
        crate::base::number::point([*.x, *.y])
    )]
    Overlap { a: usize, b: usize, x: f64, y: f64 },
    /// The coordinates are so large against an element that its shape keeps fewer than 3
    /// digits ([`precision::SHAPE_ROUNDOFF_REFUSED`]).
    #[error(
        "triangle {t} lies at coordinates up to {} but is only {} high: f64 keeps its shape to {delta:.1e} of its size (2.2e-16 x {} / {}; at most {:e} is accepted), so the element geometry, and what is computed on it, would be round-off's; translate the mesh (and the problem's data) nearer the origin",
        crate::base::number::shown(*.offset), crate::base::number::shown(*.height), crate::base::number::shown(*.offset), crate::base::number::shown(*.height), precision::SHAPE_ROUNDOFF_REFUSED
    )]
    FarFromOrigin { t: usize, delta: f64, offset: f64, height: f64 },
    #[error("triangle {t} refers to vertex {v}, but the mesh has {n} vertices")]
    BadVertex { t: usize, v: usize, n: usize },
    #[error(
        "the problem gives its boundary parts by Gmsh physical group ({groups}), but {mesh} is a built-in mesh without groups, and no Dirichlet edge is left: use a Gmsh mesh (gmsh:PATH.msh) or give the parts as predicates in x and y"
    )]
    GroupsOnBuiltIn { mesh: String, groups: String },
    /// The problem's parts change inside a boundary edge of a built-in mesh
    /// ([`Mesh::check_parts_whole`]).
    #[error(
        "the boundary parts change inside an edge of {mesh}: the edge from {} to {} is {edge:?} at its midpoint but {here:?} at {}; a part must end at a vertex of the mesh: choose a mesh whose grid lines meet the end of the part, or write the part's end where they do",
        crate::base::number::point(*.a), crate::base::number::point(*.b), crate::base::number::point([*.x, *.y])
    )]
    PartInsideEdge { mesh: String, x: f64, y: f64, here: Part, edge: Part, a: [f64; 2], b: [f64; 2] },
    /// A point the problem requires to be a vertex (`origin`: where it declares it) is not one;
    /// `outside` says so with the mesh's extent when it lies outside the mesh's bounding box.
    /// `remedy` says which meshes have a vertex there ([`vertex_remedy`]).
    #[error("{origin}: {} is not a vertex of the mesh{}{remedy}", crate::base::number::point([*.x, *.y]), outside.as_ref().map(|o| format!(" (it lies outside the mesh, {o})")).unwrap_or_default())]
    MissingVertex { origin: String, x: f64, y: f64, outside: Option<String>, remedy: String },
    /// A load break line x = c that no element crosses (`origin`: where the problem declares it).
    #[error("{origin}: the line x = {c} does not cross the mesh ({extent}): a load break is a line x = c inside the body")]
    LoadBreakOutside { origin: String, c: f64, extent: String },
    /// A Gmsh file that cannot be read, is malformed or does not fit the problem; `line` is the
    /// 1-based line of the file where that shows (None for a binary file or a missing section).
    #[error("{}{}: {}", file.display(), line.map(|l| format!(", line {l}")).unwrap_or_default(), crate::base::input::excerpt(message))]
    Gmsh { file: PathBuf, line: Option<usize>, message: String },
}

/// The forms of a mesh description.
const SPEC_FORMS: &str = "'structured:N' or 'symmetric:N' with N a positive integer (N even keeps y = 0.5 a vertex), or 'gmsh:PATH.msh'";

/// Why symmetric:N needs N even, and what to use (`suggest`).
fn even_symmetric(suggest: &str) -> String {
    format!(
        "N even (it mirrors the lower N/2 rows of squares onto the upper half about y = 0.5, so y = 0.5 must be a grid line): use {suggest}, or structured:N for any N"
    )
}

impl MeshError {
    /// What a mesh description [`MeshSpec::parse`] refused should be, in the parser's own words
    /// without the description (a manifest's "key `run[0].mesh`: expected .., got .." names it);
    /// for any other error its message.
    pub fn expected(&self) -> String {
        match self {
            MeshError::BadSpec(_) => SPEC_FORMS.to_string(),
            MeshError::OddSymmetric { suggest, .. } => format!("symmetric:N with {}", even_symmetric(suggest)),
            other => other.to_string(),
        }
    }
}

/// How a mesh is described on the command line and in manifests.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MeshSpec {
    /// The unit square, N x N squares, each cut by the diagonal from lower-left to upper-right.
    Structured(usize),
    /// The unit square with the structured mesh on the lower half mirrored onto the upper half:
    /// symmetric about y = 0.5 (N even).
    Symmetric(usize),
    /// A Gmsh file (MSH 4.1, ASCII or binary): its linear triangles, its boundary edges tagged by
    /// physical group through [`Problem::part_of_group`] ([`gmsh`]).
    Gmsh(PathBuf),
}

impl MeshSpec {
    /// The initial mesh when none is given (`adapt --mesh`, a manifest's `mesh`).
    pub const DEFAULT: &str = "structured:4";

    pub fn parse(s: &str) -> Result<Self, MeshError> {
        let bad = || MeshError::BadSpec(s.to_string());
        let (kind, rest) = s.split_once(':').ok_or_else(bad)?;
        if kind.trim() == "gmsh" {
            return if rest.trim().is_empty() { Err(bad()) } else { Ok(MeshSpec::Gmsh(PathBuf::from(rest.trim()))) };
        }
        let n: usize = rest.trim().parse().map_err(|_| bad())?;
        match kind.trim() {
            "structured" if n >= 1 => Ok(MeshSpec::Structured(n)),
            "symmetric" if n >= 2 && n.is_multiple_of(2) => Ok(MeshSpec::Symmetric(n)),
            "symmetric" => {
                let suggest = match n {
                    0 | 1 => "symmetric:2".to_string(),
                    _ => format!("symmetric:{} or symmetric:{}", n - 1, n as u128 + 1),
                };
                Err(MeshError::OddSymmetric { spec: s.to_string(), suggest })
            }
            _ => Err(bad()),
        }
    }

    /// The mesh file this description reads, if any.
    pub fn file(&self) -> Option<&std::path::Path> {
        match self {
            MeshSpec::Gmsh(p) => Some(p),
            _ => None,
        }
    }

    /// Number of P2 unknowns of the mesh before building it, as a float (a mistyped N overflows
    /// any integer type): 2 (2N + 1)^2 for the unit square; for a Gmsh file 2 (V + E), V vertices
    /// and E = (3 T + B) / 2 edges of its T triangles and B boundary edges (the file is read).
    pub fn ndof(&self) -> Result<f64, MeshError> {
        match self {
            MeshSpec::Structured(n) | MeshSpec::Symmetric(n) => Ok(2.0 * (2.0 * *n as f64 + 1.0).powi(2)),
            MeshSpec::Gmsh(path) => gmsh::read(path).map(|f| f.ndof()),
        }
    }

    /// Build the mesh. The unit square's boundary edges are tagged by `problem.part_of(edge
    /// midpoint)`, a Gmsh mesh's by `problem.part_of_group(physical group)` (with the group's
    /// `problem.curve_of_group`).
    pub fn build(&self, problem: &dyn Problem) -> Result<Mesh, MeshError> {
        let part_of = |x: [f64; 2]| problem.part_of(x);
        let mesh = match self {
            MeshSpec::Structured(n) => Mesh::unit_square(*n, false, &part_of),
            MeshSpec::Symmetric(n) => Mesh::unit_square(*n, true, &part_of),
            MeshSpec::Gmsh(path) => gmsh::read(path)?.mesh(problem)?,
        };
        // a problem written for a Gmsh mesh (parts by physical group) on a built-in mesh, which has
        // no groups: without this its predicates tag nothing Dirichlet and the system is singular
        let groups = problem.groups();
        if self.file().is_none() && !groups.is_empty() && !mesh.boundary.iter().any(|e| e.part == Part::Dirichlet) {
            return Err(MeshError::GroupsOnBuiltIn { mesh: self.to_string(), groups: groups.join(", ") });
        }
        if self.file().is_none() {
            mesh.check_parts_whole(self, &part_of, &|x| problem.part_comparisons(x))?;
        }
        // what the problem declares of its mesh, named where it declares it (refinement keeps
        // the vertices: the initial mesh is where they are checked)
        mesh.check_declared_vertices(&problem.required_vertices_declared())?;
        mesh.check_load_breaks(&problem.load_breaks_declared())?;
        Ok(mesh)
    }
}

impl fmt::Display for MeshSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshSpec::Structured(n) => write!(f, "structured:{n}"),
            MeshSpec::Symmetric(n) => write!(f, "symmetric:{n}"),
            MeshSpec::Gmsh(p) => write!(f, "gmsh:{}", p.display()),
        }
    }
}

impl Mesh {
    /// The first 16 hex digits of the SHA-256 of the mesh: vertex coordinates (their bits),
    /// triangles (vertex order included) and boundary edges with their parts. Two meshes with
    /// the same fingerprint are the same mesh, numbered the same way: what a replayed refinement
    /// history checks at every level.
    pub fn fingerprint(&self) -> String {
        use sha2::Digest;
        let mut h = sha2::Sha256::new();
        for v in &self.vertices {
            h.update(v[0].to_bits().to_le_bytes());
            h.update(v[1].to_bits().to_le_bytes());
        }
        for t in &self.triangles {
            t.iter().for_each(|i| h.update((*i as u64).to_le_bytes()));
        }
        for e in &self.boundary {
            e.v.iter().for_each(|i| h.update((*i as u64).to_le_bytes()));
            h.update(e.part.code().to_le_bytes());
        }
        h.finalize().iter().take(8).map(|b| format!("{b:02x}")).collect()
    }

    /// The unit square cut into n x n squares. Each square is split by its lower-left to
    /// upper-right diagonal; with `mirror`, squares in the upper half use the other diagonal so
    /// the mesh is symmetric about y = 0.5. Triangles are listed with the diagonal as the edge
    /// opposite their first vertex (the refinement edge of newest-vertex bisection).
    pub fn unit_square(n: usize, mirror: bool, part_of: &dyn Fn([f64; 2]) -> Part) -> Mesh {
        let idx = |i: usize, j: usize| j * (n + 1) + i;
        let h = 1.0 / n as f64;
        let mut vertices = Vec::with_capacity((n + 1) * (n + 1));
        for j in 0..=n {
            for i in 0..=n {
                vertices.push([i as f64 * h, j as f64 * h]);
            }
        }
        // exact 0.5 etc. for nice coordinates on symmetric meshes
        let mut triangles = Vec::with_capacity(2 * n * n);
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
                let upper = mirror && 2 * j >= n;
                if !upper {
                    // diagonal a-c; vertex opposite it first, counter-clockwise
                    triangles.push([b, c, a]);
                    triangles.push([d, a, c]);
                } else {
                    // diagonal d-b
                    triangles.push([a, b, d]);
                    triangles.push([c, d, b]);
                }
            }
        }
        let mut boundary = Vec::with_capacity(4 * n);
        for i in 0..n {
            boundary.push((idx(i, 0), idx(i + 1, 0))); // bottom, left to right
            boundary.push((idx(n, i), idx(n, i + 1))); // right, upwards
            boundary.push((idx(i + 1, n), idx(i, n))); // top, right to left
            boundary.push((idx(0, i + 1), idx(0, i))); // left, downwards
        }
        let boundary = boundary
            .into_iter()
            .map(|(a, b)| {
                let m = [0.5 * (vertices[a][0] + vertices[b][0]), 0.5 * (vertices[a][1] + vertices[b][1])];
                BoundaryEdge { v: [a, b], part: part_of(m), curve: None }
            })
            .collect();
        Mesh { vertices, triangles, boundary }
    }

    /// Every boundary edge of a built-in mesh lies in one part of the boundary: the predicates
    /// give the edge's part (its midpoint's, which refinement hands down) at [`PART_SAMPLES`] - 1
    /// points inside it, and on both sides of every point where one of the predicates'
    /// comparisons (`comparisons`, lhs - rhs) changes sign, located by bisection between the
    /// ends and those points. A part that ends inside an edge would be decided by the midpoint,
    /// and the contact or Dirichlet part would silently grow or shrink to the mesh's vertices
    /// (contact for y < 0.6 would read as y < 0.5 on structured:4; a band 0.002 wide between two
    /// samples would be dropped on structured:4 and 8, refused on 16). What can still
    /// escape: one comparison that changes sign twice between two adjacent samples (a band
    /// written as a single comparison, `(y - c)^2 < w^2`, narrower than 1/16 of an edge), and a
    /// change within [`PART_END`] of the body's size from an end of the edge (the `1e-12` of
    /// `y < 1e-12`).
    fn check_parts_whole(
        &self,
        spec: &MeshSpec,
        part_of: &dyn Fn([f64; 2]) -> Part,
        comparisons: &dyn Fn([f64; 2]) -> Vec<f64>,
    ) -> Result<(), MeshError> {
        let (lo, hi) = self.vertices.iter().fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), v| {
            ([lo[0].min(v[0]), lo[1].min(v[1])], [hi[0].max(v[0]), hi[1].max(v[1])])
        });
        let end = PART_END * (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        for e in &self.boundary {
            let [a, b] = e.v.map(|v| self.vertices[v]);
            let at = |t: f64| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            let len = dist(a, b);
            let mut probes: Vec<f64> = (1..PART_SAMPLES).map(|k| k as f64 / PART_SAMPLES as f64).collect();
            probes.extend(switches(&|t| comparisons(at(t))).into_iter().filter(|&t| t * len > end && (1.0 - t) * len > end));
            for t in probes {
                let x = at(t);
                let here = part_of(x);
                if here != e.part {
                    return Err(MeshError::PartInsideEdge { mesh: spec.to_string(), x: x[0], y: x[1], here, edge: e.part, a, b });
                }
            }
        }
        Ok(())
    }

    pub fn n_vertices(&self) -> usize {
        self.vertices.len()
    }

    pub fn n_triangles(&self) -> usize {
        self.triangles.len()
    }

    /// Vertex coordinates of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [[f64; 2]; 3] {
        let [a, b, c] = self.triangles[t];
        [self.vertices[a], self.vertices[b], self.vertices[c]]
    }

    /// The body's outward unit normal at `x` on boundary edge `b`: its curve's
    /// ([`Curve::outward`]) where the edge lies on one, else the straight edge's (to the right of
    /// `v[0] -> v[1]`, which runs counter-clockwise along the boundary). What `normal =
    /// "outward"` takes, edge by edge: at a vertex the two edges may disagree (a corner), which
    /// `contact::plausible` refuses on the contact part. A zero component is +0.
    pub fn outward_at(&self, b: usize, x: [f64; 2]) -> [f64; 2] {
        let e = &self.boundary[b];
        let [p, q] = e.v.map(|v| self.vertices[v]);
        let (tx, ty) = (q[0] - p[0], q[1] - p[1]);
        let l = tx.hypot(ty);
        let chord = [ty / l, -tx / l];
        let n = e.curve.map_or(chord, |c| c.outward(x, chord));
        [n[0] + 0.0, n[1] + 0.0]
    }

    /// Signed area of triangle `t` (positive for counter-clockwise).
    pub fn area(&self, t: usize) -> f64 {
        let [a, b, c] = self.corners(t);
        0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
    }

    /// Diameter of triangle `t` (its longest edge).
    pub fn diameter(&self, t: usize) -> f64 {
        let p = self.corners(t);
        (0..3).map(|i| dist(p[i], p[(i + 1) % 3])).fold(0.0, f64::max)
    }

    /// The number of P2 degrees of freedom, 2 x (vertices + edges), counted without numbering the
    /// edges: a triangulation has (3 triangles + boundary edges) / 2 edges.
    pub fn p2_ndof(&self) -> usize {
        2 * (self.n_vertices() + (3 * self.n_triangles() + self.boundary.len()) / 2)
    }

    /// (h_min, h_max) over the triangles' diameters (paper Section 3).
    pub fn h_range(&self) -> (f64, f64) {
        (0..self.n_triangles()).map(|t| self.diameter(t)).fold((f64::INFINITY, 0.0), |(lo, hi), d| (lo.min(d), hi.max(d)))
    }

    /// Smallest interior angle over all triangles, in degrees.
    pub fn min_angle_degrees(&self) -> f64 {
        let mut min = f64::INFINITY;
        for t in 0..self.n_triangles() {
            let p = self.corners(t);
            for i in 0..3 {
                let (a, b, c) = (p[i], p[(i + 1) % 3], p[(i + 2) % 3]);
                let u = [b[0] - a[0], b[1] - a[1]];
                let v = [c[0] - a[0], c[1] - a[1]];
                let cos = (u[0] * v[0] + u[1] * v[1]) / (dist(a, b) * dist(a, c));
                min = min.min(cos.clamp(-1.0, 1.0).acos().to_degrees());
            }
        }
        min
    }

    /// Check positive areas, element shapes the coordinates resolve
    /// ([`precision::SHAPE_ROUNDOFF_REFUSED`]), conformity (every edge in one or two triangles),
    /// and that the tagged edges are exactly the boundary edges: every solve, at every level. That no two triangles
    /// overlap is checked where a mesh enters ([`Mesh::check_overlap`]: the Gmsh reader, which
    /// names the file's lines; a mesh built by hand should be checked with it too), not at every
    /// level: about 3 us a triangle, and refinement keeps it (bisection of a mesh without
    /// overlap has none; a boundary vertex moved onto its curve could reach another part of a
    /// thin body only by turning a triangle over, which the area check refuses).
    pub fn check(&self) -> Result<(), MeshError> {
        let n = self.n_vertices();
        for (t, tri) in self.triangles.iter().enumerate() {
            for &v in tri {
                if v >= n {
                    return Err(MeshError::BadVertex { t, v, n });
                }
            }
            let area = self.area(t);
            if !(area > 0.0) {
                return Err(MeshError::NonPositiveArea { t, area });
            }
        }
        self.check_shape_roundoff()?;
        // every edge once per triangle, sorted: an edge's triangles are a run of equal keys (a
        // sort rather than a hash map: 5x faster on the meshes of the benchmark)
        let mut keys: Vec<(usize, usize)> = Vec::with_capacity(3 * self.triangles.len());
        for tri in &self.triangles {
            keys.extend(crate::base::element::EDGE_VERTICES.iter().map(|&[i, j]| key(tri[i], tri[j])));
        }
        keys.par_sort_unstable();
        let mut tagged: Vec<(usize, usize)> = self.boundary.iter().map(|e| key(e.v[0], e.v[1])).collect();
        tagged.sort_unstable();
        let count = |k: &(usize, usize)| keys.partition_point(|x| x <= k) - keys.partition_point(|x| x < k);
        for run in keys.chunk_by(|a, b| a == b) {
            let ((a, b), c) = (run[0], run.len());
            if c > 2 {
                return Err(MeshError::NonConforming { a, b, count: c });
            }
            if c == 1 && tagged.binary_search(&(a, b)).is_err() {
                return Err(MeshError::UntaggedBoundary { a, b });
            }
        }
        for &(a, b) in &tagged {
            if count(&(a, b)) != 1 {
                return Err(MeshError::TagNotOnBoundary { a, b });
            }
        }
        // no hanging nodes: a vertex lying inside another triangle's edge would make that edge
        // appear once only, but on the interior; the tag check above catches it because such an
        // edge is not tagged.
        Ok(())
    }

    /// Check that no two triangles overlap ([`overlap`]): a conforming, tagged topology can
    /// still be two bodies in one place, or crossing.
    pub fn check_overlap(&self) -> Result<(), MeshError> {
        match overlap::find(&self.vertices, &self.triangles) {
            Some(o) => Err(MeshError::Overlap { a: o.a, b: o.b, x: o.point[0], y: o.point[1] }),
            None => Ok(()),
        }
    }

    /// Check that each given point is a mesh vertex (e.g. the kink of the obstacle).
    pub fn check_vertices(&self, points: &[[f64; 2]]) -> Result<(), MeshError> {
        let declared: Vec<_> = points.iter().map(|&p| ("a required vertex".to_string(), p)).collect();
        self.check_declared_vertices(&declared)
    }

    /// [`Mesh::check_vertices`] for points with where they are declared (`origin`, p), which the
    /// error names; a point outside the mesh's bounding box is said to be so.
    pub fn check_declared_vertices(&self, points: &[(String, [f64; 2])]) -> Result<(), MeshError> {
        let ([x0, y0], [x1, y1]) = self.bounding_box();
        for (origin, p) in points {
            if !self.vertices.iter().any(|v| dist(*v, *p) < 1e-12) {
                let inside = (x0..=x1).contains(&p[0]) && (y0..=y1).contains(&p[1]);
                let outside = (!inside).then(|| format!("which spans x in [{x0}, {x1}], y in [{y0}, {y1}]"));
                let all: Vec<[f64; 2]> = points.iter().map(|(_, p)| *p).collect();
                let remedy = if outside.is_some() { String::new() } else { vertex_remedy(*p, &all) };
                return Err(MeshError::MissingVertex { origin: origin.clone(), x: p[0], y: p[1], outside, remedy });
            }
        }
        Ok(())
    }

    /// Check that each load break line x = c (with where it is declared) crosses the mesh:
    /// strictly between its smallest and largest x, or no element is cut by it and the value
    /// has no effect (an error, not a silently ignored input).
    pub fn check_load_breaks(&self, breaks: &[(String, f64)]) -> Result<(), MeshError> {
        let ([x0, _], [x1, _]) = self.bounding_box();
        match breaks.iter().find(|(_, c)| !(*c > x0 && *c < x1)) {
            Some((origin, c)) => {
                Err(MeshError::LoadBreakOutside { origin: origin.clone(), c: *c, extent: format!("which spans x in [{x0}, {x1}]") })
            }
            None => Ok(()),
        }
    }

    /// The smallest and the largest coordinates of the vertices.
    fn bounding_box(&self) -> ([f64; 2], [f64; 2]) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for v in &self.vertices {
            for k in 0..2 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        (lo, hi)
    }
}

/// What to do about a required vertex `p` the mesh lacks: the mesh given must have it, as no
/// mesh inserts one and refinement only keeps the vertices it starts from. Names the smallest
/// structured:N (and symmetric:N) with a vertex at `p` and at every point of `all` (the
/// problem's required vertices) in the unit square, when `p` is in it and one with N <=
/// [`REMEDY_MAX_N`] does.
fn vertex_remedy(p: [f64; 2], all: &[[f64; 2]]) -> String {
    let head = ": a required vertex (a `required_vertices` entry, a point constraint's point) must be a vertex of the mesh given; none is inserted, and refinement only keeps the vertices it starts from";
    let gmsh = "a Gmsh mesh needs a point there";
    let in_square = |q: &[f64; 2]| (0.0..=1.0).contains(&q[0]) && (0.0..=1.0).contains(&q[1]);
    let on_grid = |n: usize, q: [f64; 2]| dist(q.map(|c| (c * n as f64).round() * (1.0 / n as f64)), q) < 1e-12;
    let n = (1..=REMEDY_MAX_N).find(|&n| on_grid(n, p) && all.iter().filter(|q| in_square(q)).all(|&q| on_grid(n, q)));
    let in_square = in_square(&p);
    match n {
        Some(n) if in_square => {
            let even = if n % 2 == 0 { n } else { 2 * n };
            format!(
                "{head}. structured:N and symmetric:N have their vertices at (i/N, j/N): structured:{n} (or symmetric:{even}) and its multiples have one there and at every other required vertex in the unit square; {gmsh}"
            )
        }
        _ if in_square => format!(
            "{head}. No structured:N or symmetric:N with N <= {REMEDY_MAX_N} has one there (their vertices are at (i/N, j/N)); {gmsh}"
        ),
        _ => format!("{head}; {gmsh}"),
    }
}

/// The largest N [`vertex_remedy`] tries.
const REMEDY_MAX_N: usize = 4096;

#[inline]
pub fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// Undirected edge key.
#[inline]
pub fn key(a: usize, b: usize) -> (usize, usize) {
    if a < b { (a, b) } else { (b, a) }
}

/// Edges numbered in order of first appearance, found through a linked list per smaller vertex:
/// a triangle mesh has a handful of edges per vertex, so this beats hashing the vertex pair
/// (no crate offers this small a structure).
struct EdgeTable {
    edges: Vec<[usize; 2]>,
    /// Per vertex, the last edge inserted whose smaller vertex it is.
    head: Vec<usize>,
    /// Per edge, the previous edge with the same smaller vertex.
    next: Vec<usize>,
}

impl EdgeTable {
    const NONE: usize = usize::MAX;

    fn new(n_vertices: usize, capacity: usize) -> Self {
        EdgeTable { edges: Vec::with_capacity(capacity), head: vec![Self::NONE; n_vertices], next: Vec::with_capacity(capacity) }
    }

    fn find(&self, a: usize, b: usize) -> Option<usize> {
        let (lo, hi) = key(a, b);
        let mut e = self.head[lo];
        while e != Self::NONE {
            if self.edges[e][1] == hi {
                return Some(e);
            }
            e = self.next[e];
        }
        None
    }

    fn find_or_insert(&mut self, a: usize, b: usize) -> usize {
        if let Some(e) = self.find(a, b) {
            return e;
        }
        let (lo, hi) = key(a, b);
        self.edges.push([lo, hi]);
        self.next.push(self.head[lo]);
        self.head[lo] = self.edges.len() - 1;
        self.edges.len() - 1
    }
}

/// The P2 node numbering of a mesh: vertices first, then one node per edge (its midpoint).
#[derive(Clone, Debug)]
pub struct P2Nodes {
    pub n_vertices: usize,
    /// Edges as sorted vertex pairs; node `n_vertices + e` is the midpoint of edge `e`.
    pub edges: Vec<[usize; 2]>,
    /// Per triangle, its six nodes `[v0, v1, v2, m01, m12, m20]`.
    pub elements: Vec<[usize; 6]>,
    /// Coordinates of every node.
    pub coords: Vec<[f64; 2]>,
    /// The boundary part of every node: `None` inside; on a corner shared by two parts the
    /// strongest one in the order Dirichlet > Contact > Neumann (nodes on the closure of
    /// Gamma_D are Dirichlet nodes: the paper's spaces take the Dirichlet condition on the closed
    /// set Gamma_D, so a corner where Gamma_D meets Gamma_C carries no contact constraint).
    pub part: Vec<Option<Part>>,
    /// Per boundary node, the body's outward unit normal there ([`Mesh::outward_at`]) on the
    /// first boundary edge of the node's part (`None` inside): on a contact node, a contact
    /// edge's, what `normal = "outward"` gives it.
    pub outward: Vec<Option<[f64; 2]>>,
    /// Per boundary edge of the mesh (same order as `Mesh::boundary`), its three nodes
    /// `[a, b, midpoint]`.
    pub boundary_nodes: Vec<[usize; 3]>,
    /// Per triangle, for each local edge, `Some(index into Mesh::boundary)` if it is a boundary edge.
    pub element_boundary: Vec<[Option<usize>; 3]>,
    /// Per triangle and local edge, the neighbouring triangle across that edge (None on the boundary).
    pub neighbours: Vec<[Option<usize>; 3]>,
}

impl P2Nodes {
    pub fn new(mesh: &Mesh) -> Self {
        let nv = mesh.n_vertices();
        let mut edges = EdgeTable::new(nv, 3 * mesh.n_triangles() / 2 + mesh.boundary.len());
        let mut elements = Vec::with_capacity(mesh.n_triangles());
        let mut edge_owner: Vec<[Option<(usize, usize)>; 2]> = Vec::with_capacity(edges.edges.capacity());
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let mut nodes = [tri[0], tri[1], tri[2], 0, 0, 0];
            for (le, [i, j]) in crate::base::element::EDGE_VERTICES.iter().enumerate() {
                let e = edges.find_or_insert(tri[*i], tri[*j]);
                if e == edge_owner.len() {
                    edge_owner.push([None, None]);
                }
                if edge_owner[e][0].is_none() {
                    edge_owner[e][0] = Some((t, le));
                } else {
                    edge_owner[e][1] = Some((t, le));
                }
                nodes[3 + le] = nv + e;
            }
            elements.push(nodes);
        }
        let mut neighbours = vec![[None; 3]; mesh.n_triangles()];
        for owners in &edge_owner {
            if let [Some((t1, l1)), Some((t2, l2))] = owners {
                neighbours[*t1][*l1] = Some(*t2);
                neighbours[*t2][*l2] = Some(*t1);
            }
        }
        let mut coords = mesh.vertices.clone();
        for [a, b] in &edges.edges {
            let (pa, pb) = (mesh.vertices[*a], mesh.vertices[*b]);
            coords.push([0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])]);
        }
        let rank = |p: Part| match p {
            Part::Dirichlet => 3,
            Part::Contact => 2,
            Part::Neumann => 1,
        };
        let mut part: Vec<Option<Part>> = vec![None; coords.len()];
        let mut outward: Vec<Option<[f64; 2]>> = vec![None; coords.len()];
        let mut boundary_nodes = Vec::with_capacity(mesh.boundary.len());
        let mut element_boundary = vec![[None; 3]; mesh.n_triangles()];
        for (bi, be) in mesh.boundary.iter().enumerate() {
            let e = edges.find(be.v[0], be.v[1]).expect("a boundary edge of the mesh is an edge of a triangle");
            let m = nv + e;
            boundary_nodes.push([be.v[0], be.v[1], m]);
            for node in [be.v[0], be.v[1], m] {
                if part[node].is_none_or(|q| rank(be.part) > rank(q)) {
                    part[node] = Some(be.part);
                    outward[node] = Some(mesh.outward_at(bi, coords[node]));
                }
            }
            if let Some((t, le)) = edge_owner[e][0] {
                element_boundary[t][le] = Some(bi);
            }
        }
        let edges = edges.edges;
        P2Nodes { n_vertices: nv, edges, elements, coords, part, outward, boundary_nodes, element_boundary, neighbours }
    }

    pub fn len(&self) -> usize {
        self.coords.len()
    }

    pub fn is_empty(&self) -> bool {
        self.coords.is_empty()
    }
}

/// The outward unit normal of every boundary edge of the mesh (by index into `mesh.boundary`),
/// away from the third vertex of the triangle that holds the edge.
pub fn outward_normals(mesh: &Mesh, nodes: &P2Nodes) -> Vec<[f64; 2]> {
    let mut out = vec![[0.0; 2]; mesh.boundary.len()];
    for (t, local) in nodes.element_boundary.iter().enumerate() {
        for &b in local.iter().flatten() {
            let [p, q] = mesh.boundary[b].v.map(|v| mesh.vertices[v]);
            let inside = mesh.triangles[t].iter().map(|&v| mesh.vertices[v]).find(|&x| x != p && x != q).unwrap_or(p);
            let (tx, ty) = (q[0] - p[0], q[1] - p[1]);
            let l = tx.hypot(ty);
            let mut n = [ty / l, -tx / l];
            let m = [0.5 * (p[0] + q[0]) - inside[0], 0.5 * (p[1] + q[1]) - inside[1]];
            if n[0] * m[0] + n[1] * m[1] < 0.0 {
                n = [-n[0], -n[1]];
            }
            out[b] = n;
        }
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The disc bounded by `circle`, as eight triangles around its centre (refinement edges on
    /// the circle), its boundary Neumann on that curve.
    pub(crate) fn disc(circle: Curve) -> Mesh {
        let Curve::Circle { centre, radius } = circle;
        let mut vertices = vec![centre];
        for k in 0..8 {
            let a = std::f64::consts::FRAC_PI_4 * k as f64;
            vertices.push([centre[0] + radius * a.cos(), centre[1] + radius * a.sin()]);
        }
        let ring = |k: usize| 1 + k % 8;
        let triangles = (0..8).map(|k| [0, ring(k), ring(k + 1)]).collect();
        let boundary = (0..8).map(|k| BoundaryEdge { v: [ring(k), ring(k + 1)], part: Part::Neumann, curve: Some(circle) }).collect();
        let m = Mesh { vertices, triangles, boundary };
        m.check().unwrap();
        m
    }

    fn tag(x: [f64; 2]) -> Part {
        if x[1] < 1e-12 {
            Part::Contact
        } else if x[1] > 1.0 - 1e-12 {
            Part::Dirichlet
        } else {
            Part::Neumann
        }
    }

    #[test]
    fn structured_mesh_counts_and_checks() {
        let m = Mesh::unit_square(4, false, &tag);
        assert_eq!(m.n_vertices(), 25);
        assert_eq!(m.n_triangles(), 32);
        m.check().unwrap();
        let p2 = P2Nodes::new(&m);
        assert_eq!(p2.len(), 81); // (2N+1)^2
        let total: f64 = (0..m.n_triangles()).map(|t| m.area(t)).sum();
        assert!((total - 1.0).abs() < 1e-14);
        // corners of the contact boundary touching Dirichlet? none here: y=0 vs y=1
        assert_eq!(p2.part[0], Some(Part::Contact));
        assert_eq!(p2.part[24], Some(Part::Dirichlet));
    }

    #[test]
    fn symmetric_mesh_is_symmetric() {
        let m = Mesh::unit_square(4, true, &tag);
        m.check().unwrap();
        let p2 = P2Nodes::new(&m);
        for p in &p2.coords {
            let q = [p[0], 1.0 - p[1]];
            assert!(p2.coords.iter().any(|c| dist(*c, q) < 1e-14));
        }
    }

    #[test]
    fn checks_catch_bad_meshes() {
        let mut m = Mesh::unit_square(2, false, &tag);
        m.triangles[0].swap(1, 2);
        assert!(matches!(m.check(), Err(MeshError::NonPositiveArea { .. })));
        let mut m = Mesh::unit_square(2, false, &tag);
        m.boundary.pop();
        assert!(matches!(m.check(), Err(MeshError::UntaggedBoundary { .. })));
        // a triangle twice: its interior edges are in three triangles
        let mut m = Mesh::unit_square(2, false, &tag);
        let t = m.triangles[3];
        m.triangles.push(t);
        assert!(matches!(m.check(), Err(MeshError::NonConforming { count: 3, .. })), "{:?}", m.check());
        // a tag on an interior edge (the diagonal of the first triangle that is not on x, y in {0, 1})
        let mut m = Mesh::unit_square(2, false, &tag);
        let interior = (0..m.n_triangles())
            .flat_map(|t| crate::base::element::EDGE_VERTICES.map(|[i, j]| [m.triangles[t][i], m.triangles[t][j]]))
            .find(|e| {
                e.iter().any(|&v| {
                    let x = m.vertices[v];
                    x[0] > 0.0 && x[0] < 1.0 && x[1] > 0.0 && x[1] < 1.0
                })
            })
            .unwrap();
        let mut edge = m.boundary[0];
        edge.v = interior;
        m.boundary.push(edge);
        assert!(matches!(m.check(), Err(MeshError::TagNotOnBoundary { .. })), "{:?}", m.check());
        // two bodies crossing (the square and a copy shifted by (0.5, 0.25)), each conforming
        // and tagged: the overlap is found, with a point in both
        let m = Mesh::unit_square(2, false, &tag);
        let n = m.n_vertices();
        let mut two = m.clone();
        two.vertices.extend(m.vertices.iter().map(|v| [v[0] + 0.5, v[1] + 0.25]));
        two.triangles.extend(m.triangles.iter().map(|t| t.map(|v| v + n)));
        two.boundary.extend(m.boundary.iter().map(|e| BoundaryEdge { v: e.v.map(|v| v + n), ..*e }));
        assert!(two.check().is_ok());
        match two.check_overlap() {
            Err(MeshError::Overlap { a, b, x, y }) => {
                assert!(a < m.n_triangles() && b >= m.n_triangles(), "{a} {b}");
                assert!(x > 0.5 && x < 1.0 && y > 0.25 && y < 1.0, "({x}, {y})");
            }
            other => panic!("{other:?}"),
        }
        assert!(MeshSpec::parse("structured:x").is_err());
        assert!(MeshSpec::parse("structured").is_err());
        assert!(MeshSpec::parse("cube:4").is_err());
        assert_eq!(MeshSpec::parse("structured:8").unwrap(), MeshSpec::Structured(8));
    }
}
