//! The repaired contact terms (`contact_term = "tensile_on_full_contact"`, src/estimate/repair.rs):
//! eta_5 keeps the tensile normal stress at full-contact nodes, which the variant without
//! full-contact nodes drops; eta_7 is taken over a subset of the paper's Lambda_h^C.

use signorini::adapt::{self, Level};
use signorini::estimate::{self, Estimate};
use signorini::mesh::{Mesh, MeshSpec};
use signorini::problems::{Ex71, Fb, Problem};
use signorini::settings::adapt::{AdaptConfig, Refine};
use signorini::settings::estimator::{ContactTerm, EstimatorConfig};
use signorini::settings::pdas::PdasOptions;
use std::ops::ControlFlow;

fn estimates(problem: &dyn Problem, mesh: &str) -> (Mesh, [Estimate; 3]) {
    let mesh = MeshSpec::parse(mesh).unwrap().build(problem).unwrap();
    let sol = signorini::solve::solve(&mesh, problem, &PdasOptions::default(), &mut |_| {}).unwrap();
    let with = |contact_term| estimate::estimate(&mesh, problem, &sol, &EstimatorConfig { contact_term, ..Default::default() });
    let e = [with(ContactTerm::AsWritten), with(ContactTerm::WithoutFullContact), with(ContactTerm::TensileOnFullContact)];
    (mesh, e)
}

/// On fb's adaptive meshes the discrete normal stress is tensile somewhere on a full-contact
/// patch (near the free boundary, where the true contact pressure ((x - a)_+)^(5/2) is tiny): the
/// repaired eta_5 sees it there, the variant without full-contact nodes is blind to it, and the
/// paper's |sigma_nn| is at least as large. The full-contact edges all lie in the true contact
/// zone [a, 1]: the tension is not an overshoot of the active set.
#[test]
fn repaired_eta5_sees_tension_on_full_contact_patches() {
    let config = AdaptConfig {
        levels: 12,
        max_ndof: None,
        stop_ndof: None,
        refine: Refine::Adaptive,
        theta: 0.5,
        estimator: EstimatorConfig { contact_term: ContactTerm::TensileOnFullContact, ..Default::default() },
        pdas: PdasOptions::default(),
        warm_start: true,
    };
    let mesh = MeshSpec::parse("structured:4").unwrap().build(&Fb).unwrap();
    let mut tensile_levels = Vec::new();
    adapt::run(&Fb, mesh, &config, None, &mut |level: Level| {
        let with =
            |contact_term| estimate::estimate(level.mesh, &Fb, level.solution, &EstimatorConfig { contact_term, ..Default::default() });
        let (written, without, repaired) = (with(ContactTerm::AsWritten), with(ContactTerm::WithoutFullContact), level.estimate);
        let l = level.record.level;
        assert_eq!(without.eta5_full_contact, 0.0, "level {l}");
        assert!(repaired.eta5_full_contact <= written.eta5_full_contact, "level {l}: (s)^+ <= |s|");
        assert!(repaired.terms.eta5 >= without.terms.eta5 && repaired.terms.eta5 <= written.terms.eta5, "level {l}");
        if repaired.eta5_full_contact > 0.0 {
            tensile_levels.push(l);
        }
        // no overshoot: every full-contact node lies in the true contact zone [a, 1]
        let sol = level.solution;
        let active = |q: usize| sol.dofs.contact_index[q].is_some_and(|k| sol.active[k]);
        for (bi, bn) in sol.nodes.boundary_nodes.iter().enumerate() {
            if level.mesh.boundary[bi].part == signorini::problems::Part::Contact && bn.iter().all(|&q| active(q)) {
                for &q in bn {
                    let x = sol.nodes.coords[q][0];
                    assert!(x >= Fb::A - 1e-12, "level {l}: a full-contact edge reaches x = {x} < a = {}", Fb::A);
                }
            }
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    assert!(tensile_levels.len() >= 6, "tension on a full-contact patch at levels {tensile_levels:?} only (of 12)");
}

/// Example 7.1 is pressed along all of Gamma_C: the normal stress is compressive on every
/// full-contact patch, so the repaired eta_5 there is exactly zero, like the variant's.
#[test]
fn repaired_eta5_vanishes_under_compression() {
    let (_, [written, without, repaired]) = estimates(&Ex71, "structured:16");
    assert!(written.eta5_full_contact > 0.0);
    assert_eq!(repaired.eta5_full_contact, 0.0);
    assert_eq!(repaired.terms.eta5, without.terms.eta5);
}

/// Lambda_h^C,r is a subset of the paper's Lambda_h^C, so the repaired eta_7 is never larger;
/// everything else but eta_5 and eta_7 is the same estimator.
#[test]
fn repaired_eta7_is_taken_over_a_subset() {
    for (problem, mesh) in [(&Fb as &dyn Problem, "structured:8"), (&Fb, "structured:32"), (&Ex71, "structured:16")] {
        let (_, [written, _, repaired]) = estimates(problem, mesh);
        let (w, r) = (written.terms, repaired.terms);
        assert!(r.eta7 <= w.eta7, "{mesh}: {} > {}", r.eta7, w.eta7);
        assert_eq!([w.eta1, w.eta2, w.eta3, w.eta4, w.eta6], [r.eta1, r.eta2, r.eta3, r.eta4, r.eta6], "{mesh}");
        for (t, (a, b)) in written.element.iter().zip(&repaired.element).enumerate() {
            assert!(b <= a, "{mesh}: element {t}: repaired indicator {b} above the paper's {a}");
        }
    }
}

/// Where the search for an overshoot stands: on uniform meshes no problem tried has tension on a
/// full-contact patch, not Example 7.2, not fb, not the blister (`experiments/problems/blister.toml`,
/// a lift-off inside a contact zone), so the repaired eta_5 equals the variant's there. (On a
/// full-contact edge the nodal contact forces are, up to the volume and jump residuals, h/6 times
/// the vertex values of the linear sigma_nn(u_h) and 2h/3 times its mean: positive forces make it
/// compressive along the edge.) The tension fb's adaptive meshes show (test above) is the one
/// found so far; this test fails when a change of the solver or the estimator makes one appear.
#[test]
fn no_tension_on_full_contact_patches_of_uniform_meshes() {
    let blister =
        signorini::problems::load(&format!("{}/experiments/problems/blister.toml", env!("CARGO_MANIFEST_DIR")), &Default::default())
            .unwrap();
    for problem in [&signorini::problems::Ex72 as &dyn Problem, &Fb, blister.as_ref()] {
        for n in [4, 8, 16, 32] {
            let mesh = format!("structured:{n}");
            let (_, [written, without, repaired]) = estimates(problem, &mesh);
            assert!(repaired.full_contact_nodes > 0 && written.eta5_full_contact > 0.0, "{} {mesh}", problem.name());
            assert_eq!(repaired.eta5_full_contact, 0.0, "{} {mesh}: tension on a full-contact patch", problem.name());
            assert_eq!(repaired.terms.eta5, without.terms.eta5, "{} {mesh}", problem.name());
        }
    }
}
