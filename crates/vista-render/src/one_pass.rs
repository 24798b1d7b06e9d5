//! A one-pass kernel (no `[[pass]]`, `[[resource]]` or `[[output]]`
//! tables) planned as a graph of one pass: its entry point dispatched once
//! over one texture, which its storage binding declares and which is read
//! back as the kernel's one output ([`crate::MAIN_OUTPUT`]).

use vista_gpu::{Bind, Contents, GraphSlot, ShaderSet};
use vista_kernels::{Kernel, ParamSet};

use crate::error::RenderError;
use crate::graph::{Plan, PlannedKind, PlannedOutput};

/// The one-pass plan of `kernel` with `p` at `width` x `height`: the kernel
/// file composed for these params, its `Params` struct checked against the
/// manifest (a field with no param, a param with no field, a type mismatch
/// are bad input), its uniforms packed from naga's reflection.
pub(crate) fn plan(
    shaders: &ShaderSet,
    kernel: &Kernel,
    p: &ParamSet,
    width: u32,
    height: u32,
) -> Result<Plan, RenderError> {
    let shader = kernel.shader_for(p);
    let module = shaders.compose(&shader).map_err(|e| match e {
        // A missing or broken shader file is the user's to fix.
        vista_gpu::GpuError::Shader(m) => RenderError::BadInput(format!("kernel {}: {m}", kernel.name())),
        other => RenderError::Gpu(other),
    })?;
    let layout = kernel.layout(&module).map_err(|e| RenderError::BadInput(e.to_string()))?;
    let entry = kernel.entry();
    let constants = kernel.overrides(&module, p).map_err(|e| RenderError::BadInput(e.to_string()))?;
    let workgroup_size = crate::reflect::workgroup_size(&module, entry, &constants)
        .map_err(|e| RenderError::BadInput(format!("kernel {}: {shader}: {e}", kernel.name())))?;
    let target = layout.output.as_ref().expect("Kernel::layout resolves the output");
    let format = target.storage.format;
    let extent = target.extent(kernel.name(), p, width, height).map_err(|e| RenderError::BadInput(e.to_string()))?;
    let read_write = target.storage.access == vista_texel::Access::ReadWrite;
    let uniforms = kernel.uniforms(&layout, p, width, height);
    let table = kernel.table(&layout, p);
    use vista_kernels::bindings::Feed;
    let slots: Vec<GraphSlot> = layout
        .bindings
        .iter()
        .map(|b| GraphSlot {
            group: b.group,
            binding: b.binding,
            bind: match b.feed {
                Feed::Uniform => Bind::Uniform(
                    layout
                        .blocks
                        .iter()
                        .position(|u| (u.group, u.binding) == (b.group, b.binding))
                        .map(|n| uniforms[n].clone())
                        .expect("every uniform binding is a block"),
                ),
                Feed::Table => Bind::Table(table.clone()),
                Feed::Output(_) => Bind::StorageTexture {
                    resource: 0,
                    access: if read_write { vista_texel::Access::ReadWrite } else { vista_texel::Access::Write },
                    level: 0,
                },
                _ => unreachable!("bindings::reflect refuses the graph feeds"),
            },
        })
        .collect();
    let workgroups = match kernel.workgroups(p, width, height).map_err(|e| RenderError::BadInput(e.to_string()))? {
        Some(count) => count,
        // Cover the output, layers and slices along z: the workgroup size
        // is the shader's, never assumed.
        None => [
            extent.width.div_ceil(workgroup_size[0]),
            extent.height.div_ceil(workgroup_size[1]),
            extent.layers.div_ceil(workgroup_size[2]),
        ],
    };
    let texture = vista_gpu::TextureDesc {
        format,
        dimension: target.storage.dimension,
        width: extent.width,
        height: extent.height,
        layers: extent.layers,
        mip_levels: 1,
        // A read_write output starts as zeros (the kernel may read a texel
        // before writing it); texels left as they were are not unwritten.
        contents: if read_write { Contents::Zeros } else { Contents::Sentinel },
    };
    let pass = vista_gpu::GraphPass {
        label: format!("pass 1 ({entry}, {shader})"),
        shader: shader.clone(),
        entry: entry.to_string(),
        constants,
        workgroups,
        slots,
        repeat: 1,
        swap: Vec::new(),
        span: 1,
        workgroup_size,
    };
    let output = PlannedOutput {
        name: crate::MAIN_OUTPUT.to_string(),
        tolerance: None,
        partial: kernel.partial(),
        kind: PlannedKind::Texture { format, view: kernel.view(format), display: kernel.display_map_of(p, format) },
    };
    Ok(Plan {
        kernel: kernel.name().to_string(),
        resources: vec![vista_gpu::Resource::Texture(texture)],
        passes: vec![pass],
        output_ids: vec![0],
        outputs: vec![output],
        deterministic: true,
        shaders: vec![shader],
    })
}
