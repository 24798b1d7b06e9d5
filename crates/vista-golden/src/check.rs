//! Render one case and judge it against its golden.

use std::path::PathBuf;

use vista_image::Image;
use vista_image::metrics::{self, Metrics};

use crate::store::{Manifest, Store, params_hash};
use crate::{Case, GoldenError};
use vista_render::{Renderer, quantize16, render};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    Pass,
    /// Rendered, but a metric or invariant is outside its threshold.
    Fail,
    /// No golden on disk: never created silently.
    Missing,
    /// Could not render or read (bad params, GPU error, corrupt golden).
    Error,
    /// Failed where `expect_fail` in golden/cases.toml says it does.
    ExpectedFail,
}

/// Images written for the report (paths relative to the report dir): the
/// 16-bit files, their 8-bit display copies, and the viewer's data.
#[derive(Debug, Clone, Default)]
pub struct ReportFiles {
    pub expected: Option<String>,
    pub actual: Option<String>,
    /// Heat map on the fixed log scale (`vista_image::log_position`).
    pub diff: Option<String>,
    pub expected8: Option<String>,
    pub actual8: Option<String>,
    pub diff8: Option<String>,
    /// `view.js`: both images' 16-bit values for the viewer's readout.
    pub view: Option<String>,
}

/// The run's side of the provenance, beside the golden's manifest entry.
#[derive(Debug, Clone, Default)]
pub struct RunInfo {
    pub backend: String,
    pub adapter: String,
    pub params_hash: String,
    pub shader_hash: String,
}

/// What happened to one case. `#[must_use]`: callers decide pass/fail.
#[must_use]
#[derive(Debug, Clone)]
pub struct Outcome {
    pub id: String,
    pub kernel: String,
    pub verdict: Verdict,
    pub metrics: Option<Metrics>,
    /// The PSNR threshold that applied, and whether the adapter matched the
    /// manifest's (60 dB same driver, 35 dB other driver by default).
    pub psnr_threshold: f64,
    pub same_driver: bool,
    pub min_ssim: Option<f64>,
    pub max_flip: Option<f64>,
    /// One line per problem or note (shader changed since bless, ...).
    pub problems: Vec<String>,
    pub notes: Vec<String>,
    pub files: ReportFiles,
    pub gpu_ms: f64,
    pub bless_command: String,
    pub width: u32,
    pub height: u32,
    /// The golden's manifest entry at check time, and this run's side.
    pub golden: Option<crate::ManifestEntry>,
    pub run: RunInfo,
    /// WGSL files (relative to `shaders/`) whose hash differs from the one
    /// recorded at bless time, or that were added to or dropped from the
    /// kernel's imports.
    pub changed_files: Vec<String>,
    /// The first NaN/Inf or out-of-range raw pixel, and what it holds.
    pub first_bad: Option<(u32, u32, String)>,
}

/// A pixel is "bad" when a display channel differs by more than this.
pub const BAD_PIXEL_LIMIT: &str = "1/255";

impl Outcome {
    /// Passing for the run: a pass, or a failure that an expectation names.
    pub fn passed(&self) -> bool {
        matches!(self.verdict, Verdict::Pass | Verdict::ExpectedFail)
    }

    /// Share of the image's pixels that are bad, in percent.
    pub fn bad_percent(&self) -> Option<f64> {
        let n = self.width as f64 * self.height as f64;
        self.metrics.map(|m| if n > 0.0 { 100.0 * m.bad_pixels as f64 / n } else { 0.0 })
    }

