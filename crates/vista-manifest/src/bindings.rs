//! Every global an entry point reaches, from naga's reflection of the
//! composed module, and what feeds it. So far vista feeds three kinds: the
//! uniform blocks (params), the read-only u32 table (Perlin's permutation)
//! and one written storage texture (the output: 1d, 2d, 2d-array or 3d,
//! write or read_write), each at whatever
//! group and binding the kernel declares. Any other reached global is
//! refused before GPU work, naming the entry point, the variable, its
//! group/binding and WGSL type, and which resource kind would feed it.

use naga::{AddressSpace, Handle, ImageClass, ImageDimension, ScalarKind, StorageAccess, TypeInner};

use crate::ParamError;
use vista_texel::{Access, Dimension};

/// What feeds a binding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feed {
    /// The params, packed by name (`var<uniform>` of a struct).
    Uniform,
    /// The u32 table (`var<storage, read>` of `array<u32>`).
    Table,
    /// The output: a write or read_write storage texture.
    Output(Storage),
    /// A read-only storage texture (pass graphs only).
    StorageRead(Storage),
    /// A storage buffer other than the table (pass graphs only).
    Buffer {
        /// `var<storage, read>` (else `read_write`).
        read_only: bool,
    },
    /// A sampled texture (pass graphs only).
    Sampled {
        /// The texture's dimension.
        dim: vista_texel::Dimension,
        /// What sampling it returns.
        kind: SampledKind,
    },
    /// A sampler (pass graphs only).
    Sampler {
        /// A `sampler_comparison` (else a filtering `sampler`).
        comparison: bool,
    },
}

/// One binding the entry point reaches.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Binding {
    /// The binding's `@group`.
    pub group: u32,
    /// The binding's `@binding` within its group.
    pub binding: u32,
    /// The WGSL variable name.
    pub name: String,
    /// The import path of the module that declares it (`None`: the pass's
    /// own file), so a `bind` key may name it by path
    /// (`"package::post::lut_bindings::lut"`).
    pub module: Option<String>,
    /// What feeds it.
    pub feed: Feed,
    /// A render pass's vertex entry reaches it (it is visible to the
    /// vertex stage as well as the fragment stage).
    pub vertex: bool,
    pub(crate) global: Handle<naga::GlobalVariable>,
    /// `global` is a variable of the pass's vertex file, not its shader.
    pub(crate) in_vertex_file: bool,
}

/// A storage texture binding as WGSL declares it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Storage {
    /// Its texel format, one of [`vista_texel::format_names`].
    pub format: &'static str,
    /// Its dimension.
    pub dimension: Dimension,
    /// How the pass may use it.
    pub access: Access,
}

/// What a sampled texture binding returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampledKind {
    /// `texture_*<f32>`: sampling returns floats.
    Float,
    /// `texture_*<u32>`: sampling returns unsigned integers.
    Uint,
    /// `texture_*<i32>`: sampling returns signed integers.
    Sint,
    /// `texture_depth_*`: a depth texture.
    Depth,
}

/// `name` as one of vista-texel's formats, or the error listing them.
pub(crate) fn storage_format(name: &str) -> Result<&'static str, String> {
    vista_texel::Format::parse(name).map(|f| f.name).map_err(|_| {
        format!("format = \"{name}\" is not valid; expected one of {}", vista_texel::format_names().join(", "))
    })
}

/// A storage texture's format, where WebGPU's core lets one have it.
fn format_name(f: naga::StorageFormat) -> Option<&'static str> {
    vista_texel::Format::of_naga(f).filter(|f| f.is_storable()).map(|f| f.name)
}

impl Binding {
    /// Whether a `bind` key names this variable: by its name, or by its
    /// module's import path and its name (`package::post::lut_bindings::lut`,
    /// `mylib::camera::frame`).
    pub fn named(&self, key: &str) -> bool {
        names(key, &self.name, self.module.as_deref())
    }
}

