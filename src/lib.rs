//! signorini: a P2 finite element harness for the Signorini contact problem and its
//! supremum-norm a posteriori error estimator (Khandelwal, Porwal, Wadhawan).
//!
//! Data flows one way: `problems` and `mesh` describe a case, `assembly` builds the linear
//! elasticity system, `contact` solves the discrete variational inequality (paper eq. 3.4),
//! `solve` ties them into the SOLVE step, `norms` measures errors.

// `!(x > 0.0)` is how this crate rejects NaN together with the out-of-range values, on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod adapt;
pub mod assembly;
pub mod certify;
pub mod cholesky;
pub mod claims;
pub mod contact;
pub mod element;
pub mod estimate;
pub mod hertz;
pub mod memory;
pub mod mesh;
pub mod norms;
pub mod ordering;
pub mod page;
pub mod plot;
pub mod problems;
pub mod records;
pub mod report;
pub mod solve;
pub mod study;
pub mod symbolic;
pub mod verdict;
