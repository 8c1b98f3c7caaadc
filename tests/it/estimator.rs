//! Invariances of the estimator (src/estimate.rs) that hold whatever the estimator's constants:
//!
//! 1. exactness: a displacement in the P2 space that solves elasticity with its own f and g and
//!    no active contact (problems::Patch) has eta_1 = ... = eta_5 = 0 to round-off (and eta_6 =
//!    eta_7 = 0: the obstacle is far away and lambda_h = 0);
//! 2. rigid motions r(x) = (a - c y, b + c x) added to u_h leave the residual terms eta_1..eta_5
//!    unchanged (sigma(r) = 0, div sigma(r) = 0);
//! 3. the residual terms are linear in the data: scaling f, g, u_D and chi by k (material
//!    unchanged) scales the discrete solution and eta_1..eta_5 by k.

use crate::common;
use common::*;
use signorini::estimate;
use signorini::level::terms::Terms;
use signorini::mesh::Mesh;
use signorini::problems::{Ex71, Ex72, Exact, Material, Part, Patch, Problem};
use signorini::settings::estimator::{ContactTerm, EstimatorConfig, LogFactor};
use signorini::settings::sampling::Sampling;

/// The four estimator configurations that differ in what eta_1..eta_5 are (the log factor and
/// C_0 do not enter eta_1..eta_5, but they enter eta_h and the estimate, which are checked too).
fn configs() -> Vec<EstimatorConfig> {
    let mut out = Vec::new();
    for contact_term in [ContactTerm::AsWritten, ContactTerm::WithoutFullContact] {
        for sampling in [Sampling::Quadrature, Sampling::Dense] {
            out.push(EstimatorConfig { contact_term, sampling, log_factor: LogFactor::Squared, c0: 0.45, ..Default::default() });
        }
    }
    out
}

fn residual_terms(t: &Terms) -> [f64; 5] {
    [t.eta1, t.eta2, t.eta3, t.eta4, t.eta5]
}

/// max over mesh vertices of the largest stress component of the exact displacement.
fn max_exact_stress(problem: &dyn Problem, exact: &dyn Exact, mesh: &Mesh) -> f64 {
    mesh.vertices.iter().map(|x| problem.material().stress(exact.grad(*x)).iter().fold(0.0f64, |a, s| a.max(s.abs()))).fold(0.0, f64::max)
}

/// The stress scale against which round-off is judged: (2 mu + zeta) max |grad u|. It bounds the
/// stress, and unlike max |sigma| it does not shrink when the stress is a cancellation of large
/// terms (nearly incompressible materials: zeta tr eps against 2 mu eps).
fn stress_scale(problem: &dyn Problem, exact: &dyn Exact, mesh: &Mesh) -> f64 {
    let m = problem.material();
    let g = mesh.vertices.iter().map(|x| exact.grad(*x).iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()))).fold(0.0, f64::max);
    (2.0 * m.mu + m.zeta) * g
}

// ---------------------------------------------------------------------------------------------
// 1. exactness

fn check_patch_exactness(p: &Patch, spec: &str) {
    let m = match spec.strip_prefix("refined ") {
        // an NVB-refined mesh: local refinement towards (1, 0.5), three times
        Some(base) => {
            let mut m = mesh(p, base);
            for _ in 0..3 {
                let marked: Vec<bool> =
                    (0..m.n_triangles()).map(|t| m.corners(t).iter().any(|x| signorini::mesh::dist(*x, [1.0, 0.5]) < 0.3)).collect();
                m = signorini::mesh::refine::refine(&m, &marked).unwrap().mesh;
            }
            m
        }
        None => mesh(p, spec),
    };
    let mut sol = solve_on(p, &m);
    assert_eq!(sol.active_count(), 0, "{spec}: the obstacle is far away, no active node");
    let (_, h_max) = m.h_range();
    let sigma = max_exact_stress(p, p, &m);
    let f = p.body_force([0.5, 0.5]);
    let f_scale = f[0].abs().max(f[1].abs());
    assert!(sigma > 1e-2 && f_scale > 1e-2, "the patch has non-trivial stress {sigma} and load {f_scale}");
    // Round-off scale of each term. eta_2..eta_5 are h_p times stresses: 1e-12 (2 mu + zeta)
    // max|grad u| h. eta_1 is h_p^2 times div sigma(u_h), a second difference of nodal values
    // (hessians of the P2 basis are O(h^-2)): its round-off is O(eps (2 mu + zeta) max|u|)
    // whatever h, so its tolerance is 1e-12 (2 mu + zeta) max|u| (measured below 3e-13 of it).
    let scale = stress_scale(p, p, &m);
    assert!(scale >= sigma);
    let mat = p.material();
    let umax = sol.nodes.coords.iter().map(|x| p.u(*x)).fold(0.0f64, |a, u| a.max(u[0].abs()).max(u[1].abs()));
    let tols = [
        1e-12 * (2.0 * mat.mu + mat.zeta) * umax,
        1e-12 * scale * h_max,
        1e-12 * scale * h_max,
        1e-12 * scale * h_max,
        1e-12 * scale * h_max,
    ];
    let tol_sum: f64 = tols.iter().sum();
    for (what, u) in [("discrete solution", None), ("nodal interpolant of u", Some(()))] {
        if u.is_some() {
            // the same with u_h replaced by the exact nodal values: tests the estimator alone
            sol.u = sol.nodes.coords.iter().map(|x| p.u(*x)).collect();
        }
        for config in configs() {
            let e = estimate::estimate(&m, p, &sol, &config);
            let t = e.terms;
            eprintln!(
                "patch {spec} {what} {config:?}: eta / tol = {:?}",
                std::array::from_fn::<f64, 5, _>(|i| residual_terms(&t)[i] / tols[i])
            );
            for (i, (v, tol)) in residual_terms(&t).iter().zip(tols).enumerate() {
                assert!(v.abs() <= tol, "{spec}, {what}, {config:?}: eta_{} = {v:e} > {tol:e} (max|sigma| {sigma}, h {h_max})", i + 1);
            }
            // no penetration and no contact force: eta_6 = eta_7 = 0
            assert!(t.eta6 <= 0.0 && t.eta7 <= 0.0, "{spec}: eta_6 = {:e}, eta_7 = {:e}", t.eta6, t.eta7);
            assert!(t.estimate <= config.c0 * t.l_h * tol_sum, "{spec}: estimate {:e}", t.estimate);
            // the element indicators vanish too, so nothing would be marked by anything
            let max_el = e.element.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(max_el <= t.l_h * tol_sum, "{spec}: max element indicator {max_el:e}");
        }
    }
}

