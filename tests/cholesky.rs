//! The tree-parallel numeric Cholesky factorisation (`signorini::cholesky`): the same factor as
//! faer's sequential one, bitwise the same on one and two threads, and a clear error for a
//! matrix that is not positive definite.

mod common;

use common::*;
use faer::Side;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::{Par, Spec};
use signorini::assembly::{self, DofMap, SymCsc};
use signorini::cholesky::{self, Plan};
use signorini::mesh::{Mesh, P2Nodes, refine::refine};
use signorini::problems;

/// Example 7.2's stiffness on `mesh`, and the position of every unknown.
fn stiffness(mesh: &Mesh) -> (SymCsc, Vec<[f64; 2]>) {
    let p = problems::Ex72;
    let nodes = P2Nodes::new(mesh);
    let dofs = DofMap::new(&nodes, &p);
    let sys = assembly::assemble(mesh, &nodes, &dofs, &p);
    (sys.matrix, dofs.unknown_coords(&nodes))
}

/// A mesh refined five times towards the bottom edge (y = 0): long, thin layers, where the
/// minimum-degree ordering wins and the elimination tree is deep.
fn graded() -> Mesh {
    let mut m = mesh(&problems::Ex72, "structured:8");
    for _ in 0..5 {
        let marked: Vec<bool> = (0..m.n_triangles()).map(|t| m.corners(t).iter().any(|c| c[1] < 1e-12)).collect();
        m = refine(&m, &marked).mesh;
    }
    m
}

/// Supernodal symbolic factorisation with the project's fill-reducing ordering.
fn symbolic(matrix: &SymCsc, coords: &[[f64; 2]]) -> SymbolicCholesky<usize> {
    let n = matrix.n();
    let (fwd, _) = signorini::ordering::fill_reducing(matrix, n, coords);
    let mut inv = vec![0; n];
    for (new, &old) in fwd.iter().enumerate() {
        inv[old] = new;
    }
    let perm = faer::perm::PermRef::new_checked(&fwd, &inv, n);
    let params = CholeskySymbolicParams { supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL, ..Default::default() };
    factorize_symbolic_cholesky(matrix.as_faer().symbolic(), Side::Lower, SymmetricOrdering::Custom(perm), params).unwrap()
}

/// Our factor of `values` (on the pattern of `matrix`) on `threads` threads.
fn ours(
    symbolic: &SymbolicCholesky<usize>,
    matrix: &SymCsc,
    values: &[f64],
    threads: usize,
) -> Result<Vec<f64>, cholesky::NotPositiveDefinite> {
    let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else { panic!("supernodal") };
    let plan = Plan::new(sn, matrix, symbolic.perm().unwrap().arrays().1);
    let mut l = vec![f64::NAN; symbolic.len_val()];
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| cholesky::factorize(sn, &plan, values, &mut l))?;
    Ok(l)
}

fn faers(symbolic: &SymbolicCholesky<usize>, matrix: &SymCsc) -> Vec<f64> {
    let mut l = vec![0.0; symbolic.len_val()];
    let mut mem = MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Spec::default()));
    symbolic
        .factorize_numeric_llt(
            &mut l,
            matrix.as_faer(),
            Side::Lower,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut mem),
            Spec::default(),
        )
        .unwrap();
    l
}

#[test]
fn the_factor_is_faers_and_the_same_on_any_number_of_threads() {
    // structured:96: the top supernode (separator and contact unknowns) is large enough for the
    // dense kernels to run on both threads
    for (name, m) in [
        ("structured:24", mesh(&problems::Ex72, "structured:24")),
        ("structured:96", mesh(&problems::Ex72, "structured:96")),
        ("graded", graded()),
    ] {
        let (matrix, coords) = stiffness(&m);
        let symbolic = symbolic(&matrix, &coords);
        let reference = faers(&symbolic, &matrix);
        let one = ours(&symbolic, &matrix, matrix.values(), 1).unwrap();
        let two = ours(&symbolic, &matrix, matrix.values(), 2).unwrap();
        assert!(one.iter().zip(&two).all(|(a, b)| a.to_bits() == b.to_bits()), "{name}: one and two threads differ");
        let scale = reference.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let worst = reference.iter().zip(&one).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(worst <= 1e-13 * scale, "{name}: largest difference from faer's factor {worst:.2e} (largest entry {scale:.2e})");
        // a second factorisation on the same plan (a refactorisation) gives the same again
        let again = ours(&symbolic, &matrix, matrix.values(), 2).unwrap();
        assert!(again.iter().zip(&two).all(|(a, b)| a.to_bits() == b.to_bits()), "{name}: refactorisation differs");
    }
}

#[test]
fn a_matrix_that_is_not_positive_definite_is_an_error_naming_its_column() {
    let (matrix, coords) = stiffness(&mesh(&problems::Ex72, "structured:8"));
    let symbolic = symbolic(&matrix, &coords);
    let mut values = matrix.values().to_vec();
    // a negative diagonal entry at unknown 5
    let at = matrix.position(5, 5);
    values[at] = -values[at];
    let err = ours(&symbolic, &matrix, &values, 2).unwrap_err();
    let inv = symbolic.perm().unwrap().arrays().1;
    // columns before it do not see the entry; at its own column the pivot is -K_55 minus squares
    assert_eq!(err.column, inv[5], "{err}");
    assert!(err.to_string().contains("non-positive pivot"), "{err}");
}

#[test]
fn solves_agree_with_faers_and_on_any_number_of_threads() {
    use faer::sparse::linalg::cholesky::LltRef;
    use faer::{Conj, Mat};
    for (name, m) in [("structured:96", mesh(&problems::Ex72, "structured:96")), ("graded", graded())] {
        let (matrix, coords) = stiffness(&m);
        let symbolic = symbolic(&matrix, &coords);
        let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else { panic!("supernodal") };
        let plan = Plan::new(sn, &matrix, symbolic.perm().unwrap().arrays().1);
        let l = ours(&symbolic, &matrix, matrix.values(), 2).unwrap();
        let n = matrix.n();
        let b: Vec<f64> = (0..n).map(|i| ((i * 37 % 101) as f64 - 50.0) / 7.0).collect();
        // faer's solve (it permutes itself)
        let mut reference = Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
        let mut mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        LltRef::new(&symbolic, &l).solve_in_place_with_conj(Conj::No, reference.as_mut(), Par::Seq, MemStack::new(&mut mem));
        let inv = symbolic.perm().unwrap().arrays().1;
        let solve = |threads: usize| -> Vec<f64> {
            let mut x = vec![0.0; n];
            for i in 0..n {
                x[inv[i]] = b[i];
            }
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| cholesky::solve_in_place(sn, &plan, &l, &mut x));
            (0..n).map(|i| x[inv[i]]).collect()
        };
        let (one, two) = (solve(1), solve(2));
        assert!(one.iter().zip(&two).all(|(a, b)| a.to_bits() == b.to_bits()), "{name}: one and two threads differ");
        let scale = (0..n).fold(0.0f64, |a, i| a.max(reference[(i, 0)].abs()));
        let worst = (0..n).map(|i| (reference[(i, 0)] - one[i]).abs()).fold(0.0, f64::max);
        assert!(worst <= 1e-12 * scale, "{name}: largest difference from faer's solve {worst:.2e} (largest value {scale:.2e})");
        // and it solves K x = b: the residual is at round-off
        let kx = matrix.mul(&one);
        let res = kx.iter().zip(&b).map(|(a, c)| (a - c).abs()).fold(0.0, f64::max);
        let bmax = b.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(res <= 1e-8 * bmax, "{name}: residual {res:.2e}");
    }
}
