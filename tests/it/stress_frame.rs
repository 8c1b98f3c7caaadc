//! The two readings of sigma-hat in eta_4, eta_5 (`settings::estimator::StressFrame`): on Example 7.1's
//! bottom edge (n = (0, -1)) the Cartesian reading swaps the tangential and normal stresses, on
//! Example 7.2's right edge (n = (1, 0)) both readings agree; the other terms never change.

use crate::common;

use signorini::estimate;
use signorini::level::terms::Terms;
use signorini::problems::{Ex71, Ex72, Problem};
use signorini::settings::estimator::{EstimatorConfig, StressFrame};

fn both(problem: &dyn Problem) -> (Terms, Terms) {
    let mesh = common::mesh(problem, "structured:8");
    let sol = common::solve_on(problem, &mesh);
    let normal = estimate::estimate(&mesh, problem, &sol, &EstimatorConfig::default()).terms;
    let cartesian =
        estimate::estimate(&mesh, problem, &sol, &EstimatorConfig { stress_frame: StressFrame::Cartesian, ..Default::default() }).terms;
    (normal, cartesian)
}

#[test]
fn cartesian_reading_swaps_eta4_and_eta5_on_a_bottom_contact_edge() {
    let (n, c) = both(&Ex71);
    assert_eq!(c.eta4, n.eta5);
    assert_eq!(c.eta5, n.eta4);
    assert!(n.eta5 > 100.0 * n.eta4, "the normal stress dominates on Ex. 7.1: {} vs {}", n.eta5, n.eta4);
    for (a, b) in [(n.eta1, c.eta1), (n.eta2, c.eta2), (n.eta3, c.eta3), (n.eta6, c.eta6), (n.eta7, c.eta7)] {
        assert_eq!(a, b);
    }
}

#[test]
fn both_readings_agree_on_a_right_contact_edge() {
    let (n, c) = both(&Ex72);
    // n = (1, 0), t = (0, 1): (sigma n)_1 = n . sigma n and (sigma n)_2 = t . sigma n
    assert!((c.eta4 - n.eta4).abs() <= 1e-12 * n.eta4.max(1.0), "{} vs {}", c.eta4, n.eta4);
    assert!((c.eta5 - n.eta5).abs() <= 1e-12 * n.eta5.max(1.0), "{} vs {}", c.eta5, n.eta5);
}
