#![deny(missing_docs)]
//! vista's one check driver, behind `vista check`, `check --matrix`,
//! `vista watch` and `vista::harness`: which cases run ([`Pick`],
//! [`select`]), each one checked and filed in the report ([`Checker`]:
//! `vista_golden::check_case` renders, reads the goldens and judges, with
//! the one render-twice rule, [`options`]; `vista_report::file_case`
//! writes its folder), then what a run
//! leaves ([`finish`]: the report, `pending.toml`, `results.json`, JUnit)
//! and the goldens no case refers to ([`orphans`]); a run whose cases are
//! checked in processes of their own (cargo-nextest's), each recording its
//! cases and rebuilding the whole report ([`SharedRun`]); and the shards of
//! a split suite joined into one report ([`merge`]). `vista mutate` judges
//! every mutant with the same `vista_golden::check_case`.
//!
//! Not for: rendering or judging themselves (`vista-render`,
//! `vista-golden`), page layout (`vista-report`), or flags and printing
//! (the binary and the harness).

mod merge;
mod shared;

pub use merge::{OUTCOMES_FILE, merge};
pub use shared::{RUN_DIR, SharedRun, parent_run_id};

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use vista_golden::{Case, CheckOptions, GoldenError, Manifest, ManifestEntry, Outcome, Store, Verdict};
use vista_project::Project;
use vista_render::Renderer;
use vista_report::{Detail, RunSummary};

/// Which cases a check runs: `glob` (`--case`), then `--changed`,
/// `--failed` and `--partition`, each narrowing the one before.
#[derive(Debug, Clone, Default)]
pub struct Pick {
    /// Only cases whose id matches this glob.
    pub glob: Option<String>,
    /// Only cases whose params, WGSL or golden changed since the last bless.
    pub changed: bool,
    /// Only cases that failed in the last report.
    pub failed: bool,
    /// Only partition K of N (1-based).
    pub partition: Option<(u64, u64)>,
}

/// The cases `pick` selects from `cases`, and when it narrowed by more than
/// the glob, the line saying so (`selected 3 of 77 cases (--changed)`).
/// Needs no device: hashes from the project's WGSL, the last report in
/// `report_dir`.
pub fn select<'c>(
    project: &Project,
    cases: &'c [Case],
    manifest: &Manifest,
    pick: &Pick,
    report_dir: &Path,
) -> Result<(Vec<&'c Case>, Option<String>), GoldenError> {
    let mut picked = vista_golden::select(cases, pick.glob.as_deref())?;
    let all = picked.len();
    let mut why: Vec<String> = Vec::new();
    if pick.changed {
        let shaders = vista_render::shader_set(project)?;
        picked.retain(|c| {
            // Every file any pass reaches, as the manifest records them.
            let mut files = BTreeMap::new();
            for f in c.kernel.shader_units() {
                files.extend(shaders.file_hashes(&f).unwrap_or_default());
            }
            vista_golden::selection::change(c, manifest, &files).is_some()
        });
        why.push("--changed".into());
    }
    if pick.failed {
        let failures = vista_golden::selection::last_failures(report_dir)?;
        picked.retain(|c| failures.contains(&c.id));
        why.push("--failed".into());
    }
    if let Some(part) = pick.partition {
        picked.retain(|c| vista_golden::selection::in_partition(&c.id, part));
        why.push(format!("--partition {}/{}", part.0, part.1));
    }
    let line = (!why.is_empty()).then(|| format!("selected {} of {all} cases ({})", picked.len(), why.join(", ")));
    Ok((picked, line))
}

/// Where a run on `backend` writes its report unless told otherwise: the
/// project's `target/vista-report/` on lavapipe, `target/vista-report-<backend>/`
/// on another backend, with `-validation` under the validation layer, so
/// that checking a second backend (or the same one validated) does not
/// overwrite the first's report.
pub fn default_report_dir(project: &Project, backend: &str, validate: bool) -> Option<PathBuf> {
    let root = project.root()?;
    Some(match (backend, validate) {
        ("lavapipe", false) => project.report_dir()?,
        (b, false) => root.join(format!("target/vista-report-{b}")),
        (b, true) => root.join(format!("target/vista-report-{b}-validation")),
    })
}

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
}

