//! Why a record file could not be read or written. The functions of `records` return
//! `std::io::Result` (their callers mix them with other file operations); the error inside is a
//! [`RecordError`] (`io::Error::get_ref` and `downcast_ref` reach it), its kind the failed
//! operation's, its message naming the file and the step.

use super::NonFinite;
use std::path::PathBuf;

/// A record file that could not be read, parsed, serialised or written.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// A file operation failed: `step` says which ("reading", "creating the directory", ...).
    #[error("{step} {}: {error}", path.display())]
    Io { step: &'static str, path: PathBuf, error: std::io::Error },
    /// The file is not the JSON of the record it should hold.
    #[error("{}: {error}", path.display())]
    Parse { path: PathBuf, error: serde_json::Error },
    /// The value could not be serialised.
    #[error("serialising {}: {error}", path.display())]
    Serialise { path: PathBuf, error: serde_json::Error },
    /// A float JSON cannot hold: the file is not written.
    #[error("not writing {}: {bad} (JSON cannot hold it, and the file could not be read back)", path.display())]
    NonFinite { path: PathBuf, bad: NonFinite },
    /// A mesh snapshot whose bytes are not those its run's record holds the SHA-256 of (edited,
    /// swapped with another run's, or from before records held the hashes).
    #[error("{}: {}", path.display(), snapshot_mismatch(run, held.as_deref(), found))]
    Snapshot { path: PathBuf, run: String, held: Option<String>, found: String },
}

fn snapshot_mismatch(run: &str, held: Option<&str>, found: &str) -> String {
    match held {
        Some(held) => format!(
            "sha256 {} is not the {} that the record of run {run} holds for it: the snapshot was edited or is another run's",
            &found[..12],
            &held[..held.len().min(12)]
        ),
        None => format!("the record of run {run} holds no sha256 for it (sha256 {} found)", &found[..12]),
    }
}

impl RecordError {
    /// The failed file operation `step` on `path` (its kind is kept).
    pub fn io(step: &'static str, path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> std::io::Error {
        let path = path.into();
        move |error| RecordError::Io { step, path, error }.into()
    }

    /// A parse error of the file `path`.
    pub fn parse(path: impl Into<PathBuf>) -> impl FnOnce(serde_json::Error) -> std::io::Error {
        let path = path.into();
        move |error| RecordError::Parse { path, error }.into()
    }
}

impl From<RecordError> for std::io::Error {
    fn from(e: RecordError) -> Self {
        let kind = match &e {
            RecordError::Io { error, .. } => error.kind(),
            RecordError::NonFinite { .. } | RecordError::Snapshot { .. } => std::io::ErrorKind::InvalidData,
            RecordError::Parse { .. } | RecordError::Serialise { .. } => std::io::ErrorKind::Other,
        };
        std::io::Error::new(kind, e)
    }
}
