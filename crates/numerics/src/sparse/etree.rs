//! The elimination tree of a graph and the column counts of its Cholesky factor, on the graph
//! of the mesh nodes: what the symbolic factorisation builds on and what an ordering's cost
//! (its multiply-adds) is counted with.

/// No parent: the root of a tree.
pub(crate) const NONE: u32 = u32::MAX;

/// The elimination tree of a graph in its numbering and the column counts of L, per node:
/// `parent[p]` ([`NONE`] at a root), and strictly below node p's columns the number of later
/// nodes (`below_n`) and their total weight (`below_w`) in the structure of column p.
pub(crate) struct Counts {
    pub parent: Vec<u32>,
    pub below_w: Vec<usize>,
    pub below_n: Vec<u32>,
    /// `below_w` counting only the nodes before `lead`.
    pub below_lead: Vec<usize>,
}

impl Counts {
    /// Flops of the factorisation of the leading block (the nodes before `lead`, which are the
    /// leading block of L too): with d_j the entries of column j of L below the diagonal,
    /// sum d_j + d_j (d_j + 1) / 2 (divisions and multiply-subtract pairs, as AMD counts them);
    /// the w unknowns of node p have d = W + w - 1, ..., W with W = `below_lead[p]`.
    pub fn flops(&self, lead: usize, weight: &dyn Fn(usize) -> usize) -> f64 {
        (0..lead)
            .map(|p| (0..weight(p) as u64).map(|t| self.below_lead[p] as u64 + t).map(|d| d as f64 + (d * (d + 1) / 2) as f64).sum::<f64>())
            .sum()
    }
}

/// `neighbours(p, f)` calls f for every neighbour of node p.
pub(crate) type Neighbours<'a> = dyn Fn(usize, &mut dyn FnMut(u32)) + Sync + 'a;

/// A graph in the numbering of an ordering, compressed by rows: the neighbours of node p are
/// `adj[ptr[p]..ptr[p + 1]]`. Gathered once (in parallel), it turns the sequential passes over
/// the nodes in the new order (elimination tree, column counts, row patterns) into reads of
/// neighbouring memory.
pub(crate) struct Adjacency {
    ptr: Vec<usize>,
    adj: Vec<u32>,
}

impl Adjacency {
    /// Node p has `degree(p)` neighbours, which `neighbours(p, f)` hands to f one by one.
    pub(crate) fn gather(nodes: usize, degree: &(dyn Fn(usize) -> usize + Sync), neighbours: &Neighbours) -> Self {
        let mut ptr = vec![0usize; nodes + 1];
        for p in 0..nodes {
            ptr[p + 1] = ptr[p] + degree(p);
        }
        let mut adj = vec![0u32; ptr[nodes]];
        crate::sparse::csc::par_fill(
            &mut adj,
            &ptr,
            || (),
            |p, _, row| {
                let mut k = 0;
                neighbours(p, &mut |q| {
                    row[k] = q;
                    k += 1;
                });
                assert_eq!(k, row.len(), "node {p}: as many neighbours as its degree");
            },
        );
        Adjacency { ptr, adj }
    }

    fn nodes(&self) -> usize {
        self.ptr.len() - 1
    }

    pub(crate) fn row(&self, p: usize) -> &[u32] {
        &self.adj[self.ptr[p]..self.ptr[p + 1]]
    }
}

