//! One validation for the command line and the manifests: every bad setting of the adaptive
//! loop is refused by the same library function (`AdaptConfig::validate`,
//! `AdaptConfig::check_initial`, `Terms::check_finite`) whichever way it comes, with the same
//! expected values and the same value named; a loop with nothing to mark says so instead of
//! solving the same mesh again; `max_ndof` and a stop no level can reach are decided before a
//! level is solved.

use crate::common::{mesh, run_edited, scratch, signorini_in};
use signorini::adapt::{self, AdaptError, AdaptTermination, Level, Start};
use signorini::problems::Fb;
use signorini::settings::adapt::{AdaptConfig, Refine};
use std::ops::ControlFlow;

/// `stop_ndof` above `max_ndof` (a stop no level can reach, since no level above `max_ndof` is
/// solved) is refused by the one validation of the command line and the manifests, naming the
/// key.
#[test]
fn a_stop_no_level_can_reach_is_refused_on_the_command_line_and_in_a_manifest() {
    let dir = scratch("loop-settings-stop");
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

const SQUARE: &str = "bad_data_square.toml";

/// `--adapt-levels` at the largest integer does not wrap to 0 levels ("expected a number of
/// levels >= 1, got 0"); it is as many levels as --adapt-min-ndof needs.
#[test]
fn adapt_levels_at_the_largest_integer_do_not_wrap() {
    let args =
        ["solve", "--problem", "ex71", "--mesh", "structured:2", "--adapt-levels", "18446744073709551615", "--adapt-min-ndof", "200"];
    let (code, out, err) = run_edited("levels-max", SQUARE, &[], &args);
    assert_eq!(code, 0, "{out}{err}");
    assert!(!err.contains("got 0"), "{err}");
}

/// The part of an error from `marker` to the end of its line, the run's name dropped.
fn tail<'a>(err: &'a str, marker: &str) -> &'a str {
    let at = err.find(marker).unwrap_or_else(|| panic!("no {marker:?} in: {err}"));
    let line = err[at..].lines().next().unwrap();
    line.strip_suffix(" (run r0)").unwrap_or(line)
}

/// Each bad value as flags of `adapt` and as manifest lines (`[defaults]`, `[defaults.estimator]`),
/// with the key the manifest names and the flag the command line names.
const CASES: [(&[&str], &str, &str, &str, &str); 14] = [
    (&["--c0", "0"], "", "c0 = 0.0", "estimator.c0", "--c0"),
    (&["--c0", "-1"], "", "c0 = -1.0", "estimator.c0", "--c0"),
    (&["--c0", "nan"], "", "c0 = nan", "estimator.c0", "--c0"),
    (&["--c0", "inf"], "", "c0 = inf", "estimator.c0", "--c0"),
    (&["--c0", "1e-310"], "", "c0 = 1e-310", "estimator.c0", "--c0"),
    (&["--theta", "0"], "theta = 0.0", "", "theta", "--theta"),
    (&["--theta", "1.5"], "theta = 1.5", "", "theta", "--theta"),
    (&["--theta", "-0.5"], "theta = -0.5", "", "theta", "--theta"),
    (&["--theta", "nan"], "theta = nan", "", "theta", "--theta"),
    (&["--levels", "0"], "levels = 0", "", "levels", "--levels"),
    (&["--max-ndof", "0"], "max_ndof = 0", "", "max_ndof", "--max-ndof"),
    (&["--max-ndof", "5"], "max_ndof = 5", "", "max_ndof", "--max-ndof"),
    (&["--max-ndof", "161"], "max_ndof = 161", "", "max_ndof", "--max-ndof"),
    (&["--stop-ndof", "0"], "stop_ndof = 0", "", "stop_ndof", "--stop-ndof"),
];

fn manifest(defaults: &str, estimator: &str) -> String {
    let levels = if defaults.starts_with("levels") { "" } else { "levels = 2\n" };
    format!(
        "[defaults]\nproblem = \"ex71\"\nmesh = \"structured:4\"\n{levels}{defaults}\n[defaults.estimator]\n{estimator}\n[[run]]\nid = \"r0\"\n"
    )
}

