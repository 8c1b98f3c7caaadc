//! Gmsh meshes (`--mesh gmsh:PATH.msh`): MSH 4.1 files, ASCII or binary, read with the
//! [`mshio`] crate.
//!
//! * The mesh is made of the file's linear triangles (element type 2); the harness makes the P2
//!   nodes itself ([`P2Nodes`](super::P2Nodes)). Triangles are turned counter-clockwise where the
//!   file lists them clockwise, and each is listed with its longest edge opposite its first vertex
//!   (the refinement edge of newest-vertex bisection, [`refine`](super::refine)).
//! * Boundary parts come from the physical groups of the file's 1D elements (type 2-node lines):
//!   each group's name (from `$PhysicalNames`; a group without a name is called by its number) is
//!   mapped to a [`Part`] by [`Problem::part_of_group`] and to an optional curve by
//!   [`Problem::curve_of_group`]. A group the problem does not name, a boundary edge of the
//!   triangulation in no group, a line element that is not a boundary edge, and an element
//!   naming a node the file does not have are errors naming the file and the line.
//! * Points (type 15) are ignored, and so is every physical group of dimension 0 or 2; any other
//!   element type (quadrangles, second-order triangles or lines, 3D elements) is an error.
//! * Nodes are placed by their tags, whatever the order of the blocks and of the tags within a
//!   block (sparse tags too); a tag listed twice is an error. Nodes must lie in the plane z = 0.
//!   Nodes not used by any triangle are dropped; the others become the mesh's vertices in
//!   ascending tag order (for a file Gmsh wrote without renumbering, the file's order).
//! * The triangles must form one mesh: no edge in three triangles or twice in one direction (one
//!   folded over another, `check_folds`), and no two triangles overlapping geometrically (two
//!   bodies in one place or crossing, [`overlap`](super::overlap)); the error names both
//!   triangles, their lines and a point inside both.
//! * A partitioned file (`$PartitionedEntities`) is refused by name: its elements sit on
//!   partition entities, whose groups are their parents' (`refuse_partitioned`).
//!
//! Sections the harness does not read (`$Comments`, data sections, any other) are skipped
//! wherever they appear, before `$MeshFormat` too, as gmsh skips them: `msh_sections` blanks
//! them before any reader sees the bytes.
//!
//! `mshio` parses the `$MeshFormat`, `$Entities`, `$Nodes` and `$Elements` sections but not
//! `$PhysicalNames`, so that small section (`dim tag "name"` per line, ASCII in binary files too)
//! is read here. `mshio` also drops the node tags of a node section whose tags are contiguous (in
//! any order), so the tags are read by `mesh::msh_nodes` in every case. `mshio`'s
//! errors carry the position in the file, turned into a line number here.

use super::{BoundaryEdge, Mesh, MeshError, Part, key, msh_nodes, msh_sections};
use crate::base::number::point;
use crate::problems::Problem;
use mshio::ElementType;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

/// A 1D element of a physical group: an edge `v` (vertex indices), its group (index into
/// [`GmshFile::groups`]) and its line in the file.
#[derive(Clone, Debug)]
struct GroupEdge {
    v: [usize; 2],
    group: usize,
    line: Option<usize>,
}

/// The contents of a Gmsh file the harness uses, before the problem tags its boundary.
#[derive(Clone, Debug)]
pub struct GmshFile {
    pub path: PathBuf,
    pub vertices: Vec<[f64; 2]>,
    /// Counter-clockwise, longest edge opposite the first vertex.
    pub triangles: Vec<[usize; 3]>,
    /// The file line of every triangle (None in a binary file).
    triangle_lines: Vec<Option<usize>>,
    edges: Vec<GroupEdge>,
    /// Names of the physical groups of the 1D elements, in order of first use in the file, with
    /// the line of their `$PhysicalNames` entry.
    pub groups: Vec<(String, Option<usize>)>,
}

fn error(path: &Path, line: Option<usize>, message: impl Into<String>) -> MeshError {
    MeshError::Gmsh { file: path.to_path_buf(), line, message: message.into() }
}

/// A mesh file that cannot be read, in the words the reader always used.
fn error_io(path: &Path, e: &std::io::Error) -> MeshError {
    error(path, None, format!("cannot read the mesh file: {e}"))
}

/// 1-based line of byte `offset` of `bytes`.
fn line_at(bytes: &[u8], offset: usize) -> usize {
    1 + bytes[..offset.min(bytes.len())].iter().filter(|&&b| b == b'\n').count()
}

/// `$PhysicalNames`: (dimension, tag) -> (name, line).
type PhysicalNames = HashMap<(i32, i32), (String, usize)>;

