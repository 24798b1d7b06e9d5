//! case -> kernel -> GPU run -> image: the one path every render takes.

use std::sync::OnceLock;
use std::time::{Duration, Instant};

use vista_gpu::{Context, Dispatch, RunStats, ShaderSet};
use vista_image::Image;
use vista_kernels::{DisplayMap, Kernel, ParamSet};

use crate::GoldenError;

/// Default cap on `work_per_pixel * pixels`. Lavapipe on 2 cores evaluates
/// roughly 1e8-1e9 noise samples per second, so this keeps any accepted
/// dispatch under about a minute there instead of stalling the device.
pub const DEFAULT_MAX_WORK: f64 = 4.0e10;

fn max_work() -> f64 {
    std::env::var("VISTA_MAX_WORK").ok().and_then(|s| s.parse().ok()).unwrap_or(DEFAULT_MAX_WORK)
}

/// A rendered kernel: raw output (what the shader wrote) and, on demand,
/// display values.
#[derive(Debug, Clone)]
pub struct Rendered {
    pub raw: Image,
    pub stats: RunStats,
    to_display: DisplayMap,
    /// Display values, made on first use unless they are `raw` itself: a
    /// benchmark or a raw-only caller never pays for a second image.
    display: OnceLock<Option<Image>>,
}

impl Rendered {
    /// Display values in [0, 1] (what PNG goldens hold): `raw` itself for a
    /// display kernel, else the kernel's tone map / opaque alpha of it.
    pub fn display(&self) -> &Image {
        self.display.get_or_init(|| self.to_display.apply(&self.raw)).as_ref().unwrap_or(&self.raw)
    }
}

/// Checks size and work bounds before any GPU work.
pub fn check_request(kernel: &Kernel, p: &ParamSet, width: u32, height: u32) -> Result<(), GoldenError> {
    vista_kernels::check_size(width, height).map_err(|e| GoldenError::BadInput(e.to_string()))?;
    let work = kernel.work_per_pixel(p) * width as f64 * height as f64;
    let cap = max_work();
    if work > cap {
        return Err(GoldenError::BadInput(format!(
            "{}: this request needs about {work:.2e} inner-loop evaluations ({}x{} pixels x {:.0} per pixel), \
             above the cap of {cap:.2e}; lower the size or the step/octave counts (or raise VISTA_MAX_WORK)",
            kernel.name(),
            width,
            height,
            kernel.work_per_pixel(p)
        )));
    }
    Ok(())
}

/// The GPU context and the WGSL of one project: everything a render needs
/// besides the kernel and its params. Derefs to the [`Context`].
pub struct Renderer<'a> {
    pub ctx: &'a Context,
    pub shaders: ShaderSet,
}

impl std::ops::Deref for Renderer<'_> {
    type Target = Context;
    fn deref(&self) -> &Context {
        self.ctx
    }
}

impl<'a> Renderer<'a> {
    /// A renderer over the project's shaders (its `shaders/` layered over the
    /// built-ins).
    pub fn new(ctx: &'a Context, project: &vista_project::Project) -> Result<Renderer<'a>, GoldenError> {
        Ok(Renderer { ctx, shaders: shader_set(project)? })
    }

    /// Provenance hash of a kernel file and its imports.
    pub fn shader_hash(&self, shader: &str) -> Result<String, GoldenError> {
        Ok(self.shaders.source_hash(shader)?)
    }

    /// Hash of each file of the kernel's import closure, by path.
    pub fn shader_file_hashes(&self, shader: &str) -> Result<std::collections::BTreeMap<String, String>, GoldenError> {
        Ok(self.shaders.file_hashes(shader)?.into_iter().collect())
    }
}

/// The project's WGSL as one [`ShaderSet`].
pub fn shader_set(project: &vista_project::Project) -> Result<ShaderSet, GoldenError> {
    let label = match project.root() {
        Some(r) => format!("project {}", r.display()),
        None => "built-in shaders".to_string(),
    };
    let files = project.shader_files()?.into_iter().map(|f| (f.rel, f.text, f.origin));
    Ok(ShaderSet::from_files(&label, files))
}

/// What a dispatch needs besides the device: the uniform bytes packed from
/// naga's reflection of the composed module, and the binding-2 table, and the kernel file as composed for them.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The kernel file as composed for these params (`Kernel::shader_for`).
    pub shader: String,
    pub uniforms: Vec<u8>,
    pub table: Vec<u32>,
}

