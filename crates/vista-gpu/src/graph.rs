//! A pass graph (SPEC 14): resources made once (textures, buffers,
//! samplers, with their initial contents), passes dispatched in order
//! (each its own shader, entry point, constants, workgroup count and
//! bindings; repeated and ping-ponged), then the outputs read back. The
//! caller (vista-render) has already reflected every binding, checked every
//! input and packed every uniform; this module only makes and runs it.

use std::collections::HashMap;
use std::sync::{Arc, mpsc};
use std::time::{Duration, Instant};

use vista_image::Image;
use wgpu::util::DeviceExt;

use crate::GpuError;
use crate::context::{Context, Dimension, Engine, RunStats, WgpuEngine, read_texels};
use crate::format::{OutputFormat, SampleKind};
use crate::shaders::ShaderSet;

/// What a texture holds before the first pass.
#[derive(Debug, Clone, PartialEq)]
pub enum Contents {
    /// Zeros (a resource with no file).
    Zeros,
    /// Packed texels of the format, rows top to bottom, layers after each
    /// other (a file's contents, checked by the caller).
    Bytes(Vec<u8>),
    /// The sentinel texel: an output no pass reads, so a texel still
    /// holding it afterwards was never written.
    Sentinel,
}

/// A texture resource.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureDesc {
    /// The storage format's WGSL name (one of [`crate::format_names`]).
    pub format: &'static str,
    /// The texture's dimension.
    pub dimension: Dimension,
    /// Width in texels.
    pub width: u32,
    /// Height in texels (of one layer).
    pub height: u32,
    /// Array layers or depth (1 for 1d and 2d).
    pub layers: u32,
    /// What the texture holds before the first pass.
    pub contents: Contents,
}

/// A sampler's address mode along one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Address {
    /// Coordinates outside [0, 1] clamp to the edge texel (`clamp-to-edge`).
    ClampToEdge,
    /// The texture tiles (`repeat`).
    Repeat,
    /// The texture tiles, mirrored every other tile (`mirror-repeat`).
    MirrorRepeat,
}

impl Address {
    /// The manifest's names, in order.
    pub const NAMES: [&'static str; 3] = ["clamp-to-edge", "repeat", "mirror-repeat"];

    /// The address mode of a manifest name, or `None` if it is not one of
    /// [`Address::NAMES`].
    pub fn parse(name: &str) -> Option<Address> {
        Address::NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| [Address::ClampToEdge, Address::Repeat, Address::MirrorRepeat][i])
    }

    fn web(self) -> &'static str {
        Address::NAMES[self as usize]
    }

    fn wgpu(self) -> wgpu::AddressMode {
        match self {
            Address::ClampToEdge => wgpu::AddressMode::ClampToEdge,
            Address::Repeat => wgpu::AddressMode::Repeat,
            Address::MirrorRepeat => wgpu::AddressMode::MirrorRepeat,
        }
    }
}

/// Comparison functions of a comparison sampler, as WebGPU names them.
pub const COMPARE_NAMES: [&str; 8] =
    ["never", "less", "equal", "less-equal", "greater", "not-equal", "greater-equal", "always"];

fn compare_fn(name: &str) -> Option<wgpu::CompareFunction> {
    use wgpu::CompareFunction as C;
    let all = [C::Never, C::Less, C::Equal, C::LessEqual, C::Greater, C::NotEqual, C::GreaterEqual, C::Always];
    COMPARE_NAMES.iter().position(|n| *n == name).map(|i| all[i])
}

/// A sampler resource.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct SamplerDesc {
    /// Linear filtering (else nearest), for magnification, minification
    /// and mips alike.
    pub linear: bool,
    /// Address modes along u, v and w.
    pub address: [Address; 3],
    /// A comparison sampler's function (one of [`COMPARE_NAMES`]).
    pub compare: Option<&'static str>,
}

/// A resource of the graph.
#[derive(Debug, Clone, PartialEq)]
pub enum Resource {
    /// A texture.
    Texture(TextureDesc),
    /// A buffer's initial bytes (its size; a multiple of 4).
    Buffer(Vec<u8>),
    /// A sampler.
    Sampler(SamplerDesc),
}

/// How a storage texture is bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Access {
    /// WGSL `write` (WebGPU `write-only`).
    Write,
    /// WGSL `read` (WebGPU `read-only`).
    Read,
    /// WGSL `read_write` (WebGPU `read-write`); beyond the r32 formats it
    /// needs an adapter feature.
    ReadWrite,
}

