//! The one reader of a file the harness reads (a user's problem file, study manifest or Gmsh
//! mesh, and every file of a results folder: records, summaries, snapshots, references,
//! checkpoints, reports): what is not a regular file after following symlinks (a named pipe, a
//! device such as `/dev/zero`, a directory) is refused by its metadata before it is opened, so it
//! can neither hang nor grow a buffer without end, and so is a file larger than its kind may be.
//! The handle is then opened without blocking (a named pipe put in place meanwhile would block
//! `open` itself) and checked again by `fstat` on that same handle, so what is checked is what is
//! read. A file a running study pinned ([`super::pin`]) must read as the bytes it planned.
//!
//! Its counterpart for writes, [`check_target`], refuses to replace what is not a regular file.

use std::io::Read;
use std::path::Path;

/// What a kind of input file may be.
#[derive(Clone, Copy, Debug)]
pub struct Kind {
    /// The file in a message's words: "the problem file", "the manifest", "the mesh file".
    pub what: &'static str,
    pub limit: Limit,
}

/// How large a file of a kind may be.
#[derive(Clone, Copy, Debug)]
pub enum Limit {
    /// At most this many bytes (a text file a person writes: a problem file, a manifest).
    Bytes(u64),
    /// Reading it takes about this many bytes of memory per byte of file, which must be
    /// available ([`available_memory`](super::memory::available_memory)): a mesh file, which
    /// parsing holds together with its nodes and elements.
    MemoryPerByte(f64),
}

/// A problem file or a manifest: at most 16 MiB (the largest the project declares is a few KiB;
/// a file beyond this is not a problem or a study written by a person).
pub const TEXT_LIMIT: u64 = 16 * 1024 * 1024;

/// A file of a results folder (`runs/*.json`, `levels.csv`, `provenance.json`,
/// `references/*.json`, `meshes/*`, checkpoints, a drift report, a figure): at most 512 MiB. The
/// largest file the harness has written under the tracked `results/` is 6.8 MB
/// (`results/hertz/meshes/adaptive_level19.vtu`, 6,847,417 bytes; the largest record 5.0 MB), so
/// the bound is about 78 times that: far above any study, far below what would exhaust memory.
pub const RESULTS_LIMIT: u64 = 512 * 1024 * 1024;

/// A file of a results folder ([`RESULTS_LIMIT`]).
pub const RESULTS_FILE: Kind = Kind { what: "a file of a results folder", limit: Limit::Bytes(RESULTS_LIMIT) };

/// Why an input file was not read. The caller's error names the path.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    #[error("cannot read {what}: {error}")]
    Io { what: &'static str, error: std::io::Error },
    #[error("not a regular file ({found}): {what} is read from a file of known size")]
    NotRegular { what: &'static str, found: &'static str },
    #[error("{what} has {size}, more than the {limit} it may have (is this the file you meant?)")]
    TooLarge { what: &'static str, size: String, limit: String },
    #[error("the file has {size}: reading it needs about {needed}, more than the {available} this process can allocate")]
    Memory { size: String, needed: String, available: String },
    /// A file pinned to a run's planned bytes ([`super::pin`]) read with other bytes.
    #[error(transparent)]
    Changed(#[from] super::pin::Changed),
}

/// The bytes of the input file at `path` of kind `kind`, or why not (see the module's doc).
pub fn read(path: &Path, kind: Kind) -> Result<Vec<u8>, InputError> {
    use std::os::unix::fs::OpenOptionsExt;
    let io = |error| InputError::Io { what: kind.what, error };
    // by name first, following symlinks: what is not a regular file is never opened
    let named = std::fs::metadata(path).map_err(io)?;
    if !named.is_file() {
        return Err(InputError::NotRegular { what: kind.what, found: file_type(&named.file_type()) });
    }
    let file = std::fs::OpenOptions::new().read(true).custom_flags(libc::O_NONBLOCK).open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(InputError::NotRegular { what: kind.what, found: file_type(&meta.file_type()) });
    }
    let size = meta.len();
    check_size(size, kind)?;
    let mut bytes = Vec::with_capacity(size as usize);
    // no more than was checked, should the file grow meanwhile
    file.take(size).read_to_end(&mut bytes).map_err(io)?;
    // the bytes parsed are the bytes a pinned run planned, or nothing is parsed
    super::pin::check(path, &bytes)?;
    Ok(bytes)
}

/// The text of the input file at `path`, which must be UTF-8 ([`read`], then the encoding).
pub fn read_text(path: &Path, kind: Kind) -> Result<String, InputError> {
    String::from_utf8(read(path, kind)?).map_err(|e| InputError::Io {
        what: kind.what,
        error: std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("not UTF-8 text (byte {} is not valid UTF-8)", e.utf8_error().valid_up_to() + 1),
        ),
    })
}

