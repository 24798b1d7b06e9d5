//! The shared headless context and the dispatch/readback path.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use vista_image::Image;

use crate::shaders::ShaderSet;
use crate::{GpuError, INSTALL_HINT};
use vista_texel::Format;

/// Which adapter to ask for. Software adapters are chosen by name, never
/// by whichever CPU driver the Vulkan loader lists first.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum AdapterChoice {
    /// Mesa's lavapipe (device "llvmpipe"). Reproducible; the default.
    Lavapipe,
    /// Google's SwiftShader Vulkan ICD (device "SwiftShader ...").
    SwiftShader,
    /// A hardware adapter (discrete preferred, then integrated, then virtual).
    Hardware,
    /// The first adapter whose name contains this text (case-insensitive).
    Named(String),
    /// Headless Chromium's WebGPU: Tint compiles the project's WGSL (naga's
    /// rewrite of a naga_oil module), Dawn runs it on SwiftShader.
    Browser,
}

/// The backends `--backend` / `VISTA_BACKEND` accept.
pub const BACKENDS: &[&str] = &["lavapipe", "swiftshader", "browser", "gpu"];

/// The raw adapter settings, as the edge (the binary, a test harness) read
/// them from its flags and the environment, once.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct AdapterSettings {
    /// The `--backend` flag's value.
    pub backend_flag: Option<String>,
    /// The `--adapter` flag's value.
    pub adapter_flag: Option<String>,
    /// `WGPU_ADAPTER_NAME`.
    pub wgpu_adapter_name: Option<String>,
    /// `VISTA_BACKEND`.
    pub backend_env: Option<String>,
    /// `VISTA_ADAPTER`.
    pub adapter_env: Option<String>,
}

/// Everything the GPU context needs to know from outside. Built once at the
/// edge and passed in: this crate reads no environment.
#[derive(Debug, Clone, PartialEq)]
pub struct GpuConfig {
    /// The adapter to use (see [`AdapterChoice::from_settings`]).
    pub adapter: AdapterChoice,
    /// The Khronos validation layer (`VISTA_VALIDATION=1`): every message fails the run.
    pub validate: bool,
    /// The watchdog on every GPU wait (`VISTA_GPU_TIMEOUT_S`, default 120 s).
    pub timeout: Duration,
    /// wgpu's instance backends (`WGPU_BACKEND`, a comma list); Vulkan when `None`.
    pub wgpu_backends: Option<String>,
    /// Where the browser backend finds Chromium.
    pub browser: vista_browser::BrowserConfig,
}

/// The GPU watchdog's default.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(120);

impl Default for GpuConfig {
    fn default() -> GpuConfig {
        GpuConfig {
            adapter: AdapterChoice::Lavapipe,
            validate: false,
            timeout: DEFAULT_TIMEOUT,
            wgpu_backends: None,
            browser: vista_browser::BrowserConfig::default(),
        }
    }
}

impl AdapterChoice {
    /// The adapter of a backend name: lavapipe | swiftshader | gpu.
    pub fn of_backend(name: &str) -> Result<AdapterChoice, GpuError> {
        match name {
            "lavapipe" => Ok(AdapterChoice::Lavapipe),
            "swiftshader" => Ok(AdapterChoice::SwiftShader),
            "gpu" => Ok(AdapterChoice::Hardware),
            "browser" => Ok(AdapterChoice::Browser),
            other => Err(GpuError::Request(format!(
                "backend '{other}' is not valid; expected one of {}",
                BACKENDS.join("|")
            ))),
        }
    }

    /// The adapter named by settings as the edge read them, first given
    /// first: `--backend`, `--adapter` (cpu = lavapipe), `WGPU_ADAPTER_NAME`,
    /// `VISTA_BACKEND`, `VISTA_ADAPTER`; else lavapipe.
    pub fn from_settings(s: &AdapterSettings) -> Result<AdapterChoice, GpuError> {
        let given = |v: &Option<String>| v.clone().filter(|v| !v.is_empty());
        if let Some(b) = given(&s.backend_flag) {
            return AdapterChoice::of_backend(&b).map_err(|e| GpuError::Request(format!("--backend {b}: {e}")));
        }
        if let Some(a) = given(&s.adapter_flag) {
            return AdapterChoice::of_adapter(&a).map_err(|e| GpuError::Request(format!("--adapter {a}: {e}")));
        }
        if let Some(name) = given(&s.wgpu_adapter_name) {
            return Ok(AdapterChoice::Named(name));
        }
        if let Some(b) = given(&s.backend_env) {
            return AdapterChoice::of_backend(&b).map_err(|e| GpuError::Request(format!("VISTA_BACKEND={b}: {e}")));
        }
        match given(&s.adapter_env) {
            None => Ok(AdapterChoice::Lavapipe),
            Some(a) => AdapterChoice::of_adapter(&a).map_err(|e| GpuError::Request(format!("VISTA_ADAPTER={a}: {e}"))),
        }
    }

