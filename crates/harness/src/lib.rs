//! The harness above the solver and the store: the runner of declared studies, their reference
//! solutions, the drift check, and what a solve reports. The records, manifests and the results
//! folder's store are the store crate's (`signorini-store`: `records`, `study::manifest`,
//! `study::store`).
//!
//! Floors, top first; code uses only its own floor and the floors below, and the crates below
//! (`tests/it/layers.rs` checks the floors inside this crate, the compiler the crates):
//!
//! ```text
//!   study/            runner, references, drift, accepting a rerun
//!   report/           the solve report (`signorini solve --json`, VTU files)
//! ```
//!
//! Entry point: [`study::run_study`] (a declared study into its results folder).

// `!(x > 0.0)` is how this crate rejects NaN together with the out-of-range values, on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod report;
pub mod study;
