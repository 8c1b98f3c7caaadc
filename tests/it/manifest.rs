//! Manifests: every setting the loop cannot use is an error naming the file and the key, checked by
//! the same `AdaptConfig::validate` as the command line; unknown keys are errors everywhere;
//! serde's Rust type names never reach the reader.

use crate::common;
use crate::common::{fixture, one_run_manifest, scratch, signorini_in_time};
use common::parse_err;
use signorini::manifest::Manifest;
use signorini::settings::adapt::AdaptConfig;
use std::path::Path;

const BASE: &str = "[defaults]\nproblem = \"ex71\"\nlevels = 24\n";

fn run_with(extra: &str) -> String {
    parse_err(&format!("{BASE}[[run]]\nid = \"a\"\n{extra}\n"))
}

#[test]
fn save_levels_beyond_the_run_are_errors() {
    let e = run_with("save_levels = [99]");
    assert!(e.contains("run[0].save_levels") && e.contains("99") && e.contains("0..=23"), "{e}");
    let e = run_with("levels = 3\nsave_levels = [0, 3]");
    assert!(e.contains("run[0].save_levels") && e.contains("got 3"), "{e}");
    // the defaults' save_levels are checked against each run's levels
    let e =
        parse_err("[defaults]\nproblem = \"ex71\"\nlevels = 5\nsave_levels = [4]\n[[run]]\nid = \"a\"\n[[run]]\nid = \"b\"\nlevels = 2\n");
    assert!(e.contains("run[1].save_levels"), "{e}");
}

#[test]
fn invalid_loop_settings_are_errors_from_the_one_validation() {
    let e = run_with("max_ndof = 0");
    assert!(e.contains("run[0].max_ndof") && e.contains(">= 1"), "{e}");
    let e = run_with("levels = 0");
    assert!(e.contains("run[0].levels") && e.contains(">= 1"), "{e}");
    let e = run_with("theta = 1.01");
    assert!(e.contains("run[0].theta") && e.contains("(0, 1]"), "{e}");
    let e = run_with("estimator = { c0 = 0.0 }");
    assert!(e.contains("run[0].estimator.c0") && e.contains("positive"), "{e}");
    let e = run_with("reference = { theta = 0.5, min_ndof = 0 }");
    assert!(e.contains("run[0].reference.min_ndof"), "{e}");
}

#[test]
fn adapt_config_validate_rejects_what_the_loop_cannot_run() {
    assert_eq!(AdaptConfig::default().validate(), Ok(()));
    let bad = [
        AdaptConfig { theta: 1.5, ..Default::default() },
        AdaptConfig { theta: 0.0, ..Default::default() },
        AdaptConfig { theta: f64::NAN, ..Default::default() },
        AdaptConfig { levels: 0, ..Default::default() },
        AdaptConfig { max_ndof: Some(0), ..Default::default() },
    ];
    let keys = ["theta", "theta", "theta", "levels", "max_ndof"];
    for (c, key) in bad.iter().zip(keys) {
        let e = c.validate().unwrap_err();
        assert_eq!(e.key, key);
        assert!(e.to_string().contains("expected"), "{e}");
    }
    let mut c = AdaptConfig::default();
    c.estimator.c0 = -1.0;
    assert_eq!(c.validate().unwrap_err().key, "estimator.c0");
    c = AdaptConfig::default();
    c.pdas.max_iterations = 0;
    assert_eq!(c.validate().unwrap_err().key, "pdas.max_iterations");
}

