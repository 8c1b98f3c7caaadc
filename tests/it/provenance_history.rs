//! Every stored result names code a reader can check out: the commit each study's
//! `provenance.json` names is in the history of the commit that stores it, and the drift check
//! refuses stored results whose commit is not, saying why.

use crate::common::{scratch, signorini_in, stored_study};
use std::path::Path;

fn git(dir: &Path, args: &[&str]) -> Option<String> {
    let out =
        std::process::Command::new("git").args(["-c", "user.name=t", "-c", "user.email=t@t"]).args(args).current_dir(dir).output().ok()?;
    out.status.success().then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

#[test]
fn every_stored_provenance_names_a_commit_in_the_history_of_head() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    if git(repo, &["rev-parse", "--is-shallow-repository"]).as_deref() != Some("false") {
        eprintln!("skipped: {} is not a full git checkout (no git, or a shallow clone), so no commit can be checked", repo.display());
        return;
    }
    let mut checked = 0;
    for entry in std::fs::read_dir(repo.join("results")).unwrap().flatten() {
        let file = entry.path().join("provenance.json");
        let Ok(text) = std::fs::read_to_string(&file) else { continue };
        let prov: signorini::provenance::Provenance = serde_json::from_str(&text).unwrap();
        assert_eq!(signorini::provenance::history_fault(&prov, repo), None, "{}", file.display());
        assert!(prov.git_commit.is_some(), "{} names no commit", file.display());
        checked += 1;
    }
    assert!(checked >= 10, "only {checked} stored studies found");
}

const STUDY: &str = "description = \"one run\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\n[[run]]\nid = \"a\"\nlevels = 2\n";

#[test]
fn drift_refuses_stored_results_whose_commit_is_not_in_history_naming_it() {
    let dir = scratch("prov-history");
    if git(&dir, &["init", "-q"]).is_none() {
        eprintln!("skipped: git is not available");
        return;
    }
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/s.toml"), STUDY).unwrap();
    git(&dir, &["add", "exp"]).unwrap();
    git(&dir, &["commit", "-qm", "first"]).unwrap();
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    // a commit off the history of HEAD: made on a branch, then left
    git(&dir, &["checkout", "-qb", "side"]).unwrap();
    git(&dir, &["commit", "-q", "--allow-empty", "-m", "side"]).unwrap();
    let side = git(&dir, &["rev-parse", "HEAD"]).unwrap();
    git(&dir, &["checkout", "-q", "-"]).unwrap();
    let file = dir.join("res/s/provenance.json");
    let stored = std::fs::read_to_string(&file).unwrap();
    let head = git(&dir, &["rev-parse", "HEAD"]).unwrap();
    assert!(stored.contains(&head), "the provenance names HEAD: {stored}");
    for (commit, says) in [(side.as_str(), "not in the history of HEAD"), ("0123456789abcdef0123456789abcdef01234567", "does not hold")] {
        std::fs::write(&file, stored.replace(&head, commit)).unwrap();
        let (code, out, err) = signorini_in(&dir, &["drift", "--experiments", "exp", "--results", "res", "--against", "res"]);
        assert_eq!(code, 1, "{out}{err}");
        assert!(err.contains(says) && err.contains(&commit[..12]) && err.contains("drift --accept s"), "{err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
