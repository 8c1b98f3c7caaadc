//! METIS's nested dissection (`METIS_NodeND`, default options) of the node graph: the anchor
//! of the orderings' quality in the graded section. Built with the feature `bench-metis`
//! (metis-sys's vendored METIS 5); without it there is no METIS row.

use signorini::sparse::anatomy::NodeGraph;

/// METIS's order of the nodes (`order[new] = old`), None without the feature or if METIS fails.
#[cfg(feature = "bench-metis")]
pub fn node_nd(graph: &NodeGraph) -> Option<Vec<usize>> {
    use metis_sys::{
        METIS_NOPTIONS, METIS_NodeND, METIS_SetDefaultOptions, idx_t, moptions_et_METIS_OPTION_NUMBERING, rstatus_et_METIS_OK,
    };
    let (ptr, adj) = graph.csr();
    let mut xadj: Vec<idx_t> = ptr.iter().map(|&p| idx_t::try_from(p).ok()).collect::<Option<_>>()?;
    let mut adjncy: Vec<idx_t> = adj.iter().map(|&q| idx_t::try_from(q).ok()).collect::<Option<_>>()?;
    let mut n = idx_t::try_from(graph.n_nodes()).ok()?;
    let (mut perm, mut iperm) = (vec![0 as idx_t; graph.n_nodes()], vec![0 as idx_t; graph.n_nodes()]);
    let mut options = [0 as idx_t; METIS_NOPTIONS as usize];
    // SAFETY: the arrays are as long as METIS reads and writes (n + 1 pointers, their entries,
    // n of each permutation, METIS_NOPTIONS options), and live across the calls
    let status = unsafe {
        METIS_SetDefaultOptions(options.as_mut_ptr());
        options[moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
        METIS_NodeND(
            &mut n,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            options.as_mut_ptr(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    // METIS's `perm` is the order (row i of the permuted matrix is row perm[i]), as CHOLMOD reads it
    (status == rstatus_et_METIS_OK).then(|| perm.into_iter().map(|p| p as usize).collect())
}

#[cfg(not(feature = "bench-metis"))]
pub fn node_nd(_graph: &NodeGraph) -> Option<Vec<usize>> {
    None
}
