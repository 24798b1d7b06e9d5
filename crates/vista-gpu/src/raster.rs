//! A render pass's fixed-function state in wgpu's terms: blend equations,
//! vertex buffer layouts, primitive and depth state (SPEC 17). The plan
//! holds WebGPU's names; this maps them once.

use vista_texel::{BlendComponent, BlendFactor, BlendOp, Cull, Topology};

use crate::GpuError;
use crate::graph::{Raster, Resource, VertexBuffer};

fn blend_component(c: BlendComponent) -> wgpu::BlendComponent {
    use wgpu::BlendFactor as W;
    let factor = |f: BlendFactor| match f {
        BlendFactor::Zero => W::Zero,
        BlendFactor::One => W::One,
        BlendFactor::Src => W::Src,
        BlendFactor::OneMinusSrc => W::OneMinusSrc,
        BlendFactor::SrcAlpha => W::SrcAlpha,
        BlendFactor::OneMinusSrcAlpha => W::OneMinusSrcAlpha,
        BlendFactor::Dst => W::Dst,
        BlendFactor::OneMinusDst => W::OneMinusDst,
        BlendFactor::DstAlpha => W::DstAlpha,
        BlendFactor::OneMinusDstAlpha => W::OneMinusDstAlpha,
        BlendFactor::SrcAlphaSaturated => W::SrcAlphaSaturated,
        BlendFactor::Constant => W::Constant,
        BlendFactor::OneMinusConstant => W::OneMinusConstant,
        BlendFactor::Src1 => W::Src1,
        BlendFactor::OneMinusSrc1 => W::OneMinusSrc1,
        BlendFactor::Src1Alpha => W::Src1Alpha,
        BlendFactor::OneMinusSrc1Alpha => W::OneMinusSrc1Alpha,
    };
    let operation = match c.op {
        BlendOp::Add => wgpu::BlendOperation::Add,
        BlendOp::Subtract => wgpu::BlendOperation::Subtract,
        BlendOp::ReverseSubtract => wgpu::BlendOperation::ReverseSubtract,
        BlendOp::Min => wgpu::BlendOperation::Min,
        BlendOp::Max => wgpu::BlendOperation::Max,
    };
    wgpu::BlendComponent { src_factor: factor(c.src), dst_factor: factor(c.dst), operation }
}

/// Targets that need a feature the backend lacks (`has`, by WebGPU name):
/// a blended 32-bit float target needs float32-blendable, an rg11b10ufloat
/// one rg11b10ufloat-renderable. The case is unsupported here, naming it.
pub(crate) fn check_targets(
    r: &Raster,
    resources: &[Resource],
    label: &str,
    has: &dyn Fn(&str) -> bool,
    adapter: &dyn Fn() -> String,
) -> Result<(), GpuError> {
    for t in &r.targets {
        let Resource::Texture(desc) = &resources[t.resource] else { continue };
        let format = crate::format::parse(desc.format)?;
        let needs = if desc.format == "rg11b10ufloat" {
            Some(("rg11b10ufloat-renderable", format!("{label}: an {} target", desc.format)))
        } else if t.blend != vista_texel::Blend::Replace && format.is_float32() {
            Some(("float32-blendable", format!("{label}: a blended {} target", desc.format)))
        } else {
            None
        };
        if let Some((feature, what)) = needs.filter(|(f, _)| !has(f)) {
            return Err(GpuError::Unsupported { adapter: adapter(), what, feature: feature.into() });
        }
    }
    Ok(())
}

