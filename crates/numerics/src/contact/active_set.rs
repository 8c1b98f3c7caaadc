//! The discrete Signorini problem (paper eq. 3.4) by a primal–dual active set method
//! (Hüeber, Mair, Wohlmuth 2005) on the Schur complement of the contact normal unknowns.
//!
//! With the unknowns split into `I` (everything but the contact normals) and `C` (the normal
//! unknown of every contact node, ordered last), the stiffness K = L L^T is factorised once with
//! a fill-reducing ordering of `I` followed by `C`. The trailing block of L gives the Schur
//! complement S = K_CC - K_CI K_II^{-1} K_IC = L_CC L_CC^T, a small dense matrix. With
//! y = K^{-1} F, the displacement of the contact normals is u_C = y_C - S^{-1} lambda, so the
//! discrete problem becomes the linear complementarity problem
//!
//! ```text
//!   lambda = S (y_C - u_C),   u_C <= chi_h,   lambda >= 0,   lambda . (chi_h - u_C) = 0,
//! ```
//!
//! where lambda_p = L(phi_p n) - a(u_h, phi_p n) is the discrete nodal contact force
//! (eq. 4.5, Lemma 5.2). Each active-set iteration is a dense solve on the inactive nodes;
//! one more sparse solve recovers the whole displacement. The sparse matrix is factorised once
//! per mesh, whatever the number of iterations ([`Strategy::Schur`]). Since F - E lambda differs
//! from F only in the trailing block, the forward substitution of F is computed once and kept:
//! y_C needs only the trailing block's backward substitution, and u only the trailing block's
//! forward substitution again before the whole backward one, bit for bit the full solves
//! ([`cholesky::forward_tail`], [`cholesky::backward_tail`]); the round-off measurement's two
//! solves ([`ContactSolver::correction`]) share one forward substitution the same way.
//!
//! The dense trailing block costs O(m^3): when adaptivity puts thousands of nodes on Gamma_C
//! (Example 7.1 refines along it) the solver switches to [`Strategy::Refactor`]: the
//! constraints of the active nodes are imposed by values on the fixed sparsity pattern (row and
//! column of an active normal unknown replaced by its diagonal entry, explicit zeros kept), so
//! the symbolic factorisation is computed once and every iteration is one numeric
//! refactorisation. Both strategies share one active-set driver ([`pdas`]).
//!
//! The solver takes the matrix. The Schur strategy needs neither the matrix nor where its entries
//! go in L once L holds its values: both are released before the numeric factorisation, so that
//! L never shares the memory with them (at `structured:512` they take 0.6 GB, L 2.2 GB). The
//! Refactor strategy keeps the matrix (it imposes each iteration's constraints on its values
//! while loading them, without a copy) and computes where its entries go again for each load,
//! released before the factorisation as well.
//! The method: `docs/method.md`, section "SOLVE: the primal–dual active set method".

use crate::sparse::cholesky;
use crate::sparse::csc::SymCsc;
use crate::sparse::ordering::OrderingChoice;
use crate::sparse::symbolic::{self, Placement, Symbolic};
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use model::settings::pdas::{PdasOptions, Strategy};
use std::time::Instant;

/// Why the contact solve failed.
#[derive(Debug, thiserror::Error)]
pub enum ContactError {
    #[error(
        "the primal-dual active set method did not converge in {iterations} iterations (NCP residual {residual:.3e}, tolerance {tolerance:.1e}, {active} active nodes)"
    )]
    NotConverged { iterations: usize, residual: f64, tolerance: f64, active: usize },
    #[error(
        "the primal-dual active set method is cycling: the active set of iteration {iterations} was already seen at iteration {first_seen} (NCP residual {residual:.3e})"
    )]
    Cycling { iterations: usize, first_seen: usize, residual: f64 },
    #[error("the stiffness matrix is not positive definite: {0}")]
    NotPositiveDefinite(String),
    #[error("sparse factorisation failed: {0}")]
    Factorisation(String),
    /// A buffer of the factorisation could not be allocated ([`cholesky::OutOfMemory`]).
    #[error("{0} (lower the mesh size or raise the memory limit)")]
    OutOfMemory(String),
}

/// One active-set iteration, as logged.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PdasIteration {
    pub iteration: usize,
    pub active: usize,
    pub added: usize,
    pub removed: usize,
    /// max_p |min(lambda_p, c (chi_h(p) - u_p.n))|, relative to c times the displacement scale.
    pub residual: f64,
    pub seconds: f64,
}

