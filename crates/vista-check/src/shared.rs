//! A run whose cases are checked in processes of their own: cargo-nextest
//! starts one process per test, so each `vista::harness` process checks
//! one case. Each [`SharedRun::finish`]es by recording its cases (verdict,
//! metrics, files, pending render) in the report folder, tagged with the
//! run's id, and rebuilding the whole report from every case recorded in
//! that run: the index, `results.json`, `pending.toml`, JUnit. Both happen
//! under an exclusive lock on the report folder, so processes finishing at
//! once neither lose a case nor list one twice. The first process of a new
//! run ([`SharedRun::join`], another id in the folder) clears what an
//! earlier run left: case folders, thumbnails, records.
//!
//! The folder also keeps [`OUTCOMES_FILE`](crate::OUTCOMES_FILE), with the
//! ids of every case of the suite, so that `vista merge` joins the report
//! folders of `cargo nextest run --partition` runs: nextest does not tell
//! a test process which partition it runs, so the merge checks instead that
//! the shards hold every case of the suite once.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use vista_golden::{GoldenError, ManifestEntry, Outcome};
use vista_report::RunSummary;

use crate::checker::Filed;
use crate::files::{Results, write_run};
use crate::kept::{RUN_DIR, remove_records};

const MARK: &str = "run";
const CASES: &str = "cases";
const UNITS: &str = "units";

/// One case as one process of the run left it.
#[derive(serde::Serialize, serde::Deserialize)]
struct Record {
    run: String,
    outcome: Outcome,
    pending: Option<ManifestEntry>,
}

/// One WGSL unit test as one process of the run left it.
#[derive(serde::Serialize, serde::Deserialize)]
struct UnitRecord {
    run: String,
    test: vista_report::UnitTest,
}

fn io(path: &Path, e: std::io::Error) -> GoldenError {
    GoldenError::Io { path: path.display().to_string(), message: e.to_string() }
}

/// An exclusive lock on a report folder (`flock` on the folder itself, so
/// no lock file can be replaced under it), held until dropped.
struct Lock {
    _held: std::fs::File,
}

impl Lock {
    fn take(dir: &Path) -> Result<Lock, GoldenError> {
        std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
        let f = std::fs::File::open(dir).map_err(|e| io(dir, e))?;
        #[cfg(unix)]
        {
            use std::os::fd::AsRawFd;
            loop {
                // SAFETY: flock on a descriptor `f` owns and keeps open; the
                // lock goes with it when `f` is closed.
                if unsafe { libc::flock(f.as_raw_fd(), libc::LOCK_EX) } == 0 {
                    break;
                }
                let e = std::io::Error::last_os_error();
                if e.kind() != std::io::ErrorKind::Interrupted {
                    return Err(io(dir, e));
                }
            }
        }
        Ok(Lock { _held: f })
    }
}

/// The id of the run whose records `run_dir` holds, if any.
fn current(run_dir: &Path) -> Option<String> {
    std::fs::read_to_string(run_dir.join(MARK)).ok().map(|s| s.trim().to_string())
}

/// The id of a run of processes that gives none: the parent process (the
/// test runner that started this one) with its start time, so that a
/// later runner with the same process id is another run.
pub fn parent_run_id() -> String {
    #[cfg(unix)]
    {
        let ppid = std::os::unix::process::parent_id();
        // Field 22 of /proc/<pid>/stat, counted after the command's closing
        // parenthesis (the command may hold spaces).
        let started = std::fs::read_to_string(format!("/proc/{ppid}/stat"))
            .ok()
            .and_then(|s| s.rsplit_once(')').and_then(|(_, rest)| rest.split_whitespace().nth(19).map(String::from)))
            .unwrap_or_default();
        format!("parent-{ppid}-{started}")
    }
    #[cfg(not(unix))]
    {
        "parent".to_string()
    }
}

/// One process's part in a run shared by processes (see the module docs).
#[derive(Debug, Clone)]
pub struct SharedRun {
    report_dir: PathBuf,
    id: String,
}

