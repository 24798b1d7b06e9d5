//! vista's one render path: kernel + params + a project's shaders -> a
//! [`Plan`] (a pass graph; a one-pass kernel is a graph of one pass; every
//! check that needs no device happens while making it) -> [`run`] on the
//! context's engine (wgpu on lavapipe, SwiftShader or a GPU; or headless
//! Chromium) -> the outputs ([`Rendered`]).
//!
//! check, bless, sweep, bench, mutate and the test harnesses all render
//! through this crate; nothing else dispatches a kernel.
//!
//! Not for: judging outputs (`vista-golden`), writing files (nothing here
//! writes), or knowing any kernel's meaning (`vista-kernels`).
#![deny(missing_docs)]

mod command;
mod coverage;
mod dtype;
mod error;
pub mod graph;
pub mod leaf_values;
mod reflect;
mod sources;
pub mod worker;

pub use coverage::{CaseCoverage, cover, cover_with};
pub use error::{Crash, RenderError};
pub use graph::{Inputs, Plan, PlannedKind, PlannedOutput, check_case_defs, check_replace_keys};
pub use sources::{Sources, edited_shader_set, enum_modules, shader_set, source_specs};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use vista_gpu::Context;
pub use vista_gpu::{Reader, RunStats, ShaderSet, is_unit_test_file};
use vista_image::Image;
use vista_manifest::{DisplayMap, Kernel, ParamSet};

/// Default cap on `work_per_pixel * pixels`. Lavapipe on 2 cores evaluates
/// roughly 1e8-1e9 noise samples per second, so this keeps any accepted
/// dispatch under about a minute there instead of stalling the device.
pub const DEFAULT_MAX_WORK: f64 = 4.0e10;

/// The memory a case may ask for, in bytes, unless `VISTA_MAX_BYTES` says
/// otherwise: 4 GiB, counted before anything is allocated (every
/// resource's texels or bytes, and what its outputs read back as f32
/// RGBA). A fixed number rather than a share of the machine's memory, so
/// that a case is accepted or refused alike on every machine; a 2048^2
/// rgba32float case with three outputs needs 0.3 GiB.
pub const DEFAULT_MAX_BYTES: u64 = 4 << 30;

/// Bounds every render is held to before GPU work, set at the edge
/// (`VISTA_MAX_WORK`, `VISTA_MAX_BYTES`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderLimits {
    /// Cap on `work_per_pixel * pixels`.
    pub max_work: f64,
    /// Cap on the bytes a case's resources and read-back outputs need.
    pub max_bytes: u64,
}

impl Default for RenderLimits {
    fn default() -> RenderLimits {
        RenderLimits { max_work: DEFAULT_MAX_WORK, max_bytes: DEFAULT_MAX_BYTES }
    }
}

/// A rendered kernel: raw output (what the shader wrote) and, on demand,
/// display values.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// What the shader wrote, unchanged (the main output's own image).
    pub raw: Arc<Image>,
    /// Timing of the run.
    pub stats: RunStats,
    /// The output's storage format (an integer one compares exactly).
    pub format: &'static str,
    /// Every output, the first (the main image: for a manifest without
    /// tables, the texture its pass writes) included. A graph whose first output is a buffer
    /// has an empty `raw` (0 x 0): its outputs say everything.
    pub outputs: Vec<OutputRender>,
    /// Wall time of each graph pass (all its repeats).
    pub pass_times: Vec<std::time::Duration>,
    /// GPU time of each graph pass from the device's timestamps (all its
    /// repeats), where the backend has them and `Context::time_passes` is on.
    pub pass_gpu_times: Vec<Option<std::time::Duration>>,
    to_display: DisplayMap,
    /// Display values, made on first use unless they are `raw` itself: a
    /// benchmark or a raw-only caller never pays for a second image.
    display: OnceLock<Option<Image>>,
}

impl Rendered {
    /// The main image, owned (without a copy where nothing else holds it).
    pub fn into_raw(self) -> Image {
        let Rendered { raw, outputs, .. } = self;
        drop(outputs);
        Arc::unwrap_or_clone(raw)
    }

