//! Kernel manifests (`kernels/<name>.toml`, SPEC 10): a kernel described as
//! data. Parsing validates everything that data can get wrong (unknown keys,
//! types, ranges, defaults, enum values, presets naming unknown params) and
//! names the file, the kernel and the key.
//!
//! ```toml
//! summary = "one line"             # shown by vista list
//! shader = "hybrid.wgsl"           # under shaders/; default "<name>.wgsl"
//! language = "wgsl"                # optional: shader files of any extension (a project's .fx) are WGSL
//! output = "display"               # display | hdr (PNG = 1 - exp(-exposure L), sRGB) | normalize (min..max);
//!                                  # default display, normalize for an integer storage format
//! display_alpha = "keep"           # keep | opaque (PNG alpha = 1; the RGB is already composited)
//! work = ["octaves"]               # product of entries, each `name` or a sum `a + b + 3`
//! output_range = [0.0, 1.0]        # NaN/range guard of the raw RGB (default: display [0, 1], hdr [0, inf))
//! hash_plane = "z_slice"           # optional: every fbm2/ridged2 call samples z = this f32 param
//!                                  # (an integer value gets Perlin's corner hashes for that plane),
//!                                  # or an integer: every such call samples that fixed z
//! specialize = ["basis"]           # optional: enum params fixed when the shader is composed
//!                                  # (naga_oil def BASIS_IS_PERLIN etc.; one pipeline per value)
//! [[resource]]                     # SPEC 14 (graph.rs): textures, buffers, samplers
//! name = "sky"
//! kind = "texture"
//! format = "rgba16float"           # optional; must match the binding
//! dimension = "2d-array"           # 1d | 2d | 2d-array | 3d; must match the binding
//! size = ["width", "width", 6]     # numbers, params, width, height, + - * /, ceil_div(a, b)
//! [[pass]]                         # any number; none: one pass, entry main
//! entry = "bake_faces"             # default main
//! workgroups = [1, 1, 6]           # optional: else the output covered with the reflected size
//! bind = { sky_faces = "sky" }     # WGSL variable -> resource
//! [[output]]                       # any number; none: the texture the pass writes
//! resource = "sky"                 # a resource, or the WGSL variable of the written texture
//! view = "hdr"                     # as output = "..."
//! partial = false                  # true: unwritten texels allowed
//! [[param]]
//! name = "octaves"
//! type = "u32"                     # u32 | i32 | f32 | bool | vec2 | vec3 | vec4 | enum
//! range = [1, 16]                  # inclusive; required for numbers, per component for vectors
//! open_min = false                 # optional: the lower bound is excluded
//! default = 8
//! doc = "number of octaves"
//! [[param]]
//! name = "cloud_profile"
//! type = "enum"
//! values = ["stratiform", "anvil"]  # WGSL gets their indices as u32
//! constants = "PROFILE"            # optional: `vista::enums` then has PROFILE_STRATIFORM = 0u,
//!                                  # PROFILE_ANVIL = 1u (default prefix: the name, upper case)
//! default = "anvil"
//! [[group]]                        # optional: params filling a nested struct of the uniform
//! field = "cloud"                  # the struct-typed field
//! prefix = "cloud_"                # its leaf x is fed by param cloud_x if there is one, else by x
//! rename = { forward_g = "g1" }    # optional: leaf forward_g is param (cloud_)g1
//! [sweep_reference]                # optional: the high-quality settings sweeps compare against
//! octaves = 16
//! [preset.rough]                   # presets override defaults; `default` (the defaults) always resolves
//! doc = "what it shows"            # optional
//! octaves = 12
//! ```

use serde::Deserialize;

