//! A pass graph (SPEC 14): resources made once (textures, buffers,
//! samplers, with their initial contents), passes dispatched in order
//! (each its own shader, entry point, constants, workgroup count and
//! bindings; repeated and ping-ponged), then the outputs read back. The
//! caller (vista-render) has already reflected every binding, checked every
//! input and packed every uniform; this module only makes and runs it.

use std::time::{Duration, Instant};

use vista_image::Image;

use crate::GpuError;
use crate::wire;
use vista_texel::{Access, Dimension};

use crate::context::{Context, Engine, RunStats};
use crate::shaders::ShaderSet;

/// What a texture holds before the first pass.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Contents {
    /// Zeros (a resource with no file).
    Zeros,
    /// Packed texels of the format, rows top to bottom, layers after each
    /// other (a file's contents, checked by the caller).
    Bytes(#[serde(with = "wire::bytes")] Vec<u8>),
    /// The sentinel texel: an output no pass reads, so a texel still
    /// holding it afterwards was never written.
    Sentinel,
}

/// A texture resource.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TextureDesc {
    /// The storage format's WGSL name (one of `vista_texel::format_names`).
    pub format: &'static str,
    /// The texture's dimension.
    pub dimension: Dimension,
    /// Width in texels.
    pub width: u32,
    /// Height in texels (of one layer).
    pub height: u32,
    /// Array layers or depth (1 for 1d and 2d).
    pub layers: u32,
    /// Mip levels (1: none); `contents` fills level 0, outputs read level 0.
    pub mip_levels: u32,
    /// What the texture holds before the first pass.
    pub contents: Contents,
}

