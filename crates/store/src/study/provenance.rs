//! Provenance of a study's results (`results/STUDY/provenance.json`): git commit and dirty flag, Cargo.lock hash,
//! rustc version, the manifest's hash, machine, threads, date.

use model::base::digest::sha256_hex;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::process::Command;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Provenance {
    pub study: String,
    pub manifest: String,
    pub manifest_sha256: String,
    pub quick: bool,
    pub git_commit: Option<String>,
    /// Tracked files other than results/ differ from the commit.
    pub git_dirty: Option<bool>,
    pub cargo_lock_sha256: Option<String>,
    pub rustc: Option<String>,
    pub signorini_version: String,
    pub machine: Machine,
    pub threads: usize,
    /// The fill-reducing ordering: `auto` unless forced through `SIGNORINI_ORDERING` (a
    /// round-off measurement; see `settings::ordering::FORCE_ENV`).
    #[serde(default = "auto")]
    pub ordering: String,
    /// UTC, ISO 8601.
    pub date: String,
    /// SHA-256 of every mesh file the runs read (`gmsh:PATH` meshes), by path; absent when none.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub mesh_sha256: std::collections::BTreeMap<String, String>,
    /// Runs present in the study directory (merged by run id across shards and sessions).
    pub runs: Vec<String>,
    /// The problem files the manifest's runs name (absent for built-in problems only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub problem_files: Vec<ProblemFile>,
}

/// A problem file a study used: its path (as resolved from the manifest) and the SHA-256 of its
/// bytes (`None` if it could not be read).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProblemFile {
    pub path: String,
    pub sha256: Option<String>,
}

impl ProblemFile {
    pub fn of(path: &Path) -> Self {
        ProblemFile {
            path: path.display().to_string(),
            sha256: model::base::input::read(path, model::problems::file::PROBLEM_FILE).ok().map(|b| sha256_hex(&b)),
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Machine {
    pub cpu: String,
    pub cores: usize,
    pub memory_kb: Option<u64>,
    pub os: String,
}

fn auto() -> String {
    "auto".into()
}

fn command(cmd: &str, args: &[&str]) -> Option<String> {
    let out = Command::new(cmd).args(args).output().ok()?;
    out.status.success().then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

pub fn machine() -> Machine {
    let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let cpu =
        cpuinfo.lines().find(|l| l.starts_with("model name")).and_then(|l| l.split(':').nth(1)).unwrap_or("unknown").trim().to_string();
    let memory_kb = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| s.lines().next().and_then(|l| l.split_whitespace().nth(1)).and_then(|v| v.parse().ok()));
    Machine {
        cpu,
        cores: std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        memory_kb,
        os: format!("{} {}", std::env::consts::OS, std::env::consts::ARCH),
    }
}

/// Now as ISO 8601 UTC (days-from-civil inverse, Howard Hinnant's algorithm).
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0) as i64;
    let (days, rem) = (secs.div_euclid(86400), secs.rem_euclid(86400));
    let z = days + 719468;
    let era = z.div_euclid(146097);
    let doe = z - era * 146097;
    let yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + (m <= 2) as i64;
    format!("{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z", rem / 3600, rem / 60 % 60, rem % 60)
}

/// The checkout a manifest belongs to: the folder above its `experiments/`.
fn root_of(manifest_path: &Path) -> &Path {
    manifest_path.parent().and_then(|p| p.parent()).filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."))
}

/// A checkout's git commit and dirty flag.
type GitState = (Option<String>, Option<bool>);

/// The git commit of the checkout at `root` and whether tracked files outside results/ differ
/// from it (the study's own outputs are not the code).
fn git_state(root: &Path) -> GitState {
    let git_commit = command("git", &["-C", &root.to_string_lossy(), "rev-parse", "HEAD"]);
    let git_dirty =
        command("git", &["-C", &root.to_string_lossy(), "status", "--porcelain", "--untracked-files=no", "--", ".", ":(exclude)results"])
            .map(|s| !s.is_empty());
    (git_commit, git_dirty)
}

/// Why the commit `prov` names is no commit a reader can check out, if git can tell: the
/// checkout at `root` (the one `prov`'s manifest belongs to) does not hold it, or holds it off
/// the history of its HEAD (computed on a branch that was rewritten before it landed). `None`
/// when the commit is in that history, or when git cannot say (no git, no repository, a
/// shallow clone that lacks the older history, no commit recorded).
pub fn history_fault(prov: &Provenance, root: &Path) -> Option<String> {
    let commit = prov.git_commit.as_deref()?;
    let dir = root.to_string_lossy();
    if command("git", &["-C", &dir, "rev-parse", "--is-shallow-repository"])? != "false" {
        return None;
    }
    let status = |args: &[&str]| Command::new("git").args(["-C", &dir]).args(args).output().ok().map(|o| o.status.code());
    let known = status(&["cat-file", "-e", &format!("{commit}^{{commit}}")])? == Some(0);
    let ancestor = known && status(&["merge-base", "--is-ancestor", commit, "HEAD"])? == Some(0);
    let short = &commit[..commit.len().min(12)];
    match (known, ancestor) {
        (_, true) => None,
        (false, _) => Some(format!(
            "its results name commit {short}, which this repository does not hold (computed on a commit rewritten before it landed?): nobody can check out the code that produced them"
        )),
        (true, false) => Some(format!(
            "its results name commit {short}, which is not in the history of HEAD (computed on a branch that did not land as it was)"
        )),
    }
}

/// [`history_fault`] for the checkout `manifest_path` belongs to.
pub fn history_fault_of(prov: &Provenance, manifest_path: &Path) -> Option<String> {
    history_fault(prov, root_of(manifest_path))
}

/// The code that computes a run: what `provenance.json` names it by (the package version, the
/// git commit and whether the checkout was dirty) and the SHA-256 of the running executable,
/// which tells two builds of one dirty checkout apart. A run's checkpoint holds it, and a
/// resume takes over only the levels of this same code: levels of two builds under one
/// record's provenance would be no one build's run.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct CodeVersion {
    pub signorini_version: String,
    pub git_commit: Option<String>,
    pub git_dirty: Option<bool>,
    pub executable_sha256: Option<String>,
}

