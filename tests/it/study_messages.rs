//! What `run --plan`, `run` and the study commands say: a plan says what `run` keeps, refuses and
//! removes and lists each run once; the run table tells runs apart; messages say what is true in
//! the command's own terms.

use crate::common::{
    TWO_SHORT_RUNS, one_run_manifest, scratch, signorini_in, signorini_in_time, stored_study, stored_two_short_runs as stored,
};

#[test]
fn messages_say_what_is_true_in_the_command_s_own_terms() {
    let dir = stored("study-messages-messages");
    // M1: one space where the text continues
    std::fs::create_dir_all(dir.join("exp2")).unwrap();
    std::fs::write(dir.join("exp2/st.toml"), TWO_SHORT_RUNS.replace("levels = 3", "levels = 4")).unwrap();
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

const ADAPTIVE_STUDY: &str = "description = \"three adaptive levels\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\n[[run]]\nid = \"a\"\nrefine = \"adaptive\"\nlevels = 3\n";

/// `solve --json` carries u_h's round-off floor, as the level records do; `run --plan M.toml
/// M.toml` lists every run once, as the run stores each once.
#[test]
fn solve_json_carries_the_roundoff_floor_and_a_plan_lists_each_run_once() {
    let dir = scratch("study-messages-solve-json-carries");
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "ex72", "--mesh", "structured:4", "--json"]);
    assert_eq!(code, 0, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let floor = json["roundoff_floor"].as_f64().unwrap_or_else(|| panic!("no roundoff_floor: {out}"));
    assert!(floor > 0.0 && floor < 1e-10, "{floor}");
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/st.toml"), ADAPTIVE_STUDY.replace("levels = 3\n", "levels = 3\n[[run]]\nid = \"b\"\nlevels = 2\n"))
        .unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "exp/st.toml", "exp/st.toml", "--plan"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "st/a\nst/b\n");
    std::fs::remove_dir_all(&dir).ok();
}

const TWO_RUNS_OF_TWO_AND_THREE_LEVELS: &str = "description = \"two runs\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\n[[run]]\nid = \"a\"\nlevels = 2\n[[run]]\nid = \"b\"\nlevels = 3\n";