    /// The adapter of `--adapter` / `VISTA_ADAPTER`: cpu (lavapipe) or gpu.
    pub fn of_adapter(name: &str) -> Result<AdapterChoice, GpuError> {
        match name {
            "cpu" | "software" | "lavapipe" => Ok(AdapterChoice::Lavapipe),
            "gpu" | "hardware" => Ok(AdapterChoice::Hardware),
            other => Err(GpuError::Request(format!("adapter '{other}' is not valid; expected one of cpu|gpu"))),
        }
    }

    /// The backend name reports and manifests use.
    pub fn backend_name(&self) -> &'static str {
        match self {
            AdapterChoice::Lavapipe => "lavapipe",
            AdapterChoice::SwiftShader => "swiftshader",
            AdapterChoice::Hardware => "gpu",
            AdapterChoice::Named(_) => "named",
            AdapterChoice::Browser => "browser",
        }
    }

    fn describe(&self) -> String {
        match self {
            AdapterChoice::Lavapipe => "lavapipe Vulkan adapter (software, device 'llvmpipe')".into(),
            AdapterChoice::SwiftShader => "SwiftShader Vulkan adapter (software)".into(),
            AdapterChoice::Hardware => "hardware GPU Vulkan adapter".into(),
            AdapterChoice::Named(n) => format!("Vulkan adapter named like '{n}'"),
            AdapterChoice::Browser => "browser backend (headless Chromium with WebGPU)".into(),
        }
    }

    /// How to install what this choice needs.
    pub fn hint(&self) -> &'static str {
        match self {
            AdapterChoice::SwiftShader => SWIFTSHADER_HINT,
            AdapterChoice::Browser => vista_browser::INSTALL_HINT,
            _ => INSTALL_HINT,
        }
    }
}

/// Printed when the SwiftShader adapter is missing.
pub const SWIFTSHADER_HINT: &str = "install Google's SwiftShader Vulkan ICD with `bash ci/install-swiftshader.sh` \
(it extracts libvk_swiftshader.so from Debian's chromium-common); set VISTA_ALLOW_NO_GPU=1 to skip GPU tests loudly";

/// Timing of one run, excluding device creation and shader compilation.
#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
pub struct RunStats {
    /// Submit to completion of the compute pass and readback copy.
    pub gpu_wall: Duration,
    /// Submit to completion of the compute pass alone (the kernel).
    pub kernel: Duration,
    /// Texture-to-buffer copy, map and row unpadding (the readback).
    pub readback: Duration,
    /// Whole call: upload, dispatch, wait, map and unpack.
    pub total: Duration,
}

/// Storage formats every WebGPU device may bind `read_write` (the core
/// set); others need an adapter feature.
const CORE_READ_WRITE: &[&str] = &["r32float", "r32uint", "r32sint"];

/// Headless state shared by everything in one process: a wgpu device, or
/// the browser.
pub struct Context {
    pub(crate) engine: Engine,
    info: wgpu::AdapterInfo,
    backend: &'static str,
    pub(crate) timeout: Duration,
    /// Serialises submissions so a timeout is attributed to the right job.
    pub(crate) submit_lock: Mutex<()>,
    /// How long creating the context took (adapter and device, or the
    /// browser's launch).
    pub creation_time: Duration,
    /// Whether the Khronos validation layer is on.
    pub(crate) validate: bool,
    /// What it was made from.
    config: GpuConfig,
    /// Whether graph passes read GPU timestamps (`vista bench` turns it
    /// on): a readback per pass run, which checks need not pay.
    pub(crate) time_passes: std::sync::atomic::AtomicBool,
    /// Called with each pass's label just before it is submitted (a worker
    /// process reports it, so a driver crash names the pass it died in).
    pub(crate) on_pass: Mutex<Option<PassHook>>,
    /// Nanoseconds spent creating shader modules and pipelines (the
    /// driver's compile; a warm Mesa shader cache makes it short).
    pub(crate) compile_nanos: std::sync::atomic::AtomicU64,
}

/// Adds the time since `.1` to the counter `.0` when dropped, so an early
/// return still counts.
struct CountInto<'a>(&'a std::sync::atomic::AtomicU64, std::time::Instant);

impl Drop for CountInto<'_> {
    fn drop(&mut self) {
        self.0.fetch_add(self.1.elapsed().as_nanos() as u64, std::sync::atomic::Ordering::Relaxed);
    }
}

/// See [`Context::on_pass`].
pub type PassHook = Arc<dyn Fn(&str) + Send + Sync>;

pub(crate) enum Engine {
    Wgpu(Box<WgpuEngine>),
    Browser(Box<BrowserEngine>),
    /// A device in another process (a GPU worker), known by its facts:
    /// this process plans and judges, and runs no graph.
    Described(Box<DeviceFacts>),
}

/// What vista asks of a wgpu device, without the device: a worker sends
/// its device's to its parent, which then loads no Vulkan driver of its
/// own (the loader and lavapipe's LLVM were 60 MB of the parent's RSS)
/// and still refuses what the device cannot do before any run.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DeviceFacts {
    /// The adapter's info.
    pub info: wgpu::AdapterInfo,
    /// The device's limits.
    pub limits: wgpu::Limits,
    /// The features the device was created with.
    pub features: wgpu::Features,
    /// Storage formats the device binds `read_write`.
    pub read_write: Vec<String>,
}

