//! The `analysis/` floor (above `study/`): what the stored records say. Rates with confidence
//! intervals and the verdict rules ([`verdict`]), the claims of the paper's Section 7 and the
//! checks beyond it ([`claims`]), and Hertz's contact solution ([`hertz`]). Reads records only; may
//! import every floor below (`study` for the stored problem of a run).

pub mod claims;
pub mod hertz;
pub mod roles;
pub mod verdict;
