//! The command line refuses what it cannot use with a message naming the flag, value or file and
//! what is expected, never a panic, before anything runs: unknown problems and malformed meshes or
//! probes, flags that cannot apply, manifest values the loop cannot use, references that cannot be
//! computed; and the smaller promises of the command line (help text, export's notes, the
//! Makefile's and `cargo run`'s binary).

use crate::common::{scratch, signorini_in, signorini_in_repo};
use signorini::manifest::Manifest;
use std::path::Path;
use std::process::Command;

/// `adapt --save` to a folder, or into a folder where no file can be made: refused before level
/// 0 is solved, naming the path. Before, every level was computed and the write failed at the
/// end with "renaming the temporary file to DIR/: Not a directory".
#[test]
fn a_save_path_that_is_a_folder_is_refused_before_solving() {
    let dir = scratch("cli-refusals-save");
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["adapt", "--problem", "ex71", "--levels", "2", "--save", "."])
        .output()
        .unwrap();
    let (out, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("--save .: this is a folder; give the path of a file in it, e.g. ./solution.vtu"), "{err}");
    assert!(!out.contains("lvl"), "solved before refusing: {out}");
    let o = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["adapt", "--problem", "ex71", "--levels", "2", "--save", "s.vtu"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.join("s.vtu").is_file());
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "the probe file is removed");
    std::fs::remove_dir_all(&dir).ok();
}

const COARSE_REFERENCE: &str = r#"description = "a reference coarser than the run"
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
    let dir = scratch("cli-refusals-reference-not-finer");
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

