//! The `fem/` floor (above `sparse/`): the finite element discretisation: the unknowns of the P2
//! space, the element stiffness, the assembled system K u = F with Dirichlet data eliminated, and K
//! u element by element ([`assembly`]). May import: `base`, `problems`, `mesh`, `sparse`.

pub mod assembly;
