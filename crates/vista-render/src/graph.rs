//! Planning a pass graph (SPEC 14 part 2): every pass composed and
//! reflected, every binding resolved to a param block, the table or a
//! resource, every input file read and checked, and every resource, pass
//! and output laid out for `vista_gpu::Context::run`. All of it
//! before any GPU work: a bad file, size, element type or binding is bad
//! input, one line naming the resource, the file and what was expected.

use std::path::{Path, PathBuf};

use vista_gpu::{Bind, Contents, GraphSlot};
use vista_image::Image;
use vista_manifest::element::leaf_numpy;
use vista_manifest::graph::{Element, ResourceKind, SlotFeed, Tolerance, Usage};
use vista_manifest::{DisplayMap, Kernel, ParamSet};
use vista_texel::Dimension;

use crate::error::RenderError;

/// One output as planned.
#[derive(Debug, Clone)]
pub struct PlannedOutput {
    /// The resource's name.
    pub name: String,
    /// The manifest's tolerance.
    pub tolerance: Option<Tolerance>,
    /// Texels left unwritten are allowed.
    pub partial: bool,
    /// Texture or buffer.
    pub kind: PlannedKind,
}

/// What an output is.
#[derive(Debug, Clone)]
pub enum PlannedKind {
    /// A texture of this format, shown with this view.
    Texture {
        /// Its storage format.
        format: &'static str,
        /// Its PNG view.
        view: vista_manifest::Output,
        /// Raw to display values.
        display: DisplayMap,
    },
    /// A buffer of `count` elements.
    Buffer {
        /// The element its binding declares.
        element: Element,
        /// Elements after the fixed header.
        count: u64,
    },
}

/// A planned graph (a one-pass kernel's has one pass): what [`crate::run`]
/// takes, and how to read its outputs.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The kernel's name.
    pub kernel: String,
    /// Every resource with its initial contents.
    pub resources: Vec<vista_gpu::Resource>,
    /// The names of the kernel's resources, the first of `resources` (the
    /// rest are passes' own uniform blocks and depth buffers).
    pub names: Vec<String>,
    /// The passes in order.
    pub passes: Vec<vista_gpu::GraphPass>,
    /// Resource index of each output, in `outputs` order.
    pub output_ids: Vec<vista_gpu::OutputRef>,
    /// The outputs, the main one first.
    pub outputs: Vec<PlannedOutput>,
    /// Whether the kernel is deterministic (render-twice check).
    pub deterministic: bool,
    /// Every composed file the passes use (for hashes), in pass order.
    pub shaders: Vec<String>,
}

impl Plan {
    /// The first output's texture as it reads back, where it is one.
    pub fn main_texture(&self) -> Option<vista_gpu::TextureDesc> {
        let o = self.output_ids.first()?;
        o.texture(self.resources.get(o.resource)?)
    }
}

/// What one pass is planned from: its resolved slots and uniform layout,
/// its composed shader file and module, and its vertex entry's where that
/// lives in another file.
struct PassParts<'a> {
    slots: &'a [vista_manifest::graph::PassSlot],
    layout: &'a vista_manifest::UniformLayout,
    module: &'a naga::Module,
    file: &'a str,
    vertex: Option<(&'a naga::Module, &'a str)>,
}

/// Case-level replacements of resource files (`inputs = { name = "file" }`).
pub type Inputs = [(String, String)];

/// Every `replace` key of a pass is found in some file its modules reach
/// (the pass's shader or its separate vertex file): refused otherwise,
/// naming the key and every file the pass reaches.
pub fn check_replace_keys(shaders: &vista_gpu::ShaderSet, kernel: &Kernel, p: &ParamSet) -> Result<(), RenderError> {
    for i in 0..kernel.graph().passes.len() {
        let units = std::iter::once(kernel.pass_shader_for(i, p)).chain(kernel.vertex_shader_for(i, p));
        let mut keys: Vec<vista_gpu::ReplaceKeys> = Vec::new();
        for name in units {
            // A source that does not assemble is the user's to fix, as when composing.
            keys.extend(shaders.replace_keys(&name).map_err(|e| match e {
                vista_gpu::GpuError::Shader(m) => RenderError::BadInput(m),
                other => RenderError::Gpu(other),
            })?);
        }
        let applied = |k: &String| keys.iter().any(|r| r.applied.contains(k));
        if let Some(key) = keys.iter().flat_map(|r| &r.missed).find(|k| !applied(k)) {
            let mut files: Vec<&str> = Vec::new();
            for f in keys.iter().flat_map(|r| &r.files) {
                if !files.contains(&f.as_str()) {
                    files.push(f);
                }
            }
            return Err(RenderError::BadInput(vista_source::unmatched_error(key, &files)));
        }
    }
    Ok(())
}

/// A def the case sets (`defs = { X = true }`) must be read by a `#if`,
/// `#ifdef` or `@if` of a file some pass reaches: else it changes nothing
/// (a typo, or a def of another kernel), and the case is refused naming
/// it and the defs the files read. WESL passes are compiled before vista
/// sees their `@if`s, so a kernel with one is not checked.
pub fn check_case_defs(shaders: &vista_gpu::ShaderSet, kernel: &Kernel, p: &ParamSet) -> Result<(), RenderError> {
    if p.defs().is_empty() {
        return Ok(());
    }
    let passes = 0..kernel.graph().passes.len();
    let names: Vec<String> =
        passes.flat_map(|i| [Some(kernel.pass_shader_for(i, p)), kernel.vertex_shader_for(i, p)]).flatten().collect();
    let mut read = std::collections::BTreeSet::new();
    for name in &names {
        if name.split('|').next().is_some_and(|f| f.ends_with(".wesl")) {
            return Ok(());
        }
        read.extend(shaders.defs_read(name).map_err(|e| RenderError::BadInput(e.to_string()))?);
    }
    for def in p.defs().iter().map(|d| d.split_once('=').map_or(d.as_str(), |(name, _)| name)) {
        if !read.contains(def) {
            let known: Vec<&str> = read.iter().map(String::as_str).collect();
            return Err(RenderError::BadInput(format!(
                "defs: {def} is read by no #if, #ifdef or @if of kernel {}'s shaders; they read: {}",
                kernel.name(),
                if known.is_empty() { "none".to_string() } else { known.join(", ") }
            )));
        }
    }
    Ok(())
}