/// `size` bytes within `kind`'s limit.
fn check_size(size: u64, kind: Kind) -> Result<(), InputError> {
    use super::memory::{UNKNOWN_MEMORY_LIMIT, available_memory, human_bytes};
    match kind.limit {
        Limit::Bytes(limit) if size > limit => {
            Err(InputError::TooLarge { what: kind.what, size: human_bytes(size as f64), limit: human_bytes(limit as f64) })
        }
        Limit::MemoryPerByte(per_byte) => {
            let needed = per_byte * size as f64;
            let available = available_memory().unwrap_or(UNKNOWN_MEMORY_LIMIT);
            if needed > available {
                return Err(InputError::Memory {
                    size: human_bytes(size as f64),
                    needed: human_bytes(needed),
                    available: human_bytes(available),
                });
            }
            Ok(())
        }
        Limit::Bytes(_) => Ok(()),
    }
}

/// Why a path is not replaced by a written file.
#[derive(Debug, thiserror::Error)]
#[error(
    "not a regular file ({found}): give a file path (a file is written by renaming a new one over the path, which would replace {found})"
)]
pub struct NotFileTarget {
    pub found: &'static str,
}

/// Whether `path` may be replaced by a file written there (a temporary file renamed over it): it
/// does not exist, or is a regular file after following a symlink. A named pipe, a device (say
/// `/dev/null`) or a folder is refused, by its metadata alone (never opened). Every atomic write
/// checks its target here (`records::Batch::add`), and so do the command line's output flags
/// before any computation. The caller's error names the path.
pub fn check_target(path: &Path) -> Result<(), NotFileTarget> {
    match std::fs::metadata(path) {
        Ok(meta) if !meta.is_file() => Err(NotFileTarget { found: file_type(&meta.file_type()) }),
        // none there (or a dangling symlink), or a regular file; what cannot be looked at fails
        // at the write, naming the path
        _ => Ok(()),
    }
}

/// Create the folder `dir` and its missing parents (`create_dir_all`). Where a path on the way
/// exists and is not a folder (a file left where a results folder, `.locks` or an output folder
/// must be), the error names that path and what it is, instead of the system's "File exists".
/// Every folder the harness creates is created here.
pub fn create_folder(dir: &Path) -> std::io::Result<()> {
    if !dir.is_dir() {
        super::failpoint::step("create folder", dir);
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        let blocking = dir.ancestors().find_map(|a| std::fs::metadata(a).ok().filter(|m| !m.is_dir()).map(|m| (a, m)));
        let why = match blocking {
            Some((a, meta)) => {
                let what = if meta.is_file() { "a regular file" } else { file_type(&meta.file_type()) };
                format!("{} is {what}, not a folder: move it away or choose another folder", a.display())
            }
            None => e.to_string(),
        };
        std::io::Error::new(e.kind(), format!("cannot create the folder {}: {why}", dir.display()))
    })
}

/// The folder a file at `path` is written into: its parent, or `.` for a bare name.
pub fn folder_of(path: &Path) -> &Path {
    path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."))
}

/// A file type that is not a regular file, in words.
fn file_type(t: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    match () {
        _ if t.is_dir() => "a directory",
        _ if t.is_fifo() => "a named pipe",
        _ if t.is_char_device() => "a character device",
        _ if t.is_block_device() => "a block device",
        _ if t.is_socket() => "a socket",
        _ => "not a file",
    }
}

