//! The `records/` floor (above `estimator/`): the records schema (what a level, a run and a solve
//! report hold; [`report`]) and how records are written to disk. May import every floor below.
//!
//! Writing records to disk: always atomically (a temporary file in the same directory, then a
//! rename), so an interrupted run never leaves a half-written file behind, and a write that
//! fails leaves no temporary file either. Several files that must change together (a run's
//! record, its mesh snapshots and the summaries that list it) go through one [`Batch`]: every
//! file is written in full before any of them is renamed into place. JSON is checked before it
//! is written: a float JSON cannot hold (NaN, an infinity, which `serde_json` would write as
//! `null` and then refuse to read) is an error naming the field ([`first_non_finite`]).

mod error;
mod finite;
pub mod journal;
pub mod reference;

pub use error::RecordError;
pub use finite::{NonFinite, first_non_finite};
use model::level::sample::ContactSample;
pub use reference::{Rebuild, ReferenceRecord};

use std::io::Write;
use std::path::Path;

/// Wrap an I/O error with the step that failed and the path it failed on.
fn step(what: &'static str, on: &Path) -> impl FnOnce(std::io::Error) -> std::io::Error {
    RecordError::io(what, on)
}

/// Whether a file name is one of [`Batch`]'s temporary files (`.NAME.tmpPID.N`): what a process
/// killed while writing leaves behind.
pub fn is_temporary(name: &str) -> bool {
    let Some((_, tail)) = name.strip_prefix('.').and_then(|n| n.rsplit_once(".tmp")) else { return false };
    !tail.is_empty() && tail.split('.').all(|part| !part.is_empty() && part.bytes().all(|b| b.is_ascii_digit()))
}

/// The process that writes a temporary file ([`is_temporary`]: `.NAME.tmpPID.N`), from its name.
pub fn temporary_writer(name: &str) -> Option<u32> {
    if !is_temporary(name) {
        return None;
    }
    let (_, tail) = name.rsplit_once(".tmp")?;
    tail.split('.').next()?.parse().ok()
}

/// A temporary file next to `path`, unique within this process.
fn temporary_for(path: &Path) -> std::path::PathBuf {
    static COUNTER: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp{}.{n}", std::process::id()))
}

/// `path` may be replaced by a renamed file ([`model::base::input::check_target`]): the rename
/// would replace whatever is there, so a named pipe, a device or a folder is refused, naming it.
/// Checked when a file is staged and again just before its rename.
fn replaceable(path: &Path) -> std::io::Result<()> {
    model::base::input::check_target(path)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, format!("{}: {e}", path.display())))
}

/// What a write that failed with EFBIG ran into: the process's file-size limit (RLIMIT_FSIZE,
/// `ulimit -f`), with the size of the file, so that the message says what to raise, not only
/// which file. Empty for any other error.
fn size_limit_note(e: &std::io::Error, len: usize) -> String {
    if e.raw_os_error() != Some(libc::EFBIG) {
        return String::new();
    }
    let mut lim = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
    // SAFETY: getrlimit writes the struct it is given, nothing else
    if unsafe { libc::getrlimit(libc::RLIMIT_FSIZE, &mut lim) } != 0 || lim.rlim_cur == libc::RLIM_INFINITY {
        return format!(" (the file is {len} bytes)");
    }
    format!(
        " (the file is {len} bytes; this process may write files of at most {} bytes, its file-size limit `ulimit -f`: raise it, or write elsewhere)",
        lim.rlim_cur
    )
}

/// Files written in full to temporary files, then renamed into place together by
/// [`Batch::commit`], in the order they were added. Dropped without a commit (an error, an
/// interrupt), it removes its temporary files: nothing of it reaches the folder.
#[derive(Debug, Default)]
pub struct Batch {
    /// (temporary file, destination, SHA-256 of the bytes), in order.
    staged: Vec<(std::path::PathBuf, std::path::PathBuf, String)>,
}

