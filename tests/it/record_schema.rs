//! The record schema reads and writes every stored record byte for byte: `LevelRecord` holds the
//! estimator's terms as one flattened field (`Terms`), and the JSON is the same as when they
//! were fields of their own.

use signorini::records::{RunRecord, json_bytes};
use std::path::Path;

#[test]
fn every_stored_record_is_rewritten_byte_for_byte() {
    let results = Path::new(env!("CARGO_MANIFEST_DIR")).join("results");
    let mut checked = 0;
    for study in std::fs::read_dir(&results).unwrap().flatten() {
        let Ok(runs) = std::fs::read_dir(study.path().join("runs")) else { continue };
        for f in runs.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "json")) {
            let stored = std::fs::read(&f).unwrap();
            let record: RunRecord = serde_json::from_slice(&stored).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
            let rewritten = json_bytes(&f, &record).unwrap();
            assert!(rewritten == stored, "{} changes when read and written again", f.display());
            checked += 1;
        }
    }
    assert!(checked >= 30, "only {checked} records found under results/");
}

/// A record that cannot be read, parsed or written is a typed error (`RecordError`) inside the
/// `io::Error`, naming the file: a caller can tell the cases apart without reading the message.
#[test]
fn record_errors_are_typed_and_name_the_file() {
    use signorini::records::{RecordError, StudyDir, write_json};
    let dir = std::env::temp_dir().join(format!("signorini-record-errors-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let study = StudyDir::new(&dir, "s");
    std::fs::create_dir_all(study.root.join("runs")).unwrap();
    std::fs::write(study.run_file("broken"), "{ not json").unwrap();
    let parse = study.read_run("broken").unwrap_err();
    let inner = parse.get_ref().and_then(|e| e.downcast_ref::<RecordError>());
    assert!(matches!(inner, Some(RecordError::Parse { path, .. }) if *path == study.run_file("broken")), "{parse:?}");
    assert!(parse.to_string().starts_with(&format!("{}: ", study.run_file("broken").display())), "{parse}");
    let listed = study.read_runs().unwrap_err();
    assert!(matches!(listed.get_ref().and_then(|e| e.downcast_ref::<RecordError>()), Some(RecordError::Parse { .. })), "{listed:?}");
    let target = dir.join("nan.json");
    let not_finite = write_json(&target, &serde_json::json!({ "x": 1.0 })).map(|_| ());
    assert!(not_finite.is_ok(), "{not_finite:?}");
    let nan = write_json(&target, &[f64::NAN]).unwrap_err();
    assert_eq!(nan.kind(), std::io::ErrorKind::InvalidData);
    assert!(
        matches!(nan.get_ref().and_then(|e| e.downcast_ref::<RecordError>()), Some(RecordError::NonFinite { bad, .. }) if bad.path == "[0]"),
        "{nan:?}"
    );
    assert!(nan.to_string().contains("not writing") && nan.to_string().contains("nan.json"), "{nan}");
    let missing = signorini::records::read_text(&dir.join("absent.json")).unwrap_err();
    assert_eq!(missing.kind(), std::io::ErrorKind::NotFound);
    assert!(
        matches!(missing.get_ref().and_then(|e| e.downcast_ref::<RecordError>()), Some(RecordError::Io { step: "reading", .. })),
        "{missing:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
