//! The numeric supernodal Cholesky factorisation P K P^T = L L^T, on every core.
//!
//! [`crate::sparse::symbolic`] computes the structure (the supernodes: runs of columns of L with one row
//! pattern, the layout of L's values) and where the matrix's entries go; this module puts the
//! matrix's values in L's layout ([`load`]), factorises them there ([`factorize`]) and solves
//! with L ([`solve_in_place`]). Loading first lets a caller release the matrix before L fills up
//! (peak memory). faer's
//! own numeric step visits the supernodes one after another and parallelises only inside a
//! supernode's dense kernels, which on our matrices was slower than one thread. Yet most of the
//! work of a nested-dissection ordering lies in subtrees of the elimination tree that share
//! nothing: the two halves of a dissection only meet in their separator. So here the supernodal
//! elimination tree is the schedule: the subtrees of a supernode are factorised in parallel
//! (rayon), the supernode itself once they are all done.
//!
//! Each supernode s is computed left-looking, as faer does, by one thread:
//!
//! ```text
//!   L_s  = K_s - sum_{d in desc(s)} L_{d,rows(s)} L_{d,cols(s)}^T     (desc(s): the supernodes with rows in s's columns, ascending)
//!   L_ss = chol(L_ss),   L_{s,below} = L_{s,below} L_ss^{-T}
//! ```
//!
//! with sequential dense kernels. The descendants are visited in the same order and every update
//! is computed the same way whichever thread runs it, so L is bitwise the same on any number of
//! threads; only the order in which independent supernodes finish changes.
//!
//! Written by hand because faer 0.24 has no tree-parallel numeric factorisation (and takes no
//! structure computed elsewhere). The dense kernels (products, Cholesky, triangular solve) are
//! faer's.

use crate::sparse::csc::Shared;
use crate::sparse::symbolic::{Placement, Symbolic};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{LltParams, LltRegularization};
use faer::linalg::matmul::triangular::BlockStructure;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, MatMut, MatRef, Par, Spec};
use rayon::prelude::*;
use std::cell::RefCell;

/// Subtrees with less work than this share of the whole are factorised by one thread, in one
/// task (finer tasks cost more to schedule than they gain).
const TASK_SHARE: f64 = 1.0 / 256.0;

/// A supernode whose task has at least this many multiply-adds runs its dense kernels on every
/// thread when nothing else runs (at the top of the tree: at `structured:256` the last supernode,
/// the top separator with the contact unknowns, is a fifth of all the work).
const PAR_KERNEL_WORK: f64 = 1e7;

/// What the numeric factorisation needs beyond the symbolic structure, computed once per
/// symbolic factorisation: the supernodal elimination tree, the descendants that update each
/// supernode, and the work of every subtree (for the schedule).
pub struct Plan {
    /// Descendants updating supernode s: `upd[upd_ptr[s]..upd_ptr[s + 1]]`, ascending.
    upd_ptr: Vec<usize>,
    upd: Vec<Update>,
    /// Children of supernode s in the supernodal elimination tree: `kids[kid_ptr[s]..kid_ptr[s + 1]]`.
    kid_ptr: Vec<usize>,
    kids: Vec<u32>,
    roots: Vec<u32>,
    /// The parent of each supernode (`u32::MAX` for a root).
    parent: Vec<u32>,
    /// Multiply-add pairs of the task of each supernode (`own`) and of its subtree (`work`).
    own: Vec<f64>,
    work: Vec<f64>,
    /// Subtrees with less work are one task.
    task_work: f64,
    /// The largest update product (rows x columns) and the widest supernode, for the scratch.
    max_update: usize,
    max_cols: usize,
    max_pattern: usize,
}

/// Supernode `d` updates a later supernode s through its pattern rows `first..first + mid`,
/// the ones among s's columns.
#[derive(Clone, Copy, Default)]
struct Update {
    d: u32,
    first: u32,
    mid: u32,
}

/// The matrix is not positive definite: a pivot of this (permuted) column was not positive.
#[derive(Debug, thiserror::Error)]
#[error("non-positive pivot at column {column} of the permuted matrix")]
pub struct NotPositiveDefinite {
    pub column: usize,
}

/// A buffer of the factorisation could not be allocated: the allocator refused `bytes` (the
/// address-space limit, `ulimit -v`, or the machine's memory). The named error in place of
/// the abort an infallible allocation ends in.
#[derive(Debug, thiserror::Error)]
#[error("out of memory: allocating {what} of {bytes} bytes ({mib:.1} MiB) failed", mib = *bytes as f64 / 1048576.0)]
pub struct OutOfMemory {
    pub what: &'static str,
    pub bytes: usize,
}