/// Plans `kernel`'s graph for `p` at `width` x `height` (the case size
/// that resources without a `size` take), reading input files under
/// `root` (or the case's `inputs` instead), within `max_bytes` of memory.
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan_graph(
    shaders: &vista_gpu::ShaderSet,
    root: Option<&Path>,
    kernel: &Kernel,
    p: &ParamSet,
    inputs: &Inputs,
    width: u32,
    height: u32,
    max_bytes: u64,
) -> Result<Plan, RenderError> {
    let g = kernel.graph();
    let bad = |m: String| RenderError::BadInput(format!("kernel {}: {m}", kernel.name()));
    let compose = |file: &str| {
        shaders.compose(file).map_err(|e| match e {
            vista_gpu::GpuError::Shader(m) => bad(m),
            other => RenderError::Gpu(other),
        })
    };
    // Keys no file of a pass holds, before composing leaves them in the text.
    check_replace_keys(shaders, kernel, p).map_err(|e| match e {
        RenderError::BadInput(m) => bad(m),
        other => other,
    })?;
    let mut files = Vec::new();
    let mut modules = Vec::new();
    // A draw's vertex entry in another file: its composed file and module.
    let mut vertex = Vec::new();
    for i in 0..g.passes.len() {
        let file = kernel.pass_shader_for(i, p);
        modules.push(compose(&file)?);
        files.push(file);
        vertex.push(match kernel.vertex_shader_for(i, p) {
            Some(v) => Some((compose(&v)?, v)),
            None => None,
        });
    }
    check_case_defs(shaders, kernel, p)?;
    let pairs: Vec<(&str, &naga::Module)> =
        files.iter().map(|f| f.as_str()).zip(modules.iter().map(|m| &**m)).collect();
    let vertex_pairs: Vec<Option<(&str, &naga::Module)>> =
        vertex.iter().map(|v| v.as_ref().map(|(m, f)| (f.as_str(), &**m))).collect();
    let (resolved, layouts) =
        kernel.graph_layouts_with(&pairs, &vertex_pairs).map_err(|e| RenderError::BadInput(e.to_string()))?;
    for (k, _) in kernel.manifest_overrides() {
        if !modules.iter().any(|m| m.overrides.iter().any(|(_, o)| o.name.as_deref() == Some(k))) {
            let names: Vec<&str> =
                modules.iter().flat_map(|m| m.overrides.iter().filter_map(|(_, o)| o.name.as_deref())).collect();
            return Err(bad(format!(
                "overrides: {k} is not an override of {}; their overrides: {}",
                kernel.shader_files().join(" or "),
                if names.is_empty() { "none".to_string() } else { names.join(", ") }
            )));
        }
    }
    for (name, _) in inputs {
        if !g.resources.iter().any(|r| &r.name == name) {
            let names: Vec<&str> = g.resources.iter().map(|r| r.name.as_str()).collect();
            return Err(bad(format!("case inputs: {name} names no resource; resources: {}", names.join(", "))));
        }
    }
    let at = Planning { root, kernel, p, inputs, width, height, max_bytes, spent: std::cell::Cell::new(0) };
    let mut resources = resolved
        .resources
        .iter()
        .enumerate()
        .map(|(ri, r)| match &r.spec.kind {
            ResourceKind::Texture { size, file, mip_levels, .. } => {
                at.texture(r, size.as_deref(), file.as_ref(), *mip_levels, resolved.outputs.contains(&ri))
            }
            ResourceKind::Buffer { file, data, fill, length, fields } => {
                use crate::leaf_values::is_leaf_file;
                let replaced = at.inputs.iter().find(|(n, _)| *n == r.spec.name).map(|(_, f)| f.as_str());
                let own_leaves = file.as_deref().filter(|f| is_leaf_file(f));
                let case_leaves = replaced.filter(|f| is_leaf_file(f));
                // Leaf values in layers: the manifest's fields, its file's, then
                // the case's (a file or an inline table) over them; a case's
                // .bin or .npy replaces them all.
                let by_leaf =
                    case_leaves.is_some() || (replaced.is_none() && (own_leaves.is_some() || fields.is_some()));
                match by_leaf {
                    true => {
                        let mut all = fields.clone().unwrap_or_default();
                        for f in own_leaves.into_iter().chain(case_leaves) {
                            all.extend(at.leaf_file(r, f)?);
                        }
                        at.fields(r, &all)
                    }
                    false => at.buffer(
                        r,
                        file.as_ref(),
                        data.as_deref(),
                        *fill,
                        length.as_ref(),
                        resolved.outputs.contains(&ri),
                    ),
                }
            }
            ResourceKind::Depth { size, file } => at.depth(r, size.as_deref(), file.as_ref()),
            ResourceKind::Sampler { linear, address, compare } => {
                let a = |s: &str| vista_gpu::Address::parse(s).expect("manifest checks address modes");
                Ok(vista_gpu::Resource::Sampler(vista_gpu::SamplerDesc {
                    linear: *linear,
                    address: [a(address[0]), a(address[1]), a(address[2])],
                    compare: *compare,
                }))
            }
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut passes = Vec::new();
    for (i, ((pass, slots), layout)) in g.passes.iter().zip(&resolved.slots).zip(&layouts).enumerate() {
        let parts = PassParts {
            slots,
            layout,
            module: &modules[i],
            file: &files[i],
            vertex: vertex[i].as_ref().map(|(m, f)| (&**m, f.as_str())),
        };
        passes.push(at.pass(i, pass, parts, &mut resources, &resolved)?);
    }
    for (_, vfile) in vertex.iter().flatten() {
        if !files.contains(vfile) {
            files.push(vfile.clone());
        }
    }
    let (outputs, output_ids) = at.outputs(&resources, &resolved)?;
    // The kernel's resources come first, by name; what passes own after them.
    let names = resolved.resources.iter().map(|r| r.spec.name.clone()).collect();
    Ok(Plan {
        kernel: kernel.name().to_string(),
        names,
        resources,
        passes,
        output_ids,
        outputs,
        deterministic: g.deterministic,
        shaders: files,
    })
}

/// A draw's counts and offsets, as WebGPU's draw() and drawIndexed() take them.
#[derive(Debug, Default)]
struct Draw {
    count: u32,
    instances: u32,
    first_vertex: u32,
    first_instance: u32,
    base_vertex: i32,
}

/// What planning each resource, pass and output of one graph reads.
struct Planning<'a> {
    root: Option<&'a Path>,
    kernel: &'a Kernel,
    p: &'a ParamSet,
    inputs: &'a Inputs,
    width: u32,
    height: u32,
    /// The memory budget ([`crate::RenderLimits::max_bytes`]).
    max_bytes: u64,
    /// What the resources planned so far need of it.
    spent: std::cell::Cell<u64>,
}

impl Planning<'_> {
    fn bad(&self, m: String) -> RenderError {
        RenderError::BadInput(format!("kernel {}: {m}", self.kernel.name()))
    }

    /// Counts `bytes` of resource `name` against the memory budget, before
    /// they are allocated: past it, the case is refused naming both.
    fn spend(&self, name: &str, what: &str, bytes: u64) -> Result<(), RenderError> {
        let total = self.spent.get().saturating_add(bytes);
        self.spent.set(total);
        if total <= self.max_bytes {
            return Ok(());
        }
        Err(self.bad(format!(
            "resource {name}: {what} needs {bytes} bytes ({total} with the resources before it), above the memory \
             budget of {} bytes; make it smaller, or raise VISTA_MAX_BYTES",
            self.max_bytes
        )))
    }

    /// The file a case's `inputs` give resource `name`, else its own.
    fn file_of(&self, name: &str, own: Option<&String>) -> Option<String> {
        self.inputs.iter().find(|(n, _)| n == name).map(|(_, f)| f.clone()).or(own.cloned())
    }

    /// A texture resource: its size (its `size`, its file's, else the
    /// case's), format and contents (its file's texels, the sentinel for
    /// an output no pass reads, else zeros).
    fn texture(
        &self,
        r: &vista_manifest::graph::ResolvedResource,
        size: Option<&[vista_manifest::expr::Expr]>,
        file: Option<&String>,
        mip_levels: u32,
        is_output: bool,
    ) -> Result<vista_gpu::Resource, RenderError> {
        let (root, width, height) = (self.root, self.width, self.height);
        let bad = |m: String| self.bad(m);
        let file = self.file_of(&r.spec.name, file);
        let at = |m: String| bad(format!("resource {}: {m}", r.spec.name));
        let dim = r.dimension.unwrap_or(Dimension::D2);
        // Six square layers (per cube of an array): written through a
        // 2d-array view, sampled through a cube (array) view.
        let dimension = dim.stored();
        let cube = dim == Dimension::Cube;
        let mut extent = match size {
            Some(exprs) => {
                let mut v = [1u32; 3];
                for (i, e) in exprs.iter().enumerate() {
                    v[i] = self.size_entry(i, e).map_err(at)?;
                }
                // A cube's size is its face's edge; a cube array's, the edge and the cubes.
                Some(match dim {
                    Dimension::Cube => [v[0], v[0], 6],
                    Dimension::CubeArray => [v[0], v[0], v[1].saturating_mul(6)],
                    _ => v,
                })
            }
            None => None,
        };
        let (format, contents) = match &file {
            Some(f) if f.ends_with(".npy") => {
                let (format, [fw, fh], bytes) = read_texture_npy(root, f, r.format).map_err(at)?;
                extent = Some(file_extent(f, [fw, fh], extent, cube).map_err(at)?);
                (format, Contents::Bytes(bytes))
            }
            Some(f) => {
                let (natural, image) = read_texture(root, f, self.max_bytes).map_err(at)?;
                extent = Some(file_extent(f, [image.width, image.height], extent, cube).map_err(at)?);
                if let Some((x, y)) = image.first_nonfinite() {
                    return Err(at(format!("file {f} holds NaN/Inf at ({x}, {y}); inputs must be finite")));
                }
                let format = r.format.unwrap_or(natural);
                let out = vista_texel::Format::parse(format).map_err(at)?;
                let bytes: Vec<u8> = image.data.iter().flat_map(|px| out.encode(*px)).collect();
                (format, Contents::Bytes(bytes))
            }
            None => {
                let format = r.format.ok_or_else(|| {
                    at("needs format = \"...\" (no file gives one and no storage binding declares one)".into())
                })?;
                let contents = if is_output && !r.read { Contents::Sentinel } else { Contents::Zeros };
                (format, contents)
            }
        };
        let [w, h, l] = match (extent, dim) {
            (Some(e), _) => e,
            (None, Dimension::D1) => [width, 1, 1],
            (None, Dimension::Cube) if width == height => [width, width, 6],
            (None, Dimension::Cube) => {
                return Err(at(format!("a cube's faces are square but the case is {width}x{height}; give size = [N]")));
            }
            (None, Dimension::CubeArray) => {
                return Err(at("a cube-array needs size = [edge, cubes] (its faces' edge and how many cubes)".into()));
            }
            (None, _) => [width, height, 1],
        };
        // Each level halves every side (depth too for 3d), down to 1x1.
        let deepest = match dimension {
            Dimension::D3 => w.max(h).max(l),
            _ => w.max(h),
        };
        let most = u32::BITS - deepest.leading_zeros();
        if mip_levels > most {
            return Err(at(format!(
                "mip_levels = {mip_levels} but a {w}x{h}{} texture has at most {most} levels; allowed: [1, {most}]",
                if dimension == Dimension::D3 { format!("x{l}") } else { String::new() }
            )));
        }
        // Its texels (a full mip chain adds at most a third), and an
        // output's read-back image of f32 RGBA.
        let texels = u64::from(w) * u64::from(h) * u64::from(l);
        let texel_bytes = vista_texel::Format::parse(format).map_err(at)?.texel_bytes() as u64;
        let chain = if mip_levels > 1 { texels * texel_bytes / 3 } else { 0 };
        let readback = if is_output { texels * 16 } else { 0 };
        let what = format!("a {w}x{h}x{l} {format} texture");
        self.spend(&r.spec.name, &what, texels * texel_bytes + chain + readback)?;
        Ok(vista_gpu::Resource::Texture(vista_gpu::TextureDesc {
            format,
            dimension,
            width: w,
            height: h,
            layers: l,
            mip_levels,
            contents,
        }))
    }

    /// Entry `i` of a resource's `size` for these params, in [1, 16384].
    fn size_entry(&self, i: usize, e: &vista_manifest::expr::Expr) -> Result<u32, String> {
        let n = e.eval(self.p, self.width, self.height).map_err(|m| format!("size[{i}] {m}"))?;
        u32::try_from(n)
            .ok()
            .filter(|n| (1..=16384).contains(n))
            .ok_or_else(|| format!("size[{i}] is {n} for these params; allowed: [1, 16384]"))
    }

    /// A depth resource: its size (default the case's).
    fn depth(
        &self,
        r: &vista_manifest::graph::ResolvedResource,
        size: Option<&[vista_manifest::expr::Expr]>,
        file: Option<&String>,
    ) -> Result<vista_gpu::Resource, RenderError> {
        let at = |m: String| self.bad(format!("resource {}: {m}", r.spec.name));
        let mut wh = [self.width, self.height];
        for (i, e) in size.unwrap_or_default().iter().enumerate() {
            wh[i] = self.size_entry(i, e).map_err(at)?;
        }
        let Some(f) = self.file_of(&r.spec.name, file) else { return Ok(vista_gpu::Resource::Depth(wh, Vec::new())) };
        // First values: f32 (H, W) from a .npy, or an EXR's red channel.
        let (fw, fh, values): (u32, u32, Vec<f32>) = match f.ends_with(".npy") {
            true => {
                let (_, [w, h], bytes) = read_texture_npy(self.root, &f, Some("r32float")).map_err(at)?;
                (w, h, bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect())
            }
            false => {
                let (_, image) = read_texture(self.root, &f, self.max_bytes).map_err(at)?;
                (image.width, image.height, image.data.iter().map(|t| t[0]).collect())
            }
        };
        if size.is_some() && [fw, fh] != wh {
            return Err(at(format!("file {f} is {fw}x{fh} but size says {}x{}", wh[0], wh[1])));
        }
        if let Some(i) = values.iter().position(|v| !(0.0..=1.0).contains(v)) {
            return Err(at(format!(
                "file {f} holds {} at ({}, {}); a depth32float texture holds depths in [0, 1]",
                values[i],
                i as u32 % fw,
                i as u32 / fw
            )));
        }
        Ok(vista_gpu::Resource::Depth([fw, fh], values.iter().flat_map(|v| v.to_le_bytes()).collect()))
    }

    /// The leaf values of a `.toml` or `.json` file (root-relative), or of a
    /// case's inline table.
    fn leaf_file(
        &self,
        r: &vista_manifest::graph::ResolvedResource,
        file: &str,
    ) -> Result<Vec<(String, Vec<f64>)>, RenderError> {
        let at = |m: String| self.bad(format!("resource {}: {m}", r.spec.name));
        if let Some(json) = file.strip_prefix(crate::leaf_values::INLINE) {
            return crate::leaf_values::parse("the case's inputs", json).map_err(at);
        }
        let bytes = read_input(self.root, file, &under(self.root, file).map_err(at)?).map_err(at)?;
        let text = String::from_utf8(bytes).map_err(|_| at(format!("file {file} is not UTF-8 text")))?;
        crate::leaf_values::parse(file, &text).map_err(at)
    }

    /// A buffer of one struct from `fields`: each named field's leaves in
    /// order (`lights[1].color` is `lights.1.color`, a vector's x y z w, a
    /// matrix's columns), every other leaf zero.
    fn fields(
        &self,
        r: &vista_manifest::graph::ResolvedResource,
        fields: &[(String, Vec<f64>)],
    ) -> Result<vista_gpu::Resource, RenderError> {
        let at = |m: String| self.bad(format!("resource {}: {m}", r.spec.name));
        let Some(e) = &r.element else {
            return Err(at("no pass binds this buffer".into()));
        };
        if e.fixed != Some(1) || e.header != 0 {
            return Err(at(format!("fields fill a binding of one struct, not {}; give data or a file", e.wgsl)));
        }
        let mut bytes = vec![0u8; e.stride as usize];
        for (key, values) in fields {
            let path = key.replace('[', ".").replace(']', "");
            let leaves: Vec<&(u32, char, String)> =
                e.leaves.iter().filter(|(_, _, p)| *p == path || p.starts_with(&format!("{path}."))).collect();
            if leaves.is_empty() {
                let mut known: Vec<String> = e.leaves.iter().map(|(_, _, p)| user_path(p)).collect();
                known.dedup();
                let near = crate::leaf_values::nearest(key, known.iter().map(String::as_str));
                return Err(at(format!(
                    "fields: \"{key}\" names no leaf of {}; nearest: {} (vista list --layout lists every leaf)",
                    e.wgsl,
                    near.join(", ")
                )));
            }
            if leaves.len() != values.len() {
                return Err(at(format!(
                    "fields: \"{key}\" takes {} number{}, not {}",
                    leaves.len(),
                    if leaves.len() == 1 { "" } else { "s" },
                    values.len()
                )));
            }
            for ((offset, kind, leaf), v) in leaves.into_iter().zip(values) {
                let word = encode_leaf(*kind, *v)
                    .ok_or_else(|| at(format!("fields: {v} does not fit {leaf} ({})", leaf_type(*kind))))?;
                bytes[*offset as usize..*offset as usize + word.len()].copy_from_slice(&word);
            }
        }
        Ok(vista_gpu::Resource::Buffer(bytes))
    }

    /// A buffer resource: its header and elements from a file, inline
    /// `data`, or `length` copies of `fill`.
    fn buffer(
        &self,
        r: &vista_manifest::graph::ResolvedResource,
        file: Option<&String>,
        data: Option<&[f64]>,
        fill: Option<f64>,
        length: Option<&vista_manifest::expr::Expr>,
        is_output: bool,
    ) -> Result<vista_gpu::Resource, RenderError> {
        let (root, p, width, height) = (self.root, self.p, self.width, self.height);
        let bad = |m: String| self.bad(m);
        let file = self.file_of(&r.spec.name, file);
        let at = |m: String| bad(format!("resource {}: {m}", r.spec.name));
        let Some(e) = &r.element else {
            return Err(at("no pass binds this buffer".into()));
        };
        let count = |n: i64| -> Result<u64, RenderError> {
            u64::try_from(n)
                .ok()
                .filter(|n| (1..=1 << 28).contains(n))
                .ok_or_else(|| at(format!("length is {n}; allowed: [1, 268435456]")))
        };
        let body = match (&file, data, fill, length) {
            (Some(f), ..) => read_buffer(root, f, e).map_err(at)?,
            (None, Some(values), ..) => encode_values(values, e).map_err(at)?,
            (None, None, fill, len) => {
                let n = match (len, e.fixed) {
                    (Some(l), _) => count(l.eval(p, width, height).map_err(|m| at(format!("length {m}")))?)?,
                    (None, Some(n)) => n as u64,
                    (None, None) => {
                        return Err(at(format!(
                            "{} is runtime-sized: give it length = N (with fill), data or a file",
                            e.wgsl
                        )));
                    }
                };
                // Counted before it is made; one element encoded, then repeated.
                let bytes = u64::from(e.header) + n * u64::from(e.stride);
                let what = format!("{n} elements of {} bytes", e.stride);
                self.spend(&r.spec.name, &what, if is_output { 2 * bytes } else { bytes })?;
                let v = fill.unwrap_or(0.0);
                encode_values(&vec![v; e.leaves.len()], e).map_err(at)?.repeat(n as usize)
            }
        };
        // The header in front, without a second copy of a large body.
        let mut bytes = body;
        bytes.splice(0..0, std::iter::repeat_n(0u8, e.header as usize));
        if let Some(n) = e.fixed {
            let want = e.header as u64 + n as u64 * e.stride as u64;
            if bytes.len() as u64 != want {
                return Err(at(format!(
                    "holds {} elements but {} is fixed at {n}",
                    (bytes.len() as u64 - e.header as u64) / e.stride as u64,
                    e.wgsl
                )));
            }
        }
        Ok(vista_gpu::Resource::Buffer(bytes))
    }

    /// Pass `i`: its constants, workgroup size and count, bindings (its
    /// own uniform blocks and table, or resources), repeats and swaps.
    fn pass(
        &self,
        i: usize,
        pass: &vista_manifest::graph::PassSpec,
        parts: PassParts<'_>,
        resources: &mut Vec<vista_gpu::Resource>,
        resolved: &vista_manifest::graph::Resolved,
    ) -> Result<vista_gpu::GraphPass, RenderError> {
        let PassParts { slots, layout, module, file, vertex } = parts;
        let (kernel, width, height) = (self.kernel, self.width, self.height);
        let g = kernel.graph();
        let bad = |m: String| self.bad(m);
        let index = |name: &str| resolved.resources.iter().position(|r| r.spec.name == name).expect("resolved");
        let label = format!("pass {} ({}, {})", i + 1, pass.entry, file);
        let pp = self.pass_params(pass).map_err(|e| match e {
            RenderError::BadInput(m) => bad(format!("{label}: {m}")),
            other => other,
        })?;
        let constants = kernel.overrides_in(module, &pp, false).map_err(|e| RenderError::BadInput(e.to_string()))?;
        let blocks = kernel.uniforms(layout, &pp, width, height);
        let mut table = Some(vista_kernels::noise::table(kernel, layout, &pp));
        let tables = slots.iter().filter(|s| matches!(s.feed, SlotFeed::Table)).count();
        let mut gslots = Vec::new();
        for s in slots {
            let bind = match &s.feed {
                SlotFeed::Uniform(n) => Bind::Uniform(blocks[*n].clone()),
                // Moved into the one slot that binds it (256 KiB for noise).
                SlotFeed::Table if tables == 1 => Bind::Table(table.take().unwrap_or_default()),
                SlotFeed::Table => Bind::Table(table.clone().unwrap_or_default()),
                SlotFeed::Resource(r, usage) => match usage {
                    Usage::UniformBuffer => Bind::UniformBuffer(*r),
                    Usage::StorageBuffer { read_only } => Bind::Storage { resource: *r, read_only: *read_only },
                    Usage::StorageTexture(st) => {
                        Bind::StorageTexture { resource: *r, access: st.access, level: s.level.unwrap_or(0) }
                    }
                    Usage::Sampled { kind, dim } => Bind::Sampled {
                        resource: *r,
                        depth: *kind == vista_manifest::graph::SampledKind::Depth,
                        view: dim.is_cube().then_some(*dim),
                        level: s.level,
                    },
                    Usage::Sampler { .. } => Bind::Sampler(*r),
                },
            };
            gslots.push(GraphSlot { group: s.group, binding: s.binding, bind, vertex: s.vertex });
        }
        let (size, workgroups, raster) = match &pass.raster {
            // A render pass draws; it dispatches nothing.
            Some(r) => {
                let mut raster = self.raster(i, r, &label, resources, resolved, &pp)?;
                if let Some((vmodule, vfile)) = vertex {
                    // Its own overrides' values (the pass's, for the names it declares).
                    raster.vertex_shader = Some(vfile.to_string());
                    raster.vertex_constants =
                        kernel.overrides_in(vmodule, &pp, false).map_err(|e| RenderError::BadInput(e.to_string()))?;
                }
                ([1; 3], [1; 3], Some(raster))
            }
            None => {
                let size = crate::reflect::workgroup_size(module, &pass.entry, &constants)
                    .map_err(|e| bad(format!("{label}: {e}")))?;
                (size, self.dispatch(pass, slots, resources, resolved, &pp, size, &label)?, None)
            }
        };
        let repeat = match &pass.repeat {
            vista_manifest::graph::Repeat::Count(n) => *n,
            vista_manifest::graph::Repeat::Param(name) => {
                let n = pp.int(name);
                u32::try_from(n)
                    .ok()
                    .filter(|n| (1..=100_000).contains(n))
                    .ok_or_else(|| bad(format!("{label}: repeat = {name} is {n}; allowed: [1, 100000]")))?
            }
        };
        let swap = pass.swap.iter().map(|(a, b)| (index(a), index(b))).collect();
        Ok(vista_gpu::GraphPass {
            label,
            shader: file.to_string(),
            entry: pass.entry.clone(),
            constants,
            workgroups,
            slots: gslots,
            repeat,
            swap,
            span: g.span(i) as u32,
            workgroup_size: size,
            raster,
        })
    }

    /// A compute pass's workgroup counts: its `workgroups`, else its
    /// `dispatch` resource (or the one texture it writes, else the case
    /// size) covered with the reflected workgroup size `size`.
    #[allow(clippy::too_many_arguments)]
    fn dispatch(
        &self,
        pass: &vista_manifest::graph::PassSpec,
        slots: &[vista_manifest::graph::PassSlot],
        resources: &[vista_gpu::Resource],
        resolved: &vista_manifest::graph::Resolved,
        pp: &ParamSet,
        size: [u32; 3],
        label: &str,
    ) -> Result<[u32; 3], RenderError> {
        let (width, height) = (self.width, self.height);
        let bad = |m: String| self.bad(m);
        let index = |name: &str| resolved.resources.iter().position(|r| r.spec.name == name).expect("resolved");
        let cover = |r: usize, level: u32| -> [u32; 3] {
            match &resources[r] {
                vista_gpu::Resource::Texture(t) => {
                    let depth = if t.dimension == Dimension::D3 { (t.layers >> level).max(1) } else { t.layers };
                    [(t.width >> level).max(1), (t.height >> level).max(1), depth]
                }
                vista_gpu::Resource::Buffer(b) => {
                    let e = resolved.resources[r].element.as_ref().expect("a bound buffer");
                    [((b.len() as u32 - e.header) / e.stride.max(1)).max(1), 1, 1]
                }
                vista_gpu::Resource::Sampler(_) => [width, height, 1],
                vista_gpu::Resource::Depth([w, h], _) => [*w, *h, 1],
            }
        };
        Ok(match (&pass.workgroups, &pass.dispatch) {
            (Some(exprs), _) => {
                let mut out = [1u32; 3];
                for (k, e) in exprs.iter().enumerate() {
                    let v = e.eval(pp, width, height).map_err(|m| bad(format!("{label}: workgroups[{k}] {m}")))?;
                    out[k] = u32::try_from(v).ok().filter(|v| (1..=65535).contains(v)).ok_or_else(|| {
                        bad(format!("{label}: workgroups[{k}] is {v} for these params; allowed: [1, 65535]"))
                    })?;
                }
                out
            }
            (None, target) => {
                let extent = match target {
                    Some(l) => cover(index(&l.resource), l.level.unwrap_or(0)),
                    None => {
                        let written: Vec<(usize, u32)> = slots
                            .iter()
                            .filter_map(|s| match s.feed {
                                SlotFeed::Resource(r, Usage::StorageTexture(st))
                                    if st.access != vista_texel::Access::Read =>
                                {
                                    Some((r, s.level.unwrap_or(0)))
                                }
                                _ => None,
                            })
                            .collect();
                        match written[..] {
                            [(one, level)] => cover(one, level),
                            _ => [width, height, 1],
                        }
                    }
                };
                let wg = [extent[0].div_ceil(size[0]), extent[1].div_ceil(size[1]), extent[2].div_ceil(size[2])];
                if let Some(k) = wg.iter().position(|v| *v > 65535) {
                    return Err(bad(format!("{label}: {} workgroups along axis {k}; allowed: at most 65535", wg[k])));
                }
                wg
            }
        })
    }

    /// The case's params with the pass's `set` over them.
    fn pass_params(&self, pass: &vista_manifest::graph::PassSpec) -> Result<ParamSet, RenderError> {
        let mut pp = self.p.clone();
        for (k, v) in &pass.set {
            pp = pp.with(self.kernel.params(), k, v).map_err(|e| RenderError::BadInput(format!("set: {e}")))?;
        }
        Ok(pp)
    }

    /// A render pass as the engine draws it: its targets (each a
    /// renderable format, blended only where the format allows, all of one
    /// size), its vertex stage, buffers and counts, and its fixed-function state.
    fn raster(
        &self,
        i: usize,
        r: &vista_manifest::graph::RasterSpec,
        label: &str,
        resources: &mut Vec<vista_gpu::Resource>,
        resolved: &vista_manifest::graph::Resolved,
        pp: &ParamSet,
    ) -> Result<vista_gpu::Raster, RenderError> {
        use vista_manifest::graph::VertexStage;
        let index = |name: &str| resolved.resources.iter().position(|x| x.spec.name == name).expect("resolved");
        let mut targets = Vec::new();
        let mut size: Option<(u32, u32, String)> = None;
        let mut blend_constant: Option<[f64; 4]> = None;
        for (n, t) in r.targets.iter().enumerate() {
            let ri = index(&t.texture.resource);
            let name = &t.texture.resource;
            let vista_gpu::Resource::Texture(desc) = &resources[ri] else { unreachable!("resolve checks targets") };
            let level = t.texture.level.unwrap_or(0);
            let layer = t.layer.unwrap_or(0);
            if layer >= desc.layers {
                return Err(self.bad(format!(
                    "{label}: targets[{n}] {name}@layer{layer}: {name} has {} layers; allowed: {name}@layer0 .. {name}@layer{}",
                    desc.layers,
                    desc.layers - 1
                )));
            }
            let format = vista_texel::Format::parse(desc.format).map_err(|m| self.bad(m))?;
            if !format.is_renderable() {
                return Err(self.bad(format!(
                    "{label}: targets[{n}] {name} is {}, which WebGPU cannot render to; give it another format",
                    desc.format
                )));
            }
            // 32-bit floats blend where the backend has float32-blendable
            // (the engine reports the case unsupported where not).
            let blend = t.blend;
            if blend != vista_texel::Blend::Replace && format.sample_kind() != vista_texel::SampleKind::Float {
                return Err(self.bad(format!(
                    "{label}: targets[{n}] {name} is {}, an integer format, which does not blend; use blend = \"replace\"",
                    desc.format
                )));
            }
            if let (Some(c), Some(prev)) = (t.constant, blend_constant)
                && c != prev
            {
                return Err(self.bad(format!(
                    "{label}: targets[{n}] has blend constant {c:?} but an earlier target {prev:?}; a pass has one"
                )));
            }
            blend_constant = blend_constant.or(t.constant);
            let (w, h) = ((desc.width >> level).max(1), (desc.height >> level).max(1));
            match &size {
                Some((w0, h0, first)) if (*w0, *h0) != (w, h) => {
                    return Err(self.bad(format!(
                        "{label}: targets[{n}] {name} is {w}x{h} but {first} is {w0}x{h0}; a pass's targets share one size"
                    )));
                }
                Some(_) => {}
                None => size = Some((w, h, name.clone())),
            }
            // A draw leaves uncovered texels at the clear value: zeros on a
            // texture no earlier pass wrote, so they are not "unwritten".
            // (On its first run: a repeated draw accumulates after it.)
            let draw = r.vertex != VertexStage::Fullscreen;
            let implicit = t.clear.is_none() && draw && !self.written_before(i, ri, resolved);
            let clear = if implicit { Some([0.0; 4]) } else { t.clear };
            targets.push(vista_gpu::RasterTarget { resource: ri, level, layer, clear, clear_once: implicit, blend });
        }
        if let (Some(name), Some((w, h, first))) = (r.depth.as_ref().and_then(|d| d.resource.as_ref()), &size)
            && let vista_gpu::Resource::Depth([dw, dh], _) = &resources[index(name)]
            && (dw, dh) != (w, h)
        {
            return Err(self.bad(format!(
                "{label}: depth resource {name} is {dw}x{dh} but {first} is {w}x{h}; a pass's depth and targets share one size"
            )));
        }
        let vertex = r.vertex.entry().map(str::to_string);
        let draw = resolved.draws[i].as_ref();
        let buffers: Vec<vista_gpu::VertexBuffer> = draw
            .map(|d| {
                d.buffers
                    .iter()
                    .map(|(ri, l)| vista_gpu::VertexBuffer {
                        resource: *ri,
                        stride: l.stride,
                        instance: l.instance,
                        attributes: l
                            .attributes
                            .iter()
                            .map(|a| (a.location, a.format.name.to_string(), a.offset))
                            .collect(),
                    })
                    .collect()
            })
            .unwrap_or_default();
        let indices = draw.and_then(|d| d.indices);
        let index_u16 = draw.is_some_and(|d| d.index_u16);
        let d = self.draw_counts(r, label, resources, &buffers, indices.map(|i| (i, index_u16)), pp)?;
        // The pass's own depth buffer is one more depth resource of its
        // targets' size: the engines draw every depth test one way, and
        // make it once per run, not once per draw.
        let depth = match &r.depth {
            None => None,
            Some(d) => {
                let resource = match &d.resource {
                    Some(name) => index(name),
                    None => {
                        let (w, h, _) = size.clone().expect("a render pass has targets");
                        resources.push(vista_gpu::Resource::Depth([w, h], Vec::new()));
                        resources.len() - 1
                    }
                };
                Some(vista_gpu::Depth { resource, compare: d.compare.to_string(), write: d.write, clear: d.clear })
            }
        };
        Ok(vista_gpu::Raster {
            targets,
            vertex,
            vertex_shader: None,
            vertex_constants: Vec::new(),
            buffers,
            indices,
            index_u16,
            count: d.count,
            instances: d.instances,
            first_vertex: d.first_vertex,
            first_instance: d.first_instance,
            base_vertex: d.base_vertex,
            topology: r.topology,
            cull: r.cull,
            depth,
            blend_constant,
        })
    }

    /// Whether a pass before pass `i` writes resource `ri` (a storage
    /// texture written, or a render target).
    fn written_before(&self, i: usize, ri: usize, resolved: &vista_manifest::graph::Resolved) -> bool {
        let g = self.kernel.graph();
        (0..i).any(|j| {
            let stored = resolved.slots[j].iter().any(|s| {
                matches!(&s.feed, SlotFeed::Resource(r, Usage::StorageTexture(st))
                    if *r == ri && st.access != vista_texel::Access::Read)
            });
            let drawn = g.passes[j]
                .raster
                .as_ref()
                .is_some_and(|r| r.targets.iter().any(|t| resolved.resources[ri].spec.name == t.texture.resource));
            stored || drawn
        })
    }

    /// A draw's vertex (or index) count and instance count: as written, else
    /// every index, every vertex of the per-vertex buffers, every element
    /// of the per-instance ones; never more than the buffers hold.
    fn draw_counts(
        &self,
        r: &vista_manifest::graph::RasterSpec,
        label: &str,
        resources: &[vista_gpu::Resource],
        buffers: &[vista_gpu::VertexBuffer],
        indices: Option<(usize, bool)>,
        pp: &ParamSet,
    ) -> Result<Draw, RenderError> {
        if r.vertex == vista_manifest::graph::VertexStage::Fullscreen {
            return Ok(Draw { count: 3, instances: 1, ..Draw::default() });
        }
        let len = |ri: usize| match &resources[ri] {
            vista_gpu::Resource::Buffer(b) => b.len() as u64,
            _ => 0,
        };
        let held = |instance: bool| {
            buffers
                .iter()
                .filter(|b| b.instance == instance)
                .map(|b| (len(b.resource) / b.stride.max(1) as u64, b.resource))
                .min()
        };
        // Counts in [1, 2^26], offsets in [0, 2^26] (base_vertex: +-2^26).
        let ranged = |k: &str, e: &vista_manifest::expr::Expr, lo: i64| -> Result<i64, RenderError> {
            let n = e.eval(pp, self.width, self.height).map_err(|m| self.bad(format!("{label}: {k} {m}")))?;
            (lo..=1 << 26)
                .contains(&n)
                .then_some(n)
                .ok_or_else(|| self.bad(format!("{label}: {k} is {n}; allowed: [{lo}, 67108864]")))
        };
        let eval = |k: &str, e: &vista_manifest::expr::Expr| ranged(k, e, 1).map(|n| n as u32);
        let offset = |k: &str, e: &Option<vista_manifest::expr::Expr>, lo: i64| -> Result<i64, RenderError> {
            e.as_ref().map_or(Ok(0), |e| ranged(k, e, lo))
        };
        let first_vertex = offset("first_vertex", &r.first_vertex, 0)? as u32;
        let first_instance = offset("first_instance", &r.first_instance, 0)? as u32;
        let base_vertex = offset("base_vertex", &r.base_vertex, -(1 << 26))? as i32;
        let name = |ri: usize| self.kernel.graph().resources.get(ri).map_or("?".to_string(), |x| x.name.clone());
        let (available, what) = match (indices, held(false)) {
            (Some((ix, u16)), _) => (Some(len(ix) / if u16 { 2 } else { 4 }), format!("indices {}", name(ix))),
            (None, Some((n, ri))) => (Some(n), format!("vertices {}", name(ri))),
            (None, None) => (None, String::new()),
        };
        // Without indices the draw starts at first_vertex: by default it
        // takes the vertices from there on.
        let skipped = if indices.is_some() { 0 } else { u64::from(first_vertex) };
        let count = match (&r.count, available) {
            (Some(e), _) => eval("count", e)?,
            (None, Some(n)) => n.saturating_sub(skipped).min(u32::MAX as u64) as u32,
            (None, None) => {
                return Err(self.bad(format!(
                    "{label}: no vertex buffer or index buffer says how many vertices to draw; give count = N"
                )));
            }
        };
        if let Some(n) = available
            && skipped + count as u64 > n
        {
            return Err(self.bad(match skipped {
                0 => format!("{label}: count = {count} but {what} holds {n}"),
                s => format!(
                    "{label}: first_vertex = {s} and count = {count} reach vertex {} but {what} holds {n}",
                    s + count as u64 - 1
                ),
            }));
        }
        // Indices the host gives (a file or data) must name vertices the
        // per-vertex buffers hold: WebGPU leaves an index past them to the
        // driver (robust access reads zeros, or not). A strip's restart
        // value is not an index.
        if let (Some((ix, u16)), Some((vertices, vr))) = (indices, held(false))
            && let Some(ResourceKind::Buffer { file, data, .. }) =
                self.kernel.graph().resources.get(ix).map(|x| &x.kind)
            && (file.is_some() || data.is_some())
            && let vista_gpu::Resource::Buffer(bytes) = &resources[ix]
        {
            let strip = matches!(r.topology, vista_texel::Topology::TriangleStrip | vista_texel::Topology::LineStrip);
            let restart = if u16 { 0xFFFF } else { 0xFFFF_FFFF };
            let size = if u16 { 2 } else { 4 };
            let values = bytes.chunks_exact(size).take(count as usize).map(|c| match u16 {
                true => u64::from(u16::from_le_bytes([c[0], c[1]])),
                false => u64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]])),
            });
            // Each index plus base_vertex names the vertex fetched.
            let fetched = |v: u64| v as i64 + i64::from(base_vertex);
            if let Some((at, v)) = values
                .enumerate()
                .find(|&(_, v)| !((0..vertices as i64).contains(&fetched(v)) || strip && v == restart))
            {
                let with = if base_vertex == 0 { String::new() } else { format!(" + base_vertex {base_vertex}") };
                return Err(self.bad(format!(
                    "{label}: index {v}{with} (number {at} of indices {}) is past the {vertices} vertices {} holds; \
                     allowed: [0, {}]",
                    name(ix),
                    name(vr),
                    vertices - 1
                )));
            }
        }
        let per_instance = held(true);
        let first = u64::from(first_instance);
        let instances = match (&r.instances, per_instance) {
            (Some(e), _) => eval("instances", e)?,
            (None, Some((n, _))) => n.saturating_sub(first).min(u32::MAX as u64) as u32,
            (None, None) => 1,
        };
        if let Some((n, ri)) = per_instance
            && first + instances as u64 > n
        {
            return Err(self.bad(match first {
                0 => format!("{label}: instances = {instances} but vertices {} holds {n}", name(ri)),
                f => format!(
                    "{label}: first_instance = {f} and instances = {instances} reach instance {} but vertices {} holds {n}",
                    f + instances as u64 - 1,
                    name(ri)
                ),
            }));
        }
        if count == 0 || instances == 0 {
            return Err(self.bad(format!("{label}: the draw has no vertices (count {count}, instances {instances})")));
        }
        Ok(Draw { count, instances, first_vertex, first_instance, base_vertex })
    }

    /// The outputs as planned, and the resource each reads.
    fn outputs(
        &self,
        resources: &[vista_gpu::Resource],
        resolved: &vista_manifest::graph::Resolved,
    ) -> Result<(Vec<PlannedOutput>, Vec<vista_gpu::OutputRef>), RenderError> {
        let (kernel, p) = (self.kernel, self.p);
        let g = kernel.graph();
        let mut outputs = Vec::new();
        let mut ids = Vec::new();
        for (i, &r) in resolved.outputs.iter().enumerate() {
            // The i-th [[output]] table (a lone one may leave `resource` out).
            let spec = g.outputs.get(i);
            let (level, layer) = resolved.output_views.get(i).copied().unwrap_or((0, None));
            let id = vista_gpu::OutputRef { resource: r, level, layer };
            // A level or layer is named as the manifest writes it ("bloom@3").
            let name = match (level, layer) {
                (0, None) => resolved.resources[r].spec.name.clone(),
                _ => spec.and_then(|o| o.resource.clone()).unwrap_or_default(),
            };
            if let (Some(l), Some(t)) = (layer, resources[r].read_as())
                && l >= t.layers
            {
                return Err(self.bad(format!(
                    "[[output]] resource = \"{name}\": {} has {} layers; allowed: @layer0 .. @layer{}",
                    resolved.resources[r].spec.name,
                    t.layers,
                    t.layers - 1
                )));
            }
            ids.push(id);
            let kind = match &resources[r] {
                vista_gpu::Resource::Texture(_) | vista_gpu::Resource::Depth(..) => {
                    // A depth output reads back as r32float.
                    let t = id.texture(&resources[r]).expect("a texture");
                    let view = spec.and_then(|o| o.view).unwrap_or_else(|| kernel.default_view(t.format));
                    let display = kernel.display_map_with(p, view, t.format, spec.and_then(|o| o.exposure));
                    PlannedKind::Texture { format: t.format, view, display }
                }
                vista_gpu::Resource::Buffer(b) => {
                    let e = resolved.resources[r].element.clone().expect("a bound buffer");
                    let count = (b.len() as u64 - e.header as u64) / e.stride.max(1) as u64;
                    PlannedKind::Buffer { element: e, count }
                }
                vista_gpu::Resource::Sampler(_) => unreachable!("resolve refuses a sampler output"),
            };
            outputs.push(PlannedOutput {
                name,
                tolerance: spec.and_then(|o| o.tolerance),
                partial: spec.is_some_and(|o| o.partial),
                kind,
            });
        }
        Ok((outputs, ids))
    }
}

