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
//! per mesh, whatever the number of iterations.

use crate::assembly::SymCsc;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering, supernodal,
};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::{SupernodalThreshold, amd};
use faer::{Conj, Mat, Par, Side, Spec};
use std::collections::HashSet;
use std::time::Instant;

/// Why the contact solve failed.
#[derive(Debug, thiserror::Error)]
pub enum ContactError {
    #[error("the primal-dual active set method did not converge in {iterations} iterations (NCP residual {residual:.3e}, tolerance {tolerance:.1e}, {active} active nodes)")]
    NotConverged { iterations: usize, residual: f64, tolerance: f64, active: usize },
    #[error("the primal-dual active set method is cycling: the active set of iteration {iterations} was already seen at iteration {first_seen} (NCP residual {residual:.3e})")]
    Cycling { iterations: usize, first_seen: usize, residual: f64 },
    #[error("the stiffness matrix is not positive definite: {0}")]
    NotPositiveDefinite(String),
    #[error("sparse factorisation failed: {0}")]
    Factorisation(String),
}

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
}

impl Default for PdasOptions {
    fn default() -> Self {
        PdasOptions { max_iterations: 50, tolerance: 1e-9, c_scale: 1.0, initial_active: None }
    }
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

/// Why the iteration stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Termination {
    /// The active set repeated and the residual was below tolerance.
    Converged,
    /// No contact nodes: a single linear solve.
    NoContact,
}

/// Wall-clock seconds per phase.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Timings {
    pub symbolic: f64,
    pub numeric: f64,
    pub schur: f64,
    pub solves: f64,
    pub active_set: f64,
}

/// The result of a contact solve, on the unknowns of the assembled system.
#[derive(Clone, Debug)]
pub struct PdasOutput {
    /// All unknowns (local frames at contact nodes).
    pub u: Vec<f64>,
    /// Nodal contact force lambda_p per contact node (from the complementarity system).
    pub lambda: Vec<f64>,
    pub active: Vec<bool>,
    pub iterations: Vec<PdasIteration>,
    pub termination: Termination,
    pub c: f64,
}

/// The factorised stiffness with its contact Schur complement. Owns the ordering (fill-reducing
/// on `I`, then `C`) and the factorisation: symbolic once per mesh, numeric once per matrix.
pub struct ContactSolver {
    n: usize,
    n_interior: usize,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    /// S = L_CC L_CC^T (m x m).
    schur: Mat<f64>,
    pub timings: Timings,
}

impl ContactSolver {
    /// Order, factorise and form the Schur complement of the unknowns `n_interior..n`.
    pub fn new(matrix: &SymCsc, n_interior: usize) -> Result<Self, ContactError> {
        let mut timings = Timings::default();
        let t0 = Instant::now();
        let symbolic = symbolic_factorisation(matrix, n_interior)?;
        timings.symbolic = t0.elapsed().as_secs_f64();
        let mut solver = ContactSolver {
            n: matrix.n,
            n_interior,
            l_values: vec![0.0; symbolic.len_val()],
            symbolic,
            schur: Mat::zeros(0, 0),
            timings,
        };
        solver.refactor(matrix)?;
        Ok(solver)
    }

    /// Numeric factorisation of a matrix with the same pattern, and its Schur complement.
    pub fn refactor(&mut self, matrix: &SymCsc) -> Result<(), ContactError> {
        let t0 = Instant::now();
        let par = Par::Seq; // faster than two threads for faer's sparse Cholesky (PERF-NOTES.md)
        let req = self.symbolic.factorize_numeric_llt_scratch::<f64>(par, Spec::default());
        let mut mem = MemBuffer::try_new(req).map_err(|e| ContactError::Factorisation(format!("{e:?}")))?;
        self.symbolic
            .factorize_numeric_llt(
                &mut self.l_values,
                matrix.as_faer(),
                Side::Lower,
                LltRegularization::default(),
                par,
                MemStack::new(&mut mem),
                Spec::default(),
            )
            .map_err(|e| ContactError::NotPositiveDefinite(format!("{e:?}")))?;
        self.timings.numeric = t0.elapsed().as_secs_f64();
        let t0 = Instant::now();
        let lcc = self.trailing_factor_block()?;
        self.schur = &lcc * lcc.transpose();
        self.timings.schur = t0.elapsed().as_secs_f64();
        Ok(())
    }

    pub fn n_contact(&self) -> usize {
        self.n - self.n_interior
    }

    /// The Schur complement S of the contact normal unknowns.
    pub fn schur(&self) -> &Mat<f64> {
        &self.schur
    }