/// What feeds one binding of a pass.
#[derive(Debug, Clone, PartialEq)]
pub enum Bind {
    /// A uniform block's bytes, packed for this pass.
    Uniform(Vec<u8>),
    /// A read-only u32 table owned by the pass (the noise permutation).
    Table(Vec<u32>),
    /// A buffer resource bound as a uniform (its bytes).
    UniformBuffer(usize),
    /// A buffer resource bound as storage.
    Storage {
        /// Index of the buffer in [`Graph::resources`].
        resource: usize,
        /// Bound `read-only-storage` rather than `storage`.
        read_only: bool,
    },
    /// A texture resource bound as a storage texture.
    StorageTexture {
        /// Index of the texture in [`Graph::resources`].
        resource: usize,
        /// The storage texture's access mode.
        access: Access,
    },
    /// A texture resource bound for sampling or loads; `depth` for
    /// `texture_depth_2d`, `cube` for `texture_cube` over six layers.
    Sampled {
        /// Index of the texture in [`Graph::resources`].
        resource: usize,
        /// Bound with a depth sample type.
        depth: bool,
        /// Viewed as a cube rather than by its own dimension.
        cube: bool,
    },
    /// A sampler resource.
    Sampler(usize),
}

impl Bind {
    /// The resource this binding names, if any.
    pub fn resource(&self) -> Option<usize> {
        match *self {
            Bind::UniformBuffer(r)
            | Bind::Storage { resource: r, .. }
            | Bind::StorageTexture { resource: r, .. }
            | Bind::Sampled { resource: r, .. }
            | Bind::Sampler(r) => Some(r),
            Bind::Uniform(_) | Bind::Table(_) => None,
        }
    }
}

/// One binding of a pass.
#[derive(Debug, Clone, PartialEq)]
pub struct GraphSlot {
    /// The WGSL `@group` index.
    pub group: u32,
    /// The WGSL `@binding` number within the group.
    pub binding: u32,
    /// What feeds the binding.
    pub bind: Bind,
}

/// One pass: a dispatch of an entry point; after every run the `swap`
/// pairs exchange which resource each name binds. A pass with `span` n
/// runs itself and the n - 1 passes after it, in order, `repeat` times (a
/// group; its later passes have span 0 and are run by it); span 1 is a
/// pass alone.
#[derive(Debug, Clone, PartialEq)]
pub struct GraphPass {
    /// Names the pass in errors and timings (e.g. `flux (pass 2)`).
    pub label: String,
    /// The kernel file (relative to `shaders/`), with defs after `?`.
    pub shader: String,
    /// The compute entry point.
    pub entry: String,
    /// Values of the module's pipeline-overridable constants, by name.
    pub constants: Vec<(String, f64)>,
    /// Workgroups dispatched along x, y and z.
    pub workgroups: [u32; 3],
    /// Every binding the entry point uses.
    pub slots: Vec<GraphSlot>,
    /// How many times the pass (or the group it starts) runs.
    pub repeat: u32,
    /// Pairs of resource indices whose bindings are exchanged after every
    /// run of the pass (ping-pong).
    pub swap: Vec<(usize, usize)>,
    /// Passes in the group this pass starts (itself included); 1 alone, 0
    /// for a later member of a group.
    pub span: u32,
    /// The entry point's reflected workgroup size (checked against the
    /// device's limits before any work).
    pub workgroup_size: [u32; 3],
}

impl GraphPass {
    /// What this pass needs of the device's limits.
    pub fn needs(&self) -> crate::Needs {
        let mut n = crate::Needs {
            workgroup_size: self.workgroup_size,
            workgroups: self.workgroups,
            bind_groups: self.slots.iter().map(|s| s.group + 1).max().unwrap_or(0),
            ..Default::default()
        };
        for s in &self.slots {
            match s.bind {
                Bind::Uniform(_) | Bind::UniformBuffer(_) => n.uniform_buffers += 1,
                Bind::Table(_) | Bind::Storage { .. } => n.storage_buffers += 1,
                Bind::StorageTexture { .. } => n.storage_textures += 1,
                Bind::Sampled { .. } => n.sampled_textures += 1,
                Bind::Sampler(_) => n.samplers += 1,
            }
        }
        n
    }
}

/// A whole graph.
#[derive(Debug, Clone)]
pub struct Graph<'a> {
    /// The project's WGSL sources.
    pub shaders: &'a ShaderSet,
    /// Every resource; bindings, swaps and outputs name them by index.
    pub resources: Vec<Resource>,
    /// The passes, in order.
    pub passes: Vec<GraphPass>,
    /// Resources read back after the last pass (after its swaps: a swapped
    /// name reads the resource it binds then).
    pub outputs: Vec<usize>,
}

/// The view a binding of `t` sees: six layers as a cube for a sampled
/// `texture_cube`, else the texture's own dimension.
fn view_dimension(t: &TextureDesc, cube: bool) -> wgpu::TextureViewDimension {
    match cube {
        true => wgpu::TextureViewDimension::Cube,
        false => t.dimension.view(),
    }
}

/// The order passes run in: each group (a pass with span n and the n - 1
/// after it) `repeat` times over, a pass alone `repeat` times in a row.
pub fn run_order(passes: &[GraphPass]) -> Vec<usize> {
    let mut order = Vec::new();
    let mut i = 0;
    while i < passes.len() {
        let span = (passes[i].span.max(1) as usize).min(passes.len() - i);
        for _ in 0..passes[i].repeat {
            order.extend(i..i + span);
        }
        i += span;
    }
    order
}