#[test]
fn wrong_keys_are_errors_everywhere() {
    for (text, key) in [
        (format!("{BASE}[[run]]\nid = \"a\"\nsave_level = [1]\n"), "save_level"),
        (format!("{BASE}lvels = 3\n[[run]]\nid = \"a\"\n"), "lvels"),
        (format!("descripton = \"x\"\n{BASE}[[run]]\nid = \"a\"\n"), "descripton"),
        (format!("{BASE}[[run]]\nid = \"a\"\nestimator = {{ c_0 = 1.0 }}\n"), "c_0"),
        (format!("{BASE}[[run]]\nid = \"a\"\nreference = {{ theta = 0.5, min_ndof = 10, thta = 1 }}\n"), "thta"),
        (format!("{BASE}[defaults.estimator]\nsamplng = \"dense\"\n[[run]]\nid = \"a\"\n"), "samplng"),
    ] {
        let e = parse_err(&text);
        assert!(e.contains(key), "{key}: {e}");
    }
    // keys that only make sense per run are not silently ignored in [defaults]
    let e = parse_err(&format!("{BASE}id = \"x\"\n[[run]]\nid = \"a\"\n"));
    assert!(e.contains("defaults.id"), "{e}");
    let e = parse_err(&format!("{BASE}no_reference = true\n[[run]]\nid = \"a\"\n"));
    assert!(e.contains("defaults.no_reference"), "{e}");
}

#[test]
fn no_reference_drops_the_defaults_reference() {
    let text = "[defaults]\nproblem = \"ex72\"\nlevels = 3\nreference = { theta = 0.5, min_ndof = 4000 }\n[[run]]\nid = \"a\"\n[[run]]\nid = \"b\"\nno_reference = true\n";
    let m = Manifest::parse(Path::new("x.toml"), text).unwrap();
    assert!(m.runs[0].spec.reference.is_some());
    assert!(m.runs[1].spec.reference.is_none());
    // and the format documentation says so
    let doc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/store/src/study/manifest.rs")).unwrap();
    assert!(doc.contains("no_reference = true") && !doc.contains("`reference = false`"));
}

#[test]
fn type_errors_speak_toml_not_rust() {
    for (extra, expected) in [
        ("levels = -1", "a non-negative integer"),
        ("levels = \"many\"", "a non-negative integer"),
        ("theta = \"half\"", "a number"),
        ("save_levels = 3", "an array"),
        ("reference = 3", "a table"),
        ("estimator = 2", "a table"),
    ] {
        let e = run_with(extra);
        assert!(e.contains(expected), "{extra}: {e}");
        for rust in ["usize", "f64", "struct", "ReferenceToml", "EstimatorOverrides", "RunToml", "Option"] {
            assert!(!e.contains(rust), "{extra}: Rust type name {rust} in: {e}");
        }
    }
}

