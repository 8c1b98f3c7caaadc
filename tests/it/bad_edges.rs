//! No crash at the edges of the machine: an address-space limit gives a certified answer or the
//! named memory error, never an abort; a stderr that cannot be written gives the error's exit
//! status, not a panic's; an interrupted `adapt` stops after the current level and says what
//! it kept.

use std::io::BufRead;
use std::process::{Command, Stdio};

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
fn bad_address_space_limit_gives_an_answer_or_the_memory_error_never_a_signal() {
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
fn bad_unwritable_stderr_exits_with_the_error_status() {
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