use crate::params::{Kind, ParamSpec, ParamType, Preset, parse_value};
use crate::values::{parse_defs, value_text};
use crate::{Output, ParamError};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawManifest {
    summary: String,
    shader: Option<String>,
    /// `language = "wgsl"`: the kernel's shader files are WGSL whatever
    /// their extension (a project's `.fx`, `.shader`).
    language: Option<String>,
    /// `output = "display" | "hdr"` (SPEC 10), or `[[output]]` tables (SPEC 14).
    output: Option<toml::Value>,
    /// Deserialized for its keys only; graph.rs reads the values.
    #[serde(default, rename = "pass")]
    #[allow(dead_code)]
    passes: Vec<RawPass>,
    /// `[[resource]]` tables (SPEC 14), read by graph.rs.
    #[serde(default, rename = "resource")]
    resources: Vec<toml::Value>,
    /// `false`: no render-twice check; every output needs a tolerance.
    deterministic: Option<bool>,
    /// naga_oil shader defs: bool or integer values.
    #[serde(default)]
    defs: toml::Table,
    /// How the shader's text is assembled (SPEC 16).
    source: Option<toml::Table>,
    /// Values of the shader's pipeline-overridable constants.
    #[serde(default)]
    overrides: toml::Table,
    display_alpha: Option<String>,
    #[serde(default)]
    work: Vec<String>,
    #[serde(default, deserialize_with = "min_max")]
    output_range: Option<[f64; 2]>,
    hash_plane: Option<toml::Value>,
    #[serde(default)]
    specialize: Vec<String>,
    #[serde(default, rename = "param")]
    params: Vec<RawParam>,
    /// `[[group]]` tables: params that fill a nested struct of the uniform.
    #[serde(default, rename = "group")]
    groups: Vec<RawGroup>,
    #[serde(default)]
    sweep_reference: toml::Table,
    /// Ordered as written (toml's `preserve_order`), which `vista list` keeps.
    #[serde(default)]
    preset: toml::Table,
}

/// A `[[pass]]` table: its keys checked here, their values by graph.rs,
/// which reads them from the TOML.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct RawPass {
    kind: Option<toml::Value>,
    entry: Option<String>,
    vertex: Option<toml::Value>,
    fragment: Option<toml::Value>,
    targets: Option<toml::Value>,
    vertices: Option<toml::Value>,
    indices: Option<toml::Value>,
    count: Option<toml::Value>,
    instances: Option<toml::Value>,
    first_vertex: Option<toml::Value>,
    first_instance: Option<toml::Value>,
    base_vertex: Option<toml::Value>,
    topology: Option<toml::Value>,
    cull: Option<toml::Value>,
    depth: Option<toml::Value>,
    workgroups: Option<Vec<toml::Value>>,
    /// WGSL variable name -> resource name.
    bind: Option<toml::Table>,
    shader: Option<toml::Value>,
    /// Per-pass shader defs and source keys (read by graph.rs).
    defs: Option<toml::Value>,
    source: Option<toml::Value>,
    dispatch: Option<toml::Value>,
    set: Option<toml::Value>,
    repeat: Option<toml::Value>,
    swap: Option<toml::Value>,
    group: Option<toml::Value>,
}

/// An `[[output]]` table.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)] // the values are read by graph.rs
struct RawOutput {
    resource: Option<String>,
    view: Option<String>,
    #[serde(default)]
    partial: bool,
    tolerance: Option<toml::Value>,
    /// The hdr view's exposure (default 1; an `exposure` param wins).
    exposure: Option<f64>,
}

/// `[min, max]`: exactly two numbers (serde's fixed-size arrays took the
/// first two of `[1, 64, 3]` and dropped the rest).
fn min_max<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
    let v: Vec<f64> = Vec::deserialize(d)?;
    match v.as_slice() {
        &[lo, hi] => Ok(Some([lo, hi])),
        other => Err(serde::de::Error::custom(format!("{} numbers where [min, max] takes two", other.len()))),
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawParam {
    name: String,
    #[serde(rename = "type")]
    ty: String,
    #[serde(default, deserialize_with = "min_max")]
    range: Option<[f64; 2]>,
    #[serde(default)]
    open_min: bool,
    values: Option<Vec<String>>,
    /// An enum's WGSL constant prefix (default: the name in upper case).
    constants: Option<String>,
    /// An enum's values that set a shader def: value -> def name.
    defs: Option<toml::Table>,
    default: toml::Value,
    #[serde(default)]
    doc: String,
}

/// A `[[group]]` table.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGroup {
    field: String,
    #[serde(default)]
    prefix: String,
    #[serde(default)]
    rename: toml::Table,
}

/// A group of params filling one struct-typed field of the uniform
/// (`[[group]] field = "cloud"`, `prefix = "cloud_"`): the field's leaf
/// `x` is fed by param `<prefix>x` when the manifest has one, else by `x`;
/// `rename = { forward_g = "g1" }` first gives leaf `forward_g` the name `g1`.
/// Two kernels with differently named params can so fill one WGSL struct,
/// and their CPU references one Rust constructor ([`ParamGroup::param`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ParamGroup {
    /// The uniform's struct-typed field (its path below the variable).
    pub field: String,
    /// Prepended to a leaf's name to find its param first.
    pub prefix: String,
    /// Leaf name -> the name its param has in place of it (before the prefix).
    pub rename: Vec<(String, String)>,
}

