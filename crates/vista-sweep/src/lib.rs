#![deny(missing_docs)]
//! Quality-versus-cost sweeps: render a kernel at every value of one
//! parameter (or every point of a two-parameter grid), compare each render
//! with a high-quality reference render, and record PSNR, SSIM, max-abs and
//! GPU time, so users can pick the cheapest settings that still look right.
//!
//! Metrics are taken on display values by default (what a viewer sees, and
//! what golden checks compare), PSNR peak 1; `Metric::Linear` compares the
//! raw output instead, PSNR peak = max of the reference (SPEC 5's rule for
//! HDR data). The cost of a point is the kernel's own work
//! estimate (`Kernel::work_per_pixel`: octaves, steps x light steps, ...);
//! measured GPU time breaks ties (e.g. `relax`, which changes no count).
//!
//! Not for: drawing progress bars (the caller gets a callback) or golden
//! checks (`vista-golden`). Renders through `vista-render`, as everything does.

mod plot;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use vista_image::metrics::{self, Metrics};
use vista_kernels::{Kernel, Kind, ParamSet};
use vista_render::RenderError;

pub use plot::{PlotError, find_font, write_plots};

/// Default `--target-psnr` (dB).
pub const DEFAULT_TARGET_PSNR: f64 = 40.0;

/// What the images are compared on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Metric {
    /// Display values (tone-mapped for HDR kernels), PSNR peak 1.
    Display,
    /// Raw output (linear radiance for HDR kernels), PSNR peak = reference max.
    Linear,
}

impl Metric {
    /// Parses a `--metric` value (`display` or `linear`).
    pub fn parse(text: &str) -> Result<Metric, RenderError> {
        match text {
            "display" => Ok(Metric::Display),
            "linear" => Ok(Metric::Linear),
            _ => Err(bad(format!("--metric={text} is not valid; expected one of display|linear"))),
        }
    }
    /// The metric's name, as `--metric` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Display => "display",
            Metric::Linear => "linear",
        }
    }
}

/// One swept parameter and its values, as typed by the user.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Axis {
    /// The parameter's name.
    pub name: String,
    /// Its values, as typed.
    pub values: Vec<String>,
}

fn kernel_name<S: serde::Serializer>(k: &Arc<Kernel>, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(k.name())
}

/// A point to render: x value, y value (2-D sweeps), resolved parameters.
pub type SweepPoint = (String, Option<String>, ParamSet);

/// What to sweep.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SweepSpec {
    /// The kernel swept.
    #[serde(serialize_with = "kernel_name")]
    pub kernel: Arc<Kernel>,
    /// The preset every point and the reference start from; the kernel's
    /// defaults when `None`.
    pub preset: Option<String>,
    /// Fixed overrides applied to every point and to the reference.
    pub base: Vec<(String, String)>,
    /// The swept parameter (the x axis).
    pub x: Axis,
    /// The second swept parameter, for a two-parameter grid.
    pub y: Option<Axis>,
    /// Overrides of the reference render (default: the kernel's high-quality settings).
    pub reference: Vec<(String, String)>,
    /// Render width in pixels, of every point and the reference.
    pub width: u32,
    /// Render height in pixels, of every point and the reference.
    pub height: u32,
    /// PSNR (dB) a point must reach to count as good enough (`--target-psnr`).
    pub target_psnr: f64,
    /// Timed renders per point (median reported).
    pub runs: u32,
    /// What the images are compared on.
    pub metric: Metric,
}

/// One measured point.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Point {
    /// The x parameter's value, as typed.
    pub x: String,
    /// The y parameter's value, for a two-parameter grid.
    pub y: Option<String>,
    /// The point's render compared with the reference render, on `spec.metric`.
    pub metrics: Metrics,
    /// Median GPU wall time of the point's render, in milliseconds.
    pub gpu_ms: f64,
    /// Work per pixel of the point's settings: the manifest's estimate,
    /// averaged over the image's rays where it varies per ray.
    pub work: f64,
    /// The point's settings are the reference's own: its PSNR is inf by
    /// construction, so it is never the answer to "cheapest".
    pub is_reference: bool,
}