/// Why the iteration stopped. Only `Converged` and `NoContact` are solutions of the discrete
/// problem; [`PdasTermination::error`] turns the other two into the [`ContactError`] that
/// [`crate::contact::solve::solve`] reports.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum PdasTermination {
    /// The active set repeated and the residual was below tolerance.
    Converged,
    /// No contact nodes: a single linear solve.
    NoContact,
    /// `max_iterations` iterations without convergence: `residual` is the last iteration's NCP
    /// residual, `next_active` the size of the active set the next iteration would have used.
    MaxIterations { residual: f64, tolerance: f64, next_active: usize },
    /// The next active set was already seen at iteration `first_seen` (other than the previous one).
    Cycling { first_seen: usize, residual: f64 },
}

impl PdasTermination {
    /// Whether the iterate solves the discrete problem.
    pub fn is_converged(&self) -> bool {
        matches!(self, PdasTermination::Converged | PdasTermination::NoContact)
    }

    /// The error for a run that stopped without converging after `iterations` iterations; None
    /// if it converged.
    pub fn error(&self, iterations: usize) -> Option<ContactError> {
        match *self {
            PdasTermination::Converged | PdasTermination::NoContact => None,
            PdasTermination::MaxIterations { residual, tolerance, next_active } => {
                Some(ContactError::NotConverged { iterations, residual, tolerance, active: next_active })
            }
            PdasTermination::Cycling { first_seen, residual } => Some(ContactError::Cycling { iterations, first_seen, residual }),
        }
    }
}

/// Wall-clock seconds per phase.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Timings {
    pub symbolic: f64,
    /// numeric factorisations (all of them: one for Schur, one per iteration for Refactor)
    pub numeric: f64,
    pub schur: f64,
    pub solves: f64,
    pub active_set: f64,
}

/// The result of a contact solve, on the unknowns of the assembled system: the solution if
/// `termination` is converged, otherwise the last iterate ([`PdasOutput::converged`] makes that
/// an error).
#[derive(Clone, Debug)]
pub struct PdasOutput {
    /// All unknowns (local frames at contact nodes).
    pub u: Vec<f64>,
    /// Nodal contact force lambda_p per contact node (from the complementarity system).
    pub lambda: Vec<f64>,
    pub active: Vec<bool>,
    pub iterations: Vec<PdasIteration>,
    pub termination: PdasTermination,
    pub c: f64,
}

impl PdasOutput {
    /// The output if the iteration converged, otherwise the error naming the iterations and the
    /// residual.
    pub fn converged(self) -> Result<Self, ContactError> {
        match self.termination.error(self.iterations.len()) {
            Some(e) => Err(e),
            None => Ok(self),
        }
    }
}

/// The factorised stiffness, with its contact Schur complement ([`Strategy::Schur`]) or the
/// bookkeeping to impose constraints by values ([`Strategy::Refactor`]). Owns the ordering and
/// the factorisation: symbolic once per mesh, numeric once per matrix (Schur) or per iteration
/// (Refactor).
pub struct ContactSolver {
    n: usize,
    n_interior: usize,
    strategy: Strategy,
    symbolic: Symbolic,
    /// Where the matrix's entries go in L, from the symbolic analysis until the first load;
    /// released once L holds the values and computed again for the next load
    /// ([`ContactSolver::placement`]).
    placement: Option<Placement>,
    /// The matrix, kept by the Refactor strategy (it imposes the constraints on its values in
    /// every iteration).
    matrix: Option<SymCsc>,
    /// The schedule of the numeric factorisation.
    plan: cholesky::Plan,
    /// The values of L, allocated once per symbolic factorisation ...
    l_values: Vec<f64>,
    /// ... and zero until the first factorisation.
    l_zeroed: bool,
    /// The active set imposed on the matrix L is the factor of (all false: the stiffness K
    /// itself; None: no factor yet). [`Self::refactor`] factorises K; the Refactor strategy's
    /// `new` does not, and factorises only where a factor is used ([`Self::impose`]).
    factor_of: Option<Vec<bool>>,
    /// S = L_CC L_CC^T (m x m), Schur strategy only.
    schur: Mat<f64>,
    /// Refactor strategy: per contact node, the (column, position) of the off-diagonal entries
    /// of its normal unknown's row that lie in earlier columns.
    row_entries: Vec<Vec<(usize, usize)>>,
    /// The fill-reducing ordering that was kept (of `I` for Schur, of all unknowns for Refactor).
    pub ordering: OrderingChoice,
    pub timings: Timings,
}

