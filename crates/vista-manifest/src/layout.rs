//! The uniform block of a kernel, from naga's reflection of its composed
//! WGSL: the uniform struct the entry point reaches, at whatever group and
//! binding it is declared ([`crate::bindings`]), is walked (nested
//! structs included) into leaf fields with their WGSL type and byte offset,
//! checked against the manifest by name and type, and filled from a
//! [`ParamSet`]. Offsets, alignment and padding all come from naga, so a
//! `vec3<f32>` or a nested struct needs no hand-kept layout.

use naga::{ScalarKind, TypeInner, VectorSize};

use crate::params::{ParamType, Scalar, Value};
use crate::{Kernel, ParamError, ParamSet};

/// The WGSL type of one leaf field: its scalar, its normalised WGSL name,
/// and the byte offset of each component from the field's offset (vector
/// components 4 bytes apart, matrix columns and array elements at naga's
/// strides).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldType {
    /// The scalar of every component.
    pub scalar: Scalar,
    /// The normalised WGSL name, e.g. `vec3<f32>`.
    pub name: String,
    /// The byte offset of each component from the field's offset.
    pub components: Vec<u32>,
}

impl FieldType {
    /// The normalised WGSL name (a copy of `name`), for messages.
    pub fn wgsl(&self) -> String {
        self.name.clone()
    }

    fn scalar(scalar: Scalar) -> FieldType {
        FieldType { scalar, name: scalar.wgsl().into(), components: vec![0] }
    }
}

/// One leaf of the uniform struct: its name (nested structs are walked;
/// leaves are matched by their own name), type and absolute byte offset.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Field {
    /// The leaf's own name: a param of that name feeds it when none is named
    /// by its `qualified` or `key` name.
    pub name: String,
    /// `outer.inner` for a field inside a nested struct, for messages.
    pub path: String,
    /// Its WGSL type.
    pub ty: FieldType,
    /// Byte offset within its block.
    pub offset: u32,
    /// Index of its block in [`UniformLayout::blocks`].
    pub block: usize,
    /// `variable.path`: the name that reaches it wherever no other module
    /// declares a uniform of the same name (the variable as its declaring
    /// module spells it, without naga_oil's decoration).
    pub key: String,
    /// `module::path::variable.path` for a uniform an imported module
    /// declares (else `key`): the name that always reaches it.
    pub qualified: String,
}

/// One uniform global.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Block {
    /// The uniform's `@group`.
    pub group: u32,
    /// The uniform's `@binding` within its group.
    pub binding: u32,
    /// The WGSL variable name.
    pub var: String,
    /// Its byte size (naga's span).
    pub size: u32,
}

/// The reflected uniform blocks.
#[derive(Debug, Clone, PartialEq)]
pub struct UniformLayout {
    /// Every uniform global the entry point reaches, in binding order.
    pub blocks: Vec<Block>,
    /// The leaves of every block.
    pub fields: Vec<Field>,
    /// Whether the entry point reads the u32 table (the Perlin permutation).
    pub uses_table: bool,
    /// Every binding the entry point reaches and what feeds it.
    pub bindings: Vec<crate::bindings::Binding>,
    /// The module's `override` constants by name (a param may feed one).
    pub overrides: Vec<String>,
}

/// The uniform blocks among `bindings` (those fed by params), walked into
/// leaves; no output target.
pub fn blocks_of(
    kernel: &str,
    shader: &str,
    module: &naga::Module,
    bindings: Vec<crate::bindings::Binding>,
) -> Result<UniformLayout, ParamError> {
    let bad = |message: String| ParamError::Layout { kernel: kernel.to_string(), message };
    let uses_table = bindings.iter().any(|b| b.feed == crate::bindings::Feed::Table);
    let (mut blocks, mut fields) = (Vec::new(), Vec::new());
    for uniform in bindings.iter().filter(|b| b.feed == crate::bindings::Feed::Uniform) {
        let var = &module.global_variables[uniform.global];
        let name = uniform.name.clone();
        let from = crate::bindings::undecorate(var.name.as_deref().unwrap_or_default()).1;
        let block = blocks.len();
        let start = fields.len();
        let size = match &module.types[var.ty].inner {
            TypeInner::Struct { members, span } => {
                walk(module, members, 0, "", shader, &mut fields).map_err(bad)?;
                *span
            }
            // A bare value (`var<uniform> g: f32`) is one leaf named by its variable.
            inner => {
                let ty = leaf_type(module, inner).map_err(|what| {
                    bad(format!("{shader}: uniform {name} is {what}; allowed: the leaf types of a struct field"))
                })?;
                let (path, key, qualified) = (String::new(), String::new(), String::new());
                fields.push(Field { name: name.clone(), path, ty, offset: 0, block, key, qualified });
                module.types[var.ty].inner.size(module.to_ctx())
            }
        };
        for f in &mut fields[start..] {
            f.block = block;
            f.key = if f.path.is_empty() { name.clone() } else { format!("{name}.{}", f.path) };
            if f.path.is_empty() {
                f.path = name.clone();
            }
            f.qualified = match &from {
                Some(m) => format!("{m}::{}", f.key),
                None => f.key.clone(),
            };
        }
        blocks.push(Block { group: uniform.group, binding: uniform.binding, var: name, size });
    }
    Ok(UniformLayout { blocks, fields, uses_table, bindings, overrides: override_names(module) })
}

