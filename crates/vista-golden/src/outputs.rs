//! A kernel's outputs against their goldens (SPEC 14): the first output
//! keeps the case's names (`<case>.png`, raw `<case>.exr`, a buffer
//! `<case>.npy`), the others add their name (`<case>.<output>.png`, ...).
//! Textures keep their PNG view (what the report shows) and, beside it, raw
//! values in EXR ([`keeps_raw`]); buffers are NumPy files. Each output is
//! judged by one procedure ([`compare_output`]): by its tolerance (exact,
//! the default for integer formats and buffers, max_abs, max_rel,
//! max_ulp, rmse or histogram_emd), else a float texture by the case's
//! PSNR threshold on its raw values (on its view where it keeps no EXR),
//! and every texture's view by the case's other thresholds. The first
//! output is the case's main image. A view that is opaque while its alpha
//! means something (`display_alpha = "opaque"`) keeps that alpha in
//! `<case>.alpha.png` (16-bit gray), judged by the case's PSNR threshold.

use std::path::{Path, PathBuf};

use vista_image::metrics::format_psnr;
use vista_image::{Image, Image16, Texels};
use vista_kernels::Kernel;
use vista_manifest::graph::Tolerance;
use vista_render::{OutputRender, OutputValue, quantize16};

use crate::Case;

/// A pixel is "bad" when a display channel differs by more than this.
pub const BAD_PIXEL_LIMIT: &str = "1/255";

/// The golden files of one output.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OutputFiles {
    /// The PNG view (textures).
    pub png: Option<PathBuf>,
    /// Raw values (textures judged by a tolerance or exactly).
    pub exr: Option<PathBuf>,
    /// A buffer's values.
    pub npy: Option<PathBuf>,
    /// The alpha an opaque view drops (the main image of a kernel with
    /// `display_alpha = "opaque"`), as 16-bit gray.
    pub alpha: Option<PathBuf>,
}

impl OutputFiles {
    /// Every file, in png, exr, npy, alpha order.
    pub fn all(&self) -> Vec<&PathBuf> {
        [&self.png, &self.exr, &self.npy, &self.alpha].into_iter().flatten().collect()
    }
}

/// What the case runner found at a golden file's path.
#[derive(Debug, Clone, PartialEq)]
pub enum Found {
    /// No file there.
    Missing,
    /// The file's bytes.
    Bytes(Vec<u8>),
    /// Something there that could not be read (the error, naming the path).
    Unreadable(String),
}

/// One output's golden files and what the case runner found at each: all
/// that [`compare_output`] judges against, so the verdict reads no file.
#[derive(Debug, Clone, Default)]
pub struct GoldenFiles {
    /// Where each file is.
    pub paths: OutputFiles,
    /// What was found at each of `paths.all()`.
    pub found: Vec<(PathBuf, Found)>,
    /// The PNG view decoded, once, in 16 bits (half an `Image`'s memory):
    /// the verdict and the report both read it.
    decoded_view: std::sync::OnceLock<Result<Option<Image16>, String>>,
    /// Set where the PNG is known to hold the render's view ([`GoldenFiles::known_same`]).
    same_as_render: std::sync::OnceLock<()>,
}

impl GoldenFiles {
    /// Reads every file of `paths` (the case runner's part).
    pub fn read(paths: OutputFiles) -> GoldenFiles {
        let found = paths
            .all()
            .into_iter()
            .map(|p| {
                // A regular file under the data cap: a golden that is a
                // device or a FIFO is unreadable, never read forever.
                let found = match vista_project::guard::read_regular(p, vista_project::guard::MAX_DATA_BYTES) {
                    Ok(Some(bytes)) => Found::Bytes(bytes),
                    Ok(None) => Found::Missing,
                    Err(e) => Found::Unreadable(e.to_string()),
                };
                (p.clone(), found)
            })
            .collect();
        GoldenFiles { paths, found, decoded_view: Default::default(), same_as_render: Default::default() }
    }

    /// Golden files already read (tests hold them in memory).
    pub fn of(paths: OutputFiles, found: Vec<(PathBuf, Found)>) -> GoldenFiles {
        GoldenFiles { paths, found, decoded_view: Default::default(), same_as_render: Default::default() }
    }

    /// What was found at `path` (missing if it is not one of these files).
    pub fn at(&self, path: &Path) -> &Found {
        self.found.iter().find(|(p, _)| p == path).map_or(&Found::Missing, |(_, f)| f)
    }

    /// The PNG view's values, where there is one that decodes (the
    /// report shows it beside the render's).
    pub fn view(&self) -> Option<&Image16> {
        self.view_decoded().ok().flatten()
    }

    /// The PNG view's values and the PNG's bytes, moved out (the view
    /// decoded here if the verdict did not need it): the report's copies
    /// of a failing 2048 x 2048 case were 64 MiB and its PNG again.
    pub fn into_view_and_png(self) -> (Option<Image16>, Option<Vec<u8>>) {
        let _ = self.view_decoded();
        let view = self.decoded_view.into_inner().and_then(Result::ok).flatten();
        let png = self.paths.png.as_deref().and_then(|png| {
            let at = self.found.iter().position(|(p, _)| p == png)?;
            match self.found.into_iter().nth(at) {
                Some((_, Found::Bytes(b))) => Some(b),
                _ => None,
            }
        });
        (view, png)
    }

    /// Marks the PNG as holding exactly the render's view, so the verdict
    /// judges the view against itself without decoding the PNG: the caller
    /// knows the render's raw bits are those the golden was blessed from
    /// (a passing case needs no decode). Only where the PNG's bytes
    /// are the ones the manifest entry recorded (`golden_hash`): a file
    /// changed since is decoded and judged as ever. [`GoldenFiles::view`]
    /// still decodes it for a report that shows it.
    pub fn known_same(&self, golden_hash: &str) {
        if let Some(png) = self.paths.png.as_deref()
            && matches!(self.at(png), Found::Bytes(b) if !golden_hash.is_empty() && crate::short_hash_bytes(b) == golden_hash)
        {
            let _ = self.same_as_render.set(());
        }
    }

    /// The PNG view decoded as [`GoldenFiles::view_decoded`] gives it, or
    /// `Some(None)` where it is known to be the render's own.
    fn view_decoded_unless_same(&self) -> Result<Option<Option<&Image16>>, String> {
        match self.same_as_render.get() {
            Some(()) => Ok(Some(None)),
            None => self.view_decoded().map(|v| v.map(Some)),
        }
    }

    /// The PNG view decoded (once): `Ok(None)` when missing or when the
    /// output has none.
    fn view_decoded(&self) -> Result<Option<&Image16>, String> {
        let decoded = self.decoded_view.get_or_init(|| match self.paths.png.as_deref() {
            Some(png) => self.decode(png, vista_image::decode_png16_compact),
            None => Ok(None),
        });
        decoded.as_ref().map(Option::as_ref).map_err(Clone::clone)
    }

