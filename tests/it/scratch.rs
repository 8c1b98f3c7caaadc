//! Scratch folders as first-class citizens: a study rerun into a folder of its own is compared
//! with the stored results (`drift --against DIR`) and drawn there (`figures --results DIR
//! --study S`) without touching the tracked tree or `make test`'s drift report; a comparison
//! with nothing to compare, or with records made from an edited manifest, says so.

use crate::common::signorini_in;
use crate::common::{copy_dir, scratch};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Every file under `dir` with its contents' hash, sorted by path.
fn files_under(dir: &Path, out: &mut Vec<(PathBuf, String)>) {
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        if e.path().is_dir() {
            files_under(&e.path(), out);
        } else {
            out.push((e.path(), signorini::base::digest::sha256_hex(&std::fs::read(e.path()).unwrap())));
        }
    }
}

/// What a scratch-folder command must not change: the tracked results/ and figures/, and the
/// drift report `make test` leaves in target/drift/.
fn tracked_state() -> Vec<(PathBuf, String)> {
    let mut out = Vec::new();
    for d in ["results", "figures", "target/drift"] {
        files_under(&repo().join(d), &mut out);
    }
    out.retain(|(p, _)| !p.starts_with(repo().join("target/drift")) || p.extension().is_some_and(|e| e == "json"));
    out.sort();
    assert!(out.len() > 100, "the tracked results/ and figures/ were not found under {}", repo().display());
    out
}

/// A scratch folder holding the study `ex71` as a rerun into it would (its records are the
/// stored ones: that a rerun gives the stored numbers is what `make test`'s drift check shows,
/// so it is not computed a second time here), one copy per test (tests run concurrently and
/// write into their folder).
fn scratch_copy(name: &str) -> PathBuf {
    let dir = scratch(&format!("scratch-{name}"));
    copy_dir(&repo().join("results/ex71"), &dir.join("ex71"));
    dir
}

#[test]
fn drift_against_a_one_study_folder_compares_that_study_and_names_the_others() {
    let dir = scratch_copy("drift");
    let before = tracked_state();
    let (code, out, err) = signorini_in(repo(), &["drift", "--against", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}{err}");
    let d = dir.display();
    assert!(out.contains(&format!("drift: none (1 study of {d} compared with results at every level")), "{out}");
    assert!(
        out.contains(&format!("not compared (not in {d}): c0_sweep, contact_term_ablation, deep, estimator_repair, ex72, ex72_large")),
        "{out}"
    );
    assert!(!out.contains("--accept") && !err.contains("--accept"), "{out}{err}");
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("drift-report.json")).unwrap()).unwrap();
    assert_eq!(report["studies"].as_array().unwrap().len(), 1, "{report}");
    assert_eq!(report["studies"][0]["study"], "ex71");
    let declared = std::fs::read_dir(repo().join("experiments"))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().path().extension().is_some_and(|x| x == "toml"))
        .count();
    assert_eq!(report["not_compared"].as_array().unwrap().len(), declared - 1, "{report}");
    assert!(report["rows"].as_array().unwrap().is_empty());
    assert_eq!(tracked_state(), before, "drift --against changed results/, figures/ or target/drift/");
}

