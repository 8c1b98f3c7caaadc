//! The repaired contact terms (`contact_term = "tensile_on_full_contact"`, beyond the paper).
//!
//! Measured in the `contact_term_ablation` and `fb` studies: eta_5 taken over all contact nodes
//! (eq. 6.3 as written) decays only like h, because at a node in full contact the normal stress
//! n . sigma(u_h) n is the discrete contact pressure, of size O(1), not an error. Dropping eta_5
//! at full-contact nodes (Krause, Veeser and Walloth's energy-norm estimator) removes that, but is
//! blind where the discrete active set overshoots the true one: there sigma_nn(u_h) can be
//! tensile on a patch in full contact, which no exact solution allows.
//!
//! The repair keeps the sign information:
//!
//! ```text
//! eta_{5,p} = h_p ||(n . sigma(u_h) n)^+||_Linf(Gamma_{p,C})   p in N_h^FC (full contact),
//! eta_{5,p} = h_p ||n . sigma(u_h) n||_Linf(Gamma_{p,C})       other contact nodes (as written),
//! eta_7     = ||(chi - u_h.n)^+||_Linf(Lambda_h^C,r),
//! Lambda_h^C,r = full-contact edges  U  edges through an isolated node with positive lambda_p.
//! ```
//!
//! Why it can be reliable and efficient. The contact term enters the proof of Theorem 6.1 twice:
//! through the sign of the quasi-discrete contact force lambda_p (Lemma 5.8) and through the set
//! Gamma-bar_{p,C} on which the gap is measured, which (5.10) and Lemma 5.3 let one choose inside
//! Gamma_{p,C}. On a full-contact patch the compressive part of sigma_nn(u_h) can be absorbed into
//! the contact force (as Krause, Veeser and Walloth do in the energy norm, and Nochetto, Siebert
//! and Veeser for the obstacle problem in the maximum norm); since sigma_nn(u) <= 0 on Gamma_C,
//! (sigma_nn(u_h))^+ <= |sigma_nn(u_h) - sigma_nn(u)| there, so the kept term is bounded by the
//! error of the stress (efficiency). Narrowing Lambda_h^C: on the edge that straddles the free
//! boundary (one end active, the other not) chi - u_h.n is the true gap of the exact solution, of
//! size h_fb^(3/2) on the `fb` problem, not an error of u_h; only edges where the discrete
//! solution claims contact along the whole edge, or at a contact point of its own, are kept.
//!
//! Open step (not proved here): reliability needs the volume and jump part of lambda_p to keep
//! its sign on full-contact patches once the compressive normal stress is moved into the contact
//! force; the studies test it numerically (`estimator_repair`), they do not prove it.

use crate::contact::solve::DiscreteSolution;
use model::mesh::Mesh;
use model::problems::Part;

/// Lambda_h^C,r per boundary edge of `mesh` (in `Mesh::boundary` order): a contact edge whose
/// three nodes are all active (a full-contact edge), or one through a node with positive
/// discrete contact force (`positive`) that lies on no full-contact edge (an isolated node).
pub fn narrow_lambda(mesh: &Mesh, sol: &DiscreteSolution, positive: &dyn Fn(usize) -> bool) -> Vec<bool> {
    let nodes = &sol.nodes;
    let active = |q: usize| sol.dofs.contact_index[q].is_some_and(|k| sol.active[k]);
    let contact = |bi: usize| mesh.boundary[bi].part == Part::Contact;
    let full_edge: Vec<bool> =
        (0..mesh.boundary.len()).map(|bi| contact(bi) && nodes.boundary_nodes[bi].iter().all(|&q| active(q))).collect();
    let mut on_full = vec![false; nodes.len()];
    for (bi, _) in full_edge.iter().enumerate().filter(|(_, f)| **f) {
        for &q in &nodes.boundary_nodes[bi] {
            on_full[q] = true;
        }
    }
    let isolated = |q: usize| positive(q) && !on_full[q];
    (0..mesh.boundary.len()).map(|bi| contact(bi) && (full_edge[bi] || nodes.boundary_nodes[bi].iter().any(|&q| isolated(q)))).collect()
}
