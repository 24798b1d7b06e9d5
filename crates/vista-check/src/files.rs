//! What a run leaves ([`finish`]): the report, `pending.toml`,
//! `results.json`, a JUnit file, and for a shard or a shared run the
//! outcomes `vista merge` joins.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use vista_golden::{GoldenError, ManifestEntry, Outcome};
use vista_report::RunSummary;

use crate::checker::Filed;

/// Files a run writes beside its report, if asked.
#[derive(Debug, Clone, Default)]
pub struct Results {
    /// A JUnit XML file.
    pub junit: Option<PathBuf>,
    /// A copy of `results.json`.
    pub json: Option<PathBuf>,
    /// The project's WGSL files by project-relative path, for the coverage
    /// pages (none: the pages list counts without the text).
    pub sources: vista_render::Reader,
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
    // A coverage run's pages and lcov.info (every case's hits summed); a
    // run without coverage leaves no older run's to be read as its own.
    let total = coverage_total(outcomes, &run.unit_tests);
    run.coverage = total.as_ref().map(vista_report::coverage_line);
    let lcov = report_dir.join(LCOV_FILE);
    let pages = report_dir.join(vista_report::COVERAGE_DIR);
    let io =
        |path: &Path, e: std::io::Error| GoldenError::Io { path: path.display().to_string(), message: e.to_string() };
    match &total {
        Some(counts) => {
            vista_report::write_coverage(report_dir, counts, &|file| results.sources.read(file).map(|(text, _)| text))?;
            vista_image::atomic_write(&lcov, counts.lcov("vista").as_bytes())?;
        }
        None => {
            if lcov.is_file() {
                std::fs::remove_file(&lcov).map_err(|e| io(&lcov, e))?;
            }
            // The folder itself, never through a link (remove_dir_all does not follow one).
            if std::fs::symlink_metadata(&pages).is_ok_and(|m| m.is_dir()) {
                std::fs::remove_dir_all(&pages).map_err(|e| io(&pages, e))?;
            }
        }
    }
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
        crate::kept::save(report_dir, &run, outcomes, suite)?;
    } else {
        crate::kept::remove(report_dir)?;
    }
    // A whole run in a folder a shared run left: its records are stale.
    if suite.is_none() {
        crate::kept::remove_records(report_dir)?;
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

/// The LCOV tracefile a coverage run leaves in its report folder.
pub const LCOV_FILE: &str = "lcov.info";

/// The hits of every case (and WGSL unit test file) a coverage run
/// measured, summed; none when nothing ran with coverage.
pub fn coverage_total(outcomes: &[Outcome], units: &[vista_report::UnitTest]) -> Option<vista_coverage::Counts> {
    let cases = outcomes.iter().filter_map(|o| o.coverage.as_ref());
    let mut measured = cases.chain(units.iter().filter_map(|u| u.coverage.as_ref())).peekable();
    measured.peek()?;
    let mut total = vista_coverage::Counts::default();
    for lcov in measured.flatten() {
        total.merge(&vista_coverage::Counts::from_lcov(lcov));
    }
    Some(total)
}

/// `vista bless --from-report <dir>`, where a run left pending renders.
pub fn accept_command(report_dir: &Path, filed: &[Filed]) -> Option<String> {
    filed.iter().any(|f| f.pending.is_some()).then(|| format!("vista bless --from-report {}", report_dir.display()))
}