fn physical_names(path: &Path, bytes: &[u8]) -> Result<PhysicalNames, MeshError> {
    let mut names = HashMap::new();
    let text = String::from_utf8_lossy(bytes);
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim()));
    let Some((start, _)) = lines.find(|(_, l)| *l == "$PhysicalNames") else { return Ok(names) };
    let (n_line, n) = lines.next().ok_or_else(|| error(path, Some(start), "$PhysicalNames: the file ends before the number of names"))?;
    let n: usize = n.parse().map_err(|_| error(path, Some(n_line), format!("$PhysicalNames: expected the number of names, got {n:?}")))?;
    for _ in 0..n {
        let (i, l) =
            lines.next().ok_or_else(|| error(path, Some(n_line), format!("$PhysicalNames: the file ends before its {n} names")))?;
        let bad = || error(path, Some(i), format!("$PhysicalNames: expected `dimension tag \"name\"`, got {l:?}"));
        // fields separated by any run of spaces or tabs; the name is the rest of the line
        let field = |s: &str| s.split_once(char::is_whitespace).map(|(f, rest)| (f.to_string(), rest.trim_start().to_string()));
        let (dim, rest) = field(l).ok_or_else(bad)?;
        let (tag, rest) = field(&rest).ok_or_else(bad)?;
        let (dim, tag): (i32, i32) = (dim.parse().map_err(|_| bad())?, tag.parse().map_err(|_| bad())?);
        let name = rest.trim().strip_prefix('"').and_then(|s| s.strip_suffix('"')).ok_or_else(bad)?;
        // a problem names groups by name: two groups of one dimension under one name would be
        // one boundary part the file keeps apart (Gmsh itself gives a name one tag)
        if let Some(((_, other), (_, at))) = names.iter().find(|((d, t), (m, _))| *d == dim && *t != tag && m == name) {
            return Err(error(
                path,
                Some(i),
                format!(
                    "$PhysicalNames: the name \"{name}\" is given to groups {other} (line {at}) and {tag} of dimension {dim}: a name must be one group"
                ),
            ));
        }
        names.insert((dim, tag), (name.to_string(), i));
    }
    match lines.next() {
        Some((_, "$EndPhysicalNames")) => Ok(names),
        Some((i, l)) => Err(error(path, Some(i), format!("$PhysicalNames: expected $EndPhysicalNames after {n} names, got {l:?}"))),
        None => Err(error(path, None, "$PhysicalNames: the file ends before $EndPhysicalNames")),
    }
}

/// Element tag -> line, for an ASCII file's `$Elements` section (walked block by block: a block
/// header `dim entity type count`, then one element per line, its tag first).
fn element_lines(bytes: &[u8]) -> HashMap<u64, usize> {
    let mut out = HashMap::new();
    let text = String::from_utf8_lossy(bytes);
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim()));
    if lines.find(|(_, l)| *l == "$Elements").is_none() {
        return out;
    }
    let n_blocks = lines.next().and_then(|(_, l)| l.split_whitespace().next()?.parse::<usize>().ok()).unwrap_or(0);
    for _ in 0..n_blocks {
        let Some(count) = lines.next().and_then(|(_, l)| l.split_whitespace().nth(3)?.parse::<usize>().ok()) else { break };
        for _ in 0..count {
            let Some((i, l)) = lines.next() else { return out };
            if let Some(tag) = l.split_whitespace().next().and_then(|t| t.parse().ok()) {
                out.insert(tag, i);
            }
        }
    }
    out
}

/// A mesh file as [`crate::base::input::read`] reads it: a regular file (not `/dev/zero` or a
/// pipe: they have no end to read to) no larger than the memory this process can allocate
/// allows (parsing holds the file and its nodes and elements: about eight times its size).
pub const MESH_FILE: crate::base::input::Kind =
    crate::base::input::Kind { what: "a mesh", limit: crate::base::input::Limit::MemoryPerByte(8.0) };

/// A triangulation, not a folded or overlapping set of triangles: with every triangle turned
/// counter-clockwise, an edge inside the mesh is run through once in each direction by the two
/// triangles that share it. An edge run twice in the same direction belongs to two triangles
/// on the same side of it (one folded over the other); an edge in three or more triangles is
/// not a 2D mesh.
fn check_folds(
    path: &Path,
    vertices: &[[f64; 2]],
    triangles: &[[usize; 3]],
    tags: &[([u64; 3], u64)],
    line_of: &dyn Fn(u64) -> Option<usize>,
) -> Result<(), MeshError> {
    let mut seen: HashMap<[usize; 2], (usize, usize)> = HashMap::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (tri[i], tri[(i + 1) % 3]);
            let (count, first) = seen.entry([a.min(b), a.max(b)]).or_insert((0, t));
            *count += 1;
            let other = triangles[*first];
            let same_direction = *first != t && (0..3).any(|k| other[k] == a && other[(k + 1) % 3] == b);
            if same_direction || *count > 2 {
                let (tag, other_tag) = (tags[t].1, tags[*first].1);
                let [pa, pb] = [vertices[a], vertices[b]];
                let why = if *count > 2 {
                    "is shared by three or more triangles"
                } else {
                    "has both on the same side: one is folded over the other"
                };
                return Err(error(
                    path,
                    line_of(tag),
                    format!("triangles {other_tag} and {tag} overlap: their edge {}-{} {why}", point(pa), point(pb)),
                ));
            }
        }
    }
    Ok(())
}

