//! `vista test`'s own time for one file of 100 `@test` functions (each an
//! `expectNear` of `hg_phase` at its own angle): the rewrite, the manifest,
//! composition, 100 pipelines and one submission, on the process's device.
//! The first run compiles every pipeline (its time is printed); criterion
//! then times a warm run (SPEC 21's target: under 2 s of vista's own time
//! on lavapipe). `--profile dev` times the build `make test` uses.
//! `cargo bench --profile dev --features bench --bench wgsl_tests`.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;

/// A file of `n` tests of the Henyey-Greenstein phase function against
/// (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5), worked in f64 here.
fn test_file(n: usize) -> String {
    let mut text = String::from("#import vista::phase::{hg_phase}\n#import wgsl_test::{expectNear}\n");
    for i in 0..n {
        let (mu, g) = (-1.0 + 2.0 * i as f64 / n as f64, 0.7);
        let want = (1.0 - g * g) / (4.0 * std::f64::consts::PI * (1.0 + g * g - 2.0 * g * mu).powf(1.5));
        text += &format!("@test fn hg_{i}() {{ expectNear(hg_phase({mu:?}, {g:?}), {want:?}, 1e-4); }}\n");
    }
    text
}

fn wgsl_tests(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("a temp dir");
    std::fs::write(dir.path().join("vista.toml"), "").expect("vista.toml");
    std::fs::create_dir(dir.path().join("shaders")).expect("shaders/");
    let text = test_file(100);
    std::fs::write(dir.path().join("shaders/phase100.test.wgsl"), &text).expect("the test file");
    let project = vista_project::Project::at(dir.path()).expect("a project");
    let gpu = common::gpu_for_bench();
    let sources = vista_render::Sources::of(&project).expect("its sources");
    let base = vista_render::Renderer::new(gpu.ctx, &project, common::config().limits).expect("its shaders");
    let run = || vista_wgsl_test::run_file(&base, &sources, "phase100.test.wgsl", &text);
    let started = std::time::Instant::now();
    let first = run();
    eprintln!("wgsl_tests: the first run, 100 pipelines compiled: {:.0} ms", started.elapsed().as_secs_f64() * 1e3);
    assert_eq!(first.len(), 100);
    assert!(first.iter().all(|r| r.passed()), "{:?}", first.iter().find(|r| !r.passed()));
    let mut g = c.benchmark_group("wgsl_tests");
    g.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(5));
    g.bench_function("100 tests in one file", |b| b.iter(run));
    g.finish();
}

criterion_group!(benches, wgsl_tests);
criterion_main!(benches);
