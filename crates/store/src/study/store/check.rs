//! The store's integrity check ([`super::Store::check`]): what in a study folder does not hold
//! together (a record that is not its file's run, a snapshot missing or not its level, summaries
//! that are not what the records render, a reference that is not the runs'), and the leftovers
//! of an unfinished run (`orphans`).

use crate::records::{self, RunRecord, StudyDir};
use crate::study::provenance::Provenance;
use anyhow::{Context, Result};
use std::path::PathBuf;

/// Something in a study folder that does not hold together: the file and what is wrong with it.
#[derive(Clone, Debug, PartialEq)]
pub struct Fault {
    pub file: PathBuf,
    pub what: String,
    /// The stem of the record file at fault (`runs/STEM.json`, and its snapshots); `None` for a
    /// summary (`levels.csv`, `provenance.json`), which is rendered from the records.
    pub record: Option<String>,
}

impl std::fmt::Display for Fault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.file.display(), self.what)
    }
}

/// A study folder as read by [`super::Store::check`].
#[derive(Clone, Debug, Default)]
pub struct Checked {
    /// The records, in file-name order.
    pub runs: Vec<RunRecord>,
    /// What does not hold together (empty for a sound folder).
    pub faults: Vec<Fault>,
    /// Files of an unfinished run no record accounts for (`orphans`): `run` removes them,
    /// every reader names and ignores them.
    pub leftovers: Vec<PathBuf>,
}

impl Checked {
    /// The faults, one per line, for an error message.
    pub fn faults_text(&self) -> String {
        self.faults.iter().map(|f| format!("\n  {f}")).collect()
    }
}

/// Whether a finished run's record accounts for the snapshot of `run` at `level`.
fn saved(runs: &[RunRecord], run: &str, level: usize) -> bool {
    runs.iter().any(|r| r.run.id == run && r.run.save_levels.contains(&level) && level < r.levels.len())
}

/// The entries of `dir` that are not folders (one level, sorted by name): files, and also
/// symlinks, named pipes and devices, so that one the study never wrote under a snapshot's or a
/// temporary file's name is named as a leftover like a file; none if `dir` does not exist.
pub(super) fn files_in(dir: &std::path::Path) -> Result<Vec<(String, PathBuf)>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e).with_context(|| format!("reading the directory {}", dir.display())),
    };
    let mut out: Vec<(String, PathBuf)> = entries
        .flatten()
        .filter(|e| e.file_type().is_ok_and(|t| !t.is_dir()))
        .map(|e| (e.file_name().to_string_lossy().into_owned(), e.path()))
        .collect();
    out.sort();
    Ok(out)
}

/// The files of the study folder no finished run accounts for: temporary files (of a process
/// killed while writing) anywhere in it, and mesh snapshots of a run without a record or of a
/// level its record does not save (a run killed before it finished, an old binary's leftovers).
/// Files the study never writes are left alone, and so are the temporary files of a run another
/// process computes now (its run lock is held; ask under the study lock) and those of a process
/// that is running (a commit of another process, seen by a reader).
pub(super) fn orphans(dir: &StudyDir, runs: &[RunRecord]) -> Result<Vec<PathBuf>> {
    let meshes = dir.root.join("meshes");
    let mut out = Vec::new();
    let runs_dir = dir.root.join("runs");
    let references = dir.root.join("references");
    let keys: Vec<String> = runs.iter().filter_map(|r| records::ReferenceRecord::key_of(&r.run)).collect();
    // runs whose record is there but could not be read (a damaged record, a fault of its run):
    // what they saved and what they are measured against is not known, so none of it is an
    // orphan (a truncated record's snapshots and reference are kept, not removed as orphans)
    let unread: Vec<String> = files_in(&runs_dir)?
        .into_iter()
        .filter_map(|(name, _)| {
            name.strip_suffix(".json")
                .filter(|id| !records::is_temporary(&name) && !runs.iter().any(|r| r.run.id == *id))
                .map(str::to_string)
        })
        .collect();
    for sub in [dir.root.clone(), runs_dir.clone(), meshes.clone(), references.clone()] {
        for (name, path) in files_in(&sub)? {
            let stray_mesh = sub == meshes
                && StudyDir::parse_mesh_name(&name)
                    .is_some_and(|(run, level)| !saved(runs, run, level) && !unread.iter().any(|u| u == run));
            // a reference no stored run is measured against (its runs replaced or removed)
            let stray_reference =
                sub == references && unread.is_empty() && name.strip_suffix(".json").is_some_and(|k| !keys.iter().any(|key| key == k));
            let temporary = records::is_temporary(&name);
            // a temporary file of a run another process computes now is not an orphan
            let of_run = name.strip_prefix('.').and_then(|n| n.rsplit_once(".tmp")).and_then(|(target, _)| {
                if sub == runs_dir {
                    target.strip_suffix(".json").map(str::to_string)
                } else {
                    StudyDir::parse_mesh_name(target).map(|(run, _)| run.to_string()).filter(|_| sub == meshes)
                }
            });
            // nor is one whose writer (the process its name holds) is running: a summary being
            // committed by another process now
            let writer_alive =
                temporary && records::temporary_writer(&name).is_some_and(|pid| pid != std::process::id() && super::lock::running(pid));
            let in_progress = temporary && (writer_alive || of_run.is_some_and(|id| super::lock::run_in_progress(dir, &id)));
            if (temporary || stray_mesh || stray_reference) && !in_progress {
                out.push(path);
            }
        }
    }
    Ok(out)
}