/// No two triangles overlap geometrically ([`super::overlap`]): the topology [`check_folds`]
/// checks can be perfect for two bodies meshed in one place (each its own nodes) or crossing
/// each other, whose solution would be either body's at a point. Named by the
/// triangles' tags and lines and a point inside both.
fn check_overlaps(
    path: &Path,
    vertices: &[[f64; 2]],
    triangles: &[[usize; 3]],
    tags: &[([u64; 3], u64)],
    line_of: &LineOf,
) -> Result<(), MeshError> {
    let Some(o) = super::overlap::find(vertices, triangles) else { return Ok(()) };
    let (first, second) = (tags[o.a].1, tags[o.b].1);
    let at = line_of(first).map(|l| format!(" (line {l})")).unwrap_or_default();
    Err(error(
        path,
        line_of(second),
        format!(
            "triangles {first}{at} and {second} overlap: both hold the point {}; two bodies meshed in one place or crossing each other, or a body folded onto itself (the triangles of a mesh must meet only at shared edges and vertices)",
            point(o.point)
        ),
    ))
}

/// Every node of the `$Nodes` section by its tag (ascending: the order the vertices take). The
/// tags are the file's own, read by [`msh_nodes`] (`mshio` drops them when they look contiguous,
/// whatever their order), after checking that it and `mshio` read the same section; the
/// coordinates are `mshio`'s. A tag listed twice, a tag outside the header's range or a
/// coordinate that is not finite is an error naming the node (and its line in an ASCII file).
fn nodes_by_tag(
    path: &Path,
    bytes: &[u8],
    binary: bool,
    nodes: &mshio::Nodes<u64, i32, f64>,
) -> Result<BTreeMap<u64, [f64; 3]>, MeshError> {
    let fail = |m: String| error(path, None, m);
    let encoding = msh_nodes::Encoding::of(bytes)
        .filter(|e| e.binary == binary)
        .ok_or_else(|| fail("cannot read the encoding of the $MeshFormat header".into()))?;
    let section = msh_nodes::read(bytes, encoding)
        .map_err(fail)?
        .ok_or_else(|| fail("the $Nodes section is not where the file's sections lead".into()))?;
    section.check_against(nodes).map_err(fail)?;
    // The header's counts first, then each tag (our own reader's, which keeps every tag even where
    // mshio drops a section's contiguous-looking tags): in its range, listed once. A header that
    // declares more nodes than its range holds is then blamed on what is really wrong (a count the
    // blocks do not hold, a tag outside the declared range, a tag listed twice), never guessed.
    let (min, max) = (nodes.min_node_tag, nodes.max_node_tag);
    let listed: usize = nodes.node_blocks.iter().map(|b| b.nodes.len()).sum();
    if listed as u64 != nodes.num_nodes {
        return Err(fail(format!("the $Nodes header declares {} nodes, its blocks hold {listed}", nodes.num_nodes)));
    }
    let mut node_at: BTreeMap<u64, [f64; 3]> = BTreeMap::new();
    for (mine, theirs) in section.blocks.iter().zip(&nodes.node_blocks) {
        for ((&tag, &offset), n) in mine.tags.iter().zip(&mine.offsets).zip(&theirs.nodes) {
            let here = |message: String| error(path, (!binary).then(|| line_at(bytes, offset)), message);
            let at = [n.x, n.y, n.z];
            if let Some(c) = at.iter().find(|c| !c.is_finite()) {
                return Err(here(format!("node {tag} has the coordinate {c}: every coordinate must be a finite number")));
            }
            if !(min..=max).contains(&tag) {
                return Err(here(format!("node tag {tag} is outside the range {min} to {max} that the $Nodes header declares")));
            }
            if let Some(before) = node_at.insert(tag, at) {
                return Err(here(format!(
                    "node tag {tag} is listed twice, at ({}, {}, {}) and at ({}, {}, {})",
                    before[0], before[1], before[2], at[0], at[1], at[2]
                )));
            }
        }
    }
    Ok(node_at)
}

/// The linear triangles of the file, as node tags with their element tag.
type TriangleTags = Vec<([u64; 3], u64)>;
/// The 2-node lines of the file's physical groups: node tags, physical group, element tag.
type GroupLineTags = Vec<([u64; 2], i32, u64)>;
/// The line of an element in the file, by its tag (None in a binary file).
type LineOf<'a> = dyn Fn(u64) -> Option<usize> + 'a;
/// The vertex index of every node tag a triangle uses.
type VertexOf = HashMap<u64, usize>;
/// A physical group's name and the line of its `$PhysicalNames` entry.
type Group = (String, Option<usize>);
/// Triangles (vertex indices) with their lines in the file.
type Triangles = (Vec<[usize; 3]>, Vec<Option<usize>>);

