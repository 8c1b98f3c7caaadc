//! Fill-reducing ordering of the unknowns: nested dissection by coordinate bisection, or
//! approximate minimum degree (AMD), whichever needs fewer flops.
//!
//! The sparse Cholesky factorisation costs what its fill costs, and it runs near the machine's
//! dense flop rate (about 25 GFlop/s on one core here), so the ordering decides its time. On
//! the quasi-uniform meshes of the benchmark, AMD is far from the best: at `structured:512`
//! (2.1M unknowns) it leaves 1.7e11 flops (2.4e11 on the graph of the unknowns, 4.1e8 entries
//! of L), while nested dissection leaves 8.3e10 (2.7e8 entries of L; `ordering` in
//! `results/bench/solver.json`). A 2D finite element mesh gives separators for free through its
//! coordinates: split the unknowns at the median of one coordinate, take the unknowns of one
//! half coupled to the other half as the separator (one layer of nodes when the split follows
//! a mesh line), number both halves first, recursively, and the separator last.
//! On meshes graded towards a boundary line (Example 7.1 refines Gamma_C to thousands of
//! contact nodes) it is the other way round: AMD orders the thin layers almost as a band and
//! needs 25 times fewer flops than the dissection, and so it does on Example 7.2's adaptive
//! meshes (graded towards the singularities). So AMD is computed as well, and the ordering
//! with fewer flops kept, where it can win: on small meshes (at most [`BOTH_MAX_NODES`] nodes,
//! where both cost under 0.1 s) and on graded ones (the ratio of the largest to the smallest
//! local mesh size, [`grading`], above [`GRADED`]); a large quasi-uniform mesh gets nested
//! dissection alone, which saves AMD and its flop count (about 1.5 s of one core at
//! `structured:512`). The numbers behind the rule are in [`fill_reducing`]. The flops of both
//! come from the column counts of L (elimination tree, row subtrees).
//!
//! Both orderings work on the graph of the nodes, not of the unknowns: the two unknowns of a
//! node (consecutive, at the same position) couple to the same unknowns, so the graph of the
//! unknowns is the node graph with every node doubled, and ordering the nodes and numbering each
//! node's unknowns together loses nothing. The node graph has half the vertices and a quarter
//! of the edges, which makes both orderings and their flop counts 2-4 times cheaper; the flops
//! are still those of the unknowns (each node weighted by its number of unknowns).
//!
//! Written by hand because no Rust crate offers a geometric nested dissection, and METIS
//! (through C bindings) took 6-11 s to order `structured:512` on this machine, more than it
//! saves. The nodes are sorted along both axes once; every subset keeps both orders, so a
//! median is an index and a split two stable partitions (no selection per split: at
//! `structured:512` the dissection takes 0.5 s, against 0.8 s with one). Deterministic: the recursion
//! splits by a total order on (coordinate, index) and the two halves are ordered independently
//! (in parallel) and concatenated in a fixed order, so the ordering does not depend on the
//! number of threads.

use super::etree::Adjacency;
use crate::sparse::csc::SymCsc;
use model::settings::ordering::{Method, forced};
use rayon::prelude::*;
use std::sync::atomic::AtomicU8;
use std::sync::atomic::Ordering::Relaxed;

/// Subsets at most this large are not split further; they are numbered along the axis of the
/// split that made them.
const LEAF: usize = 8;

/// The graph of the nodes is built in this many runs of nodes (a constant, so that the work does
/// not depend on the number of threads; enough for two cores to share).
const GRAPH_CHUNKS: usize = 4;

/// Subsets larger than this are split in parallel.
const PAR_MIN: usize = 20_000;

/// The symmetric adjacency of the nodes of the unknowns `0..n` (entries of the lower triangle
/// `matrix` with both indices below `n`), compressed by rows, without the diagonal. A node is a
/// run of consecutive unknowns at the same position (`coords`, bitwise): the two components of
/// a P2 node, or a lone unknown (the tangential one at a contact node whose normal unknown is
/// ordered apart). Node k holds the unknowns `first[k]..first[k + 1]`.
pub(crate) struct Graph {
    ptr: Vec<u32>,
    adj: Vec<u32>,
    first: Vec<usize>,
}