pub(crate) struct WgpuEngine {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    /// Pipelines with their bind group layouts (one per group up to the
    /// highest the kernel binds), by shader hash, entry, slots and format.
    pub(crate) pipelines: Mutex<HashMap<String, Arc<Compiled>>>,
    /// What the last runs left for the next to take (see [`crate::spares::Spares`]).
    pub(crate) spares: Mutex<crate::spares::Spares>,
    /// Storage formats this device binds `read_write`.
    read_write: Vec<&'static str>,
}

/// A render pipeline's stages and state beside the fragment entry, in
/// wgpu's terms (made from a pass's `Raster` by `raster.rs`).
pub(crate) struct RenderStages<'a> {
    /// Each target's format and blend.
    pub targets: &'a [Option<wgpu::ColorTargetState>],
    /// The pass's own vertex entry; `None`: vista's full-screen triangle.
    pub vertex_entry: Option<&'a str>,
    /// The module holding it when another file does, with its overrides.
    pub vertex_module: Option<(&'a naga::Module, &'a [(String, f64)])>,
    /// The vertex buffer layouts, one per slot.
    pub buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    pub primitive: wgpu::PrimitiveState,
    pub depth_stencil: Option<wgpu::DepthStencilState>,
}

pub(crate) struct Compiled {
    pub(crate) pipeline: Pipeline,
    pub(crate) groups: Vec<wgpu::BindGroupLayout>,
}

/// A compute pass's pipeline or a render pass's.
pub(crate) enum Pipeline {
    Compute(wgpu::ComputePipeline),
    Render(wgpu::RenderPipeline),
}

pub(crate) struct BrowserEngine {
    pub(crate) browser: vista_browser::Browser,
    /// The WebGPU device's features (requested: every one the adapter has).
    pub(crate) features: Vec<String>,
    /// The WGSL Tint gets for each kernel file, by source hash.
    pub(crate) sources: Mutex<HashMap<String, Arc<crate::tint::TintWgsl>>>,
}

/// Where Debian's vulkan-validationlayers puts the layer's manifest.
pub const VALIDATION_LAYER_JSON: &str = "/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json";

static SHARED: OnceLock<(GpuConfig, Result<Context, GpuError>)> = OnceLock::new();