/// Read and check a Gmsh file (everything that does not depend on the problem), phase by phase:
/// parse, nodes by tag, elements by kind, vertices, triangles, the boundary groups' edges.
pub fn read(path: &Path) -> Result<GmshFile, MeshError> {
    let bytes = crate::base::input::read(path, MESH_FILE).map_err(|e| match e {
        crate::base::input::InputError::Io { error, .. } => error_io(path, &error),
        other => error(path, None, other.to_string()),
    })?;
    let bytes = single_spaced(bytes);
    // the sections gmsh skips are skipped by every reader below: blanked, lines kept
    let bytes = msh_sections::blank_ignored(bytes).map_err(|(line, why)| error(path, Some(line), why))?;
    refuse_text_declared_binary(path, &bytes)?;
    refuse_truncated(path, &bytes)?;
    refuse_partitioned(path, &bytes)?;
    let names = physical_names(path, &bytes)?;
    let msh = parse(path, &bytes)?;
    let binary = msh.header.file_type != 0;
    let lines = if binary { HashMap::new() } else { element_lines(&bytes) };
    let line_of = |tag: u64| lines.get(&tag).copied();
    let nodes = msh.data.nodes.as_ref().ok_or_else(|| error(path, None, "the file has no $Nodes section"))?;
    let elements = msh.data.elements.as_ref().ok_or_else(|| error(path, None, "the file has no $Elements section"))?;
    let node_at = nodes_by_tag(path, &bytes, binary, nodes)?;
    let (tri_nodes, line_elems) = elements_by_kind(path, &msh, elements, &names, &line_of)?;
    let (vertices, used) = vertices_of(path, &tri_nodes, &node_at, &line_of)?;
    let (triangles, triangle_lines) = oriented_triangles(path, &vertices, &used, &tri_nodes, &line_of)?;
    check_folds(path, &vertices, &triangles, &tri_nodes, &line_of)?;
    check_overlaps(path, &vertices, &triangles, &tri_nodes, &line_of)?;
    let (edges, groups) = group_edges(path, line_elems, &used, &node_at, &names, &line_of)?;
    Ok(GmshFile { path: path.to_path_buf(), vertices, triangles, triangle_lines, edges, groups })
}

/// A file whose `$MeshFormat` header declares binary data (file-type 1) while it holds none is
/// refused as such: every binary MSH file holds zero bytes (the int 1 written after the header
/// alone has three), a text file none. Read as binary, its text ended "truncated" at the header.
fn refuse_text_declared_binary(path: &Path, bytes: &[u8]) -> Result<(), MeshError> {
    if !msh_nodes::Encoding::of(bytes).is_some_and(|e| e.binary) || bytes.contains(&0) {
        return Ok(());
    }
    let line = msh_sections::header(bytes).map(|h| line_at(bytes, h) + 1);
    Err(error(
        path,
        line,
        "the $MeshFormat header declares a binary file (file-type 1, its second field), but the data reads as text (the file holds no zero byte, where a binary file's int 1 after the header alone has three): write file-type 0 for an ASCII file (`4.1 0 8`), or save the mesh again as binary",
    ))
}

/// A file that ends inside a section it reads (the last section opened has no `$End` line, and
/// no line after its opening starts a section) is refused as truncated, naming the section and
/// where the file ends: read on, the cut data of a binary `$Nodes` section would be blamed on
/// whatever its bytes happen to read as (a node tag "the internally reserved value of 0").
fn refuse_truncated(path: &Path, bytes: &[u8]) -> Result<(), MeshError> {
    let Some(last) = msh_sections::walk(bytes).pop().filter(|s| s.end.is_none()) else { return Ok(()) };
    if bytes[last.body..].split(|&b| b == b'\n').any(|l| l.trim_ascii().starts_with(b"$")) {
        return Ok(());
    }
    let (name, end) = (&last.name, line_at(bytes, bytes.len().saturating_sub(1)));
    Err(error(
        path,
        Some(end),
        format!(
            "the file ends inside its ${name} section (opened at line {}): no line $End{name} and no section follow, so the file is truncated (cut short while written or copied); write or copy it again",
            line_at(bytes, last.start)
        ),
    ))
}

/// A partitioned file (Gmsh's `Mesh.partition`) puts its elements on partition entities, listed
/// in `$PartitionedEntities` with their parents' physical groups, which `mshio` does not read:
/// its boundary lines would come out in no group, and the problem's groups reported missing.
/// Refused, naming the section's line and how to write the mesh whole.
fn refuse_partitioned(path: &Path, bytes: &[u8]) -> Result<(), MeshError> {
    let at = bytes.split(|&b| b == b'\n').position(|l| l.trim_ascii_end() == b"$PartitionedEntities");
    match at {
        None => Ok(()),
        Some(i) => Err(error(
            path,
            Some(i + 1),
            "a partitioned mesh ($PartitionedEntities): its elements sit on partition entities, which this reader does not follow; write the mesh unpartitioned (without gmsh.model.mesh.partition, or `gmsh.model.mesh.unpartition()` before writing)",
        )),
    }
}

/// An ASCII file with every run of blanks (spaces, tabs, a carriage return) between two fields
/// made one space and none at the ends of a line, outside double quotes (a physical name keeps
/// its spaces); lines stay where they are, so every line number still names the file's line.
/// MSH separates fields by white space of any length, as Gmsh reads it, but `mshio` takes one
/// space only: it refuses a valid file written with aligned columns, naming a line far from the
/// first double space. A binary file is returned as it is (its data are bytes, not text).
fn single_spaced(bytes: Vec<u8>) -> Vec<u8> {
    if msh_nodes::Encoding::of(&bytes).is_none_or(|e| e.binary) {
        return bytes;
    }
    let blank = |b: u8| matches!(b, b' ' | b'\t' | b'\r');
    let mut out = Vec::with_capacity(bytes.len());
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        if i > 0 {
            out.push(b'\n');
        }
        let (mut quoted, mut gap) = (false, false);
        for &b in line {
            if !quoted && blank(b) {
                gap = true;
                continue;
            }
            if gap && out.last().is_some_and(|&c| c != b'\n') {
                out.push(b' ');
            }
            gap = false;
            quoted ^= b == b'"';
            out.push(b);
        }
    }
    out
}