    /// The decoded file at `path`: `Ok(None)` when missing, `Err` naming the
    /// path when it cannot be read or decoded.
    fn decode<T>(
        &self,
        path: &Path,
        decode: impl Fn(&Path, &[u8]) -> Result<T, vista_image::ImageError>,
    ) -> Result<Option<T>, String> {
        match self.at(path) {
            Found::Missing => Ok(None),
            Found::Unreadable(e) => Err(e.clone()),
            // A Git LFS pointer where the golden should be: the clone lacks the file.
            Found::Bytes(bytes) if bytes.starts_with(b"version https://git-lfs.github.com/spec/") => Err(format!(
                "{} is a Git LFS pointer, not a {}: run `git lfs pull` (and `git lfs install` once) to fetch the \
                 goldens",
                path.display(),
                path.extension().and_then(|e| e.to_str()).unwrap_or("golden file").to_ascii_uppercase()
            )),
            Found::Bytes(bytes) => decode(path, bytes).map(Some).map_err(|e| e.to_string()),
        }
    }
}

/// The allowance a float buffer without a tolerance gets on a driver other
/// than the one that blessed it (SPEC 16): each value within this many f32
/// units in the last place of the golden's...
pub const CROSS_DRIVER_MAX_ULP: u64 = 16;
/// ...or, for values near zero where ulps are tiny, within this absolute
/// difference. The blessing driver itself compares exactly.
pub const CROSS_DRIVER_MAX_ABS: f64 = 1e-6;

/// How an output is judged: its tolerance, else exact for an integer
/// texture or a buffer (a float buffer on another driver than the
/// blessing one: within [`CROSS_DRIVER_MAX_ULP`] or [`CROSS_DRIVER_MAX_ABS`]),
/// else `None` (a float texture: PSNR of its view).
pub fn effective_tolerance(out: &OutputRender, same_driver: bool) -> Option<Tolerance> {
    match (&out.value, out.tolerance) {
        (_, Some(t)) => Some(t),
        (OutputValue::Buffer { element, .. }, None) if !same_driver && is_f32(element) => {
            Some(Tolerance::UlpOrAbs { max_ulp: CROSS_DRIVER_MAX_ULP, max_abs: CROSS_DRIVER_MAX_ABS })
        }
        (OutputValue::Buffer { .. }, None) => Some(Tolerance::Exact),
        (OutputValue::Texture { format, .. }, None) if vista_kernels::is_integer_format(format) => {
            Some(Tolerance::Exact)
        }
        _ => None,
    }
}

/// Whether a texture output of `format` keeps its raw values in an EXR
/// golden beside its PNG view (SPEC 14): every output of a kernel that
/// describes its own resources, passes or outputs, and any output in
/// another format than the seed's. The seed's contract (one rgba32float
/// image whose display values are the golden, SPEC 3-4: the built-ins and
/// kernels written like them) keeps its PNG and the manifest's raw hash.
pub fn keeps_raw(kernel: &Kernel, format: &str) -> bool {
    kernel.describes_resources() || format != "rgba32float"
}

/// The golden files of output `index` of `case` under `golden_dir`, for
/// golden `key` (the case's id, or `<id>@<backend>` for a per-backend
/// golden).
pub fn output_files(golden_dir: &Path, case: &Case, key: &str, index: usize, out: &OutputRender) -> OutputFiles {
    let stem = match index {
        0 => key.to_string(),
        // A level or layer ("bloom@3") without the @ that marks a per-backend golden.
        _ => format!("{key}.{}", out.name.replace('@', "-")),
    };
    let at = |ext: &str| golden_dir.join(case.kernel.name()).join(format!("{stem}.{ext}"));
    match &out.value {
        OutputValue::Buffer { .. } => OutputFiles { npy: Some(at("npy")), ..Default::default() },
        OutputValue::Texture { format, .. } => OutputFiles {
            png: Some(at("png")),
            exr: (effective_tolerance(out, true).is_some() || keeps_raw(&case.kernel, format)).then(|| at("exr")),
            npy: None,
            alpha: (index == 0 && case.kernel.opaque_display()).then(|| at("alpha.png")),
        },
    }
}

/// One output's verdict.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct OutputVerdict {
    /// The output's name: its resource's (the WGSL variable of an implicit
    /// texture).
    pub name: String,
    /// What it is: `texture rgba16float 64x32`, `buffer <u4 [65536]`.
    pub kind: String,
    /// How it is judged: its tolerance, or the case's PSNR threshold.
    pub judged_by: String,
    /// Its golden files' names.
    pub files: Vec<String>,
    /// Judged by a tolerance (its own, or exact by default): for the main
    /// image, instead of the case's PSNR thresholds.
    pub by_tolerance: bool,
    /// Judged by the case's PSNR threshold on its raw values (its EXR): for
    /// the main image, instead of the PSNR of its view.
    pub by_raw: bool,
    /// That PSNR (dB), where it was measured.
    pub raw_psnr: Option<f64>,
    /// Where values were compared one by one (a tolerance): the elements
    /// or texel channels that differ most, (where, this run, golden).
    pub worst: Vec<(String, f64, f64)>,
    /// And how far they differ: (|difference| range, values in it).
    pub histogram: Vec<(String, u64)>,
    /// Golden files that do not exist.
    pub missing: Vec<PathBuf>,
    /// Golden files that exist but cannot be read.
    pub errors: Vec<String>,
    /// Why the output fails, one line each (a guard, a golden changed outside
    /// bless, a difference beyond its threshold).
    pub problems: Vec<String>,
    /// One line: what was compared and how it came out.
    pub summary: String,
    /// A texture's view against its golden PNG (the main image's are the
    /// case's metrics; `psnr` is its raw values' where an EXR judged them).
    pub metrics: Option<vista_image::metrics::Metrics>,
    /// How it was judged, where that is not the plain rule (a bad-pixel
    /// budget, ignore rectangles, a tolerance instead of PSNR).
    pub notes: Vec<String>,
}