/// A finished sweep: `curve.json` is this, serialised.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Sweep {
    /// What was swept.
    pub spec: SweepSpec,
    /// The description of the adapter the sweep ran on.
    pub adapter: String,
    /// Median GPU wall time of the reference render, in milliseconds.
    pub reference_ms: f64,
    /// The reference's resolved parameters, canonical (`name=value;...`).
    pub reference_params: String,
    /// Every measured point: x values inner, y values outer.
    pub points: Vec<Point>,
    /// Points whose render crashed the driver (the worker died): the
    /// setting (`octaves=4`) and the crash, in sweep order. The sweep goes
    /// on past them; `vista sweep` exits 1.
    pub crashed: Vec<(String, String)>,
}

fn bad(e: impl std::fmt::Display) -> RenderError {
    RenderError::BadInput(e.to_string())
}

/// Splits `a,b,c` into values; `a:b` style ranges are not accepted so a CSV
/// row always shows exactly what was typed.
pub fn parse_values(flag: &str, text: &str) -> Result<Vec<String>, RenderError> {
    let values: Vec<String> = text.split(',').map(|v| v.trim().to_string()).collect();
    if values.iter().any(String::is_empty) {
        return Err(bad(format!("{flag} '{text}' has an empty value; give a comma-separated list like 8,16,32")));
    }
    if values.len() > 64 {
        return Err(bad(format!("{flag} has {} values; allowed: 1 to 64", values.len())));
    }
    Ok(values)
}

impl SweepSpec {
    /// Every point's parameter set and the reference's, validated before
    /// any GPU work: unknown names and out-of-range values fail here, and so
    /// does a sweep whose total work is past the per-dispatch cap.
    pub fn resolve(&self, limits: &vista_render::RenderLimits) -> Result<(ParamSet, Vec<SweepPoint>), RenderError> {
        let k = &self.kernel;
        for axis in std::iter::once(&self.x).chain(&self.y) {
            let spec = k.params().iter().find(|s| s.name == axis.name).ok_or_else(|| {
                bad(format!(
                    "{} has no parameter '{}'; valid: {}",
                    k.name(),
                    axis.name,
                    k.params().iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")
                ))
            })?;
            if !matches!(spec.kind, Kind::Float { .. } | Kind::Int { .. }) {
                return Err(bad(format!(
                    "{}: cannot sweep '{}' ({}); sweeps need a numeric parameter (use --set for choices)",
                    k.name(),
                    axis.name,
                    spec.kind.range_text()
                )));
            }
        }
        if self.y.as_ref().is_some_and(|y| y.name == self.x.name) {
            return Err(bad(format!("--param and --param2 are both '{}'", self.x.name)));
        }
        if !(1..=100).contains(&self.runs) {
            return Err(bad(format!("--runs {} is out of range; allowed: [1, 100]", self.runs)));
        }
        if !self.target_psnr.is_finite() || !(0.0..=200.0).contains(&self.target_psnr) {
            return Err(bad(format!("--target-psnr {} is out of range; allowed: [0, 200] dB", self.target_psnr)));
        }
        let preset = self.preset.as_deref();
        let reference = k.resolve(preset, &[self.base.clone(), self.reference.clone()].concat()).map_err(bad)?;
        vista_render::check_request(k, &reference, self.width, self.height, limits)?;
        let ys: Vec<Option<&String>> = match &self.y {
            Some(y) => y.values.iter().map(Some).collect(),
            None => vec![None],
        };
        let mut points = Vec::new();
        for yv in ys {
            for xv in &self.x.values {
                let mut set = self.base.clone();
                set.push((self.x.name.clone(), xv.clone()));
                if let (Some(axis), Some(v)) = (&self.y, yv) {
                    set.push((axis.name.clone(), v.clone()));
                }
                let p = k.resolve(preset, &set).map_err(bad)?;
                vista_render::check_request(k, &p, self.width, self.height, limits)?;
                points.push((xv.clone(), yv.cloned(), p));
            }
        }
        Ok((reference, points))
    }
}

