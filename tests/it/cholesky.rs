//! The Cholesky factorisation of our own (`signorini::symbolic`, `signorini::cholesky`): the
//! symbolic structure is faer's for the same ordering, array for array; the factor is faer's
//! sequential one's, bitwise the same on one and two threads; a matrix that is not positive
//! definite is a clear error.

use crate::common;

use common::*;
use faer::Side;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::{Par, Spec};
use signorini::assembly::{self, DofMap};
use signorini::cholesky::{self, Plan};
use signorini::mesh::{Mesh, P2Nodes, refine::refine};
use signorini::problems;
use signorini::sparse::csc::SymCsc;
use signorini::symbolic::{Placement, Symbolic};

/// Example 7.2's stiffness on `mesh`, the position of every unknown, and the number of unknowns
/// that are not contact normals.
fn stiffness_and_contact(mesh: &Mesh) -> (SymCsc, Vec<[f64; 2]>, usize) {
    let p = problems::Ex72;
    let nodes = P2Nodes::new(mesh);
    let dofs = DofMap::new(&nodes, &p);
    let sys = assembly::assemble(mesh, &nodes, &dofs, &p);
    (sys.matrix, dofs.unknown_coords(&nodes), dofs.n_interior)
}

fn stiffness(mesh: &Mesh) -> (SymCsc, Vec<[f64; 2]>) {
    let (matrix, coords, _) = stiffness_and_contact(mesh);
    (matrix, coords)
}

/// A mesh refined five times towards the bottom edge (y = 0): long, thin layers, where the
/// minimum-degree ordering wins and the elimination tree is deep.
fn graded() -> Mesh {
    let mut m = mesh(&problems::Ex72, "structured:8");
    for _ in 0..5 {
        let marked: Vec<bool> = (0..m.n_triangles()).map(|t| m.corners(t).iter().any(|c| c[1] < 1e-12)).collect();
        m = refine(&m, &marked).unwrap().mesh;
    }
    m
}

/// The meshes of the tests: uniform ones (nested dissection; at structured:96 the top supernode,
/// separator and contact unknowns, is large enough for the dense kernels to run on both threads)
/// and a graded one (minimum degree).
fn meshes() -> [(&'static str, Mesh); 3] {
    [
        ("structured:24", mesh(&problems::Ex72, "structured:24")),
        ("structured:96", mesh(&problems::Ex72, "structured:96")),
        ("graded", graded()),
    ]
}

/// Our symbolic factorisation with the project's fill-reducing ordering of `0..n_order`.
fn symbolic(matrix: &SymCsc, n_order: usize, coords: &[[f64; 2]]) -> Symbolic {
    signorini::symbolic::analyse(matrix, n_order, coords).0
}

/// Where the entries of `matrix` go in the structure `symbolic`.
fn placement(matrix: &SymCsc, symbolic: &Symbolic) -> Placement {
    Placement::new(matrix, symbolic.inv())
}

/// faer's supernodal symbolic factorisation with the ordering of `ours`.
fn faers_symbolic(matrix: &SymCsc, ours: &Symbolic) -> SymbolicCholesky<usize> {
    let perm = faer::perm::PermRef::new_checked(ours.perm(), ours.inv(), matrix.n());
    let params = CholeskySymbolicParams { supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL, ..Default::default() };
    factorize_symbolic_cholesky(matrix.as_faer().symbolic(), Side::Lower, SymmetricOrdering::Custom(perm), params).unwrap()
}

/// Our factor of `matrix` (or of other `values` on its pattern) on `threads` threads.
fn ours(matrix: &SymCsc, symbolic: &Symbolic, values: &[f64], threads: usize) -> Result<Vec<f64>, cholesky::FactorError> {
    let plan = Plan::new(symbolic);
    let mut l = vec![f64::NAN; symbolic.len_val()];
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        cholesky::load(symbolic, &placement(matrix, symbolic), values, None, &mut l, false);
        cholesky::factorize(symbolic, &plan, &mut l)
    })?;
    Ok(l)
}