/// The orphans' paths relative to the study folder, comma-separated.
pub fn names(dir: &StudyDir, files: &[PathBuf]) -> String {
    files.iter().map(|f| f.strip_prefix(&dir.root).unwrap_or(f).display().to_string()).collect::<Vec<_>>().join(", ")
}

/// The mesh snapshots `record` saves that are missing, are not the bytes the record holds the
/// SHA-256 of ([`StudyDir::read_snapshot`]: edited, another run's), or (the JSON the mesh
/// figures read) are not the run's level with the level's NDF, each with what is wrong.
pub(super) fn snapshot_faults(dir: &StudyDir, record: &RunRecord) -> Vec<(PathBuf, String)> {
    let id = &record.run.id;
    let mut out = Vec::new();
    for l in record.saved_levels() {
        for ext in ["json", "vtu"] {
            let file = dir.mesh_file(id, l, ext);
            match dir.read_snapshot(record, l, ext) {
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => out.push((file, format!("missing: run {id} saves level {l}"))),
                Err(e) => {
                    let what = without_path(&e.to_string(), &file);
                    out.push((file, what))
                }
                Ok(_) => {}
            }
        }
        match dir.read_mesh(record, l) {
            Ok(s) if s.run != *id || s.level != l || s.ndof != record.levels[l].ndof => out.push((
                dir.mesh_file(id, l, "json"),
                format!(
                    "is run {} level {} with {} unknowns, not run {id} level {l} with {}",
                    s.run, s.level, s.ndof, record.levels[l].ndof
                ),
            )),
            Err(e) if e.kind() == std::io::ErrorKind::Other => {
                out.push((dir.mesh_file(id, l, "json"), format!("does not parse as a mesh snapshot ({e})")))
            }
            _ => {}
        }
    }
    out
}

/// An error's text without the leading `PATH: ` or `reading PATH: ` it names (the fault names
/// the file already).
fn without_path(text: &str, file: &std::path::Path) -> String {
    let text = text.strip_prefix(&format!("{}: ", file.display())).unwrap_or(text);
    text.strip_prefix(&format!("reading {}: ", file.display())).unwrap_or(text).to_string()
}

/// The first line where two texts differ, shortened, as it reads in each.
/// (The excerpt starts a little before the first character that differs, so a long line shows
/// where it differs.)
pub fn first_difference(a: &str, b: &str) -> (String, String) {
    let (al, bl): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    let Some(i) = (0..al.len().max(bl.len())).find(|&i| al.get(i) != bl.get(i)) else {
        // the same lines: what differs is how they end (`lines` drops "\r\n" and a last "\n",
        // so a CRLF levels.csv would otherwise read "line 72: (none)" on both sides)
        return (line_endings(a), line_endings(b));
    };
    let (la, lb): (Vec<char>, Vec<char>) = (al.get(i).unwrap_or(&"").chars().collect(), bl.get(i).unwrap_or(&"").chars().collect());
    let at = la.iter().zip(&lb).take_while(|(x, y)| x == y).count();
    let from = at.saturating_sub(20);
    let cut = |s: Option<&&str>| {
        let text = s.map(|s| {
            let excerpt: String = s.chars().skip(from).take(60).collect();
            if from > 0 { format!("...{excerpt}") } else { excerpt }
        });
        format!("line {}: {}", i + 1, text.unwrap_or("(none)".into()))
    };
    (cut(al.get(i)), cut(bl.get(i)))
}

