//! Studies: malformed manifests are clear errors; results are the same on 1 and 2 threads; an
//! interrupted study resumes; the quick form is an exact prefix of the full one.

use crate::common;
use crate::common::{fixture_path, scratch};
use common::parse_err;

use signorini::manifest::{Manifest, ManifestError};
use signorini::records::{RunRecord, StudyDir};
use std::path::Path;
use std::process::Command;

fn signorini(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_signorini")).args(args).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "{err}");
    (out.status.success(), err)
}

/// Records without timings (fields t_*), as JSON values.
fn numbers(r: &RunRecord) -> serde_json::Value {
    let mut v = serde_json::to_value(r).unwrap();
    for l in v["levels"].as_array_mut().unwrap() {
        l.as_object_mut().unwrap().retain(|k, _| !signorini::level::record::is_measurement(k));
    }
    v
}

#[test]
fn malformed_manifests_name_file_key_and_expectation() {
    let base = "[defaults]\nproblem = \"ex71\"\nlevels = 3\n";
    let e = parse_err(&format!("{base}[[run]]\nid = \"a\"\ntheta = 1.5\n"));
    assert!(e.contains("run[0].theta") && e.contains("(0, 1]") && e.contains("1.5"), "{e}");
    let e = parse_err(&format!("{base}[[run]]\nid = \"a\"\nproblem = \"ex9\"\n"));
    assert!(e.contains("run[0].problem") && e.contains("ex71") && e.contains("ex9"), "{e}");
    let e = parse_err(&format!("{base}[[run]]\nid = \"a\"\nmesh = \"cube:3\"\n"));
    assert!(e.contains("run[0].mesh") && e.contains("structured:N"), "{e}");
    let e = parse_err(&format!("{base}[[run]]\ntheta = 0.5\n"));
    assert!(e.contains("run[0].id"), "{e}");
    let e = parse_err(&format!("{base}[[run]]\nid = \"a\"\n[[run]]\nid = \"a\"\n"));
    assert!(e.contains("run[1].id") && e.contains("unique"), "{e}");
    let e = parse_err(&format!("{base}[[run]]\nid = \"a\"\ntheeta = 0.5\n"));
    assert!(e.contains("theeta"), "unknown keys are named: {e}");
    let e = parse_err(&format!("{base}[[run]]\nid = \"a\"\nlevels = \"many\"\n"));
    assert!(e.contains("levels"), "{e}");
    let e = parse_err(&format!("{base}[[run]]\nid = \"a\"\nestimator = {{ c0 = -1.0 }}\n"));
    assert!(e.contains("estimator.c0") && e.contains("positive"), "{e}");
    let e = parse_err(&format!("{base}[[run]]\nid = \"a\"\nestimator = {{ log_factor = \"cubed\" }}\n"));
    assert!(e.contains("cubed") && e.contains("squared"), "{e}");
    let e = parse_err(base);
    assert!(e.contains("run"), "{e}");
    assert!(matches!(Manifest::load(Path::new("experiments/does_not_exist.toml")), Err(ManifestError::Read { .. })));
}

#[test]
fn a_malformed_manifest_via_cli_is_a_clear_error() {
    let d = scratch("study-badcli");
    let f = d.join("bad_study.toml");
    std::fs::write(&f, "[[run]]\nid = \"a\"\nproblem = \"ex71\"\nlevels = 0\n").unwrap();
    let (ok, err) = signorini(&["run", f.to_str().unwrap(), "--results", d.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("bad_study.toml") && err.contains("run[0].levels"), "{err}");
    let (ok, err) = signorini(&["run", &fixture_path("tiny.toml"), "--shard", "3/2", "--results", d.to_str().unwrap()]);
    assert!(!ok && err.contains("--shard"), "{err}");
}

#[test]
fn same_numbers_on_one_and_two_threads() {
    let (d1, d2) = (scratch("study-j1"), scratch("study-j2"));
    assert!(signorini(&["run", &fixture_path("tiny.toml"), "--jobs", "1", "--results", d1.to_str().unwrap()]).0);
    assert!(signorini(&["run", &fixture_path("tiny.toml"), "--jobs", "2", "--results", d2.to_str().unwrap()]).0);
    let (r1, r2) = (StudyDir::new(&d1, "tiny").read_runs().unwrap(), StudyDir::new(&d2, "tiny").read_runs().unwrap());
    assert_eq!(r1.len(), 2);
    for (a, b) in r1.iter().zip(&r2) {
        assert_eq!(numbers(a), numbers(b), "run {} differs between 1 and 2 threads", a.run.id);
    }
    // errors against the reference solution are there for ex72
    assert!(r1[0].levels.iter().all(|l| l.err_quadrature.is_some()));
}

#[test]
fn interrupted_study_resumes_and_shards_merge() {
    let d = scratch("study-resume");
    let res = d.to_str().unwrap();
    // the first shard stands for a study interrupted after its first run
    assert!(signorini(&["run", &fixture_path("tiny.toml"), "--shard", "1/2", "--results", res]).0);
    let dir = StudyDir::new(&d, "tiny");
    assert_eq!(dir.read_runs().unwrap().len(), 1);
    let before = std::fs::metadata(dir.run_file("a")).unwrap().modified().unwrap();
    let (ok, err) = signorini(&["run", &fixture_path("tiny.toml"), "--results", res]);
    assert!(ok);
    assert!(err.contains("tiny/a: finished earlier, kept"), "{err}");
    assert_eq!(std::fs::metadata(dir.run_file("a")).unwrap().modified().unwrap(), before, "finished run rewritten");
    let runs = dir.read_runs().unwrap();
    assert_eq!(runs.len(), 2);
    let csv = std::fs::read_to_string(dir.csv_file()).unwrap();
    assert_eq!(csv.lines().count(), 1 + 5 + 4);
    let prov: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.provenance_file()).unwrap()).unwrap();
    for key in ["git_commit", "git_dirty", "cargo_lock_sha256", "rustc", "manifest_sha256", "machine", "threads", "date"] {
        assert!(prov.get(key).is_some(), "provenance lacks {key}");
    }
    // --fresh starts over
    let (ok, err) = signorini(&["run", &fixture_path("tiny.toml"), "--fresh", "--results", res]);
    assert!(ok && !err.contains("finished earlier"), "{err}");
}

