//! The measured numbers live in one place, `docs/measured.json` (rendered into
//! `docs/measured.md` by `scripts/measured.py`, rewritten by `make measured`). README.md and the
//! workflow quote some of them: every quote must agree with the file, every memory figure and
//! every dated commit they state must be one the file (or `results/`) gives, and the figures they
//! take from `results/` (a stored level's unknowns and recorded peak) must be what `results/` holds.
//! A stale hand copy fails here, naming the file and what it should say.

use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

fn measured() -> Value {
    serde_json::from_str(&read("docs/measured.json")).expect("docs/measured.json parses")
}

fn int(v: &Value, path: &str) -> u64 {
    path.split('.').fold(v, |v, k| &v[k]).as_u64().unwrap_or_else(|| panic!("docs/measured.json: {path} is not a whole number"))
}

fn text<'a>(v: &'a Value, path: &str) -> &'a str {
    path.split('.').fold(v, |v, k| &v[k]).as_str().unwrap_or_else(|| panic!("docs/measured.json: {path} is not a string"))
}

/// 6744992 -> "6,744,992"
fn commas(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

fn kib(n: u64) -> String {
    format!("{} KiB", commas(n))
}

/// KiB as /usr/bin/time reports them: GiB = KiB / 2^20.
fn gib(kib: u64) -> String {
    format!("{:.2} GiB", kib as f64 / 1048576.0)
}

/// GB = 1e9 bytes.
fn gb(bytes: u64) -> String {
    format!("{:.2} GB", bytes as f64 / 1e9)
}

fn mmss(s: u64) -> String {
    format!("{}:{:02}", s / 60, s % 60)
}

/// 12088138 -> "1.21e7"
fn sci(n: u64) -> String {
    format!("{:.2e}", n as f64)
}

/// A file's prose with line breaks, and the `#` of YAML comments, folded into single spaces, so a
/// quote may wrap anywhere.
fn prose(rel: &str) -> String {
    let raw = read(rel);
    let lines = raw.lines().map(|l| {
        let l = l.trim();
        if rel.ends_with(".yml") { l.strip_prefix('#').unwrap_or(l).trim() } else { l }
    });
    lines.collect::<Vec<_>>().join(" ").split_whitespace().collect::<Vec<_>>().join(" ")
}

fn require(rel: &str, body: &str, fragments: &[String]) {
    let missing: Vec<&String> = fragments.iter().filter(|f| !body.contains(f.as_str())).collect();
    assert!(
        missing.is_empty(),
        "{rel} does not say what docs/measured.json or results/ give (a stale or missing copy); it should contain:\n{}",
        missing.iter().map(|f| format!("  {f}")).collect::<Vec<_>>().join("\n")
    );
}

/// One level of a stored study: run, level, unknowns, recorded peak in MiB.
struct Level {
    run: String,
    level: u64,
    ndof: u64,
    mem_mib: f64,
}

fn levels(study: &str) -> Vec<Level> {
    let csv = read(&format!("results/{study}/levels.csv"));
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("levels.csv of {study}: no column {name}"));
    let (run, level, ndof, mem) = (col("run"), col("level"), col("ndof"), col("mem_peak_mib"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            Level {
                run: f[run].to_string(),
                level: f[level].parse().unwrap(),
                ndof: f[ndof].parse().unwrap(),
                mem_mib: f[mem].parse().unwrap(),
            }
        })
        .collect()
}

/// What README.md and the workflow take from results/: the deep study's largest level, its level
/// with the largest recorded peak, and the levels past the replayed one of its replay run.
struct Deep {
    max_ndof: u64,
    peak: (String, u64, u64, u64),
    replay_run: String,
    beyond: (u64, u64),
}

fn deep() -> Deep {
    let rows = levels("deep");
    let max_ndof = rows.iter().map(|r| r.ndof).max().unwrap();
    let p = rows.iter().max_by(|a, b| a.mem_mib.total_cmp(&b.mem_mib)).unwrap();
    let manifest: toml::Value = toml::from_str(&read("experiments/deep.toml")).unwrap();
    let tiers = &manifest["drift"]["deep"];
    let replay_run = tiers["replay"][0].as_str().unwrap().to_string();
    let limit = tiers["replay_max_ndof"].as_integer().unwrap() as u64;
    let run: Vec<&Level> = rows.iter().filter(|r| r.run == replay_run).collect();
    let replayed = run.iter().filter(|r| r.ndof <= limit).map(|r| r.level).max().unwrap();
    let last = run.iter().map(|r| r.level).max().unwrap();
    Deep { max_ndof, peak: (p.run.clone(), p.level, p.ndof, p.mem_mib.round() as u64), replay_run, beyond: (replayed + 1, last) }
}

