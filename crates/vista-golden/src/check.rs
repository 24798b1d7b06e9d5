//! The verdict: one pure function from what a check observed of a case
//! (its render, its golden as read, this run's provenance) and what the
//! case and manifest say, to an [`Outcome`]. No rendering, no file I/O:
//! `vista check`, the golden tests, `vista bless` (through [`guards`]) and
//! `vista mutate` all judge with it.

use std::collections::BTreeMap;

use vista_image::Image;
use vista_image::metrics::{self, Metrics};

use crate::Case;
use crate::outputs::BAD_PIXEL_LIMIT;
use crate::store::{ManifestEntry, RunInfo};

/// How a case came out of [`judge`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Verdict {
    /// No problem: every guard, provenance check and threshold holds.
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
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct ReportFiles {
    /// The golden's values as a 16-bit PNG (`<id>/expected.png`), when the
    /// golden could be read.
    pub expected: Option<String>,
    /// The render's display values as a 16-bit PNG (`<id>/actual.png`).
    pub actual: Option<String>,
    /// Heat map on the fixed log scale (`vista_image::log_position`).
    pub diff: Option<String>,
    /// 8-bit display copy of `expected`.
    pub expected8: Option<String>,
    /// 8-bit display copy of `actual`.
    pub actual8: Option<String>,
    /// 8-bit display copy of `diff`.
    pub diff8: Option<String>,
    /// `view.js`: both images' 16-bit values for the viewer's readout.
    pub view: Option<String>,
    /// A passing case's one image: its render, at most
    /// `vista_report::THUMB_EDGE` texels across (`<id>/thumb.png`).
    pub thumb: Option<String>,
    /// The golden file as a link from the report folder (set by the check
    /// driver, which knows both folders).
    pub golden_href: Option<String>,
    /// A pass graph's other texture outputs: (name, expected 8-bit, actual
    /// 8-bit).
    pub outputs: Vec<(String, Option<String>, Option<String>)>,
    /// A pass graph's inputs: (resource, where from, an 8-bit image).
    pub inputs: Vec<(String, String, Option<String>)>,
}

/// What happened to one case. `#[must_use]`: callers decide pass/fail.
#[must_use]
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Outcome {
    /// The case id.
    pub id: String,
    /// The name of the case's kernel.
    pub kernel: String,
    /// How the case came out.
    pub verdict: Verdict,
    /// Metrics of the render against the golden; `None` when no comparison was
    /// made.
    pub metrics: Option<Metrics>,
    /// The PSNR threshold that applied, and whether the adapter matched the
    /// manifest's (60 dB same driver, 35 dB other driver by default).
    pub psnr_threshold: f64,
    /// Whether this run's adapter is the one the golden was blessed on (true
    /// without a manifest entry).
    pub same_driver: bool,
    /// The least SSIM the case allows (`min_ssim`), if any.
    pub min_ssim: Option<f64>,
    /// The largest mean FLIP error the case allows (`max_flip`), if any.
    pub max_flip: Option<f64>,
    /// One line per problem or note (shader changed since bless, ...).
    pub problems: Vec<String>,
    /// Remarks that do not fail the case (another adapter, parameters changed
    /// since bless, an expected failure).
    pub notes: Vec<String>,
    /// The render's worker process died: the driver crashed (the problem
    /// says how and where). `vista check` prints it as a `CRASH` block.
    pub crashed: bool,
    /// The report's images of the case; filled in by the caller (`vista-report`).
    pub files: ReportFiles,
    /// GPU wall time of the render in milliseconds; filled in by the caller.
    pub gpu_ms: f64,
    /// The `vista bless` command that re-blesses this case's golden.
    pub bless_command: String,
    /// Width in pixels of the rendered image (the case's size when nothing was
    /// rendered).
    pub width: u32,
    /// Height in pixels of the rendered image, layers and slices stacked top to
    /// bottom (the case's size when nothing was rendered).
    pub height: u32,
    /// The golden's manifest entry at check time, and this run's side.
    pub golden: Option<crate::ManifestEntry>,
    /// This run's side of the provenance.
    pub run: RunInfo,
    /// WGSL files (relative to `shaders/`) whose hash differs from the one
    /// recorded at bless time, or that were added to or dropped from the
    /// kernel's imports.
    pub changed_files: Vec<String>,
    /// The first NaN/Inf or out-of-range raw pixel, and what it holds.
    pub first_bad: Option<(u32, u32, String)>,
    /// A pass graph's outputs as judged (empty for a one-pass kernel).
    pub outputs: Vec<crate::outputs::OutputVerdict>,
    /// The case's ignore rectangles `[x, y, w, h]` (drawn in the report).
    pub ignore: Vec<[u32; 4]>,
    /// The golden judged against, relative to `golden/`
    /// (`<kernel>/<case>.png`, or a per-backend `<kernel>/<case>@<backend>.png`).
    pub golden_file: String,
    /// A coverage run's hits of this case (`check --coverage`) as LCOV,
    /// or why it was not measured; none without coverage.
    #[serde(default)]
    pub coverage: Option<Result<String, String>>,
}