impl Context {
    /// The process-wide context, created on first use from `config`. Every
    /// later call must pass the same configuration: one process, one device.
    pub fn shared(config: &GpuConfig) -> Result<&'static Context, GpuError> {
        Context::shared_with(config, || Context::new(config))
    }

    /// [`Context::shared`], made by `make` on first use (a context that
    /// describes a worker's device, [`Context::described`]).
    pub fn shared_with(
        config: &GpuConfig,
        make: impl FnOnce() -> Result<Context, GpuError>,
    ) -> Result<&'static Context, GpuError> {
        let (made_with, ctx) = SHARED.get_or_init(|| (config.clone(), make()));
        if made_with != config {
            return Err(GpuError::Request(format!(
                "this process's shared context was made for {:?}, not {:?}; one process has one context",
                made_with.adapter, config.adapter
            )));
        }
        ctx.as_ref().map_err(Clone::clone)
    }

    /// A context as `config` says, with the Khronos validation layer when
    /// `config.validate`; every validation message then fails the dispatch
    /// it arrives in.
    pub fn new(config: &GpuConfig) -> Result<Context, GpuError> {
        let start = Instant::now();
        let (choice, validate, timeout) = (&config.adapter, config.validate, config.timeout);
        if *choice == AdapterChoice::Browser {
            if validate {
                return Err(GpuError::Request(
                    "VISTA_VALIDATION=1 runs the Khronos layer under wgpu; the browser backend has Dawn's own \
                     validation always on: unset VISTA_VALIDATION or pick another backend"
                        .into(),
                ));
            }
            return Context::browser(timeout, &config.browser, start);
        }
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = match config.wgpu_backends.as_deref() {
            None => wgpu::Backends::VULKAN,
            Some(list) => match wgpu::Backends::from_comma_list(list) {
                b if b.is_empty() => {
                    return Err(GpuError::Request(format!(
                        "WGPU_BACKEND={list} names no backend; expected a comma list such as vulkan"
                    )));
                }
                b => b,
            },
        };
        if validate {
            crate::validation::install().map_err(GpuError::Request)?;
            if !std::path::Path::new(VALIDATION_LAYER_JSON).exists() {
                return Err(GpuError::Request(format!(
                    "VISTA_VALIDATION=1 needs the Khronos validation layer ({VALIDATION_LAYER_JSON}); install it with \
                     `bash ci/install-validation.sh` (Debian's vulkan-validationlayers)"
                )));
            }
            desc.flags |= wgpu::InstanceFlags::VALIDATION;
        }
        let backends = desc.backends;
        let instance = wgpu::Instance::new(desc);
        let adapters = pollster::block_on(instance.enumerate_adapters(backends));
        let seen = adapters
            .iter()
            .map(|a| {
                let i = a.get_info();
                format!("{} [{:?}, {:?}]", i.name, i.device_type, i.backend)
            })
            .collect::<Vec<_>>();
        let adapter = pick(adapters, choice).ok_or_else(|| GpuError::NoAdapter {
            wanted: choice.describe(),
            seen: if seen.is_empty() { "no adapters".into() } else { seen.join("; ") },
            hint: choice.hint(),
        })?;
        let info = adapter.get_info();
        // Adapter-specific format features: read_write storage beyond the
        // core r32 formats, where the driver has it.
        let specific = wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES;
        // Linear sampling of r32float/rg32float/rgba32float inputs, where
        // the driver has it (SPEC 14, features and limits).
        // GPU timestamps around each graph pass, where the driver has them.
        // Blending into 32-bit float render targets, where the driver has it.
        // 16-bit floats and dual-source blending in shaders (`enable f16;`,
        // `enable dual_source_blending;`), where the driver has them.
        // Storage writes from the vertex stage, so that coverage counts
        // vertex code (WebGPU's core has none: a browser never counts it).
        let wanted = specific
            | wgpu::Features::VERTEX_WRITABLE_STORAGE
            | wgpu::Features::FLOAT32_FILTERABLE
            | wgpu::Features::FLOAT32_BLENDABLE
            | wgpu::Features::RG11B10UFLOAT_RENDERABLE
            | wgpu::Features::SHADER_F16
            | wgpu::Features::DUAL_SOURCE_BLENDING
            | wgpu::Features::TIMESTAMP_QUERY;
        let required_features = adapter.features() & wanted;
        let read_write = vista_texel::format_names()
            .into_iter()
            .filter(|name| vista_texel::Format::parse(name).is_ok_and(|f| f.is_storable()))
            .filter(|name| {
                CORE_READ_WRITE.contains(name)
                    || (required_features.contains(specific)
                        && crate::format::parse(name).is_ok_and(|f| {
                            adapter
                                .get_texture_format_features(crate::format::wgpu_format(&f))
                                .flags
                                .contains(wgpu::TextureFormatFeatureFlags::STORAGE_READ_WRITE)
                        }))
            })
            .collect();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("vista"),
            required_features,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device { adapter: info.name.clone(), message: e.to_string() })?;
        Ok(Context {
            engine: Engine::Wgpu(Box::new(WgpuEngine {
                device,
                queue,
                pipelines: Mutex::new(HashMap::new()),
                spares: Default::default(),
                read_write,
            })),
            info,
            backend: choice.backend_name(),
            timeout,
            submit_lock: Mutex::new(()),
            creation_time: start.elapsed(),
            validate,
            config: config.clone(),
            time_passes: Default::default(),
            on_pass: Mutex::new(None),
            compile_nanos: Default::default(),
        })
    }

    /// Headless Chromium with a WebGPU device on its SwiftShader adapter.
    fn browser(timeout: Duration, config: &vista_browser::BrowserConfig, start: Instant) -> Result<Context, GpuError> {
        let browser = vista_browser::Browser::launch(timeout, config).map_err(|e| match e {
            vista_browser::BrowserError::NotInstalled { looked, hint } => GpuError::NoAdapter {
                wanted: AdapterChoice::Browser.describe(),
                seen: format!("no Chromium; looked for {looked}"),
                hint,
            },
            other => GpuError::Device { adapter: "headless Chromium".into(), message: other.to_string() },
        })?;
        let b = browser.info();
        // Reports and manifests read the same fields as for a wgpu adapter.
        let mut info = wgpu::AdapterInfo::new(wgpu::DeviceType::Cpu, wgpu::Backend::BrowserWebGpu);
        info.name = format!("{} {} (WebGPU in headless Chromium)", b.vendor, b.architecture);
        info.driver = format!("{} Dawn/Tint", b.product);
        info.driver_info = b.description.clone();
        Ok(Context {
            engine: Engine::Browser(Box::new(BrowserEngine {
                features: browser.info().features.clone(),
                browser,
                sources: Mutex::new(HashMap::new()),
            })),
            info,
            backend: AdapterChoice::Browser.backend_name(),
            timeout,
            submit_lock: Mutex::new(()),
            creation_time: start.elapsed(),
            validate: false,
            config: GpuConfig {
                adapter: AdapterChoice::Browser,
                timeout,
                browser: config.clone(),
                ..Default::default()
            },
            time_passes: Default::default(),
            on_pass: Mutex::new(None),
            compile_nanos: Default::default(),
        })
    }

    /// The facts of this context's wgpu device, which a worker sends its
    /// parent ([`Context::described`]); `None` for the browser.
    pub fn facts(&self) -> Option<DeviceFacts> {
        match &self.engine {
            Engine::Wgpu(w) => Some(DeviceFacts {
                info: self.info.clone(),
                limits: w.device.limits(),
                features: w.device.features(),
                read_write: w.read_write.iter().map(ToString::to_string).collect(),
            }),
            Engine::Browser(_) => None,
            Engine::Described(f) => Some(DeviceFacts::clone(f)),
        }
    }

    /// A context for a device another process holds, made from `config`
    /// and the facts that process sent: it answers every question about
    /// the device as the device's own context would, and refuses to run a
    /// graph. `creation_time` is how long getting the facts took.
    pub fn described(config: &GpuConfig, facts: DeviceFacts, creation_time: Duration) -> Context {
        Context {
            info: facts.info.clone(),
            engine: Engine::Described(Box::new(facts)),
            backend: config.adapter.backend_name(),
            timeout: config.timeout,
            submit_lock: Mutex::new(()),
            creation_time,
            validate: config.validate,
            config: config.clone(),
            time_passes: Default::default(),
            on_pass: Mutex::new(None),
            compile_nanos: Default::default(),
        }
    }

    /// Turns GPU timestamps around every graph pass run on or off (where
    /// the device has them): `Rendered::pass_gpu_times` for benches. Off by
    /// default, since each run then waits for a timestamp readback.
    pub fn time_passes(&self, on: bool) {
        self.time_passes.store(on, std::sync::atomic::Ordering::Relaxed);
    }

    /// The configuration it was made from (with the watchdog
    /// [`Context::with_timeout`] set).
    pub fn config(&self) -> &GpuConfig {
        &self.config
    }

    /// Whether [`Context::time_passes`] is on.
    pub fn timing_passes(&self) -> bool {
        self.time_passes.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Calls `hook` with each pass's label just before the pass is
    /// submitted (wgpu engines), or stops calling one (`None`).
    pub fn on_pass(&self, hook: Option<PassHook>) {
        *self.on_pass.lock().expect("pass hook") = hook;
    }

    /// The same context with another GPU watchdog (mutation runs use a short
    /// one: a mutant can loop for ever).
    pub fn with_timeout(mut self, timeout: Duration) -> Context {
        self.timeout = timeout;
        self.config.timeout = timeout;
        if let Engine::Browser(b) = &mut self.engine {
            b.browser.set_timeout(timeout);
        }
        self
    }

    /// Whether the Khronos validation layer is on (`VISTA_VALIDATION=1`).
    pub fn validating(&self) -> bool {
        self.validate
    }

    /// Time spent so far creating shader modules and pipelines (on the
    /// browser, compiling is inside the page and not counted here).
    pub fn compile_time(&self) -> Duration {
        Duration::from_nanos(self.compile_nanos.load(std::sync::atomic::Ordering::Relaxed))
    }

    /// lavapipe | swiftshader | gpu (or "named" for WGPU_ADAPTER_NAME).
    pub fn backend(&self) -> &'static str {
        self.backend
    }

    /// wgpu's info on the adapter in use; for the browser backend, filled in
    /// from the page's WebGPU adapter and Chromium's version.
    pub fn adapter_info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }

    /// "name | driver driver_info | backend | device type": recorded in every
    /// report and golden manifest.
    pub fn adapter_description(&self) -> String {
        let i = &self.info;
        format!("{} | {} {} | {:?} | {:?}", i.name, i.driver, i.driver_info, i.backend, i.device_type)
    }

    /// True for CPU (software) adapters such as lavapipe.
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Largest width/height a storage texture may have on this device.
    pub fn max_dimension(&self) -> u32 {
        match &self.engine {
            Engine::Wgpu(w) => w.device.limits().max_texture_dimension_2d,
            Engine::Browser(b) => b.browser.info().max_dimension,
            Engine::Described(f) => f.limits.max_texture_dimension_2d,
        }
    }

    /// The WGSL the browser backend hands to Tint for `shader`'s `entry`
    /// with override `constants`: the project's own text wherever naga
    /// parses it directly (overrides then go as WebGPU pipeline constants),
    /// else naga's rewrite of the naga_oil-composed module, with `override`
    /// constants resolved to `constants` first (naga's WGSL writer writes an
    /// overridden `@workgroup_size` as its placeholder, so the values are
    /// baked in instead).
    pub fn wgsl_for_tint(
        shaders: &ShaderSet,
        shader: &str,
        entry: &str,
        constants: &[(String, f64)],
    ) -> Result<crate::tint::TintWgsl, GpuError> {
        if let Some(source) = shaders.source_text(shader)? {
            return Ok(crate::tint::TintWgsl::source(source, constants));
        }
        let module = shaders.compose(shader)?;
        let (resolved, info) = crate::shaders::resolve_overrides(shader, &module, entry, constants)?;
        let text = naga::back::wgsl::write_string(&resolved, &info, naga::back::wgsl::WriterFlags::empty())
            .map_err(|e| GpuError::Shader(format!("{shader}: naga's WGSL writer failed: {e}")))?;
        let (wgsl, written) =
            crate::shaders::keep_struct_layouts(shader, &resolved, crate::shaders::exact_f32_max(&text))?;
        Ok(crate::tint::TintWgsl::rewrite(&resolved, &written, wgsl))
    }

    /// Compiles a kernel file's entry point with one bind group layout per
    /// group (entries given per group, groups 0..n): a compute pipeline, or
    /// with `targets` a render pipeline of vista's full-screen triangle and
    /// the entry as its fragment stage.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn compile(
        &self,
        w: &WgpuEngine,
        shaders: &ShaderSet,
        shader: &str,
        entry: &str,
        constants: &[(String, f64)],
        layouts: &[Vec<wgpu::BindGroupLayoutEntry>],
        render: Option<RenderStages<'_>>,
    ) -> Result<Arc<Compiled>, GpuError> {
        let module = shaders.compose(shader)?;
        self.check_features(shader, [Some(&*module), render.as_ref().and_then(|r| r.vertex_module.map(|(m, _)| m))])?;
        self.check_declared(shader, &shaders.declared_features(shader)?)?;
        let started = std::time::Instant::now();
        let _count = CountInto(&self.compile_nanos, started);
        let scope = w.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let sm = w.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(shader),
            source: wgpu::ShaderSource::Naga(std::borrow::Cow::Owned((*module).clone())),
        });
        let groups: Vec<wgpu::BindGroupLayout> = layouts
            .iter()
            .map(|entries| {
                w.device
                    .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("vista group"), entries })
            })
            .collect();
        let layout_refs: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(Some).collect();
        let pipeline_layout = w.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(shader),
            bind_group_layouts: &layout_refs,
            immediate_size: 0,
        });
        let constants: Vec<(&str, f64)> = constants.iter().map(|(k, v)| (k.as_str(), *v)).collect();
        let options = || wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
        let pipeline = match render {
            None => Pipeline::Compute(w.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(shader),
                layout: Some(&pipeline_layout),
                module: &sm,
                entry_point: Some(entry),
                compilation_options: options(),
                cache: None,
            })),
            Some(r) => {
                // vista's full-screen triangle, or the pass's own vertex entry.
                let (fullscreen, other);
                let vertex_constants: Vec<(&str, f64)> =
                    r.vertex_module.iter().flat_map(|(_, c)| c.iter().map(|(k, v)| (k.as_str(), *v))).collect();
                let (vertex, vertex_entry) = match (r.vertex_entry, r.vertex_module) {
                    (Some(vs), None) => (&sm, vs),
                    (Some(vs), Some((module, _))) => {
                        other = w.device.create_shader_module(wgpu::ShaderModuleDescriptor {
                            label: Some(vs),
                            source: wgpu::ShaderSource::Naga(std::borrow::Cow::Owned(module.clone())),
                        });
                        (&other, vs)
                    }
                    (None, _) => {
                        // As a naga module, like every kernel: the SPIR-V wgpu
                        // writes for WGSL text names WGSL as its source
                        // language, which Debian's validation layer rejects.
                        let module = naga::front::wgsl::parse_str(crate::FULLSCREEN_WGSL).expect("vista's own WGSL");
                        fullscreen = w.device.create_shader_module(wgpu::ShaderModuleDescriptor {
                            label: Some("vista full-screen triangle"),
                            source: wgpu::ShaderSource::Naga(std::borrow::Cow::Owned(module)),
                        });
                        (&fullscreen, crate::FULLSCREEN_ENTRY)
                    }
                };
                Pipeline::Render(w.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(shader),
                    layout: Some(&pipeline_layout),
                    vertex: wgpu::VertexState {
                        module: vertex,
                        entry_point: Some(vertex_entry),
                        compilation_options: match r.vertex_module {
                            Some(_) => {
                                wgpu::PipelineCompilationOptions { constants: &vertex_constants, ..Default::default() }
                            }
                            None => options(),
                        },
                        buffers: r.buffers,
                    },
                    primitive: r.primitive,
                    depth_stencil: r.depth_stencil,
                    multisample: wgpu::MultisampleState::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &sm,
                        entry_point: Some(entry),
                        compilation_options: options(),
                        targets: r.targets,
                    }),
                    multiview_mask: None,
                    cache: None,
                }))
            }
        };
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError::wgpu(shader, &e));
        }
        Ok(Arc::new(Compiled { pipeline, groups }))
    }

    /// Whether this device binds `format` as a read_write (or read-only)
    /// storage texture: the core r32 formats everywhere, others where the
    /// adapter's format features (or Dawn's `texture-formats-tier2`) say so.
    pub(crate) fn binds_read_write(&self, format: &Format) -> bool {
        CORE_READ_WRITE.contains(&format.name)
            || match &self.engine {
                Engine::Wgpu(w) => w.read_write.contains(&format.name),
                Engine::Browser(b) => b.features.iter().any(|f| f == "texture-formats-tier2"),
                Engine::Described(f) => f.read_write.iter().any(|n| n == format.name),
            }
    }

    /// A module that needs a shader feature the device lacks (f16,
    /// dual-source blending): unsupported here, naming the feature.
    pub(crate) fn check_features(&self, shader: &str, modules: [Option<&naga::Module>; 2]) -> Result<(), GpuError> {
        for (feature, enable) in modules.into_iter().flatten().flat_map(crate::shaders::features_used) {
            if !self.has_feature(feature) {
                return Err(GpuError::Unsupported {
                    adapter: self.adapter_description(),
                    what: format!("{shader}: {enable} (enable {enable};)"),
                    feature: feature.into(),
                });
            }
        }
        Ok(())
    }

    /// The features a shader's `enable` directives declare: each one the
    /// device lacks makes the pass unsupported, used or not.
    pub(crate) fn check_declared(&self, shader: &str, declared: &[(&str, &str)]) -> Result<(), GpuError> {
        match declared.iter().find(|(feature, _)| !self.has_feature(feature)) {
            Some((feature, enable)) => Err(GpuError::Unsupported {
                adapter: self.adapter_description(),
                what: format!("{shader}: enable {enable};"),
                feature: feature.to_string(),
            }),
            None => Ok(()),
        }
    }

    /// Whether this device has one of the optional features vista asks
    /// for, by its WebGPU name (`float32-blendable`, `shader-f16`, ...).
    pub(crate) fn has_feature(&self, feature: &str) -> bool {
        let wgpu_feature = || match feature {
            "shader-f16" => wgpu::Features::SHADER_F16,
            "dual-source-blending" => wgpu::Features::DUAL_SOURCE_BLENDING,
            "float32-blendable" => wgpu::Features::FLOAT32_BLENDABLE,
            "rg11b10ufloat-renderable" => wgpu::Features::RG11B10UFLOAT_RENDERABLE,
            other => unreachable!("vista asks for no feature {other}"),
        };
        match &self.engine {
            Engine::Wgpu(w) => w.device.features().contains(wgpu_feature()),
            Engine::Browser(b) => b.features.iter().any(|f| f == feature),
            Engine::Described(f) => f.features.contains(wgpu_feature()),
        }
    }

    /// The feature that [`Context::binds_read_write`] depends on here.
    pub(crate) fn read_write_feature(&self) -> &'static str {
        match &self.engine {
            Engine::Wgpu(_) | Engine::Described(_) => {
                "TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES with STORAGE_READ_WRITE for this format"
            }
            Engine::Browser(_) => "texture-formats-tier2",
        }
    }

    /// Blocks until `index` completes, or fails after the watchdog timeout.
    pub(crate) fn wait(&self, w: &WgpuEngine, index: wgpu::SubmissionIndex, what: &str) -> Result<(), GpuError> {
        w.device
            .poll(wgpu::PollType::Wait { submission_index: Some(index), timeout: Some(self.timeout) })
            .map(|_| ())
            .map_err(|e| match e {
                wgpu::PollError::Timeout => {
                    GpuError::Timeout { what: what.to_string(), seconds: self.timeout.as_secs_f64() }
                }
                other => GpuError::Validation { what: what.to_string(), message: other.to_string() },
            })
    }
}

