//! The settings of the primal-dual active set method and how its linear algebra is done.

/// Settings of the active-set method.
#[derive(Clone, Debug)]
pub struct PdasOptions {
    pub max_iterations: usize,
    /// Relative tolerance on the complementarity (NCP) residual.
    pub tolerance: f64,
    /// The complementarity constant is c = c_scale * mean(diag S), scaled to the problem.
    pub c_scale: f64,
    /// Warm start: the initial active set, one flag per contact node.
    pub initial_active: Option<Vec<bool>>,
    /// How the linear algebra is done; None chooses by the number of contact nodes.
    pub strategy: Option<Strategy>,
}

impl Default for PdasOptions {
    fn default() -> Self {
        PdasOptions { max_iterations: 50, tolerance: 1e-9, c_scale: 1.0, initial_active: None, strategy: None }
    }
}

/// How the complementarity problem is solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Strategy {
    /// One factorisation with the contact normals last; active-set iterations on the dense Schur
    /// complement.
    Schur,
    /// Constraints by values on the fixed pattern; one numeric refactorisation per iteration.
    Refactor,
}

/// Up to this many contact nodes the dense Schur complement (O(m^3)) is always cheaper than a
/// few sparse refactorisations.
pub const SCHUR_MAX_CONTACT: usize = 1500;

impl Strategy {
    /// Schur for at most [`SCHUR_MAX_CONTACT`] contact nodes, and beyond while the dense work on
    /// the Schur complement, m^3 for m contact nodes, stays below n^1.5 for n unknowns (the order
    /// of the flops of one sparse factorisation of a 2D mesh, about 27 n^1.5 with nested
    /// dissection on `structured:N`), which Refactor pays once per active-set iteration. On the
    /// meshes graded towards Gamma_C (thousands of contact nodes among a few 100k unknowns) m^3
    /// exceeds n^1.5 a thousandfold: Refactor; on `structured:1024` (2049 contact nodes, 8.4M
    /// unknowns) m^3 is a third of n^1.5: Schur, one factorisation instead of ten.
    pub fn auto(n_contact: usize, n_unknowns: usize) -> Self {
        let (m, n) = (n_contact as f64, n_unknowns as f64);
        if n_contact <= SCHUR_MAX_CONTACT || m.powi(3) <= n.powf(1.5) { Strategy::Schur } else { Strategy::Refactor }
    }
}
