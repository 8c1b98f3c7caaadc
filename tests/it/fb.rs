//! The free-boundary problem `fb` (beyond the paper): its data satisfy the Signorini conditions
//! with the contact zone exactly [a, 1], a = sqrt(2) - 1; uniform P2 errors converge; the discrete
//! contact zone tends to [a, 1]; the discrete KKT conditions hold; the CLI solves it.
#![allow(clippy::needless_range_loop)] // component loops read as the formulas they check

use crate::common;
use common::*;
use signorini::norms;
use signorini::problems::{self, Exact, Fb, Problem};

const A: f64 = Fb::A;

/// The stress of the exact solution from central differences of u (not from `Exact::grad`).
fn stress_fd(x: [f64; 2]) -> [f64; 3] {
    let p = Fb;
    let h = 1e-6;
    let mut g = [[0.0; 2]; 2];
    for i in 0..2 {
        g[i][0] = (p.u([x[0] + h, x[1]])[i] - p.u([x[0] - h, x[1]])[i]) / (2.0 * h);
        g[i][1] = (p.u([x[0], x[1] + h])[i] - p.u([x[0], x[1] - h])[i]) / (2.0 * h);
    }
    p.material().stress(g)
}

/// Points on both sides of x = a, none within 0.03 of it (f is not smooth across x = a).
const XS: [f64; 7] = [0.05, 0.2, 0.38, 0.45, 0.6, 0.8, 0.97];

#[test]
fn fb_gradient_and_body_force_match_finite_differences() {
    let p = Fb;
    for &x in &XS {
        for &y in &[0.1, 0.5, 0.9] {
            let pt = [x, y];
            // grad u against differences of u
            let g = p.grad(pt);
            let h = 1e-6;
            for i in 0..2 {
                let dx = (p.u([x + h, y])[i] - p.u([x - h, y])[i]) / (2.0 * h);
                let dy = (p.u([x, y + h])[i] - p.u([x, y - h])[i]) / (2.0 * h);
                assert!((g[i][0] - dx).abs() < 1e-8 && (g[i][1] - dy).abs() < 1e-8, "grad u_{i} at {pt:?}");
            }
            // f = -div sigma(u), sigma from the exact gradient, differentiated numerically
            let s = |q: [f64; 2]| p.material().stress(p.grad(q));
            let h = 1e-5;
            let div1 = (s([x + h, y])[0] - s([x - h, y])[0] + s([x, y + h])[1] - s([x, y - h])[1]) / (2.0 * h);
            let div2 = (s([x + h, y])[1] - s([x - h, y])[1] + s([x, y + h])[2] - s([x, y - h])[2]) / (2.0 * h);
            let f = p.body_force(pt);
            assert!((f[0] + div1).abs() < 1e-6, "f1 at {pt:?}: {} vs {}", f[0], -div1);
            assert!((f[1] + div2).abs() < 1e-6, "f2 at {pt:?}: {} vs {}", f[1], -div2);
        }
    }
    // f is bounded but not smooth: continuous across x = a, its x-derivative jumps there
    // (p'' = -(15/4) ((x - a)_+)^(1/2) has an infinite slope at a+)
    let (l, r) = (p.body_force([A - 1e-9, 0.5]), p.body_force([A + 1e-9, 0.5]));
    assert!((l[1] - r[1]).abs() < 1e-3, "f2 continuous at x = a");
    let bound = (0..=200)
        .flat_map(|i| (0..=20).map(move |j| [i as f64 / 200.0, j as f64 / 20.0]))
        .map(|q| p.body_force(q))
        .fold(0.0f64, |m, f| m.max(f[0].abs()).max(f[1].abs()));
    assert!(bound < 50.0, "f bounded: max |f| = {bound}");
}