/// The fragment entry's outputs against the pass's targets, before any
/// pipeline is made (wgpu would only say "Color state [0] is invalid"):
/// each target's `@location` must be written with the scalar kind its
/// format stores (f32 for float and normalized formats, u32, i32), and a
/// `src1` blend factor needs the entry's second (`@blend_src(1)`) output.
pub(crate) fn check_fragment(
    module: &naga::Module,
    entry: &str,
    r: &Raster,
    resources: &[Resource],
    label: &str,
) -> Result<(), GpuError> {
    let Some(ep) = module.entry_points.iter().find(|e| e.name == entry && e.stage == naga::ShaderStage::Fragment)
    else {
        return Ok(()); // naga and wgpu name a missing entry themselves.
    };
    // (location, blend_src, scalar kind) of every output.
    let mut outputs: Vec<(u32, Option<u32>, Option<naga::ScalarKind>)> = Vec::new();
    let kind = |ty: naga::Handle<naga::Type>| module.types[ty].inner.scalar_kind();
    if let Some(result) = &ep.function.result {
        match (&result.binding, &module.types[result.ty].inner) {
            (Some(naga::Binding::Location { location, blend_src, .. }), _) => {
                outputs.push((*location, *blend_src, kind(result.ty)))
            }
            (None, naga::TypeInner::Struct { members, .. }) => {
                for m in members {
                    if let Some(naga::Binding::Location { location, blend_src, .. }) = &m.binding {
                        outputs.push((*location, *blend_src, kind(m.ty)));
                    }
                }
            }
            _ => {}
        }
    }
    let name = |k: naga::ScalarKind| match k {
        naga::ScalarKind::Uint => "u32",
        naga::ScalarKind::Sint => "i32",
        naga::ScalarKind::Bool => "bool",
        _ => "f32",
    };
    for (n, t) in r.targets.iter().enumerate() {
        let Resource::Texture(desc) = &resources[t.resource] else { continue };
        let format = crate::format::parse(desc.format)?;
        let want = match format.sample_kind() {
            vista_texel::SampleKind::Float => naga::ScalarKind::Float,
            vista_texel::SampleKind::Uint => naga::ScalarKind::Uint,
            vista_texel::SampleKind::Sint => naga::ScalarKind::Sint,
        };
        let written = outputs.iter().find(|(l, b, _)| *l == n as u32 && b.unwrap_or(0) == 0).and_then(|o| o.2);
        if let Some(got) = written.filter(|g| *g != want) {
            return Err(GpuError::Request(format!(
                "{label}: fragment entry {entry} writes @location({n}) as {}, but target {n} is {}, which stores {}; \
                 write {} there, or draw into a format that stores {}",
                name(got),
                desc.format,
                name(want),
                name(want),
                name(got)
            )));
        }
        if t.blend.uses_src1() && !outputs.iter().any(|(l, b, _)| *l == n as u32 && *b == Some(1)) {
            return Err(GpuError::Request(format!(
                "{label}: target {n} ({}) blends with a src1 factor, but fragment entry {entry} has no \
                 @location({n}) @blend_src(1) output; add one (enable dual_source_blending;) or use src factors",
                desc.format
            )));
        }
    }
    Ok(())
}

/// Each target's format and blend state.
pub(crate) fn color_targets(
    r: &Raster,
    resources: &[Resource],
    label: &str,
) -> Result<Vec<Option<wgpu::ColorTargetState>>, GpuError> {
    r.targets
        .iter()
        .map(|t| {
            let Resource::Texture(desc) = &resources[t.resource] else {
                return Err(GpuError::Request(format!("{label}: a target that is not a texture")));
            };
            Ok(Some(wgpu::ColorTargetState {
                format: crate::format::wgpu_format(&crate::format::parse(desc.format)?),
                blend: t.blend.components().map(|(color, alpha)| wgpu::BlendState {
                    color: blend_component(color),
                    alpha: blend_component(alpha),
                }),
                write_mask: wgpu::ColorWrites::ALL,
            }))
        })
        .collect()
}

fn vertex_format(name: &str) -> wgpu::VertexFormat {
    use wgpu::VertexFormat as F;
    match name {
        "uint8" => F::Uint8,
        "uint8x2" => F::Uint8x2,
        "uint8x4" => F::Uint8x4,
        "sint8" => F::Sint8,
        "sint8x2" => F::Sint8x2,
        "sint8x4" => F::Sint8x4,
        "unorm8" => F::Unorm8,
        "unorm8x2" => F::Unorm8x2,
        "unorm8x4" => F::Unorm8x4,
        "snorm8" => F::Snorm8,
        "snorm8x2" => F::Snorm8x2,
        "snorm8x4" => F::Snorm8x4,
        "uint16" => F::Uint16,
        "uint16x2" => F::Uint16x2,
        "uint16x4" => F::Uint16x4,
        "sint16" => F::Sint16,
        "sint16x2" => F::Sint16x2,
        "sint16x4" => F::Sint16x4,
        "unorm16" => F::Unorm16,
        "unorm16x2" => F::Unorm16x2,
        "unorm16x4" => F::Unorm16x4,
        "snorm16" => F::Snorm16,
        "snorm16x2" => F::Snorm16x2,
        "snorm16x4" => F::Snorm16x4,
        "float16" => F::Float16,
        "float16x2" => F::Float16x2,
        "float16x4" => F::Float16x4,
        "float32" => F::Float32,
        "float32x2" => F::Float32x2,
        "float32x3" => F::Float32x3,
        "float32x4" => F::Float32x4,
        "uint32" => F::Uint32,
        "uint32x2" => F::Uint32x2,
        "uint32x3" => F::Uint32x3,
        "uint32x4" => F::Uint32x4,
        "sint32" => F::Sint32,
        "sint32x2" => F::Sint32x2,
        "sint32x3" => F::Sint32x3,
        "sint32x4" => F::Sint32x4,
        "unorm10-10-10-2" => F::Unorm10_10_10_2,
        "unorm8x4-bgra" => F::Unorm8x4Bgra,
        other => unreachable!("vista_texel::VertexFormat has no {other}"),
    }
}

/// Each buffer's attributes in wgpu's terms (kept alive for the layouts).
pub(crate) fn attributes(buffers: &[VertexBuffer]) -> Vec<Vec<wgpu::VertexAttribute>> {
    buffers
        .iter()
        .map(|b| {
            b.attributes
                .iter()
                .map(|(location, format, offset)| wgpu::VertexAttribute {
                    format: vertex_format(format),
                    offset: *offset as u64,
                    shader_location: *location,
                })
                .collect()
        })
        .collect()
}

