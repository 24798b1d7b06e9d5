//! SPEC 14's pass graphs: `[[resource]]` textures, buffers and samplers
//! (with their files, inline data, fill and length), `[[pass]]` tables
//! (entry, shader, bind, dispatch or workgroups, set, repeat, swap) and
//! `[[output]]` tables (any texture or buffer a pass writes, with a view,
//! `partial` and a tolerance). Every manifest is a graph: one without these
//! tables is one pass (`main`) whose written storage texture is its one
//! output (SPEC 14: "for today's kernels that equals section 10").
//!
//! Parsing checks everything that needs no shader; [`resolve`] then checks
//! each pass against naga's reflection of its composed module and says what
//! feeds every binding.

use crate::bindings::Storage;
use crate::bindings::{Binding, Feed};
use crate::expr::Expr;
use crate::params::ParamSpec;
use crate::{Output, ParamError};
use vista_texel::{Access, Blend, Cull, Dimension, Topology};

pub use crate::bindings::SampledKind;
pub use crate::element::Element;
pub use crate::vertex::{Attribute, VertexBufferSpec, VertexLayout};

/// The sampler address modes a manifest may name.
pub const ADDRESS_MODES: [&str; 3] = ["clamp-to-edge", "repeat", "mirror-repeat"];
/// The comparison functions a comparison sampler may name (WebGPU's).
pub const COMPARE_FUNCTIONS: [&str; 8] =
    ["never", "less", "equal", "less-equal", "greater", "not-equal", "greater-equal", "always"];

/// What a resource is.
#[derive(Debug, Clone, PartialEq)]
pub enum ResourceKind {
    /// A texture (`kind = "texture"`): written as a storage texture, sampled, or both.
    Texture {
        /// Its storage format (one of [`vista_texel::format_names`]); `None`:
        /// a storage binding's, else its file's.
        format: Option<&'static str>,
        /// 1d | 2d | 2d-array | 3d (storage and sampled) or cube (sampled).
        dimension: Option<Dimension>,
        /// Its size as expressions of the params and the case size: one entry for
        /// 1d or a cube (the face edge), two for 2d, three for 2d-array and 3d;
        /// `None`: its file's size, else the case's.
        size: Option<Vec<Expr>>,
        /// A `.png` or `.exr` file under the project root holding its contents.
        file: Option<String>,
        /// Mip levels (`mip_levels`, default 1): a `bind` or `dispatch` names
        /// one as `name@level`; a file or the sentinel fills level 0.
        mip_levels: u32,
    },
    /// A storage or uniform buffer (`kind = "buffer"`).
    Buffer {
        /// A `.npy` or `.bin` file under the project root holding its contents.
        file: Option<String>,
        /// Inline contents, one number per scalar (nested lists flattened, booleans as 0 or 1).
        data: Option<Vec<f64>>,
        /// The value every scalar starts at (`file`, `data` and `fill` are exclusive).
        fill: Option<f64>,
        /// Its element count as an expression of the params and the case size, with
        /// `fill` or alone (a runtime-sized array needs one).
        length: Option<Expr>,
        /// Values by field path (`world_position`, `lights.1.color`) for a
        /// binding of one struct; every leaf not named is zero.
        fields: Option<Vec<(String, Vec<f64>)>>,
    },
    /// A depth texture (`kind = "depth"`, depth32float): a render pass's
    /// `depth` attachment that later passes sample as `texture_depth_2d`.
    Depth {
        /// `[w, h]` as expressions; `None`: the file's size, else the case size.
        size: Option<Vec<Expr>>,
        /// Its first values (`file = "inputs/depth.npy"`: f32 (H, W), or
        /// an EXR's red channel), in [0, 1]; `None`: cleared by the pass
        /// that tests against it.
        file: Option<String>,
    },
    /// A sampler (`kind = "sampler"`).
    Sampler {
        /// `filter = "linear"`; false: nearest.
        linear: bool,
        /// The address mode per axis (u, v, w), each one of [`ADDRESS_MODES`] (default clamp-to-edge).
        address: [&'static str; 3],
        /// The comparison function (one of [`COMPARE_FUNCTIONS`]); `None`: a filtering sampler.
        compare: Option<&'static str>,
    },
}

/// One `[[resource]]` table.
#[derive(Debug, Clone, PartialEq)]
pub struct ResourceSpec {
    /// Its name, which `bind`, `dispatch`, `swap` and `[[output]]` refer to (a
    /// binding of the same variable name is bound to it).
    pub name: String,
    /// What it is, with the settings of its kind.
    pub kind: ResourceKind,
}

impl ResourceSpec {
    /// The manifest's `kind`: `texture`, `buffer`, `sampler` or `depth`.
    pub fn kind_name(&self) -> &'static str {
        match self.kind {
            ResourceKind::Texture { .. } => "texture",
            ResourceKind::Buffer { .. } => "buffer",
            ResourceKind::Sampler { .. } => "sampler",
            ResourceKind::Depth { .. } => "depth",
        }
    }
}

/// A resource a pass names, with one of its mip levels (`pyramid@3`);
/// `level: None` is the whole texture (or a buffer or sampler).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Level {
    /// The resource's name.
    pub resource: String,
    /// The mip level, below the texture's `mip_levels`.
    pub level: Option<u32>,
}

impl Level {
    /// Reads `name` or `name@level` against the resources; the error says
    /// what is allowed.
    fn parse(text: &str, res: &[ResourceSpec]) -> Result<Level, String> {
        let names = || names_of(res);
        let (name, level) = match text.split_once('@') {
            Some((n, l)) => (n, Some(l)),
            None => (text, None),
        };
        let Some(r) = res.iter().find(|r| r.name == name) else {
            return Err(format!("\"{text}\" names no resource; resources: {}", names()));
        };
        let Some(level) = level else { return Ok(Level { resource: name.to_string(), level: None }) };
        let levels = match r.kind {
            ResourceKind::Texture { mip_levels, .. } => mip_levels,
            _ => {
                return Err(format!(
                    "\"{text}\" names a level of {name}, a {}; only textures have levels",
                    r.kind_name()
                ));
            }
        };
        match level.parse::<u32>() {
            Ok(l) if l < levels => Ok(Level { resource: name.to_string(), level: Some(l) }),
            _ => Err(format!(
                "\"{text}\": {name} has {levels} mip level{}; allowed: {name}@0 .. {name}@{}{}",
                if levels == 1 { "" } else { "s" },
                levels - 1,
                if levels == 1 { " (give the resource mip_levels = N for more)" } else { "" }
            )),
        }
    }
}

/// How often a pass runs.
#[derive(Debug, Clone, PartialEq)]
pub enum Repeat {
    /// A fixed number of runs, in [1, 100000].
    Count(u32),
    /// The value of this integer param.
    Param(String),
}

/// One of a render pass's `targets`.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetSpec {
    /// The texture (and mip level) drawn into.
    pub texture: Level,
    /// The one layer of a 2d-array or cube texture drawn into (`"cube@layer3"`).
    pub layer: Option<u32>,
    /// `clear = [r, g, b, a]`: cleared before the draw; without, drawn
    /// over what the texture holds (texels a full-screen pass leaves keep
    /// the unwritten sentinel).
    pub clear: Option<[f64; 4]>,
    /// `blend`.
    pub blend: Blend,
    /// The blend table's `constant`, for the constant factors.
    pub constant: Option<[f64; 4]>,
}

/// A render pass's vertex stage.
#[derive(Debug, Clone, PartialEq)]
pub enum VertexStage {
    /// `vertex = "fullscreen"`: vista's full-screen triangle.
    Fullscreen,
    /// A `@vertex` entry of the pass's shader.
    Entry(String),
    /// `{ shader = "other.wgsl", entry = "vs" }`: an entry of another file,
    /// composed with the pass's defs and source keys; what both entries bind
    /// must agree, and params fill only the pass shader's uniforms.
    File {
        /// The kernel file (relative to `shaders/`), or an import module's
        /// (a file with its own `#define_import_path`).
        shader: String,
        /// The `@vertex` entry.
        entry: String,
        /// `source = { ... }`: `[source]` keys for this file, over the pass's.
        source: Box<vista_source::SourceSpec>,
    },
}

impl VertexStage {
    /// The vertex entry's name, if it is not vista's full-screen triangle.
    pub fn entry(&self) -> Option<&str> {
        match self {
            VertexStage::Fullscreen => None,
            VertexStage::Entry(e) | VertexStage::File { entry: e, .. } => Some(e),
        }
    }
}

/// A render pass's `depth` table: a depth32float buffer of the targets'
/// size, the pass's own or a depth resource.
#[derive(Debug, Clone, PartialEq)]
pub struct DepthSpec {
    /// A `kind = "depth"` resource later passes may sample; `None`: the
    /// pass's own buffer.
    pub resource: Option<String>,
    /// The comparison (one of [`COMPARE_FUNCTIONS`]).
    pub compare: &'static str,
    /// Whether passing fragments write their depth.
    pub write: bool,
    /// Cleared to this before the draw (default 1).
    pub clear: f64,
}

/// What makes a pass a render pass (`kind = "render"`, SPEC 17).
#[derive(Debug, Clone, PartialEq)]
pub struct RasterSpec {
    /// The vertex stage.
    pub vertex: VertexStage,
    /// `@location(n)` of the fragment entry goes to `targets[n]`.
    pub targets: Vec<TargetSpec>,
    /// The vertex buffers, one per slot.
    pub vertices: Vec<VertexBufferSpec>,
    /// The index buffer resource, and whether it holds u16 (else u32).
    pub indices: Option<(String, bool)>,
    /// Vertices (or indices) per instance; `None`: every one the buffer holds.
    pub count: Option<Expr>,
    /// Instances; `None`: the per-instance buffer's elements, else 1.
    pub instances: Option<Expr>,
    /// The draw's first vertex (`first_vertex`, a draw without indices).
    pub first_vertex: Option<Expr>,
    /// The draw's first instance (`first_instance`).
    pub first_instance: Option<Expr>,
    /// Added to every index (`base_vertex`, an indexed draw; may be negative).
    pub base_vertex: Option<Expr>,
    /// How vertices make primitives.
    pub topology: Topology,
    /// Which faces are discarded.
    pub cull: Cull,
    /// The pass's depth test.
    pub depth: Option<DepthSpec>,
}

/// The keys of a render pass's target table.
pub const TARGET_KEYS: [&str; 3] = ["resource", "clear", "blend"];
/// The keys of a target's blend table.
pub const BLEND_KEYS: [&str; 3] = ["color", "alpha", "constant"];
/// The keys of a render pass's depth table.
pub const DEPTH_KEYS: [&str; 4] = ["resource", "compare", "write", "clear"];
/// A render pass's keys beyond `kind`, `vertex`, `fragment` and `targets`.
const DRAW_KEYS: [&str; 9] =
    ["vertices", "indices", "count", "instances", "first_vertex", "first_instance", "base_vertex", "topology", "cull"];

/// One `[[pass]]` table.
#[derive(Debug, Clone, PartialEq)]
pub struct PassSpec {
    /// The compute entry point (default `main`), or a render pass's
    /// `fragment` entry.
    pub entry: String,
    /// A render pass's vertex stage and targets; `None`: a compute pass.
    pub raster: Option<RasterSpec>,
    /// Default: the manifest's shader.
    pub shader: Option<String>,
    /// Shader defs (`NAME=value`) merged over the kernel's `defs` for this
    /// pass: one composed module per distinct set (bevy's downsampler,
    /// `FIRST_PASS` for one pipeline and `SECOND_PASS` for the other).
    pub defs: Vec<String>,
    /// The pass's `source` keys (merged over the kernel's `[source]` by
    /// [`crate::Kernel::source_for`]).
    pub source: vista_source::SourceSpec,
    /// WGSL variable name -> resource (and mip level, `name@level`).
    pub bind: Vec<(String, Level)>,
    /// Cover this resource (at this mip level) with the reflected workgroup size.
    pub dispatch: Option<Level>,
    /// Explicit workgroup counts `[x, y, z]` as expressions of the params and the
    /// case size (exclusive with `dispatch`).
    pub workgroups: Option<[Expr; 3]>,
    /// Params overridden for this pass's uniforms: (param, value text).
    pub set: Vec<(String, String)>,
    /// How many times the pass runs (on a group's first pass: the whole group's runs).
    pub repeat: Repeat,
    /// Resource pairs exchanged after every run of the pass.
    pub swap: Vec<(String, String)>,
    /// Consecutive passes with one `group` run together, in order, the
    /// group's `repeat` times (given on its first pass).
    pub group: Option<String>,
}