/// Whether a `bind` key names variable `name` of the module at import path
/// `module`: by its name, or by the path and its name.
pub fn names(key: &str, name: &str, module: Option<&str>) -> bool {
    key == name || module.is_some_and(|m| key.strip_prefix(m).and_then(|r| r.strip_prefix("::")) == Some(name))
}

/// A name as its declaring module spells it, and that module's import
/// path where naga_oil decorated it (`frameX_naga_oil_mod_X<base32>X`:
/// an item of an imported module).
pub fn undecorate(name: &str) -> (String, Option<String>) {
    vista_source::undecorate(name)
}

/// The entry point `entry` of `stage` in `module`.
fn entry_point<'m>(module: &'m naga::Module, entry: &str, stage: naga::ShaderStage) -> Option<&'m naga::EntryPoint> {
    module.entry_points.iter().find(|e| e.name == entry && e.stage == stage)
}

/// WGSL's word for a stage.
fn stage_name(stage: naga::ShaderStage) -> &'static str {
    match stage {
        naga::ShaderStage::Fragment => "fragment",
        naga::ShaderStage::Vertex => "vertex",
        _ => "compute",
    }
}

/// The `@location(n)` outputs of fragment entry `entry`, ascending (a
/// struct's members or a single result).
pub fn fragment_outputs(module: &naga::Module, entry: &str) -> Vec<u32> {
    let Some(ep) = entry_point(module, entry, naga::ShaderStage::Fragment) else { return Vec::new() };
    let Some(result) = &ep.function.result else { return Vec::new() };
    let location = |b: &Option<naga::Binding>| match b {
        Some(naga::Binding::Location { location, .. }) => Some(*location),
        _ => None,
    };
    let mut out: Vec<u32> = match (&result.binding, &module.types[result.ty].inner) {
        (Some(_), _) => location(&result.binding).into_iter().collect(),
        (None, naga::TypeInner::Struct { members, .. }) => {
            members.iter().filter_map(|m| location(&m.binding)).collect()
        }
        _ => Vec::new(),
    };
    // Dual-source blending's two outputs share @location(0).
    out.sort_unstable();
    out.dedup();
    out
}

/// One `@location` input of a vertex entry (an argument or a member of
/// an argument struct), in location order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct VertexInput {
    /// Its `@location`.
    pub location: u32,
    /// The argument or member name.
    pub name: String,
    /// Scalar kind: 'f', 'u' or 'i'.
    pub kind: char,
    /// 1 for a scalar, else the vector size.
    pub components: u32,
}

impl VertexInput {
    /// Its WGSL type, for messages.
    pub fn wgsl(&self) -> String {
        let s = match self.kind {
            'f' => "f32",
            'u' => "u32",
            _ => "i32",
        };
        match self.components {
            1 => s.to_string(),
            n => format!("vec{n}<{s}>"),
        }
    }
}

/// The `@location` inputs of a vertex entry; a type a vertex buffer cannot
/// feed (f16, a matrix) is refused naming it.
pub fn vertex_inputs(module: &naga::Module, entry: &str) -> Result<Vec<VertexInput>, String> {
    let Some(ep) = entry_point(module, entry, naga::ShaderStage::Vertex) else { return Ok(Vec::new()) };
    let mut out = Vec::new();
    let mut add = |name: &str, binding: &Option<naga::Binding>, ty: Handle<naga::Type>| -> Result<(), String> {
        let Some(naga::Binding::Location { location, .. }) = binding else { return Ok(()) };
        let (scalar, components) = match &module.types[ty].inner {
            TypeInner::Scalar(s) => (*s, 1),
            TypeInner::Vector { size, scalar } => (*scalar, *size as u32),
            _ => return Err(format!("{entry}'s input @location({location}) {name} is not a scalar or vector")),
        };
        let kind = match (scalar.kind, scalar.width) {
            (ScalarKind::Float, 4) => 'f',
            (ScalarKind::Uint, 4) => 'u',
            (ScalarKind::Sint, 4) => 'i',
            _ => {
                return Err(format!(
                    "{entry}'s input @location({location}) {name} has a type vertex buffers do not feed yet \
                     (32-bit scalars and vectors only)"
                ));
            }
        };
        out.push(VertexInput { location: *location, name: name.to_string(), kind, components });
        Ok(())
    };
    for arg in &ep.function.arguments {
        let name = arg.name.as_deref().unwrap_or("argument");
        match (&arg.binding, &module.types[arg.ty].inner) {
            (None, TypeInner::Struct { members, .. }) => {
                for m in members {
                    add(m.name.as_deref().unwrap_or("member"), &m.binding, m.ty)?;
                }
            }
            _ => add(name, &arg.binding, arg.ty)?,
        }
    }
    out.sort_by_key(|i| i.location);
    Ok(out)
}

