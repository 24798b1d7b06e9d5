//! What a run keeps in its report folder for other processes: the
//! outcomes a shard leaves for `vista merge` ([`OUTCOMES_FILE`]) and the
//! records of a run shared by processes ([`RUN_DIR`]).

use std::path::Path;

use vista_golden::{GoldenError, Outcome};
use vista_report::RunSummary;

/// The file a `--partition` check (or a run shared by processes) leaves
/// beside `results.json`: its run and every outcome, losslessly (CBOR keeps
/// PSNR +inf and NaN), for `vista merge`.
pub const OUTCOMES_FILE: &str = "outcomes.cbor";

#[derive(serde::Serialize, serde::Deserialize)]
pub(crate) struct Saved {
    pub(crate) run: RunSummary,
    pub(crate) outcomes: Vec<Outcome>,
    /// A shared run's: every case id of the project's suite.
    #[serde(default)]
    pub(crate) suite: Option<Vec<String>>,
}

/// Writes `outcomes.cbor` into `report_dir`.
pub(crate) fn save(
    report_dir: &Path,
    run: &RunSummary,
    outcomes: &[Outcome],
    suite: Option<&[String]>,
) -> Result<(), GoldenError> {
    let mut bytes = Vec::new();
    let saved = Saved { run: run.clone(), outcomes: outcomes.to_vec(), suite: suite.map(<[String]>::to_vec) };
    ciborium::into_writer(&saved, &mut bytes).map_err(|e| GoldenError::Io {
        path: report_dir.join(OUTCOMES_FILE).display().to_string(),
        message: e.to_string(),
    })?;
    vista_image::atomic_write(&report_dir.join(OUTCOMES_FILE), &bytes)?;
    Ok(())
}

/// Removes an earlier shard's `outcomes.cbor` from a folder a whole run now
/// reports into, so it is never merged as that run's.
pub(crate) fn remove(report_dir: &Path) -> Result<(), GoldenError> {
    gone(&report_dir.join(OUTCOMES_FILE), |p| std::fs::remove_file(p))
}

/// The hidden folder of a shared run's records in the report folder: `run`
/// (the run's id), `cases/<id>.cbor`, one record per case, and
/// `units/<id>.cbor`, one per WGSL unit test.
pub const RUN_DIR: &str = ".vista-run";

/// Removes a report folder's [`RUN_DIR`] and all in it, if it is there.
pub(crate) fn remove_records(report_dir: &Path) -> Result<(), GoldenError> {
    gone(&report_dir.join(RUN_DIR), |p| std::fs::remove_dir_all(p))
}

/// `path` removed by `remove`; nothing if it is not there.
fn gone(path: &Path, remove: impl Fn(&Path) -> std::io::Result<()>) -> Result<(), GoldenError> {
    match remove(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(GoldenError::Io { path: path.display().to_string(), message: e.to_string() })
        }
        _ => Ok(()),
    }
}
