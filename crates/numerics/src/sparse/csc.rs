//! Symmetric sparse matrices by their lower triangle ([`SymCsc`]) and the deterministic parallel
//! helpers compressed layouts are built with (grouping items by target, filling the slices of a
//! layout in parallel): used by the assembly, the orderings and the factorisation alike.

use rayon::prelude::*;

/// A symmetric sparse matrix stored as its lower triangle (diagonal included), compressed by
/// columns with sorted row indices.
///
/// Invariant (checked by [`SymCsc::new`], the only constructor; the fields are private and only
/// the values can change afterwards): `col_ptr` has n + 1 entries, starts at 0, is
/// non-decreasing and ends at nnz = `row_idx.len()` = `values.len()`; the row indices of column
/// j are strictly increasing, lie in j..n, and the first is j (every diagonal entry is stored,
/// first in its column).
#[derive(Clone, Debug)]
pub struct SymCsc {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
}

/// A compressed column layout that breaks the [`SymCsc`] invariant: what is wrong, where.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("not a lower-triangular compressed column matrix: {0}")]
pub struct SymCscError(pub String);

impl SymCsc {
    /// The n x n lower triangle with columns `col_ptr`, row indices `row_idx` and `values`, after
    /// checking the invariant (see [`SymCsc`]) in O(nnz).
    ///
    /// ```rust
    /// use signorini_numerics::sparse::csc::SymCsc;
    /// // [[2, -1], [-1, 2]]: column 0 holds rows 0 and 1, column 1 holds row 1
    /// let a = SymCsc::new(2, vec![0, 2, 3], vec![0, 1, 1], vec![2.0, -1.0, 2.0]).unwrap();
    /// assert_eq!(a.mul(&[1.0, 1.0]), vec![1.0, 1.0]);
    /// // an entry above the diagonal is refused
    /// assert!(SymCsc::new(2, vec![0, 1, 3], vec![0, 0, 1], vec![2.0, -1.0, 2.0]).is_err());
    /// ```
    pub fn new(n: usize, col_ptr: Vec<usize>, row_idx: Vec<usize>, values: Vec<f64>) -> Result<Self, SymCscError> {
        let bad = |s: String| Err(SymCscError(s));
        if col_ptr.len() != n + 1 {
            return bad(format!("{} column pointers for {n} columns (expected {})", col_ptr.len(), n + 1));
        }
        if col_ptr[0] != 0 {
            return bad(format!("the first column pointer is {}, not 0", col_ptr[0]));
        }
        if col_ptr[n] != row_idx.len() || row_idx.len() != values.len() {
            return bad(format!("last column pointer {}, {} row indices, {} values", col_ptr[n], row_idx.len(), values.len()));
        }
        // all pointers first: with them monotone, every column's range lies in 0..nnz
        if let Some(j) = (0..n).find(|&j| col_ptr[j + 1] < col_ptr[j]) {
            return bad(format!("column pointers decrease at column {j} ({} then {})", col_ptr[j], col_ptr[j + 1]));
        }
        for j in 0..n {
            let (lo, hi) = (col_ptr[j], col_ptr[j + 1]);
            let rows = &row_idx[lo..hi];
            if rows.first() != Some(&j) {
                return bad(format!("column {j} does not start with its diagonal entry"));
            }
            if let Some(w) = rows.windows(2).find(|w| w[0] >= w[1]) {
                return bad(format!("row indices of column {j} are not strictly increasing ({} then {})", w[0], w[1]));
            }
            if let Some(&i) = rows.last().filter(|&&i| i >= n) {
                return bad(format!("row index {i} in column {j} is out of range (n = {n})"));
            }
        }
        Ok(SymCsc { n, col_ptr, row_idx, values })
    }

    /// Number of rows and columns.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Column pointers: column j's entries are at `col_ptr()[j]..col_ptr()[j + 1]`.
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }

    /// Row index of every stored entry.
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }

    /// Value of every stored entry.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The structure (`col_ptr`, `row_idx`) to read and the values to write, at once: what a
    /// parallel fill of the values by column ranges needs.
    pub fn structure_and_values_mut(&mut self) -> (&[usize], &[usize], &mut [f64]) {
        (&self.col_ptr, &self.row_idx, &mut self.values)
    }

    /// The values, to fill or change (the pattern stays fixed).
    pub fn values_mut(&mut self) -> &mut [f64] {
        &mut self.values
    }

    /// A faer view of the lower triangle.
    pub fn as_faer(&self) -> faer::sparse::SparseColMatRef<'_, usize, f64> {
        // SAFETY: faer needs col_ptr non-decreasing from 0 to nnz (n + 1 entries) and row indices
        // < n, sorted within each column; `SymCsc::new`, the only way to build a SymCsc, checked
        // that, and the pattern cannot change afterwards (private fields, only values_mut).
        let sym = unsafe { faer::sparse::SymbolicSparseColMatRef::new_unchecked(self.n, self.n, &self.col_ptr, None, &self.row_idx) };
        faer::sparse::SparseColMatRef::new(sym, &self.values)
    }

    /// Position of entry (row, col), row >= col, in `values`.
    #[inline]
    pub fn position(&self, row: usize, col: usize) -> usize {
        let (lo, hi) = (self.col_ptr[col], self.col_ptr[col + 1]);
        lo + self.row_idx[lo..hi].binary_search(&row).expect("entry outside the sparsity pattern")
    }

    /// y = A x using the lower triangle for both halves.
    pub fn mul(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.n];
        for j in 0..self.n {
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                let (i, a) = (self.row_idx[k], self.values[k]);
                y[i] += a * x[j];
                if i != j {
                    y[j] += a * x[i];
                }
            }
        }
        y
    }

    /// The diagonal.
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.n).map(|j| self.values[self.col_ptr[j]]).collect()
    }
}