/// One run's output: decoded, and the indices (ascending) of the texels
/// whose bytes are the run's sentinel texel.
pub(crate) struct Texels {
    pub(crate) image: Image,
    pub(crate) holding_sentinel: Vec<usize>,
}

/// Fills depth texture `texture` with `values` (f32 per texel): WebGPU
/// copies into no depth32float texture, so an r32float texture of the
/// values is drawn into its depth aspect by a full-screen pass writing
/// `frag_depth` ([`crate::fullscreen::depth_fill_wgsl`]), as the page does.
/// Here, beside the pipeline cache: this file alone makes pipelines.
pub(crate) fn fill_depth(w: &WgpuEngine, texture: &wgpu::Texture, [width, height]: [u32; 2], values: &[u8]) {
    let d = &w.device;
    let extent = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
    let source = d.create_texture(&wgpu::TextureDescriptor {
        label: Some("depth values"),
        size: extent,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    w.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: &source,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        values,
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * width), rows_per_image: Some(height) },
        extent,
    );
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("depth fill"),
        source: wgpu::ShaderSource::Wgsl(crate::fullscreen::depth_fill_wgsl().into()),
    });
    let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("depth fill"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        }],
    });
    let pipeline_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("depth fill"),
        bind_group_layouts: &[Some(&layout)],
        ..Default::default()
    });
    let pipeline = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("depth fill"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some(crate::fullscreen::FULLSCREEN_ENTRY),
            buffers: &[],
            compilation_options: Default::default(),
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some(crate::fullscreen::DEPTH_FILL_ENTRY),
            targets: &[],
            compilation_options: Default::default(),
        }),
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    });
    let view = source.create_view(&Default::default());
    let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("depth fill"),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) }],
    });
    let target = texture.create_view(&Default::default());
    let mut encoder = d.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("depth fill"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }
    w.queue.submit([encoder.finish()]);
}