    /// The compact block `vista check` and the golden tests print under a
    /// case's status line: metrics against thresholds on one line, the
    /// changed shader files, each problem and note, where to look, and
    /// (for a failure) the bless command.
    pub fn explain(&self, report_dir: &std::path::Path) -> String {
        let mut s = String::new();
        match &self.metrics {
            Some(m) => {
                s += &format!(
                    "  PSNR {} (>= {:.1} dB, {} driver) | SSIM {:.5}{} | FLIP {} | max-abs {:.3e} | bad pixels {} \
                     ({:.3}%, > {BAD_PIXEL_LIMIT}) | NaN/Inf {}\n",
                    metrics::format_psnr(m.psnr),
                    self.psnr_threshold,
                    if self.same_driver { "same" } else { "other" },
                    m.ssim,
                    self.min_ssim.map(|t| format!(" (>= {t})")).unwrap_or_default(),
                    m.flip_mean.map(|f| format!("{f:.5}")).unwrap_or_else(|| "-".into()),
                    m.max_abs,
                    m.bad_pixels,
                    self.bad_percent().unwrap_or(0.0),
                    m.nan
                );
            }
            None => s += &format!("  {:?}: no comparison\n", self.verdict),
        }
        if !self.changed_files.is_empty() {
            s += &format!("  changed shader files: {}\n", self.changed_files.join(", "));
        }
        for p in &self.problems {
            s += &format!("  FAIL: {p}\n");
        }
        for n in &self.notes {
            s += &format!("  note: {n}\n");
        }
        if !self.passed() {
            s += &format!("  report: {}#case-{}\n", report_dir.join("index.html").display(), self.id);
            s += &format!("  if this change is intended, bless it: {}\n", self.bless_command);
        }
        s
    }
}

/// Options for checking.
#[derive(Debug, Clone)]
pub struct CheckOptions {
    /// Where expected/actual/diff images go (`target/vista-report`).
    pub report_dir: PathBuf,
    /// Render twice in this process and require bit-identical output.
    pub twice: bool,
}

/// Renders `case`, compares it with its golden and manifest entry, writes
/// report images, and returns the outcome (errors become `Verdict::Error`).
pub fn check_case(ctx: &Renderer, store: &Store, manifest: &Manifest, case: &Case, opts: &CheckOptions) -> Outcome {
    let mut out = Outcome {
        id: case.id.clone(),
        kernel: case.kernel.name().to_string(),
        verdict: Verdict::Pass,
        metrics: None,
        psnr_threshold: case.psnr_same_driver,
        same_driver: true,
        min_ssim: case.min_ssim,
        max_flip: case.max_flip,
        problems: Vec::new(),
        notes: Vec::new(),
        files: ReportFiles::default(),
        gpu_ms: 0.0,
        bless_command: case.bless_command(),
        width: case.width,
        height: case.height,
        golden: manifest.case.get(&case.id).cloned(),
        run: RunInfo {
            backend: ctx.backend().to_string(),
            adapter: ctx.adapter_description(),
            params_hash: params_hash(case),
            shader_hash: ctx.shader_hash(case.kernel.shader()).unwrap_or_else(|e| format!("unavailable: {e}")),
        },
        changed_files: Vec::new(),
        first_bad: None,
    };
    if let Err(e) = judge(ctx, store, manifest, case, opts, &mut out) {
        out.verdict = Verdict::Error;
        out.problems.push(e.to_string());
    } else if out.verdict == Verdict::Pass && !out.problems.is_empty() {
        out.verdict = Verdict::Fail;
    }
    let adapter = ctx.adapter_description();
    if let Some(x) = case.expect_fail.iter().find(|x| x.matches(ctx.backend(), &adapter)) {
        if out.passed() {
            out.verdict = Verdict::Fail;
            out.problems.push(format!(
                "expected to fail on {} (driver '{}': {}) but passed: remove the expectation from golden/cases.toml",
                x.backend, x.driver, x.reason
            ));
        } else {
            out.notes.push(format!(
                "expected failure on {} (driver '{}'): {}; it failed with: {}",
                x.backend,
                x.driver,
                x.reason,
                out.problems.join("; ")
            ));
            out.problems.clear();
            out.verdict = Verdict::ExpectedFail;
        }
    }
    out
}