/// The group of every item when group g holds the items `bounds[g]..bounds[g + 1]` (runs of
/// consecutive items: the unknowns of a node, the columns of a supernode).
pub(crate) fn group_of(bounds: &[usize]) -> Vec<u32> {
    let mut group = vec![0u32; *bounds.last().unwrap_or(&0)];
    for g in 0..bounds.len().saturating_sub(1) {
        group[bounds[g]..bounds[g + 1]].fill(g as u32);
    }
    group
}

/// `emit(chunk, sink)` of [`group_by_target`]: calls `sink(target, item)` for every item of the chunk.
pub(crate) type Emit<'a, T> = dyn Fn(usize, &mut dyn FnMut(usize, T)) + Sync + 'a;

/// A counting sort on every core, deterministic: `emit(chunk, sink)` calls `sink(target, item)`
/// for the items of chunk `chunk` (of `0..chunks`), the same ones in the same order each time
/// (it is called twice: to count, then to place). Returns the items grouped by target
/// (`0..targets`) as offsets and items, within a target in chunk order and then in the order
/// emitted: the array one sequential pass over the chunks would give, whatever the number of
/// threads. `chunks` should be a constant (the work then does not depend on the number of
/// threads) with enough chunks for every core.
pub(crate) fn group_by_target<T: Copy + Default + Send + Sync>(targets: usize, chunks: usize, emit: &Emit<T>) -> (Vec<usize>, Vec<T>) {
    let mut counts: Vec<Vec<u32>> = (0..chunks)
        .into_par_iter()
        .map(|b| {
            let mut count = vec![0u32; targets];
            emit(b, &mut |t, _| count[t] += 1);
            count
        })
        .collect();
    // target t starts at ptr[t]; chunk b's items of it after those of the chunks before
    let mut ptr = vec![0usize; targets + 1];
    for t in 0..targets {
        let mut at = ptr[t];
        for count in counts.iter_mut() {
            let k = count[t] as usize;
            count[t] = u32::try_from(at).expect("more than 2^32 items: widen group_by_target's counts");
            at += k;
        }
        ptr[t + 1] = at;
    }
    let mut items = vec![T::default(); ptr[targets]];
    let out = Shared::new(&mut items);
    counts.into_par_iter().enumerate().for_each(|(b, mut next)| {
        emit(b, &mut |t, item| {
            // SAFETY: each slot belongs to one chunk (the offsets above) and is written once
            unsafe { out.slice(next[t] as usize, 1)[0] = item };
            next[t] += 1;
        });
    });
    (ptr, items)
}

/// Runs `fill(item, scratch, slice)` for every item of a compressed layout (`offsets`, one slice
/// of `buf` per item), in parallel over blocks of items, and returns what each call returns, in
/// item order. Every block makes its own `scratch` with `init`. The slices are disjoint, so any
/// thread count writes the same values.
pub(crate) fn par_fill<T: Send, S, R: Send>(
    buf: &mut [T],
    offsets: &[usize],
    init: impl Fn() -> S + Sync,
    fill: impl Fn(usize, &mut S, &mut [T]) -> R + Sync,
) -> Vec<R> {
    const BLOCK: usize = 4096;
    let n = offsets.len() - 1;
    let mut blocks = Vec::with_capacity(n.div_ceil(BLOCK));
    let mut rest = buf;
    for start in (0..n).step_by(BLOCK) {
        let end = (start + BLOCK).min(n);
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(offsets[end] - offsets[start]);
        blocks.push((start, end, head));
        rest = tail;
    }
    let results: Vec<Vec<R>> = blocks
        .into_par_iter()
        .map(|(start, end, mut block)| {
            let mut scratch = init();
            let mut out = Vec::with_capacity(end - start);
            for item in start..end {
                let (head, tail) = std::mem::take(&mut block).split_at_mut(offsets[item + 1] - offsets[item]);
                out.push(fill(item, &mut scratch, head));
                block = tail;
            }
            out
        })
        .collect();
    results.into_iter().flatten().collect()
}

/// Prefix sums of counts: the offsets of a compressed layout.
pub(crate) fn offsets(counts: impl Iterator<Item = usize>) -> Vec<usize> {
    let mut ptr = vec![0];
    for c in counts {
        ptr.push(ptr.last().unwrap() + c);
    }
    ptr
}

/// L's values (or a solution vector), shared by the threads: each supernode's block (its
/// columns of L, its rows of the vector) is written by the one task that computes it and read
/// by others only after that task has finished (the schedules `Plan::upward` and
/// `Plan::downward` of the factorisation order them), so no value is ever accessed concurrently with a write.
#[derive(Clone, Copy)]
pub(crate) struct Shared<T = f64> {
    ptr: *mut T,
    len: usize,
}

// SAFETY: see the type's documentation; the schedule keeps accesses disjoint or ordered
unsafe impl<T: Send> Send for Shared<T> {}
unsafe impl<T: Send> Sync for Shared<T> {}

impl<T> Shared<T> {
    pub(crate) fn new(values: &mut [T]) -> Self {
        Shared { ptr: values.as_mut_ptr(), len: values.len() }
    }

    /// `len` values from `begin`.
    /// # Safety
    /// No other live reference to them may be used while the slice is (see [`Shared`]).
    #[allow(clippy::mut_from_ref)]
    pub(crate) unsafe fn slice(&self, begin: usize, len: usize) -> &mut [T] {
        assert!(begin + len <= self.len);
        // SAFETY: inside the allocation (checked); exclusivity is the caller's
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(begin), len) }
    }
}