/// A render pass's bindings: its fragment entry's and its vertex entry's
/// (one module), each global once; two globals at one group and binding
/// are refused, since the stages share one pipeline layout.
pub fn merge_stages(
    kernel: &str,
    mut fragment: Vec<Binding>,
    vertex: Vec<Binding>,
) -> Result<Vec<Binding>, ParamError> {
    for mut v in vertex {
        if let Some(f) = fragment.iter_mut().find(|f| (f.group, f.binding) == (v.group, v.binding)) {
            if f.global != v.global {
                return Err(ParamError::Layout {
                    kernel: kernel.to_string(),
                    message: format!(
                        "@group({}) @binding({}) is {} in the fragment entry but {} in the vertex entry; one \
                         render pipeline has one binding there",
                        v.group, v.binding, f.name, v.name
                    ),
                });
            }
            f.vertex = true;
            continue;
        }
        v.vertex = true;
        fragment.push(v);
    }
    fragment.sort_by_key(|b| (b.group, b.binding));
    Ok(fragment)
}

/// A render pass's bindings when its vertex entry lives in another file
/// (`file`, module `vmodule`): what both bind must be the same name and
/// type at the same group and binding, and becomes visible to the vertex
/// stage; what only the vertex entry binds joins the pass's bindings,
/// read from its own module (a uniform that params would fill is refused
/// later, since the pass's uniform layout is its shader's).
pub fn match_vertex_file(
    kernel: &str,
    mut fragment: Vec<Binding>,
    module: &naga::Module,
    vertex: Vec<Binding>,
    vmodule: &naga::Module,
    file: &str,
) -> Result<Vec<Binding>, ParamError> {
    for v in vertex {
        let vtype = wgsl_type(vmodule, &vmodule.global_variables[v.global]);
        match fragment.iter_mut().find(|f| (f.group, f.binding) == (v.group, v.binding)) {
            Some(f) if f.name == v.name && wgsl_type(module, &module.global_variables[f.global]) == vtype => {
                f.vertex = true
            }
            Some(f) => {
                let ftype = wgsl_type(module, &module.global_variables[f.global]);
                return Err(ParamError::Layout {
                    kernel: kernel.to_string(),
                    message: format!(
                        "@group({}) @binding({}) is {} ({ftype}) in the fragment entry but {} ({vtype}) in the vertex \
                         entry in {file}; one render pipeline has one binding there",
                        v.group, v.binding, f.name, v.name
                    ),
                });
            }
            None => fragment.push(Binding { vertex: true, in_vertex_file: true, ..v }),
        }
    }
    fragment.sort_by_key(|b| (b.group, b.binding));
    Ok(fragment)
}

