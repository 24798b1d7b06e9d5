//! One case through the pipeline: render it (`vista-render`), read its
//! golden, judge it (`check::judge`, pure). The images come back with the
//! outcome, for the caller to hand to `vista-report`.

use vista_image::Image;
use vista_render::{Rendered, Renderer, quantize16, render_with};

use crate::Case;
use crate::check::{Observed, Outcome, judge};
use crate::outputs::GoldenFiles;
use crate::store::RunInfo;
use crate::store::{Manifest, Store, params_hash};

/// Options for checking.
#[derive(Debug, Clone, Default)]
pub struct CheckOptions {
    /// Render twice in this process and require bit-identical output,
    /// unless the render is bit-identical with the bless-time one.
    pub twice: bool,
    /// Read the golden's images of a case that passed too (a report that
    /// shows every case in full); otherwise only a case that did not pass
    /// decodes them: at 1920 x 1080 the golden PNG's decode was a sixth of
    /// a passing case's own time.
    pub images_of_passing: bool,
}

/// One judged case and the images the report shows of it.
#[must_use]
#[derive(Debug, Clone)]
pub struct Checked {
    /// The verdict on the case and everything it was judged on.
    pub outcome: Outcome,
    /// The render's display values as a 16-bit PNG holds them (none when it failed).
    pub actual: Option<Image>,
    /// The golden's values, when it could be read (in 16 bits, as its PNG
    /// holds them: the report makes its `Image` once the render is gone).
    pub expected: Option<vista_image::Image16>,
    /// With `expected`: the golden PNG's bytes, which decode to it (the
    /// report copies them rather than encode it again).
    pub expected_png: Option<Vec<u8>>,
    /// The manifest entry a bless of this very render would write (its
    /// `golden_hash` is set once the PNG is written): what the report's
    /// `pending.toml` keeps for `vista bless --from-report`.
    pub pending: Option<crate::ManifestEntry>,
    /// With `pending`, for a failing or missing case: the golden files a
    /// bless would write besides the main PNG (file name, bytes), which the
    /// report keeps under `<id>/golden/`.
    pub pending_files: Vec<(String, Vec<u8>)>,
    /// A pass graph's other texture outputs for the report: (name, display
    /// values as a 16-bit PNG holds them, its golden PNG when readable).
    pub output_images: Vec<(String, Image, Option<Image>)>,
    /// A pass graph's inputs for the report: (resource, where it comes
    /// from, a texture's values as shown).
    pub inputs: Vec<(String, String, Option<Image>)>,
    /// The render's raw hash (none when it failed).
    pub raw_hash: Option<String>,
    /// The render failed because the device's watchdog ended it (a hung
    /// or endless kernel; `vista mutate` counts such a mutant a timeout).
    pub timed_out: bool,
}

/// A pass graph's resources that start from a file or inline data (a
/// case's `inputs` replacing the manifest's file), for the report: (name,
/// what and where from, a texture's values in [0, 1] (normalized when
/// they leave it)). Files are read relative to `root`; one that cannot be
/// read says so (the render refuses it before this is asked).
pub fn inputs_of(case: &Case, root: Option<&std::path::Path>) -> Vec<(String, String, Option<Image>)> {
    use vista_manifest::graph::ResourceKind;
    let g = case.kernel.graph();
    let mut out = Vec::new();
    for r in &g.resources {
        let replaced = case.inputs.iter().find(|(n, _)| *n == r.name).map(|(_, f)| f.clone());
        // Through the guard as the render reads them: a FIFO, a device or a
        // file out of the project is named, never opened.
        let at = |f: &str| -> Result<std::path::PathBuf, String> {
            let Some(root) = root else { return Ok(f.into()) };
            vista_project::guard::check_file(root, &root.join(f), vista_project::guard::MAX_DATA_BYTES)
                .map_err(|e| e.to_string())
        };
        match &r.kind {
            ResourceKind::Texture { file, .. } => {
                let Some(f) = replaced.or(file.clone()) else { continue };
                match at(&f).and_then(|p| vista_image::load(&p).map_err(|e| e.to_string())) {
                    Ok(img) => out.push((
                        r.name.clone(),
                        format!("texture from {f} ({}x{})", img.width, img.height),
                        Some(shown(&img)),
                    )),
                    Err(e) => out.push((r.name.clone(), format!("texture from {f}: {e}"), None)),
                }
            }
            ResourceKind::Buffer { file, data, .. } => {
                let what = match (replaced.or(file.clone()), data) {
                    (Some(f), _) if f.starts_with(vista_render::leaf_values::INLINE) => {
                        format!("buffer from the case's leaf values {}", &f[vista_render::leaf_values::INLINE.len()..])
                    }
                    (Some(f), _) if f.ends_with(".npy") => {
                        match at(&f).and_then(|p| vista_image::npy::read_npy(&p).map_err(|e| e.to_string())) {
                            Ok(n) => format!("buffer from {f} (dtype {}, shape {:?})", n.descr, n.shape),
                            Err(e) => format!("buffer from {f}: {e}"),
                        }
                    }
                    (Some(f), _) => match at(&f).and_then(|p| std::fs::metadata(p).map_err(|e| e.to_string())) {
                        Ok(m) => format!("buffer from {f} ({} bytes)", m.len()),
                        Err(e) => format!("buffer from {f}: {e}"),
                    },
                    (None, Some(values)) => format!("buffer from inline data ({} values)", values.len()),
                    (None, None) => continue,
                };
                out.push((r.name.clone(), what, None));
            }
            ResourceKind::Sampler { .. } | ResourceKind::Depth { .. } => {}
        }
    }
    out
}

