//! The symbolic Cholesky factorisation: which entries of L = chol(P K P^T) can be nonzero, and
//! how the columns of L group into supernodes (runs of columns with one row pattern below them,
//! stored as dense blocks), computed on the graph of the mesh nodes.
//!
//! The structure is exactly the one faer's supernodal symbolic factorisation computes for the
//! same permutation (the test in `tests/it/cholesky.rs` compares every array): the elimination tree
//! and the column counts of L, fundamental supernodes (column j joins column j - 1 when j is the
//! only parent of j - 1 and its column count is one less), faer's default relaxation (a supernode
//! absorbs the one just before it, its child, while the share of explicit zeros this adds stays
//! under 100% / 80% / 10% / 5% for up to 4 / 16 / 48 / more columns), and the sorted row pattern
//! of every supernode. So the numeric factorisation and every number computed from it are the
//! same as with faer's symbolic step.
//!
//! Written by hand because faer's symbolic step works on the graph of the unknowns and finds the
//! column counts by walking the elimination tree once per entry of L (O(|L|): 2.8e8 steps at
//! `structured:512`, 1.65 s of one core), and it has no way to take a structure computed
//! elsewhere. Here the counts come from Gilbert, Ng and Peyton's algorithm (`tree_and_counts`,
//! near-linear in the edges) on the graph of the nodes, which has half the vertices and a
//! quarter of the edges of the graph of the unknowns: the two unknowns of a node couple to the
//! same unknowns, so in
//! the ordered matrix they are consecutive columns with nested patterns. The first is the only
//! child of the second in the elimination tree and has one more entry, so they always fall in the
//! same fundamental supernode, every supernode is a run of whole nodes, and the structure of the
//! unknowns follows from that of the nodes with each node weighted by its number of unknowns:
//! with W the unknowns of later nodes in the column of node k of L, the w unknowns of node k have
//! column counts W + w, W + w - 1, ..., W + 1.

use crate::sparse::csc::{SymCsc, group_of};
use crate::sparse::ordering::{Graph, OrderingChoice};

/// faer's default supernode relaxation (`SymbolicSupernodalParams::default`): two adjacent
/// supernodes of together at most `.0` columns merge while the share of explicit zeros in the
/// merged one stays at most `.1`.
const RELAX: [(usize, f64); 4] = [(4, 1.0), (16, 0.8), (48, 0.1), (usize::MAX, 0.05)];

use super::etree::{Adjacency, Counts, NONE, tree_and_counts};

/// The ordering and supernodal structure of L for P K P^T = L L^T.
pub struct Symbolic {
    /// `perm[new] = old`, `inv[old] = new`.
    perm: Vec<usize>,
    inv: Vec<usize>,
    /// Supernode s holds the columns `begin[s]..begin[s + 1]` of L ...
    begin: Vec<usize>,
    /// ... the rows `rows[row_ptr[s]..row_ptr[s + 1]]` below them (ascending) ...
    row_ptr: Vec<usize>,
    rows: Vec<u32>,
    /// ... and its values, column-major (rows: its columns, then its pattern), at
    /// `val_ptr[s]..val_ptr[s + 1]` of L's values.
    val_ptr: Vec<usize>,
}

/// Where the entries of a matrix go in L: for each column j of P K P^T, its entries on and
/// below the diagonal, each as (row of P K P^T, position in the matrix's values). It depends on
/// the matrix's pattern and the ordering only, so it serves every matrix with that pattern
/// ([`crate::sparse::cholesky::load`] puts the values in place); once L holds them a solver that will
/// not refactorise can release it (a quarter of the memory of the symbolic phase at
/// `structured:512`).
pub struct Placement {
    /// Column j's entries: `entries[entry_ptr[j]..entry_ptr[j + 1]]`.
    entry_ptr: Vec<usize>,
    entries: Vec<(u32, u32)>,
}

/// The structure of L alone: [`Symbolic`]'s `begin`, `row_ptr`, `rows`, `val_ptr`.
type Structure = (Vec<usize>, Vec<usize>, Vec<u32>, Vec<usize>);