impl Batch {
    /// Write `bytes` to a temporary file next to `path` (creating the directory). On an error
    /// the temporary file is removed and the error names the path and the step.
    pub fn add(&mut self, path: &Path, bytes: &[u8]) -> std::io::Result<()> {
        replaceable(path)?;
        model::base::input::create_folder(model::base::input::folder_of(path))?;
        let tmp = temporary_for(path);
        model::base::failpoint::step("write", &tmp);
        let written = std::fs::File::create(&tmp).and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        });
        if let Err(e) = written {
            let _ = std::fs::remove_file(&tmp);
            // named by the file meant (the temporary name means nothing to a reader), and the
            // folder a full disk must be cleared in
            let what = format!(
                "{} (through the temporary file {}, removed)",
                path.display(),
                tmp.file_name().unwrap_or_default().to_string_lossy()
            );
            return Err(std::io::Error::new(e.kind(), format!("writing {what}: {e}{}", size_limit_note(&e, bytes.len()))));
        }
        self.staged.push((tmp, path.to_path_buf(), model::base::digest::sha256_hex(bytes)));
        Ok(())
    }

    /// [`Batch::add`] for a value serialised as pretty JSON (see [`json_bytes`]).
    pub fn add_json<T: serde::Serialize>(&mut self, path: &Path, value: &T) -> std::io::Result<()> {
        self.add(path, &json_bytes(path, value)?)
    }

    /// The destinations of the files added so far, in order.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.staged.iter().map(|(_, p, _)| p.as_path())
    }

    /// The SHA-256 of the bytes staged for `path` (the last ones, if it was added twice).
    pub fn sha256_of(&self, path: &Path) -> Option<&str> {
        self.staged.iter().rev().find(|(_, p, _)| p == path).map(|(_, _, h)| h.as_str())
    }

    /// Rename every file into place, in order. If a rename fails, the files not yet renamed are
    /// removed (those renamed before stay) and the error names the file.
    pub fn commit(mut self) -> std::io::Result<()> {
        let staged = std::mem::take(&mut self.staged);
        let mut rest = staged.iter();
        for (tmp, path, _) in rest.by_ref() {
            model::base::failpoint::step("rename", path);
            let renamed = replaceable(path).and_then(|()| std::fs::rename(tmp, path).map_err(step("renaming the temporary file to", path)));
            if let Err(e) = renamed {
                let _ = std::fs::remove_file(tmp);
                rest.for_each(|(t, _, _)| drop(std::fs::remove_file(t)));
                return Err(e);
            }
        }
        Ok(())
    }
}

impl Batch {
    /// The renames that put the staged files into place, as a [`journal::Journal`] of `folder`
    /// (every staged file must lie inside it), and `removals` after them: what a change of a
    /// study folder commits as one. The temporary files are the journal's from here on: the
    /// batch no longer removes them when dropped.
    pub fn into_journal(mut self, folder: &Path, removals: Vec<std::path::PathBuf>) -> std::io::Result<journal::Journal> {
        let relative = |p: &Path| {
            p.strip_prefix(folder)
                .map(Path::to_path_buf)
                .map_err(|_| std::io::Error::other(format!("{} is staged outside the folder {} it changes", p.display(), folder.display())))
        };
        let mut renames = Vec::new();
        for (tmp, path, _) in &self.staged {
            renames.push((relative(tmp)?, relative(path)?));
        }
        let removals = removals.iter().map(|p| relative(p)).collect::<std::io::Result<_>>()?;
        self.staged.clear();
        Ok(journal::Journal { renames, removals })
    }
}