/// Compares output `index` with its goldens as the case runner read them
/// ([`GoldenFiles::read`]); pure: it reads and writes nothing. Every output
/// goes through the same steps: guards, golden files against the manifest
/// entry, raw values (EXR, NumPy) by its tolerance or PSNR, an opaque
/// view's alpha, and a texture's view (`view`: its display values as a
/// 16-bit PNG holds them) against its golden PNG with the case's
/// thresholds. Output 0 is the case's main image: its view's metrics are
/// the case's, and the case's `ignore` rectangles are its.
pub fn compare_output(
    case: &Case,
    golden: &GoldenFiles,
    index: usize,
    out: &OutputRender,
    view: Option<&Image>,
    threshold: crate::DriverThreshold,
    blessed: Option<&crate::ManifestEntry>,
) -> OutputVerdict {
    let files = golden.paths.clone();
    // A case's own tolerance for this output replaces the manifest's; which
    // golden files the output has stays the manifest's (`output_files`).
    let own = case.tolerances.iter().find(|(n, _)| *n == out.name).map(|(_, t)| *t);
    let tolerance = own.or_else(|| effective_tolerance(out, threshold.same_driver));
    let psnr_threshold = threshold.psnr;
    let mut v = OutputVerdict {
        name: out.name.clone(),
        kind: match &out.value {
            OutputValue::Texture { raw, format, .. } => format!("texture {format} {}x{}", raw.width, raw.height),
            OutputValue::Buffer { .. } => {
                let (descr, shape) = out.npy().expect("a buffer");
                format!("buffer {descr} {shape:?}")
            }
        },
        judged_by: match (tolerance, &files.exr, index) {
            (Some(t), _, _) => t.describe(),
            (None, Some(_), _) => format!("PSNR >= {psnr_threshold:.1} dB of its raw values"),
            (None, None, 0) if files.alpha.is_some() => {
                format!("the case's thresholds (the main image); its alpha PSNR >= {psnr_threshold:.1} dB")
            }
            (None, None, 0) => "the case's thresholds (the main image)".into(),
            (None, None, _) => format!("PSNR >= {psnr_threshold:.1} dB of its view"),
        },
        by_tolerance: tolerance.is_some(),
        files: files.all().iter().filter_map(|p| p.file_name().map(|n| n.to_string_lossy().to_string())).collect(),
        ..Default::default()
    };
    v.problems = guard_one(index, out);
    v.problems.extend(changed_outside_bless(case, golden, index, blessed));
    match &out.value {
        OutputValue::Buffer { .. } => {
            let path = files.npy.expect("a buffer's npy");
            let golden = match golden.decode(&path, vista_image::npy::decode_npy) {
                Ok(Some(n)) => n,
                Ok(None) => {
                    v.missing.push(path);
                    return v;
                }
                Err(e) => {
                    v.errors.push(e);
                    return v;
                }
            };
            let (descr, shape) = out.npy().expect("a buffer");
            if golden.descr != descr || golden.shape != shape {
                v.problems.push(format!(
                    "output {}: golden {} has dtype {} shape {:?}, the render {} shape {:?}; re-bless if intended",
                    out.name,
                    path.display(),
                    golden.descr,
                    golden.shape,
                    descr,
                    shape
                ));
                return v;
            }
            let OutputValue::Buffer { element, .. } = &out.value else { unreachable!("a buffer") };
            let expected = vista_render::graph::leaf_values(&golden.data, element);
            let actual = vista_render::graph::leaf_values(out.buffer_body().expect("a buffer"), element);
            let per = element.leaves.len().max(1);
            let locate = |i: usize| {
                let leaf = &element.leaves[i % per].2;
                if leaf.is_empty() { format!("[{}]", i / per) } else { format!("[{}].{leaf}", i / per) }
            };
            judge_values(
                &mut v,
                &out.name,
                tolerance.expect("buffers have one"),
                &expected,
                &actual,
                is_f32(element),
                &locate,
            );
        }
        OutputValue::Texture { raw, format, .. } => {
            if let Some(exr) = &files.exr {
                match golden.decode(exr, vista_image::decode_exr) {
                    Ok(None) => v.missing.push(exr.clone()),
                    Err(e) => v.errors.push(e),
                    Ok(Some(g)) if (g.width, g.height) != (raw.width, raw.height) => v.problems.push(format!(
                        "output {}: golden {} is {}x{} but the render is {}x{}",
                        out.name,
                        exr.display(),
                        g.width,
                        g.height,
                        raw.width,
                        raw.height
                    )),
                    Ok(Some(g)) => match tolerance {
                        Some(t) => {
                            let w = raw.width as usize;
                            let locate = |i: usize| {
                                let t = i / 4;
                                format!("({}, {}).{}", t % w, t / w, ["r", "g", "b", "a"][i % 4])
                            };
                            judge_values(&mut v, &out.name, t, &flat(&g), &flat(raw), true, &locate)
                        }
                        None => judge_raw(&mut v, case, index, format, &g, raw, psnr_threshold),
                    },
                }
            }
            if let Some(alpha) = &files.alpha {
                judge_alpha(&mut v, case, alpha, golden, raw, psnr_threshold);
            }
            let png = files.png.expect("a texture's png");
            let view = view.expect("a texture's view");
            judge_view(&mut v, case, index, raw, view, &png, golden, tolerance.is_some(), psnr_threshold);
        }
    }
    v
}

/// Each golden file of an output that its manifest entry names but whose
/// bytes are not the ones it describes (changed outside vista bless, or
/// left by an interrupted one). The main image's PNG (output 0's) is the
/// entry's `golden_hash`; the other files are its `outputs`.
fn changed_outside_bless(
    case: &Case,
    golden: &GoldenFiles,
    index: usize,
    blessed: Option<&crate::ManifestEntry>,
) -> Vec<String> {
    let mut problems = Vec::new();
    let Some(entry) = blessed else { return problems };
    for (path, found) in &golden.found {
        let Found::Bytes(bytes) = found else { continue };
        let hash = crate::short_hash_bytes(bytes);
        if index == 0 && golden.paths.png.as_ref() == Some(path) {
            if entry.golden_hash.is_empty() {
                continue;
            }
            if entry.replacing.as_deref() == Some(hash.as_str()) {
                problems.push(format!(
                    "golden {} is the file an interrupted bless was replacing; finish it with: {}",
                    path.display(),
                    case.bless_command()
                ));
            } else if hash != entry.golden_hash {
                problems.push(format!(
                    "golden {} (hash {hash}) is not the file its manifest entry describes ({}): it was changed \
                     outside vista bless; review it and re-bless: {}",
                    path.display(),
                    entry.golden_hash,
                    case.bless_command()
                ));
            }
            continue;
        }
        let name = path.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default();
        let Some(want) = entry.outputs.get(&name) else { continue };
        if &hash != want {
            problems.push(format!(
                "golden {} (hash {hash}) is not the file its manifest entry describes ({want}): it was changed \
                 outside vista bless or by an interrupted one; review it and re-bless: {}",
                path.display(),
                case.bless_command()
            ));
        }
    }
    problems
}