#[test]
fn measured_md_is_the_rendering_of_measured_json_and_its_sums_add_up() {
    let out = Command::new("python3")
        .arg("scripts/measured.py")
        .args(["render", "--check"])
        .current_dir(root())
        .output()
        .expect("python3 runs (a prerequisite of make test)");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let m = measured();
    let t = &m["make_test"];
    let steps = t["steps_s"].as_object().unwrap();
    // the steps before the checks: the formatting check, then the compiling and installing side
    // by side (`beside`: the longest of them counts); or, in runs before, the compiling and
    // installing one after another (then a `check` step among them) and the checks from fmt on
    let beside: Vec<&str> = t["beside"].as_array().map(|b| b.iter().map(|s| s.as_str().unwrap()).collect()).unwrap_or_default();
    let secs = |k: &str| steps[k].as_u64().unwrap();
    let (compile_steps, compiling, n_compiling): (Vec<&str>, u64, u64) = if beside.is_empty() {
        let c: Vec<&str> = ["build-tests", "check", "venv"].into_iter().filter(|k| steps.contains_key(*k)).collect();
        let sum = c.iter().map(|k| secs(k)).sum();
        let n = c.len() as u64;
        (c, sum, n)
    } else {
        let longest = beside.iter().map(|k| secs(k)).max().unwrap();
        ([vec!["fmt"], beside.clone()].concat(), secs("fmt") + longest, 2)
    };
    let checks: u64 = steps.iter().filter(|(k, _)| !compile_steps.contains(&k.as_str())).map(|(_, v)| v.as_u64().unwrap()).sum();
    // each step's seconds are a difference of whole-second timestamps (within 1 s of its
    // duration), and a total also holds the commands between steps (git status, the scratch
    // folder: a second or two): a total is its steps' sum within one second a step, plus those
    let near = |total: u64, sum: u64, n: u64| total + n >= sum && total <= sum + n + 3;
    let n_checks = (steps.len() - compile_steps.len()) as u64;
    assert!(
        near(int(t, "compiling_s"), compiling, n_compiling),
        "compiling_s {} is the sum of {compile_steps:?}, the steps side by side counted by the longest ({compiling})",
        int(t, "compiling_s")
    );
    assert!(near(int(t, "checks_s"), checks, n_checks), "checks_s {} is the sum of the other steps ({checks})", int(t, "checks_s"));
    assert_eq!(int(t, "after_build_s"), int(t, "compiling_s") + int(t, "checks_s"));
}