/// Why [`factorize`] failed.
#[derive(Debug, thiserror::Error)]
pub enum FactorError {
    #[error(transparent)]
    NotPositiveDefinite(#[from] NotPositiveDefinite),
    #[error(transparent)]
    OutOfMemory(#[from] OutOfMemory),
}

/// `len` zeros, allocated fallibly: the one allocation of L's values (a vector of the length
/// of [`Symbolic::len_val`]). Zeroed by the allocator (calloc), so that its pages are first
/// touched by [`load`] and the factorisation, as `vec![0.0; len]` would leave them.
pub fn zeros(len: usize, what: &'static str) -> Result<Vec<f64>, OutOfMemory> {
    let bytes = len.saturating_mul(std::mem::size_of::<f64>());
    if len == 0 {
        return Ok(Vec::new());
    }
    let layout = std::alloc::Layout::array::<f64>(len).map_err(|_| OutOfMemory { what, bytes })?;
    // SAFETY: the layout has a nonzero size; a non-null pointer from alloc_zeroed holds `len`
    // zeroed f64 (0.0 is all zero bits) with the alignment of f64, allocated by the global
    // allocator with this layout, as Vec::from_raw_parts requires
    unsafe {
        let ptr = std::alloc::alloc_zeroed(layout) as *mut f64;
        if ptr.is_null() {
            return Err(OutOfMemory { what, bytes });
        }
        Ok(Vec::from_raw_parts(ptr, len, len))
    }
}

/// Grow `v` to at least `len` (new entries zero), fallibly.
fn grow<T: Clone + Default>(v: &mut Vec<T>, len: usize, what: &'static str) -> Result<(), OutOfMemory> {
    if v.len() < len {
        v.try_reserve_exact(len - v.len()).map_err(|_| OutOfMemory { what, bytes: len.saturating_mul(std::mem::size_of::<T>()) })?;
        v.resize(len, T::default());
    }
    Ok(())
}

/// A supernode's place in L: first column, columns, row pattern below them, offset of its values.
struct Supernode<'a> {
    begin: usize,
    ncols: usize,
    pattern: &'a [u32],
    offset: usize,
}

impl Supernode<'_> {
    fn nrows(&self) -> usize {
        self.ncols + self.pattern.len()
    }
}

fn supernode(sn: &Symbolic, s: usize) -> Supernode<'_> {
    let begin = sn.supernode_begin();
    Supernode { begin: begin[s], ncols: begin[s + 1] - begin[s], pattern: sn.pattern(s), offset: sn.val_ptr()[s] }
}

impl Plan {
    /// The plan for factorising with the structure `sn`.
    pub fn new(sn: &Symbolic) -> Self {
        let ns = sn.n_supernodes();
        let begin = sn.supernode_begin();
        let super_of = crate::sparse::csc::group_of(begin);
        // descendants: d updates every supernode its pattern rows fall in (each once, d ascending)
        let super_of = &super_of;
        let targets = |d: usize| {
            let p = supernode(sn, d).pattern;
            p.iter()
                .enumerate()
                .filter(move |&(i, &r)| i == 0 || super_of[p[i - 1] as usize] != super_of[r as usize])
                .map(|(_, &r)| super_of[r as usize] as usize)
        };
        let mut upd_ptr = vec![0usize; ns + 1];
        let mut kid_ptr = vec![0usize; ns + 1];
        let mut roots = Vec::new();
        for d in 0..ns {
            targets(d).for_each(|s| upd_ptr[s + 1] += 1);
            match targets(d).next() {
                Some(parent) => kid_ptr[parent + 1] += 1,
                None => roots.push(d as u32),
            }
        }
        for s in 0..ns {
            upd_ptr[s + 1] += upd_ptr[s];
            kid_ptr[s + 1] += kid_ptr[s];
        }
        let (mut upd, mut kids) = (vec![Update::default(); upd_ptr[ns]], vec![0u32; kid_ptr[ns]]);
        let (mut upd_fill, mut kid_fill) = (upd_ptr.clone(), kid_ptr.clone());
        let mut max_update = 0;
        for d in 0..ns {
            let node = supernode(sn, d);
            let mut first = true;
            let mut i = 0;
            while i < node.pattern.len() {
                let s = super_of[node.pattern[i] as usize] as usize;
                let mid = node.pattern[i..].iter().take_while(|&&r| super_of[r as usize] as usize == s).count();
                max_update = max_update.max((node.pattern.len() - i) * mid);
                upd[upd_fill[s]] = Update { d: d as u32, first: i as u32, mid: mid as u32 };
                upd_fill[s] += 1;
                if first {
                    kids[kid_fill[s]] = d as u32;
                    kid_fill[s] += 1;
                    first = false;
                }
                i += mid;
            }
        }
        // work: what the task of each supernode computes (left-looking: the updates it pulls from
        // its descendants, its dense Cholesky and triangular solve), summed over subtrees
        // (children have smaller numbers than their parent)
        let mut work: Vec<f64> = (0..ns)
            .map(|s| {
                let node = supernode(sn, s);
                let (c, p) = (node.ncols as f64, node.pattern.len() as f64);
                let pulled: f64 = upd[upd_ptr[s]..upd_ptr[s + 1]]
                    .iter()
                    .map(|u| {
                        let dn = supernode(sn, u.d as usize);
                        let (rows, mid) = ((dn.pattern.len() - u.first as usize) as f64, u.mid as f64);
                        (rows - mid / 2.0) * mid * dn.ncols as f64
                    })
                    .sum();
                pulled + c * c * c / 6.0 + p * c * c / 2.0
            })
            .collect();
        let own = work.clone();
        for s in 0..ns {
            let w: f64 = kids[kid_ptr[s]..kid_ptr[s + 1]].iter().map(|&k| work[k as usize]).sum();
            work[s] += w;
        }
        let mut parent = vec![u32::MAX; ns];
        for s in 0..ns {
            for &k in &kids[kid_ptr[s]..kid_ptr[s + 1]] {
                parent[k as usize] = s as u32;
            }
        }
        let total: f64 = roots.iter().map(|&r| work[r as usize]).sum();
        let max_cols = (0..ns).map(|s| begin[s + 1] - begin[s]).max().unwrap_or(0);
        let max_pattern = (0..ns).map(|s| sn.pattern(s).len()).max().unwrap_or(0);
        Plan { upd_ptr, upd, kid_ptr, kids, roots, parent, own, work, task_work: total * TASK_SHARE, max_update, max_cols, max_pattern }
    }