/// An input texture as the report shows it: as is when its RGB values lie
/// in [0, 1], else mapped from their min..max; alpha 1.
fn shown(img: &Image) -> Image {
    let in_unit = img.data.iter().flat_map(|p| p[..3].iter()).all(|v| !v.is_finite() || (0.0..=1.0).contains(v));
    match in_unit {
        // As is (non-finite values black, alpha 1), like the normalized view.
        true => Image::from_raw(
            img.width,
            img.height,
            img.data
                .iter()
                .map(|p| {
                    let f = |v: f32| if v.is_finite() { v } else { 0.0 };
                    [f(p[0]), f(p[1]), f(p[2]), 1.0]
                })
                .collect(),
        )
        .expect("same size"),
        false => vista_kernels::normalized(img, 3),
    }
}

/// This run's side of `case`'s provenance: backend, adapter, params hash
/// and the hash of the WGSL the renderer's shaders give the kernel.
pub fn run_info(ctx: &Renderer, case: &Case) -> RunInfo {
    RunInfo {
        backend: ctx.backend().to_string(),
        adapter: ctx.adapter_description(),
        params_hash: params_hash(case),
        shader_hash: ctx.kernel_shader_hash(&case.kernel).unwrap_or_else(|e| format!("unavailable: {e}")),
    }
}

/// Whether this render is bit-identical with the bless-time one on the same
/// adapter, shader and params. Bless rendered twice, so that already shows
/// the kernel deterministic across processes, and check's second render
/// (`CheckOptions::twice`) would only repeat it: it runs where this cannot
/// speak, or fails, to tell a non-deterministic kernel from a changed one.
/// A third of the lavapipe golden run's time (40.7 s to 26.7 s).
fn as_blessed(entry: Option<&crate::ManifestEntry>, run: &RunInfo, raw_hash: &str) -> bool {
    entry.is_some_and(|e| e.same_inputs(run) && e.raw_hash == raw_hash)
}