#[test]
fn the_symbolic_structure_is_faers_for_the_same_ordering() {
    // uniform and graded meshes (nested dissection and minimum degree), all unknowns ordered
    // (the Refactor strategy) or the contact normals last, each its own node (Schur)
    for (name, m) in meshes() {
        let (matrix, coords, n_interior) = stiffness_and_contact(&m);
        assert!(n_interior < matrix.n(), "{name}: a mesh with contact unknowns");
        for n_order in [matrix.n(), n_interior] {
            let ours = symbolic(&matrix, n_order, &coords);
            let faers = faers_symbolic(&matrix, &ours);
            let SymbolicCholeskyRaw::Supernodal(theirs) = faers.raw() else { panic!("supernodal") };
            let ns = ours.n_supernodes();
            assert_eq!(ours.supernode_begin()[..ns], theirs.supernode_begin()[..], "{name}, {n_order} ordered: supernodes");
            assert_eq!(ours.supernode_begin()[1..], theirs.supernode_end()[..], "{name}, {n_order} ordered: supernodes");
            for s in 0..ns {
                let start = theirs.col_ptr_for_row_idx()[s];
                let pattern: Vec<u32> = theirs.row_idx()[start..start + theirs.nnz_per_super()[s]].iter().map(|&r| r as u32).collect();
                assert_eq!(ours.pattern(s), &pattern[..], "{name}, {n_order} ordered: pattern of supernode {s}");
            }
            assert_eq!(ours.val_ptr(), theirs.col_ptr_for_val(), "{name}, {n_order} ordered: layout of the values");
            // and the contact normals stayed in place at the end
            assert!((n_order..matrix.n()).all(|i| ours.inv()[i] == i), "{name}: contact normals moved");
        }
    }
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
    for (name, m) in meshes() {
        let (matrix, coords) = stiffness(&m);
        let symbolic = symbolic(&matrix, matrix.n(), &coords);
        let reference = faers(&faers_symbolic(&matrix, &symbolic), &matrix);
        let one = ours(&matrix, &symbolic, matrix.values(), 1).unwrap();
        let two = ours(&matrix, &symbolic, matrix.values(), 2).unwrap();
        assert!(one.iter().zip(&two).all(|(a, b)| a.to_bits() == b.to_bits()), "{name}: one and two threads differ");
        let scale = reference.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let worst = reference.iter().zip(&one).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(worst <= 1e-13 * scale, "{name}: largest difference from faer's factor {worst:.2e} (largest entry {scale:.2e})");
        // a refactorisation in place (loading over the finished factor) gives the same again
        let mut again = two.clone();
        cholesky::load(&symbolic, &placement(&matrix, &symbolic), matrix.values(), None, &mut again, false);
        cholesky::factorize(&symbolic, &Plan::new(&symbolic), &mut again).unwrap();
        assert!(again.iter().zip(&two).all(|(a, b)| a.to_bits() == b.to_bits()), "{name}: refactorisation differs");
    }
}

