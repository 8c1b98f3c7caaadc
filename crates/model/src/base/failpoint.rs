//! Crash points for the tests of the writers. Every change the harness makes to the filesystem
//! (a file created and written, renamed or removed, a folder created or removed) passes [`step`]
//! first. Unset, as shipped, a step costs one atomic increment and nothing else; with
//! `SIGNORINI_FAILPOINT=K` the process stops at once before its K-th change, the way `kill -9`
//! stops it: no destructor runs, no temporary file is cleaned and no lock is released by hand
//! (exit status [`EXIT`], one line on standard error naming the change). A test stops a writing
//! command at every K until it finishes, and checks what each stop leaves behind.
//!
//! Written here rather than taken from a failpoint crate (fail-rs): its points are named one by
//! one and set per name, while what is tested here is "stop at the K-th change, whichever it is",
//! which needs a counter over every change and nothing else.

use std::path::Path;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

/// The environment variable that sets the change to stop before (1 = the first).
pub const ENV: &str = "SIGNORINI_FAILPOINT";

/// The exit status of a process stopped at its failpoint.
pub const EXIT: i32 = 86;

/// The environment variable that sets the wait before every change, in milliseconds.
pub const PAUSE_ENV: &str = "SIGNORINI_FAILPOINT_PAUSE_MS";

static CHANGES: AtomicUsize = AtomicUsize::new(0);

fn stop_at() -> Option<usize> {
    static AT: OnceLock<Option<usize>> = OnceLock::new();
    *AT.get_or_init(|| std::env::var(ENV).ok().and_then(|v| v.trim().parse().ok()).filter(|&k| k > 0))
}

fn pause() -> Option<Duration> {
    static PAUSE: OnceLock<Option<Duration>> = OnceLock::new();
    *PAUSE.get_or_init(|| std::env::var(PAUSE_ENV).ok().and_then(|v| v.trim().parse().ok()).map(Duration::from_millis))
}

/// The next change to the filesystem: `what` (`write`, `rename`, `remove`, `create folder`, ...)
/// on `path`. With the pause set, it waits that long first; with the failpoint set to this
/// change's number, the process stops here.
pub fn step(what: &str, path: &Path) {
    if let Some(pause) = pause() {
        std::thread::sleep(pause);
    }
    let k = CHANGES.fetch_add(1, Ordering::SeqCst) + 1;
    if stop_at() == Some(k) {
        eprintln!("failpoint: stopped before change {k}: {what} {}", path.display());
        // SAFETY: _exit ends the process at once; nothing after it runs
        unsafe { libc::_exit(EXIT) }
    }
}

/// How many changes this process has made so far.
pub fn changes() -> usize {
    CHANGES.load(Ordering::SeqCst)
}