impl ParamGroup {
    /// The param that feeds the group's leaf `leaf`, given the params a
    /// kernel has: `<prefix><leaf>` if it is one of them, else `leaf`.
    pub fn param(&self, leaf: &str, has: impl Fn(&str) -> bool) -> String {
        let leaf = self.rename.iter().find(|(l, _)| l == leaf).map_or(leaf, |(_, n)| n.as_str());
        let prefixed = format!("{}{leaf}", self.prefix);
        match !self.prefix.is_empty() && has(&prefixed) {
            true => prefixed,
            false => leaf.to_string(),
        }
    }
}

/// One factor of the work estimate: a sum of params and constants.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkFactor {
    /// The number params summed into this factor.
    pub params: Vec<String>,
    /// The sum of the factor's constant terms.
    pub constant: f64,
}

/// Where a kernel's fbm2/ridged2 calls sample z (manifest `hash_plane`).
#[derive(Debug, Clone, PartialEq)]
pub enum HashPlane {
    /// At this f32 param's value: a hash plane when it is an integer.
    Param(String),
    /// Always at this integer z (the terrains' height field, z = 0).
    Fixed(i64),
}

/// A parsed, validated manifest; it owns everything it holds.
#[derive(Debug, Clone)]
pub struct Manifest {
    /// The kernel's name: the manifest's file stem.
    pub name: String,
    /// One line for `vista list` (`summary`).
    pub summary: String,
    /// The WGSL file under `shaders/` (`shader`; default `<name>.wgsl`).
    pub shader: String,
    /// `language = "wgsl"`: its shader files are WGSL whatever their
    /// extension.
    pub language: Option<String>,
    /// The PNG view, where the manifest gives one (else display, or
    /// normalize for an integer format: `Kernel::view`).
    pub output: Option<Output>,
    /// `display_alpha = "opaque"`: display alpha is forced to 1 (the RGB is already composited).
    pub opaque_display: bool,
    /// The pass graph (SPEC 14): resources, passes, outputs. A manifest
    /// without those tables is one pass (`main`) writing one texture.
    pub graph: crate::graph::GraphSpec,
    /// The manifest has `[[pass]]`, `[[resource]]` or `[[output]]` tables
    /// (SPEC 14): it describes its own resources instead of following the
    /// seed's contract.
    pub describes_resources: bool,
    /// naga_oil shader defs (`defs = { MAX_LIGHTS = 10, FIRST_PASS = true }`),
    /// as `NAME=value` in declaration order.
    pub defs: Vec<String>,
    /// The kernel's `[source]`: how its shaders' text is assembled (a
    /// pass's `source` merges over it).
    pub source: vista_source::SourceSpec,
    /// Values of `override` constants (`overrides = { BLOCK = 128 }`); a
    /// param of an override's name feeds it too, and wins.
    pub overrides: Vec<(String, f64)>,
    /// The work estimate per pixel: the product of these factors (`work`).
    pub work: Vec<WorkFactor>,
    /// Inclusive bounds of every raw RGB value (`output_range`); `None`: by the
    /// view (display [0, 1], hdr [0, inf)).
    pub output_range: Option<(f64, f64)>,
    /// The z every fbm2/ridged2 call of the shader takes.
    pub hash_plane: Option<HashPlane>,
    /// Enum params whose value is a shader def (`NAME_IS_VALUE`, upper case)
    /// rather than only a uniform, so the shader can drop the other cases
    /// at composition.
    pub specialize: Vec<String>,
    /// The declared parameters (`[[param]]`), in manifest order.
    pub params: Vec<ParamSpec>,
    /// Every enum value as a WGSL constant (`PREFIX_VALUE`, its index):
    /// the module `vista::enums` the kernel's WGSL imports them from.
    pub enum_constants: Vec<(String, u32)>,
    /// `[[group]]` tables: params filling a nested struct of the uniform.
    pub groups: Vec<ParamGroup>,
    /// The presets (`[preset.NAME]`), in manifest order.
    pub presets: Vec<Preset>,
    /// `[sweep_reference]`: the params (values as text) of the high-quality
    /// reference that sweeps compare against.
    pub sweep_reference: Vec<(String, String)>,
}