fn judge(
    ctx: &Renderer,
    store: &Store,
    manifest: &Manifest,
    case: &Case,
    opts: &CheckOptions,
    out: &mut Outcome,
) -> Result<(), GoldenError> {
    let r = render(ctx, case.kernel, &case.params, case.width, case.height)?;
    out.gpu_ms = r.stats.gpu_wall.as_secs_f64() * 1e3;
    let case_dir = opts.report_dir.join(&case.id);
    let write8 = |name: &str, img: &Image| -> Result<String, GoldenError> {
        vista_image::write_png8(&case_dir.join(name), img)?;
        Ok(format!("{}/{name}", case.id))
    };
    let write = |name: &str, img: &Image| -> Result<String, GoldenError> {
        std::fs::create_dir_all(&case_dir).map_err(|e| GoldenError::Io {
            path: case_dir.display().to_string(),
            message: format!("cannot create report dir: {e}"),
        })?;
        // Marks the folder as vista's, so a later run may clear it and nothing else.
        let marker = case_dir.join(crate::report::CASE_MARKER);
        if !marker.exists() {
            std::fs::write(&marker, b"")
                .map_err(|e| GoldenError::Io { path: marker.display().to_string(), message: e.to_string() })?;
        }
        vista_image::write_png16(&case_dir.join(name), img)?;
        Ok(format!("{}/{name}", case.id))
    };
    let actual = quantize16(r.display());
    out.files.actual = Some(write("actual.png", &actual)?);
    out.files.actual8 = Some(write8("actual8.png", &actual)?);

    // Invariants that need no golden: finite, within the documented range.
    if let Some((x, y)) = r.raw.first_nonfinite() {
        out.first_bad = Some((x, y, format!("NaN/Inf {:?}", r.raw.get(x, y))));
        out.problems.push(format!(
            "{} pixels contain NaN/Inf; first at ({x}, {y}) = {:?}",
            r.raw.nonfinite_count(),
            r.raw.get(x, y)
        ));
    }
    let (lo, hi) = case.kernel.output_bounds(&case.params);
    if let Some((x, y, v)) = first_out_of_bounds(&r.raw, lo, hi) {
        out.first_bad.get_or_insert((x, y, format!("{v} outside [{lo}, {hi}]")));
        out.problems.push(format!("raw output {v} at ({x}, {y}) is outside the kernel's range [{lo}, {hi}]"));
    }
    if opts.twice {
        let again = render(ctx, case.kernel, &case.params, case.width, case.height)?;
        if !again.raw.bit_identical(&r.raw) {
            out.problems.push("two renders in one process are not bit-identical (non-deterministic kernel)".into());
        }
    }

    let entry = manifest.case.get(&case.id);
    let adapter = ctx.adapter_description();
    let shader_hash = ctx.shader_hash(case.kernel.shader())?;
    match entry {
        Some(e) => {
            out.same_driver = e.adapter == adapter;
            if !out.same_driver {
                out.psnr_threshold = case.psnr_other_driver;
                out.notes.push(format!("golden blessed on '{}', running on '{adapter}'", e.adapter));
            }
            if e.shader_hash != shader_hash {
                // Named files are reported from `changed_files` (terminal
                // block, report); only an old manifest needs the note.
                if e.shader_files.is_empty() {
                    out.notes.push(format!(
                        "shader changed since the last bless (manifest {}, now {shader_hash}); the manifest \
                         predates per-file hashes, so the files are not named",
                        e.shader_hash
                    ));
                } else {
                    let now = ctx.shader_file_hashes(case.kernel.shader())?;
                    out.changed_files = changed_files(&e.shader_files, &now);
                }
            }
            if e.params_hash != params_hash(case) {
                out.notes.push("case parameters changed since the last bless".into());
            } else if out.same_driver && e.shader_hash == shader_hash && e.raw_hash != r.raw.content_hash() {
                out.problems.push(format!(
                    "not bit-identical with the bless-time render on the same adapter, shader and params \
                     (raw hash {} vs manifest {})",
                    r.raw.content_hash(),
                    e.raw_hash
                ));
            }
        }
        None => out.notes.push("no manifest entry for this case".into()),
    }

    let golden_path = store.golden_path(case);
    if !golden_path.exists() {
        out.verdict = Verdict::Missing;
        out.problems.push(format!(
            "golden {} does not exist; render and review it, then create it with: {}",
            golden_path.display(),
            case.bless_command()
        ));
        return Ok(());
    }
    // Read once: hashed against the manifest, then decoded.
    let bytes = std::fs::read(&golden_path)
        .map_err(|source| vista_image::ImageError::Io { path: golden_path.clone(), source })?;
    if let Some(e) = entry
        && !e.golden_hash.is_empty()
    {
        let on_disk = crate::short_hash_bytes(&bytes);
        if e.replacing.as_deref() == Some(on_disk.as_str()) {
            out.problems.push(format!(
                "golden {} is the file an interrupted bless was replacing; finish it with: {}",
                golden_path.display(),
                case.bless_command()
            ));
        } else if on_disk != e.golden_hash {
            out.problems.push(format!(
                "golden {} (hash {on_disk}) is not the file its manifest entry describes ({}): it was changed \
                 outside vista bless; review it and re-bless: {}",
                golden_path.display(),
                e.golden_hash,
                case.bless_command()
            ));
        }
    }
    let expected = vista_image::decode_png16(&golden_path, &bytes)?;
    out.files.expected = Some(write("expected.png", &expected)?);
    out.files.expected8 = Some(write8("expected8.png", &expected)?);
    if (expected.width, expected.height) != (actual.width, actual.height) {
        out.problems.push(format!(
            "golden {} is {}x{} but the case renders {}x{}; re-bless if the size change is intended",
            golden_path.display(),
            expected.width,
            expected.height,
            actual.width,
            actual.height
        ));
        return Ok(());
    }
    let mut m = metrics::compare(&expected, &actual)?;
    m.nan = r.raw.nonfinite_count();
    let heat = vista_image::diff_heatmap_log(&expected, &actual);
    out.files.diff = Some(write("diff.png", &heat)?);
    out.files.diff8 = Some(write8("diff8.png", &heat)?);
    let view = crate::report::view_js(&case.id, &expected, &actual, out.first_bad.as_ref().map(|b| (b.0, b.1)));
    let view_path = case_dir.join("view.js");
    vista_image::atomic_write(&view_path, view.as_bytes())?;
    out.files.view = Some(format!("{}/view.js", case.id));
    if m.psnr < out.psnr_threshold {
        out.problems.push(format!(
            "PSNR {} is below the threshold {:.1} dB",
            metrics::format_psnr(m.psnr),
            out.psnr_threshold
        ));
    }
    if let Some(t) = case.min_ssim
        && m.ssim < t
    {
        out.problems.push(format!("SSIM {:.5} is below the threshold {t}", m.ssim));
    }
    if let (Some(t), Some(f)) = (case.max_flip, m.flip_mean)
        && f > t
    {
        out.problems.push(format!("FLIP mean {f:.5} is above the threshold {t}"));
    }
    out.metrics = Some(m);
    Ok(())
}

