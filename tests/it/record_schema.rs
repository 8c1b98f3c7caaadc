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
