#![deny(missing_docs)]
//! vista's one check driver, behind `vista check`, `check --matrix`,
//! `vista watch`, `vista mutate` and `vista::harness`: which cases run
//! ([`Pick`], [`select`]); each one checked and filed in the report
//! ([`Checker`]: `vista_golden::check_case` renders, reads the goldens and
//! judges, with the one render-twice rule, [`options`];
//! `vista_report::file_case` writes its folder); the one run loop that
//! checks them in order through a [`Reporter`] and finishes ([`Run`];
//! mutants through the same loop, [`mutants`]); what a run leaves
//! ([`finish`]: the report, `pending.toml`, `results.json`, JUnit) and the
//! goldens no case refers to ([`orphans`]); a run whose cases are checked
//! in processes of their own (cargo-nextest's), each recording its cases
//! and rebuilding the whole report ([`SharedRun`]); and the shards of a
//! split suite joined into one report ([`merge`]).
//!
//! Not for: rendering or judging themselves (`vista-render`,
//! `vista-golden`), page layout (`vista-report`), or flags and printing
//! (the binary and the harness).

mod checker;
mod files;
mod kept;
mod merge;
mod run;
mod select;
mod shared;

pub use checker::{Checker, Filed, interrupt, interrupted, options};
pub use files::{LCOV_FILE, Results, accept_command, coverage_total, finish};
pub use kept::{OUTCOMES_FILE, RUN_DIR};
pub use merge::merge;
pub use run::{Ran, Reporter, Run, in_order, mutants};
pub use select::{Pick, default_report_dir, orphans, select};
pub use shared::{SharedRun, parent_run_id};