/// Decodes `height` rows of `width` texels of `format`, rows `stride` bytes
/// apart (a readback buffer pads them to 256 bytes), into f32 RGBA, noting
/// the texels that hold `sentinel`: one pass over the mapped memory.
pub(crate) fn read_texels(
    bytes: &[u8],
    stride: usize,
    format: &Format,
    width: u32,
    height: u32,
    sentinel: &[u8],
) -> Texels {
    let mut data = vec![[0.0f32; 4]; width as usize * height as usize];
    let mut holding_sentinel = Vec::new();
    decode_rows(bytes, stride, format, &mut data, width as usize, 0, sentinel, &mut holding_sentinel);
    Texels { image: Image::from_raw(width, height, data).expect("one texel per pixel"), holding_sentinel }
}

/// [`read_texels`] of a band of rows into `dst` (whole rows of `width`
/// texels), the first of which is texel `first` of the image: sentinel
/// positions are the image's.
#[allow(clippy::too_many_arguments)]
pub(crate) fn decode_rows(
    bytes: &[u8],
    stride: usize,
    format: &Format,
    dst: &mut [[f32; 4]],
    width: usize,
    first: usize,
    sentinel: &[u8],
    holding_sentinel: &mut Vec<usize>,
) {
    let tb = format.texel_bytes();
    let rgba32 = format.storage == naga::StorageFormat::Rgba32Float;
    for (y, dst) in dst.chunks_exact_mut(width).enumerate() {
        let row = &bytes[y * stride..][..width * tb];
        for (x, (px, texel)) in dst.iter_mut().zip(row.chunks_exact(tb)).enumerate() {
            if texel == sentinel {
                holding_sentinel.push(first + y * width + x);
            }
            if rgba32 {
                // Written in place (no per-pixel push), so even the tests'
                // opt-level 1 build turns it into straight copies.
                for (c, b) in px.iter_mut().zip(texel.chunks_exact(4)) {
                    *c = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                }
            } else {
                *px = format.decode(texel);
            }
        }
    }
}