impl Drop for Batch {
    fn drop(&mut self) {
        for (tmp, _, _) in &self.staged {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

/// Write `bytes` to `path` atomically, creating the parent directory. An error names the path
/// and the step that failed; no temporary file is left.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut batch = Batch::default();
    batch.add(path, bytes)?;
    batch.commit()
}

/// The bytes of a file of a results folder (a record, `levels.csv`, `provenance.json`, a
/// reference, a mesh snapshot, a checkpoint, a drift report, a figure), through the one bounded
/// reader [`model::base::input::read`]: a path that is not a regular file after following
/// symlinks (a named pipe, `/dev/zero`, a folder) or is larger than
/// [`RESULTS_LIMIT`](model::base::input::RESULTS_LIMIT) is refused before it is opened (kind
/// `InvalidData`); a missing file keeps its kind (`NotFound`). An error names the path.
pub fn read_bytes(path: &Path) -> std::io::Result<Vec<u8>> {
    model::base::input::read(path, model::base::input::RESULTS_FILE).map_err(|e| step("reading", path)(input_error(e)))
}

/// Read a text file of a results folder ([`read_bytes`], then UTF-8); an error names the path.
pub fn read_text(path: &Path) -> std::io::Result<String> {
    model::base::input::read_text(path, model::base::input::RESULTS_FILE).map_err(|e| step("reading", path)(input_error(e)))
}

/// The reader's error as an `io::Error`: a failed file operation keeps its own (and kind),
/// a file refused for its type or size is `InvalidData`.
fn input_error(e: model::base::input::InputError) -> std::io::Error {
    match e {
        model::base::input::InputError::Io { error, .. } => error,
        other => std::io::Error::new(std::io::ErrorKind::InvalidData, other.to_string()),
    }
}

/// `value` as pretty JSON with a final newline, for the file `path`; an error (naming the path
/// and the field) if a float in it is not finite, since JSON cannot hold it.
pub fn json_bytes<T: serde::Serialize>(path: &Path, value: &T) -> std::io::Result<Vec<u8>> {
    if let Some(bad) = first_non_finite(value) {
        return Err(RecordError::NonFinite { path: path.into(), bad }.into());
    }
    let mut s = serde_json::to_string_pretty(value).map_err(|error| RecordError::Serialise { path: path.into(), error })?;
    s.push('\n');
    Ok(s.into_bytes())
}

/// The SHA-256 of a run record's file as the harness writes it ([`json_bytes`]; a stored
/// record is checked to be exactly that): what a drift report keeps of each record it compared,
/// and what the study page compares with the records it shows.
pub fn record_sha256(record: &RunRecord) -> String {
    json_bytes(Path::new("runs"), record).map(|b| model::base::digest::sha256_hex(&b)).unwrap_or_else(|e| format!("(not written: {e})"))
}

/// Serialise as pretty JSON (checked by [`json_bytes`]) and write atomically.
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> std::io::Result<()> {
    write_atomic(path, &json_bytes(path, value)?)
}

use model::level::history::History;
use model::level::record::LevelRecord;
use model::settings::adapt::{AdaptConfig, Refine};
use model::settings::estimator::{ContactTerm, EstimatorConfig};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// One run of a study: a problem, an initial mesh and every choice that affects the numbers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSpec {
    /// Unique within the study; names the run's record file.
    pub id: String,
    pub problem: String,
    pub mesh: String,
    pub refine: Refine,
    pub theta: f64,
    pub levels: usize,
    pub max_ndof: Option<usize>,
    /// Stop after the first level with at least this many unknowns (a deep run "to at least
    /// 1e7 NDF", whatever the marking makes of the last step); absent in runs without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stop_ndof: Option<usize>,
    pub estimator: EstimatorConfig,
    /// Example 7.2 has no exact solution: errors are measured against a reference solution
    /// computed on a finer mesh (see `study::reference`), if this is set.
    pub reference: Option<ReferenceSpec>,
    /// Levels whose mesh and fields are written as VTU (and as JSON for the mesh figure).
    pub save_levels: Vec<usize>,
    /// Values for some of a problem file's `[constants]` (the same problem at another load);
    /// empty for the file's own values and for built-in problems.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub constants: std::collections::BTreeMap<String, f64>,
    /// The SHA-256 of every file the run reads (problem file, Gmsh mesh), by its path as the
    /// manifest writes it: part of what the run is, so a run whose input changed is not the
    /// stored one. Empty for built-in problems and meshes.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub inputs: std::collections::BTreeMap<String, String>,
}

impl RunSpec {
    /// The adaptive loop's settings for this run.
    pub fn adapt_config(&self) -> AdaptConfig {
        AdaptConfig {
            levels: self.levels,
            max_ndof: self.max_ndof,
            stop_ndof: self.stop_ndof,
            refine: self.refine,
            theta: self.theta,
            estimator: self.estimator,
            ..Default::default()
        }
    }
}

/// How a reference solution is computed: adaptive refinement (maximum strategy with `theta`,
/// the estimator with `contact_term`) from the run's initial mesh until the NDF reaches
/// `min_ndof`. Fixed by the manifest, not by the run's length, so the quick form measures the
/// same errors. The default contact term drops full-contact nodes: with eta_5 as written the
/// refinement piles up along Gamma_C and leaves the body coarse, a biased reference.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceSpec {
    pub theta: f64,
    pub min_ndof: usize,
    pub contact_term: ContactTerm,
}

impl ReferenceSpec {
    /// The contact term of a reference whose manifest names none.
    pub const DEFAULT_CONTACT_TERM: ContactTerm = ContactTerm::WithoutFullContact;
}

