//! The device's limits by WebGPU's names (`maxStorageTexturesPerShaderStage`),
//! so that a kernel needing more than a backend grants is reported
//! *unsupported*, naming the limit (SPEC 14, "Features and limits"), before
//! any GPU work, instead of failing as a driver validation error.

use crate::GpuError;

/// What one dispatch needs of the device.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Needs {
    /// The entry point's `@workgroup_size` (x, y, z).
    pub workgroup_size: [u32; 3],
    /// Workgroups dispatched along x, y and z.
    pub workgroups: [u32; 3],
    /// Bind groups used: the highest `@group` index plus one.
    pub bind_groups: u32,
    /// Uniform buffer bindings (`maxUniformBuffersPerShaderStage`).
    pub uniform_buffers: u32,
    /// Storage buffer bindings (`maxStorageBuffersPerShaderStage`).
    pub storage_buffers: u32,
    /// Storage texture bindings (`maxStorageTexturesPerShaderStage`).
    pub storage_textures: u32,
    /// Sampled texture bindings (`maxSampledTexturesPerShaderStage`).
    pub sampled_textures: u32,
    /// Sampler bindings (`maxSamplersPerShaderStage`).
    pub samplers: u32,
}

/// Reads one limit from wgpu's.
type Read = fn(&wgpu::Limits) -> u64;

/// The limits vista checks, by WebGPU's name, read from wgpu's.
const WGPU_LIMITS: [(&str, Read); 19] = [
    ("maxComputeWorkgroupSizeX", |l| l.max_compute_workgroup_size_x as u64),
    ("maxComputeWorkgroupSizeY", |l| l.max_compute_workgroup_size_y as u64),
    ("maxComputeWorkgroupSizeZ", |l| l.max_compute_workgroup_size_z as u64),
    ("maxComputeInvocationsPerWorkgroup", |l| l.max_compute_invocations_per_workgroup as u64),
    ("maxComputeWorkgroupsPerDimension", |l| l.max_compute_workgroups_per_dimension as u64),
    ("maxComputeWorkgroupStorageSize", |l| l.max_compute_workgroup_storage_size as u64),
    ("maxBindGroups", |l| l.max_bind_groups as u64),
    ("maxUniformBuffersPerShaderStage", |l| l.max_uniform_buffers_per_shader_stage as u64),
    ("maxStorageBuffersPerShaderStage", |l| l.max_storage_buffers_per_shader_stage as u64),
    ("maxStorageTexturesPerShaderStage", |l| l.max_storage_textures_per_shader_stage as u64),
    ("maxSampledTexturesPerShaderStage", |l| l.max_sampled_textures_per_shader_stage as u64),
    ("maxSamplersPerShaderStage", |l| l.max_samplers_per_shader_stage as u64),
    ("maxTextureDimension1D", |l| l.max_texture_dimension_1d as u64),
    ("maxTextureDimension2D", |l| l.max_texture_dimension_2d as u64),
    ("maxTextureDimension3D", |l| l.max_texture_dimension_3d as u64),
    ("maxTextureArrayLayers", |l| l.max_texture_array_layers as u64),
    ("maxStorageBufferBindingSize", |l| l.max_storage_buffer_binding_size),
    ("maxUniformBufferBindingSize", |l| l.max_uniform_buffer_binding_size),
    ("maxBufferSize", |l| l.max_buffer_size),
];

/// Limit `name` (WebGPU's spelling) of a wgpu device, where vista checks it.
pub(crate) fn wgpu_limit(limits: &wgpu::Limits, name: &str) -> Option<u64> {
    WGPU_LIMITS.iter().find(|(n, _)| *n == name).map(|(_, f)| f(limits))
}

/// Refuses `what` as unsupported on `adapter` when it needs more of limit
/// `name` than `limit` (the device's, by name) gives.
pub(crate) fn require(
    limit: &dyn Fn(&str) -> Option<u64>,
    adapter: &str,
    what: &str,
    name: &str,
    needed: u64,
) -> Result<(), GpuError> {
    match limit(name) {
        Some(have) if needed > have => Err(GpuError::Unsupported {
            adapter: adapter.to_string(),
            what: what.to_string(),
            feature: format!("{name} >= {needed} (this device has {have})"),
        }),
        _ => Ok(()),
    }
}

/// Checks a dispatch's workgroup size and count and its bindings against
/// `limit`; `what` names it (a pass, a kernel).
pub(crate) fn require_needs(
    limit: &dyn Fn(&str) -> Option<u64>,
    adapter: &str,
    what: &str,
    n: &Needs,
) -> Result<(), GpuError> {
    let [x, y, z] = n.workgroup_size;
    let invocations = x as u64 * y as u64 * z as u64;
    let size = format!("@workgroup_size({x}, {y}, {z})");
    let most = n.workgroups.iter().copied().max().unwrap_or(0) as u64;
    // Bindings of one kind, against their per-stage limit.
    let count = |k: u32, what: &str, name: &'static str| (format!("{k} {what}"), name, k as u64);
    let checks: Vec<(String, &str, u64)> = vec![
        (format!("{size}: {invocations} invocations per workgroup"), "maxComputeInvocationsPerWorkgroup", invocations),
        (size.clone(), "maxComputeWorkgroupSizeX", x as u64),
        (size.clone(), "maxComputeWorkgroupSizeY", y as u64),
        (size, "maxComputeWorkgroupSizeZ", z as u64),
        (format!("{most} workgroups along one axis"), "maxComputeWorkgroupsPerDimension", most),
        (format!("bind group {}", n.bind_groups.saturating_sub(1)), "maxBindGroups", n.bind_groups as u64),
        count(n.uniform_buffers, "uniform buffers", "maxUniformBuffersPerShaderStage"),
        count(n.storage_buffers, "storage buffers", "maxStorageBuffersPerShaderStage"),
        count(n.storage_textures, "storage textures", "maxStorageTexturesPerShaderStage"),
        count(n.sampled_textures, "sampled textures", "maxSampledTexturesPerShaderStage"),
        count(n.samplers, "samplers", "maxSamplersPerShaderStage"),
    ];
    for (need, name, value) in &checks {
        require(limit, adapter, &format!("{what}: {need}"), name, *value)?;
    }
    Ok(())
}
