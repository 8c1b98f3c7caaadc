//! signorini: a P2 finite element harness for the Signorini contact problem and its
//! supremum-norm a posteriori error estimator (Khandelwal, Porwal, Wadhawan).
//!
//! The crate is built in floors, one folder each; code uses only its own floor and the floors
//! below (`tests/it/layers.rs` checks it, and that no two files use each other):
//!
//! ```text
//!   main.rs, bin/     the command line, the benchmark
//!   plot/             figures and study pages, from records only
//!   analysis/         rates, verdict rules, the claims of Section 7, Hertz
//!   study/            manifests, runner, store, references, provenance, drift
//!   records/          run and solve records; atomic writes
//!   adapt/            SOLVE -> ESTIMATE -> MARK -> REFINE, level records, replaying a refinement history
//!   estimator/        eta_1 .. eta_7 and their variants
//!   contact/          active-set method, the SOLVE step, KKT certificate, error norms
//!   fem/              P2 unknowns, element stiffness, assembly
//!   sparse/           symmetric CSC, orderings, symbolic and numeric Cholesky
//!   mesh/             triangulations, refinement, Gmsh, point location
//!   problems/         the Problem trait, boundary parts, built-ins, problem files
//!   base/             reference element, statistics, memory
//! ```
//!
//! Three entry points: [`solve::solve`] (one discrete solution on a mesh, certified by its KKT
//! conditions), [`adapt::run`] (the adaptive loop) and [`study::run_study`] (a declared study
//! into its results folder). Every module has one path in the crate (`crate::contact::solve`);
//! the most used keep a short name at the root for users, examples and tests
//! (`signorini::solve`, `signorini::estimate`, `signorini::cholesky`), which code inside the
//! crate never uses (`tests/it/layers.rs` reads the `pub use` lines below and checks it).

// `!(x > 0.0)` is how this crate rejects NaN together with the out-of-range values, on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod adapt;
pub mod analysis;
pub mod base;
pub mod contact;
pub mod estimator;
pub mod fem;
pub mod mesh;
pub mod plot;
pub mod problems;
pub mod records;
pub mod sparse;
pub mod study;

// The users' prelude: short names at the root (`signorini::solve`, `signorini::estimate`) for
// examples, tests and user programs; inside the crate only the full paths (`crate::contact::solve`).
pub use analysis::{claims, hertz, verdict};
pub use base::{element, memory};
pub use contact::{certify, norms, solve};
pub use estimator::estimate;
pub use fem::assembly;
pub use plot::page;
pub use records::report;
pub use sparse::{cholesky, ordering, symbolic};