/// The record of one finished run: its spec and one `LevelRecord` per level.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    pub study: String,
    pub run: RunSpec,
    pub levels: Vec<LevelRecord>,
    /// NDF of the reference solution, when errors are against one.
    pub reference_ndof: Option<usize>,
    /// The refinement history (marks and warm starts per level), from which any level can be
    /// rebuilt and solved again (`adapt::replay`, the drift check's replay tier).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub history: Option<History>,
    /// The SHA-256 of every mesh snapshot the run saved ([`RunRecord::saved_levels`]: the JSON
    /// and the VTU of each, by file name in `meshes/`), taken from the bytes stored with the
    /// record: what binds the snapshots to their run, so a swapped or edited snapshot is a fault
    /// of the run ([`StudyDir::read_snapshot`]). Empty for a run that saves none.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub snapshots: std::collections::BTreeMap<String, String>,
}

impl RunRecord {
    /// The levels whose mesh snapshot the run saves: those of `save_levels` it reached,
    /// ascending.
    pub fn saved_levels(&self) -> Vec<usize> {
        let mut levels: Vec<usize> = self.run.save_levels.iter().copied().filter(|&l| l < self.levels.len()).collect();
        levels.sort_unstable();
        levels.dedup();
        levels
    }
}

/// A mesh snapshot for the mesh figure: vertices, triangles, and the contact nodes (active or not,
/// with their contact forces).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MeshSnapshot {
    pub study: String,
    pub run: String,
    pub level: usize,
    pub ndof: usize,
    pub vertices: Vec<[f64; 2]>,
    pub triangles: Vec<[usize; 3]>,
    /// The contact nodes, in the order of the contact unknowns.
    pub contact_nodes: Vec<ContactSample>,
    /// Points the problem requires as vertices (the obstacle's kink).
    pub kinks: Vec<[f64; 2]>,
}

/// The JSON file at `path` read as a `T`; `None` if there is no such file; one that does not
/// parse, or cannot be read, is an error naming it.
fn read_if_present<T: serde::de::DeserializeOwned>(path: &Path) -> std::io::Result<Option<T>> {
    match read_text(path) {
        Ok(text) => serde_json::from_str(&text).map(Some).map_err(RecordError::parse(path)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(e),
    }
}

/// The folders of a results root that hold no study: what the commands write beside the
/// studies (`figures`, `report` with `--results DIR`, the bench's and the cross-check's tables,
/// the round-off measurements). No study may be named after one.
pub const NOT_STUDIES: [&str; 5] = ["figures", "report", "bench", "crosscheck", "roundoff"];

/// Why `name` cannot name a study (its folder `RESULTS/NAME`), if it cannot: empty, `.` or
/// `..`, hidden (a leading `.`: the harness's own folders, such as the staging folder of
/// `drift --accept`), starting with `-` (read as a flag), `runs` (a results root holding
/// `runs/` is taken for a study folder), a folder the results root holds that is no study
/// ([`NOT_STUDIES`]), or
/// holding a character other than ASCII letters, digits, `_`, `-` and `.` (a separator would
/// reach outside the results root). The one rule every study name is held to.
pub fn study_name_fault(name: &str) -> Option<String> {
    let fault = if name.is_empty() {
        "it is empty".to_string()
    } else if name == "." || name == ".." {
        format!("`{name}` names a folder that is no study's own (the results root or the one above it)")
    } else if name.starts_with('.') {
        "it starts with `.` (hidden names are the harness's own folders)".to_string()
    } else if name.starts_with('-') {
        "it starts with `-`, which the command line reads as a flag (`drift --accept -s` is refused as an unknown flag)".to_string()
    } else if name == "runs" {
        "`runs` would make the results root look like a study folder (a folder holding runs/ is one), and every command would then refuse the results root".to_string()
    } else if NOT_STUDIES.contains(&name) {
        format!("`{name}` is a folder the results root holds for other outputs ({})", NOT_STUDIES.join(", "))
    } else if let Some(c) = name.chars().find(|c| !(c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))) {
        format!("it holds {c:?}; a study name is ASCII letters, digits, `_`, `-` and `.`")
    } else {
        return None;
    };
    Some(fault)
}

/// A record file `runs/*.json`: its path, its text, and the run it holds or why it holds none.
pub type RunFile = (PathBuf, String, Result<RunRecord, serde_json::Error>);