impl SharedRun {
    /// Joins run `id` in `report_dir`. If the folder holds another run's
    /// records (or none), this is the run's first process: it clears the
    /// earlier run's case folders, thumbnails and records first. Call it
    /// before checking a case, so no case folder of this run is cleared.
    pub fn join(report_dir: &Path, id: &str) -> Result<SharedRun, GoldenError> {
        let _lock = Lock::take(report_dir)?;
        let run_dir = report_dir.join(RUN_DIR);
        if current(&run_dir).as_deref() != Some(id) {
            vista_report::clear_case_folders(report_dir)?;
            vista_report::prune_thumbs(report_dir, &[]);
            remove_records(report_dir)?;
            let cases = run_dir.join(CASES);
            std::fs::create_dir_all(&cases).map_err(|e| io(&cases, e))?;
            vista_image::atomic_replace(&run_dir.join(MARK), id.as_bytes())?;
        }
        Ok(SharedRun { report_dir: report_dir.to_path_buf(), id: id.to_string() })
    }

    /// The run's id.
    pub fn id(&self) -> &str {
        &self.id
    }

    /// Records `filed` and rebuilds the report from every case recorded in
    /// this run, listed in the order of `suite` (every case id of the
    /// project, kept for `vista merge`): the index (whose path is
    /// returned), `results.json`, `pending.toml` and `results`' files. A
    /// case recorded twice (a retry) is listed once, as last recorded.
    pub fn finish(
        &self,
        run: &RunSummary,
        filed: &[Filed],
        results: &Results,
        suite: &[String],
    ) -> Result<PathBuf, GoldenError> {
        let _lock = Lock::take(&self.report_dir)?;
        let run_dir = self.report_dir.join(RUN_DIR);
        let now = current(&run_dir);
        if now.as_deref() != Some(self.id.as_str()) {
            return Err(GoldenError::BadInput(format!(
                "{} holds the report of another run now ({}); this run's ({}) cases are not recorded",
                self.report_dir.display(),
                now.as_deref().unwrap_or("none"),
                self.id
            )));
        }
        let cases = run_dir.join(CASES);
        for f in filed {
            let record = Record { run: self.id.clone(), outcome: f.outcome.clone(), pending: f.pending.clone() };
            write_record(&cases.join(format!("{}.cbor", f.outcome.id)), &record)?;
        }
        let units = run_dir.join(UNITS);
        if !run.unit_tests.is_empty() {
            std::fs::create_dir_all(&units).map_err(|e| io(&units, e))?;
        }
        for t in &run.unit_tests {
            let record = UnitRecord { run: self.id.clone(), test: t.clone() };
            write_record(&units.join(format!("{}.cbor", t.id.replace("::", "."))), &record)?;
        }
        let mut recorded: Vec<Record> =
            read_records::<Record>(&cases)?.into_iter().filter(|r| r.run == self.id).collect();
        let mut run = run.clone();
        run.unit_tests =
            read_records::<UnitRecord>(&units)?.into_iter().filter(|r| r.run == self.id).map(|r| r.test).collect();
        run.unit_tests.sort_by(|a, b| a.id.cmp(&b.id));
        let order: BTreeMap<&str, usize> = suite.iter().enumerate().map(|(i, id)| (id.as_str(), i)).collect();
        recorded.sort_by(|a, b| {
            let at = |r: &Record| order.get(r.outcome.id.as_str()).copied().unwrap_or(usize::MAX);
            at(a).cmp(&at(b)).then_with(|| a.outcome.id.cmp(&b.outcome.id))
        });
        let pending: BTreeMap<String, ManifestEntry> =
            recorded.iter().filter_map(|r| Some((r.outcome.id.clone(), r.pending.clone()?))).collect();
        let outcomes: Vec<Outcome> = recorded.into_iter().map(|r| r.outcome).collect();
        write_run(&self.report_dir, &run, &outcomes, pending, results, Some(suite))
    }
}

/// Writes one record (a case's, a unit test's) atomically.
fn write_record(path: &Path, record: &impl serde::Serialize) -> Result<(), GoldenError> {
    let mut bytes = Vec::new();
    ciborium::into_writer(record, &mut bytes)
        .map_err(|e| GoldenError::Io { path: path.display().to_string(), message: e.to_string() })?;
    Ok(vista_image::atomic_replace(path, &bytes)?)
}