impl ContactSolver {
    /// Order, factorise and prepare the contact unknowns `n_interior..n` of `matrix`, with the
    /// strategy chosen by the number of contact nodes.
    /// `coords` holds the position of every unknown (its node's), for the ordering.
    pub fn new(matrix: SymCsc, n_interior: usize, coords: &[[f64; 2]]) -> Result<Self, ContactError> {
        let strategy = Strategy::auto(matrix.n() - n_interior, matrix.n());
        Self::with_strategy(matrix, n_interior, coords, strategy)
    }

    pub fn with_strategy(matrix: SymCsc, n_interior: usize, coords: &[[f64; 2]], strategy: Strategy) -> Result<Self, ContactError> {
        let mut timings = Timings::default();
        let t0 = Instant::now();
        // Schur: the leading block `I` is ordered and `C` kept in place at the end, so that the
        // trailing block of L is L_CC; Refactor: all unknowns are ordered
        let n_order = if strategy == Strategy::Schur { n_interior } else { matrix.n() };
        let (symbolic, placement, ordering) = symbolic::analyse(&matrix, n_order, coords);
        let row_entries = match strategy {
            Strategy::Schur => Vec::new(),
            Strategy::Refactor => {
                let mut rows = vec![Vec::new(); matrix.n() - n_interior];
                for j in 0..matrix.n() {
                    for k in matrix.col_ptr()[j]..matrix.col_ptr()[j + 1] {
                        let i = matrix.row_idx()[k];
                        if i >= n_interior && i != j {
                            rows[i - n_interior].push((j, k));
                        }
                    }
                }
                rows
            }
        };
        let plan = cholesky::Plan::new(&symbolic);
        timings.symbolic = t0.elapsed().as_secs_f64();
        let mut solver = ContactSolver {
            n: matrix.n(),
            n_interior,
            strategy,
            // not touched here: loading the values writes every one
            l_values: cholesky::zeros(symbolic.len_val(), "the Cholesky factor L").map_err(|e| ContactError::OutOfMemory(e.to_string()))?,
            l_zeroed: true,
            factor_of: None,
            symbolic,
            placement: Some(placement),
            matrix: None,
            plan,
            schur: Mat::zeros(0, 0),
            row_entries,
            ordering,
            timings,
        };
        match strategy {
            Strategy::Schur => solver.refactor(matrix)?,
            // K's own factor is used only where the active-set iteration starts from the
            // unconstrained solution or takes no step ([`Self::factor_k`]): a level warm-started
            // from the previous level's active set factorises only matrices with it imposed
            // (factorising K on every level, unused, would cost fb a third of its numeric time at
            // 2e6 unknowns). The same factors are computed where used.
            Strategy::Refactor => solver.matrix = Some(matrix),
        }
        Ok(solver)
    }

    /// Make L the factor of K (`matrix`, the Refactor strategy's), unless it is: what the
    /// unconstrained solution needs.
    fn factor_k(&mut self, matrix: &SymCsc) -> Result<(), ContactError> {
        self.impose(matrix, &vec![false; self.n_contact()])
    }

