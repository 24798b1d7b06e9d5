//! The wgpu engine's one executor: a graph's resources made (sentinel-
//! filled outputs and readback buffers taken from the last run's spares),
//! its pipelines compiled once, its passes dispatched in order, its outputs
//! read back.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};

use wgpu::util::DeviceExt;

use crate::GpuError;
use crate::context::{Compiled, Context, Pipeline, RunStats, WgpuEngine, decode_rows};
use crate::graph::{
    Bind, Contents, Graph, GraphPass, OutputData, Raster, Readback, Resource, TextureDesc, compare_fn, run_order,
    view_dimension,
};
use crate::spares::{Spares, TextureKey};
use vista_texel::{Access, Format, SampleKind};

/// Kept at most per kind: a graph's outputs, and a little more.
const SPARES: usize = 8;

/// The most bytes one readback band or sentinel fill copies: the staging
/// and fill buffers' size for large textures (4 MiB: 128 rows of 2048
/// rgba32float texels).
const READBACK_BAND: u64 = 4 << 20;

/// Rows of `padded` bytes per readback band or sentinel fill copy: as many
/// as [`READBACK_BAND`] holds, at least one, at most the texture's height.
fn band_rows(padded: u32, height: u32) -> u32 {
    (READBACK_BAND / u64::from(padded)).clamp(1, u64::from(height)) as u32
}

fn texture_key(t: &TextureDesc) -> TextureKey {
    (t.format, t.dimension, t.width, t.height, t.layers)
}

/// Takes the first spare with this key.
fn take<K: PartialEq, V>(pool: &Mutex<Spares>, pick: impl Fn(&mut Spares) -> &mut Vec<(K, V)>, key: &K) -> Option<V> {
    let mut spares = pool.lock().expect("spares");
    let list = pick(&mut spares);
    let at = list.iter().position(|(k, _)| k == key)?;
    Some(list.remove(at).1)
}

/// Keeps a spare, dropping the oldest past [`SPARES`].
fn keep<K, V>(list: &mut Vec<(K, V)>, key: K, value: V) {
    list.push((key, value));
    if list.len() > SPARES {
        list.remove(0);
    }
}