/// A name as a WGSL constant's part: upper case, any other character `_`
/// (`cumuliform` -> `CUMULIFORM`, `cloud_layer` -> `CLOUD_LAYER`).
pub fn constant_name(s: &str) -> String {
    s.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_uppercase() } else { '_' }).collect()
}

/// Reserved names: the image size fields of every `Params` struct, and the
/// preset table's doc key.
const RESERVED: &[&str] = &["width", "height", "doc"];

/// Parses `kernels/<name>.toml`. `origin` (a path, or `<built-in>/...`)
/// prefixes every error, with line and column for TOML errors.
pub fn parse(name: &str, origin: &str, text: &str) -> Result<Manifest, ParamError> {
    let fail = |message: String| ParamError::Manifest { file: origin.to_string(), message };
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
        return Err(fail(format!("kernel name '{name}' must use only letters, digits, '-' and '_'")));
    }
    let raw: RawManifest = toml::from_str(text).map_err(|e| fail(vista_project::one_line_toml_error(text, &e)))?;
    let kfail = |message: String| fail(format!("kernel {name}: {message}"));
    // The graph parser reads the tables as TOML (their keys were checked above).
    let doc: toml::Table = toml::from_str(text).map_err(|e| fail(vista_project::one_line_toml_error(text, &e)))?;
    let tables = |k: &str| doc.get(k).and_then(|v| v.as_array()).cloned().unwrap_or_default();
    let (pass_tables, output_tables) = (tables("pass"), tables("output"));
    let describes_resources = !pass_tables.is_empty() || !raw.resources.is_empty() || !output_tables.is_empty();
    let output = parse_view(raw.output.as_ref(), &kfail)?;
    let opaque_display = match raw.display_alpha.as_deref() {
        None | Some("keep") => false,
        Some("opaque") => true,
        Some(other) => return Err(kfail(format!("display_alpha = \"{other}\" is not valid; expected keep|opaque"))),
    };

    let (params, enum_constants) = parse_params(&raw.params, &kfail)?;
    let (presets, sweep_reference) = parse_presets(&raw.preset, &raw.sweep_reference, &params, &kfail)?;

    let work = parse_work(&raw.work, &params, &kfail)?;
    if let Some([lo, hi]) = raw.output_range
        && (lo.is_nan() || hi.is_nan() || lo > hi)
    {
        return Err(kfail(format!("output_range = [{lo}, {hi}] is not valid; expected min <= max")));
    }
    if let Some(p) = params.iter().find(|p| p.name == "exposure")
        && output == Some(Output::Hdr)
        && !matches!(p.kind, Kind::Float { .. })
    {
        return Err(kfail("param exposure sets the hdr view's tone map; it must be an f32".into()));
    }
    let hash_plane = match &raw.hash_plane {
        None => None,
        Some(toml::Value::Integer(z)) => Some(HashPlane::Fixed(*z)),
        Some(v) => match params.iter().find(|p| v.as_str() == Some(p.name.as_str())) {
            Some(p) if matches!(p.kind, Kind::Float { .. }) => Some(HashPlane::Param(p.name.clone())),
            _ => return Err(kfail(format!("hash_plane = {v} must name an f32 param or be an integer z"))),
        },
    };
    let mut specialize: Vec<String> = Vec::new();
    for n in &raw.specialize {
        match params.iter().find(|p| &p.name == n) {
            Some(p) if matches!(p.kind, Kind::Enum(_)) && !specialize.contains(&p.name) => {
                specialize.push(p.name.clone())
            }
            Some(p) if matches!(p.kind, Kind::Enum(_)) => {
                return Err(kfail(format!("specialize lists \"{n}\" twice")));
            }
            _ => return Err(kfail(format!("specialize = [\"{n}\"]: \"{n}\" must name an enum param"))),
        }
    }
    let graph =
        crate::graph::parse(&raw.resources, &pass_tables, &output_tables, raw.deterministic, output, &params, &kfail)?;
    let defs = parse_defs(&raw.defs).map_err(kfail)?;
    let source = match &raw.source {
        Some(t) => vista_source::SourceSpec::parse(t).map_err(kfail)?,
        None => Default::default(),
    };
    let overrides = parse_overrides(&raw.overrides).map_err(kfail)?;
    let groups = parse_groups(&raw.groups, &kfail)?;
    let pass_sources = graph.passes.iter().map(|p| &p.source);
    check_replacements(std::iter::once(&source).chain(pass_sources), &params).map_err(kfail)?;
    let shader = raw.shader.unwrap_or_else(|| format!("{name}.wgsl"));
    let language = match raw.language.as_deref() {
        None | Some("wgsl") => raw.language,
        Some(other) => {
            return Err(kfail(format!(
                "language = \"{other}\" is not known; allowed: \"wgsl\" (a shader file of any extension read as WGSL)"
            )));
        }
    };
    let files = std::iter::once(&shader).chain(graph.passes.iter().filter_map(|p| p.shader.as_ref()));
    for f in files {
        let known = f.ends_with(".wgsl") || f.ends_with(".wesl");
        // A command's output is WGSL whatever its template is called.
        let generated = source.command.is_some() || graph.passes.iter().any(|p| p.source.command.is_some());
        if !known && language.is_none() && !generated {
            return Err(kfail(format!(
                "shader \"{f}\" is not a .wgsl or .wesl file; add language = \"wgsl\" to read it as WGSL"
            )));
        }
        if f.ends_with(".wesl") && language.is_some() {
            return Err(kfail(format!("shader \"{f}\" is WESL; language = \"wgsl\" is for other extensions")));
        }
    }
    Ok(Manifest {
        name: name.to_string(),
        summary: raw.summary,
        shader,
        language,
        output,
        opaque_display,
        graph,
        describes_resources,
        defs,
        source,
        overrides,
        work,
        output_range: raw.output_range.map(|[a, b]| (a, b)),
        hash_plane,
        specialize,
        params,
        enum_constants,
        groups,
        presets,
        sweep_reference,
    })
}