/// A sampler's address mode along one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
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

    pub(crate) fn web(self) -> &'static str {
        Address::NAMES[self as usize]
    }

    pub(crate) fn wgpu(self) -> wgpu::AddressMode {
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

pub(crate) fn compare_fn(name: &str) -> Option<wgpu::CompareFunction> {
    use wgpu::CompareFunction as C;
    let all = [C::Never, C::Less, C::Equal, C::LessEqual, C::Greater, C::NotEqual, C::GreaterEqual, C::Always];
    COMPARE_NAMES.iter().position(|n| *n == name).map(|i| all[i])
}

/// A sampler resource.
#[derive(Debug, Clone, PartialEq, Eq, Hash, serde::Serialize)]
pub struct SamplerDesc {
    /// Linear filtering (else nearest), for magnification, minification
    /// and mips alike.
    pub linear: bool,
    /// Address modes along u, v and w.
    pub address: [Address; 3],
    /// A comparison sampler's function (one of [`COMPARE_NAMES`]).
    pub compare: Option<&'static str>,
}

// Names as the tables' own `&'static str`s (what plans hold): read as
// strings and looked up, so a worker's graph is the plan's.
#[derive(serde::Deserialize)]
struct TextureWire {
    format: String,
    dimension: Dimension,
    width: u32,
    height: u32,
    layers: u32,
    mip_levels: u32,
    contents: Contents,
}

impl<'de> serde::Deserialize<'de> for TextureDesc {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<TextureDesc, D::Error> {
        let w = TextureWire::deserialize(d)?;
        let format = vista_texel::Format::parse(&w.format).map_err(serde::de::Error::custom)?.name;
        let TextureWire { dimension, width, height, layers, mip_levels, contents, .. } = w;
        Ok(TextureDesc { format, dimension, width, height, layers, mip_levels, contents })
    }
}

#[derive(serde::Deserialize)]
struct SamplerWire {
    linear: bool,
    address: [Address; 3],
    compare: Option<String>,
}

impl<'de> serde::Deserialize<'de> for SamplerDesc {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<SamplerDesc, D::Error> {
        let w = SamplerWire::deserialize(d)?;
        let compare = match &w.compare {
            None => None,
            Some(name) => Some(
                *COMPARE_NAMES
                    .iter()
                    .find(|n| *n == name)
                    .ok_or_else(|| serde::de::Error::custom(format!("unknown compare function {name}")))?,
            ),
        };
        Ok(SamplerDesc { linear: w.linear, address: w.address, compare })
    }
}

/// A resource of the graph.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Resource {
    /// A texture.
    Texture(TextureDesc),
    /// A buffer's initial bytes (its size; a multiple of 4).
    Buffer(#[serde(with = "wire::bytes")] Vec<u8>),
    /// A sampler.
    Sampler(SamplerDesc),
    /// A depth32float texture of this width and height: a render pass's
    /// depth attachment, sampled by later passes as `texture_depth_2d`;
    /// with its first values (f32, little-endian, rows top to bottom) when
    /// a file gives them, else none (cleared by the pass that tests
    /// against it).
    Depth([u32; 2], #[serde(with = "wire::bytes")] Vec<u8>),
}

impl Resource {
    /// The texture an output of this resource reads back: a depth texture
    /// is read as r32float (its depth aspect's bytes are those of one).
    pub fn read_as(&self) -> Option<TextureDesc> {
        match self {
            Resource::Texture(t) => Some(t.clone()),
            Resource::Depth([width, height], _) => Some(TextureDesc {
                format: "r32float",
                dimension: Dimension::D2,
                width: *width,
                height: *height,
                layers: 1,
                mip_levels: 1,
                contents: Contents::Zeros,
            }),
            Resource::Buffer(_) | Resource::Sampler(_) => None,
        }
    }
}

/// One output read back after the last pass: a resource and, for a
/// texture, one mip level and one layer or all of them
/// (`[[output]] resource = "bloom@3"`, `"cube@layer2"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct OutputRef {
    /// Index of the resource in [`Graph::resources`].
    pub resource: usize,
    /// The mip level read (0: the full-size image).
    pub level: u32,
    /// The one layer read (`None`: every layer, stacked top to bottom).
    pub layer: Option<u32>,
}

impl OutputRef {
    /// The whole of resource `resource` (level 0, every layer).
    pub fn whole(resource: usize) -> OutputRef {
        OutputRef { resource, level: 0, layer: None }
    }

    /// The texture this output reads back from `r` (`None` for a buffer):
    /// its level's size, one layer or all. Only level 0 starts filled with
    /// a sentinel, so a deeper level has no unwritten texels to find.
    pub fn texture(&self, r: &Resource) -> Option<TextureDesc> {
        let mut t = r.read_as()?;
        if self.level > 0 {
            t.width = (t.width >> self.level).max(1);
            t.height = (t.height >> self.level).max(1);
            if t.dimension == Dimension::D3 {
                t.layers = (t.layers >> self.level).max(1);
            }
            if t.contents == Contents::Sentinel {
                t.contents = Contents::Zeros;
            }
        }
        if self.layer.is_some() {
            t.layers = 1;
        }
        Some(t)
    }

    /// The first layer (or depth slice) read.
    pub fn first_layer(&self) -> u32 {
        self.layer.unwrap_or(0)
    }
}

/// What feeds one binding of a pass.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Bind {
    /// A uniform block's bytes, packed for this pass.
    Uniform(#[serde(with = "wire::bytes")] Vec<u8>),
    /// A read-only u32 table owned by the pass (the noise permutation).
    Table(#[serde(with = "wire::words")] Vec<u32>),
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
        /// The one mip level it sees.
        level: u32,
    },
    /// A texture resource bound for sampling or loads; `depth` for
    /// `texture_depth_2d`, `view` for `texture_cube` (`texture_cube_array`)
    /// over its layers.
    Sampled {
        /// Index of the texture in [`Graph::resources`].
        resource: usize,
        /// Bound with a depth sample type.
        depth: bool,
        /// Viewed as a cube or cube array rather than by its own dimension.
        view: Option<Dimension>,
        /// The one mip level it sees; `None`: all of them.
        level: Option<u32>,
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
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GraphSlot {
    /// The WGSL `@group` index.
    pub group: u32,
    /// The WGSL `@binding` number within the group.
    pub binding: u32,
    /// What feeds the binding.
    pub bind: Bind,
    /// A render pass's vertex entry reads it (visible to the vertex stage).
    #[serde(default)]
    pub vertex: bool,
}

/// One colour target of a render pass: `@location(n)` of its fragment
/// entry goes to `targets[n]`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RasterTarget {
    /// Index of the texture in [`Graph::resources`].
    pub resource: usize,
    /// The mip level drawn into.
    pub level: u32,
    /// The array layer drawn into (0 for a 2d texture).
    #[serde(default)]
    pub layer: u32,
    /// Cleared to this before the draw; `None`: drawn over what the
    /// texture holds (a sentinel-filled output keeps its sentinel where the
    /// fragment entry discards: unwritten).
    pub clear: Option<[f64; 4]>,
    /// `clear` applies to the pass's first run only, later runs draw over
    /// (vista's default clear of a draw's target, not the manifest's).
    #[serde(default)]
    pub clear_once: bool,
    /// How the output meets the texel.
    pub blend: vista_texel::Blend,
}

/// One vertex buffer of a draw.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct VertexBuffer {
    /// Index of the buffer in [`Graph::resources`].
    pub resource: usize,
    /// Bytes from one element to the next.
    pub stride: u32,
    /// Advanced per instance rather than per vertex.
    pub instance: bool,
    /// (shader location, WebGPU vertex format name, byte offset).
    pub attributes: Vec<(u32, String, u32)>,
}

/// A render pass's depth test, on a depth resource (cleared every run).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Depth {
    /// The depth resource tested against (a pass's own buffer is one the
    /// plan adds).
    pub resource: usize,
    /// WebGPU's comparison name.
    pub compare: String,
    /// Whether passing fragments write their depth.
    pub write: bool,
    /// The value it is cleared to.
    pub clear: f64,
}