/// Renders `case` and judges it against its golden and manifest entry
/// (errors become `Verdict::Error`).
pub fn check_case(ctx: &Renderer, store: &Store, manifest: &Manifest, case: &Case, opts: &CheckOptions) -> Checked {
    let run = run_info(ctx, case);
    // A per-backend golden, where this backend has one, with its own entry.
    let (golden_path, golden_key) = store.golden_for(case, ctx.backend());
    let entry = manifest.case.get(&golden_key);
    let r = match render_case(ctx, case) {
        Ok(r) => r,
        Err(e) => {
            let mut outcome = judge(case, entry, run, Err(e.to_string()));
            outcome.crashed = matches!(e, vista_render::RenderError::Crashed(_));
            return Checked {
                timed_out: e.is_timeout(),
                outcome,
                actual: None,
                expected: None,
                expected_png: None,
                pending: None,
                pending_files: Vec::new(),
                output_images: Vec::new(),
                inputs: inputs_of(case, ctx.root.as_deref()),
                raw_hash: None,
            };
        }
    };
    let has_image = r.raw.width > 0;
    // Each texture output's display values as a 16-bit PNG holds them,
    // made once: the verdict compares them and the report shows them.
    let make_views = || -> Vec<Option<Image>> {
        r.outputs
            .iter()
            .enumerate()
            .map(|(i, o)| match i {
                0 => has_image.then(|| quantize16(r.display())),
                _ => o.display().map(|d| quantize16(&d)),
            })
            .collect()
    };
    // Hashed once: at 1920 x 1080 each pass over the raw bits costs ~0.03 s;
    // beside the views where the jobs leave a core idle.
    let (raw_hash, mut views) = match vista_image::threads_for(r.raw.data.len()) > 1 {
        true => std::thread::scope(|s| {
            let hash = s.spawn(|| r.raw.content_hash());
            let views = make_views();
            (hash.join().expect("hashing the render"), views)
        }),
        false => (r.raw.content_hash(), make_views()),
    };
    let deterministic = case.kernel.graph().deterministic;
    let gathered = (|| -> Result<_, String> {
        let repeat_identical = match opts.twice && deterministic && !as_blessed(entry, &run, &raw_hash) {
            true => Some(same_render(&render_case(ctx, case).map_err(|e| e.to_string())?, &r)),
            false => None,
        };
        let files = ctx.kernel_file_hashes(&case.kernel).map_err(|e| e.to_string())?;
        Ok((repeat_identical, files))
    })();
    // Each output's golden files, read once: the verdict judges them and
    // the report shows their PNG.
    let golden_files: Vec<GoldenFiles> = match &gathered {
        Ok(_) => r
            .outputs
            .iter()
            .enumerate()
            .map(|(i, o)| GoldenFiles::read(crate::outputs::output_files(&store.dir, case, &golden_key, i, o)))
            .collect(),
        Err(_) => Vec::new(),
    };
    // The very bits the golden was blessed from, with the same inputs: its
    // PNG holds this view, so judging it needs no decode.
    if let (Some(e), Some(g)) = (entry, golden_files.first())
        && as_blessed(entry, &run, &raw_hash)
    {
        g.known_same(&e.golden_hash);
    }
    let mut out = match &gathered {
        Err(e) => judge(case, entry, run, Err(e.clone())),
        Ok((repeat_identical, files)) => {
            let threshold = crate::DriverThreshold::of(case, entry, &run.adapter);
            let outputs: Vec<crate::outputs::OutputVerdict> = r
                .outputs
                .iter()
                .zip(&golden_files)
                .zip(&views)
                .enumerate()
                .map(|(i, ((o, golden), view))| {
                    crate::outputs::compare_output(case, golden, i, o, view.as_ref(), threshold, entry)
                })
                .collect();
            let observed = Observed {
                raw_hash: &raw_hash,
                format: r.format,
                raw: &r.raw,
                repeat_identical: *repeat_identical,
                shader_files: files,
                outputs: &outputs,
                deterministic,
            };
            judge(case, entry, run, Ok(observed))
        }
    };
    out.gpu_ms = r.stats.gpu_wall.as_secs_f64() * 1e3;
    if golden_key != case.id {
        out.golden_file = format!("{}/{golden_key}.png", case.kernel.name());
        out.notes.push(format!("judged against the per-backend golden {}", golden_path.display()));
        out.bless_command = format!("{} --backend {} --per-backend", out.bless_command, ctx.backend());
    }
    let (pending, pending_files) = match &gathered {
        Ok((_, files)) => pending(store, case, &out, files, &raw_hash, &r),
        Err(_) => (None, Vec::new()),
    };
    let images = opts.images_of_passing || !out.passed();
    // The golden files are moved into what the report shows, not copied.
    let mut golden_files: Vec<Option<GoldenFiles>> = golden_files.into_iter().map(Some).collect();
    let mut golden_of = |i: usize| golden_files.get_mut(i).and_then(Option::take).map(GoldenFiles::into_view_and_png);
    let (expected, expected_png) = match images.then(|| golden_of(0)).flatten() {
        Some((Some(view), png)) => (Some(view), png),
        _ => (None, None),
    };
    let output_images = r
        .outputs
        .iter()
        .zip(views.iter_mut())
        .enumerate()
        .skip(1)
        .filter_map(|(i, (o, view))| {
            let golden = match golden_of(i) {
                _ if !images => None,
                Some((view, _)) => view.map(|v| v.to_image()),
                None => crate::outputs::output_files(&store.dir, case, &golden_key, i, o)
                    .png
                    .and_then(|p| vista_image::read_png16(&p).ok()),
            };
            Some((o.name.clone(), view.take()?, golden))
        })
        .collect();
    let inputs = inputs_of(case, ctx.root.as_deref());
    Checked {
        outcome: out,
        actual: views.into_iter().next().flatten(),
        expected,
        expected_png,
        pending,
        pending_files,
        output_images,
        inputs,
        raw_hash: Some(raw_hash),
        timed_out: false,
    }
}

