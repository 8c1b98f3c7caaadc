//! The discrete KKT conditions at every discrete solution: no penetration at contact nodes,
//! lambda_p >= 0, lambda_p = 0 off the active set, the equations at free nodes.

mod common;
use common::*;
use signorini::problems::{self, Problem};

#[test]
fn kkt_holds_for_both_examples() {
    for spec in ["structured:4", "structured:16", "structured:48", "symmetric:20"] {
        assert_kkt(&problems::Ex71, spec);
        assert_kkt(&problems::Ex72, spec);
    }
}

#[test]
fn warm_start_from_the_solution_converges_in_one_iteration() {
    let p = problems::Ex72;
    let m = mesh(&p, "structured:32");
    let cold = solve_on(&p, &m);
    assert!(cold.pdas.len() > 2);
    let options = signorini::contact::PdasOptions { initial_active: Some(cold.active.clone()), ..Default::default() };
    let warm = signorini::solve::solve(&m, &p, &options, &mut |_| {}).unwrap();
    assert_eq!(warm.pdas.len(), 1);
    assert_eq!(warm.active, cold.active);
}

#[test]
fn schur_and_refactor_strategies_agree() {
    use signorini::contact::{PdasOptions, Strategy};
    for (problem, spec) in
        [(&problems::Ex72 as &dyn Problem, "structured:24"), (&problems::Ex71, "structured:12"), (&problems::Ex72, "symmetric:16")]
    {
        let m = mesh(problem, spec);
        let run = |s: Strategy| {
            signorini::solve::solve(&m, problem, &PdasOptions { strategy: Some(s), ..Default::default() }, &mut |_| {}).unwrap()
        };
        let (a, b) = (run(Strategy::Schur), run(Strategy::Refactor));
        assert_eq!((a.strategy, b.strategy), (Strategy::Schur, Strategy::Refactor));
        assert_eq!(a.active, b.active, "{} on {spec}: active sets differ", problem.name());
        let scale = a.u.iter().fold(0.0f64, |s, u| s.max(u[0].abs()).max(u[1].abs()));
        let diff = a.u.iter().zip(&b.u).fold(0.0f64, |s, (x, y)| s.max((x[0] - y[0]).abs()).max((x[1] - y[1]).abs()));
        assert!(diff < 1e-11 * scale, "{} on {spec}: displacements differ by {diff:e}", problem.name());
        let ldiff = a.lambda.iter().zip(&b.lambda).fold(0.0f64, |s, (x, y)| s.max((x - y).abs()));
        assert!(ldiff < 1e-9 * a.force_scale, "{} on {spec}: lambda differs by {ldiff:e}", problem.name());
        let k = b.kkt();
        assert!(
            k.max_penetration <= 1e-12 && k.min_lambda >= -1e-10 * k.force_scale && k.max_inactive_lambda <= 1e-10 * k.force_scale,
            "refactor KKT {k:?}"
        );
    }
}

/// A run that stops without converging returns its last iterate and the reason; `converged()`
/// (what `solve::solve` calls) turns it into the error naming the iterations and the residual.
#[test]
fn non_converged_active_set_method_returns_its_last_iterate() {
    use signorini::assembly::{self, DofMap};
    use signorini::contact::{ContactSolver, PdasOptions, Strategy, Termination};
    use signorini::mesh::P2Nodes;
    let p = problems::Ex72;
    let m = mesh(&p, "structured:16");
    let nodes = P2Nodes::new(&m);
    let dofs = DofMap::new(&nodes, &p);
    let sys = assembly::assemble(&m, &nodes, &dofs, &p);
    let gap: Vec<f64> = dofs.contact.iter().map(|c| c.gap).collect();
    for strategy in [Strategy::Schur, Strategy::Refactor] {
        let mut solver = ContactSolver::with_strategy(sys.matrix.clone(), dofs.n_interior, &dofs.unknown_coords(&nodes), strategy).unwrap();
        let options = PdasOptions { max_iterations: 2, ..Default::default() };
        let out = solver.solve_contact(&sys.rhs, &gap, &options, &mut |_| {}).unwrap();
        assert!(matches!(out.termination, Termination::MaxIterations { .. }), "{strategy:?}: {:?}", out.termination);
        assert!(!out.termination.is_converged());
        assert_eq!((out.iterations.len(), out.u.len(), out.lambda.len(), out.active.len()), (2, sys.matrix.n(), gap.len(), gap.len()));
        assert!(out.u.iter().all(|v| v.is_finite()));
        let err = out.converged().unwrap_err().to_string();
        assert!(err.contains("did not converge in 2 iterations") && err.contains("residual"), "{err}");
    }
    let err = signorini::solve::solve(&m, &p, &PdasOptions { max_iterations: 2, ..Default::default() }, &mut |_| {}).err().unwrap();
    assert!(err.to_string().contains("did not converge in 2 iterations"), "{err}");
}

/// An active set seen before: the iteration stops with `Cycling` and the iterate that led there.
#[test]
fn cycling_active_set_method_returns_its_last_iterate() {
    use signorini::contact::{PdasOptions, Termination, pdas};
    let g = [0.5];
    // inactive -> the node penetrates (next: active); active -> negative force (next: inactive)
    let mut step = |a: &[bool]| Ok(if a[0] { (vec![0.5], vec![-1.0]) } else { (vec![1.5], vec![0.0]) });
    let out = pdas(&g, 1.0, vec![false], &PdasOptions::default(), &mut |_| {}, &mut step).unwrap();
    assert_eq!(out.termination, Termination::Cycling { first_seen: 1, residual: out.iterations[1].residual });
    assert_eq!((out.u, out.lambda, out.active, out.iterations.len()), (vec![0.5], vec![-1.0], vec![true], 2));
    let err = Termination::Cycling { first_seen: 1, residual: 0.25 }.error(2).unwrap().to_string();
    assert!(err.contains("cycling") && err.contains("iteration 2") && err.contains("iteration 1"), "{err}");
}