impl Outcome {
    /// Whether `metrics.psnr` is of the main image's raw values (its EXR
    /// golden, which judged it), the rest of the metrics of its view.
    pub fn psnr_of_raw(&self) -> bool {
        self.outputs.first().is_some_and(|o| o.by_raw && o.raw_psnr.is_some())
    }

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
        // A missing golden or an error explains itself in its problem line.
        if let Some(m) = &self.metrics {
            s += &format!(
                "  PSNR {}{} (>= {:.1} dB, {} driver) | SSIM {:.5}{} | FLIP {} | max-abs {:.3e} | bad pixels {} \
                     ({:.3}%, > {BAD_PIXEL_LIMIT}) | NaN/Inf {}\n",
                metrics::format_psnr(m.psnr),
                if self.psnr_of_raw() { " of raw values" } else { "" },
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
            s += &format!("  {}\n", self.advice());
        }
        s
    }

    /// What the case's status line shows: where its main output is judged
    /// by a tolerance, the value it was judged by (`rmse 2.350e-2 (<=
    /// 6.000e-2)`), else its PSNR.
    pub fn headline(&self) -> String {
        if let Some(main) = self.outputs.first().filter(|o| o.by_tolerance && !o.summary.is_empty()) {
            let prefix = format!("output {}: ", main.name);
            return main.summary.strip_prefix(&prefix).unwrap_or(&main.summary).to_string();
        }
        format!("PSNR {}", self.metrics.map(|m| metrics::format_psnr(m.psnr)).unwrap_or_else(|| "-".into()))
    }

    /// The next step for a case that did not pass: blessing fixes a change
    /// of output, not a shader that does not compile or a backend that
    /// lacks a feature.
    pub fn advice(&self) -> String {
        let text = self.problems.join("\n");
        if let Some(at) = text.find("unsupported on ") {
            let feature = text[at..]
                .split("needs ")
                .nth(1)
                .and_then(|r| r.split([' ', ',', ';']).next())
                .filter(|f| !f.is_empty())
                .unwrap_or("<feature>");
            return format!(
                "if {} cannot run it, expect it in golden/cases.toml: expect_fail = [{{ backend = \"{}\", \
                 unsupported = \"{feature}\", reason = \"...\" }}]",
                self.run.backend, self.run.backend
            );
        }
        if self.crashed {
            return format!(
                "the driver crashed, not the kernel's output (bless cannot fix it): report it to the driver's \
                 makers; if {} cannot run the case, expect it in golden/cases.toml: expect_fail = [{{ backend = \
                 \"{}\", reason = \"...\" }}]",
                self.run.backend, self.run.backend
            );
        }
        if text.contains("GPU wait exceeded") {
            return "the kernel did not finish within the watchdog (bless cannot fix it): lower its size or step \
                    counts, or raise VISTA_GPU_TIMEOUT_S"
                .into();
        }
        if self.verdict == Verdict::Error
            && ["WGSL error", "WESL error", "naga validation failed", "#include"].iter().any(|w| text.contains(w))
        {
            return "the shader does not compile: fix it at the file and line above (bless cannot)".into();
        }
        format!("if this change is intended, bless it: {}", self.bless_command)
    }
}

