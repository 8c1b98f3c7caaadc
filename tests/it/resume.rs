//! A run stopped mid-way (the process killed, as a cluster's time limit does) resumes after its
//! last finished level, not from level 0, and ends with the same numbers and history as a run
//! that was never stopped; the checkpoint it resumed from is gone once the run has landed.

use crate::common::{LONG, checkpoint_levels, scratch, signorini_in};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// [`LONG`] cut to 12 levels, two of its levels' meshes saved: started with [`stopped_at`],
/// which makes every change to its files wait 50 ms, it is still in progress when it is
/// killed, at the cost in computing of a run of a second.
fn small_with_saved_meshes() -> String {
    format!("{}save_levels = [3, 11]\n", small())
}

fn small() -> String {
    LONG.replace("levels = 22", "levels = 12")
}

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_signorini")
}

/// `signorini args` in `dir`, every change to its files paused ([`signorini::base::failpoint`]),
/// killed (SIGKILL: no handler runs) once its checkpoint `partial` holds `levels` levels.
fn stopped_at(dir: &Path, args: &[&str], partial: &Path, levels: usize) {
    let mut child = Command::new(bin())
        .current_dir(dir)
        .args(args)
        .env(signorini::base::failpoint::PAUSE_ENV, "50")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while checkpoint_levels(partial) < levels {
        assert!(child.try_wait().unwrap().is_none(), "the run finished before it could be stopped");
        assert!(started.elapsed() < Duration::from_secs(300), "no checkpoint of {levels} levels after 300 s");
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    child.wait().unwrap();
}

fn run(results: &Path, manifest: &Path) -> std::process::Output {
    Command::new(bin()).args(["run", manifest.to_str().unwrap(), "--results", results.to_str().unwrap()]).output().unwrap()
}

fn without_measurements(file: PathBuf) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap();
    for l in v["levels"].as_array_mut().unwrap() {
        l.as_object_mut().unwrap().retain(|k, _| !signorini::level::record::is_measurement(k));
    }
    v
}

#[test]
fn a_killed_run_resumes_after_its_last_finished_level_with_the_same_numbers() {
    let root = std::env::temp_dir().join(format!("signorini-resume-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&root).unwrap();
    let manifest = root.join("resumed.toml");
    std::fs::write(&manifest, small_with_saved_meshes()).unwrap();
    // the reference: never stopped
    let whole = root.join("whole");
    assert!(run(&whole, &manifest).status.success());
    // killed once 6 levels are kept
    let stopped = root.join("stopped");
    let partial = stopped.join("resumed/.partial/long.json");
    stopped_at(&root, &["run", manifest.to_str().unwrap(), "--results", stopped.to_str().unwrap()], &partial, 6);
    let kept = checkpoint_levels(&partial);
    assert!((6..12).contains(&kept), "{kept}");
    assert!(!stopped.join("resumed/runs/long.json").exists());
    let out = run(&stopped, &manifest);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains(&format!("resuming after level {}", kept - 1)), "{stderr}");
    let file = |r: &Path| r.join("resumed/runs/long.json");
    assert_eq!(without_measurements(file(&stopped)), without_measurements(file(&whole)));
    for l in [3, 11] {
        for ext in ["vtu", "json"] {
            let name = format!("resumed/meshes/long_level{l}.{ext}");
            assert_eq!(std::fs::read(stopped.join(&name)).unwrap(), std::fs::read(whole.join(&name)).unwrap(), "{name}");
        }
    }
    assert!(!stopped.join("resumed/.partial").exists(), "the checkpoint stays after the run landed");
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn a_checkpoint_is_resumed_only_as_written_by_this_code() {
    let dir = scratch("resume-checkpoint-is-resumed");
    std::fs::write(dir.join("long.toml"), small()).unwrap();
    let partial = dir.join("killed/long/.partial/long.json");
    stopped_at(&dir, &["run", "long.toml", "--results", "killed"], &partial, 6);
    let text = std::fs::read_to_string(&partial).unwrap();
    let kept: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(kept["sha256"].as_str().map(str::len), Some(64), "{}", &text[..text.len().min(400)]);
    let edited = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut v = kept.clone();
        f(&mut v);
        serde_json::to_string_pretty(&v).unwrap()
    };
    let cases = [
        ("as-written", text.clone(), "resuming after level"),
        ("edited", edited(&|v| v["levels"][0]["eta1"] = 0.1234.into()), "its levels are not what was written"),
        ("truncated", text[..text.len() / 2].to_string(), "it does not parse as a checkpoint"),
        ("other-code", edited(&|v| v["code"]["executable_sha256"] = "0".repeat(64).into()), "it was written by other code"),
    ];
    let mut eta1 = Vec::new();
    for (name, checkpoint, said) in cases {
        let results = dir.join(name);
        std::fs::create_dir_all(results.join("long/.partial")).unwrap();
        std::fs::write(results.join("long/.partial/long.json"), checkpoint).unwrap();
        let (code, _, err) = signorini_in(&dir, &["run", "long.toml", "--results", name]);
        assert_eq!(code, 0, "{name}: {err}");
        assert!(err.contains(said), "{name}: {err}");
        if name != "as-written" {
            assert!(err.contains(&format!("{name}/long/.partial/long.json: not resumed from: ")), "{err}");
            assert!(err.contains("the run starts over") && !err.contains("resuming after"), "{err}");
        }
        let record: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(results.join("long/runs/long.json")).unwrap()).unwrap();
        assert_eq!(record["levels"].as_array().unwrap().len(), 12);
        eta1.push(record["levels"][0]["eta1"].as_f64().unwrap());
    }
    assert!(eta1.iter().all(|&e| e == eta1[0] && e != 0.1234), "{eta1:?}");
    std::fs::remove_dir_all(&dir).ok();
}