/// Every record in `dir` (none if it does not exist), skipping the temp
/// files of a write in flight (`.<name>.tmp`).
fn read_records<R: serde::de::DeserializeOwned>(dir: &Path) -> Result<Vec<R>, GoldenError> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io(dir, e)),
    };
    let mut out = Vec::new();
    for e in entries {
        let path = e.map_err(|e| io(dir, e))?.path();
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        if name.starts_with('.') || !name.ends_with(".cbor") {
            continue;
        }
        let bytes = std::fs::read(&path).map_err(|e| io(&path, e))?;
        out.push(
            ciborium::from_reader(bytes.as_slice()).map_err(|e| {
                GoldenError::BadInput(format!("{}: not a record this vista wrote: {e}", path.display()))
            })?,
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn filed(id: &str, pass: bool) -> Filed {
        let text = format!("[[case]]\nid = \"{id}\"\nkernel = \"fbm\"\nsize = \"8x8\"\n");
        let case = vista_golden::parse_cases(Path::new("cases.toml"), &text, vista_kernels::Registry::builtin())
            .expect("a case")
            .remove(0);
        let observed = Err("not rendered: a test of the records".to_string());
        let mut outcome = vista_golden::judge(&case, None, vista_golden::RunInfo::default(), observed);
        let mut pending = None;
        if pass {
            outcome.verdict = vista_golden::Verdict::Pass;
            outcome.problems.clear();
        } else {
            pending = Some(ManifestEntry {
                kernel: "fbm".into(),
                size: "8x8".into(),
                params_hash: String::new(),
                shader_hash: String::new(),
                shader_files: BTreeMap::new(),
                adapter: String::new(),
                backend: "lavapipe".into(),
                date: String::new(),
                raw_hash: String::new(),
                psnr_vs_previous: "new".into(),
                golden_hash: format!("hash-of-{id}"),
                replacing: None,
                outputs: BTreeMap::new(),
            });
        }
        Filed { outcome, pending, check_time: Duration::ZERO, report_time: Duration::ZERO, report_errors: Vec::new() }
    }

    fn ids_in_results(dir: &Path) -> Vec<String> {
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
        json["cases"].as_array().unwrap().iter().map(|c| c["id"].as_str().unwrap().to_string()).collect()
    }

    /// Twenty processes' worth of threads, each with a lock of its own
    /// (flock excludes separate opens in one process as across processes),
    /// finishing at once: every case listed once; a second run's first
    /// process clears the first run.
    #[test]
    fn cases_finishing_at_once_are_each_listed_once_and_a_new_run_starts_clean() {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("report");
        let ids: Vec<String> = (1..=20).map(|i| format!("c{i:02}")).collect();
        let run = RunSummary { command: "cargo nextest run".into(), backend: "lavapipe".into(), ..Default::default() };
        // Three runs, as a lost update shows only in some interleavings.
        for round in ["run-0", "run-1", "run-a"] {
            std::thread::scope(|s| {
                for (i, id) in ids.iter().enumerate() {
                    let (dir, ids, run) = (&dir, &ids, &run);
                    s.spawn(move || {
                        let shared = SharedRun::join(dir, round).unwrap();
                        shared.finish(run, &[filed(id, i % 5 != 0)], &Results::default(), ids).unwrap();
                    });
                }
            });
            assert_eq!(ids_in_results(&dir), ids, "{round}: every case once, in the suite's order");
        }
        let pending = vista_golden::pending::read_pending(&dir).unwrap();
        assert_eq!(pending.keys().cloned().collect::<Vec<_>>(), ["c01", "c06", "c11", "c16"]);
        let index = std::fs::read_to_string(dir.join("index.html")).unwrap();
        for id in &ids {
            assert_eq!(index.matches(&format!("id=\"case-{id}\"")).count(), 1, "{id} in index.html");
        }
        // A later run of two cases: nothing of run-a is mixed in.
        let shared = SharedRun::join(&dir, "run-b").unwrap();
        shared.finish(&run, &[filed("c03", false)], &Results::default(), &ids).unwrap();
        let shared = SharedRun::join(&dir, "run-b").unwrap();
        shared.finish(&run, &[filed("c07", true)], &Results::default(), &ids).unwrap();
        assert_eq!(ids_in_results(&dir), ["c03", "c07"]);
        let pending = vista_golden::pending::read_pending(&dir).unwrap();
        assert_eq!(pending.keys().cloned().collect::<Vec<_>>(), ["c03"]);
        // A process of run-a finishing after run-b began records nothing.
        let late = SharedRun { report_dir: dir.clone(), id: "run-a".into() };
        let e = late.finish(&run, &[filed("c09", true)], &Results::default(), &ids).unwrap_err().to_string();
        assert!(e.contains("another run now (run-b)"), "{e}");
        assert_eq!(ids_in_results(&dir), ["c03", "c07"]);
        // A whole run (vista check, cargo test) into the folder drops the records.
        crate::finish(&dir, &run, &[filed("c01", true)], &Results::default()).unwrap();
        assert!(!dir.join(RUN_DIR).exists() && !dir.join(crate::OUTCOMES_FILE).exists());
    }

    /// Shared runs' folders (nextest's partitions) merge into the report of
    /// the whole suite, verdicts as recorded; a partition missing, given
    /// twice, of another suite, or mixed with a `check --partition` shard
    /// is refused, naming what is wrong.
    #[test]
    fn partitions_of_a_shared_run_merge_only_when_they_hold_the_suite_once() {
        let t = tempfile::tempdir().unwrap();
        let ids: Vec<String> = (1..=6).map(|i| format!("c{i}")).collect();
        let run = RunSummary { command: "cargo nextest run".into(), backend: "lavapipe".into(), ..Default::default() };
        let part = |k: usize, suite: &[String]| {
            let dir = t.path().join(format!("part-{k}"));
            for (i, id) in ids.iter().enumerate().filter(|(i, _)| i % 3 == k - 1) {
                let shared = SharedRun::join(&dir, &format!("run-{k}")).unwrap();
                shared.finish(&run, &[filed(id, i != 4)], &Results::default(), suite).unwrap();
            }
            dir
        };
        let dirs: Vec<PathBuf> = (1..=3).map(|k| part(k, &ids)).collect();
        let merge = |dirs: &[PathBuf], out: &str| {
            crate::merge(dirs, &t.path().join(out), &Results::default(), "vista merge".into()).map(|(_, o)| o)
        };
        let outcomes = merge(&dirs, "merged").unwrap();
        let got: Vec<(String, bool)> = outcomes.iter().map(|o| (o.id.clone(), o.passed())).collect();
        let want: Vec<(String, bool)> = ids.iter().enumerate().map(|(i, id)| (id.clone(), i != 4)).collect();
        assert_eq!(got, want);
        assert_eq!(ids_in_results(&t.path().join("merged")), ids);
        let pending = vista_golden::pending::read_pending(&t.path().join("merged")).unwrap();
        assert_eq!(pending.keys().cloned().collect::<Vec<_>>(), ["c5"]);
        let refused = |dirs: &[PathBuf], out: &str| merge(dirs, out).unwrap_err().to_string();
        let e = refused(&dirs[..2], "two");
        assert!(e.contains("2 of the suite's 6 cases are in none of the 2 shards given (c3, c6)"), "{e}");
        let e = refused(&[dirs[0].clone(), dirs[0].clone(), dirs[1].clone(), dirs[2].clone()], "twice");
        assert!(e.contains("case c1 is in both") && e.contains("given twice"), "{e}");
        let other = part(3, &ids[..5]);
        let e = refused(&[dirs[0].clone(), dirs[1].clone(), other], "suites");
        assert!(e.contains("different suites"), "{e}");
        let check_shard = t.path().join("check-shard");
        let shard_run = RunSummary { partition: Some((1, 3)), ..run.clone() };
        crate::finish(&check_shard, &shard_run, &[filed("c1", true)], &Results::default()).unwrap();
        let e = refused(&[dirs[0].clone(), check_shard], "mixed");
        assert!(e.contains("merge the shards of one kind"), "{e}");
        for out in ["two", "twice", "suites", "mixed"] {
            assert!(!t.path().join(out).exists(), "a refused merge wrote {out}");
        }
    }

    /// Without nextest's run id, a run is the test runner that started the
    /// process: the same for every call, naming the parent and when it started.
    #[test]
    fn a_run_without_an_id_is_the_parent_process() {
        let id = parent_run_id();
        assert_eq!(id, parent_run_id());
        let ppid = std::os::unix::process::parent_id();
        let started = id.strip_prefix(&format!("parent-{ppid}-")).unwrap_or_else(|| panic!("{id}"));
        assert!(!started.is_empty() && started.chars().all(|c| c.is_ascii_digit()), "{id}");
    }
}
