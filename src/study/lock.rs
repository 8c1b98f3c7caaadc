//! The lock on a study's results folder (`STUDY/.lock`).

use super::provenance;
use crate::records::StudyDir;
use anyhow::{Context, Result, bail};

/// An exclusive lock on a study's results folder (`STUDY/.lock`, holding the owner's process id
/// and command line), held while a study is written, so that two runs of one study neither
/// compute everything twice nor delete each other's runs. Released when dropped (or when the
/// process dies: the operating system drops the lock with the file descriptor).
pub struct StudyLock {
    _file: std::fs::File,
}

impl StudyLock {
    pub fn acquire(dir: &StudyDir, wait: bool) -> Result<StudyLock> {
        use std::io::{Read, Seek, Write};
        std::fs::create_dir_all(&dir.root).with_context(|| format!("creating {}", dir.root.display()))?;
        let path = dir.root.join(".lock");
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .with_context(|| format!("opening the lock file {}", path.display()))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = if holder.trim().is_empty() { "another process".to_string() } else { holder.trim().to_string() };
                if !wait {
                    bail!(
                        "{} is being written by {holder}; wait for it to finish, or pass --wait to wait for it (the lock is {})",
                        dir.root.display(),
                        path.display()
                    );
                }
                eprintln!("{} is being written by {holder}; waiting for it to finish", dir.root.display());
                file.lock().with_context(|| format!("waiting for the lock {}", path.display()))?;
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(e).with_context(|| format!("locking {}", path.display())),
        }
        let me =
            format!("process {} ({}) since {}", std::process::id(), std::env::args().collect::<Vec<_>>().join(" "), provenance::utc_now());
        file.set_len(0)
            .and_then(|_| file.rewind())
            .and_then(|_| file.write_all(me.as_bytes()))
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(StudyLock { _file: file })
    }
}
