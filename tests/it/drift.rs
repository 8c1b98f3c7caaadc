//! The drift check reports what moved, with the right row, and passes an unperturbed copy.

use crate::common::{LONG, TWO_SHORT_RUNS, checkpoint_levels, output_in, scratch, signorini_in, stored_study};
use signorini::manifest::Manifest;
use signorini::records::{RunRecord, StudyDir};
use signorini::study::drift::{DECADES, ORDER_OF_MAGNITUDE, compare_study, observed_rate};
use signorini::study::{self, RunOptions};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn manifest() -> Manifest {
    Manifest::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tiny.toml")).unwrap()
}

/// Full and quick runs of the tiny study, computed once.
fn stored_and_quick() -> &'static (Vec<RunRecord>, Vec<RunRecord>, Vec<RunRecord>) {
    static RUNS: OnceLock<(Vec<RunRecord>, Vec<RunRecord>, Vec<RunRecord>)> = OnceLock::new();
    RUNS.get_or_init(|| {
        let root: PathBuf = std::env::temp_dir().join(format!("signorini-drift-{}", std::process::id()));
        let m = manifest();
        let run = |quick: bool, sub: &str| {
            let results = root.join(sub);
            study::run_study(
                &m,
                &RunOptions {
                    quick,
                    shard: None,
                    fresh: true,
                    replace: false,
                    results: results.clone(),
                    progress: false,
                    wait_for_lock: false,
                },
            )
            .unwrap();
            StudyDir::new(&results, &m.study).read_runs().unwrap()
        };
        (run(false, "full"), run(true, "quick"), run(false, "full2"))
    })
}

#[test]
fn unperturbed_copies_pass_quick_and_full() {
    let (stored, quick, full2) = stored_and_quick();
    let m = manifest();
    assert_eq!(compare_study(&m, stored, quick, true), vec![]);
    assert_eq!(compare_study(&m, stored, full2, false), vec![]);
}

#[test]
fn perturbed_float_beyond_tolerance_is_reported_with_its_row() {
    let (stored, quick, _) = stored_and_quick();
    let mut s = stored.clone();
    s[0].levels[2].terms.eta1 *= 1.0 + 1e-6; // tolerance is rel 1e-9 by default
    let rows = compare_study(&manifest(), &s, quick, true);
    assert_eq!(rows.len(), 1, "{rows:?}");
    let r = &rows[0];
    assert_eq!((r.run.as_str(), r.level, r.field.as_str()), ("a", Some(2), "eta1"));
    assert!((r.relative_change.unwrap() - 1e-6).abs() < 1e-9);
    // within tolerance: no drift
    let mut s = stored.clone();
    s[0].levels[2].terms.eta1 *= 1.0 + 1e-12;
    assert!(compare_study(&manifest(), &s, quick, true).is_empty());
}

#[test]
fn changed_integer_is_reported_exactly() {
    let (stored, quick, _) = stored_and_quick();
    let mut s = stored.clone();
    s[1].levels[1].active_nodes += 1;
    let rows = compare_study(&manifest(), &s, quick, true);
    assert_eq!(rows.len(), 1, "{rows:?}");
    assert_eq!(
        (rows[0].run.as_str(), rows[0].level, rows[0].field.as_str(), rows[0].tolerance.as_str()),
        ("b", Some(1), "active_nodes", "exact")
    );
}

#[test]
fn dropped_level_missing_run_and_timings() {
    let (stored, quick, full2) = stored_and_quick();
    let m = manifest();
    let mut s = stored.clone();
    s[0].levels.pop();
    let rows = compare_study(&m, &s, full2, false);
    assert!(rows.iter().any(|r| r.run == "a" && r.field == "levels"), "{rows:?}");
    assert!(rows.iter().any(|r| r.run == "a" && r.level == Some(4) && r.stored == "(missing)"), "{rows:?}");
    // in the quick form, a stored run shorter than the quick prefix is drift too
    let mut s = stored.clone();
    s[1].levels.truncate(1);
    let rows = compare_study(&m, &s, quick, true);
    assert!(rows.iter().any(|r| r.run == "b" && r.level == Some(1) && r.stored == "(missing)"), "{rows:?}");
    // a missing run
    let rows = compare_study(&m, &stored[..1], quick, true);
    assert!(rows.iter().any(|r| r.run == "b" && r.field == "run"), "{rows:?}");
    // a missing study
    let rows = compare_study(&m, &[], quick, true);
    assert!(rows.iter().any(|r| r.field == "study"), "{rows:?}");
    // timings are never compared
    let mut s = stored.clone();
    s[0].levels[0].t_solve += 100.0;
    assert!(compare_study(&m, &s, quick, true).is_empty());
}

