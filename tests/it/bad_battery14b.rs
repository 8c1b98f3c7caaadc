//! Battery 14, the leftovers of issue 38 (its "Minor notes" and the rollers case of F3):
//! * A point constraint on Gamma_D with a value on a component `dirichlet` also prescribes
//!   (ex72_rollers with `u = [0.25, 0]` at its point (0, 0.5), where `dirichlet = [0.1, "free"]`
//!   sets u_1 = 0.1) was accepted, exit 0, one of the two values silently dropped. The solve now
//!   checks, once per mesh before assembling (`contact::point::check_on_dirichlet`), that such a
//!   value equals Gamma_D's there (to 1e-12 of the prescribed displacements' scale) and refuses
//!   it otherwise, naming the point, the component, both values and the part; an equal value
//!   (redundant) is still accepted and solves the same problem. A contact node sets no value
//!   (a point there leaves the contact nodes; `contact::plausible` and the reaction check judge
//!   it), and rollers or a symmetry hold are Dirichlet components: no other case exists.
//! * `export` / `adapt --save` with standard output on /dev/full said only "writing standard
//!   output: No space left on device" (exit 1) though the files were written. The error now
//!   names the files written and says only the printed report was lost; exit 1 stays.
//! * A point constraint at a non-vertex (`at = [1, 0.3]` on structured:4) said only "is not a
//!   vertex of the mesh". It now says that a required vertex must be one of the mesh given (none
//!   is inserted) and names the smallest structured:N (and symmetric:N) with a vertex there.
//! * `adapt | head -c 10` dying by SIGPIPE (141 under pipefail) is the deliberate policy of
//!   `main` (a closed stdout ends the program as `ls | head` does), kept and tested by
//!   `bad_input::closed_stdout_ends_quietly`.

use super::common::{scratch, signorini_in};
use std::path::Path;
use std::process::Command;

fn rollers() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/experiments/problems/ex72_rollers.toml")).unwrap()
}

/// ex72_rollers without its required vertex (the wedge's tip) and with its point constraint at
/// (0, 0.4) (on structured:5, as (0.2, 0.6) is).
fn ex72_rollers_without_tip() -> String {
    rollers().replace("required_vertices = [[1, 0.5]]", "").replace("at = [0, 0.5]", "at = [0, 0.4]")
}

/// ex72_rollers with its point constraint's `u` replaced by `u`.
fn rollers_with(u: &str) -> String {
    let text = rollers();
    assert!(text.contains("u = [\"free\", 0]"), "the rollers' point constraint changed");
    text.replace("u = [\"free\", 0]", u)
}

fn solve(dir: &Path, problem: &str, mesh: &str) -> (i32, String, String) {
    std::fs::write(dir.join("p.toml"), problem).unwrap();
    signorini_in(dir, &["solve", "--problem", "p.toml", "--mesh", mesh])
}

/// The summary's lines that describe the solution (not the timings).
fn solution_lines(out: &str) -> Vec<&str> {
    out.lines().filter(|l| l.starts_with("contact:") || l.contains("estimate")).collect()
}