    /// Make L the factor of `matrix` (the Refactor strategy's K) with the constraints of the
    /// contact nodes in `active` imposed by values on its pattern: the row and column of an
    /// active normal unknown are zero but for the diagonal (explicit zeros kept). If L holds the
    /// factor for another active set, only the supernodes that the changed nodes' rows and
    /// columns reach are computed again ([`cholesky::refactorize`], bit for bit a whole
    /// factorisation): an active-set step that moves a few nodes refactorises the paths from them
    /// to the root of the elimination tree, not the whole tree.
    fn impose(&mut self, matrix: &SymCsc, active: &[bool]) -> Result<(), ContactError> {
        if self.factor_of.as_deref() == Some(active) {
            return Ok(());
        }
        let placement = self.placement(matrix);
        let (ni, m) = (self.n_interior, self.n_contact());
        let inv = self.symbolic.inv();
        let mut fixed = vec![false; self.n];
        for k in (0..m).filter(|&k| active[k]) {
            fixed[inv[ni + k]] = true;
        }
        let (values, fixed) = (matrix.values(), Some(&fixed[..]));
        // numeric time: the load here, the factorisation in `factorize` (which times itself)
        let t0 = Instant::now();
        match self.factor_of.take() {
            None => {
                cholesky::load(&self.symbolic, &placement, values, fixed, &mut self.l_values, self.l_zeroed);
                self.l_zeroed = false;
                drop(placement);
                self.timings.numeric += t0.elapsed().as_secs_f64();
                self.factorize()?;
            }
            Some(before) => {
                // an entry (i, j) of the permuted matrix lies in column min(i, j) of L
                let columns = (0..m)
                    .filter(|&k| before[k] != active[k])
                    .flat_map(|k| self.normal_entries(matrix, k).map(move |(other, _)| inv[other].min(inv[ni + k])));
                let which = self.plan.changed(&self.symbolic, columns);
                cholesky::load_changed(&self.symbolic, &placement, values, fixed, &mut self.l_values, &which);
                drop(placement);
                let refactorized = cholesky::refactorize(&self.symbolic, &self.plan, &mut self.l_values, &which);
                self.timings.numeric += t0.elapsed().as_secs_f64();
                refactorized.map_err(factor_error)?;
            }
        }
        self.factor_of = Some(active.to_vec());
        Ok(())
    }

    pub fn strategy(&self) -> Strategy {
        self.strategy
    }

    /// The off-diagonal entries of contact node k's normal unknown in `matrix` (the Refactor
    /// strategy's): its column below the diagonal, then its row left of it, each as (the other
    /// unknown, position in the matrix's values).
    fn normal_entries<'a>(&'a self, matrix: &'a SymCsc, k: usize) -> impl Iterator<Item = (usize, usize)> + 'a {
        let (col, col_ptr, row_idx) = (self.n_interior + k, matrix.col_ptr(), matrix.row_idx());
        (col_ptr[col] + 1..col_ptr[col + 1]).map(move |pos| (row_idx[pos], pos)).chain(self.row_entries[k].iter().copied())
    }

    /// Where the entries of `matrix` go in L: the placement the symbolic analysis computed, taken,
    /// or computed again (counted as symbolic time). Released once L holds the values, before the
    /// numeric factorisation (see the module docs).
    fn placement(&mut self, matrix: &SymCsc) -> Placement {
        self.placement.take().unwrap_or_else(|| {
            let t0 = Instant::now();
            let placement = Placement::new(matrix, self.symbolic.inv());
            self.timings.symbolic += t0.elapsed().as_secs_f64();
            placement
        })
    }

    /// Numeric factorisation of a matrix with the same pattern (and, for the Schur strategy, its
    /// Schur complement). The Schur strategy releases the matrix before factorising (see the
    /// module docs); the Refactor strategy keeps it.
    pub fn refactor(&mut self, matrix: SymCsc) -> Result<(), ContactError> {
        self.timings.numeric = 0.0;
        let placement = self.placement(&matrix);
        let t0 = Instant::now();
        cholesky::load(&self.symbolic, &placement, matrix.values(), None, &mut self.l_values, self.l_zeroed);
        self.l_zeroed = false;
        self.timings.numeric += t0.elapsed().as_secs_f64();
        drop(placement);
        match self.strategy {
            Strategy::Refactor => self.matrix = Some(matrix),
            Strategy::Schur => drop(matrix),
        }
        self.factorize()?;
        self.factor_of = Some(vec![false; self.n_contact()]);
        if self.strategy == Strategy::Schur {
            let t0 = Instant::now();
            let lcc = self.trailing_factor_block()?;
            self.schur = &lcc * lcc.transpose();
            self.timings.schur = t0.elapsed().as_secs_f64();
        }
        Ok(())
    }

    /// Numeric factorisation of the loaded values in place ([`cholesky::factorize`]).
    fn factorize(&mut self) -> Result<(), ContactError> {
        let t0 = Instant::now();
        cholesky::factorize(&self.symbolic, &self.plan, &mut self.l_values).map_err(factor_error)?;
        self.timings.numeric += t0.elapsed().as_secs_f64();
        Ok(())
    }

    pub fn n_contact(&self) -> usize {
        self.n - self.n_interior
    }

    /// The Schur complement S of the contact normal unknowns (Schur strategy).
    pub fn schur(&self) -> &Mat<f64> {
        &self.schur
    }