#[test]
fn p2_exact_patch_has_zero_residual_terms() {
    let patches = [
        Patch::default(),
        // a nearly incompressible material and other coefficients: large zeta
        Patch::traction_free_right(Material::from_young(500.0, 0.45), [0.02, -0.01, 0.03, 0.01, 0.02, -0.04]),
    ];
    for p in &patches {
        for spec in ["structured:3", "structured:8", "symmetric:6", "symmetric:10", "refined structured:4", "refined symmetric:6"] {
            check_patch_exactness(p, spec);
        }
    }
}

/// Control for the test above: the same estimator does see a wrong field. Perturbing one interior
/// node (a vertex), one edge midpoint, or the Dirichlet side of the patch makes the terms that
/// must see it positive, so zero is not simply what the estimator always returns.
#[test]
fn patch_estimator_sees_a_perturbation() {
    let p = Patch::default();
    let m = mesh(&p, "structured:8");
    let mut sol = solve_on(&p, &m);
    let base = sol.u.clone();
    let config = EstimatorConfig::default();
    let (_, h) = m.h_range();
    let sigma = max_exact_stress(&p, &p, &m);
    // interior vertex (0.5, 0.5) and the midpoint node nearest to (0.5625, 0.5)
    let find = |x: [f64; 2]| sol.nodes.coords.iter().position(|y| signorini::mesh::dist(*y, x) < 1e-12).unwrap();
    let (v, mid, right) = (find([0.5, 0.5]), find([0.5625, 0.5]), find([1.0, 0.5]));
    for (what, node) in [("interior vertex", v), ("interior midpoint", mid), ("contact vertex", right)] {
        sol.u = base.clone();
        sol.u[node][0] += 1e-3;
        let t = estimate::estimate(&m, &p, &sol, &config).terms;
        eprintln!("perturbed {what}: eta = {:?}", t.eta());
        assert!(t.eta1 > 1e-6 * sigma * h && t.eta2 > 1e-6 * sigma * h, "{what}: {:?}", t.eta());
        if what == "contact vertex" {
            // traction on x = 1 is no longer zero: sigma_nn (and sigma_nt, through the
            // shear component) show up in eta_5 and eta_4
            assert!(t.eta5 > 1e-6 * sigma * h && t.eta4 > 1e-6 * sigma * h, "{what}: {:?}", t.eta());
        }
    }
    // a Neumann node: the traction residual on the top side appears in eta_3
    sol.u = base.clone();
    let top = find([0.5, 1.0]);
    sol.u[top][1] += 1e-3;
    let t = estimate::estimate(&m, &p, &sol, &config).terms;
    assert!(t.eta3 > 1e-6 * sigma * h, "Neumann node: {:?}", t.eta());
    // the exact field again: zero again (the test is not stateful)
    sol.u = base;
    let t = estimate::estimate(&m, &p, &sol, &config).terms;
    assert!(residual_terms(&t).iter().all(|v| *v <= 1e-12 * sigma * h));
}

