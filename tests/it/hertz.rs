//! The contact pressure recovered from the nodal contact forces (`solve::contact_samples`), which
//! the Hertz comparison reads.

use crate::common;

use signorini::problems::Ex71;
use signorini::solve;

/// Example 7.1 is in contact along the whole bottom with the pressure -sigma_nn = 6 - 3x (linear):
/// the recovered pressure converges to it at every node, vertices and midpoints alike, and the
/// nodal forces add up to its integral, 4.5 (second order: the pressure is a derivative of u).
#[test]
fn recovered_pressure_converges_to_example_7_1s() {
    let mut errors = Vec::new();
    for spec in ["structured:8", "structured:16", "structured:32"] {
        let m = common::mesh(&Ex71, spec);
        let sol = common::solve_on(&Ex71, &m);
        let samples = solve::contact_samples(&m, &sol);
        assert_eq!(samples.len(), sol.dofs.contact.len());
        let err = samples.iter().map(|s| (s.pressure - (6.0 - 3.0 * s.x[0])).abs()).fold(0.0, f64::max);
        let force: f64 = samples.iter().map(|s| s.lambda).sum();
        eprintln!("{spec}: max |p_h - p| = {err:e}, F = {force}");
        assert!((force - 4.5).abs() < 2e-6, "{spec}: total contact force {force} vs 4.5");
        errors.push(err);
    }
    assert!(errors[2] < 1e-3, "{errors:?}");
    assert!(errors[1] / errors[2] > 3.5 && errors[0] / errors[1] > 3.5, "not second order: {errors:?}");
}
