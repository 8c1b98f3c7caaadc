//! The locks of a study's results folder: the study lock (`STUDY/.lock`), held while the folder's
//! shared files change (setting up, committing a finished run), and one lock per run
//! (`STUDY/.locks/RUN.lock`), held while the run is computed. Shards of one study (a Slurm
//! array) compute their runs side by side and take turns only to commit; two processes never
//! compute the same run (the second waits or is refused, naming the holder), and neither removes
//! the other's files of a run in progress.
//!
//! Only the store hands locks out ([`super::Store::lock`], [`super::Store::lock_run`]): every
//! write to the folder needs the guard of the lock that covers it.

use crate::records::StudyDir;
use crate::study::provenance;
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// How long a process waits for a study lock another process holds before it is refused
/// (without `--wait`): setting up and committing take seconds. `SIGNORINI_LOCK_PATIENCE`
/// (seconds) sets another.
pub const STUDY_LOCK_PATIENCE: std::time::Duration = std::time::Duration::from_secs(30);

/// [`STUDY_LOCK_PATIENCE`], or `SIGNORINI_LOCK_PATIENCE` seconds where that is set to a number
/// in 0 ..= 3600 (otherwise the default, with a note).
fn patience() -> std::time::Duration {
    // read once per process, so a bad value is named once
    static PATIENCE: std::sync::OnceLock<std::time::Duration> = std::sync::OnceLock::new();
    *PATIENCE.get_or_init(|| {
        let Ok(text) = std::env::var("SIGNORINI_LOCK_PATIENCE") else { return STUDY_LOCK_PATIENCE };
        match text.trim().parse::<f64>() {
            Ok(s) if (0.0..=3600.0).contains(&s) => std::time::Duration::from_secs_f64(s),
            _ => {
                model::base::note::line(format_args!(
                    "SIGNORINI_LOCK_PATIENCE={text:?} is not a number of seconds in 0 ..= 3600; waiting the default {} s",
                    STUDY_LOCK_PATIENCE.as_secs()
                ));
                STUDY_LOCK_PATIENCE
            }
        }
    })
}

/// An exclusive lock on a file holding the owner's process id and command line. Released when
/// dropped (or when the process dies: the operating system drops the lock with the file
/// descriptor).
pub struct Lock {
    _file: std::fs::File,
}

impl Lock {
    /// The study lock of `dir`. It is held only while shared files change (setting up,
    /// committing: seconds), so a process that finds it taken waits up to
    /// [`STUDY_LOCK_PATIENCE`] ([`patience`]) even without `wait` (two shards started at the same moment
    /// both run); past that it is refused naming the holder, unless `wait`, then waits for it.
    pub(super) fn study(dir: &StudyDir, wait: bool) -> Result<Lock> {
        check_run_lock_folder(dir)?;
        let path = dir.root.join(".lock");
        let file = open(&path)?;
        let patience = patience();
        let deadline = std::time::Instant::now() + patience;
        while !wait && std::time::Instant::now() < deadline {
            match file.try_lock() {
                Ok(()) => return own(file, &path),
                Err(std::fs::TryLockError::WouldBlock) => std::thread::sleep(std::time::Duration::from_millis(50)),
                Err(std::fs::TryLockError::Error(e)) => return Err(e).with_context(|| format!("locking {}", path.display())),
            }
        }
        let claimed = claim(file, &path, &dir.root.display().to_string(), wait);
        if wait {
            return claimed;
        }
        claimed.with_context(|| {
            format!("the study lock was held for more than {} s (it is held only to set up and to commit)", patience.as_secs_f64())
        })
    }

    /// The lock of run `id` of `dir`, held while it is computed. Tried first under the study
    /// lock, where [`run_in_progress`] looks at it too, so that the look never makes a run's
    /// owner find its lock taken; if another process computes the run, refused (naming it)
    /// unless `wait`, then waits for it without holding the study lock.
    pub(super) fn run(dir: &StudyDir, id: &str, wait: bool) -> Result<Lock> {
        let path = run_lock_file(dir, id);
        let file = {
            let _study = Self::study(dir, true)?;
            let file = open(&path)?;
            match file.try_lock() {
                Ok(()) => return own(file, &path),
                Err(std::fs::TryLockError::WouldBlock) => file,
                Err(std::fs::TryLockError::Error(e)) => return Err(e).with_context(|| format!("locking {}", path.display())),
            }
        };
        claim(file, &path, &format!("run {id} of {}", dir.root.display()), wait)
    }

