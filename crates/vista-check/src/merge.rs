//! `vista merge`: the report folders of `vista check --partition K/N` runs
//! (CI shards), or of the harness's runs under `cargo nextest run
//! --partition` ([`SharedRun`](crate::SharedRun)), joined into one report,
//! `results.json`, JUnit file and `pending.toml`, with every verdict and
//! metric as its shard gave it. A shard missing or given twice is named and
//! nothing is written: a merge never passes as a smaller suite. `check`'s
//! shards say which K of N they are; nextest's do not (it tells a test
//! process nothing of its partition), so theirs must hold every case of
//! the suite they name once.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use vista_golden::{GoldenError, ManifestEntry, Outcome};
use vista_report::RunSummary;

use crate::files::{Results, write_run};
use crate::kept::{OUTCOMES_FILE, Saved};

/// One shard as read back.
struct Shard {
    dir: PathBuf,
    run: RunSummary,
    outcomes: Vec<Outcome>,
    suite: Option<Vec<String>>,
}

/// Why a whole run's report is not a shard.
fn unpartitioned(dir: &Path) -> String {
    format!(
        "{} is the report of a check without --partition (or of `cargo test`); merge joins the shards of `vista \
         check --partition K/N` runs, or of the golden harness's `cargo nextest run --partition` runs",
        dir.display()
    )
}

fn read(dir: &Path) -> Result<Shard, GoldenError> {
    let path = dir.join(OUTCOMES_FILE);
    let bytes = std::fs::read(&path).map_err(|e| {
        GoldenError::BadInput(match dir.join("results.json").is_file() {
            true => unpartitioned(dir),
            false => format!(
                "{} is not a check's report folder ({OUTCOMES_FILE}: {e}); merge takes the --report-dir of each \
                 `vista check --partition K/N` run (or the VISTA_REPORT_DIR of each `cargo nextest run --partition` \
                 run)",
                dir.display()
            ),
        })
    })?;
    let saved: Saved = ciborium::from_reader(bytes.as_slice())
        .map_err(|e| GoldenError::BadInput(format!("{}: not a report this vista wrote: {e}", path.display())))?;
    Ok(Shard { dir: dir.to_path_buf(), run: saved.run, outcomes: saved.outcomes, suite: saved.suite })
}

/// Every shard's K of one N, each once, on one backend; else the error
/// naming the shard missing, given twice, or out of place.
fn check_shards(shards: &[Shard]) -> Result<u64, GoldenError> {
    let bad = |m: String| Err(GoldenError::BadInput(m));
    if let Some(shared) = shards.iter().find(|s| s.suite.is_some()) {
        if let Some(s) = shards.iter().find(|s| s.suite.is_none()) {
            return bad(format!(
                "{} is the report of the golden harness under cargo-nextest, {} is not: merge the shards of one kind",
                shared.dir.display(),
                s.dir.display()
            ));
        }
        return check_suite(shards);
    }
    let mut n = None;
    let mut seen: BTreeMap<u64, &Path> = BTreeMap::new();
    for s in shards {
        let Some((k, sn)) = s.run.partition else { return bad(unpartitioned(&s.dir)) };
        match n {
            Some(first) if first != sn => {
                return bad(format!(
                    "{} is shard {k}/{sn} but {} is shard {}/{first}: the shards of one split have one N",
                    s.dir.display(),
                    shards[0].dir.display(),
                    shards[0].run.partition.map_or(0, |p| p.0)
                ));
            }
            _ => n = Some(sn),
        }
        if let Some(other) = seen.insert(k, &s.dir) {
            return bad(format!("shard {k}/{sn} is given twice: {} and {}", other.display(), s.dir.display()));
        }
        if s.run.backend != shards[0].run.backend {
            return bad(format!(
                "{} ran on {} but {} on {}: merge the shards of one backend",
                s.dir.display(),
                s.run.backend,
                shards[0].dir.display(),
                shards[0].run.backend
            ));
        }
    }
    let n = n.expect("at least one shard");
    let missing: Vec<String> = (1..=n).filter(|k| !seen.contains_key(k)).map(|k| format!("{k}/{n}")).collect();
    if !missing.is_empty() {
        let given: Vec<String> = seen.keys().map(|k| format!("{k}/{n}")).collect();
        return bad(format!(
            "shard{} {} {} missing (given: {}); a merge of fewer shards would pass as a smaller suite",
            if missing.len() == 1 { "" } else { "s" },
            missing.join(", "),
            if missing.len() == 1 { "is" } else { "are" },
            given.join(", ")
        ));
    }
    Ok(n)
}