/// Files whose hash differs between bless time and now, or that only one
/// side has, by path.
fn changed_files(
    then: &std::collections::BTreeMap<String, String>,
    now: &std::collections::BTreeMap<String, String>,
) -> Vec<String> {
    let mut changed: Vec<String> = now
        .iter()
        .filter(|(f, h)| then.get(*f) != Some(h))
        .map(|(f, _)| if then.contains_key(f) { f.clone() } else { format!("{f} (new import)") })
        .collect();
    changed.extend(then.keys().filter(|f| !now.contains_key(*f)).map(|f| format!("{f} (no longer imported)")));
    changed
}

/// The first finite raw RGB value outside the kernel's output bounds for
/// `p`, as (x, y, value): the range guard of check, mutate and the fuzzer.
pub fn first_out_of_range(
    kernel: &vista_kernels::Kernel,
    p: &vista_kernels::ParamSet,
    img: &Image,
) -> Option<(u32, u32, f32)> {
    let (lo, hi) = kernel.output_bounds(p);
    first_out_of_bounds(img, lo, hi)
}

fn first_out_of_bounds(img: &Image, lo: f32, hi: f32) -> Option<(u32, u32, f32)> {
    img.data.iter().enumerate().find_map(|(i, p)| {
        p[..3]
            .iter()
            .find(|v| v.is_finite() && (**v < lo || **v > hi))
            .map(|v| (i as u32 % img.width, i as u32 / img.width, *v))
    })
}