impl Graph {
    pub(crate) fn new(matrix: &SymCsc, n: usize, coords: &[[f64; 2]]) -> Self {
        let same = |a: [f64; 2], b: [f64; 2]| a[0].to_bits() == b[0].to_bits() && a[1].to_bits() == b[1].to_bits();
        let mut first = vec![0];
        for i in 1..n {
            if !same(coords[i], coords[i - 1]) {
                first.push(i);
            }
        }
        if n > 0 {
            first.push(n); // (no unknowns: no node)
        }
        let nodes = first.len() - 1;
        let node_of = crate::sparse::csc::group_of(&first);
        // couplings (k, l), k < l, each once: node numbers follow the unknowns', so an entry (i, j),
        // i > j, of the lower triangle lies in a column of node k = node(j) <= l = node(i); `seen`
        // drops the repeats within node k's columns
        let couplings = |k: usize, seen: &mut [u32], found: &mut dyn FnMut(usize)| {
            for j in first[k]..first[k + 1] {
                for &i in &matrix.row_idx()[matrix.col_ptr()[j]..matrix.col_ptr()[j + 1]] {
                    if i < n && node_of[i] as usize != k && seen[node_of[i] as usize] != k as u32 {
                        seen[node_of[i] as usize] = k as u32;
                        found(node_of[i] as usize);
                    }
                }
            }
        };
        // in GRAPH_CHUNKS runs of nodes at once, each coupling placed with both its nodes: the
        // same adjacency as one sequential pass over the nodes (each node's neighbours in the
        // order they are found), whatever the number of threads
        let nnz = matrix.col_ptr()[n];
        let mut bounds: Vec<usize> =
            (0..GRAPH_CHUNKS).map(|b| first[..nodes].partition_point(|&f| matrix.col_ptr()[f] < nnz * b / GRAPH_CHUNKS)).collect();
        bounds.push(nodes);
        let (ptr, adj) = crate::sparse::csc::group_by_target(nodes, GRAPH_CHUNKS, &|b, sink| {
            let mut seen = vec![u32::MAX; nodes];
            for k in bounds[b]..bounds[b + 1] {
                couplings(k, &mut seen, &mut |l| {
                    sink(k, l as u32);
                    sink(l, k as u32);
                });
            }
        });
        assert!(adj.len() < u32::MAX as usize, "more than 2^32 couplings: widen the graph's indices");
        let ptr = ptr.into_iter().map(|p| p as u32).collect();
        Graph { ptr, adj, first }
    }

    pub(crate) fn n_nodes(&self) -> usize {
        self.first.len() - 1
    }

    /// The position of every node, from the positions of the unknowns.
    pub(crate) fn node_coords(&self, coords: &[[f64; 2]]) -> Vec<[f64; 2]> {
        self.first[..self.n_nodes()].iter().map(|&i| coords[i]).collect()
    }

    /// The adjacency compressed by rows, without the diagonal: node i's neighbours are
    /// `adj[ptr[i]..ptr[i + 1]]`.
    pub(crate) fn csr(&self) -> (&[u32], &[u32]) {
        (&self.ptr, &self.adj)
    }

    /// The unknowns of node k.
    pub(crate) fn unknowns_of(&self, k: usize) -> std::ops::Range<usize> {
        self.first[k]..self.first[k + 1]
    }

    /// The number of unknowns of node k.
    pub(crate) fn weight(&self, k: usize) -> usize {
        self.first[k + 1] - self.first[k]
    }

    /// The number of neighbours of node i.
    pub(crate) fn degree(&self, i: usize) -> usize {
        (self.ptr[i + 1] - self.ptr[i]) as usize
    }

    pub(crate) fn neighbours(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.adj[self.ptr[i] as usize..self.ptr[i + 1] as usize].iter().map(|&j| j as usize)
    }

    /// The order of the unknowns from an order of the nodes: each node's unknowns together.
    pub(crate) fn unknowns(&self, node_order: &[usize]) -> Vec<usize> {
        node_order.iter().flat_map(|&k| self.first[k]..self.first[k + 1]).collect()
    }
}