/// Order the unknowns `0..n_order` of `matrix` (as [`crate::sparse::ordering::fill_reducing`] does; the
/// others stay at the end in place) and compute the symbolic factorisation with that order, and
/// where the matrix's entries go in it.
pub fn analyse(matrix: &SymCsc, n_order: usize, coords: &[[f64; 2]]) -> (Symbolic, Placement, OrderingChoice) {
    let ((symbolic, placement), choice) = crate::sparse::ordering::fill_reducing_then(matrix, n_order, coords, |graph, node_order| {
        Symbolic::new(matrix, n_order, graph, node_order)
    });
    (symbolic, placement, choice)
}

impl Symbolic {
    /// The structure of L for `matrix` with the nodes of `graph` (the unknowns `0..n_order`) in
    /// `node_order` (`node_order[new] = old`), each node's unknowns together, followed by the
    /// unknowns `n_order..n` in place, each a node of its own; with the placement of the
    /// matrix's entries and the flops of factorising the ordered block (the leading block of L).
    pub(crate) fn new(matrix: &SymCsc, n_order: usize, graph: &Graph, node_order: &[usize]) -> ((Self, Placement), f64) {
        let n = matrix.n();
        assert!(n < NONE as usize, "2^32 unknowns or more: widen the symbolic factorisation's indices");
        let mut perm = graph.unknowns(node_order);
        perm.extend(n_order..n);
        let mut inv = vec![0usize; n];
        for (new, &old) in perm.iter().enumerate() {
            inv[old] = new;
        }
        // where the matrix entries go needs only the ordering: on the other core meanwhile
        let (((begin, row_ptr, rows, val_ptr), flops), placement) =
            rayon::join(|| structure(matrix, n_order, graph, node_order), || Placement::new(matrix, &inv));
        ((Symbolic { perm, inv, begin, row_ptr, rows, val_ptr }, placement), flops)
    }

    /// Unknowns (rows and columns of L).
    pub fn n(&self) -> usize {
        self.perm.len()
    }

    /// The ordering, `perm[new] = old`.
    pub fn perm(&self) -> &[usize] {
        &self.perm
    }

    /// Its inverse, `inv[old] = new`.
    pub fn inv(&self) -> &[usize] {
        &self.inv
    }

    pub fn n_supernodes(&self) -> usize {
        self.begin.len() - 1
    }

    /// Supernode s holds the columns `begin[s]..begin[s + 1]`.
    pub fn supernode_begin(&self) -> &[usize] {
        &self.begin
    }

    /// The rows of supernode s below its columns, ascending.
    pub fn pattern(&self, s: usize) -> &[u32] {
        &self.rows[self.row_ptr[s]..self.row_ptr[s + 1]]
    }

    /// Supernode s's values lie at `val_ptr[s]..val_ptr[s + 1]` of L's values.
    pub fn val_ptr(&self) -> &[usize] {
        &self.val_ptr
    }

    /// The number of values of L.
    pub fn len_val(&self) -> usize {
        *self.val_ptr.last().unwrap()
    }
}

/// The structure of L (see [`Symbolic::new`]), in the phases of faer's symbolic module: the
/// nodes' unknowns and neighbours, the elimination tree with the column counts, fundamental
/// supernodes, their relaxation, the row patterns; computed on nodes, then spelt in unknowns.
fn structure(matrix: &SymCsc, n_order: usize, graph: &Graph, node_order: &[usize]) -> (Structure, f64) {
    let n = matrix.n();
    assert_eq!(node_order.len(), graph.n_nodes());
    assert!(n < NONE as usize, "more than 2^32 unknowns: widen the symbolic factorisation's indices");
    let (first, position) = node_unknowns(n, n_order, graph, node_order);
    let nodes = first.len() - 1;
    let adjacency = node_adjacency(matrix, n_order, graph, node_order, &position, nodes);
    let nodes_i = node_order.len();
    let weight = |p: usize| first[p + 1] - first[p];
    let counts = tree_and_counts(&adjacency, nodes_i, &weight);
    let flops = counts.flops(nodes_i, &weight);
    if nodes == 0 {
        return ((vec![0], vec![0], Vec::new(), vec![0]), 0.0);
    }
    let fund = fundamental(&counts, &weight);
    let bounds = relax(&fund, &first, &counts);
    let node_rows = node_patterns(&adjacency, &bounds, &counts);
    (in_unknowns(&bounds, &first, &counts, &node_rows), flops)
}