#[test]
fn fb_tractions_are_sigma_n_on_the_sides() {
    let p = Fb;
    for &y in &[0.05, 0.3, 0.5, 0.77, 0.95] {
        for (x, n) in [(0.0, [-1.0, 0.0]), (1.0, [1.0, 0.0])] {
            // one-sided differences would be needed at x = 0, 1: u extends smoothly, so central is fine
            let s = stress_fd([x, y]);
            let expect = [s[0] * n[0] + s[1] * n[1], s[1] * n[0] + s[2] * n[1]];
            let g = p.traction([x, y], n);
            assert!((g[0] - expect[0]).abs() < 1e-7 && (g[1] - expect[1]).abs() < 1e-7, "g at ({x}, {y}): {g:?} vs {expect:?}");
            assert_eq!(p.part_of([x, y]), signorini::problems::Part::Neumann);
        }
    }
    // Dirichlet data are the exact solution on the top
    for &x in &XS {
        assert_eq!(p.dirichlet([x, 1.0]), p.u([x, 1.0]));
        assert_eq!(p.part_of([x, 1.0]), signorini::problems::Part::Dirichlet);
        assert_eq!(p.part_of([x, 0.0]), signorini::problems::Part::Contact);
    }
}

#[test]
fn fb_satisfies_the_signorini_conditions_on_gamma_c() {
    let p = Fb;
    let n = p.contact_normal([0.5, 0.0], [0.0, -1.0]);
    assert_eq!(n, [0.0, -1.0]);
    let mut in_contact = Vec::new();
    for i in 0..=1000 {
        let x = i as f64 / 1000.0;
        // the stress on y = 0 from differences of u (a 1e-6 step straddles y = 0: u is smooth in y)
        let s = stress_fd([x, 0.0]);
        let pp = Fb::p(x)[0];
        assert!(s[1].abs() < 1e-8, "sigma_12 = {} at x = {x}", s[1]);
        assert!((s[2] - pp).abs() < 1e-8, "sigma_22 = {} vs p = {pp} at x = {x}", s[2]);
        // sigma_nn = n . sigma n = sigma_22 <= 0, the contact force density -sigma_nn >= 0
        let sigma_nn = s[0] * n[0] * n[0] + 2.0 * s[1] * n[0] * n[1] + s[2] * n[1] * n[1];
        assert!(sigma_nn <= 1e-8, "sigma_nn = {sigma_nn} at x = {x}");
        // the exact tangential traction vanishes (frictionless)
        let t = p.material().traction(p.grad([x, 0.0]), n);
        assert!(t[0].abs() < 1e-14, "tangential traction at x = {x}");
        // the gap chi - u.n >= 0: exactly ((a - x)_+)^(3/2)
        let u = p.u([x, 0.0]);
        let gap = p.gap([x, 0.0]) - (u[0] * n[0] + u[1] * n[1]);
        assert!(gap >= 0.0, "penetration {gap} at x = {x}");
        assert!((gap - (A - x).max(0.0).powf(1.5)).abs() < 1e-14, "gap at x = {x}");
        // complementarity
        assert!((sigma_nn * gap).abs() < 1e-9, "sigma_nn (u.n - chi) = {} at x = {x}", sigma_nn * gap);
        // exact contact: gap = 0 exactly on [a, 1], and the force is positive on (a, 1]
        if gap == 0.0 {
            in_contact.push(x);
            assert!(x > A, "contact at x = {x} < a");
            assert!(-pp > 0.0, "no force in the contact zone at x = {x}");
        } else {
            assert!(x < A && pp == 0.0, "x = {x}: gap {gap}, p {pp}");
        }
    }
    let (first, last) = (in_contact[0], *in_contact.last().unwrap());
    assert!(first - A < 1e-3 && first > A && last == 1.0, "contact zone of the exact solution [{first}, {last}]");
}

#[test]
fn fb_meshes_never_put_a_vertex_on_the_free_boundary() {
    for n in 1..=256 {
        for kind in ["structured", "symmetric"] {
            if kind == "symmetric" && n % 2 == 1 {
                continue;
            }
            let m = mesh(&Fb, &format!("{kind}:{n}"));
            let d = m.vertices.iter().map(|v| (v[0] - A).abs()).fold(f64::INFINITY, f64::min);
            // |i/N - a| >= 1/(3 N^2) for a = sqrt(2) - 1 (Liouville for a quadratic irrational)
            assert!(d > 1.0 / (3.0 * (n * n) as f64), "{kind}:{n}: a vertex {d:e} from x = a");
        }
    }
}

