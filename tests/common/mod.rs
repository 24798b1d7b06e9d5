//! The one set of helpers the top-level test files share: this checkout as
//! a vista project, and its GPU renderer. Test code may name the checkout
//! through the build-time path; the library crates never do.
#![allow(dead_code)]

use std::path::Path;
use std::sync::OnceLock;

use vista_golden::{Renderer, allow_no_gpu};
use vista_kernels::{Kernel, ParamSet};
use vista_project::Project;

/// `kernel`'s params from a preset and `name=value` overrides; panics with
/// the error on bad test input.
pub fn params(kernel: &Kernel, preset: Option<&str>, set: &[(&str, &str)]) -> ParamSet {
    let o: Vec<(String, String)> = set.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    kernel.resolve(preset, &o).unwrap_or_else(|e| panic!("{} {preset:?} {set:?}: {e}", kernel.name()))
}

/// This checkout as a project (its `vista.toml`, `shaders/`, `golden/`).
pub fn project() -> Project {
    Project::at(Path::new(env!("CARGO_MANIFEST_DIR"))).expect("the repository is a vista project")
}

/// The shared renderer over this checkout's shaders. Without an adapter
/// this panics with the install hint, unless `VISTA_ALLOW_NO_GPU=1`, in
/// which case it prints a loud SKIPPED line naming the test and returns
/// `None`.
pub fn gpu_for_test(test: &str) -> Option<&'static Renderer<'static>> {
    static GPU: OnceLock<Result<Renderer<'static>, String>> = OnceLock::new();
    let gpu = GPU.get_or_init(|| {
        let ctx = vista_gpu::Context::shared().map_err(|e| e.to_string())?;
        Renderer::new(ctx, &project()).map_err(|e| e.to_string())
    });
    match gpu {
        Ok(r) => Some(r),
        Err(e) if allow_no_gpu() => {
            eprintln!("!!! VISTA_ALLOW_NO_GPU=1: SKIPPED GPU test '{test}': {e}");
            None
        }
        Err(e) => panic!("GPU test '{test}' cannot run: {e}"),
    }
}
