//! What a study folder holds, sorted into what the store wrote and what it did not. The store
//! removes only its own files (`--fresh`, `--replace`, `drift --accept`); anything else in the
//! folder (a user's notes, a backup copy, another study stored inside by a `--results` that
//! pointed there) is named, and a command that would remove files around it refuses instead.
//!
//! The store's files, by where they sit in `STUDY/`:
//! - `levels.csv`, `provenance.json`, `.lock`, the journal of a change in progress
//!   ([`records::journal::FILE`]);
//! - `runs/RUN.json`, `references/KEY.json`, `.partial/RUN.json` (a checkpoint);
//! - `meshes/RUN_levelL.json` and `.vtu`;
//! - `.locks/RUN.lock`;
//! - in any of these folders, the temporary files of a write ([`records::is_temporary`]).

use crate::records::{self, StudyDir};
use std::path::{Path, PathBuf};

/// A study folder's files: the store's data (what `--fresh` removes), its locks and journal
/// (which stay), and what the store never writes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Inventory {
    /// Records, snapshots, references, checkpoints, summaries and temporary files.
    pub data: Vec<PathBuf>,
    /// Lock files and a pending journal.
    pub control: Vec<PathBuf>,
    /// Files and folders the store does not write, each named as found.
    pub foreign: Vec<PathBuf>,
}

/// Whether a file name is one the store writes in a given sub-folder.
type Fits = fn(&str) -> bool;

/// The store's sub-folders, with the test a file name in each must pass.
/// (A name starting with `.` is never one the store gives a record, a snapshot, a checkpoint or
/// a lock: every run id starts with a letter or a digit. Its temporary files are matched apart.)
const FOLDERS: [(&str, Fits); 5] = [
    ("runs", |n| n.ends_with(".json") && !n.starts_with('.')),
    ("references", |n| n.ends_with(".json") && !n.starts_with('.')),
    (".partial", |n| n.ends_with(".json") && !n.starts_with('.')),
    ("meshes", |n| StudyDir::parse_mesh_name(n).is_some() && !n.starts_with('.')),
    (".locks", |n| n.ends_with(".lock") && !n.starts_with('.')),
];

/// Sort every entry of `dir`'s folder (missing: empty). A sub-folder of a store folder, or a
/// top-level entry the store does not write, is foreign; symlinks are judged by their name.
pub fn inventory(dir: &StudyDir) -> std::io::Result<Inventory> {
    let mut inv = Inventory::default();
    for (name, path, is_dir) in entries(&dir.root)? {
        if let Some((_, fits)) = FOLDERS.iter().find(|(f, _)| *f == name).filter(|_| is_dir) {
            for (name, path, is_dir) in entries(&path)? {
                let ours = !is_dir && (fits(&name) || records::is_temporary(&name));
                let slot = if !ours {
                    &mut inv.foreign
                } else if path.starts_with(dir.root.join(".locks")) {
                    &mut inv.control
                } else {
                    &mut inv.data
                };
                slot.push(path);
            }
            continue;
        }
        match name.as_str() {
            _ if is_dir => inv.foreign.push(path),
            "levels.csv" | "provenance.json" => inv.data.push(path),
            ".lock" | records::journal::FILE => inv.control.push(path),
            n if records::is_temporary(n) => inv.data.push(path),
            _ => inv.foreign.push(path),
        }
    }
    Ok(inv)
}

/// The entries of `folder` (name, path, whether a folder, not following symlinks), sorted.
fn entries(folder: &Path) -> std::io::Result<Vec<(String, PathBuf, bool)>> {
    let read = match std::fs::read_dir(folder) {
        Ok(read) => read,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(std::io::Error::new(e.kind(), format!("reading the folder {}: {e}", folder.display()))),
    };
    let mut out = Vec::new();
    for entry in read {
        let entry = entry?;
        let is_dir = entry.file_type()?.is_dir();
        out.push((entry.file_name().to_string_lossy().into_owned(), entry.path(), is_dir));
    }
    out.sort();
    Ok(out)
}

/// The refusal of a command that would remove the store's files around `foreign` ones.
pub fn refusal(command: &str, dir: &StudyDir, foreign: &[PathBuf]) -> anyhow::Error {
    let names: Vec<String> = foreign.iter().map(|f| f.strip_prefix(&dir.root).unwrap_or(f).display().to_string()).collect();
    anyhow::anyhow!(
        "{command}: {} holds {} file(s) or folder(s) the store did not write: {}. {command} removes the study's own files (records, snapshots, references, checkpoints, summaries) and never a file it did not write; nothing was removed. Move them out of {} (or remove them), then run the command again",
        dir.root.display(),
        names.len(),
        names.join(", "),
        dir.root.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_users_file_in_runs_is_foreign_and_a_record_is_data() {
        let root = std::env::temp_dir().join(format!("signorini-owned-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let dir = StudyDir::new(&root, "s");
        for f in [
            "runs/a.json",
            "runs/notes.txt",
            "runs/a.json.bak",
            "meshes/a_level0.vtu",
            "meshes/x.vtu",
            ".locks/a.lock",
            "levels.csv",
            "README",
        ] {
            let p = dir.root.join(f);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(&p, "x").unwrap();
        }
        std::fs::create_dir_all(dir.root.join("runs/other/runs")).unwrap();
        let inv = inventory(&dir).unwrap();
        let rel = |v: &[PathBuf]| v.iter().map(|p| p.strip_prefix(&dir.root).unwrap().display().to_string()).collect::<Vec<_>>();
        assert_eq!(rel(&inv.data), ["levels.csv", "meshes/a_level0.vtu", "runs/a.json"]);
        assert_eq!(rel(&inv.control), [".locks/a.lock"]);
        assert_eq!(rel(&inv.foreign), ["README", "meshes/x.vtu", "runs/a.json.bak", "runs/notes.txt", "runs/other"]);
        std::fs::remove_dir_all(&root).unwrap();
    }
}