    /// L_CC: the trailing m x m block of the Cholesky factor (rows and columns of `C`, which the
    /// ordering leaves in place at the end).
    fn trailing_factor_block(&self) -> Result<Mat<f64>, ContactError> {
        let (n, ni) = (self.n, self.n_interior);
        let m = n - ni;
        let mut lcc = Mat::<f64>::zeros(m, m);
        let SymbolicCholeskyRaw::Supernodal(sn) = self.symbolic.raw() else {
            return Err(ContactError::Factorisation("expected a supernodal factorisation".into()));
        };
        let l = supernodal::SupernodalLltRef::new(sn, &self.l_values);
        for s in 0..sn.n_supernodes() {
            let node = l.supernode(s);
            let (start, val, pattern) = (node.start(), node.val(), node.pattern());
            let ncols = val.ncols();
            for jc in 0..ncols {
                let j = start + jc;
                if j < ni {
                    continue;
                }
                for rc in jc..ncols {
                    lcc[(start + rc - ni, j - ni)] = val[(rc, jc)];
                }
                for (k, &row) in pattern.iter().enumerate() {
                    lcc[(row - ni, j - ni)] = val[(ncols + k, jc)];
                }
            }
        }
        Ok(lcc)
    }

    /// Solve K x = b.
    pub fn solve(&mut self, b: &[f64]) -> Vec<f64> {
        let t0 = Instant::now();
        let mut x = Mat::<f64>::from_fn(self.n, 1, |i, _| b[i]);
        let par = Par::Seq;
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(1, par));
        LltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(Conj::No, x.as_mut(), par, MemStack::new(&mut mem));
        self.timings.solves += t0.elapsed().as_secs_f64();
        (0..self.n).map(|i| x[(i, 0)]).collect()
    }

    /// Solve the discrete Signorini problem K u = F - E lambda with u_C <= gap, lambda >= 0,
    /// complementarity (E places lambda on the contact normal unknowns). `observe` sees every
    /// iteration as it ends.
    pub fn solve_contact(
        &mut self,
        rhs: &[f64],
        gap: &[f64],
        options: &PdasOptions,
        observe: &mut dyn FnMut(&PdasIteration),
    ) -> Result<PdasOutput, ContactError> {
        let (ni, m) = (self.n_interior, self.n_contact());
        assert_eq!(gap.len(), m);
        let y = self.solve(rhs);
        if m == 0 {
            return Ok(PdasOutput { u: y, lambda: vec![], active: vec![], iterations: vec![], termination: Termination::NoContact, c: 0.0 });
        }
        let yc = &y[ni..];
        let t_pdas = Instant::now();
        let (u_c, lambda, active, iterations, c) = pdas(&self.schur, yc, gap, options, observe)?;
        self.timings.active_set = t_pdas.elapsed().as_secs_f64();
        // u = K^{-1} (F - E lambda)
        let mut b = rhs.to_vec();
        for k in 0..m {
            b[ni + k] -= lambda[k];
        }
        let mut u = self.solve(&b);
        // the sparse solve reproduces u_C; keep the exact constraint values on active nodes
        for k in 0..m {
            if active[k] {
                debug_assert!((u[ni + k] - u_c[k]).abs() <= 1e-6 * (1.0 + u_c[k].abs()));
                u[ni + k] = gap[k];
            }
        }
        Ok(PdasOutput { u, lambda, active, iterations, termination: Termination::Converged, c })
    }
}

/// Symbolic Cholesky with a custom ordering: AMD on the leading block `I`, then `C` in place.
/// The supernodal variant is forced so that the trailing block of L can be read.
fn symbolic_factorisation(matrix: &SymCsc, ni: usize) -> Result<SymbolicCholesky<usize>, ContactError> {
    let n = matrix.n;
    // pattern of K_II (lower triangle): rows are sorted, so rows < ni form a prefix of each column
    let mut col_ptr = Vec::with_capacity(ni + 1);
    let mut row_idx = Vec::new();
    col_ptr.push(0);
    for j in 0..ni {
        for &i in &matrix.row_idx[matrix.col_ptr[j]..matrix.col_ptr[j + 1]] {
            if i < ni {
                row_idx.push(i);
            }
        }
        col_ptr.push(row_idx.len());
    }
    let mut fwd = vec![0usize; n];
    let mut inv = vec![0usize; n];
    if ni > 0 {
        let sym = faer::sparse::SymbolicSparseColMatRef::new_checked(ni, ni, &col_ptr, None, &row_idx);
        let mut mem = MemBuffer::try_new(amd::order_scratch::<usize>(ni, row_idx.len()))
            .map_err(|e| ContactError::Factorisation(format!("{e:?}")))?;
        amd::order(&mut fwd[..ni], &mut inv[..ni], sym, amd::Control::default(), MemStack::new(&mut mem))
            .map_err(|e| ContactError::Factorisation(format!("{e:?}")))?;
    }
    for k in ni..n {
        fwd[k] = k;
        inv[k] = k;
    }
    let perm = faer::perm::PermRef::new_checked(&fwd, &inv, n);
    let params = CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
        ..Default::default()
    };
    faer::sparse::linalg::cholesky::factorize_symbolic_cholesky(
        matrix.as_faer().symbolic(),
        Side::Lower,
        SymmetricOrdering::Custom(perm),
        params,
    )
    .map_err(|e| ContactError::Factorisation(format!("{e:?}")))
}