/// The file parsed by `mshio`; its error turned into one naming the line. `mshio` has a few
/// `expect`s left on malformed input: a panic there is a malformed file too.
fn parse(path: &Path, bytes: &[u8]) -> Result<mshio::MshFile<u64, i32, f64>, MeshError> {
    // from the $MeshFormat line on: gmsh skips what comes before it (sections blanked by
    // `msh_sections::blank_ignored`, stray lines); mshio wants the header first
    let start = msh_sections::header(bytes);
    let parsed = std::panic::catch_unwind(|| {
        mshio::parse_msh_bytes(&bytes[start.unwrap_or(0)..]).map_err(|e| {
            let first = e.begin_msh_errors().next().or(e.backtrace.first());
            let (rest, kind) = first
                .map(|(r, k)| (r.len(), k.context().map_or_else(|| k.to_string(), |c| format!("cannot read the {c}"))))
                .unwrap_or((0, String::new()));
            let header = first.is_some_and(|(_, k)| {
                matches!(k, mshio::error::MshParserErrorKind::UnsupportedMshVersion | mshio::error::MshParserErrorKind::InvalidFileHeader)
            });
            // mshio places header errors past the header: they are on the line after $MeshFormat
            let offset = match header {
                true => start.map_or(0, |p| p + 12),
                false => bytes.len() - rest,
            };
            let within: Vec<String> = e.filter_msh_errors().skip(1).filter_map(|(_, k)| k.context().map(str::to_string)).collect();
            let end = if rest == 0 { " (the file ends here: truncated?)" } else { "" };
            let within = if within.is_empty() { String::new() } else { format!(" (in the {})", within.join(" of the ")) };
            // what gmsh writes on request and mshio does not read: say which option to turn off
            let advice = if kind.contains("parametric") || within.contains("parametric") {
                " (write the file with gmsh's option Mesh.SaveParametric = 0, its default)"
            } else {
                ""
            };
            (offset, format!("not a valid MSH 4.1 file: {kind}{within}{end}{advice}"))
        })
    });
    match parsed {
        Ok(Ok(m)) => Ok(m),
        Ok(Err((offset, message))) => Err(error(path, Some(line_at(bytes, offset)), message)),
        Err(_) => Err(error(path, None, "not a valid MSH 4.1 file (the MSH parser gave up)")),
    }
}

/// The `$Elements` section sorted by kind: the linear triangles, and the 2-node lines of curves
/// in a physical group (a curve in several groups is an error); points are ignored, any other
/// element type is an error.
fn elements_by_kind(
    path: &Path,
    msh: &mshio::MshFile<u64, i32, f64>,
    elements: &mshio::Elements<u64, i32>,
    names: &PhysicalNames,
    line_of: &LineOf,
) -> Result<(TriangleTags, GroupLineTags), MeshError> {
    let listed: usize = elements.element_blocks.iter().map(|b| b.elements.len()).sum();
    if listed as u64 != elements.num_elements {
        return Err(error(
            path,
            None,
            format!("the $Elements header declares {} elements, its blocks hold {listed}", elements.num_elements),
        ));
    }
    // the physical groups of every curve entity
    let curve_groups: HashMap<i32, Vec<i32>> = msh
        .data
        .entities
        .as_ref()
        .map(|e| e.curves.iter().map(|c| (c.tag, c.physical_tags.iter().map(|t| t.abs()).collect())).collect())
        .unwrap_or_default();
    let mut tri_nodes: TriangleTags = Vec::new();
    let mut line_elems: GroupLineTags = Vec::new();
    for block in &elements.element_blocks {
        let first = block.elements.first().map(|e| e.element_tag);
        match (block.entity_dim, block.element_type) {
            (2, ElementType::Tri3) => {
                tri_nodes.extend(block.elements.iter().map(|e| ([e.nodes[0], e.nodes[1], e.nodes[2]], e.element_tag)))
            }
            (1, ElementType::Lin2) => {
                let groups = curve_groups.get(&block.entity_tag).cloned().unwrap_or_default();
                if groups.len() > 1 {
                    return Err(error(
                        path,
                        first.and_then(line_of),
                        format!(
                            "curve {} is in {} physical groups ({}): one boundary part per edge is needed (a group of all walls beside the parts cannot be read; remove it or split the curve)",
                            block.entity_tag,
                            groups.len(),
                            groups.iter().map(|&g| group_name(names, g)).collect::<Vec<_>>().join(", ")
                        ),
                    ));
                }
                if let Some(&g) = groups.first() {
                    line_elems.extend(block.elements.iter().map(|e| ([e.nodes[0], e.nodes[1]], g, e.element_tag)));
                }
            }
            (0, ElementType::Pnt) => {}
            (dim, ty) => {
                return Err(error(
                    path,
                    first.and_then(line_of),
                    format!(
                        "elements of type {ty:?} (dimension {dim}): only linear triangles (type 2), 2-node lines (type 1) and points (type 15) are read (set Mesh.ElementOrder = 1 and Mesh.RecombineAll = 0)"
                    ),
                ));
            }
        }
    }
    if tri_nodes.is_empty() {
        return Err(error(path, None, "the file has no linear triangles (element type 2): a 2D mesh is expected"));
    }
    Ok((tri_nodes, line_elems))
}

