//! Input files pinned to the bytes a study planned a run with: while a run computes, every read
//! of one of its input files ([`super::input::read`], the one reader) must give the bytes whose
//! SHA-256 the run's spec holds, so the hash a record stores is the hash of the very bytes the
//! run parsed. A file edited after the study was planned (while an earlier run computed) is
//! refused by name when the run reads it, never computed and stored under the planned hash.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

/// One pinned file: whose guard pinned it, where it is (canonical where it exists), its SHA-256.
struct Pinned {
    guard: u64,
    path: PathBuf,
    sha256: String,
}

static PINNED: Mutex<Vec<Pinned>> = Mutex::new(Vec::new());
static NEXT: AtomicU64 = AtomicU64::new(1);

/// A file read with other bytes than its pin's.
#[derive(Debug, thiserror::Error)]
#[error(
    "the input file {file} changed while the study ran: planned sha256 {planned}, read {read}; nothing was computed from it. Run the study again (its spec now names the new bytes)"
)]
pub struct Changed {
    pub file: String,
    pub planned: String,
    pub read: String,
}

/// The files of a run, pinned until the guard is dropped.
#[must_use = "the files are pinned only while the guard lives"]
pub struct Pins {
    guard: u64,
}

impl Drop for Pins {
    fn drop(&mut self) {
        pinned().retain(|p| p.guard != self.guard);
    }
}

fn pinned() -> std::sync::MutexGuard<'static, Vec<Pinned>> {
    PINNED.lock().unwrap_or_else(|e| e.into_inner())
}

/// The path as pins compare it: canonical where it exists (one file by two spellings is one pin).
fn key(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf()))
}

/// Pin `files` (path, planned SHA-256 in hex) until the returned guard is dropped.
pub fn pin(files: impl IntoIterator<Item = (PathBuf, String)>) -> Pins {
    let guard = NEXT.fetch_add(1, Ordering::Relaxed);
    let mut all = pinned();
    all.extend(files.into_iter().map(|(path, sha256)| Pinned { guard, path: key(&path), sha256 }));
    Pins { guard }
}

/// `bytes`, just read from `path`, against every pin of `path`: the first whose hash differs is
/// an error naming the file and both hashes. Unpinned files pass without being hashed.
pub fn check(path: &Path, bytes: &[u8]) -> Result<(), Changed> {
    let all = pinned();
    if all.is_empty() {
        return Ok(());
    }
    let at = key(path);
    let mut read = None;
    for p in all.iter().filter(|p| p.path == at) {
        let hash = read.get_or_insert_with(|| super::digest::sha256_hex(bytes));
        if *hash != p.sha256 {
            let short = |h: &str| h[..h.len().min(16)].to_string();
            return Err(Changed { file: path.display().to_string(), planned: short(&p.sha256), read: short(hash) });
        }
    }
    Ok(())
}