/// Names each leaf by the param that feeds it: a leaf inside a
/// `[[group]]`'s struct field takes [`crate::manifest::ParamGroup::param`]'s
/// name, the others keep their own. Leaves of one uniform may share a name
/// (`camera.inv_proj`, `ocean_camera.inv_proj`): a param reaches each by
/// its full path, and [`check_fields`] refuses the bare name for them.
/// ([`check_groups`] refuses a group that names no struct field.)
pub fn name_leaves(kernel: &Kernel, l: &mut UniformLayout) {
    let has = |n: &str| kernel.params().iter().any(|s| s.name == n);
    for g in &kernel.manifest.groups {
        for f in l.fields.iter_mut().filter(|f| in_group(g, f)) {
            f.name = g.param(&f.name, has);
        }
    }
}

/// The ungrouped leaves of `fields` whose own name is `name`, when more
/// than one: a bare param name would feed them all with one value. A
/// grouped leaf may share its param with another (landscape's clouds take
/// the terrain's seed): the group's rule says so.
fn twins<'f>(kernel: &Kernel, fields: &'f [Field], name: &str) -> Vec<&'f Field> {
    let same: Vec<&Field> = fields.iter().filter(|g| g.name == name && !grouped(kernel, g)).collect();
    if same.len() > 1 { same } else { Vec::new() }
}

/// The refusal of a bare param name that several leaves share, listing the
/// full paths that reach each (the module-qualified one where two modules'
/// uniforms share a variable name).
fn ambiguous(kernel: &Kernel, name: &str, leaves: &[&Field]) -> ParamError {
    let full = |f: &Field| {
        let key_shared = leaves.iter().filter(|g| g.key == f.key).count() > 1;
        if key_shared { f.qualified.clone() } else { f.key.clone() }
    };
    let paths: Vec<String> = leaves.iter().map(|f| full(f)).collect();
    ParamError::Layout {
        kernel: kernel.name().to_string(),
        message: format!(
            "param {name} is ambiguous: {} leaves share the name ({}); name each by its full path: {}",
            leaves.len(),
            leaves.iter().map(|f| f.key.as_str()).collect::<Vec<_>>().join(", "),
            paths.join(" or ")
        ),
    }
}

/// Whether leaf `f` lies in group `g`'s struct field (by its path below
/// the variable, or as `variable.path`).
fn in_group(g: &crate::manifest::ParamGroup, f: &Field) -> bool {
    let dot = format!("{}.", g.field);
    f.path.starts_with(&dot) || f.key.starts_with(&dot)
}

/// Whether leaf `f` lies in any of the kernel's `[[group]]`s.
fn grouped(kernel: &Kernel, f: &Field) -> bool {
    kernel.manifest.groups.iter().any(|g| in_group(g, f))
}

/// Every `[[group]]` field is a struct field of the uniform of one of the
/// kernel's passes (`layouts`); the refusal lists the struct fields there are.
pub fn check_groups(kernel: &Kernel, layouts: &[&UniformLayout]) -> Result<(), ParamError> {
    for g in &kernel.manifest.groups {
        if layouts.iter().any(|l| l.fields.iter().any(|f| in_group(g, f))) {
            continue;
        }
        let mut structs: Vec<&str> = Vec::new();
        for f in layouts.iter().flat_map(|l| &l.fields) {
            if let Some((s, _)) = f.path.rsplit_once('.')
                && !structs.contains(&s)
            {
                structs.push(s);
            }
        }
        return Err(ParamError::Layout {
            kernel: kernel.name().to_string(),
            message: format!(
                "[[group]] field = \"{}\" is no struct field of the uniform in {}; its struct fields: {}",
                g.field,
                kernel.shader_files().join(" or "),
                if structs.is_empty() { "none".to_string() } else { structs.join(", ") }
            ),
        });
    }
    Ok(())
}

fn override_names(module: &naga::Module) -> Vec<String> {
    module.overrides.iter().filter_map(|(_, o)| o.name.clone()).collect()
}

