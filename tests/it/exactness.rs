//! Exactness and structure: a quadratic displacement in the P2 space is reproduced to round-off,
//! for any contact normal (local frames at contact nodes), and the assembled operator is
//! symmetric with a correct Schur complement.

use crate::common;
use common::*;
use signorini::assembly::{self, DofMap};
use signorini::contact::ContactSolver;
use signorini::element::{self, Affine};
use signorini::mesh::P2Nodes;
use signorini::problems::{Exact, Material, Patch};

fn max_nodal_error(p: &Patch, sol: &signorini::solve::DiscreteSolution) -> f64 {
    sol.nodes
        .coords
        .iter()
        .zip(&sol.u)
        .map(|(x, uh)| {
            let u = p.u(*x);
            (u[0] - uh[0]).abs().max((u[1] - uh[1]).abs())
        })
        .fold(0.0, f64::max)
}

#[test]
fn quadratic_displacement_is_reproduced_to_round_off() {
    for spec in ["structured:3", "structured:8", "symmetric:6"] {
        let p = Patch::default();
        let m = mesh(&p, spec);
        let sol = solve_on(&p, &m);
        assert_eq!(sol.active_count(), 0, "the obstacle is far away");
        let err = max_nodal_error(&p, &sol);
        assert!(err < 1e-13, "{spec}: nodal error {err:e}");
        // and everywhere in between, since u is in the P2 space
        let e = signorini::norms::linf_error(&m, &sol, &|x| p.u(x));
        assert!(e.linf_dense < 1e-13 && e.linf_quadrature < 1e-13, "{spec}: {e:?}");
    }
}

#[test]
fn oblique_contact_normal_changes_nothing_when_inactive() {
    let mut p = Patch::traction_free_right(Material::from_young(3.0, 0.41), [0.02, -0.01, 0.03, 0.01, 0.02, -0.04]);
    p.normal = [0.6, 0.8];
    let m = mesh(&p, "structured:5");
    let sol = solve_on(&p, &m);
    let err = max_nodal_error(&p, &sol);
    assert!(err < 1e-13, "nodal error {err:e} with an oblique frame");
}

#[test]
fn oblique_contact_normal_active_satisfies_kkt() {
    // an obstacle close enough to touch, along an oblique normal
    let p = Patch { normal: [0.8, -0.6], gap: 0.0, ..Patch::default() };
    let m = mesh(&p, "structured:8");
    let sol = solve_on(&p, &m);
    let k = sol.kkt();
    assert!(
        sol.active_count() > 0 && sol.active_count() < sol.dofs.contact.len(),
        "a genuine free boundary: {} active",
        sol.active_count()
    );
    assert!(k.max_penetration < 1e-12, "{k:?}");
    assert!(k.min_lambda > -1e-10 * k.force_scale, "{k:?}");
    assert!(k.max_inactive_lambda < 1e-10 * k.force_scale, "{k:?}");
    assert!(sol.free_residual < 1e-11, "free equations hold: {}", sol.free_residual);
}

#[test]
fn element_stiffness_is_symmetric_with_rigid_kernel() {
    let map = Affine::new([[0.1, 0.2], [0.9, 0.3], [0.4, 0.8]]);
    let rule = element::triangle_rule(2);
    let k = assembly::element_stiffness(&map, Material::from_young(500.0, 0.3), &rule);
    let scale = k.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    for (i, row) in k.iter().enumerate() {
        for (j, kij) in row.iter().enumerate() {
            assert!((kij - k[j][i]).abs() < 1e-13 * scale);
        }
    }
    // rigid motions (two translations, one rotation) are in the kernel
    let nodes = [[0.1, 0.2], [0.9, 0.3], [0.4, 0.8], [0.5, 0.25], [0.65, 0.55], [0.25, 0.5]];
    let modes: [fn([f64; 2]) -> [f64; 2]; 3] = [|_| [1.0, 0.0], |_| [0.0, 1.0], |x| [-x[1], x[0]]];
    for mode in &modes {
        let v: Vec<f64> = nodes.iter().flat_map(|x| mode(*x)).collect();
        for row in &k {
            let kv: f64 = row.iter().zip(&v).map(|(a, b)| a * b).sum();
            assert!(kv.abs() < 1e-12 * scale);
        }
    }
}

#[test]
fn schur_complement_inverts_the_contact_block_of_the_inverse() {
    // (K^{-1})_CC = S^{-1}: check S * (K^{-1})_CC = I, which tests the ordering and the
    // extraction of the trailing block of the supernodal factor
    let p = signorini::problems::Ex72;
    let m = mesh(&p, "structured:6");
    let nodes = P2Nodes::new(&m);
    let dofs = DofMap::new(&nodes, &p);
    let sys = assembly::assemble(&m, &nodes, &dofs, &p);
    let mut solver = ContactSolver::new(sys.matrix.clone(), dofs.n_interior, &dofs.unknown_coords(&nodes)).unwrap();
    let (ni, mc) = (dofs.n_interior, dofs.contact.len());
    assert_eq!(mc, 13);
    let s = solver.schur().clone();
    for j in 0..mc {
        let mut e = vec![0.0; sys.matrix.n()];
        e[ni + j] = 1.0;
        let x = solver.solve(&e);
        for i in 0..mc {
            let v: f64 = (0..mc).map(|k| s[(i, k)] * x[ni + k]).sum();
            assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-10, "S (K^-1)_CC [{i},{j}] = {v}");
        }
    }
    // and K x = e really holds (the solve itself is right)
    let mut e = vec![0.0; sys.matrix.n()];
    e[3] = 1.0;
    let x = solver.solve(&e);
    let kx = sys.matrix.mul(&x);
    for (i, v) in kx.iter().enumerate() {
        assert!((v - e[i]).abs() < 1e-10);
    }
}
