//! `vista bench`: median kernel throughput after a warm-up run, optionally
//! beside the f32 CPU reference on all cores.

use vista_golden::GoldenError;
use vista_gpu::Context;
use vista_project::Project;
use vista_render::Renderer;

use crate::{bad, parse_sets};

#[allow(clippy::too_many_arguments)]
pub fn bench(
    project: &Project,
    config: &vista::Config,
    kernel: &str,
    preset: Option<&str>,
    set: &[String],
    size: &str,
    runs: u32,
    json: bool,
    cpu: bool,
) -> Result<i32, GoldenError> {
    if !(1..=1000).contains(&runs) {
        return Err(bad(format!("--runs {runs} is out of range; allowed: [1, 1000]")));
    }
    let k = crate::registry(project)?.find(kernel).map_err(bad)?;
    let p = k.resolve(preset, &parse_sets(set)?).map_err(bad)?;
    let (w, h) = vista_kernels::parse_size(size).map_err(bad)?;
    let shaders = vista_render::shader_set(project)?;
    vista_render::plan(&shaders, k, &p, w, h, &config.limits)?;
    if cpu && !k.has_reference() {
        return Err(bad(format!("--cpu: kernel {kernel} has no CPU reference (only built-in kernels have one)")));
    }
    let ctx = &Renderer { ctx: Context::shared(&config.gpu)?, shaders, limits: config.limits };
    // Warm-up: compiles the pipeline and touches every allocation path once.
    // Whole first call: WGSL composition, pipeline creation (lavapipe JIT), dispatch, readback.
    let first = vista_render::render(ctx, k, &p, w, h)?.stats.total.as_secs_f64();
    let mut stats = Vec::new();
    for _ in 0..runs {
        stats.push(vista_render::render(ctx, k, &p, w, h)?.stats);
    }
    let med = |f: fn(&vista_gpu::RunStats) -> std::time::Duration| {
        vista_render::median(stats.iter().map(f).collect()).as_secs_f64()
    };
    let (median, kernel_s, readback_s) = (med(|s| s.gpu_wall), med(|s| s.kernel), med(|s| s.readback));
    let mpix = (w as f64 * h as f64) / 1e6 / median;
    // The CPU side: the reference in f32 on every core (rayon), median of
    // up to 3 runs since the slow ones take seconds per image.
    let cpu_ms = cpu.then(|| {
        let t = vista_render::median_wall(runs.min(3), || {
            k.reference_f32(&p, w, h);
        });
        t.as_secs_f64() * 1e3
    });
    if json {
        let mut out = serde_json::json!({
            "kernel": kernel, "width": w, "height": h, "runs": runs,
            "median_ms": median * 1e3, "mpix_per_s": mpix,
            "kernel_ms": kernel_s * 1e3, "readback_ms": readback_s * 1e3,
            "device_creation_ms": ctx.creation_time.as_secs_f64() * 1e3,
            "first_dispatch_ms": first * 1e3,
            "adapter": ctx.adapter_description(), "params": p.canonical(),
        });
        if let Some(ms) = cpu_ms {
            out["cpu_f32_ms"] = ms.into();
            out["cpu_threads"] = rayon::current_num_threads().into();
            out["cpu_over_gpu"] = (ms / (median * 1e3)).into();
        }
        println!("{out}");
    } else {
        println!(
            "{kernel} {w}x{h}: median {:.2} ms over {runs} runs, {mpix:.2} Mpix/s on {}",
            median * 1e3,
            ctx.adapter_description()
        );
        println!(
            "  of which the kernel {:.2} ms and the readback (copy, map, unpad) {:.2} ms",
            kernel_s * 1e3,
            readback_s * 1e3
        );
        println!(
            "device creation {:.1} ms, first call (compose + pipeline compile + dispatch + readback) {:.1} ms",
            ctx.creation_time.as_secs_f64() * 1e3,
            first * 1e3
        );
        if let Some(ms) = cpu_ms {
            println!(
                "f32 CPU reference on {} threads: {ms:.2} ms = {:.2}x the GPU time",
                rayon::current_num_threads(),
                ms / (median * 1e3)
            );
        }
    }
    Ok(0)
}