#[test]
fn a_point_value_that_gamma_d_sets_otherwise_is_refused() {
    let dir = scratch("b14b-dirichlet");
    for mesh in ["structured:4", "structured:16"] {
        let (code, out, err) = solve(&dir, &rollers_with("u = [0.25, 0]"), mesh);
        assert_eq!(code, 1, "{mesh}: {out}{err}");
        assert!(!out.contains("contact:"), "{mesh}: solved: {out}");
        for part in [
            "the point constraint at (0, 0.5) prescribes u_1 = 0.25",
            "on the Dirichlet part (parts.dirichlet",
            "already sets u_1 = 0.1 there",
            "drop it, or write \"free\" for u_1",
        ] {
            assert!(err.contains(part), "{mesh}: {part:?} not in {err}");
        }
    }
    // the adaptive loop gets the same refusal from its first solve
    let (code, _, err) = signorini_in(&dir, &["adapt", "--problem", "p.toml", "--levels", "3"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("already sets u_1 = 0.1 there"), "{err}");
}

#[test]
fn an_equal_point_value_on_gamma_d_is_accepted_and_changes_nothing() {
    let dir = scratch("b14b-dirichlet-equal");
    let (code, plain, err) = solve(&dir, &rollers(), "structured:8");
    assert_eq!(code, 0, "{err}");
    // 0.3 - 0.2 is 0.1 less 2.8e-17: the same value to round-off
    for u in ["u = [0.1, 0]", "u = [\"0.3 - 0.2\", 0]"] {
        let (code, out, err) = solve(&dir, &rollers_with(u), "structured:8");
        assert_eq!(code, 0, "{u}: {err}");
        assert!(!solution_lines(&plain).is_empty(), "{plain}");
        assert_eq!(solution_lines(&out), solution_lines(&plain), "{u}");
    }
    // 1e-9 off is no round-off
    let (code, _, err) = solve(&dir, &rollers_with("u = [0.100000001, 0]"), "structured:8");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("prescribes u_1 = 0.100000001") && err.contains("already sets u_1 = 0.1 there"), "{err}");
}

#[test]
fn a_failed_stdout_names_the_files_already_written() {
    let dir = scratch("b14b-devfull");
    let full = || std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let run = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_signorini")).current_dir(&dir).args(args).stdout(full()).output().unwrap();
        (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
    };
    let (code, err) = run(&["export", "--problem", "ex72", "--mesh", "structured:4", "--out", "case"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("error: writing standard output: No space left on device"), "{err}");
    assert!(err.contains("Only the printed report was lost"), "{err}");
    for f in ["mesh.vtu", "case.json"] {
        let path = dir.join("case").join(f);
        assert!(err.contains(&Path::new("case").join(f).display().to_string()), "{f} not named: {err}");
        assert!(std::fs::metadata(&path).unwrap().len() > 0, "{f} empty");
    }
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("case/case.json")).unwrap()).unwrap();
    assert!(json.is_object());
    let (code, err) = run(&["adapt", "--problem", "ex72", "--levels", "2", "--save", "last.vtu"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("No space left on device") && err.contains("Only the printed report was lost: ") && err.contains("last.vtu"),
        "{err}"
    );
    assert!(std::fs::read_to_string(dir.join("last.vtu")).unwrap().trim_end().ends_with("</VTKFile>"));
}

#[test]
fn a_point_constraint_off_the_vertices_says_which_mesh_has_one() {
    let dir = scratch("b14b-vertex");
    let text = format!("{}\n[[point_constraints]]\nat = [1, 0.3]\nu = [\"free\", 0]\n", rollers());
    let (code, _, err) = solve(&dir, &text, "structured:4");
    assert_eq!(code, 1, "{err}");
    for part in [
        "point_constraints[1].at`: (1, 0.3) is not a vertex of the mesh",
        "must be a vertex of the mesh given; none is inserted",
        "structured:10 (or symmetric:10)",
        "a Gmsh mesh needs a point there",
    ] {
        assert!(err.contains(part), "{part:?} not in {err}");
    }
    // the mesh it names has the vertex (whatever else it then says of the point)
    let (_, _, err) = solve(&dir, &text, "structured:10");
    assert!(!err.contains("is not a vertex"), "{err}");
    // the N named has every required vertex: (0.2, 0.6) alone is on structured:5, and the
    // wedge's tip (1, 0.5) needs N even
    let text = rollers().replace("required_vertices = [[1, 0.5]]", "required_vertices = [[1, 0.5], [0.2, 0.6]]");
    let (code, _, err) = solve(&dir, &text, "structured:4");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("structured:10 (or symmetric:10) and its multiples have one there and at every other required vertex"), "{err}");
    // an odd N is doubled for symmetric:N
    let text = format!("{}\n[[point_constraints]]\nat = [0.2, 0.6]\nu = [\"free\", 0]\n", ex72_rollers_without_tip());
    let (code, _, err) = solve(&dir, &text, "structured:4");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("structured:5 (or symmetric:10)"), "{err}");
}