/// A WGSL spelling of a global's type, for messages.
pub fn wgsl_type(module: &naga::Module, var: &naga::GlobalVariable) -> String {
    let ty = &module.types[var.ty];
    let inner = match &ty.inner {
        TypeInner::Image { dim, arrayed, class } => {
            let dim = match (dim, arrayed) {
                (ImageDimension::D1, _) => "1d",
                (ImageDimension::D2, false) => "2d",
                (ImageDimension::D2, true) => "2d_array",
                (ImageDimension::D3, _) => "3d",
                (ImageDimension::Cube, false) => "cube",
                (ImageDimension::Cube, true) => "cube_array",
            };
            match class {
                ImageClass::Storage { format, access } => {
                    let access = match (access.contains(StorageAccess::LOAD), access.contains(StorageAccess::STORE)) {
                        (true, true) => "read_write",
                        (true, false) => "read",
                        _ => "write",
                    };
                    let f = format_name(*format)
                        .map(str::to_string)
                        .unwrap_or_else(|| format!("{format:?}").to_lowercase());
                    format!("texture_storage_{dim}<{f}, {access}>")
                }
                ImageClass::Depth { .. } => format!("texture_depth_{dim}"),
                ImageClass::Sampled { kind, .. } => {
                    let k = match kind {
                        ScalarKind::Sint => "i32",
                        ScalarKind::Uint => "u32",
                        _ => "f32",
                    };
                    format!("texture_{dim}<{k}>")
                }
                ImageClass::External => "texture_external".into(),
            }
        }
        TypeInner::Sampler { comparison: true } => "sampler_comparison".into(),
        TypeInner::Sampler { comparison: false } => "sampler".into(),
        _ => {
            use naga::common::wgsl::TypeContext;
            module.to_ctx().type_to_string(var.ty)
        }
    };
    match buffer_space(var.space) {
        Some(space) => format!("var<{space}> {inner}"),
        None => inner,
    }
}

/// A buffer's address space as WGSL writes it in `var<...>`: `uniform`,
/// `storage, read` or `storage, read_write`; `None` for any other space.
pub fn buffer_space(space: AddressSpace) -> Option<&'static str> {
    match space {
        AddressSpace::Uniform => Some("uniform"),
        AddressSpace::Storage { access } if access.contains(StorageAccess::STORE) => Some("storage, read_write"),
        AddressSpace::Storage { .. } => Some("storage, read"),
        _ => None,
    }
}

/// The globals `entry` reaches, directly or through the functions it calls.
fn reached(module: &naga::Module, entry: &naga::Function) -> Vec<Handle<naga::GlobalVariable>> {
    fn calls(block: &naga::Block, out: &mut Vec<Handle<naga::Function>>) {
        for s in block.iter() {
            match s {
                naga::Statement::Block(b) => calls(b, out),
                naga::Statement::If { accept, reject, .. } => {
                    calls(accept, out);
                    calls(reject, out);
                }
                naga::Statement::Switch { cases, .. } => cases.iter().for_each(|c| calls(&c.body, out)),
                naga::Statement::Loop { body, continuing, .. } => {
                    calls(body, out);
                    calls(continuing, out);
                }
                naga::Statement::Call { function, .. } => out.push(*function),
                _ => {}
            }
        }
    }
    let mut globals = Vec::new();
    let mut seen: Vec<Handle<naga::Function>> = Vec::new();
    let mut work: Vec<&naga::Function> = vec![entry];
    while let Some(f) = work.pop() {
        for (_, e) in f.expressions.iter() {
            if let naga::Expression::GlobalVariable(g) = e
                && !globals.contains(g)
            {
                globals.push(*g);
            }
        }
        let mut called = Vec::new();
        calls(&f.body, &mut called);
        for h in called {
            if !seen.contains(&h) {
                seen.push(h);
                work.push(&module.functions[h]);
            }
        }
    }
    globals
}

