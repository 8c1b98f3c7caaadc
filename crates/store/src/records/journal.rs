//! Changes of several files made as one: a [`Journal`] lists them (files renamed into place,
//! files removed), is written atomically beside the files it changes, then carried out, then
//! removed. Once the journal is on disk the change is decided: a process stopped part-way
//! (killed, out of power) leaves the journal, and the next writer carries out what it lists
//! before anything else ([`roll_forward`]); until then a reader finds the journal and refuses
//! the folder rather than read a change half made. Before the journal is on disk nothing of the
//! change is visible (its new files are temporary files or sit in a staging folder).
//!
//! This is the write-ahead discipline of storage engines, at the scale of a results folder: a
//! rename replaces one file atomically, and the journal makes a list of renames and removals
//! atomic too. Carrying it out again is harmless: a rename whose source is gone and whose
//! destination exists was done, a removal of a missing file was done.

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The journal's file name in the folder it changes.
pub const FILE: &str = ".journal.json";

/// The staging folder beside the folders a journal changes (in the same parent): a file
/// renamed into `FOLDER` may come from `../STAGING/FOLDER/` (the swap of `drift --accept`).
pub const STAGING: &str = ".accept";

/// A list of renames and removals to be made as one. Paths are relative to the folder the
/// journal sits in (a staging folder beside it is reached through `..`), so a results folder
/// moved or copied with a journal pending still rolls forward.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Journal {
    /// (from, to): `from` renamed onto `to`, replacing it.
    pub renames: Vec<(PathBuf, PathBuf)>,
    /// Files removed after the renames.
    pub removals: Vec<PathBuf>,
}

impl Journal {
    /// Whether it changes nothing.
    pub fn is_empty(&self) -> bool {
        self.renames.is_empty() && self.removals.is_empty()
    }

    /// Write the journal into `folder`, carry it out, remove it. An error before the journal is
    /// on disk changes nothing; an error after it leaves the journal for [`roll_forward`].
    pub fn commit(&self, folder: &Path) -> std::io::Result<()> {
        if self.is_empty() {
            return Ok(());
        }
        let file = folder.join(FILE);
        super::write_json(&file, self)?;
        self.carry_out(folder).map_err(|e| {
            std::io::Error::new(
                e.kind(),
                format!(
                    "{e}; the change is listed in {} (perhaps part made): readers refuse the folder until the next command that writes the study completes it (once the cause is fixed)",
                    file.display()
                ),
            )
        })?;
        model::base::failpoint::step("remove", &file);
        std::fs::remove_file(&file).map_err(super::step("removing the finished journal", &file))
    }

    /// The first path it lists that reaches outside `folder` (an absolute path, a `..` other
    /// than a source's way into the staging folder of `folder`), with why: a journal is written
    /// by the harness and never names one, so one that does was made or edited by hand and is
    /// carried out nowhere.
    fn outside(&self, folder: &Path) -> Option<String> {
        use std::path::Component;
        let inside = |p: &Path| !p.as_os_str().is_empty() && p.components().all(|c| matches!(c, Component::Normal(_)));
        let name = folder.file_name()?;
        let staged = |p: &Path| p.strip_prefix(Path::new("..").join(STAGING).join(name)).is_ok_and(inside);
        let sources = self.renames.iter().map(|(from, _)| from).find(|p| !inside(p) && !staged(p));
        let targets = self.renames.iter().map(|(_, to)| to).chain(&self.removals).find(|p| !inside(p));
        sources.or(targets).map(|p| format!("it names {}, outside {}", p.display(), folder.display()))
    }

    /// Make every change it lists that is not made yet; a journal naming a path outside the
    /// folder is refused and nothing is changed ([`Journal::outside`]).
    fn carry_out(&self, folder: &Path) -> std::io::Result<()> {
        if let Some(why) = self.outside(folder) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "{}: {why}; the harness never writes such a journal, so nothing it lists was done. Remove it (the change it lists is then not made: `signorini run --replace` recomputes what is at fault)",
                    folder.join(FILE).display()
                ),
            ));
        }
        for (from, to) in &self.renames {
            let (from, to) = (folder.join(from), folder.join(to));
            if !from.exists() && to.exists() {
                continue;
            }
            if let Some(parent) = to.parent() {
                model::base::input::create_folder(parent)?;
            }
            model::base::failpoint::step("rename", &to);
            std::fs::rename(&from, &to).map_err(super::step("renaming into place", &to))?;
        }
        for gone in &self.removals {
            let gone = folder.join(gone);
            model::base::failpoint::step("remove", &gone);
            match std::fs::remove_file(&gone) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(super::step("removing", &gone)(e)),
                _ => {}
            }
        }
        Ok(())
    }
}