    /// L_CC: the trailing m x m block of the Cholesky factor (rows and columns of `C`, which the
    /// ordering leaves in place at the end).
    fn trailing_factor_block(&self) -> Result<Mat<f64>, ContactError> {
        let (n, ni) = (self.n, self.n_interior);
        let m = n - ni;
        let mut lcc = Mat::<f64>::zeros(m, m);
        let sn = &self.symbolic;
        let (begin, val_ptr) = (sn.supernode_begin(), sn.val_ptr());
        for s in 0..sn.n_supernodes() {
            let (start, ncols, pattern) = (begin[s], begin[s + 1] - begin[s], sn.pattern(s));
            let nrows = ncols + pattern.len();
            let val = faer::MatRef::from_column_major_slice(&self.l_values[val_ptr[s]..val_ptr[s + 1]], nrows, ncols);
            for jc in 0..ncols {
                let j = start + jc;
                if j < ni {
                    continue;
                }
                for rc in jc..ncols {
                    lcc[(start + rc - ni, j - ni)] = val[(rc, jc)];
                }
                for (k, &row) in pattern.iter().enumerate() {
                    lcc[(row as usize - ni, j - ni)] = val[(ncols + k, jc)];
                }
            }
        }
        Ok(lcc)
    }

    /// Solve with the current factorisation ([`cholesky::solve_in_place`]).
    pub fn solve(&mut self, b: &[f64]) -> Vec<f64> {
        let t0 = Instant::now();
        let mut x = self.permuted(b);
        cholesky::solve_in_place(&self.symbolic, &self.plan, &self.l_values, &mut x);
        let u = self.unpermuted(&x);
        self.timings.solves += t0.elapsed().as_secs_f64();
        u
    }

    /// b in the numbering of L (row `inv[i]` holds unknown i).
    fn permuted(&self, b: &[f64]) -> Vec<f64> {
        let mut x = vec![0.0; self.n];
        for (&k, &v) in self.symbolic.inv().iter().zip(b) {
            x[k] = v;
        }
        x
    }

    /// x from the numbering of L back to the unknowns'.
    fn unpermuted(&self, x: &[f64]) -> Vec<f64> {
        self.symbolic.inv().iter().map(|&k| x[k]).collect()
    }

    /// The forward substitution z = L^{-1} P b (permuted numbering): the first half of
    /// [`Self::solve`], kept to finish solves whose right-hand sides differ from b only at the
    /// contact normals ([`Self::contact_rows`], [`Self::solve_from`]).
    fn forward(&mut self, b: &[f64]) -> Vec<f64> {
        let t0 = Instant::now();
        let mut z = self.permuted(b);
        cholesky::forward_in_place(&self.symbolic, &self.plan, &self.l_values, &mut z);
        self.timings.solves += t0.elapsed().as_secs_f64();
        z
    }

    /// (K^{-1} b)_C, the contact normals' rows of the solution, from the forward substitution z
    /// of b: the backward substitution of the trailing block only (Schur strategy, where C keeps
    /// its place at the end). Bit for bit the rows of [`Self::solve`]`(b)`.
    fn contact_rows(&mut self, z: &[f64]) -> Vec<f64> {
        debug_assert_eq!(self.strategy, Strategy::Schur);
        let t0 = Instant::now();
        let ni = self.n_interior;
        let mut x = z.to_vec();
        cholesky::backward_tail(&self.symbolic, &self.plan, &self.l_values, &mut x, ni);
        self.timings.solves += t0.elapsed().as_secs_f64();
        x.split_off(ni)
    }

    /// K^{-1} b for a b that differs only at the contact normals from the right-hand side whose
    /// forward substitution is z (Schur strategy): the forward substitution of the trailing
    /// block again, then the backward one. Bit for bit [`Self::solve`]`(b)`, for a forward
    /// substitution of the trailing block's share of L instead of all of it.
    fn solve_from(&mut self, z: Vec<f64>, b: &[f64]) -> Vec<f64> {
        debug_assert_eq!(self.strategy, Strategy::Schur);
        let t0 = Instant::now();
        let bp = self.permuted(b);
        let mut x = z;
        cholesky::forward_tail(&self.symbolic, &self.plan, &self.l_values, &mut x, &bp, self.n_interior);
        cholesky::backward_in_place(&self.symbolic, &self.plan, &self.l_values, &mut x);
        let u = self.unpermuted(&x);
        self.timings.solves += t0.elapsed().as_secs_f64();
        u
    }