#[test]
fn rate_floors_are_one_sided() {
    let (stored, _, full2) = stored_and_quick();
    let rate = observed_rate(&full2[1], "err_quadrature", 3).unwrap();
    assert!(rate > 1.2 && rate < 1.7, "ex71 uniform error rate in NDF {rate}");
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tiny.toml")).unwrap();
    for (min, drift) in [(1.2, false), (2.0, true)] {
        let t = format!(
            "{text}\n[drift]\ndefault = {{ rel = 1e-9, floor = 1e-14 }}\n[[drift.rates]]\nrun = \"b\"\nfield = \"err_quadrature\"\nmin = {min}\nlast = 3\n"
        );
        let m = Manifest::parse(Path::new("tiny.toml"), &t).unwrap();
        let rows = compare_study(&m, stored, full2, false);
        assert_eq!(!rows.is_empty(), drift, "floor {min}: {rows:?}");
    }
}

/// Every declared study with its stored records.
fn declared() -> Vec<(Manifest, Vec<RunRecord>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    signorini::manifest::declared(&root.join("experiments"), &[])
        .unwrap()
        .into_iter()
        .map(|m| {
            let runs = StudyDir::new(&root.join("results"), &m.study).read_runs().unwrap();
            (m, runs)
        })
        .collect()
}

/// With the tolerances the manifests declare, a change of 1e-5 relative to any float field of
/// the stored records, at the first, a middle and the last level of every run, is drift --
/// wherever measured round-off allows it. The tolerances are 10x the measured round-off
/// (`manifest_tolerances_are_the_measured_round_off_times_the_margin`); where that exceeds 1e-5
/// of a value (a field far below its largest value in the run: an error of 1e-8 in a run that
/// starts at 1e-3, eta_4 decaying at NDF^-3.3), no tolerance honest about round-off can see a
/// change of 1e-5. Those entries are listed and must be a small minority; every declared `rel`
/// is below 1e-6.
#[test]
fn declared_tolerances_catch_a_relative_change_of_1e_5_wherever_round_off_allows() {
    // roundoff_floor is compared by its order of magnitude (test below), not to 1e-5
    let floats: Vec<_> =
        signorini::level::record::float_fields().into_iter().filter(|f| !ORDER_OF_MAGNITUDE.contains(&f.as_str())).collect();
    let (mut checked, mut limited) = (0, Vec::new());
    for (m, stored) in declared() {
        assert!(!stored.is_empty(), "{}: no stored results", m.study);
        for field in &floats {
            assert!(m.drift.tolerance(field).rel < 1e-6, "{}: rel tolerance of {field} is {:e}", m.study, m.drift.tolerance(field).rel);
        }
        for run in &stored {
            // each change compared on its run alone (a manifest of that run, one record): the
            // other runs cannot hold its row, and copying the whole study per change made this
            // test the suite's slowest (75 s)
            let mut alone = m.clone();
            alone.runs.retain(|p| p.spec.id == run.run.id);
            let mut perturbed = vec![run.clone()];
            let n = run.levels.len();
            let levels: Vec<serde_json::Value> = run.levels.iter().map(|l| serde_json::to_value(l).unwrap()).collect();
            for level in [0, n / 2, n - 1] {
                for field in &floats {
                    let Some(v) = levels[level][field].as_f64() else { continue };
                    if v == 0.0 {
                        continue;
                    }
                    let scale = levels.iter().filter_map(|l| l[field].as_f64()).fold(0.0f64, |a, x| a.max(x.abs()));
                    let tol = m.drift.tolerance(field);
                    if tol.rel * v.abs() + tol.floor * scale >= 1e-5 * v.abs() {
                        limited.push(format!(
                            "{}/{} L{level} {field} {:.1e}",
                            m.study,
                            run.run.id,
                            (tol.rel * v.abs() + tol.floor * scale) / v.abs()
                        ));
                        continue;
                    }
                    let mut lv = levels[level].clone();
                    lv[field] = serde_json::json!(v * (1.0 + 1e-5));
                    perturbed[0].levels[level] = serde_json::from_value(lv).unwrap();
                    let rows = compare_study(&alone, std::slice::from_ref(run), &perturbed, false);
                    perturbed[0].levels[level] = run.levels[level].clone();
                    assert!(
                        rows.iter().any(|r| r.run == run.run.id && r.level == Some(level) && &r.field == field),
                        "{}/{} level {level}: {field} = {v:e} changed by 1e-5 relative is not drift under {tol:?}",
                        m.study,
                        run.run.id
                    );
                    checked += 1;
                }
            }
        }
    }
    eprintln!("{checked} values caught at 1e-5; {} limited by round-off (smallest detectable relative change): {limited:?}", limited.len());
    assert!(checked > 500, "only {checked} values checked");
    assert!(limited.len() * 10 < checked, "{} of {} values cannot be checked to 1e-5", limited.len(), checked + limited.len());
}