fn walk(
    module: &naga::Module,
    members: &[naga::StructMember],
    base: u32,
    prefix: &str,
    shader: &str,
    out: &mut Vec<Field>,
) -> Result<(), String> {
    for m in members {
        let name = m.name.clone().unwrap_or_default();
        let path = if prefix.is_empty() { name.clone() } else { format!("{prefix}.{name}") };
        let offset = base + m.offset;
        let unsupported = |what: &str| {
            Err(format!(
                "{shader}: Params field {path} is {what}; allowed: u32, i32, f32, vecN of them, matCxR<f32>, \
                 fixed-size arrays of these, nested structs and fixed-size arrays of structs"
            ))
        };
        let ty = match &module.types[m.ty].inner {
            TypeInner::Struct { members, .. } => {
                walk(module, members, offset, &path, shader, out)?;
                continue;
            }
            // An array of structs feeds like a struct of arrays: one param
            // per leaf of the element, a list over the elements
            // (`lights.color`: array<vec3<f32>, 4>).
            TypeInner::Array { base, size: naga::ArraySize::Constant(n), stride }
                if matches!(module.types[*base].inner, TypeInner::Struct { .. }) =>
            {
                let TypeInner::Struct { members, .. } = &module.types[*base].inner else { unreachable!() };
                let mut element = Vec::new();
                walk(module, members, 0, "", shader, &mut element)?;
                for leaf in element {
                    let components = (0..n.get())
                        .flat_map(|i| leaf.ty.components.iter().map(move |c| i * stride + leaf.offset + c))
                        .collect();
                    out.push(Field {
                        name: leaf.name,
                        path: format!("{path}.{}", leaf.path),
                        ty: FieldType {
                            scalar: leaf.ty.scalar,
                            name: format!("array<{}, {n}>", leaf.ty.name),
                            components,
                        },
                        offset,
                        block: 0,
                        key: String::new(),
                        qualified: String::new(),
                    });
                }
                continue;
            }
            inner => match leaf_type(module, inner) {
                Ok(t) => t,
                Err(what) => return unsupported(what),
            },
        };
        out.push(Field { name, path, ty, offset, block: 0, key: String::new(), qualified: String::new() });
    }
    Ok(())
}

fn scalar_of(s: &naga::Scalar) -> Option<Scalar> {
    match (s.kind, s.width) {
        (ScalarKind::Float, 4) => Some(Scalar::F32),
        (ScalarKind::Uint, 4) => Some(Scalar::U32),
        (ScalarKind::Sint, 4) => Some(Scalar::I32),
        _ => None,
    }
}

fn size_of(v: VectorSize) -> u32 {
    match v {
        VectorSize::Bi => 2,
        VectorSize::Tri => 3,
        VectorSize::Quad => 4,
    }
}

/// The leaf type of a non-struct member, or what it is instead.
fn leaf_type(module: &naga::Module, inner: &TypeInner) -> Result<FieldType, &'static str> {
    match inner {
        TypeInner::Scalar(s) => scalar_of(s).map(FieldType::scalar).ok_or("a bool or abstract scalar"),
        TypeInner::Vector { size, scalar } => {
            let sc = scalar_of(scalar).ok_or("a vector of bools")?;
            let n = size_of(*size);
            Ok(FieldType {
                scalar: sc,
                name: format!("vec{n}<{}>", sc.wgsl()),
                components: (0..n).map(|i| 4 * i).collect(),
            })
        }
        TypeInner::Matrix { columns, rows, scalar } => {
            if scalar_of(scalar) != Some(Scalar::F32) {
                return Err("a matrix of f16");
            }
            let (c, r) = (size_of(*columns), size_of(*rows));
            // A column is a vecR: vec2 aligns to 8 bytes, vec3 and vec4 to 16.
            let stride = if r == 2 { 8 } else { 16 };
            let components = (0..c).flat_map(|col| (0..r).map(move |row| col * stride + 4 * row)).collect();
            Ok(FieldType { scalar: Scalar::F32, name: format!("mat{c}x{r}<f32>"), components })
        }
        TypeInner::Array { base, size: naga::ArraySize::Constant(n), stride } => {
            let elem = match &module.types[*base].inner {
                TypeInner::Struct { .. } => return Err("an array of structs"),
                TypeInner::Array { .. } => return Err("an array of arrays"),
                other => leaf_type(module, other)?,
            };
            let components = (0..n.get()).flat_map(|i| elem.components.iter().map(move |c| i * stride + c)).collect();
            Ok(FieldType { scalar: elem.scalar, name: format!("array<{}, {n}>", elem.name), components })
        }
        TypeInner::Array { .. } => Err("a runtime-sized array"),
        TypeInner::Atomic(_) => Err("an atomic"),
        _ => Err("of an unsupported type"),
    }
}

