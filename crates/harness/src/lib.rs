//! The harness above the numerics: what a run and a solve report hold and how they are written
//! (atomically, journaled), the store of a results folder, studies declared in manifests, their
//! runner, reference solutions, provenance and the drift check.
//!
//! Floors, top first; code uses only its own floor and the floors below, and the numerics crate
//! (`tests/it/layers.rs` checks the floors inside this crate, the compiler the crates):
//!
//! ```text
//!   study/            manifests, runner, store, references, provenance, drift
//!   records/          run and solve records; atomic writes, the journal
//! ```
//!
//! Entry point: [`study::run_study`] (a declared study into its results folder).

// `!(x > 0.0)` is how this crate rejects NaN together with the out-of-range values, on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod records;
pub mod study;