    /// Display values in [0, 1] (what PNG goldens hold): `raw` itself for a
    /// display kernel, else the kernel's tone map / opaque alpha of it.
    pub fn display(&self) -> &Image {
        self.display.get_or_init(|| self.to_display.apply(&self.raw)).as_ref().unwrap_or(&self.raw)
    }
}

/// Checks size and work bounds before any GPU work.
pub fn check_request(
    kernel: &Kernel,
    p: &ParamSet,
    width: u32,
    height: u32,
    limits: &RenderLimits,
) -> Result<(), RenderError> {
    vista_manifest::check_size(width, height).map_err(|e| RenderError::BadInput(e.to_string()))?;
    let work = kernel.work_per_pixel(p) * width as f64 * height as f64;
    let cap = limits.max_work;
    if work > cap {
        return Err(RenderError::BadInput(format!(
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

/// A device of its own instead of the process's shared one: on another
/// backend than `gpu` names (`vista check --matrix`), or with a watchdog of
/// its own (`vista mutate`). A [`Renderer`] borrows it.
pub fn own_device(
    gpu: &vista_gpu::GpuConfig,
    backend: Option<&str>,
    timeout: Option<Duration>,
) -> Result<Context, RenderError> {
    let mut config = gpu.clone();
    if let Some(b) = backend {
        config.adapter = vista_gpu::AdapterChoice::of_backend(b)?;
    }
    if let Some(t) = timeout {
        config.timeout = t;
    }
    Ok(context_for(&config)?)
}

/// The process's shared context for `gpu` ([`context_for`] on first use).
fn shared_context(gpu: &vista_gpu::GpuConfig) -> Result<&'static Context, vista_gpu::GpuError> {
    Context::shared_with(gpu, || context_for(gpu))
}

/// A context for `config`: where GPU work runs in workers, one that
/// describes the device a worker holds (this process then loads no
/// Vulkan driver: 60 MB less of its peak), else the device.
fn context_for(config: &vista_gpu::GpuConfig) -> Result<Context, vista_gpu::GpuError> {
    match worker::Worker::for_config(config) {
        Some(w) => {
            let start = std::time::Instant::now();
            let facts = w.describe()?;
            Ok(Context::described(config, facts, start.elapsed()))
        }
        None => Context::new(config),
    }
}

/// The GPU context and the WGSL of one project: everything a render needs
/// besides the kernel and its params. Derefs to the [`Context`].
pub struct Renderer<'a> {
    /// The process's device (or browser).
    pub ctx: &'a Context,
    /// Where its graphs run instead, when GPU work runs in a worker process
    /// ([`worker`]); the context then only describes the device.
    pub worker: Option<std::sync::Arc<worker::Worker>>,
    /// The files of the project `shaders` replaces (a mutant, a unit test
    /// file's rewrite), so a worker can compose the same set.
    pub edits: Vec<(String, String)>,
    /// The project's WGSL over the built-ins.
    pub shaders: ShaderSet,
    /// Bounds every render is held to.
    pub limits: RenderLimits,
    /// The project root, under which a graph's input files lie.
    pub root: Option<std::path::PathBuf>,
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
    pub fn new(
        ctx: &'a Context,
        project: &vista_project::Project,
        limits: RenderLimits,
    ) -> Result<Renderer<'a>, RenderError> {
        Ok(Renderer::with_shaders(ctx, shader_set(project)?, limits, project.root().map(Into::into)))
    }

    /// A renderer over `shaders` (with a worker for the context's
    /// configuration when GPU work runs in worker processes).
    pub fn with_shaders(
        ctx: &'a Context,
        shaders: ShaderSet,
        limits: RenderLimits,
        root: Option<std::path::PathBuf>,
    ) -> Renderer<'a> {
        Renderer { ctx, worker: worker::Worker::for_config(ctx.config()), edits: Vec::new(), shaders, limits, root }
    }

    /// A renderer on the process's shared context (made from `gpu` on
    /// first use: one process, one device).
    pub fn shared(
        gpu: &vista_gpu::GpuConfig,
        project: &vista_project::Project,
        limits: RenderLimits,
    ) -> Result<Renderer<'static>, RenderError> {
        Renderer::new(shared_context(gpu)?, project, limits)
    }

    /// A renderer over `shaders` on the process's shared device (made
    /// from `gpu` on first use): for commands that read and plan their
    /// shaders before touching a device.
    pub fn shared_with_shaders(
        gpu: &vista_gpu::GpuConfig,
        shaders: ShaderSet,
        limits: RenderLimits,
        root: Option<std::path::PathBuf>,
    ) -> Result<Renderer<'static>, RenderError> {
        Ok(Renderer::with_shaders(shared_context(gpu)?, shaders, limits, root))
    }

    /// Time spent so far compiling pipelines, here or in workers.
    pub fn compile_time(&self) -> Duration {
        self.ctx.compile_time() + self.worker.as_ref().map_or(Duration::ZERO, |w| w.compile_time())
    }

    /// Provenance hash of a kernel file and its imports.
    pub fn shader_hash(&self, shader: &str) -> Result<String, RenderError> {
        Ok(self.shaders.source_hash(shader)?)
    }

    /// Provenance hash of every file a kernel's passes reach (one file:
    /// [`Renderer::shader_hash`] of it).
    pub fn kernel_shader_hash(&self, kernel: &Kernel) -> Result<String, RenderError> {
        let files = kernel.shader_units();
        if let [one] = &files[..] {
            return self.shader_hash(one);
        }
        let hashes: Vec<String> = files.iter().map(|f| self.shader_hash(f)).collect::<Result<_, _>>()?;
        Ok(blake3::hash(hashes.join("|").as_bytes()).to_hex()[..16].to_string())
    }

    /// Hash of each file any of a kernel's passes reaches, by path.
    pub fn kernel_file_hashes(
        &self,
        kernel: &Kernel,
    ) -> Result<std::collections::BTreeMap<String, String>, RenderError> {
        let mut out = std::collections::BTreeMap::new();
        for f in kernel.shader_units() {
            out.extend(self.shader_file_hashes(&f)?);
        }
        Ok(out)
    }

    /// Hash of each file of the kernel's import closure, by path.
    pub fn shader_file_hashes(&self, shader: &str) -> Result<std::collections::BTreeMap<String, String>, RenderError> {
        Ok(self.shaders.file_hashes(shader)?)
    }
}