/// Where a study's records live: `results/STUDY/`.
#[derive(Clone, Debug)]
pub struct StudyDir {
    pub root: PathBuf,
}

impl StudyDir {
    pub fn new(results: &Path, study: &str) -> Self {
        StudyDir { root: results.join(study) }
    }
    /// `runs/RUN.json`, one per run.
    pub fn run_file(&self, run: &str) -> PathBuf {
        self.root.join("runs").join(format!("{run}.json"))
    }
    /// `levels.csv`, one row per level of every run.
    pub fn csv_file(&self) -> PathBuf {
        self.root.join("levels.csv")
    }
    pub fn provenance_file(&self) -> PathBuf {
        self.root.join("provenance.json")
    }
    /// `references/KEY.json`: a reference solution's refinement history
    /// ([`ReferenceRecord::key_of`]).
    pub fn reference_file(&self, key: &str) -> PathBuf {
        self.root.join("references").join(format!("{key}.json"))
    }

    /// The stored reference solution of `key`, if there is one; one that does not parse is an
    /// error naming the file.
    pub fn read_reference(&self, key: &str) -> std::io::Result<Option<ReferenceRecord>> {
        read_if_present(&self.reference_file(key))
    }

    /// `meshes/RUN_levelL.vtu` and `.json`.
    pub fn mesh_file(&self, run: &str, level: usize, ext: &str) -> PathBuf {
        self.root.join("meshes").join(format!("{run}_level{level}.{ext}"))
    }

    /// The run and level of a mesh file's name (`RUN_levelL.vtu` or `.json`, the inverse of
    /// [`StudyDir::mesh_file`]); `None` for any other name.
    pub fn parse_mesh_name(name: &str) -> Option<(&str, usize)> {
        let stem = name.strip_suffix(".vtu").or_else(|| name.strip_suffix(".json"))?;
        let (run, level) = stem.rsplit_once("_level")?;
        let digits = !run.is_empty() && !level.is_empty() && level.bytes().all(|b| b.is_ascii_digit());
        if !digits {
            return None;
        }
        Some((run, level.parse().ok()?))
    }

    /// Every finished run of the study, in file-name order; a record that does not parse is an
    /// error naming it.
    pub fn read_runs(&self) -> std::io::Result<Vec<RunRecord>> {
        self.read_run_files()?.into_iter().map(|(f, _, r)| r.map_err(RecordError::parse(f))).collect()
    }

