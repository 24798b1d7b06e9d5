//! The uniform block of a kernel, from naga's reflection of its composed
//! WGSL: the uniform struct the entry point reaches, at whatever group and
//! binding it is declared ([`crate::bindings`]), is walked (nested
//! structs included) into leaf fields with their WGSL type and byte offset,
//! checked against the manifest by name and type, and filled from a
//! [`ParamSet`]. Offsets, alignment and padding all come from naga, so a
//! `vec3<f32>` or a nested struct needs no hand-kept layout.

use naga::{ScalarKind, TypeInner, VectorSize};

use crate::params::{ParamType, Value};
use crate::{Kernel, ParamError, ParamSet};

/// The WGSL type of one leaf field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldType {
    U32,
    I32,
    F32,
    /// `vecN<f32>`.
    VecF32(u8),
}

impl FieldType {
    pub fn wgsl(&self) -> String {
        match self {
            FieldType::U32 => "u32".into(),
            FieldType::I32 => "i32".into(),
            FieldType::F32 => "f32".into(),
            FieldType::VecF32(n) => format!("vec{n}<f32>"),
        }
    }

    fn of(param: ParamType) -> FieldType {
        match param {
            ParamType::U32 | ParamType::Bool | ParamType::Enum => FieldType::U32,
            ParamType::I32 => FieldType::I32,
            ParamType::F32 => FieldType::F32,
            ParamType::Vec(n) => FieldType::VecF32(n),
        }
    }
}

/// One leaf of the `Params` struct: its name (nested structs are walked;
/// leaves are matched by their own name), type and absolute byte offset.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Field {
    pub name: String,
    /// `outer.inner` for a field inside a nested struct, for messages.
    pub path: String,
    pub ty: FieldType,
    pub offset: u32,
}

/// The reflected uniform block.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UniformLayout {
    /// The struct's byte size (naga's span).
    pub size: u32,
    pub fields: Vec<Field>,
    /// Whether the entry point reads the u32 table (the Perlin permutation).
    pub uses_table: bool,
    /// Every binding the entry point reaches and what feeds it.
    pub bindings: Vec<crate::bindings::Binding>,
}

/// Reflects the uniform block of `module` for `kernel` (named in errors).
pub fn reflect(kernel: &str, shader: &str, entry: &str, module: &naga::Module) -> Result<UniformLayout, ParamError> {
    let bad = |message: String| ParamError::Layout { kernel: kernel.to_string(), message };
    let bindings = crate::bindings::reflect(kernel, shader, entry, module)?;
    let uses_table = bindings.iter().any(|b| b.feed == crate::bindings::Feed::Table);
    let Some(uniform) = bindings.iter().find(|b| b.feed == crate::bindings::Feed::Uniform) else {
        // No uniform: the kernel takes no params (a param would feed nothing).
        return Ok(UniformLayout { size: 0, fields: Vec::new(), uses_table, bindings });
    };
    let var = &module.global_variables[uniform.global];
    let TypeInner::Struct { members, span } = &module.types[var.ty].inner else {
        unreachable!("bindings::reflect feeds only struct uniforms");
    };
    let mut fields = Vec::new();
    walk(module, members, 0, "", shader, &mut fields).map_err(bad)?;
    for (i, f) in fields.iter().enumerate() {
        if let Some(g) = fields[..i].iter().find(|g| g.name == f.name) {
            return Err(bad(format!("{shader}: Params fields {} and {} share the name '{}'", g.path, f.path, f.name)));
        }
    }
    Ok(UniformLayout { size: *span, fields, uses_table, bindings })
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
                "{shader}: Params field {path} is {what}; allowed: u32, i32, f32, vec2/3/4<f32>, nested structs"
            ))
        };
        let ty = match &module.types[m.ty].inner {
            TypeInner::Scalar(s) if s.width == 4 => match s.kind {
                ScalarKind::Uint => FieldType::U32,
                ScalarKind::Sint => FieldType::I32,
                ScalarKind::Float => FieldType::F32,
                _ => return unsupported("a bool or abstract scalar"),
            },
            TypeInner::Vector { size, scalar } if scalar.kind == ScalarKind::Float && scalar.width == 4 => {
                FieldType::VecF32(match size {
                    VectorSize::Bi => 2,
                    VectorSize::Tri => 3,
                    VectorSize::Quad => 4,
                })
            }
            TypeInner::Struct { members, .. } => {
                walk(module, members, offset, &path, shader, out)?;
                continue;
            }
            TypeInner::Vector { .. } => return unsupported("an integer vector"),
            TypeInner::Matrix { .. } => return unsupported("a matrix"),
            TypeInner::Array { .. } => return unsupported("an array"),
            _ => return unsupported("of an unsupported type"),
        };
        out.push(Field { name, path, ty, offset });
    }
    Ok(())
}