/// How the lines of `text` end: "\r\n" (Windows) or "\n", and whether the last one does.
fn line_endings(text: &str) -> String {
    let crlf = if text.contains("\r\n") { "\\r\\n (Windows line endings)" } else { "\\n" };
    let last = if text.ends_with('\n') { "the last line ends with one" } else { "the last line has no line end" };
    format!("the same lines, ending with {crlf}; {last}")
}

/// The summaries of a study against what its records render: `levels.csv` byte for byte,
/// `provenance.json` readable, of this study and listing exactly these runs. A folder with no
/// record and no summary has nothing to disagree.
pub fn summary_faults(dir: &StudyDir, study: &str, runs: &[RunRecord]) -> Vec<Fault> {
    let (csv, prov) = (dir.csv_file(), dir.provenance_file());
    if runs.is_empty() && !csv.exists() && !prov.exists() {
        return Vec::new();
    }
    let mut out = Vec::new();
    let mut by_run = Vec::new();
    let mut fault = |file: &std::path::Path, what: String| out.push(Fault { file: file.to_path_buf(), what, record: None });
    match (records::read_bytes(&csv), dir.csv_bytes(runs)) {
        (Ok(on_disk), Ok(rendered)) if on_disk == rendered => {}
        (Ok(on_disk), Ok(rendered)) => {
            let (a, b) = first_difference(&String::from_utf8_lossy(&on_disk), &String::from_utf8_lossy(&rendered));
            fault(&csv, format!("is not what runs/*.json render: {a}, rendered {b}"));
            by_run = csv_row_faults(dir, &on_disk, runs);
        }
        (Err(e), _) => fault(&csv, format!("cannot be read ({e})")),
        (_, Err(e)) => fault(&csv, format!("cannot be rendered from the records ({e})")),
    }
    let ids: Vec<String> = runs.iter().map(|r| r.run.id.clone()).collect();
    match records::read_text(&prov)
        .map_err(|e| e.to_string())
        .and_then(|t| serde_json::from_str::<Provenance>(&t).map_err(|e| e.to_string()))
    {
        Err(e) => fault(&prov, format!("cannot be read ({e})")),
        Ok(p) if p.runs != ids => fault(&prov, format!("lists the runs {}, the records are {}", p.runs.join(" "), ids.join(" "))),
        Ok(p) if p.study != study => fault(&prov, format!("is the provenance of study {}, not {study}", p.study)),
        Ok(p) => {
            if let Some((run, file, hash)) = input_not_in(&p, runs) {
                fault(&prov, format!("does not hold the sha256 {} of the input {file} that run {run} read", &hash[..hash.len().min(12)]))
            }
        }
    }
    out.extend(by_run);
    out
}

/// The first input a record read (its `inputs`: problem or mesh file and hash) whose hash the
/// provenance does not list among its meshes' and problem files' (an edited provenance; the
/// provenance may list more, the inputs of declared runs not stored yet).
pub(super) fn input_not_in<'r>(p: &Provenance, runs: &'r [RunRecord]) -> Option<(&'r str, &'r str, &'r str)> {
    let listed: std::collections::BTreeSet<&str> =
        p.mesh_sha256.values().map(String::as_str).chain(p.problem_files.iter().filter_map(|f| f.sha256.as_deref())).collect();
    runs.iter()
        .flat_map(|r| r.run.inputs.iter().map(move |(file, hash)| (r.run.id.as_str(), file.as_str(), hash.as_str())))
        .find(|(_, _, hash)| !listed.contains(hash))
}