#[test]
fn a_refactorisation_of_the_changed_supernodes_is_the_whole_one_bit_for_bit() {
    // a few contact normals constrained as the Refactor strategy does (the off-diagonal entries
    // of their rows and columns zero), released again, and constrained by marking them fixed:
    // each time only the supernodes the changed entries reach are computed, and L is the whole
    // factorisation's to the bit
    for (name, m) in meshes() {
        let (matrix, coords, n_interior) = stiffness_and_contact(&m);
        let symbolic = symbolic(&matrix, matrix.n(), &coords);
        let (plan, placement) = (Plan::new(&symbolic), placement(&matrix, &symbolic));
        let picked: Vec<usize> = (n_interior..matrix.n()).step_by(7).take(4).collect();
        let (col_ptr, row_idx, inv) = (matrix.col_ptr(), matrix.row_idx(), symbolic.inv());
        let mut constrained = matrix.values().to_vec();
        let mut columns = Vec::new();
        for j in 0..matrix.n() {
            for pos in col_ptr[j]..col_ptr[j + 1] {
                let i = row_idx[pos];
                if i != j && (picked.contains(&i) || picked.contains(&j)) {
                    constrained[pos] = 0.0;
                    columns.push(inv[i].min(inv[j]));
                }
            }
        }
        let which = plan.changed(&symbolic, columns);
        let share = plan.share(&which);
        assert!(share > 0.0 && share < 0.9, "{name}: the changed supernodes hold {share:.2} of the work");
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let free = ours(&matrix, &symbolic, matrix.values(), threads).unwrap();
            let whole = ours(&matrix, &symbolic, &constrained, threads).unwrap();
            let mut l = free.clone();
            pool.install(|| {
                cholesky::load_changed(&symbolic, &placement, &constrained, None, &mut l, &which);
                cholesky::refactorize(&symbolic, &plan, &mut l, &which)
            })
            .unwrap();
            assert!(l.iter().zip(&whole).all(|(a, b)| a.to_bits() == b.to_bits()), "{name}, {threads} threads: constrained");
            pool.install(|| {
                cholesky::load_changed(&symbolic, &placement, matrix.values(), None, &mut l, &which);
                cholesky::refactorize(&symbolic, &plan, &mut l, &which)
            })
            .unwrap();
            assert!(l.iter().zip(&free).all(|(a, b)| a.to_bits() == b.to_bits()), "{name}, {threads} threads: released");
            // the same constraints marked as fixed unknowns (permuted numbering) on K's own values
            let mut fixed = vec![false; matrix.n()];
            picked.iter().for_each(|&i| fixed[inv[i]] = true);
            pool.install(|| {
                cholesky::load_changed(&symbolic, &placement, matrix.values(), Some(&fixed), &mut l, &which);
                cholesky::refactorize(&symbolic, &plan, &mut l, &which)
            })
            .unwrap();
            assert!(l.iter().zip(&whole).all(|(a, b)| a.to_bits() == b.to_bits()), "{name}, {threads} threads: fixed");
        }
    }
}

#[test]
fn a_matrix_that_is_not_positive_definite_is_an_error_naming_its_column() {
    let (matrix, coords) = stiffness(&mesh(&problems::Ex72, "structured:8"));
    let symbolic = symbolic(&matrix, matrix.n(), &coords);
    let mut values = matrix.values().to_vec();
    // a negative diagonal entry at unknown 5
    let at = matrix.position(5, 5);
    values[at] = -values[at];
    let cholesky::FactorError::NotPositiveDefinite(err) = ours(&matrix, &symbolic, &values, 2).unwrap_err() else {
        panic!("not the pivot error")
    };
    let inv = symbolic.inv();
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
        let symbolic = symbolic(&matrix, matrix.n(), &coords);
        let plan = Plan::new(&symbolic);
        let l = ours(&matrix, &symbolic, matrix.values(), 2).unwrap();
        let faers_symbolic = faers_symbolic(&matrix, &symbolic);
        let n = matrix.n();
        let b: Vec<f64> = (0..n).map(|i| ((i * 37 % 101) as f64 - 50.0) / 7.0).collect();
        // faer's solve (it permutes itself)
        let mut reference = Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
        let mut mem = MemBuffer::new(faers_symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        LltRef::new(&faers_symbolic, &l).solve_in_place_with_conj(Conj::No, reference.as_mut(), Par::Seq, MemStack::new(&mut mem));
        let inv = symbolic.inv();
        let solve = |threads: usize| -> Vec<f64> {
            let mut x = vec![0.0; n];
            for i in 0..n {
                x[inv[i]] = b[i];
            }
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| cholesky::solve_in_place(&symbolic, &plan, &l, &mut x));
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

#[test]
fn the_symbolic_analysis_is_the_same_on_any_number_of_threads() {
    // the node graph, the dissection, the gathered graph and the placement of the matrix entries
    // all run in parallel; each must give the same arrays on one and two threads
    for (name, m) in [("structured:96", mesh(&problems::Ex72, "structured:96")), ("graded", graded())] {
        let (matrix, coords, n_interior) = stiffness_and_contact(&m);
        for n_order in [matrix.n(), n_interior] {
            let on = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| signorini::symbolic::analyse(&matrix, n_order, &coords))
            };
            let ((one, place_one, choice_one), (two, place_two, choice_two)) = (on(1), on(2));
            assert_eq!(choice_one, choice_two, "{name}: ordering choice");
            assert_eq!(one.perm(), two.perm(), "{name}: ordering");
            assert_eq!(one.supernode_begin(), two.supernode_begin(), "{name}: supernodes");
            assert!((0..one.n_supernodes()).all(|s| one.pattern(s) == two.pattern(s)), "{name}: row patterns");
            assert!((0..matrix.n()).all(|j| place_one.entries(j) == place_two.entries(j)), "{name}: placement of the matrix entries");
        }
    }
}

