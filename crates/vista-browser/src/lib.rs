#![deny(missing_docs)]
//! Runs one WGSL compute kernel in headless Chromium's WebGPU: Tint
//! compiles it and Dawn runs it on Chromium's SwiftShader adapter. The
//! browser is driven over the DevTools protocol through
//! `--remote-debugging-pipe` ([`cdp`]); the page side is `runner.js`.
//!
//! The I/O contract is the one vista's wgpu path has: the job's slots (a
//! uniform buffer, a read-only `array<u32>` table, a write-only storage
//! texture of the job's format, each at its own group and binding), the
//! entry point and workgroup count the job names, the output filled with
//! the job's sentinel texel before the kernel, its texel bytes read back.
//!
//! One [`Browser`] holds one Chromium process, reused across runs. Every
//! protocol call has a watchdog; a run that overruns it, a page error or a
//! browser that dies is an error naming the run's label, and the process is
//! dropped (killed) so the next run starts a fresh one.

pub mod cdp;
mod profile;

use std::path::PathBuf;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use base64::Engine;
use base64::engine::general_purpose::STANDARD as B64;
use serde::Deserialize;

use crate::cdp::{CallError, Chromium};

/// Printed when Chromium is missing.
pub const INSTALL_HINT: &str = "install Debian's chromium with `bash ci/install-browser.sh` (or point VISTA_CHROMIUM \
at a Chromium binary); set VISTA_ALLOW_NO_GPU=1 to skip GPU tests loudly";

/// The flags that give headless Chromium a WebGPU adapter on SwiftShader.
pub const WEBGPU_FLAGS: &[&str] = &["--enable-unsafe-webgpu", "--use-webgpu-adapter=swiftshader"];

const RUNNER: &str = include_str!("runner.js");

/// Output bytes fetched per DevTools message (a multiple of 3 and of 16, so
/// each chunk is whole base64 quads and whole texels).
const CHUNK: usize = 3 << 20;

/// Why finding, launching or running the browser failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum BrowserError {
    /// No Chromium binary was found, or `VISTA_CHROMIUM` names no file.
    #[error("no Chromium found ({looked}); {hint}")]
    NotInstalled {
        /// Where the search looked.
        looked: String,
        /// How to install Chromium ([`INSTALL_HINT`]).
        hint: &'static str,
    },
    /// Chromium could not be started, the runner page could not be written
    /// or loaded, or the call to the page's WebGPU init failed.
    #[error("Chromium ({path}) did not start: {message}")]
    Launch {
        /// The Chromium binary.
        path: String,
        /// What failed.
        message: String,
    },
    /// The page's WebGPU init reported an error (e.g. no adapter, or device
    /// creation failed) or an unreadable reply; holds the message.
    #[error("Chromium has no usable WebGPU adapter: {0}")]
    NoWebGpu(String),
    /// The page reported an error (e.g. Tint rejected the WGSL, a WebGPU
    /// validation error), a DevTools call failed, or the reply or its output
    /// bytes were malformed.
    #[error("{case}: in the browser: {message}")]
    Page {
        /// The run's label.
        case: String,
        /// The page's or protocol's error message.
        message: String,
    },
    /// A DevTools call got no answer within the watchdog timeout.
    #[error(
        "{case}: the browser did not answer within {seconds} s (watchdog; raise VISTA_GPU_TIMEOUT_S); Chromium was killed"
    )]
    Timeout {
        /// The run's label.
        case: String,
        /// The watchdog timeout, in seconds.
        seconds: f64,
    },
    /// Chromium or its page's renderer exited, or the DevTools pipe closed.
    #[error("{case}: Chromium died or closed the DevTools connection: {message}")]
    Died {
        /// The run's label.
        case: String,
        /// Why the browser or connection is gone.
        message: String,
    },
}