impl PassSpec {
    /// The entry points the pass runs, each with its file (`own`: the
    /// manifest's shader): its compute or fragment entry, and a draw's
    /// vertex entry.
    pub fn entries<'a>(&'a self, own: &'a str) -> Vec<(&'a str, &'a str)> {
        let file = self.shader.as_deref().unwrap_or(own);
        let mut out = vec![(file, self.entry.as_str())];
        match &self.raster {
            Some(RasterSpec { vertex: VertexStage::Entry(vs), .. }) => out.push((file, vs)),
            Some(RasterSpec { vertex: VertexStage::File { shader, entry, .. }, .. }) => out.push((shader, entry)),
            _ => {}
        }
        out
    }

    /// The vertex entry's file when it is another file than the pass's.
    pub fn vertex_file(&self) -> Option<&str> {
        match &self.raster {
            Some(RasterSpec { vertex: VertexStage::File { shader, .. }, .. }) => Some(shader),
            _ => None,
        }
    }

    /// The `source` keys a separate vertex file takes over the pass's.
    pub fn vertex_source(&self) -> Option<&vista_source::SourceSpec> {
        match &self.raster {
            Some(RasterSpec { vertex: VertexStage::File { source, .. }, .. }) => Some(source),
            _ => None,
        }
    }
}

impl GraphSpec {
    /// How many passes, pass `i` first, run together (its group's length
    /// when `i` starts a group, 1 for a pass alone); 0 for a later pass of
    /// a group, which its first pass runs.
    pub fn span(&self, i: usize) -> usize {
        let Some(g) = self.passes[i].group.as_deref() else { return 1 };
        if i > 0 && self.passes[i - 1].group.as_deref() == Some(g) {
            return 0;
        }
        self.passes[i..].iter().take_while(|p| p.group.as_deref() == Some(g)).count()
    }
}

/// How an output is compared with its golden.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// Every value equal to the golden's, bit for bit.
    Exact,
    /// The largest absolute difference from the golden is at most this.
    MaxAbs(f64),
    /// The largest difference relative to the golden's magnitude is at most this.
    MaxRel(f64),
    /// The largest difference in f32 units in the last place is at most this (float outputs only).
    MaxUlp(u64),
    /// The root-mean-square difference from the golden is at most this.
    Rmse(f64),
    /// Each value within `max_ulp` f32 units in the last place or within
    /// `max_abs` of the golden's: the cross-driver allowance of a float
    /// buffer without a tolerance (not a manifest key).
    UlpOrAbs {
        /// Units in the last place.
        max_ulp: u64,
        /// Absolute difference, for values near zero.
        max_abs: f64,
    },
    /// Earth mover's distance between the value histograms (`bins` bins
    /// over the golden's range), in units of that range.
    HistogramEmd {
        /// The largest distance allowed (`histogram_emd`).
        max: f64,
        /// The number of bins (`bins`; default 64, in [2, 4096]).
        bins: u32,
    },
}

impl Tolerance {
    /// The keys a tolerance table may have.
    pub const KEYS: [&'static str; 7] = ["exact", "max_abs", "max_rel", "max_ulp", "rmse", "histogram_emd", "bins"];

    /// The tolerance in one phrase for messages, e.g. `max_abs 0.001`.
    pub fn describe(&self) -> String {
        match self {
            Tolerance::Exact => "exact".into(),
            Tolerance::MaxAbs(v) => format!("max_abs {v}"),
            Tolerance::MaxRel(v) => format!("max_rel {v}"),
            Tolerance::MaxUlp(v) => format!("max_ulp {v}"),
            Tolerance::Rmse(v) => format!("rmse {v}"),
            Tolerance::UlpOrAbs { max_ulp, max_abs } => {
                format!("max_ulp {max_ulp} or max_abs {max_abs:e} per value (the cross-driver default)")
            }
            Tolerance::HistogramEmd { max, bins } => format!("histogram_emd {max} over {bins} bins"),
        }
    }
}

/// One `[[output]]` table.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputSpec {
    /// The texture or buffer resource (one a pass writes) compared with its
    /// golden; `None` (a lone `[[output]]` without `resource`): the first
    /// texture a pass writes, as without `[[output]]` tables.
    pub resource: Option<String>,
    /// The PNG view of a texture (`view`; default: the manifest's `output`).
    pub view: Option<Output>,
    /// Whether texels no pass writes are allowed.
    pub partial: bool,
    /// How it is compared with its golden; `None`: `vista-golden`'s default (exact
    /// for a buffer or integer texture, PSNR of the view otherwise).
    pub tolerance: Option<Tolerance>,
    /// The hdr view's exposure (`exposure`; default 1, an `exposure` param wins).
    pub exposure: Option<f64>,
}

impl OutputSpec {
    /// `resource` split into the resource's name, its mip level and one
    /// layer: `"bloom@3"` is level 3 of bloom, `"cube@layer2"` layer 2 of
    /// cube, `"arr@1@layer0"` both (`None` without `resource`).
    pub fn target(&self) -> Option<(&str, u32, Option<u32>)> {
        split_target(self.resource.as_deref()?).ok()
    }
}

/// `name[@level][@layerN]` into its parts; the error says what is allowed.
fn split_target(text: &str) -> Result<(&str, u32, Option<u32>), String> {
    let (rest, layer) = match text.rsplit_once("@layer") {
        None => (text, None),
        Some((n, l)) => match l.parse::<u32>() {
            Ok(l) => (n, Some(l)),
            Err(_) => return Err(format!("\"{text}\": @layer needs a layer number, e.g. {n}@layer0")),
        },
    };
    match rest.split_once('@') {
        None => Ok((rest, 0, layer)),
        Some((n, level)) => match level.parse::<u32>() {
            Ok(level) => Ok((n, level, layer)),
            Err(_) => Err(format!("\"{text}\": a level is a number ({n}@2) and a layer @layerN ({n}@layer1)")),
        },
    }
}

/// A kernel's pass graph.
#[derive(Debug, Clone, PartialEq)]
pub struct GraphSpec {
    /// The `[[resource]]` tables, in manifest order.
    pub resources: Vec<ResourceSpec>,
    /// The `[[pass]]` tables in run order (one default pass when the manifest has none).
    pub passes: Vec<PassSpec>,
    /// The `[[output]]` tables; empty: the first texture a pass writes is the output.
    pub outputs: Vec<OutputSpec>,
    /// False: no render-twice check; every output needs a tolerance.
    pub deterministic: bool,
}

/// Resource keys by kind, for messages and the README's table.
pub const RESOURCE_KEYS: [&str; 13] = [
    "name",
    "kind",
    "format",
    "dimension",
    "size",
    "file",
    "mip_levels",
    "data",
    "fill",
    "length",
    "filter",
    "address",
    "compare",
];
/// The keys of a `[[pass]]` table.
pub const PASS_KEYS: [&str; 25] = [
    "kind",
    "entry",
    "vertex",
    "fragment",
    "targets",
    "vertices",
    "indices",
    "count",
    "instances",
    "first_vertex",
    "first_instance",
    "base_vertex",
    "topology",
    "cull",
    "depth",
    "shader",
    "defs",
    "source",
    "bind",
    "dispatch",
    "workgroups",
    "set",
    "repeat",
    "swap",
    "group",
];
/// The keys of an `[[output]]` table.
pub const OUTPUT_KEYS: [&str; 5] = ["resource", "view", "partial", "tolerance", "exposure"];