/// A composition error's place (`file:line:col`, from the diagnostic's
/// `┌─` line) and its first message line, for errors shown on one line
/// (`vista list`, `vista test`).
pub fn compose_error_parts(text: &str) -> (Option<&str>, &str) {
    let at = text.lines().find_map(|l| l.trim().strip_prefix("┌─ ")).map(str::trim);
    let message = text
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("error:") || l.contains("not found") || l.contains("failed"))
        .map(|l| l.trim_start_matches("error:").trim())
        .find(|l| !l.is_empty())
        .unwrap_or_else(|| text.lines().next().unwrap_or_default());
    (at, message)
}

/// Whether every pass of `kernel` composes at its default params: `Err`
/// holds the first error on one line (`file:line:col: message`), for
/// `vista list`.
pub fn composes(shaders: &ShaderSet, kernel: &Kernel) -> Result<(), String> {
    let p = kernel.resolve(None, &[]).map_err(|e| e.to_string())?;
    check_replace_keys(shaders, kernel, &p).map_err(|e| e.to_string())?;
    for name in (0..kernel.graph().passes.len()).map(|i| kernel.pass_shader_for(i, &p)) {
        if let Err(e) = shaders.compose(&name) {
            let text = e.to_string();
            let (at, message) = compose_error_parts(&text);
            return Err(match at {
                Some(at) => format!("{at}: {message}"),
                None => message.to_string(),
            });
        }
    }
    Ok(())
}