/// A texture file under the project root: its natural format (8-bit PNG:
/// rgba8unorm; 16-bit PNG and EXR: rgba32float) and its values.
fn read_texture(root: Option<&Path>, file: &str, max_bytes: u64) -> Result<(&'static str, Image), String> {
    let path = under(root, file)?;
    let bytes = read_input(root, file, &path)?;
    // A small PNG may decode to a huge image: its header says how large,
    // before any decoding (4 f32 per texel).
    if bytes.starts_with(b"\x89PNG") && bytes.len() >= 24 {
        let [w, h] = [16, 20].map(|o| u128::from(u32::from_be_bytes(bytes[o..o + 4].try_into().expect("4 bytes"))));
        // In u128: 2^32 x 2^32 x 16 does not fit in u64.
        let decoded = w * h * 16;
        if decoded > u128::from(max_bytes) {
            return Err(format!(
                "file {file} is a {w}x{h} PNG: {decoded} bytes decoded, above the memory budget of {max_bytes} \
                 bytes; make it smaller, or raise VISTA_MAX_BYTES"
            ));
        }
    }
    if file.ends_with(".exr") {
        let image = vista_image::read_exr(&path).map_err(|e| format!("file {file}: {e}"))?;
        return Ok(("rgba32float", image));
    }
    // PNG: bit depth is byte 24 of the IHDR chunk.
    if !bytes.starts_with(b"\x89PNG") || bytes.len() < 25 {
        return Err(format!("file {file} is not a PNG"));
    }
    let image = vista_image::decode_png16(&path, &bytes).map_err(|e| format!("file {file}: {e}"))?;
    Ok((if bytes[24] == 16 { "rgba32float" } else { "rgba8unorm" }, image))
}