fn valid_name(name: &str) -> bool {
    !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// Parses a graph manifest's tables; `fail` prefixes file and kernel.
pub(crate) fn parse(
    resources: &[toml::Value],
    passes: &[toml::Value],
    outputs: &[toml::Value],
    deterministic: Option<bool>,
    default_view: Option<Output>,
    params: &[ParamSpec],
    fail: &dyn Fn(String) -> ParamError,
) -> Result<GraphSpec, ParamError> {
    let res = parse_resources(resources, params, fail)?;
    let out_passes = parse_passes(passes, &res, params, fail)?;
    let outs = parse_outputs(outputs, default_view, fail)?;
    // A level past the texture's mip count is refused here, by name.
    for o in outs.iter().filter(|o| o.resource.as_deref().is_some_and(|r| r.contains('@'))) {
        let text = o.resource.as_deref().unwrap_or_default();
        let (name, level, _) = split_target(text).map_err(|m| fail(format!("[[output]] resource = {m}")))?;
        let leveled = if level > 0 { format!("{name}@{level}") } else { name.to_string() };
        Level::parse(&leveled, &res).map_err(|m| fail(format!("[[output]] resource = {m}")))?;
    }
    if outs.iter().any(|o| o.view == Some(Output::Hdr))
        && params.iter().any(|p| p.name == "exposure" && p.ty != crate::params::ParamType::F32)
    {
        return Err(fail("param exposure sets the hdr view's tone map; it must be an f32".into()));
    }
    let deterministic = deterministic.unwrap_or(true);
    if !deterministic {
        if outs.is_empty() {
            return Err(fail("deterministic = false needs [[output]] tables, each with a tolerance".into()));
        }
        if let Some(o) = outs.iter().find(|o| o.tolerance.is_none()) {
            return Err(fail(format!(
                "[[output]] {}: deterministic = false needs a tolerance on every output ({})",
                o.resource.as_deref().unwrap_or("(the written texture)"),
                Tolerance::KEYS[1..6].join(", ")
            )));
        }
    }
    Ok(GraphSpec { resources: res, passes: out_passes, outputs: outs, deterministic })
}

/// The `[[resource]]` tables: each resource's kind and its kind's keys.
fn parse_resources(
    resources: &[toml::Value],
    params: &[ParamSpec],
    fail: &dyn Fn(String) -> ParamError,
) -> Result<Vec<ResourceSpec>, ParamError> {
    let mut res: Vec<ResourceSpec> = Vec::new();
    for t in resources {
        let Some(t) = t.as_table() else { return Err(fail("[[resource]] must be a table".into())) };
        let name = match t.get("name") {
            Some(toml::Value::String(s)) => s.clone(),
            _ => return Err(fail("[[resource]] needs name = \"...\"".into())),
        };
        if !valid_name(&name) {
            return Err(fail(format!("[[resource]] name \"{name}\" must use only letters, digits, '-' and '_'")));
        }
        if res.iter().any(|r| r.name == name) {
            return Err(fail(format!("[[resource]] name \"{name}\" is used twice")));
        }
        let at = |m: String| fail(format!("[[resource]] {name}: {m}"));
        let text = |k: &str| string_key(t, k, &at);
        let kind =
            text("kind")?.ok_or_else(|| at("needs kind = \"texture\", \"buffer\", \"sampler\" or \"depth\"".into()))?;
        let allowed: &[&str] = match kind.as_str() {
            "texture" => &["name", "kind", "format", "dimension", "size", "file", "mip_levels"],
            "buffer" => &["name", "kind", "file", "data", "fill", "length", "fields"],
            "sampler" => &["name", "kind", "filter", "address", "compare"],
            "depth" => &["name", "kind", "size", "file"],
            other => {
                return Err(at(format!("kind = \"{other}\" is not valid; expected texture|buffer|sampler|depth")));
            }
        };
        for k in t.keys() {
            if !allowed.contains(&k.as_str()) {
                return Err(at(format!("key {k} does not apply to a {kind}; allowed: {}", allowed.join(", "))));
            }
        }
        let file = text("file")?;
        if let Some(f) = &file
            && (f.starts_with('/') || f.split(['/', '\\']).any(|c| c == ".."))
        {
            return Err(at(format!("file = \"{f}\" must be a path under the project root (no '/' start, no '..')")));
        }
        let kind = match kind.as_str() {
            "texture" => texture_kind(t, file, params, &at)?,
            "buffer" => buffer_kind(t, file, params, &at)?,
            "depth" => {
                if let Some(f) = file.as_ref().filter(|f| !f.ends_with(".npy") && !f.ends_with(".exr")) {
                    return Err(at(format!(
                        "file = \"{f}\" is not valid for a depth texture; expected .npy (f32) or .exr"
                    )));
                }
                ResourceKind::Depth { size: depth_size(t, params, &at)?, file }
            }
            _ => sampler_kind(t, &at)?,
        };
        res.push(ResourceSpec { name, kind });
    }
    Ok(res)
}

/// A depth resource's `size = [w, h]`.
fn depth_size(
    t: &toml::Table,
    params: &[ParamSpec],
    at: &dyn Fn(String) -> ParamError,
) -> Result<Option<Vec<Expr>>, ParamError> {
    match t.get("size") {
        None => Ok(None),
        Some(toml::Value::Array(list)) if list.len() == 2 => {
            let e: Result<Vec<Expr>, _> = list.iter().map(|v| Expr::parse_entry(v, params)).collect();
            Ok(Some(e.map_err(|e| at(format!("size {e}")))?))
        }
        Some(other) => Err(at(format!("size = {other} is not valid; a depth texture takes [w, h]"))),
    }
}

/// A texture resource's keys: format, dimension, size (and its file).
fn texture_kind(
    t: &toml::Table,
    file: Option<String>,
    params: &[ParamSpec],
    at: &dyn Fn(String) -> ParamError,
) -> Result<ResourceKind, ParamError> {
    let format = match string_key(t, "format", at)? {
        None => None,
        Some(f) => Some(crate::bindings::storage_format(&f).map_err(at)?),
    };
    let dimension = match string_key(t, "dimension", at)? {
        None => None,
        Some(d) => Some(
            Dimension::parse(&d)
                .ok_or_else(|| at(format!("dimension = \"{d}\" is not valid; expected {}", Dimension::NAMES)))?,
        ),
    };
    if let Some(f) = &file
        && !(f.ends_with(".png") || f.ends_with(".exr") || f.ends_with(".npy"))
    {
        return Err(at(format!("file = \"{f}\" is not valid for a texture; expected a .png, .exr or .npy file")));
    }
    let size = match t.get("size") {
        None => None,
        Some(toml::Value::Array(list)) => {
            let want = dimension.unwrap_or(Dimension::D2).size_entries();
            if list.len() != want {
                return Err(at(format!("size has {} entries; this texture takes {want}", list.len())));
            }
            let mut exprs = Vec::new();
            for v in list {
                exprs.push(Expr::parse_entry(v, params).map_err(|e| at(format!("size {e}")))?);
            }
            Some(exprs)
        }
        Some(other) => return Err(at(format!("size = {other} is not valid; expected a list"))),
    };
    let mip_levels = match t.get("mip_levels") {
        None => 1,
        Some(toml::Value::Integer(n)) if (1..=15).contains(n) => *n as u32,
        Some(other) => return Err(at(format!("mip_levels = {other} is not valid; expected an integer in [1, 15]"))),
    };
    if mip_levels > 1 && dimension == Some(Dimension::D1) {
        return Err(at(format!("mip_levels = {mip_levels}: a 1d texture has one level (WebGPU)")));
    }
    Ok(ResourceKind::Texture { format, dimension, size, file, mip_levels })
}

/// `v`'s scalars in order, nested lists flattened.
fn flatten_numbers(v: &toml::Value, out: &mut Vec<toml::Value>) {
    match v {
        toml::Value::Array(l) => l.iter().for_each(|x| flatten_numbers(x, out)),
        other => out.push(other.clone()),
    }
}

/// A buffer resource's keys: its file, inline data, fields, or fill and length.
fn buffer_kind(
    t: &toml::Table,
    file: Option<String>,
    params: &[ParamSpec],
    at: &dyn Fn(String) -> ParamError,
) -> Result<ResourceKind, ParamError> {
    let number = |v: &toml::Value| match v {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(f) => Some(*f),
        toml::Value::Boolean(b) => Some(*b as u8 as f64),
        _ => None,
    };
    let data = match t.get("data") {
        None => None,
        Some(toml::Value::Array(list)) => {
            let mut out = Vec::new();
            let mut flat = Vec::new();
            list.iter().for_each(|v| flatten_numbers(v, &mut flat));
            for v in &flat {
                out.push(number(v).ok_or_else(|| at(format!("data entry {v} is not a number")))?);
            }
            Some(out)
        }
        Some(other) => return Err(at(format!("data = {other} is not valid; expected a list of numbers"))),
    };
    let fill = match t.get("fill") {
        None => None,
        Some(v) => Some(number(v).ok_or_else(|| at(format!("fill = {v} is not valid; expected a number")))?),
    };
    let length = match t.get("length") {
        None => None,
        Some(v) => Some(Expr::parse_entry(v, params).map_err(|e| at(format!("length {e}")))?),
    };
    if let Some(f) = &file
        && ![".npy", ".bin", ".toml", ".json"].iter().any(|e| f.ends_with(e))
    {
        return Err(at(format!(
            "file = \"{f}\" is not valid for a buffer; expected a .npy or .bin file, or .toml or .json leaf values"
        )));
    }
    let fields = match t.get("fields") {
        None => None,
        Some(toml::Value::Table(table)) => {
            let mut out = Vec::new();
            for (key, v) in table {
                let mut flat = Vec::new();
                flatten_numbers(v, &mut flat);
                let values: Option<Vec<f64>> = flat.iter().map(number).collect();
                match values {
                    Some(values) if !values.is_empty() => out.push((key.clone(), values)),
                    _ => {
                        return Err(at(format!(
                            "fields: {key} = {v} is not valid; expected a number or a list of numbers"
                        )));
                    }
                }
            }
            Some(out)
        }
        Some(other) => {
            return Err(at(format!(
                "fields = {other} is not valid; expected a table of field paths, e.g. {{ exposure = 1.5, \"lights[0].color\" = [1, 0, 0, 1] }}"
            )));
        }
    };
    let sources = [file.is_some(), data.is_some(), fill.is_some(), fields.is_some()].iter().filter(|b| **b).count();
    if sources > 1 {
        return Err(at("file, data, fill and fields are exclusive; give one".into()));
    }
    if length.is_some() && (file.is_some() || data.is_some() || fields.is_some()) {
        return Err(at("length goes with fill or nothing; a file, data or fields give their own length".into()));
    }
    Ok(ResourceKind::Buffer { file, data, fill, length, fields })
}

/// A sampler resource's keys: filter, address modes, comparison.
fn sampler_kind(t: &toml::Table, at: &dyn Fn(String) -> ParamError) -> Result<ResourceKind, ParamError> {
    let linear = match string_key(t, "filter", at)?.as_deref() {
        None | Some("nearest") => false,
        Some("linear") => true,
        Some(other) => {
            return Err(at(format!("filter = \"{other}\" is not valid; expected nearest|linear")));
        }
    };
    let mode = |s: &str| {
        ADDRESS_MODES
            .iter()
            .copied()
            .find(|m| *m == s)
            .ok_or_else(|| at(format!("address \"{s}\" is not valid; expected {}", ADDRESS_MODES.join("|"))))
    };
    let address = match t.get("address") {
        None => ["clamp-to-edge"; 3],
        Some(toml::Value::String(s)) => [mode(s)?; 3],
        Some(toml::Value::Array(l)) if (1..=3).contains(&l.len()) => {
            let mut out = ["clamp-to-edge"; 3];
            for (i, v) in l.iter().enumerate() {
                out[i] = mode(v.as_str().ok_or_else(|| at(format!("address entry {v} is not a string")))?)?;
            }
            out
        }
        Some(other) => {
            return Err(at(format!("address = {other} is not valid; expected a mode or [u, v, w]")));
        }
    };
    let compare =
        match string_key(t, "compare", at)? {
            None => None,
            Some(c) => Some(COMPARE_FUNCTIONS.iter().copied().find(|f| *f == c).ok_or_else(|| {
                at(format!("compare = \"{c}\" is not valid; expected {}", COMPARE_FUNCTIONS.join("|")))
            })?),
        };
    Ok(ResourceKind::Sampler { linear, address, compare })
}

/// Key `k` of `t` as a string, if given.
fn string_key(t: &toml::Table, k: &str, at: &dyn Fn(String) -> ParamError) -> Result<Option<String>, ParamError> {
    match t.get(k) {
        None => Ok(None),
        Some(toml::Value::String(s)) => Ok(Some(s.clone())),
        Some(other) => Err(at(format!("{k} = {other} is not valid; expected a string"))),
    }
}

/// The `[[pass]]` tables (one default pass where there are none), their
/// bindings naming resources of `res`.
fn parse_passes(
    passes: &[toml::Value],
    res: &[ResourceSpec],
    params: &[ParamSpec],
    fail: &dyn Fn(String) -> ParamError,
) -> Result<Vec<PassSpec>, ParamError> {
    let named = |r: &str| res.iter().any(|x| x.name == r);
    let names = || names_of(res);
    let mut out_passes = Vec::new();
    let raw_passes: Vec<toml::Value> =
        if passes.is_empty() { vec![toml::Value::Table(Default::default())] } else { passes.to_vec() };
    for (i, t) in raw_passes.iter().enumerate() {
        let Some(t) = t.as_table() else { return Err(fail("[[pass]] must be a table".into())) };
        let at = |m: String| fail(format!("[[pass]] {}: {m}", i + 1));
        for k in t.keys() {
            if !PASS_KEYS.contains(&k.as_str()) {
                return Err(at(format!("unknown key {k}; allowed: {}", PASS_KEYS.join(", "))));
            }
        }
        let text = |k: &str| string_key(t, k, &at);
        let raster = parse_raster(t, res, params, &at)?;
        let entry = match &raster {
            Some(_) => text("fragment")?.ok_or_else(|| at("a render pass needs fragment = \"<entry>\"".into()))?,
            None => text("entry")?.unwrap_or_else(|| "main".into()),
        };
        if entry.is_empty() || !entry.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(at(format!("entry = \"{entry}\" is not a WGSL function name")));
        }
        let shader = text("shader")?;
        let defs = match t.get("defs") {
            None => Vec::new(),
            Some(toml::Value::Table(d)) => crate::values::parse_defs(d).map_err(at)?,
            Some(other) => return Err(at(format!("defs = {other} is not valid; expected a table {{ NAME = value }}"))),
        };
        let source = match t.get("source") {
            None => Default::default(),
            Some(toml::Value::Table(s)) => vista_source::SourceSpec::parse(s).map_err(at)?,
            Some(other) => return Err(at(format!("source = {other} is not valid; expected a table like [source]"))),
        };
        let bind = parse_bind(t, res, &at)?;
        let dispatch = match text("dispatch")? {
            None => None,
            Some(d) => Some(Level::parse(&d, res).map_err(|m| at(format!("dispatch = {m}")))?),
        };
        let workgroups = parse_workgroups(t, params, &at)?;
        if workgroups.is_some() && dispatch.is_some() {
            return Err(at("dispatch and workgroups are exclusive; give one".into()));
        }
        let mut set = Vec::new();
        match t.get("set") {
            None => {}
            Some(toml::Value::Table(s)) => {
                for (k, v) in s {
                    let Some(spec) = params.iter().find(|p| &p.name == k) else {
                        let all: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
                        return Err(at(format!("set: {k} is not a param; params: {}", all.join(", "))));
                    };
                    let text = crate::values::value_text(v);
                    crate::params::parse_value(spec, &text).map_err(|e| at(format!("set: {e}")))?;
                    set.push((spec.name.clone(), text));
                }
            }
            Some(other) => return Err(at(format!("set = {other} is not valid; expected a table of params"))),
        }
        let repeat = match t.get("repeat") {
            None => Repeat::Count(1),
            Some(toml::Value::Integer(n)) if (1..=100_000).contains(n) => Repeat::Count(*n as u32),
            Some(toml::Value::String(s)) => match params.iter().find(|p| &p.name == s) {
                Some(p) if p.ty == crate::params::ParamType::U32 || p.ty == crate::params::ParamType::I32 => {
                    Repeat::Param(p.name.clone())
                }
                _ => return Err(at(format!("repeat = \"{s}\" must name an integer param"))),
            },
            Some(other) => {
                return Err(at(format!("repeat = {other} is not valid; expected a number in [1, 100000] or a param")));
            }
        };
        let mut swap = Vec::new();
        match t.get("swap") {
            None => {}
            Some(toml::Value::Array(pairs)) => {
                for p in pairs {
                    let pair: Option<Vec<&str>> = p.as_array().map(|l| l.iter().filter_map(|v| v.as_str()).collect());
                    match pair.as_deref() {
                        Some([a, b]) if named(a) && named(b) && a != b => swap.push((a.to_string(), b.to_string())),
                        _ => {
                            return Err(at(format!(
                                "swap entry {p} is not valid; expected [\"a\", \"b\"], two different resources of {}",
                                names()
                            )));
                        }
                    }
                }
            }
            Some(other) => return Err(at(format!("swap = {other} is not valid; expected [[\"a\", \"b\"], ..]"))),
        }
        let group = text("group")?;
        if let Some(g) = &group {
            if !valid_name(g) {
                return Err(at(format!("group = \"{g}\" must use only letters, digits, '-' and '_'")));
            }
            let first = out_passes.iter().position(|q: &PassSpec| q.group.as_deref() == Some(g));
            match first {
                Some(f) if out_passes.last().and_then(|q| q.group.as_deref()) != Some(g.as_str()) => {
                    return Err(at(format!(
                        "group \"{g}\" must be consecutive passes; pass {} starts it and another pass comes between",
                        f + 1
                    )));
                }
                Some(f) if repeat != Repeat::Count(1) => {
                    return Err(at(format!(
                        "repeat goes on the first pass of group \"{g}\" (pass {}), which repeats the whole group",
                        f + 1
                    )));
                }
                _ => {}
            }
        }
        if raster.is_some() && (dispatch.is_some() || workgroups.is_some()) {
            return Err(at("a render pass draws its targets; dispatch and workgroups are for compute passes".into()));
        }
        out_passes.push(PassSpec {
            entry,
            raster,
            shader,
            defs,
            source,
            bind,
            dispatch,
            workgroups,
            set,
            repeat,
            swap,
            group,
        });
    }
    Ok(out_passes)
}

