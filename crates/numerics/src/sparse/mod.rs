//! The `sparse/` floor (above `mesh/`): sparse linear algebra, nothing of finite elements.
//! Symmetric matrices stored by their lower triangle ([`csc`]), fill-reducing orderings
//! ([`ordering`]), the symbolic supernodal Cholesky structure ([`symbolic`]) and the numeric
//! factorisation and solves ([`cholesky`]); [`anatomy`] runs their pieces one at a time for the
//! bench. May import: `base`, `mesh` (the node graph an ordering is computed on).

pub mod anatomy;
pub mod cholesky;
pub mod csc;
pub mod etree;
pub mod ordering;
pub mod symbolic;
