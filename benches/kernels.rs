//! Every kernel's default preset at 256 x 256: GPU (lavapipe by default,
//! `VISTA_ADAPTER=gpu` for hardware) beside its CPU reference on all cores,
//! built in f32 (the CPU doing the GPU's work at the GPU's precision) and in
//! f64 (the oracle). A kernel whose reference is a different algorithm
//! (heightfield's brute-force oracle) also runs the shader's own algorithm on
//! the CPU in f32 (`Kernel::shader_algorithm_f32`): the like-for-like ratio. Device creation and shader compilation happen before
//! measurement. Prints the medians and ratios after each kernel.
//!
//! The heightfield oracle takes about 20 s per 256 x 256 image on 2 cores,
//! so a full run takes several minutes; filter with `-- fbm` etc.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{Bencher, Criterion, criterion_group, criterion_main};
use std::time::{Duration, Instant};
use vista_kernels::Kernel;

const SIZE: (u32, u32) = (256, 256);

/// Times every iteration criterion asks for and keeps the durations, so
/// the ratio can be printed from the same measurements.
fn timed(b: &mut Bencher, seen: &mut Vec<Duration>, mut f: impl FnMut()) {
    b.iter_custom(|iters| {
        let mut total = Duration::ZERO;
        for _ in 0..iters {
            let t = Instant::now();
            f();
            let d = t.elapsed();
            seen.push(d);
            total += d;
        }
        total
    });
}

/// Median in ms; None when a filter skipped the benchmark.
fn median_ms(v: Vec<Duration>) -> Option<f64> {
    (!v.is_empty()).then(|| vista_render::median(v).as_secs_f64() * 1e3)
}

fn kernels(c: &mut Criterion) {
    let ctx = common::gpu_for_bench();
    let (w, h) = SIZE;
    let threads = rayon::current_num_threads();
    for k in vista_kernels::registry() {
        let k: &Kernel = k;
        let p = k.resolve(None, &[]).expect("defaults are valid");
        let mut g = c.benchmark_group(k.name());
        g.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(3));
        let (mut gpu, mut f32_ref, mut f64_ref, mut march) = (vec![], vec![], vec![], vec![]);
        vista_render::render(ctx, k, &p, w, h).expect("warm-up render");
        g.bench_function("gpu 256x256", |b| {
            timed(b, &mut gpu, || {
                vista_render::render(ctx, k, &p, w, h).expect("render");
            })
        });
        g.bench_function(format!("cpu f32 reference 256x256 ({threads} threads)"), |b| {
            timed(b, &mut f32_ref, || {
                k.reference_f32(&p, w, h);
            })
        });
        g.bench_function(format!("cpu f64 reference 256x256 ({threads} threads)"), |b| {
            timed(b, &mut f64_ref, || {
                k.reference(&p, w, h);
            })
        });
        if k.shader_algorithm_f32(&p, 1, 1).is_some() {
            g.bench_function(format!("cpu f32 shader algorithm 256x256 ({threads} threads)"), |b| {
                timed(b, &mut march, || {
                    k.shader_algorithm_f32(&p, w, h);
                })
            });
        }
        g.finish();
        let Some(gpu) = median_ms(gpu) else { continue };
        let mut line = format!("{}: gpu {gpu:.2} ms ({})", k.name(), ctx.adapter_description());
        for (what, v) in
            [("cpu f32 reference", f32_ref), ("cpu f64 reference", f64_ref), ("cpu f32 shader algorithm", march)]
        {
            if let Some(ms) = median_ms(v) {
                line += &format!("; {what} {ms:.2} ms = {:.2}x the gpu time", ms / gpu);
            }
        }
        println!("{line}");
    }
}

criterion_group!(benches, kernels);
criterion_main!(benches);
