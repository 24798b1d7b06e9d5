//! `vista bless`: re-render cases and write their goldens and manifest.
//!
//! Everything selected is rendered first; nothing is written unless every
//! render succeeded and is finite. Each golden and the manifest are then
//! written atomically, one case at a time, so an interrupted bless leaves
//! every golden either old or new, never truncated.

use std::path::PathBuf;

use vista_image::metrics;

use crate::store::{ManifestEntry, Store, params_hash};
use crate::{GoldenError, select};
use vista_render::{Rendered, Renderer, quantize16};

/// What `vista bless` blesses, and how.
#[derive(Debug, Clone, Default)]
pub struct BlessOptions {
    /// Glob over case ids; all cases when `None`.
    pub glob: Option<String>,
    /// Bless even when `CI=true`.
    pub force: bool,
    /// Running in CI (`CI=true`, read at the edge): bless is refused unless forced.
    pub in_ci: bool,
    /// Delete golden PNGs that no case refers to (otherwise only listed).
    pub prune: bool,
    /// Write `<case>@<backend>.png` (entry `<case>@<backend>`), the golden
    /// this backend is judged against from now on, instead of the case's own.
    pub per_backend: bool,
}

/// One blessed case, for the summary table.
#[derive(Debug, Clone)]
pub struct BlessRow {
    /// The case id.
    pub id: String,
    /// "new", "changed" or "unchanged".
    pub status: &'static str,
    /// PSNR of the new golden against the old one.
    pub psnr_vs_previous: String,
    /// The golden file written (for a case without a main image, its first other golden file).
    pub path: PathBuf,
}

/// Result of a bless: the rows, and orphaned goldens (deleted if pruned).
#[derive(Debug, Clone, Default)]
pub struct BlessSummary {
    /// One row per blessed case, in selection order.
    pub rows: Vec<BlessRow>,
    /// Goldens over 1 MiB, one line each.
    pub warnings: Vec<String>,
    /// Golden files on disk that no case refers to (`Store::orphans`).
    pub orphans: Vec<PathBuf>,
    /// Whether the orphans were deleted (`BlessOptions::prune`).
    pub pruned: bool,
}

/// A golden larger than this is named when blessed.
pub const GOLDEN_WARN_BYTES: usize = 1 << 20;

/// Renders every selected case and, only if all succeed and pass the guards
/// `vista check` applies, writes each golden and its manifest entry
/// (atomically, case by case); lists orphaned goldens and deletes them with
/// `prune`. Refused when `in_ci` is set without `force`.
pub fn bless(ctx: &Renderer, store: &Store, opts: &BlessOptions) -> Result<BlessSummary, GoldenError> {
    if opts.in_ci && !opts.force {
        return Err(GoldenError::Refused(
            "CI=true: refusing to bless goldens in CI (a failing golden must be reviewed, not overwritten); \
             bless locally, or pass --force"
                .into(),
        ));
    }
    let cases = store.load_cases()?;
    let picked = select(&cases, opts.glob.as_deref())?;
    let mut manifest = store.manifest()?;
    let adapter = ctx.adapter_description();
    let rendered = render_checked(ctx, &picked, opts.per_backend)?;

    // Temp files of a writer that was killed earlier are never read; clear them.
    vista_image::remove_stale_temps(&store.dir);
    for case in &picked {
        if let Some(dir) = store.golden_path(case).parent() {
            vista_image::remove_stale_temps(dir);
        }
    }
    let mut rows = Vec::new();
    let mut warnings = Vec::new();
    for (case, r) in rendered {
        let (path, key) = match opts.per_backend {
            true => (store.backend_golden_path(case, ctx.backend()), format!("{}@{}", case.id, ctx.backend())),
            false => (store.golden_path(case), case.id.clone()),
        };
        // A pass graph's other files first: each atomic, named in the entry.
        let extra = crate::outputs::golden_bytes(&store.dir, case, &key, &r.outputs)?;
        let (extra_hashes, extra_changed) = write_extra_files(store, &extra)?;
        let run = crate::RunInfo {
            backend: ctx.backend().to_string(),
            adapter: adapter.clone(),
            params_hash: params_hash(case),
            shader_hash: ctx.kernel_shader_hash(&case.kernel)?,
        };
        let files = ctx.kernel_file_hashes(&case.kernel)?;
        if r.raw.width == 0 {
            // No main image (a graph whose first output is a buffer).
            let previous = manifest.case.get(&key);
            let status = match previous {
                None => "new",
                Some(p) if p.outputs == extra_hashes && !extra_changed => "unchanged",
                Some(_) => "changed",
            };
            let mut entry =
                ManifestEntry::of_render(case, &run, files, r.raw.content_hash(), status.into(), String::new());
            entry.outputs = extra_hashes;
            manifest.case.insert(key.clone(), entry);
            store.write_manifest(&manifest)?;
            let shown = extra.first().map(|(p, _)| p.clone()).unwrap_or(path);
            rows.push(BlessRow { id: case.id.clone(), status, psnr_vs_previous: status.into(), path: shown });
            continue;
        }
        let entry = ManifestEntry::of_render(case, &run, files, r.raw.content_hash(), String::new(), String::new());
        let (status, psnr) = write_main_image(
            store,
            &mut manifest,
            &key,
            &path,
            r.display(),
            entry,
            extra_hashes,
            extra_changed,
            &mut warnings,
        )?;
        rows.push(BlessRow { id: case.id.clone(), status, psnr_vs_previous: psnr, path });
    }

    let orphans = store.orphans(&cases);
    if opts.prune {
        for o in &orphans {
            std::fs::remove_file(o)
                .map_err(|e| GoldenError::Io { path: o.display().to_string(), message: e.to_string() })?;
        }
        let live: std::collections::HashSet<&str> = cases.iter().map(|c| c.id.as_str()).collect();
        // Per-backend entries (`<case>@<backend>`) live with their case.
        manifest.case.retain(|key, _| live.contains(key.split('@').next().unwrap_or_default()));
        store.write_manifest(&manifest)?;
    }
    Ok(BlessSummary { rows, orphans, pruned: opts.prune, warnings })
}