/// The manifest entry a bless of this render would write (its
/// `golden_hash` is set once the report has written the PNG) and, for a
/// failing or missing case, its other golden files (raw EXR, other outputs,
/// buffers) with their hashes in the entry, which the report keeps so
/// `bless --from-report` accepts the render whole.
fn pending(
    store: &Store,
    case: &Case,
    out: &Outcome,
    files: &std::collections::BTreeMap<String, String>,
    raw_hash: &str,
    r: &Rendered,
) -> (Option<crate::ManifestEntry>, Vec<(String, Vec<u8>)>) {
    let mut e = crate::ManifestEntry::of_render(
        case,
        &out.run,
        files.clone(),
        raw_hash.to_string(),
        out.metrics.map(|m| vista_image::metrics::format_psnr(m.psnr)).unwrap_or_else(|| "new".into()),
        String::new(),
    );
    if !matches!(out.verdict, crate::Verdict::Fail | crate::Verdict::Missing) {
        return (Some(e), Vec::new());
    }
    // Accepted as the case's own golden (bless --from-report writes no per-backend one).
    match crate::outputs::golden_bytes(&store.dir, case, &case.id, &r.outputs) {
        Ok(files) => {
            let named: Vec<(String, Vec<u8>)> = files
                .into_iter()
                .map(|(p, b)| (p.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default(), b))
                .collect();
            e.outputs = named.iter().map(|(n, b)| (n.clone(), crate::short_hash_bytes(b))).collect();
            (Some(e), named)
        }
        Err(_) => (None, Vec::new()),
    }
}

/// Renders a case: its kernel, params, size and replacement inputs.
pub fn render_case(ctx: &Renderer, case: &Case) -> Result<Rendered, vista_render::RenderError> {
    vista_render::for_case(&case.id, || {
        render_with(ctx, &case.kernel, &case.params, &case.inputs, case.width, case.height)
    })
}

/// A case's coverage run: its kernel, params, size and replacement inputs
/// with coverage counters (vista-render's `cover`), counted as the case's.
pub fn cover_case(ctx: &Renderer, case: &Case) -> Result<vista_render::CaseCoverage, vista_render::RenderError> {
    vista_render::for_case(&case.id, || {
        vista_render::cover_with(ctx, &case.kernel, &case.params, &case.inputs, case.width, case.height)
    })
}

/// Whether two renders are bit-identical in every output.
pub fn same_render(a: &Rendered, b: &Rendered) -> bool {
    a.raw.bit_identical(&b.raw)
        && a.outputs.len() == b.outputs.len()
        && a.outputs.iter().zip(&b.outputs).all(|(x, y)| match (&x.value, &y.value) {
            (vista_render::OutputValue::Texture { raw: p, .. }, vista_render::OutputValue::Texture { raw: q, .. }) => {
                p.bit_identical(q)
            }
            (
                vista_render::OutputValue::Buffer { bytes: p, .. },
                vista_render::OutputValue::Buffer { bytes: q, .. },
            ) => p == q,
            _ => false,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry() -> crate::ManifestEntry {
        crate::ManifestEntry {
            kernel: "fbm".into(),
            size: "8x8".into(),
            params_hash: "p".into(),
            shader_hash: "s".into(),
            shader_files: Default::default(),
            adapter: "llvmpipe".into(),
            backend: "lavapipe".into(),
            date: String::new(),
            raw_hash: "r".into(),
            psnr_vs_previous: "new".into(),
            golden_hash: String::new(),
            replacing: None,
            outputs: Default::default(),
        }
    }

    #[test]
    fn the_second_render_is_skipped_only_for_the_bless_time_bits() {
        let run = RunInfo {
            backend: "lavapipe".into(),
            adapter: "llvmpipe".into(),
            params_hash: "p".into(),
            shader_hash: "s".into(),
        };
        assert!(as_blessed(Some(&entry()), &run, "r"));
        assert!(!as_blessed(Some(&entry()), &run, "other bits"), "a changed render renders again");
        assert!(!as_blessed(None, &run, "r"), "no entry: nothing to agree with");
        let other = |f: fn(&mut RunInfo)| {
            let mut r = run.clone();
            f(&mut r);
            as_blessed(Some(&entry()), &r, "r")
        };
        assert!(!other(|r| r.adapter = "SwiftShader".into()), "another adapter");
        assert!(!other(|r| r.shader_hash = "s2".into()), "another shader");
        assert!(!other(|r| r.params_hash = "p2".into()), "other params");
    }
}