/// Bytes per padded row of a texture's readback or fill (rows of a buffer
/// copy are 256-byte aligned).
fn padded_row(t: &TextureDesc, format: &Format) -> u32 {
    let row = t.width * format.texel_bytes() as u32;
    row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT
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
    /// Each buffer with the bytes it was declared with: every binding and
    /// vertex or index slice covers exactly those (wgpu pads a buffer with
    /// VERTEX usage, and a shader sees a binding's size in `arrayLength`).
    buffers: HashMap<usize, (wgpu::Buffer, u64)>,
    samplers: HashMap<usize, wgpu::Sampler>,
    /// The fill buffers the sentinel copies read (spares again after the run).
    fills: Vec<((&'static str, usize, u64), wgpu::Buffer)>,
}

impl Context {
    /// One run over sentinel `which`: the outputs, and per output the
    /// texels holding the sentinel (empty for buffers and non-sentinel
    /// textures).
    pub(crate) fn run_wgpu(
        &self,
        w: &WgpuEngine,
        g: &Graph<'_>,
        which: usize,
    ) -> Result<(Readback, Vec<Vec<usize>>), GpuError> {
        let d = &w.device;
        let start = Instant::now();
        // A resource the device cannot allocate is this case's error, never
        // a panic of wgpu's uncaptured-error handler.
        let memory = d.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let scope = d.push_error_scope(wgpu::ErrorFilter::Validation);
        // Textures some render pass draws into: RENDER_ATTACHMENT, never pooled.
        let targets: Vec<usize> =
            g.passes.iter().flat_map(|p| p.raster.iter().flat_map(|r| r.targets.iter().map(|t| t.resource))).collect();
        let (made, fill) = self.make_resources(w, g, which, &targets)?;
        let pipelines: Vec<Arc<Compiled>> =
            g.passes.iter().map(|p| self.pipeline(w, g, p)).collect::<Result<_, _>>()?;
        let invalid = pollster::block_on(scope.pop());
        if let Some(e) = pollster::block_on(memory.pop()) {
            return Err(GpuError::Request(format!(
                "the device could not allocate the pass graph's resources: {e}; make them smaller"
            )));
        }
        if let Some(e) = invalid {
            return Err(GpuError::wgpu("the pass graph's resources", &e));
        }
        // Contents and sentinels land before the first pass is timed.
        let index = w.queue.submit([fill.finish()]);
        self.wait(w, index, "the pass graph's resources")?;
        // Which physical resource each name binds now (swaps exchange them).
        let mut current: Vec<usize> = (0..g.resources.len()).collect();
        let mut pass_times = vec![Duration::ZERO; g.passes.len()];
        let stamps = (self.time_passes.load(std::sync::atomic::Ordering::Relaxed)
            && w.device.features().contains(wgpu::Features::TIMESTAMP_QUERY))
        .then(|| Stamps::new(w));
        let mut gpu_times = vec![Duration::ZERO; g.passes.len()];
        let _serial = self.submit_lock.lock().expect("submit lock");
        let hook = self.on_pass.lock().expect("pass hook").clone();
        let mut ran = vec![false; g.passes.len()];
        for (pi, pass, compiled) in run_order(&g.passes).into_iter().map(|i| (i, &g.passes[i], &pipelines[i])) {
            let pass_start = Instant::now();
            let first_run = !std::mem::replace(&mut ran[pi], true);
            {
                let scope = d.push_error_scope(wgpu::ErrorFilter::Validation);
                let groups = bind_groups(d, g, pass, compiled, &made, &current);
                let mut encoder = d.create_command_encoder(&Default::default());
                let stamp_set = stamps.as_ref().map(|s| &s.set);
                match (&compiled.pipeline, &pass.raster) {
                    (Pipeline::Render(p), Some(raster)) => {
                        encode_draw(&mut encoder, p, &groups, raster, (&made, &current), first_run, stamp_set)
                    }
                    (Pipeline::Compute(p), _) => encode_dispatch(&mut encoder, p, &groups, pass.workgroups, stamp_set),
                    (Pipeline::Render(_), None) => unreachable!("render pipelines are made for render passes"),
                }
                if let Some(s) = &stamps {
                    s.resolve(&mut encoder);
                }
                if let Some(e) = pollster::block_on(scope.pop()) {
                    return Err(GpuError::wgpu(&pass.label, &e));
                }
                if let Some(hook) = &hook {
                    hook(&pass.label);
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
        for &o in g.outputs.iter() {
            let (data, held) = self.read_resource(w, g, &made, o, current[o.resource], which)?;
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
        let mut spares = w.spares.lock().expect("spares");
        for (i, texture) in made.textures {
            if let Resource::Texture(t @ TextureDesc { contents: Contents::Sentinel, mip_levels: 1, .. }) =
                &g.resources[i]
                && !targets.contains(&i)
            {
                keep(&mut spares.textures, texture_key(t), texture);
            }
        }
        for (key, buffer) in made.fills {
            keep(&mut spares.fills, key, buffer);
        }
        Ok((Readback { outputs, stats, pass_times, pass_gpu_times }, sentinels))
    }

    /// Texture resource `i` (`t`) created (or taken from the spares) with
    /// its contents: written, or the sentinel copies recorded on `fill`.
    #[allow(clippy::too_many_arguments)]
    fn make_texture(
        &self,
        w: &WgpuEngine,
        t: &crate::graph::TextureDesc,
        i: usize,
        which: usize,
        target: bool,
        fill: &mut wgpu::CommandEncoder,
        made: &mut Made,
    ) -> Result<wgpu::Texture, GpuError> {
        let d = &w.device;
        let format = crate::format::parse(t.format)?;
        let size = wgpu::Extent3d { width: t.width, height: t.height, depth_or_array_layers: t.layers };
        // Only single-level textures that no pass draws into are
        // kept (the key has no levels or usages).
        let spare = match t.contents {
            Contents::Sentinel if t.mip_levels == 1 && !target => take(&w.spares, |s| &mut s.textures, &texture_key(t)),
            _ => None,
        };
        let texture = spare.unwrap_or_else(|| {
            d.create_texture(&wgpu::TextureDescriptor {
                label: Some("resource"),
                size,
                mip_level_count: t.mip_levels,
                sample_count: 1,
                dimension: crate::format::texture_dimension(t.dimension),
                format: crate::format::wgpu_format(&format),
                usage: if format.is_storable() {
                    wgpu::TextureUsages::STORAGE_BINDING
                } else {
                    wgpu::TextureUsages::empty()
                } | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC
                    | wgpu::TextureUsages::COPY_DST
                    | if target { wgpu::TextureUsages::RENDER_ATTACHMENT } else { wgpu::TextureUsages::empty() },
                view_formats: &[],
            })
        });
        let row = t.width * format.texel_bytes() as u32;
        match &t.contents {
            Contents::Zeros => {}
            Contents::Bytes(bytes) => {
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
                    bytes,
                    wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(t.height) },
                    size,
                );
            }
            Contents::Sentinel => {
                // Copies from a kept buffer of sentinel texels,
                // rows padded as buffer copies need them: one
                // band of rows at most READBACK_BAND bytes, copied
                // over each band (every texel is the same).
                let padded = padded_row(t, &format);
                let band = band_rows(padded, t.height);
                let key = (t.format, which, u64::from(padded) * u64::from(band));
                let buffer = take(&w.spares, |s| &mut s.fills, &key).unwrap_or_else(|| {
                    d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("unwritten sentinel"),
                        contents: &format.sentinel(which).repeat(key.2 as usize / format.texel_bytes()),
                        usage: wgpu::BufferUsages::COPY_SRC,
                    })
                });
                for layer in 0..t.layers {
                    for y in (0..t.height).step_by(band as usize) {
                        let rows = band.min(t.height - y);
                        fill.copy_buffer_to_texture(
                            wgpu::TexelCopyBufferInfo {
                                buffer: &buffer,
                                layout: wgpu::TexelCopyBufferLayout {
                                    offset: 0,
                                    bytes_per_row: Some(padded),
                                    rows_per_image: Some(rows),
                                },
                            },
                            wgpu::TexelCopyTextureInfo {
                                texture: &texture,
                                mip_level: 0,
                                origin: wgpu::Origin3d { x: 0, y, z: layer },
                                aspect: wgpu::TextureAspect::All,
                            },
                            wgpu::Extent3d { width: t.width, height: rows, depth_or_array_layers: 1 },
                        );
                    }
                }
                made.fills.push((key, buffer));
            }
        }
        Ok(texture)
    }

    /// Creates every resource with its initial contents (`which` picks the
    /// sentinel of sentinel-filled textures; `targets` are drawn into), and
    /// the copies of the sentinel over them, to submit before the first pass.
    fn make_resources(
        &self,
        w: &WgpuEngine,
        g: &Graph<'_>,
        which: usize,
        targets: &[usize],
    ) -> Result<(Made, wgpu::CommandEncoder), GpuError> {
        let d = &w.device;
        let mut made =
            Made { textures: HashMap::new(), buffers: HashMap::new(), samplers: HashMap::new(), fills: Vec::new() };
        let mut fill = d.create_command_encoder(&Default::default());
        let usages = crate::graph::buffer_usages(&g.resources, &g.passes);
        for (i, r) in g.resources.iter().enumerate() {
            match r {
                Resource::Texture(t) => {
                    let texture = self.make_texture(w, t, i, which, targets.contains(&i), &mut fill, &mut made)?;
                    made.textures.insert(i, texture);
                }
                Resource::Buffer(bytes) => {
                    let mut contents = bytes.clone();
                    contents.resize(crate::graph::buffer_size(bytes) as usize, 0);
                    let buffer = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("resource"),
                        contents: &contents,
                        usage: usages[i].unwrap_or_default().wgpu(),
                    });
                    made.buffers.insert(i, (buffer, contents.len() as u64));
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
                Resource::Depth(size, values) => {
                    let texture = depth_texture(d, *size);
                    if !values.is_empty() {
                        crate::context::fill_depth(w, &texture, *size, values);
                    }
                    made.textures.insert(i, texture);
                }
            }
        }
        Ok((made, fill))
    }

    /// The binding type of slot `s` of `pass`, checked against what the
    /// device binds.
    fn binding_type(
        &self,
        w: &WgpuEngine,
        g: &Graph<'_>,
        pass: &GraphPass,
        s: &crate::graph::GraphSlot,
    ) -> Result<wgpu::BindingType, GpuError> {
        let filterable32 = w.device.features().contains(wgpu::Features::FLOAT32_FILTERABLE);
        Ok(match s.bind {
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
            Bind::StorageTexture { resource, access, .. } => {
                let Resource::Texture(t) = &g.resources[resource] else {
                    return Err(GpuError::Request(format!("{}: a storage texture bound to a non-texture", pass.label)));
                };
                let format = crate::format::parse(t.format)?;
                // Read-only storage is core for every storage format;
                // read_write beyond the r32 formats needs a feature.
                if access == Access::ReadWrite && !self.binds_read_write(&format) {
                    return Err(GpuError::Unsupported {
                        adapter: self.adapter_description(),
                        what: format!("{}: a {} {} storage texture", pass.label, access.wgsl(), t.format),
                        feature: self.read_write_feature().to_string(),
                    });
                }
                wgpu::BindingType::StorageTexture {
                    access: match access {
                        Access::Write => wgpu::StorageTextureAccess::WriteOnly,
                        Access::Read => wgpu::StorageTextureAccess::ReadOnly,
                        Access::ReadWrite => wgpu::StorageTextureAccess::ReadWrite,
                    },
                    format: crate::format::wgpu_format(&format),
                    view_dimension: crate::format::view_dimension(t.dimension),
                }
            }
            // A depth resource: texture_depth_2d, or texture_2d<f32> as
            // WebGPU allows (unfilterable-float).
            Bind::Sampled { resource, depth, .. } if matches!(g.resources[resource], Resource::Depth(..)) => {
                wgpu::BindingType::Texture {
                    sample_type: match depth {
                        true => wgpu::TextureSampleType::Depth,
                        false => wgpu::TextureSampleType::Float { filterable: false },
                    },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                }
            }
            Bind::Sampled { resource, depth, view, .. } => {
                let Resource::Texture(t) = &g.resources[resource] else {
                    return Err(GpuError::Request(format!("{}: a texture bound to a non-texture", pass.label)));
                };
                let format = crate::format::parse(t.format)?;
                wgpu::BindingType::Texture {
                    sample_type: match (depth, format.sample_kind()) {
                        (true, _) => wgpu::TextureSampleType::Depth,
                        (_, SampleKind::Uint) => wgpu::TextureSampleType::Uint,
                        (_, SampleKind::Sint) => wgpu::TextureSampleType::Sint,
                        (_, SampleKind::Float) => {
                            wgpu::TextureSampleType::Float { filterable: !format.is_float32() || filterable32 }
                        }
                    },
                    view_dimension: view_dimension(t, view),
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
        })
    }

    /// The pipeline of one pass, with bind group layouts from its slots
    /// and the resources they name; cached like single dispatches.
    fn pipeline(&self, w: &WgpuEngine, g: &Graph<'_>, pass: &GraphPass) -> Result<Arc<Compiled>, GpuError> {
        let mut entries: Vec<(u32, wgpu::BindGroupLayoutEntry)> = Vec::new();
        for s in &pass.slots {
            let ty = self.binding_type(w, g, pass, s)?;
            entries.push((
                s.group,
                wgpu::BindGroupLayoutEntry { binding: s.binding, visibility: stages(pass, s), ty, count: None },
            ));
        }
        let targets = match &pass.raster {
            Some(r) => {
                let adapter = || self.adapter_description();
                crate::raster::check_targets(r, &g.resources, &pass.label, &|f| self.has_feature(f), &adapter)?;
                let module = g.shaders.compose(&pass.shader)?;
                crate::raster::check_fragment(&module, &pass.entry, r, &g.resources, &pass.label)?;
                Some(crate::raster::color_targets(r, &g.resources, &pass.label)?)
            }
            None => None,
        };
        // A vertex entry of another file, composed.
        let vertex_module = match pass.raster.as_ref().and_then(|r| r.vertex_shader.as_ref()) {
            Some(file) => Some((g.shaders.compose(file)?, g.shaders.source_hash(file)?)),
            None => None,
        };
        // A render pipeline differs by its targets and fixed-function state too.
        let key = format!(
            "graph {}#{}@{}{:?}{:?}{:?}{:?}{:?}",
            pass.shader,
            g.shaders.source_hash(&pass.shader)?,
            pass.entry,
            entries,
            pass.constants,
            targets,
            pass.raster.as_ref().map(|r| (
                &r.vertex,
                &r.buffers,
                r.topology,
                r.cull,
                &r.depth,
                r.indices.map(|_| r.index_u16)
            )),
            pass.raster.as_ref().map(|r| (&r.vertex_shader, &r.vertex_constants, vertex_module.as_ref().map(|v| &v.1)))
        );
        if let Some(p) = w.pipelines.lock().expect("pipeline cache").get(&key) {
            return Ok(p.clone());
        }
        let last = entries.iter().map(|(g, _)| *g).max();
        let layouts: Vec<Vec<wgpu::BindGroupLayoutEntry>> = (0..last.map_or(0, |g| g + 1))
            .map(|gi| entries.iter().filter(|(g, _)| *g == gi).map(|(_, e)| *e).collect())
            .collect();
        let attributes = pass.raster.as_ref().map(|r| crate::raster::attributes(&r.buffers));
        let buffers =
            pass.raster.as_ref().zip(attributes.as_ref()).map(|(r, a)| crate::raster::buffer_layouts(&r.buffers, a));
        let render =
            pass.raster.as_ref().zip(targets.as_deref()).zip(buffers.as_deref()).map(|((r, targets), buffers)| {
                crate::context::RenderStages {
                    targets,
                    vertex_entry: r.vertex.as_deref(),
                    vertex_module: vertex_module.as_ref().map(|(m, _)| (&**m, r.vertex_constants.as_slice())),
                    buffers,
                    primitive: crate::raster::primitive(r),
                    depth_stencil: crate::raster::depth_stencil(r),
                }
            });
        let compiled = self.compile(w, g.shaders, &pass.shader, &pass.entry, &pass.constants, &layouts, render)?;
        w.pipelines.lock().expect("pipeline cache").insert(key, compiled.clone());
        Ok(compiled)
    }

    /// Reads one output back: `logical` is the name's index (its
    /// description), `physical` the resource it binds after the swaps. A
    /// texture comes back in bands of rows through one staging buffer of at
    /// most [`READBACK_BAND`] bytes: a whole-texture buffer was as large as
    /// the image again (64 MiB at 2048 x 2048 rgba32float), and kept.
    fn read_resource(
        &self,
        w: &WgpuEngine,
        g: &Graph<'_>,
        made: &Made,
        output: crate::graph::OutputRef,
        physical: usize,
        which: usize,
    ) -> Result<(OutputData, Vec<usize>), GpuError> {
        let logical = output.resource;
        let d = &w.device;
        let staging_of = |size: u64| {
            take(&w.spares, |s| &mut s.staging, &size).unwrap_or_else(|| {
                d.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("readback"),
                    size,
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                })
            })
        };
        let t = match (output.texture(&g.resources[logical]), &g.resources[logical]) {
            (Some(t), _) => t,
            (None, Resource::Buffer(bytes)) => {
                let size = crate::graph::buffer_size(bytes);
                let staging = staging_of(size);
                let mut encoder = d.create_command_encoder(&Default::default());
                encoder.copy_buffer_to_buffer(&made.buffers[&physical].0, 0, &staging, 0, size);
                let data = self.map_read(w, &staging, encoder, |mapped| mapped[..bytes.len()].to_vec())?;
                keep(&mut w.spares.lock().expect("spares").staging, staging.size(), staging);
                return Ok((OutputData::Buffer(data), Vec::new()));
            }
            (None, _) => return Err(GpuError::Request("a sampler cannot be an output".into())),
        };
        let format = crate::format::parse(t.format)?;
        let padded = padded_row(&t, &format);
        let band = band_rows(padded, t.height);
        let staging = staging_of(u64::from(padded) * u64::from(band));
        // A depth texture's depth aspect reads back as r32float.
        let aspect = match &g.resources[logical] {
            Resource::Depth(..) => wgpu::TextureAspect::DepthOnly,
            _ => wgpu::TextureAspect::All,
        };
        let sentinel = format.sentinel(which);
        let width = t.width as usize;
        let mut data = vec![[0.0f32; 4]; width * (t.height * t.layers) as usize];
        let mut holding = Vec::new();
        let mut first_row = 0usize;
        for layer in 0..t.layers {
            for y in (0..t.height).step_by(band as usize) {
                let rows = band.min(t.height - y);
                let mut encoder = d.create_command_encoder(&Default::default());
                encoder.copy_texture_to_buffer(
                    wgpu::TexelCopyTextureInfo {
                        texture: &made.textures[&physical],
                        mip_level: output.level,
                        origin: wgpu::Origin3d { x: 0, y, z: output.first_layer() + layer },
                        aspect,
                    },
                    wgpu::TexelCopyBufferInfo {
                        buffer: &staging,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset: 0,
                            bytes_per_row: Some(padded),
                            rows_per_image: Some(rows),
                        },
                    },
                    wgpu::Extent3d { width: t.width, height: rows, depth_or_array_layers: 1 },
                );
                let dst = &mut data[first_row * width..(first_row + rows as usize) * width];
                self.map_read(w, &staging, encoder, |mapped| {
                    let at = first_row * width;
                    decode_rows(mapped, padded as usize, &format, dst, width, at, &sentinel, &mut holding);
                })?;
                first_row += rows as usize;
            }
        }
        keep(&mut w.spares.lock().expect("spares").staging, staging.size(), staging);
        let image = vista_image::Image::from_raw(t.width, t.height * t.layers, data).expect("one texel per pixel");
        let held = match t.contents {
            Contents::Sentinel => holding,
            _ => Vec::new(),
        };
        Ok((OutputData::Texture { image, unwritten: 0 }, held))
    }

    /// Submits `encoder` (copies into `staging`), maps `staging` once they
    /// are done, and returns `read` of its bytes, unmapped again.
    fn map_read<T>(
        &self,
        w: &WgpuEngine,
        staging: &wgpu::Buffer,
        encoder: wgpu::CommandEncoder,
        read: impl FnOnce(&[u8]) -> T,
    ) -> Result<T, GpuError> {
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
            read(&mapped)
        };
        staging.unmap();
        Ok(out)
    }
}