/// The last node of supernode `s` of the runs `bounds`.
fn top(s: usize, bounds: &[usize]) -> usize {
    bounds[s + 1] - 1
}

/// Node p (new numbering; the unknowns `n_order..n` after the graph's nodes, one node each)
/// holds the unknowns `first[p]..first[p + 1]`; `position[old]` is the graph node's new number.
fn node_unknowns(n: usize, n_order: usize, graph: &Graph, node_order: &[usize]) -> (Vec<usize>, Vec<u32>) {
    let nodes_i = node_order.len();
    let nodes = nodes_i + (n - n_order);
    let mut first = Vec::with_capacity(nodes + 1);
    first.push(0usize);
    for p in 0..nodes {
        let w = if p < nodes_i { graph.weight(node_order[p]) } else { 1 };
        first.push(first[p] + w);
    }
    assert_eq!(first[nodes], n);
    let mut position = vec![0u32; nodes_i];
    for (p, &old) in node_order.iter().enumerate() {
        position[old] = p as u32;
    }
    (first, position)
}

/// The neighbours of every node in the new numbering: the graph's, and for the unknowns
/// `n_order..n` (not in the graph) their couplings from the matrix (entries with rows >=
/// `n_order`; rows are sorted within a column), as an extra adjacency.
fn node_adjacency(matrix: &SymCsc, n_order: usize, graph: &Graph, node_order: &[usize], position: &[u32], nodes: usize) -> Adjacency {
    let (n, nodes_i) = (matrix.n(), node_order.len());
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    let (cols, row_idx) = (matrix.col_ptr(), matrix.row_idx());
    if n > n_order {
        let columns = (0..nodes_i)
            .flat_map(|k| graph.unknowns_of(k).map(move |j| (j, position[k])))
            .chain((n_order..n).map(|j| (j, (nodes_i + j - n_order) as u32)));
        for (j, p) in columns {
            let rows = &row_idx[cols[j]..cols[j + 1]];
            pairs.extend(rows[rows.partition_point(|&i| i < n_order.max(j + 1))..].iter().map(|&i| (p, (nodes_i + i - n_order) as u32)));
        }
        pairs.sort_unstable();
        pairs.dedup();
    }
    let mut extra_ptr = vec![0usize; nodes + 1];
    for &(a, b) in &pairs {
        extra_ptr[a as usize + 1] += 1;
        extra_ptr[b as usize + 1] += 1;
    }
    for p in 0..nodes {
        extra_ptr[p + 1] += extra_ptr[p];
    }
    let mut extra = vec![0u32; extra_ptr[nodes]];
    let mut fill = extra_ptr.clone();
    for &(a, b) in &pairs {
        extra[fill[a as usize]] = b;
        fill[a as usize] += 1;
        extra[fill[b as usize]] = a;
        fill[b as usize] += 1;
    }
    let degree = |p: usize| if p < nodes_i { graph.degree(node_order[p]) } else { 0 } + extra_ptr[p + 1] - extra_ptr[p];
    Adjacency::gather(nodes, &degree, &|p, f| {
        if p < nodes_i {
            graph.neighbours(node_order[p]).for_each(|q| f(position[q]));
        }
        extra[extra_ptr[p]..extra_ptr[p + 1]].iter().for_each(|&q| f(q));
    })
}