/// The folders and files the project's `[source]` tables name outside
/// `shaders/` (include folders, joined files, WESL packages), each once.
pub fn paths_outside_shaders(project: &vista_project::Project) -> Result<Vec<String>, RenderError> {
    let registry = sources::registry(project)?;
    let specs = registry.kernels().iter().flat_map(|k| k.source_specs());
    let mut out: Vec<String> = Vec::new();
    // What a `[source] command` reads: its inputs and script.
    if let Some(root) = project.root() {
        for k in registry.kernels() {
            for (file, g) in k.generated_files() {
                for p in command::dependencies(root, &format!("shaders/{file}"), &g) {
                    if !out.contains(&p) {
                        out.push(p);
                    }
                }
            }
        }
    }
    for (_, s) in specs {
        let named = s.include.iter().chain(&s.prepend).chain(&s.append).flatten().cloned();
        for p in named.chain(s.packages.into_iter().map(|(_, dir)| dir)) {
            if !p.starts_with("shaders/") && p != "shaders" && !out.contains(&p) {
                out.push(p);
            }
        }
    }
    Ok(out)
}

/// The plan of `kernel` with `p` at `width` x `height` (the case size),
/// after every check that needs no device: size and work bounds, every
/// pass's composition and reflection, its uniforms against the manifest,
/// every input file (`inputs` replaces resource files for a case). A
/// manifest without tables is a graph of one pass writing one texture.
#[allow(clippy::too_many_arguments)]
pub fn plan(
    shaders: &ShaderSet,
    root: Option<&std::path::Path>,
    kernel: &Kernel,
    p: &ParamSet,
    inputs: &Inputs,
    width: u32,
    height: u32,
    limits: &RenderLimits,
) -> Result<Plan, RenderError> {
    check_request(kernel, p, width, height, limits)?;
    graph::plan_graph(shaders, root, kernel, p, inputs, width, height, limits.max_bytes)
}

/// One output of a pass graph as read back.
#[derive(Debug, Clone)]
pub struct OutputRender {
    /// The resource's name (golden files add it after the case id).
    pub name: String,
    /// The manifest's tolerance, if any.
    pub tolerance: Option<vista_manifest::graph::Tolerance>,
    /// Texels left unwritten are allowed.
    pub partial: bool,
    /// What the passes left in it.
    pub value: OutputValue,
}

/// A graph output's values.
#[derive(Debug, Clone)]
pub enum OutputValue {
    /// A texture: raw f32 RGBA (layers stacked top to bottom).
    Texture {
        /// What the passes wrote (shared with [`Rendered::raw`] for the
        /// main image: at 2048 x 2048 a copy was 64 MiB).
        raw: Arc<Image>,
        /// Its storage format.
        format: &'static str,
        /// Its PNG view.
        view: vista_manifest::Output,
        /// Texels of a sentinel-filled output no pass wrote.
        unwritten: u64,
        /// Raw values to display values.
        display: DisplayMap,
    },
    /// A buffer: its bytes and element layout.
    Buffer {
        /// Every byte, a struct's fixed header included.
        bytes: Vec<u8>,
        /// The element its binding declares.
        element: vista_manifest::graph::Element,
        /// Elements after the header.
        count: u64,
    },
}

impl OutputRender {
    /// A texture output's display values (a buffer has none).
    pub fn display(&self) -> Option<Image> {
        match &self.value {
            OutputValue::Texture { raw, display, .. } => Some(display.apply(raw).unwrap_or_else(|| Image::clone(raw))),
            OutputValue::Buffer { .. } => None,
        }
    }

    /// A buffer's dtype and shape as NumPy writes them.
    pub fn npy(&self) -> Option<(String, Vec<u64>)> {
        match &self.value {
            OutputValue::Buffer { element, count, .. } => {
                let (descr, tail) = graph::npy_dtype(element);
                Some((descr, std::iter::once(*count).chain(tail).collect()))
            }
            OutputValue::Texture { .. } => None,
        }
    }

    /// A buffer's bytes without its fixed header (what its `.npy` holds).
    pub fn buffer_body(&self) -> Option<&[u8]> {
        match &self.value {
            OutputValue::Buffer { bytes, element, .. } => Some(&bytes[element.header as usize..]),
            OutputValue::Texture { .. } => None,
        }
    }
}