    /// The lock of run `id` taken by a process that holds the study lock (to remove a stored
    /// run): at once, or refused naming the process that computes the run. Never waited for: the
    /// holder needs the study lock to store its run.
    pub(super) fn run_now(dir: &StudyDir, id: &str) -> Result<Lock> {
        let path = run_lock_file(dir, id);
        claim(open(&path)?, &path, &format!("run {id} of {}", dir.root.display()), false)
            .context("a run another process computes is not removed")
    }
}

/// The lock of a scratch folder a whole command reruns studies into (`drift`'s
/// `target/drift/full`): the file `FOLDER.lock` beside it, held until the command ends. A second
/// process waits for it, saying who holds it: two drifts in one checkout would otherwise start
/// over each other's reruns and compare what the other had removed (a false drift).
pub fn scratch_folder(folder: &Path) -> Result<Lock> {
    let mut name = folder.file_name().map(|n| n.to_os_string()).unwrap_or_else(|| "scratch".into());
    name.push(".lock");
    let path = folder.with_file_name(name);
    claim(open(&path)?, &path, &format!("the scratch folder {}", folder.display()), true)
}

/// The lock file at `path`, made if missing; one that is not a regular file (a named pipe, a
/// symlink to a device: its holder's text would be read without end) is refused, naming it.
fn open(path: &Path) -> Result<std::fs::File> {
    if let Err(e) = model::base::input::check_target(path) {
        bail!("the lock file {} is {}, not a file: remove it", path.display(), e.found);
    }
    if let Some(parent) = path.parent() {
        model::base::input::create_folder(parent)?;
    }
    if !path.exists() {
        model::base::failpoint::step("create", path);
    }
    std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)
        .with_context(|| format!("opening the lock file {}", path.display()))
}

/// A lock another process holds, refused without waiting: what it covers, who holds it, the
/// lock file. A command whose own advice differs (`drift --accept` has no `--wait`) finds it
/// in the error's chain.
#[derive(Debug, thiserror::Error)]
#[error("{what} is being written by {holder}; wait for it to finish, or pass --wait to wait for it (the lock is {})", lock.display())]
pub struct Held {
    pub what: String,
    pub holder: String,
    pub lock: std::path::PathBuf,
}

/// Take the lock on `file`: at once if free; if held, refused naming the holder, or with `wait`
/// after waiting for it.
fn claim(mut file: std::fs::File, path: &Path, what: &str, wait: bool) -> Result<Lock> {
    match file.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => {
            let holder = holder(&mut file);
            if !wait {
                return Err(Held { what: what.to_string(), holder, lock: path.to_path_buf() }.into());
            }
            model::base::note::line(format_args!("{what} is being written by {holder}; waiting for it to finish"));
            file.lock().with_context(|| format!("waiting for the lock {}", path.display()))?;
        }
        Err(std::fs::TryLockError::Error(e)) => return Err(e).with_context(|| format!("locking {}", path.display())),
    }
    own(file, path)
}

/// Who holds the lock on `file`, as its text says. A new holder takes the lock first and writes
/// its name just after, so for a moment the text still names the previous holder, whose process
/// has ended (a refusal once named a dead process): the text is read again, for up to a second,
/// until the process it names is running; if it never is, that is said.
fn holder(file: &mut std::fs::File) -> String {
    use std::io::{Read, Seek};
    let mut text = String::new();
    for attempt in 0..20 {
        if attempt > 0 {
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
        text.clear();
        let _ = file.rewind().and_then(|_| file.read_to_string(&mut text));
        match named_pid(&text) {
            Some(pid) if !running(pid) => continue,
            _ => break,
        }
    }
    let text = text.trim();
    match named_pid(text) {
        _ if text.is_empty() => "another process".to_string(),
        Some(pid) if !running(pid) => format!("another process (the lock file still names process {pid}, which has ended)"),
        _ => text.to_string(),
    }
}

/// The process id a lock file's text names (`process PID (...`), as [`own`] writes it.
fn named_pid(text: &str) -> Option<u32> {
    text.trim().strip_prefix("process ")?.split_whitespace().next()?.parse().ok()
}

/// Whether process `pid` exists and has not ended (signal 0 checks without sending; EPERM: it
/// exists, owned by another user). A process that has exited but that its parent has not reaped
/// yet (a zombie: state `Z` in /proc/PID/stat) has ended: it holds no lock, and `--wait`
/// waiting for it waited as long as its parent did not wait for it (a driver that starts `run`
/// and calls `figures --wait` before reaping it: forever).
pub(super) fn running(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else { return false };
    // SAFETY: kill with signal 0 sends nothing; it only reports whether the process exists
    let r = unsafe { libc::kill(pid, 0) };
    let exists = r == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM);
    exists && !zombie(pid)
}