/// Fundamental supernodes as runs of nodes (the first node of each, then the number of nodes):
/// node p continues the run of p - 1 when, in unknowns, its first column is the only parent of
/// the last column of p - 1 and has one entry less.
fn fundamental(counts: &Counts, weight: &dyn Fn(usize) -> usize) -> Vec<usize> {
    let Counts { parent, below_w, .. } = counts;
    let nodes = parent.len();
    let mut children = vec![0u32; nodes];
    for &q in parent.iter().filter(|&&q| q != NONE) {
        children[q as usize] += 1;
    }
    let mut fund = vec![0usize];
    for p in 1..nodes {
        let joins = parent[p - 1] as usize == p && children[p] == 1 && below_w[p - 1] == below_w[p] + weight(p);
        if !joins {
            fund.push(p);
        }
    }
    fund.push(nodes);
    fund
}

/// Relaxation, as faer does it: in ascending order, a supernode absorbs the one just before it
/// if that is its child and the explicit zeros stay under the thresholds [`RELAX`] (sizes and
/// zeros accumulate along a chain of merges; `size` 0 marks an absorbed supernode). The relaxed
/// supernodes, as runs of nodes.
fn relax(fund: &[usize], first: &[usize], counts: &Counts) -> Vec<usize> {
    let Counts { parent, below_w, .. } = counts;
    let nf = fund.len() - 1;
    let super_of = group_of(fund);
    let mut size: Vec<usize> = (0..nf).map(|s| first[fund[s + 1]] - first[fund[s]]).collect();
    let degree: Vec<usize> = (0..nf).map(|s| below_w[top(s, fund)]).collect();
    let mut zeros = vec![0usize; nf];
    for s in 1..nf {
        let c = s - 1;
        let parent_of_c = parent[top(c, fund)];
        if parent_of_c == NONE || super_of[parent_of_c as usize] as usize != s {
            continue;
        }
        let (ps, cs, pd, cd) = (size[s], size[c], degree[s], degree[c]);
        let new_zeros = (ps + pd - cd) * cs;
        let merged = if new_zeros == 0 {
            Some(zeros[s] + zeros[c])
        } else {
            let z = new_zeros + zeros[c] + zeros[s];
            let cols = cs + ps;
            let entries = cols * (cols + 1) / 2 + pd * cols;
            RELAX.iter().any(|&(max_cols, share)| max_cols >= cols && entries as f64 * share >= z as f64).then_some(z)
        };
        if let Some(z) = merged {
            size[s] += cs;
            size[c] = 0;
            zeros[s] = z;
        }
    }
    let mut bounds = vec![0usize];
    for s in 0..nf {
        if size[s] > 0 {
            bounds.push(fund[s + 1]);
        }
    }
    bounds
}

/// Row patterns in nodes, supernode after supernode of `bounds` (each as long as its column
/// count in nodes, `below_n` of its last node): node p is in the pattern of every supernode on
/// the tree paths from its lower neighbours' supernodes up to its own (faer's `ereach_super`),
/// so each pattern fills in ascending order.
fn node_patterns(adjacency: &Adjacency, bounds: &[usize], counts: &Counts) -> Vec<u32> {
    let Counts { parent, below_n, .. } = counts;
    let (nodes, ns) = (parent.len(), bounds.len() - 1);
    let super_of = group_of(bounds);
    let super_parent: Vec<u32> = (0..ns)
        .map(|s| match parent[top(s, bounds)] {
            NONE => NONE,
            q => super_of[q as usize],
        })
        .collect();
    let mut node_ptr = vec![0usize; ns + 1];
    for s in 0..ns {
        node_ptr[s + 1] = node_ptr[s] + below_n[top(s, bounds)] as usize;
    }
    let mut node_rows = vec![0u32; node_ptr[ns]];
    let mut next = node_ptr.clone();
    let mut seen = vec![NONE; ns];
    for p in 0..nodes {
        seen[super_of[p] as usize] = p as u32;
        for &q in adjacency.row(p).iter().filter(|&&q| (q as usize) < p) {
            let mut t = super_of[q as usize] as usize;
            while seen[t] != p as u32 {
                node_rows[next[t]] = p as u32;
                next[t] += 1;
                seen[t] = p as u32;
                t = super_parent[t] as usize;
            }
        }
    }
    assert_eq!(next[..ns], node_ptr[1..], "row patterns disagree with the column counts");
    node_rows
}