/// Renders every picked case (twice where it is deterministic) and refuses
/// the whole bless, writing nothing, if any fails a check `vista check`
/// would fail it by without a golden, with the same words.
fn render_checked<'c>(
    ctx: &Renderer,
    picked: &[&'c crate::Case],
    per_backend: bool,
) -> Result<Vec<(&'c crate::Case, Rendered)>, GoldenError> {
    let mut rendered: Vec<(&crate::Case, Rendered)> = Vec::new();
    for case in picked {
        let r = crate::run::render_case(ctx, case)?;
        if per_backend && r.raw.width == 0 {
            return Err(GoldenError::BadInput(format!(
                "--per-backend: case {}'s first output is a buffer; a per-backend golden is found by its main PNG \
                 (<case>@<backend>.png), so its first output must be a texture; nothing was written",
                case.id
            )));
        }
        // The checks of `vista check` that need no golden, with the same
        // words: a golden is never blessed from output check would fail.
        let identical = match case.kernel.graph().deterministic {
            true => Some(crate::run::same_render(&crate::run::render_case(ctx, case)?, &r)),
            false => None,
        };
        let (mut problems, _) = crate::guards(case, &r.raw, r.format, identical);
        problems.extend(crate::outputs::output_guards(&r.outputs));
        if !problems.is_empty() {
            return Err(GoldenError::Rejected(format!(
                "case {}: {}; refusing to bless it (vista check would fail it); nothing was written",
                case.id,
                problems.join("; ")
            )));
        }
        rendered.push((case, r));
    }

    Ok(rendered)
}

/// Makes `dir` (under the store's folder) a real folder reached from the
/// project without a symlink: goldens are never written through one.
fn golden_dir(store: &Store, dir: &std::path::Path) -> Result<(), GoldenError> {
    let from = store.dir.parent().unwrap_or(&store.dir);
    vista_image::real_dir_under(from, dir).map_err(|e| GoldenError::BadInput(e.to_string()))
}

/// Writes the golden files a case keeps besides its main image (each only
/// if its bytes changed); their hashes by file name, and whether any changed.
fn write_extra_files(
    store: &Store,
    extra: &[(std::path::PathBuf, Vec<u8>)],
) -> Result<(std::collections::BTreeMap<String, String>, bool), GoldenError> {
    let mut extra_hashes = std::collections::BTreeMap::new();
    let mut extra_changed = false;
    for (file, bytes) in extra {
        if let Some(parent) = file.parent() {
            golden_dir(store, parent)?;
        }
        let hash = crate::short_hash_bytes(bytes);
        // The old file, if a regular one (a FIFO or device is rewritten, never read).
        let old = vista_project::guard::read_regular(file, vista_project::guard::MAX_DATA_BYTES).ok().flatten();
        if old.map(|b| crate::short_hash_bytes(&b)).as_deref() != Some(hash.as_str()) {
            extra_changed = true;
            vista_image::atomic_write(file, bytes)?;
        }
        let name = file.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default();
        extra_hashes.insert(name, hash);
    }
    Ok((extra_hashes, extra_changed))
}