/// [`Counts`] for the graph `adjacency` with the given `weight`s (`below_lead` counting the
/// nodes before `lead`), in O(|edges| alpha) (Gilbert, Ng and Peyton's skeleton
/// algorithm, as in Davis' `cs_etree`, `cs_post`, `cs_counts`): row q of L has an entry in column
/// p exactly when p lies in the row subtree of q (the union of the tree paths from q's earlier
/// neighbours up to q); each row subtree adds its weight at its leaves and takes it off again at
/// the least common ancestor of consecutive leaves (in postorder) and above its root, and a
/// column's count is the sum over its subtree.
pub(crate) fn tree_and_counts(adjacency: &Adjacency, lead: usize, weight: &dyn Fn(usize) -> usize) -> Counts {
    let nodes = adjacency.nodes();
    assert!(nodes < NONE as usize);
    // elimination tree, with path compression through `ancestor`
    let (mut parent, mut ancestor) = (vec![NONE; nodes], vec![NONE; nodes]);
    for k in 0..nodes {
        for &i in adjacency.row(k) {
            let mut i = i as usize;
            while i < k {
                let next = ancestor[i];
                ancestor[i] = k as u32;
                if next == NONE {
                    parent[i] = k as u32;
                    break;
                }
                i = next as usize;
            }
        }
    }
    // postorder: children in ascending order, roots in ascending order
    let (mut head, mut next) = (vec![NONE; nodes], vec![NONE; nodes]);
    for j in (0..nodes).rev() {
        if parent[j] != NONE {
            next[j] = head[parent[j] as usize];
            head[parent[j] as usize] = j as u32;
        }
    }
    let mut post = Vec::with_capacity(nodes);
    let mut stack = Vec::new();
    for root in (0..nodes).filter(|&j| parent[j] == NONE) {
        stack.push(root as u32);
        while let Some(&p) = stack.last() {
            let child = head[p as usize];
            if child == NONE {
                stack.pop();
                post.push(p);
            } else {
                head[p as usize] = next[child as usize];
                stack.push(child);
            }
        }
    }
    // first[j]: the first postorder position in j's subtree; a leaf of the tree is the only leaf
    // of its own row subtree
    let mut first = vec![NONE; nodes];
    let (mut delta_w, mut delta_n, mut delta_l) = (vec![0i64; nodes], vec![0i64; nodes], vec![0i64; nodes]);
    let weight_lead = |p: usize| if p < lead { weight(p) as i64 } else { 0 };
    for (k, &j) in post.iter().enumerate() {
        let mut j = j as usize;
        if first[j] == NONE {
            delta_w[j] = weight(j) as i64;
            delta_n[j] = 1;
            delta_l[j] = weight_lead(j);
        }
        while j != NONE as usize && first[j] == NONE {
            first[j] = k as u32;
            j = if parent[j] == NONE { NONE as usize } else { parent[j] as usize };
        }
    }
    // `max_first[i]`: 1 + the largest `first` among the leaves of row subtree i seen so far
    let (mut max_first, mut prev_leaf) = (vec![0u32; nodes], vec![NONE; nodes]);
    for (i, a) in ancestor.iter_mut().enumerate() {
        *a = i as u32;
    }
    for &j in &post {
        let j = j as usize;
        if parent[j] != NONE {
            delta_w[parent[j] as usize] -= weight(j) as i64;
            delta_n[parent[j] as usize] -= 1;
            delta_l[parent[j] as usize] -= weight_lead(j);
        }
        for &i in adjacency.row(j) {
            let i = i as usize;
            // is j a new leaf of row subtree i (j not below an earlier leaf)?
            if i <= j || first[j] < max_first[i] {
                continue;
            }
            max_first[i] = first[j] + 1;
            let (wi, li) = (weight(i) as i64, weight_lead(i));
            delta_w[j] += wi;
            delta_n[j] += 1;
            delta_l[j] += li;
            let prev = std::mem::replace(&mut prev_leaf[i], j as u32);
            if prev != NONE {
                // the least common ancestor of the previous leaf and j, compressing the path
                let mut q = prev as usize;
                while ancestor[q] as usize != q {
                    q = ancestor[q] as usize;
                }
                let mut s = prev as usize;
                while s != q {
                    let up = ancestor[s] as usize;
                    ancestor[s] = q as u32;
                    s = up;
                }
                delta_w[q] -= wi;
                delta_n[q] -= 1;
                delta_l[q] -= li;
            }
        }
        if parent[j] != NONE {
            ancestor[j] = parent[j];
        }
    }
    for j in 0..nodes {
        if parent[j] != NONE {
            let p = parent[j] as usize;
            delta_w[p] += delta_w[j];
            delta_n[p] += delta_n[j];
            delta_l[p] += delta_l[j];
        }
    }
    let below_w = (0..nodes).map(|j| (delta_w[j] - weight(j) as i64) as usize).collect();
    let below_n = delta_n.iter().map(|&c| (c - 1) as u32).collect();
    let below_lead = (0..nodes).map(|j| (delta_l[j] - weight_lead(j)) as usize).collect();
    Counts { parent, below_w, below_n, below_lead }
}