    /// Run `kernel(s, alone)` for every supernode of `which` (all if None; a set closed under
    /// ancestors, as [`Plan::changed`] gives), each after all its descendants (for the
    /// factorisation and the forward substitution): the children's subtrees in parallel, then
    /// the supernode; subtrees with less work than [`TASK_SHARE`] of the whole in one task. A
    /// chain of supernodes with one large child each is walked without recursion (its small side
    /// subtrees run just before their parent), so the depth of recursion is bounded by the number
    /// of tasks, not by the height of the tree. `alone`: nothing else runs meanwhile (the top of
    /// the tree), so the kernel may use every thread. A subtree outside `which` is skipped
    /// whole (its root is not in the set, so none of its supernodes is).
    fn upward<E: Send>(&self, which: Option<&[bool]>, kernel: &(dyn Fn(usize, bool) -> Result<(), E> + Sync)) -> Result<(), E> {
        let roots: Vec<usize> = self.roots.iter().map(|&r| r as usize).filter(|&r| which.is_none_or(|w| w[r])).collect();
        let alone = roots.len() == 1;
        roots.into_par_iter().try_for_each(|r| self.up(r, alone, which, kernel))
    }

    fn up<E: Send>(
        &self,
        s: usize,
        alone: bool,
        which: Option<&[bool]>,
        kernel: &(dyn Fn(usize, bool) -> Result<(), E> + Sync),
    ) -> Result<(), E> {
        let kept = |x: &usize| which.is_none_or(|w| w[*x]);
        if self.work[s] < self.task_work {
            return self.subtree(s).into_iter().filter(kept).try_for_each(|x| kernel(x, alone));
        }
        let mut chain = vec![s];
        loop {
            let top = *chain.last().unwrap();
            let large: Vec<usize> = self.kids(top).filter(kept).filter(|&k| self.work[k] >= self.task_work).collect();
            if large.len() != 1 {
                break;
            }
            chain.push(large[0]);
        }
        let bottom = *chain.last().unwrap();
        let kids: Vec<usize> = self.kids(bottom).filter(kept).collect();
        let kids_alone = alone && kids.len() == 1;
        kids.into_par_iter().try_for_each(|k| self.up(k, kids_alone, which, kernel))?;
        kernel(bottom, alone)?;
        for w in chain.windows(2).rev() {
            let (x, large) = (w[0], w[1]);
            for k in self.kids(x).filter(kept).filter(|&k| k != large) {
                self.up(k, alone, which, kernel)?;
            }
            kernel(x, alone)?;
        }
        Ok(())
    }

    /// The supernodes whose blocks of L change when the matrix's values change in the columns
    /// `columns` of L (the permuted numbering; an entry (i, j) of the permuted matrix lies in
    /// column min(i, j)): the supernodes holding those columns and all their ancestors. Every
    /// other supernode is computed from the same values and the same (unchanged) descendants,
    /// so a refactorisation of only these ([`refactorize`]) gives L bit for bit.
    pub fn changed(&self, sn: &Symbolic, columns: impl IntoIterator<Item = usize>) -> Vec<bool> {
        let begin = sn.supernode_begin();
        let mut which = vec![false; self.own.len()];
        for j in columns {
            let mut s = begin.partition_point(|&b| b <= j) - 1;
            while !which[s] {
                which[s] = true;
                match self.parent[s] {
                    u32::MAX => break,
                    p => s = p as usize,
                }
            }
        }
        which
    }

    /// The share of the factorisation's multiply-adds in the supernodes of `which`.
    pub fn share(&self, which: &[bool]) -> f64 {
        let part: f64 = self.own.iter().zip(which).filter(|(_, w)| **w).map(|(o, _)| o).sum();
        part / self.multiply_adds().max(f64::MIN_POSITIVE)
    }

