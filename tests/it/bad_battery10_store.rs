//! Battery 10, the store, outputs and messages:
//! * F8: an output flag wrote into a study folder without its lock: `drift --report
//!   res/st/runs/a.json` replaced run a's record (the run lost), `adapt --save
//!   res/st/meshes/b_level1.vtu` a snapshot (the folder then refused), `report --out` and
//!   `figures --figures` wrote pages and PNGs into `runs/` and `meshes/`. Every output flag now
//!   refuses a target inside a study folder (one holding `runs/`, `.lock` or `.locks`), before
//!   anything is computed; the defaults, beside the study folders, still work.
//! * F6: a run's checkpoint (`.partial/RUN.json`) was trusted on resume: an edited `eta1`
//!   landed in the record and `levels.csv`, one that did not parse was dropped without a word,
//!   and none named the code that wrote it. A checkpoint now holds the SHA-256 of its content
//!   and the code version (provenance's commit and version, the executable's hash); one whose
//!   content, code or format does not check is discarded with a line naming the file and why,
//!   and the run starts over.
//! * F3: a reference solution coarser than the run it measures (min_ndof 200, stopping at NDF
//!   218, while the run reached 710) was accepted, and the stored errors measured the
//!   reference's own error (1e-17 at its own mesh). A reference must now have at least
//!   `REFERENCE_MARGIN` (1.5) times the NDF of every level measured against it: refused when
//!   the manifest is checked if `min_ndof` is not that far above level 0, and when a level is
//!   solved that comes closer (the run stops, nothing of it stored).
//! * F5: the study page quoted "no drift" from a drift report older than the records it
//!   showed (`drift --against X`, then `run --replace` into X, then `report`). A drift report
//!   now holds the SHA-256 of every record it compared (both sides with --against), and the
//!   page says "not checked: the drift report ... predates these records" naming the runs
//!   that changed.
//! * Messages: M1 a run of spaces inside two messages of `run`; M2 `export --out DIR` wrote
//!   mesh.vtu before refusing a named pipe at DIR/case.json (both targets are now checked before
//!   the solve, and written as one batch); M3 an interrupted `drift` advised a `run` into its
//!   scratch folder (now: run drift again); M4 `drift --accept` refused by a held lock advised
//!   --fresh and --wait, which drift has not; M5 `report` on an incomplete study wrote its page
//!   without a word (now the page and stderr name the missing runs).

use super::common::{scratch, signorini_in, stored_study};

const STUDY: &str = r#"description = "battery 10: two short runs"
[defaults]
problem = "ex71"
mesh = "structured:4"
levels = 3
save_levels = [1]
[[run]]
id = "a"
[[run]]
id = "b"
theta = 0.3
"#;

/// A scratch folder with `exp/st.toml` ([`STUDY`]) run into `res/`.
fn stored(name: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    stored_study(&dir, "exp/st.toml", STUDY, "res");
    dir
}

