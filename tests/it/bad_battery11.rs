//! Battery 11:
//! * N6: a nearly tangent declared normal (`["x - 0.5", "-1e-3"]`) was refused as a "corner ...
//!   0.0001 degrees apart": the per-node normal checks now run first, and a corner needs 1e-3
//!   radians between the two sides' normals (`contact::plausible::CORNER_ANGLE`).
//! * N2: the gap bound "chi below minus the body's size" was the bounding box's diagonal, so a
//!   thin body could be pushed through itself; it is now the body's extent along the contact
//!   normal at that point (`contact::plausible::Extent`).
//! * N3: a rigid translation of the data far beyond the deformation left u_h's round-off as large
//!   as the deformation, yet the solve was certified and an estimate printed; one decision
//!   (`adapt::resolution`) now makes `solve` warn where the estimate is at round-off and refuse
//!   (as every level of `adapt` does) where the round-off exceeds 1e-2 of the deformation above it.
//! * N1: `drift --against` the stored folder itself (the same path, `./DIR/`, a symlink) compared
//!   every record with itself and said "no drift", and the study page quoted it as a rerun; drift
//!   now says so, and the page says "not checked".
//! * N5: `drift --against W`, `report --results W` and `figures --results W` while `run --fresh`
//!   rewrote W reported both runs as drifted ("run present -> (missing)", with the advice to
//!   rerun W with --fresh), "W holds no study", or a missing run. Every reader now asks the
//!   folder's locks first (`study::store::Store::check`, shared and without waiting) and names
//!   the process that writes it. Given `--wait`, `figures` and `report` wait for it instead
//!   (the Slurm finish job of one array while a second array of the same study still held the
//!   folder was refused, and `make cluster-test` failed).

use super::common::{scratch, signorini_in, stored_study};

const TANGENT: &str = "dirichlet = [0, -0.01]\n[material]\nE = 100\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = \"y < 1e-12\"\ndirichlet = \"y > 1 - 1e-12\"\n[contact]\nnormal = [\"x - 0.5\", \"-1e-3\"]\nchi = 0\n";

