//! Goldens from the CI driver (SPEC 15): `vista check` keeps, in the report,
//! each failing or missing case's render (`<id>/actual.png`) and the
//! manifest entry a bless of it would write (`pending.toml`); `vista bless
//! --from-report DIR` accepts exactly those files, after checking that this
//! checkout's params and WGSL still hash as they did, so a developer on
//! another machine blesses what CI's driver rendered without re-rendering.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::bless::{BlessRow, BlessSummary};
use crate::{GoldenError, Manifest, ManifestEntry, Store, params_hash};

/// The file in a report folder that lists the renders a bless may accept.
pub const PENDING_FILE: &str = "pending.toml";

/// Writes (or, with no entries, removes) `pending.toml` in `report_dir`.
pub fn write_pending(report_dir: &Path, entries: BTreeMap<String, ManifestEntry>) -> Result<(), GoldenError> {
    let path = report_dir.join(PENDING_FILE);
    if entries.is_empty() {
        return match std::fs::remove_file(&path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                Err(GoldenError::Io { path: path.display().to_string(), message: e.to_string() })
            }
            _ => Ok(()),
        };
    }
    let m = Manifest { case: entries };
    let text = format!(
        "# Written by `vista check`: renders `vista bless --from-report` may accept as goldens.\n\n{}",
        toml::to_string_pretty(&m).map_err(|e| GoldenError::BadInput(format!("pending encode: {e}")))?
    );
    vista_image::atomic_write(&path, text.as_bytes())?;
    Ok(())
}

/// The hash of every WGSL file a kernel file reaches in this checkout.
pub type FileHashes<'a> = &'a dyn Fn(&str) -> Result<BTreeMap<String, String>, String>;

/// The rendered PNG of case `id` in a report folder.
pub fn pending_png(report_dir: &Path, id: &str) -> PathBuf {
    report_dir.join(id).join("actual.png")
}

/// Accepts the report's pending renders (those matching `glob`) as goldens.
/// Every selected entry is verified first (case still there, same params
/// hash, same hash for every WGSL file the kernel reaches, the PNG the one
/// the check wrote); one stale entry refuses the whole bless, exit 2, naming
/// what changed, and nothing is written. `files_now` gives the hashes of the
/// files a kernel file reaches in this checkout.
pub fn bless_from_report(
    store: &Store,
    report_dir: &Path,
    glob: Option<&str>,
    files_now: FileHashes<'_>,
) -> Result<BlessSummary, GoldenError> {
    let path = report_dir.join(PENDING_FILE);
    let text = std::fs::read_to_string(&path).map_err(|e| {
        GoldenError::BadInput(format!(
            "{}: {e}; `vista check` writes it into its report folder when a case fails or has no golden",
            path.display()
        ))
    })?;
    let pending: Manifest = toml::from_str(&text).map_err(|e| GoldenError::Cases {
        path: path.display().to_string(),
        message: format!("malformed pending file: {}", crate::cases::one_line_toml_error(&text, &e)),
    })?;
    let ids: Vec<&String> = match glob {
        None => pending.case.keys().collect(),
        Some(g) => {
            let m = globset::Glob::new(g)
                .map_err(|e| GoldenError::BadInput(format!("--case '{g}' is not a valid glob: {e}")))?
                .compile_matcher();
            pending.case.keys().filter(|id| m.is_match(id.as_str())).collect()
        }
    };
    if ids.is_empty() {
        return Err(GoldenError::BadInput(format!(
            "{} holds no pending render{}; it holds: {}",
            path.display(),
            glob.map(|g| format!(" matching '{g}'")).unwrap_or_default(),
            pending.case.keys().cloned().collect::<Vec<_>>().join(", ")
        )));
    }
    let cases = store.load_cases()?;
    let stale = |id: &str, why: String| {
        GoldenError::BadInput(format!(
            "case {id} in {} is stale: {why}; run vista check again and bless from its report",
            path.display()
        ))
    };
    // Verify everything before writing anything.
    let mut accepted = Vec::new();
    for id in ids {
        let entry = &pending.case[id];
        let case = cases
            .iter()
            .find(|c| &c.id == id)
            .ok_or_else(|| stale(id, "it is no longer in golden/cases.toml".into()))?;
        if case.kernel.graph().is_some() {
            return Err(GoldenError::BadInput(format!(
                "case {id}: kernel {} is a pass graph, whose other outputs the report does not keep; bless it by \
                 rendering: {}",
                case.kernel.name(),
                case.bless_command()
            )));
        }
        if params_hash(case) != entry.params_hash {
            return Err(stale(id, "its params (preset, set or size) changed since the check".into()));
        }
        let now = files_now(case.kernel.shader()).map_err(|e| stale(id, e))?;
        let changed = crate::changed_files(&entry.shader_files, &now);
        if !changed.is_empty() {
            return Err(stale(id, format!("WGSL changed since the check: {}", changed.join(", "))));
        }
        let png = pending_png(report_dir, id);
        let bytes = std::fs::read(&png)
            .map_err(|e| GoldenError::Io { path: png.display().to_string(), message: e.to_string() })?;
        if crate::short_hash_bytes(&bytes) != entry.golden_hash {
            return Err(stale(id, format!("{} is not the file the check wrote", png.display())));
        }
        accepted.push((case, entry.clone(), bytes));
    }
    let mut manifest = store.manifest()?;
    let mut rows = Vec::new();
    for (case, entry, bytes) in accepted {
        let golden = store.golden_path(case);
        if let Some(parent) = golden.parent() {
            std::fs::create_dir_all(parent)
                .map_err(|e| GoldenError::Io { path: parent.display().to_string(), message: e.to_string() })?;
        }
        let old = std::fs::read(&golden).ok().map(|b| crate::short_hash_bytes(&b));
        // Two-phase, as bless: the manifest accepts both files, the golden
        // is replaced, then the manifest names only the new one.
        let mut e = entry.clone();
        e.replacing = Some(old.clone().unwrap_or_else(|| "none".into()));
        manifest.case.insert(case.id.clone(), e);
        store.write_manifest(&manifest)?;
        vista_image::atomic_write(&golden, &bytes)?;
        manifest.case.insert(case.id.clone(), entry.clone());
        store.write_manifest(&manifest)?;
        rows.push(BlessRow {
            id: case.id.clone(),
            status: if old.is_some() { "changed" } else { "new" },
            psnr_vs_previous: entry.psnr_vs_previous.clone(),
            path: golden,
        });
    }
    Ok(BlessSummary { rows, orphans: Vec::new(), pruned: false, warnings: Vec::new() })
}
