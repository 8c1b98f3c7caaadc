//! What a solve and the adaptive loop are told: the estimator's settings ([`estimator`]), the
//! active-set method's ([`pdas`]), the loop's ([`adapt`]) and where the norms are sampled
//! ([`sampling`]), and the ordering a process may be forced to ([`ordering`]).

pub mod adapt;
pub mod estimator;
pub mod ordering;
pub mod pdas;
pub mod sampling;