/// The longest line of an error message that quotes a user's input in full.
pub const EXCERPT_LINE: usize = 2000;

/// `message` with every line longer than [`EXCERPT_LINE`] characters cut to its first and last
/// 500 and the count of those between: what every error that quotes a user's input shows of it
/// (a manifest of one 200 MB line must not come back as a 200 MB message). The end is kept
/// because the reason follows the quote (`cannot parse "...": the ( at character 4001 nests ...`:
/// a cut after the first 1000 would lose the reason). Errors of manifests, problem
/// files and meshes format their text through it.
pub fn excerpt(message: &str) -> String {
    if message.lines().all(|l| l.chars().count() <= EXCERPT_LINE) {
        return message.to_string();
    }
    const KEPT: usize = 500;
    let short = |l: &str| {
        let n = l.chars().count();
        if n <= EXCERPT_LINE {
            l.to_string()
        } else {
            let head: String = l.chars().take(KEPT).collect();
            let tail: String = l.chars().skip(n - KEPT).collect();
            format!("{head} ... ({} characters cut) ... {tail}", n - 2 * KEPT)
        }
    };
    message.split('\n').map(short).collect::<Vec<_>>().join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_excerpt_is_bounded_and_short_lines_are_kept() {
        assert_eq!(excerpt("a\nb c"), "a\nb c");
        let long = format!("got \"{}\": the reason\nnext", "x".repeat(10_000));
        let e = excerpt(&long);
        assert!(e.len() < 1100 && e.contains(" ... (9018 characters cut) ... ") && e.ends_with("x\": the reason\nnext"), "{e}");
        assert!(e.starts_with("got \"xxx"));
    }

    const TEXT: Kind = Kind { what: "the test file", limit: Limit::Bytes(8) };

    #[test]
    fn a_regular_file_within_its_limit_is_read_and_others_are_refused() {
        let dir = std::env::temp_dir().join(format!("signorini-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let small = dir.join("small");
        std::fs::write(&small, "12345678").unwrap();
        assert_eq!(read_text(&small, TEXT).unwrap(), "12345678");
        std::fs::write(&small, "123456789").unwrap();
        let e = read(&small, TEXT).unwrap_err().to_string();
        assert!(e.starts_with("the test file has 9 B, more than the 8 B"), "{e}");
        std::fs::write(&small, [b'a', 0xff]).unwrap();
        assert!(read_text(&small, TEXT).unwrap_err().to_string().contains("byte 2 is not valid UTF-8"));
        let e = read(&dir, TEXT).unwrap_err().to_string();
        assert_eq!(e, "not a regular file (a directory): the test file is read from a file of known size");
        let e = read(Path::new("/dev/zero"), TEXT).unwrap_err().to_string();
        assert!(e.starts_with("not a regular file (a character device)"), "{e}");
        let fifo = dir.join("fifo");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo reads the NUL-terminated path it is given
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = read(&fifo, TEXT).unwrap_err().to_string();
        assert!(e.starts_with("not a regular file (a named pipe)"), "{e}");
        // a symlink is followed: to a regular file it reads, to a device it is refused
        let link = dir.join("link");
        std::os::unix::fs::symlink(&small, &link).unwrap();
        assert_eq!(read(&link, TEXT).unwrap(), [b'a', 0xff]);
        let zero = dir.join("zero");
        std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
        assert!(read(&zero, TEXT).unwrap_err().to_string().starts_with("not a regular file (a character device)"));
        // a write may replace a regular file or nothing, never a pipe, a device or a folder
        assert!(check_target(&small).is_ok() && check_target(&link).is_ok() && check_target(&dir.join("none")).is_ok());
        assert_eq!(check_target(&fifo).unwrap_err().found, "a named pipe");
        assert_eq!(check_target(&zero).unwrap_err().found, "a character device");
        assert_eq!(check_target(&dir).unwrap_err().found, "a directory");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
