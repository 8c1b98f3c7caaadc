//! The repaired contact terms (`contact_term = "tensile_on_full_contact"`, src/estimate/repair.rs):
//! eta_5 keeps the tensile normal stress at full-contact nodes, which the variant without
//! full-contact nodes drops; eta_7 is taken over a subset of the paper's Lambda_h^C.

use signorini::adapt::{self, AdaptConfig, Level, Refine};
use signorini::contact::PdasOptions;
use signorini::estimate::{self, ContactTerm, Estimate, EstimatorConfig};
use signorini::mesh::{Mesh, MeshSpec};
use signorini::problems::{Ex71, Fb, Problem};
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
/// paper's |sigma_nn| is at least as large.
#[test]
fn repaired_eta5_sees_tension_on_full_contact_patches() {
    let config = AdaptConfig {
        levels: 12,
        max_ndof: None,
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
