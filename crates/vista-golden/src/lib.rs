#![deny(missing_docs)]
//! vista's golden cases: the case file, the golden store and its manifest,
//! the verdict (`check::judge`, pure), and bless. Reports are written from
//! its outcomes by `vista-report`.
//!
//! Not for: kernel math (`vista-kernels`), device handling (`vista-gpu`) or
//! rendering (`vista-render`, the one render path, which this crate calls).
//! This is the only crate that writes goldens, and it writes every file
//! atomically (temp file + rename).

pub mod agreement;
pub mod bless;
pub mod cases;
pub mod check;
pub mod outputs;
pub mod pending;
pub mod run;
pub mod selection;
pub mod store;

pub use agreement::{Agreement, agreement};
pub use bless::{BlessOptions, BlessRow, BlessSummary, bless};
pub use cases::{Case, bless_all_command, load_cases, parse_cases, select};
pub use check::{Observed, Outcome, Verdict, changed_files, first_out_of_range, guards, judge};
pub use outputs::{BAD_PIXEL_LIMIT, output_guards, unwritten_problem};
pub use run::{CheckOptions, Checked, check_case, cover_case, run_info};
pub use store::{DriverThreshold, Manifest, ManifestEntry, RunInfo, Store, params_hash};

use vista_gpu::GpuError;
use vista_image::ImageError;

/// Errors of the golden workflow; [`GoldenError::exit_code`] maps each to the
/// process exit code.
#[derive(Debug, thiserror::Error)]
pub enum GoldenError {
    /// The case file, the golden manifest or a report's pending file cannot be
    /// read or parsed, or a case in it is invalid.
    #[error("{path}: {message}")]
    Cases {
        /// The file.
        path: String,
        /// What is wrong with it (for TOML syntax, with the line).
        message: String,
    },
    /// A command-line value, environment variable or input the user can fix is
    /// not valid (a glob that matches no case, a stale pending render, ...).
    #[error("{0}")]
    BadInput(String),
    /// `vista bless` refused to run in CI (`CI=true`) without `--force`.
    #[error("{0}")]
    Refused(String),
    /// A render that a check would fail (exit 1, like the failed check).
    #[error("{0}")]
    Rejected(String),
    /// A GPU error (`vista-gpu`): no adapter, a device failure, a timeout, an
    /// unsupported feature, ...
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// A render failed or its request was refused (`vista-render`).
    #[error(transparent)]
    Render(#[from] vista_render::RenderError),
    /// The project could not be found or its configuration read (`vista-project`).
    #[error(transparent)]
    Project(#[from] vista_project::ProjectError),
    /// An image file could not be read, decoded, encoded or written (`vista-image`).
    #[error(transparent)]
    Image(#[from] ImageError),
    /// A file or directory could not be read, created, written or removed.
    #[error("{path}: {message}")]
    Io {
        /// The path.
        path: String,
        /// What went wrong.
        message: String,
    },
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
            GoldenError::Project(_) => 2,
            GoldenError::Render(e) => e.exit_code(),
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
    short_hash_bytes(text.as_bytes())
}

/// Short stable hash of bytes (golden file hashes in the manifest).
pub fn short_hash_bytes(bytes: &[u8]) -> String {
    blake3::hash(bytes).to_hex()[..16].to_string()
}