/// Uniform errors on structured:N, N = 8 .. 128. Measured rates in h between consecutive N:
/// quadrature 2.98, 2.98, 2.99, 3.00 and dense 2.97, 2.98, 2.90, 2.94: NDF^-1.5 at these sizes
/// (the error is dominated by the smooth part r of u; the free-boundary term y p(x) / 3 is small).
/// The floor 2.8 is 0.1 below the slowest measured pair.
#[test]
fn fb_uniform_errors_converge() {
    let p = Fb;
    let mut rows = Vec::new();
    for n in [8usize, 16, 32, 64, 128] {
        let m = mesh(&p, &format!("structured:{n}"));
        let sol = solve_on(&p, &m);
        rows.push((1.0 / n as f64, norms::linf_error(&m, &sol, &|x| p.u(x))));
    }
    for w in rows.windows(2) {
        let ((h1, e1), (h2, e2)) = (w[0], w[1]);
        for (name, a, b) in [("quadrature", e1.linf_quadrature, e2.linf_quadrature), ("dense", e1.linf_dense, e2.linf_dense)] {
            let r = rate(a, b, h1, h2);
            eprintln!("fb uniform: {name} rate {r:.3} between h = {h1} and {h2}");
            assert!(r >= 2.8, "{name} rate {r:.3} between h = {h1} and {h2}");
            assert!(r <= 3.3, "{name} rate {r:.3}: faster than P2 can be, something is off");
        }
    }
    assert!(rows.last().unwrap().1.linf_quadrature < 5e-7, "error at N = 128: {:e}", rows.last().unwrap().1.linf_quadrature);
}

/// The discrete contact zone [zone_min, zone_max] (active contact nodes) against [a, 1]. The left
/// end is not monotone from one N to the next (N = 8: 0.023 from a, N = 16: 0.055; it stays
/// within about 2.5 node spacings h/2 of a up to N = 192), but it is over h / 4 steps:
/// 0.023 (N = 8), 0.0077 (N = 32), 0.0038 (N = 128). The right end is the corner x = 1.
/// The active set is not one interval: next to the free boundary, vertices and edge midpoints
/// may alternate (N = 8: 0.5 inactive inside [0.4375, 1]; N = 32: 0.4375, 0.46875; N = 128:
/// 0.421875, 0.4296875, at most 3 node spacings right of the zone's left end). The last inactive
/// node also moves to a: 0.086, 0.055, 0.016 from it.
#[test]
fn fb_discrete_contact_zone_tends_to_a_1() {
    let p = Fb;
    let (mut first_active, mut last_inactive) = (Vec::new(), Vec::new());
    for n in [8usize, 32, 128] {
        let m = mesh(&p, &format!("structured:{n}"));
        let sol = solve_on(&p, &m);
        let [lo, hi] = sol.contact_zone().expect("some contact");
        assert_eq!(hi, 1.0, "N = {n}: the zone ends at x = 1");
        assert!(lo > A, "N = {n}: an active node left of a: {lo}");
        let x = |i: usize| sol.nodes.coords[sol.dofs.contact[i].node][0];
        let last = (0..sol.dofs.contact.len()).filter(|&i| !sol.active[i]).map(x).fold(f64::NEG_INFINITY, f64::max);
        eprintln!("fb structured:{n}: discrete contact zone [{lo}, {hi}], {:.3e} from a; last inactive node {last}", lo - A);
        first_active.push(lo - A);
        last_inactive.push(last - A);
    }
    for d in [&first_active, &last_inactive] {
        assert!(
            d.windows(2).all(|w| w[1] < w[0]),
            "distances to a: first active node {first_active:?}, last inactive node {last_inactive:?}"
        );
    }
    assert!(first_active[2] < 0.01, "N = 128: zone starts {:.4} right of a", first_active[2]);
    assert!(last_inactive[2] < 0.03, "N = 128: an inactive node {:.4} right of a", last_inactive[2]);
}

