//! The commands that read stored results only, as a library: `figures` ([`figures::run`],
//! [`figures::draw`]) with the declared studies read once ([`workspace::Workspace`]), the
//! places a command may write and read ([`places`]), and how the binaries print ([`output`]).
//! The `signorini` binary re-exports them among its commands; `signorini-figures` is `figures`
//! built without the solver.

/// A note on standard error that a failed write cannot stop ([`model::base::note::line`]).
macro_rules! note {
    ($($arg:tt)*) => { model::base::note::line(format_args!($($arg)*)) };
}

pub mod figures;
pub mod output;
pub mod places;
pub mod workspace;
