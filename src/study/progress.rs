//! Progress of the long steps (a run's levels, a reference solution): a bar on a terminal, and
//! where standard error is not one (a CI log, a file) plain lines, one at most every
//! [`PLAIN_EVERY`], so that no step is silent for long. Each line says where the step is (level,
//! unknowns, how many levels are left where that is known) and how long it has taken.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The longest a plain-line progress stays silent while its step reports.
pub const PLAIN_EVERY: Duration = Duration::from_secs(10);

/// A progress display: hidden, a bar, or plain lines.
pub struct Progress {
    bar: ProgressBar,
    plain: Option<Mutex<Plain>>,
}

struct Plain {
    prefix: String,
    len: u64,
    pos: u64,
    started: Instant,
    last: Instant,
}

impl Progress {
    /// `len` steps (0: unknown, a spinner) under `prefix`; nothing at all unless `progress`.
    pub fn new(progress: bool, len: u64, prefix: &str) -> Progress {
        if !progress {
            return Progress { bar: ProgressBar::hidden(), plain: None };
        }
        if !std::io::stderr().is_terminal() {
            let now = Instant::now();
            let plain = Plain { prefix: prefix.to_string(), len, pos: 0, started: now, last: now };
            return Progress { bar: ProgressBar::hidden(), plain: Some(Mutex::new(plain)) };
        }
        let bar = if len == 0 { ProgressBar::new_spinner() } else { ProgressBar::new(len) };
        let style = if len == 0 {
            ProgressStyle::with_template("{spinner} {prefix} {msg} [{elapsed}]").expect("valid template")
        } else {
            ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} {msg} [{elapsed}, about {eta} left]")
                .expect("valid template")
                .progress_chars("=> ")
        };
        bar.set_style(style);
        bar.set_prefix(prefix.to_string());
        bar.enable_steady_tick(Duration::from_millis(200));
        Progress { bar, plain: None }
    }

    /// `n` more steps done.
    pub fn inc(&self, n: u64) {
        self.bar.inc(n);
        if let Some(p) = &self.plain {
            p.lock().expect("progress").pos += n;
        }
    }

    /// Where the step is now; a plain line if the last one is [`PLAIN_EVERY`] old.
    pub fn message(&self, msg: String) {
        let Some(p) = &self.plain else {
            self.bar.set_message(msg);
            return;
        };
        let mut p = p.lock().expect("progress");
        if p.last.elapsed() < PLAIN_EVERY {
            return;
        }
        p.last = Instant::now();
        let left = if p.len > 0 { format!(", {} of {} levels left", p.len.saturating_sub(p.pos), p.len) } else { String::new() };
        // a progress line that cannot be written is no reason to stop the computation
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "{}: {msg}{left} [{:.0} s]", p.prefix, p.started.elapsed().as_secs_f64());
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