/// A pass's `bind`: WGSL variable -> resource (and mip level).
fn parse_bind(
    t: &toml::Table,
    res: &[ResourceSpec],
    at: &dyn Fn(String) -> ParamError,
) -> Result<Vec<(String, Level)>, ParamError> {
    let mut bind = Vec::new();
    match t.get("bind") {
        None => {}
        Some(toml::Value::Table(b)) => {
            for (var, r) in b {
                let Some(r) = r.as_str() else {
                    return Err(at(format!("bind: {var} = {r} is not valid; expected a resource name")));
                };
                bind.push((var.clone(), Level::parse(r, res).map_err(|m| at(format!("bind: {var} = {m}")))?));
            }
        }
        Some(other) => return Err(at(format!("bind = {other} is not valid; expected a table"))),
    }
    Ok(bind)
}

/// A pass's explicit `workgroups = [x, y, z]`, expressions of the params
/// and the case size.
fn parse_workgroups(
    t: &toml::Table,
    params: &[ParamSpec],
    at: &dyn Fn(String) -> ParamError,
) -> Result<Option<[Expr; 3]>, ParamError> {
    match t.get("workgroups") {
        None => Ok(None),
        Some(toml::Value::Array(list)) if list.len() == 3 => {
            let mut e = Vec::new();
            for v in list {
                e.push(Expr::parse_entry(v, params).map_err(|m| at(format!("workgroups {m}")))?);
            }
            let [x, y, z]: [Expr; 3] = e.try_into().expect("three entries");
            Ok(Some([x, y, z]))
        }
        Some(other) => Err(at(format!("workgroups = {other} is not valid; expected [x, y, z]"))),
    }
}

/// A pass's `kind` and, for `kind = "render"`, its vertex stage, targets,
/// buffers, draw counts and fixed-function state (the `fragment` entry is
/// read with `entry`); the keys of one kind on the other are refused.
fn parse_raster(
    t: &toml::Table,
    res: &[ResourceSpec],
    params: &[ParamSpec],
    at: &dyn Fn(String) -> ParamError,
) -> Result<Option<RasterSpec>, ParamError> {
    let kind = string_key(t, "kind", at)?;
    match kind.as_deref() {
        None | Some("compute") => {
            let render_keys = ["vertex", "fragment", "targets", "depth"].into_iter().chain(DRAW_KEYS);
            if let Some(k) = render_keys.into_iter().find(|k| t.contains_key(*k)) {
                return Err(at(format!("{k} is a render pass's key; add kind = \"render\"")));
            }
            return Ok(None);
        }
        Some("render") => {}
        Some(other) => return Err(at(format!("kind = \"{other}\" is not valid; expected compute|render"))),
    }
    if t.contains_key("entry") {
        return Err(at("a render pass names its fragment entry as fragment = \"...\", not entry".into()));
    }
    let vertex = parse_vertex_stage(t, at)?;
    if vertex == VertexStage::Fullscreen
        && let Some(k) = DRAW_KEYS.into_iter().find(|k| t.contains_key(*k))
    {
        return Err(at(format!(
            "{k} needs a vertex entry; vertex = \"fullscreen\" draws vista's own triangle (name a @vertex entry)"
        )));
    }
    let targets = parse_targets(t, res, at)?;
    let buffer = |name: &str| match res.iter().find(|r| r.name == name) {
        Some(r) if matches!(r.kind, ResourceKind::Buffer { .. }) => Ok(()),
        Some(r) => Err(format!("{name} is a {}; expected a buffer resource", r.kind_name())),
        None => Err(format!("{name} names no resource; resources: {}", names_of(res))),
    };
    let vertices = match t.get("vertices") {
        None => Vec::new(),
        Some(v) => crate::vertex::parse(v, &buffer).map_err(at)?,
    };
    let indices = parse_indices(t, at)?;
    if let Some((i, _)) = &indices {
        buffer(i).map_err(|m| at(format!("indices = {m}")))?;
    }
    let expr = |k: &str| t.get(k).map(|v| Expr::parse_entry(v, params).map_err(|e| at(format!("{k} {e}")))).transpose();
    let (count, instances) = (expr("count")?, expr("instances")?);
    let offset =
        |k: &str| t.get(k).map(|v| Expr::parse_offset(v, params).map_err(|e| at(format!("{k} {e}")))).transpose();
    let (first_vertex, first_instance, base_vertex) =
        (offset("first_vertex")?, offset("first_instance")?, offset("base_vertex")?);
    // WebGPU: firstVertex belongs to draw(), baseVertex to drawIndexed().
    match (&indices, &first_vertex, &base_vertex) {
        (Some(_), Some(_), _) => {
            return Err(at("first_vertex is for a draw without indices; an indexed draw takes base_vertex".into()));
        }
        (None, _, Some(_)) => {
            return Err(at(
                "base_vertex is for an indexed draw (indices = ...); without indices use first_vertex".into()
            ));
        }
        _ => {}
    }
    let topology = match string_key(t, "topology", at)? {
        None => Topology::TriangleList,
        Some(name) => Topology::parse(&name).map_err(at)?,
    };
    let cull = match string_key(t, "cull", at)? {
        None => Cull::None,
        Some(name) => Cull::parse(&name).map_err(at)?,
    };
    let depth = match t.get("depth") {
        None => None,
        Some(toml::Value::Table(d)) => {
            let depth = parse_depth(d, at)?;
            if let Some(name) = &depth.resource {
                match res.iter().find(|r| &r.name == name) {
                    Some(r) if matches!(r.kind, ResourceKind::Depth { .. }) => {}
                    Some(r) => {
                        return Err(at(format!(
                            "depth: resource {name} is a {}; it needs kind = \"depth\"",
                            r.kind_name()
                        )));
                    }
                    None => {
                        return Err(at(format!(
                            "depth: resource = \"{name}\" names no resource; resources: {}",
                            names_of(res)
                        )));
                    }
                }
            }
            Some(depth)
        }
        Some(other) => return Err(at(format!("depth = {other} is not valid; expected {{ compare, write, clear }}"))),
    };
    Ok(Some(RasterSpec {
        vertex,
        targets,
        vertices,
        indices,
        count,
        instances,
        first_vertex,
        first_instance,
        base_vertex,
        topology,
        cull,
        depth,
    }))
}

/// A render pass's `vertex`: vista's fullscreen triangle, an entry of the
/// pass's shader, or `{ shader, entry }` in another file.
fn parse_vertex_stage(t: &toml::Table, at: &dyn Fn(String) -> ParamError) -> Result<VertexStage, ParamError> {
    Ok(match t.get("vertex") {
        None => VertexStage::Fullscreen,
        Some(toml::Value::String(v)) if v == "fullscreen" => VertexStage::Fullscreen,
        Some(toml::Value::String(v)) if valid_name(v) => VertexStage::Entry(v.clone()),
        Some(toml::Value::Table(v)) => {
            if let Some(k) = v.keys().find(|k| !["shader", "entry", "source"].contains(&k.as_str())) {
                return Err(at(format!("vertex: unknown key {k}; allowed: shader, entry, source")));
            }
            let source = match v.get("source") {
                None => Default::default(),
                Some(toml::Value::Table(s)) => {
                    vista_source::SourceSpec::parse(s).map_err(|e| at(format!("vertex {e}")))?
                }
                Some(other) => {
                    return Err(at(format!("vertex source = {other} is not valid; expected a table of [source] keys")));
                }
            };
            let shader = string_key(v, "shader", at)?.ok_or_else(|| at("vertex needs shader = \"<file>\"".into()))?;
            let entry =
                string_key(v, "entry", at)?.ok_or_else(|| at("vertex needs entry = \"<@vertex entry>\"".into()))?;
            if !valid_name(&entry) {
                return Err(at(format!("vertex entry = \"{entry}\" is not a WGSL function name")));
            }
            VertexStage::File { shader, entry, source: Box::new(source) }
        }
        Some(other) => {
            return Err(at(format!(
                "vertex = {other} is not valid; expected \"fullscreen\" or a @vertex entry of the pass's shader"
            )));
        }
    })
}

