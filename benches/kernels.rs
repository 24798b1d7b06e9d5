//! Every kernel's default preset at 256 x 256: GPU (lavapipe by default,
//! `VISTA_ADAPTER=gpu` for hardware) beside its f64 CPU reference on all
//! cores, so the ratio is visible. Device creation and shader compilation
//! happen before measurement.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;

fn kernels(c: &mut Criterion) {
    let ctx = vista_gpu::Context::shared().expect("GPU adapter (bash ci/install-lavapipe.sh)");
    let (w, h) = (256, 256);
    for k in vista_kernels::registry() {
        let p = k.resolve(None, &[]).expect("defaults are valid");
        vista_golden::render(ctx, *k, &p, w, h).expect("warm-up render");
        let mut g = c.benchmark_group(k.name());
        g.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(3));
        g.bench_function("gpu 256x256", |b| b.iter(|| vista_golden::render(ctx, *k, &p, w, h).expect("render")));
        g.bench_function("cpu f64 reference 256x256 (all cores)", |b| b.iter(|| k.reference(&p, w, h)));
        g.finish();
    }
}

criterion_group!(benches, kernels);
criterion_main!(benches);