/// The manifest's view: `output = "display"|"hdr"|"normalize"`; `None`
/// for `[[output]]` tables (their keys checked here, their values by
/// `graph.rs`) or no `output`.
fn parse_view(
    output: Option<&toml::Value>,
    kfail: &dyn Fn(String) -> ParamError,
) -> Result<Option<Output>, ParamError> {
    match output {
        None => Ok(None),
        Some(toml::Value::Array(tables)) => {
            for t in tables {
                RawOutput::deserialize(t.clone()).map_err(|e| kfail(format!("[[output]]: {e}")))?;
            }
            Ok(None)
        }
        Some(toml::Value::String(s)) => match s.as_str() {
            "display" => Ok(Some(Output::Display)),
            "hdr" => Ok(Some(Output::Hdr)),
            "normalize" => Ok(Some(Output::Normalize)),
            other => Err(kfail(format!("output view \"{other}\" is not valid; expected display|hdr|normalize"))),
        },
        Some(other) => {
            Err(kfail(format!("output = {other} is not valid; expected \"display\", \"hdr\" or [[output]] tables")))
        }
    }
}

/// Each enum value's WGSL constant name and index.
type EnumConstants = Vec<(String, u32)>;
/// Param values by name, as written (`sweep_reference`, a preset's).
type Settings = Vec<(String, String)>;

