//! One case checked and filed ([`Checker::check`]): `vista_golden::check_case`
//! renders, reads the goldens and judges, with the one render-twice rule
//! ([`options`]); `vista_report::file_case` writes its folder. And the
//! interrupt every run loop obeys ([`interrupt`]).

use std::path::Path;
use std::time::{Duration, Instant};

use vista_golden::{Case, CheckOptions, Manifest, ManifestEntry, Outcome, Store, Verdict};
use vista_render::Renderer;
use vista_report::Detail;

/// The one render-twice rule: the in-process determinism check (two
/// renders, bit-identical) runs on the default backend, lavapipe, where
/// goldens are blessed (and only where the render is not the bless-time
/// bits: `CheckOptions::twice`); other backends render once. A passing
/// case's golden images are read only for a report that shows it in full.
pub fn options(ctx: &Renderer, detail: Detail) -> CheckOptions {
    CheckOptions { twice: ctx.backend() == "lavapipe", images_of_passing: detail == Detail::All }
}

/// One case checked and filed in the report folder.
#[derive(Debug, Clone)]
pub struct Filed {
    /// The verdict as the report has it.
    pub outcome: Outcome,
    /// For a failing or missing case, the manifest entry `vista bless
    /// --from-report` would write from the render the report keeps.
    pub pending: Option<ManifestEntry>,
    /// Rendering, reading and judging.
    pub check_time: Duration,
    /// Writing the case's report folder.
    pub report_time: Duration,
    /// What of the case's report folder could not be written: the run
    /// fails (exit 2), the verdict stays as judged.
    pub report_errors: Vec<String>,
}

/// What checking a case reads and where it files it.
pub struct Checker<'a> {
    /// The device and the project's shaders.
    pub ctx: &'a Renderer<'a>,
    /// The goldens.
    pub store: &'a Store,
    /// Their provenance.
    pub manifest: &'a Manifest,
    /// The report folder each case is filed in.
    pub report_dir: &'a Path,
    /// Which cases get 16-bit images and the pixel viewer.
    pub detail: Detail,
    /// Each case also runs with coverage counters (`check --coverage`),
    /// after its judged render, which the counters never touch.
    pub coverage: bool,
}

impl Checker<'_> {
    /// Checks `case` (render, goldens, verdict) and writes its report folder.
    pub fn check(&self, case: &Case) -> Filed {
        let started = Instant::now();
        let mut checked =
            vista_golden::check_case(self.ctx, self.store, self.manifest, case, &options(self.ctx, self.detail));
        if self.coverage {
            checked.outcome.coverage = Some(self.cover(case));
        }
        let check_time = started.elapsed();
        let golden = self.store.dir.join(&checked.outcome.golden_file);
        checked.outcome.files.golden_href = Some(vista_report::href(self.report_dir, &golden));
        let entry = checked.pending.take();
        let started = Instant::now();
        let (outcome, report_errors) = vista_report::file_case(self.report_dir, checked, self.detail);
        let report_time = started.elapsed();
        vista_image::release_after_case(u64::from(outcome.width) * u64::from(outcome.height));
        // A failing or missing case's render, as bless --from-report may take it.
        let pending = match entry {
            Some(mut entry) if matches!(outcome.verdict, Verdict::Fail | Verdict::Missing) => {
                // A graph whose first output is a buffer has no main PNG.
                let png = match outcome.files.actual {
                    Some(_) => std::fs::read(vista_golden::pending::pending_png(self.report_dir, &outcome.id))
                        .ok()
                        .map(|bytes| vista_golden::short_hash_bytes(&bytes)),
                    None => Some(String::new()),
                };
                png.map(|hash| {
                    entry.golden_hash = hash;
                    entry
                })
            }
            _ => None,
        };
        Filed { outcome, pending, check_time, report_time, report_errors }
    }

    /// `case`'s coverage run as LCOV, or why it was not measured.
    fn cover(&self, case: &Case) -> Result<String, String> {
        match vista_golden::cover_case(self.ctx, case) {
            Ok(c) if c.not_measured.is_empty() => Ok(c.counts.lcov(&case.id)),
            Ok(c) => Err(c.not_measured.join("; ")),
            Err(e) => Err(format!("the coverage run failed: {e}")),
        }
    }

    /// How many of `requested` workers check `cases` cases at once: 1 under
    /// the validation layer, whose messages are process-wide, so each is
    /// attributed to the dispatch that caused it; never more than the cases.
    pub fn jobs(&self, requested: usize, cases: usize) -> usize {
        if self.ctx.validating() { 1 } else { requested.clamp(1, cases.max(1)) }
    }
}

/// Set by [`interrupt`] (the binary's SIGINT handler): runs stop starting
/// cases and write the report of those that finished.
static INTERRUPTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Marks the process interrupted; only an atomic store, so a signal
/// handler may call it.
pub fn interrupt() {
    INTERRUPTED.store(true, std::sync::atomic::Ordering::SeqCst);
}

/// Whether [`interrupt`] was called.
pub fn interrupted() -> bool {
    INTERRUPTED.load(std::sync::atomic::Ordering::SeqCst)
}