#[test]
fn readme_and_workflow_quote_measured_json_as_it_is() {
    let m = measured();
    let t = &m["make_test"];
    let d = &m["make_drift"];
    let k = &m["disk"];
    let f = &m["make_figures"];
    let step = |name: &str| int(t, &format!("steps_s.{name}"));
    let (tk, dk) = (int(t, "peak_kib"), int(d, "peak_kib"));
    let (target, venv) = (int(k, "target_bytes"), int(k, "venv_bytes"));
    let readme = vec![
        format!(
            "peaked at {} by `/usr/bin/time` ({}, {}; `{}` on a fresh clone of commit {}, {})",
            kib(tk),
            gib(tk),
            gb(tk * 1024),
            text(t, "command"),
            text(t, "commit"),
            text(t, "date")
        ),
        format!("`make drift` peaked at {} ({}, {}; {}, commit {},", kib(dk), gib(dk), gb(dk * 1024), text(d, "date"), text(d, "commit")),
        format!(
            "`make test` on a fresh clone ({}, commit {}, run by `{}`, the machine {}) took {} s after `make build`",
            text(t, "date"),
            text(t, "commit"),
            text(t, "command"),
            text(t, "load"),
            int(t, "after_build_s")
        ),
        if t["beside"].as_array().is_some_and(|b| !b.is_empty()) {
            format!(
                "{} s for the formatting check ({} s), then compiling and installing side by side (the test binaries and the example {} s, clippy with the check build of its dependencies {} s, the cross-check's Python environment {} s), then {} s of checks: the tests {} s ({} integration tests, {} unit tests, {} doc tests), the drift check {} s",
                int(t, "compiling_s"),
                step("fmt"),
                step("build-tests"),
                step("clippy"),
                step("venv"),
                int(t, "checks_s"),
                step("cargo-test"),
                int(t, "tests.integration"),
                int(t, "tests.unit"),
                int(t, "tests.doc"),
                step("drift")
            )
        } else if t["steps_s"].get("check").is_some() {
            // a run that checked clippy's dependencies in a step of their own
            format!(
                "{} s compiling and installing (the test binaries and the example {} s, `cargo check` of the dependencies clippy shares {} s, the cross-check's Python environment {} s), then {} s of checks: fmt and clippy {} s, the tests {} s ({} integration tests, {} unit tests, {} doc tests), the drift check {} s",
                int(t, "compiling_s"),
                step("build-tests"),
                step("check"),
                step("venv"),
                int(t, "checks_s"),
                step("fmt") + step("clippy"),
                step("cargo-test"),
                int(t, "tests.integration"),
                int(t, "tests.unit"),
                int(t, "tests.doc"),
                step("drift")
            )
        } else {
            format!(
                "{} s compiling and installing (the test binaries and the example {} s, the cross-check's Python environment {} s), then {} s of checks: fmt {} s, clippy with the check build of its dependencies {} s, the tests {} s ({} integration tests, {} unit tests, {} doc tests), the drift check {} s",
                int(t, "compiling_s"),
                step("build-tests"),
                step("venv"),
                int(t, "checks_s"),
                step("fmt"),
                step("clippy"),
                step("cargo-test"),
                int(t, "tests.integration"),
                int(t, "tests.unit"),
                int(t, "tests.doc"),
                step("drift")
            )
        },
        format!("the study pages {} s and the NGSolve cross-check (solutions and estimator) {} s", step("report"), step("crosscheck")),
        format!("about {:.1} GB of disk** (`target/` {}, `crosscheck/.venv` {}", (target + venv) as f64 / 1e9, gb(target), gb(venv)),
        format!("({} when last measured", mmss(int(d, "wall_s"))),
        format!(
            "`make figures` took {} from `git clone` to the last figure ({}, commit {}, the machine {}), {} s of it compiling",
            mmss(int(f, "wall_s")),
            text(f, "date"),
            text(f, "commit"),
            text(f, "load"),
            int(f, "build_s")
        ),
    ];
    require("README.md", &prose("README.md"), &readme);
    let workflow = vec![
        format!(
            "({}, commit {}, {}): {} s after make build, its largest process peaking at {} = {} = {}",
            text(t, "date"),
            text(t, "commit"),
            text(t, "load"),
            int(t, "after_build_s"),
            kib(tk),
            gib(tk),
            gb(tk * 1024)
        ),
        format!("make drift peaked at {} = {} = {}", kib(dk), gib(dk), gb(dk * 1024)),
    ];
    require(".github/workflows/ci.yml", &prose(".github/workflows/ci.yml"), &workflow);
}

#[test]
fn readme_and_workflow_take_the_deep_study_figures_from_results() {
    let deep = deep();
    let (run, level, ndof, mib) = &deep.peak;
    require(
        "README.md",
        &prose("README.md"),
        &[format!("the deep study's largest level alone records {} MiB, {run}'s level {level}, {} unknowns", commas(*mib), sci(*ndof))],
    );
    require(
        ".github/workflows/ci.yml",
        &prose(".github/workflows/ci.yml"),
        &[
            format!("{} levels {} to {}, to {} unknowns", deep.replay_run, deep.beyond.0, deep.beyond.1, sci(deep.max_ndof)),
            format!("largest recorded peak is {} MiB at {run}'s level {level}, {} unknowns", commas(*mib), sci(*ndof)),
            format!("the deep study's to {} unknowns", sci(deep.max_ndof)),
        ],
    );
}