/// Physical curve group `g` as messages name it: `"name" (tag g)`, or `tag g` without a name.
fn group_name(names: &PhysicalNames, g: i32) -> String {
    match names.get(&(1, g)) {
        Some((name, _)) => format!("\"{name}\" (tag {g})"),
        None => format!("tag {g}"),
    }
}

/// How far from z = 0, relative to the diagonal of the bounding box of the triangles' nodes, a
/// node may lie (CAD round-off) and be read as in the plane.
pub const PLANAR_TOLERANCE: f64 = 1e-12;

/// The vertices: the nodes of the triangles (each must be in `$Nodes`, in the plane z = 0), in
/// ascending tag order; with the vertex index of every node tag used.
fn vertices_of(
    path: &Path,
    tri_nodes: &TriangleTags,
    node_at: &BTreeMap<u64, [f64; 3]>,
    line_of: &LineOf,
) -> Result<(Vec<[f64; 2]>, VertexOf), MeshError> {
    let mut used: VertexOf = HashMap::new();
    for (tri, tag) in tri_nodes {
        for n in tri {
            if !node_at.contains_key(n) {
                return Err(error(path, line_of(*tag), format!("triangle {tag} names node {n}, which the $Nodes section does not have")));
            }
            used.insert(*n, usize::MAX);
        }
    }
    // CAD round-off leaves z = 1e-17 and the like: a z within PLANAR_TOLERANCE of the size of
    // the triangles' nodes (the diagonal of their bounding box) is taken as 0
    let bounds = used.keys().map(|n| node_at[n]).fold([f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY], |b, p| {
        [b[0].min(p[0]), b[1].min(p[1]), b[2].max(p[0]), b[3].max(p[1])]
    });
    let planar = PLANAR_TOLERANCE * (bounds[2] - bounds[0]).hypot(bounds[3] - bounds[1]);
    let mut vertices = Vec::with_capacity(used.len());
    for tag in node_at.keys() {
        if let Some(index) = used.get_mut(tag)
            && *index == usize::MAX
        {
            let [x, y, z] = node_at[tag];
            if !(z.abs() <= planar) {
                return Err(error(
                    path,
                    None,
                    format!(
                        "node {tag} has z = {}: a planar mesh in z = 0 is expected (|z| at most {PLANAR_TOLERANCE:e} times the mesh's size, {})",
                        crate::base::number::shown(z),
                        crate::base::number::shown(planar / PLANAR_TOLERANCE)
                    ),
                ));
            }
            *index = vertices.len();
            vertices.push([x, y]);
        }
    }
    Ok((vertices, used))
}

/// The triangles in vertex indices, counter-clockwise (none of zero or no finite area: a
/// [`scale_fault`] is named as such) and with the longest
/// edge opposite the first vertex; with their lines in the file.
fn oriented_triangles(
    path: &Path,
    vertices: &[[f64; 2]],
    used: &VertexOf,
    tri_nodes: &TriangleTags,
    line_of: &LineOf,
) -> Result<Triangles, MeshError> {
    let mut triangles = Vec::with_capacity(tri_nodes.len());
    let mut triangle_lines = Vec::with_capacity(tri_nodes.len());
    for (tri, tag) in tri_nodes {
        let [a, b, c] = tri.map(|n| used[&n]);
        let (pa, pb, pc) = (vertices[a], vertices[b], vertices[c]);
        let area = 0.5 * ((pb[0] - pa[0]) * (pc[1] - pa[1]) - (pb[1] - pa[1]) * (pc[0] - pa[0]));
        if !(area.abs() > 0.0 && area.is_finite()) {
            let why = scale_fault([pa, pb, pc], area).unwrap_or_else(|| "has zero area".to_string());
            return Err(error(path, line_of(*tag), format!("triangle {tag} {why}")));
        }
        let t = if area > 0.0 { [a, b, c] } else { [a, c, b] };
        // longest edge opposite the first vertex (first of equal lengths)
        let len = |i: usize| super::dist(vertices[t[(i + 1) % 3]], vertices[t[(i + 2) % 3]]);
        let first = (0..3).fold(0, |best, i| if len(i) > len(best) { i } else { best });
        triangles.push([t[first], t[(first + 1) % 3], t[(first + 2) % 3]]);
        triangle_lines.push(line_of(*tag));
    }
    Ok((triangles, triangle_lines))
}

