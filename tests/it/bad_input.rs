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
fn bad_odd_symmetric_mesh_says_n_must_be_even() {
    for (spec, suggest) in
        [("symmetric:5", "use symmetric:4 or symmetric:6"), ("symmetric:1", "use symmetric:2"), ("symmetric:0", "use symmetric:2")]
    {
        let (code, err) = run(&["solve", "--problem", "ex71", "--mesh", spec]);
        assert_eq!(code, 1, "{spec}: {err}");
        assert!(err.contains(&format!("'{spec}'")) && err.contains("symmetric:N needs N even") && err.contains(suggest), "{spec}: {err}");
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
    for key in [
        "problem",
        "ndof",
        "ndof_free",
        "n_elements",
        "h_min",
        "h_max",
        "pdas_iterations",
        "active_nodes",
        "contact_zone",
        "kkt",
        "error",
        "probes",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["ndof"], 2 * 81);
    for key in ["linf_quadrature", "linf_dense", "linf_nodal"] {
        assert!(v["error"][key].as_f64().unwrap() > 0.0);
    }
    let u = v["probes"][0]["u"].as_array().unwrap();
    assert_eq!(u.len(), 2);
}

/// Exit code, stdout and stderr of a run that must not panic.
fn run_out(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_signorini")).args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into_owned(), stderr)
}

#[test]
fn bad_huge_mesh_is_refused_with_the_memory_estimate_before_allocating() {
    // this used to abort (SIGABRT) allocating 160 GB of vertices
    for mesh in ["structured:100000", "symmetric:100000"] {
        let (code, err) = run(&["solve", "--problem", "ex71", "--mesh", mesh]);
        assert_eq!(code, 1, "{err}");
        assert!(err.contains(mesh) && err.contains("149.0 TiB") && err.contains("available"), "{err}");
        if std::path::Path::new("/proc/meminfo").exists() {
            assert!(err.contains("MemAvailable"), "{err}");
        }
    }
    let (code, err) = run(&["adapt", "--problem", "ex72", "--mesh", "structured:100000"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("needs about"), "{err}");
    let (code, err) = run(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--adapt-min-ndof", "100000000000"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--adapt-min-ndof") && err.contains("needs about"), "{err}");
}

#[test]
fn memory_estimate_covers_the_measured_peaks() {
    // peak RSS of `signorini solve` measured with /usr/bin/time -v (bytes), and the NDF
    for (ndof, kib) in
        [(8450.0, 16964.0), (33282.0, 54412.0), (132098.0, 197736.0), (526338.0, 839248.0), (1182722.0, 1936888.0), (2101250.0, 3501300.0)]
    {
        let est = signorini::base::memory::memory_estimate(ndof);
        assert!(est >= 1.2 * kib * 1024.0, "NDF {ndof}: estimate {est} below measured peak {kib} KiB + 20 %");
    }
    assert_eq!(signorini::mesh::MeshSpec::Structured(512).ndof().unwrap(), 2101250.0);
}

/// The next level of an adaptive loop is estimated from the previous level's measured peak where
/// that is smaller than the per-unknown estimate and the bound is the machine's memory: Example
/// 7.1's deep run peaked at 8.1 GiB with 8.46e6 unknowns, and the estimate alone (23 GiB) refused
/// its next level of 1.22e7 unknowns on a 24 GiB machine.
#[test]
fn a_level_after_a_measured_one_is_estimated_from_its_peak_where_that_is_smaller() {
    use signorini::base::memory::memory_estimate;
    use signorini::memory::level_estimate;
    const GIB: f64 = 1024.0 * 1024.0 * 1024.0;
    let (n, previous) = (1.22e7, (8.46e6, 8.1 * GIB));
    // without a measurement, or against an address-space limit: the per-unknown estimate
    assert_eq!(level_estimate(n, None, true).0, memory_estimate(n));
    assert_eq!(level_estimate(n, Some(previous), false).0, memory_estimate(n));
    let (need, basis) = level_estimate(n, Some(previous), true);
    assert!((need - 1.25 * 8.1 * GIB * n / 8.46e6).abs() < 1.0, "{need}");
    assert!(need < 0.65 * memory_estimate(n) && basis.contains("previous level's peak"), "{basis}");
    // a measured peak above the per-unknown estimate never raises it, nor does a level with
    // fewer unknowns scale it down
    assert_eq!(level_estimate(1.0e6, Some((5e5, 4.0 * GIB)), true).0, memory_estimate(1.0e6));
    assert_eq!(level_estimate(1.0e6, Some((2e6, 1.0 * GIB)), true).0, 1.25 * GIB);
}

#[test]
fn bad_probe_outside_the_domain_or_not_finite_is_an_error() {
    for p in ["2,0.5", "0.5,-0.1", "1.0000001,0.5", "-0.1,0.5"] {
        let (code, err) = run(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", p]);
        assert_eq!(code, 1, "{p}: {err}");
        assert!(err.contains("outside the mesh") && err.contains(p), "{p}: {err}");
    }
    for p in ["nan,0.5", "0.5,NaN", "inf,0.5", "0.5,-inf", "1e999,0"] {
        let (code, err) = run(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", p]);
        assert_eq!(code, 1, "{p}: {err}");
        assert!(err.contains("malformed --probe") && err.contains("finite"), "{p}: {err}");
    }
}

#[test]
fn probe_accepts_negative_numbers_and_corners() {
    // a negative coordinate is a value, not a flag: read as such and then found outside
    let (code, err) = run(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", "-0.1,0.5"]);
    assert_eq!(code, 1);
    assert!(!err.contains("unexpected argument") && err.contains("outside the mesh"), "{err}");
    let (code, out, err) =
        run_out(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", "-0,0", "--probe", "1,1", "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    for p in v["probes"].as_array().unwrap() {
        assert!(p["x"].is_f64() && p["u"][0].is_f64() && p["u"][1].is_f64(), "{p}");
    }
}

#[test]
fn bad_inert_flags_are_rejected() {
    let (code, err) = run(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--theta", "0.3"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--adapt-levels"), "{err}");
    let (code, err) = run(&["adapt", "--problem", "ex71", "--uniform", "--theta", "0.3"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--uniform") && err.contains("--theta"), "{err}");
    let d = std::env::temp_dir().join(format!("signorini-inert-{}", std::process::id()));
    let (code, err) = run(&["export", "--problem", "ex71", "--mesh", "structured:4", "--json", "--out", d.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--json"), "{err}");
    assert!(!d.exists());
}

#[test]
fn bad_loop_settings_are_errors_naming_the_flag() {
    for (args, flag, expected) in [
        (&["--levels", "0"][..], "--levels", ">= 1"),
        (&["--theta", "1.5"][..], "--theta", "(0, 1]"),
        (&["--theta", "0"][..], "--theta", "(0, 1]"),
        (&["--theta", "-0.5"][..], "--theta", "(0, 1]"),
        (&["--max-ndof", "0"][..], "--max-ndof", ">= 1"),
        (&["--c0", "-1"][..], "--c0", "positive"),
        (&["--c0", "nan"][..], "--c0", "positive"),
    ] {
        let mut a = vec!["adapt", "--problem", "ex71"];
        if flag != "--levels" {
            a.extend_from_slice(&["--levels", "2"]);
        }
        a.extend_from_slice(args);
        let (code, out, err) = run_out(&a);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?}: printed before failing: {out}");
        assert!(err.contains(flag) && err.contains(expected), "{args:?}: {err}");
    }
    let (code, err) = run(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--adapt-levels", "1", "--theta", "1.5"]);
    assert_eq!(code, 1);
    assert!(err.contains("--theta") && err.contains("1.5"), "{err}");
    let (code, err) = run(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--max-pdas-iterations", "0"]);
    assert_eq!(code, 1);
    assert!(err.contains("--max-pdas-iterations"), "{err}");
}

#[test]
fn adapt_without_exact_solution_says_so_instead_of_nan() {
    let (code, out, err) = run_out(&["adapt", "--problem", "ex72", "--levels", "2"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("no exact solution"), "{out}");
    assert!(!out.contains("NaN"), "{out}");
}

#[test]
fn human_output_has_no_rust_internals() {
    let (code, out, err) = run_out(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--probe", "0.5,0.5"]);
    assert_eq!(code, 0, "{err}");
    for internal in ["Some(", "None", "1 active-set iterations"] {
        assert!(!out.contains(internal), "{internal}: {out}");
    }
    assert!(out.contains("1 active-set iteration") && out.contains("contact zone [0, 1]") && out.contains("u_h(0.5, 0.5) = ("), "{out}");
    let (code, out, _) = run_out(&["solve", "--problem", "ex72", "--mesh", "structured:4"]);
    assert_eq!(code, 0);
    assert!(out.contains("no exact solution") && !out.contains("None") && !out.contains("Some("), "{out}");
}

#[test]
fn bad_unwritable_output_names_the_path_and_the_step() {
    let d = std::env::temp_dir().join(format!("signorini-unwritable-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    // a file where a folder should be: unwritable even for root
    let file = d.join("a_file");
    std::fs::write(&file, "").unwrap();
    let out = file.join("out");
    let (code, err) = run(&["export", "--problem", "ex71", "--mesh", "structured:4", "--out", out.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains(out.to_str().unwrap()) && err.contains(&format!("{} is a regular file, not a folder", file.display())), "{err}");
    let fixture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tiny.toml");
    let (code, err) = run(&["run", fixture.to_str().unwrap(), "--quick", "--results", out.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains(out.to_str().unwrap()), "{err}");
    let (code, err) = run(&["figures", "--results", "results", "--figures", out.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains(out.to_str().unwrap()), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn write_helpers_name_the_path() {
    let d = std::env::temp_dir().join(format!("signorini-write-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("f"), "").unwrap();
    let target = d.join("f").join("x.json");
    let e = signorini::records::write_json(&target, &1).unwrap_err().to_string();
    assert!(e.contains(&format!("{} is a regular file, not a folder", d.join("f").display())), "{e}");
    // a directory where the file should be: the rename fails, and no temporary file is left
    std::fs::create_dir_all(d.join("dir.json").join("sub")).unwrap();
    let e = signorini::records::write_atomic(&d.join("dir.json"), b"{}").unwrap_err().to_string();
    assert!(e.contains("dir.json") && e.contains("renaming"), "{e}");
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 2, "temporary file left behind");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_missing_manifest_is_named_once() {
    let (code, err) = run(&["run", "experiments/no_such_study.toml"]);
    assert_eq!(code, 1);
    assert!(err.contains("experiments/no_such_study.toml"), "{err}");
    assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
}

#[test]
fn every_flag_of_every_subcommand_has_a_description() {
    for cmd in [&[][..], &["solve"], &["adapt"], &["run"], &["drift"], &["figures"], &["export"]] {
        let mut args = cmd.to_vec();
        args.push("--help");
        let (code, out, _) = run_out(&args);
        assert_eq!(code, 0);
        let lines: Vec<&str> = out.lines().collect();
        let mut flags = 0;
        for (i, line) in lines.iter().enumerate() {
            let t = line.trim_start();
            if !(t.starts_with("--") || (t.starts_with('-') && t.chars().nth(1).is_some_and(|c| c.is_ascii_alphabetic()))) {
                continue;
            }
            flags += 1;
            // the description follows on the same line after two spaces, or on the next, indented further
            let same_line = t.split_once("  ").is_some_and(|(_, d)| !d.trim().is_empty());
            let indent = line.len() - t.len();
            let next_line = lines.get(i + 1).is_some_and(|n| {
                let nt = n.trim_start();
                n.len() - nt.len() > indent && !nt.is_empty() && !nt.starts_with('-')
            });
            assert!(same_line || next_line, "{cmd:?}: flag without a description: {line}");
        }
        assert!(flags >= 1, "{cmd:?}: no flags found in\n{out}");
    }
}

/// An adaptive loop that outgrows the memory it may use stops before the level that would not
/// fit, with the levels it solved printed and the level it reached named, never an allocation
/// failure (the address space is limited with the shell's `ulimit -v`, in KiB).
#[test]
fn bad_adaptive_loop_outgrowing_memory_stops_with_the_level_reached() {
    let bin = env!("CARGO_BIN_EXE_signorini");
    // 1.2 GB for the levels beyond what the threads reserve (which grows with the CPU's cache;
    // counted once per process, memory::thread_reserve)
    let kib = 1_200_000 + (signorini::base::memory::thread_reserve() / 1024.0) as u64;
    let script = format!("ulimit -v {kib} && exec {bin} adapt --problem ex72 --mesh structured:8 --uniform --levels 10000");
    let out = Command::new("sh").args(["-c", &script]).output().unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked") && !stderr.contains("memory allocation"), "{stderr}");
    let level: usize =
        stderr.split("stopped before level ").nth(1).and_then(|s| s.split(' ').next()).and_then(|s| s.parse().ok()).expect(&stderr);
    assert!(level >= 3, "{stderr}");
    assert!(stderr.contains(&format!("levels 0 to {} were solved", level - 1)) && stderr.contains("address-space limit"), "{stderr}");
    // the solved levels were printed, one row each, the last one being level - 1
    let last_row = stdout.lines().rev().find(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).expect(&stdout);
    assert_eq!(last_row.split_whitespace().next(), Some((level - 1).to_string().as_str()), "{stdout}");
}

/// A closed standard output (`signorini adapt ... | head -c 1`) ends the process quietly, with
/// SIGPIPE's exit status 141 as command-line tools do, not a panic about a broken pipe (the
/// levels are printed as they are solved, so later rows meet the closed pipe).
#[test]
fn closed_stdout_ends_quietly() {
    let bin = env!("CARGO_BIN_EXE_signorini");
    let script = format!("set -o pipefail; {bin} adapt --problem ex72 --mesh structured:8 --levels 6 | head -c 1 >/dev/null; echo $?");
    let out = Command::new("bash").args(["-c", &script]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked") && !stderr.contains("Broken pipe"), "{stderr}");
    assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), "141", "{stderr}");
}