/// Whether param `name` feeds something on the host rather than a uniform
/// leaf or an override, so the shader may leave it out: the hdr view's
/// `exposure`, or a name a `workgroups` or `size` expression reads.
fn host_only(kernel: &Kernel, name: &str) -> bool {
    let m = &kernel.manifest;
    let hdr =
        kernel.output() == crate::Output::Hdr || m.graph.outputs.iter().any(|o| o.view == Some(crate::Output::Hdr));
    (hdr && name == "exposure")
        || crate::graph::host_params(&m.graph).contains(&name)
        || m.source.params().contains(&name)
        || m.graph.passes.iter().any(|p| p.source.params().contains(&name))
}

/// The param feeding `f`, if any: one named by its `variable.path`, else
/// one named by its bare leaf name.
fn param_of<'k>(kernel: &'k Kernel, f: &Field) -> Option<&'k crate::ParamSpec> {
    let params = kernel.params();
    params
        .iter()
        .find(|s| s.name == f.qualified)
        .or_else(|| params.iter().find(|s| s.name == f.key))
        .or_else(|| params.iter().find(|s| s.name == f.name))
}

/// Every leaf of `layout` has a param of its type (or is padding).
pub fn check_fields(kernel: &Kernel, layout: &UniformLayout) -> Result<(), ParamError> {
    let bad = |message: String| ParamError::Layout { kernel: kernel.name().to_string(), message };
    for f in &layout.fields {
        if f.name == "width" || f.name == "height" {
            if f.ty.name != "u32" {
                return Err(bad(format!("Params field {} is WGSL {} but the image size is u32", f.path, f.ty.wgsl())));
            }
            continue;
        }
        let spec = param_of(kernel, f);
        // `_`-prefixed leaves are padding: zero unless a param names them.
        if spec.is_none() && f.name.starts_with('_') {
            continue;
        }
        let shared = twins(kernel, &layout.fields, &f.name);
        let Some(spec) = spec else {
            let names = if shared.is_empty() { format!("{} (or {})", f.name, f.key) } else { f.key.clone() };
            return Err(bad(format!(
                "Params field {} (WGSL {}) has no param in {}; declare a [[param]] named {names} or compute it in WGSL",
                f.path,
                f.ty.wgsl(),
                kernel.origin(),
            )));
        };
        if spec.name == f.name && spec.name != f.key && spec.name != f.qualified && !shared.is_empty() {
            return Err(ambiguous(kernel, &spec.name, &shared));
        }
        let want = spec.ty.wgsl();
        if want != f.ty.name {
            return Err(bad(format!(
                "Params field {} is WGSL {} but {} declares param {} as {} (WGSL {})",
                f.path,
                f.ty.wgsl(),
                kernel.origin(),
                spec.name,
                spec.ty.name(),
                want
            )));
        }
    }
    Ok(())
}

/// Every param feeds something in one of `layouts` (a graph's passes), a
/// host-side expression or an override, and names no two leaves at once.
pub fn check_params(kernel: &Kernel, layouts: &[&UniformLayout]) -> Result<(), ParamError> {
    let mut fed: Vec<&str> = Vec::new();
    for layout in layouts {
        for spec in kernel.params() {
            if layout.fields.iter().any(|f| f.qualified == spec.name || f.key == spec.name || f.name == spec.name)
                || layout.overrides.contains(&spec.name)
            {
                fed.push(&spec.name);
            }
        }
    }
    for layout in layouts {
        check_names(kernel, layout, &fed, layouts.len() > 1)?;
    }
    Ok(())
}