/// Why a triangle whose computed `area` is zero or not a number is not degenerate, if it is
/// not: the scale of its coordinates. Lengths beyond about 1e154 square past f64's largest
/// number (the area is infinite, or NaN as inf - inf), lengths below about 1e-154 square to 0;
/// the same triangle with its coordinates divided by its longest edge has an area.
fn scale_fault(p: [[f64; 2]; 3], area: f64) -> Option<String> {
    use crate::base::number::shown;
    // hypot, not the square root of the squares: the lengths themselves neither overflow nor
    // underflow where their squares do
    let length = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let edges = [length(p[0], p[1]), length(p[1], p[2]), length(p[2], p[0])];
    let longest = edges.iter().fold(0.0f64, |a, &l| a.max(l));
    let size = p.iter().flatten().fold(0.0f64, |a, &v| a.max(v.abs()));
    let what = if !area.is_finite() { "an area that is not a finite number" } else { "an area that underflows to 0" };
    let advice = "f64 cannot hold the squares of lengths at that scale: rescale the mesh (other units)";
    if longest == 0.0 {
        return None;
    }
    if !longest.is_finite() {
        return Some(format!("has {what}: its coordinates reach {}, {advice}", shown(size)));
    }
    let q = p.map(|v| [v[0] / longest, v[1] / longest]);
    let scaled = 0.5 * ((q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]));
    (scaled.abs() > 0.0)
        .then(|| format!("has {what} at coordinates of size {} (its longest edge {}): {advice}", shown(size), shown(longest)))
}

/// The line elements of the physical groups as edges between vertices (a node of no triangle is
/// an error), and the groups in order of first use, named from `$PhysicalNames` (or by number).
fn group_edges(
    path: &Path,
    line_elems: GroupLineTags,
    used: &VertexOf,
    node_at: &BTreeMap<u64, [f64; 3]>,
    names: &PhysicalNames,
    line_of: &LineOf,
) -> Result<(Vec<GroupEdge>, Vec<Group>), MeshError> {
    let mut groups: Vec<Group> = Vec::new();
    let mut group_index: BTreeMap<i32, usize> = BTreeMap::new();
    let mut edges = Vec::with_capacity(line_elems.len());
    for ([a, b], g, tag) in line_elems {
        let v = [a, b].map(|n| used.get(&n).copied());
        let [Some(va), Some(vb)] = v else {
            let n = if v[0].is_none() { a } else { b };
            let why = if node_at.contains_key(&n) { "a node of no triangle" } else { "a node the $Nodes section does not have" };
            return Err(error(path, line_of(tag), format!("line element {tag} names node {n}, {why}")));
        };
        let group = *group_index.entry(g).or_insert_with(|| {
            let (name, line) = names.get(&(1, g)).map(|(n, l)| (n.clone(), Some(*l))).unwrap_or((g.to_string(), None));
            groups.push((name, line));
            groups.len() - 1
        });
        edges.push(GroupEdge { v: [va, vb], group, line: line_of(tag) });
    }
    distinct_group_names(path, &group_index, &groups)?;
    Ok((edges, groups))
}

/// A problem names a group by its name, an unnamed one by its tag: a group named "5" beside the
/// unnamed group 5 would be one boundary part the file keeps apart (both read as "5"), so a name
/// that is the tag of another group is refused.
fn distinct_group_names(path: &Path, group_index: &BTreeMap<i32, usize>, groups: &[Group]) -> Result<(), MeshError> {
    let mut seen: HashMap<&str, i32> = HashMap::new();
    for (&tag, &g) in group_index {
        let (name, line) = &groups[g];
        if let Some(other) = seen.insert(name.as_str(), tag) {
            let (named, unnamed) = if line.is_some() { (tag, other) } else { (other, tag) };
            return Err(error(
                path,
                groups[group_index[&named]].1,
                format!(
                    "the physical group {named} is named \"{name}\", the tag of the unnamed group {unnamed}: a problem naming \"{name}\" could not tell them apart; rename the group or name group {unnamed}"
                ),
            ));
        }
    }
    Ok(())
}