/// Which ordering [`fill_reducing`] kept, the flops (multiply-subtract pairs and divisions of
/// the factorisation of the ordered block) of the candidates it computed, and the mesh grading
/// that decided whether AMD was a candidate.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct OrderingChoice {
    pub method: Method,
    pub flops_nested_dissection: f64,
    /// None (`null`) if AMD was not computed: a large quasi-uniform mesh, see [`fill_reducing`].
    pub flops_minimum_degree: Option<f64>,
    /// The largest over the smallest local mesh size of the ordered nodes (see [`grading`]).
    pub grading: f64,
}

impl OrderingChoice {
    /// The multiply-subtract pairs (and divisions) of the kept ordering: the work of the
    /// factorisation without the explicit zeros that supernodes add.
    pub fn multiply_adds(&self) -> f64 {
        match self.method {
            Method::NestedDissection => self.flops_nested_dissection,
            Method::MinimumDegree => self.flops_minimum_degree.expect("a kept minimum-degree ordering has its flops"),
        }
    }
}

thread_local! {
    /// Set while [`automatic`] runs: [`FORCE_ENV`](model::settings::ordering::FORCE_ENV) does not apply on this thread.
    static AUTOMATIC: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Run `f` with the automatic ordering whatever [`FORCE_ENV`](model::settings::ordering::FORCE_ENV) says (on this thread, where the
/// solves of `f` order their unknowns). The reference solutions of a study are computed so: a
/// round-off measurement perturbs the runs it measures, against a reference that stays what the
/// stored results were computed with. Forced on the reference as well, the ordering can tip a
/// marking decision of its adaptive loop (two indicators equal to round-off), and the reference
/// mesh itself changes: every error of the study then moves by about 2e-11 at once (ex72_large
/// with minimum degree forced), which is a different reference, not round-off of the errors.
pub fn automatic<R>(f: impl FnOnce() -> R) -> R {
    /// Restores the flag however `f` ends (an unwinding panic too).
    struct Restore(bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            AUTOMATIC.set(self.0);
        }
    }
    let _restore = Restore(AUTOMATIC.replace(true));
    f()
}

/// The ordering forced for the solves of this thread: [`forced`], unless inside [`automatic`].
fn forced_here() -> Option<Method> {
    if AUTOMATIC.get() { None } else { forced().ok().flatten() }
}

/// Up to this many nodes both orderings are computed and the one with fewer flops kept, whatever
/// the mesh: together they cost under 0.1 s there (and AMD wins by up to 1.5x on some uniformly
/// refined meshes of this size).
pub const BOTH_MAX_NODES: usize = 100_000;

/// A mesh whose [`grading`] exceeds this is graded: both orderings are computed. A uniform
/// mesh of P2 triangles is at 2 (`structured:N` and its uniform refinements), one round of
/// local bisection takes it to 4; the adaptive meshes of the studies are at 32 to 131072 from
/// 2.3k nodes up, the Hertz study's Gmsh meshes at 35 to 4900. So any local refinement counts.
pub const GRADED: f64 = 3.0;

/// A fill-reducing ordering of the unknowns `0..n_order` of `matrix` (the others keep their
/// places at the end, after them), from the coordinates of every unknown. Returns the
/// permutation as `order[new] = old`.
///
/// Nested dissection is always computed. AMD is computed too, and the one with fewer flops
/// kept, only where it can win: on meshes of at most [`BOTH_MAX_NODES`] nodes, and on graded
/// meshes ([`grading`] above [`GRADED`]). Measured over every level of the studies `ex71`,
/// `ex72`, `ex72_large`, `hertz` (flops, nested dissection / AMD): on uniform meshes nested
/// dissection wins (0.46-0.63 on half of the uniform refinements of Example 7.1's and 7.2's
/// meshes above 8k nodes, 0.50 on `structured:256` and `structured:512`) or loses by little
/// (1.25-1.5 on the other half, all below 66k nodes, where both are computed anyway); on every
/// graded mesh of those studies above 2.3k nodes AMD wins, by a lot on most (Example 7.1 graded
/// towards Gamma_C: 10-67 from 18k nodes up; Example 7.2's adaptive meshes: 1.7-27, 25 at 1.1M
/// unknowns; Hertz: 2-7). There the flops of nested dissection per n^1.5 for n unknowns
/// overlap those of `structured:N` (27 on `structured:N`, 35-65 on `ex72_large`), so the flop
/// count of nested dissection alone cannot tell the two kinds of mesh apart: the
/// grading does. On the deep study's graded meshes either can win, so neither is skipped there
/// (nested dissection / AMD above 100k nodes: 22-41 on Example 7.1 as written, graded
/// 512-2048; 0.87-2.0 on fb as written, graded 128-512; 0.68-0.96 from 257k nodes up on fb
/// without full-contact nodes and repaired, graded 16; 0.80-1.16 on those runs of Example 7.1).
/// The rule is a function of the mesh only (never of timing or threads).
/// [`FORCE_ENV`](model::settings::ordering::FORCE_ENV) overrides it: a forced AMD is computed whatever the mesh.
pub fn fill_reducing(matrix: &SymCsc, n_order: usize, coords: &[[f64; 2]]) -> (Vec<usize>, OrderingChoice) {
    fill_reducing_then(matrix, n_order, coords, |graph, node_order| {
        let mut order = graph.unknowns(node_order);
        order.extend(n_order..matrix.n());
        (order, factorisation_flops(graph, node_order))
    })
}

/// [`fill_reducing`], handing the node graph and the order of its nodes (`node_order[new] =
/// old`) to `then` (the symbolic factorisation) and returning what it returns. `then` returns
/// the flops of factorising the ordered block too (the symbolic factorisation has the column
/// counts anyway): when nested dissection is the only candidate they are not needed for the
/// choice and are not computed twice.
pub(crate) fn fill_reducing_then<T: Send>(
    matrix: &SymCsc,
    n_order: usize,
    coords: &[[f64; 2]],
    then: impl FnOnce(&Graph, &[usize]) -> (T, f64) + Send,
) -> (T, OrderingChoice) {
    let graph = Graph::new(matrix, n_order, coords);
    let nodes = graph.n_nodes();
    let node_coords = graph.node_coords(coords);
    let reach = reach(&graph, &node_coords);
    let grading = grading(&reach);
    let forced = forced_here();
    let with_amd = amd_is_candidate(nodes, grading, forced);
    let minimum_degree = || {
        let (order, ordered) = minimum_degree(&graph);
        // AMD counts the flops of the node graph; ours weighs each node by its unknowns
        let flops = if ordered { factorisation_flops(&graph, &order) } else { f64::INFINITY };
        (order, flops)
    };
    let nested = || nested_dissection(&graph, &node_coords, &reach);
    let (method, out, nd_flops, amd_flops) = if with_amd {
        let ((nd, nd_flops), (amd, amd_flops)) = rayon::join(
            || {
                let order = nested();
                let flops = factorisation_flops(&graph, &order);
                (order, flops)
            },
            minimum_degree,
        );
        let method = match forced {
            Some(m) => m,
            None if amd_flops < nd_flops => Method::MinimumDegree,
            None => Method::NestedDissection,
        };
        let (kept, kept_flops) = if method == Method::MinimumDegree { (&amd, amd_flops) } else { (&nd, nd_flops) };
        let (out, flops) = then(&graph, kept);
        assert!(!kept_flops.is_finite() || flops == kept_flops, "two flop counts of one ordering disagree: {flops} and {kept_flops}");
        (method, out, nd_flops, Some(amd_flops))
    } else {
        let nd = nested();
        let (out, nd_flops) = then(&graph, &nd);
        (Method::NestedDissection, out, nd_flops, None)
    };
    (out, OrderingChoice { method, flops_nested_dissection: nd_flops, flops_minimum_degree: amd_flops, grading })
}

/// AMD's order of the nodes of `graph` (`order[new] = old`), and whether AMD ran (false: it
/// could not get its workspace, and the order is not one).
pub(crate) fn minimum_degree(graph: &Graph) -> (Vec<usize>, bool) {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::amd;
    let nodes = graph.n_nodes();
    let pattern = faer::sparse::SymbolicSparseColMatRef::new_checked(nodes, nodes, &graph.ptr, None, &graph.adj);
    let (mut fwd, mut inv) = (vec![0u32; nodes], vec![0u32; nodes]);
    let ordered = MemBuffer::try_new(amd::order_maybe_unsorted_scratch::<u32>(nodes, graph.adj.len()))
        .ok()
        .and_then(|mut mem| amd::order_maybe_unsorted(&mut fwd, &mut inv, pattern, amd::Control::default(), MemStack::new(&mut mem)).ok());
    (fwd.into_iter().map(|i| i as usize).collect(), ordered.is_some())
}

/// Whether [`fill_reducing`] computes AMD: when forced, on small meshes and on graded ones.
fn amd_is_candidate(nodes: usize, grading: f64, forced: Option<Method>) -> bool {
    match forced {
        Some(Method::MinimumDegree) => true,
        Some(Method::NestedDissection) => false,
        None => nodes <= BOTH_MAX_NODES || grading > GRADED,
    }
}

/// The grading of a mesh: the largest over the smallest local mesh size, with the local mesh
/// size of a node the farthest its neighbours lie from it along an axis (`reach`; nodes without
/// neighbours left out). About 2 on a quasi-uniform mesh of P2 triangles (a vertex reaches h,
/// an edge midpoint h/2); each bisection towards a point or a line doubles it at most.
pub fn grading(reach: &[[f64; 2]]) -> f64 {
    let sizes = reach.iter().map(|r| r[0].max(r[1])).filter(|&h| h > 0.0);
    let (lo, hi) = sizes.fold((f64::INFINITY, 0.0f64), |(lo, hi), h| (lo.min(h), hi.max(h)));
    if hi > 0.0 { hi / lo } else { 1.0 }
}

/// How far the neighbours of every node of `graph` (at `coords`) lie from it along each axis.
pub(crate) fn reach(graph: &Graph, coords: &[[f64; 2]]) -> Vec<[f64; 2]> {
    (0..graph.n_nodes())
        .into_par_iter()
        .map(|i| {
            let d = |axis: usize| graph.neighbours(i).map(|j| (coords[j][axis] - coords[i][axis]).abs()).fold(0.0, f64::max);
            [d(0), d(1)]
        })
        .collect()
}

/// Nested dissection of all nodes of `graph` (at `coords`, with their `reach`), as
/// `order[new] = old`.
pub(crate) fn nested_dissection(graph: &Graph, coords: &[[f64; 2]], reach: &[[f64; 2]]) -> Vec<usize> {
    let n = graph.n_nodes();
    assert!(coords.len() >= n && reach.len() >= n && n < u32::MAX as usize);
    // side[i]: which half of the current split node i is in; the halves being split at the
    // same time are disjoint and not coupled, so one array serves the whole parallel recursion
    let side: Vec<AtomicU8> = (0..n).map(|_| AtomicU8::new(0)).collect();
    // the nodes sorted along each axis by (coordinate, index), once: every subset keeps both
    // orders, so a median is an index and a split two stable partitions
    let sorted = |axis: usize| {
        let mut list: Vec<u32> = (0..n as u32).collect();
        list.par_sort_unstable_by(|&a, &b| coords[a as usize][axis].total_cmp(&coords[b as usize][axis]).then(a.cmp(&b)));
        list
    };
    let (xs, ys) = rayon::join(|| sorted(0), || sorted(1));
    let ctx = Dissection { graph, coords, reach, side: &side };
    ctx.dissect([xs, ys], 0)
}

/// What every split of [`nested_dissection`] reads.
struct Dissection<'a> {
    graph: &'a Graph,
    coords: &'a [[f64; 2]],
    reach: &'a [[f64; 2]],
    side: &'a [AtomicU8],
}