/// The bind groups of one pass run: each slot's resource as the swaps
/// left it, a pass's own uniform blocks and table in buffers of their own.
fn bind_groups(
    d: &wgpu::Device,
    g: &Graph<'_>,
    pass: &GraphPass,
    compiled: &Compiled,
    made: &Made,
    current: &[usize],
) -> Vec<wgpu::BindGroup> {
    let owned: Vec<Option<wgpu::Buffer>> = pass
        .slots
        .iter()
        .map(|s| match &s.bind {
            Bind::Uniform(bytes) => Some(d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("params"),
                contents: bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            })),
            Bind::Table(words) => {
                // An empty table still binds: four zero words.
                let words: &[u32] = if words.is_empty() { &[0; 4] } else { words };
                Some(d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("table"),
                    contents: &words.iter().flat_map(|w| w.to_le_bytes()).collect::<Vec<u8>>(),
                    usage: wgpu::BufferUsages::STORAGE,
                }))
            }
            _ => None,
        })
        .collect();
    let views: Vec<Option<wgpu::TextureView>> = pass
        .slots
        .iter()
        .map(|s| match s.bind {
            Bind::StorageTexture { resource, .. } | Bind::Sampled { resource, .. } => {
                if let Resource::Depth(..) = &g.resources[resource] {
                    return Some(made.textures[&current[resource]].create_view(&Default::default()));
                }
                let Resource::Texture(t) = &g.resources[resource] else { return None };
                let view = match s.bind {
                    Bind::Sampled { view, .. } => view,
                    _ => None,
                };
                // A storage view sees one level; a sampled one, its level or all.
                let level = match s.bind {
                    Bind::StorageTexture { level, .. } | Bind::Sampled { level: Some(level), .. } => Some(level),
                    _ => None,
                };
                Some(made.textures[&current[resource]].create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(view_dimension(t, view)),
                    base_mip_level: level.unwrap_or(0),
                    mip_level_count: level.map(|_| 1),
                    ..Default::default()
                }))
            }
            _ => None,
        })
        .collect();
    compiled
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
                            let (buffer, size) = &made.buffers[&current[r]];
                            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                                buffer,
                                offset: 0,
                                size: std::num::NonZeroU64::new(*size),
                            })
                        }
                        Bind::StorageTexture { .. } | Bind::Sampled { .. } => {
                            wgpu::BindingResource::TextureView(views[i].as_ref().expect("a view"))
                        }
                        Bind::Sampler(r) => wgpu::BindingResource::Sampler(&made.samplers[&current[r]]),
                    },
                })
                .collect();
            d.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(&pass.label), layout, entries: &entries })
        })
        .collect()
}

