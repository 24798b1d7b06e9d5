//! vista's golden cases: the case file, the golden store and its manifest,
//! render-and-compare with per-case thresholds, bless, and the HTML report.
//!
//! Not for: kernel math (`vista-kernels`) or device handling (`vista-gpu`).
//! This is the only crate that writes goldens, and it writes every file
//! atomically (temp file + rename).

pub mod bless;
pub mod cases;
pub mod check;
pub mod render;
pub mod report;
pub mod store;

pub use bless::{BlessOptions, BlessRow, BlessSummary, bless};
pub use cases::{Case, load_cases, parse_cases, select};
pub use check::{CheckOptions, Outcome, Verdict, check_case};
pub use report::{default_report_dir, write_report};
pub use render::{Rendered, check_request, median, median_wall, quantize16, render, render_median};
pub use store::{Manifest, ManifestEntry, Store};

use vista_gpu::GpuError;
use vista_image::ImageError;

#[derive(Debug, thiserror::Error)]
pub enum GoldenError {
    #[error("{path}: {message}")]
    Cases { path: String, message: String },
    #[error("{0}")]
    BadInput(String),
    #[error("{0}")]
    Refused(String),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Image(#[from] ImageError),
    #[error("{path}: {message}")]
    Io { path: String, message: String },
}

impl GoldenError {
    /// Process exit code: 2 for bad input (the user can fix the command or
    /// files), 1 for failures while running.
    pub fn exit_code(&self) -> i32 {
        match self {
            GoldenError::Cases { .. } | GoldenError::BadInput(_) | GoldenError::Refused(_) => 2,
            GoldenError::Gpu(GpuError::Request(_)) => 2,
            // Unreadable, corrupt or unwritable image paths are the user's to fix.
            GoldenError::Image(_) => 2,
            GoldenError::Io { .. } => 2,
            _ => 1,
        }
    }
}

/// Current UTC time, RFC 3339 to the second (manifest dates).
pub fn now_utc() -> String {
    humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string()
}

/// Short stable hash of a text (params hashes in the manifest).
pub fn short_hash(text: &str) -> String {
    blake3::hash(text.as_bytes()).to_hex()[..16].to_string()
}

/// True when the user set `VISTA_ALLOW_NO_GPU=1`.
pub fn allow_no_gpu() -> bool {
    std::env::var("VISTA_ALLOW_NO_GPU").is_ok_and(|v| v == "1" || v.eq_ignore_ascii_case("true"))
}

/// The shared GPU context for a test. Without an adapter this panics with
/// the install hint, unless `VISTA_ALLOW_NO_GPU=1`, in which case it prints a
/// loud SKIPPED line naming the test and returns `None`.
pub fn gpu_for_test(test: &str) -> Option<&'static vista_gpu::Context> {
    match vista_gpu::Context::shared() {
        Ok(ctx) => Some(ctx),
        Err(e) if allow_no_gpu() => {
            eprintln!("!!! VISTA_ALLOW_NO_GPU=1: SKIPPED GPU test '{test}': {e}");
            None
        }
        Err(e) => panic!("GPU test '{test}' cannot run: {e}"),
    }
}

/// The repository root (two levels above this crate), where `golden/`,
/// `shaders/` and `target/` live.
pub fn repo_root() -> std::path::PathBuf {
    let here = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    here.ancestors().nth(2).unwrap_or(here).to_path_buf()
}
