//! A minimal Chrome DevTools Protocol client over `--remote-debugging-pipe`:
//! Chromium reads commands from fd 3 and writes replies and events to fd 4,
//! each a JSON object ending in a NUL byte. One browser process, one page
//! (a target attached in flat mode); every call has a deadline, and a
//! crashed or closed page ends every wait at once.

use std::collections::HashMap;
use std::io::{BufRead, BufReader, Write};
use std::os::fd::AsRawFd;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

/// Why a call did not return a result.
#[derive(Debug, Clone, PartialEq)]
pub enum CallError {
    /// The protocol answered with an error.
    Protocol(String),
    /// No answer before the deadline.
    Timeout,
    /// The page's renderer crashed, or Chromium closed the pipe.
    Gone(String),
}

impl std::fmt::Display for CallError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CallError::Protocol(m) => write!(f, "DevTools error: {m}"),
            CallError::Timeout => write!(f, "no answer before the deadline"),
            CallError::Gone(m) => write!(f, "{m}"),
        }
    }
}

type Waiters = Arc<Mutex<HashMap<u64, mpsc::Sender<Value>>>>;

/// State the reader thread shares with callers.
#[derive(Default)]
struct Shared {
    /// Set when the page's renderer goes (crash or detach) or the pipe closes.
    gone: Mutex<Option<String>>,
    loads: AtomicU64,
    /// Console errors, uncaught exceptions and error log entries, in order.
    errors: Mutex<Vec<String>>,
}

/// One Chromium process with one page.
pub struct Chromium {
    child: Child,
    to_browser: Mutex<std::io::PipeWriter>,
    waiters: Waiters,
    shared: Arc<Shared>,
    next_id: AtomicU64,
    session: String,
    profile: tempfile::TempDir,
}