/// A texture from a `.npy` (SPEC 17: integer textures from raw data): an
/// (H, W) or (H, W, C) array whose dtype and C are the format's channels
/// (layers stacked along H), its bytes the texels unchanged; the format is
/// the resource's, else the first whose channels the dtype matches.
fn read_texture_npy(
    root: Option<&Path>,
    file: &str,
    declared: Option<&'static str>,
) -> Result<(&'static str, [u32; 2], Vec<u8>), String> {
    let path = under(root, file)?;
    let bytes = read_input(root, file, &path)?;
    let n = vista_image::npy::decode_npy(&path, &bytes).map_err(|e| format!("file {file}: {e}"))?;
    let (h, w, c) = match n.shape[..] {
        [h, w] => (h, w, 1),
        [h, w, c] => (h, w, c as usize),
        _ => return Err(format!("file {file} has shape {:?}; a texture is (H, W) or (H, W, channels)", n.shape)),
    };
    let format = match declared {
        Some(name) => vista_texel::Format::parse(name)?,
        None => vista_texel::Format::of_numpy(&n.descr, c).ok_or_else(|| {
            format!("file {file} holds {} x {c}, which no texture format stores; give the resource a format", n.descr)
        })?,
    };
    let (dtype, channels) = format.numpy();
    if !format.holds_numpy(&n.descr, c) {
        return Err(format!(
            "file {file} holds {} x {c} per texel but {} needs {dtype} x {channels} (shape (H, W{}))",
            n.descr,
            format.name,
            if channels == 1 { String::new() } else { format!(", {channels}") }
        ));
    }
    let (w, h) = (u32::try_from(w).ok().filter(|w| (1..=16384).contains(w)), u32::try_from(h).ok().filter(|h| *h >= 1));
    let (Some(w), Some(h)) = (w, h) else { return Err(format!("file {file}: shape {:?} is out of range", n.shape)) };
    if !format.is_integer()
        && let Some(i) = (0..(w * h) as usize).find(|i| {
            let b = format.texel_bytes();
            format.decode(&n.data[i * b..(i + 1) * b]).iter().any(|v| !v.is_finite())
        })
    {
        return Err(format!("file {file} holds NaN/Inf at texel {i}; inputs must be finite"));
    }
    Ok((format.name, [w, h], n.data))
}