/// The supernodes `bounds` and their row patterns `node_rows` (in nodes) spelt in unknowns:
/// [`Symbolic`]'s `begin`, `row_ptr`, `rows`, `val_ptr`.
fn in_unknowns(bounds: &[usize], first: &[usize], counts: &Counts, node_rows: &[u32]) -> Structure {
    let ns = bounds.len() - 1;
    let begin: Vec<usize> = bounds.iter().map(|&b| first[b]).collect();
    let mut row_ptr = vec![0usize; ns + 1];
    let mut val_ptr = vec![0usize; ns + 1];
    for s in 0..ns {
        let (ncols, deg) = (begin[s + 1] - begin[s], counts.below_w[top(s, bounds)]);
        row_ptr[s + 1] = row_ptr[s] + deg;
        val_ptr[s + 1] = val_ptr[s] + (ncols + deg) * ncols;
    }
    let mut rows = Vec::with_capacity(row_ptr[ns]);
    for &q in node_rows {
        rows.extend(first[q as usize] as u32..first[q as usize + 1] as u32);
    }
    assert_eq!(rows.len(), row_ptr[ns]);
    (begin, row_ptr, rows, val_ptr)
}

impl Placement {
    /// Where each entry (i, j), i >= j, of `matrix` goes with the ordering `inv` (`inv[old] =
    /// new`): column min(inv i, inv j) of P K P^T, row max (its place in the column's supernode is
    /// looked up when loading, where the supernode's rows are mapped anyway); grouped by column in
    /// the order of the matrix's entries (a deterministic parallel counting sort over a fixed
    /// number of runs of the matrix's columns: the same on any number of threads).
    pub fn new(matrix: &SymCsc, inv: &[usize]) -> Self {
        let (n, cols, row_idx) = (matrix.n(), matrix.col_ptr(), matrix.row_idx());
        assert!(cols[n] < u32::MAX as usize, "more than 2^32 matrix entries: widen the placement's indices");
        let nnz = cols[n];
        // chunk b holds the columns bounds[b]..bounds[b + 1], about nnz / PLACE_CHUNKS entries each
        let bounds: Vec<usize> = (0..=PLACE_CHUNKS).map(|b| cols.partition_point(|&c| c < nnz * b / PLACE_CHUNKS).min(n)).collect();
        let (entry_ptr, entries) = crate::sparse::csc::group_by_target(n, PLACE_CHUNKS, &|b, sink| {
            for j in bounds[b]..bounds[b + 1] {
                for (k, &i) in (cols[j]..cols[j + 1]).zip(&row_idx[cols[j]..cols[j + 1]]) {
                    let (a, c) = (inv[i], inv[j]);
                    sink(a.min(c), (a.max(c) as u32, k as u32));
                }
            }
        });
        Placement { entry_ptr, entries }
    }

    /// The matrix entries of column j of P K P^T below the diagonal and on it, each as (row of
    /// P K P^T, position in the matrix's values).
    pub fn entries(&self, j: usize) -> &[(u32, u32)] {
        &self.entries[self.entry_ptr[j]..self.entry_ptr[j + 1]]
    }
}

/// The matrix's columns are placed in this many chunks (a constant, so that the work does not
/// depend on the number of threads; enough for two cores to share).
const PLACE_CHUNKS: usize = 4;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn systems_without_unknowns_or_with_one() {
        let empty = SymCsc::new(0, vec![0], Vec::new(), Vec::new()).unwrap();
        let (sym, _, _) = analyse(&empty, 0, &[]);
        assert_eq!((sym.n(), sym.n_supernodes(), sym.len_val()), (0, 0, 0));
        // one unknown, ordered or kept in place at the end (a contact normal)
        let one = SymCsc::new(1, vec![0, 1], vec![0], vec![2.0]).unwrap();
        for n_order in [0, 1] {
            let (sym, placement, _) = analyse(&one, n_order, &[[0.0, 0.0]]);
            assert_eq!((sym.n(), sym.n_supernodes(), sym.len_val(), placement.entries(0)), (1, 1, 1, &[(0, 0)][..]));
        }
    }
}