    /// Run `kernel(s)` for every supernode, each after all its ancestors (for the backward
    /// substitution): the supernode, then its children's subtrees in parallel; small subtrees
    /// in one task, chains walked without recursion as in [`Plan::upward`].
    fn downward(&self, kernel: &(dyn Fn(usize) + Sync)) {
        self.roots.par_iter().for_each(|&r| self.down(r as usize, kernel));
    }

    fn down(&self, s: usize, kernel: &(dyn Fn(usize) + Sync)) {
        let mut s = s;
        loop {
            if self.work[s] < self.task_work {
                self.subtree(s).into_iter().rev().for_each(kernel);
                return;
            }
            kernel(s);
            let large: Vec<usize> = self.kids(s).filter(|&k| self.work[k] >= self.task_work).collect();
            if large.len() != 1 {
                self.kids(s).collect::<Vec<_>>().into_par_iter().for_each(|k| self.down(k, kernel));
                return;
            }
            for k in self.kids(s).filter(|&k| k != large[0]) {
                self.down(k, kernel);
            }
            s = large[0];
        }
    }

    /// The multiply-adds the factorisation executes: every supernode's updates from its
    /// descendants, dense Cholesky and triangular solve, explicit zeros of the relaxed
    /// supernodes included (the work the schedule balances).
    pub fn multiply_adds(&self) -> f64 {
        self.own.iter().sum()
    }

    /// Supernodes, and the share of the multiply-adds in supernodes of at least `cols` columns.
    pub fn shape(&self, sn: &Symbolic, cols: usize) -> (usize, f64) {
        let begin = sn.supernode_begin();
        let wide: f64 = (0..self.own.len()).filter(|&s| begin[s + 1] - begin[s] >= cols).map(|s| self.own[s]).sum();
        (self.own.len(), wide / self.multiply_adds())
    }

    fn kids(&self, s: usize) -> impl Iterator<Item = usize> + '_ {
        self.kids[self.kid_ptr[s]..self.kid_ptr[s + 1]].iter().map(|&k| k as usize)
    }

    /// The supernodes of the subtree of s, ascending (a valid order: children before parents).
    fn subtree(&self, s: usize) -> Vec<usize> {
        let mut nodes = vec![s];
        let mut i = 0;
        while i < nodes.len() {
            let x = nodes[i];
            nodes.extend(self.kids(x));
            i += 1;
        }
        nodes.sort_unstable();
        nodes
    }
}

/// Per-thread scratch of the factorisation: the update product and the dense Cholesky's
/// workspace.
struct Scratch {
    update: Vec<f64>,
    /// the rows of the current update product in the target's block
    rel: Vec<usize>,
    stack: MemBuffer,
    stack_bytes: usize,
}

thread_local! {
    static SCRATCH: RefCell<Option<Scratch>> = const { RefCell::new(None) };
    /// Per thread: the position of each row of the current supernode in its block (the rows of
    /// its pattern; its own columns are found by subtraction).
    static LOCAL: RefCell<Vec<u32>> = const { RefCell::new(Vec::new()) };
}

/// Run `f` with this thread's row map, at least `n` long.
fn with_local_map<R>(n: usize, f: impl FnOnce(&mut [u32]) -> R) -> R {
    LOCAL.with_borrow_mut(|local| {
        if local.len() < n {
            local.resize(n, 0);
        }
        f(local)
    })
}

/// [`with_local_map`] with the map grown fallibly (the factorisation's path).
fn try_with_local_map<R>(n: usize, f: impl FnOnce(&mut [u32]) -> R) -> Result<R, OutOfMemory> {
    LOCAL.with_borrow_mut(|local| {
        grow(local, n, "the factorisation's row map")?;
        Ok(f(local))
    })
}

/// Runs of supernodes that [`load`] hands to the threads, each about this share of L's values.
const LOAD_RUNS: usize = 64;

