//! Headless wgpu compute for vista: one shared context per process (instance,
//! adapter choice, device, queue), WGSL composition of a [`ShaderSet`], dispatch
//! of a compute entry point over a W x H image, and readback into an f32 RGBA
//! [`Image`](vista_image::Image).
//!
//! Not for: knowing about specific kernels. A dispatch is a shader file name,
//! an entry point, a workgroup count, a uniform block, a u32 table and a
//! size; meaning lives in `vista-kernels`, the plan in `vista-render`.

mod context;
mod format;
mod graph;
mod limits;
mod shaders;
pub mod validation;

pub use context::{
    AdapterChoice, AdapterSettings, BACKENDS, Context, DEFAULT_TIMEOUT, Dimension, Dispatch, GpuConfig, Readback,
    RunStats, SWIFTSHADER_HINT, Slot, SlotKind, UNWRITTEN, VALIDATION_LAYER_JSON,
};
pub use format::{OutputFormat, SampleKind, format_names};
pub use graph::{
    Access, Address, Bind, COMPARE_NAMES, Contents, Graph, GraphPass, GraphReadback, GraphSlot, OutputData, Resource,
    SamplerDesc, TextureDesc,
};
pub use limits::Needs;
pub use shaders::{ShaderSet, resolve_overrides, validate};

/// Hint printed whenever no usable Vulkan adapter is found.
pub const INSTALL_HINT: &str = "install Mesa's lavapipe software Vulkan driver with `bash ci/install-lavapipe.sh` \
(or `sudo apt-get install mesa-vulkan-drivers libvulkan1`); set VISTA_ALLOW_NO_GPU=1 to skip GPU tests loudly";

#[derive(Debug, Clone, thiserror::Error)]
pub enum GpuError {
    #[error("no {wanted} found (seen: {seen}); {hint}")]
    NoAdapter { wanted: String, seen: String, hint: &'static str },
    #[error("device request failed on {adapter}: {message}")]
    Device { adapter: String, message: String },
    #[error("{0}")]
    Shader(String),
    #[error("GPU validation error in {what}: {message}")]
    Validation { what: String, message: String },
    #[error(
        "GPU wait exceeded {seconds} s ({what}); the dispatch is too heavy for this device or the driver hung; lower the size or step counts, or raise VISTA_GPU_TIMEOUT_S"
    )]
    Timeout { what: String, seconds: f64 },
    #[error("{0}")]
    Request(String),
    /// The kernel needs a feature or limit this backend lacks (SPEC 14,
    /// "Features and limits"): the case is unsupported here, not broken.
    #[error("unsupported on {adapter}: {what} needs {feature}, which this backend lacks")]
    Unsupported { adapter: String, what: String, feature: String },
}