    /// Solve the discrete Signorini problem K u = F - E lambda with u_C <= gap, lambda >= 0,
    /// complementarity (E places lambda on the contact normal unknowns), K the matrix the solver
    /// was last factorised with. `observe` sees every iteration as it ends. An iteration that does
    /// not converge is not an error here: the output holds the last iterate and its
    /// `termination` says why it stopped (see [`PdasOutput::converged`]).
    pub fn solve_contact(
        &mut self,
        rhs: &[f64],
        gap: &[f64],
        options: &PdasOptions,
        observe: &mut dyn FnMut(&PdasIteration),
    ) -> Result<PdasOutput, ContactError> {
        let (ni, m) = (self.n_interior, self.n_contact());
        assert_eq!(gap.len(), m);
        if m == 0 {
            if let Some(matrix) = self.matrix.take() {
                let factored = self.factor_k(&matrix);
                self.matrix = Some(matrix);
                factored?;
            }
            let u = self.solve(rhs);
            return Ok(PdasOutput {
                u,
                lambda: vec![],
                active: vec![],
                iterations: vec![],
                termination: PdasTermination::NoContact,
                c: 0.0,
            });
        }
        let t_pdas = Instant::now();
        let (solves0, numeric0) = (self.timings.solves, self.timings.numeric);
        let out = match self.strategy {
            Strategy::Schur => self.solve_schur(rhs, gap, options, observe),
            Strategy::Refactor => {
                let matrix = self.matrix.take().expect("the Refactor strategy keeps its matrix");
                let out = self.solve_refactor(&matrix, rhs, gap, options, observe);
                self.matrix = Some(matrix);
                out
            }
        };
        // the rest of the contact solve: dense active-set work (Schur) or bookkeeping (Refactor)
        let inner = (self.timings.solves - solves0) + (self.timings.numeric - numeric0);
        self.timings.active_set = t_pdas.elapsed().as_secs_f64() - inner;
        let (mut u, NormalIterate { lambda, active, iterations, termination, .. }, c) = out?;
        for k in 0..m {
            if active[k] {
                u[ni + k] = gap[k]; // the constraint holds exactly, not to solver round-off
            }
        }
        Ok(PdasOutput { u, lambda, active, iterations, termination, c })
    }

    /// One step of iterative refinement of a converged contact solution, in working precision:
    /// the correction du with du = 0 at the active contact normals and (K du)_i = r_i at every
    /// other unknown, for the residual r = F - K u (its entries at active normals, the contact
    /// forces, are ignored). Solved with the factorisation the solution was computed with:
    /// Refactor's last one imposes the active set already; Schur's (of K) gets the active set
    /// through one more Schur step with gap 0. Its size measures the round-off the computed u
    /// carries (the floor below which no error can be measured).
    pub fn correction(&mut self, residual: &[f64], active: &[bool]) -> Result<Vec<f64>, ContactError> {
        let (ni, m) = (self.n_interior, self.n_contact());
        let mut r = residual.to_vec();
        for k in (0..m).filter(|&k| active[k]) {
            r[ni + k] = 0.0;
        }
        let mut du = match self.strategy {
            Strategy::Refactor => self.solve(&r),
            Strategy::Schur => {
                let z = self.forward(&r);
                let yc = self.contact_rows(&z);
                let (_, dlambda) = schur_step(&self.schur, &yc, &vec![0.0; m], active)?;
                for k in 0..m {
                    r[ni + k] -= dlambda[k];
                }
                self.solve_from(z, &r)
            }
        };
        for k in (0..m).filter(|&k| active[k]) {
            du[ni + k] = 0.0;
        }
        Ok(du)
    }

    fn solve_schur(
        &mut self,
        rhs: &[f64],
        gap: &[f64],
        options: &PdasOptions,
        observe: &mut dyn FnMut(&PdasIteration),
    ) -> Result<PdasResult, ContactError> {
        let (ni, m) = (self.n_interior, self.n_contact());
        // y_C = (K^{-1} F)_C; the forward substitution of F is kept for u below
        let z = self.forward(rhs);
        let yc = &self.contact_rows(&z);
        let s = &self.schur;
        let c = options.c_scale * (0..m).map(|i| s[(i, i)]).sum::<f64>() / m as f64;
        let initial = options.initial_active.clone().filter(|a| a.len() == m).unwrap_or_else(|| (0..m).map(|i| yc[i] > gap[i]).collect());
        let mut step = |active: &[bool]| schur_step(s, yc, gap, active);
        let outcome = pdas(gap, c, initial, options, observe, &mut step)?;
        // u = K^{-1} (F - E lambda)
        let mut b = rhs.to_vec();
        for k in 0..m {
            b[ni + k] -= outcome.lambda[k];
        }
        let u = self.solve_from(z, &b);
        Ok((u, outcome, c))
    }

