//! Fault injection for the write path, so tests can prove that an
//! interrupted `vista bless` leaves every file old or new. The binary parses
//! `VISTA_FAULT` once and installs the plan; libraries never read it.
//!
//! Plan syntax, comma-separated: `partial:N` (stop the process halfway
//! through writing the N-th file), `before-rename:N` (stop after the N-th
//! temp file is complete and synced, before its rename), `after:N` (stop
//! after the N-th file is in place), `plain` (write files in place, without
//! temp file and rename: the non-atomic writer a test substitutes to show
//! that its consistency check can fail). N counts writes from 1.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Where in a write the process stops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// Halfway through the bytes of the write.
    Partial,
    /// The temp file is complete and synced; not yet renamed.
    BeforeRename,
    /// The file is in place.
    After,
}

/// A parsed `VISTA_FAULT` plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FaultPlan {
    /// Stop at this point of the N-th write (1-based).
    pub stop: Option<(Stop, usize)>,
    /// Write in place instead of temp file + rename.
    pub plain_writer: bool,
}

impl FaultPlan {
    /// Parses the plan; the error names the bad item and the syntax.
    pub fn parse(text: &str) -> Result<FaultPlan, String> {
        let mut plan = FaultPlan::default();
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            if item == "plain" {
                plan.plain_writer = true;
                continue;
            }
            let bad = || {
                format!("VISTA_FAULT item '{item}' is not valid; expected partial:N, before-rename:N, after:N or plain")
            };
            let (what, n) = item.split_once(':').ok_or_else(bad)?;
            let n: usize = n.parse().ok().filter(|n| *n >= 1).ok_or_else(bad)?;
            let stop = match what {
                "partial" => Stop::Partial,
                "before-rename" => Stop::BeforeRename,
                "after" => Stop::After,
                _ => return Err(bad()),
            };
            plan.stop = Some((stop, n));
        }
        Ok(plan)
    }
}

static PLAN: OnceLock<FaultPlan> = OnceLock::new();
static WRITES: AtomicUsize = AtomicUsize::new(0);

/// Installs the plan for this process (once; later calls are ignored).
pub fn install(plan: FaultPlan) {
    let _ = PLAN.set(plan);
}

pub(crate) fn plan() -> FaultPlan {
    PLAN.get().copied().unwrap_or_default()
}

/// Numbers a new write (1-based).
pub(crate) fn next_write() -> usize {
    WRITES.fetch_add(1, Ordering::SeqCst) + 1
}

/// Stops the process if the plan says so for write `n` at `at`.
pub(crate) fn maybe_stop(n: usize, at: Stop, path: &std::path::Path) {
    if plan().stop == Some((at, n)) {
        eprintln!("VISTA_FAULT: stopping at {at:?} of write {n} ({})", path.display());
        std::process::abort();
    }
}