/// The partial substitutions the contact solver reuses (the contact normals are the trailing
/// block): the rows of the trailing block from the forward substitution alone, and the solve of a
/// right-hand side that differs only there from the forward substitution kept, are bit for bit
/// what the whole solve gives, on one and two threads, also where the trailing block begins
/// inside a supernode.
#[test]
fn solves_finished_from_a_kept_forward_substitution_are_the_whole_solves() {
    for (name, m) in meshes() {
        let (matrix, coords, ni) = stiffness_and_contact(&m);
        let symbolic = symbolic(&matrix, ni, &coords);
        let plan = Plan::new(&symbolic);
        let l = ours(&matrix, &symbolic, matrix.values(), 2).unwrap();
        let n = matrix.n();
        let b: Vec<f64> = (0..n).map(|i| ((i * 37 % 101) as f64 - 50.0) / 7.0).collect();
        let mut b2 = b.clone();
        for (k, v) in b2[ni..].iter_mut().enumerate() {
            *v -= 0.3 + k as f64 * 1e-3; // contact forces, say
        }
        let whole = |b: &[f64]| {
            let mut x = b.to_vec();
            cholesky::solve_in_place(&symbolic, &plan, &l, &mut x);
            x
        };
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        // the contact normals keep their places (the ordering orders 0..ni only), so b needs no permutation here
        assert!((ni..n).all(|i| symbolic.inv()[i] == i), "{name}");
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut z = b.clone();
                cholesky::forward_in_place(&symbolic, &plan, &l, &mut z);
                let mut tail = z.clone();
                cholesky::backward_tail(&symbolic, &plan, &l, &mut tail, ni);
                assert_eq!(bits(&tail[ni..]), bits(&whole(&b)[ni..]), "{name}, {threads} thread(s): trailing rows");
                for from in [ni, ni - 1, ni - 7] {
                    let mut x = z.clone();
                    cholesky::forward_tail(&symbolic, &plan, &l, &mut x, &b2, from);
                    cholesky::backward_in_place(&symbolic, &plan, &l, &mut x);
                    assert_eq!(bits(&x), bits(&whole(&b2)), "{name}, {threads} thread(s), from {from}: the solve of b2");
                }
            });
        }
    }
}

/// L's values are allocated fallibly: a length the allocator cannot give is the named memory
/// error with the size asked, not an abort; a length it can is zeros, as `vec!` would give.
#[test]
fn an_allocation_of_l_that_cannot_be_made_is_the_named_memory_error() {
    let len = usize::MAX / 16;
    let err = cholesky::zeros(len, "the Cholesky factor L").unwrap_err();
    assert_eq!(err.bytes, len * 8);
    let text = err.to_string();
    assert!(text.contains("out of memory") && text.contains("the Cholesky factor L") && text.contains(&(len * 8).to_string()), "{text}");
    // larger than the address space: refused by the layout, named the same way
    let err = cholesky::zeros(usize::MAX, "L").unwrap_err();
    assert!(err.to_string().contains("out of memory"), "{err}");
    let ok = cholesky::zeros(1000, "L").unwrap();
    assert!(ok.len() == 1000 && ok.iter().all(|v| v.to_bits() == 0));
    assert!(cholesky::zeros(0, "L").unwrap().is_empty());
}
