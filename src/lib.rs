//! signorini: a P2 finite element harness for the Signorini contact problem and its
//! supremum-norm a posteriori error estimator (Khandelwal, Porwal, Wadhawan).
//!
//! The workspace is built in floors; each crate is one or more of them, and a crate uses only
//! the crates below it (the compiler keeps that; `tests/it/layers.rs` keeps the floors inside a
//! crate). Top first:
//!
//! ```text
//!   signorini            main.rs, bin/: the command line, the benchmark; this prelude
//!   signorini-harness    study/, report/: the runner, references, drift; the solve report
//!   signorini-claims     commands/, plot/, analysis/: figures (also as `signorini-figures`, built
//!                        without the solver), study pages, verdict rules, Section 7's claims
//!   signorini-numerics   adapt/, estimator/, contact/, fem/, sparse/: the solver
//!   signorini-store      study/, records/: manifests, the results folder's store; run records
//!   signorini-model      level/, settings/, mesh/, problems/, base/
//! ```
//!
//! Three entry points: [`solve::solve`] (one discrete solution on a mesh, certified by its KKT
//! conditions), [`adapt::run`] (the adaptive loop) and [`study::run_study`] (a declared study
//! into its results folder); every command of the command line is a function of [`commands`].
//! This crate re-exports every floor under its own name
//! (`signorini::mesh`, `signorini::study`) and the most used modules under a short one
//! (`signorini::solve`, `signorini::estimate`, `signorini::cholesky`): the users' prelude, for
//! examples, tests and user programs. Code inside the crates never uses it. The store's `study/`
//! shares its name with the harness's `signorini::study`; its modules are here under their own
//! names (`signorini::manifest`, `signorini::store`, `signorini::provenance`).

pub mod commands;

pub use signorini_claims::{analysis, plot};
pub use signorini_harness::{report, study};
pub use signorini_model::{base, level, mesh, problems, settings};
pub use signorini_numerics::{adapt, contact, estimator, fem, sparse};
pub use signorini_store::records;
pub use signorini_store::study::{check_complete, manifest, provenance, store};

pub use analysis::{claims, hertz, verdict};
pub use base::{element, memory};
pub use contact::{certify, norms, solve};
pub use estimator::estimate;
pub use fem::assembly;
pub use plot::page;
pub use sparse::{cholesky, ordering, symbolic};