/// What the page's WebGPU adapter and the browser say about themselves.
#[derive(Debug, Clone, Default, Deserialize)]
pub struct AdapterInfo {
    /// The adapter's `GPUAdapterInfo.vendor`.
    pub vendor: String,
    /// The adapter's `GPUAdapterInfo.architecture`.
    pub architecture: String,
    /// The adapter's `GPUAdapterInfo.device`.
    pub device: String,
    /// The adapter's `GPUAdapterInfo.description`.
    pub description: String,
    /// The page's `navigator.userAgent`.
    pub user_agent: String,
    /// The device's `maxTextureDimension2D` limit, in texels.
    pub max_dimension: u32,
    /// The device's features (the page requests every one the adapter has).
    #[serde(default)]
    pub features: Vec<String>,
    /// The device's limits by WebGPU's names (the page requests the
    /// adapter's).
    #[serde(default)]
    pub limits: std::collections::BTreeMap<String, f64>,
    /// "Chrome/156.0.8078.114" from `Browser.getVersion`.
    #[serde(skip)]
    pub product: String,
}

/// Standard base64, as the page's `fromBase64` reads it (for callers that
/// build a graph job's JSON).
pub fn base64(bytes: &[u8]) -> String {
    B64.encode(bytes)
}

/// A pass graph's outputs as the page read them back (each output's bytes:
/// a texture's texels row-major and unpadded, a buffer whole) and timings.
#[derive(Debug, Clone)]
pub struct Output {
    /// Each output's bytes, in the order of the job's `outputs`.
    pub outputs: Vec<Vec<u8>>,
    /// Wall time of each pass in the page, all its repeats.
    pub passes: Vec<Duration>,
    /// Copy, map and unpad of every output in the page (not the DevTools
    /// transfer).
    pub readback: Duration,
    /// The whole call from Rust, transfer included.
    pub total: Duration,
}

struct Session {
    chromium: Chromium,
}

/// One headless Chromium with a WebGPU device, reused across runs.
pub struct Browser {
    path: PathBuf,
    timeout: Duration,
    session: Mutex<Option<Session>>,
    info: AdapterInfo,
    /// Launch, page load and device creation of the first session.
    pub launch_time: Duration,
}

impl Browser {
    /// Starts Chromium and creates the page's WebGPU device; `timeout` is the
    /// watchdog on every later call.
    pub fn launch(timeout: Duration, config: &BrowserConfig) -> Result<Browser, BrowserError> {
        let start = Instant::now();
        let path = find_chromium(config)?;
        let (session, info) = Session::start(&path, timeout)?;
        Ok(Browser { path, timeout, session: Mutex::new(Some(session)), info, launch_time: start.elapsed() })
    }

    /// Another watchdog for later runs (mutation runs use a short one).
    pub fn set_timeout(&mut self, timeout: Duration) {
        self.timeout = timeout;
    }

    /// What the adapter and browser reported at launch.
    pub fn info(&self) -> &AdapterInfo {
        &self.info
    }

    /// The Chromium binary in use.
    pub fn path(&self) -> &std::path::Path {
        &self.path
    }

    /// Crashes the page's renderer process (chrome://crash), as a broken
    /// driver would, and waits until Chromium reports it: for tests of the
    /// recovery path.
    #[doc(hidden)]
    pub fn crash_page_for_test(&self) {
        let guard = self.session.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(s) = guard.as_ref() {
            s.chromium.crash_page();
            let start = Instant::now();
            while s.chromium.gone().is_none() && start.elapsed() < Duration::from_secs(30) {
                std::thread::sleep(Duration::from_millis(20));
            }
        }
    }