/// The stored results of every study are consistent with themselves: levels.csv and the
/// provenance's run list are what the records render, and the runs are the declared ones.
#[test]
fn stored_views_match_the_records() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("results");
    for (m, stored) in declared() {
        let rows = signorini::study::drift::check_derived(&signorini::store::Store::new(&root, &m.study), &stored);
        assert!(rows.is_empty(), "{}: {rows:?}", m.study);
        signorini::check_complete(&m, &root).unwrap();
    }
}

/// Through the command line: a perturbed float at the last level, an edited levels.csv and an
/// edited CLAIMS.md each fail `signorini drift`; the untouched store passes.
#[test]
fn drift_command_fails_on_perturbed_record_csv_or_claims() {
    let d = std::env::temp_dir().join(format!("signorini-drift-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    let (exp, res) = (d.join("experiments"), d.join("results"));
    std::fs::create_dir_all(&exp).unwrap();
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tiny.toml"), exp.join("tiny.toml")).unwrap();
    let bin = env!("CARGO_BIN_EXE_signorini");
    let run = |args: &[&str]| {
        let out = std::process::Command::new(bin).args(args).current_dir(&d).output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
        assert!(!text.contains("panicked"), "{text}");
        (out.status.success(), text)
    };
    assert!(run(&["run", "experiments/tiny.toml", "--quick", "--results", "results"]).0);
    // CLAIMS.md as rendered from this results folder (drawn by `figures`, which needs no figure data here)
    let claims = signorini::claims::markdown(
        &signorini::claims::claims(&crate::common::shelf(&res), &signorini::analysis::roles::read(&exp).unwrap()).unwrap(),
    );
    std::fs::write(res.join("CLAIMS.md"), &claims).unwrap();
    let drift = || run(&["drift", "--quick", "--experiments", "experiments", "--results", "results"]);
    let (ok, text) = drift();
    assert!(ok, "{text}");
    let dir = StudyDir::new(&res, "tiny");
    // the reference solution of run a is stored with its history, and drift rebuilt it from there
    assert!(text.contains("reference solution from its stored history") && text.contains("rebuilt in"), "{text}");
    let key = signorini::records::ReferenceRecord::key_of(&dir.read_run("a").unwrap().unwrap().run).unwrap();
    let reference = std::fs::read_to_string(dir.reference_file(&key)).unwrap();
    // a deleted reference: drift computes it and names the stored one missing; run stores it again
    std::fs::remove_file(dir.reference_file(&key)).unwrap();
    let (ok, text) = drift();
    assert!(!ok && text.contains(&format!("reference {key}")) && text.contains("(missing)"), "{text}");
    let (ok, text) = run(&["run", "experiments/tiny.toml", "--quick", "--results", "results"]);
    assert!(ok && text.contains("computing it once"), "{text}");
    let (again, before) =
        (dir.read_reference(&key).unwrap().unwrap(), serde_json::from_str::<signorini::records::ReferenceRecord>(&reference).unwrap());
    assert!(
        again.rebuild.history == before.rebuild.history && again.rebuild.ndof == before.rebuild.ndof,
        "the reference computed again is the stored one"
    );
    // a reference file that does not rebuild what it records: an error naming the file
    std::fs::write(dir.reference_file(&key), reference.replacen("\"ndof\": ", "\"ndof\": 1", 1)).unwrap();
    let (ok, text) = drift();
    assert!(!ok && text.contains(&format!("{key}.json")) && text.contains("replays to"), "{text}");
    // and the store's own check says the runs were measured against another reference
    let checked = signorini::store::Store::new(&res, "tiny").check().unwrap();
    assert!(checked.faults_text().contains("measured against a reference of"), "{}", checked.faults_text());
    std::fs::write(dir.reference_file(&key), &reference).unwrap();
    assert!(drift().0);
    // a float at the last level
    let original = std::fs::read_to_string(dir.run_file("b")).unwrap();
    let mut rec: RunRecord = serde_json::from_str(&original).unwrap();
    let last = rec.levels.len() - 1;
    rec.levels[last].terms.eta2 *= 1.0 + 1e-5;
    std::fs::write(dir.run_file("b"), serde_json::to_string_pretty(&rec).unwrap()).unwrap();
    std::fs::write(dir.csv_file(), dir.csv_bytes(&dir.read_runs().unwrap()).unwrap()).unwrap(); // keep the view in step: only the number moved
    let (ok, text) = drift();
    assert!(!ok && text.contains("eta2"), "{text}");
    std::fs::write(dir.run_file("b"), &original).unwrap();
    std::fs::write(dir.csv_file(), dir.csv_bytes(&dir.read_runs().unwrap()).unwrap()).unwrap();
    assert!(drift().0);
    // an edited CSV
    let csv = std::fs::read_to_string(dir.csv_file()).unwrap();
    std::fs::write(dir.csv_file(), csv.replacen("ex71", "ex7l", 1)).unwrap();
    let (ok, text) = drift();
    assert!(!ok && text.contains("levels.csv"), "{text}");
    std::fs::write(dir.csv_file(), &csv).unwrap();
    // an edited CLAIMS.md
    std::fs::write(res.join("CLAIMS.md"), format!("{claims}a line added by hand\n")).unwrap();
    let (ok, text) = drift();
    assert!(!ok && text.contains("CLAIMS.md"), "{text}");
    std::fs::remove_dir_all(&d).ok();
}

/// The manifests' tolerances are what the round-off measurement (`make roundoff`, reports in
/// results/roundoff/) asks for, field by field: MARGIN x the largest change seen when the
/// studies are rerun with another ordering or thread count. On failure the message is the
/// `[drift]` table to put in the manifest.
#[test]
fn manifest_tolerances_are_the_measured_round_off_times_the_margin() {
    use signorini::study::drift::{DriftReport, measured_tolerances, tolerances_toml};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("results/roundoff");
    let mut files: Vec<PathBuf> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "json")).collect();
    files.sort();
    assert!(files.len() >= 3, "expected a report per variant (orderings forced, one thread) in {}", dir.display());
    let reports: Vec<DriftReport> = files.iter().map(|f| serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap()).collect();
    let measured = measured_tolerances(&reports);
    let mut wrong = Vec::new();
    for (m, _) in declared() {
        let want = measured.get(&m.study).unwrap_or_else(|| panic!("{}: not in the round-off measurement: run `make roundoff`", m.study));
        let declared: std::collections::BTreeMap<String, _> = want.keys().map(|f| (f.clone(), m.drift.tolerance(f))).collect();
        if &declared != want {
            wrong.push(format!("{}: the [drift] table should read\n{}", m.file.display(), tolerances_toml(want)));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // the fields compared by order of magnitude moved less than that under every variant
    for (file, r) in files.iter().zip(&reports) {
        for (study, fields) in &r.changes {
            for f in ORDER_OF_MAGNITUDE {
                if let Some(c) = fields.get(*f) {
                    assert!(c.max_decades <= DECADES, "{}: {study} {f} moved {:.2} decades", file.display(), c.max_decades);
                }
            }
        }
    }
}

/// `drift --merge` (`make roundoff STUDIES=...`): the measured studies' entries, rows and
/// changes replace theirs in the stored report, every other study's are kept as written, byte
/// for byte and in their order, and the merged file reads back as a report.
#[test]
fn a_round_off_report_merged_in_replaces_only_the_studies_it_measured() {
    use signorini::study::drift::DriftReport;
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("results/roundoff/nested-dissection-2-threads.json");
    let text = std::fs::read_to_string(file).unwrap();
    let (older, raw): (DriftReport, serde_json::Value) = (serde_json::from_str(&text).unwrap(), serde_json::from_str(&text).unwrap());
    let all = older.checked();
    assert!(all.len() >= 10 && all.iter().any(|s| s == "hertz"), "{all:?}");
    // a fresh measurement of hertz alone, every change of it doubled
    let mut fresh = older.clone();
    fresh.studies.retain(|s| s["study"] == "hertz");
    fresh.rows.retain(|r| r.study == "hertz");
    fresh.changes.retain(|s, _| s == "hertz");
    for c in fresh.changes.get_mut("hertz").unwrap().values_mut() {
        c.max_rel = 2.0 * c.max_rel + 1e-30;
    }
    fresh.date = "later".into();
    let merged = fresh.merged_into(raw.clone()).unwrap();
    let entries = |v: &serde_json::Value| v["studies"].as_array().unwrap().clone();
    let names: Vec<String> = entries(&merged).iter().map(|s| s["study"].as_str().unwrap().to_string()).collect();
    assert_eq!(names, all, "every study once, in the stored order");
    assert_eq!(merged["date"], raw["date"], "the top-level fields stay the stored report's");
    for (i, s) in all.iter().enumerate() {
        if s == "hertz" {
            assert_eq!(merged["changes"][s], serde_json::to_value(&fresh.changes[s]).unwrap());
            assert_eq!(entries(&merged)[i]["date"], "later", "a merged study's entry carries its date");
        } else {
            assert_eq!(merged["changes"][s].to_string(), raw["changes"][s].to_string(), "{s}: kept as written");
            assert_eq!(entries(&merged)[i].to_string(), entries(&raw)[i].to_string(), "{s}: its entry kept as written");
        }
    }
    let rows = |v: &serde_json::Value, hertz: bool| {
        v["rows"].as_array().unwrap().iter().filter(|r| (r["study"] == "hertz") == hertz).cloned().collect::<Vec<_>>()
    };
    assert_eq!(rows(&merged, false), rows(&raw, false), "the other studies' rows kept");
    assert_eq!(rows(&merged, true).len(), fresh.rows.len());
    serde_json::from_value::<DriftReport>(merged).unwrap();
}

/// roundoff_floor passes a factor 5 (another ordering moves it by up to 79%) and is drift at a
/// factor 20, on every level, floors of the tiny first meshes included.
#[test]
fn roundoff_floor_is_compared_by_its_order_of_magnitude() {
    let (stored, quick, _) = stored_and_quick();
    let m = manifest();
    let n = quick[0].levels.len();
    let scale = stored[0].levels.iter().map(|l| l.roundoff_floor).fold(0.0f64, f64::max);
    assert!(scale > 0.0);
    for level in 0..n {
        let mut s = stored.clone();
        s[0].levels[level].roundoff_floor *= 5.0;
        assert_eq!(compare_study(&m, &s, quick, true), vec![], "level {level}: a factor 5 is within an order of magnitude");
        s[0].levels[level].roundoff_floor *= 4.0;
        let rows = compare_study(&m, &s, quick, true);
        let caught = rows.iter().any(|r| r.level == Some(level) && r.field == "roundoff_floor");
        // a floor that stays below 1e-3 of the run's largest after the change is not compared
        let visible = stored[0].levels[level].roundoff_floor * 20.0 > 1e-3 * scale;
        assert_eq!(caught, visible, "level {level}: factor 20 ({rows:?})");
    }
}

/// The text of the Drift section of a study page.
fn drift_section(page: &std::path::Path) -> String {
    let html = std::fs::read_to_string(page).unwrap();
    let start = html.find("<h2>Drift</h2>").unwrap_or_else(|| panic!("{html}"));
    html[start..].split("<h2>Claims").next().unwrap().to_string()
}

#[test]
fn the_page_quotes_a_drift_report_only_for_the_records_it_compared() {
    let dir = scratch("drift-page-quotes-drift");
    stored_study(&dir, "exp/st.toml", TWO_SHORT_RUNS, "x");
    // a copy of the folder compared with it (the folder with itself is no check)
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
    std::fs::write(dir.join("exp/st.toml"), TWO_SHORT_RUNS.replace("theta = 0.3", "theta = 0.3\nlevels = 4")).unwrap();
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
fn drift_advises_drift_when_interrupted_or_refused_by_a_lock() {
    let dir = scratch("drift-drift-advice");
    stored_study(&dir, "exp/long.toml", LONG, "res");
    // M4: a run of the study holds its lock (here: this test, through the library)
    let store = signorini::store::Store::new(&dir.join("res"), "long");
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

#[test]
fn drift_against_the_stored_folder_itself_says_so_and_the_page_does_not_quote_it() {
    let dir = scratch("drift-self");
    stored_study(
        &dir,
        "exp/st.toml",
        "description = \"two levels of Example 7.2\"\n[defaults]\nproblem = \"ex72\"\nmesh = \"structured:4\"\n[[run]]\nid = \"a\"\nlevels = 2\n",
        "x",
    );
    std::os::unix::fs::symlink(dir.join("x"), dir.join("link")).unwrap();
    for against in ["x", "./x/", "link"] {
        let (code, out, err) = signorini_in(&dir, &["drift", "--experiments", "exp", "--against", against, "--results", "x"]);
        assert_eq!(code, 0, "{against}: {out}{err}");
        assert!(out.contains("is the stored results folder itself") && out.contains("nothing was rerun"), "{against}: {out}");
    }
    let (code, _, err) = signorini_in(&dir, &["report", "--experiments", "exp", "--results", "x"]);
    assert_eq!(code, 0, "{err}");
    let page = std::fs::read_to_string(dir.join("x/report/st.html")).unwrap();
    assert!(page.contains("compared this folder with itself") && !page.contains("<b>no drift</b>"), "{page}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A cut drift report makes `report` fail with more than the parser's words: the refusal says
/// how it came about and what to do.
#[test]
fn a_cut_drift_report_is_refused_with_what_to_do() {
    let dir = scratch("drift-cut-report");
    let repo = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::write(dir.join("cut.json"), "{\"studies\": [").unwrap();
    // from the repository (its records name their problem files relative to it)
    let (cut, page) = (dir.join("cut.json"), dir.join("page"));
    let args = ["report", "--study", "ex71", "--drift-report", cut.to_str().unwrap(), "--out", page.to_str().unwrap()];
    let (code, out, err) = signorini_in(repo, &args);
    assert_ne!(code, 0, "{out}{err}");
    assert!(err.contains("cut.json") && err.contains("run `signorini drift` to write it again"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

const ADAPTIVE_STUDY: &str = "description = \"three adaptive levels\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\n[[run]]\nid = \"a\"\nrefine = \"adaptive\"\nlevels = 3\n";

/// The Drift paragraph of a study page.
fn drift_paragraph(page: &Path) -> String {
    let page = std::fs::read_to_string(page).unwrap();
    let at = page.find("<h2>Drift</h2>").expect("a Drift section");
    page[at..].split("</p>").next().unwrap().to_string()
}

#[test]
fn drift_against_a_copy_of_the_stored_folder_is_no_rerun() {
    let dir = scratch("drift-copy");
    stored_study(&dir, "exp/st.toml", ADAPTIVE_STUDY, "res");
    let status = std::process::Command::new("cp").args(["-r", "res", "cp1"]).current_dir(&dir).status().unwrap();
    assert!(status.success());
    let (code, out, err) = signorini_in(&dir, &["drift", "--experiments", "exp", "--against", "cp1", "--results", "res"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(err.contains("the records of st in cp1 are byte-identical to the stored ones, timings (t_*) included"), "{err}");
    assert!(err.contains("cp1 is a copy of the stored folder, not a rerun"), "{err}");
    let (code, _, err) =
        signorini_in(&dir, &["report", "--experiments", "exp", "--results", "res", "--drift-report", "cp1/drift-report.json"]);
    assert_eq!(code, 0, "{err}");
    let said = drift_paragraph(&dir.join("res/report/st.html"));
    assert!(said.contains("not checked") && said.contains("a copy of this folder, not a rerun"), "{said}");
    assert!(!said.contains("no drift") && !said.contains("rerun and compared"), "{said}");
    // a real rerun into another folder differs in its timings: compared, and quoted as such
    let (code, _, err) = signorini_in(&dir, &["run", "exp/st.toml", "--results", "again"]);
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = signorini_in(&dir, &["drift", "--experiments", "exp", "--against", "again", "--results", "res"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(!err.contains("byte-identical"), "{err}");
    let (code, _, err) =
        signorini_in(&dir, &["report", "--experiments", "exp", "--results", "res", "--drift-report", "again/drift-report.json"]);
    assert_eq!(code, 0, "{err}");
    let said = drift_paragraph(&dir.join("res/report/st.html"));
    assert!(said.contains("<b>no drift</b>: rerun and compared"), "{said}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_pages_drift_advice_makes_the_next_page_checked() {
    let dir = scratch("drift-advice");
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    std::fs::write(dir.join("experiments/rf.toml"), ADAPTIVE_STUDY).unwrap();
    // the tracked results/ and a scratch folder: each page's advice, run as given, checks it
    for (results, page) in [(None, "target/report/rf.html"), (Some("res"), "res/report/rf.html")] {
        let mut run = vec!["run", "experiments/rf.toml"];
        let mut report = vec!["report", "--study", "rf"];
        if let Some(r) = results {
            run.extend(["--results", r]);
            report.extend(["--results", r]);
        }
        let (code, _, err) = signorini_in(&dir, &run);
        assert_eq!(code, 0, "{err}");
        let (code, _, err) = signorini_in(&dir, &report);
        assert_eq!(code, 0, "{err}");
        let said = drift_paragraph(&dir.join(page));
        let advice = said.split("<code>").nth(1).and_then(|a| a.split("</code>").next()).unwrap_or_else(|| panic!("no advice: {said}"));
        let expected = match results {
            None => "signorini drift --study rf".to_string(),
            Some(r) => format!("signorini drift --study rf --results {r}"),
        };
        assert_eq!(advice, expected, "{said}");
        let args: Vec<&str> = advice.split(' ').skip(1).collect();
        let (code, out, err) = signorini_in(&dir, &args);
        assert_eq!(code, 0, "{advice}: {out}{err}");
        let (code, _, err) = signorini_in(&dir, &report);
        assert_eq!(code, 0, "{err}");
        let said = drift_paragraph(&dir.join(page));
        assert!(said.contains("<b>no drift</b>: rerun and compared at every level"), "after `{advice}`: {said}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

const REF: &str = "description = \"tiny ex72 with a reference\"\n[defaults]\nproblem = \"ex72\"\nmesh = \"structured:4\"\ntheta = 0.5\nlevels = 8\nmax_ndof = 20000\n[defaults.reference]\ntheta = 0.5\nmin_ndof = 30000\ncontact_term = \"without_full_contact\"\n[[run]]\nid = \"adaptive\"\nrole = \"as-written\"\n";

#[test]
fn drift_against_a_copy_whose_reference_record_was_edited_names_the_field() {
    let dir = scratch("drift-ref");
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    std::fs::write(dir.join("experiments/ref.toml"), REF).unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/ref.toml", "--results", "res"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(std::process::Command::new("cp").args(["-r", "res", "alt"]).current_dir(&dir).status().unwrap().success());
    let against = ["drift", "--against", "alt", "--results", "res", "--experiments", "experiments", "--study", "ref"];
    let (code, out, err) = signorini_in(&dir, &against);
    assert_eq!(code, 0, "an unchanged copy: {out}{err}");
    let file = std::fs::read_dir(dir.join("alt/ref/references")).unwrap().next().unwrap().unwrap().path();
    let mut reference: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    reference["last"]["eta_h"] = serde_json::json!(1.5);
    std::fs::write(&file, serde_json::to_string_pretty(&reference).unwrap()).unwrap();
    let (code, out, err) = signorini_in(&dir, &against);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.contains("last.eta_h") && out.contains("reference "), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

const SCRATCH_STUDY: &str =
    "description = \"scratch\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\ntheta = 0.5\n[[run]]\nid = \"a\"\nlevels = 2\n";

#[test]
fn a_named_drift_report_that_does_not_exist_is_an_error_and_the_page_says_what_provenance_checks() {
    let dir = scratch("drift-report");
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    std::fs::write(dir.join("experiments/mine.toml"), SCRATCH_STUDY).unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/mine.toml", "--results", "res"]);
    assert_eq!(code, 0, "{out}{err}");
    let report = ["report", "--results", "res", "--experiments", "experiments", "--drift-report", "res/drift-reprot.json"];
    let (code, out, err) = signorini_in(&dir, &report);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("res/drift-reprot.json") && err.contains("does not exist"), "{err}");
    // without the flag, a missing default report is "not checked", and the page is written
    let (code, out, err) = signorini_in(&dir, &["report", "--results", "res", "--experiments", "experiments"]);
    assert_eq!(code, 0, "{out}{err}");
    let page = std::fs::read_to_string(dir.join("res/report/mine.html")).unwrap();
    assert!(page.contains("nothing checks them"), "{page}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn drift_against_a_folder_from_where_there_is_no_stored_results_folder_is_named() {
    let dir = std::env::temp_dir().join(format!("signorini-drift-noresults-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::create_dir_all(dir.join("empty")).unwrap();
    let text =
        "description = \"t\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:2\"\nlevels = 2\nquick_levels = 1\n[[run]]\nid = \"a\"\n";
    std::fs::write(dir.join("exp/s.toml"), text).unwrap();
    let (code, out) = output_in(&dir, &["run", "exp/s.toml", "--results", "s7"]);
    assert_eq!(code, 0, "{out}");
    // from a folder without ./results: an error naming it, not a drift with advice to rerun
    let empty = dir.join("empty");
    let (code, out) = output_in(&empty, &["drift", "--against", "../s7", "--experiments", "../exp"]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains("no stored results folder `results` (relative to the current folder): it does not exist; pass --results DIR"),
        "{out}"
    );
    assert!(!out.contains("field(s)") && !out.contains("rerun the study"), "{out}");
    // a file where the folder should be, and without --against (nothing is rerun first)
    std::fs::write(empty.join("results"), "").unwrap();
    let (code, out) = output_in(&empty, &["drift", "--quick", "--experiments", "../exp"]);
    assert!(code == 1 && out.contains("no stored results folder `results`") && out.contains("is not a folder"), "{out}");
    assert!(!empty.join("target").exists(), "drift reran a study before refusing");
    // named with --results, the same comparison is no drift
    let (code, out) = output_in(&empty, &["drift", "--against", "../s7", "--experiments", "../exp", "--results", "../s7"]);
    assert_eq!(code, 0, "{out}");
    std::fs::remove_dir_all(&dir).ok();
}