    /// Every record file `runs/*.json` with its text and the run it holds, in file-name order
    /// (what the store's integrity check reads: a record's run id must be its file name, its
    /// text what [`json_bytes`] writes for it). A file whose text is no record (truncated, not
    /// JSON, a link to another file) comes with the parser's error, for the check to name as a
    /// fault of its run (not an error here, which would leave `run --replace` no way past it).
    pub fn read_run_files(&self) -> std::io::Result<Vec<RunFile>> {
        let dir = self.root.join("runs");
        let mut files: Vec<PathBuf> = match std::fs::read_dir(&dir) {
            // a hidden name (`.NAME.json`) is no record: no run id starts with `.`
            Ok(rd) => rd
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == "json"))
                .filter(|p| !p.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.')))
                .collect(),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
            Err(e) => return Err(step("reading the directory", &dir)(e)),
        };
        files.sort();
        files
            .into_iter()
            .map(|f| {
                let text = read_text(&f)?;
                let record = serde_json::from_str(&text);
                Ok((f, text, record))
            })
            .collect()
    }

    pub fn read_run(&self, run: &str) -> std::io::Result<Option<RunRecord>> {
        read_if_present(&self.run_file(run))
    }

    /// The bytes of the snapshot `ext` (`json` or `vtu`) that `record` saves at `level`, checked
    /// against the SHA-256 the record holds for it: a snapshot edited, swapped with another run's
    /// or saved by no record is an error ([`RecordError::Snapshot`]), never read as this run's.
    pub fn read_snapshot(&self, record: &RunRecord, level: usize, ext: &str) -> std::io::Result<Vec<u8>> {
        let file = self.mesh_file(&record.run.id, level, ext);
        let bytes = read_bytes(&file)?;
        let name = file.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let found = model::base::digest::sha256_hex(&bytes);
        match record.snapshots.get(&name) {
            Some(held) if *held == found => Ok(bytes),
            held => Err(RecordError::Snapshot { path: file, run: record.run.id.clone(), held: held.cloned(), found }.into()),
        }
    }

    /// The mesh snapshot (JSON) `record` saves at `level`, its bytes checked by
    /// [`StudyDir::read_snapshot`].
    pub fn read_mesh(&self, record: &RunRecord, level: usize) -> std::io::Result<MeshSnapshot> {
        let bytes = self.read_snapshot(record, level, "json")?;
        serde_json::from_slice(&bytes).map_err(RecordError::parse(self.mesh_file(&record.run.id, level, "json")))
    }

    /// The bytes of `levels.csv` for these runs (written by the study's store): columns `run`,
    /// `problem`, `refine`, `theta`, `contact_term`, `log_factor`, `sampling`, then every
    /// `LevelRecord` field in its order. (The csv crate cannot serialise flattened structs, so
    /// rows go through serde_json values, whose maps keep field order.)
    pub fn csv_bytes(&self, runs: &[RunRecord]) -> std::io::Result<Vec<u8>> {
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut header_written = false;
        let text = |v: &serde_json::Value| match v {
            serde_json::Value::Null => String::new(),
            serde_json::Value::String(s) => s.clone(),
            other => other.to_string(),
        };
        for r in runs {
            let e = &r.run.estimator;
            let prefix = serde_json::json!({
                "run": r.run.id, "problem": r.run.problem, "refine": r.run.refine, "theta": r.run.theta,
                "contact_term": e.contact_term, "log_factor": e.log_factor, "sampling": e.sampling,
            });
            for l in &r.levels {
                let mut row = prefix.as_object().cloned().unwrap_or_default();
                if let serde_json::Value::Object(fields) = serde_json::to_value(l).map_err(std::io::Error::other)? {
                    row.extend(fields);
                }
                if !header_written {
                    w.write_record(row.keys()).map_err(std::io::Error::other)?;
                    header_written = true;
                }
                w.write_record(row.values().map(text)).map_err(std::io::Error::other)?;
            }
        }
        w.into_inner().map_err(std::io::Error::other)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_has_one_row_per_level_with_run_columns() {
        let dir = std::env::temp_dir().join(format!("signorini-csv-{}", std::process::id()));
        let study = StudyDir::new(&dir, "s");
        let level: LevelRecord = serde_json::from_value(serde_json::json!({
            "level": 0, "ndof": 10, "ndof_free": 8, "n_elements": 2, "h_min": 0.5, "h_max": 1.0, "min_angle": 45.0,
            "contact_nodes": 3, "active_nodes": 1, "full_contact_nodes": 0, "pdas_iterations": 2, "zone_min": null, "zone_max": null,
            "eta1": 1.0, "eta2": 2.0, "eta3": 3.0, "eta4": 4.0, "eta5": 5.0, "eta6": 6.0, "eta7": 7.0, "l_h": 1.5, "psi": 15.0,
            "eta_h": 30.0, "c0": 0.45, "estimate": 13.5, "err_quadrature": 0.1, "err_dense": 0.11, "err_nodal": null,
            "efficiency": 135.0, "marked": 1, "t_assembly": 0.0, "t_factorisation": 0.0, "t_active_set": 0.0, "t_solve": 0.0,
            "t_estimate": 0.0, "t_refine": 0.0, "t_level": 0.0
        }))
        .unwrap();
        let run = RunRecord {
            study: "s".into(),
            run: RunSpec {
                id: "a".into(),
                problem: "ex71".into(),
                mesh: "structured:4".into(),
                refine: Refine::Adaptive,
                theta: 0.5,
                levels: 2,
                max_ndof: None,
                stop_ndof: None,
                estimator: EstimatorConfig::default(),
                reference: None,
                save_levels: vec![],
                constants: Default::default(),
                inputs: Default::default(),
            },
            levels: vec![level.clone(), LevelRecord { level: 1, ..level }],
            reference_ndof: None,
            history: None,
            snapshots: Default::default(),
        };
        let text = String::from_utf8(study.csv_bytes(&[run]).unwrap()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(lines[0].starts_with("run,problem,refine,theta,contact_term,log_factor,sampling,level,ndof"), "{}", lines[0]);
        assert!(lines[1].starts_with("a,ex71,adaptive,0.5,as_written,squared,quadrature,0,10"), "{}", lines[1]);
        std::fs::remove_dir_all(&dir).ok();
    }
}
