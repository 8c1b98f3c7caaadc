//! Example 7.2 (rigid wedge): symmetry about y = 0.5 on a mesh that is itself symmetric, and a
//! contact zone that settles as the mesh is refined.

use crate::common;
use common::*;
use signorini::mesh::dist;
use signorini::problems::Ex72;

#[test]
fn ex72_is_symmetric_about_the_wedge_tip() {
    let p = Ex72;
    let m = mesh(&p, "symmetric:24");
    let sol = solve_on(&p, &m);
    let scale = sol.u.iter().fold(0.0f64, |a, u| a.max(u[0].abs()).max(u[1].abs()));
    let mut checked = 0;
    for (i, x) in sol.nodes.coords.iter().enumerate() {
        let mirror = [x[0], 1.0 - x[1]];
        let j = sol.nodes.coords.iter().position(|y| dist(*y, mirror) < 1e-12).expect("mirror node exists");
        assert!((sol.u[i][0] - sol.u[j][0]).abs() < 1e-12 * scale, "u1 even at {x:?}");
        assert!((sol.u[i][1] + sol.u[j][1]).abs() < 1e-12 * scale, "u2 odd at {x:?}");
        checked += 1;
    }
    assert_eq!(checked, sol.nodes.len());
    // the active set is symmetric too
    let zone = sol.contact_zone().unwrap();
    assert!((zone[0] - (1.0 - zone[1])).abs() < 1e-12, "zone {zone:?}");
}

#[test]
fn ex72_contact_zone_settles() {
    let p = Ex72;
    let mut zones = Vec::new();
    for n in [16usize, 32, 64, 128] {
        let sol = solve_on(&p, &mesh(&p, &format!("structured:{n}")));
        zones.push((1.0 / n as f64, sol.contact_zone().unwrap()));
    }
    // the zone is about (0.18, 0.82) and moves by at most a few mesh sizes between levels
    for w in zones.windows(2) {
        let ((h, a), (_, b)) = (w[0], w[1]);
        assert!((a[0] - b[0]).abs() <= 2.0 * h && (a[1] - b[1]).abs() <= 2.0 * h, "zone moved from {a:?} to {b:?}");
    }
    let last = zones.last().unwrap().1;
    assert!((0.15..0.2).contains(&last[0]) && (0.8..0.85).contains(&last[1]), "zone {last:?}");
}
