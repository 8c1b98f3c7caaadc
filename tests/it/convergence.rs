//! Example 7.1 on structured meshes: the observed L-infinity rate in h is at least 2.85 on the
//! finest pairs (NDF^(-3/2)), and the active set is the whole contact boundary.

use crate::common;
use common::*;
use signorini::norms;
use signorini::problems::{Ex71, Exact};

#[test]
fn ex71_linf_rates_on_structured_meshes() {
    let p = Ex71;
    let mut rows = Vec::new();
    for n in [4usize, 8, 16, 32, 64] {
        let m = mesh(&p, &format!("structured:{n}"));
        let sol = solve_on(&p, &m);
        assert_eq!(sol.active_count(), sol.dofs.contact.len(), "N={n}: the whole of Gamma_C is in contact");
        let e = norms::linf_error(&m, &sol, &|x| p.u(x));
        rows.push((1.0 / n as f64, e));
    }
    for w in rows.windows(2).skip(2) {
        let ((h1, e1), (h2, e2)) = (w[0], w[1]);
        for (name, a, b) in [("quadrature", e1.linf_quadrature, e2.linf_quadrature), ("dense", e1.linf_dense, e2.linf_dense)] {
            let r = rate(a, b, h1, h2);
            assert!(r >= 2.85, "{name} rate {r:.3} between h = {h1} and {h2}");
            assert!(r <= 3.3, "{name} rate {r:.3}: faster than P2 can be, something is off");
        }
    }
    // the nodal maximum is not the L-infinity norm: it is smaller
    let last = rows.last().unwrap().1;
    assert!(last.linf_nodal < last.linf_quadrature && last.linf_quadrature <= last.linf_dense * 1.0001);
}
