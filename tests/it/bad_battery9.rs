//! Battery 9: two `signorini drift` in one checkout share the scratch folder they rerun into
//! (`target/drift/full`); each started its studies over while the other compared, and one
//! reported stored runs as missing (a false drift, exit 1). The scratch folder is locked for
//! the whole command: the second waits, saying who holds it, and both find no drift.

use super::common::scratch;
use std::process::{Command, Stdio};

const STUDY: &str = r#"description = "battery 9: one run of a few seconds"
[defaults]
problem = "ex71"
mesh = "structured:8"
[[run]]
id = "a"
levels = 16
theta = 0.5
"#;

fn drift(dir: &std::path::Path) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(dir)
        .args(["drift", "--experiments", "exp", "--results", "results", "--study", "s", "--report", "r.json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn finish(child: std::process::Child) -> (i32, String) {
    let o = child.wait_with_output().unwrap();
    (o.status.code().unwrap_or(-1), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

#[test]
fn two_drifts_in_one_checkout_take_turns_and_neither_reports_a_false_drift() {
    let dir = scratch("battery9-two-drifts");
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/s.toml"), STUDY).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["run", "exp/s.toml", "--results", "results"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let first = drift(&dir);
    // the first reruns the study now: its scratch copy of the run is being computed
    let start = std::time::Instant::now();
    while !dir.join("target/drift/full/s/.partial").exists() && !dir.join("target/drift/full/s/runs/a.json").exists() {
        assert!(start.elapsed().as_secs() < 120, "the first drift never started its rerun");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let second = drift(&dir);
    let ((c1, o1), (c2, o2)) = (finish(first), finish(second));
    assert_eq!(c1, 0, "first: {o1}");
    assert_eq!(c2, 0, "second: {o2}");
    for o in [&o1, &o2] {
        assert!(o.contains("drift: none"), "{o}");
        assert!(!o.contains("(missing)"), "{o}");
    }
    assert!(
        o2.contains("the scratch folder target/drift/full is being written by process") && o2.contains("waiting for it to finish"),
        "{o2}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
