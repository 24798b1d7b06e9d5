//! A coverage run of a planned case (SPEC 20): the same graph with every
//! pass's shader composed with counters, one counter buffer per shader
//! bound at the group after the kernel's own, and only those buffers read
//! back. It runs beside the judged render, never instead of it: the
//! outputs it leaves are not looked at.

use std::borrow::Cow;

use vista_coverage::Counts;
use vista_gpu::{Bind, GraphSlot, OutputData, Resource};

use crate::{Plan, RenderError, Renderer};

/// What one coverage run measured.
#[derive(Debug, Clone, Default)]
pub struct CaseCoverage {
    /// Hits per line and branch arm of every file the passes compose.
    pub counts: Counts,
    /// Shaders not measured, each with why (the device has too few bind
    /// groups for the counter buffer's).
    pub not_measured: Vec<String>,
}

/// Plans `kernel` with `p` as [`crate::render_with`] does, then [`cover`]s it.
pub fn cover_with(
    gpu: &Renderer,
    kernel: &vista_manifest::Kernel,
    p: &vista_manifest::ParamSet,
    inputs: &crate::Inputs,
    width: u32,
    height: u32,
) -> Result<CaseCoverage, RenderError> {
    let plan = crate::plan(&gpu.shaders, gpu.root.as_deref(), kernel, p, inputs, width, height, &gpu.limits)?;
    cover(gpu, &plan)
}

/// Runs `plan` with counters and returns the hits.
pub fn cover(gpu: &Renderer, plan: &Plan) -> Result<CaseCoverage, RenderError> {
    // Vertex code is counted where the device lets the vertex stage write
    // storage, except in a case with a pass whose vertex entry lies in a
    // module of its own: that module's counters would need a binding of
    // their own beside the pass's shader's.
    let separate = plan.passes.iter().any(|p| p.raster.as_ref().is_some_and(|r| r.vertex_shader.is_some()));
    let vertex = gpu.ctx.vertex_writes_storage() && !separate;
    let shaders = gpu.shaders.covered(vertex);
    let mut names: Vec<&str> = plan.passes.iter().map(|p| p.shader.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    let groups = gpu.ctx.limit("maxBindGroups").unwrap_or(4);
    let mut out = CaseCoverage::default();
    let mut counted = Vec::new();
    for name in names {
        let cov = shaders.coverage(name)?;
        if u64::from(cov.group) >= groups {
            out.not_measured.push(format!(
                "{name}: binds group {} and the counters need group {}; this device has {groups} bind groups",
                cov.group - 1,
                cov.group
            ));
            continue;
        }
        counted.push((name, cov));
    }
    // A pass whose shader cannot be counted runs instrumented all the same
    // (its module declares the counters); without a buffer it cannot run.
    if !out.not_measured.is_empty() {
        return Ok(out);
    }
    let mut resources = plan.resources.clone();
    let mut resource_names = plan.names.clone();
    let first = resources.len();
    for (name, cov) in &counted {
        resources.push(Resource::Buffer(vec![0; cov.buffer_size() as usize]));
        resource_names.push(format!("coverage counters of {name}"));
    }
    let passes: Vec<vista_gpu::GraphPass> = plan
        .passes
        .iter()
        .map(|p| {
            let i = counted.iter().position(|(n, _)| *n == p.shader).expect("every pass's shader counted");
            let mut p = p.clone();
            p.slots.push(GraphSlot {
                group: counted[i].1.group,
                binding: 0,
                bind: Bind::Storage { resource: first + i, read_only: false },
                vertex,
            });
            p
        })
        .collect();
    let outputs: Vec<vista_gpu::OutputRef> = (first..first + counted.len()).map(vista_gpu::OutputRef::whole).collect();
    let graph = vista_gpu::Graph {
        shaders: &shaders,
        resources: Cow::Owned(resources),
        passes: Cow::Owned(passes),
        outputs: Cow::Owned(outputs),
    };
    let twin = Plan { names: resource_names, ..plan.clone() };
    let readback = crate::execute(gpu, &graph, &twin)?;
    for ((_, cov), data) in counted.iter().zip(readback.outputs) {
        let OutputData::Buffer(bytes) = data else { unreachable!("counter buffers read back as buffers") };
        let values: Vec<u32> = bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
        cov.add(&mut out.counts, &values);
    }
    Ok(out)
}
