//! The problem data agree with their definitions: Example 7.1's f and g against finite
//! differences of the exact stress (the paper prints u but not f and g: we derive them, and
//! check the derivation here).

use signorini::problems::{Ex71, Exact, Problem};

fn stress(p: &Ex71, x: [f64; 2]) -> [f64; 3] {
    p.material().stress(p.grad(x))
}

#[test]
fn ex71_body_force_is_minus_div_sigma() {
    let p = Ex71;
    let h = 1e-5;
    for &x in &[[0.1, 0.2], [0.5, 0.5], [0.9, 0.7], [0.3, 0.95]] {
        let dx = |f: &dyn Fn([f64; 2]) -> f64| (f([x[0] + h, x[1]]) - f([x[0] - h, x[1]])) / (2.0 * h);
        let dy = |f: &dyn Fn([f64; 2]) -> f64| (f([x[0], x[1] + h]) - f([x[0], x[1] - h])) / (2.0 * h);
        let div1 = dx(&|y| stress(&p, y)[0]) + dy(&|y| stress(&p, y)[1]);
        let div2 = dx(&|y| stress(&p, y)[1]) + dy(&|y| stress(&p, y)[2]);
        let f = p.body_force(x);
        assert!((f[0] + div1).abs() < 1e-7, "f1 at {x:?}: {} vs {}", f[0], -div1);
        assert!((f[1] + div2).abs() < 1e-7, "f2 at {x:?}: {} vs {}", f[1], -div2);
    }
}

#[test]
fn ex71_gradient_matches_finite_differences() {
    let p = Ex71;
    let h = 1e-6;
    let x = [0.37, 0.61];
    let g = p.grad(x);
    for (i, gi) in g.iter().enumerate() {
        let dx = (p.u([x[0] + h, x[1]])[i] - p.u([x[0] - h, x[1]])[i]) / (2.0 * h);
        let dy = (p.u([x[0], x[1] + h])[i] - p.u([x[0], x[1] - h])[i]) / (2.0 * h);
        assert!((gi[0] - dx).abs() < 1e-8 && (gi[1] - dy).abs() < 1e-8);
    }
}

#[test]
fn ex71_tractions_match_the_paper_notes() {
    let p = Ex71;
    for &y in &[0.0, 0.25, 0.5, 0.8] {
        let e = f64::exp(y);
        let left = p.traction([0.0, y], [-1.0, 0.0]);
        let expect_left = [2.0 * (1.0 - y - y * y) * e, y * (2.0 - 3.0 * y + (y - 1.0) * e)];
        let right = p.traction([1.0, y], [1.0, 0.0]);
        let expect_right = [(y * y + y - 1.0) * e, y * (3.0 * y - 2.0 - (y - 1.0) * e)];
        for i in 0..2 {
            assert!((left[i] - expect_left[i]).abs() < 1e-13, "left g at y={y}");
            assert!((right[i] - expect_right[i]).abs() < 1e-13, "right g at y={y}");
        }
    }
    // on Gamma_C: no tangential stress, sigma_nn = 3x - 6 < 0 (contact everywhere)
    for &x in &[0.0, 0.4, 1.0] {
        let t = p.traction([x, 0.0], [0.0, -1.0]);
        assert!(t[0].abs() < 1e-14);
        assert!((-t[1] - (3.0 * x - 6.0)).abs() < 1e-13);
    }
    assert_eq!(p.u([0.3, 0.0]), [0.0, 0.0]);
    assert_eq!(p.u([0.3, 1.0]), [0.0, 0.0]);
}