/// Params that vista consumes on the host, so the shader may leave them out:
/// `exposure` of an HDR kernel (the PNG tone map).
fn host_only(kernel: &Kernel, name: &str) -> bool {
    kernel.output() == crate::Output::Hdr && name == "exposure"
}

/// Refuses a layout that does not match the manifest: a field with no
/// param, a param with no field, or a type mismatch.
pub fn check(kernel: &Kernel, layout: &UniformLayout) -> Result<(), ParamError> {
    let bad = |message: String| ParamError::Layout { kernel: kernel.name().to_string(), message };
    for f in &layout.fields {
        if f.name == "width" || f.name == "height" {
            if f.ty != FieldType::U32 {
                return Err(bad(format!("Params field {} is WGSL {} but the image size is u32", f.path, f.ty.wgsl())));
            }
            continue;
        }
        let Some(spec) = kernel.params().iter().find(|s| s.name == f.name) else {
            return Err(bad(format!(
                "Params field {} (WGSL {}) has no param in {}; declare a [[param]] named {} or compute it in WGSL",
                f.path,
                f.ty.wgsl(),
                kernel.origin(),
                f.name
            )));
        };
        let want = FieldType::of(spec.ty);
        if want != f.ty {
            return Err(bad(format!(
                "Params field {} is WGSL {} but {} declares param {} as {} (WGSL {})",
                f.path,
                f.ty.wgsl(),
                kernel.origin(),
                spec.name,
                spec.ty.name(),
                want.wgsl()
            )));
        }
    }
    for spec in kernel.params() {
        if !layout.fields.iter().any(|f| f.name == spec.name) && !host_only(kernel, spec.name) {
            return Err(bad(format!(
                "param {} ({}) has no field in the Params struct of {}; add `{}: {}` to it",
                spec.name,
                spec.ty.name(),
                kernel.shader(),
                spec.name,
                FieldType::of(spec.ty).wgsl()
            )));
        }
    }
    Ok(())
}

/// The uniform bytes for `p` at `width` x `height`, padded to a multiple of
/// 16 bytes. The layout must have passed [`check`].
pub fn pack(kernel: &Kernel, layout: &UniformLayout, p: &ParamSet, width: u32, height: u32) -> Vec<u8> {
    let mut bytes = vec![0u8; (layout.size.div_ceil(16).max(1) * 16) as usize];
    let mut put = |offset: u32, word: [u8; 4]| {
        bytes[offset as usize..offset as usize + 4].copy_from_slice(&word);
    };
    for f in &layout.fields {
        match f.name.as_str() {
            "width" => put(f.offset, width.to_le_bytes()),
            "height" => put(f.offset, height.to_le_bytes()),
            name => {
                let spec = kernel.params().iter().find(|s| s.name == name).expect("checked layout");
                match (p.value(name).expect("resolved params hold every param"), spec.ty) {
                    (Value::Int(v), ParamType::I32) => put(f.offset, (*v as i32).to_le_bytes()),
                    (Value::Int(v), _) => put(f.offset, (*v as u32).to_le_bytes()),
                    (Value::Float(v), _) => put(f.offset, (*v as f32).to_le_bytes()),
                    (Value::Bool(b), _) => put(f.offset, (*b as u32).to_le_bytes()),
                    (Value::Enum(s), _) => {
                        let crate::Kind::Enum(names) = spec.kind else { unreachable!("enum value of an enum param") };
                        let index = names.iter().position(|n| n == s).expect("validated enum value") as u32;
                        put(f.offset, index.to_le_bytes())
                    }
                    (Value::Vector(v), _) => {
                        for (i, c) in v.iter().enumerate() {
                            put(f.offset + 4 * i as u32, (*c as f32).to_le_bytes());
                        }
                    }
                }
            }
        }
    }
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let layout = k.layout(&m).unwrap();
        let at = |n: &str| layout.fields.iter().find(|f| f.name == n).map(|f| (f.path.clone(), f.offset)).unwrap();
        // vec3 aligns to 16: camera starts at 16, fov packs into pos's padding.
        assert_eq!(at("pos"), ("camera.pos".to_string(), 16));
        assert_eq!(at("fov"), ("camera.fov".to_string(), 28));
        assert_eq!(at("mode").1, 32);
        assert!(!layout.uses_table);
        let p = k.resolve(None, &[]).unwrap();
        let b = k.uniforms(&layout, &p, 7, 5);
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
        let e = k.layout(&m).unwrap_err().to_string();
        assert!(e.contains("Params fields a.fov and fov share the name 'fov'"), "{e}");
        let m = module("struct Params { width: u32, height: u32, m: mat2x2<f32> }");
        let e = k.layout(&m).unwrap_err().to_string();
        assert!(e.contains("Params field m is a matrix"), "{e}");
        let m = module("struct Params { width: u32, height: f32 }");
        let e = k.layout(&m).unwrap_err().to_string();
        assert!(e.contains("Params field height is WGSL f32 but the image size is u32"), "{e}");
    }
}