impl GmshFile {
    /// Every physical group `problem` names in its parts is a group of the file's boundary lines:
    /// a misspelt name (`["contcat", "contact"]`), a group of another dimension (a surface) or
    /// a group of another mesh would otherwise tag nothing, silently.
    fn check_named_groups(&self, problem: &dyn Problem) -> Result<(), MeshError> {
        let have: Vec<&str> = self.groups.iter().map(|(g, _)| g.as_str()).collect();
        for g in problem.groups() {
            if !have.contains(&g.as_str()) {
                return Err(error(
                    &self.path,
                    None,
                    format!(
                        "problem {} names the physical group \"{g}\", which is not a group of boundary lines of this file (its groups of lines: {}); a group of surfaces or points is not a boundary part",
                        problem.name(),
                        have.iter().map(|g| format!("\"{g}\"")).collect::<Vec<_>>().join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Both vertices of line element `e` lie on the curve `c` its group is declared on (within
    /// [`crate::problems::Curve::VERTEX_TOLERANCE`] of its size).
    fn check_on_curve(&self, c: &crate::problems::Curve, e: &GroupEdge, problem: &dyn Problem) -> Result<(), MeshError> {
        for v in e.v {
            let x = self.vertices[v];
            let off = c.relative_distance(x);
            if !(off <= crate::problems::Curve::VERTEX_TOLERANCE) {
                return Err(error(
                    &self.path,
                    e.line,
                    format!(
                        "the vertex {} of this line element of group \"{}\" is off the curve problem {} declares for the group ([curves]: {c:?}) by {off:.3e} of its size: the curve must be the one the mesh follows (refinement puts new boundary vertices on it)",
                        point(x),
                        self.groups[e.group].0,
                        problem.name()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Number of P2 unknowns: 2 (V + E), E counted from the triangles.
    pub fn ndof(&self) -> f64 {
        let mut count: HashMap<(usize, usize), u8> = HashMap::new();
        for t in &self.triangles {
            for [i, j] in crate::base::element::EDGE_VERTICES {
                *count.entry(key(t[i], t[j])).or_default() += 1;
            }
        }
        2.0 * (self.vertices.len() + count.len()) as f64
    }

    /// The mesh with its boundary tagged by `problem`'s names for the physical groups.
    pub fn mesh(&self, problem: &dyn Problem) -> Result<Mesh, MeshError> {
        let path = &self.path;
        // every group's part and curve, or the list of what the file has and the problem names
        let mut parts = Vec::with_capacity(self.groups.len());
        for (name, line) in &self.groups {
            match problem.part_of_group(name) {
                Some(p) => parts.push((p, problem.curve_of_group(name))),
                None if problem.groups().is_empty() && self.groups.iter().all(|(g, _)| problem.part_of_group(g).is_none()) => {
                    // a problem that names no group tags its parts by predicates or by its own rule
                    let declared = problem.declared_parts();
                    let how = if declared.is_empty() {
                        "by its own rule on x and y".to_string()
                    } else {
                        format!("by predicates on x and y ({})", declared.join("; "))
                    };
                    return Err(MeshError::Gmsh {
                        file: path.clone(),
                        line: *line,
                        message: format!(
                            "problem {} declares its boundary parts {how}, which tag the built-in meshes (structured:N, symmetric:N) only; a Gmsh mesh's parts are its physical groups, named in a problem file (`[parts] contact = [\"{name}\"]`, ...; docs/problems-and-meshes.md)",
                            problem.name(),
                        ),
                    });
                }
                None => {
                    let listed: Vec<String> = self
                        .groups
                        .iter()
                        .map(|(g, _)| match problem.part_of_group(g) {
                            Some(p) => format!("\"{g}\" ({p:?})"),
                            None => format!("\"{g}\" (not named by {})", problem.name()),
                        })
                        .collect();
                    return Err(MeshError::Gmsh {
                        file: path.clone(),
                        line: *line,
                        message: format!(
                            "physical group \"{name}\" is not a boundary part of problem {}: every physical group of boundary lines must be named by the problem; the file's groups: {}",
                            problem.name(),
                            listed.join(", ")
                        ),
                    });
                }
            }
        }
        self.check_named_groups(problem)?;
        // edges: owners (triangle, local edge)
        let mut owners: HashMap<(usize, usize), Vec<(usize, usize)>> = HashMap::new();
        for (t, tri) in self.triangles.iter().enumerate() {
            for (le, [i, j]) in crate::base::element::EDGE_VERTICES.iter().enumerate() {
                let o = owners.entry(key(tri[*i], tri[*j])).or_default();
                o.push((t, le));
                if o.len() > 2 {
                    return Err(MeshError::Gmsh {
                        file: path.clone(),
                        line: self.triangle_lines[t],
                        message: format!(
                            "the mesh is not conforming: this triangle's edge ({}, {}) is in three triangles",
                            tri[*i], tri[*j]
                        ),
                    });
                }
            }
        }
        let mut tag: HashMap<(usize, usize), &GroupEdge> = HashMap::new();
        for e in &self.edges {
            let k = key(e.v[0], e.v[1]);
            if owners.get(&k).is_none_or(|o| o.len() != 1) {
                return Err(MeshError::Gmsh {
                    file: path.clone(),
                    line: e.line,
                    message: format!("this line element of group \"{}\" is not a boundary edge of the triangles", self.groups[e.group].0),
                });
            }
            if let Some(prev) = tag.insert(k, e)
                && parts[prev.group].0 != parts[e.group].0
            {
                return Err(MeshError::Gmsh {
                    file: path.clone(),
                    line: e.line,
                    message: format!(
                        "this edge is in groups \"{}\" and \"{}\", which the problem makes different boundary parts",
                        self.groups[prev.group].0, self.groups[e.group].0
                    ),
                });
            }
        }
        let mut boundary = Vec::new();
        for (t, tri) in self.triangles.iter().enumerate() {
            for [i, j] in crate::base::element::EDGE_VERTICES {
                let k = key(tri[i], tri[j]);
                if owners[&k].len() != 1 {
                    continue;
                }
                let Some(e) = tag.get(&k) else {
                    let (p, q) = (self.vertices[tri[i]], self.vertices[tri[j]]);
                    return Err(MeshError::Gmsh {
                        file: path.clone(),
                        line: self.triangle_lines[t],
                        message: format!(
                            "this triangle's edge from {} to {} is on the boundary but in no physical group of lines: every boundary edge needs a part",
                            point(p),
                            point(q)
                        ),
                    });
                };
                let (part, curve): (Part, _) = parts[e.group];
                if let Some(c) = curve {
                    self.check_on_curve(&c, e, problem)?;
                }
                boundary.push(BoundaryEdge { v: [tri[i], tri[j]], part, curve });
            }
        }
        let mesh = Mesh { vertices: self.vertices.clone(), triangles: self.triangles.clone(), boundary };
        mesh.check()?;
        Ok(mesh)
    }
}
