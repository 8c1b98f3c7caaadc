//! The node tags of an MSH 4.1 file's `$Nodes` section, read from the file's bytes.
//!
//! Why this exists: `mshio` drops the tags of a whole `$Nodes` section whenever they span exactly
//! as many values as there are nodes (max - min = count - 1), leaving only the order in which the
//! blocks list the nodes. That order need not be the tags' order: Gmsh writes tags 3, 4, 1, 2
//! after renumbering, and so do other meshers. Reading the nodes in block order then permutes
//! the mesh (a correct solution of the wrong mesh). So the Gmsh reader takes every node's tag
//! from here, in every case, and checks that this scan and `mshio` agree on the section's
//! structure ([`Section::check_against`]).
//!
//! The section (after `$Nodes`): `numEntityBlocks numNodes minNodeTag maxNodeTag`, then per block
//! `entityDim entityTag parametric numNodesInBlock`, its `numNodesInBlock` tags, then three
//! coordinates per node. In an ASCII file these are whitespace-separated numbers; in a binary
//! file the counts and tags are `size_t` (the width the `$MeshFormat` header gives), the entity
//! fields `int` (4 bytes), the coordinates `double` (8 bytes), in the byte order of the header's
//! `int` 1. Parametric nodes (which `mshio` refuses) are not read here either.

/// How the numbers of a file are written (from its `$MeshFormat` header).
#[derive(Clone, Copy, Debug)]
pub struct Encoding {
    pub binary: bool,
    /// Bytes of a `size_t` in a binary file.
    pub size_t: usize,
    pub big_endian: bool,
}

impl Encoding {
    /// The encoding the `$MeshFormat` header of `bytes` declares (`version fileType dataSize`,
    /// then in a binary file the `int` 1 in the file's byte order); None without that header.
    pub fn of(bytes: &[u8]) -> Option<Encoding> {
        let start = super::msh_sections::header(bytes)? + 11;
        let line_start = start + bytes[start..].iter().position(|&b| b == b'\n')? + 1;
        let line_end = line_start + bytes[line_start..].iter().position(|&b| b == b'\n')?;
        let line = std::str::from_utf8(&bytes[line_start..line_end]).ok()?;
        let fields: Vec<&str> = line.split_whitespace().collect();
        let (binary, size_t) = (*fields.get(1)? == "1", fields.get(2)?.parse().ok()?);
        let big_endian = binary && bytes.get(line_end + 1..line_end + 5)? == [0, 0, 0, 1];
        Some(Encoding { binary, size_t, big_endian })
    }
}

/// One node block: its entity, and per node its tag, coordinates and the byte offset of its tag.
#[derive(Clone, Debug)]
pub struct Block {
    pub entity_dim: i32,
    pub entity_tag: i32,
    pub tags: Vec<u64>,
    pub coordinates: Vec<[f64; 3]>,
    pub offsets: Vec<usize>,
}

/// The `$Nodes` section as the file writes it.
#[derive(Clone, Debug)]
pub struct Section {
    pub num_nodes: u64,
    pub min_tag: u64,
    pub max_tag: u64,
    pub blocks: Vec<Block>,
}

/// A reader of the numbers of a section, ASCII or binary.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    encoding: Encoding,
}

impl Cursor<'_> {
    /// The next whitespace-separated token of an ASCII file, and its offset.
    fn token(&mut self, what: &str) -> Result<(usize, &str), String> {
        let b = self.bytes;
        while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let start = self.pos;
        while self.pos < b.len() && !b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        match std::str::from_utf8(&b[start..self.pos]) {
            Ok(t) if !t.is_empty() => Ok((start, t)),
            _ => Err(format!("the file ends or has no text where the $Nodes section's {what} should be")),
        }
    }

    /// The next `n` bytes of a binary file, in big-endian order, and their offset.
    fn raw(&mut self, n: usize, what: &str) -> Result<(usize, Vec<u8>), String> {
        let start = self.pos;
        let chunk = self.bytes.get(start..start + n).ok_or_else(|| format!("the file ends before the $Nodes section's {what}"))?;
        self.pos += n;
        let mut v = chunk.to_vec();
        if !self.encoding.big_endian {
            v.reverse();
        }
        Ok((start, v))
    }

    /// A count or a tag (`size_t`), and its offset.
    fn size_t(&mut self, what: &str) -> Result<(usize, u64), String> {
        if !self.encoding.binary {
            let (at, t) = self.token(what)?;
            return t.parse().map(|v| (at, v)).map_err(|_| format!("the $Nodes section's {what} is {t:?}, not a whole number"));
        }
        let (at, v) = self.raw(self.encoding.size_t, what)?;
        // a size_t wider than 8 bytes holds a value that fits in u64 only if its high bytes are 0
        let (high, low) = v.split_at(v.len().saturating_sub(8));
        if high.iter().any(|&b| b != 0) {
            return Err(format!("the $Nodes section's {what} does not fit in 64 bits"));
        }
        Ok((at, low.iter().fold(0u64, |acc, &b| (acc << 8) | b as u64)))
    }

    /// An entity field (`int`).
    fn int(&mut self, what: &str) -> Result<i32, String> {
        if !self.encoding.binary {
            let (_, t) = self.token(what)?;
            return t.parse().map_err(|_| format!("the $Nodes section's {what} is {t:?}, not an integer"));
        }
        let (_, v) = self.raw(4, what)?;
        Ok(i32::from_be_bytes([v[0], v[1], v[2], v[3]]))
    }

    /// A coordinate (`double`).
    fn double(&mut self, what: &str) -> Result<f64, String> {
        if !self.encoding.binary {
            let (_, t) = self.token(what)?;
            return t.parse().map_err(|_| format!("the $Nodes section's {what} is {t:?}, not a number"));
        }
        let (_, v) = self.raw(8, what)?;
        Ok(f64::from_be_bytes(std::array::from_fn(|i| v[i])))
    }
}