    /// Runs a pass graph (`runner.js`'s `vistaRun`, whose comment gives
    /// the job's shape) and reads every output back. A failure drops the
    /// browser, so one bad case cannot leave a wedged page for the next.
    pub fn run(&self, label: &str, job: &serde_json::Value) -> Result<Output, BrowserError> {
        let start = Instant::now();
        let mut guard = self.session.lock().unwrap_or_else(|p| p.into_inner());
        if guard.is_none() {
            let (session, _) = Session::start(&self.path, self.timeout)?;
            *guard = Some(session);
        }
        let session = guard.as_ref().expect("session just set");
        let result = (|| {
            let reply = session.call(label, &format!("vistaRun({job})"), self.timeout)?;
            #[derive(Deserialize)]
            struct Ran {
                pass_ms: Vec<f64>,
                readback_ms: f64,
                lengths: Vec<usize>,
                bytes: usize,
            }
            let ran: Ran = parse_ok(&reply).map_err(|message| BrowserError::Page { case: label.into(), message })?;
            let bytes = self.fetch(session, label, ran.bytes)?;
            let mut outputs = Vec::new();
            let mut at = 0;
            for n in ran.lengths {
                outputs.push(bytes[at..at + n].to_vec());
                at += n;
            }
            let ms = |v: f64| Duration::from_secs_f64(v.max(0.0) / 1e3);
            Ok(Output {
                outputs,
                passes: ran.pass_ms.into_iter().map(ms).collect(),
                readback: ms(ran.readback_ms),
                total: start.elapsed(),
            })
        })();
        if result.is_err() {
            *guard = None;
        }
        result
    }

    /// The page's last output (`expected` bytes), in chunks.
    fn fetch(&self, s: &Session, label: &str, expected: usize) -> Result<Vec<u8>, BrowserError> {
        let mut bytes = Vec::with_capacity(expected);
        for offset in (0..expected).step_by(CHUNK) {
            let chunk = s.call(label, &format!("vistaChunk({offset}, {CHUNK})"), self.timeout)?;
            let decoded = B64.decode(chunk.as_bytes()).map_err(|e| BrowserError::Page {
                case: label.into(),
                message: format!("output chunk at byte {offset} is not base64: {e}"),
            })?;
            bytes.extend_from_slice(&decoded);
        }
        if bytes.len() != expected {
            return Err(BrowserError::Page {
                case: label.into(),
                message: format!("received {} output bytes, expected {expected}", bytes.len()),
            });
        }
        Ok(bytes)
    }
}

impl Session {
    fn start(path: &std::path::Path, timeout: Duration) -> Result<(Session, AdapterInfo), BrowserError> {
        let launch_err = |message: String| BrowserError::Launch { path: path.display().to_string(), message };
        let timeout = timeout.max(Duration::from_secs(5));
        let chromium = Chromium::launch(path, WEBGPU_FLAGS, timeout).map_err(launch_err)?;
        let product = chromium.version(timeout).unwrap_or_default();
        // WebGPU needs a secure context; a file:// page is one, about:blank
        // and data: URLs are not.
        let page = chromium.profile_dir().join("runner.html");
        std::fs::write(
            &page,
            format!("<!doctype html><meta charset=utf-8><title>vista</title><script>\n{RUNNER}\n</script>"),
        )
        .map_err(|e| launch_err(format!("writing {}: {e}", page.display())))?;
        chromium
            .navigate(&format!("file://{}", page.display()), timeout)
            .map_err(|e| launch_err(format!("loading the runner page: {e}")))?;
        let session = Session { chromium };
        let reply = session.call("WebGPU init", "vistaInit()", timeout).map_err(|e| launch_err(e.to_string()))?;
        let mut info: AdapterInfo = parse_ok(&reply).map_err(BrowserError::NoWebGpu)?;
        info.product = product;
        Ok((session, info))
    }

    /// Evaluates `expr` in the page and returns the string it yields; the
    /// watchdog and a renderer crash end the wait, whatever the page does.
    fn call(&self, label: &str, expr: &str, timeout: Duration) -> Result<String, BrowserError> {
        match self.chromium.evaluate(expr, timeout) {
            Ok(serde_json::Value::String(s)) => Ok(s),
            Ok(other) => Err(BrowserError::Page { case: label.into(), message: format!("the page returned {other}") }),
            Err(CallError::Protocol(message)) => Err(BrowserError::Page { case: label.into(), message }),
            Err(CallError::Timeout) => {
                Err(BrowserError::Timeout { case: label.into(), seconds: timeout.as_secs_f64() })
            }
            Err(CallError::Gone(message)) => Err(BrowserError::Died { case: label.into(), message }),
        }
    }
}

