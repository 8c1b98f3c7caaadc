//! The commands of `signorini`, as a library: what each command checks, computes and writes,
//! with the policies that keep a user's work (which outputs may be overwritten, which places
//! are refused, when a reader waits), so that a program can drive a study, the drift check or
//! the figures without the command line. `main.rs` only parses the flags into these options
//! and prints what comes back.
//!
//! | command | function |
//! | --- | --- |
//! | `solve`, `export` | [`solve::solve`], [`solve::export`] |
//! | `adapt` | [`adapt::run`], with an [`adapt::AdaptObserver`] |
//! | `run` | [`run::run_studies`] |
//! | `drift` | [`drift::check`], then [`drift::Checked`]'s tables, report and outcome |
//! | `figures` | [`figures::draw`] |
//! | `report` | [`report::write`] |
//!
//! A program that checks one study against its stored results and redraws the figures, as
//! `signorini drift --study ex71` and `signorini figures` do:
//!
//! ```no_run
//! use signorini::commands::{drift, figures};
//! let request = drift::DriftRequest {
//!     only: vec!["ex71".into()],
//!     experiments: "experiments".into(),
//!     results: "results".into(),
//!     ..Default::default()
//! };
//! if let drift::Drift::Checked(checked) = drift::check(&request)? {
//!     print!("{}", checked.tables());
//!     checked.write_report()?;
//!     for line in checked.outcome()? {
//!         println!("{line}");
//!     }
//! }
//! let workspace = signorini::commands::workspace::Workspace::load("experiments".as_ref())?;
//! let written = figures::draw(None, None, &workspace, &[], false)?;
//! println!("{} files written", written.len());
//! # Ok::<(), anyhow::Error>(())
//! ```
//!
//! `figures`, `report` and `drift` read the declared studies once, as a
//! [`workspace::Workspace`].
//!
//! Notes for the user (a note, a warning) go to standard error through
//! [`crate::base::note::line`]; what a command prints on standard output comes back as values.

/// A note on standard error that a failed write cannot stop ([`crate::base::note::line`]).
macro_rules! note {
    ($($arg:tt)*) => { $crate::base::note::line(format_args!($($arg)*)) };
}

pub mod adapt;
pub mod drift;
pub mod report;
pub mod run;
pub mod solve;
pub mod threads;

// the commands that read stored results only, from the claims crate (`signorini-figures` is built
// from them without the solver)
pub use signorini_claims::commands::{figures, output, places, workspace};