/// What makes a pass a render pass (SPEC 17): a vertex stage (vista's
/// full-screen triangle, [`crate::FULLSCREEN_WGSL`], or an entry of the
/// pass's shader with its buffers), the pass's entry as the fragment
/// stage, its targets and fixed-function state.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Raster {
    /// The colour targets, in `@location` order.
    pub targets: Vec<RasterTarget>,
    /// The `@vertex` entry (of the pass's shader, or of `vertex_shader`);
    /// `None`: the full-screen triangle.
    pub vertex: Option<String>,
    /// The composed file holding `vertex` when it is not the pass's shader.
    pub vertex_shader: Option<String>,
    /// That file's override values.
    pub vertex_constants: Vec<(String, f64)>,
    /// The vertex buffers, one per slot.
    pub buffers: Vec<VertexBuffer>,
    /// The index buffer.
    pub indices: Option<usize>,
    /// It holds u16 indices (else u32).
    #[serde(default)]
    pub index_u16: bool,
    /// Vertices (or indices) drawn per instance.
    pub count: u32,
    /// Instances drawn.
    pub instances: u32,
    /// The first vertex of a draw without indices.
    #[serde(default)]
    pub first_vertex: u32,
    /// The first instance.
    #[serde(default)]
    pub first_instance: u32,
    /// Added to each index of an indexed draw.
    #[serde(default)]
    pub base_vertex: i32,
    /// How vertices make primitives.
    pub topology: vista_texel::Topology,
    /// Which faces are discarded.
    pub cull: vista_texel::Cull,
    /// The depth test, if any.
    pub depth: Option<Depth>,
    /// The blend constant of the constant factors.
    pub blend_constant: Option<[f64; 4]>,
}

/// One pass: a dispatch of an entry point; after every run the `swap`
/// pairs exchange which resource each name binds. A pass with `span` n
/// runs itself and the n - 1 passes after it, in order, `repeat` times (a
/// group; its later passes have span 0 and are run by it); span 1 is a
/// pass alone.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
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
    /// A render pass: `entry` is its fragment stage, drawn into these
    /// targets (no dispatch: `workgroups` and `workgroup_size` are 1).
    #[serde(default)]
    pub raster: Option<Raster>,
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
    /// Borrowed from a plan where one runs it (a noise kernel's passes hold
    /// a 256 KiB table: a copy per case was a tenth of a small case's time).
    pub resources: std::borrow::Cow<'a, [Resource]>,
    /// The passes, in order.
    pub passes: std::borrow::Cow<'a, [GraphPass]>,
    /// Resources read back after the last pass (after its swaps: a swapped
    /// name reads the resource it binds then).
    pub outputs: std::borrow::Cow<'a, [OutputRef]>,
}

/// The usages each buffer resource needs, by index (`None` for other
/// resources): only what the passes bind it as, plus copies for reading it
/// back. WebGPU lets a shader observe a buffer's size (`arrayLength`), and
/// wgpu grows a buffer with VERTEX usage by a few bytes, so a buffer no draw
/// reads must not carry it. Ping-pong partners exchange bindings, so each
/// takes the other's usages too.
pub fn buffer_usages(resources: &[Resource], passes: &[GraphPass]) -> Vec<Option<BufferUse>> {
    let mut uses: Vec<Option<BufferUse>> =
        resources.iter().map(|r| matches!(r, Resource::Buffer(_)).then(BufferUse::default)).collect();
    let mut mark = |i: usize, f: &dyn Fn(&mut BufferUse)| {
        if let Some(Some(u)) = uses.get_mut(i) {
            f(u)
        }
    };
    for pass in passes {
        for s in &pass.slots {
            match s.bind {
                Bind::UniformBuffer(r) => mark(r, &|u| u.uniform = true),
                Bind::Storage { resource, .. } => mark(resource, &|u| u.storage = true),
                _ => {}
            }
        }
        if let Some(raster) = &pass.raster {
            for v in &raster.buffers {
                mark(v.resource, &|u| u.vertex = true);
            }
            if let Some(i) = raster.indices {
                mark(i, &|u| u.index = true);
            }
        }
    }
    // Swapped pairs share usages (to a fixed point: chains of pairs).
    loop {
        let mut changed = false;
        for pass in passes {
            for &(a, b) in &pass.swap {
                if let (Some(Some(x)), Some(Some(y))) = (uses.get(a).cloned(), uses.get(b).cloned()) {
                    let both = x.union(y);
                    if both != x || both != y {
                        uses[a] = Some(both);
                        uses[b] = Some(both);
                        changed = true;
                    }
                }
            }
        }
        if !changed {
            return uses;
        }
    }
}