/// The `[[param]]` tables: each param's type, range, default and doc, and
/// the WGSL constants of the enum values (`PREFIX_VALUE`), every value and
/// name checked; errors name the param.
fn parse_params(
    raw: &[RawParam],
    kfail: &dyn Fn(String) -> ParamError,
) -> Result<(Vec<ParamSpec>, EnumConstants), ParamError> {
    let mut params: Vec<ParamSpec> = Vec::new();
    let mut enum_constants: Vec<(String, u32)> = Vec::new();
    for p in raw {
        let pfail = |message: String| kfail(format!("param {}: {message}", p.name));
        let ident = |w: &str| !w.is_empty() && w.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        // `module::path::variable.path`: the module's path, then the name.
        let (module, local) = p.name.rsplit_once("::").unwrap_or(("", &p.name));
        if !local.split('.').all(ident) || !(module.is_empty() || module.split("::").all(ident)) {
            return Err(pfail(
                "a name is a WGSL field name, variable.path or module::path::variable.path (letters, digits and \
                 '_' between dots)"
                    .into(),
            ));
        }
        if RESERVED.contains(&p.name.as_str()) {
            return Err(pfail(format!("'{}' is reserved (width and height are the image size)", p.name)));
        }
        if params.iter().any(|q| q.name == p.name) {
            return Err(pfail("declared twice".into()));
        }
        let ty = ParamType::from_name(&p.ty).ok_or_else(|| {
            pfail(format!(
                "type = \"{}\" is not valid; expected u32|i32|f32|bool|vec2|vec3|vec4|enum or a WGSL leaf type \
                 (vec2<u32>, vec3i, mat4x4<f32>, array<vec4<f32>, 4>, ...)",
                p.ty
            ))
        })?;
        let kind = param_kind(p, &ty, &pfail)?;
        if p.values.is_some() && ty != ParamType::Enum {
            return Err(pfail(format!("values is only for type enum, not {}", p.ty)));
        }
        if let Kind::Enum(values) = &kind {
            let prefix = match &p.constants {
                Some(c)
                    if c.starts_with(|c: char| c.is_ascii_uppercase())
                        && c.chars().all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_') =>
                {
                    c.clone()
                }
                Some(c) => {
                    return Err(pfail(format!(
                        "constants = \"{c}\" is not a WGSL constant prefix; allowed: upper-case letters, digits \
                         and '_', starting with a letter"
                    )));
                }
                None => constant_name(&p.name),
            };
            for (i, v) in values.iter().enumerate() {
                let name = format!("{prefix}_{}", constant_name(v));
                match enum_constants.iter().find(|(n, _)| *n == name) {
                    Some((_, j)) if *j != i as u32 => {
                        return Err(pfail(format!(
                            "WGSL constant {name} would be {i} here but {j} for an earlier enum; give one of \
                             them other constants = \"...\""
                        )));
                    }
                    Some(_) => {}
                    None => enum_constants.push((name, i as u32)),
                }
            }
        } else if p.constants.is_some() {
            return Err(pfail(format!("constants is only for type enum, not {}", p.ty)));
        }
        if p.open_min && !matches!(ty, ParamType::F32) {
            return Err(pfail("open_min is only for type f32".into()));
        }
        let defs = param_defs(p, &kind, &pfail)?;
        let spec =
            ParamSpec { name: p.name.clone(), ty, kind, default: value_text(&p.default), doc: p.doc.clone(), defs };
        parse_value(&spec, &spec.default).map_err(|e| pfail(format!("default: {e}")))?;
        params.push(spec);
    }
    Ok((params, enum_constants))
}

/// What param `p` of type `ty` holds: its range checked against what the
/// type holds, or its enum values.
fn param_kind(p: &RawParam, ty: &ParamType, pfail: &dyn Fn(String) -> ParamError) -> Result<Kind, ParamError> {
    let range = |limits: (f64, f64)| -> Result<(f64, f64), ParamError> {
        let [lo, hi] = p.range.ok_or_else(|| pfail(format!("type {} needs range = [min, max]", p.ty)))?;
        if !(lo.is_finite() && hi.is_finite()) || lo > hi {
            return Err(pfail(format!("range = [{lo}, {hi}] is not valid; expected finite min <= max")));
        }
        if lo < limits.0 || hi > limits.1 {
            return Err(pfail(format!(
                "range = [{lo}, {hi}] exceeds what {} holds: [{}, {}]",
                p.ty, limits.0, limits.1
            )));
        }
        Ok((lo, hi))
    };
    let no_range = |what: &str| -> Result<(), ParamError> {
        match p.range {
            Some(_) => Err(pfail(format!("type {what} takes no range"))),
            None => Ok(()),
        }
    };
    let int = |r: (f64, f64)| -> Result<(i64, i64), ParamError> {
        if r.0.fract() != 0.0 || r.1.fract() != 0.0 {
            return Err(pfail(format!("range = [{}, {}] of an integer type must be whole numbers", r.0, r.1)));
        }
        Ok((r.0 as i64, r.1 as i64))
    };
    Ok(match ty {
        ParamType::U32 => {
            let (min, max) = int(range((0.0, u32::MAX as f64))?)?;
            Kind::Int { min, max }
        }
        ParamType::I32 => {
            let (min, max) = int(range((i32::MIN as f64, i32::MAX as f64))?)?;
            Kind::Int { min, max }
        }
        ParamType::F32 => {
            let (min, max) = range((-f32::MAX as f64, f32::MAX as f64))?;
            Kind::Float { min, max, open_min: p.open_min }
        }
        ParamType::Vec(n) => {
            let (min, max) = range((-f32::MAX as f64, f32::MAX as f64))?;
            Kind::Vector { n: *n as usize, min, max }
        }
        ParamType::Wgsl(leaf) => match leaf.scalar {
            crate::params::Scalar::F32 => {
                let (min, max) = range((-f32::MAX as f64, f32::MAX as f64))?;
                Kind::Vector { n: leaf.count, min, max }
            }
            crate::params::Scalar::U32 => {
                let (min, max) = int(range((0.0, u32::MAX as f64))?)?;
                Kind::IntVector { n: leaf.count, min, max }
            }
            crate::params::Scalar::I32 => {
                let (min, max) = int(range((i32::MIN as f64, i32::MAX as f64))?)?;
                Kind::IntVector { n: leaf.count, min, max }
            }
        },
        ParamType::Bool => {
            no_range("bool")?;
            Kind::Bool
        }
        ParamType::Enum => {
            no_range("enum")?;
            let values = p.values.as_ref().filter(|v| !v.is_empty()).ok_or_else(|| {
                pfail("type enum needs values = [\"a\", \"b\", ...] (WGSL receives the index as u32)".into())
            })?;
            for (i, v) in values.iter().enumerate() {
                if v.is_empty() || values[..i].contains(v) {
                    return Err(pfail(format!("values: '{v}' is empty or repeated")));
                }
            }
            Kind::Enum(values.clone())
        }
    })
}

