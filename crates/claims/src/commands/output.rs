//! What a command prints, without panicking: standard output kept writable to the end (the
//! first failed write kept and reported, the files written named), messages on standard error
//! that a failed write cannot stop, the command line parsed with help and version through the
//! same checked output, and the exit status. Both binaries (`signorini`, `signorini-figures`)
//! print through here.

use anyhow::Result;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `eprintln!` that cannot panic: a message whose write to stderr fails (a full device, a
/// file-size limit, a closed stderr) is dropped, and the exit status still says what happened.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// The first error writing standard output, if one happened (a full device, a file-size limit).
static STDOUT_ERROR: std::sync::OnceLock<String> = std::sync::OnceLock::new();

/// Write to standard output without panicking: std's `println!` panics when the write fails
/// (`> /dev/full` would end in exit 101). The first error is kept, later output dropped, and
/// [`exit_status`] reports it. The binaries' `print!`/`println!` come here.
pub fn stdout_write(args: std::fmt::Arguments, newline: bool) {
    use std::io::Write as _;
    if STDOUT_ERROR.get().is_some() {
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|_| if newline { out.write_all(b"\n") } else { Ok(()) }) {
        let _ = STDOUT_ERROR.set(e.to_string());
    }
}

/// Flush standard output (its last lines are buffered) and report the first write error.
pub fn stdout_result() -> std::result::Result<(), String> {
    use std::io::Write as _;
    if let Err(e) = std::io::stdout().flush() {
        let _ = STDOUT_ERROR.set(e.to_string());
    }
    STDOUT_ERROR.get().map_or(Ok(()), |e| Err(e.clone()))
}

/// The files this command wrote, in order, each complete (written to a temporary name and
/// renamed). A failed standard output then names them: they are kept and valid, and only the
/// printed report was lost (`export > /dev/full` says which files it wrote, not only "No space left on device").
static WRITTEN: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Print `line` for the file `path` just written, and remember the file ([`WRITTEN`]). Every
/// "wrote" line comes here.
pub fn wrote(path: &Path, line: std::fmt::Arguments) {
    let mut written = WRITTEN.lock().unwrap_or_else(|e| e.into_inner());
    if !written.iter().any(|w| w == path) {
        written.push(path.to_path_buf());
    }
    drop(written);
    stdout_write(line, true);
}

/// Print a "wrote" line for each file written.
pub fn wrote_all(files: &[PathBuf]) {
    for f in files {
        wrote(f, format_args!("wrote {}", f.display()));
    }
}

/// The error of a failed standard output (`e`): with the files written, which it did not touch.
fn stdout_error(e: &str) -> anyhow::Error {
    let written = WRITTEN.lock().unwrap_or_else(|e| e.into_inner());
    if written.is_empty() {
        return anyhow::anyhow!("writing standard output: {e}");
    }
    let files: Vec<String> = written.iter().map(|f| f.display().to_string()).collect();
    anyhow::anyhow!(
        "writing standard output: {e}. Only the printed report was lost: the files were written before, complete and valid: {}",
        files.join(", ")
    )
}

/// The command line, or the exit status of what parsing printed instead: help and version go
/// through [`stdout_write`], so that a standard output that fails is an error there too (clap's
/// own printing ignores the failure, and `--help > /dev/full` would exit 0); a usage
/// error goes to standard error with clap's status.
pub fn parse<C: clap::Parser>() -> std::result::Result<C, ExitCode> {
    let e = match C::try_parse() {
        Ok(cli) => return Ok(cli),
        Err(e) => e,
    };
    if e.use_stderr() {
        let _ = e.print();
        return Err(ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2)));
    }
    stdout_write(format_args!("{}", e.render()), false);
    match stdout_result() {
        Ok(()) => Err(ExitCode::SUCCESS),
        Err(msg) => {
            say!("error: writing standard output: {msg}");
            Err(ExitCode::FAILURE)
        }
    }
}

/// A file-size limit (`ulimit -f`, a quota) makes a write fail with EFBIG instead of killing
/// the process, so the store can clean up and say which file it was writing. Called first, before
/// any thread is started.
pub fn ignore_file_size_signal() {
    // SAFETY: setting a signal's disposition, before any thread is started.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

/// The exit status of a command that ended with `result`: 0, 130 for an interrupt that kept
/// what was finished (`interrupted` says which errors are), 1 for an error (printed as
/// `error: ...`). What was computed and kept stays; output that could not be written is an error.
pub fn exit_status(result: Result<()>, interrupted: impl Fn(&anyhow::Error) -> bool) -> ExitCode {
    match result.and_then(|()| stdout_result().map_err(|e| stdout_error(&e))) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if interrupted(&e) => {
            say!("{e:#}");
            ExitCode::from(130)
        }
        Err(e) => {
            say!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
