//! Bad input gets a clear error and a non-zero exit, never a panic.

use std::process::Command;

fn run(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_signorini")).args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    (out.status.code().unwrap_or(-1), stderr)
}

#[test]
fn bad_unknown_problem_lists_the_known_ones() {
    let (code, err) = run(&["solve", "--problem", "ex73", "--mesh", "structured:4"]);
    assert_ne!(code, 0);
    assert!(err.contains("unknown problem 'ex73'") && err.contains("ex71") && err.contains("ex72"), "{err}");
}

#[test]
fn bad_mesh_string_says_what_is_expected() {
    for spec in ["structured", "structured:", "structured:-3", "structured:4x", "hexagons:4", "structured:0"] {
        let (code, err) = run(&["solve", "--problem", "ex71", "--mesh", spec]);
        assert_ne!(code, 0, "{spec}");
        assert!(err.contains("malformed mesh description") && err.contains("structured:N"), "{spec}: {err}");
    }
}

#[test]
fn bad_odd_mesh_for_the_wedge_names_the_missing_kink() {
    let (code, err) = run(&["solve", "--problem", "ex72", "--mesh", "structured:5"]);
    assert_ne!(code, 0);
    assert!(err.contains("(1, 0.5)") && err.contains("kink"), "{err}");
}

#[test]
fn bad_non_converging_solver_reports_iterations_and_residual() {
    let (code, err) = run(&["solve", "--problem", "ex72", "--mesh", "structured:16", "--max-pdas-iterations", "2"]);
    assert_ne!(code, 0);
    assert!(err.contains("did not converge in 2 iterations") && err.contains("residual"), "{err}");
}

#[test]
fn bad_probe_is_a_clear_error() {
    let (code, err) = run(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", "0.5;0.5"]);
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
    for key in ["problem", "ndof", "ndof_free", "n_elements", "h_min", "h_max", "pdas_iterations", "active_nodes", "contact_zone", "kkt", "error", "probes"] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["ndof"], 2 * 81);
    for key in ["linf_quadrature", "linf_dense", "linf_nodal"] {
        assert!(v["error"][key].as_f64().unwrap() > 0.0);
    }
    let u = v["probes"][0]["u"].as_array().unwrap();
    assert_eq!(u.len(), 2);
}