/// A draw's `indices`: a buffer's name, or `{ resource, format }`; the
/// name and whether its indices are uint16.
fn parse_indices(t: &toml::Table, at: &dyn Fn(String) -> ParamError) -> Result<Option<(String, bool)>, ParamError> {
    Ok(match t.get("indices") {
        None => None,
        Some(toml::Value::String(name)) => Some((name.clone(), false)),
        Some(toml::Value::Table(i)) => {
            if let Some(k) = i.keys().find(|k| !["resource", "format"].contains(&k.as_str())) {
                return Err(at(format!("indices: unknown key {k}; allowed: resource, format")));
            }
            let name =
                string_key(i, "resource", at)?.ok_or_else(|| at("indices needs resource = \"<buffer>\"".into()))?;
            let u16 = match string_key(i, "format", at)?.as_deref() {
                None | Some("uint32") => false,
                Some("uint16") => true,
                Some(other) => {
                    return Err(at(format!("indices format = \"{other}\" is not valid; expected uint32|uint16")));
                }
            };
            Some((name, u16))
        }
        Some(other) => {
            return Err(at(format!(
                "indices = {other} is not valid; expected a buffer name or {{ resource, format }}"
            )));
        }
    })
}

/// The resources' names for a message ("none" for none).
fn names_of(res: &[ResourceSpec]) -> String {
    let n: Vec<&str> = res.iter().map(|r| r.name.as_str()).collect();
    if n.is_empty() { "none".to_string() } else { n.join(", ") }
}

/// Four finite numbers `[r, g, b, a]`.
fn four(v: &toml::Value) -> Option<[f64; 4]> {
    let c = v.as_array().filter(|c| c.len() == 4)?;
    let v: Vec<f64> = c.iter().filter_map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64))).collect();
    <[f64; 4]>::try_from(v).ok().filter(|c| c.iter().all(|x| x.is_finite()))
}

/// A render pass's `targets`: resource (and level), clear, blend.
fn parse_targets(
    t: &toml::Table,
    res: &[ResourceSpec],
    at: &dyn Fn(String) -> ParamError,
) -> Result<Vec<TargetSpec>, ParamError> {
    let Some(toml::Value::Array(list)) = t.get("targets") else {
        return Err(at("a render pass needs targets = [{ resource = \"...\" }, ...]".into()));
    };
    let mut targets = Vec::new();
    for (n, v) in list.iter().enumerate() {
        let tat = |m: String| at(format!("targets[{n}]: {m}"));
        let Some(tt) = v.as_table() else { return Err(tat("must be a table { resource = \"...\" }".into())) };
        if let Some(k) = tt.keys().find(|k| !TARGET_KEYS.contains(&k.as_str())) {
            return Err(tat(format!("unknown key {k}; allowed: {}", TARGET_KEYS.join(", "))));
        }
        let name = string_key(tt, "resource", &tat)?.ok_or_else(|| tat("needs resource = \"...\"".into()))?;
        // "cube@layer3", "arr@2@layer1": one layer (of one level).
        let (name, layer) = match name.rsplit_once("@layer") {
            None => (name.clone(), None),
            Some((n, l)) => match l.parse::<u32>() {
                Ok(l) => (n.to_string(), Some(l)),
                Err(_) => {
                    return Err(tat(format!("resource = \"{name}\": @layer needs a layer number, e.g. {n}@layer0")));
                }
            },
        };
        let texture = Level::parse(&name, res).map_err(|m| tat(format!("resource = {m}")))?;
        let clear =
            match tt.get("clear") {
                None => None,
                Some(c) => Some(four(c).ok_or_else(|| {
                    tat(format!("clear = {c} is not valid; expected four finite numbers [r, g, b, a]"))
                })?),
            };
        let (blend, constant) = parse_blend(tt.get("blend"), &tat)?;
        targets.push(TargetSpec { texture, layer, clear, blend, constant });
    }
    if targets.is_empty() {
        return Err(at("targets is empty; a render pass draws into at least one texture".into()));
    }
    Ok(targets)
}

/// `blend = "replace" | "alpha" | "additive"` or `{ color = [src, dst,
/// op], alpha = [...], constant = [r, g, b, a] }` (alpha defaults to color).
fn parse_blend(
    v: Option<&toml::Value>,
    at: &dyn Fn(String) -> ParamError,
) -> Result<(Blend, Option<[f64; 4]>), ParamError> {
    let t = match v {
        None => return Ok((Blend::Replace, None)),
        Some(toml::Value::String(name)) => return Ok((Blend::parse(name).map_err(at)?, None)),
        Some(toml::Value::Table(t)) => t,
        Some(other) => {
            return Err(at(format!("blend = {other} is not valid; expected a name or {{ color, alpha, constant }}")));
        }
    };
    if let Some(k) = t.keys().find(|k| !BLEND_KEYS.contains(&k.as_str())) {
        return Err(at(format!("blend: unknown key {k}; allowed: {}", BLEND_KEYS.join(", "))));
    }
    let component = |k: &str| -> Result<Option<vista_texel::BlendComponent>, ParamError> {
        let Some(v) = t.get(k) else { return Ok(None) };
        let words: Option<Vec<&str>> = v.as_array().map(|a| a.iter().filter_map(|w| w.as_str()).collect());
        match words {
            Some(w) if w.len() == v.as_array().map_or(0, |a| a.len()) => {
                vista_texel::BlendComponent::parse(&w).map(Some).map_err(|m| at(format!("blend {k}: {m}")))
            }
            _ => Err(at(format!("blend {k} = {v} is not valid; expected [src factor, dst factor, operation]"))),
        }
    };
    let color = component("color")?.ok_or_else(|| at("blend needs color = [src, dst, op]".into()))?;
    let alpha = component("alpha")?.unwrap_or(color);
    let blend = Blend::Factors { color, alpha };
    let constant = match t.get("constant") {
        None => None,
        Some(c) => {
            Some(four(c).ok_or_else(|| at(format!("blend constant = {c} is not valid; expected [r, g, b, a]")))?)
        }
    };
    if blend.uses_constant() != constant.is_some() {
        return Err(at(match constant {
            None => "blend uses a constant factor; give constant = [r, g, b, a]".into(),
            Some(_) => "blend constant is given but no factor is constant or one-minus-constant".into(),
        }));
    }
    Ok((blend, constant))
}

/// A render pass's `depth` table.
fn parse_depth(d: &toml::Table, at: &dyn Fn(String) -> ParamError) -> Result<DepthSpec, ParamError> {
    let dat = |m: String| at(format!("depth: {m}"));
    if let Some(k) = d.keys().find(|k| !DEPTH_KEYS.contains(&k.as_str())) {
        return Err(dat(format!("unknown key {k}; allowed: {}", DEPTH_KEYS.join(", "))));
    }
    let resource = string_key(d, "resource", &dat)?;
    let compare =
        match string_key(d, "compare", &dat)? {
            None => "less",
            Some(c) => COMPARE_FUNCTIONS.iter().copied().find(|f| *f == c).ok_or_else(|| {
                dat(format!("compare = \"{c}\" is not valid; expected {}", COMPARE_FUNCTIONS.join("|")))
            })?,
        };
    let write = match d.get("write") {
        None => true,
        Some(toml::Value::Boolean(b)) => *b,
        Some(other) => return Err(dat(format!("write = {other} is not valid; expected true or false"))),
    };
    let clear = match d.get("clear") {
        None => 1.0,
        Some(v) => v
            .as_float()
            .or_else(|| v.as_integer().map(|i| i as f64))
            .filter(|c| (0.0..=1.0).contains(c))
            .ok_or_else(|| dat(format!("clear = {v} is not valid; expected a number in [0, 1]")))?,
    };
    Ok(DepthSpec { resource, compare, write, clear })
}

/// The `[[output]]` tables: resource, view, exposure, partial, tolerance.
fn parse_outputs(
    outputs: &[toml::Value],
    default_view: Option<Output>,
    fail: &dyn Fn(String) -> ParamError,
) -> Result<Vec<OutputSpec>, ParamError> {
    let mut outs = Vec::new();
    for t in outputs {
        let Some(t) = t.as_table() else { return Err(fail("[[output]] must be a table".into())) };
        for k in t.keys() {
            if !OUTPUT_KEYS.contains(&k.as_str()) {
                return Err(fail(format!("[[output]]: unknown key {k}; allowed: {}", OUTPUT_KEYS.join(", "))));
            }
        }
        let resource = match t.get("resource") {
            Some(toml::Value::String(r)) if !r.is_empty() => Some(r.as_str()),
            // One output may leave it to the texture its pass writes.
            None if outputs.len() == 1 => None,
            _ => {
                return Err(fail(
                    "[[output]] needs resource = \"...\" (a texture or buffer a pass writes; only a lone [[output]] may \
                     leave it out)"
                        .into(),
                ));
            }
        };
        let at = |m: String| match resource {
            Some(r) => fail(format!("[[output]] {r}: {m}")),
            None => fail(format!("[[output]]: {m}")),
        };
        if let Some(r) = resource {
            split_target(r).map_err(|m| fail(format!("[[output]] resource = {m}")))?;
        }
        let view = match t.get("view") {
            None => default_view,
            Some(toml::Value::String(v)) => Some(match v.as_str() {
                "display" => Output::Display,
                "hdr" => Output::Hdr,
                "normalize" => Output::Normalize,
                other => return Err(at(format!("view = \"{other}\" is not valid; expected display|hdr|normalize"))),
            }),
            Some(other) => return Err(at(format!("view = {other} is not valid; expected a string"))),
        };
        let exposure = match t.get("exposure") {
            None => None,
            Some(v) => match v.as_float().or_else(|| v.as_integer().map(|i| i as f64)) {
                Some(e) if e.is_finite() && e > 0.0 => Some(e),
                _ => return Err(at(format!("exposure = {v} is not valid; expected a number > 0"))),
            },
        };
        let partial = match t.get("partial") {
            None => false,
            Some(toml::Value::Boolean(b)) => *b,
            Some(other) => return Err(at(format!("partial = {other} is not valid; expected true or false"))),
        };
        let tolerance = t.get("tolerance").map(parse_tolerance).transpose().map_err(at)?;
        if outs.iter().any(|o: &OutputSpec| o.resource.as_deref() == resource) {
            return Err(at("is listed twice".into()));
        }
        outs.push(OutputSpec { resource: resource.map(str::to_string), view, partial, tolerance, exposure });
    }
    Ok(outs)
}

/// A tolerance as a manifest's `[[output]]` or a case's `tolerances` gives
/// it: `"exact"`, or a table with one of [`Tolerance::KEYS`].
pub fn parse_tolerance(v: &toml::Value) -> Result<Tolerance, String> {
    match v {
        toml::Value::String(s) if s == "exact" => Ok(Tolerance::Exact),
        toml::Value::Table(t) => tolerance(t),
        other => Err(format!(
            "tolerance = {other} is not valid; expected \"exact\" or a table with one of {}",
            Tolerance::KEYS.join(", ")
        )),
    }
}

fn tolerance(t: &toml::Table) -> Result<Tolerance, String> {
    for k in t.keys() {
        if !Tolerance::KEYS.contains(&k.as_str()) {
            return Err(format!("tolerance: unknown key {k}; allowed: {}", Tolerance::KEYS.join(", ")));
        }
    }
    let num = |k: &str| -> Result<Option<f64>, String> {
        match t.get(k) {
            None => Ok(None),
            Some(toml::Value::Integer(i)) if *i >= 0 => Ok(Some(*i as f64)),
            Some(toml::Value::Float(f)) if f.is_finite() && *f >= 0.0 => Ok(Some(*f)),
            Some(other) => Err(format!("tolerance {k} = {other} is not valid; expected a number >= 0")),
        }
    };
    let given: Vec<&str> = Tolerance::KEYS[..6].iter().copied().filter(|k| t.contains_key(*k)).collect();
    if given.len() != 1 {
        return Err(format!(
            "tolerance needs exactly one of {} (found {})",
            Tolerance::KEYS[..6].join(", "),
            if given.is_empty() { "none".into() } else { given.join(", ") }
        ));
    }
    if t.contains_key("bins") && given[0] != "histogram_emd" {
        return Err("tolerance bins goes with histogram_emd".into());
    }
    Ok(match given[0] {
        "exact" => match t.get("exact") {
            Some(toml::Value::Boolean(true)) => Tolerance::Exact,
            other => return Err(format!("tolerance exact = {} is not valid; expected true", other.expect("given"))),
        },
        "max_abs" => Tolerance::MaxAbs(num("max_abs")?.expect("given")),
        "max_rel" => Tolerance::MaxRel(num("max_rel")?.expect("given")),
        "max_ulp" => Tolerance::MaxUlp(num("max_ulp")?.expect("given") as u64),
        "rmse" => Tolerance::Rmse(num("rmse")?.expect("given")),
        _ => {
            let bins = num("bins")?.unwrap_or(64.0);
            if !(2.0..=4096.0).contains(&bins) {
                return Err(format!("tolerance bins = {bins} is not valid; expected [2, 4096]"));
            }
            Tolerance::HistogramEmd { max: num("histogram_emd")?.expect("given"), bins: bins as u32 }
        }
    })
}