/// A texture's view against its golden PNG, the same for every output: the
/// case's ignore rectangles (output 0, the case's image, only) hold the
/// golden's values on both sides; then the case's thresholds: a bad-pixel
/// budget instead of PSNR where the case has one, else PSNR (of the raw
/// values where an EXR golden judged them; none where a tolerance judges
/// the output), the alpha a view keeps, SSIM and FLIP. Problems of outputs
/// after the first name the output.
#[allow(clippy::too_many_arguments)]
fn judge_view(
    v: &mut OutputVerdict,
    case: &Case,
    index: usize,
    raw: &Image,
    actual: &Image,
    png: &Path,
    golden: &GoldenFiles,
    by_tolerance: bool,
    psnr_threshold: f64,
) {
    let expected: &dyn Texels = match golden.view_decoded_unless_same() {
        Ok(Some(Some(g))) => g,
        Ok(Some(None)) => actual,
        Ok(None) => return v.missing.push(png.to_path_buf()),
        Err(e) => return v.errors.push(e),
    };
    let named = if index == 0 { String::new() } else { format!("output {}: ", v.name) };
    if expected.size() != (actual.width, actual.height) {
        let what = if index == 0 { "the case renders" } else { "the render is" };
        return v.problems.push(format!(
            "{named}golden {} is {}x{} but {what} {}x{}; re-bless if the size change is intended",
            png.display(),
            expected.size().0,
            expected.size().1,
            actual.width,
            actual.height
        ));
    }
    let masked;
    let actual = match index == 0 && !case.ignore.is_empty() {
        false => actual,
        true => {
            let (mut a, mut row) = (actual.clone(), Vec::new());
            let mut n = 0u64;
            for &[x, y, w, h] in &case.ignore {
                for yy in y..(y + h).min(a.height) {
                    let theirs = expected.row(yy, &mut row);
                    for xx in x..(x + w).min(a.width) {
                        a.set(xx, yy, theirs[xx as usize]);
                        n += 1;
                    }
                }
            }
            v.notes.push(format!("{n} pixels in {} ignore rectangles left out of the comparison", case.ignore.len()));
            masked = a;
            &masked
        }
    };
    let mut m = match vista_image::metrics::compare(expected, actual) {
        Ok(m) => m,
        Err(e) => return v.errors.push(format!("{named}{e}")),
    };
    m.nan = raw.nonfinite_count();
    if by_tolerance {
        // Judged by the tolerance alone; the metrics stay for the reader.
        if index == 0 {
            v.notes.push("the main image is judged by its output's tolerance instead of PSNR".into());
        }
    } else {
        thresholds(v, case, &named, &mut m, expected, actual, raw, psnr_threshold);
    }
    if index > 0 && v.summary.is_empty() {
        v.summary = format!("output {}: PSNR {} (>= {psnr_threshold:.1} dB)", v.name, format_psnr(m.psnr));
    }
    v.metrics = Some(m);
}

/// A view's metrics against the case's thresholds: its bad-pixel budget or
/// PSNR (its raw values' where they carried the verdict), the alpha a view
/// keeps, SSIM and FLIP.
#[allow(clippy::too_many_arguments)]
fn thresholds(
    v: &mut OutputVerdict,
    case: &Case,
    named: &str,
    m: &mut vista_image::metrics::Metrics,
    expected: &dyn Texels,
    actual: &Image,
    raw: &Image,
    psnr_threshold: f64,
) {
    // A case with a bad-pixel budget is judged by it instead of PSNR: a few
    // pixels that flip far (a crest across drivers) pass, more do not.
    let by_bad_pixels = case.max_bad_pixels.is_some() || case.max_bad_ratio.is_some();
    if by_bad_pixels {
        v.notes.push(format!("{named}judged by its bad-pixel budget (max_bad_pixels / max_bad_ratio) instead of PSNR"));
    } else if let Some(raw_psnr) = v.raw_psnr.filter(|_| v.by_raw) {
        // Its raw values (the EXR golden) carried the PSNR verdict; the
        // view's other metrics stay.
        m.psnr = raw_psnr;
    } else if m.psnr < psnr_threshold {
        v.problems.push(format!("{named}PSNR {} is below the threshold {psnr_threshold:.1} dB", format_psnr(m.psnr)));
    }
    // PSNR, SSIM and FLIP see RGB; a view that keeps the kernel's alpha
    // (display_alpha = "keep") has it compared here, by the same threshold.
    // An opaque view's alpha is judged from its own golden (`judge_alpha`).
    if !case.kernel.opaque_display() && !by_bad_pixels {
        let alpha = alpha_psnr(expected, actual);
        if alpha < psnr_threshold {
            v.problems.push(format!(
                "{named}alpha PSNR {} is below the threshold {psnr_threshold:.1} dB (the view's RGB: PSNR {})",
                format_psnr(alpha),
                format_psnr(m.psnr)
            ));
        }
    }
    if let Some(t) = case.min_ssim
        && m.ssim < t
    {
        v.problems.push(format!("{named}SSIM {:.5} is below the threshold {t}", m.ssim));
    }
    if let (Some(t), Some(f)) = (case.max_flip, m.flip_mean)
        && f > t
    {
        v.problems.push(format!("{named}FLIP mean {f:.5} is above the threshold {t}"));
    }
    if let Some(t) = case.max_bad_pixels
        && m.bad_pixels > t
    {
        v.problems
            .push(format!("{named}{} bad pixels (> {}) is above max_bad_pixels {t}", m.bad_pixels, BAD_PIXEL_LIMIT));
    }
    let pixels = raw.width as f64 * raw.height as f64;
    if let Some(t) = case.max_bad_ratio
        && pixels > 0.0
        && m.bad_pixels as f64 / pixels > t
    {
        v.problems.push(format!(
            "{named}{} bad pixels are {:.5} of the image, above max_bad_ratio {t}",
            m.bad_pixels,
            m.bad_pixels as f64 / pixels
        ));
    }
}

/// PSNR (peak 1) of two views' alpha channels.
fn alpha_psnr(a: &dyn Texels, b: &Image) -> f64 {
    let n = b.data.len().max(1) as f64;
    let (w, mut row, mut sum) = (b.width as usize, Vec::new(), 0.0);
    for y in 0..b.height {
        for (x, y) in a.row(y, &mut row).iter().zip(&b.data[y as usize * w..][..w]) {
            sum += (x[3] as f64 - y[3] as f64).powi(2);
        }
    }
    vista_image::metrics::psnr_from_mse(sum / n, 1.0)
}

/// "N of M texels never written": a workgroup size, dispatch or bounds check
/// that does not cover the output. Shared by check, bless and render.
pub fn unwritten_problem(unwritten: u64, raw: &vista_image::Image) -> String {
    format!(
        "{unwritten} of {} texels never written (the dispatch or a bounds check does not cover the output); \
         if that is intended, add [[output]] partial = true to the kernel's manifest",
        raw.width as u64 * raw.height as u64
    )
}

/// The checks of each output that need no golden: every texel of a
/// texture written unless it is `partial`, finite textures and float
/// buffers (the case's range and determinism are `check::guards`).
pub fn output_guards(outputs: &[OutputRender]) -> Vec<String> {
    outputs.iter().enumerate().flat_map(|(i, o)| guard_one(i, o)).collect()
}

/// [`output_guards`] of output `i`.
fn guard_one(i: usize, o: &OutputRender) -> Vec<String> {
    let mut problems = Vec::new();
    match &o.value {
        OutputValue::Texture { raw, unwritten, .. } => {
            // The main image's problems are the case's; the others name their output.
            let named = if i == 0 { String::new() } else { format!("output {}: ", o.name) };
            if *unwritten > 0 && !o.partial {
                problems.push(format!("{named}{}", unwritten_problem(*unwritten, raw)));
            }
            if let Some((x, y)) = raw.first_nonfinite() {
                problems.push(format!(
                    "{named}{} pixels contain NaN/Inf; first at ({x}, {y}) = {:?}",
                    raw.nonfinite_count(),
                    raw.get(x, y)
                ));
            }
        }
        OutputValue::Buffer { element, .. } => {
            let values = vista_render::graph::leaf_values(o.buffer_body().expect("a buffer"), element);
            if let Some(at) = values.iter().position(|v| !v.is_finite()) {
                let n = values.iter().filter(|v| !v.is_finite()).count();
                problems.push(format!("output {}: {n} values are NaN/Inf; first at value {at}", o.name));
            }
        }
    }
    problems
}