/// The reply of a page function: `{ok: true, ...}` parsed as `T`, or the
/// page's error message.
fn parse_ok<T: serde::de::DeserializeOwned>(reply: &str) -> Result<T, String> {
    let v: serde_json::Value = serde_json::from_str(reply).map_err(|e| format!("unreadable reply ({e}): {reply}"))?;
    if v.get("ok") != Some(&serde_json::Value::Bool(true)) {
        let msg = v.get("error").and_then(|e| e.as_str()).unwrap_or(reply);
        return Err(msg.to_string());
    }
    serde_json::from_value(v).map_err(|e| format!("unexpected reply ({e}): {reply}"))
}

/// Where to look for Chromium, as read once at the edge (the binary or the
/// test harness): this crate reads no environment.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct BrowserConfig {
    /// `VISTA_CHROMIUM`: this binary and no other.
    pub chromium: Option<PathBuf>,
    /// The directories of `PATH`, searched after Debian's binary.
    pub search_path: Vec<PathBuf>,
}

impl BrowserConfig {
    /// From settings looked up by name (the edge passes `std::env::var_os`):
    /// `VISTA_CHROMIUM` and `PATH`.
    pub fn from_lookup(get: &dyn Fn(&str) -> Option<std::ffi::OsString>) -> BrowserConfig {
        BrowserConfig {
            chromium: get("VISTA_CHROMIUM").filter(|p| !p.is_empty()).map(PathBuf::from),
            search_path: get("PATH").map(|p| std::env::split_paths(&p).collect()).unwrap_or_default(),
        }
    }
}

/// The configured binary, else Debian's, else the usual names on the search path.
pub fn find_chromium(config: &BrowserConfig) -> Result<PathBuf, BrowserError> {
    if let Some(p) = config.chromium.as_ref().filter(|p| !p.as_os_str().is_empty()) {
        return if p.is_file() {
            Ok(p.clone())
        } else {
            Err(BrowserError::NotInstalled {
                looked: format!("VISTA_CHROMIUM={} is not a file", p.display()),
                hint: INSTALL_HINT,
            })
        };
    }
    // The binary itself, not Debian's wrapper script, so that killing the
    // process we started kills Chromium.
    let debian = PathBuf::from("/usr/lib/chromium/chromium");
    if debian.is_file() {
        return Ok(debian);
    }
    const NAMES: &[&str] = &["chromium", "chromium-browser", "google-chrome", "google-chrome-stable"];
    for dir in &config.search_path {
        for name in NAMES {
            let p = dir.join(name);
            if p.is_file() {
                return Ok(p);
            }
        }
    }
    Err(BrowserError::NotInstalled {
        looked: format!("/usr/lib/chromium/chromium and {} on PATH", NAMES.join(", ")),
        hint: INSTALL_HINT,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn page_replies_parse_or_name_the_page_error() {
        #[derive(Deserialize, Debug)]
        struct R {
            bytes: usize,
        }
        let ok: R = parse_ok(r#"{"ok":true,"bytes":16}"#).unwrap();
        assert_eq!(ok.bytes, 16);
        let err = parse_ok::<R>(r#"{"ok":false,"error":"Tint rejected the WGSL: line 3:1: x"}"#).unwrap_err();
        assert_eq!(err, "Tint rejected the WGSL: line 3:1: x");
        assert!(parse_ok::<R>("not json").unwrap_err().contains("unreadable reply"));
    }

    #[test]
    fn a_missing_vista_chromium_is_a_clear_error() {
        let config = BrowserConfig { chromium: Some("/nonexistent/chromium".into()), search_path: Vec::new() };
        let e = find_chromium(&config).unwrap_err().to_string();
        assert!(e.contains("VISTA_CHROMIUM=/nonexistent/chromium is not a file"), "{e}");
        assert!(e.contains("ci/install-browser.sh"), "{e}");
    }
}