// ---------------------------------------------------------------------------------------------
// 2. rigid motions

fn rel_diff(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

fn check_rigid(problem: &dyn Problem, spec: &str) {
    let m = mesh(problem, spec);
    let mut sol = solve_on(problem, &m);
    let base = sol.u.clone();
    let umax = base.iter().fold(0.0f64, |a, u| a.max(u[0].abs()).max(u[1].abs()));
    for config in configs() {
        let e0 = estimate::estimate(&m, problem, &sol, &config);
        let t0 = e0.terms;
        assert!(residual_terms(&t0).iter().filter(|v| **v > 0.0).count() >= 4, "{spec}: non-trivial terms {:?}", t0.eta());
        // motions of the size of the solution and much larger ones (round-off grows with them)
        for (a, b, c) in [(0.3, -0.7, 0.5), (1.0, 2.0, -3.0), (-20.0, 5.0, 13.0)] {
            let (a, b, c) = (a * umax, b * umax, c * umax);
            sol.u = base.iter().zip(&sol.nodes.coords).map(|(u, x)| [u[0] + a - c * x[1], u[1] + b + c * x[0]]).collect();
            let e1 = estimate::estimate(&m, problem, &sol, &config);
            let t1 = e1.terms;
            for (i, (v0, v1)) in residual_terms(&t0).iter().zip(residual_terms(&t1)).enumerate() {
                let d = rel_diff(*v0, v1);
                assert!(
                    d <= 1e-10,
                    "{} {spec} {config:?}, r = ({a}, {b}, {c}): eta_{} {v0:e} -> {v1:e} (rel {d:e})",
                    problem.name(),
                    i + 1
                );
            }
            // the indicators' residual parts are unchanged too; for these problems (Ex71 in full
            // contact with chi = 0, Ex72 with no penetration) only eta_6/eta_7 may change
            assert_eq!(t0.l_h, t1.l_h);
            assert!(rel_diff(t0.psi, t1.psi) <= 1e-10);
        }
        sol.u = base.clone();
    }
}

#[test]
fn rigid_motions_leave_residual_terms_unchanged() {
    check_rigid(&Ex71, "structured:8");
    check_rigid(&Ex71, "symmetric:12");
    check_rigid(&Ex72, "structured:16");
    check_rigid(&Ex72, "symmetric:12");
}

// ---------------------------------------------------------------------------------------------
// 3. scaling of the data

/// `inner` with f, g, u_D and chi multiplied by k; material, boundary parts and normal unchanged.
struct Scaled<'a> {
    inner: &'a dyn Problem,
    k: f64,
}

impl Problem for Scaled<'_> {
    fn name(&self) -> &str {
        "scaled"
    }
    fn description(&self) -> &str {
        "a problem with all data scaled by k"
    }
    fn material(&self) -> Material {
        self.inner.material()
    }
    fn part_of(&self, x: [f64; 2]) -> Part {
        self.inner.part_of(x)
    }
    fn body_force(&self, x: [f64; 2]) -> [f64; 2] {
        self.inner.body_force(x).map(|v| self.k * v)
    }
    fn traction(&self, x: [f64; 2], n: [f64; 2]) -> [f64; 2] {
        self.inner.traction(x, n).map(|v| self.k * v)
    }
    fn dirichlet(&self, x: [f64; 2]) -> [f64; 2] {
        self.inner.dirichlet(x).map(|v| self.k * v)
    }
    fn contact_normal(&self, x: [f64; 2], outward: [f64; 2]) -> [f64; 2] {
        self.inner.contact_normal(x, outward)
    }
    fn gap(&self, x: [f64; 2]) -> f64 {
        self.k * self.inner.gap(x)
    }
    fn required_vertices(&self) -> Vec<[f64; 2]> {
        self.inner.required_vertices()
    }
}

/// The scale factor: below 1, because Example 7.2 scaled by 3.7 pushes its clamped side 0.37 and
/// its obstacle 0.74 into a body 1 wide, which the gap bound refuses (its held end counts where
/// the Dirichlet data put it).
const K: f64 = 0.37;