/// Every check that needs no device: size and work bounds, composition of
/// the kernel's WGSL, and its `Params` struct against the manifest (a field
/// with no param, a param with no field, a type mismatch are bad input).
pub fn prepare(
    shaders: &ShaderSet,
    kernel: &Kernel,
    p: &ParamSet,
    width: u32,
    height: u32,
) -> Result<Prepared, GoldenError> {
    check_request(kernel, p, width, height)?;
    let shader = kernel.shader_for(p);
    let module = shaders.compose(&shader).map_err(|e| match e {
        // A missing or broken shader file is the user's to fix.
        vista_gpu::GpuError::Shader(m) => GoldenError::BadInput(format!("kernel {}: {m}", kernel.name())),
        other => GoldenError::Gpu(other),
    })?;
    let layout = kernel.layout(&module).map_err(|e| GoldenError::BadInput(e.to_string()))?;
    Ok(Prepared { shader, uniforms: kernel.uniforms(&layout, p, width, height), table: kernel.table(&layout, p) })
}

/// Renders `kernel` with `p` at `width` x `height` on the GPU.
pub fn render(gpu: &Renderer, kernel: &Kernel, p: &ParamSet, width: u32, height: u32) -> Result<Rendered, GoldenError> {
    let Prepared { shader, uniforms, table } = prepare(&gpu.shaders, kernel, p, width, height)?;
    let job = Dispatch { shaders: &gpu.shaders, shader: &shader, uniforms: &uniforms, table: &table, width, height };
    let (raw, stats) = gpu.ctx.run(&job)?;
    Ok(Rendered { raw, stats, to_display: kernel.display_map(p), display: OnceLock::new() })
}

/// Renders `runs` (at least 1) times; returns the first render and the
/// median GPU wall time, for benchmarks and sweeps.
pub fn render_median(
    gpu: &Renderer,
    kernel: &Kernel,
    p: &ParamSet,
    width: u32,
    height: u32,
    runs: u32,
) -> Result<(Rendered, Duration), GoldenError> {
    let first = render(gpu, kernel, p, width, height)?;
    let mut times = vec![first.stats.gpu_wall];
    for _ in 1..runs {
        times.push(render(gpu, kernel, p, width, height)?.stats.gpu_wall);
    }
    Ok((first, median(times)))
}

/// The middle time (the upper one for an even count) of a non-empty list.
///
/// # Panics
/// If `times` is empty.
pub fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times[times.len() / 2]
}

/// Median wall-clock time of `runs` calls of `f` (at least one): the
/// CPU-side twin of [`render_median`], for baselines timed beside it.
pub fn median_wall(runs: u32, mut f: impl FnMut()) -> Duration {
    median(
        (0..runs.max(1))
            .map(|_| {
                let start = Instant::now();
                f();
                start.elapsed()
            })
            .collect(),
    )
}

/// Display values as a 16-bit PNG stores them, so a fresh render compares
/// with a golden exactly as it would after being blessed.
pub fn quantize16(img: &Image) -> Image {
    let q = |v: f32| {
        if v.is_nan() { 0.0 } else { (v.clamp(0.0, 1.0) * 65535.0).round() / 65535.0 }
    };
    Image::from_raw(img.width, img.height, img.data.iter().map(|p| p.map(q)).collect()).expect("same size")
}