#[test]
fn fb_kkt_holds() {
    for spec in ["structured:4", "structured:16", "structured:48", "symmetric:20"] {
        assert_kkt(&Fb, spec);
    }
}

#[test]
fn fb_is_known_and_solved_from_the_command_line() {
    assert!(problems::KNOWN.contains(&"fb"));
    assert_eq!(problems::by_name("fb").unwrap().name(), "fb");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["solve", "--problem", "fb", "--mesh", "structured:8", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    for key in ["error", "estimator", "contact_zone", "kkt"] {
        assert!(!v[key].is_null(), "no {key} in {v}");
    }
    assert!(v["error"]["linf_quadrature"].as_f64().unwrap() > 0.0);
    let zone = v["contact_zone"].as_array().unwrap();
    assert!(zone[0].as_f64().unwrap() > A && zone[1].as_f64().unwrap() == 1.0);
}

/// `assembly::split_load`, used on the triangles crossed by x = a: exact for polynomials (equal to
/// the degree-10 rule) and, unlike a Gauss rule on the whole triangle, for the root terms of f.
#[test]
fn split_load_integrates_root_singularities_exactly() {
    use signorini::assembly::{LOAD_DEGREE, split_load};
    use signorini::element::{self, Affine};
    let corners = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let map = Affine::new(corners);
    let gauss = |f: &dyn Fn([f64; 2]) -> [f64; 2], degree: usize| {
        let rule = element::triangle_rule(degree);
        let mut load = [0.0; 12];
        for (q, w) in rule.points.iter().zip(&rule.weights) {
            let (phi, fx) = (element::p2_values(q[0], q[1]), f(map.map(*q)));
            for a in 0..6 {
                load[2 * a] += w * map.det.abs() * fx[0] * phi[a];
                load[2 * a + 1] += w * map.det.abs() * fx[1] * phi[a];
            }
        }
        load
    };
    let poly = |x: [f64; 2]| [1.0 + x[0] - 2.0 * x[1] * x[1] + x[0] * x[1] * x[1], 3.0 * x[0] * x[0] * x[0] - x[1]];
    let (split, full) = (split_load(&map, corners, 0.3, &poly), gauss(&poly, LOAD_DEGREE));
    for i in 0..12 {
        assert!((split[i] - full[i]).abs() < 1e-14, "polynomial load {i}: {} vs {}", split[i], full[i]);
    }
    // f = (((x - c)_+)^(1/2), ((x - c)_+)^(3/2)): the sum over the six basis functions is int_T f,
    // (4/15) L^(5/2) and (4/35) L^(7/2) with L = 1 - c on this triangle
    let c = 0.3;
    let root = |x: [f64; 2]| {
        let s = (x[0] - c).max(0.0);
        [s.sqrt(), s * s.sqrt()]
    };
    let l = 1.0 - c;
    let exact = [4.0 / 15.0 * l.powf(2.5), 4.0 / 35.0 * l.powf(3.5)];
    let sum = |load: [f64; 12], k: usize| (0..6).map(|a| load[2 * a + k]).sum::<f64>();
    let (split, full) = (split_load(&map, corners, c, &root), gauss(&root, LOAD_DEGREE));
    for k in 0..2 {
        assert!((sum(split, k) - exact[k]).abs() < 1e-14, "split: int f_{k} = {} vs {}", sum(split, k), exact[k]);
        eprintln!(
            "int f_{k}: split {:.3e}, degree-{LOAD_DEGREE} rule {:.3e} off",
            (sum(split, k) - exact[k]).abs(),
            (sum(full, k) - exact[k]).abs()
        );
    }
    // the whole-triangle rule is not exact there: why fb needs the split
    assert!((sum(full, 0) - exact[0]).abs() > 1e-7);
}
