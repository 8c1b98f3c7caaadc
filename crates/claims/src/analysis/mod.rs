//! The `analysis/` floor (above `study/`): what the stored records say. Rates with confidence
//! intervals and the verdict rules ([`verdict`]), the claims of the paper's Section 7 and the
//! checks beyond it ([`claims`]), and Hertz's contact solution ([`hertz`]); the studies and runs
//! they read are named once ([`studies`], [`roles`], [`problem_names`]). Reads records only; may
//! import every floor below (`study` for the stored problem of a run).

pub mod claims;
pub mod hertz;
pub mod problem_names;
pub mod roles;
pub mod studies;
pub mod verdict;