/// Picks the adapter matching `choice` from those enumerated.
fn pick(adapters: Vec<wgpu::Adapter>, choice: &AdapterChoice) -> Option<wgpu::Adapter> {
    use wgpu::DeviceType as T;
    let rank = |a: &wgpu::Adapter| -> Option<u8> {
        let i = a.get_info();
        match choice {
            AdapterChoice::Lavapipe => (i.device_type == T::Cpu && i.name.contains("llvmpipe")).then_some(0),
            AdapterChoice::SwiftShader => i.name.contains("SwiftShader").then_some(0),
            AdapterChoice::Hardware => match i.device_type {
                T::DiscreteGpu => Some(0),
                T::IntegratedGpu => Some(1),
                T::VirtualGpu => Some(2),
                _ => None,
            },
            AdapterChoice::Named(n) => i.name.to_lowercase().contains(&n.to_lowercase()).then_some(0),
            AdapterChoice::Browser => None,
        }
    };
    adapters.into_iter().filter_map(|a| rank(&a).map(|r| (r, a))).min_by_key(|(r, _)| *r).map(|(_, a)| a)
}

impl Context {
    /// Whether the vertex stage may write storage buffers on this device
    /// (wgpu's `VERTEX_WRITABLE_STORAGE`): coverage then counts vertex code.
    pub fn vertex_writes_storage(&self) -> bool {
        let feature = wgpu::Features::VERTEX_WRITABLE_STORAGE;
        match &self.engine {
            Engine::Wgpu(w) => w.device.features().contains(feature),
            Engine::Browser(_) => false,
            Engine::Described(f) => f.features.contains(feature),
        }
    }