#[test]
fn invalid_settings_get_the_same_refusal_from_the_command_line_and_a_manifest() {
    for (flags, defaults, estimator, key, flag) in CASES {
        let d = scratch("loop-settings-both");
        let mut args = vec!["adapt", "--problem", "ex71", "--mesh", "structured:4"];
        if flags[0] != "--levels" {
            args.extend(["--levels", "2"]);
        }
        args.extend_from_slice(flags);
        let (code, out, cli) = signorini_in(&d, &args);
        assert_eq!(code, 1, "{flags:?}: {cli}");
        assert!(out.is_empty(), "{flags:?}: solved before refusing:\n{out}");
        assert!(cli.contains(&format!("error: {flag}: expected ")), "{flags:?}: {cli}");
        std::fs::write(d.join("m.toml"), manifest(defaults, estimator)).unwrap();
        let (code, _, man) = signorini_in(&d, &["run", "m.toml", "--results", "res"]);
        assert_eq!(code, 1, "{flags:?}: {man}");
        assert!(man.contains(&format!("m.toml: key `run[0].{key}`: expected ")), "{flags:?}: {man}");
        assert!(!d.join("res").exists(), "{flags:?}: the manifest's run was started");
        assert_eq!(tail(&cli, ": expected "), tail(&man, ": expected "), "{flags:?}");
        if key == "max_ndof" && flags[1] != "0" {
            assert!(cli.contains("expected a number of unknowns >= 162 (the initial mesh structured:4 has 162"), "{cli}");
        }
    }
}

/// A C_0 so large that C_0 eta_h overflows cannot be known bad before eta_h is: both paths stop
/// at level 0 with the same named error (the command line printed `inf` and exited 0).
#[test]
fn an_estimate_that_overflows_is_refused_by_both_paths_at_level_0() {
    let d = scratch("loop-settings-overflow");
    let (code, out, cli) = signorini_in(&d, &["adapt", "--problem", "ex71", "--levels", "2", "--c0", "1e308"]);
    assert_eq!(code, 1, "{cli}");
    assert!(!out.contains("inf"), "{out}");
    std::fs::write(d.join("m.toml"), manifest("", "c0 = 1e308")).unwrap();
    let (code, _, man) = signorini_in(&d, &["run", "m.toml", "--results", "res"]);
    assert_eq!(code, 1, "{man}");
    let marker = "level 0: the estimate C_0 eta_h = 1e308 x ";
    assert_eq!(tail(&cli, marker), tail(&man, marker));
    assert!(cli.contains("is inf, not a finite number"), "{cli}");
    // `solve` refuses it too
    let (code, out, err) = signorini_in(&d, &["solve", "--problem", "ex71", "--mesh", "structured:4", "--c0", "1e308"]);
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty() && err.contains("is inf, not a finite number"), "{out}{err}");
    // a large C_0 whose estimate is finite stays accepted
    let (code, _, err) = signorini_in(&d, &["adapt", "--problem", "ex71", "--levels", "1", "--c0", "1e300"]);
    assert_eq!(code, 0, "{err}");
}

/// A problem whose estimate is zero everywhere (no load, no contact) has nothing to mark: the
/// loop stops after level 0 and says why, instead of solving the same mesh `levels` times.
#[test]
fn nothing_to_mark_stops_the_loop_and_says_so() {
    let d = scratch("loop-settings-unmarked");
    std::fs::write(
        d.join("still.toml"),
        "[material]\nmu = 1\nlambda = 1\n[parts]\ncontact = \"y < 1e-12\"\ndirichlet = \"x < 1e-12\"\n[contact]\nchi = \"1\"\nnormal = [0, -1]\n",
    )
    .unwrap();
    let (code, out, err) = signorini_in(&d, &["adapt", "--problem", "still.toml", "--levels", "4"]);
    assert_eq!(code, 0, "{err}");
    let rows: Vec<&str> = out.lines().filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).collect();
    assert_eq!(rows.len(), 1, "{out}");
    // (the note does not call every such u_h exact: translated data can stop here too)
    assert!(out.contains("# stopped: the estimate is zero, or at round-off (u_h has no deformation above 30 delta, or eta_h is at most 1e3 times what u_h's round-off can do to it: the smaller of (2 mu + lambda) delta, delta the round-off of u_h (the larger of its round-off floor and 2.2e-16 max |u_h|), and the largest stress the round-off's energy allows: u_h is a rigid motion or a field the P2 space reproduces, to round-off, or a rigid translation in the data left it no digits of the deformation), so nothing is marked"), "{out}");
    // uniform refinement marks everything: all levels are solved
    let (code, out, err) = signorini_in(&d, &["adapt", "--problem", "still.toml", "--levels", "3", "--uniform"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).count(), 3, "{out}");
}

