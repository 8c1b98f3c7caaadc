//! The error measures away from the corners and the free-boundary edge of a level record:
//! zero error on Gamma_C for a P2 field, errors on parts never above the whole, the contact edge
//! on Gamma_C sampled at its own points, and the edge straddling a free boundary found where
//! there is one (Example 7.2) and not where contact is everywhere (Example 7.1).

use crate::common;
use common::*;
use signorini::adapt;
use signorini::norms;
use signorini::problems::{Ex71, Ex72, Exact, Patch, Problem};
use signorini::settings::sampling::Sampling;

#[test]
fn p2_field_has_no_error_on_gamma_c() {
    let p = Patch::default();
    let m = mesh(&p, "structured:6");
    let sol = solve_on(&p, &m);
    let e = norms::linf_error_contact(&m, &sol, &|x| p.u(x)).expect("the patch mesh has contact edges");
    assert!(e < 1e-13, "{e:e}");
}

#[test]
fn parts_never_exceed_the_whole_and_gamma_c_is_sampled_on_its_edge() {
    let p = Ex71;
    let m = mesh(&p, "structured:8");
    let sol = solve_on(&p, &m);
    let exact = p.exact().unwrap();
    let u = |x: [f64; 2]| exact.u(x);
    let whole = norms::linf_error_on(&m, &sol, &u, Sampling::Dense);
    let right = norms::linf_error_where(&m, &sol, &u, Sampling::Dense, &|x| x[0] >= 0.5).unwrap();
    let contact = norms::linf_error_contact(&m, &sol, &u).unwrap();
    assert!(right <= whole && right > 0.0);
    // the record's pair, from one evaluation per lattice point: the same two numbers
    let (error, kept) = norms::linf_error_with(&m, &sol, &u, &|x| x[0] >= 0.5);
    assert_eq!((error.linf_dense, kept), (whole, Some(right)));
    // the lattice contains the edge points at 1/6 spacing; Gamma_C is sampled at 1/12 spacing,
    // so it may exceed the lattice maximum only slightly
    assert!(contact > 0.0 && contact <= 1.5 * whole, "{contact:e} vs {whole:e}");
    // a predicate keeping nothing gives no value
    assert_eq!(norms::linf_error_where(&m, &sol, &u, Sampling::Dense, &|x| x[0] > 2.0), None);
    // the contact error is the maximum over points with y = 0: recompute it by brute force
    let mut brute = 0.0f64;
    for t in 0..m.n_triangles() {
        let refs: Vec<[f64; 2]> = (0..=12)
            .flat_map(|k| {
                let s = k as f64 / 12.0;
                [[s, 0.0], [0.0, s], [s, 1.0 - s]]
            })
            .collect();
        for (x, uh) in sol.eval_element(&m, t, &refs) {
            if x[1].abs() < 1e-14 {
                let ue = exact.u(x);
                brute = brute.max((ue[0] - uh[0]).abs().max((ue[1] - uh[1]).abs()));
            }
        }
    }
    assert!((brute - contact).abs() <= 1e-15 + 1e-12 * contact, "{brute:e} vs {contact:e}");
}

#[test]
fn free_boundary_edge_exists_only_with_a_free_boundary() {
    let p = Ex71;
    let m = mesh(&p, "structured:8");
    let sol = solve_on(&p, &m);
    assert_eq!(adapt::free_boundary_edge(&m, &sol), None, "Ex. 7.1 is in contact on all of Gamma_C");
    let p = Ex72;
    let m = mesh(&p, "structured:16");
    let sol = solve_on(&p, &m);
    let h = adapt::free_boundary_edge(&m, &sol).expect("Ex. 7.2 has two free-boundary points");
    assert!((h - 1.0 / 16.0).abs() < 1e-14, "a boundary edge of structured:16: {h}");
}