/// The bytes of every golden file of a kernel's outputs (for golden `key`)
/// except the first output's PNG (the case's main golden, which bless
/// writes itself): (path, bytes).
pub fn golden_bytes(
    golden_dir: &Path,
    case: &Case,
    key: &str,
    outputs: &[OutputRender],
) -> Result<Vec<(PathBuf, Vec<u8>)>, vista_image::ImageError> {
    let mut out = Vec::new();
    for (i, o) in outputs.iter().enumerate() {
        let files = output_files(golden_dir, case, key, i, o);
        if let (Some(png), true) = (&files.png, i > 0) {
            out.push((
                png.clone(),
                vista_image::encode_png16_small(png, &quantize16(&o.display().expect("a texture")))?,
            ));
        }
        if let (Some(exr), OutputValue::Texture { raw, .. }) = (&files.exr, &o.value) {
            out.push((exr.clone(), vista_image::encode_exr(exr, raw)?));
        }
        if let (Some(alpha), OutputValue::Texture { raw, .. }) = (&files.alpha, &o.value) {
            out.push((alpha.clone(), vista_image::encode_png16_channel(alpha, raw, 3)?));
        }
        if let Some(npy) = &files.npy {
            let (descr, shape) = o.npy().expect("a buffer");
            out.push((npy.clone(), vista_image::npy::encode_npy(&descr, &shape, o.buffer_body().expect("a buffer"))));
        }
    }
    Ok(out)
}

/// Judges the alpha an opaque view drops against its golden (16-bit gray):
/// PSNR (peak 1) of the raw alpha, clamped and quantized as the golden was,
/// against the case's threshold; the main image's ignore rectangles are
/// left out.
fn judge_alpha(v: &mut OutputVerdict, case: &Case, path: &Path, files: &GoldenFiles, raw: &Image, threshold: f64) {
    let golden = match files.decode(path, vista_image::decode_png16) {
        Ok(Some(g)) => g,
        Ok(None) => {
            v.missing.push(path.to_path_buf());
            return;
        }
        Err(e) => {
            v.errors.push(e);
            return;
        }
    };
    if (golden.width, golden.height) != (raw.width, raw.height) {
        v.problems.push(format!(
            "output {}: golden {} is {}x{} but the render is {}x{}",
            v.name,
            path.display(),
            golden.width,
            golden.height,
            raw.width,
            raw.height
        ));
        return;
    }
    let ignored =
        |x: u32, y: u32| case.ignore.iter().any(|&[rx, ry, w, h]| x >= rx && x < rx + w && y >= ry && y < ry + h);
    let (mut sum, mut count, mut worst) = (0.0f64, 0u64, (0.0f64, 0u32, 0u32));
    for y in 0..raw.height {
        for x in 0..raw.width {
            if ignored(x, y) {
                continue;
            }
            // As the golden was written and is read back: 16 bits, then f32.
            let a = (vista_image::quantize16(raw.get(x, y)[3]) as f32 / 65535.0) as f64;
            let d = (a - golden.get(x, y)[0] as f64).abs();
            sum += d * d;
            count += 1;
            if d > worst.0 || d.is_nan() {
                worst = (d, x, y);
            }
        }
    }
    let mse = if count == 0 { 0.0 } else { sum / count as f64 };
    let psnr = vista_image::metrics::psnr_from_mse(mse, 1.0);
    let shown = vista_image::metrics::format_psnr(psnr);
    v.summary = format!("output {}: alpha PSNR {shown} (>= {threshold:.1} dB; the view is opaque)", v.name);
    if psnr < threshold {
        v.problems.push(format!(
            "output {}: alpha PSNR {shown} is below the threshold {threshold:.1} dB (the PNG view is opaque; the \
             alpha is kept in {}); worst ({}, {}) {:.5} vs golden {:.5}",
            v.name,
            path.display(),
            worst.1,
            worst.2,
            raw.get(worst.1, worst.2)[3],
            golden.get(worst.1, worst.2)[0]
        ));
    }
}

/// Judges a float texture's raw values against its EXR golden by PSNR over
/// the format's colour channels (peak: the golden's largest value for a
/// float format, 1 for unorm and snorm; SPEC 5) against the case's
/// threshold, with max-abs and the worst texel beside it. The main image's
/// ignore rectangles are left out; a main image with a bad-pixel budget is
/// judged by that budget on its view, so here it is only measured.
fn judge_raw(
    v: &mut OutputVerdict,
    case: &Case,
    index: usize,
    format: &str,
    golden: &Image,
    actual: &Image,
    threshold: f64,
) {
    let n = colour_channels(format);
    let ignored = |x: u32, y: u32| {
        index == 0 && case.ignore.iter().any(|&[rx, ry, w, h]| x >= rx && x < rx + w && y >= ry && y < ry + h)
    };
    let (mut sum, mut count, mut worst) = (0.0f64, 0u64, (0.0f64, 0u32, 0u32, 0usize));
    let mut peak = f64::NEG_INFINITY;
    for y in 0..golden.height {
        for x in 0..golden.width {
            if ignored(x, y) {
                continue;
            }
            let (g, a) = (golden.get(x, y), actual.get(x, y));
            for c in 0..n {
                let (g, a) = (g[c] as f64, a[c] as f64);
                if g.is_finite() {
                    peak = peak.max(g);
                }
                let d = (a - g).abs();
                sum += d * d;
                count += 1;
                if d > worst.0 || d.is_nan() {
                    worst = (d, x, y, c);
                }
            }
        }
    }
    let peak = match format.ends_with("float") && peak > 0.0 {
        true => peak,
        false => 1.0,
    };
    let mse = if count == 0 { 0.0 } else { sum / count as f64 };
    let psnr = vista_image::metrics::psnr_from_mse(mse, peak);
    let shown = vista_image::metrics::format_psnr(psnr);
    let worst_at = match worst.0 > 0.0 {
        true => format!(
            ", worst ({}, {}).{} {} vs golden {}",
            worst.1,
            worst.2,
            ["r", "g", "b"][worst.3],
            actual.get(worst.1, worst.2)[worst.3],
            golden.get(worst.1, worst.2)[worst.3]
        ),
        false => String::new(),
    };
    let budget = index == 0 && (case.max_bad_pixels.is_some() || case.max_bad_ratio.is_some());
    v.by_raw = !budget;
    v.raw_psnr = Some(psnr);
    v.summary = match budget {
        true => format!(
            "output {}: raw PSNR {shown} (peak {peak:.4}), max_abs {:.3e}; judged by the bad-pixel budget",
            v.name, worst.0
        ),
        false => format!(
            "output {}: raw PSNR {shown} (peak {peak:.4}, >= {threshold:.1} dB), max_abs {:.3e}",
            v.name, worst.0
        ),
    };
    if !budget && psnr < threshold {
        v.problems.push(format!(
            "output {}: raw PSNR {shown} (peak {peak:.4}) is below the threshold {threshold:.1} dB; max_abs {:.3e}{worst_at}",
            v.name, worst.0
        ));
    }
}