    fn solve_refactor(
        &mut self,
        matrix: &SymCsc,
        rhs: &[f64],
        gap: &[f64],
        options: &PdasOptions,
        observe: &mut dyn FnMut(&PdasIteration),
    ) -> Result<PdasResult, ContactError> {
        let (ni, m) = (self.n_interior, self.n_contact());
        let diag = |k: usize| matrix.values()[matrix.col_ptr()[ni + k]];
        let c = options.c_scale * (0..m).map(diag).sum::<f64>() / m as f64;
        let initial = match options.initial_active.clone().filter(|a| a.len() == m) {
            Some(a) => a,
            None => {
                // the unconstrained solution, with the factorisation of K
                self.factor_k(matrix)?;
                let y = self.solve(rhs);
                (0..m).map(|i| y[ni + i] > gap[i]).collect()
            }
        };
        let mut last_u = Vec::new();
        let mut step = |active: &[bool]| -> Result<(Vec<f64>, Vec<f64>), ContactError> {
            // the known values of the active normals move to the right-hand side
            let mut b = rhs.to_vec();
            for k in (0..m).filter(|&k| active[k]) {
                for (other, pos) in self.normal_entries(matrix, k) {
                    b[other] -= matrix.values()[pos] * gap[k];
                }
            }
            for k in (0..m).filter(|&k| active[k]) {
                b[ni + k] = diag(k) * gap[k];
            }
            self.impose(matrix, active)?;
            let u = self.solve(&b);
            let ku = matrix.mul(&u);
            let lambda: Vec<f64> = (0..m).map(|k| if active[k] { rhs[ni + k] - ku[ni + k] } else { 0.0 }).collect();
            let uc = u[ni..].to_vec();
            last_u = u;
            Ok((uc, lambda))
        };
        let outcome = pdas(gap, c, initial, options, observe, &mut step)?;
        if last_u.is_empty() {
            // no iteration: the unconstrained solution
            self.factor_k(matrix)?;
            last_u = self.solve(rhs);
        }
        Ok((last_u, outcome, c))
    }
}

/// The contact solver's error for a failed numeric factorisation.
fn factor_error(e: cholesky::FactorError) -> ContactError {
    match e {
        cholesky::FactorError::NotPositiveDefinite(e) => ContactError::NotPositiveDefinite(e.to_string()),
        cholesky::FactorError::OutOfMemory(e) => ContactError::OutOfMemory(e.to_string()),
    }
}

/// One active-set step on the Schur complement `s`: u_C and lambda for the active set `active`,
/// with y_C = (K^{-1} F)_C = `yc` and the gap `gap` (u = g on A, lambda = 0 off A):
/// S_II z = S_IA (y_A - g_A), u_I = y_I + z, lambda = S (y - u).
fn schur_step(s: &Mat<f64>, yc: &[f64], gap: &[f64], active: &[bool]) -> Result<Pair, ContactError> {
    let m = gap.len();
    let inact: Vec<usize> = (0..m).filter(|&i| !active[i]).collect();
    let act: Vec<usize> = (0..m).filter(|&i| active[i]).collect();
    let mut u: Vec<f64> = (0..m).map(|i| if active[i] { gap[i] } else { 0.0 }).collect();
    if !inact.is_empty() {
        let sii = Mat::<f64>::from_fn(inact.len(), inact.len(), |a, b| s[(inact[a], inact[b])]);
        let r = Mat::<f64>::from_fn(inact.len(), 1, |a, _| act.iter().map(|&j| s[(inact[a], j)] * (yc[j] - gap[j])).sum::<f64>());
        let llt = sii.llt(Side::Lower).map_err(|e| ContactError::NotPositiveDefinite(format!("Schur block: {e:?}")))?;
        let z = llt.solve(&r);
        for (a, &i) in inact.iter().enumerate() {
            u[i] = yc[i] + z[(a, 0)];
        }
    }
    // lambda = S (y - u); zero off the active set by construction
    let lambda = (0..m).map(|i| if active[i] { (0..m).map(|j| s[(i, j)] * (yc[j] - u[j])).sum() } else { 0.0 }).collect();
    Ok((u, lambda))
}

