//! The one set of helpers the top-level test files share: this checkout as
//! a vista project, and its GPU renderer. Test code may name the checkout
//! through the build-time path; the library crates never do.
#![allow(dead_code)]

use std::path::Path;
use std::sync::OnceLock;

use vista_kernels::{Kernel, ParamSet};
use vista_project::Project;
use vista_render::Renderer;

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

/// This process's configuration, read once from the environment (the test
/// harness is an edge, like the binary).
pub fn config() -> &'static vista::Config {
    static CONFIG: OnceLock<vista::Config> = OnceLock::new();
    CONFIG.get_or_init(|| vista::Config::from_env(&vista::Flags::default()).unwrap_or_else(|e| panic!("{e}")))
}

/// True when the user set `VISTA_ALLOW_NO_GPU=1`.
pub fn allow_no_gpu() -> bool {
    config().allow_no_gpu
}

/// The shared renderer over this checkout's shaders, or why there is none.
pub fn renderer() -> Result<&'static Renderer<'static>, String> {
    static GPU: OnceLock<Result<Renderer<'static>, String>> = OnceLock::new();
    GPU.get_or_init(|| {
        let ctx = vista_gpu::Context::shared(&config().gpu).map_err(|e| e.to_string())?;
        Renderer::new(ctx, &project(), config().limits).map_err(|e| e.to_string())
    })
    .as_ref()
    .map_err(Clone::clone)
}

/// A context of its own on backend `name` (lavapipe, swiftshader,
/// browser) with this process's settings; the Khronos layer, being wgpu's,
/// is left off for the browser, whose Dawn validates always.
pub fn backend_context(name: &str) -> Result<vista_gpu::Context, String> {
    let base = &config().gpu;
    let config = vista_gpu::GpuConfig {
        adapter: vista_gpu::AdapterChoice::of_backend(name).map_err(|e| e.to_string())?,
        validate: base.validate && name != "browser",
        ..base.clone()
    };
    vista_gpu::Context::new(&config).map_err(|e| format!("{name}: {e}"))
}

/// Renders `kernel` of the vista project at `dir` on `ctx`, its params the
/// defaults with `set` over them, at `width` x `height`.
pub fn render_in_project(
    ctx: &vista_gpu::Context,
    dir: &Path,
    kernel: &str,
    set: &[(String, String)],
    size: (u32, u32),
) -> Result<vista_render::Rendered, String> {
    let project = Project::at(dir).map_err(|e| e.to_string())?;
    let gpu = Renderer::new(ctx, &project, config().limits).map_err(|e| e.to_string())?;
    let kernels = vista_kernels::Registry::of_project(&project).map_err(|e| e.to_string())?;
    let kernel = kernels.find(kernel).map_err(|e| e.to_string())?;
    let params = kernel.resolve(None, set).map_err(|e| e.to_string())?;
    vista_render::render(&gpu, kernel, &params, size.0, size.1)
        .map_err(|e| format!("{} on {}: {e}", kernel.name(), gpu.backend()))
}

/// For benches: the renderer, or a panic with the install hint.
pub fn gpu_for_bench() -> &'static Renderer<'static> {
    renderer().unwrap_or_else(|e| panic!("benchmarks need a GPU adapter: {e}"))
}

/// A GPU test: its name and body.
pub type GpuTest = (&'static str, fn(&Renderer<'static>));

/// Runs a file's GPU tests under libtest-mimic (filters, `--list`,
/// `--ignored` as cargo test has them). Without an adapter every test fails
/// with the install hint, unless `VISTA_ALLOW_NO_GPU=1`: then each is
/// reported *ignored* by the harness (never "ok") and a loud line counts them.
pub fn run_gpu_tests(tests: &[GpuTest]) -> ! {
    let args = libtest_mimic::Arguments::from_args();
    let skip = if args.list { None } else { renderer().err().filter(|_| allow_no_gpu()) };
    if let Some(e) = &skip {
        let names: Vec<&str> = tests.iter().map(|t| t.0).collect();
        eprintln!("\n!!! VISTA_ALLOW_NO_GPU=1 and no adapter: {e}");
        eprintln!("!!! SKIPPED {} GPU tests (reported ignored): {}\n", tests.len(), names.join(", "));
    }
    let trials = tests
        .iter()
        .map(|&(name, body)| {
            libtest_mimic::Trial::test(name, move || {
                let gpu = renderer().map_err(|e| format!("GPU test '{name}' cannot run: {e}"))?;
                body(gpu);
                Ok(())
            })
            .with_ignored_flag(skip.is_some())
        })
        .collect();
    libtest_mimic::run(&args, trials).exit()
}

/// A renderer over this checkout's shaders with one edit (`from`, which
/// must occur exactly once in `file`, replaced by `to`), composed in memory
/// as `vista mutate` composes its mutants: nothing is written anywhere.
pub fn with_edit(gpu: &Renderer<'static>, file: &str, from: &str, to: &str) -> Renderer<'static> {
    let files = project().shader_files().expect("the checkout's shaders");
    let target = files.iter().find(|f| f.rel == file).unwrap_or_else(|| panic!("no shader {file}"));
    assert_eq!(target.text.matches(from).count(), 1, "{file}: '{from}' must occur exactly once (shader changed?)");
    let shaders = vista_render::edited_shader_set(&project(), "edited", |rel, text| match rel == file {
        true => text.replace(from, to),
        false => text,
    })
    .expect("the checkout's shaders");
    // In this process: the edit is not a file a worker could rebuild.
    Renderer { ctx: gpu.ctx, worker: None, edits: Vec::new(), shaders, limits: gpu.limits, root: gpu.root.clone() }
}

/// Runs a file's GPU test functions, each named by itself (see
/// [`run_gpu_tests`]).
#[allow(unused_macros)] // files without GPU tests include this module too
macro_rules! gpu_tests {
    ($($f:ident),* $(,)?) => {
        common::run_gpu_tests(&[$((stringify!($f), $f as fn(&vista_render::Renderer<'static>))),*])
    };
}
#[allow(unused_imports)]
pub(crate) use gpu_tests;
