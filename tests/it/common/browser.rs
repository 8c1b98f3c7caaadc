//! A page loaded in headless Chromium, asked what a reader would see: whether every image
//! loaded, the page's text, and every console error or uncaught exception.
//!
//! Chromium is driven through the DevTools protocol over `--remote-debugging-pipe` (JSON
//! messages ended by a NUL byte, commands on the child's fd 3, replies and events on its fd 4):
//! no WebDriver, no Node. Written here because the protocol needs a dozen messages, fewer lines
//! than wiring a client crate and its async runtime into a test.

use serde_json::{Value, json};
use std::io::{BufRead, BufReader, Write};
use std::os::fd::AsRawFd;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

/// What the page showed.
#[derive(Debug)]
pub struct PageCheck {
    /// Per `<img>`: its `alt` text (or the start of its `src`), and whether it loaded (complete
    /// with a natural width above 0).
    pub images: Vec<(String, bool)>,
    /// `document.body.innerText`.
    pub text: String,
    /// Console messages of level error, uncaught exceptions and browser log errors.
    pub errors: Vec<String>,
}

/// The Chromium binary: `$CHROMIUM`, else `chromium`, `chromium-browser` or Google Chrome on the PATH.
pub fn chromium() -> Option<String> {
    let candidates = std::env::var("CHROMIUM")
        .into_iter()
        .chain(["chromium", "chromium-browser", "google-chrome", "google-chrome-stable"].map(String::from));
    candidates
        .into_iter()
        .find(|c| Command::new(c).arg("--version").stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok_and(|s| s.success()))
}

struct Browser {
    child: Child,
    commands: std::io::PipeWriter,
    messages: Receiver<Value>,
    next_id: u64,
    /// Events seen while waiting for replies.
    events: Vec<Value>,
}

impl Browser {
    fn start(binary: &str, profile: &Path) -> Browser {
        let (to_child, commands) = std::io::pipe().unwrap();
        let (replies, from_child) = std::io::pipe().unwrap();
        let (fd_in, fd_out) = (to_child.as_raw_fd(), from_child.as_raw_fd());
        let mut cmd = Command::new(binary);
        cmd.args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--remote-debugging-pipe",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
        // SAFETY: only async-signal-safe calls (fcntl, dup2) between fork and exec. The pipes are
        // first copied above fd 10, so that moving one onto 3 cannot close the other.
        unsafe {
            cmd.pre_exec(move || {
                let (a, b) = (libc::fcntl(fd_in, libc::F_DUPFD, 10), libc::fcntl(fd_out, libc::F_DUPFD, 10));
                if a < 0 || b < 0 || libc::dup2(a, 3) < 0 || libc::dup2(b, 4) < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let child = cmd.spawn().expect("start chromium");
        drop((to_child, from_child));
        let (tx, messages) = channel();
        std::thread::spawn(move || {
            let mut reader = BufReader::new(replies);
            let mut buf = Vec::new();
            while reader.read_until(0, &mut buf).is_ok_and(|n| n > 0) {
                buf.pop_if(|b| *b == 0);
                if let Ok(v) = serde_json::from_slice::<Value>(&buf)
                    && tx.send(v).is_err()
                {
                    break;
                }
                buf.clear();
            }
        });
        Browser { child, commands, messages, next_id: 0, events: Vec::new() }
    }

    /// Send a command (to `session` if given) and wait for its reply's `result`.
    fn call(&mut self, session: Option<&str>, method: &str, params: Value) -> Value {
        self.next_id += 1;
        let id = self.next_id;
        let mut msg = json!({ "id": id, "method": method, "params": params });
        if let Some(s) = session {
            msg["sessionId"] = json!(s);
        }
        let mut bytes = serde_json::to_vec(&msg).unwrap();
        bytes.push(0);
        self.commands.write_all(&bytes).expect("write to chromium");
        loop {
            let v = self.next_message(Duration::from_secs(30)).unwrap_or_else(|| panic!("chromium did not answer {method}"));
            if v["id"] == json!(id) {
                assert!(v.get("error").is_none(), "{method}: {}", v["error"]);
                return v["result"].clone();
            }
            self.events.push(v);
        }
    }

    fn next_message(&mut self, timeout: Duration) -> Option<Value> {
        self.messages.recv_timeout(timeout).ok()
    }

    /// Wait until an event `method` arrives (or was seen already).
    fn wait_for(&mut self, method: &str, timeout: Duration) {
        let end = Instant::now() + timeout;
        while !self.events.iter().any(|e| e["method"] == json!(method)) {
            let left = end.saturating_duration_since(Instant::now());
            let v = self.next_message(left).unwrap_or_else(|| panic!("no {method} within {timeout:?}"));
            self.events.push(v);
        }
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Load `page` (a file) in headless Chromium `binary` and report what it showed.
pub fn check_page(binary: &str, page: &Path) -> PageCheck {
    let profile =
        std::env::temp_dir().join(format!("signorini-chromium-{}-{}", std::process::id(), page.file_stem().unwrap().to_string_lossy()));
    let mut b = Browser::start(binary, &profile);
    let target = b.call(None, "Target.createTarget", json!({ "url": "about:blank" }))["targetId"].clone();
    let session =
        b.call(None, "Target.attachToTarget", json!({ "targetId": target, "flatten": true }))["sessionId"].as_str().unwrap().to_string();
    let s = Some(session.as_str());
    for domain in ["Page.enable", "Runtime.enable", "Log.enable"] {
        b.call(s, domain, json!({}));
    }
    let url = format!("file://{}", page.canonicalize().unwrap().display());
    b.call(s, "Page.navigate", json!({ "url": url }));
    b.wait_for("Page.loadEventFired", Duration::from_secs(30));
    let probe = "JSON.stringify({ images: Array.from(document.images).map(i => [i.alt || i.src.slice(0, 60), i.complete && i.naturalWidth > 0]), text: document.body.innerText })";
    let got = b.call(s, "Runtime.evaluate", json!({ "expression": probe, "returnByValue": true }));
    let got: Value = serde_json::from_str(got["result"]["value"].as_str().expect("the probe returns a string")).unwrap();
    // late events (a console error after load) arrive within a moment
    while let Some(v) = b.next_message(Duration::from_millis(300)) {
        b.events.push(v);
    }
    let errors = b.events.iter().filter_map(error_of).collect();
    let images = got["images"].as_array().unwrap().iter().map(|i| (i[0].as_str().unwrap().to_string(), i[1].as_bool().unwrap())).collect();
    let text = got["text"].as_str().unwrap().to_string();
    drop(b);
    let _ = std::fs::remove_dir_all(&profile);
    PageCheck { images, text, errors }
}

/// The text of an event that reports an error: a console message of level error, an uncaught
/// exception, or a browser log entry of level error (e.g. a resource that failed to load).
fn error_of(e: &Value) -> Option<String> {
    let p = &e["params"];
    match e["method"].as_str()? {
        "Runtime.consoleAPICalled" if p["type"] == json!("error") => Some(format!("console.error: {}", p["args"])),
        "Runtime.exceptionThrown" => Some(format!("exception: {}", p["exceptionDetails"])),
        "Log.entryAdded" if p["entry"]["level"] == json!("error") => Some(format!("log: {}", p["entry"]["text"])),
        _ => None,
    }
}