/// Put a matrix's values (the pattern `placement` was made for) in `l`, the layout of `sn`: the
/// lower triangle of P K P^T, zeros elsewhere, ready for [`factorize`]. Each supernode's block is
/// zeroed (unless `zeroed`: `l` holds zeros already) and each entry added to its slot, which no
/// other entry shares: the same bits as a copy. In parallel over runs of supernodes of about
/// equal size. On a fresh allocation (`zeroed`) only the pages with entries are touched here; the
/// rest of L is first touched by the factorisation, after the caller could release the matrix.
/// `fixed` (permuted numbering) marks unknowns whose rows and columns are taken as zero but for
/// the diagonal: the constraints of the Refactor strategy, imposed without a copy of the values.
pub fn load(sn: &Symbolic, placement: &Placement, values: &[f64], fixed: Option<&[bool]>, l: &mut [f64], zeroed: bool) {
    assert_eq!(l.len(), sn.len_val());
    let (ns, val_ptr) = (sn.n_supernodes(), sn.val_ptr());
    let total = sn.len_val();
    let mut bounds = vec![0usize];
    for r in 1..=LOAD_RUNS {
        let s = if r == LOAD_RUNS { ns } else { val_ptr.partition_point(|&v| v < total * r / LOAD_RUNS).min(ns) };
        if s > *bounds.last().unwrap() {
            bounds.push(s);
        }
    }
    let mut runs = Vec::with_capacity(bounds.len());
    let mut rest = l;
    for w in bounds.windows(2) {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(val_ptr[w[1]] - val_ptr[w[0]]);
        runs.push((w[0], w[1], head));
        rest = tail;
    }
    runs.into_par_iter().for_each(|(first, last, run)| {
        with_local_map(sn.n(), |local| {
            let base = val_ptr[first];
            for s in first..last {
                let node = supernode(sn, s);
                let block = &mut run[node.offset - base..][..node.nrows() * node.ncols];
                load_supernode(&node, placement, values, fixed, block, zeroed, local);
            }
        })
    });
}

/// Supernode `node`'s part of [`load`] into its `block`, with this thread's row map `local`.
fn load_supernode(
    node: &Supernode,
    placement: &Placement,
    values: &[f64],
    fixed: Option<&[bool]>,
    block: &mut [f64],
    zeroed: bool,
    local: &mut [u32],
) {
    let (ncols, nrows) = (node.ncols, node.nrows());
    if !zeroed {
        block.fill(0.0);
    }
    for (i, &r) in node.pattern.iter().enumerate() {
        local[r as usize] = (ncols + i) as u32;
    }
    let end = node.begin + ncols;
    for j in node.begin..end {
        let column = &mut block[(j - node.begin) * nrows..][..nrows];
        for &(r, pos) in placement.entries(j) {
            let r = r as usize;
            // a store, not `+=`: no other entry shares the slot, which holds zero, so the bits
            // are those of adding the value to zero; and a first access that writes is one page
            // fault on a fresh L (a read first maps the zero page, and the write then faults
            // again: 2.0 s instead of 0.44 s at structured:512)
            let value = match fixed {
                Some(fixed) if r != j && (fixed[r] || fixed[j]) => 0.0,
                _ => 0.0 + values[pos as usize],
            };
            column[if r < end { r - node.begin } else { local[r] as usize }] = value;
        }
    }
}

/// Load into `l`, the factor of a matrix with the pattern `placement` was made for, new
/// `values` (with `fixed`, as [`load`] takes them) that differ from that matrix's only in the
/// columns of L whose supernodes [`Plan::changed`] marked in `which`: only those supernodes'
/// blocks are loaded, for [`refactorize`].
pub fn load_changed(sn: &Symbolic, placement: &Placement, values: &[f64], fixed: Option<&[bool]>, l: &mut [f64], which: &[bool]) {
    assert_eq!((l.len(), which.len()), (sn.len_val(), sn.n_supernodes()));
    let shared = Shared::new(l);
    let marked: Vec<usize> = (0..which.len()).filter(|&s| which[s]).collect();
    marked.par_iter().for_each(|&s| {
        with_local_map(sn.n(), |local| {
            let node = supernode(sn, s);
            // SAFETY: each marked supernode's block is written by this one task only
            let block = unsafe { shared.slice(node.offset, node.nrows() * node.ncols) };
            load_supernode(&node, placement, values, fixed, block, false, local);
        })
    });
}

/// Factorise again only the supernodes marked in `which` ([`load_changed`] loaded them), in the
/// factorisation's own schedule. The result is bit for bit [`load`] and [`factorize`] of the
/// new values: every other supernode holds what they would compute (the same values, the same
/// descendants). Where an active-set step changes a few contact nodes, that is the path from
/// them to the root of the elimination tree instead of the whole tree.
pub fn refactorize(sn: &Symbolic, plan: &Plan, l: &mut [f64], which: &[bool]) -> Result<(), FactorError> {
    assert_eq!(which.len(), sn.n_supernodes());
    factorize_some(sn, plan, l, Some(which))
}

/// Overwrite `l` (the layout of `sn`, holding a matrix's values from [`load`]) with the
/// Cholesky factor of that matrix, permuted as planned.
pub fn factorize(sn: &Symbolic, plan: &Plan, l: &mut [f64]) -> Result<(), FactorError> {
    factorize_some(sn, plan, l, None)
}

/// [`factorize`] of the supernodes in `which` (all if None).
fn factorize_some(sn: &Symbolic, plan: &Plan, l: &mut [f64], which: Option<&[bool]>) -> Result<(), FactorError> {
    assert_eq!(l.len(), sn.len_val());
    let ctx = Context { sn, plan, l: Shared::new(l) };
    plan.upward(which, &|s, alone| ctx.supernode(s, alone))
}

struct Context<'a> {
    sn: &'a Symbolic,
    plan: &'a Plan,
    l: Shared,
}