type PdasResult = (Vec<f64>, Vec<f64>, Vec<bool>, Vec<PdasIteration>, f64);

/// The primal–dual active set iteration on lambda = S (y - u), u <= g, lambda >= 0.
/// Active set A = {p : lambda_p + c (u_p - g_p) > 0}; on A, u = g; off A, lambda = 0, i.e.
/// S_II (y_I - u_I) + S_IA (y_A - g_A) = 0. Stops when A repeats and the NCP residual is below
/// tolerance; a set seen before (not the previous one) means cycling.
pub fn pdas(
    s: &Mat<f64>,
    y: &[f64],
    g: &[f64],
    options: &PdasOptions,
    observe: &mut dyn FnMut(&PdasIteration),
) -> Result<PdasResult, ContactError> {
    let m = y.len();
    let c = options.c_scale * (0..m).map(|i| s[(i, i)]).sum::<f64>() / m as f64;
    let scale = c * y.iter().chain(g).fold(0.0f64, |a, v| a.max(v.abs())).max(f64::MIN_POSITIVE);
    let mut active: Vec<bool> = match &options.initial_active {
        Some(a) if a.len() == m => a.clone(),
        // lambda = 0, u = y: active where the unconstrained solution penetrates
        _ => (0..m).map(|i| y[i] > g[i]).collect(),
    };
    let mut seen: HashSet<Vec<bool>> = HashSet::new();
    let mut first_seen: Vec<(Vec<bool>, usize)> = Vec::new();
    let mut iterations = Vec::new();
    let mut u = vec![0.0; m];
    let mut lambda = vec![0.0; m];
    for it in 1..=options.max_iterations {
        let t0 = Instant::now();
        let inact: Vec<usize> = (0..m).filter(|&i| !active[i]).collect();
        let act: Vec<usize> = (0..m).filter(|&i| active[i]).collect();
        for &i in &act {
            u[i] = g[i];
        }
        if !inact.is_empty() {
            // S_II z = S_IA (y_A - g_A);  u_I = y_I + z
            let sii = Mat::<f64>::from_fn(inact.len(), inact.len(), |a, b| s[(inact[a], inact[b])]);
            let rhs = Mat::<f64>::from_fn(inact.len(), 1, |a, _| act.iter().map(|&j| s[(inact[a], j)] * (y[j] - g[j])).sum::<f64>());
            let llt = sii.llt(Side::Lower).map_err(|e| ContactError::NotPositiveDefinite(format!("Schur block: {e:?}")))?;
            let z = llt.solve(&rhs);
            for (a, &i) in inact.iter().enumerate() {
                u[i] = y[i] + z[(a, 0)];
            }
        }
        // lambda = S (y - u); exactly zero off the active set by construction
        for i in 0..m {
            lambda[i] = if active[i] { (0..m).map(|j| s[(i, j)] * (y[j] - u[j])).sum() } else { 0.0 };
        }
        let next: Vec<bool> = (0..m).map(|i| lambda[i] + c * (u[i] - g[i]) > 0.0).collect();
        let residual = (0..m).map(|i| lambda[i].min(c * (g[i] - u[i])).abs()).fold(0.0, f64::max) / scale;
        let added = (0..m).filter(|&i| next[i] && !active[i]).count();
        let removed = (0..m).filter(|&i| !next[i] && active[i]).count();
        let record = PdasIteration { iteration: it, active: act.len(), added, removed, residual, seconds: t0.elapsed().as_secs_f64() };
        observe(&record);
        iterations.push(record);
        if next == active && residual <= options.tolerance {
            return Ok((u, lambda, active, iterations, c));
        }
        seen.insert(active.clone());
        first_seen.push((active.clone(), it));
        if next != active && seen.contains(&next) {
            let first = first_seen.iter().find(|(a, _)| *a == next).map(|(_, k)| *k).unwrap_or(0);
            return Err(ContactError::Cycling { iterations: it, first_seen: first, residual });
        }
        active = next;
    }
    let residual = iterations.last().map(|r: &PdasIteration| r.residual).unwrap_or(f64::NAN);
    Err(ContactError::NotConverged {
        iterations: options.max_iterations,
        residual,
        tolerance: options.tolerance,
        active: active.iter().filter(|a| **a).count(),
    })
}
