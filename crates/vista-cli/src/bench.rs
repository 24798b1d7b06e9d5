//! `vista bench`: median kernel throughput after a warm-up run, optionally
//! beside the f32 CPU reference on all cores; or, with `--open-report`, how
//! long a report's index.html takes to open in headless Chromium.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use vista_golden::GoldenError;
use vista_project::Project;
use vista_render::Renderer;

use crate::input::{bad, parse_sets};

/// `vista bench`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The kernel's name.
    #[arg(required_unless_present = "open_report")]
    pub kernel: Option<String>,
    /// A preset of the kernel.
    #[arg(long)]
    pub preset: Option<String>,
    /// Parameter override NAME=VALUE (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x1024")]
    pub size: String,
    /// Timed runs after the warm-up (the median is reported).
    #[arg(long, default_value_t = 7)]
    pub runs: u32,
    /// Print the result as one JSON object (field mpix_per_s among them).
    #[arg(long)]
    pub json: bool,
    /// Also time the kernel's CPU reference built in f32 on all cores
    /// (median of up to 3 runs) and print the CPU / GPU ratio.
    #[arg(long)]
    pub cpu: bool,
    /// Instead of a kernel: open DIR/index.html (a `check` report) in
    /// headless Chromium `--runs` times and report the median time to its
    /// load event, over the DevTools protocol.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["kernel", "preset", "set", "cpu"])]
    pub open_report: Option<PathBuf>,
}