impl Context<'_> {
    /// Compute supernode s's block of L from the matrix's values there and its (finished)
    /// descendants.
    fn supernode(&self, s: usize, alone: bool) -> Result<(), FactorError> {
        let (sn, plan) = (self.sn, self.plan);
        // faer's parallel dense kernels give the same bits as its sequential ones (tested: one and
        // two threads agree bitwise), so this choice changes only the time
        let par = if alone && plan.own[s] >= PAR_KERNEL_WORK { Par::rayon(0) } else { Par::Seq };
        let node = supernode(sn, s);
        let (ncols, nrows) = (node.ncols, node.nrows());
        let len = nrows * ncols;
        // SAFETY: this block is written only here, and nothing reads it before this task ends
        let block = unsafe { self.l.slice(node.offset, len) };
        map_for_writing(block);
        SCRATCH.with_borrow_mut(|scratch| {
            let scratch = scratch.get_or_insert_with(|| Scratch {
                update: Vec::new(),
                rel: Vec::new(),
                stack: MemBuffer::new(faer::dyn_stack::StackReq::EMPTY),
                stack_bytes: 0,
            });
            grow(&mut scratch.update, plan.max_update, "the factorisation's update product")?;
            let need = faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f64>(
                plan.max_cols,
                Par::rayon(0),
                Spec::<LltParams, f64>::default(),
            );
            if scratch.stack_bytes < need.unaligned_bytes_required() {
                let bytes = need.unaligned_bytes_required();
                scratch.stack = MemBuffer::try_new(need).map_err(|_| OutOfMemory { what: "the dense Cholesky's workspace", bytes })?;
                scratch.stack_bytes = bytes;
            }
            try_with_local_map(sn.n(), |local| {
                for (i, &r) in node.pattern.iter().enumerate() {
                    local[r as usize] = (ncols + i) as u32;
                }
                for u in &plan.upd[plan.upd_ptr[s]..plan.upd_ptr[s + 1]] {
                    let dn = supernode(sn, u.d as usize);
                    // SAFETY: supernode d is a descendant of s, finished before this task started
                    let dvals: &[f64] = unsafe { self.l.slice(dn.offset, dn.nrows() * dn.ncols) };
                    let ld = MatRef::from_column_major_slice(dvals, dn.nrows(), dn.ncols);
                    let (first, mid) = (u.first as usize, u.mid as usize);
                    let rows = dn.pattern.len() - first;
                    let below = ld.subrows(dn.ncols + first, rows);
                    let (ld_mid, ld_bot) = below.split_at_row(mid);
                    let product = &mut scratch.update[..rows * mid];
                    let mut upd = MatMut::from_column_major_slice_mut(&mut *product, rows, mid);
                    {
                        let (top, bot) = upd.rb_mut().split_at_row_mut(mid);
                        faer::linalg::matmul::triangular::matmul(
                            top,
                            BlockStructure::TriangularLower,
                            Accum::Replace,
                            ld_mid,
                            BlockStructure::Rectangular,
                            ld_mid.transpose(),
                            BlockStructure::Rectangular,
                            1.0,
                            par,
                        );
                        faer::linalg::matmul::matmul(bot, Accum::Replace, ld_bot, ld_mid.transpose(), 1.0, par);
                    }
                    // where the product's rows go in s's block: its own columns by subtraction,
                    // its pattern rows through the row map
                    let rel = &mut scratch.rel;
                    rel.clear();
                    rel.extend(dn.pattern[first..].iter().enumerate().map(|(ii, &r)| {
                        let r = r as usize;
                        if ii < mid { r - node.begin } else { local[r] as usize }
                    }));
                    scatter_subtract(block, nrows, product, rows, mid, rel);
                }
            })?;
            let ls = MatMut::from_column_major_slice_mut(block, nrows, ncols);
            let (mut top, bot) = ls.split_at_row_mut(ncols);
            faer::linalg::cholesky::llt::factor::cholesky_in_place(
                top.rb_mut(),
                LltRegularization::default(),
                par,
                MemStack::new(&mut scratch.stack),
                Spec::<LltParams, f64>::default(),
            )
            .map_err(|e| match e {
                faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } => {
                    FactorError::from(NotPositiveDefinite { column: node.begin + index })
                }
            })?;
            faer::linalg::triangular_solve::solve_lower_triangular_in_place(top.rb(), bot.transpose_mut(), par);
            Ok(())
        })
    }
}