fn check_names(kernel: &Kernel, layout: &UniformLayout, fed_elsewhere: &[&str], graph: bool) -> Result<(), ParamError> {
    let bad = |message: String| ParamError::Layout { kernel: kernel.name().to_string(), message };
    for spec in kernel.params() {
        let by_qualified = layout.fields.iter().any(|f| f.qualified == spec.name);
        let by_key: Vec<&Field> = layout.fields.iter().filter(|f| f.key == spec.name).collect();
        if !by_qualified && by_key.len() > 1 {
            return Err(bad(format!(
                "param {} is ambiguous: uniforms of two modules share the name ({}); name one as {}",
                spec.name,
                by_key.iter().map(|f| f.qualified.as_str()).collect::<Vec<_>>().join(", "),
                by_key.iter().map(|f| f.qualified.as_str()).collect::<Vec<_>>().join(" or ")
            )));
        }
        let by_key: Vec<&Field> =
            if by_qualified { layout.fields.iter().filter(|f| f.qualified == spec.name).collect() } else { by_key };
        let by_name: Vec<&Field> = layout.fields.iter().filter(|f| f.name == spec.name).collect();
        let shared = twins(kernel, &layout.fields, &spec.name);
        if by_key.is_empty() && !shared.is_empty() {
            return Err(ambiguous(kernel, &spec.name, &shared));
        }
        let feeds_override = layout.overrides.contains(&spec.name);
        if by_key.is_empty()
            && by_name.is_empty()
            && !host_only(kernel, &spec.name)
            && !feeds_override
            && !(graph && fed_elsewhere.contains(&spec.name.as_str()))
        {
            return Err(bad(format!(
                "param {} ({}) has no field in the Params struct of {}; add `{}: {}` to it",
                spec.name,
                spec.ty.name(),
                kernel.shader_files().join(" or "),
                spec.name,
                spec.ty.wgsl()
            )));
        }
    }
    Ok(())
}

/// Each uniform block's bytes for `p` at `width` x `height`, padded to a
/// multiple of 16 bytes. The layout must have passed [`check`].
pub fn pack(kernel: &Kernel, layout: &UniformLayout, p: &ParamSet, width: u32, height: u32) -> Vec<Vec<u8>> {
    let mut blocks: Vec<Vec<u8>> =
        layout.blocks.iter().map(|b| vec![0u8; (b.size.div_ceil(16).max(1) * 16) as usize]).collect();
    let mut put = |block: usize, offset: u32, word: [u8; 4]| {
        blocks[block][offset as usize..offset as usize + 4].copy_from_slice(&word);
    };
    for f in &layout.fields {
        let words: Vec<[u8; 4]> = match f.name.as_str() {
            "width" => vec![width.to_le_bytes()],
            "height" => vec![height.to_le_bytes()],
            _ => {
                let Some(spec) = param_of(kernel, f) else {
                    continue; // padding: stays zero
                };
                let name = spec.name.as_str();
                let scalar = |v: f64| match f.ty.scalar {
                    Scalar::F32 => (v as f32).to_le_bytes(),
                    Scalar::U32 => (v as u32).to_le_bytes(),
                    Scalar::I32 => (v as i32).to_le_bytes(),
                };
                match p.value(name).expect("resolved params hold every param") {
                    Value::Int(v) if spec.ty == ParamType::I32 => vec![(*v as i32).to_le_bytes()],
                    Value::Int(v) => vec![(*v as u32).to_le_bytes()],
                    Value::Float(v) => vec![(*v as f32).to_le_bytes()],
                    Value::Bool(b) => vec![(*b as u32).to_le_bytes()],
                    Value::Enum(s) => {
                        let crate::Kind::Enum(names) = &spec.kind else { unreachable!("enum value of an enum param") };
                        vec![(names.iter().position(|n| n == s).expect("validated enum value") as u32).to_le_bytes()]
                    }
                    Value::Vector(v) => v.iter().map(|c| scalar(*c)).collect(),
                }
            }
        };
        for (word, at) in words.iter().zip(&f.ty.components) {
            put(f.block, f.offset + at, *word);
        }
    }
    blocks
}

/// The layouts of a kernel's passes, from naga's reflection of each.
impl Kernel {
    /// Reflects every pass of the graph (`modules[i]`: pass i's composed
    /// file name and module), resolves what feeds each binding, and checks
    /// each pass's uniform blocks against the params: a leaf with no param,
    /// or a param that feeds nothing in any pass, is refused.
    pub fn graph_layouts(
        &self,
        modules: &[(&str, &naga::Module)],
    ) -> Result<(crate::graph::Resolved, Vec<UniformLayout>), ParamError> {
        self.graph_layouts_with(modules, &[])
    }