impl Chromium {
    /// Starts headless Chromium with `flags` and attaches to a new blank page.
    pub fn launch(path: &Path, flags: &[&str], timeout: Duration) -> Result<Chromium, String> {
        let profile = crate::profile::create().map_err(|e| format!("profile dir: {e}"))?;
        let (from_us, to_browser) = std::io::pipe().map_err(|e| format!("pipe: {e}"))?;
        let (from_browser, to_us) = std::io::pipe().map_err(|e| format!("pipe: {e}"))?;
        let (read_fd, write_fd) = (from_us.as_raw_fd(), to_us.as_raw_fd());
        let mut cmd = Command::new(path);
        cmd.args([
            "--headless",
            "--remote-debugging-pipe",
            // Chromium's sandbox needs user namespaces that containers and
            // root CI runners lack; the pages are vista's own.
            "--no-sandbox",
            "--no-first-run",
            "--no-default-browser-check",
            "--disable-background-networking",
            "--disable-extensions",
            "--disable-sync",
            "--mute-audio",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(flags)
        .arg("about:blank")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        // Its own group, so that its helper processes end with it.
        .process_group(0);
        // SAFETY: between fork and exec only async-signal-safe fcntl/dup2
        // calls, putting the pipe ends where --remote-debugging-pipe expects
        // them. Both are first copied above fd 9, so that neither target is
        // one of the sources; dup2 onto 3 and 4 clears close-on-exec.
        unsafe {
            cmd.pre_exec(move || {
                let r = libc::fcntl(read_fd, libc::F_DUPFD_CLOEXEC, 10);
                let w = libc::fcntl(write_fd, libc::F_DUPFD_CLOEXEC, 10);
                if r < 0 || w < 0 || libc::dup2(r, 3) < 0 || libc::dup2(w, 4) < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let child = cmd.spawn().map_err(|e| format!("cannot start {}: {e}", path.display()))?;
        crate::profile::started(child.id(), profile.path());
        drop((from_us, to_us));
        let waiters: Waiters = Arc::default();
        let shared = Arc::new(Shared::default());
        spawn_reader(from_browser, waiters.clone(), shared.clone());
        let mut chromium = Chromium {
            child,
            to_browser: Mutex::new(to_browser),
            waiters,
            shared,
            next_id: AtomicU64::new(1),
            session: String::new(),
            profile,
        };
        let target = chromium
            .call_browser("Target.createTarget", json!({ "url": "about:blank" }), timeout)
            .map_err(|e| format!("Target.createTarget: {e}"))?;
        let target_id = target["targetId"].as_str().unwrap_or_default().to_string();
        let attached = chromium
            .call_browser("Target.attachToTarget", json!({ "targetId": target_id, "flatten": true }), timeout)
            .map_err(|e| format!("Target.attachToTarget: {e}"))?;
        chromium.session = attached["sessionId"].as_str().unwrap_or_default().to_string();
        for domain in ["Page.enable", "Runtime.enable", "Inspector.enable", "Log.enable"] {
            chromium.call(domain, json!({}), timeout).map_err(|e| format!("{domain}: {e}"))?;
        }
        Ok(chromium)
    }

    /// This browser's profile folder, removed with it.
    pub fn profile_dir(&self) -> &Path {
        self.profile.path()
    }

    /// A command to the attached page.
    pub fn call(&self, method: &str, params: Value, timeout: Duration) -> Result<Value, CallError> {
        self.send(method, params, Some(&self.session), timeout)
    }

    fn call_browser(&self, method: &str, params: Value, timeout: Duration) -> Result<Value, CallError> {
        self.send(method, params, None, timeout)
    }

    fn send(&self, method: &str, params: Value, session: Option<&str>, timeout: Duration) -> Result<Value, CallError> {
        if let Some(why) = self.gone() {
            return Err(CallError::Gone(why));
        }
        let id = self.next_id.fetch_add(1, Ordering::SeqCst);
        let mut msg = json!({ "id": id, "method": method, "params": params });
        if let Some(s) = session {
            msg["sessionId"] = json!(s);
        }
        let (tx, rx) = mpsc::channel();
        self.waiters.lock().expect("waiters").insert(id, tx);
        let mut bytes = serde_json::to_vec(&msg).expect("a JSON value serialises");
        bytes.push(0);
        if let Err(e) = self.to_browser.lock().expect("pipe").write_all(&bytes) {
            self.waiters.lock().expect("waiters").remove(&id);
            return Err(CallError::Gone(format!("Chromium closed the DevTools pipe ({e})")));
        }
        let start = Instant::now();
        let result = loop {
            match rx.recv_timeout(Duration::from_millis(20)) {
                Ok(reply) => break Ok(reply),
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    break Err(CallError::Gone(
                        self.gone().unwrap_or_else(|| "Chromium closed the DevTools pipe".into()),
                    ));
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {}
            }
            if let Some(why) = self.gone() {
                break Err(CallError::Gone(why));
            }
            if start.elapsed() >= timeout {
                break Err(CallError::Timeout);
            }
        };
        self.waiters.lock().expect("waiters").remove(&id);
        let reply = result?;
        if let Some(e) = reply.get("error") {
            return Err(CallError::Protocol(e["message"].as_str().unwrap_or("unknown").to_string()));
        }
        Ok(reply.get("result").cloned().unwrap_or(Value::Null))
    }

    /// The browser's product string, "Chrome/156.0.8078.114".
    pub fn version(&self, timeout: Duration) -> Result<String, CallError> {
        let r = self.call_browser("Browser.getVersion", json!({}), timeout)?;
        Ok(r["product"].as_str().unwrap_or_default().to_string())
    }

    /// Why the page can no longer answer, if it cannot.
    pub fn gone(&self) -> Option<String> {
        self.shared.gone.lock().expect("gone").clone()
    }

    /// Loads `url` and waits for its load event.
    pub fn navigate(&self, url: &str, timeout: Duration) -> Result<(), CallError> {
        let before = self.shared.loads.load(Ordering::SeqCst);
        let r = self.call("Page.navigate", json!({ "url": url }), timeout)?;
        if let Some(e) = r.get("errorText").and_then(Value::as_str) {
            return Err(CallError::Protocol(format!("navigating to {url}: {e}")));
        }
        let start = Instant::now();
        while self.shared.loads.load(Ordering::SeqCst) == before {
            if let Some(why) = self.gone() {
                return Err(CallError::Gone(why));
            }
            if start.elapsed() >= timeout {
                return Err(CallError::Timeout);
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        Ok(())
    }

    /// Evaluates `expr` in the page (awaiting a promise) and returns its
    /// value; an exception thrown by the page is a protocol error.
    pub fn evaluate(&self, expr: &str, timeout: Duration) -> Result<Value, CallError> {
        let r = self.call(
            "Runtime.evaluate",
            json!({ "expression": expr, "awaitPromise": true, "returnByValue": true }),
            timeout,
        )?;
        if let Some(x) = r.get("exceptionDetails") {
            let text = x["exception"]["description"].as_str().or(x["text"].as_str()).unwrap_or("exception");
            return Err(CallError::Protocol(format!("the page threw: {text}")));
        }
        Ok(r["result"].get("value").cloned().unwrap_or(Value::Null))
    }

    /// A PNG of the page's viewport.
    pub fn screenshot(&self, timeout: Duration) -> Result<Vec<u8>, CallError> {
        use base64::Engine;
        let r = self.call("Page.captureScreenshot", json!({ "format": "png" }), timeout)?;
        base64::engine::general_purpose::STANDARD
            .decode(r["data"].as_str().unwrap_or_default())
            .map_err(|e| CallError::Protocol(format!("screenshot is not base64: {e}")))
    }

    /// Console errors, uncaught exceptions and error log entries so far.
    pub fn errors(&self) -> Vec<String> {
        self.shared.errors.lock().expect("errors").clone()
    }

    /// Sends a key press (keyDown + keyUp) of a printable character.
    pub fn press(&self, key: &str, timeout: Duration) -> Result<(), CallError> {
        for kind in ["keyDown", "keyUp"] {
            let text = if kind == "keyDown" { key } else { "" };
            self.call("Input.dispatchKeyEvent", json!({ "type": kind, "key": key, "text": text }), timeout)?;
        }
        Ok(())
    }

    /// Crashes the page's renderer (chrome://crash), as a broken driver would.
    pub fn crash_page(&self) {
        let _ = self.call("Page.navigate", json!({ "url": "chrome://crash" }), Duration::from_millis(200));
    }
}

impl Drop for Chromium {
    fn drop(&mut self) {
        // Killing its group ends the renderer and GPU processes too.
        crate::profile::kill_group(self.child.id());
        let _ = self.child.wait();
        crate::profile::ended(self.child.id(), self.profile.path());
    }
}

fn spawn_reader(from_browser: std::io::PipeReader, waiters: Waiters, shared: Arc<Shared>) {
    std::thread::spawn(move || {
        let mut reader = BufReader::new(from_browser);
        let mut buf = Vec::new();
        loop {
            buf.clear();
            match reader.read_until(0, &mut buf) {
                Ok(0) | Err(_) => break,
                Ok(_) => {}
            }
            if buf.last() == Some(&0) {
                buf.pop();
            }
            let Ok(msg) = serde_json::from_slice::<Value>(&buf) else { continue };
            if let Some(id) = msg.get("id").and_then(Value::as_u64) {
                if let Some(tx) = waiters.lock().expect("waiters").remove(&id) {
                    let _ = tx.send(msg);
                }
                continue;
            }
            event(&msg, &shared);
        }
        shared.gone.lock().expect("gone").get_or_insert_with(|| "Chromium closed the DevTools pipe".into());
        // Dropping the senders wakes every waiting call.
        waiters.lock().expect("waiters").clear();
    });
}

fn event(msg: &Value, shared: &Shared) {
    let p = &msg["params"];
    match msg["method"].as_str().unwrap_or_default() {
        "Page.loadEventFired" => {
            shared.loads.fetch_add(1, Ordering::SeqCst);
        }
        "Inspector.targetCrashed" => {
            *shared.gone.lock().expect("gone") = Some("the page's renderer process crashed".into());
        }
        "Inspector.detached" => {
            let why = p["reason"].as_str().unwrap_or("detached");
            *shared.gone.lock().expect("gone") = Some(format!("the page is gone ({why})"));
        }
        "Runtime.exceptionThrown" => {
            let d = &p["exceptionDetails"];
            let text = d["exception"]["description"].as_str().or(d["text"].as_str()).unwrap_or("exception");
            shared.errors.lock().expect("errors").push(format!("uncaught: {text}"));
        }
        "Runtime.consoleAPICalled" if p["type"] == "error" => {
            let args: Vec<String> = p["args"]
                .as_array()
                .map(|a| a.iter().map(|v| v.get("value").map(Value::to_string).unwrap_or_default()).collect())
                .unwrap_or_default();
            shared.errors.lock().expect("errors").push(format!("console.error: {}", args.join(" ")));
        }
        "Log.entryAdded" if p["entry"]["level"] == "error" => {
            let text = p["entry"]["text"].as_str().unwrap_or_default();
            shared.errors.lock().expect("errors").push(format!("log: {text}"));
        }
        _ => {}
    }
}