/// Map every page of `block` writable before the updates read it. On a fresh L the pages
/// without entries of the matrix were not touched by [`load`]; the first update into such a
/// page reads before it writes, so the kernel maps the shared zero page and, at the write,
/// replaces it, which on two threads costs a TLB shootdown (an interrupt to the other core):
/// 5.8% of the CPU time of fb adaptive to 1.8e6 unknowns went there (perf). A locked
/// compare-exchange of zero with zero is a write access whatever the value (the page is mapped
/// once, for writing) and changes no bit; on a page mapped already it costs one atomic.
fn map_for_writing(block: &mut [f64]) {
    const PAGE: usize = 4096 / std::mem::size_of::<f64>();
    let first = block.as_ptr() as usize / std::mem::size_of::<f64>();
    let (len, ptr) = (block.len(), block.as_mut_ptr());
    let boundaries = (PAGE - first % PAGE) % PAGE;
    for i in std::iter::once(0).chain((boundaries..len).step_by(PAGE)).filter(|&i| i < len) {
        // SAFETY: an f64 of the block (aligned as u64), accessed by this task only
        let word = unsafe { std::sync::atomic::AtomicU64::from_ptr(ptr.add(i).cast::<u64>()) };
        let _ = word.compare_exchange(0, 0, std::sync::atomic::Ordering::Relaxed, std::sync::atomic::Ordering::Relaxed);
    }
}

/// `block[rel[i], rel[j]] -= product[i, j]` for the lower triangle `i >= j` of the `rows x mid`
/// product (column-major), `block` column-major with `nrows` rows; `rel[j]` for `j < mid` is
/// also the column of the block. Entry by entry in the same order as an indexed loop (the
/// same bits), without bounds checks in the inner loop: it runs once per entry of every update,
/// and with faer's checked indexing it was a seventh of the factorisation.
fn scatter_subtract(block: &mut [f64], nrows: usize, product: &[f64], rows: usize, mid: usize, rel: &[usize]) {
    assert!(product.len() >= rows * mid && rel.len() == rows && mid <= rows);
    assert!(rel.iter().all(|&r| r < nrows) && rel[..mid].iter().all(|&c| (c + 1) * nrows <= block.len()));
    for jj in 0..mid {
        let column = &mut block[rel[jj] * nrows..][..nrows];
        let source = &product[jj * rows..][..rows];
        for ii in jj..rows {
            // SAFETY: rel[ii] < nrows = column.len() and ii < rows = source.len(), checked above
            unsafe { *column.get_unchecked_mut(*rel.get_unchecked(ii)) -= *source.get_unchecked(ii) };
        }
    }
}

thread_local! {
    static SOLVE_SCRATCH: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// Solve L L^T x = b in place for the factor `l` of [`factorize`], with b and x in the permuted
/// numbering (row `inv[i]` holds unknown i): [`forward_in_place`], then [`backward_in_place`].
pub fn solve_in_place(sn: &Symbolic, plan: &Plan, l: &[f64], x: &mut [f64]) {
    forward_in_place(sn, plan, l, x);
    backward_in_place(sn, plan, l, x);
}

/// Forward substitution L y = b in place, up the tree (each supernode pulls the products of its
/// descendants, in the order faer pushes them), independent subtrees in parallel; the same bits
/// on any number of threads.
pub fn forward_in_place(sn: &Symbolic, plan: &Plan, l: &[f64], x: &mut [f64]) {
    assert_eq!((l.len(), x.len()), (sn.len_val(), sn.n()));
    let x = Shared::new(x);
    // SAFETY: a task writes only its supernode's rows of x, and reads rows of descendants, which
    // the schedule has finished
    let _ = plan.upward(None, &|s, _| -> Result<(), std::convert::Infallible> {
        unsafe { forward_supernode(sn, plan, l, x, s) };
        Ok(())
    });
}

/// Backward substitution L^T x = y in place, down the tree, independent subtrees in parallel;
/// the same bits on any number of threads.
pub fn backward_in_place(sn: &Symbolic, plan: &Plan, l: &[f64], x: &mut [f64]) {
    assert_eq!((l.len(), x.len()), (sn.len_val(), sn.n()));
    let x = Shared::new(x);
    // SAFETY: a task writes only its supernode's rows of x, and reads rows of ancestors, which
    // the schedule has finished
    plan.downward(&|s| unsafe { backward_supernode(sn, plan, l, x, s) });
}

/// The supernodes holding the rows `from..n`: every supernode that ends after `from` (the first
/// may begin before it). Supernodes are numbered in a postorder, so these are the last ones, each
/// an ancestor of none of the others before it.
fn tail(sn: &Symbolic, from: usize) -> std::ops::Range<usize> {
    let begin = sn.supernode_begin();
    let first = begin.partition_point(|&b| b <= from).saturating_sub(1);
    first..sn.n_supernodes()
}

/// [`forward_in_place`] again for a right-hand side `b` that differs only in rows `from..n` from
/// the one `x` holds the forward substitution of: the supernodes of those rows are recomputed
/// from `b` (in order, one thread), the others are kept. Bit for bit what [`forward_in_place`]
/// gives for `b`: rows before `from` do not depend on rows after it, and every supernode is
/// computed by the same kernel from the same values. Work: the trailing block's share of L.
pub fn forward_tail(sn: &Symbolic, plan: &Plan, l: &[f64], x: &mut [f64], b: &[f64], from: usize) {
    assert_eq!((l.len(), x.len(), b.len()), (sn.len_val(), sn.n(), sn.n()));
    let tail = tail(sn, from);
    let start = sn.supernode_begin()[tail.start];
    x[start..].copy_from_slice(&b[start..]);
    let x = Shared::new(x);
    for s in tail {
        // SAFETY: one thread; the kernel's slices of x are dropped before it returns
        unsafe { forward_supernode(sn, plan, l, x, s) };
    }
}

/// The rows `from..n` of [`backward_in_place`] of the forward substitution `x`, without the
/// other rows (left as they are: not a solution there): the supernodes of those rows, from the
/// last, one thread. Bit for bit the rows a full backward substitution gives, since they depend
/// on no row before `from`. Work: the trailing block's share of L.
pub fn backward_tail(sn: &Symbolic, plan: &Plan, l: &[f64], x: &mut [f64], from: usize) {
    assert_eq!((l.len(), x.len()), (sn.len_val(), sn.n()));
    let tail = tail(sn, from);
    let x = Shared::new(x);
    for s in tail.rev() {
        // SAFETY: as in forward_tail
        unsafe { backward_supernode(sn, plan, l, x, s) };
    }
}

/// Supernode `node`'s block of the factor `l` (its columns, own rows then pattern rows).
fn block_of<'a>(l: &'a [f64], node: &Supernode) -> MatRef<'a, f64> {
    MatRef::from_column_major_slice(&l[node.offset..node.offset + node.nrows() * node.ncols], node.nrows(), node.ncols)
}