/// Whether process `pid` has exited and waits to be reaped (Linux's /proc; elsewhere: no).
fn zombie(pid: libc::pid_t) -> bool {
    let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else { return false };
    // "PID (COMMAND) STATE ...": the command may hold spaces and parentheses, the state follows
    // the last ')'
    stat.rsplit_once(')').and_then(|(_, rest)| rest.split_whitespace().next()).is_some_and(|state| matches!(state, "Z" | "X"))
}

/// A locked file made this process's lock: its text names the process, its command and since when.
fn own(mut file: std::fs::File, path: &Path) -> Result<Lock> {
    use std::io::{Seek, Write};
    let me = format!("process {} ({}) since {}", std::process::id(), std::env::args().collect::<Vec<_>>().join(" "), provenance::utc_now());
    file.set_len(0)
        .and_then(|_| file.rewind())
        .and_then(|_| file.write_all(me.as_bytes()))
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(Lock { _file: file })
}

/// A study folder another process is writing, found by a reader: what it writes, who, and the
/// lock that says so. Its records are what the writer has not finished changing (`run --fresh`
/// has removed them, a run's record is not there yet), so a reader names the writer instead of
/// reporting them as missing or drifted.
#[derive(Debug, thiserror::Error)]
#[error(
    "{what} is being written by {holder}: what it holds now is not what it will hold, so nothing was read; run this again when that process has finished (the lock is {})",
    lock.display()
)]
pub struct BeingWritten {
    pub what: String,
    pub holder: String,
    pub lock: PathBuf,
}

/// The writer of `dir`, if another process writes it now: the holder of the study lock, or else
/// of a run lock. A reader asks before it reads ([`super::Store::check`]), taking each lock
/// *shared* and without waiting, so readers never block one another; the run locks are looked
/// at under the shared study lock, which a process takes exclusively to claim a run lock
/// ([`Lock::run`]): a reader's look never makes a run's owner find its lock taken. Lock files
/// are opened for reading and never made: a reader changes nothing (a read-only checkout stays
/// readable); one that is not a regular file is an error naming it. A process that holds a
/// lock of the folder itself must not ask (its own lock
/// would count): writers check through their guard ([`super::Writer::check`]).
pub(super) fn writer_of(dir: &StudyDir) -> Result<Option<BeingWritten>> {
    // a lock file that is not a regular file (a named pipe would block the open itself) is
    // refused by its metadata, never opened, as a writer refuses it ([`open`])
    let shared = |path: &Path| -> Result<Option<std::result::Result<std::fs::File, std::fs::File>>> {
        if let Err(e) = model::base::input::check_target(path) {
            bail!("the lock file {} is {}, not a file: remove it", path.display(), e.found);
        }
        let Ok(file) = std::fs::File::open(path) else { return Ok(None) };
        Ok(Some(match file.try_lock_shared() {
            Err(std::fs::TryLockError::WouldBlock) => Err(file),
            _ => Ok(file),
        }))
    };
    let written =
        |mut file: std::fs::File, path: &Path, what: String| BeingWritten { what, holder: holder(&mut file), lock: path.to_path_buf() };
    check_run_lock_folder(dir)?;
    let study = dir.root.join(".lock");
    let _study = match shared(&study)? {
        Some(Err(file)) => return Ok(Some(written(file, &study, dir.root.display().to_string()))),
        held => held,
    };
    for id in runs_of(dir, std::iter::empty()) {
        let path = run_lock_file(dir, &id);
        if let Some(Err(file)) = shared(&path)? {
            return Ok(Some(written(file, &path, format!("run {id} of {}", dir.root.display()))));
        }
    }
    Ok(None)
}