/// A split of a subset along `axis`: the first `mid` nodes in that axis's order form one half,
/// the rest the other; `separator` lists the nodes of one half coupled to the other.
struct Split {
    axis: usize,
    mid: usize,
    separator: Vec<u32>,
}

impl Dissection<'_> {
    /// Order the subset whose nodes are `by[axis]`, sorted along each axis: both halves of a
    /// coordinate split first, then the separator. A subset of at most [`LEAF`] nodes keeps the
    /// order along `last_axis` (the axis of the split that made it).
    fn dissect(&self, by: [Vec<u32>; 2], last_axis: usize) -> Vec<usize> {
        let as_usize = |list: &[u32]| list.iter().map(|&i| i as usize).collect::<Vec<_>>();
        if by[0].len() <= LEAF {
            return as_usize(&by[last_axis]);
        }
        // split at the median along either axis, keeping the one with the smaller separator (the
        // longer side of the bounding box is not enough: on meshes graded towards a boundary line
        // most unknowns can sit on that line, and a split along it is all separator)
        let mut best: Option<Split> = None;
        for (axis, list) in by.iter().enumerate() {
            let Some(split) = self.split_along(list, axis) else { continue };
            if best.as_ref().is_none_or(|b| split.separator.len() < b.separator.len()) {
                best = Some(split);
            }
        }
        let Some(best) = best else {
            return as_usize(&by[last_axis]); // all unknowns at one point
        };
        // the halves of the kept split (the other axis's trial overwrote them), the separator
        // out of both for good: the splits below must not see it as a half
        for (k, &i) in by[best.axis].iter().enumerate() {
            self.side[i as usize].store(if k < best.mid { 1 } else { 2 }, Relaxed);
        }
        for &i in &best.separator {
            self.side[i as usize].store(0, Relaxed);
        }
        let halves = |list: &[u32]| {
            let (mut a, mut b) = (Vec::with_capacity(best.mid), Vec::with_capacity(list.len() - best.mid));
            for &i in list {
                match self.side[i as usize].load(Relaxed) {
                    1 => a.push(i),
                    2 => b.push(i),
                    _ => {}
                }
            }
            (a, b)
        };
        let ((ax, bx), (ay, by_)) = (halves(&by[0]), halves(&by[1]));
        // the separator lies on a line across the split axis: numbered along it
        let other = 1 - best.axis;
        let separator: Vec<usize> = by[other].iter().filter(|&&i| self.side[i as usize].load(Relaxed) == 0).map(|&i| i as usize).collect();
        debug_assert_eq!(separator.len(), best.separator.len());
        let len = by[0].len();
        drop(by);
        let (mut oa, ob) = if len >= PAR_MIN {
            rayon::join(|| self.dissect([ax, ay], best.axis), || self.dissect([bx, by_], best.axis))
        } else {
            (self.dissect([ax, ay], best.axis), self.dissect([bx, by_], best.axis))
        };
        oa.extend(ob);
        oa.extend(separator);
        oa
    }

    /// Split the subset `list` (sorted along `axis`) at its median along `axis` (unknowns on the
    /// median line all on one side, so that a split along a line of nodes leaves a separator one
    /// node thick) and take as the separator the unknowns of one half coupled to the other, of
    /// the half where they are fewer. None if all unknowns have the same coordinate.
    fn split_along(&self, list: &[u32], axis: usize) -> Option<Split> {
        let (coords, reach, side) = (self.coords, self.reach, self.side);
        let at = |i: u32| coords[i as usize][axis];
        let v = at(list[list.len() / 2]);
        let below = list.partition_point(|&i| at(i) < v);
        let mid = if below > 0 { below } else { list.partition_point(|&i| at(i) <= v) };
        if mid == list.len() {
            return None;
        }
        let (left, right) = list.split_at(mid);
        for &i in left {
            side[i as usize].store(1, Relaxed);
        }
        for &i in right {
            side[i as usize].store(2, Relaxed);
        }
        // every coordinate of the left half is below every one of the right half
        let (left_max, right_min) = (at(left[left.len() - 1]), at(right[0]));
        let coupled = |half: &[u32], other: u8, line: f64| -> Vec<u32> {
            half.iter()
                .copied()
                .filter(|&i| {
                    (at(i) - line).abs() <= reach[i as usize][axis]
                        && self.graph.neighbours(i as usize).any(|j| side[j].load(Relaxed) == other)
                })
                .collect()
        };
        let (in_left, in_right) = (coupled(left, 2, right_min), coupled(right, 1, left_max));
        Some(if in_right.len() <= in_left.len() {
            Split { axis, mid, separator: in_right }
        } else {
            Split { axis, mid, separator: in_left }
        })
    }
}

