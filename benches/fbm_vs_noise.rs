//! SPEC 7 target: fbm (perlin, 8 octaves, 1024 x 1024) on lavapipe against
//! the `noise` crate's `Fbm<Perlin>` (8 octaves, all cores) on the same
//! machine, side by side in one run. Prints the throughput ratio.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use rayon::prelude::*;
use std::time::Duration;

const SIZE: u32 = 1024;

fn noise_crate_fbm(f: &Fbm<Perlin>) -> Vec<f64> {
    (0..SIZE * SIZE)
        .into_par_iter()
        .map(|i| {
            let (x, y) = ((i % SIZE) as f64 + 0.5, (i / SIZE) as f64 + 0.5);
            f.get([4.0 * x / SIZE as f64, 4.0 * y / SIZE as f64])
        })
        .collect()
}

fn fbm_vs_noise(c: &mut Criterion) {
    let ctx = common::gpu_for_bench();
    let k = vista_kernels::find("fbm").unwrap();
    let p = k.resolve(None, &[("basis".into(), "perlin".into()), ("octaves".into(), "8".into())]).unwrap();
    let noise_fbm = Fbm::<Perlin>::new(0).set_octaves(8).set_frequency(1.0).set_lacunarity(2.0).set_persistence(0.5);
    vista_render::render(ctx, k, &p, SIZE, SIZE).unwrap();

    // Direct side-by-side medians (what the closing note reports): the GPU
    // wall (kernel dispatch to mapped readback), the whole `render` call (also
    // the host's table and uniforms, buffer setup and the unpadded f32 image),
    // and the crate's Vec of values, alternated.
    let mut gpu = Vec::new();
    let mut whole = Vec::new();
    let mut cpu = Vec::new();
    for _ in 0..7 {
        let t = std::time::Instant::now();
        gpu.push(vista_render::render(ctx, k, &p, SIZE, SIZE).unwrap().stats.gpu_wall);
        whole.push(t.elapsed());
        cpu.push(vista_render::median_wall(1, || {
            std::hint::black_box(noise_crate_fbm(&noise_fbm));
        }));
    }
    let [gpu, whole, cpu] = [gpu, whole, cpu].map(|v| vista_render::median(v).as_secs_f64());
    let mpix = (SIZE * SIZE) as f64 / 1e6;
    println!(
        "fbm perlin 8 oct 1024x1024: vista on {} {:.1} Mpix/s (GPU wall {:.1} ms; whole render call {:.1} ms) | noise::Fbm<Perlin> on {} cores {:.1} Mpix/s ({:.1} ms) | ratio {:.2}x GPU wall, {:.2}x whole call (target >= 2x)",
        ctx.adapter_description(),
        mpix / gpu,
        gpu * 1e3,
        whole * 1e3,
        rayon::current_num_threads(),
        mpix / cpu,
        cpu * 1e3,
        cpu / gpu,
        cpu / whole
    );

    let mut g = c.benchmark_group("fbm 1024x1024 perlin 8 octaves");
    g.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(5));
    g.bench_function("vista gpu", |b| b.iter(|| vista_render::render(ctx, k, &p, SIZE, SIZE).unwrap()));
    g.bench_function("noise crate Fbm<Perlin> all cores", |b| b.iter(|| noise_crate_fbm(&noise_fbm)));
    g.finish();
}

criterion_group!(benches, fbm_vs_noise);
criterion_main!(benches);
