//! `SIGNORINI_ORDERING` forces the ordering of every factorisation in the process (the round-off
//! measurement, `make roundoff`), except inside `ordering::automatic`, where the reference
//! solutions of a study are computed. A test binary of its own: the variable is read once per
//! process, and this is its only test.

use signorini::assembly::{self, DofMap};
use signorini::mesh::{MeshSpec, P2Nodes};
use signorini::ordering::{self, fill_reducing};
use signorini::problems::Ex72;
use signorini::settings::ordering::{FORCE_ENV, Method};

#[test]
fn a_forced_ordering_applies_outside_automatic_only() {
    // SAFETY: set before anything in this process reads the environment or starts a thread
    // (the one test of this binary, first statement)
    unsafe { std::env::set_var(FORCE_ENV, "minimum-degree") };
    // a uniform mesh: nested dissection needs about half the flops of AMD, so the automatic
    // choice differs from the forced one
    let mesh = MeshSpec::parse("structured:48").unwrap().build(&Ex72).unwrap();
    let nodes = P2Nodes::new(&mesh);
    let dofs = DofMap::new(&nodes, &Ex72);
    let sys = assembly::assemble(&mesh, &nodes, &dofs, &Ex72);
    let coords = dofs.unknown_coords(&nodes);
    let order = || fill_reducing(&sys.matrix, dofs.n_interior, &coords).1;
    let forced = order();
    assert_eq!(forced.method, Method::MinimumDegree, "{forced:?}");
    let automatic = ordering::automatic(order);
    assert!(automatic.flops_nested_dissection < automatic.flops_minimum_degree.unwrap(), "{automatic:?}");
    assert_eq!(automatic.method, Method::NestedDissection, "{automatic:?}");
    // and forced again after it
    assert_eq!(order().method, Method::MinimumDegree);
}