/// Every binding `entry` of `module` reaches, each with what feeds it
/// (any kind SPEC 14 names); only a type no resource can feed, or an
/// unknown entry point, is refused.
pub fn reflect_all(
    kernel: &str,
    shader: &str,
    entry: &str,
    stage: naga::ShaderStage,
    module: &naga::Module,
) -> Result<Vec<Binding>, ParamError> {
    let bad = |message: String| ParamError::Layout { kernel: kernel.to_string(), message };
    let ep = entry_point(module, entry, stage).ok_or_else(|| {
        let kind = stage_name(stage);
        let named: Vec<&str> =
            module.entry_points.iter().filter(|e| e.stage == stage).map(|e| e.name.as_str()).collect();
        bad(format!(
            "{shader} has no {kind} entry point '{entry}'; its {kind} entry points: {}",
            if named.is_empty() { "none".to_string() } else { named.join(", ") }
        ))
    })?;
    let mut out: Vec<Binding> = Vec::new();
    // In binding order, so that every message names the same variable first.
    let mut globals = reached(module, &ep.function);
    globals.sort_by_key(|g| module.global_variables[*g].binding.as_ref().map(|b| (b.group, b.binding)));
    for g in globals {
        let var = &module.global_variables[g];
        let Some(rb) = &var.binding else { continue };
        let (name, module_path) = undecorate(var.name.as_deref().unwrap_or_default());
        let unfed = |feed: &str| {
            bad(format!(
                "pass {entry}: {name} (@group({}) @binding({}), {}) cannot be fed; it would need {feed}",
                rb.group,
                rb.binding,
                wgsl_type(module, var)
            ))
        };
        use vista_texel::{Access, Dimension};
        let feed = match (&var.space, &module.types[var.ty].inner) {
            (AddressSpace::Uniform, _) => Feed::Uniform,
            (AddressSpace::Storage { access }, TypeInner::Array { base, .. })
                if !access.contains(StorageAccess::STORE)
                    && matches!(module.types[*base].inner, TypeInner::Scalar(s) if s.kind == ScalarKind::Uint && s.width == 4) =>
            {
                Feed::Table
            }
            (AddressSpace::Storage { access }, _) => Feed::Buffer { read_only: !access.contains(StorageAccess::STORE) },
            (_, TypeInner::Image { dim, arrayed, class: ImageClass::Storage { format, access } }) => {
                let dimension = match Dimension::of_naga(*dim, *arrayed) {
                    Some(Dimension::Cube | Dimension::CubeArray) | None => {
                        return Err(unfed("a storage texture of dimension 1d, 2d, 2d-array or 3d"));
                    }
                    Some(d) => d,
                };
                let access = Access::of_naga(*access);
                let Some(format) = format_name(*format) else {
                    return Err(unfed(
                        "a storage texture of one of WebGPU's core storage formats (rgba8unorm .. rg32sint; \
                         r8unorm, rg11b10ufloat and the like are render targets and sampled textures only)",
                    ));
                };
                let storage = Storage { format, dimension, access };
                if access == Access::Read { Feed::StorageRead(storage) } else { Feed::Output(storage) }
            }
            (_, TypeInner::Image { dim, arrayed, class }) => {
                let Some(dim) = Dimension::of_naga(*dim, *arrayed) else {
                    return Err(unfed("a texture of dimension 1d, 2d, 2d-array, 3d or cube"));
                };
                let kind = match class {
                    ImageClass::Sampled { multi: true, .. } | ImageClass::Depth { multi: true } => {
                        return Err(unfed("a multisampled texture, which compute passes cannot make"));
                    }
                    ImageClass::Sampled { kind: ScalarKind::Uint, .. } => SampledKind::Uint,
                    ImageClass::Sampled { kind: ScalarKind::Sint, .. } => SampledKind::Sint,
                    ImageClass::Sampled { .. } => SampledKind::Float,
                    ImageClass::Depth { .. } => SampledKind::Depth,
                    _ => return Err(unfed("an external texture, which compute passes cannot bind")),
                };
                Feed::Sampled { dim, kind }
            }
            (_, TypeInner::Sampler { comparison }) => Feed::Sampler { comparison: *comparison },
            _ => return Err(unfed("a resource")),
        };
        out.push(Binding {
            group: rb.group,
            binding: rb.binding,
            name,
            module: module_path,
            feed,
            vertex: stage == naga::ShaderStage::Vertex,
            global: g,
            in_vertex_file: false,
        });
    }
    out.sort_by_key(|b| (b.group, b.binding));
    Ok(out)
}