/// The journal pending in `folder`, if a process stopped while carrying it out. A file there
/// that is not a journal the harness writes (it does not parse, or it names a path outside the
/// folder: [`Journal::outside`]) is an error of kind `InvalidData` that says so, for readers
/// and writers alike: no command carries it out.
pub fn pending(folder: &Path) -> std::io::Result<Option<Journal>> {
    let file = folder.join(FILE);
    if !file.exists() {
        return Ok(None);
    }
    let text = super::read_text(&file)?;
    let damaged = |why: String| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "{} is not a journal the store writes ({why}); no command carries it out, and nothing it lists was done. Compare what it lists with the folder, then remove it by hand (`signorini run --replace` recomputes what is at fault)",
                file.display()
            ),
        )
    };
    let journal: Journal = serde_json::from_str(&text).map_err(|e| damaged(format!("it does not parse: {e}")))?;
    if let Some(why) = journal.outside(folder) {
        return Err(damaged(why));
    }
    Ok(Some(journal))
}

/// Carry out the journal a stopped process left in `folder`, if any, and remove it; returns it.
/// Called by every writer of the folder before it changes anything, under its lock.
pub fn roll_forward(folder: &Path) -> std::io::Result<Option<Journal>> {
    let Some(journal) = pending(folder)? else { return Ok(None) };
    journal.carry_out(folder)?;
    let file = folder.join(FILE);
    model::base::failpoint::step("remove", &file);
    std::fs::remove_file(&file).map_err(super::step("removing the finished journal", &file))?;
    Ok(Some(journal))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("signorini-journal-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("runs")).unwrap();
        dir
    }

    #[test]
    fn a_journal_carried_out_twice_is_carried_out_once() {
        let dir = folder("twice");
        std::fs::write(dir.join("runs/.a.json.tmp1.0"), "new").unwrap();
        std::fs::write(dir.join("runs/a.json"), "old").unwrap();
        std::fs::write(dir.join("runs/b.json"), "gone").unwrap();
        let journal = Journal { renames: vec![("runs/.a.json.tmp1.0".into(), "runs/a.json".into())], removals: vec!["runs/b.json".into()] };
        journal.carry_out(&dir).unwrap();
        journal.carry_out(&dir).unwrap();
        assert_eq!(std::fs::read_to_string(dir.join("runs/a.json")).unwrap(), "new");
        assert!(!dir.join("runs/b.json").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_journal_naming_a_path_outside_its_folder_changes_nothing() {
        let dir = folder("outside");
        let study = dir.join("s");
        std::fs::create_dir_all(study.join("runs")).unwrap();
        std::fs::write(dir.join("victim"), "keep").unwrap();
        std::fs::write(study.join("runs/a.json"), "a").unwrap();
        for journal in [
            Journal { renames: vec![], removals: vec!["runs/a.json".into(), "../victim".into()] },
            Journal { renames: vec![], removals: vec![dir.join("victim")] },
            Journal { renames: vec![("runs/a.json".into(), "../victim".into())], removals: vec![] },
            Journal { renames: vec![("../victim".into(), "runs/b.json".into())], removals: vec![] },
            Journal { renames: vec![("../.accept/other/x".into(), "runs/b.json".into())], removals: vec![] },
        ] {
            let e = journal.carry_out(&study).unwrap_err();
            assert!(e.to_string().contains("outside"), "{e}");
            assert_eq!(std::fs::read_to_string(dir.join("victim")).unwrap(), "keep");
            assert!(study.join("runs/a.json").exists());
        }
        let staged = Journal { renames: vec![("../.accept/s/runs/a.json".into(), "runs/a.json".into())], removals: vec![] };
        assert_eq!(staged.outside(&study), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_pending_journal_rolls_forward_and_goes() {
        let dir = folder("pending");
        std::fs::write(dir.join("runs/.a.json.tmp1.0"), "new").unwrap();
        let journal = Journal { renames: vec![("runs/.a.json.tmp1.0".into(), "runs/a.json".into())], removals: vec![] };
        super::super::write_json(&dir.join(FILE), &journal).unwrap();
        assert_eq!(pending(&dir).unwrap(), Some(journal.clone()));
        assert_eq!(roll_forward(&dir).unwrap(), Some(journal));
        assert_eq!(std::fs::read_to_string(dir.join("runs/a.json")).unwrap(), "new");
        assert_eq!(pending(&dir).unwrap(), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
