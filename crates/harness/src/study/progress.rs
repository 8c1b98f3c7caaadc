//! Progress of the long steps (a run's levels, a reference solution): a bar on a terminal, and
//! where standard error is not one (a CI log, a file) plain lines, one at most every
//! [`PLAIN_EVERY`], so that no step is silent for long. Each line says where the step is (level,
//! unknowns, how many levels are left where that is known) and how long it has taken.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The longest a plain-line progress stays silent while its step reports.
pub const PLAIN_EVERY: Duration = Duration::from_secs(10);

/// The environment variable that turns every progress display off: `SIGNORINI_PROGRESS=off`.
/// Progress lines depend on time (a step slower than [`PLAIN_EVERY`] prints one), so output
/// compared line by line (the documentation's commands, `tests/it/doc_commands.rs`) is taken
/// without them; a log that wants only results does the same. Any other value (or none): shown.
pub const PROGRESS_ENV: &str = "SIGNORINI_PROGRESS";

/// Whether [`PROGRESS_ENV`] turns progress off, read once per process.
fn switched_off() -> bool {
    static OFF: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *OFF.get_or_init(|| std::env::var(PROGRESS_ENV).is_ok_and(|v| v == "off"))
}

/// A progress display: hidden, a bar, or plain lines (with a heartbeat: a step that reports
/// nothing for [`PLAIN_EVERY`], one long solve, still prints a line saying it is at work).
pub struct Progress {
    bar: ProgressBar,
    plain: Option<Arc<Mutex<Plain>>>,
    heartbeat: Mutex<Option<Heartbeat>>,
}

/// The thread that prints a plain line when the step has been silent for [`PLAIN_EVERY`];
/// stopped (and joined) when the progress is finished or dropped.
struct Heartbeat {
    stop: std::sync::mpsc::Sender<()>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Drop for Heartbeat {
    fn drop(&mut self) {
        let _ = self.stop.send(());
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

struct Plain {
    prefix: String,
    len: u64,
    pos: u64,
    started: Instant,
    last: Instant,
    /// The step's latest report (what the heartbeat repeats).
    msg: Option<String>,
}

impl Plain {
    /// Print where the step is now, and remember when.
    fn print(&mut self) {
        self.last = Instant::now();
        let left =
            if self.len > 0 { format!(", {} of {} levels left", self.len.saturating_sub(self.pos), self.len) } else { String::new() };
        let msg = self.msg.as_deref().unwrap_or("at work");
        // a progress line that cannot be written is no reason to stop the computation
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "{}: {msg}{left} [{:.0} s]", self.prefix, self.started.elapsed().as_secs_f64());
    }
}

impl Progress {
    /// `len` steps (0: unknown, a spinner) under `prefix`; nothing at all unless `progress`.
    pub fn new(progress: bool, len: u64, prefix: &str) -> Progress {
        if !progress || switched_off() {
            return Progress { bar: ProgressBar::hidden(), plain: None, heartbeat: Mutex::new(None) };
        }
        if !std::io::stderr().is_terminal() {
            let now = Instant::now();
            let plain = Arc::new(Mutex::new(Plain { prefix: prefix.to_string(), len, pos: 0, started: now, last: now, msg: None }));
            let heartbeat = Heartbeat::start(plain.clone());
            return Progress { bar: ProgressBar::hidden(), plain: Some(plain), heartbeat: Mutex::new(Some(heartbeat)) };
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
        // drawn through the process's one display: a bar of another study's run takes its own line
        let bar = model::base::note::bars().add(bar);
        bar.enable_steady_tick(Duration::from_millis(200));
        Progress { bar, plain: None, heartbeat: Mutex::new(None) }
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
        p.msg = Some(msg);
        if p.last.elapsed() >= PLAIN_EVERY {
            p.print();
        }
    }

    pub fn finish(&self) {
        drop(self.heartbeat.lock().unwrap_or_else(|e| e.into_inner()).take());
        self.bar.finish_and_clear();
        model::base::note::bars().remove(&self.bar);
    }
}

/// A step that ends by an error or an interruption takes its bar off the display too.
impl Drop for Progress {
    fn drop(&mut self) {
        self.finish();
    }
}

impl Heartbeat {
    fn start(plain: Arc<Mutex<Plain>>) -> Heartbeat {
        let (stop, stopped) = std::sync::mpsc::channel::<()>();
        let thread = std::thread::spawn(move || {
            loop {
                let wait = PLAIN_EVERY.saturating_sub(plain.lock().expect("progress").last.elapsed());
                match stopped.recv_timeout(wait.max(Duration::from_millis(100))) {
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
                    _ => return,
                }
                let mut p = plain.lock().expect("progress");
                if p.last.elapsed() >= PLAIN_EVERY {
                    p.print();
                }
            }
        });
        Heartbeat { stop, thread: Some(thread) }
    }
}
