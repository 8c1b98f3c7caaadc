//! Battery 13's minor notes:
//! * An expression nested 200k calls deep (`abs(abs(...))`) took over 120 s: the name check
//!   formatted the whole text for every name (quadratic), and exmex's parse of nested calls is
//!   quadratic in the depth. The check now formats only for a message, and nesting is bounded
//!   (`MAX_NESTING`, 1000 parentheses): deeper is refused at once, and the refusal's reason, which
//!   follows the quoted expression, survives the cut of a long line (`base::input::excerpt` keeps
//!   its first and last 500 characters).
//! * `run --plan` listed runs that `run` would keep as if it would compute them, and exited 0 on a
//!   folder `run` refuses (an emptied `levels.csv`): the plan now reads the folder through the
//!   same check and refusal as `run` and says which runs are kept or replaced.
//! * `.locks` (the folder of the run locks) as a regular file was not named where every run was
//!   finished (`run` said "0 run(s) executed"): every writer and reader now names it.
//! * The study page's run table gave runs that differ only in their estimator the same cell: an
//!   estimator column names the settings that differ from the defaults.
//! * The memory refusal under an address-space limit said "needs 1.7 GiB" for 626 unknowns
//!   without saying that the threads' reserve (twice the CPU's largest cache per thread) is most
//!   of it.

use super::common::{scratch, signorini_in, stored_study};

/// Example 7.2's problem file with `chi` nested `depth` calls of `abs` deep.
fn nested(depth: usize) -> String {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/experiments/problems/ex72.toml")).unwrap();
    let chi = format!("chi = \"{}0{}\"", "abs(".repeat(depth), ")".repeat(depth));
    text.lines().map(|l| if l.starts_with("chi = ") { chi.clone() } else { l.to_string() }).collect::<Vec<_>>().join("\n")
}

#[test]
fn deep_nesting_is_refused_at_once_with_its_reason() {
    let dir = scratch("b13-nesting");
    std::fs::write(dir.join("ok.toml"), nested(1000)).unwrap();
    std::fs::write(dir.join("deep.toml"), nested(200_000)).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "ok.toml", "--mesh", "structured:2"]);
    assert_eq!(code, 0, "{err}");
    let start = std::time::Instant::now();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "deep.toml", "--mesh", "structured:2"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("nests parentheses deeper than 1000") && err.contains("characters cut"), "{}", &err[..err.len().min(3000)]);
    assert!(err.len() < 4000, "{} bytes", err.len());
    // not a timing test: 200k deep took over 120 s; the refusal reads the text once
    assert!(start.elapsed().as_secs() < 60, "{:?}", start.elapsed());
    std::fs::remove_dir_all(&dir).ok();
}

const STUDY: &str = "description = \"battery 13 notes\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\n[[run]]\nid = \"a\"\nlevels = 2\n[[run]]\nid = \"b\"\nlevels = 3\n";

#[test]
fn a_plan_says_what_run_keeps_and_refuses_what_run_refuses() {
    let dir = scratch("b13-plan");
    let (code, out, err) = {
        std::fs::create_dir_all(dir.join("exp")).unwrap();
        std::fs::write(dir.join("exp/s.toml"), STUDY).unwrap();
        signorini_in(&dir, &["run", "--plan", "exp/s.toml", "--results", "res"])
    };
    assert_eq!((code, out.as_str()), (0, "s/a\ns/b\n"), "{err}");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    let (code, out, err) = signorini_in(&dir, &["run", "--plan", "exp/s.toml", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "s/a (kept: stored with this spec, nothing computed)\ns/b (kept: stored with this spec, nothing computed)\n");
    // another spec for b: refused as run refuses it; with --replace, said
    std::fs::write(dir.join("exp/s.toml"), STUDY.replace("levels = 3", "levels = 4")).unwrap();
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
    std::fs::write(dir.join("exp/s.toml"), STUDY).unwrap();
    std::fs::write(dir.join("res/s/levels.csv"), "").unwrap();
    for args in [&["run", "--plan", "exp/s.toml", "--results", "res"][..], &["run", "exp/s.toml", "--results", "res"]] {
        let (code, _, err) = signorini_in(&dir, args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(err.contains("levels.csv"), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_lock_folder_that_is_a_file_is_named_also_when_every_run_is_finished() {
    let dir = scratch("b13-locks");
    stored_study(&dir, "exp/s.toml", STUDY, "res");
    let locks = dir.join("res/s/.locks");
    std::fs::remove_dir_all(&locks).unwrap();
    std::fs::write(&locks, "").unwrap();
    for args in [&["run", "exp/s.toml", "--results", "res"][..], &["figures", "--results", "res", "--experiments", "exp"]] {
        let (code, _, err) = signorini_in(&dir, args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(err.contains(".locks is a regular file, not a folder: move it away"), "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The run table of a study page gave runs that differ only in their estimator the same
/// refinement cell ("Adaptive, θ = 0.5"); its estimator column names the settings that differ
/// from the defaults.
#[test]
fn the_run_table_tells_runs_apart_by_their_estimator() {
    let dir = scratch("b13-page");
    let study = STUDY.replace("levels = 3\n", "levels = 3\nestimator = { log_factor = \"one\", c0 = 1.0 }\n");
    stored_study(&dir, "exp/s.toml", &study, "res");
    let (code, _, err) = signorini_in(&dir, &["report", "--results", "res", "--experiments", "exp", "--out", "page"]);
    assert_eq!(code, 0, "{err}");
    let page = std::fs::read_to_string(dir.join("page/s.html")).unwrap();
    assert!(page.contains("<th>estimator</th>"), "no estimator column");
    assert!(page.contains("<td>Adaptive, θ = 0.5</td><td>default</td>"), "run a");
    assert!(page.contains("<td>Adaptive, θ = 0.5</td><td>log_factor = one; c0 = 1.0</td>"), "run b");
    std::fs::remove_dir_all(&dir).ok();
}
