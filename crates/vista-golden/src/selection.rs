//! Which cases a check runs (SPEC 15 "Selection"): `--changed` (the
//! params hash or a reached WGSL file's hash differs from the manifest, or
//! there is no entry), `--failed` (the failures of the last report's
//! `results.json`) and `--partition K/N` (stable by id), on top of `--case`.

use std::collections::BTreeMap;
use std::path::Path;

use crate::{Case, GoldenError, Manifest};

/// `K/N` with 1 <= K <= N.
pub fn parse_partition(text: &str) -> Result<(u64, u64), GoldenError> {
    let bad =
        || GoldenError::BadInput(format!("--partition {text} is not valid; expected K/N with 1 <= K <= N, e.g. 2/4"));
    let (k, n) = text.split_once('/').ok_or_else(bad)?;
    let (k, n): (u64, u64) = (k.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
    if k == 0 || n == 0 || k > n {
        return Err(bad());
    }
    Ok((k, n))
}

/// Whether case `id` falls in partition `k` of `n`: by a hash of the id, so
/// adding a case never moves the others.
pub fn in_partition(id: &str, (k, n): (u64, u64)) -> bool {
    let h = blake3::hash(id.as_bytes());
    let word = u64::from_le_bytes(h.as_bytes()[..8].try_into().expect("8 bytes"));
    word % n == k - 1
}

/// Why `case` must run again under `--changed`, or None: no manifest entry,
/// other params, or a reached file added, dropped or edited since the bless.
/// `files` is the hash of every file the kernel reaches now.
pub fn change(case: &Case, manifest: &Manifest, files: &BTreeMap<String, String>) -> Option<String> {
    let Some(e) = manifest.case.get(&case.id) else { return Some("no manifest entry".into()) };
    if e.params_hash != crate::params_hash(case) {
        return Some("params changed".into());
    }
    if e.shader_files.is_empty() {
        return Some("the manifest predates per-file hashes".into());
    }
    let edited = crate::changed_files(&e.shader_files, files);
    (!edited.is_empty()).then(|| format!("changed: {}", edited.join(", ")))
}

/// The ids the last report (its `results.json`) says failed.
pub fn last_failures(report_dir: &Path) -> Result<Vec<String>, GoldenError> {
    let path = report_dir.join("results.json");
    let text = std::fs::read_to_string(&path).map_err(|e| {
        GoldenError::BadInput(format!(
            "--failed reads the last report's {}: {e}; run vista check once first",
            path.display()
        ))
    })?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| GoldenError::BadInput(format!("{}: not a vista results file: {e}", path.display())))?;
    Ok(v["cases"]
        .as_array()
        .into_iter()
        .flatten()
        .filter(|c| c["passed"] == false)
        .filter_map(|c| c["id"].as_str().map(str::to_string))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partitions_cover_every_id_once_and_bad_specs_are_refused() {
        let ids: Vec<String> = (0..200).map(|i| format!("case-{i}")).collect();
        for n in 1..=5 {
            for id in &ids {
                let hits = (1..=n).filter(|&k| in_partition(id, (k, n))).count();
                assert_eq!(hits, 1, "{id} in {hits} of {n} partitions");
            }
        }
        let sizes: Vec<usize> = (1..=4).map(|k| ids.iter().filter(|id| in_partition(id, (k, 4))).count()).collect();
        assert!(sizes.iter().all(|&s| s > 25), "unbalanced: {sizes:?}");
        assert_eq!(parse_partition("2/4").unwrap(), (2, 4));
        for bad in ["0/4", "5/4", "x/4", "2", "2/0"] {
            assert!(parse_partition(bad).is_err(), "{bad}");
        }
    }
}