/// What a check observed of one case, gathered by the caller.
#[derive(Debug, Clone, Copy)]
pub struct Observed<'a> {
    /// What the shader wrote.
    pub raw: &'a Image,
    /// Its [`Image::content_hash`], taken once by the caller.
    pub raw_hash: &'a str,
    /// The output's storage format: an integer one compares exactly.
    pub format: &'a str,
    /// Whether a second render in this process was bit-identical; `None`
    /// when the case was rendered once.
    pub repeat_identical: Option<bool>,
    /// Hash of each WGSL file the kernel reaches now, by path.
    pub shader_files: &'a BTreeMap<String, String>,
    /// Every output as compared with its goldens
    /// (`outputs::compare_output`), the main image first.
    pub outputs: &'a [crate::outputs::OutputVerdict],
    /// False for a kernel whose manifest says `deterministic = false`: no
    /// bit-identity with the bless-time render is asked.
    pub deterministic: bool,
}

/// The checks of the case as a whole that need no golden, and so also
/// gate `vista bless` (beside each output's own, written and finite:
/// [`crate::outputs::output_guards`]): the main image within the kernel's
/// documented range, deterministic in one process. Returns each problem
/// (the text check prints) and the main image's first bad raw pixel (NaN
/// or out of range), which the report marks.
pub fn guards(
    case: &Case,
    raw: &Image,
    format: &str,
    repeat_identical: Option<bool>,
) -> (Vec<String>, Option<(u32, u32, String)>) {
    let (mut problems, mut first_bad) = (Vec::new(), None);
    if let Some((x, y)) = raw.first_nonfinite() {
        first_bad = Some((x, y, format!("NaN/Inf {:?}", raw.get(x, y))));
    }
    let (lo, hi) = case.kernel.output_bounds_of(&case.params, format);
    if let Some((x, y, v)) = first_out_of_bounds(raw, lo, hi) {
        first_bad.get_or_insert((x, y, format!("{v} outside [{lo}, {hi}]")));
        problems.push(format!("raw output {v} at ({x}, {y}) is outside the kernel's range [{lo}, {hi}]"));
    }
    if repeat_identical == Some(false) {
        problems.push("two renders in one process are not bit-identical (non-deterministic kernel)".into());
    }
    (problems, first_bad)
}