/// The binary in `dir` with RAYON_NUM_THREADS = `threads`, under an address-space limit of
/// `bytes` if given: (exit code or None for a signal, stderr).
fn with_threads(dir: &Path, threads: usize, bytes: Option<u64>, args: &[&str]) -> (Option<i32>, String) {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"));
    cmd.args(args).current_dir(dir).env("RAYON_NUM_THREADS", threads.to_string());
    if let Some(bytes) = bytes {
        super::common::limit(&mut cmd, libc::RLIMIT_AS, bytes);
    }
    let o = cmd.output().unwrap();
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn rayon_threads_far_above_the_cores_are_refused_and_threads_that_cannot_start_are_named() {
    let dir = scratch("cli-refusals-threads");
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let solve = ["solve", "--problem", "ex72", "--mesh", "structured:4"];
    // 2000 under 4 GB panicked (exit 101); more than 8 per core is refused at once
    for (threads, limit) in [(2000, Some(4_000_000_000)), (8 * cores + 1, None), (20000, None)] {
        let started = std::time::Instant::now();
        let (code, err) = with_threads(&dir, threads, limit, &solve);
        assert_eq!(code, Some(1), "{threads}: {err}");
        assert!(err.contains(&format!("RAYON_NUM_THREADS={threads} is more than 8 times the {cores} core(s)")), "{threads}: {err}");
        assert!(!err.contains("panicked") && started.elapsed().as_secs() < 30, "{threads}: {err}");
    }
    // within the cap, a pool that cannot start under a small limit is an error naming
    // RAYON_NUM_THREADS, or the memory check's refusal; never a panic
    for mb in [30, 60, 100] {
        let (code, err) = with_threads(&dir, 8 * cores, Some(mb * 1_000_000), &solve);
        assert_eq!(code, Some(1), "{mb} MB: {err}");
        let named = err.contains(&format!("starting the solver's threads (RAYON_NUM_THREADS={}) failed", 8 * cores));
        assert!(named || err.contains("address-space limit (ulimit -v) leaves"), "{mb} MB: {err}");
        assert!(!err.contains("panicked"), "{mb} MB: {err}");
    }
    // and the count within the cap solves as before
    let (code, err) = with_threads(&dir, 2 * cores, None, &solve);
    assert_eq!(code, Some(0), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

fn repo(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path).display().to_string()
}

/// A manifest of one or two short ex71 runs with `defaults` and `runs` appended to its tables.
fn manifest_text(defaults: &str, runs: &[&str], tail: &str) -> String {
    let mut s = format!("[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\nlevels = 2\n{defaults}\n");
    for (i, r) in runs.iter().enumerate() {
        s += &format!("[[run]]\nid = \"r{i}\"\n{r}\n");
    }
    s + tail
}

/// The parse error of `text` as the file `cli_case.toml`.
fn parse_error(text: &str) -> String {
    match Manifest::parse(Path::new("experiments/cli_case.toml"), text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn accept_with_flags_it_would_ignore_is_refused_before_anything_runs() {
    for (extra, flag) in [
        (&["--quick"][..], "--quick"),
        (&["--report", "x.json"][..], "--report"),
        (&["--study", "ex71"][..], "--study"),
        (&["--against", "somewhere"][..], "--against"),
    ] {
        let d = scratch("cli-refusals-accept");
        let mut args = vec!["drift", "--accept", "hertz", "--results", d.to_str().unwrap()];
        args.extend_from_slice(extra);
        let (code, out, err) = signorini_in_repo(&args);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains("--accept") && err.contains(flag) && err.contains("cannot be used with"), "{extra:?}: {err}");
        assert!(out.is_empty());
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0, "{extra:?}: something was written into --results");
    }
}

/// `drift --merge` (a round-off measurement of some studies merged into the reports of all)
/// needs --study and --report; a --report file that is not a drift report is an error naming
/// it before anything is rerun, and the file is left as it was.
#[test]
fn merge_without_its_flags_or_into_another_file_is_refused_before_anything_runs() {
    for (extra, missing) in [(&["--study", "hertz"][..], "--report"), (&["--report", "x.json"][..], "--study")] {
        let mut args = vec!["drift", "--merge"];
        args.extend_from_slice(extra);
        let (code, _, err) = signorini_in_repo(&args);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains(missing) && err.contains("required"), "{extra:?}: {err}");
    }
    let d = scratch("cli-refusals-merge");
    let file = d.join("notes.json");
    std::fs::write(&file, "{\"these\": \"are notes\"}").unwrap();
    let (code, out, err) = signorini_in_repo(&["drift", "--study", "hertz", "--merge", "--report", file.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("notes.json") && err.contains("not a drift report") && err.contains("nothing was rerun"), "{err}");
    assert!(!out.contains("hertz/"), "nothing is rerun: {out}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "{\"these\": \"are notes\"}");
}

#[test]
fn an_empty_experiments_folder_is_an_error_and_claims_nothing() {
    let d = scratch("cli-refusals-empty-exp");
    let (exp, res) = (d.join("experiments"), d.join("results"));
    std::fs::create_dir_all(&exp).unwrap();
    std::fs::create_dir_all(&res).unwrap();
    let (code, _, err) = signorini_in_repo(&[
        "figures",
        "--experiments",
        exp.to_str().unwrap(),
        "--results",
        res.to_str().unwrap(),
        "--figures",
        d.join("f").to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains(exp.to_str().unwrap()) && err.contains("no study manifest"), "{err}");
    assert!(!res.join("CLAIMS.md").exists() && !d.join("f").exists(), "figures wrote something about no data");
    let (code, _, err) = signorini_in(&d, &["drift", "--experiments", "experiments", "--results", "results"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("no study manifest"), "{err}");
    assert!(!d.join("target").exists(), "drift wrote a report about nothing");
}

/// A CLAIMS.md rendered from a folder without data says "no data" everywhere: the sampling row
/// (which compares verdicts) included, which used to say "holds".
#[test]
fn claims_from_no_data_hold_nothing() {
    let d = scratch("cli-refusals-no-data");
    let claims = signorini::claims::claims(&crate::common::shelf(&d), crate::common::roles()).unwrap();
    for c in &claims {
        assert_eq!(c.verdict, signorini::claims::Verdict::NoData, "{}: {}", c.id, c.verdict.text());
    }
    let md = signorini::claims::markdown_for(&claims, &d);
    assert!(!md.contains("holds"), "{md}");
    assert!(md.contains(&format!("from the records in `{}/`", d.display())), "{md}");
    // the tracked document keeps its wording
    assert!(signorini::claims::markdown(&claims).contains("from the records in `results/`"));
}

#[test]
fn wrong_manifest_values_are_errors_naming_key_and_value() {
    let reference = "reference = { theta = 0.5, min_ndof = 4000 }";
    for (text, key, got, expected) in [
        (manifest_text("save_levels = [1, 1, 1]", &[""], ""), "run[0].save_levels", "[1, 1, 1]", "distinct levels"),
        (manifest_text("", &[""], "[drift]\ndefault = { rel = 1e300 }\n"), "drift.default.rel", "1e300", "[0, 1]"),
        (manifest_text("", &[""], "[drift]\nfields = { eta1 = { rel = 1e-9, floor = 2 } }\n"), "drift.fields.eta1.floor", "2e0", "[0, 1]"),
        (manifest_text("", &["no_reference = true"], ""), "run[0].no_reference", "true", "[defaults] declares a reference"),
        (manifest_text(reference, &["no_reference = false"], ""), "run[0].no_reference", "false", "true (drop the reference"),
        (
            manifest_text(reference, &[&format!("no_reference = true\n{reference}")], ""),
            "run[0].no_reference",
            "no_reference = true beside reference",
            "not both",
        ),
        (
            manifest_text("", &[""], "[[drift.rates]]\nrun = \"r0\"\nfield = \"err_quadratur\"\nmin = 1.4\nlast = 2\n"),
            "drift.rates[0].field",
            "\"err_quadratur\"",
            "err_quadrature",
        ),
        (
            manifest_text("", &[""], "[[drift.rates]]\nrun = \"r0\"\nfield = \"err_quadrature\"\nmin = 1.4\nlast = 5\n"),
            "drift.rates[0].last",
            "5",
            "2..=2",
        ),
        (
            manifest_text("", &[""], "[[drift.rates]]\nrun = \"r0\"\nfield = \"err_quadrature\"\nmin = nan\nlast = 2\n"),
            "drift.rates[0].min",
            "NaN",
            "a finite rate",
        ),
    ] {
        let e = parse_error(&text);
        assert!(e.starts_with("experiments/cli_case.toml: key `") && e.contains(&format!("`{key}`")), "{key}: {e}");
        assert!(e.contains(&format!("got {got}")) && e.contains(expected), "{key}: {e}");
    }
    // the measured tolerances and a rate floor on a real field stay accepted
    let ok = manifest_text(
        "",
        &[""],
        "[drift]\ndefault = { rel = 1e-12 }\nfields = { eta1 = { rel = 6e-7, floor = 2e-8 } }\n[[drift.rates]]\nrun = \"r0\"\nfield = \"err_quadrature\"\nmin = 1.4\nlast = 2\n",
    );
    Manifest::parse(Path::new("ok.toml"), &ok).unwrap();
}

/// Through the command line: a manifest with max_ndof below the initial mesh's unknowns is
/// refused with the file, key, value and the mesh's count, and nothing is run.
#[test]
fn a_max_ndof_below_the_initial_mesh_is_refused_with_its_count() {
    let d = scratch("cli-refusals-max-ndof");
    std::fs::write(d.join("cli_case.toml"), manifest_text("max_ndof = 5", &[""], "")).unwrap();
    let (code, _, err) = signorini_in(&d, &["run", "cli_case.toml", "--results", "res"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("cli_case.toml: key `run[0].max_ndof`") && err.contains("got 5"), "{err}");
    assert!(err.contains(">= 162") && err.contains("structured:4"), "{err}");
    assert!(!d.join("res").exists(), "a run was started");
}

/// A run that cannot be solved (a mesh too large for memory, a missing mesh file, a mesh the
/// problem cannot be solved on) is found before the first run is solved, naming the run.
#[test]
fn an_unsolvable_later_run_is_found_before_any_run_is_solved() {
    let quarter = repo("experiments/meshes/quarter_disc.msh");
    for (mesh, expected) in [
        ("structured:100000".to_string(), "fits in this machine's memory"),
        ("gmsh:no_such_mesh.msh".to_string(), "no_such_mesh.msh"),
        // ex71 names no Gmsh group: the file's groups cannot be mapped
        (format!("gmsh:{quarter}"), "a mesh problem ex71 can be solved on"),
    ] {
        let d = scratch("cli-refusals-later-run");
        std::fs::write(d.join("cli_case.toml"), manifest_text("", &["", &format!("mesh = \"{mesh}\"")], "")).unwrap();
        let (code, _, err) = signorini_in(&d, &["run", "cli_case.toml", "--results", "res"]);
        assert_eq!(code, 1, "{mesh}: {err}");
        assert!(err.contains("cli_case.toml: key `run[1].mesh`") && err.contains(expected), "{mesh}: {err}");
        assert!(!d.join("res").exists(), "{mesh}: the first run was solved before the second was checked");
        // a mesh file that cannot be read is refused when the manifest is read (its hash is part
        // of the run's spec); the others when the runs are checked, naming the run
        match Manifest::load(&d.join("cli_case.toml")) {
            Err(e) => assert!(mesh.contains("no_such_mesh") && e.to_string().contains("a readable file"), "{mesh}: {e}"),
            Ok(m) => {
                assert!(err.contains("(run r1)"), "{mesh}: {err}");
                assert!(m.check_runs().is_err());
            }
        }
    }
}

#[test]
fn a_reference_for_a_problem_with_an_exact_solution_is_found_before_solving() {
    let text = manifest_text("", &["", "reference = { theta = 0.5, min_ndof = 4000 }"], "");
    let m = Manifest::parse(Path::new("cli_case.toml"), &text).unwrap();
    let e = m.check_runs().unwrap_err().to_string();
    assert!(e.contains("run[1].reference") && e.contains("exact solution"), "{e}");
}

#[test]
fn a_shard_without_runs_says_how_many_runs_the_study_has() {
    let d = scratch("cli-refusals-shard");
    let pair = repo("tests/fixtures/cli_pair.toml");
    let (code, _, err) = signorini_in(&d, &["run", &pair, "--shard", "5/9", "--results", "res"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--shard 5/9") && err.contains("holds no run") && err.contains("cli_pair has 2 run(s)"), "{err}");
    assert!(!d.join("res").exists());
    // a shard with runs in one manifest and none in the other runs, with a note for the other
    std::fs::write(d.join("single.toml"), manifest_text("", &[""], "")).unwrap();
    let (code, _, err) = signorini_in(&d, &["run", &pair, "single.toml", "--shard", "2/2", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("holds no run of single (1 run(s))"), "{err}");
    assert!(d.join("res/cli_pair/runs/uniform.json").exists() && !d.join("res/single/runs/r0.json").exists());
}

#[test]
fn jobs_beyond_the_cores_are_capped_with_a_note() {
    let d = scratch("cli-refusals-jobs");
    let cores = std::thread::available_parallelism().unwrap().get();
    let (code, _, err) = signorini_in(&d, &["run", &repo("tests/fixtures/cli_pair.toml"), "--quick", "--jobs", "5000", "--results", "res"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains(&format!("--jobs 5000 is more than the {cores} core(s)")) && err.contains(&format!("using {cores}")), "{err}");
    let prov: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("res/cli_pair/provenance.json")).unwrap()).unwrap();
    assert_eq!(prov["threads"].as_u64(), Some(cores as u64));
    let (code, _, err) = signorini_in(&d, &["run", &repo("tests/fixtures/cli_pair.toml"), "--jobs", "0", "--results", "res"]);
    assert_eq!(code, 1);
    assert!(err.contains("--jobs must be at least 1"), "{err}");
}

/// `RAYON_NUM_THREADS` that is not a positive integer means one thread per core, as rayon reads
/// it, and a one-line note says so rather than nothing.
#[test]
fn rayon_threads_that_are_not_a_positive_integer_are_named_in_a_note() {
    let cores = std::thread::available_parallelism().unwrap().get();
    for given in ["abc", "-1", "0"] {
        let out = Command::new(env!("CARGO_BIN_EXE_signorini"))
            .args(["solve", "--problem", "ex72", "--mesh", "structured:4"])
            .env("RAYON_NUM_THREADS", given)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{given}: {err}");
        let note = format!("note: RAYON_NUM_THREADS=\"{given}\" is not a positive integer; using one thread per core ({cores})");
        assert_eq!(err.lines().filter(|l| l.starts_with(&note)).count(), 1, "{given}: {err}");
    }
    let unset = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["solve", "--problem", "ex72", "--mesh", "structured:4"])
        .env_remove("RAYON_NUM_THREADS")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&unset.stderr);
    assert!(unset.status.success() && !err.contains("RAYON_NUM_THREADS"), "{err}");
}

/// A reference solution whose loop ends short of min_ndof says how far it got and why, instead
/// of "interrupted".
#[test]
fn a_reference_that_never_reaches_min_ndof_says_what_happened() {
    let d = scratch("cli-refusals-short-ref");
    let text = "[defaults]\nproblem = \"ex72\"\nlevels = 2\n[[run]]\nid = \"a\"\nreference = { theta = 1.0, min_ndof = 100000 }\n";
    std::fs::write(d.join("short.toml"), text).unwrap();
    let (code, _, err) = signorini_in(&d, &["run", "short.toml", "--results", "res"]);
    assert_eq!(code, 1, "{err}");
    assert!(!err.contains("interrupted"), "{err}");
    assert!(err.contains("short/a") && err.contains("after 200 levels") && err.contains("min_ndof = 100000"), "{err}");
    assert!(err.contains("theta = 1") && err.contains("lower reference.theta"), "{err}");
    assert!(!d.join("res/short/runs/a.json").exists());
}

#[test]
fn help_says_solve_takes_gmsh_meshes() {
    let (code, out, _) = signorini_in_repo(&["--help"]);
    assert_eq!(code, 0);
    let line = out.lines().find(|l| l.trim_start().starts_with("solve")).unwrap();
    assert!(line.contains("gmsh") && !line.contains("structured mesh"), "{line}");
}

#[test]
fn export_says_what_it_wrote() {
    let d = scratch("cli-refusals-export");
    let (code, out, err) = signorini_in_repo(&["export", "--problem", "ex71", "--mesh", "structured:2", "--out", d.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    for f in ["mesh.vtu", "case.json"] {
        let p = d.join(f);
        assert!(p.exists() && out.contains(&format!("wrote {}", p.display())), "{f}: {out}");
    }
}

/// On a curved Gmsh boundary the arc lengths of the contact zone are printed to 6 significant
/// digits like the other numbers of the summary; `--json` keeps every digit.
#[test]
fn contact_zone_on_a_gmsh_mesh_is_printed_with_six_digits() {
    let args = ["solve", "--problem", "experiments/problems/hertz.toml", "--mesh", "gmsh:experiments/meshes/hertz.msh"];
    let (code, out, err) = signorini_in_repo(&args);
    assert_eq!(code, 0, "{err}");
    let zone = out.split("contact zone [").nth(1).and_then(|s| s.split(']').next()).unwrap_or_else(|| panic!("{out}"));
    for v in zone.split(", ") {
        let digits = v.trim_start_matches("0.").trim_start_matches('0').len();
        assert!(v.parse::<f64>().is_ok() && digits <= 6, "{v} in {out}");
    }
    let (_, json, _) = signorini_in_repo(&[&args[..], &["--json"]].concat());
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let s0 = v["contact_zones"][0]["s"][0].as_f64().unwrap();
    assert!(((s0 - zone.split(", ").next().unwrap().parse::<f64>().unwrap()) / s0).abs() < 5e-6, "{s0} vs {zone}");
}

/// `make` finds the binary where cargo puts it: $(CARGO_TARGET_DIR) when set.
#[test]
fn makefile_binary_follows_cargo_target_dir() {
    let out = Command::new("make")
        .args(["-n", "figures"])
        .env("CARGO_TARGET_DIR", "/tmp/elsewhere")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("make is a prerequisite");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("/tmp/elsewhere/figures/signorini-figures"), "{text}");
    let out = Command::new("make")
        .args(["-n", "figures"])
        .env_remove("CARGO_TARGET_DIR")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stdout).contains("target/figures/signorini-figures"));
}

/// `cargo run -- ARGS` runs the command line although the crate has a second binary (bench).
#[test]
fn cargo_run_has_a_default_binary() {
    let text = std::fs::read_to_string(repo("Cargo.toml")).unwrap();
    let cargo: toml::Table = toml::from_str(&text).unwrap();
    assert_eq!(cargo["package"]["default-run"].as_str(), Some("signorini"));
    assert!(Path::new(&repo("src/bin")).is_dir(), "the default only matters with a second binary");
}

#[test]
fn an_unknown_problem_lists_the_known_ones() {
    let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex73", "--mesh", "structured:4"]);
    assert_ne!(code, 0);
    assert!(err.contains("unknown problem 'ex73'") && err.contains("ex71") && err.contains("ex72"), "{err}");
}

#[test]
fn a_malformed_mesh_string_says_what_is_expected() {
    for spec in ["structured", "structured:", "structured:-3", "structured:4x", "hexagons:4", "structured:0"] {
        let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", spec]);
        assert_ne!(code, 0, "{spec}");
        assert!(err.contains("malformed mesh description") && err.contains("structured:N"), "{spec}: {err}");
    }
}

#[test]
fn an_odd_symmetric_mesh_says_n_must_be_even() {
    for (spec, suggest) in
        [("symmetric:5", "use symmetric:4 or symmetric:6"), ("symmetric:1", "use symmetric:2"), ("symmetric:0", "use symmetric:2")]
    {
        let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", spec]);
        assert_eq!(code, 1, "{spec}: {err}");
        assert!(err.contains(&format!("'{spec}'")) && err.contains("symmetric:N needs N even") && err.contains(suggest), "{spec}: {err}");
    }
}

#[test]
fn an_odd_mesh_for_the_wedge_names_the_missing_kink() {
    let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex72", "--mesh", "structured:5"]);
    assert_ne!(code, 0);
    assert!(err.contains("(1, 0.5)") && err.contains("kink"), "{err}");
}

#[test]
fn a_non_converging_solver_reports_iterations_and_residual() {
    let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex72", "--mesh", "structured:16", "--max-pdas-iterations", "2"]);
    assert_ne!(code, 0);
    assert!(err.contains("did not converge in 2 iterations") && err.contains("residual"), "{err}");
}

#[test]
fn a_malformed_probe_is_a_clear_error() {
    let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", "0.5;0.5"]);
    assert_ne!(code, 0);
    assert!(err.contains("malformed --probe"), "{err}");
}

#[test]
fn solve_json_has_the_contract_fields() {
    let out = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", "0.5,0.5", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "problem",
        "ndof",
        "ndof_free",
        "n_elements",
        "h_min",
        "h_max",
        "pdas_iterations",
        "active_nodes",
        "contact_zone",
        "kkt",
        "error",
        "probes",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["ndof"], 2 * 81);
    for key in ["linf_quadrature", "linf_dense", "linf_nodal"] {
        assert!(v["error"][key].as_f64().unwrap() > 0.0);
    }
    let u = v["probes"][0]["u"].as_array().unwrap();
    assert_eq!(u.len(), 2);
}

#[test]
fn a_probe_outside_the_domain_or_not_finite_is_an_error() {
    for p in ["2,0.5", "0.5,-0.1", "1.0000001,0.5", "-0.1,0.5"] {
        let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", p]);
        assert_eq!(code, 1, "{p}: {err}");
        assert!(err.contains("outside the mesh") && err.contains(p), "{p}: {err}");
    }
    for p in ["nan,0.5", "0.5,NaN", "inf,0.5", "0.5,-inf", "1e999,0"] {
        let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", p]);
        assert_eq!(code, 1, "{p}: {err}");
        assert!(err.contains("malformed --probe") && err.contains("finite"), "{p}: {err}");
    }
}

#[test]
fn probe_accepts_negative_numbers_and_corners() {
    // a negative coordinate is a value, not a flag: read as such and then found outside
    let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", "-0.1,0.5"]);
    assert_eq!(code, 1);
    assert!(!err.contains("unexpected argument") && err.contains("outside the mesh"), "{err}");
    let (code, out, err) =
        signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", "-0,0", "--probe", "1,1", "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for p in v["probes"].as_array().unwrap() {
        assert!(p["x"].is_f64() && p["u"][0].is_f64() && p["u"][1].is_f64(), "{p}");
    }
}

#[test]
fn inert_flags_are_rejected() {
    let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--theta", "0.3"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--adapt-levels"), "{err}");
    let (code, _, err) = signorini_in_repo(&["adapt", "--problem", "ex71", "--uniform", "--theta", "0.3"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--uniform") && err.contains("--theta"), "{err}");
    let d = std::env::temp_dir().join(format!("signorini-inert-{}", std::process::id()));
    let (code, _, err) =
        signorini_in_repo(&["export", "--problem", "ex71", "--mesh", "structured:4", "--json", "--out", d.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--json"), "{err}");
    assert!(!d.exists());
}

#[test]
fn invalid_loop_settings_are_errors_naming_the_flag() {
    for (args, flag, expected) in [
        (&["--levels", "0"][..], "--levels", ">= 1"),
        (&["--theta", "1.5"][..], "--theta", "(0, 1]"),
        (&["--theta", "0"][..], "--theta", "(0, 1]"),
        (&["--theta", "-0.5"][..], "--theta", "(0, 1]"),
        (&["--max-ndof", "0"][..], "--max-ndof", ">= 1"),
        (&["--c0", "-1"][..], "--c0", "positive"),
        (&["--c0", "nan"][..], "--c0", "positive"),
    ] {
        let mut a = vec!["adapt", "--problem", "ex71"];
        if flag != "--levels" {
            a.extend_from_slice(&["--levels", "2"]);
        }
        a.extend_from_slice(args);
        let (code, out, err) = signorini_in_repo(&a);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?}: printed before failing: {out}");
        assert!(err.contains(flag) && err.contains(expected), "{args:?}: {err}");
    }
    let (code, _, err) =
        signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--adapt-levels", "1", "--theta", "1.5"]);
    assert_eq!(code, 1);
    assert!(err.contains("--theta") && err.contains("1.5"), "{err}");
    let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--max-pdas-iterations", "0"]);
    assert_eq!(code, 1);
    assert!(err.contains("--max-pdas-iterations"), "{err}");
}

#[test]
fn adapt_without_exact_solution_says_so_instead_of_nan() {
    let (code, out, err) = signorini_in_repo(&["adapt", "--problem", "ex72", "--levels", "2"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("no exact solution"), "{out}");
    assert!(!out.contains("NaN"), "{out}");
}

#[test]
fn human_output_has_no_rust_internals() {
    let (code, out, err) = signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", "0.5,0.5"]);
    assert_eq!(code, 0, "{err}");
    for internal in ["Some(", "None", "1 active-set iterations"] {
        assert!(!out.contains(internal), "{internal}: {out}");
    }
    assert!(out.contains("1 active-set iteration") && out.contains("contact zone [0, 1]") && out.contains("u_h(0.5, 0.5) = ("), "{out}");
    let (code, out, _) = signorini_in_repo(&["solve", "--problem", "ex72", "--mesh", "structured:4"]);
    assert_eq!(code, 0);
    assert!(out.contains("no exact solution") && !out.contains("None") && !out.contains("Some("), "{out}");
}

#[test]
fn an_unwritable_output_names_the_path_and_the_step() {
    let d = std::env::temp_dir().join(format!("signorini-unwritable-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    // a file where a folder should be: unwritable even for root
    let file = d.join("a_file");
    std::fs::write(&file, "").unwrap();
    let out = file.join("out");
    let (code, _, err) = signorini_in_repo(&["export", "--problem", "ex71", "--mesh", "structured:4", "--out", out.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains(out.to_str().unwrap()) && err.contains(&format!("{} is a regular file, not a folder", file.display())), "{err}");
    let fixture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tiny.toml");
    let (code, _, err) = signorini_in_repo(&["run", fixture.to_str().unwrap(), "--quick", "--results", out.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains(out.to_str().unwrap()), "{err}");
    let (code, _, err) = signorini_in_repo(&["figures", "--results", "results", "--figures", out.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains(out.to_str().unwrap()), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn write_helpers_name_the_path() {
    let d = std::env::temp_dir().join(format!("signorini-write-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("f"), "").unwrap();
    let target = d.join("f").join("x.json");
    let e = signorini::records::write_json(&target, &1).unwrap_err().to_string();
    assert!(e.contains(&format!("{} is a regular file, not a folder", d.join("f").display())), "{e}");
    // a directory where the file should be: the rename fails, and no temporary file is left
    std::fs::create_dir_all(d.join("dir.json").join("sub")).unwrap();
    let e = signorini::records::write_atomic(&d.join("dir.json"), b"{}").unwrap_err().to_string();
    assert!(e.contains("dir.json") && e.contains("renaming"), "{e}");
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 2, "temporary file left behind");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_missing_manifest_is_named_once() {
    let (code, _, err) = signorini_in_repo(&["run", "experiments/no_such_study.toml"]);
    assert_eq!(code, 1);
    assert!(err.contains("experiments/no_such_study.toml"), "{err}");
    assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
}

#[test]
fn every_flag_of_every_subcommand_has_a_description() {
    for cmd in [&[][..], &["solve"], &["adapt"], &["run"], &["drift"], &["figures"], &["export"]] {
        let mut args = cmd.to_vec();
        args.push("--help");
        let (code, out, _) = signorini_in_repo(&args);
        assert_eq!(code, 0);
        let lines: Vec<&str> = out.lines().collect();
        let mut flags = 0;
        for (i, line) in lines.iter().enumerate() {
            let t = line.trim_start();
            if !(t.starts_with("--") || (t.starts_with('-') && t.chars().nth(1).is_some_and(|c| c.is_ascii_alphabetic()))) {
                continue;
            }
            flags += 1;
            // the description follows on the same line after two spaces, or on the next, indented further
            let same_line = t.split_once("  ").is_some_and(|(_, d)| !d.trim().is_empty());
            let indent = line.len() - t.len();
            let next_line = lines.get(i + 1).is_some_and(|n| {
                let nt = n.trim_start();
                n.len() - nt.len() > indent && !nt.is_empty() && !nt.starts_with('-')
            });
            assert!(same_line || next_line, "{cmd:?}: flag without a description: {line}");
        }
        assert!(flags >= 1, "{cmd:?}: no flags found in\n{out}");
    }
}
