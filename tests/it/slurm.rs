//! `scripts/slurm/submit.sh` checks every argument before it creates a folder or calls `sbatch`:
//! a bad call exits non-zero with a message naming what is wrong, creates nothing and submits
//! nothing. The script runs with a fake `sbatch` first on PATH that records each call.

use crate::common::scratch;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Every path under `dir`, sorted.
fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(listing(&p));
        }
        out.push(p);
    }
    out.sort();
    out
}

/// A folder to run the script in (`work`: a manifest `m.toml` and an executable `fake-bin`),
/// and a folder holding the fake `sbatch` and its log of calls.
struct Setup {
    work: PathBuf,
    tools: PathBuf,
}

impl Setup {
    fn new(name: &str) -> Self {
        use std::os::unix::fs::PermissionsExt;
        let root = scratch(&format!("slurm-{name}"));
        let (work, tools) = (root.join("work"), root.join("tools"));
        std::fs::create_dir_all(&work).unwrap();
        std::fs::create_dir_all(&tools).unwrap();
        std::fs::write(work.join("m.toml"), "").unwrap();
        let exe = |p: &Path, text: &str| {
            std::fs::write(p, text).unwrap();
            std::fs::set_permissions(p, std::fs::Permissions::from_mode(0o755)).unwrap();
        };
        exe(&work.join("fake-bin"), "#!/bin/sh\nexit 0\n");
        exe(&tools.join("sbatch"), &format!("#!/bin/sh\necho \"$*\" >> {}\necho 42\n", tools.join("calls").display()));
        Setup { work, tools }
    }

    /// (exit code, stderr) of `submit.sh args` in the work folder.
    fn submit(&self, args: &[&str]) -> (i32, String) {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/slurm/submit.sh");
        let path = format!("{}:{}", self.tools.display(), std::env::var("PATH").unwrap_or_default());
        let out = Command::new("bash").arg(script).args(args).current_dir(&self.work).env("PATH", path).output().unwrap();
        (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).into_owned())
    }

    fn sbatch_calls(&self) -> usize {
        std::fs::read_to_string(self.tools.join("calls")).map_or(0, |s| s.lines().count())
    }
}

#[test]
fn invalid_submit_arguments_are_refused_before_anything_is_created_or_submitted() {
    for (args, expected) in [
        (&["--tasks", "0", "m.toml"][..], "--tasks 0: expected a whole number >= 1"),
        (&["--tasks", "abc", "m.toml"][..], "--tasks abc: expected a whole number >= 1"),
        (&["--tasks", "-3", "m.toml"][..], "--tasks -3: expected"),
        (&["--tasks", "2.5", "m.toml"][..], "--tasks 2.5: expected"),
        (&["--cpus", "0", "m.toml"][..], "--cpus 0: expected"),
        (&["--tasks"][..], "--tasks needs a value"),
        (&["m.toml", "--tasks"][..], "the manifest comes last"),
        (&["--tasks", "--results", "r", "m.toml"][..], "--tasks needs a value"),
        (&["m.toml", "--tasks", "2"][..], "the manifest comes last"),
        (&["--bogus", "1", "m.toml"][..], "unknown option --bogus"),
        (&["--tasks", "2", "missing.toml"][..], "no manifest missing.toml"),
        (&["--tasks", "2"][..], "no manifest given"),
        (&[][..], "no manifest given"),
        (&["--bin", "no-such-bin", "m.toml"][..], "no binary no-such-bin"),
    ] {
        let s = Setup::new("bad");
        let before = listing(&s.work);
        let (code, err) = s.submit(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.starts_with("submit.sh: ") && err.contains(expected), "{args:?}: {err}");
        assert_eq!(listing(&s.work), before, "{args:?}: created something");
        assert_eq!(s.sbatch_calls(), 0, "{args:?}: called sbatch");
    }
}

#[test]
fn a_valid_submit_calls_sbatch_for_the_array_and_the_finish_job() {
    let s = Setup::new("good");
    let (code, err) = s.submit(&["--tasks", "3", "--results", "res", "--bin", "fake-bin", "m.toml"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(s.sbatch_calls(), 2, "{err}");
    let calls = std::fs::read_to_string(s.tools.join("calls")).unwrap();
    assert!(calls.contains("--array=1-3") && calls.contains("--dependency=afterok:42"), "{calls}");
    assert!(s.work.join("res/slurm-logs").is_dir());
}

/// `--tasks 5` for a study of 3 runs is not submitted (tasks 4 and 5 would fail, "this shard
/// holds no run", and the finish job, afterok, never run): the script asks the binary
/// (`run --plan --shard N/N`, which runs nothing) before it creates or submits anything.
#[test]
fn more_tasks_than_runs_are_refused_before_anything_is_submitted() {
    let s = Setup::new("tasks");
    std::fs::write(
        s.work.join("m.toml"),
        "[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\nlevels = 3\n[[run]]\nid = \"r1\"\n[[run]]\nid = \"r2\"\ntheta = 0.3\n[[run]]\nid = \"r3\"\nrefine = \"uniform\"\n",
    )
    .unwrap();
    let bin = env!("CARGO_BIN_EXE_signorini");
    let before = listing(&s.work);
    let (code, err) = s.submit(&["--tasks", "5", "--results", "res", "--bin", bin, "m.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.starts_with("submit.sh: --tasks 5: ") && err.contains("this shard holds no run (m has 3 run(s))"), "{err}");
    assert_eq!(listing(&s.work), before, "created something");
    assert_eq!(s.sbatch_calls(), 0);
    // as many tasks as runs: submitted
    let (code, err) = s.submit(&["--tasks", "3", "--results", "res", "--bin", bin, "m.toml"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(s.sbatch_calls(), 2, "{err}");
    // what --plan prints: the shard's runs, and nothing run
    let out = Command::new(bin).args(["run", "--plan", "--shard", "2/2", "m.toml"]).current_dir(&s.work).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(String::from_utf8_lossy(&out.stdout), "m/r2\n");
    assert!(!s.work.join("results").exists());
}