/// Colour channels a storage format holds (alpha is left out of PSNR).
fn colour_channels(format: &str) -> usize {
    match format {
        f if f.starts_with("rgba") || f.starts_with("bgra") => 3,
        f if f.starts_with("rg") => 2,
        _ => 1,
    }
}

fn is_f32(e: &vista_manifest::graph::Element) -> bool {
    e.leaves.iter().all(|l| l.1 == 'f')
}

fn flat(img: &Image) -> Vec<f64> {
    img.data.iter().flat_map(|p| p.iter().map(|c| *c as f64)).collect()
}

/// The values that differ most, (where, this run, golden), and a
/// histogram of |difference|, (range, values in it).
pub type Differences = (Vec<(String, f64, f64)>, Vec<(String, u64)>);

/// The |difference| ranges of [`difference_profile`]'s histogram.
pub const DIFFERENCE_BINS: [&str; 7] = ["0", "<= 1e-6", "<= 1e-4", "<= 1e-2", "<= 1", "> 1", "NaN/Inf"];

/// The `n` values of `actual` that differ most from `expected` (where,
/// this run, golden) and a histogram of |difference| by decade.
pub fn difference_profile(expected: &[f64], actual: &[f64], locate: &dyn Fn(usize) -> String, n: usize) -> Differences {
    let mut counts = [0u64; DIFFERENCE_BINS.len()];
    let mut differing: Vec<(usize, f64)> = Vec::new();
    for (i, (a, e)) in actual.iter().zip(expected).enumerate() {
        let d = (a - e).abs();
        let bin = match d {
            _ if a.to_bits() == e.to_bits() => 0,
            d if !d.is_finite() => 6,
            d if d <= 1e-6 => 1,
            d if d <= 1e-4 => 2,
            d if d <= 1e-2 => 3,
            d if d <= 1.0 => 4,
            _ => 5,
        };
        counts[bin] += 1;
        if bin > 0 {
            differing.push((i, if d.is_finite() { d } else { f64::INFINITY }));
        }
    }
    differing.sort_by(|a, b| b.1.total_cmp(&a.1));
    let worst = differing.iter().take(n).map(|&(i, _)| (locate(i), actual[i], expected[i])).collect();
    (worst, DIFFERENCE_BINS.iter().zip(counts).map(|(b, c)| (b.to_string(), c)).collect())
}

/// Judges `actual` against `expected` by `t`, with the worst values named.
fn judge_values(
    v: &mut OutputVerdict,
    name: &str,
    t: Tolerance,
    expected: &[f64],
    actual: &[f64],
    floats: bool,
    locate: &dyn Fn(usize) -> String,
) {
    if expected.len() == actual.len() {
        (v.worst, v.histogram) = difference_profile(expected, actual, locate, 8);
    }
    match within_at(t, expected, actual, floats, locate) {
        Ok(summary) => v.summary = format!("output {name}: {summary}"),
        Err(problem) => {
            v.summary = format!("output {name}: {problem}");
            v.problems.push(format!("output {name}: {problem}"));
        }
    }
}

/// Whether `actual` is within `t` of `expected`: Ok with the measured
/// figure, or Err naming it, the bound and the worst elements.
pub fn within(t: Tolerance, expected: &[f64], actual: &[f64], floats: bool) -> Result<String, String> {
    within_at(t, expected, actual, floats, &|i| format!("[{i}]"))
}

/// [`within`], each value named by `locate` (a texel and channel, or an
/// element and field).
pub fn within_at(
    t: Tolerance,
    expected: &[f64],
    actual: &[f64],
    floats: bool,
    locate: &dyn Fn(usize) -> String,
) -> Result<String, String> {
    if expected.len() != actual.len() {
        return Err(format!("{} values against {} in the golden", actual.len(), expected.len()));
    }
    let nonfinite = actual.iter().filter(|v| !v.is_finite()).count();
    if nonfinite > 0 && t != Tolerance::Exact {
        return Err(format!("{nonfinite} values are NaN/Inf"));
    }
    let diff = |i: usize| (actual[i] - expected[i]).abs();
    let worst = |score: &dyn Fn(usize) -> f64| -> String {
        let mut idx: Vec<usize> = (0..actual.len()).filter(|i| score(*i) > 0.0 || score(*i).is_nan()).collect();
        idx.sort_by(|a, b| score(*b).total_cmp(&score(*a)));
        let shown: Vec<String> =
            idx.iter().take(5).map(|i| format!("{} {} vs golden {}", locate(*i), actual[*i], expected[*i])).collect();
        format!("{} differ; worst: {}", idx.len(), shown.join(", "))
    };
    match t {
        Tolerance::Exact => {
            let differ = (0..actual.len()).filter(|i| actual[*i].to_bits() != expected[*i].to_bits()).count();
            match differ {
                0 => Ok(format!("{} values, exact", actual.len())),
                _ => Err(format!(
                    "not exact: {}",
                    worst(&|i| if actual[i].to_bits() != expected[i].to_bits() {
                        diff(i).max(f64::MIN_POSITIVE)
                    } else {
                        0.0
                    })
                )),
            }
        }
        Tolerance::MaxAbs(bound) => {
            let m = (0..actual.len()).map(diff).fold(0.0, f64::max);
            match m <= bound {
                true => Ok(format!("max_abs {m:.3e} (<= {bound:.3e})")),
                false => Err(format!("max_abs {m:.3e} is above {bound:.3e}: {}", worst(&diff))),
            }
        }
        Tolerance::MaxRel(bound) => {
            let rel = |i: usize| diff(i) / expected[i].abs().max(f64::MIN_POSITIVE);
            let m = (0..actual.len()).map(rel).fold(0.0, f64::max);
            match m <= bound {
                true => Ok(format!("max_rel {m:.3e} (<= {bound:.3e})")),
                false => Err(format!("max_rel {m:.3e} is above {bound:.3e}: {}", worst(&rel))),
            }
        }
        Tolerance::MaxUlp(bound) => {
            if !floats {
                return Err("max_ulp applies to f32 values; this output holds integers (use exact or max_abs)".into());
            }
            let ulp = |i: usize| ulps(actual[i], expected[i]);
            let m = (0..actual.len()).map(ulp).fold(0.0, f64::max);
            match m <= bound as f64 {
                true => Ok(format!("max_ulp {m} (<= {bound})")),
                false => Err(format!("max_ulp {m} is above {bound}: {}", worst(&ulp))),
            }
        }
        Tolerance::UlpOrAbs { max_ulp, max_abs } => {
            // A value's excess over the allowance: 0 where either bound holds.
            let excess = |i: usize| {
                if diff(i) <= max_abs { 0.0 } else { (ulps(actual[i], expected[i]) - max_ulp as f64).max(0.0) }
            };
            let (m, a) = (0..actual.len()).fold((0.0f64, 0.0f64), |(m, a), i| {
                if excess(i) > 0.0 { (m.max(ulps(actual[i], expected[i])), a.max(diff(i))) } else { (m, a) }
            });
            match m == 0.0 {
                true => Ok(format!(
                    "{} values within max_ulp {max_ulp} or max_abs {max_abs:e} (the cross-driver default)",
                    actual.len()
                )),
                false => Err(format!(
                    "max_ulp {m} (above {max_ulp}) where max_abs {a:.3e} is above {max_abs:e} (the cross-driver \
                     default for a float buffer): {}",
                    worst(&excess)
                )),
            }
        }
        Tolerance::Rmse(bound) => {
            let n = actual.len().max(1) as f64;
            let r = ((0..actual.len()).map(|i| diff(i) * diff(i)).sum::<f64>() / n).sqrt();
            match r <= bound {
                true => Ok(format!("rmse {r:.3e} (<= {bound:.3e})")),
                false => Err(format!("rmse {r:.3e} is above {bound:.3e}: {}", worst(&diff))),
            }
        }
        Tolerance::HistogramEmd { max, bins } => {
            let emd = histogram_emd(expected, actual, bins);
            match emd <= max {
                true => Ok(format!("histogram EMD {emd:.3e} over {bins} bins (<= {max:.3e})")),
                false => Err(format!("histogram EMD {emd:.3e} over {bins} bins is above {max:.3e}")),
            }
        }
    }
}