/// Wait until no other process writes `dir` ([`writer_of`]): for each writer found, block on a
/// shared lock of the lock file it holds (saying who it is, once per process), then look again;
/// and where no lock is held, wait until every process seen writing has ended. A `run` holds no
/// lock for a moment between committing one run and claiming the next: a reader that woke in
/// that moment would meet the next run's lock (exit 1) or read the study with its later runs
/// missing (exit 0). What a reader given `--wait` does before it reads (the Slurm
/// finish job of one array, while another array's tasks still hold the folder). A process that
/// starts writing after the wait makes the read refuse as without `--wait`: never a silent read.
pub(super) fn wait_for_writers(dir: &StudyDir) -> Result<()> {
    let mut seen: Vec<u32> = Vec::new();
    loop {
        let Some(written) = writer_of(dir)? else {
            if !seen.iter().any(|&pid| running(pid)) {
                return Ok(());
            }
            std::thread::sleep(std::time::Duration::from_millis(100));
            continue;
        };
        match named_pid(&written.holder) {
            Some(pid) if seen.contains(&pid) => {}
            pid => {
                seen.extend(pid);
                model::base::note::line(format_args!("{} is being written by {}; waiting for it to finish", written.what, written.holder));
            }
        }
        let file = std::fs::File::open(&written.lock).with_context(|| format!("opening the lock file {}", written.lock.display()))?;
        file.lock_shared().with_context(|| format!("waiting for the lock {}", written.lock.display()))?;
    }
}

/// The folder of the run locks (`STUDY/.locks`), where it exists, is a folder: one that is a file
/// is named by every writer (which takes the study lock first) and reader, also where every
/// run is finished and no run lock is opened (`run` then names it too, never "0 run(s) executed").
fn check_run_lock_folder(dir: &StudyDir) -> Result<()> {
    let folder = dir.root.join(".locks");
    match std::fs::metadata(&folder) {
        Ok(m) if !m.is_dir() => {
            let what = if m.is_file() { "a regular file" } else { "not a regular file either" };
            bail!("{} is {what}, not a folder: move it away (it is where the run locks go, and holds no run)", folder.display())
        }
        _ => Ok(()),
    }
}

fn run_lock_file(dir: &StudyDir, id: &str) -> PathBuf {
    dir.root.join(".locks").join(format!("{id}.lock"))
}

/// Whether another process holds the lock of run `id` (computes it now). Ask only under the
/// study lock (see [`Lock::run`]). A lock this process holds counts too (asked through another
/// open file); the study's own code never asks about a run it computes.
pub(super) fn run_in_progress(dir: &StudyDir, id: &str) -> bool {
    let Ok(file) = std::fs::OpenOptions::new().read(true).write(true).open(run_lock_file(dir, id)) else { return false };
    matches!(file.try_lock(), Err(std::fs::TryLockError::WouldBlock))
}

/// Every run of the study a process may compute or have left: `declared`, the stored records
/// (`runs/RUN.json`), the run locks (`.locks/RUN.lock`) and the checkpoints
/// (`.partial/RUN.json`), sorted, each once. What `--fresh` holds before it removes anything.
pub(super) fn runs_of(dir: &StudyDir, declared: impl Iterator<Item = String>) -> Vec<String> {
    let mut ids: Vec<String> = declared.collect();
    for (sub, ext) in [("runs", "json"), (".locks", "lock"), (".partial", "json")] {
        for e in std::fs::read_dir(dir.root.join(sub)).into_iter().flatten().flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if let Some(id) = name.strip_suffix(&format!(".{ext}")).filter(|id| !id.is_empty() && !id.starts_with('.')) {
                ids.push(id.to_string());
            }
        }
    }
    ids.sort();
    ids.dedup();
    ids
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_holder_is_named_only_while_its_process_runs() {
        let me = std::process::id();
        assert_eq!(named_pid(&format!("process {me} (signorini run x.toml) since now")), Some(me));
        assert_eq!(named_pid("another text"), None);
        assert!(running(me));
        // a pid above the kernel's limit (pid_max is at most 2^22) names no process
        assert!(!running(1 << 23));
        let path = std::env::temp_dir().join(format!("signorini-lock-holder-{me}"));
        std::fs::write(&path, format!("process {} (gone) since then", 1 << 23)).unwrap();
        let mut file = std::fs::File::open(&path).unwrap();
        let started = std::time::Instant::now();
        let said = holder(&mut file);
        assert!(said.contains("still names process 8388608, which has ended"), "{said}");
        assert!(started.elapsed() < std::time::Duration::from_secs(3));
        std::fs::write(&path, format!("process {me} (signorini run) since now")).unwrap();
        assert_eq!(holder(&mut std::fs::File::open(&path).unwrap()), format!("process {me} (signorini run) since now"));
        std::fs::remove_file(&path).ok();
    }
}