/// A texture file's extent: the `size` given (which the file, its layers
/// stacked top to bottom, must match), else a cube's six stacked faces
/// (W x 6W), else the file's own width and height.
fn file_extent(file: &str, [fw, fh]: [u32; 2], size: Option<[u32; 3]>, cube: bool) -> Result<[u32; 3], String> {
    match size {
        Some(e) if fw != e[0] || fh != e[1] * e[2] => Err(format!(
            "file {file} is {fw}x{fh} but size says {}x{}{}",
            e[0],
            e[1],
            if e[2] > 1 { format!(" x {} layers stacked ({}x{})", e[2], e[0], e[1] * e[2]) } else { String::new() }
        )),
        Some(e) => Ok(e),
        None if cube && fh != 6 * fw => {
            Err(format!("file {file} is {fw}x{fh}; a cube's six square faces stack to W x 6W (or give size = [W])"))
        }
        None if cube => Ok([fw, fw, 6]),
        None => Ok([fw, fh, 1]),
    }
}

fn under(root: Option<&Path>, file: &str) -> Result<PathBuf, String> {
    let root = root.ok_or_else(|| format!("file {file} needs a project root (vista.toml) to be found under"))?;
    Ok(root.join(file))
}

/// A leaf's path as a user writes it: `lights[0].color` for the element
/// path `lights.0.color.x` (a vector's or matrix's components are one leaf).
fn user_path(p: &str) -> String {
    let component = |s: &str| {
        matches!(s, "x" | "y" | "z" | "w")
            || (s.len() == 4 && s.starts_with('c') && s.as_bytes()[2] == b'r' && s[1..2].parse::<u8>().is_ok())
    };
    let parts: Vec<&str> = p.split('.').collect();
    let keep = match parts.last() {
        Some(last) if parts.len() > 1 && component(last) => &parts[..parts.len() - 1],
        _ => &parts[..],
    };
    let mut out = String::new();
    for part in keep {
        match part.parse::<u32>() {
            Ok(i) => out.push_str(&format!("[{i}]")),
            Err(_) if out.is_empty() => out.push_str(part),
            Err(_) => out.push_str(&format!(".{part}")),
        }
    }
    out
}

