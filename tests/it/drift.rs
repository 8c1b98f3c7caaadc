//! The drift check reports what moved, with the right row, and passes an unperturbed copy.

use signorini::records::{RunRecord, StudyDir};
use signorini::study::drift::{DECADES, ORDER_OF_MAGNITUDE, compare_study, observed_rate};
use signorini::study::manifest::Manifest;
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
    signorini::study::manifest::declared(&root.join("experiments"), &[])
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
    let floats: Vec<_> = signorini::adapt::float_fields().into_iter().filter(|f| !ORDER_OF_MAGNITUDE.contains(&f.as_str())).collect();
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
        let rows = signorini::study::drift::check_derived(&signorini::study::store::Store::new(&root, &m.study), &stored);
        assert!(rows.is_empty(), "{}: {rows:?}", m.study);
        signorini::study::check_complete(&m, &root).unwrap();
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
    let checked = signorini::study::store::Store::new(&res, "tiny").check().unwrap();
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
