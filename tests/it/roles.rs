//! Run roles (`role = "..."` in a manifest's [[run]] table): CLAIMS rows and figures find their
//! runs by role (`analysis::roles`). A role they need that a study does not declare is an error
//! when the manifests are read, by `figures`, `drift` and `run` alike, naming the role, the study and
//! what needs it; a role declared twice in a study is refused; the repository's manifests declare
//! every role needed; and a role is not part of what the provenance hashes.

use crate::common::{copy_dir, parse_err, scratch, signorini_in};
use signorini::analysis::roles::{self, NEEDED};
use signorini::manifest::{self, Manifest};
use std::path::{Path, PathBuf};

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A scratch copy of `experiments/` with `ex71.toml`'s run `adaptive` renamed and its role
/// line dropped (the run table rewritten by hand, as a maintainer might).
fn renamed_without_role(name: &str) -> PathBuf {
    let d = scratch(&format!("roles-{name}"));
    copy_dir(&repo().join("experiments"), &d.join("experiments"));
    let file = d.join("experiments/ex71.toml");
    let text = std::fs::read_to_string(&file).unwrap();
    let old = "id = \"adaptive\"\nrole = \"as-written\"\n";
    assert!(text.contains(old), "ex71.toml no longer declares its adaptive run as expected:\n{text}");
    std::fs::write(&file, text.replacen(old, "id = \"adaptive_paper\"\n", 1)).unwrap();
    d
}

/// The error names the role, the study's manifest and what needs the role.
fn assert_names_the_missing_role(code: i32, stderr: &str) {
    assert_ne!(code, 0, "{stderr}");
    assert!(stderr.contains("role = \"as-written\""), "does not name the role: {stderr}");
    assert!(stderr.contains("ex71.toml") && stderr.contains("study ex71"), "does not name the study: {stderr}");
    assert!(stderr.contains("7.1-") && stderr.contains("fig4a"), "does not say what needs it: {stderr}");
}

#[test]
fn a_run_renamed_without_its_role_fails_when_figures_reads_the_manifests() {
    let d = renamed_without_role("figures");
    let (code, _, err) = signorini_in(&d, &["figures", "--experiments", "experiments", "--results", "results", "--figures", "figures"]);
    assert_names_the_missing_role(code, &err);
    assert!(!d.join("figures").exists() && !d.join("results/CLAIMS.md").exists(), "drew something before the check");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn a_run_renamed_without_its_role_fails_when_drift_reads_the_manifests() {
    let d = renamed_without_role("drift");
    let (code, out, err) =
        signorini_in(&d, &["drift", "--quick", "--experiments", "experiments", "--results", "results", "--study", "ex71"]);
    assert_names_the_missing_role(code, &err);
    assert!(!out.contains("ex71/"), "reran a run before the check: {out}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn a_run_renamed_without_its_role_is_refused_by_run_before_anything_is_computed() {
    let d = renamed_without_role("run");
    let (code, out, err) = signorini_in(&d, &["run", "experiments/ex71.toml", "--quick", "--results", "results"]);
    assert_names_the_missing_role(code, &err);
    assert!(!d.join("results").exists() && !out.contains("ex71/"), "computed before the check: {out}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn the_check_reports_every_missing_role_of_the_manifests_read() {
    let d = renamed_without_role("check");
    let manifests = manifest::declared(&d.join("experiments"), &[]).unwrap();
    let e = roles::check(&manifests).unwrap_err().to_string();
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.contains("\"as-written\"") && e.contains("study ex71"), "{e}");
    // a study without a manifest has no data (its rows say so): its roles are not needed
    let only_fb: Vec<Manifest> = manifests.into_iter().filter(|m| m.study == "fb").collect();
    assert!(roles::check(&only_fb).is_ok());
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn a_role_declared_twice_in_a_study_is_refused() {
    let e = parse_err(
        "[defaults]\nproblem = \"ex71\"\nlevels = 4\n[[run]]\nid = \"a\"\nrole = \"as-written\"\n[[run]]\nid = \"b\"\nrole = \"as-written\"\n",
    );
    assert!(e.contains("run[1].role") && e.contains("\"as-written\" twice") && e.contains("\"a\" and \"b\""), "{e}");
    // in two studies it is two roles
    let ok = "[defaults]\nproblem = \"ex71\"\nlevels = 4\n[[run]]\nid = \"a\"\nrole = \"as-written\"\n";
    assert!(Manifest::parse(Path::new("experiments/one.toml"), ok).is_ok());
}

#[test]
fn a_role_is_a_plain_name_on_a_line_of_its_own() {
    let base = "[defaults]\nproblem = \"ex71\"\nlevels = 4\n[[run]]\nid = \"a\"\n";
    let e = parse_err(&format!("{base}role = \"As Written\"\n"));
    assert!(e.contains("run[0].role") && e.contains("lower-case"), "{e}");
    // written otherwise it would be hashed into the provenance
    let e = parse_err(&format!("{base}role = \"as-written\"   # the paper's run\n"));
    assert!(e.contains("run[0].role") && e.contains("a line of its own"), "{e}");
    let e = parse_err("[defaults]\nproblem = \"ex71\"\nlevels = 4\nrole = \"as-written\"\n[[run]]\nid = \"a\"\n");
    assert!(e.contains("defaults.role"), "{e}");
}

#[test]
fn the_declared_roles_satisfy_what_claims_and_figures_need() {
    let manifests = manifest::declared(&repo().join("experiments"), &[]).unwrap();
    let declared = roles::check(&manifests).unwrap_or_else(|e| panic!("{e}"));
    for role in NEEDED {
        // every needed study is declared (else its role would not be checked) ...
        let m = manifests.iter().find(|m| m.study == role.study).unwrap_or_else(|| panic!("{role:?}: no manifest {}", role.study));
        // ... and its role names a declared run, whose records are stored
        let id = declared.id(*role).unwrap();
        assert!(m.runs.iter().any(|p| p.spec.id == id), "{role:?}: run {id} not declared");
        let runs = signorini::records::StudyDir::new(&repo().join("results"), role.study).read_runs().unwrap();
        assert!(declared.find(&runs, *role).is_some(), "{role:?}: run {id} not stored in results/{}", role.study);
    }
    // one constant per (study, role)
    for (i, a) in NEEDED.iter().enumerate() {
        assert!(!NEEDED[..i].iter().any(|b| (b.study, b.name) == (a.study, a.name)), "{a:?} twice in NEEDED");
    }
}

#[test]
fn roles_are_not_hashed_into_the_provenance() {
    for m in manifest::declared(&repo().join("experiments"), &[]).unwrap() {
        let text = std::fs::read_to_string(&m.file).unwrap();
        let roles = text.lines().filter(|l| l.starts_with("role = ")).count();
        assert_eq!(m.roles.len(), roles, "{}", m.study);
        // the same manifest without its role lines: the same bytes hashed, the same runs
        let kept: String = text.split_inclusive('\n').filter(|l| !l.starts_with("role = ")).collect();
        let bare = Manifest::parse(&m.file, &kept).unwrap();
        assert!(bare.roles.is_empty());
        assert_eq!(m.bytes, kept.as_bytes(), "{}", m.study);
        assert_eq!(bare.bytes, m.bytes, "{}", m.study);
        assert_eq!(bare.runs, m.runs, "{}", m.study);
        let hash = signorini::base::digest::sha256_hex;
        assert_eq!(hash(text.as_bytes()) == hash(&m.bytes), roles == 0, "{}: the hash covers the role lines", m.study);
    }
}
