//! Run records and where they are kept, without the solver: what a run stores and how it is
//! written (atomically, journaled), the manifests that declare studies, the results folder that
//! holds their runs, and their provenance. The figures and the claims read results through this
//! crate alone; the runner (`signorini-harness`) writes them through it.
//!
//! Floors, top first; code uses only its own floor and the floors below, and the model crate
//! (`tests/it/layers.rs` checks the floors inside this crate, the compiler the crates):
//!
//! ```text
//!   study/            manifests, the results folder's store, provenance, complete or not
//!   records/          run records; atomic writes, the journal
//! ```

// `!(x > 0.0)` is how this crate rejects NaN together with the out-of-range values, on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod records;
pub mod study;