/// One supernode of the forward substitution: x_s -= L_{s,d} x_d for every descendant d that
/// updates it (in the order faer pushes them), then x_s = L_ss^{-1} x_s.
/// # Safety
/// Nothing else may access the rows of `s` in `x` meanwhile, nor write those of its descendants.
unsafe fn forward_supernode(sn: &Symbolic, plan: &Plan, l: &[f64], x: Shared, s: usize) {
    let rows = |begin: usize, len: usize| unsafe { x.slice(begin, len) };
    let node = supernode(sn, s);
    let xs = rows(node.begin, node.ncols);
    SOLVE_SCRATCH.with_borrow_mut(|tmp| {
        tmp.resize(plan.max_pattern.max(plan.max_cols), 0.0);
        for u in &plan.upd[plan.upd_ptr[s]..plan.upd_ptr[s + 1]] {
            let dn = supernode(sn, u.d as usize);
            let (first, mid) = (u.first as usize, u.mid as usize);
            // t = L_{d, rows in s} x_d: the rows of faer's product L_{d, below} x_d that fall
            // in s, computed by the same kernel (a loop of our own here would round differently)
            let xd = MatRef::from_column_major_slice(rows(dn.begin, dn.ncols), dn.ncols, 1);
            let t = &mut tmp[..mid];
            faer::linalg::matmul::matmul(
                MatMut::from_column_major_slice_mut(&mut *t, mid, 1),
                Accum::Replace,
                block_of(l, &dn).subrows(dn.ncols + first, mid),
                xd,
                1.0,
                Par::Seq,
            );
            for (&tj, &r) in t.iter().zip(&dn.pattern[first..first + mid]) {
                xs[r as usize - node.begin] -= tj;
            }
        }
    });
    let ls = block_of(l, &node);
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(
        ls.subrows(0, node.ncols),
        MatMut::from_column_major_slice_mut(xs, node.ncols, 1),
        Par::Seq,
    );
}

/// One supernode of the backward substitution: x_s -= L_{below,s}^T x_below, then
/// x_s = L_ss^{-T} x_s.
/// # Safety
/// Nothing else may access the rows of `s` in `x` meanwhile, nor write those of its ancestors.
unsafe fn backward_supernode(sn: &Symbolic, plan: &Plan, l: &[f64], x: Shared, s: usize) {
    let rows = |begin: usize, len: usize| unsafe { x.slice(begin, len) };
    let node = supernode(sn, s);
    let xs = rows(node.begin, node.ncols);
    let ls = block_of(l, &node);
    SOLVE_SCRATCH.with_borrow_mut(|tmp| {
        tmp.resize(plan.max_pattern.max(plan.max_cols), 0.0);
        let p = node.pattern.len();
        for (t, &r) in tmp[..p].iter_mut().zip(node.pattern) {
            *t = rows(r as usize, 1)[0];
        }
        let t = MatRef::from_column_major_slice(&tmp[..p], p, 1);
        faer::linalg::matmul::matmul(
            MatMut::from_column_major_slice_mut(&mut *xs, node.ncols, 1),
            Accum::Add,
            ls.subrows(node.ncols, p).transpose(),
            t,
            -1.0,
            Par::Seq,
        );
    });
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(
        ls.subrows(0, node.ncols).transpose(),
        MatMut::from_column_major_slice_mut(xs, node.ncols, 1),
        Par::Seq,
    );
}