pub fn bench(project: &Project, config: &vista::Config, a: Args) -> Result<i32, GoldenError> {
    let Args { kernel, preset, set, size, runs, json, cpu, open_report } = a;
    if !(1..=1000).contains(&runs) {
        return Err(bad(format!("--runs {runs} is out of range; allowed: [1, 1000]")));
    }
    let kernel = match (open_report, kernel) {
        (Some(dir), _) => return open_report_page(&dir, runs, json),
        (None, Some(k)) => k,
        (None, None) => return Err(bad("give a kernel to bench, or --open-report DIR")),
    };
    let (kernel, preset, set, size) = (kernel.as_str(), preset.as_deref(), set.as_slice(), size.as_str());
    let k = crate::input::registry(project)?.find(kernel).cloned().map_err(bad)?;
    let p = k.resolve(preset, &parse_sets(set)?).map_err(bad)?;
    let (w, h) = vista_kernels::parse_size(size).map_err(bad)?;
    let shaders = vista_render::shader_set(project)?;
    // Every check that needs no device, before it is made.
    let plan = vista_render::plan(&shaders, project.root(), &k, &p, &[], w, h, &config.limits)?;
    let graph_passes: Vec<String> = plan.passes.iter().map(|p| p.label.clone()).collect();
    if cpu && !k.has_reference() {
        return Err(bad(match k.reference_mismatch() {
            Some(how) => format!(
                "--cpu: kernel {kernel} has no CPU reference: its manifest ({}) is the built-in {kernel}'s {how}, \
                 and the built-in's reference reads those",
                k.origin()
            ),
            None => format!("--cpu: kernel {kernel} has no CPU reference (only built-in kernels have one)"),
        }));
    }
    let ctx = &Renderer::shared_with_shaders(&config.gpu, shaders, config.limits, project.root().map(Into::into))?;
    // GPU timestamps around each graph pass, where the device has them.
    ctx.time_passes(true);
    // Warm-up: compiles the pipeline and touches every allocation path once.
    // Whole first call: WGSL composition, pipeline creation (lavapipe JIT), dispatch, readback.
    let first = vista_render::render(ctx, &k, &p, w, h)?.stats.total.as_secs_f64();
    let mut stats = Vec::new();
    let mut pass_times: Vec<Vec<std::time::Duration>> = vec![Vec::new(); graph_passes.len()];
    let mut gpu_times: Vec<Vec<std::time::Duration>> = vec![Vec::new(); graph_passes.len()];
    for _ in 0..runs {
        let r = vista_render::render(ctx, &k, &p, w, h)?;
        for (all, t) in pass_times.iter_mut().zip(&r.pass_times) {
            all.push(*t);
        }
        for (all, t) in gpu_times.iter_mut().zip(&r.pass_gpu_times) {
            all.extend(*t);
        }
        stats.push(r.stats);
    }
    // A pass graph's passes, each by its median wall time (submit to done,
    // all its repeats) and, where the device has timestamps, its median
    // GPU time between them.
    let passes: Vec<PassTime> = graph_passes
        .into_iter()
        .zip(pass_times)
        .zip(gpu_times)
        .map(|((pass, times), gpu)| PassTime {
            pass,
            median_ms: vista_render::median(times).as_secs_f64() * 1e3,
            gpu_median_ms: (!gpu.is_empty()).then(|| vista_render::median(gpu).as_secs_f64() * 1e3),
        })
        .collect();
    let med = |f: fn(&vista_render::RunStats) -> std::time::Duration| {
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
    let result = BenchResult {
        kernel: kernel.to_string(),
        width: w,
        height: h,
        runs,
        median_ms: median * 1e3,
        mpix_per_s: mpix,
        kernel_ms: kernel_s * 1e3,
        readback_ms: readback_s * 1e3,
        device_creation_ms: ctx.creation_time.as_secs_f64() * 1e3,
        first_dispatch_ms: first * 1e3,
        adapter: ctx.adapter_description(),
        params: p.canonical(),
        cpu_f32_ms: cpu_ms,
        cpu_threads: cpu_ms.map(|_| rayon::current_num_threads()),
        cpu_over_gpu: cpu_ms.map(|ms| ms / (median * 1e3)),
        passes,
    };
    if json {
        println!("{}", serde_json::to_string(&result).map_err(|e| bad(format!("JSON encode: {e}")))?);
    } else {
        let r = &result;
        println!(
            "{} {}x{}: median {:.2} ms over {} runs, {:.2} Mpix/s on {}",
            r.kernel, r.width, r.height, r.median_ms, r.runs, r.mpix_per_s, r.adapter
        );
        println!(
            "  of which the kernel {:.2} ms and the readback (copy, map, unpad) {:.2} ms",
            r.kernel_ms, r.readback_ms
        );
        println!(
            "device creation {:.1} ms, first call (compose + pipeline compile + dispatch + readback) {:.1} ms",
            r.device_creation_ms, r.first_dispatch_ms
        );
        for p in &r.passes {
            match p.gpu_median_ms {
                Some(gpu) => {
                    println!("  {}: median {:.2} ms ({:.3} ms on the GPU's timestamps)", p.pass, p.median_ms, gpu)
                }
                None => println!("  {}: median {:.2} ms (no GPU timestamps on this backend)", p.pass, p.median_ms),
            }
        }
        if let (Some(ms), Some(threads), Some(ratio)) = (r.cpu_f32_ms, r.cpu_threads, r.cpu_over_gpu) {
            println!("f32 CPU reference on {threads} threads: {ms:.2} ms = {ratio:.2}x the GPU time");
        }
    }
    Ok(0)
}

/// `--open-report DIR`: DIR/index.html opened `runs` times in headless
/// Chromium (a blank page between), each timed from the navigation to the
/// load event; then what the page holds, as the reader sees it.
fn open_report_page(dir: &Path, runs: u32, json: bool) -> Result<i32, GoldenError> {
    let index = dir.join("index.html");
    let bytes = std::fs::metadata(&index).map(|m| m.len()).map_err(|e| {
        bad(format!(
            "--open-report {}: no index.html there ({e}); give a report folder (check --report-dir)",
            dir.display()
        ))
    })?;
    let url = format!("file://{}", std::path::absolute(&index).unwrap_or(index.clone()).display());
    let config = vista_browser::BrowserConfig::from_lookup(&|k| std::env::var_os(k));
    let failed = |e: String| GoldenError::Rejected(format!("--open-report: {e}"));
    let chromium = vista_browser::find_chromium(&config).map_err(|e| failed(e.to_string()))?;
    let wait = Duration::from_secs(120);
    let page = vista_browser::cdp::Chromium::launch(&chromium, &["--window-size=1400,1000"], wait).map_err(failed)?;
    let mut times = Vec::new();
    for _ in 0..runs {
        page.navigate("about:blank", wait).map_err(|e| failed(e.to_string()))?;
        let start = Instant::now();
        page.navigate(&url, wait).map_err(|e| failed(format!("{}: {e}", index.display())))?;
        times.push(start.elapsed());
    }
    // Cases and images as loaded: lazy thumbnails below the fold wait.
    let facts = page
        .evaluate(
            "(() => { const im = [...document.images]; return { cases: document.querySelectorAll('[id^=\"case-\"]').length, \
             images: im.length, lazy: im.filter((i) => i.loading === 'lazy').length, \
             loaded: im.filter((i) => i.complete && i.naturalWidth > 0).length }; })()",
            wait,
        )
        .map_err(|e| failed(e.to_string()))?;
    let median_ms = vista_render::median(times).as_secs_f64() * 1e3;
    let version = page.version(wait).unwrap_or_default();
    let n = |k: &str| facts[k].as_u64().unwrap_or(0);
    if json {
        let out = serde_json::json!({
            "report": index, "bytes": bytes, "runs": runs, "load_median_ms": median_ms, "browser": version,
            "cases": n("cases"), "images": n("images"), "lazy_images": n("lazy"), "images_loaded": n("loaded"),
        });
        println!("{out}");
    } else {
        println!(
            "{} ({:.1} MB, {} cases, {} images of which {} lazy, {} loaded): load event after median {median_ms:.0} ms \
             over {runs} runs in headless {version}",
            index.display(),
            bytes as f64 / 1e6,
            n("cases"),
            n("images"),
            n("lazy"),
            n("loaded")
        );
    }
    Ok(0)
}

/// One pass of a graph and its median wall time.
#[derive(Debug, serde::Serialize)]
struct PassTime {
    pass: String,
    median_ms: f64,
    /// From the device's timestamps; absent where it has none.
    #[serde(skip_serializing_if = "Option::is_none")]
    gpu_median_ms: Option<f64>,
}

/// What `vista bench` measured: printed as text, or serialised whole by `--json`.
#[derive(Debug, serde::Serialize)]
struct BenchResult {
    kernel: String,
    width: u32,
    height: u32,
    runs: u32,
    /// Median GPU wall (dispatch to mapped readback).
    median_ms: f64,
    mpix_per_s: f64,
    kernel_ms: f64,
    readback_ms: f64,
    device_creation_ms: f64,
    /// Whole first call: composition, pipeline compilation, dispatch, readback.
    first_dispatch_ms: f64,
    adapter: String,
    params: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    cpu_f32_ms: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    cpu_threads: Option<usize>,
    /// A pass graph's passes (empty for a one-pass kernel).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    passes: Vec<PassTime>,
    #[serde(skip_serializing_if = "Option::is_none")]
    cpu_over_gpu: Option<f64>,
}
