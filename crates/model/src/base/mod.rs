//! The `base/` floor (the lowest): what every floor above uses and that uses nothing of the crate:
//! the reference triangle ([`element`]: P2 basis, affine maps, Gauss rules, sampling lattices),
//! content hashes ([`digest`]), the crash points of the writers' tests ([`failpoint`]) and
//! the memory a solve needs and may still allocate ([`memory`]), the one reader of a user's input
//! file ([`input`]: a regular file of bounded size, never a pipe or a device), least-squares lines with
//! confidence intervals ([`stats`]), and notes to standard error that a failed write cannot stop
//! ([`note`]), numbers shown in messages at any magnitude ([`number`]), and TOML errors in the files' words ([`toml_text`]).

pub mod digest;
pub mod element;
pub mod failpoint;
pub mod input;
pub mod memory;
pub mod note;
pub mod number;
pub mod pin;
pub mod stats;
pub mod toml_text;
