//! Why a render could not be made, and the exit code that says so.

/// Why a render could not be made.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The request is the user's to fix (size, work cap, a shader that does
    /// not compose, a `Params` struct that does not fit the manifest).
    #[error("{0}")]
    BadInput(String),
    /// The device failed, or refused the request.
    #[error(transparent)]
    Gpu(#[from] vista_gpu::GpuError),
    /// The project's files could not be read.
    #[error(transparent)]
    Project(#[from] vista_project::ProjectError),
    /// An image could not be read, written or compared.
    #[error(transparent)]
    Image(#[from] vista_image::ImageError),
    /// The worker process running the graph died: the driver crashed.
    #[error("{0}")]
    Crashed(Box<Crash>),
    /// A file or directory could not be used.
    #[error("{path}: {message}")]
    Io {
        /// The path.
        path: String,
        /// What went wrong.
        message: String,
    },
}

/// A worker that died while running a graph.
#[derive(Debug, Clone, thiserror::Error)]
#[error("the {backend} driver ({adapter}) crashed ({how}) in {pass} of kernel {kernel}")]
pub struct Crash {
    /// lavapipe | swiftshader | gpu.
    pub backend: String,
    /// The adapter's description (name, driver and version).
    pub adapter: String,
    /// `signal 11, SIGSEGV` and the like.
    pub how: String,
    /// The pass it was running (`pass 1 (main, fbm.wgsl)`).
    pub pass: String,
    /// The kernel.
    pub kernel: String,
}

impl RenderError {
    /// The device's watchdog ended the render (a hung or endless kernel).
    pub fn is_timeout(&self) -> bool {
        matches!(self, RenderError::Gpu(vista_gpu::GpuError::Timeout { .. }))
    }

    /// Process exit code: 2 for bad input, 1 for failures while running.
    pub fn exit_code(&self) -> i32 {
        match self {
            RenderError::BadInput(_) | RenderError::Project(_) | RenderError::Image(_) | RenderError::Io { .. } => 2,
            RenderError::Gpu(vista_gpu::GpuError::Request(_)) => 2,
            RenderError::Gpu(_) | RenderError::Crashed(_) => 1,
        }
    }
}
