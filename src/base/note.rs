//! Messages to standard error that cannot stop the program: `eprintln!` panics when the write
//! fails (a full disk, a closed standard error, a file-size limit), which would turn a note
//! about the computation into a crash of it. [`line()`] writes and drops a failed write.

use std::io::Write;

/// Write one line to standard error; a failed write is dropped.
pub fn line(args: std::fmt::Arguments) {
    let _ = writeln!(std::io::stderr(), "{args}");
}
