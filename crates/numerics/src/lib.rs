//! The numerics of the signorini harness: a conforming P2 finite element method for 2D linear
//! elasticity with frictionless unilateral contact, solved by a primal–dual active set method,
//! the supremum-norm a posteriori estimator of Khandelwal, Porwal and Wadhawan, and the adaptive
//! loop SOLVE -> ESTIMATE -> MARK -> REFINE. Nothing here knows of studies or results folders.
//! Problems, meshes, settings and level records are the model crate's (`signorini-model`), named
//! there (`model::level::record::LevelRecord`, `model::settings::pdas::PdasOptions`,
//! `model::settings::estimator::EstimatorConfig`).
//!
//! Floors, one folder each, top first; code uses only its own floor and the floors below
//! (`tests/it/layers.rs` checks it, and that no two files use each other):
//!
//! ```text
//!   adapt/            SOLVE -> ESTIMATE -> MARK -> REFINE, level records, replaying a refinement history
//!   estimator/        eta_1 .. eta_7 and their variants
//!   contact/          active-set method, the SOLVE step, KKT certificate, error norms
//!   fem/              P2 unknowns, element stiffness, assembly
//!   sparse/           symmetric CSC, orderings, symbolic and numeric Cholesky
//!   (signorini-model) base, problems, mesh, settings, level records
//! ```
//!
//! Two entry points: [`contact::solve::solve`] (one discrete solution on a mesh, certified by its
//! KKT conditions) and [`adapt::run`] (the adaptive loop).

// `!(x > 0.0)` is how this crate rejects NaN together with the out-of-range values, on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod adapt;
pub mod contact;
pub mod estimator;
pub mod fem;
pub mod sparse;