/// An exact discrete solution (a rigid translation: no load, the gap never reached) has an
/// estimate of round-off only (about 1e-13 of (2 mu + lambda) max |u_h|): the loop does not
/// refine on that noise, it stops after level 0 and says why; a real estimate still refines.
#[test]
fn an_estimate_at_round_off_marks_nothing_and_says_so() {
    let d = scratch("loop-settings-roundoff-estimate");
    let problem = "dirichlet = [0.1, 0]\n[material]\nE = 500\nnu = 0.3\nmodel = \"plane_strain\"\n[parts]\ncontact = \"x > 1 - 1e-12\"\ndirichlet = \"x < 1e-12\"\n[contact]\nnormal = \"outward\"\nchi = CHI\n";
    std::fs::write(d.join("shift.toml"), problem.replace("CHI", "1")).unwrap();
    let (code, out, err) = signorini_in(&d, &["adapt", "--problem", "shift.toml", "--mesh", "structured:4", "--levels", "4"]);
    assert_eq!(code, 0, "{err}");
    let rows: Vec<&str> = out.lines().filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).collect();
    assert_eq!(rows.len(), 1, "{out}");
    assert!(out.contains("# stopped: the estimate is zero, or at round-off"), "{out}");
    // the same body pressed 0.05 into contact: a real estimate, every level solved
    std::fs::write(d.join("pressed.toml"), problem.replace("CHI", "0.05")).unwrap();
    let (code, out, err) = signorini_in(&d, &["adapt", "--problem", "pressed.toml", "--mesh", "structured:4", "--levels", "4"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).count(), 4, "{out}");
    assert!(!out.contains("# stopped"), "{out}");
}

/// The defaults are the library's, whichever way a run comes: the command line shows and uses
/// `AdaptConfig::default()`, `EstimatorConfig::default()` and `MeshSpec::DEFAULT` (clap reads
/// them), and a manifest that leaves every setting out gets the same values.
#[test]
fn the_command_line_and_the_manifests_default_to_the_librarys_values() {
    use clap::ValueEnum;
    use signorini::mesh::MeshSpec;
    use signorini::settings::adapt::AdaptConfig;
    let (a, e) = (AdaptConfig::default(), AdaptConfig::default().estimator);
    let name = |v: Option<clap::builder::PossibleValue>| v.unwrap().get_name().to_string();
    let expected = [
        ("--mesh", MeshSpec::DEFAULT.to_string()),
        ("--levels", a.levels.to_string()),
        ("--theta", a.theta.to_string()),
        ("--c0", e.c0.to_string()),
        ("--contact-term", name(e.contact_term.to_possible_value())),
        ("--log-factor", name(e.log_factor.to_possible_value())),
        ("--sampling", name(e.sampling.to_possible_value())),
    ];
    let dir = scratch("loop-settings-defaults");
    let (code, help, err) = signorini_in(&dir, &["adapt", "--help"]);
    assert_eq!(code, 0, "{err}");
    for (flag, value) in &expected {
        let line = help.lines().find(|l| l.trim_start().starts_with(&format!("{flag} "))).unwrap_or_else(|| panic!("{flag}: {help}"));
        assert!(line.contains(&format!("[default: {value}]")), "{flag}: {line}");
    }
    let manifest = dir.join("defaults.toml");
    std::fs::write(&manifest, "[defaults]\nproblem = \"ex71\"\nlevels = 3\n\n[[run]]\nid = \"a\"\n").unwrap();
    let m = signorini::manifest::Manifest::load(&manifest).unwrap();
    let run = &m.runs[0].spec;
    assert_eq!((run.mesh.as_str(), run.theta, run.refine, run.estimator), (MeshSpec::DEFAULT, a.theta, a.refine, e));
    std::fs::remove_dir_all(&dir).unwrap();
}