pub(crate) fn buffer_layouts<'a>(
    buffers: &[VertexBuffer],
    attributes: &'a [Vec<wgpu::VertexAttribute>],
) -> Vec<Option<wgpu::VertexBufferLayout<'a>>> {
    buffers
        .iter()
        .zip(attributes)
        .map(|(b, a)| {
            Some(wgpu::VertexBufferLayout {
                array_stride: b.stride as u64,
                step_mode: if b.instance { wgpu::VertexStepMode::Instance } else { wgpu::VertexStepMode::Vertex },
                attributes: a,
            })
        })
        .collect()
}

pub(crate) fn primitive(r: &Raster) -> wgpu::PrimitiveState {
    use wgpu::PrimitiveTopology as P;
    wgpu::PrimitiveState {
        topology: match r.topology {
            Topology::TriangleList => P::TriangleList,
            Topology::TriangleStrip => P::TriangleStrip,
            Topology::LineList => P::LineList,
            Topology::LineStrip => P::LineStrip,
            Topology::PointList => P::PointList,
        },
        // WebGPU wants the strip's index format in the pipeline when indexed.
        strip_index_format: match (r.topology, r.indices) {
            (Topology::TriangleStrip | Topology::LineStrip, Some(_)) => Some(index_format(r)),
            _ => None,
        },
        front_face: wgpu::FrontFace::Ccw,
        cull_mode: match r.cull {
            Cull::None => None,
            Cull::Back => Some(wgpu::Face::Back),
            Cull::Front => Some(wgpu::Face::Front),
        },
        ..Default::default()
    }
}

pub(crate) fn index_format(r: &Raster) -> wgpu::IndexFormat {
    if r.index_u16 { wgpu::IndexFormat::Uint16 } else { wgpu::IndexFormat::Uint32 }
}

pub(crate) fn depth_stencil(r: &Raster) -> Option<wgpu::DepthStencilState> {
    let d = r.depth.as_ref()?;
    Some(wgpu::DepthStencilState {
        format: wgpu::TextureFormat::Depth32Float,
        depth_write_enabled: Some(d.write),
        depth_compare: Some(crate::graph::compare_fn(&d.compare).expect("plans name WebGPU's comparisons")),
        stencil: Default::default(),
        bias: Default::default(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::{Contents, RasterTarget, TextureDesc};

    #[test]
    fn targets_name_the_features_they_need() {
        let texture = |format| {
            Resource::Texture(TextureDesc {
                format,
                dimension: vista_texel::Dimension::D2,
                width: 4,
                height: 4,
                layers: 1,
                mip_levels: 1,
                contents: Contents::Sentinel,
            })
        };
        let raster = |blend| Raster {
            targets: vec![RasterTarget { resource: 0, level: 0, layer: 0, clear: None, clear_once: false, blend }],
            vertex: None,
            vertex_shader: None,
            vertex_constants: Vec::new(),
            buffers: Vec::new(),
            indices: None,
            index_u16: false,
            count: 3,
            instances: 1,
            first_vertex: 0,
            first_instance: 0,
            base_vertex: 0,
            topology: Topology::TriangleList,
            cull: Cull::None,
            depth: None,
            blend_constant: None,
        };
        let adapter = || "test adapter".to_string();
        let (none, all) = (|_: &str| false, |_: &str| true);
        let f32s = [texture("rgba32float")];
        let e = check_targets(&raster(vista_texel::Blend::Additive), &f32s, "pass 1 (add)", &none, &adapter);
        let message = e.unwrap_err().to_string();
        assert!(message.contains("pass 1 (add): a blended rgba32float target needs float32-blendable"), "{message}");
        assert!(check_targets(&raster(vista_texel::Blend::Additive), &f32s, "p", &all, &adapter).is_ok());
        assert!(check_targets(&raster(vista_texel::Blend::Replace), &f32s, "p", &none, &adapter).is_ok());
        let f16s = [texture("rgba16float")];
        assert!(check_targets(&raster(vista_texel::Blend::Alpha), &f16s, "p", &none, &adapter).is_ok());
        let packed = [texture("rg11b10ufloat")];
        let e = check_targets(&raster(vista_texel::Blend::Replace), &packed, "pass 2 (bloom)", &none, &adapter);
        let message = e.unwrap_err().to_string();
        assert!(
            message.contains("pass 2 (bloom): an rg11b10ufloat target needs rg11b10ufloat-renderable"),
            "{message}"
        );
        let only_blendable = |f: &str| f == "float32-blendable";
        assert!(check_targets(&raster(vista_texel::Blend::Replace), &packed, "p", &only_blendable, &adapter).is_err());
        assert!(check_targets(&raster(vista_texel::Blend::Additive), &packed, "p", &all, &adapter).is_ok());
    }
}
