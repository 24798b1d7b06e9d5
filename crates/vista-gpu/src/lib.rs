#![deny(missing_docs)]
//! Headless wgpu compute for vista: one shared context per process (instance,
//! adapter choice, device, queue), WGSL composition of a [`ShaderSet`], dispatch
//! of a compute entry point over a W x H image, and readback into an f32 RGBA
//! [`Image`](vista_image::Image).
//!
//! Not for: knowing about specific kernels. A dispatch is a shader file name,
//! an entry point, a workgroup count, a uniform block, a u32 table and a
//! size; meaning lives in `vista-kernels`, the plan in `vista-render`.

mod browser_run;
mod context;
mod coverage;
mod format;
mod fullscreen;
mod graph;
mod limits;
mod raster;
mod shaders;
mod spares;
mod tint;
pub mod validation;
mod wgpu_run;
pub mod wire;

pub use context::{
    AdapterChoice, AdapterSettings, BACKENDS, Context, DEFAULT_TIMEOUT, DeviceFacts, GpuConfig, PassHook, RunStats,
    SWIFTSHADER_HINT, VALIDATION_LAYER_JSON,
};
pub use coverage::Coverage;
pub use fullscreen::{FULLSCREEN_ENTRY, FULLSCREEN_WGSL};
pub use graph::{
    Address, Bind, BufferUse, COMPARE_NAMES, Contents, Depth, Graph, GraphPass, GraphSlot, OutputData, OutputRef,
    Raster, RasterTarget, Readback, Resource, SamplerDesc, TextureDesc, VertexBuffer, buffer_size, buffer_usages,
    run_order,
};
pub use limits::Needs;
pub use shaders::{
    DEFAULT_COMPOSE_LIMIT, ENUMS_MODULE, Reader, ReplaceKeys, ShaderSet, SourceText, compose_limit, generated_origin,
    is_unit_test_file, resolve_overrides, runaway_compositions, set_compose_limit, validate,
};
pub use tint::TintWgsl;

/// Hint printed whenever no usable Vulkan adapter is found.
pub const INSTALL_HINT: &str = "install Mesa's lavapipe software Vulkan driver with `bash ci/install-lavapipe.sh` \
(or `sudo apt-get install mesa-vulkan-drivers libvulkan1`); set VISTA_ALLOW_NO_GPU=1 to skip GPU tests loudly";

/// Everything that can go wrong creating the context or running a dispatch
/// or pass graph on it.
#[derive(Debug, Clone, thiserror::Error)]
pub enum GpuError {
    /// No enumerated adapter matches the [`AdapterChoice`], or, for the
    /// browser backend, no Chromium was found.
    #[error("no {wanted} found (seen: {seen}); {hint}")]
    NoAdapter {
        /// The adapter asked for, in words.
        wanted: String,
        /// The adapters enumerated (`name [device type, backend]`), or where
        /// Chromium was looked for.
        seen: String,
        /// How to install the missing driver or browser.
        hint: &'static str,
    },
    /// wgpu's device request failed, or headless Chromium failed to launch,
    /// died or had no WebGPU device.
    #[error("device request failed on {adapter}: {message}")]
    Device {
        /// The adapter's name or description.
        adapter: String,
        /// What failed.
        message: String,
    },
    /// A kernel file was not found, or its WGSL failed to parse, compose,
    /// pass naga's validation, resolve its overrides or be written back as
    /// WGSL; holds the message.
    #[error("{0}")]
    Shader(String),
    /// wgpu reported a validation error (error scope, device poll or buffer
    /// map), the Khronos validation layer reported messages, or the browser
    /// page reported an error.
    #[error("GPU validation error in {what}: {message}")]
    Validation {
        /// The shader, pass or step the error arose in.
        what: String,
        /// The error or the joined validation messages.
        message: String,
    },
    /// A GPU wait or readback map took longer than the context's watchdog.
    #[error(
        "GPU wait exceeded {seconds} s ({what}); the dispatch is too heavy for this device or the driver hung; lower the size or step counts, or raise VISTA_GPU_TIMEOUT_S"
    )]
    Timeout {
        /// The shader, pass or step that was waited on.
        what: String,
        /// The watchdog timeout, in seconds.
        seconds: f64,
    },
    /// The request cannot be carried out as made, e.g. an unknown backend,
    /// adapter or output format name, a size outside the device's range, a
    /// resource bound as the wrong kind, or a second configuration for the
    /// process's shared context.
    #[error("{0}")]
    Request(String),
    /// The kernel needs a feature or limit this backend lacks (SPEC 14,
    /// "Features and limits"): the case is unsupported here, not broken.
    #[error("unsupported on {adapter}: {what} needs {feature}, which this backend lacks")]
    Unsupported {
        /// [`Context::adapter_description`] of the device.
        adapter: String,
        /// The kernel or pass, and what of it needs the feature or limit.
        what: String,
        /// The missing feature, or the limit with the value needed and had.
        feature: String,
    },
}

impl GpuError {
    /// A wgpu validation error of `what`, its innermost cause first: wgpu's
    /// own text starts "Validation Error" and puts the reason last.
    pub(crate) fn wgpu(what: &str, e: &wgpu::Error) -> GpuError {
        GpuError::Validation { what: what.to_string(), message: detail_first(&e.to_string()) }
    }
}

/// wgpu's "Validation Error\n\nCaused by:\n  In ...\n    reason" as
/// "reason (In ...; ...)"; any other text as it is.
fn detail_first(text: &str) -> String {
    let Some((_, causes)) = text.split_once("Caused by:") else { return text.to_string() };
    let mut lines: Vec<&str> = causes.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    match lines.pop() {
        None => text.to_string(),
        Some(last) if lines.is_empty() => last.to_string(),
        Some(last) => format!("{last} ({})", lines.join("; ")),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn wgpu_errors_put_their_reason_first() {
        let wgpu = "Validation Error\n\nCaused by:\n  In Device::create_render_pipeline, label = 'k.wgsl'\n    Color state [0] is \
                    invalid\n      Output format Float32x4 is incompatible with the shader Uint32x4\n";
        assert_eq!(
            super::detail_first(wgpu),
            "Output format Float32x4 is incompatible with the shader Uint32x4 (In Device::create_render_pipeline, \
             label = 'k.wgsl'; Color state [0] is invalid)"
        );
        assert_eq!(super::detail_first("map failed"), "map failed");
    }
}