impl std::fmt::Display for CodeVersion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let commit = self.git_commit.as_deref().map_or("no git commit".to_string(), |c| format!("commit {}", &c[..c.len().min(12)]));
        let dirty = if self.git_dirty == Some(true) { " (dirty)" } else { "" };
        let exe = self.executable_sha256.as_deref().map_or("unknown".to_string(), |h| h[..h.len().min(12)].to_string());
        write!(f, "signorini {}, {commit}{dirty}, executable sha256 {exe}", self.signorini_version)
    }
}

/// This process's [`CodeVersion`] for the manifest at `manifest_path` (found once per checkout
/// and process: the code of a running process does not change).
pub fn code_version(manifest_path: &Path) -> CodeVersion {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    static EXE: OnceLock<Option<String>> = OnceLock::new();
    static BY_ROOT: OnceLock<Mutex<HashMap<std::path::PathBuf, GitState>>> = OnceLock::new();
    let executable_sha256 = EXE.get_or_init(|| std::env::current_exe().and_then(std::fs::read).ok().map(|b| sha256_hex(&b))).clone();
    let root = root_of(manifest_path).to_path_buf();
    let (git_commit, git_dirty) = BY_ROOT
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .entry(root)
        .or_insert_with_key(|r| git_state(r))
        .clone();
    CodeVersion { signorini_version: env!("CARGO_PKG_VERSION").to_string(), git_commit, git_dirty, executable_sha256 }
}

pub fn collect(study: &str, manifest_path: &Path, manifest_bytes: &[u8], quick: bool, runs: Vec<String>, meshes: &[&Path]) -> Provenance {
    let root = root_of(manifest_path);
    let (git_commit, git_dirty) = git_state(root);
    Provenance {
        study: study.to_string(),
        manifest: manifest_path.display().to_string(),
        manifest_sha256: sha256_hex(manifest_bytes),
        quick,
        git_commit,
        git_dirty,
        cargo_lock_sha256: std::fs::read(root.join("Cargo.lock")).ok().map(|b| sha256_hex(&b)),
        rustc: command("rustc", &["--version"]),
        signorini_version: env!("CARGO_PKG_VERSION").to_string(),
        machine: machine(),
        threads: rayon::current_num_threads(),
        ordering: match model::settings::ordering::forced() {
            Ok(Some(m)) => serde_json::to_value(m).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default(),
            _ => "auto".into(),
        },
        date: utc_now(),
        mesh_sha256: meshes
            .iter()
            .map(|m| {
                (
                    m.display().to_string(),
                    model::base::input::read(m, model::mesh::gmsh::MESH_FILE)
                        .map(|b| sha256_hex(&b))
                        .unwrap_or_else(|e| format!("(cannot read: {e})")),
                )
            })
            .collect(),
        runs,
        problem_files: Vec::new(),
    }
}