#[test]
fn no_output_flag_writes_into_a_study_folder() {
    let dir = stored("battery10-f8");
    let record = std::fs::read(dir.join("res/st/runs/a.json")).unwrap();
    let snapshot = std::fs::read(dir.join("res/st/meshes/b_level1.vtu")).unwrap();
    let tries: [&[&str]; 6] = [
        &["drift", "--experiments", "exp", "--study", "st", "--against", "res", "--results", "res", "--report", "res/st/runs/a.json"],
        &["adapt", "--problem", "ex71", "--levels", "1", "--save", "res/st/meshes/b_level1.vtu"],
        &["report", "--experiments", "exp", "--results", "res", "--out", "res/st/runs"],
        &["figures", "--experiments", "exp", "--results", "res", "--figures", "res/st/meshes"],
        &["export", "--problem", "ex71", "--mesh", "structured:4", "--out", "res/st"],
        // a new file in a subfolder of the study folder, through a symlink to it
        &["adapt", "--problem", "ex71", "--levels", "1", "--save", "link/runs/new.vtu"],
    ];
    std::os::unix::fs::symlink(dir.join("res/st"), dir.join("link")).unwrap();
    for args in tries {
        let (code, out, err) = signorini_in(&dir, args);
        assert_ne!(code, 0, "{args:?}: {out}");
        let folder = if args.contains(&"link/runs/new.vtu") { "link" } else { "res/st" };
        assert!(err.contains(&format!("this is inside the study folder {folder} ")), "{args:?}: {err}");
        assert!(err.contains("Nothing was computed or written"), "{err}");
    }
    assert_eq!(std::fs::read(dir.join("res/st/runs/a.json")).unwrap(), record);
    assert_eq!(std::fs::read(dir.join("res/st/meshes/b_level1.vtu")).unwrap(), snapshot);
    assert!(!dir.join("res/st/runs/new.vtu").exists());
    assert!(!dir.join("res/st/runs/index.html").exists() && !dir.join("res/st/runs/st").exists());
    let (code, _, err) = signorini_in(&dir, &["run", "exp/st.toml", "--results", "res"]);
    assert_eq!(code, 0, "the folder is still sound: {err}");
    // the defaults are beside the study folders: figures, report and drift --against write there
    let (code, _, err) = signorini_in(&dir, &["figures", "--experiments", "exp", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = signorini_in(&dir, &["report", "--experiments", "exp", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("res/figures").is_dir() && dir.join("res/report").is_dir());
    std::fs::remove_dir_all(&dir).ok();
}

fn checkpoint_levels(file: &std::path::Path) -> usize {
    let Ok(text) = std::fs::read_to_string(file) else { return 0 };
    serde_json::from_str::<serde_json::Value>(&text).ok().and_then(|v| v["levels"].as_array().map(|l| l.len())).unwrap_or(0)
}

const LONG: &str = r#"description = "battery 10: one run long enough to be stopped"
[defaults]
problem = "ex71"
mesh = "structured:4"
theta = 0.5
[[run]]
id = "long"
levels = 22
"#;

#[test]
fn a_checkpoint_is_resumed_only_as_written_by_this_code() {
    let dir = scratch("battery10-f6");
    std::fs::write(dir.join("long.toml"), LONG).unwrap();
    let partial = dir.join("killed/long/.partial/long.json");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["run", "long.toml", "--results", "killed"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while checkpoint_levels(&partial) < 6 {
        assert!(child.try_wait().unwrap().is_none(), "the run finished before it could be stopped");
        assert!(started.elapsed().as_secs() < 300, "no checkpoint of 6 levels after 300 s");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
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
        assert_eq!(record["levels"].as_array().unwrap().len(), 22);
        eta1.push(record["levels"][0]["eta1"].as_f64().unwrap());
    }
    assert!(eta1.iter().all(|&e| e == eta1[0] && e != 0.1234), "{eta1:?}");
    std::fs::remove_dir_all(&dir).ok();
}

const COARSE_REFERENCE: &str = r#"description = "battery 10: a reference coarser than the run"
[defaults]
problem = "ex72"
mesh = "structured:4"
levels = 6
[defaults.reference]
theta = 0.5
min_ndof = 200
[[run]]
id = "a"
"#;

#[test]
fn a_reference_not_finer_than_every_level_is_refused() {
    let dir = scratch("battery10-f3");
    std::fs::write(dir.join("c.toml"), COARSE_REFERENCE).unwrap();
    // min_ndof 200 against level 0's 162: refused before anything is solved
    let (code, out, err) = signorini_in(&dir, &["run", "c.toml", "--results", "res"]);
    assert_ne!(code, 0, "{out}");
    assert!(err.contains("run[0].reference.min_ndof") && err.contains("at least 1.5 times the NDF of every level"), "{err}");
    assert!(err.contains("level 0 (structured:4) has 162, so at least 243") && err.contains("got 200"), "{err}");
    assert!(!dir.join("res/c/runs").exists());
    // min_ndof 300 passes the plan (the reference stops at 410); level 2 (NDF 290) stops the run
    std::fs::write(dir.join("c.toml"), COARSE_REFERENCE.replace("min_ndof = 200", "min_ndof = 300")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "c.toml", "--results", "res"]);
    assert_ne!(code, 0, "{out}");
    assert!(err.contains("c/a: level 2 has NDF 290, and its errors would be measured against a reference solution of NDF 410"), "{err}");
    assert!(err.contains("raise reference.min_ndof"), "{err}");
    assert!(!dir.join("res/c/runs/a.json").exists());
    // fine enough: stored
    std::fs::write(dir.join("c.toml"), COARSE_REFERENCE.replace("min_ndof = 200", "min_ndof = 2000")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["run", "c.toml", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    let record: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("res/c/runs/a.json")).unwrap()).unwrap();
    let reference = record["reference_ndof"].as_f64().unwrap();
    assert!(record["levels"].as_array().unwrap().iter().all(|l| reference >= 1.5 * l["ndof"].as_f64().unwrap()), "{record}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The text of the Drift section of a study page.
fn drift_section(page: &std::path::Path) -> String {
    let html = std::fs::read_to_string(page).unwrap();
    let start = html.find("<h2>Drift</h2>").unwrap_or_else(|| panic!("{html}"));
    html[start..].split("<h2>Claims").next().unwrap().to_string()
}

#[test]
fn the_page_quotes_a_drift_report_only_for_the_records_it_compared() {
    let dir = scratch("battery10-f5");
    stored_study(&dir, "exp/st.toml", STUDY, "x");
    // a copy of the folder compared with it (the folder with itself is no check: battery 11, N1)
    let (code, _, err) = signorini_in(&dir, &["run", "exp/st.toml", "--results", "y"]);
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = signorini_in(&dir, &["drift", "--experiments", "exp", "--against", "y", "--results", "x"]);
    assert_eq!(code, 0, "{out}{err}");
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("y/drift-report.json")).unwrap()).unwrap();
    let hashes = &report["studies"][0]["records"];
    assert_eq!(hashes["a"].as_str().map(str::len), Some(64), "{report}");
    // both sides' records, each by its own hash (two runs differ in their timings)
    assert_eq!(report["studies"][0]["against_records"]["a"].as_str().map(str::len), Some(64), "{report}");
    let page = dir.join("y/report/st.html");
    let (code, _, err) = signorini_in(&dir, &["report", "--experiments", "exp", "--results", "y"]);
    assert_eq!(code, 0, "{err}");
    assert!(drift_section(&page).contains("<b>no drift</b>"), "{}", drift_section(&page));
    // run b again with other levels: the report did not see the record now shown
    std::fs::write(dir.join("exp/st.toml"), STUDY.replace("theta = 0.3", "theta = 0.3\nlevels = 4")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["run", "exp/st.toml", "--results", "y", "--replace"]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = signorini_in(&dir, &["report", "--experiments", "exp", "--results", "y"]);
    assert_eq!(code, 0, "{err}");
    let section = drift_section(&page);
    assert!(!section.contains("no drift"), "{section}");
    assert!(section.contains("not checked: the drift report of") && section.contains("run(s) b changed since"), "{section}");
    // a report without hashes (an older harness) speaks for no records
    let mut old = report.clone();
    old["studies"][0].as_object_mut().unwrap().retain(|k, _| !k.ends_with("records"));
    std::fs::write(dir.join("y/drift-report.json"), serde_json::to_string_pretty(&old).unwrap()).unwrap();
    let (code, _, err) = signorini_in(&dir, &["report", "--experiments", "exp", "--results", "y"]);
    assert_eq!(code, 0, "{err}");
    assert!(drift_section(&page).contains("records no hashes"), "{}", drift_section(&page));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn messages_say_what_is_true_in_the_command_s_own_terms() {
    let dir = stored("battery10-messages");
    // M1: one space where the text continues
    std::fs::create_dir_all(dir.join("exp2")).unwrap();
    std::fs::write(dir.join("exp2/st.toml"), STUDY.replace("levels = 3", "levels = 4")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["run", "exp/st.toml", "exp2/st.toml", "--results", "m1"]);
    assert_ne!(code, 0);
    assert!(err.contains("stored with another spec") && !err.contains("  "), "{err}");
    // M2: a named pipe where case.json goes: refused before anything is solved or written
    std::fs::create_dir_all(dir.join("out")).unwrap();
    assert!(std::process::Command::new("mkfifo").arg(dir.join("out/case.json")).status().unwrap().success());
    let (code, out, err) = signorini_in(&dir, &["export", "--problem", "ex71", "--mesh", "structured:4", "--out", "out"]);
    assert_ne!(code, 0, "{out}");
    assert!(err.contains("--out out/case.json: not a regular file (a named pipe)"), "{err}");
    assert!(!dir.join("out/mesh.vtu").exists(), "a half-written export");
    // M5: a study missing runs: the page and stderr say which
    let (code, _, err) = signorini_in(&dir, &["run", "exp/st.toml", "--results", "part", "--shard", "1/2"]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = signorini_in(&dir, &["report", "--experiments", "exp", "--results", "part"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("report: st is incomplete in part (its page says so): b (missing)"), "{err}");
    let page = std::fs::read_to_string(dir.join("part/report/st.html")).unwrap();
    assert!(page.contains("<b>Incomplete</b>") && page.contains("b (missing)"), "{page}");
    let page = |results: &str| std::fs::read_to_string(dir.join(results).join("report/st.html")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["report", "--experiments", "exp", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("incomplete") && !page("res").contains("Incomplete"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn drift_advises_drift_when_interrupted_or_refused_by_a_lock() {
    let dir = scratch("battery10-drift-advice");
    stored_study(&dir, "exp/long.toml", LONG, "res");
    // M4: a run of the study holds its lock (here: this test, through the library)
    let store = signorini::study::store::Store::new(&dir.join("res"), "long");
    let held = store.lock_run("long", false).unwrap();
    let (code, out, err) = signorini_in(&dir, &["drift", "--experiments", "exp", "--results", "res", "--accept", "long"]);
    assert_ne!(code, 0, "{out}");
    assert!(err.contains("drift --accept long: run long of") && err.contains("then run `signorini drift --accept long` again"), "{err}");
    assert!(!err.contains("--wait") && !err.contains("--fresh"), "{err}");
    drop(held);
    // M3: SIGINT while drift reruns the study into its scratch folder
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["drift", "--experiments", "exp", "--results", "res", "--report", "d.json"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while checkpoint_levels(&dir.join("target/drift/full/long/.partial/long.json")) < 2 {
        assert!(started.elapsed().as_secs() < 120, "drift never started its rerun");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) }, 0);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(err.contains("drift: interrupted while rerunning long into its scratch folder target/drift/full"), "{err}");
    assert!(err.contains("Run the same `signorini drift` again") && !err.contains("Resume with"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