/// An enum param's `defs`: each value's shader def, checked.
fn param_defs(
    p: &RawParam,
    kind: &Kind,
    pfail: &dyn Fn(String) -> ParamError,
) -> Result<Vec<(String, String)>, ParamError> {
    let ident = |w: &str| !w.is_empty() && w.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    Ok(match (&p.defs, kind) {
        (None, _) => Vec::new(),
        (Some(table), Kind::Enum(values)) => {
            let mut defs = Vec::new();
            for (value, def) in table {
                if !values.contains(value) {
                    return Err(pfail(format!("defs: '{value}' is not one of its values ({})", values.join(", "))));
                }
                match def.as_str() {
                    Some(d) if ident(d) && !d.starts_with(|c: char| c.is_ascii_digit()) => {
                        defs.push((value.clone(), d.to_string()))
                    }
                    _ => {
                        return Err(pfail(format!(
                            "defs: {value} = {def} is not a shader def name (letters, digits and '_')"
                        )));
                    }
                }
            }
            defs
        }
        (Some(_), _) => return Err(pfail(format!("defs is only for type enum, not {}", p.ty))),
    })
}

/// The `[preset.<name>]` tables and `[sweep_reference]`: every value
/// parsed against its param; an unknown param is named.
fn parse_presets(
    preset: &toml::Table,
    sweep: &toml::Table,
    params: &[ParamSpec],
    kfail: &dyn Fn(String) -> ParamError,
) -> Result<(Vec<Preset>, Settings), ParamError> {
    let find = |pname: &str, context: &str| find_param(params, pname, context, kfail);
    let settings = |table: &toml::Table, context: &str| -> Result<Vec<(String, String)>, ParamError> {
        let mut out = Vec::new();
        for (k, v) in table {
            let spec = find(k, context)?;
            let text = value_text(v);
            parse_value(spec, &text).map_err(|e| kfail(format!("{context}: {e}")))?;
            out.push((spec.name.clone(), text));
        }
        Ok(out)
    };

    let mut presets = Vec::new();
    for (pname, table) in preset {
        // A name is printed in lists and errors: letters, digits, '-' and '_' only.
        if pname.is_empty() || !pname.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
            return Err(kfail(format!("preset '{}' must use only letters, digits, '-' and '_'", pname.escape_debug())));
        }
        let Some(mut table) = table.as_table().cloned() else {
            return Err(kfail(format!("preset {pname} must be a table ([preset.{pname}] with name = value lines)")));
        };
        let doc = match table.remove("doc") {
            None => String::new(),
            Some(toml::Value::String(s)) => s,
            Some(other) => return Err(kfail(format!("preset {pname}: doc = {other} must be a string"))),
        };
        let set = settings(&table, &format!("preset {pname}"))?;
        presets.push(Preset { name: pname.clone(), doc, set });
    }
    let sweep_reference = settings(sweep, "sweep_reference")?;
    Ok((presets, sweep_reference))
}

