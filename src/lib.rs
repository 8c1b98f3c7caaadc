//! signorini: a P2 finite element harness for the Signorini contact problem and its
//! supremum-norm a posteriori error estimator (Khandelwal, Porwal, Wadhawan).

pub mod element;
pub mod mesh;