/// How many f32 units in the last place lie between `a` and `b` (as f32).
fn ulps(a: f64, b: f64) -> f64 {
    let key = |v: f64| {
        let b = (v as f32).to_bits() as i64;
        if b < 0x8000_0000 { b } else { 0x8000_0000 - b }
    };
    (key(a) - key(b)).unsigned_abs() as f64
}

/// Earth mover's distance between the value histograms of `a` and `b`,
/// `bins` bins over the range of both, in units of that range (0: same
/// distribution, 1: all mass moved across the whole range).
pub fn histogram_emd(a: &[f64], b: &[f64], bins: u32) -> f64 {
    let (lo, hi) = a.iter().chain(b).fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) || a.is_empty() || b.is_empty() {
        return 0.0;
    }
    let hist = |v: &[f64]| {
        let mut h = vec![0.0; bins as usize];
        for x in v {
            let i = (((x - lo) / (hi - lo)) * bins as f64).floor().clamp(0.0, bins as f64 - 1.0) as usize;
            h[i] += 1.0 / v.len() as f64;
        }
        h
    };
    let (ha, hb) = (hist(a), hist(b));
    let (mut ca, mut cb, mut emd) = (0.0, 0.0, 0.0);
    for i in 0..bins as usize {
        ca += ha[i];
        cb += hb[i];
        emd += (ca - cb).abs();
    }
    emd / bins as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tolerances_measure_and_name_the_worst_values() {
        let g = [1.0, 2.0, 3.0, 4.0];
        assert!(within(Tolerance::Exact, &g, &g, true).unwrap().contains("exact"));
        let e = within(Tolerance::Exact, &g, &[1.0, 2.0, 3.5, 4.0], true).unwrap_err();
        assert!(e.contains("1 differ") && e.contains("[2] 3.5 vs golden 3"), "{e}");
        assert!(within(Tolerance::MaxAbs(0.5), &g, &[1.0, 2.0, 3.5, 4.0], true).is_ok());
        assert!(within(Tolerance::MaxAbs(0.4), &g, &[1.0, 2.0, 3.5, 4.0], true).unwrap_err().contains("above"));
        assert!(within(Tolerance::MaxRel(0.2), &g, &[1.1, 2.0, 3.0, 4.0], true).is_ok());
        assert!(within(Tolerance::MaxRel(0.05), &g, &[1.1, 2.0, 3.0, 4.0], true).is_err());
        let next = f32::from_bits(3.0f32.to_bits() + 2) as f64;
        assert!(within(Tolerance::MaxUlp(2), &g, &[1.0, 2.0, next, 4.0], true).is_ok());
        assert!(within(Tolerance::MaxUlp(1), &g, &[1.0, 2.0, next, 4.0], true).is_err());
        assert!(within(Tolerance::MaxUlp(1), &g, &g, false).unwrap_err().contains("integers"));
        assert!(within(Tolerance::Rmse(0.25), &g, &[1.0, 2.0, 3.0, 4.5], true).is_ok());
        assert!(within(Tolerance::Rmse(0.24), &g, &[1.0, 2.0, 3.0, 4.5], true).is_err());
        // The same values in another order: no mass moves.
        assert_eq!(histogram_emd(&g, &[4.0, 3.0, 2.0, 1.0], 8), 0.0);
        let moved = histogram_emd(&[0.0, 0.0], &[1.0, 1.0], 10);
        assert!((moved - 0.9).abs() < 1e-12, "{moved}");
        let t = Tolerance::HistogramEmd { max: 0.1, bins: 10 };
        assert!(within(t, &[0.0, 0.0], &[1.0, 1.0], true).is_err());
        assert!(within(Tolerance::MaxAbs(1.0), &g, &[1.0, f64::NAN, 3.0, 4.0], true).unwrap_err().contains("NaN"));
    }

    /// One procedure for every texture's view: the main image (output 0)
    /// and a later output are judged by the same thresholds (alpha, the
    /// case's min_ssim), the later one's problems naming it; the view's
    /// metrics come back with the verdict.
    #[test]
    fn every_texture_view_is_judged_by_one_procedure() {
        let text = "[[case]]\nid = \"a\"\nkernel = \"fbm\"\nmin_ssim = 0.99\n";
        let case = crate::cases::parse_cases(Path::new("cases.toml"), text, vista_kernels::Registry::builtin())
            .unwrap()
            .remove(0);
        let image = |f: &dyn Fn(u32, u32) -> [f32; 4]| {
            Image::from_raw(16, 16, (0..256).map(|i| f(i % 16, i / 16)).collect()).unwrap()
        };
        let raw = image(&|x, y| [x as f32 / 15.0, y as f32 / 15.0, 0.5, 1.0]);
        let out = OutputRender {
            name: "t".into(),
            tolerance: None,
            partial: false,
            value: OutputValue::Texture {
                raw: raw.clone().into(),
                format: "rgba32float",
                view: vista_kernels::Output::Display,
                unwritten: 0,
                display: vista_kernels::DisplayMap::identity(),
            },
        };
        let view = quantize16(&raw);
        let png = PathBuf::from("/nonexistent/golden/fbm/a.t.png");
        let judge = |golden: &Image, index: usize| {
            let bytes = vista_image::encode_png16_small(&png, golden).unwrap();
            let files = GoldenFiles::of(
                OutputFiles { png: Some(png.clone()), ..Default::default() },
                vec![(png.clone(), Found::Bytes(bytes))],
            );
            let threshold = crate::DriverThreshold { psnr: 60.0, same_driver: true };
            compare_output(&case, &files, index, &out, Some(&view), threshold, None)
        };
        for index in [0, 1] {
            let same = judge(&view, index);
            assert!(same.problems.is_empty(), "{index}: {:?}", same.problems);
            assert_eq!(same.metrics.map(|m| m.psnr), Some(f64::INFINITY), "{index}");
            let named = if index == 0 { "" } else { "output t: " };
            // Alpha halved, RGB the same.
            let alpha = judge(&image(&|x, y| [x as f32 / 15.0, y as f32 / 15.0, 0.5, 0.5]), index);
            assert!(
                alpha.problems.iter().any(|p| p.starts_with(&format!("{named}alpha PSNR"))),
                "{index}: {:?}",
                alpha.problems
            );
            // A checkerboard of +-0.2 over the ramp: PSNR and SSIM fall.
            let noisy = image(&|x, y| {
                let d = if (x + y) % 2 == 0 { 0.2 } else { -0.2 };
                [(x as f32 / 15.0 * 0.5 + 0.25 + d), y as f32 / 15.0, 0.5, 1.0]
            });
            let v = judge(&noisy, index);
            for what in ["PSNR", "SSIM"] {
                assert!(
                    v.problems.iter().any(|p| p.starts_with(&format!("{named}{what}"))),
                    "{index} {what}: {:?}",
                    v.problems
                );
            }
        }
    }

    /// A golden known to hold the render's view (its bless-time bits) is
    /// judged without decoding the PNG (these bytes would not decode); a
    /// missing PNG or an LFS pointer stays what it is.
    #[test]
    fn a_known_view_is_not_decoded() {
        let png = PathBuf::from("/nowhere/golden/fbm/a.png");
        let files = |found: Found| {
            GoldenFiles::of(OutputFiles { png: Some(png.clone()), ..Default::default() }, vec![(png.clone(), found)])
        };
        let bytes = b"not a PNG at all".to_vec();
        let recorded = crate::short_hash_bytes(&bytes);
        let g = files(Found::Bytes(bytes.clone()));
        g.known_same(&recorded);
        assert_eq!(g.view_decoded_unless_same(), Ok(Some(None)), "judged as the render's own view");
        assert!(g.view().is_none(), "the report's copy is still decoded (and these bytes fail)");
        let undecoded = files(Found::Bytes(bytes.clone()));
        assert!(undecoded.view_decoded_unless_same().is_err(), "without it, the bytes are decoded (and fail)");
        let changed = files(Found::Bytes(b"not the recorded bytes".to_vec()));
        changed.known_same(&recorded);
        assert!(changed.view_decoded_unless_same().is_err(), "a file changed since the bless is decoded");
        let missing = files(Found::Missing);
        missing.known_same(&recorded);
        assert_eq!(missing.view_decoded_unless_same(), Ok(None), "a missing golden stays missing");
        let lfs = files(Found::Bytes(b"version https://git-lfs.github.com/spec/v1\noid sha256:0".to_vec()));
        lfs.known_same(&recorded);
        assert!(lfs.view_decoded_unless_same().unwrap_err().contains("Git LFS pointer"));
    }

    /// The verdict judges the golden files as the runner read them and
    /// reads nothing itself: golden bytes held in memory, at a path with no
    /// file behind it, decide it (equal values pass, one changed value
    /// fails, no bytes is a missing golden).
    #[test]
    fn compare_output_judges_what_the_runner_read_and_reads_nothing() {
        let text = "[[case]]\nid = \"a\"\nkernel = \"fbm\"\n";
        let case = crate::cases::parse_cases(Path::new("cases.toml"), text, vista_kernels::Registry::builtin())
            .unwrap()
            .remove(0);
        let element = vista_manifest::graph::Element {
            stride: 4,
            header: 0,
            fixed: None,
            leaves: vec![(0, 'u', String::new())],
            wgsl: "array<u32>".into(),
        };
        let words = |w: &[u32]| w.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>();
        let out = OutputRender {
            name: "counts".into(),
            tolerance: None,
            partial: false,
            value: OutputValue::Buffer { bytes: words(&[1, 2, 3]), element, count: 3 },
        };
        let npy = PathBuf::from("/nonexistent/golden/fbm/a.counts.npy");
        let golden = |found: Found| {
            GoldenFiles::of(OutputFiles { npy: Some(npy.clone()), ..Default::default() }, vec![(npy.clone(), found)])
        };
        let (descr, shape) = out.npy().unwrap();
        let judge = |g: &GoldenFiles| {
            let threshold = crate::DriverThreshold { psnr: 60.0, same_driver: true };
            compare_output(&case, g, 1, &out, None, threshold, None)
        };
        let same = judge(&golden(Found::Bytes(vista_image::npy::encode_npy(&descr, &shape, &words(&[1, 2, 3])))));
        assert!(same.problems.is_empty() && same.missing.is_empty() && same.errors.is_empty(), "{same:?}");
        let changed = judge(&golden(Found::Bytes(vista_image::npy::encode_npy(&descr, &shape, &words(&[1, 5, 3])))));
        assert!(changed.problems.iter().any(|p| p.contains("[1] 2 vs golden 5")), "{:?}", changed.problems);
        assert_eq!(judge(&golden(Found::Missing)).missing, vec![npy.clone()]);
        let unreadable = judge(&golden(Found::Unreadable("I/O error on x: denied".into())));
        assert_eq!(unreadable.errors, ["I/O error on x: denied"]);
    }

    /// A float buffer compares exactly on the blessing driver and within
    /// the cross-driver default on another (one ulp apart, as boids on
    /// SwiftShader against lavapipe); an integer buffer stays exact.
    #[test]
    fn float_buffers_get_the_cross_driver_default_on_another_driver() {
        let buffer = |kind: char| OutputRender {
            name: "boids".into(),
            tolerance: None,
            partial: false,
            value: OutputValue::Buffer {
                bytes: vec![0; 16],
                element: vista_manifest::graph::Element {
                    stride: 16,
                    header: 0,
                    fixed: None,
                    leaves: vec![(0, kind, "pos".into()), (8, kind, "vel".into())],
                    wgsl: "Boid".into(),
                },
                count: 1,
            },
        };
        let default = Tolerance::UlpOrAbs { max_ulp: CROSS_DRIVER_MAX_ULP, max_abs: CROSS_DRIVER_MAX_ABS };
        assert_eq!(effective_tolerance(&buffer('f'), true), Some(Tolerance::Exact));
        assert_eq!(effective_tolerance(&buffer('f'), false), Some(default));
        assert_eq!(effective_tolerance(&buffer('u'), false), Some(Tolerance::Exact));
        let g = [0.25, -0.5, 1e-9, 3.0];
        let one_ulp = f32::from_bits(0.25f32.to_bits() + 1) as f64;
        assert!(within(Tolerance::Exact, &g, &[one_ulp, -0.5, 1e-9, 3.0], true).is_err(), "same driver: exact");
        assert!(within(default, &g, &[one_ulp, -0.5, -1e-9, 3.0], true).is_ok(), "1 ulp, and a sign flip near 0");
        let e = within(default, &g, &[0.25, -0.5, 1e-9, 3.001], true).unwrap_err();
        assert!(e.contains("[3] 3.001 vs golden 3") && e.contains("cross-driver default"), "{e}");
    }
}