/// How a pass uses a resource it binds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Usage {
    /// A storage buffer (`var<storage>`).
    StorageBuffer {
        /// `var<storage, read>` (else `read_write`).
        read_only: bool,
    },
    /// A uniform buffer (`var<uniform>` bound to a buffer resource).
    UniformBuffer,
    /// A storage texture of this format, dimension and access.
    StorageTexture(Storage),
    /// A sampled texture.
    Sampled {
        /// The binding's dimension.
        dim: Dimension,
        /// What sampling it returns.
        kind: SampledKind,
    },
    /// A sampler.
    Sampler {
        /// A `sampler_comparison` (else a filtering `sampler`).
        comparison: bool,
    },
}

/// What feeds one binding of a pass.
#[derive(Debug, Clone, PartialEq)]
pub enum SlotFeed {
    /// Params, packed into uniform block `n` of the pass's layout.
    Uniform(usize),
    /// The noise permutation table.
    Table,
    /// Resource `n` of [`Resolved::resources`].
    Resource(usize, Usage),
}

/// One binding of a pass and what feeds it.
#[derive(Debug, Clone, PartialEq)]
pub struct PassSlot {
    /// The binding's `@group`.
    pub group: u32,
    /// The binding's `@binding` within its group.
    pub binding: u32,
    /// The WGSL variable name.
    pub var: String,
    /// What feeds the binding.
    pub feed: SlotFeed,
    /// For a storage buffer: its element layout (stride, fixed header
    /// bytes before a runtime-sized array, leaf scalars of one element).
    pub element: Option<Element>,
    /// The texture's mip level the binding sees (`bind = { v = "t@2" }`);
    /// `None`: every level for a sampled binding, level 0 for storage.
    pub level: Option<u32>,
    /// A render pass's vertex entry reaches it too.
    pub vertex: bool,
}

/// A draw's buffers as resolved: each vertex buffer's resource and
/// layout, and the index buffer's resource.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawLayout {
    /// (resource index, layout), one per vertex-buffer slot.
    pub buffers: Vec<(usize, VertexLayout)>,
    /// The index buffer.
    pub indices: Option<usize>,
    /// It holds u16 indices (else u32).
    pub index_u16: bool,
}

impl PassSlot {
    /// The mip levels of its texture this binding touches: one for a
    /// storage binding, all (`None`) for a sampled one without a level.
    fn levels(&self) -> Option<u32> {
        match self.feed {
            SlotFeed::Resource(_, Usage::StorageTexture(_)) => Some(self.level.unwrap_or(0)),
            _ => self.level,
        }
    }
}

/// A texture level a pass writes is bound nowhere else in that pass
/// (WebGPU forbids it; the message says which bindings clash).
fn check_levels(
    slots: &[PassSlot],
    resources: &[ResolvedResource],
    label: &str,
    bad: &dyn Fn(String) -> ParamError,
) -> Result<(), ParamError> {
    for (i, w) in slots.iter().enumerate() {
        let SlotFeed::Resource(r, Usage::StorageTexture(st)) = w.feed else { continue };
        if st.access == Access::Read {
            continue;
        }
        let level = w.levels().expect("storage binds one level");
        for (j, o) in slots.iter().enumerate() {
            let same = matches!(o.feed, SlotFeed::Resource(q, _) if q == r);
            if j == i || !same || o.levels().is_some_and(|l| l != level) {
                continue;
            }
            let name = &resources[r].spec.name;
            return Err(bad(format!(
                "{label}: {} writes {name}@{level} and {} binds {}; a pass cannot read or write a level it writes through another binding (bind one a different level, e.g. {name}@{})",
                w.var,
                o.var,
                match o.levels() {
                    Some(l) => format!("{name}@{l} too"),
                    None => format!("all of {name}'s levels"),
                },
                level.saturating_sub(1)
            )));
        }
    }
    Ok(())
}

/// The graph's resources after reflection: the manifest's, then one
/// implicit texture per written storage texture no `bind` names.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolved {
    /// The manifest's resources, then the implicit textures; [`SlotFeed::Resource`]
    /// indexes this list.
    pub resources: Vec<ResolvedResource>,
    /// Per pass, its slots (sorted by group and binding).
    pub slots: Vec<Vec<PassSlot>>,
    /// Per pass, a draw's buffers (`None`: a compute or full-screen pass).
    pub draws: Vec<Option<DrawLayout>>,
    /// The outputs' resources (indexes into `resources`), in `[[output]]`
    /// order; without tables, or for a lone one without `resource`, the
    /// first texture a pass writes.
    pub outputs: Vec<usize>,
    /// Per output, the mip level and the one layer it reads (`(0, None)`:
    /// the whole texture, or a buffer).
    pub output_views: Vec<(u32, Option<u32>)>,
}

/// One resource with what reflection adds to its table.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedResource {
    /// Its `[[resource]]` table (an implicit texture's: only its variable's name).
    pub spec: ResourceSpec,
    /// A texture's format: its own, else a storage binding's, else its
    /// file's (decided when the file is read: `None` here).
    pub format: Option<&'static str>,
    /// A texture's dimension: its own, else its bindings'.
    pub dimension: Option<Dimension>,
    /// A buffer's element (from its first storage or uniform binding).
    pub element: Option<Element>,
    /// Some pass writes it (a write or read_write storage binding).
    pub written: bool,
    /// Some pass reads it (sampled, read, read_write, storage read).
    pub read: bool,
}

/// Checks every pass's reflected bindings against the graph and says what
/// feeds each. `passes[i]` is pass i's bindings and module.
pub fn resolve(
    kernel: &str,
    graph: &GraphSpec,
    passes: &[(&str, &[Binding], &naga::Module)],
    vertex_modules: &[Option<&naga::Module>],
) -> Result<Resolved, ParamError> {
    let bad = |message: String| ParamError::Layout { kernel: kernel.to_string(), message };
    let mut resources: Vec<ResolvedResource> = graph
        .resources
        .iter()
        .map(|spec| {
            let (format, dimension) = match &spec.kind {
                ResourceKind::Texture { format, dimension, .. } => (*format, *dimension),
                _ => (None, None),
            };
            ResolvedResource { spec: spec.clone(), format, dimension, element: None, written: false, read: false }
        })
        .collect();
    let mut all_slots = Vec::new();
    for (i, ((shader, bindings, module), pass)) in passes.iter().zip(&graph.passes).enumerate() {
        let label = format!("pass {} ({})", i + 1, pass.entry);
        // A binding only a vertex file declares is a variable of its module.
        let vertex_module = vertex_modules.get(i).copied().flatten();
        let module_of = |b: &Binding| match (b.in_vertex_file, vertex_module) {
            (true, Some(v)) => v,
            _ => *module,
        };
        let describe = |b: &Binding| {
            let m = module_of(b);
            format!(
                "{} (@group({}) @binding({}), {})",
                b.name,
                b.group,
                b.binding,
                crate::bindings::wgsl_type(m, &m.global_variables[b.global])
            )
        };
        check_bind_declared(pass, shader, bindings, module, &label, &bad)?;
        let mut slots = Vec::new();
        let mut blocks = 0usize;
        for b in bindings.iter() {
            // Bound by the pass's bind, else to the resource of its own name
            // unless the bind gives that resource to another variable (a
            // uniform `sky` beside `bind = { sky_faces = "sky" }`).
            let given = pass.bind.iter().find(|(v, _)| b.named(v)).map(|(_, r)| r);
            let level = given.and_then(|r| r.level);
            let bound = given.map(|r| r.resource.clone()).or_else(|| {
                graph
                    .resources
                    .iter()
                    .find(|r| r.name == b.name && !pass.bind.iter().any(|(_, l)| l.resource == r.name))
                    .map(|r| r.name.clone())
            });
            let bound = bound.as_deref();
            let feed = match (b.feed, bound) {
                (Feed::Uniform, None) => {
                    blocks += 1;
                    SlotFeed::Uniform(blocks - 1)
                }
                (Feed::Uniform, Some(r)) => {
                    let ri = find(&resources, r);
                    needs_kind(&resources, ri, "buffer", &label, &describe(b), &bad)?;
                    SlotFeed::Resource(ri, Usage::UniformBuffer)
                }
                (Feed::Table, None) => SlotFeed::Table,
                (Feed::Table | Feed::Buffer { .. }, Some(r)) => {
                    let ri = find(&resources, r);
                    needs_kind(&resources, ri, "buffer", &label, &describe(b), &bad)?;
                    let read_only = match b.feed {
                        Feed::Buffer { read_only } => read_only,
                        _ => true,
                    };
                    SlotFeed::Resource(ri, Usage::StorageBuffer { read_only })
                }
                (Feed::Buffer { .. }, None) => {
                    return Err(bad(format!(
                        "{label}: {} is fed by nothing; it needs a buffer resource ([[resource]] kind = \"buffer\", named in this pass's bind)",
                        describe(b)
                    )));
                }
                (Feed::Output(storage) | Feed::StorageRead(storage), bound) => {
                    storage_slot(&mut resources, storage, bound, b, &label, &describe(b), &bad)?
                }
                (Feed::Sampled { dim, kind }, bound) => {
                    sampled_slot(&mut resources, dim, kind, bound, &label, &describe(b), &bad)?
                }
                (Feed::Sampler { comparison }, bound) => {
                    let Some(rn) = bound else {
                        return Err(bad(format!(
                            "{label}: {} is fed by nothing; it needs a sampler resource ([[resource]] kind = \"sampler\", named in this pass's bind)",
                            describe(b)
                        )));
                    };
                    let ri = find(&resources, rn);
                    needs_kind(&resources, ri, "sampler", &label, &describe(b), &bad)?;
                    if let ResourceKind::Sampler { compare, .. } = &resources[ri].spec.kind
                        && compare.is_some() != comparison
                    {
                        return Err(bad(format!(
                            "{label}: resource {rn} is {} but is bound to {}",
                            if comparison { "a filtering sampler" } else { "a comparison sampler" },
                            describe(b)
                        )));
                    }
                    SlotFeed::Resource(ri, Usage::Sampler { comparison })
                }
            };
            let element = buffer_element(&feed, module_of(b), b, &mut resources, &label, &describe(b), &bad)?;
            slots.push(PassSlot {
                group: b.group,
                binding: b.binding,
                var: b.name.clone(),
                feed,
                element,
                level,
                vertex: b.vertex,
            });
        }
        check_levels(&slots, &resources, &label, &bad)?;
        if let Some(raster) = &pass.raster {
            check_targets(raster, &slots, &mut resources, module, &pass.entry, &label, &bad)?;
        }
        all_slots.push(slots);
    }
    let mut draws = Vec::new();
    for (i, ((_, _, module), pass)) in passes.iter().zip(&graph.passes).enumerate() {
        let vs = pass.raster.as_ref().and_then(|r| r.vertex.entry().map(|vs| (r, vs)));
        draws.push(match vs {
            Some((raster, vs)) => {
                let module = vertex_modules.get(i).copied().flatten().unwrap_or(module);
                Some(
                    draw_layout(raster, vs, module, &mut resources)
                        .map_err(|m| bad(format!("pass {} ({vs}, {}): {m}", i + 1, pass.entry)))?,
                )
            }
            None => None,
        });
    }
    let (outputs, output_views) = check_swaps_and_outputs(graph, &resources, &bad)?.into_iter().unzip();
    check_default_output(graph, &resources, &all_slots, &bad)?;
    check_read_before_written(graph, &resources, &bad)?;
    Ok(Resolved { resources, slots: all_slots, outputs, output_views, draws })
}