impl Checker<'_> {
    /// Checks `case` (render, goldens, verdict) and writes its report folder.
    pub fn check(&self, case: &Case) -> Filed {
        let started = Instant::now();
        let mut checked =
            vista_golden::check_case(self.ctx, self.store, self.manifest, case, &options(self.ctx, self.detail));
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

    /// How many of `requested` workers check `cases` cases at once: 1 under
    /// the validation layer, whose messages are process-wide, so each is
    /// attributed to the dispatch that caused it; never more than the cases.
    pub fn jobs(&self, requested: usize, cases: usize) -> usize {
        if self.ctx.validating() { 1 } else { requested.clamp(1, cases.max(1)) }
    }

    /// Checks and files every case of `picked` with [`Checker::jobs`]
    /// workers, handing each to `each` in case order as soon as it and every
    /// earlier one are done.
    /// Stops starting cases once [`interrupted`]: what finished before the
    /// interrupt is returned and passed to `each`; a case in flight then
    /// (its worker killed by the same Ctrl-C) is left out, not failed.
    pub fn check_all(&self, picked: &[&Case], jobs: usize, mut each: impl FnMut(&Filed)) -> Vec<Filed> {
        let jobs = self.jobs(jobs, picked.len());
        // Cores the jobs leave idle go to each case's FLIP and report images.
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        vista_image::set_case_threads(cores / jobs);
        let mut out = Vec::with_capacity(picked.len());
        // The device serialises the workers' GPU runs while the others plan,
        // judge and write their report folder.
        vista_golden::in_order(
            picked,
            jobs,
            |case| (!interrupted()).then(|| self.check(case)),
            |_, filed| {
                if let Some(filed) = filed.filter(|_| !interrupted()) {
                    each(&filed);
                    out.push(filed);
                }
            },
        );
        out
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

/// Files a run writes beside its report, if asked.
#[derive(Debug, Clone, Default)]
pub struct Results {
    /// A JUnit XML file.
    pub junit: Option<PathBuf>,
    /// A copy of `results.json`.
    pub json: Option<PathBuf>,
}

/// What a run leaves: the report (`index.html`, whose path is returned),
/// `pending.toml` (the pending renders of `filed`), `results.json` beside
/// them (what `check --failed` reads next time) and `results`' files.
pub fn finish(report_dir: &Path, run: &RunSummary, filed: &[Filed], results: &Results) -> Result<PathBuf, GoldenError> {
    let pending: BTreeMap<String, ManifestEntry> =
        filed.iter().filter_map(|f| Some((f.outcome.id.clone(), f.pending.clone()?))).collect();
    let outcomes: Vec<Outcome> = filed.iter().map(|f| f.outcome.clone()).collect();
    write_run(report_dir, run, &outcomes, pending, results, None)
}

/// The files a run's outcomes make, for `finish`, `merge` and a
/// [`SharedRun`] alike: the report, `outcomes.cbor` for a shard,
/// `pending.toml`, `results.json` and `results`' files. `run` gets the
/// pending ids and, unless it names one, `report_dir` as the folder `bless
/// --from-report` takes. `suite` is a shared run's (every case id of the
/// project): its processes may still be filing cases, so no thumbnail is
/// pruned, and `outcomes.cbor` is always kept, naming the suite.
pub(crate) fn write_run(
    report_dir: &Path,
    run: &RunSummary,
    outcomes: &[Outcome],
    pending: BTreeMap<String, ManifestEntry>,
    results: &Results,
    suite: Option<&[String]>,
) -> Result<PathBuf, GoldenError> {
    let mut run = run.clone();
    run.pending = pending.keys().cloned().collect();
    if run.accept_from.is_empty() {
        run.accept_from = report_dir.display().to_string();
    }
    let index = match suite {
        Some(_) => vista_report::write_index(report_dir, &run, outcomes)?,
        None => vista_report::write_report(report_dir, &run, outcomes)?,
    };
    // Only a shard is merged: a whole run's report keeps no second copy of
    // its outcomes. A shared run cannot tell (nextest does not say which
    // partition a process runs), so it always keeps one.
    if run.partition.is_some() || suite.is_some() {
        merge::save(report_dir, &run, outcomes, suite)?;
    } else {
        merge::remove(report_dir)?;
    }
    // A whole run in a folder a shared run left: its records are stale.
    if suite.is_none() {
        shared::remove_records(report_dir)?;
    }
    vista_golden::pending::write_pending(report_dir, pending)?;
    let json_text = vista_report::json_text(&run, outcomes);
    vista_image::atomic_write(&report_dir.join("results.json"), json_text.as_bytes())?;
    if let Some(p) = &results.junit {
        vista_image::atomic_write(p, vista_report::junit_xml(&run, outcomes, report_dir)?.as_bytes())?;
    }
    if let Some(p) = &results.json {
        vista_image::atomic_write(p, json_text.as_bytes())?;
    }
    Ok(index)
}

/// `vista bless --from-report <dir>`, where a run left pending renders.
pub fn accept_command(report_dir: &Path, filed: &[Filed]) -> Option<String> {
    filed.iter().any(|f| f.pending.is_some()).then(|| format!("vista bless --from-report {}", report_dir.display()))
}

/// Goldens no case refers to (a renamed or deleted case left them behind).
pub fn orphans(store: &Store, cases: &[Case]) -> Vec<PathBuf> {
    store.orphans(cases)
}