thread_local! {
    /// The case this thread renders (named in a crash, matched by a fault).
    static CASE: std::cell::RefCell<Option<String>> = const { std::cell::RefCell::new(None) };
}

/// Runs `f` with renders on this thread counted as case `id`'s.
pub fn for_case<R>(id: &str, f: impl FnOnce() -> R) -> R {
    let before = CASE.with(|c| c.replace(Some(id.to_string())));
    let out = f();
    CASE.with(|c| *c.borrow_mut() = before);
    out
}

/// Runs a plan on the renderer's engine (in its worker process, if it has one).
pub fn run(gpu: &Renderer, plan: &Plan) -> Result<Rendered, RenderError> {
    let graph = vista_gpu::Graph {
        shaders: &gpu.shaders,
        resources: std::borrow::Cow::Borrowed(&plan.resources),
        passes: std::borrow::Cow::Borrowed(&plan.passes),
        outputs: std::borrow::Cow::Borrowed(&plan.output_ids),
    };
    let out = execute(gpu, &graph, plan)?;
    let outputs: Vec<OutputRender> = plan
        .outputs
        .iter()
        .zip(out.outputs)
        .map(|(o, data)| OutputRender {
            name: o.name.clone(),
            tolerance: o.tolerance,
            partial: o.partial,
            value: match (&o.kind, data) {
                (
                    PlannedKind::Texture { format, view, display },
                    vista_gpu::OutputData::Texture { image, unwritten },
                ) => OutputValue::Texture { raw: Arc::new(image), format, view: *view, unwritten, display: *display },
                (PlannedKind::Buffer { element, count }, vista_gpu::OutputData::Buffer(bytes)) => {
                    OutputValue::Buffer { bytes, element: element.clone(), count: *count }
                }
                _ => unreachable!("outputs come back as planned"),
            },
        })
        .collect();
    let (raw, format, display) = match outputs.first().map(|o| &o.value) {
        Some(OutputValue::Texture { raw, format, display, .. }) => (raw.clone(), *format, *display),
        _ => (Arc::new(Image::new(0, 0)), "rgba32float", DisplayMap::identity()),
    };
    Ok(Rendered {
        raw,
        stats: out.stats,
        format,
        outputs,
        pass_times: out.pass_times,
        pass_gpu_times: out.pass_gpu_times,
        to_display: display,
        display: OnceLock::new(),
    })
}

/// Runs `graph` (`plan`'s, or its coverage twin) on the renderer's engine,
/// in its worker process if it has one.
fn execute(gpu: &Renderer, graph: &vista_gpu::Graph<'_>, plan: &Plan) -> Result<vista_gpu::Readback, RenderError> {
    // Refused here, with the kernel's names, before a worker holds a copy
    // of the graph.
    gpu.ctx.require_graph(graph, &plan.names)?;
    Ok(match &gpu.worker {
        Some(w) => {
            let source = worker::ShaderSource {
                root: gpu.root.clone(),
                edits: gpu.edits.clone(),
                coverage: graph.shaders.is_covered(),
                vertex_counted: graph.shaders.counts_vertex(),
            };
            let case = CASE.with(|c| c.borrow().clone());
            w.run(gpu.ctx, graph, &source, &plan.kernel, case.as_deref())?
        }
        None => gpu.ctx.run(graph)?,
    })
}

/// Renders `kernel` with `p` at `width` x `height`: [`plan`], then [`run`].
pub fn render(gpu: &Renderer, kernel: &Kernel, p: &ParamSet, width: u32, height: u32) -> Result<Rendered, RenderError> {
    render_with(gpu, kernel, p, &[], width, height)
}

/// [`render`] with a case's replacement input files (`inputs`).
pub fn render_with(
    gpu: &Renderer,
    kernel: &Kernel,
    p: &ParamSet,
    inputs: &Inputs,
    width: u32,
    height: u32,
) -> Result<Rendered, RenderError> {
    let plan = plan(&gpu.shaders, gpu.root.as_deref(), kernel, p, inputs, width, height, &gpu.limits)?;
    run(gpu, &plan)
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
) -> Result<(Rendered, Duration), RenderError> {
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