/// Flops of the Cholesky factorisation of the matrix of the unknowns with the nodes in the given
/// order (each node's unknowns together), from the column counts of the node graph
/// ([`super::etree::tree_and_counts`], `Counts::flops`).
fn factorisation_flops(graph: &Graph, order: &[usize]) -> f64 {
    let weight = |p: usize| graph.weight(order[p]);
    ordered_counts(graph, order).flops(order.len(), &weight)
}

/// The elimination tree and column counts of the node graph with the nodes in the given order
/// ([`super::etree::tree_and_counts`], each node weighted by its unknowns).
pub(crate) fn ordered_counts(graph: &Graph, order: &[usize]) -> super::etree::Counts {
    let mut position = vec![0u32; order.len()];
    for (new, &old) in order.iter().enumerate() {
        position[old] = new as u32;
    }
    let weight = |p: usize| graph.weight(order[p]);
    let adjacency =
        Adjacency::gather(order.len(), &|p| graph.degree(order[p]), &|p, f| graph.neighbours(order[p]).for_each(|q| f(position[q])));
    super::etree::tree_and_counts(&adjacency, order.len(), &weight)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::assembly::{self, DofMap};
    use model::mesh::{MeshSpec, P2Nodes};
    use model::problems::Ex72;

    fn system(n: usize) -> (SymCsc, Vec<[f64; 2]>) {
        let p = Ex72;
        let mesh = MeshSpec::Structured(n).build(&p).expect("the unit square");
        let nodes = P2Nodes::new(&mesh);
        let dofs = DofMap::new(&nodes, &p);
        let sys = assembly::assemble(&mesh, &nodes, &dofs, &p);
        (sys.matrix, dofs.unknown_coords(&nodes))
    }

    #[test]
    fn nested_dissection_is_a_permutation_and_beats_amd_on_a_uniform_mesh() {
        let (matrix, coords) = system(32);
        let (order, choice) = fill_reducing(&matrix, matrix.n(), &coords);
        let mut seen = vec![false; matrix.n()];
        for &i in &order {
            assert!(!seen[i], "{i} twice");
            seen[i] = true;
        }
        assert!(seen.iter().all(|&s| s));
        assert_eq!(choice.method, Method::NestedDissection, "{choice:?}");
        assert!(choice.flops_nested_dissection < 0.8 * choice.flops_minimum_degree.expect("both computed on a small mesh"), "{choice:?}");
    }

    #[test]
    fn amd_only_where_it_can_win_or_when_forced() {
        assert!(amd_is_candidate(BOTH_MAX_NODES, 2.0, None), "small: both");
        assert!(!amd_is_candidate(BOTH_MAX_NODES + 1, 2.0, None), "large and quasi-uniform: nested dissection alone");
        assert!(amd_is_candidate(BOTH_MAX_NODES + 1, 2.0 * GRADED, None), "large and graded: both");
        assert!(amd_is_candidate(10 * BOTH_MAX_NODES, 2.0, Some(Method::MinimumDegree)), "forced AMD is computed");
        assert!(!amd_is_candidate(10, 1e3, Some(Method::NestedDissection)));
    }

    #[test]
    fn grading_tells_a_uniform_mesh_from_one_graded_towards_gamma_c() {
        // structured and uniformly refined: 2 (vertices reach h, edge midpoints h/2)
        let (matrix, coords) = system(24);
        let (_, choice) = fill_reducing(&matrix, matrix.n(), &coords);
        assert!((choice.grading - 2.0).abs() < 1e-9, "{choice:?}");
        // graded towards the contact boundary y = 0 as Example 7.1's adaptive meshes: AMD is
        // computed and needs several times fewer flops than nested dissection
        let p = model::problems::Ex71;
        let mut mesh = MeshSpec::Structured(8).build(&p).expect("the unit square");
        for _ in 0..12 {
            let marked: Vec<bool> = (0..mesh.n_triangles()).map(|t| mesh.corners(t).iter().any(|c| c[1] == 0.0)).collect();
            mesh = model::mesh::refine::refine(&mesh, &marked).unwrap().mesh;
        }
        let nodes = P2Nodes::new(&mesh);
        let dofs = DofMap::new(&nodes, &p);
        let sys = assembly::assemble(&mesh, &nodes, &dofs, &p);
        let (_, choice) = fill_reducing(&sys.matrix, sys.matrix.n(), &dofs.unknown_coords(&nodes));
        assert!(choice.grading > GRADED, "{choice:?}");
        assert_eq!(choice.method, Method::MinimumDegree, "{choice:?}");
        let amd = choice.flops_minimum_degree.expect("computed on a graded mesh");
        assert!(amd < 0.5 * choice.flops_nested_dissection, "{choice:?}");
        model::base::note::line(format_args!("graded: {} unknowns, {choice:?}", sys.matrix.n()));
    }

    #[test]
    fn flop_count_matches_amd_on_its_own_ordering() {
        // the column-count routine against AMD's own count of the same ordering, on the graph of
        // the unknowns (every unknown a node of its own: all positions distinct)
        let (matrix, _) = system(16);
        let n = matrix.n();
        let graph = Graph::new(&matrix, n, &distinct_positions(n));
        assert_eq!(graph.n_nodes(), n);
        let pattern = faer::sparse::SymbolicSparseColMatRef::new_checked(n, n, &graph.ptr, None, &graph.adj);
        let (mut fwd, mut inv) = (vec![0u32; n], vec![0u32; n]);
        let mut mem = faer::dyn_stack::MemBuffer::new(faer::sparse::linalg::amd::order_maybe_unsorted_scratch::<u32>(n, graph.adj.len()));
        let f = faer::sparse::linalg::amd::order_maybe_unsorted(
            &mut fwd,
            &mut inv,
            pattern,
            Default::default(),
            faer::dyn_stack::MemStack::new(&mut mem),
        )
        .unwrap();
        let order: Vec<usize> = fwd.iter().map(|&i| i as usize).collect();
        let ours = factorisation_flops(&graph, &order);
        let amd = f.n_div + f.n_mult_subs_ldl;
        assert!((ours - amd).abs() <= 1e-12 * amd, "ours {ours:e}, AMD {amd:e}");
    }

    fn distinct_positions(n: usize) -> Vec<[f64; 2]> {
        (0..n).map(|i| [i as f64, 0.0]).collect()
    }

    #[test]
    fn node_graph_flops_are_those_of_the_unknowns() {
        // the weighted count on the node graph against the plain count on the graph of the
        // unknowns, for both orderings, with the contact normals ordered apart (lone tangential
        // unknowns) and with all unknowns ordered
        let (matrix, coords) = system(12);
        let n = matrix.n();
        for n_order in [n - 13, n] {
            let nodes = Graph::new(&matrix, n_order, &coords);
            assert!(nodes.n_nodes() < n_order * 6 / 10, "{} nodes for {n_order} unknowns", nodes.n_nodes());
            let unknowns = Graph::new(&matrix, n_order, &distinct_positions(n_order));
            let node_coords: Vec<[f64; 2]> = nodes.first[..nodes.n_nodes()].iter().map(|&i| coords[i]).collect();
            let nd = nested_dissection(&nodes, &node_coords, &reach(&nodes, &node_coords));
            let reversed: Vec<usize> = (0..nodes.n_nodes()).rev().collect();
            for order in [nd, reversed] {
                let (weighted, plain) = (factorisation_flops(&nodes, &order), factorisation_flops(&unknowns, &nodes.unknowns(&order)));
                assert_eq!(weighted, plain, "n_order {n_order}");
            }
        }
    }

    #[test]
    fn the_same_ordering_on_one_and_two_threads() {
        let (matrix, coords) = system(160); // large enough for the parallel recursion
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| fill_reducing(&matrix, matrix.n() - 7, &coords))
        };
        let (one, two) = (run(1), run(2));
        assert_eq!(one.0, two.0);
        assert_eq!(one.1, two.1);
        assert_eq!(&one.0[matrix.n() - 7..], &(matrix.n() - 7..matrix.n()).collect::<Vec<_>>()[..], "the trailing unknowns stay last");
    }
}