    /// [`Kernel::graph_layouts`], with the composed file and module of each
    /// pass's vertex entry that lives in another file (`vertex[i]`).
    pub fn graph_layouts_with(
        &self,
        modules: &[(&str, &naga::Module)],
        vertex: &[Option<(&str, &naga::Module)>],
    ) -> Result<(crate::graph::Resolved, Vec<UniformLayout>), ParamError> {
        let g = self.graph();
        let mut reflected = Vec::new();
        for (i, ((shader, module), pass)) in modules.iter().zip(&g.passes).enumerate() {
            let stage = match pass.raster {
                Some(_) => naga::ShaderStage::Fragment,
                None => naga::ShaderStage::Compute,
            };
            let mut b = crate::bindings::reflect_all(self.name(), shader, &pass.entry, stage, module)?;
            let vs = pass.raster.as_ref().and_then(|r| r.vertex.entry());
            match (vs, vertex.get(i).copied().flatten()) {
                (Some(vs), None) => {
                    let v = crate::bindings::reflect_all(self.name(), shader, vs, naga::ShaderStage::Vertex, module)?;
                    b = crate::bindings::merge_stages(self.name(), b, v)?;
                }
                (Some(vs), Some((file, vmodule))) => {
                    let v = crate::bindings::reflect_all(self.name(), file, vs, naga::ShaderStage::Vertex, vmodule)?;
                    b = crate::bindings::match_vertex_file(self.name(), b, module, v, vmodule, file)?;
                }
                (None, _) => {}
            }
            reflected.push(b);
        }
        let passes: Vec<(&str, &[crate::bindings::Binding], &naga::Module)> =
            modules.iter().zip(&reflected).map(|((s, m), b)| (*s, b.as_slice(), *m)).collect();
        let vertex_modules: Vec<Option<&naga::Module>> = vertex.iter().map(|v| v.map(|(_, m)| m)).collect();
        let resolved = crate::graph::resolve(self.name(), g, &passes, &vertex_modules)?;
        let mut layouts = Vec::new();
        for (((shader, module), bindings), slots) in modules.iter().zip(reflected).zip(&resolved.slots) {
            // Params feed the uniforms and the table that no resource feeds.
            let by_params = |b: &crate::bindings::Binding| {
                slots.iter().any(|s| {
                    (s.group, s.binding) == (b.group, b.binding)
                        && matches!(s.feed, crate::graph::SlotFeed::Uniform(_) | crate::graph::SlotFeed::Table)
                })
            };
            // The pass's uniform layout is its shader's: a vertex file's own
            // uniform must come from a buffer resource.
            if let Some(b) = bindings.iter().find(|b| b.in_vertex_file && by_params(b)) {
                return Err(ParamError::Layout {
                    kernel: self.name().to_string(),
                    message: format!(
                        "{shader}: the vertex entry's file binds {} (@group({}) @binding({})), which params would \
                         fill, but the fragment entry does not; declare it in the pass's shader too, or bind it to \
                         a buffer resource in the pass's bind",
                        b.name, b.group, b.binding
                    ),
                });
            }
            let fed: Vec<crate::bindings::Binding> = bindings.iter().filter(|b| by_params(b)).cloned().collect();
            layouts.push((*shader, blocks_of(self.name(), shader, module, fed)?));
        }
        // As for one pass: a group that names no struct field first.
        check_groups(self, &layouts.iter().map(|(_, l)| l).collect::<Vec<_>>())?;
        for (_, l) in &mut layouts {
            name_leaves(self, l);
            check_fields(self, l)?;
        }
        let layouts: Vec<UniformLayout> = layouts.into_iter().map(|(_, l)| l).collect();
        check_params(self, &layouts.iter().collect::<Vec<_>>())?;
        Ok((resolved, layouts))
    }