/// The `work` entries: sums of number params and constants, multiplied.
fn parse_work(
    entries: &[String],
    params: &[ParamSpec],
    kfail: &dyn Fn(String) -> ParamError,
) -> Result<Vec<WorkFactor>, ParamError> {
    let mut work = Vec::new();
    for entry in entries {
        let mut factor = WorkFactor { params: Vec::new(), constant: 0.0 };
        for term in entry.split('+').map(str::trim) {
            if let Ok(c) = term.parse::<f64>() {
                factor.constant += c;
                continue;
            }
            let spec = find_param(params, term, &format!("work entry \"{entry}\""), kfail)?;
            if !matches!(spec.kind, Kind::Int { .. } | Kind::Float { .. }) {
                return Err(kfail(format!("work entry \"{entry}\": '{term}' is not a number param")));
            }
            factor.params.push(spec.name.clone());
        }
        work.push(factor);
    }
    Ok(work)
}

/// The param named `pname`, or an error naming `context` and the params.
fn find_param<'p>(
    params: &'p [ParamSpec],
    pname: &str,
    context: &str,
    kfail: &dyn Fn(String) -> ParamError,
) -> Result<&'p ParamSpec, ParamError> {
    params.iter().find(|s| s.name == pname).ok_or_else(|| {
        kfail(format!(
            "{context} names unknown param '{pname}'; valid params: {}",
            params.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")
        ))
    })
}

/// The `[[group]]` tables: a struct-typed uniform field, the prefix and
/// renames of the params that fill its leaves.
fn parse_groups(raw: &[RawGroup], kfail: &dyn Fn(String) -> ParamError) -> Result<Vec<ParamGroup>, ParamError> {
    let mut groups: Vec<ParamGroup> = Vec::new();
    for g in raw {
        let ident = |w: &str| !w.is_empty() && w.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !g.field.split('.').all(ident) {
            return Err(kfail(format!(
                "[[group]] field = \"{}\" is not a uniform field path (letters, digits and '_' between dots)",
                g.field
            )));
        }
        if !g.prefix.is_empty() && !ident(&g.prefix) {
            return Err(kfail(format!("[[group]] prefix = \"{}\" is not valid; letters, digits and '_'", g.prefix)));
        }
        if groups.iter().any(|h| h.field == g.field) {
            return Err(kfail(format!("[[group]] field = \"{}\" is listed twice", g.field)));
        }
        let mut rename = Vec::new();
        for (leaf, name) in &g.rename {
            match name.as_str() {
                Some(n) if ident(leaf) && ident(n) => rename.push((leaf.clone(), n.to_string())),
                _ => {
                    return Err(kfail(format!(
                        "[[group]] rename: {leaf} = {name} is not valid; expected leaf = \"param_name\" (letters, \
                         digits and '_')"
                    )));
                }
            }
        }
        groups.push(ParamGroup { field: g.field.clone(), prefix: g.prefix.clone(), rename });
    }
    Ok(groups)
}

/// The `overrides` table: each pipeline-overridable constant's value.
fn parse_overrides(table: &toml::Table) -> Result<Vec<(String, f64)>, String> {
    let mut overrides = Vec::new();
    for (k, v) in table {
        let value = match v {
            toml::Value::Boolean(b) => *b as u8 as f64,
            toml::Value::Integer(i) => *i as f64,
            toml::Value::Float(f) if f.is_finite() => *f,
            other => {
                return Err(format!("overrides: {k} = {other} is not valid; expected a number or a bool"));
            }
        };
        overrides.push((k.clone(), value));
    }
    Ok(overrides)
}

/// A replacement's param gives text: an enum's value name or a number's.
fn check_replacements<'s>(
    sources: impl Iterator<Item = &'s vista_source::SourceSpec>,
    params: &[ParamSpec],
) -> Result<(), String> {
    for p in sources.flat_map(|s| s.params()) {
        match params.iter().find(|s| s.name == p).map(|s| &s.ty) {
            Some(ParamType::Enum | ParamType::U32 | ParamType::I32 | ParamType::F32) => {}
            Some(other) => {
                return Err(format!(
                    "[source] replace: param {p} is {}; a replacement takes an enum or a number (u32, i32, f32)",
                    other.name()
                ));
            }
            None => {
                let names: Vec<&str> = params.iter().map(|s| s.name.as_str()).collect();
                return Err(format!(
                    "[source] replace: {{ param = \"{p}\" }} names no param; params: {}",
                    if names.is_empty() { "none".into() } else { names.join(", ") }
                ));
            }
        }
    }
    Ok(())
}