#[test]
fn a_plan_says_what_run_keeps_and_refuses_what_run_refuses() {
    let dir = scratch("study-messages-plan");
    let (code, out, err) = {
        std::fs::create_dir_all(dir.join("exp")).unwrap();
        std::fs::write(dir.join("exp/s.toml"), TWO_RUNS_OF_TWO_AND_THREE_LEVELS).unwrap();
        signorini_in(&dir, &["run", "--plan", "exp/s.toml", "--results", "res"])
    };
    assert_eq!((code, out.as_str()), (0, "s/a\ns/b\n"), "{err}");
    stored_study(&dir, "exp/s.toml", TWO_RUNS_OF_TWO_AND_THREE_LEVELS, "res");
    let (code, out, err) = signorini_in(&dir, &["run", "--plan", "exp/s.toml", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "s/a (kept: stored with this spec, nothing computed)\ns/b (kept: stored with this spec, nothing computed)\n");
    // another spec for b: refused as run refuses it; with --replace, said
    std::fs::write(dir.join("exp/s.toml"), TWO_RUNS_OF_TWO_AND_THREE_LEVELS.replace("levels = 3", "levels = 4")).unwrap();
    let (code, _, err) = signorini_in(&dir, &["run", "--plan", "exp/s.toml", "--results", "res"]);
    assert_eq!(code, 1);
    assert!(err.contains("not overwriting the stored results") && err.contains("run b is stored with another spec"), "{err}");
    let (code, out, err) = signorini_in(&dir, &["run", "--plan", "--replace", "exp/s.toml", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.starts_with("s/a (kept") && out.contains("s/b (replaces the stored run: levels"), "{out}");
    let (code, out, _) = signorini_in(&dir, &["run", "--plan", "--fresh", "exp/s.toml", "--results", "res"]);
    let removes = "s (--fresh first removes 4 file(s): res/s/levels.csv, res/s/provenance.json, res/s/runs/a.json, res/s/runs/b.json)\n";
    assert_eq!((code, out.as_str()), (0, format!("{removes}s/a\ns/b\n").as_str()));
    // a damaged folder: refused by the plan as by run, naming the file
    std::fs::write(dir.join("exp/s.toml"), TWO_RUNS_OF_TWO_AND_THREE_LEVELS).unwrap();
    std::fs::write(dir.join("res/s/levels.csv"), "").unwrap();
    for args in [&["run", "--plan", "exp/s.toml", "--results", "res"][..], &["run", "exp/s.toml", "--results", "res"]] {
        let (code, _, err) = signorini_in(&dir, args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(err.contains("levels.csv"), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The run table of a study page gave runs that differ only in their estimator the same
/// refinement cell ("Adaptive, θ = 0.5"); its estimator column names the settings that differ
/// from the defaults.
#[test]
fn the_run_table_tells_runs_apart_by_their_estimator() {
    let dir = scratch("study-messages-page");
    let study = TWO_RUNS_OF_TWO_AND_THREE_LEVELS.replace("levels = 3\n", "levels = 3\nestimator = { log_factor = \"one\", c0 = 1.0 }\n");
    stored_study(&dir, "exp/s.toml", &study, "res");
    let (code, _, err) = signorini_in(&dir, &["report", "--results", "res", "--experiments", "exp", "--out", "page"]);
    assert_eq!(code, 0, "{err}");
    let page = std::fs::read_to_string(dir.join("page/s.html")).unwrap();
    assert!(page.contains("<th>estimator</th>"), "no estimator column");
    assert!(page.contains("<td>Adaptive, θ = 0.5</td><td>default</td>"), "run a");
    assert!(page.contains("<td>Adaptive, θ = 0.5</td><td>log_factor = one; c0 = 1.0</td>"), "run b");
    std::fs::remove_dir_all(&dir).ok();
}

/// `run --plan --replace` says which stored runs `run --replace` removes (a run no longer
/// declared among them, a run whose record cannot be read as a removal, not a new run) and the
/// leftover files `run` removes first.
#[test]
fn the_plan_names_every_removal() {
    let dir = scratch("study-messages-plan-plan-names-every");
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    let two = "description = \"plan\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\nlevels = 3\nsave_levels = [1]\n[[run]]\nid = \"adaptive\"\n[[run]]\nid = \"uniform\"\nrefine = \"uniform\"\n";
    std::fs::write(dir.join("experiments/s.toml"), two).unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/s.toml", "--results", "res"]);
    assert_eq!(code, 0, "{out}{err}");
    let plan = ["run", "experiments/s.toml", "--results", "res", "--plan", "--replace"];
    // a leftover of a killed process: named as what run removes first
    std::fs::write(dir.join("res/s/meshes/gone_level1.json"), "{}").unwrap();
    let (code, out, err) = signorini_in(&dir, &plan);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("s (first removes 1 leftover file(s) of an unfinished run:") && out.contains("gone_level1.json"), "{out}");
    std::fs::remove_file(dir.join("res/s/meshes/gone_level1.json")).unwrap();
    // a record that cannot be read: replaced
    let record = dir.join("res/s/runs/uniform.json");
    let good = std::fs::read(&record).unwrap();
    std::fs::write(&record, &good[..500]).unwrap();
    let (code, out, err) = signorini_in(&dir, &plan);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("s/uniform (replaces the stored run: its record does not hold together)"), "{out}");
    // a run no longer declared: removed
    std::fs::write(&record, &good).unwrap();
    std::fs::write(dir.join("experiments/s.toml"), &two[..two.find("[[run]]\nid = \"uniform\"").unwrap()]).unwrap();
    let (code, out, err) = signorini_in(&dir, &plan);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("s/uniform (removes the stored run and its snapshots: not declared in experiments/s.toml)"), "{out}");
    assert!(out.contains("s/adaptive (kept"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_quick_run_into_a_folder_of_full_runs_does_not_advise_replace() {
    let dir = scratch("study-messages-quick-full");
    let file = one_run_manifest(&dir, "s", "a", "");
    assert_eq!(signorini_in_time(&dir, &["run", &file, "--results", "r"]).0, 0);
    let before = std::fs::read(dir.join("r/s/runs/a.json")).unwrap();
    let (code, _, err) = signorini_in_time(&dir, &["run", &file, "--quick", "--results", "r"]);
    assert_eq!(code, 1, "{err}");
    for says in ["holds the full form of study s", "the first 1 levels", "--results target/quick-results"] {
        assert!(err.contains(says), "no {says:?} in {err}");
    }
    assert!(!err.contains("--replace"), "{err}");
    assert_eq!(std::fs::read(dir.join("r/s/runs/a.json")).unwrap(), before);
    // the quick form in its own folder is fine
    assert_eq!(signorini_in_time(&dir, &["run", &file, "--quick", "--results", "q"]).0, 0);
    std::fs::remove_dir_all(&dir).ok();
}