/// Every "N KiB/MiB/GiB/GB" in the file, N as written.
fn memory_figures(body: &str) -> Vec<String> {
    let mut out = Vec::new();
    for unit in [" KiB", " MiB", " GiB", " GB"] {
        for (at, _) in body.match_indices(unit) {
            let end = body[at + unit.len()..].chars().next();
            if end.is_some_and(|c| c.is_alphanumeric()) {
                continue;
            }
            let start = body[..at].rfind(|c: char| !(c.is_ascii_digit() || c == ',' || c == '.')).map_or(0, |i| i + 1);
            let n = body[start..at].trim_end_matches(['.', ',']);
            if !n.is_empty() {
                out.push(format!("{n}{unit}"));
            }
        }
    }
    out
}

#[test]
fn every_memory_figure_and_dated_commit_in_readme_and_workflow_comes_from_a_measurement() {
    let m = measured();
    let mut known: Vec<String> = Vec::new();
    for section in ["make_test", "make_drift", "make_figures"] {
        let p = int(&m[section], "peak_kib");
        known.extend([kib(p), gib(p), gb(p * 1024)]);
    }
    let (target, venv) = (int(&m["disk"], "target_bytes"), int(&m["disk"], "venv_bytes"));
    known.extend([gb(target), gb(venv), format!("{:.1} GB", (target + venv) as f64 / 1e9)]);
    known.push(format!("{} MiB", commas(deep().peak.3)));
    // not measured here: GitHub's runner sizes (its documentation) and the memory of the machine
    // docs/performance.md names
    known.extend(["16 GB", "7 GB", "32 GB", "24 GiB"].map(String::from));
    let commits: Vec<&str> = ["make_test", "make_drift", "make_figures", "disk"].iter().map(|s| text(&m[*s], "commit")).collect();
    for rel in ["README.md", ".github/workflows/ci.yml"] {
        let body = prose(rel);
        let stray: Vec<String> = memory_figures(&body).into_iter().filter(|f| !known.contains(f)).collect();
        assert!(
            stray.is_empty(),
            "{rel} states memory or disk figures that docs/measured.json and results/ do not give (stale copies?): {stray:?}; known: {known:?}"
        );
        for (at, _) in body.match_indices("commit ") {
            let hash: String = body[at + 7..].chars().take_while(|c| c.is_ascii_hexdigit()).collect();
            if hash.len() >= 7 {
                assert!(
                    commits.contains(&hash.as_str()),
                    "{rel} quotes a measurement at commit {hash}, which docs/measured.json does not hold (measured at {commits:?})"
                );
            }
        }
    }
}

#[test]
fn test_summary_sums_cargo_output_and_counts_filtered_and_ignored_as_skipped() {
    let dir = std::env::temp_dir().join(format!("signorini-measured-summary-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log = dir.join("cargo.log");
    std::fs::write(
        &log,
        "     Running unittests src/lib.rs (target/release/deps/signorini-1)\n\nrunning 2 tests\ntest result: ok. 2 passed; 0 failed; 1 ignored; 0 measured; 0 filtered out; finished in 0.01s\n\n\
         \x20    Running tests/it/main.rs (target/release/deps/it-2)\n\nrunning 5 tests\ntest result: FAILED. 4 passed; 1 failed; 0 ignored; 0 measured; 1 filtered out; finished in 1.00s\n\n\
         \x20    Running tests/ordering_forced.rs (target/release/deps/ordering_forced-3)\nthread 'main' panicked\n\
         \x20  Doc-tests signorini_numerics\n\nrunning 3 tests\ntest result: ok. 3 passed; 0 failed; 0 ignored; 0 measured; 0 filtered out; finished in 0.50s\n",
    )
    .unwrap();
    let counts = dir.join("counts");
    let out = Command::new("sh").arg(root().join("scripts/test-summary.sh")).arg(&log).arg(&counts).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // the binary that died before its "test result:" line counts as one failure
    assert_eq!(String::from_utf8_lossy(&out.stdout), "9 passed, 2 failed, 2 skipped\n");
    assert_eq!(std::fs::read_to_string(&counts).unwrap(), "passed 9\nfailed 2\nskipped 2\nunit 2\nintegration 6\ndoc 3\n");
    std::fs::remove_dir_all(&dir).ok();
}