/// A buffer binding's element (its WGSL type's stride, header and
/// leaves), recorded on the resource it binds, which is marked read (and
/// written, for a read_write storage buffer); `None` for other bindings.
fn buffer_element(
    feed: &SlotFeed,
    module: &naga::Module,
    b: &Binding,
    resources: &mut [ResolvedResource],
    label: &str,
    describe: &str,
    bad: &dyn Fn(String) -> ParamError,
) -> Result<Option<Element>, ParamError> {
    Ok(match *feed {
        SlotFeed::Resource(ri, Usage::StorageBuffer { read_only }) => {
            let e = element(module, &module.global_variables[b.global])
                .map_err(|m| bad(format!("{label}: {describe}: {m}")))?;
            let r = &mut resources[ri];
            if let Some(prev) = &r.element
                && (prev.stride != e.stride || prev.header != e.header)
            {
                return Err(bad(format!(
                    "{label}: resource {} is bound as {} here but as {} elsewhere",
                    r.spec.name, e.wgsl, prev.wgsl
                )));
            }
            r.element.get_or_insert(e.clone());
            if read_only {
                r.read = true;
            } else {
                r.written = true;
                r.read = true;
            }
            Some(e)
        }
        SlotFeed::Resource(ri, Usage::UniformBuffer) => {
            let e = element(module, &module.global_variables[b.global])
                .map_err(|m| bad(format!("{label}: {describe}: {m}")))?;
            resources[ri].element.get_or_insert(e.clone());
            resources[ri].read = true;
            Some(e)
        }
        _ => None,
    })
}

/// A draw's vertex and index buffers against its vertex entry's inputs,
/// after every pass's bindings (a compute pass may give a buffer its
/// element): each buffer read, and given the vertex layout's element where
/// no binding gives one.
fn draw_layout(
    raster: &RasterSpec,
    vs: &str,
    module: &naga::Module,
    resources: &mut [ResolvedResource],
) -> Result<DrawLayout, String> {
    let inputs = crate::bindings::vertex_inputs(module, vs)?;
    let ids: Vec<usize> = raster.vertices.iter().map(|v| find(resources, &v.resource)).collect();
    let elements: Vec<Option<&Element>> = ids.iter().map(|&r| resources[r].element.as_ref()).collect();
    let laid = crate::vertex::layouts(vs, &inputs, &raster.vertices, &elements)?;
    let mut buffers = Vec::new();
    for (&r, (layout, synth)) in ids.iter().zip(laid) {
        if let Some(e) = synth {
            match &resources[r].element {
                Some(prev) if prev.stride != e.stride => {
                    return Err(format!(
                        "vertices {}: read with stride {} here but {} elsewhere",
                        resources[r].spec.name, e.stride, prev.stride
                    ));
                }
                Some(_) => {}
                None => resources[r].element = Some(e),
            }
        }
        resources[r].read = true;
        buffers.push((r, layout));
    }
    let indices = match &raster.indices {
        None => None,
        Some((name, u16)) => {
            let r = find(resources, name);
            let res = &mut resources[r];
            // A u16 index is a 2-byte leaf ('h'), read from "<u2" or data.
            let (stride, kind, wgsl) = if *u16 { (2, 'h', "u16") } else { (4, 'u', "u32") };
            let index =
                Element { stride, header: 0, fixed: None, leaves: vec![(0, kind, String::new())], wgsl: wgsl.into() };
            match &res.element {
                Some(e) if (e.stride, e.header, e.leaves.len(), e.leaves[0].1) != (stride, 0, 1, kind) => {
                    return Err(format!("indices {name} holds {} but the draw reads {wgsl} indices", e.wgsl));
                }
                Some(_) => {}
                None => res.element = Some(index),
            }
            res.read = true;
            Some(r)
        }
    };
    let index_u16 = raster.indices.as_ref().is_some_and(|(_, u16)| *u16);
    Ok(DrawLayout { buffers, indices, index_u16 })
}

/// A render pass's targets: each a 2d texture (or one level of one) that
/// the pass does not also bind at that level, marked written; `@location(n)` of the
/// fragment entry for each `targets[n]`, and no output without a target.
fn check_targets(
    raster: &RasterSpec,
    slots: &[PassSlot],
    resources: &mut [ResolvedResource],
    module: &naga::Module,
    entry: &str,
    label: &str,
    bad: &dyn Fn(String) -> ParamError,
) -> Result<(), ParamError> {
    for (n, t) in raster.targets.iter().enumerate() {
        let ri = find(resources, &t.texture.resource);
        let name = &t.texture.resource;
        if kind_of(resources, ri) != "texture" {
            return Err(bad(format!(
                "{label}: targets[{n}] names {name}, a {}; a target is a texture",
                kind_of(resources, ri)
            )));
        }
        // Another level of the same texture may be read (a mip chain).
        let drawn = t.texture.level.unwrap_or(0);
        let overlaps =
            |s: &&PassSlot| matches!(s.feed, SlotFeed::Resource(r, _) if r == ri) && s.level.is_none_or(|l| l == drawn);
        if let Some(s) = slots.iter().find(overlaps) {
            return Err(bad(format!(
                "{label}: targets[{n}] {name} is also bound to {} in this pass; a pass cannot draw into what it \
                 reads (another mip level of it, \"{name}@k\", it may)",
                s.var
            )));
        }
        let r = &mut resources[ri];
        match (r.dimension, t.layer) {
            (None, None) => r.dimension = Some(Dimension::D2),
            (Some(Dimension::D2), None)
            | (Some(Dimension::D2Array | Dimension::Cube | Dimension::CubeArray), Some(_)) => {}
            (Some(d @ (Dimension::D2Array | Dimension::Cube | Dimension::CubeArray)), None) => {
                return Err(bad(format!(
                    "{label}: targets[{n}] {name} is a {} texture, drawn one layer at a time: \"{name}@layer0\" ..",
                    d.name()
                )));
            }
            (d, Some(_)) => {
                return Err(bad(format!(
                    "{label}: targets[{n}] {name}@layer.. needs a 2d-array or cube texture (dimension = \"cube\"); \
                     {name} is {}",
                    d.map_or("2d".to_string(), |d| d.name().to_string())
                )));
            }
            (Some(d), None) => {
                return Err(bad(format!(
                    "{label}: targets[{n}] {name} is a {} texture; a render target is 2d, or one layer of a \
                     2d-array or cube",
                    d.name()
                )));
            }
        }
        r.written = true;
    }
    if let Some(d) = raster.depth.as_ref().and_then(|d| d.resource.as_ref()) {
        let ri = find(resources, d);
        if let Some(s) = slots.iter().find(|s| matches!(s.feed, SlotFeed::Resource(r, _) if r == ri)) {
            return Err(bad(format!(
                "{label}: depth resource {d} is also bound to {} in this pass; a pass cannot test against what it reads",
                s.var
            )));
        }
        resources[ri].written = true;
    }
    let outputs = crate::bindings::fragment_outputs(module, entry);
    if let Some(extra) = outputs.iter().find(|&&l| l as usize >= raster.targets.len()) {
        return Err(bad(format!(
            "{label}: {entry}'s output @location({extra}) has no target; targets has {} (targets[n] takes @location(n))",
            raster.targets.len()
        )));
    }
    if let Some(n) = (0..raster.targets.len()).find(|n| !outputs.contains(&(*n as u32))) {
        return Err(bad(format!(
            "{label}: targets[{n}] ({}) has no @location({n}) output in {entry}",
            raster.targets[n].texture.resource
        )));
    }
    Ok(())
}

/// A texture that passes read but none writes, no swap exchanges and no
/// file fills holds only zeros: a `bind` left out (the writing pass's
/// variable got an implicit texture of its own), refused naming the
/// resource. (Swapped state starts as zeros on purpose.)
fn check_read_before_written(
    graph: &GraphSpec,
    resources: &[ResolvedResource],
    bad: &dyn Fn(String) -> ParamError,
) -> Result<(), ParamError> {
    let swapped = |name: &str| graph.passes.iter().any(|p| p.swap.iter().any(|(a, b)| a == name || b == name));
    for r in resources {
        if matches!(&r.spec.kind, ResourceKind::Texture { file: None, .. } | ResourceKind::Depth { file: None, .. })
            && r.read
            && !r.written
            && !swapped(&r.spec.name)
        {
            let name = &r.spec.name;
            return Err(bad(format!(
                "resource {name} is read but no pass writes it and it has no file, so it would hold zeros; bind it \
                 in the pass that writes it ({{ <variable> = \"{name}\" }}) or give it a file"
            )));
        }
    }
    Ok(())
}

/// A pass's `bind` may name a global its entry point does not reach (one
/// bind table for several entry points of a file), not one the module
/// lacks.
fn check_bind_declared(
    pass: &PassSpec,
    shader: &str,
    bindings: &[Binding],
    module: &naga::Module,
    label: &str,
    bad: &dyn Fn(String) -> ParamError,
) -> Result<(), ParamError> {
    for (var, _) in &pass.bind {
        let declared = bindings.iter().any(|b| b.named(var))
            || module
                .global_variables
                .iter()
                .any(|(_, g)| g.name.as_deref().map(|n| crate::bindings::undecorate(n).0).as_deref() == Some(var));
        if !declared {
            let reached: Vec<&str> = bindings.iter().map(|b| b.name.as_str()).collect();
            return Err(bad(format!(
                "{label}: bind names {var}, which {shader} does not declare; {} reaches: {}",
                pass.entry,
                reached.join(", ")
            )));
        }
    }
    Ok(())
}

/// Without `[[output]]` tables naming resources the output is the first
/// texture a pass writes; a second texture written and never read makes
/// that a guess, refused naming both.
fn check_default_output(
    graph: &GraphSpec,
    resources: &[ResolvedResource],
    all_slots: &[Vec<PassSlot>],
    bad: &dyn Fn(String) -> ParamError,
) -> Result<(), ParamError> {
    if graph.outputs.iter().any(|o| o.resource.is_some()) {
        return Ok(());
    }
    let mut only_written = (0..resources.len())
        .filter(|&r| resources[r].written && !resources[r].read && kind_of(resources, r) == "texture");
    let (Some(first), Some(second)) = (only_written.next(), only_written.next()) else { return Ok(()) };
    let (i, slot) = all_slots
        .iter()
        .enumerate()
        .find_map(|(i, slots)| {
            slots.iter().find(|s| matches!(s.feed, SlotFeed::Resource(r, _) if r == second)).map(|s| (i, s))
        })
        .expect("a written resource has a slot");
    Err(bad(format!(
        "pass {} ({}): {} (@group({}) @binding({})) is a second output texture after {}; list both as [[output]] \
         tables",
        i + 1,
        graph.passes[i].entry,
        slot.var,
        slot.group,
        slot.binding,
        resources[first].spec.name
    )))
}

