//! The pass-graph kernels of `examples/graphs` (atmosphere LUT chain,
//! erosion steps, blur, scan, boids, droplets) at their first case's size:
//! criterion times the whole render, and after each kernel its passes are
//! printed by median wall time (submit to done, all repeats) and, where the
//! device has timestamps (`Context::time_passes`), median GPU time between
//! them. Device creation and pipeline compilation happen before
//! measurement. Filter with `-- erosion` etc.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::Path;
use std::time::Duration;
use vista_render::Renderer;

fn graphs(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/graphs");
    let project = vista_project::Project::at(&root).expect("examples/graphs is a vista project");
    let gpu = common::gpu_for_bench();
    let ctx = Renderer::new(gpu.ctx, &project, common::config().limits).expect("examples/graphs' shaders");
    ctx.time_passes(true);
    let store = vista_golden::Store::of_project(&project, "the graphs bench").expect("examples/graphs' goldens");
    let cases = store.load_cases().expect("examples/graphs' cases");
    let registry = vista_kernels::Registry::of_project(&project).expect("examples/graphs' manifests");
    for k in registry.kernels() {
        let Some(case) = cases.iter().find(|c| c.kernel.name() == k.name()) else { continue };
        let (w, h) = (case.width, case.height);
        let p = &case.params;
        let plan =
            vista_render::plan(&ctx.shaders, project.root(), k, p, &case.inputs, w, h, &ctx.limits).expect("plan");
        let labels: Vec<String> = plan.passes.iter().map(|p| p.label.clone()).collect();
        let render = || vista_golden::run::render_case(&ctx, case).expect("render");
        render(); // compiles every pass's pipeline
        let mut g = c.benchmark_group(k.name());
        g.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
        let (mut wall, mut gpu_t): (Vec<Vec<Duration>>, Vec<Vec<Duration>>) =
            (vec![Vec::new(); labels.len()], vec![Vec::new(); labels.len()]);
        g.bench_function(format!("{} {w}x{h}", case.id), |b| {
            b.iter(|| {
                let r = render();
                for (all, t) in wall.iter_mut().zip(&r.pass_times) {
                    all.push(*t);
                }
                for (all, t) in gpu_t.iter_mut().zip(&r.pass_gpu_times) {
                    all.extend(*t);
                }
            })
        });
        g.finish();
        if wall.first().is_none_or(|v| v.is_empty()) {
            continue; // filtered out
        }
        println!("{} ({}), per pass:", k.name(), ctx.adapter_description());
        for ((label, wall), gpu) in labels.iter().zip(wall).zip(gpu_t) {
            let ms = |v: Vec<Duration>| vista_render::median(v).as_secs_f64() * 1e3;
            let gpu = match gpu.is_empty() {
                true => "no GPU timestamps".to_string(),
                false => format!("GPU {:.3} ms", ms(gpu)),
            };
            println!("  {label:<40} wall {:.3} ms, {gpu}", ms(wall));
        }
    }
}

criterion_group!(benches, graphs);
criterion_main!(benches);