/// Writes a case's main golden PNG from its display values and its
/// manifest entry (`entry`, completed here), two-phase, keeping the old
/// bytes where the pixels did not change; its status and PSNR against the
/// previous golden.
#[allow(clippy::too_many_arguments)]
fn write_main_image(
    store: &Store,
    manifest: &mut crate::Manifest,
    key: &str,
    path: &std::path::Path,
    display: &vista_image::Image,
    mut entry: ManifestEntry,
    extra_hashes: std::collections::BTreeMap<String, String>,
    extra_changed: bool,
    warnings: &mut Vec<String>,
) -> Result<(&'static str, String), GoldenError> {
    let new = quantize16(display);
    // Read once: decoded for the PSNR against the new golden, hashed below.
    // A regular file only: a FIFO or a device in its place is replaced, never read.
    let old_bytes = vista_project::guard::read_regular(path, vista_project::guard::MAX_DATA_BYTES).ok().flatten();
    let old = old_bytes.as_deref().map(|b| vista_image::decode_png16(path, b));
    let (status, psnr) = match old {
        Some(Ok(old)) if (old.width, old.height) == (new.width, new.height) => {
            let p = metrics::psnr(&old, &new);
            (if p.is_infinite() { "unchanged" } else { "changed" }, metrics::format_psnr(p))
        }
        Some(Ok(_)) => ("changed", "size changed".to_string()),
        Some(Err(_)) => ("changed", "old golden unreadable".to_string()),
        None if path.exists() => ("changed", "old golden unreadable".to_string()),
        None => ("new", "new".to_string()),
    };
    if let Some(parent) = path.parent() {
        golden_dir(store, parent)?;
    }
    // Goldens live in a repository: the smallest lossless encoding, and
    // a golden whose pixels did not change keeps its bytes (another
    // encoder version must not churn the history).
    let bytes = match (status, &old_bytes) {
        ("unchanged", Some(old)) => old.clone(),
        _ => vista_image::encode_png16_small(path, &new)?,
    };
    if bytes.len() > GOLDEN_WARN_BYTES {
        warnings.push(format!(
            "golden {} is {:.1} MiB (over 1 MiB): a smaller case size, or Git LFS for golden/ (see the README)",
            path.display(),
            bytes.len() as f64 / (1 << 20) as f64
        ));
    }
    let new_hash = crate::short_hash_bytes(&bytes);
    let old_hash = old_bytes.as_deref().map(crate::short_hash_bytes);
    entry.psnr_vs_previous = psnr.clone();
    entry.golden_hash = new_hash.clone();
    entry.outputs = extra_hashes;
    let status = if status == "unchanged" && extra_changed { "changed" } else { status };
    let same_render = |e: &ManifestEntry| {
        (&e.params_hash, &e.shader_hash, &e.adapter, &e.raw_hash)
            == (&entry.params_hash, &entry.shader_hash, &entry.adapter, &entry.raw_hash)
    };
    if old_hash.as_deref() == Some(new_hash.as_str())
        && let Some(previous) = manifest.case.get(key).filter(|e| same_render(e))
    {
        // Nothing changed: keep the entry's date and PSNR-vs-previous (the
        // provenance of the last real change), only completing its hashes
        // (per-file shader hashes too: equal shader_hash, equal files).
        let (shader_files, backend) = (entry.shader_files.clone(), entry.backend.clone());
        entry = ManifestEntry {
            golden_hash: new_hash.clone(),
            replacing: None,
            shader_files,
            backend,
            outputs: entry.outputs.clone(),
            ..previous.clone()
        };
    } else if old_hash.as_deref() != Some(new_hash.as_str()) {
        // Two-phase per case: the manifest first accepts both files, then
        // the golden is replaced, then the manifest names only the new one.
        // A stop anywhere leaves a golden that its entry describes.
        entry.replacing = Some(old_hash.unwrap_or_else(|| "none".into()));
        manifest.case.insert(key.to_string(), entry.clone());
        store.write_manifest(manifest)?;
        vista_image::atomic_write(path, &bytes)?;
        entry.replacing = None;
    }
    manifest.case.insert(key.to_string(), entry);
    store.write_manifest(manifest)?;
    Ok((status, psnr))
}