    /// The device's limit `name` (WebGPU's spelling), where the backend
    /// reports it.
    pub fn limit(&self, name: &str) -> Option<u64> {
        match &self.engine {
            Engine::Wgpu(w) => crate::limits::wgpu_limit(&w.device.limits(), name),
            Engine::Browser(b) => b.browser.info().limits.get(name).map(|v| *v as u64),
            Engine::Described(f) => crate::limits::wgpu_limit(&f.limits, name),
        }
    }

    /// Refuses `what` as unsupported when it needs more of limit `name`
    /// than this device has.
    pub fn require(&self, what: &str, name: &str, needed: u64) -> Result<(), GpuError> {
        crate::limits::require(&|n| self.limit(n), &self.adapter_description(), what, name, needed)
    }

    /// Checks a dispatch's workgroup size and count and its bindings
    /// against the device's limits; `what` names it (a pass, a kernel).
    pub fn require_needs(&self, what: &str, n: &crate::Needs) -> Result<(), GpuError> {
        crate::limits::require_needs(&|name| self.limit(name), &self.adapter_description(), what, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texels_skip_row_padding_decode_the_format_and_find_the_sentinel() {
        // 3 x 2 rgba32float texels, rows padded to 256 bytes: padding bytes are garbage.
        let (w, h, padded) = (3u32, 2u32, 256usize);
        let mut bytes = vec![0xAB_u8; padded * h as usize];
        for y in 0..h {
            for x in 0..w {
                for c in 0..4 {
                    let v = (y * 100 + x * 10 + c) as f32;
                    let at = y as usize * padded + (x * 16 + c * 4) as usize;
                    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
                }
            }
        }
        let rgba32 = crate::format::parse("rgba32float").unwrap();
        let sentinel = rgba32.sentinel(0);
        bytes[padded + 16..padded + 32].copy_from_slice(&sentinel);
        let t = read_texels(&bytes, padded, &rgba32, w, h, &sentinel);
        assert_eq!(t.image.get(2, 1), [120.0, 121.0, 122.0, 123.0]);
        assert_eq!(t.image.get(0, 0), [0.0, 1.0, 2.0, 3.0]);
        assert_eq!(t.holding_sentinel, [4], "texel (1, 1)");
        let r8 = crate::format::parse("rgba8unorm").unwrap();
        let t = read_texels(&[255, 0, 51, 255], 4, &r8, 1, 1, &r8.sentinel(0));
        assert_eq!((t.image.get(0, 0), t.holding_sentinel.len()), ([1.0, 0.0, 0.2, 1.0], 0));
    }
}