/// A depth resource's texture (a pass's own depth buffer is one too):
/// cleared by the pass that tests against it, never filled.
fn depth_texture(d: &wgpu::Device, [width, height]: [u32; 2]) -> wgpu::Texture {
    d.create_texture(&wgpu::TextureDescriptor {
        label: Some("depth resource"),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// The stages that see a binding: a render pass's fragment stage (and its
/// vertex stage where that reads it), else compute.
fn stages(pass: &GraphPass, s: &crate::graph::GraphSlot) -> wgpu::ShaderStages {
    match (&pass.raster, s.vertex) {
        (Some(_), true) => wgpu::ShaderStages::VERTEX_FRAGMENT,
        (Some(_), false) => wgpu::ShaderStages::FRAGMENT,
        (None, _) => wgpu::ShaderStages::COMPUTE,
    }
}

/// One render pass: each target's view (its level; cleared where it says
/// so, on the first run only where `clear_once`, else drawn over), its
/// depth resource, the pipeline, its bind groups, vertex and index
/// buffers, the draw.
fn encode_draw(
    encoder: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::RenderPipeline,
    groups: &[wgpu::BindGroup],
    raster: &Raster,
    (made, current): (&Made, &[usize]),
    first_run: bool,
    stamps: Option<&wgpu::QuerySet>,
) {
    let views: Vec<wgpu::TextureView> = raster
        .targets
        .iter()
        .map(|t| {
            made.textures[&current[t.resource]].create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_mip_level: t.level,
                mip_level_count: Some(1),
                base_array_layer: t.layer,
                array_layer_count: Some(1),
                ..Default::default()
            })
        })
        .collect();
    let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = raster
        .targets
        .iter()
        .zip(&views)
        .map(|(t, view)| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: match t.clear {
                        Some([r, g, b, a]) if first_run || !t.clear_once => {
                            wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a })
                        }
                        _ => wgpu::LoadOp::Load,
                    },
                    store: wgpu::StoreOp::Store,
                },
            })
        })
        .collect();
    let depth_view =
        raster.depth.as_ref().map(|d| made.textures[&current[d.resource]].create_view(&Default::default()));
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: None,
        color_attachments: &attachments,
        depth_stencil_attachment: raster.depth.as_ref().zip(depth_view.as_ref()).map(|(depth, view)| {
            wgpu::RenderPassDepthStencilAttachment {
                view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(depth.clear as f32),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }
        }),
        timestamp_writes: stamps.map(|query_set| wgpu::RenderPassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        }),
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    for (g, group) in groups.iter().enumerate() {
        pass.set_bind_group(g as u32, group, &[]);
    }
    if let Some([r, g, b, a]) = raster.blend_constant {
        pass.set_blend_constant(wgpu::Color { r, g, b, a });
    }
    for (slot, v) in raster.buffers.iter().enumerate() {
        let (buffer, size) = &made.buffers[&current[v.resource]];
        pass.set_vertex_buffer(slot as u32, buffer.slice(..*size));
    }
    let instances = raster.first_instance..raster.first_instance + raster.instances;
    match raster.indices {
        Some(i) => {
            let (buffer, size) = &made.buffers[&current[i]];
            pass.set_index_buffer(buffer.slice(..*size), crate::raster::index_format(raster));
            pass.draw_indexed(0..raster.count, raster.base_vertex, instances);
        }
        None => pass.draw(raster.first_vertex..raster.first_vertex + raster.count, instances),
    }
}

/// One compute pass: the pipeline, its bind groups in order, the dispatch.
fn encode_dispatch(
    encoder: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::ComputePipeline,
    groups: &[wgpu::BindGroup],
    workgroups: [u32; 3],
    stamps: Option<&wgpu::QuerySet>,
) {
    // Timestamps 0 and 1 at the pass's beginning and end, where asked.
    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: None,
        timestamp_writes: stamps.map(|query_set| wgpu::ComputePassTimestampWrites {
            query_set,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        }),
    });
    pass.set_pipeline(pipeline);
    for (g, group) in groups.iter().enumerate() {
        pass.set_bind_group(g as u32, group, &[]);
    }
    let [x, y, z] = workgroups;
    pass.dispatch_workgroups(x, y, z);
}