#[test]
fn every_declared_study_still_parses() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments");
    for f in std::fs::read_dir(&dir).unwrap() {
        let f = f.unwrap().path();
        if f.extension().is_some_and(|e| e == "toml") {
            Manifest::load(&f).unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

/// One file spelt two ways in a manifest (`./p.toml`, `problems/../p.toml`) is one spec:
/// `./p.toml` is no changed input against a run stored with `p.toml`.
#[test]
fn a_path_spelt_another_way_is_the_same_spec() {
    use signorini::manifest::spelled;
    assert_eq!(spelled("./problems/hertz.toml"), "problems/hertz.toml");
    assert_eq!(spelled("problems/./../problems//hertz.toml"), "problems/hertz.toml");
    assert_eq!(spelled("../shared/p.toml"), "../shared/p.toml");
    assert_eq!(spelled("/abs/./dir/../p.toml"), "/abs/p.toml");
    let dir = std::env::temp_dir().join(format!("signorini-spelled-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/problems/ex71.toml"), dir.join("p.toml")).unwrap();
    let text = |problem: &str| {
        format!("description = \"d\"\n[defaults]\nproblem = \"{problem}\"\nmesh = \"structured:2\"\n[[run]]\nid = \"a\"\nlevels = 2\n")
    };
    let a = Manifest::parse(&dir.join("s.toml"), &text("p.toml")).unwrap();
    let b = Manifest::parse(&dir.join("s.toml"), &text("./p.toml")).unwrap();
    assert_eq!(a.runs[0].spec, b.runs[0].spec);
    // the same file by its absolute path (not "changed ... none now")
    let c = Manifest::parse(&dir.join("s.toml"), &text(&dir.join("p.toml").display().to_string())).unwrap();
    assert_eq!(c.runs[0].spec, a.runs[0].spec);
    // one mesh, one spelling
    for mesh in ["structured:02", "structured: 2", " structured:2 "] {
        let c = Manifest::parse(&dir.join("s.toml"), &text("p.toml").replace("structured:2", mesh)).unwrap();
        assert_eq!(c.runs[0].spec, a.runs[0].spec, "{mesh:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_run_id_that_hides_its_record_or_clashes_by_case_is_refused() {
    for (id, says) in [
        (".", "starts with a letter or digit"),
        (".hidden", "starts with a letter or digit"),
        ("-a", "starts with a letter or digit"),
        ("A", r#""A" and "a", the same name but for case"#),
        ("a", r#""a" twice"#),
    ] {
        let text = fixture("tiny.toml").replace(r#"id = "b""#, &format!("id = {id:?}"));
        let err = common::parse_err(&text);
        assert!(err.contains("key `run[1].id`") && err.contains(says), "{id}: {err}");
    }
    // what the id check still accepts
    for id in ["b.2", "B_2-x", "0"] {
        let text = fixture("tiny.toml").replace(r#"id = "b""#, &format!("id = {id:?}"));
        signorini::manifest::Manifest::parse(std::path::Path::new("experiments/tiny.toml"), &text).unwrap();
    }
}

#[test]
fn a_run_id_longer_than_the_store_s_file_names_allow_is_refused_by_key() {
    let dir = scratch("manifest-long-id");
    let long = "x".repeat(300);
    let file = one_run_manifest(&dir, "s", &long, "");
    let (code, _, err) = signorini_in_time(&dir, &["run", &file, "--results", "r"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("key `run[0].id`") && err.contains("at most 128 characters") && err.contains("300 characters"), "{err}");
    assert!(!dir.join("r").exists(), "something was written before the refusal");
    // the longest accepted id makes every file of a run, snapshots included
    let longest = "y".repeat(128);
    let file = one_run_manifest(&dir, "t", &longest, "save_levels = [1]\n");
    let (code, _, err) = signorini_in_time(&dir, &["run", &file, "--results", "r"]);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("r/t/runs").join(format!("{longest}.json")).is_file());
    assert!(dir.join("r/t/meshes").join(format!("{longest}_level1.vtu")).is_file());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_odd_symmetric_mesh_in_a_manifest_keeps_the_parser_s_reason() {
    let dir = scratch("manifest-symmetric");
    let file = one_run_manifest(&dir, "s", "a", "mesh = \"symmetric:3\"\n");
    let (code, _, err) = signorini_in_time(&dir, &["run", &file, "--results", "r"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("key `run[0].mesh`") && err.contains("N even") && err.contains("use symmetric:2 or symmetric:4"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn two_manifests_of_one_study_with_different_runs_are_refused_before_any_run() {
    let dir = scratch("manifest-two");
    for sub in ["one", "two"] {
        std::fs::create_dir(dir.join(sub)).unwrap();
    }
    one_run_manifest(&dir.join("one"), "s", "a", "");
    one_run_manifest(&dir.join("two"), "s", "a", "theta = 0.3\n");
    let (code, _, err) = signorini_in_time(&dir, &["run", "one/s.toml", "two/s.toml", "--results", "r"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("one/s.toml and two/s.toml both declare study s with different runs"), "{err}");
    assert!(!dir.join("r").exists(), "a run was computed before the refusal");
    // the same declaration twice is no conflict
    std::fs::copy(dir.join("one/s.toml"), dir.join("two/s.toml")).unwrap();
    let (code, _, err) = signorini_in_time(&dir, &["run", "one/s.toml", "two/s.toml", "--results", "r"]);
    assert_eq!(code, 0, "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
