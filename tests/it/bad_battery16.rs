//! Battery 16, finding F1 [crash]: a study run interrupted (SIGINT) in its last level, the one
//! after which the refined mesh would pass `max_ndof`, kept a checkpoint saying the loop
//! continues (a refined mesh existed); the resume started at that mesh, stopped before solving
//! anything and panicked ("the first level is always solved"), and so did every later `run` and
//! `run --replace`. The loop now decides at the level itself that a refined mesh above
//! `max_ndof` is not solved (that level does not continue, so no checkpoint points past it),
//! and a start whose mesh is above `max_ndof` is a named error, never a panic.
//!
//! F2 [silent]: the gap bound's chord stopped at a held end but took that end as held at zero:
//! a 0.1 plate whose top is held at u_y = -0.05 took chi = -0.08 (its bottom face ending above
//! its top), certified; one held at +0.05 was refused at chi = -0.12 with 0.03 left; and
//! `[0, -0.2]` with chi = 0.01 (no negative gap, so no check) turned the plate inside out. A held
//! end now counts where its Dirichlet data put it (`contact::chord::Room::left`), and a gap that
//! is not negative is checked too where the data move a held end.
//! F3 [message]: a study page said "No CLAIMS row rests on this study" of a study whose runs the
//! c0 row reads (every stored run with an error, since battery 15's F2): the pages now take a
//! row's studies from `page::rests_on`, the c0 row's being every study.
//! F4 [message]: `drift` with a failing standard output did not say that its report file was
//! written, as `figures`, `report`, `export` and `adapt --save` do: its "report:" line now
//! goes through the one list of files written.

use super::common::msh::{grid, msh};
use super::common::{mesh, scratch, signorini_in};
use signorini::adapt::Refine;
use signorini::adapt::{self, AdaptConfig, AdaptError, AdaptTermination, Level, Start};
use signorini::problems::Fb;
use std::ops::ControlFlow;

#[test]
fn the_level_before_max_ndof_does_not_continue() {
    for refine in [Refine::Uniform, Refine::Adaptive] {
        let config = AdaptConfig { levels: 30, max_ndof: Some(40_000), theta: 0.5, refine, ..Default::default() };
        let mut seen = Vec::new();
        let result = adapt::run(&Fb, mesh(&Fb, "structured:4"), &config, None, &mut |l: Level| {
            seen.push((l.record.ndof, l.continues));
            ControlFlow::Continue(())
        })
        .unwrap();
        assert_eq!(result.termination, AdaptTermination::MaxNdofReached, "{refine:?}");
        let (last, earlier) = seen.split_last().unwrap();
        assert!(!last.1, "{refine:?}: the last level ({} unknowns) says it continues: {seen:?}", last.0);
        assert!(earlier.iter().all(|l| l.1), "{refine:?}: {seen:?}");
        assert!(last.0 <= 40_000 && earlier.len() >= 3, "{refine:?}: {seen:?}");
    }
}

#[test]
fn a_start_above_max_ndof_is_a_named_error() {
    let config = AdaptConfig { levels: 30, max_ndof: Some(1000), refine: Refine::Uniform, ..Default::default() };
    let start = Start { level: 3, ..Start::new(mesh(&Fb, "structured:16")) };
    match adapt::run_from(&Fb, start, &config, None, &mut |_| ControlFlow::Continue(())) {
        Err(e @ AdaptError::BeyondMaxNdof { start: 3, max: 1000, .. }) => {
            assert!(e.to_string().contains("above max_ndof 1000"), "{e}");
        }
        Err(e) => panic!("another error: {e}"),
        Ok(r) => panic!("solved {} levels", r.records.len()),
    }
}

const TINY: &str = "description = \"tiny\"\n[defaults]\nproblem = \"fb\"\nmesh = \"structured:4\"\ntheta = 0.5\nmax_ndof = 3000\n[[run]]\nid = \"adaptive\"\nrole = \"as-written\"\nrefine = \"adaptive\"\nlevels = 4\n";

#[test]
fn a_study_page_shows_the_c0_row_and_drift_names_its_report_when_stdout_fails() {
    let dir = scratch("b16-page");
    std::fs::create_dir_all(dir.join("experiments")).unwrap();
    std::fs::write(dir.join("experiments/tiny.toml"), TINY).unwrap();
    let ok = |args: &[&str]| {
        let (code, out, err) = signorini_in(&dir, args);
        assert_eq!(code, 0, "{args:?}: {out}{err}");
    };
    ok(&["run", "experiments/tiny.toml", "--results", "res"]);
    ok(&["figures", "--results", "res", "--experiments", "experiments"]);
    ok(&["report", "--results", "res", "--experiments", "experiments"]);
    let page = std::fs::read_to_string(dir.join("res/report/tiny.html")).unwrap();
    assert!(!page.contains("No CLAIMS row rests on this study"), "tiny's page lists no row");
    assert!(page.contains("id=\"claim-c0\""), "tiny's page lacks the c0 row");
    // drift --against a copy, standard output on /dev/full: the report is written and named
    let copy = std::process::Command::new("cp").args(["-r", "res", "copy"]).current_dir(&dir).status().unwrap();
    assert!(copy.success());
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
        .current_dir(&dir)
        .args(["drift", "--against", "copy", "--results", "res", "--experiments", "experiments", "--study", "tiny"])
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("Only the printed report was lost") && err.contains("drift-report.json"), "{err}");
    assert!(std::fs::metadata(dir.join("copy/drift-report.json")).unwrap().len() > 0);
    std::fs::remove_dir_all(&dir).ok();
}

/// A plate [0, 1] x [0, 0.1], its top held at `top` = u, contact on its bottom at gap `chi`.
fn plate(top: &str, chi: &str) -> String {
    format!(
        "dirichlet = {top}\n[material]\nE = 1000\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = [\"contact\"]\ndirichlet = [\"top\"]\nneumann = [\"free\"]\n[contact]\nnormal = \"outward\"\nchi = \"{chi}\"\n"
    )
}

#[test]
fn a_held_end_counts_where_its_dirichlet_data_put_it() {
    let dir = scratch("b16-held");
    let sides = |side: &str| match side {
        "bottom" => "contact",
        "top" => "top",
        _ => "free",
    };
    std::fs::write(dir.join("plate.msh"), msh(&[(grid(10, 2, [0.0, 0.0], [1.0, 0.1]), &sides)])).unwrap();
    let solve = |top: &str, chi: &str| {
        std::fs::write(dir.join("p.toml"), plate(top, chi)).unwrap();
        signorini_in(&dir, &["solve", "--problem", "p.toml", "--mesh", "gmsh:plate.msh"])
    };
    // the top moved 0.05 towards the face leaves 0.05: -0.08 refused, -0.03 solved
    for (top, chi, room) in [("[0, -0.05]", "-0.08", "0.05"), ("[0, -0.2]", "0.01", "-0.1")] {
        let (code, out, err) = solve(top, chi);
        assert_eq!(code, 1, "{top} {chi}: {out}{err}");
        let part = format!(
            "which the Dirichlet data move {} towards the contact face: {room} of room",
            &top[4..top.len() - 1].trim_start_matches('-')
        );
        assert!(err.contains(&part), "{top} {chi}: {part}: {err}");
        assert!(!out.contains("certified"), "{out}");
    }
    for (top, chi) in [("[0, -0.05]", "-0.03"), ("[0, 0.05]", "-0.12"), ("[0, 0]", "-0.09")] {
        let (code, out, err) = solve(top, chi);
        assert_eq!(code, 0, "{top} {chi}: {out}{err}");
        assert!(out.contains("certified"), "{top} {chi}: {out}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
