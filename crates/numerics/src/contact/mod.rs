//! The `contact/` floor (above `fem/`): the SOLVE step. The primal–dual active set method on the
//! assembled system ([`active_set`], whose items, named below, are the floor's front door), one
//! discrete Signorini solution with its contact force ([`solve`]), the checks that its contact data
//! make physical sense ([`plausible`]), that its exact solution is one ([`consistent`]), the certificate of its KKT conditions ([`certify`]) and the
//! L-infinity norms of its error ([`norms`]). May import: `base`, `problems`, `mesh`, `sparse`,
//! `fem`.

pub mod active_set;
pub mod certify;
mod chord;
pub mod consistent;
pub mod norms;
pub mod plausible;
pub mod point;
pub mod solve;

pub use active_set::{ContactError, ContactSolver, NormalIterate, Pair, PdasIteration, PdasOutput, PdasTermination, Timings, pdas};
