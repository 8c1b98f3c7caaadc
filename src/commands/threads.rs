//! The solver's threads: rayon's global pool, built once at startup from `--jobs` or
//! `RAYON_NUM_THREADS`, refused where it would only add overhead or cannot start.

use anyhow::{Result, bail};

/// How many times the cores available to this process `RAYON_NUM_THREADS` may ask for: more
/// only adds overhead (the results do not depend on the thread count), and thousands of threads
/// make a tiny solve take minutes (20000 threads take a 162-unknown solve past 100 s, where 2
/// threads take 3 ms).
pub const MAX_THREADS_PER_CORE: usize = 8;

/// Build rayon's global pool once, at startup, before anything uses it: `--jobs J` of `run`
/// ([`threads`]), else `RAYON_NUM_THREADS` as rayon reads it (a positive integer; anything else
/// means one thread per core, and a note on standard error says so: [`rayon_threads`]), refused
/// above [`MAX_THREADS_PER_CORE`] times the cores. Built lazily, a pool that cannot start its
/// threads (an address-space limit, a process limit) would make the first parallel call panic
/// (`RAYON_NUM_THREADS=2000` under `prlimit --as=4e9`); built here, the failure is an error
/// naming where the thread count came from.
pub fn start_threads(jobs: Option<usize>) -> Result<()> {
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let env = rayon_threads(jobs.is_none(), cores);
    let (builder, from) = match (jobs, env) {
        (Some(j), _) => {
            let n = threads(j)?;
            (rayon::ThreadPoolBuilder::new().num_threads(n), format!("--jobs {j} ({n} threads)"))
        }
        (None, Some(n)) if n > MAX_THREADS_PER_CORE * cores => bail!(
            "RAYON_NUM_THREADS={n} is more than {MAX_THREADS_PER_CORE} times the {cores} core(s) available to this process: the results do not depend on the thread count, and thousands of threads on a few cores only add overhead (a tiny solve can take minutes). Nothing was computed; set it to at most {} or unset it (one thread per core)",
            MAX_THREADS_PER_CORE * cores
        ),
        (None, Some(n)) => (rayon::ThreadPoolBuilder::new().num_threads(n), format!("RAYON_NUM_THREADS={n}")),
        (None, None) => (rayon::ThreadPoolBuilder::new(), format!("one thread per core ({cores})")),
    };
    builder.build_global().map_err(|e| {
        anyhow::anyhow!(
            "starting the solver's threads ({from}) failed: {e}. An address-space limit (ulimit -v) or a limit on processes (ulimit -u) can stop threads from starting; nothing was computed. Ask for fewer threads (RAYON_NUM_THREADS, at least 1) or raise the limit"
        )
    })
}

/// `RAYON_NUM_THREADS` if it is a positive integer. Any other value set means one thread per
/// core, as rayon reads it; where it decides (`noted`: no `--jobs`), a one-line note says what
/// was given and what is used instead of ignoring it without a word.
fn rayon_threads(noted: bool, cores: usize) -> Option<usize> {
    let given = std::env::var_os("RAYON_NUM_THREADS")?;
    let n = given.to_str().and_then(|v| v.trim().parse::<usize>().ok()).filter(|&n| n > 0);
    if n.is_none() && noted {
        note!(
            "note: RAYON_NUM_THREADS={:?} is not a positive integer; using one thread per core ({cores}), as when it is unset",
            given.to_string_lossy()
        );
    }
    n
}

/// The thread count for `--jobs J`: at least 1; more than the cores available to this process
/// is reduced to them with a note (results do not depend on it, and a pool of thousands of
/// threads on a few cores only adds overhead; refusing would break a script that passes the
/// machine's nominal core count where a container allows fewer).
fn threads(jobs: usize) -> Result<usize> {
    if jobs == 0 {
        bail!("--jobs must be at least 1");
    }
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    if jobs > cores {
        note!(
            "note: --jobs {jobs} is more than the {cores} core(s) available to this process; using {cores} (the results do not depend on the thread count; more threads than cores only add overhead)"
        );
    }
    Ok(jobs.min(cores))
}