/// One output as read back.
#[derive(Debug, Clone, PartialEq)]
pub enum OutputData {
    /// A texture decoded to f32 RGBA (layers stacked top to bottom), and
    /// how many texels of a sentinel-filled output no pass wrote.
    Texture {
        /// The texels as f32 RGBA; never-written texels read 0.
        image: Image,
        /// Texels no pass wrote (0 unless the texture was sentinel-filled).
        unwritten: u64,
    },
    /// A buffer's bytes.
    Buffer(Vec<u8>),
}

/// A graph's outputs and timings.
#[derive(Debug, Clone)]
pub struct GraphReadback {
    /// One per [`Graph::outputs`], in that order.
    pub outputs: Vec<OutputData>,
    /// `kernel` sums every pass; `readback` is the copies and maps.
    pub stats: RunStats,
    /// Wall time of each pass, all its repeats together.
    pub pass_times: Vec<Duration>,
    /// GPU time of each pass from the device's timestamps, all its repeats
    /// together; `None` where the backend has no timestamps or
    /// [`Context::time_passes`] is off.
    pub pass_gpu_times: Vec<Option<Duration>>,
}

/// Two GPU timestamps around one pass run, resolved and read back.
struct Stamps {
    set: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    staging: wgpu::Buffer,
    /// Nanoseconds per timestamp tick.
    period: f64,
}

impl Stamps {
    fn new(w: &WgpuEngine) -> Stamps {
        let d = &w.device;
        let buffer = |usage| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps"),
                size: 16,
                usage,
                mapped_at_creation: false,
            })
        };
        Stamps {
            set: d.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolved: buffer(wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            staging: buffer(wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ),
            period: w.queue.get_timestamp_period() as f64,
        }
    }

    fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.set, 0..2, &self.resolved, 0);
        encoder.copy_buffer_to_buffer(&self.resolved, 0, &self.staging, 0, 16);
    }

    /// The pass's GPU time, once its submission is done.
    fn read(&self, ctx: &Context, w: &WgpuEngine, what: &str) -> Result<Duration, GpuError> {
        let (tx, rx) = mpsc::channel();
        self.staging.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        w.device
            .poll(wgpu::PollType::Wait { submission_index: None, timeout: Some(ctx.timeout) })
            .map_err(|e| GpuError::Validation { what: format!("{what}: timestamps"), message: e.to_string() })?;
        match rx.recv_timeout(ctx.timeout) {
            Ok(Ok(())) => {}
            _ => {
                return Err(GpuError::Validation { what: format!("{what}: timestamps"), message: "map failed".into() });
            }
        }
        let ticks = {
            let mapped = self
                .staging
                .slice(..)
                .get_mapped_range()
                .map_err(|e| GpuError::Validation { what: format!("{what}: timestamps"), message: e.to_string() })?;
            let at = |i: usize| u64::from_le_bytes(mapped[i * 8..i * 8 + 8].try_into().expect("8 bytes"));
            at(1).saturating_sub(at(0))
        };
        self.staging.unmap();
        Ok(Duration::from_nanos((ticks as f64 * self.period) as u64))
    }
}

struct Made {
    textures: HashMap<usize, wgpu::Texture>,
    buffers: HashMap<usize, wgpu::Buffer>,
    samplers: HashMap<usize, wgpu::Sampler>,
}

impl Context {
    /// Runs a pass graph and reads its outputs back. Sentinel-filled
    /// textures that still hold sentinel 0 somewhere are run again over
    /// sentinel 1: a texel holding each run's sentinel was never written.
    pub fn run_graph(&self, g: &Graph<'_>) -> Result<GraphReadback, GpuError> {
        for pass in &g.passes {
            self.require_needs(&pass.label, &pass.needs())?;
        }
        let start = Instant::now();
        let once = |which: usize| match &self.engine {
            Engine::Wgpu(w) => self.graph_once(w, g, which),
            Engine::Browser(b) => self.graph_in_browser(b, g, which),
        };
        let mut first = once(0)?;
        let suspects: Vec<Vec<usize>> = first.1.clone();
        if suspects.iter().any(|s| !s.is_empty()) {
            let second = once(1)?;
            for (i, out) in first.0.outputs.iter_mut().enumerate() {
                if let OutputData::Texture { image, unwritten } = out {
                    let never: Vec<usize> =
                        suspects[i].iter().copied().filter(|t| second.1[i].binary_search(t).is_ok()).collect();
                    for &t in &never {
                        image.data[t] = [0.0; 4];
                    }
                    *unwritten = never.len() as u64;
                }
            }
        }
        first.0.stats.total = start.elapsed();
        Ok(first.0)
    }

