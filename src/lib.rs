#![deny(missing_docs)]
//! vista: headless GPU compute validation for procedural WGSL kernels.
//!
//! This root package re-exports the workspace crates; its `tests/` hold the
//! golden harness and the kernel test suites, `benches/` the benchmarks.

pub mod config;
pub mod harness;

pub use config::{Config, Flags};
pub use vista_golden as golden;
pub use vista_gpu as gpu;
pub use vista_image as image;
pub use vista_kernels as kernels;
pub use vista_mutate as mutate;
pub use vista_project as project;
pub use vista_render as render;
pub use vista_report as report;
