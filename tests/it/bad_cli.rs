//! Flags and manifests that would mislead: a flag that cannot apply, a manifest value that is
//! accepted but wrong, a run that cannot be solved found only after the others, a reference
//! solution that falls short, and the smaller things a reviewer trips over (help text, export's
//! silence, 17-digit contact zones, the Makefile's binary, `cargo run`'s binary).

use crate::common::signorini_in;
use signorini::study::manifest::Manifest;
use std::path::{Path, PathBuf};
use std::process::Command;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("signorini-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn signorini(args: &[&str]) -> (i32, String, String) {
    signorini_in(Path::new(env!("CARGO_MANIFEST_DIR")), args)
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
fn bad_accept_with_flags_it_would_ignore_is_refused_before_anything_runs() {
    for (extra, flag) in [
        (&["--quick"][..], "--quick"),
        (&["--report", "x.json"][..], "--report"),
        (&["--study", "ex71"][..], "--study"),
        (&["--against", "somewhere"][..], "--against"),
    ] {
        let d = tmp("accept");
        let mut args = vec!["drift", "--accept", "hertz", "--results", d.to_str().unwrap()];
        args.extend_from_slice(extra);
        let (code, out, err) = signorini(&args);
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
fn bad_merge_without_its_flags_or_into_another_file_is_refused_before_anything_runs() {
    for (extra, missing) in [(&["--study", "hertz"][..], "--report"), (&["--report", "x.json"][..], "--study")] {
        let mut args = vec!["drift", "--merge"];
        args.extend_from_slice(extra);
        let (code, _, err) = signorini(&args);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains(missing) && err.contains("required"), "{extra:?}: {err}");
    }
    let d = tmp("merge");
    let file = d.join("notes.json");
    std::fs::write(&file, "{\"these\": \"are notes\"}").unwrap();
    let (code, out, err) = signorini(&["drift", "--study", "hertz", "--merge", "--report", file.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("notes.json") && err.contains("not a drift report") && err.contains("nothing was rerun"), "{err}");
    assert!(!out.contains("hertz/"), "nothing is rerun: {out}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "{\"these\": \"are notes\"}");
}

#[test]
fn bad_empty_experiments_folder_is_an_error_and_claims_nothing() {
    let d = tmp("empty-exp");
    let (exp, res) = (d.join("experiments"), d.join("results"));
    std::fs::create_dir_all(&exp).unwrap();
    std::fs::create_dir_all(&res).unwrap();
    let (code, _, err) = signorini(&[
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
    let d = tmp("no-data");
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
fn bad_manifest_values_that_were_accepted_are_errors_naming_key_and_value() {
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
fn bad_max_ndof_below_the_initial_mesh_is_refused_with_its_count() {
    let d = tmp("max-ndof");
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
fn bad_later_run_is_found_before_any_run_is_solved() {
    let quarter = repo("experiments/meshes/quarter_disc.msh");
    for (mesh, expected) in [
        ("structured:100000".to_string(), "fits in this machine's memory"),
        ("gmsh:no_such_mesh.msh".to_string(), "no_such_mesh.msh"),
        // ex71 names no Gmsh group: the file's groups cannot be mapped
        (format!("gmsh:{quarter}"), "a mesh problem ex71 can be solved on"),
    ] {
        let d = tmp("later-run");
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
fn bad_reference_for_a_problem_with_an_exact_solution_is_found_before_solving() {
    let text = manifest_text("", &["", "reference = { theta = 0.5, min_ndof = 4000 }"], "");
    let m = Manifest::parse(Path::new("cli_case.toml"), &text).unwrap();
    let e = m.check_runs().unwrap_err().to_string();
    assert!(e.contains("run[1].reference") && e.contains("exact solution"), "{e}");
}

#[test]
fn bad_shard_without_runs_says_how_many_runs_the_study_has() {
    let d = tmp("shard");
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
    let d = tmp("jobs");
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
fn bad_reference_that_never_reaches_min_ndof_says_what_happened() {
    let d = tmp("short-ref");
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
    let (code, out, _) = signorini(&["--help"]);
    assert_eq!(code, 0);
    let line = out.lines().find(|l| l.trim_start().starts_with("solve")).unwrap();
    assert!(line.contains("gmsh") && !line.contains("structured mesh"), "{line}");
}

#[test]
fn export_says_what_it_wrote() {
    let d = tmp("export");
    let (code, out, err) = signorini(&["export", "--problem", "ex71", "--mesh", "structured:2", "--out", d.to_str().unwrap()]);
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
    let (code, out, err) = signorini(&args);
    assert_eq!(code, 0, "{err}");
    let zone = out.split("contact zone [").nth(1).and_then(|s| s.split(']').next()).unwrap_or_else(|| panic!("{out}"));
    for v in zone.split(", ") {
        let digits = v.trim_start_matches("0.").trim_start_matches('0').len();
        assert!(v.parse::<f64>().is_ok() && digits <= 6, "{v} in {out}");
    }
    let (_, json, _) = signorini(&[&args[..], &["--json"]].concat());
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
    assert!(out.status.success() && text.contains("/tmp/elsewhere/release/signorini figures"), "{text}");
    let out = Command::new("make")
        .args(["-n", "figures"])
        .env_remove("CARGO_TARGET_DIR")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stdout).contains("target/release/signorini figures"));
}

/// `cargo run -- ARGS` runs the command line although the crate has a second binary (bench).
#[test]
fn cargo_run_has_a_default_binary() {
    let text = std::fs::read_to_string(repo("Cargo.toml")).unwrap();
    let cargo: toml::Table = toml::from_str(&text).unwrap();
    assert_eq!(cargo["package"]["default-run"].as_str(), Some("signorini"));
    assert!(Path::new(&repo("src/bin")).is_dir(), "the default only matters with a second binary");
}