    /// One run over sentinel `which`: the outputs, and per output the
    /// texels holding the sentinel (empty for buffers and non-sentinel
    /// textures).
    fn graph_once(
        &self,
        w: &WgpuEngine,
        g: &Graph<'_>,
        which: usize,
    ) -> Result<(GraphReadback, Vec<Vec<usize>>), GpuError> {
        let d = &w.device;
        let start = Instant::now();
        let scope = d.push_error_scope(wgpu::ErrorFilter::Validation);
        let made = self.make_resources(w, g, which)?;
        let pipelines: Vec<Arc<crate::context::Compiled>> =
            g.passes.iter().map(|p| self.graph_pipeline(w, g, p)).collect::<Result<_, _>>()?;
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError::Validation { what: "the pass graph's resources".into(), message: e.to_string() });
        }
        // Which physical resource each name binds now (swaps exchange them).
        let mut current: Vec<usize> = (0..g.resources.len()).collect();
        let mut pass_times = vec![Duration::ZERO; g.passes.len()];
        let stamps = (self.time_passes.load(std::sync::atomic::Ordering::Relaxed)
            && w.device.features().contains(wgpu::Features::TIMESTAMP_QUERY))
        .then(|| Stamps::new(w));
        let mut gpu_times = vec![Duration::ZERO; g.passes.len()];
        let _serial = self.submit_lock.lock().expect("submit lock");
        for (pi, pass, compiled) in run_order(&g.passes).into_iter().map(|i| (i, &g.passes[i], &pipelines[i])) {
            let pass_start = Instant::now();
            {
                let scope = d.push_error_scope(wgpu::ErrorFilter::Validation);
                let owned: Vec<Option<wgpu::Buffer>> = pass
                    .slots
                    .iter()
                    .map(|s| match &s.bind {
                        Bind::Uniform(bytes) => Some(d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                            label: Some("params"),
                            contents: bytes,
                            usage: wgpu::BufferUsages::UNIFORM,
                        })),
                        Bind::Table(words) => Some(d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                            label: Some("table"),
                            contents: &words.iter().flat_map(|w| w.to_le_bytes()).collect::<Vec<u8>>(),
                            usage: wgpu::BufferUsages::STORAGE,
                        })),
                        _ => None,
                    })
                    .collect();
                let views: Vec<Option<wgpu::TextureView>> = pass
                    .slots
                    .iter()
                    .map(|s| match s.bind {
                        Bind::StorageTexture { resource, .. } | Bind::Sampled { resource, .. } => {
                            let Resource::Texture(t) = &g.resources[resource] else { return None };
                            let cube = matches!(s.bind, Bind::Sampled { cube: true, .. });
                            Some(made.textures[&current[resource]].create_view(&wgpu::TextureViewDescriptor {
                                dimension: Some(view_dimension(t, cube)),
                                ..Default::default()
                            }))
                        }
                        _ => None,
                    })
                    .collect();
                let groups: Vec<wgpu::BindGroup> = compiled
                    .groups
                    .iter()
                    .enumerate()
                    .map(|(gi, layout)| {
                        let entries: Vec<wgpu::BindGroupEntry> = pass
                            .slots
                            .iter()
                            .enumerate()
                            .filter(|(_, s)| s.group == gi as u32)
                            .map(|(i, s)| wgpu::BindGroupEntry {
                                binding: s.binding,
                                resource: match s.bind {
                                    Bind::Uniform(_) | Bind::Table(_) => {
                                        owned[i].as_ref().expect("owned buffer").as_entire_binding()
                                    }
                                    Bind::UniformBuffer(r) | Bind::Storage { resource: r, .. } => {
                                        made.buffers[&current[r]].as_entire_binding()
                                    }
                                    Bind::StorageTexture { .. } | Bind::Sampled { .. } => {
                                        wgpu::BindingResource::TextureView(views[i].as_ref().expect("a view"))
                                    }
                                    Bind::Sampler(r) => wgpu::BindingResource::Sampler(&made.samplers[&current[r]]),
                                },
                            })
                            .collect();
                        d.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some(&pass.label),
                            layout,
                            entries: &entries,
                        })
                    })
                    .collect();
                let mut encoder = d.create_command_encoder(&Default::default());
                crate::context::encode_dispatch(
                    &mut encoder,
                    compiled,
                    &groups,
                    pass.workgroups,
                    stamps.as_ref().map(|s| &s.set),
                );
                if let Some(s) = &stamps {
                    s.resolve(&mut encoder);
                }
                if let Some(e) = pollster::block_on(scope.pop()) {
                    return Err(GpuError::Validation { what: pass.label.clone(), message: e.to_string() });
                }
                let index = w.queue.submit([encoder.finish()]);
                self.wait(w, index, &pass.label)?;
                for &(a, b) in &pass.swap {
                    current.swap(a, b);
                }
            }
            pass_times[pi] += pass_start.elapsed();
            // Read after the wall time stops: the map is not the pass's.
            if let Some(s) = &stamps {
                gpu_times[pi] += s.read(self, w, &pass.label)?;
            }
        }
        let kernel: Duration = pass_times.iter().sum();
        let copy_start = Instant::now();
        let mut outputs = Vec::new();
        let mut sentinels = Vec::new();
        for &o in &g.outputs {
            let (data, held) = self.read_resource(w, g, &made, o, current[o], which)?;
            outputs.push(data);
            sentinels.push(held);
        }
        let readback = copy_start.elapsed();
        if self.validate {
            let messages = crate::validation::take();
            if !messages.is_empty() {
                return Err(GpuError::Validation {
                    what: format!("the pass graph (Khronos validation layer, {} messages)", messages.len()),
                    message: messages.join(" | "),
                });
            }
        }
        let stats = RunStats { gpu_wall: kernel + readback, kernel, readback, total: start.elapsed() };
        let pass_gpu_times = gpu_times.into_iter().map(|t| stamps.as_ref().map(|_| t)).collect();
        Ok((GraphReadback { outputs, stats, pass_times, pass_gpu_times }, sentinels))
    }

    /// The same graph in headless Chromium: naga's WGSL of each pass, the
    /// same resources, contents, bindings, repeats and swaps (`runner.js`,
    /// `vistaRunGraph`), the outputs decoded as on wgpu.
    fn graph_in_browser(
        &self,
        b: &crate::context::BrowserEngine,
        g: &Graph<'_>,
        which: usize,
    ) -> Result<(GraphReadback, Vec<Vec<usize>>), GpuError> {
        use serde_json::json;
        let b64 = vista_browser::base64;
        let filterable32 = b.features.iter().any(|f| f == "float32-filterable");
        let mut resources = Vec::new();
        for r in &g.resources {
            resources.push(match r {
                Resource::Texture(t) => {
                    let format = OutputFormat::parse(t.format)?;
                    let texels = (t.width * t.height * t.layers) as usize;
                    let contents = match &t.contents {
                        Contents::Zeros => None,
                        Contents::Bytes(bytes) => Some(b64(bytes)),
                        Contents::Sentinel => Some(b64(&format.sentinel(which).repeat(texels))),
                    };
                    json!({
                        "kind": "texture", "format": t.format, "dimension": t.dimension.web_names().0,
                        "width": t.width, "height": t.height, "layers": t.layers,
                        "texel_bytes": format.texel_bytes(), "contents": contents,
                    })
                }
                Resource::Buffer(bytes) => json!({ "kind": "buffer", "size": bytes.len(), "contents": b64(bytes) }),
                Resource::Sampler(s) => json!({
                    "kind": "sampler",
                    "filter": if s.linear { "linear" } else { "nearest" },
                    "address": s.address.iter().map(|a| a.web()).collect::<Vec<_>>(),
                    "compare": s.compare,
                }),
            });
        }
        let mut passes = Vec::new();
        for pass in &g.passes {
            let key =
                format!("{}#{}@{}{:?}", pass.shader, g.shaders.source_hash(&pass.shader)?, pass.entry, pass.constants);
            let cached = b.sources.lock().expect("wgsl cache").get(&key).cloned();
            let wgsl = match cached {
                Some(w) => w,
                None => {
                    let w = Arc::new(Context::wgsl_source(g.shaders, &pass.shader, &pass.entry, &pass.constants)?);
                    b.sources.lock().expect("wgsl cache").insert(key.clone(), w.clone());
                    w
                }
            };
            let mut slots = Vec::new();
            for s in &pass.slots {
                let texture = |r: usize| match &g.resources[r] {
                    Resource::Texture(t) => Ok(t),
                    _ => Err(GpuError::Request(format!("{}: a texture binding names a non-texture", pass.label))),
                };
                let (layout, source) = match &s.bind {
                    Bind::Uniform(bytes) => {
                        (json!({ "buffer": { "type": "uniform" } }), json!({ "owned": b64(bytes) }))
                    }
                    Bind::Table(words) => {
                        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
                        (json!({ "buffer": { "type": "read-only-storage" } }), json!({ "owned": b64(&bytes) }))
                    }
                    Bind::UniformBuffer(r) => (json!({ "buffer": { "type": "uniform" } }), json!({ "resource": r })),
                    Bind::Storage { resource, read_only } => (
                        json!({ "buffer": { "type": if *read_only { "read-only-storage" } else { "storage" } } }),
                        json!({ "resource": resource }),
                    ),
                    Bind::StorageTexture { resource, access } => {
                        let t = texture(*resource)?;
                        let format = OutputFormat::parse(t.format)?;
                        if *access == Access::ReadWrite && !self.binds_read_write(&format) {
                            return Err(GpuError::Unsupported {
                                adapter: self.adapter_description(),
                                what: format!("{}: a {} {} storage texture", pass.label, access.name(), t.format),
                                feature: self.read_write_feature().to_string(),
                            });
                        }
                        let access = match access {
                            Access::Write => "write-only",
                            Access::Read => "read-only",
                            Access::ReadWrite => "read-write",
                        };
                        (
                            json!({ "storageTexture": { "access": access, "format": t.format, "viewDimension": t.dimension.web_names().1 } }),
                            json!({ "resource": resource }),
                        )
                    }
                    Bind::Sampled { resource, depth, cube } => {
                        let t = texture(*resource)?;
                        let format = OutputFormat::parse(t.format)?;
                        let sample = match (depth, format.sample_kind()) {
                            (true, _) => "depth",
                            (_, SampleKind::Uint) => "uint",
                            (_, SampleKind::Sint) => "sint",
                            (_, SampleKind::Float) if format.is_float32() && !filterable32 => "unfilterable-float",
                            (_, SampleKind::Float) => "float",
                        };
                        (
                            json!({ "texture": { "sampleType": sample, "viewDimension": match cube {
                                true => "cube",
                                false => t.dimension.web_names().1,
                            } } }),
                            json!({ "resource": resource }),
                        )
                    }
                    Bind::Sampler(r) => {
                        let Resource::Sampler(sd) = &g.resources[*r] else {
                            return Err(GpuError::Request(format!("{}: a sampler bound to a non-sampler", pass.label)));
                        };
                        let ty = match (sd.compare.is_some(), sd.linear) {
                            (true, _) => "comparison",
                            (false, true) => "filtering",
                            (false, false) => "non-filtering",
                        };
                        (json!({ "sampler": { "type": ty } }), json!({ "resource": r }))
                    }
                };
                let mut slot = json!({ "group": s.group, "binding": s.binding, "layout": layout });
                slot.as_object_mut().expect("an object").extend(source.as_object().expect("an object").clone());
                slots.push(slot);
            }
            passes.push(json!({
                "key": key, "label": pass.label, "wgsl": *wgsl, "entry": pass.entry,
                "workgroups": pass.workgroups, "repeat": pass.repeat, "span": pass.span,
                "swap": pass.swap.iter().map(|(a, b)| [a, b]).collect::<Vec<_>>(),
                "slots": slots,
            }));
        }
        let job = json!({ "resources": resources, "passes": passes, "outputs": g.outputs });
        let label = g.passes.first().map(|p| p.shader.clone()).unwrap_or_default();
        let _serial = self.submit_lock.lock().expect("submit lock");
        let out = b.browser.run_graph(&label, &job).map_err(|e| match e {
            vista_browser::BrowserError::Timeout { case, seconds } => GpuError::Timeout { what: case, seconds },
            vista_browser::BrowserError::Page { case, message } => {
                GpuError::Validation { what: format!("{case} (in the browser)"), message }
            }
            other => GpuError::Device { adapter: self.adapter_description(), message: other.to_string() },
        })?;
        let mut outputs = Vec::new();
        let mut sentinels = Vec::new();
        for (&o, bytes) in g.outputs.iter().zip(out.outputs) {
            match &g.resources[o] {
                Resource::Texture(t) => {
                    let format = OutputFormat::parse(t.format)?;
                    let row = t.width as usize * format.texel_bytes();
                    let texels =
                        read_texels(&bytes, row, &format, t.width, t.height * t.layers, &format.sentinel(which));
                    sentinels.push(match t.contents {
                        Contents::Sentinel => texels.holding_sentinel,
                        _ => Vec::new(),
                    });
                    outputs.push(OutputData::Texture { image: texels.image, unwritten: 0 });
                }
                _ => {
                    sentinels.push(Vec::new());
                    outputs.push(OutputData::Buffer(bytes));
                }
            }
        }
        let kernel: Duration = out.passes.iter().sum();
        let stats = RunStats { gpu_wall: kernel + out.readback, kernel, readback: out.readback, total: out.total };
        let pass_gpu_times = vec![None; out.passes.len()];
        Ok((GraphReadback { outputs, stats, pass_times: out.passes, pass_gpu_times }, sentinels))
    }

    /// Creates every resource with its initial contents (`which` picks the
    /// sentinel of sentinel-filled textures).
    fn make_resources(&self, w: &WgpuEngine, g: &Graph<'_>, which: usize) -> Result<Made, GpuError> {
        let d = &w.device;
        let mut made = Made { textures: HashMap::new(), buffers: HashMap::new(), samplers: HashMap::new() };
        for (i, r) in g.resources.iter().enumerate() {
            match r {
                Resource::Texture(t) => {
                    let format = OutputFormat::parse(t.format)?;
                    let size = wgpu::Extent3d { width: t.width, height: t.height, depth_or_array_layers: t.layers };
                    let texture = d.create_texture(&wgpu::TextureDescriptor {
                        label: Some("resource"),
                        size,
                        mip_level_count: 1,
                        sample_count: 1,
                        dimension: t.dimension.texture(),
                        format: format.wgpu,
                        usage: wgpu::TextureUsages::STORAGE_BINDING
                            | wgpu::TextureUsages::TEXTURE_BINDING
                            | wgpu::TextureUsages::COPY_SRC
                            | wgpu::TextureUsages::COPY_DST,
                        view_formats: &[],
                    });
                    let texels = (t.width * t.height * t.layers) as usize;
                    let bytes = match &t.contents {
                        Contents::Zeros => None,
                        Contents::Bytes(b) => Some(b.clone()),
                        Contents::Sentinel => Some(format.sentinel(which).repeat(texels)),
                    };
                    if let Some(bytes) = bytes {
                        let row = t.width * format.texel_bytes() as u32;
                        if bytes.len() != row as usize * (t.height * t.layers) as usize {
                            return Err(GpuError::Request(format!(
                                "texture resource {i}: {} bytes of contents for {}x{}x{} {} texels",
                                bytes.len(),
                                t.width,
                                t.height,
                                t.layers,
                                t.format
                            )));
                        }
                        w.queue.write_texture(
                            texture.as_image_copy(),
                            &bytes,
                            wgpu::TexelCopyBufferLayout {
                                offset: 0,
                                bytes_per_row: Some(row),
                                rows_per_image: Some(t.height),
                            },
                            size,
                        );
                    }
                    made.textures.insert(i, texture);
                }
                Resource::Buffer(bytes) => {
                    // Zero-length buffers cannot be bound; a 4-byte floor.
                    let mut contents = bytes.clone();
                    contents.resize(contents.len().max(4).next_multiple_of(4), 0);
                    made.buffers.insert(
                        i,
                        d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                            label: Some("resource"),
                            contents: &contents,
                            usage: wgpu::BufferUsages::STORAGE
                                | wgpu::BufferUsages::UNIFORM
                                | wgpu::BufferUsages::COPY_SRC
                                | wgpu::BufferUsages::COPY_DST,
                        }),
                    );
                }
                Resource::Sampler(s) => {
                    let filter = if s.linear { wgpu::FilterMode::Linear } else { wgpu::FilterMode::Nearest };
                    let sampler = d.create_sampler(&wgpu::SamplerDescriptor {
                        label: Some("resource"),
                        address_mode_u: s.address[0].wgpu(),
                        address_mode_v: s.address[1].wgpu(),
                        address_mode_w: s.address[2].wgpu(),
                        mag_filter: filter,
                        min_filter: filter,
                        mipmap_filter: match s.linear {
                            true => wgpu::MipmapFilterMode::Linear,
                            false => wgpu::MipmapFilterMode::Nearest,
                        },
                        compare: s.compare.and_then(compare_fn),
                        ..Default::default()
                    });
                    made.samplers.insert(i, sampler);
                }
            }
        }
        Ok(made)
    }

    /// The pipeline of one pass, with bind group layouts from its slots
    /// and the resources they name; cached like single dispatches.
    fn graph_pipeline(
        &self,
        w: &WgpuEngine,
        g: &Graph<'_>,
        pass: &GraphPass,
    ) -> Result<Arc<crate::context::Compiled>, GpuError> {
        let filterable32 = w.device.features().contains(wgpu::Features::FLOAT32_FILTERABLE);
        let mut entries: Vec<(u32, wgpu::BindGroupLayoutEntry)> = Vec::new();
        for s in &pass.slots {
            let ty = match s.bind {
                Bind::Uniform(_) | Bind::UniformBuffer(_) => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                Bind::Table(_) => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                Bind::Storage { read_only, .. } => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                Bind::StorageTexture { resource, access } => {
                    let Resource::Texture(t) = &g.resources[resource] else {
                        return Err(GpuError::Request(format!(
                            "{}: a storage texture bound to a non-texture",
                            pass.label
                        )));
                    };
                    let format = OutputFormat::parse(t.format)?;
                    // Read-only storage is core for every storage format;
                    // read_write beyond the r32 formats needs a feature.
                    if access == Access::ReadWrite && !self.binds_read_write(&format) {
                        return Err(GpuError::Unsupported {
                            adapter: self.adapter_description(),
                            what: format!("{}: a {} {} storage texture", pass.label, access.name(), t.format),
                            feature: self.read_write_feature().to_string(),
                        });
                    }
                    wgpu::BindingType::StorageTexture {
                        access: match access {
                            Access::Write => wgpu::StorageTextureAccess::WriteOnly,
                            Access::Read => wgpu::StorageTextureAccess::ReadOnly,
                            Access::ReadWrite => wgpu::StorageTextureAccess::ReadWrite,
                        },
                        format: format.wgpu,
                        view_dimension: t.dimension.view(),
                    }
                }
                Bind::Sampled { resource, depth, cube } => {
                    let Resource::Texture(t) = &g.resources[resource] else {
                        return Err(GpuError::Request(format!("{}: a texture bound to a non-texture", pass.label)));
                    };
                    let format = OutputFormat::parse(t.format)?;
                    wgpu::BindingType::Texture {
                        sample_type: match (depth, format.sample_kind()) {
                            (true, _) => wgpu::TextureSampleType::Depth,
                            (_, SampleKind::Uint) => wgpu::TextureSampleType::Uint,
                            (_, SampleKind::Sint) => wgpu::TextureSampleType::Sint,
                            (_, SampleKind::Float) => {
                                wgpu::TextureSampleType::Float { filterable: !format.is_float32() || filterable32 }
                            }
                        },
                        view_dimension: view_dimension(t, cube),
                        multisampled: false,
                    }
                }
                Bind::Sampler(r) => {
                    let Resource::Sampler(sd) = &g.resources[r] else {
                        return Err(GpuError::Request(format!("{}: a sampler bound to a non-sampler", pass.label)));
                    };
                    wgpu::BindingType::Sampler(match (sd.compare.is_some(), sd.linear) {
                        (true, _) => wgpu::SamplerBindingType::Comparison,
                        (false, true) => wgpu::SamplerBindingType::Filtering,
                        (false, false) => wgpu::SamplerBindingType::NonFiltering,
                    })
                }
            };
            entries.push((
                s.group,
                wgpu::BindGroupLayoutEntry {
                    binding: s.binding,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty,
                    count: None,
                },
            ));
        }
        let key = format!(
            "graph {}#{}@{}{:?}{:?}",
            pass.shader,
            g.shaders.source_hash(&pass.shader)?,
            pass.entry,
            entries,
            pass.constants
        );
        if let Some(p) = w.pipelines.lock().expect("pipeline cache").get(&key) {
            return Ok(p.clone());
        }
        let last = entries.iter().map(|(g, _)| *g).max();
        let layouts: Vec<Vec<wgpu::BindGroupLayoutEntry>> = (0..last.map_or(0, |g| g + 1))
            .map(|gi| entries.iter().filter(|(g, _)| *g == gi).map(|(_, e)| *e).collect())
            .collect();
        let compiled = self.compile(w, g.shaders, &pass.shader, &pass.entry, &pass.constants, &layouts)?;
        w.pipelines.lock().expect("pipeline cache").insert(key, compiled.clone());
        Ok(compiled)
    }

    /// Reads one output back: `logical` is the name's index (its
    /// description), `physical` the resource it binds after the swaps.
    fn read_resource(
        &self,
        w: &WgpuEngine,
        g: &Graph<'_>,
        made: &Made,
        logical: usize,
        physical: usize,
        which: usize,
    ) -> Result<(OutputData, Vec<usize>), GpuError> {
        let d = &w.device;
        let mut encoder = d.create_command_encoder(&Default::default());
        let (staging, texture) = match &g.resources[logical] {
            Resource::Texture(t) => {
                let format = OutputFormat::parse(t.format)?;
                let row = t.width * format.texel_bytes() as u32;
                let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
                let rows = t.height * t.layers;
                let staging = d.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("readback"),
                    size: padded as u64 * rows as u64,
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                });
                encoder.copy_texture_to_buffer(
                    made.textures[&physical].as_image_copy(),
                    wgpu::TexelCopyBufferInfo {
                        buffer: &staging,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset: 0,
                            bytes_per_row: Some(padded),
                            rows_per_image: Some(t.height),
                        },
                    },
                    wgpu::Extent3d { width: t.width, height: t.height, depth_or_array_layers: t.layers },
                );
                (staging, Some((t, format, padded, rows)))
            }
            Resource::Buffer(bytes) => {
                let size = bytes.len().max(4).next_multiple_of(4) as u64;
                let staging = d.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("readback"),
                    size,
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                });
                encoder.copy_buffer_to_buffer(&made.buffers[&physical], 0, &staging, 0, size);
                (staging, None)
            }
            Resource::Sampler(_) => return Err(GpuError::Request("a sampler cannot be an output".into())),
        };
        let index = w.queue.submit([encoder.finish()]);
        let (tx, rx) = mpsc::channel();
        staging.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.wait(w, index, "readback")?;
        match rx.recv_timeout(self.timeout) {
            Ok(Ok(())) => {}
            Ok(Err(e)) => return Err(GpuError::Validation { what: "readback map".into(), message: e.to_string() }),
            Err(_) => {
                return Err(GpuError::Timeout { what: "readback map".into(), seconds: self.timeout.as_secs_f64() });
            }
        }
        let out = {
            let mapped = staging
                .slice(..)
                .get_mapped_range()
                .map_err(|e| GpuError::Validation { what: "readback map".into(), message: e.to_string() })?;
            match texture {
                Some((t, format, padded, rows)) => {
                    let sentinel = format.sentinel(which);
                    let texels = read_texels(&mapped, padded as usize, &format, t.width, rows, &sentinel);
                    let held = match t.contents {
                        Contents::Sentinel => texels.holding_sentinel,
                        _ => Vec::new(),
                    };
                    (OutputData::Texture { image: texels.image, unwritten: 0 }, held)
                }
                None => {
                    let Resource::Buffer(bytes) = &g.resources[logical] else { unreachable!("a buffer") };
                    (OutputData::Buffer(mapped[..bytes.len()].to_vec()), Vec::new())
                }
            }
        };
        staging.unmap();
        Ok(out)
    }
}

impl Access {
    fn name(self) -> &'static str {
        match self {
            Access::Write => "write",
            Access::Read => "read",
            Access::ReadWrite => "read_write",
        }
    }
}