/// Runs the sweep. `progress(done, total, label)` is called before each render group.
pub fn run(
    ctx: &vista_render::Renderer,
    spec: &SweepSpec,
    mut progress: impl FnMut(usize, usize, &str),
) -> Result<Sweep, RenderError> {
    let (reference_params, points) = spec.resolve(&ctx.limits)?;
    let (k, w, h) = (&spec.kernel, spec.width, spec.height);
    let total = points.len() + 1;
    progress(0, total, "reference");
    // Warm-up: pipeline compilation is not part of any timing. Renders are
    // named (as cases are) so that a crash says which point it was.
    let (reference, reference_time) = vista_render::for_case("reference", || {
        vista_render::render(ctx, k, &reference_params, 8, 8)?;
        vista_render::render_median(ctx, k, &reference_params, w, h, spec.runs)
    })?;
    let reference_ms = reference_time.as_secs_f64() * 1e3;
    if let Some((x, y)) = reference.raw.first_nonfinite() {
        return Err(RenderError::BadInput(format!("the reference render has NaN/Inf, first at ({x}, {y})")));
    }
    let mut out = Vec::with_capacity(points.len());
    let mut crashed = Vec::new();
    for (i, (xv, yv, p)) in points.iter().enumerate() {
        let label = match yv {
            Some(y) => format!("{}={xv} {}={y}", spec.x.name, spec.y.as_ref().map(|a| a.name.as_str()).unwrap_or("")),
            None => format!("{}={xv}", spec.x.name),
        };
        progress(i + 1, total, &label);
        let (r, time) = match vista_render::for_case(&label, || vista_render::render_median(ctx, k, p, w, h, spec.runs))
        {
            Err(RenderError::Crashed(c)) => {
                crashed.push((label, c.to_string()));
                continue;
            }
            other => other?,
        };
        let gpu_ms = time.as_secs_f64() * 1e3;
        let m = match spec.metric {
            Metric::Display => metrics::compare(reference.display(), r.display())?,
            Metric::Linear => metrics::compare_hdr(&reference.raw, &r.raw)?,
        };
        out.push(Point {
            x: xv.clone(),
            y: yv.clone(),
            metrics: m,
            gpu_ms,
            work: k.mean_work_per_pixel(p, w, h),
            is_reference: p.canonical() == reference_params.canonical(),
        });
    }
    progress(total, total, "done");
    Ok(Sweep {
        spec: spec.clone(),
        adapter: ctx.adapter_description(),
        reference_ms,
        reference_params: reference_params.canonical(),
        points: out,
        crashed,
    })
}

fn fmt_psnr(p: f64) -> String {
    if p.is_infinite() { "inf".into() } else { format!("{p:.2}") }
}

impl Sweep {
    /// The cheapest point reaching the target PSNR: least work, then least
    /// time; never the reference's own settings.
    pub fn cheapest(&self) -> Option<&Point> {
        self.points
            .iter()
            .filter(|p| p.metrics.psnr >= self.spec.target_psnr && !p.is_reference)
            .min_by(|a, b| a.work.total_cmp(&b.work).then(a.gpu_ms.total_cmp(&b.gpu_ms)))
    }

    fn setting(&self, p: &Point) -> String {
        match (&self.spec.y, &p.y) {
            (Some(axis), Some(y)) => format!("{}={} {}={y}", self.spec.x.name, p.x, axis.name),
            _ => format!("{}={}", self.spec.x.name, p.x),
        }
    }

    /// `value[,value2],psnr,ssim,max_abs,bad_pixels,gpu_ms,work_per_pixel,flip_mean`
    /// (flip_mean empty for linear-value sweeps).
    pub fn csv(&self) -> String {
        let mut s = String::new();
        let y_col = self.spec.y.as_ref().map(|a| format!(",{}", a.name)).unwrap_or_default();
        let _ = writeln!(s, "{}{y_col},psnr,ssim,max_abs,bad_pixels,gpu_ms,work_per_pixel,flip_mean", self.spec.x.name);
        for p in &self.points {
            let y = p.y.as_ref().map(|v| format!(",{v}")).unwrap_or_default();
            let _ = writeln!(
                s,
                "{}{y},{},{:.6},{:.6e},{},{:.3},{},{}",
                p.x,
                fmt_psnr(p.metrics.psnr),
                p.metrics.ssim,
                p.metrics.max_abs,
                p.metrics.bad_pixels,
                p.gpu_ms,
                p.work,
                p.metrics.flip_mean.map(|f| format!("{f:.6}")).unwrap_or_default()
            );
        }
        s
    }