#[test]
fn a_nearly_tangent_declared_normal_is_named_as_such_not_as_a_corner() {
    let dir = scratch("b11-tangent");
    std::fs::write(dir.join("t.toml"), TANGENT).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "t.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("nearly tangent to the boundary"), "{err}");
    assert!(!err.contains("corner"), "{err}");
    // a normal that turns fast but stays well away from the surface is no corner either
    let steep = TANGENT.replace("\"-1e-3\"", "\"-1\"").replace("\"x - 0.5\"", "\"1e-3*(x - 0.5)\"");
    std::fs::write(dir.join("s.toml"), steep).unwrap();
    let (code, _, err) = signorini_in(&dir, &["solve", "--problem", "s.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 0, "{err}");
}

const SQUARE_GAP: &str = "dirichlet = [0, 0]\n[material]\nE = 100\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = \"y < 1e-12\"\ndirichlet = \"y > 1 - 1e-12\"\n[contact]\nnormal = [0, -1]\nchi = CHI\n";

#[test]
fn a_gap_below_minus_the_bodys_extent_along_the_normal_is_refused() {
    let dir = scratch("b11-gap");
    // the unit square is 1 thick along (0, -1): -1.2 pushes its bottom through the clamped top
    // (the bounding box's diagonal, the former bound, is 1.414)
    std::fs::write(dir.join("deep.toml"), SQUARE_GAP.replace("CHI", "-1.2")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "deep.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 1, "{out}{err}");
    for part in ["is -1.2", "more than the body's thickness along the contact normal (0.000000, -1.000000)", "inside the body, 1)"] {
        assert!(err.contains(part), "{part}: {err}");
    }
    // half the thickness is a (large) displacement the body can take
    std::fs::write(dir.join("half.toml"), SQUARE_GAP.replace("CHI", "-0.5")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "half.toml", "--mesh", "structured:4"]);
    assert_eq!(code, 0, "{out}{err}");
}

fn translated(c: &str) -> String {
    format!(
        "dirichlet = [\"0.1 + {c}\", 0]\nrequired_vertices = [[1, 0.5]]\n[material]\nE = 500\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = \"x > 1 - 1e-12\"\ndirichlet = \"x < 1e-12\"\n[contact]\nnormal = \"outward\"\nchi = \"{c} + (-0.2 + 0.5*abs(y - 0.5))\"\n"
    )
}

#[test]
fn a_rigid_translation_that_drowns_the_deformation_in_round_off_is_not_silent() {
    let dir = scratch("b11-rigid");
    // from about 3e11 the estimate is at u_h's round-off (its contact set changes at 1e12, and
    // by 1e16 no node is active): `solve` says so, or refuses when the round-off is above 1e-2
    // of the deformation while the estimate is not; `adapt` never refines on it
    for c in ["1e12", "1e16"] {
        std::fs::write(dir.join("rt.toml"), translated(c)).unwrap();
        let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "rt.toml", "--mesh", "structured:8"]);
        let refused = code == 1 && err.contains("u_h does not resolve the deformation") && !out.contains("estimator:");
        let warned = code == 0 && err.contains("warning: the estimate is at the round-off of u_h");
        assert!(refused || warned, "{c}: {out}{err}");
        let (code, out, err) = signorini_in(&dir, &["adapt", "--problem", "rt.toml", "--mesh", "structured:8", "--levels", "2"]);
        assert!(
            code == 1 && err.contains("u_h does not resolve the deformation") || code == 0 && out.contains("# stopped"),
            "{c}: {out}{err}"
        );
    }
    // a translation whose contact forces keep 6 digits (docs/choices.md): no warning (1e9 is
    // warned since battery 12, F1: its forces' round-off is 3.6e-3 of the largest)
    std::fs::write(dir.join("rt.toml"), translated("1e4")).unwrap();
    let (code, out, err) = signorini_in(&dir, &["solve", "--problem", "rt.toml", "--mesh", "structured:8"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(!err.contains("warning"), "{err}");
}

#[test]
fn drift_against_the_stored_folder_itself_says_so_and_the_page_does_not_quote_it() {
    let dir = scratch("b11-self");
    stored_study(
        &dir,
        "exp/st.toml",
        "description = \"N1\"\n[defaults]\nproblem = \"ex72\"\nmesh = \"structured:4\"\n[[run]]\nid = \"a\"\nlevels = 2\n",
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

/// A study of one run that takes a few seconds (Example 7.1, 19 adaptive levels from
/// structured:8), so that readers reliably start while it is computed again.
const N5_STUDY: &str =
    "description = \"battery 11 N5\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:8\"\n[[run]]\nid = \"a\"\nlevels = 19\n";

#[test]
fn readers_of_a_folder_being_written_name_the_writer_instead_of_a_verdict() {
    let dir = scratch("b11-n5");
    stored_study(&dir, "experiments/s.toml", N5_STUDY, "res");
    let (code, out, err) = signorini_in(&dir, &["run", "experiments/s.toml", "--results", "w"]);
    assert_eq!(code, 0, "{out}{err}");
    let writer = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["run", "experiments/s.toml", "--results", "w", "--fresh"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let checkpoint = dir.join("w/s/.partial/a.json");
    let start = std::time::Instant::now();
    while !checkpoint.exists() {
        assert!(start.elapsed().as_secs() < 120, "{} never appeared", checkpoint.display());
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let named = format!("is being written by process {}", writer.id());
    // a reader given --wait waits for the writer, then reads (the Slurm finish job while a
    // second array of the same study holds the folder: refused, it failed `make cluster-test`)
    let waiting = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["figures", "--results", "w", "--wait"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let readers: [&[&str]; 3] = [
        &["drift", "--study", "s", "--results", "res", "--against", "w", "--report", "drift.json"],
        &["report", "--results", "w", "--out", "page"],
        &["figures", "--results", "w"],
    ];
    for args in readers {
        let (code, out, err) = signorini_in(&dir, args);
        assert_ne!(code, 0, "{args:?} read a folder being written: {out}{err}");
        assert!(err.contains(&named) && !err.contains("missing") && !err.contains("holds no study"), "{args:?}: {err}");
    }
    assert!(!dir.join("drift.json").exists() && !dir.join("w/drift-report.json").exists(), "a drift report of a folder being written");
    let status = { writer }.wait().unwrap();
    assert!(status.success());
    let waited = waiting.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&waited.stderr);
    assert!(waited.status.success(), "figures --wait: {err}");
    assert!(err.contains(&named) && err.contains("waiting for it to finish"), "figures --wait did not wait: {err}");
    assert!(dir.join("w/CLAIMS.md").exists(), "figures --wait drew nothing");
    // written, the folder reads: the same run again, no drift
    let (code, out, err) = signorini_in(&dir, &["drift", "--study", "s", "--results", "res", "--against", "w", "--report", "drift.json"]);
    assert_eq!(code, 0, "{out}{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Battery 11, a minor note: `stop_ndof` above `max_ndof` (a stop no level can reach, since no
/// level above `max_ndof` is solved) was accepted; the one validation of the command line and
/// the manifests refuses it, naming the key.
#[test]
fn a_stop_no_level_can_reach_is_refused_on_the_command_line_and_in_a_manifest() {
    let dir = scratch("b11-stop");
    let (code, _, err) = signorini_in(&dir, &["adapt", "--problem", "ex71", "--max-ndof", "500", "--stop-ndof", "1000"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--stop-ndof") && err.contains("max_ndof = 500") && err.contains("never reached"), "{err}");
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    let manifest = "description = \"stop above max\"\n[defaults]\nproblem = \"ex71\"\nlevels = 5\nmax_ndof = 500\nstop_ndof = 1000\n[[run]]\nid = \"a\"\n";
    std::fs::write(dir.join("experiments/s.toml"), manifest).unwrap();
    let (code, _, err) = signorini_in(&dir, &["run", "experiments/s.toml", "--results", "res"]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("experiments/s.toml") && err.contains("stop_ndof") && err.contains("never reached"), "{err}");
    assert!(!dir.join("res").exists(), "a refused manifest wrote results");
    std::fs::remove_dir_all(&dir).ok();
}

/// Battery 11, a minor note: a cut drift report made `report` fail with the parser's words
/// alone; the refusal now says how it came about and what to do.
#[test]
fn a_cut_drift_report_is_refused_with_what_to_do() {
    let dir = scratch("b11-cut-report");
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

/// N5's look at the locks opened each lock file to read it: a named pipe there (`.lock` or
/// `.locks/RUN.lock`) blocked the open, and `report`, `figures` and `drift` hung. A lock file that
/// is not a regular file is refused by its metadata, naming it, as writers refuse it.
#[test]
fn a_reader_refuses_a_lock_file_that_is_a_pipe_without_hanging() {
    let dir = scratch("b11-n5-fifo");
    stored_study(
        &dir,
        "experiments/s.toml",
        "description = \"fifo\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\n[[run]]\nid = \"a\"\nlevels = 3\n",
        "res",
    );
    for lock in ["res/s/.lock", "res/s/.locks/a.lock"] {
        let path = dir.join(lock);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::remove_file(&path).ok();
        let made = std::process::Command::new("mkfifo").arg(&path).status().unwrap();
        assert!(made.success());
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
            .current_dir(&dir)
            .args(["report", "--results", "res", "--out", "page"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let start = std::time::Instant::now();
        while child.try_wait().unwrap().is_none() {
            if start.elapsed().as_secs() > 60 {
                child.kill().ok();
                panic!("report hung on the named pipe {lock}");
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let o = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{lock}: {err}");
        assert!(err.contains(&format!("the lock file res/s/{}", lock.trim_start_matches("res/s/"))) && err.contains("named pipe"), "{err}");
        std::fs::remove_file(&path).unwrap();
    }
    std::fs::remove_dir_all(&dir).ok();
}
