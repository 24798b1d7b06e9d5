//! `vista bench`: median kernel throughput after a warm-up run.

use vista_golden::GoldenError;
use vista_gpu::Context;

use crate::{bad, parse_sets};

pub fn bench(kernel: &str, preset: Option<&str>, set: &[String], size: &str, runs: u32, json: bool) -> Result<i32, GoldenError> {
    if !(1..=1000).contains(&runs) {
        return Err(bad(format!("--runs {runs} is out of range; allowed: [1, 1000]")));
    }
    let k = vista_kernels::find(kernel).map_err(bad)?;
    let p = k.resolve(preset, &parse_sets(set)?).map_err(bad)?;
    let (w, h) = vista_kernels::parse_size(size).map_err(bad)?;
    vista_golden::check_request(k, &p, w, h)?;
    let ctx = Context::shared()?;
    // Warm-up: compiles the pipeline and touches every allocation path once.
    // Whole first call: WGSL composition, pipeline creation (lavapipe JIT), dispatch, readback.
    let first = vista_golden::render(ctx, k, &p, w, h)?.stats.total.as_secs_f64();
    let median = vista_golden::render_median(ctx, k, &p, w, h, runs)?.1.as_secs_f64();
    let mpix = (w as f64 * h as f64) / 1e6 / median;
    if json {
        println!(
            "{}",
            serde_json::json!({
                "kernel": kernel, "width": w, "height": h, "runs": runs,
                "median_ms": median * 1e3, "mpix_per_s": mpix,
                "device_creation_ms": ctx.creation_time.as_secs_f64() * 1e3,
                "first_dispatch_ms": first * 1e3,
                "adapter": ctx.adapter_description(), "params": p.canonical(),
            })
        );
    } else {
        println!("{kernel} {w}x{h}: median {:.2} ms over {runs} runs, {mpix:.2} Mpix/s on {}", median * 1e3, ctx.adapter_description());
        println!(
            "device creation {:.1} ms, first call (compose + pipeline compile + dispatch + readback) {:.1} ms",
            ctx.creation_time.as_secs_f64() * 1e3,
            first * 1e3
        );
    }
    Ok(0)
}