/// The byte offset just after the line `$Nodes` (its end of line included), found by walking the
/// file's sections from the start ([`super::msh_sections::walk`]).
fn nodes_start(bytes: &[u8]) -> Option<usize> {
    super::msh_sections::walk(bytes).into_iter().find(|s| s.name == "Nodes").map(|s| s.body)
}

/// Read the `$Nodes` section of `bytes` (an MSH 4.1 file `mshio` has parsed); None when the file
/// has no such section.
pub fn read(bytes: &[u8], encoding: Encoding) -> Result<Option<Section>, String> {
    let Some(pos) = nodes_start(bytes) else { return Ok(None) };
    let mut c = Cursor { bytes, pos, encoding };
    let (_, n_blocks) = c.size_t("number of blocks")?;
    let (_, num_nodes) = c.size_t("number of nodes")?;
    let (_, min_tag) = c.size_t("smallest node tag")?;
    let (_, max_tag) = c.size_t("largest node tag")?;
    let mut blocks = Vec::new();
    for b in 0..n_blocks {
        let what = |field: &str| format!("{field} of node block {} of {n_blocks}", b + 1);
        let entity_dim = c.int(&what("entity dimension"))?;
        let entity_tag = c.int(&what("entity tag"))?;
        if c.int(&what("parametric flag"))? != 0 {
            return Err(format!("{} is not 0: parametric nodes are not read", what("the parametric flag")));
        }
        let (_, n) = c.size_t(&what("number of nodes"))?;
        // every node takes at least two bytes of the file: a larger count is malformed
        if n > bytes.len() as u64 {
            return Err(format!("{} is {n}, more than the file can hold", what("the number of nodes")));
        }
        let (mut tags, mut offsets) = (Vec::with_capacity(n as usize), Vec::with_capacity(n as usize));
        for _ in 0..n {
            let (at, tag) = c.size_t(&what("node tags"))?;
            tags.push(tag);
            offsets.push(at);
        }
        let mut coordinates = Vec::with_capacity(n as usize);
        for _ in 0..n {
            coordinates.push([c.double(&what("x"))?, c.double(&what("y"))?, c.double(&what("z"))?]);
        }
        blocks.push(Block { entity_dim, entity_tag, tags, coordinates, offsets });
    }
    Ok(Some(Section { num_nodes, min_tag, max_tag, blocks }))
}

/// Two readings of one coordinate: the same number (NaN with NaN), up to the last bits two
/// correct decimal-to-binary conversions might differ in.
fn same(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan()) || (a - b).abs() <= 1e-14 * a.abs().max(b.abs())
}

impl Section {
    /// That `mshio` read the same section: the same header, blocks, entities, node counts and
    /// coordinates, and the same tags where it kept them. A disagreement is a bug of one of the
    /// two readers (or a file outside what both read), never a guess.
    pub fn check_against(&self, nodes: &mshio::Nodes<u64, i32, f64>) -> Result<(), String> {
        let differ = |what: String| Err(format!("the $Nodes section reads differently in two readers ({what}): the file is not read"));
        if (self.num_nodes, self.min_tag, self.max_tag) != (nodes.num_nodes, nodes.min_node_tag, nodes.max_node_tag) {
            return differ("its header".into());
        }
        if self.blocks.len() != nodes.node_blocks.len() {
            return differ(format!("{} or {} blocks", self.blocks.len(), nodes.node_blocks.len()));
        }
        for (i, (mine, theirs)) in self.blocks.iter().zip(&nodes.node_blocks).enumerate() {
            let block = format!("node block {} of {}", i + 1, self.blocks.len());
            if (mine.entity_dim, mine.entity_tag, mine.tags.len()) != (theirs.entity_dim, theirs.entity_tag, theirs.nodes.len()) {
                return differ(format!("{block}: its entity or its number of nodes"));
            }
            let at = |n: &mshio::Node<f64>| [n.x, n.y, n.z];
            if let Some(k) = (0..mine.tags.len()).find(|&k| !(0..3).all(|d| same(mine.coordinates[k][d], at(&theirs.nodes[k])[d]))) {
                return differ(format!("{block}: the coordinates of node {}", mine.tags[k]));
            }
            if let Some(map) = &theirs.node_tags
                && let Some((tag, _)) = map.iter().find(|&(&tag, &k)| mine.tags.get(k) != Some(&tag))
            {
                return differ(format!("{block}: node tag {tag}"));
            }
        }
        Ok(())
    }
}
