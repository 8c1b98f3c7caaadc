//! No crash at the edges of the machine: an address-space limit gives a certified answer or the
//! named memory error, never an abort; memory estimates cover the measured peaks; a stdout or
//! stderr that is full, closed or cannot be written gives the error's exit status (or ends
//! quietly), never a panic, after the files are written; a file-size limit is named; an
//! interrupted `adapt` stops after the current level and says what it kept.

use crate::common::{scratch, signorini_in, signorini_in_repo};
use std::io::BufRead;
use std::path::Path;
use std::process::{Command, Stdio};

/// Standard output on a full device: the error's exit status (1) naming it, not a panic (101,
/// as std's `println!` ended before), for `solve`, `solve --json` and `adapt`.
#[test]
fn a_full_stdout_exits_with_the_error_status_not_a_panic() {
    for args in [
        &["solve", "--problem", "ex71", "--mesh", "structured:4"][..],
        &["solve", "--problem", "ex71", "--mesh", "structured:4", "--json"],
        &["adapt", "--problem", "ex71", "--levels", "3"],
    ] {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_signorini")).args(args).stdout(full).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("error: writing standard output: No space left on device") && !err.contains("panicked"), "{args:?}: {err}");
    }
}

#[test]
fn a_failed_stdout_names_the_files_already_written() {
    let dir = scratch("machine-limits-devfull");
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

const TINY: &str = "description = \"tiny\"\n[defaults]\nproblem = \"fb\"\nmesh = \"structured:4\"\ntheta = 0.5\nmax_ndof = 3000\n[[run]]\nid = \"adaptive\"\nrole = \"as-written\"\nrefine = \"adaptive\"\nlevels = 4\n";

#[test]
fn a_study_page_shows_the_c0_row_and_drift_names_its_report_when_stdout_fails() {
    let dir = scratch("machine-limits-page");
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

#[test]
fn help_and_version_to_a_full_device_are_an_error() {
    let dir = scratch("machine-limits-help");
    for args in [&["--help"][..], &["--version"], &["help", "solve"], &["solve", "--help"]] {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"))
            .args(args)
            .current_dir(&dir)
            .stdout(full)
            .stderr(std::process::Stdio::piped())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&status.stderr);
        assert_eq!(status.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("writing standard output"), "{args:?}: {err}");
    }
    // to a working stdout: exit 0 with the text
    let (code, out, _) = signorini_in(&dir, &["--version"]);
    assert_eq!(code, 0);
    assert!(out.starts_with("signorini "), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `adapt --save x.vtu | head` writes the VTU: a command that writes files goes on past a closed
/// standard output, writes them and names them; one that only prints ends quietly by SIGPIPE.
#[test]
fn a_closed_stdout_does_not_stop_a_command_before_its_files_are_written() {
    let dir = scratch("machine-limits-pipe");
    let sig = env!("CARGO_BIN_EXE_signorini");
    let sh = |cmd: &str| {
        let out = std::process::Command::new("bash")
            .args(["-c", &format!("set -o pipefail; {cmd} | head -c 1 > /dev/null")])
            .current_dir(&dir)
            .output()
            .unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).to_string())
    };
    let (code, err) = sh(&format!("{sig} adapt --problem ex72 --levels 14 --save x.vtu"));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("Broken pipe") && err.contains("x.vtu"), "{err}");
    let vtu = std::fs::read_to_string(dir.join("x.vtu")).unwrap();
    assert!(vtu.trim_end().ends_with("</VTKFile>"), "the VTU is whole");
    let (code, err) = sh(&format!("{sig} adapt --problem ex72 --levels 14"));
    assert_eq!(code, Some(141), "{err}");
    assert!(err.is_empty(), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A write stopped by the file-size limit names the limit, not only the file.
#[test]
fn a_file_beyond_the_size_limit_names_the_limit() {
    let dir = scratch("machine-limits-fsize");
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_signorini"));
    cmd.args(["export", "--problem", "ex72", "--mesh", "structured:8", "--out", "z"]).current_dir(&dir);
    super::common::limit(&mut cmd, libc::RLIMIT_FSIZE, 4000);
    let out = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("z/mesh.vtu") && err.contains("at most 4000 bytes") && err.contains("file-size limit"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The binary with `args`, under an address-space limit of `bytes` (RLIMIT_AS, as
/// `prlimit --as` sets it): (exit code or None for a signal, stdout, stderr).
fn limited(bytes: u64, args: &[&str]) -> (Option<i32>, String, String) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_signorini"));
    cmd.args(args);
    super::common::limit(&mut cmd, libc::RLIMIT_AS, bytes);
    let o = cmd.output().unwrap();
    (o.status.code(), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// From 50 MB to 1 GB of address space: `solve` either certifies its answer or refuses with the
/// named memory error before solving; `adapt` either finishes or stops before the level that
/// would not fit. Before, faer's dense kernels aborted (SIGABRT) between 100 and 300 MB: the
/// check counted resident memory only, not the address space each thread reserves.
#[test]
fn an_address_space_limit_gives_an_answer_or_the_memory_error_never_a_signal() {
    let (mut solved, mut refused) = (0, 0);
    // what the threads reserve grows with the CPU's cache (faer's packing buffers are twice the
    // L3 per thread: 0.3 GB with a 32 MiB L3, 1.7 GB with 260 MiB): the range covers it
    let top = 1000 + (signorini::base::memory::thread_reserve() / 1e6) as u64;
    for mb in (1..=20).map(|k| k * top / 20) {
        let bytes = mb * 1_000_000;
        let (code, out, err) = limited(bytes, &["solve", "--problem", "ex71", "--mesh", "structured:4"]);
        match code {
            Some(0) => {
                assert!(out.contains("certified:"), "{mb} MB: {out}");
                solved += 1;
            }
            Some(1) => {
                assert!(err.contains("address-space limit") && err.contains("162 unknowns"), "{mb} MB: {err}");
                refused += 1;
            }
            _ => panic!("{mb} MB: solve ended with {code:?} (a signal or a panic):\n{err}"),
        }
        let (code, _, err) = limited(bytes, &["adapt", "--problem", "ex71", "--levels", "4"]);
        match code {
            Some(0) => {}
            Some(1) => assert!(err.contains("address-space limit"), "{mb} MB: {err}"),
            _ => panic!("{mb} MB: adapt ended with {code:?} (a signal or a panic):\n{err}"),
        }
    }
    assert!(solved > 0 && refused > 0, "solved {solved}, refused {refused}: the range should hold both");
}

/// The threads' address-space reserve is counted once per process, not again at every level on
/// top of a virtual size that already holds it: under a limit that leaves 512 MiB beyond the
/// reserve, Example 7.1's adaptive loop runs all 8 levels, as its level 0 fits; a limit of the
/// reserve alone is refused before level 0, naming what was counted.
#[test]
fn the_threads_reserve_is_counted_once_not_again_at_every_level() {
    let reserve = signorini::base::memory::thread_reserve();
    let args = ["adapt", "--problem", "ex71", "--levels", "8"];
    let (code, out, err) = limited((reserve + 512.0 * 1024.0 * 1024.0) as u64, &args);
    assert_eq!(code, Some(0), "{err}");
    let rows = out.lines().filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).count();
    assert_eq!(rows, 8, "{out}");
    let (code, out, err) = limited(reserve as u64, &args);
    assert_eq!(code, Some(1), "{out}{err}");
    for part in [
        "structured:4 has 162 unknowns: solving needs about",
        "of address space the threads reserve whatever the size, counted once per process (per each of",
        "this process's address-space limit (ulimit -v) leaves",
        "this process uses)",
    ] {
        assert!(err.contains(part), "{part}: {err}");
    }
}

/// The exit code of `solve --problem nope` (an error) run by a shell that first applies
/// `redirect` to its stderr and then execs the binary.
fn unwritable_stderr(redirect: &str) -> Option<i32> {
    let bin = env!("CARGO_BIN_EXE_signorini");
    let script = format!("exec {redirect}; exec {bin} solve --problem nope --mesh structured:4");
    Command::new("bash").args(["-c", &script]).output().unwrap().status.code()
}

/// The error message cannot be written (stderr to a file under a file-size limit of 40 bytes,
/// as `prlimit --fsize=40` sets it; a full device; a closed stderr): the exit status is still
/// the error's, 1, not a panic's 101 nor death by SIGXFSZ.
#[test]
fn an_unwritable_stderr_exits_with_the_error_status() {
    let dir = std::env::temp_dir().join(format!("signorini-edges-stderr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("err.txt");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_signorini"));
    cmd.args(["solve", "--problem", "nope", "--mesh", "structured:4"]).stderr(std::fs::File::create(&file).unwrap());
    super::common::limit(&mut cmd, libc::RLIMIT_FSIZE, 40);
    let status = cmd.status().unwrap();
    assert_eq!(status.code(), Some(1), "file-size limit: {status:?}");
    let written = std::fs::read_to_string(&file).unwrap();
    assert!(written.len() <= 40 && written.starts_with("error: "), "{written:?}");
    assert_eq!(unwritable_stderr("2>/dev/full"), Some(1), "/dev/full");
    assert_eq!(unwritable_stderr("2>&-"), Some(1), "closed stderr");
}

/// SIGINT to a running `adapt` (sent after its first level row): it finishes the level it is
/// on, prints it, writes `--save`'s file of the last level kept and exits with 130, naming the
/// level it stopped after; it does not die by the signal.
#[test]
fn interrupted_adapt_stops_after_the_current_level_and_says_what_it_kept() {
    let dir = std::env::temp_dir().join(format!("signorini-edges-sigint-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let save = dir.join("last.vtu");
    let _ = std::fs::remove_file(&save);
    let mut child = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(["adapt", "--problem", "ex72", "--mesh", "structured:8", "--levels", "40", "--save"])
        .arg(&save)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = std::io::BufReader::new(child.stdout.take().unwrap()).lines();
    let mut rows = Vec::new();
    for line in lines.by_ref() {
        let line = line.unwrap();
        if line.trim_start().starts_with(|c: char| c.is_ascii_digit()) {
            rows.push(line);
            break;
        }
    }
    assert_eq!(rows.len(), 1, "no level row before the process ended");
    // SAFETY: a signal to the child this test started
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) }, 0);
    let rest: Vec<String> = lines.map(|l| l.unwrap()).collect();
    let status = child.wait().unwrap();
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    assert_eq!(status.code(), Some(130), "{status:?}: {err}");
    rows.extend(rest.iter().filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).cloned());
    let last: usize = rows.last().unwrap().split_whitespace().next().unwrap().parse().unwrap();
    assert!(last < 39, "the loop was not stopped: {rows:?}");
    assert!(err.contains(&format!("interrupted after level {last}; the table above holds levels 0 to {last}")), "{err}");
    assert!(save.exists() && rest.iter().any(|l| l.contains(&format!("(level {last},"))), "{rest:?}");
}

/// The library's own notes (a study's progress, "finished earlier, kept", drift's lines) cannot
/// stop it either: a study run twice with stderr on a full device computes, then keeps, and
/// exits 0 both times (it exited with a panic's 101 while the library wrote with `eprintln!`).
#[test]
fn a_study_whose_notes_cannot_be_written_still_runs_and_exits_0() {
    let dir = std::env::temp_dir().join(format!("signorini-edges-notes-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let manifest = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tiny.toml");
    let bin = env!("CARGO_BIN_EXE_signorini");
    for pass in ["computes", "keeps"] {
        let script = format!("exec 2>/dev/full; exec {bin} run {} --results {}", manifest.display(), dir.join("res").display());
        let out = Command::new("bash").args(["-c", &script]).output().unwrap();
        assert_eq!(out.status.code(), Some(0), "the run that {pass}: {}", String::from_utf8_lossy(&out.stdout));
    }
    assert!(dir.join("res").read_dir().unwrap().next().is_some(), "the study was stored");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_huge_mesh_is_refused_with_the_memory_estimate_before_allocating() {
    // this used to abort (SIGABRT) allocating 160 GB of vertices
    for mesh in ["structured:100000", "symmetric:100000"] {
        let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", mesh]);
        assert_eq!(code, 1, "{err}");
        assert!(err.contains(mesh) && err.contains("149.0 TiB") && err.contains("available"), "{err}");
        if std::path::Path::new("/proc/meminfo").exists() {
            assert!(err.contains("MemAvailable"), "{err}");
        }
    }
    let (code, _, err) = signorini_in_repo(&["adapt", "--problem", "ex72", "--mesh", "structured:100000"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("needs about"), "{err}");
    let (code, _, err) = signorini_in_repo(&["solve", "--problem", "ex71", "--mesh", "structured:4", "--adapt-min-ndof", "100000000000"]);
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

/// An adaptive loop that outgrows the memory it may use stops before the level that would not
/// fit, with the levels it solved printed and the level it reached named, never an allocation
/// failure (the address space is limited with the shell's `ulimit -v`, in KiB).
#[test]
fn an_adaptive_loop_outgrowing_memory_stops_with_the_level_reached() {
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
