//! Battery 14, F2: `figures --wait` and `report --wait` waited for the lock a `run` held, then
//! woke in the moment between its commit of one run and its claim of the next, when it holds
//! no lock: they met the next run's lock (exit 1, despite `--wait`) or read the study with its
//! later runs missing (exit 0). A reader given `--wait` now waits until every process it saw
//! writing has ended (`study::store::lock::wait_for_writers`), and reads again, after waiting, where
//! a process starts writing during its read (`make cluster-test` met one: a second array's task).

use super::common::scratch;

/// Three runs one `run` process computes one after the other (each long enough that the
/// readers start during the first).
const STUDY: &str = "description = \"battery 14 F2\"\n[defaults]\nproblem = \"ex71\"\nmesh = \"structured:8\"\nlevels = 17\n[[run]]\nid = \"a\"\n[[run]]\nid = \"b\"\nestimator = { log_factor = \"one\" }\n[[run]]\nid = \"c\"\nestimator = { log_factor = \"linear\" }\n";

#[test]
fn readers_given_wait_wait_for_the_writer_through_all_its_runs() {
    let dir = scratch("b14-wait");
    std::fs::create_dir_all(dir.join("exp")).unwrap();
    std::fs::write(dir.join("exp/w.toml"), STUDY).unwrap();
    let bin = env!("CARGO_BIN_EXE_signorini");
    let spawn = |args: &[&str]| {
        std::process::Command::new(bin)
            .current_dir(&dir)
            .env("SIGNORINI_PROGRESS", "off")
            .args(args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let writer = spawn(&["run", "exp/w.toml", "--results", "res"]);
    // the first run is being computed: its checkpoint is written after its first level
    let checkpoint = dir.join("res/w/.partial/a.json");
    let start = std::time::Instant::now();
    while !checkpoint.exists() {
        assert!(start.elapsed().as_secs() < 120, "{} never appeared", checkpoint.display());
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let readers = [
        spawn(&["figures", "--results", "res", "--experiments", "exp", "--study", "w", "--wait"]),
        spawn(&["report", "--results", "res", "--experiments", "exp", "--study", "w", "--out", "page", "--wait"]),
    ];
    let written = writer.wait_with_output().unwrap();
    assert!(written.status.success(), "{}", String::from_utf8_lossy(&written.stderr));
    for reader in readers {
        let out = reader.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "a reader given --wait was refused: {err}");
        assert!(err.contains("waiting for it to finish") && !err.contains("missing") && !err.contains("incomplete"), "{err}");
    }
    let page = std::fs::read_to_string(dir.join("page/w.html")).unwrap();
    assert!(!page.contains("(missing)"), "the page was drawn from a study still being computed");
    std::fs::remove_dir_all(&dir).ok();
}