/// An input file's bytes: a regular file inside the project after
/// symlinks, at most [`vista_project::guard::MAX_DATA_BYTES`].
fn read_input(root: Option<&Path>, file: &str, path: &Path) -> Result<Vec<u8>, String> {
    let root = root.ok_or_else(|| format!("file {file} needs a project root (vista.toml) to be found under"))?;
    vista_project::guard::read_bytes(root, path, vista_project::guard::MAX_DATA_BYTES)
        .map_err(|e| format!("file {file} cannot be read: {e}"))
}

/// A buffer file: `.npy` (dtype checked against the element) or `.bin`
/// (raw little-endian bytes, a whole number of elements).
fn read_buffer(root: Option<&Path>, file: &str, e: &Element) -> Result<Vec<u8>, String> {
    let path = under(root, file)?;
    let bytes = read_input(root, file, &path)?;
    let data = match file.ends_with(".npy") {
        true => {
            let n = vista_image::npy::decode_npy(&path, &bytes).map_err(|err| format!("file {file}: {err}"))?;
            let (descr, _) = npy_dtype(e);
            let scalar_of = |d: &str| d.chars().nth(1);
            let leaf_kind = e.leaves.first().map(|l| l.1).unwrap_or('u');
            let (numpy_kind, size) = leaf_numpy(leaf_kind);
            let simple_ok = !n.descr.starts_with('[')
                && scalar_of(&n.descr) == Some(numpy_kind)
                && n.descr.ends_with(&size.to_string())
                && e.leaves.iter().all(|l| l.1 == leaf_kind);
            if !(simple_ok || (n.descr.starts_with('[') && n.item_bytes == e.stride as u64)) {
                return Err(format!(
                    "file {file} has dtype {} but {} needs {descr} (or a structured dtype of its members, {} \
                     bytes per element)",
                    n.descr, e.wgsl, e.stride
                ));
            }
            // A structured dtype's fields are the struct's members, by name.
            if n.descr.starts_with('[') {
                crate::dtype::check_structured(file, &n.descr, e)?;
            }
            n.data
        }
        false => bytes,
    };
    // A simple dtype of a padded element (vec3 at 16-byte stride) is packed:
    // spread it over the stride.
    let packed: u32 = e.leaves.iter().map(|l| leaf_numpy(l.1).1).sum();
    let data = if packed != e.stride
        && data.len().is_multiple_of(packed as usize)
        && !data.len().is_multiple_of(e.stride as usize)
    {
        let mut out = Vec::new();
        for chunk in data.chunks(packed as usize) {
            let mut el = vec![0u8; e.stride as usize];
            let mut at = 0;
            for leaf in &e.leaves {
                let size = leaf_numpy(leaf.1).1 as usize;
                el[leaf.0 as usize..leaf.0 as usize + size].copy_from_slice(&chunk[at..at + size]);
                at += size;
            }
            out.extend(el);
        }
        out
    } else {
        data
    };
    if data.is_empty() || !data.len().is_multiple_of(e.stride as usize) {
        return Err(format!(
            "file {file} holds {} bytes, not a whole number of {}-byte elements of {}",
            data.len(),
            e.stride,
            e.wgsl
        ));
    }
    if let Some((i, v)) = leaf_values(&data, e).iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(format!("file {file} holds {v} at value {i}; inputs must be finite"));
    }
    Ok(data)
}

