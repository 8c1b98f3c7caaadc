//! Battery 12:
//! * F2: the gap bound (a gap below minus the body's extent along the contact normal is refused)
//!   took the extent of the whole mesh, so a second, unrelated body meshed 5 above a plate 0.1
//!   thick let the plate be pushed 5 thicknesses through its clamped top, certified. The extent
//!   is now the edge-connected body's that holds the point (`contact::plausible::Extent`, over
//!   the bodies `certify::check_held` splits the mesh into).
//! * F6: `RAYON_NUM_THREADS=2000` under an address-space limit panicked (exit 101) in the first
//!   parallel call, as rayon's lazily built pool failed to start; 20000 threads without a limit
//!   made a tiny solve take minutes. The pool is now built at startup: above 8 times the cores
//!   is refused, and threads that cannot start are an error naming where the count came from.
//! * F4: `drift --against` a `cp -r` copy of the stored folder said "no drift" and the page
//!   "rerun and compared". Records byte-identical to the stored ones, timings included, are a
//!   copy (`study::drift::compared_a_copy`): drift says so and the page says "not checked".
//! * F5: the page advised `signorini drift --study S`, which writes `target/drift/report-S.json`,
//!   a file `report` never read, so the page said "not checked" forever (and without the
//!   `--results` the page was made with). `report` now reads every report drift writes there,
//!   and the advice carries `--results`: after it, the page says "checked".
//! * Minor notes: `solve --json` now carries `roundoff_floor`; `run --plan M.toml M.toml` lists
//!   each run once; `adapt`'s efficiency column prints values far from 1 in exponent form.

use super::common::msh::{grid, msh};
use super::common::{scratch, signorini_in, stored_study};
use std::path::Path;

const PLATE: &str = "dirichlet = [0, 0]\n[material]\nE = 1000\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = [\"contact\"]\ndirichlet = [\"top\"]\nneumann = [\"free\"]\n[contact]\nnormal = [0, -1]\nchi = \"CHI\"\n";

#[test]
fn a_second_body_does_not_widen_the_gap_bound_of_a_thin_plate() {
    let dir = scratch("b12-gap");
    let plate = |side: &str| match side {
        "bottom" => "contact",
        "top" => "top",
        _ => "free",
    };
    let held = |side: &str| if side == "top" { "top" } else { "free" };
    let two = msh(&[(grid(40, 2, [0.0, 0.0], [10.0, 0.1]), &plate), (grid(4, 4, [0.0, 5.0], [1.0, 1.0]), &held)]);
    std::fs::write(dir.join("two.msh"), two).unwrap();
    // chi = -0.5 pushes the plate (0.1 thick) 5 thicknesses through its clamped top; the square
    // 5 above it made the whole mesh 6 high along n, and the solve was certified
    std::fs::write(dir.join("thin.toml"), PLATE.replace("CHI", "-0.5")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "thin.toml", "--mesh", "gmsh:two.msh"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("is -0.5") && err.contains("inside the body, 0.1)"), "{err}");
    // each body in contact, each within its own thickness (the plate 0.05 of its 0.1, the
    // square 0.5 of its 1, more than the plate's extent): solved
    let both = |side: &str| match side {
        "bottom" => "contact",
        "top" => "top",
        _ => "free",
    };
    let pair = msh(&[(grid(40, 2, [0.0, 0.0], [10.0, 0.1]), &plate), (grid(4, 4, [0.0, 5.0], [1.0, 1.0]), &both)]);
    std::fs::write(dir.join("pair.msh"), pair).unwrap();
    std::fs::write(dir.join("each.toml"), PLATE.replace("CHI", "-0.05 - 0.45*min(1, max(0, y - 1))")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "each.toml", "--mesh", "gmsh:pair.msh", "--probe", "0.5,5"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("certified"), "{out}");
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
    let dir = scratch("b12-threads");
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

const STUDY: &str = "description = \"battery 12\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\n[[run]]\nid = \"a\"\nrefine = \"adaptive\"\nlevels = 3\n";

/// The Drift paragraph of a study page.
fn drift_paragraph(page: &Path) -> String {
    let page = std::fs::read_to_string(page).unwrap();
    let at = page.find("<h2>Drift</h2>").expect("a Drift section");
    page[at..].split("</p>").next().unwrap().to_string()
}

#[test]
fn drift_against_a_copy_of_the_stored_folder_is_no_rerun() {
    let dir = scratch("b12-copy");
    stored_study(&dir, "exp/st.toml", STUDY, "res");
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
    let dir = scratch("b12-advice");
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    std::fs::write(dir.join("experiments/rf.toml"), STUDY).unwrap();
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

/// Minor notes: `solve --json` carries u_h's round-off floor (the level records did, the JSON
/// did not); `run --plan M.toml M.toml` listed every run twice, though the run stores each once.
#[test]
fn solve_json_carries_the_roundoff_floor_and_a_plan_lists_each_run_once() {
    let dir = scratch("b12-minor");
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "ex72", "--mesh", "structured:4", "--json"]);
    assert_eq!(code, 0, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let floor = json["roundoff_floor"].as_f64().unwrap_or_else(|| panic!("no roundoff_floor: {out}"));
    assert!(floor > 0.0 && floor < 1e-10, "{floor}");
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/st.toml"), STUDY.replace("levels = 3\n", "levels = 3\n[[run]]\nid = \"b\"\nlevels = 2\n")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["run", "exp/st.toml", "exp/st.toml", "--plan"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "st/a\nst/b\n");
    std::fs::remove_dir_all(&dir).ok();
}
