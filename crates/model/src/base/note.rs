//! Messages to standard error that cannot stop the program: `eprintln!` panics when the write
//! fails (a full disk, a closed standard error, a file-size limit), which would turn a note
//! about the computation into a crash of it. [`line()`] writes and drops a failed write.
//!
//! Every progress bar of the process is drawn through one display, [`bars()`], so that two bars
//! at once (`drift` reruns two studies at a time) take a line each, and a note is written above
//! the bars rather than through them.

use indicatif::MultiProgress;
use std::io::Write;

/// The one display every progress bar is added to (drawn on standard error where that is a
/// terminal; nothing is drawn elsewhere).
pub fn bars() -> &'static MultiProgress {
    static BARS: std::sync::OnceLock<MultiProgress> = std::sync::OnceLock::new();
    BARS.get_or_init(MultiProgress::new)
}

/// Write one line to standard error, above any progress bar; a failed write is dropped.
pub fn line(args: std::fmt::Arguments) {
    let text = args.to_string();
    bars().suspend(|| {
        let _ = writeln!(std::io::stderr(), "{text}");
    });
}