/// One leaf's bytes: an f32, or a u32/i32/u16 that holds `v` exactly.
fn encode_leaf(kind: char, v: f64) -> Option<Vec<u8>> {
    let whole = v.fract() == 0.0;
    Some(match kind {
        'f' => (v as f32).to_le_bytes().to_vec(),
        'u' if whole && v >= 0.0 && v <= u32::MAX as f64 => (v as u32).to_le_bytes().to_vec(),
        'i' if whole && v >= i32::MIN as f64 && v <= i32::MAX as f64 => (v as i32).to_le_bytes().to_vec(),
        'h' if whole && v >= 0.0 && v <= u16::MAX as f64 => (v as u16).to_le_bytes().to_vec(),
        _ => return None,
    })
}

/// A leaf kind as NumPy names it with its width: `f32`, `u16`.
fn leaf_type(kind: char) -> String {
    let (k, bytes) = leaf_numpy(kind);
    format!("{k}{}", bytes * 8)
}

/// Numbers converted to the element's leaves in order (a whole number of
/// elements).
fn encode_values(values: &[f64], e: &Element) -> Result<Vec<u8>, String> {
    let per = e.leaves.len();
    if per == 0 || values.is_empty() || !values.len().is_multiple_of(per) {
        return Err(format!(
            "{} numbers are not a whole number of elements of {} ({per} numbers each)",
            values.len(),
            e.wgsl
        ));
    }
    let mut out = Vec::new();
    for chunk in values.chunks(per) {
        let mut el = vec![0u8; e.stride as usize];
        for ((offset, kind, path), v) in e.leaves.iter().zip(chunk) {
            let Some(word) = encode_leaf(*kind, *v) else {
                let ty = leaf_type(*kind);
                return Err(match path.is_empty() {
                    true => format!("{v} does not fit {} ({ty})", e.wgsl),
                    false => format!("{v} does not fit {path} ({ty}) of {}", e.wgsl),
                });
            };
            el[*offset as usize..*offset as usize + word.len()].copy_from_slice(&word);
        }
        out.extend(el);
    }
    Ok(out)
}