/// The runs whose rows in `levels.csv` (`on_disk`, which differs from what the records render)
/// are not what their records render, each a fault of its record: a hand-edited record or CSV
/// row, a run missing from the CSV. Neither side can be trusted, so `run` refuses the folder and
/// `run --replace` computes those runs again instead of rendering the CSV from the records.
/// Rows are compared as fields (a CSV saved with other line ends or quoting is a fault of the
/// file alone, not of a run).
fn csv_row_faults(dir: &StudyDir, on_disk: &[u8], runs: &[RunRecord]) -> Vec<Fault> {
    let rows = |bytes: &[u8]| -> Vec<Vec<String>> {
        let mut reader = csv::ReaderBuilder::new().has_headers(true).flexible(true).from_reader(bytes);
        reader.records().filter_map(|r| r.ok()).map(|r| r.iter().map(str::to_string).collect()).collect()
    };
    let stored = rows(on_disk);
    let file = dir.csv_file();
    runs.iter()
        .filter_map(|r| {
            let rendered = rows(&dir.csv_bytes(std::slice::from_ref(r)).ok()?);
            let mine: Vec<&Vec<String>> = stored.iter().filter(|row| row.first() == Some(&r.run.id)).collect();
            let same = mine.len() == rendered.len() && mine.iter().zip(&rendered).all(|(a, b)| *a == b);
            (!same).then(|| {
                let what = match rendered.iter().zip(&mine).position(|(b, a)| *a != b) {
                    _ if mine.is_empty() => {
                        format!("has no row of run {} (runs/{}.json has {} levels)", r.run.id, r.run.id, rendered.len())
                    }
                    Some(level) => format!(
                        "row of run {} level {level} is not what runs/{}.json renders (the record or the row was changed)",
                        r.run.id, r.run.id
                    ),
                    None => format!("has {} rows of run {}, runs/{}.json has {} levels", mine.len(), r.run.id, r.run.id, rendered.len()),
                };
                Fault { file: file.clone(), what, record: Some(r.run.id.clone()) }
            })
        })
        .collect()
}

/// The stored reference solutions against the runs measured against them: each one present
/// parses, is the reference of the runs naming it (its key) and has the NDF they record. A
/// reference not stored is no fault here (a folder written before references were stored; the
/// drift check computes it and names it missing); `run` stores it (`RunWriter::stage_reference`).
pub fn reference_faults(dir: &StudyDir, runs: &[RunRecord]) -> Vec<Fault> {
    let mut out = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for r in runs {
        let Some(key) = records::ReferenceRecord::key_of(&r.run) else { continue };
        let file = dir.reference_file(&key);
        let what = match dir.read_reference(&key) {
            Ok(None) => continue,
            Err(e) => format!("cannot be read ({e})"),
            Ok(Some(stored)) if stored.key() != key => {
                format!("is the reference of {} on {}, not of run {}", stored.problem, stored.mesh, r.run.id)
            }
            Ok(Some(stored)) if Some(stored.rebuild.ndof) != r.reference_ndof => format!(
                "has {} unknowns; run {} was measured against a reference of {}",
                stored.rebuild.ndof,
                r.run.id,
                r.reference_ndof.map_or("none".to_string(), |n| n.to_string())
            ),
            Ok(Some(_)) => continue,
        };
        if seen.insert(file.clone()) {
            out.push(Fault { file, what, record: None });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    /// Texts with the same lines that differ in their line ends: the message says so
    /// rather than "line 72: (none)" on both sides.
    #[test]
    fn the_same_lines_with_other_line_ends_are_named_as_such() {
        let (a, b) = super::first_difference("a,b\r\n1,2\r\n", "a,b\n1,2\n");
        assert!(a.contains("\\r\\n (Windows line endings)") && b.contains("ending with \\n;"), "{a} / {b}");
        let (a, b) = super::first_difference("a,b\n1,2", "a,b\n1,2\n");
        assert!(a.contains("the last line has no line end") && b.contains("the last line ends with one"), "{a} / {b}");
        let (a, b) = super::first_difference("a,b\n1,2\n", "a,b\n1,3\n");
        assert_eq!((a.as_str(), b.as_str()), ("line 2: 1,2", "line 2: 1,3"));
    }
}