/// The shards of runs shared by processes (nextest's partitions): one
/// backend, one suite, and together every case of it once; else the error
/// naming the case given twice or the cases missing.
fn check_suite(shards: &[Shard]) -> Result<u64, GoldenError> {
    let bad = |m: String| Err(GoldenError::BadInput(m));
    let first = &shards[0];
    let suite = first.suite.as_deref().unwrap_or_default();
    let mut seen: BTreeMap<&str, &Path> = BTreeMap::new();
    for s in shards {
        if s.suite.as_deref().unwrap_or_default() != suite {
            return bad(format!(
                "{} and {} are reports of different suites (golden/cases.toml changed between the runs): merge the \
                 shards of one suite",
                first.dir.display(),
                s.dir.display()
            ));
        }
        if s.run.backend != first.run.backend {
            return bad(format!(
                "{} ran on {} but {} on {}: merge the shards of one backend",
                s.dir.display(),
                s.run.backend,
                first.dir.display(),
                first.run.backend
            ));
        }
        for o in &s.outcomes {
            if let Some(other) = seen.insert(&o.id, &s.dir) {
                return bad(format!(
                    "case {} is in both {} and {}: a shard is given twice, or the runs overlapped",
                    o.id,
                    other.display(),
                    s.dir.display()
                ));
            }
        }
    }
    let missing: Vec<&str> = suite.iter().map(String::as_str).filter(|id| !seen.contains_key(id)).collect();
    if !missing.is_empty() {
        let named = missing.iter().take(5).copied().collect::<Vec<_>>().join(", ");
        return bad(format!(
            "{} of the suite's {} cases {} in none of the {} shards given ({named}{}): a shard is missing, or a run \
             was filtered or stopped early; a merge of fewer cases would pass as a smaller suite",
            missing.len(),
            suite.len(),
            if missing.len() == 1 { "is" } else { "are" },
            shards.len(),
            if missing.len() > 5 { ", ..." } else { "" }
        ));
    }
    Ok(shards.len() as u64)
}

fn copy_dir(from: &Path, to: &Path) -> Result<(), GoldenError> {
    let io = |p: &Path, e: std::io::Error| GoldenError::Io { path: p.display().to_string(), message: e.to_string() };
    std::fs::create_dir_all(to).map_err(|e| io(to, e))?;
    for entry in std::fs::read_dir(from).map_err(|e| io(from, e))? {
        let entry = entry.map_err(|e| io(from, e))?;
        let (src, dst) = (entry.path(), to.join(entry.file_name()));
        if src.is_dir() {
            copy_dir(&src, &dst)?;
        } else {
            std::fs::copy(&src, &dst).map_err(|e| io(&src, e))?;
        }
    }
    Ok(())
}

/// Joins the shards in `dirs` into `out`: checks them first (nothing is
/// written if one is missing, given twice or of another split), then
/// copies each case's folder, and writes the report, `pending.toml`
/// (every shard's pending renders), `results.json` and what `results`
/// asks for. Returns the index path and the outcomes, by id.
pub fn merge(
    dirs: &[PathBuf],
    out: &Path,
    results: &Results,
    command: String,
) -> Result<(PathBuf, Vec<Outcome>), GoldenError> {
    if dirs.is_empty() {
        return Err(GoldenError::BadInput("merge needs the report folders of the shards".into()));
    }
    let shards = dirs.iter().map(|d| read(d)).collect::<Result<Vec<_>, _>>()?;
    let n = check_shards(&shards)?;
    let out_abs = std::path::absolute(out).unwrap_or_else(|_| out.to_path_buf());
    if let Some(s) = shards.iter().find(|s| std::path::absolute(&s.dir).is_ok_and(|d| d == out_abs)) {
        return Err(GoldenError::BadInput(format!(
            "--report-dir {} is shard {}: merge into a folder of its own",
            out.display(),
            s.dir.display()
        )));
    }
    let mut pending: BTreeMap<String, ManifestEntry> = BTreeMap::new();
    for s in &shards {
        pending.extend(vista_golden::pending::read_pending(&s.dir)?);
    }
    std::fs::create_dir_all(out)
        .map_err(|e| GoldenError::Io { path: out.display().to_string(), message: e.to_string() })?;
    vista_report::clear_case_folders(out)?;
    for s in &shards {
        for o in &s.outcomes {
            let case = s.dir.join(&o.id);
            if case.is_dir() {
                copy_dir(&case, &out.join(&o.id))?;
            }
            // A passing case's thumbnail lives in the shard's thumbnail folder.
            if let Some(thumb) = o.files.thumb.as_deref().filter(|t| t.starts_with(vista_report::THUMBS_DIR)) {
                let to = out.join(thumb);
                if let Some(parent) = to.parent() {
                    std::fs::create_dir_all(parent)
                        .map_err(|e| GoldenError::Io { path: parent.display().to_string(), message: e.to_string() })?;
                }
                std::fs::copy(s.dir.join(thumb), &to)
                    .map_err(|e| GoldenError::Io { path: to.display().to_string(), message: e.to_string() })?;
            }
        }
    }
    let mut outcomes: Vec<Outcome> = shards.iter().flat_map(|s| s.outcomes.iter().cloned()).collect();
    outcomes.sort_by(|a, b| a.id.cmp(&b.id));
    let first = &shards[0].run;
    // Each shard ran the unit tests its partition held; one listing each.
    let units: BTreeMap<String, vista_report::UnitTest> =
        shards.iter().flat_map(|s| s.run.unit_tests.iter().map(|t| (t.id.clone(), t.clone()))).collect();
    let run = RunSummary {
        command: format!("{command} (the {n} shards of: {})", first.command),
        backend: first.backend.clone(),
        adapter: first.adapter.clone(),
        unit_tests: units.into_values().collect(),
        ..Default::default()
    };
    let index = write_run(out, &run, &outcomes, pending, results, None)?;
    Ok((index, outcomes))
}