/// A storage texture binding's feed: the resource bound to it (an unbound
/// written or read_write variable gets an implicit texture of its own name,
/// which a read_write one finds as zeros), whose format and dimension it
/// fixes and which it marks written or read.
fn storage_slot(
    resources: &mut Vec<ResolvedResource>,
    storage: Storage,
    bound: Option<&str>,
    b: &Binding,
    label: &str,
    described: &str,
    bad: &dyn Fn(String) -> ParamError,
) -> Result<SlotFeed, ParamError> {
    let ri = match bound {
        Some(r) => find(resources, r),
        None if storage.access != Access::Read => {
            // Implicit: one resource per unbound written variable.
            match resources.iter().position(|r| r.spec.name == b.name) {
                Some(ri) => ri,
                None => {
                    resources.push(ResolvedResource {
                        spec: ResourceSpec {
                            name: b.name.clone(),
                            kind: ResourceKind::Texture {
                                format: None,
                                dimension: None,
                                size: None,
                                file: None,
                                mip_levels: 1,
                            },
                        },
                        format: None,
                        dimension: None,
                        element: None,
                        written: false,
                        read: false,
                    });
                    resources.len() - 1
                }
            }
        }
        None => {
            return Err(bad(format!(
                "{label}: {} is fed by nothing; it needs a texture resource ([[resource]] kind = \"texture\", named in this pass's bind)",
                described
            )));
        }
    };
    needs_kind(resources, ri, "texture", label, described, bad)?;
    let r = &mut resources[ri];
    match r.format {
        Some(f) if f != storage.format => {
            return Err(bad(format!(
                "{label}: resource {} has format {f} but is bound to {}; would fit: format = \"{}\"",
                r.spec.name, described, storage.format
            )));
        }
        _ => r.format = Some(storage.format),
    }
    let dim = storage.dimension;
    match r.dimension {
        // A cube's six faces are written through a 2d-array view.
        Some(Dimension::Cube | Dimension::CubeArray) if dim == Dimension::D2Array => {}
        Some(d) if d != dim => {
            return Err(bad(format!(
                "{label}: resource {} has dimension {} but is bound to {}; would fit: dimension = \"{}\"",
                r.spec.name,
                d.name(),
                described,
                dim.name()
            )));
        }
        _ => r.dimension = Some(dim),
    }
    match storage.access {
        Access::Write => r.written = true,
        Access::Read => r.read = true,
        Access::ReadWrite => {
            r.written = true;
            r.read = true;
        }
    }
    Ok(SlotFeed::Resource(ri, Usage::StorageTexture(storage)))
}

/// A sampled texture binding's feed: the resource bound to it, whose
/// dimension it fixes (a cube and its 2d-array of faces agree) and which
/// it marks read.
fn sampled_slot(
    resources: &mut [ResolvedResource],
    dim: Dimension,
    kind: SampledKind,
    bound: Option<&str>,
    label: &str,
    described: &str,
    bad: &dyn Fn(String) -> ParamError,
) -> Result<SlotFeed, ParamError> {
    let Some(rn) = bound else {
        return Err(bad(format!(
            "{label}: {} is fed by nothing; it needs a texture resource ([[resource]] kind = \"texture\" with a file or written by an earlier pass, named in this pass's bind)",
            described
        )));
    };
    let ri = find(resources, rn);
    // A depth resource is sampled as texture_depth_2d, or read as
    // texture_2d<f32> (WebGPU's unfilterable-float view of depth32float).
    if kind_of(resources, ri) == "depth" {
        if !matches!((kind, dim), (SampledKind::Depth | SampledKind::Float, Dimension::D2)) {
            return Err(bad(format!(
                "{label}: {described} is bound to {rn}, a depth texture; it is sampled as texture_depth_2d or \
                 read as texture_2d<f32>"
            )));
        }
        resources[ri].read = true;
        return Ok(SlotFeed::Resource(ri, Usage::Sampled { dim, kind }));
    }
    needs_kind(resources, ri, "texture", label, described, bad)?;
    let r = &mut resources[ri];
    match r.dimension {
        // Six layers sampled as a cube, or a cube read as its 2d-array of faces.
        Some(Dimension::Cube | Dimension::CubeArray) if dim == Dimension::D2Array => {}
        Some(d) if d != dim && !(d == Dimension::D2Array && dim.is_cube()) => {
            return Err(bad(format!(
                "{label}: resource {rn} has dimension {} but is bound to {}; would fit: dimension = \"{}\"",
                d.name(),
                described,
                dim.name()
            )));
        }
        _ => r.dimension = Some(dim),
    }
    r.read = true;
    Ok(SlotFeed::Resource(ri, Usage::Sampled { dim, kind }))
}

/// Resource `ri` is of `kind`, or the error naming the binding.
fn needs_kind(
    resources: &[ResolvedResource],
    ri: usize,
    kind: &str,
    label: &str,
    described: &str,
    bad: &dyn Fn(String) -> ParamError,
) -> Result<(), ParamError> {
    match kind_of(resources, ri) {
        k if k == kind => Ok(()),
        k => {
            Err(bad(format!("{label}: {described} is bound to {}, a {k}; it needs a {kind}", resources[ri].spec.name)))
        }
    }
}

/// Swapped resources are alike; every output names a resource some pass
/// writes (or swaps). Returns the outputs' resources ([`Resolved::outputs`]).
/// An output's resource index with the mip level and layer it reads.
type OutputAt = (usize, (u32, Option<u32>));

fn check_swaps_and_outputs(
    graph: &GraphSpec,
    resources: &[ResolvedResource],
    bad: &dyn Fn(String) -> ParamError,
) -> Result<Vec<OutputAt>, ParamError> {
    for (i, pass) in graph.passes.iter().enumerate() {
        for (a, b) in &pass.swap {
            let (ra, rb) = (
                resources.iter().find(|r| &r.spec.name == a).expect("parsed"),
                resources.iter().find(|r| &r.spec.name == b).expect("parsed"),
            );
            if ra.spec.kind_name() != rb.spec.kind_name() || ra.format != rb.format || ra.dimension != rb.dimension {
                return Err(bad(format!(
                    "pass {} ({}): swap [\"{a}\", \"{b}\"] pairs resources of different kinds, formats or dimensions",
                    i + 1,
                    pass.entry
                )));
            }
        }
    }
    let mut outputs = Vec::new();
    for o in &graph.outputs {
        let Some((name, level, layer)) = o.target() else { continue };
        let Some(ri) = resources.iter().position(|r| r.spec.name == name) else {
            let n: Vec<&str> = resources.iter().map(|r| r.spec.name.as_str()).collect();
            return Err(bad(format!(
                "[[output]] resource = \"{name}\" names no resource; resources: {}",
                n.join(", ")
            )));
        };
        let r = &resources[ri];
        let swapped = graph.passes.iter().any(|p| p.swap.iter().any(|(a, b)| a == name || b == name));
        if r.spec.kind_name() == "sampler" || !(r.written || swapped) {
            return Err(bad(format!(
                "[[output]] resource = \"{name}\" is not written by any pass (a {}); an output is a texture or buffer a pass writes",
                r.spec.kind_name()
            )));
        }
        if let Some(l) = layer
            && !matches!(r.dimension, Some(Dimension::D2Array | Dimension::Cube | Dimension::CubeArray))
        {
            return Err(bad(format!(
                "[[output]] resource = \"{name}@layer{l}\": {name} is not a 2d-array or cube texture; only they have layers"
            )));
        }
        outputs.push((ri, (level, layer)));
    }
    if graph.outputs.iter().all(|o| o.resource.is_none()) {
        // No [[output]] tables, or a lone one without `resource`.
        let first = resources.iter().position(|r| r.written && r.spec.kind_name() == "texture");
        let first =
            first.ok_or_else(|| bad("no pass writes a texture; name the outputs in [[output]] tables".into()))?;
        outputs.push((first, (0, None)));
    }
    Ok(outputs)
}

fn find(resources: &[ResolvedResource], name: &str) -> usize {
    resources.iter().position(|r| r.spec.name == name).expect("parse checks bind")
}

fn kind_of(resources: &[ResolvedResource], r: usize) -> &'static str {
    resources[r].spec.kind_name()
}

/// The element layout of a buffer binding's type.
fn element(module: &naga::Module, var: &naga::GlobalVariable) -> Result<Element, String> {
    use naga::TypeInner as T;
    let ty = &module.types[var.ty].inner;
    let gctx = module.to_ctx();
    let (header, base, stride, fixed) = match ty {
        T::Array { base, size, stride } => (
            0,
            *base,
            *stride,
            match size {
                naga::ArraySize::Constant(n) => Some(n.get()),
                _ => None,
            },
        ),
        T::Struct { members, span } => match members.last().map(|m| (m, &module.types[m.ty].inner)) {
            Some((m, T::Array { base, size: naga::ArraySize::Dynamic, stride })) => (m.offset, *base, *stride, None),
            _ => (0, var.ty, *span, Some(1)),
        },
        _ => (0, var.ty, ty.size(gctx), Some(1)),
    };
    let mut leaves = Vec::new();
    leaves_of(module, base, 0, "", &mut leaves)?;
    Ok(Element { stride, header, fixed, leaves, wgsl: crate::bindings::wgsl_type(module, var) })
}

fn leaves_of(
    module: &naga::Module,
    ty: naga::Handle<naga::Type>,
    offset: u32,
    path: &str,
    out: &mut Vec<(u32, char, String)>,
) -> Result<(), String> {
    use naga::TypeInner as T;
    let kind = |s: &naga::Scalar| match (s.kind, s.width) {
        (naga::ScalarKind::Float, 4) => Ok('f'),
        (naga::ScalarKind::Uint, 4) => Ok('u'),
        (naga::ScalarKind::Sint, 4) => Ok('i'),
        _ => Err(format!(
            "element scalar {:?}{} is not supported; allowed: f32, u32, i32 (and atomics of them)",
            s.kind,
            s.width * 8
        )),
    };
    let name = |suffix: String| {
        if path.is_empty() {
            suffix
        } else if suffix.is_empty() {
            path.to_string()
        } else {
            format!("{path}.{suffix}")
        }
    };
    match &module.types[ty].inner {
        T::Scalar(s) | T::Atomic(s) => out.push((offset, kind(s)?, name(String::new()))),
        T::Vector { size, scalar } => {
            for c in 0..*size as u32 {
                out.push((offset + 4 * c, kind(scalar)?, name(["x", "y", "z", "w"][c as usize].into())));
            }
        }
        T::Matrix { columns, rows, scalar } => {
            let col_stride = if *rows as u32 == 2 { 8 } else { 16 };
            for c in 0..*columns as u32 {
                for r in 0..*rows as u32 {
                    out.push((offset + c * col_stride + 4 * r, kind(scalar)?, name(format!("c{c}r{r}"))));
                }
            }
        }
        T::Array { base, size: naga::ArraySize::Constant(n), stride } => {
            for i in 0..n.get() {
                leaves_of(module, *base, offset + i * stride, &name(format!("{i}")), out)?;
            }
        }
        T::Struct { members, .. } => {
            for m in members {
                let n = m.name.clone().unwrap_or_default();
                leaves_of(module, m.ty, offset + m.offset, &name(n), out)?;
            }
        }
        other => return Err(format!("element type {other:?} is not supported in a buffer")),
    }
    Ok(())
}

/// Every param a graph consumes outside uniforms and overrides: repeat
/// counts, sizes, lengths and workgroup expressions.
pub fn host_params(graph: &GraphSpec) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    let mut exprs: Vec<&Expr> = Vec::new();
    for r in &graph.resources {
        match &r.kind {
            ResourceKind::Texture { size: Some(s), .. } => exprs.extend(s.iter()),
            ResourceKind::Buffer { length: Some(l), .. } => exprs.push(l),
            _ => {}
        }
    }
    for p in &graph.passes {
        if let Repeat::Param(n) = &p.repeat {
            names.push(n);
        }
        exprs.extend(p.workgroups.iter().flatten());
    }
    for e in exprs {
        e.names(&mut names);
    }
    names
}
