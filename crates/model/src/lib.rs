//! What the signorini harness computes with and records, without the solver: problems and
//! their data, meshes (Gmsh input, refinement, snapshots), the settings of a solve and of the
//! adaptive loop, and what a level of the loop leaves behind. The figures, the claims and the
//! store of results are built on this crate alone; the solver (`signorini-numerics`) above it.
//!
//! Floors, one folder each, top first; code uses only its own floor and the floors below
//! (`tests/it/layers.rs` checks it, and that no two files use each other):
//!
//! ```text
//!   level/            a level's record, its estimator terms, contact samples, the refinement history
//!   settings/         the estimator's, the active-set method's and the loop's settings, sampling
//!   mesh/             triangulations, refinement, Gmsh, point location
//!   problems/         the Problem trait, boundary parts, built-ins, problem files
//!   base/             reference element, statistics, memory, input files, notes
//! ```
// `!(x > 0.0)` is how this crate rejects NaN together with the out-of-range values, on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod base;
pub mod level;
pub mod mesh;
pub mod problems;
pub mod settings;