/// The verdict on one case: `observed` is what the run saw, or why it saw
/// nothing (a render or read error). Applies the guards, the provenance
/// checks against the manifest entry, the golden comparison at the case's
/// thresholds, and last the case's expectations. Pure: the caller fills in
/// `files` and `gpu_ms`.
pub fn judge(case: &Case, entry: Option<&ManifestEntry>, run: RunInfo, observed: Result<Observed, String>) -> Outcome {
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
        crashed: false,
        files: ReportFiles::default(),
        gpu_ms: 0.0,
        bless_command: case.bless_command(),
        width: case.width,
        height: case.height,
        golden: entry.cloned(),
        run,
        changed_files: Vec::new(),
        first_bad: None,
        outputs: Vec::new(),
        golden_file: case.golden_rel_path(),
        ignore: case.ignore.clone(),
        coverage: None,
    };
    match observed {
        Err(e) => {
            out.verdict = Verdict::Error;
            out.problems.push(e);
        }
        Ok(obs) => {
            // The image's own size: layers and slices are stacked top to bottom.
            (out.width, out.height) = (obs.raw.width, obs.raw.height);
            compare(case, entry, &obs, &mut out);
            if out.verdict == Verdict::Pass && !out.problems.is_empty() {
                out.verdict = Verdict::Fail;
            }
        }
    }
    if let Some(x) = case.expect_fail.iter().find(|x| x.matches(&out.run.backend, &out.run.adapter)) {
        if out.passed() {
            out.verdict = Verdict::Fail;
            out.problems.push(format!(
                "expected to fail on {} (driver '{}': {}) but passed: remove the expectation from golden/cases.toml",
                x.backend, x.driver, x.reason
            ));
        } else if !x.unsupported.is_empty()
            && !out
                .problems
                .iter()
                .any(|p| p.starts_with("unsupported on ") && p.contains(&format!("needs {}", x.unsupported)))
        {
            out.problems.push(format!(
                "expected to be unsupported on {} for lack of {} ({}), but it failed otherwise",
                x.backend, x.unsupported, x.reason
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

fn compare(case: &Case, entry: Option<&ManifestEntry>, obs: &Observed, out: &mut Outcome) {
    let (problems, first_bad) = guards(case, obs.raw, obs.format, obs.repeat_identical);
    out.problems.extend(problems);
    out.first_bad = first_bad;
    provenance(case, entry, obs, out);
    outputs_verdict(case, obs.outputs, out);
    // The main image's metrics are the case's.
    out.metrics = obs.outputs.first().and_then(|o| o.metrics);
}

/// The run against the case's manifest entry: the driver (same or other
/// threshold), the changed files, and bit-identity where the adapter,
/// shader and params are the bless-time ones.
fn provenance(case: &Case, entry: Option<&ManifestEntry>, obs: &Observed, out: &mut Outcome) {
    let run = out.run.clone();
    match entry {
        Some(e) => {
            let threshold = crate::DriverThreshold::of(case, Some(e), &run.adapter);
            (out.same_driver, out.psnr_threshold) = (threshold.same_driver, threshold.psnr);
            if !out.same_driver {
                out.notes.push(format!("golden blessed on '{}', running on '{}'", e.adapter, run.adapter));
            }
            if e.shader_hash != run.shader_hash {
                // Named files are reported from `changed_files` (terminal
                // block, report); only an old manifest needs the note.
                if e.shader_files.is_empty() {
                    out.notes.push(format!(
                        "shader changed since the last bless (manifest {}, now {}); the manifest predates per-file \
                         hashes, so the files are not named",
                        e.shader_hash, run.shader_hash
                    ));
                } else {
                    out.changed_files = changed_files(&e.shader_files, obs.shader_files);
                }
            }
            // Integer outputs compare exactly in `outputs` (their EXR golden).
            if e.params_hash != run.params_hash {
                out.notes.push("case parameters changed since the last bless".into());
            } else if obs.deterministic && e.same_inputs(&run) {
                let raw_hash = obs.raw_hash;
                if e.raw_hash != raw_hash {
                    out.problems.push(format!(
                        "not bit-identical with the bless-time render on the same adapter, shader and params \
                         (raw hash {raw_hash} vs manifest {})",
                        e.raw_hash
                    ));
                }
            }
        }
        None => out.notes.push("no manifest entry for this case".into()),
    }
}

/// Folds the output verdicts into the case's: a missing golden file makes
/// the case missing, an unreadable one an error, a difference a failure;
/// each output's notes, and the summary of one that passed, are notes.
fn outputs_verdict(case: &Case, outputs: &[crate::outputs::OutputVerdict], out: &mut Outcome) {
    out.outputs = outputs.to_vec();
    for o in outputs {
        for path in &o.missing {
            out.verdict = Verdict::Missing;
            out.problems.push(format!(
                "golden {} (output {}) does not exist; render and review it, then create it with: {}",
                path.display(),
                o.name,
                case.bless_command()
            ));
        }
        out.notes.extend(o.notes.iter().cloned());
        if !o.errors.is_empty() {
            out.verdict = Verdict::Error;
            out.problems.extend(o.errors.iter().cloned());
        }
        out.problems.extend(o.problems.iter().cloned());
        if o.problems.is_empty() && !o.summary.is_empty() {
            out.notes.push(o.summary.clone());
        }
    }
}

/// Files whose hash differs between bless time and now, or that only one
/// side has, by path.
pub fn changed_files(then: &BTreeMap<String, String>, now: &BTreeMap<String, String>) -> Vec<String> {
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