/// All unknowns, the active-set outcome and the complementarity constant c.
type PdasResult = (Vec<f64>, NormalIterate, f64);

/// The values of u and lambda at the contact normals (one active-set step's result).
pub type Pair = (Vec<f64>, Vec<f64>);

/// What [`pdas`] returns: the last iterate (u and lambda at the contact normals, the active set
/// it was computed with), every iteration, and why the iteration stopped.
#[derive(Clone, Debug)]
pub struct NormalIterate {
    pub u: Vec<f64>,
    pub lambda: Vec<f64>,
    pub active: Vec<bool>,
    pub iterations: Vec<PdasIteration>,
    /// `Converged`, `MaxIterations` or `Cycling`.
    pub termination: PdasTermination,
}

/// The primal–dual active set iteration, whatever solves its linear systems.
/// Active set A = {p : lambda_p + c (u_p - g_p) > 0}; `step(A)` returns (u_C, lambda) with
/// u = g on A and lambda = 0 off A. Stops when A repeats and the NCP residual
/// max |min(lambda, c (g - u))| / (c max(|u|, |g|)) is below tolerance; an active set seen
/// before (other than the previous one) means cycling. Only a failing `step` is an error: a run
/// that does not converge returns its last iterate with the reason (`MaxIterations`, `Cycling`).
pub fn pdas(
    g: &[f64],
    c: f64,
    initial: Vec<bool>,
    options: &PdasOptions,
    observe: &mut dyn FnMut(&PdasIteration),
    step: &mut dyn FnMut(&[bool]) -> Result<Pair, ContactError>,
) -> Result<NormalIterate, ContactError> {
    let m = g.len();
    let mut active = initial;
    let mut seen: Vec<(Vec<bool>, usize)> = Vec::new();
    let mut iterations = Vec::new();
    // the last iterate (zeros with the initial active set if there was no iteration)
    let mut last: Pair = (vec![0.0; m], vec![0.0; m]);
    let mut last_active = active.clone();
    for it in 1..=options.max_iterations {
        let t0 = Instant::now();
        let (u, lambda) = step(&active)?;
        let scale = c * u.iter().chain(g).fold(0.0f64, |a, v| a.max(v.abs())).max(f64::MIN_POSITIVE);
        let next: Vec<bool> = (0..m).map(|i| lambda[i] + c * (u[i] - g[i]) > 0.0).collect();
        let residual = (0..m).map(|i| lambda[i].min(c * (g[i] - u[i])).abs()).fold(0.0, f64::max) / scale;
        let record = PdasIteration {
            iteration: it,
            active: active.iter().filter(|a| **a).count(),
            added: (0..m).filter(|&i| next[i] && !active[i]).count(),
            removed: (0..m).filter(|&i| !next[i] && active[i]).count(),
            residual,
            seconds: t0.elapsed().as_secs_f64(),
        };
        observe(&record);
        iterations.push(record);
        if next == active && residual <= options.tolerance {
            return Ok(NormalIterate { u, lambda, active, iterations, termination: PdasTermination::Converged });
        }
        if next != active
            && let Some((_, first_seen)) = seen.iter().find(|(a, _)| *a == next)
        {
            let termination = PdasTermination::Cycling { first_seen: *first_seen, residual };
            return Ok(NormalIterate { u, lambda, active, iterations, termination });
        }
        seen.push((active.clone(), it));
        last = (u, lambda);
        last_active = std::mem::replace(&mut active, next);
    }
    let termination = PdasTermination::MaxIterations {
        residual: iterations.last().map(|r| r.residual).unwrap_or(f64::NAN),
        tolerance: options.tolerance,
        next_active: active.iter().filter(|a| **a).count(),
    };
    let (u, lambda) = last;
    Ok(NormalIterate { u, lambda, active: last_active, iterations, termination })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strategy_by_the_dense_work_against_a_factorisation() {
        assert_eq!(Strategy::auto(1500, 10_000), Strategy::Schur);
        // Example 7.1 graded towards Gamma_C: 16385 contact nodes among 305k unknowns
        assert_eq!(Strategy::auto(16385, 305_000), Strategy::Refactor);
        assert_eq!(Strategy::auto(2000, 100_000), Strategy::Refactor);
        // structured:1024: 2049 contact nodes among 8.4M unknowns
        assert_eq!(Strategy::auto(2049, 8_392_704), Strategy::Schur);
    }
}