#[test]
fn quick_form_is_an_exact_prefix() {
    let (dq, df) = (scratch("study-quick"), scratch("study-full"));
    assert!(signorini(&["run", &fixture_path("tiny.toml"), "--quick", "--results", dq.to_str().unwrap()]).0);
    assert!(signorini(&["run", &fixture_path("tiny.toml"), "--results", df.to_str().unwrap()]).0);
    let (q, f) = (StudyDir::new(&dq, "tiny").read_runs().unwrap(), StudyDir::new(&df, "tiny").read_runs().unwrap());
    for (q, f) in q.iter().zip(&f) {
        let (qn, fn_) = (numbers(q), numbers(f));
        let (ql, fl) = (qn["levels"].as_array().unwrap(), fn_["levels"].as_array().unwrap());
        assert!(ql.len() < fl.len());
        for (a, b) in ql.iter().zip(fl) {
            assert_eq!(a, b, "run {}: quick level differs from the full run", q.run.id);
        }
    }
}

/// A reference solution rebuilt from its stored history in one solve is the one the adaptive
/// loop computed, bit for bit, at points anywhere in the body; a history whose marks were
/// altered does not rebuild (its meshes' fingerprints are checked) and says at which level.
#[test]
fn stored_reference_replays_to_the_computed_one() {
    use signorini::mesh::MeshSpec;
    use signorini::study::reference;
    let m = Manifest::load(Path::new(&fixture_path("tiny.toml"))).unwrap();
    let spec = &m.runs[0].spec;
    let reference_spec = spec.reference.as_ref().unwrap();
    let problem = signorini::problems::load(&spec.problem, &spec.constants).unwrap();
    let mesh_spec = MeshSpec::parse(&spec.mesh).unwrap();
    let computed =
        reference::compute(problem.as_ref(), &mesh_spec, reference_spec, &mut |_| std::ops::ControlFlow::Continue(())).unwrap().unwrap();
    assert!(computed.rebuild.history.levels.len() > 3, "the reference loop refines several levels");
    let replayed = reference::replay(problem.as_ref(), &mesh_spec, reference_spec, &computed.rebuild, &m.drift).unwrap();
    assert_eq!(replayed.ndof, computed.ndof);
    for i in 0..=20 {
        for j in 0..=20 {
            let x = [i as f64 / 20.0, j as f64 / 20.0];
            assert_eq!(replayed.eval(x), computed.eval(x), "at {x:?}");
        }
    }
    let mut altered = computed.rebuild.clone();
    let level = altered.history.levels.len() / 2;
    let mut marks = altered.history.levels[level].marks.decode().unwrap();
    let first_unmarked = marks.iter().position(|m| !m).unwrap();
    marks[first_unmarked] = true;
    altered.history.levels[level].marks = signorini::level::history::Flags::encode(&marks);
    let e = reference::replay(problem.as_ref(), &mesh_spec, reference_spec, &altered, &m.drift)
        .err()
        .expect("altered marks do not replay")
        .to_string();
    assert!(e.contains(&format!("level {}", level + 1)) && e.contains("fingerprint"), "{e}");
}
