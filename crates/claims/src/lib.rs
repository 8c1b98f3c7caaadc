//! The paper's claims and figures, from stored records only: rates and their verdict rules, the
//! rows of Section 7, Hertz's solution, the figures and the study pages.
//!
//! Floors, top first (`tests/it/layers.rs` checks them):
//!
//! ```text
//!   bin/              signorini-figures: the figures command without the solver
//!   commands/         the figures command, the places a command may use, printing
//!   plot/             figures and study pages, from records only
//!   analysis/         rates, verdict rules, the claims of Section 7, Hertz
//! ```

// `!(x > 0.0)` is how this crate rejects NaN together with the out-of-range values, on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod analysis;
pub mod commands;
pub mod plot;