    /// Each uniform block's bytes for `p` at `width` x `height`, in
    /// [`UniformLayout::blocks`] order.
    pub fn uniforms(&self, layout: &UniformLayout, p: &ParamSet, width: u32, height: u32) -> Vec<Vec<u8>> {
        pack(self, layout, p, width, height)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The checked uniform layout of a one-pass kernel's module.
    fn one_pass(k: &Kernel, m: &naga::Module) -> Result<UniformLayout, ParamError> {
        k.graph_layouts(&[(k.shader(), m)]).map(|(_, mut l)| l.remove(0))
    }

    const MANIFEST: &str = r#"summary = "nested"
[[param]]
name = "pos"
type = "vec3"
range = [-10, 10]
default = [1, 2, 3]
[[param]]
name = "fov"
type = "f32"
range = [1, 90]
default = 45
[[param]]
name = "mode"
type = "enum"
values = ["a", "b", "c"]
default = "c"
[[param]]
name = "flip"
type = "bool"
default = true
[[param]]
name = "shift"
type = "i32"
range = [-5, 5]
default = -3
"#;

    fn module(params_struct: &str) -> naga::Module {
        let src = format!(
            "{params_struct}\n@group(0) @binding(0) var<uniform> params: Params;\n\
             @group(0) @binding(1) var out: texture_storage_2d<rgba32float, write>;\n\
             @compute @workgroup_size(8, 8) fn main() {{ textureStore(out, vec2(0u), vec4(f32(params.width))); }}\n"
        );
        naga::front::wgsl::parse_str(&src).unwrap()
    }

    #[test]
    fn nested_structs_vec3_enum_bool_and_i32_pack_at_naga_offsets() {
        let k = Kernel::from_manifest("nested", "nested.toml", MANIFEST).unwrap();
        let m = module(
            "struct Camera { pos: vec3<f32>, fov: f32 }\n\
             struct Params { width: u32, height: u32, camera: Camera, mode: u32, flip: u32, shift: i32 }",
        );
        let layout = one_pass(&k, &m).unwrap();
        let at = |n: &str| layout.fields.iter().find(|f| f.name == n).map(|f| (f.path.clone(), f.offset)).unwrap();
        // vec3 aligns to 16: camera starts at 16, fov packs into pos's padding.
        assert_eq!(at("pos"), ("camera.pos".to_string(), 16));
        assert_eq!(at("fov"), ("camera.fov".to_string(), 28));
        assert_eq!(at("mode").1, 32);
        assert!(!layout.uses_table);
        let p = k.resolve(None, &[]).unwrap();
        let b = k.uniforms(&layout, &p, 7, 5).remove(0);
        let word = |o: usize| u32::from_le_bytes(b[o..o + 4].try_into().unwrap());
        assert_eq!((word(0), word(4)), (7, 5));
        assert_eq!([f32::from_bits(word(16)), f32::from_bits(word(20)), f32::from_bits(word(24))], [1.0, 2.0, 3.0]);
        assert_eq!(f32::from_bits(word(28)), 45.0);
        assert_eq!((word(32), word(36), word(40) as i32), (2, 1, -3));
        assert_eq!(b.len() % 16, 0);
    }

    #[test]
    fn duplicate_leaf_names_and_unsupported_types_are_refused() {
        let k = Kernel::from_manifest("nested", "nested.toml", MANIFEST).unwrap();
        let m = module("struct A { fov: f32 }\nstruct Params { width: u32, height: u32, a: A, fov: f32 }");
        let e = one_pass(&k, &m).unwrap_err().to_string();
        assert!(
            e.contains("param fov is ambiguous: 2 leaves share the name (params.a.fov, params.fov); name each by its full path: \
                        params.a.fov or params.fov"),
            "{e}"
        );
        let m = module("struct Params { width: u32, height: u32, m: array<array<f32, 2>, 2> }");
        let e = one_pass(&k, &m).unwrap_err().to_string();
        assert!(e.contains("Params field m is an array of arrays"), "{e}");
        let m = module("struct Params { width: u32, height: f32 }");
        let e = one_pass(&k, &m).unwrap_err().to_string();
        assert!(e.contains("Params field height is WGSL f32 but the image size is u32"), "{e}");
    }

    /// Two leaves of one uniform that share their last name (a camera and
    /// an ocean camera, each with `inv_proj`), one of them three structs
    /// deep: `variable.path` reaches each; the bare name is refused,
    /// listing the full paths that would work.
    #[test]
    fn same_named_leaves_are_reached_by_their_full_paths() {
        const TWINS: &str = r#"summary = "twins"
[[param]]
name = "params.camera.inv_proj"
type = "f32"
range = [-10, 10]
default = 1.5
[[param]]
name = "params.ocean.view.cam.inv_proj"
type = "f32"
range = [-10, 10]
default = -2.5
"#;
        let structs = "struct Cam { inv_proj: f32 }\nstruct View { cam: Cam }\nstruct Ocean { view: View }\n\
                       struct Params { width: u32, height: u32, camera: Cam, ocean: Ocean }";
        let k = Kernel::from_manifest("twins", "twins.toml", TWINS).unwrap();
        let layout = one_pass(&k, &module(structs)).unwrap();
        let b = k.uniforms(&layout, &k.resolve(None, &[]).unwrap(), 1, 1).remove(0);
        let f = |o: usize| f32::from_le_bytes(b[o..o + 4].try_into().unwrap());
        assert_eq!((f(8), f(12)), (1.5, -2.5), "each leaf its own param");
        let bare = TWINS.replace("params.camera.inv_proj", "inv_proj");
        let k = Kernel::from_manifest("twins", "twins.toml", &bare).unwrap();
        let e = one_pass(&k, &module(structs)).unwrap_err().to_string();
        assert!(
            e.contains(
                "param inv_proj is ambiguous: 2 leaves share the name (params.camera.inv_proj, \
                        params.ocean.view.cam.inv_proj); \
                        name each by its full path: params.camera.inv_proj or params.ocean.view.cam.inv_proj"
            ),
            "{e}"
        );
    }

    const LEAVES: &str = r#"summary = "every leaf type"
[[param]]
name = "view"
type = "mat4x4<f32>"
range = [-100, 100]
default = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16]
[[param]]
name = "res"
type = "vec2u"
range = [0, 4096]
default = [640, 480]
[[param]]
name = "weights"
type = "array<vec4<f32>, 2>"
range = [0, 1]
default = [[0.5, 0.25, 0.125, 1], [0, 0.75, 1, 0.5]]
[[param]]
name = "offs"
type = "vec3<i32>"
range = [-9, 9]
default = [-1, 2, -3]
[[param]]
name = "rot"
type = "mat3x3f"
range = [-1, 1]
default = [1, 0, 0, 0, 1, 0, 0, 0, -1]
"#;

