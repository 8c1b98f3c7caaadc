//! The `estimator/` floor (above `contact/`): the paper's supremum-norm a posteriori estimator,
//! eta_1 .. eta_7, its declared variants and the repaired contact terms ([`estimate`]). May import
//! every floor below.

pub mod estimate;
