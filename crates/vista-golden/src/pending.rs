//! Goldens from the CI driver (SPEC 15): `vista check` keeps, in the report,
//! each failing or missing case's render (`<id>/actual.png`, its other
//! golden files under `<id>/golden/`) and the manifest entry a bless of it
//! would write (`pending.toml`); `vista bless
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

/// The pending renders `pending.toml` in `report_dir` lists (none where
/// there is no such file).
pub fn read_pending(report_dir: &Path) -> Result<BTreeMap<String, ManifestEntry>, GoldenError> {
    let path = report_dir.join(PENDING_FILE);
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(BTreeMap::new()),
        Err(e) => return Err(GoldenError::Io { path: path.display().to_string(), message: e.to_string() }),
    };
    let pending: Manifest = toml::from_str(&text).map_err(|e| GoldenError::Cases {
        path: path.display().to_string(),
        message: format!("malformed pending file: {}", crate::cases::one_line_toml_error(&text, &e)),
    })?;
    Ok(pending.case)
}

/// The hash of every WGSL file a kernel file reaches in this checkout.
pub type FileHashes<'a> = &'a dyn Fn(&str) -> Result<BTreeMap<String, String>, String>;

/// The rendered PNG of case `id` in a report folder.
pub fn pending_png(report_dir: &Path, id: &str) -> PathBuf {
    report_dir.join(id).join("actual.png")
}

/// Where the report keeps a pending render's other golden file `name`
/// (a raw EXR, another output, a buffer).
pub fn pending_file(report_dir: &Path, id: &str, name: &str) -> PathBuf {
    report_dir.join(id).join("golden").join(name)
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
        // Every field that lands in golden/manifest.toml is checked as the
        // manifest's own: a crafted kernel or golden path is refused.
        if entry.kernel != case.kernel.name() {
            return Err(stale(
                id,
                format!(
                    "it names kernel '{}', but the case's kernel is {}",
                    entry.kernel.escape_debug(),
                    case.kernel.name()
                ),
            ));
        }
        if entry.size != format!("{}x{}", case.width, case.height) {
            return Err(stale(
                id,
                format!("it says size '{}', but the case is {}x{}", entry.size.escape_debug(), case.width, case.height),
            ));
        }
        if params_hash(case) != entry.params_hash {
            return Err(stale(id, "its params (preset, set or size) changed since the check".into()));
        }
        let mut now = BTreeMap::new();
        for f in case.kernel.shader_units() {
            now.extend(files_now(&f).map_err(|e| stale(id, e))?);
        }
        let changed = crate::changed_files(&entry.shader_files, &now);
        if !changed.is_empty() {
            return Err(stale(id, format!("WGSL changed since the check: {}", changed.join(", "))));
        }
        let read_checked = |path: PathBuf, want: &str| -> Result<Vec<u8>, GoldenError> {
            let bytes = std::fs::read(&path)
                .map_err(|e| GoldenError::Io { path: path.display().to_string(), message: e.to_string() })?;
            match crate::short_hash_bytes(&bytes) == want {
                true => Ok(bytes),
                false => Err(stale(id, format!("{} is not the file the check wrote", path.display()))),
            }
        };
        // A graph whose first output is a buffer has no main PNG.
        let png = match entry.golden_hash.is_empty() {
            true => None,
            false => Some(read_checked(pending_png(report_dir, id), &entry.golden_hash)?),
        };
        let mut others = Vec::new();
        for (name, hash) in &entry.outputs {
            // Only the case's own golden files, in its kernel's folder.
            let own = name.starts_with(&format!("{id}."))
                && !name.contains(['/', '\\'])
                && [".png", ".exr", ".npy"].iter().any(|e| name.ends_with(e));
            if !own {
                return Err(stale(id, format!("it names {name}, which is not one of the case's golden files")));
            }
            let bytes = read_checked(pending_file(report_dir, id, name), hash)?;
            others.push((store.dir.join(case.kernel.name()).join(name), bytes));
        }
        accepted.push((case, entry.clone(), png, others));
    }
    let mut manifest = store.manifest()?;
    let mut rows = Vec::new();
    for (case, entry, png, others) in accepted {
        let golden = store.golden_path(case);
        if let Some(parent) = golden.parent() {
            // A real folder reached without a symlink, as bless writes.
            let from = store.dir.parent().unwrap_or(&store.dir);
            vista_image::real_dir_under(from, parent).map_err(|e| GoldenError::BadInput(e.to_string()))?;
        }
        // The other files first, each atomic and named in the entry (as
        // bless writes them).
        for (path, bytes) in &others {
            vista_image::atomic_write(path, bytes)?;
        }
        let Some(bytes) = png else {
            manifest.case.insert(case.id.clone(), entry.clone());
            store.write_manifest(&manifest)?;
            let path = others.first().map(|(p, _)| p.clone()).unwrap_or(golden);
            rows.push(BlessRow { id: case.id.clone(), status: "changed", psnr_vs_previous: "-".into(), path });
            continue;
        };
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