    #[test]
    fn matrices_integer_vectors_arrays_and_padding_pack_at_naga_offsets() {
        let k = Kernel::from_manifest("leaves", "leaves.toml", LEAVES).unwrap();
        let m = module(
            "struct Params { width: u32, height: u32, view: mat4x4<f32>, res: vec2<u32>, _pad0: u32, \
             weights: array<vec4<f32>, 2>, offs: vec3<i32>, rot: mat3x3<f32>, _pad1: vec4<f32> }",
        );
        let layout = one_pass(&k, &m).unwrap();
        let p = k.resolve(None, &[("res".into(), "1920,1080".into())]).unwrap();
        let b = k.uniforms(&layout, &p, 3, 2).remove(0);
        let word = |o: u32| u32::from_le_bytes(b[o as usize..o as usize + 4].try_into().unwrap());
        let f = |o: u32| f32::from_bits(word(o));
        // mat4x4 at 16, column after column.
        assert_eq!((16..80).step_by(4).map(f).collect::<Vec<_>>(), (1..=16).map(|v| v as f32).collect::<Vec<_>>());
        assert_eq!((word(80), word(84), word(88)), (1920, 1080, 0), "vec2<u32>, then _pad0 zero");
        assert_eq!([f(96), f(100), f(108), f(116), f(124)], [0.5, 0.25, 1.0, 0.75, 0.5], "array stride 16");
        assert_eq!([word(128) as i32, word(132) as i32, word(136) as i32], [-1, 2, -3]);
        // mat3x3 at 144: columns 16 bytes apart, the fourth word of each is padding.
        assert_eq!([f(144), f(160 + 4), f(176 + 8), f(156)], [1.0, 1.0, -1.0, 0.0]);
        assert!((192..208).step_by(4).all(|o| word(o) == 0), "_pad1 stays zero");
        // A param whose WGSL type differs from its field is refused, naming both.
        let m = module(
            "struct Params { width: u32, height: u32, view: mat4x4<f32>, res: vec2<i32>, \
                        weights: array<vec4<f32>, 2>, offs: vec3<i32>, rot: mat3x3<f32> }",
        );
        let e = one_pass(&k, &m).unwrap_err().to_string();
        assert!(
            e.contains("Params field res is WGSL vec2<i32> but leaves.toml declares param res as vec2<u32>"),
            "{e}"
        );
        assert!(
            k.resolve(None, &[("res".into(), "1,2.5".into())]).unwrap_err().to_string().contains("integers"),
            "an integer vector takes integers"
        );
    }

    const LIGHTS: &str = r#"summary = "an array of structs"
[[param]]
name = "pos"
type = "array<vec3<f32>, 2>"
range = [-10, 10]
default = [[1, 2, 3], [4, 5, 6]]
[[param]]
name = "params.lights.power"
type = "array<f32, 2>"
range = [0, 100]
default = [7, 8]
"#;

    #[test]
    fn arrays_of_structs_pack_as_a_struct_of_arrays() {
        let k = Kernel::from_manifest("lights", "lights.toml", LIGHTS).unwrap();
        let m = module(
            "struct Light { pos: vec3<f32>, power: f32 }\n\
             struct Params { width: u32, height: u32, lights: array<Light, 2> }",
        );
        let layout = one_pass(&k, &m).unwrap();
        let b = k.uniforms(&layout, &k.resolve(None, &[]).unwrap(), 3, 2).remove(0);
        let f = |o: usize| f32::from_le_bytes(b[o..o + 4].try_into().unwrap());
        // The array starts at 16; each Light is 16 bytes: pos, then power in its padding.
        assert_eq!((16..48).step_by(4).map(f).collect::<Vec<_>>(), [1.0, 2.0, 3.0, 7.0, 4.0, 5.0, 6.0, 8.0]);
    }

    #[test]
    fn naga_oil_decoration_is_read_back_as_the_module_path() {
        let decorated = "frameX_naga_oil_mod_XNV4WY2LCHI5GGYLNMVZGCX";
        assert_eq!(crate::bindings::undecorate(decorated), ("frame".to_string(), Some("mylib::camera".to_string())));
        assert_eq!(crate::bindings::undecorate("frame"), ("frame".to_string(), None));
    }
}
