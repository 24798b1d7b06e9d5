//! Every buffer binding's memory layout as an engine packs it: each leaf
//! (scalar, vector, matrix, atomic) by its path from the variable (`a.b`,
//! `lights[i].color`), byte offset (with the stride of each array on the
//! way), and WGSL type, from naga's reflection. What `vista list --layout`
//! prints, so a project writes engine data (a `View`, a `Lights`) into
//! `.bin` files at the offsets the shader reads.

use naga::{ArraySize, TypeInner};

/// One leaf of a binding's type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Leaf {
    /// Its path from the variable: `.field`, `[i]` for an array element
    /// (`[j]` for a second level, and so on).
    pub path: String,
    /// Its offset in bytes when every index is 0.
    pub offset: u32,
    /// The bytes each index adds: `(index name, stride, element count;
    /// None for a runtime-sized array)`.
    pub strides: Vec<(char, u32, Option<u32>)>,
    /// Its WGSL type.
    pub ty: String,
}

/// A buffer binding (`var<uniform>`, `var<storage>`) and its leaves.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BufferLayout {
    /// `@group`.
    pub group: u32,
    /// `@binding`.
    pub binding: u32,
    /// The variable as its module names it (naga_oil's decoration removed).
    pub name: String,
    /// The import path of the module that declares it, where imported.
    pub module: Option<String>,
    /// `uniform`, `storage, read` or `storage, read_write`.
    pub space: String,
    /// Its type's size in bytes (a runtime-sized array's fixed part plus
    /// one element).
    pub size: u32,
    /// Every leaf in offset order.
    pub leaves: Vec<Leaf>,
}

impl BufferLayout {
    /// Whether a pass's `bind` key names this variable: by its name, or
    /// by its module's path and name (`engine::view::view`).
    pub fn named(&self, key: &str) -> bool {
        crate::bindings::names(key, &self.name, self.module.as_deref())
    }
}

/// The buffer bindings of `module`, in group and binding order.
pub fn buffer_layouts(module: &naga::Module) -> Vec<BufferLayout> {
    let mut layouter = naga::proc::Layouter::default();
    if layouter.update(module.to_ctx()).is_err() {
        return Vec::new();
    }
    let mut out: Vec<BufferLayout> = module
        .global_variables
        .iter()
        .filter_map(|(_, g)| {
            let b = g.binding?;
            let space = crate::bindings::buffer_space(g.space)?.to_string();
            let mut leaves = Vec::new();
            walk(module, g.ty, String::new(), 0, &mut Vec::new(), &mut leaves);
            leaves.sort_by_key(|l| l.offset);
            let (name, from) = crate::bindings::undecorate(g.name.as_deref().unwrap_or_default());
            Some(BufferLayout {
                group: b.group,
                binding: b.binding,
                name,
                module: from,
                space,
                size: layouter[g.ty].size,
                leaves,
            })
        })
        .collect();
    out.sort_by_key(|l| (l.group, l.binding));
    out
}

/// Collects the leaves of `ty` at `offset` under `path`.
fn walk(
    module: &naga::Module,
    ty: naga::Handle<naga::Type>,
    path: String,
    offset: u32,
    strides: &mut Vec<(char, u32, Option<u32>)>,
    out: &mut Vec<Leaf>,
) {
    match &module.types[ty].inner {
        TypeInner::Struct { members, .. } => {
            for m in members {
                let name = crate::bindings::undecorate(m.name.as_deref().unwrap_or("?")).0;
                walk(module, m.ty, format!("{path}.{name}"), offset + m.offset, strides, out);
            }
        }
        TypeInner::Array { base, size, stride } => {
            let index = ['i', 'j', 'k', 'l', 'm', 'n'].get(strides.len()).copied().unwrap_or('x');
            let count = match size {
                ArraySize::Constant(n) => Some(n.get()),
                _ => None,
            };
            strides.push((index, *stride, count));
            walk(module, *base, format!("{path}[{index}]"), offset, strides, out);
            strides.pop();
        }
        _ => out.push(Leaf {
            path: if path.is_empty() { "(the whole)".into() } else { path.trim_start_matches('.').to_string() },
            offset,
            strides: strides.clone(),
            ty: {
                use naga::common::wgsl::TypeContext;
                module.to_ctx().type_to_string(ty)
            },
        }),
    }
}

/// The leaf's offset as `vista list --layout` prints it: `96`, or
/// `16 + 32 i (i < 4)` for an element of an array.
pub fn offset_text(leaf: &Leaf) -> String {
    let mut text = leaf.offset.to_string();
    for (index, stride, count) in &leaf.strides {
        let bound = count.map_or(String::new(), |n| format!(" ({index} < {n})"));
        text += &format!(" + {stride} {index}{bound}");
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Offsets by WGSL's layout rules, worked by hand: vec3 aligns to 16
    /// and takes 12; mat3x3<f32> is three 16-byte columns; an array of a
    /// struct steps by the struct's size rounded to its alignment.
    #[test]
    fn leaves_of_a_view_like_uniform_and_a_storage_array() {
        let src = "struct Light { color: vec4<f32>, dir: vec3<f32>, range: f32 }
struct View {
    clip_from_world: mat4x4<f32>,
    world_position: vec3<f32>,
    exposure: f32,
    normal_from_world: mat3x3<f32>,
    viewport: vec4<f32>,
    lights: array<Light, 4>,
    count: u32,
}
@group(0) @binding(0) var<uniform> view: View;
@group(1) @binding(2) var<storage, read_write> counts: array<atomic<u32>>;
@compute @workgroup_size(1) fn main() { _ = view.count; atomicAdd(&counts[0], 1u); }
";
        let module = naga::front::wgsl::parse_str(src).unwrap();
        let layouts = buffer_layouts(&module);
        assert_eq!(layouts.len(), 2);
        let view = &layouts[0];
        assert_eq!((view.group, view.binding, view.name.as_str(), view.space.as_str()), (0, 0, "view", "uniform"));
        let got: Vec<(&str, String, &str)> =
            view.leaves.iter().map(|l| (l.path.as_str(), offset_text(l), l.ty.as_str())).collect();
        assert_eq!(
            got,
            [
                ("clip_from_world", "0".to_string(), "mat4x4<f32>"),
                ("world_position", "64".to_string(), "vec3<f32>"),
                ("exposure", "76".to_string(), "f32"),
                ("normal_from_world", "80".to_string(), "mat3x3<f32>"),
                ("viewport", "128".to_string(), "vec4<f32>"),
                ("lights[i].color", "144 + 32 i (i < 4)".to_string(), "vec4<f32>"),
                ("lights[i].dir", "160 + 32 i (i < 4)".to_string(), "vec3<f32>"),
                ("lights[i].range", "172 + 32 i (i < 4)".to_string(), "f32"),
                ("count", "272".to_string(), "u32"),
            ]
        );
        // 276 bytes rounded up to the struct's 16-byte alignment.
        assert_eq!(view.size, 288);
        let counts = &layouts[1];
        assert_eq!((counts.group, counts.binding, counts.space.as_str()), (1, 2, "storage, read_write"));
        assert_eq!(offset_text(&counts.leaves[0]), "0 + 4 i");
        assert_eq!(counts.leaves[0].ty, "atomic<u32>");
    }
}