#[test]
fn figures_of_one_study_are_drawn_into_its_scratch_folder_only() {
    let dir = scratch_copy("figures");
    let before = tracked_state();
    let (code, out, err) = signorini_in(repo(), &["figures", "--results", dir.to_str().unwrap(), "--study", "ex71"]);
    assert_eq!(code, 0, "{out}{err}");
    let mut top: Vec<String> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    top.sort();
    assert_eq!(top, ["CLAIMS.md", "ex71", "figures"]);
    let mut figs: Vec<String> =
        std::fs::read_dir(dir.join("figures")).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    figs.sort();
    assert_eq!(figs, ["fig2a.png", "fig2a.svg", "fig2b.png", "fig2b.svg", "fig4a.png", "fig4a.svg"]);
    let claims = std::fs::read_to_string(dir.join("CLAIMS.md")).unwrap();
    assert!(claims.contains(&format!("from the records in `{}/`", dir.display())), "{claims}");
    // the row of the study it holds, judged on its runs (the deep study is not in the folder)
    let rate = claims.lines().find(|l| l.starts_with("| [**7.1-error-rate**]")).unwrap();
    assert!(rate.contains("ex71/adaptive") && !rate.contains("| no data |"), "{rate}");
    assert!(out.contains(&format!("wrote {}", dir.join("CLAIMS.md").display())), "{out}");
    assert_eq!(tracked_state(), before, "figures --results DIR changed results/, figures/ or target/drift/");
    // a study the folder does not hold is an error whose advice writes into that folder
    let (code, _, err) = signorini_in(repo(), &["figures", "--results", dir.to_str().unwrap(), "--study", "hertz"]);
    assert_eq!(code, 1);
    assert!(err.contains("does not hold it") && err.contains(&format!("--results {}", dir.display())), "{err}");
}

/// Two small declared studies (`one`, `two`, the same two runs) stored in `results/`, `one`
/// rerun into `scratch/`, and `one` rerun from an edited copy of its manifest into `edited/`.
fn small_store() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = scratch("scratch-small");
        let text = std::fs::read_to_string(repo().join("tests/fixtures/cli_pair.toml")).unwrap();
        for (folder, name, body) in
            [("experiments", "one", text.clone()), ("experiments", "two", text.clone()), ("edited", "one", text + "# edited\n")]
        {
            std::fs::create_dir_all(d.join(folder)).unwrap();
            std::fs::write(d.join(folder).join(format!("{name}.toml")), body).unwrap();
        }
        for args in [
            &["run", "experiments/one.toml", "experiments/two.toml", "--results", "results"][..],
            &["run", "experiments/one.toml", "--results", "scratch"],
            &["run", "edited/one.toml", "--results", "edited_results"],
        ] {
            let (code, _, err) = signorini_in(&d, args);
            assert_eq!(code, 0, "{args:?}: {err}");
        }
        d
    })
}

#[test]
fn drift_against_writes_its_report_beside_the_records_not_over_make_tests() {
    let d = small_store();
    let (code, out, err) = signorini_in(d, &["drift", "--against", "scratch"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("not compared (not in scratch): two") && out.contains("report: scratch/drift-report.json"), "{out}");
    assert!(!d.join("target").exists(), "the default report of `make test` (target/drift/) was written");
}

#[test]
fn drift_against_a_folder_with_nothing_to_compare_fails() {
    let d = small_store();
    std::fs::create_dir_all(d.join("empty")).unwrap();
    for (dir, args, expected) in [
        ("empty", &[][..], "nothing to compare"),
        ("no_such_folder", &[], "no_such_folder"),
        ("scratch", &["--study", "two"], "does not hold two"),
    ] {
        let mut a = vec!["drift", "--against", dir];
        a.extend_from_slice(args);
        let (code, out, err) = signorini_in(d, &a);
        assert_eq!(code, 1, "{dir}: {out}{err}");
        assert!(err.contains(expected) && err.contains(&format!("--against {dir}")), "{dir}: {err}");
        assert!(!out.contains("drift: none"), "{dir}: {out}");
    }
}

/// Records rerun from an edited manifest are not "no drift": the manifest's hash differs from
/// the stored provenance's, and the advice is about the scratch folder, not --accept.
#[test]
fn drift_against_records_of_an_edited_manifest_reports_the_manifest() {
    let d = small_store();
    let (code, out, err) = signorini_in(d, &["drift", "--against", "edited_results", "--study", "one"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.contains("manifest_sha256") && out.contains("edited/one.toml"), "{out}");
    assert!(err.contains("differ from the stored results in results") && err.contains("the stored results are unchanged"), "{err}");
    assert!(err.contains("--results edited_results") && !err.contains("--accept"), "{err}");
}