/// Every leaf value of every element, as f64, in order.
pub fn leaf_values(bytes: &[u8], e: &Element) -> Vec<f64> {
    let mut out = Vec::new();
    for el in bytes.chunks_exact(e.stride.max(1) as usize) {
        for (offset, kind, _) in &e.leaves {
            let b = &el[*offset as usize..];
            if *kind == 'h' {
                out.push(u16::from_le_bytes([b[0], b[1]]) as f64);
                continue;
            }
            let w = [b[0], b[1], b[2], b[3]];
            out.push(match kind {
                'f' => f32::from_le_bytes(w) as f64,
                'u' => u32::from_le_bytes(w) as f64,
                _ => i32::from_le_bytes(w) as f64,
            });
        }
    }
    out
}

/// The NumPy dtype of an element and the shape of one element: a simple
/// dtype when its leaves are one scalar kind packed without padding
/// (`<u4` shape `()`, `<f4` shape `(4,)`), else a structured dtype with
/// padding as void fields.
pub fn npy_dtype(e: &Element) -> (String, Vec<u64>) {
    let kind = e.leaves.first().map(|l| l.1).unwrap_or('u');
    let (numpy, size) = leaf_numpy(kind);
    let packed = e.leaves.iter().enumerate().all(|(i, l)| l.0 == size * i as u32 && l.1 == kind);
    if packed && e.stride == size * e.leaves.len() as u32 {
        let tail = if e.leaves.len() == 1 { vec![] } else { vec![e.leaves.len() as u64] };
        return (format!("<{numpy}{size}"), tail);
    }
    let mut fields = Vec::new();
    let mut at = 0;
    for (offset, kind, path) in &e.leaves {
        if *offset > at {
            fields.push(format!("('_pad{at}', '|V{}')", offset - at));
        }
        let name = if path.is_empty() { "value".to_string() } else { path.clone() };
        let (numpy, size) = leaf_numpy(*kind);
        fields.push(format!("('{name}', '<{numpy}{size}')"));
        at = offset + size;
    }
    if e.stride > at {
        fields.push(format!("('_pad{at}', '|V{}')", e.stride - at));
    }
    (format!("[{}]", fields.join(", ")), vec![])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// PNG, EXR and .npy files take one rule for their extent.
    #[test]
    fn a_files_extent_is_its_size_its_cube_or_its_own() {
        assert_eq!(file_extent("a.npy", [4, 24], None, true), Ok([4, 4, 6]));
        assert_eq!(file_extent("a.npy", [4, 24], None, false), Ok([4, 24, 1]));
        assert_eq!(file_extent("a.npy", [4, 12], Some([4, 4, 3]), false), Ok([4, 4, 3]));
        let e = file_extent("a.npy", [4, 20], None, true).unwrap_err();
        assert!(e.contains("file a.npy is 4x20; a cube's six square faces stack to W x 6W"), "{e}");
        let e = file_extent("a.png", [4, 12], Some([4, 4, 2]), false).unwrap_err();
        assert_eq!(e, "file a.png is 4x12 but size says 4x4 x 2 layers stacked (4x8)");
        let e = file_extent("a.png", [8, 8], Some([4, 4, 1]), false).unwrap_err();
        assert_eq!(e, "file a.png is 8x8 but size says 4x4");
    }

    #[test]
    fn u16_indices_are_two_byte_leaves() {
        let e =
            Element { stride: 2, header: 0, fixed: None, leaves: vec![(0, 'h', String::new())], wgsl: "u16".into() };
        let bytes = encode_values(&[0.0, 65535.0, 7.0], &e).unwrap();
        assert_eq!(bytes, [0, 0, 255, 255, 7, 0]);
        assert_eq!(leaf_values(&bytes, &e), [0.0, 65535.0, 7.0]);
        assert_eq!(npy_dtype(&e), ("<u2".to_string(), vec![]));
        assert_eq!(encode_values(&[65536.0], &e).unwrap_err(), "65536 does not fit u16 (u16)");
        let u32s =
            Element { stride: 4, header: 0, fixed: None, leaves: vec![(0, 'u', String::new())], wgsl: "u32".into() };
        assert_eq!(npy_dtype(&u32s).0, "<u4");
    }
}