    /// The table printed to the terminal, ending with the cheapest setting.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let sp = &self.spec;
        let pairs = |v: &[(String, String)]| v.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(" ");
        let _ = writeln!(
            s,
            "{} {}x{} on {}\nsweep: preset {}{}, metrics on {} values\nreference: {} ({:.1} ms)",
            sp.kernel.name(),
            sp.width,
            sp.height,
            self.adapter,
            sp.preset.as_deref().unwrap_or("(defaults)"),
            if sp.base.is_empty() { String::new() } else { format!(" + {}", pairs(&sp.base)) },
            sp.metric.name(),
            if sp.reference.is_empty() { "same settings".to_string() } else { pairs(&sp.reference) },
            self.reference_ms
        );
        let _ = writeln!(
            s,
            "{:<32} {:>9} {:>8} {:>9} {:>11} {:>10}",
            "setting", "PSNR dB", "SSIM", "FLIP", "max abs", "gpu ms"
        );
        for p in &self.points {
            let mark = match (p.is_reference, p.metrics.psnr >= self.spec.target_psnr) {
                (true, _) => "  (the reference itself)",
                (false, true) => "",
                (false, false) => "  (below target)",
            };
            let _ = writeln!(
                s,
                "{:<32} {:>9} {:>8.4} {:>9} {:>11.3e} {:>10.2}{mark}",
                self.setting(p),
                fmt_psnr(p.metrics.psnr),
                p.metrics.ssim,
                p.metrics.flip_mean.map(|f| format!("{f:.5}")).unwrap_or_else(|| "-".into()),
                p.metrics.max_abs,
                p.gpu_ms
            );
        }
        for (setting, crash) in &self.crashed {
            let _ = writeln!(s, "CRASH {setting}: {crash}");
        }
        match self.cheapest() {
            Some(p) => {
                let _ = writeln!(
                    s,
                    "cheapest reaching {:.1} dB: {} ({} dB, {:.2} ms)",
                    self.spec.target_psnr,
                    self.setting(p),
                    fmt_psnr(p.metrics.psnr),
                    p.gpu_ms
                );
            }
            None => {
                let but = if self.points.iter().any(|p| p.is_reference) { " except the reference itself" } else { "" };
                let _ = writeln!(s, "no swept setting{but} reaches {:.1} dB", self.spec.target_psnr);
            }
        }
        s
    }

    /// Writes `curve.csv`, `summary.txt`, `curve.json` (the whole result), and (when a font is found)
    /// `curve.svg` and `curve.png` into `dir`, atomically each. Returns the
    /// written paths and, when the plots could not be drawn, why.
    /// `font` is the configured font file (`VISTA_FONT`), else a system one.
    pub fn write(&self, dir: &Path, font: Option<&Path>) -> Result<(Vec<PathBuf>, Option<String>), RenderError> {
        std::fs::create_dir_all(dir)
            .map_err(|e| RenderError::Io { path: dir.display().to_string(), message: format!("cannot create: {e}") })?;
        let mut written = Vec::new();
        let json = serde_json::to_string_pretty(self).map_err(|e| bad(format!("JSON encode: {e}")))?;
        for (name, text) in [("curve.csv", self.csv()), ("summary.txt", self.table()), ("curve.json", json)] {
            let path = dir.join(name);
            vista_image::atomic_write(&path, text.as_bytes())?;
            written.push(path);
        }
        match write_plots(self, dir, font) {
            Ok(paths) => {
                written.extend(paths);
                Ok((written, None))
            }
            Err(e) => Ok((written, Some(e.to_string()))),
        }
    }
}