fn check_scaling(problem: &dyn Problem, spec: &str) {
    let scaled = Scaled { inner: problem, k: K };
    let m = mesh(problem, spec);
    let sol = solve_on(problem, &m);
    // (a) the scaled nodal field, estimated against the scaled data
    let mut sol_k = solve_on(problem, &m);
    sol_k.u = sol.u.iter().map(|u| [K * u[0], K * u[1]]).collect();
    // lambda_h scales by k as well (the set Lambda_h^C of positive forces does not change)
    sol_k.lambda = sol.lambda.iter().map(|l| K * l).collect();
    sol_k.lambda_floor = sol.lambda_floor.iter().map(|l| K * l).collect();
    sol_k.force_scale = K * sol.force_scale;
    // (b) the discrete solution of the scaled problem
    let sol_s = solve_on(&scaled, &m);
    let umax = sol.u.iter().fold(0.0f64, |a, u| a.max(u[0].abs()).max(u[1].abs()));
    assert_eq!(sol_s.active, sol.active, "{spec}: the active set of the scaled problem is the same");
    let du = sol_s.u.iter().zip(&sol.u).fold(0.0f64, |a, (s, u)| a.max((s[0] - K * u[0]).abs()).max((s[1] - K * u[1]).abs()));
    assert!(du <= 1e-10 * K * umax, "{spec}: u_h(k data) - k u_h = {du:e} (|u_h| {umax})");
    for config in configs() {
        let t = estimate::estimate(&m, problem, &sol, &config).terms;
        for (what, s) in [("k u_h", &sol_k), ("solution of the scaled problem", &sol_s)] {
            let tk = estimate::estimate(&m, &scaled, s, &config).terms;
            eprintln!("{} {spec} {what} {config:?}\n   eta   = {:?}\n   eta_k = {:?}", problem.name(), t.eta(), tk.eta());
            for (i, (v, vk)) in residual_terms(&t).iter().zip(residual_terms(&tk)).enumerate() {
                let d = rel_diff(K * v, vk);
                assert!(d <= 1e-10, "{} {spec} {what} {config:?}: eta_{}: {K} x {v:e} vs {vk:e} (rel {d:e})", problem.name(), i + 1);
            }
            // eta_6, eta_7 are positive parts of u_h.n - chi: they scale by k too (up to round-off
            // of the size of k |u_h|, since both are round-off for these problems)
            for (v, vk) in [(t.eta6, tk.eta6), (t.eta7, tk.eta7)] {
                assert!((K * v - vk).abs() <= 1e-10 * K * umax.max(1.0), "{spec} {what}: eta_6/7 {v:e} -> {vk:e}");
            }
            assert_eq!(t.l_h, tk.l_h, "l_h depends on the mesh only");
        }
    }
}

#[test]
fn scaling_the_data_scales_the_residual_terms() {
    check_scaling(&Ex71, "structured:8");
    check_scaling(&Ex71, "symmetric:10");
    check_scaling(&Ex72, "structured:16");
    check_scaling(&Ex72, "symmetric:12");
}

/// eta_6 and eta_7 of Example 7.1: chi = 0 = chi_h and the discrete solution is in contact at every
/// contact node, so (u_h.n - chi)^+ and (chi - u_h.n)^+ vanish on Gamma_C (u_h.n is the P2
/// interpolant of its nodal values, all equal to 0).
#[test]
fn ex71_has_no_penetration_and_no_separation_terms() {
    for spec in ["structured:4", "structured:16", "symmetric:12"] {
        let p = Ex71;
        let m = mesh(&p, spec);
        let sol = solve_on(&p, &m);
        assert_eq!(sol.active_count(), sol.dofs.contact.len(), "{spec}: full contact");
        for config in configs() {
            let e = estimate::estimate(&m, &p, &sol, &config);
            assert!(
                e.terms.eta6 <= 1e-14 && e.terms.eta7 <= 1e-14,
                "{spec} {config:?}: eta_6 = {:e}, eta_7 = {:e}",
                e.terms.eta6,
                e.terms.eta7
            );
            // every contact node's patch is in full contact
            assert!(e.full_contact_nodes > 0);
            if config.contact_term == ContactTerm::WithoutFullContact {
                assert_eq!(e.terms.eta5, 0.0, "{spec}: every contact node is a full-contact node, eta_5 drops out");
            }
        }
    }
}

#[test]
fn terms_are_consistent() {
    // eta_h = l_h Psi + eta_6 + eta_7, estimate = C_0 eta_h, l_h = 1 + |log h_min|^2
    let p = Ex72;
    let m = mesh(&p, "structured:8");
    let sol = solve_on(&p, &m);
    let (h_min, _) = m.h_range();
    for log_factor in [LogFactor::Squared, LogFactor::Linear, LogFactor::One] {
        let config = EstimatorConfig { log_factor, c0: 0.45, ..Default::default() };
        let t = estimate::estimate(&m, &p, &sol, &config).terms;
        let l = h_min.ln().abs();
        let expect = match log_factor {
            LogFactor::Squared => 1.0 + l * l,
            LogFactor::Linear => 1.0 + l,
            LogFactor::One => 1.0,
        };
        assert!(rel_diff(t.l_h, expect) < 1e-14);
        assert!(rel_diff(t.psi, t.eta1 + t.eta2 + t.eta3 + t.eta4 + t.eta5) < 1e-14);
        assert!(rel_diff(t.eta_h, t.l_h * t.psi + t.eta6 + t.eta7) < 1e-14);
        assert!(rel_diff(t.estimate, 0.45 * t.eta_h) < 1e-14);
    }
}