/// How a buffer resource is bound by the passes of a graph.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct BufferUse {
    /// Bound as `var<storage>`.
    pub storage: bool,
    /// Bound as `var<uniform>`.
    pub uniform: bool,
    /// Read by a draw as a vertex buffer.
    pub vertex: bool,
    /// Read by a draw as its index buffer.
    pub index: bool,
}

impl BufferUse {
    fn union(self, o: BufferUse) -> BufferUse {
        BufferUse {
            storage: self.storage || o.storage,
            uniform: self.uniform || o.uniform,
            vertex: self.vertex || o.vertex,
            index: self.index || o.index,
        }
    }

    /// WebGPU's usage names, as the browser engine passes them.
    pub fn web_names(self) -> Vec<&'static str> {
        [(self.storage, "STORAGE"), (self.uniform, "UNIFORM"), (self.vertex, "VERTEX"), (self.index, "INDEX")]
            .into_iter()
            .filter_map(|(on, name)| on.then_some(name))
            .collect()
    }

    pub(crate) fn wgpu(self) -> wgpu::BufferUsages {
        let mut u = wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        for (on, usage) in [
            (self.storage, wgpu::BufferUsages::STORAGE),
            (self.uniform, wgpu::BufferUsages::UNIFORM),
            (self.vertex, wgpu::BufferUsages::VERTEX),
            (self.index, wgpu::BufferUsages::INDEX),
        ] {
            if on {
                u |= usage;
            }
        }
        u
    }
}

/// The bytes a buffer resource is made and bound with: its declared size,
/// with a 4-byte floor (WebGPU binds no empty buffer; every WGSL type's
/// size is a multiple of 4).
pub fn buffer_size(bytes: &[u8]) -> u64 {
    bytes.len().max(4).next_multiple_of(4) as u64
}

/// The view a binding of `t` sees: its layers as a cube or cube array for a
/// sampled `texture_cube` (`_array`), else the texture's own dimension.
pub(crate) fn view_dimension(t: &TextureDesc, view: Option<Dimension>) -> wgpu::TextureViewDimension {
    crate::format::view_dimension(view.unwrap_or(t.dimension))
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
pub struct Readback {
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

impl Context {
    /// Runs a pass graph (a one-pass kernel is a graph of one pass) and
    /// reads its outputs back. Sentinel-filled textures that still hold
    /// sentinel 0 somewhere are run again over sentinel 1: a texel holding
    /// each run's sentinel was never written.
    pub fn run(&self, g: &Graph<'_>) -> Result<Readback, GpuError> {
        self.require_graph(g, &[])?;
        let start = Instant::now();
        let once = |which: usize| match &self.engine {
            Engine::Wgpu(w) => self.run_wgpu(w, g, which),
            Engine::Browser(b) => self.run_in_browser(b, g, which),
            Engine::Described(_) => Err(GpuError::Request(
                "this process only describes a worker's device; its graphs run in the worker".into(),
            )),
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

    /// What the graph needs of the device, refused before any run (the
    /// parent asks this of a worker's device before sending the graph):
    /// texture sizes, each pass's workgroups and bindings, and each
    /// buffer's size. `names`: the first resources' names, for messages
    /// (a resource without one is named by its index).
    pub fn require_graph(&self, g: &Graph<'_>, names: &[String]) -> Result<(), GpuError> {
        let max = self.max_dimension();
        for r in g.resources.iter() {
            if let Resource::Texture(t) = r
                && (t.width > max || t.height > max)
            {
                return Err(GpuError::Request(format!(
                    "size {}x{} is outside this device's range: each side in [1, {max}]",
                    t.width, t.height
                )));
            }
        }
        for pass in g.passes.iter() {
            self.require_needs(&pass.label, &pass.needs())?;
        }
        // A buffer is bound whole: one past the device's binding size is
        // refused here, before a worker or the device holds a copy of it.
        for (i, used) in buffer_usages(&g.resources, &g.passes).iter().enumerate() {
            let (Some(used), Resource::Buffer(bytes)) = (used, &g.resources[i]) else { continue };
            let what = match names.get(i) {
                Some(name) => format!("buffer {name} ({} bytes)", bytes.len()),
                None => format!("buffer resource {i} ({} bytes)", bytes.len()),
            };
            let size = bytes.len() as u64;
            self.require(&what, "maxBufferSize", size)?;
            if used.storage {
                self.require(&format!("{what}, bound as storage"), "maxStorageBufferBindingSize", size)?;
            }
            if used.uniform {
                self.require(&format!("{what}, bound as uniform"), "maxUniformBufferBindingSize", size)?;
            }
        }
        Ok(())
    }
}
