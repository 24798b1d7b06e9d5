//! Reliability: non-finite output fails a case naming the count and first
//! pixel; NaN renders are never blessed; random in-range parameters for every
//! kernel (proptest) give finite output inside each kernel's documented range.

mod common;

use std::cell::Cell;
use std::sync::Arc;

use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestRunner};
use vista_golden::{Case, CheckOptions, Store};
use vista_image::Image;
use vista_kernels::{Kernel, Kind, ParamSpec};

/// Test-only kernel backed by `shaders/test/nan.wgsl`, described as data
/// like any project's kernel (no params, no CPU reference).
fn nan_kernel() -> Arc<Kernel> {
    static NAN: std::sync::OnceLock<Arc<Kernel>> = std::sync::OnceLock::new();
    NAN.get_or_init(|| {
        let manifest = "summary = \"writes NaN at (5, 3) and +Inf at (7, 3)\"\nshader = \"test/nan.wgsl\"\n";
        Arc::new(Kernel::from_manifest("test-nan", "tests/reliability.rs", manifest).expect("valid manifest"))
    })
    .clone()
}

fn nan_case() -> Case {
    Case {
        id: "nan-injected".into(),
        kernel: nan_kernel(),
        preset: None,
        overrides: vec![],
        params: nan_kernel().resolve(None, &[]).unwrap(),
        width: 16,
        height: 8,
        psnr_same_driver: 60.0,
        psnr_other_driver: 35.0,
        min_ssim: None,
        max_flip: None,
        max_bad_pixels: None,
        max_bad_ratio: None,
        ignore: vec![],
        expect_fail: vec![],
        inputs: vec![],
        tolerances: vec![],
        doc: String::new(),
    }
}

fn injected_nan_fails_the_case_naming_count_and_first_pixel(ctx: &vista_render::Renderer) {
    let dir = tempfile::tempdir().unwrap();
    let store = Store { dir: dir.path().to_path_buf(), kernels: vista_kernels::Registry::builtin().clone() };
    // A golden that would otherwise match: NaN must fail on its own.
    let golden = store.golden_path(&nan_case());
    std::fs::create_dir_all(golden.parent().unwrap()).unwrap();
    vista_image::write_png16(&golden, &Image::from_fn(16, 8, |_, _| [0.5, 0.5, 0.5, 1.0])).unwrap();
    let report_dir = dir.path().join("report");
    let checked = vista_golden::check_case(
        ctx,
        &store,
        &Default::default(),
        &nan_case(),
        &CheckOptions { twice: false, images_of_passing: false },
    );
    let (o, unwritten) = vista_report::file_case(&report_dir, checked, vista_report::Detail::Failing);
    assert!(unwritten.is_empty(), "{unwritten:?}");
    assert!(!o.passed(), "a NaN render passed: {o:?}");
    let text = o.explain(&report_dir);
    assert!(text.contains("2 pixels contain NaN/Inf; first at (5, 3)"), "{text}");
    assert_eq!(o.metrics.map(|m| m.nan), Some(2), "{text}");
}

fn render_path_reports_nan_from_the_gpu_bit_exactly(ctx: &vista_render::Renderer) {
    let r = vista_render::render(ctx, &nan_kernel(), &nan_case().params, 16, 8).unwrap();
    assert!(r.raw.get(5, 3)[0].is_nan());
    assert_eq!(r.raw.get(7, 3)[0], f32::INFINITY);
    assert_eq!(r.raw.first_nonfinite(), Some((5, 3)));
    assert_eq!(r.raw.nonfinite_count(), 2);
}

/// Test-only kernel backed by `shaders/test/partial.wgsl`: writes
/// (1, y, x, 1) to the columns x < cut only.
fn partial_kernel() -> Arc<Kernel> {
    static PARTIAL: std::sync::OnceLock<Arc<Kernel>> = std::sync::OnceLock::new();
    PARTIAL
        .get_or_init(|| {
            let manifest = "summary = \"writes (1, y, x, 1) to the columns x < cut\"\nshader = \"test/partial.wgsl\"\n\
                        [[param]]\nname = \"cut\"\ntype = \"u32\"\nrange = [0, 64]\ndefault = 16\n";
            Arc::new(Kernel::from_manifest("test-partial", "tests/reliability.rs", manifest).expect("valid manifest"))
        })
        .clone()
}

/// Runs of one size share an output texture (vista-gpu's scratch): a pixel
/// the kernel does not write must still read 0, as in a fresh texture, and
/// never the value an earlier run wrote there.
fn an_unwritten_pixel_reads_zero_after_a_run_that_wrote_it(ctx: &vista_render::Renderer) {
    let k = partial_kernel();
    let full = vista_render::render(ctx, &k, &k.resolve(None, &[]).unwrap(), 16, 8).unwrap();
    assert_eq!(full.raw.get(12, 5), [1.0, 5.0, 12.0, 1.0]);
    for _ in 0..2 {
        let part = vista_render::render(ctx, &k, &k.resolve(None, &[("cut".into(), "4".into())]).unwrap(), 16, 8);
        let part = part.unwrap().raw;
        assert_eq!(part.get(3, 5), [1.0, 5.0, 3.0, 1.0]);
        assert_eq!(part.get(4, 0), [0.0; 4], "an earlier run's value leaked into an unwritten pixel");
        assert_eq!(part.get(15, 7), [0.0; 4], "an earlier run's value leaked into an unwritten pixel");
    }
}

/// Textures are filled with the sentinel and read back in bands of rows
/// (at most 4 MiB each): a render three bands tall (2 KiB rows, 2048 rows a
/// band) comes back with every row in place, its unwritten texels counted
/// in every band, and nothing of an earlier, fully written run.
fn a_render_taller_than_a_readback_band_comes_back_whole(ctx: &vista_render::Renderer) {
    let k = partial_kernel();
    let (w, h) = (128, 5000);
    let render =
        |cut: &str| vista_render::render(ctx, &k, &k.resolve(None, &[("cut".into(), cut.into())]).unwrap(), w, h);
    let full = render("64").unwrap();
    assert_eq!(full.raw.get(63, h - 1), [1.0, (h - 1) as f32, 63.0, 1.0]);
    let part = render("5").unwrap();
    for y in [0, 2047, 2048, 4095, 4096, h - 1] {
        assert_eq!(part.raw.get(4, y), [1.0, y as f32, 4.0, 1.0], "row {y}");
        assert_eq!(part.raw.get(5, y), [0.0; 4], "row {y}: unwritten");
        assert_eq!(part.raw.get(w - 1, y), [0.0; 4], "row {y}: unwritten");
    }
    let unwritten = match &part.outputs[0].value {
        vista_render::OutputValue::Texture { unwritten, .. } => *unwritten,
        _ => panic!("a texture output"),
    };
    assert_eq!(unwritten, u64::from((w - 5) * h), "unwritten texels, counted in every band");
}

// ---- parameter fuzzing -----------------------------------------------------

/// A strategy producing text for one parameter, anywhere in its range.
fn value_strategy(spec: &ParamSpec) -> BoxedStrategy<String> {
    match spec.kind.clone() {
        Kind::Float { min, max, open_min } => {
            let lo = if open_min { min + (max - min) * 1e-6 } else { min };
            prop_oneof![
                1 => Just(lo),
                1 => Just(max),
                6 => lo..=max,
            ]
            .prop_map(|v| v.to_string())
            .boxed()
        }
        // Counts (steps, octaves) spanning decades are also drawn log-uniformly,
        // so small and large ones are both common and the work budget rejects
        // a bounded share of draws.
        Kind::Int { min, max } => prop_oneof![
            1 => Just(min),
            1 => Just(max),
            3 => min..=max,
            3 => (0.0f64..=1.0).prop_map(move |t| {
                let (lo, hi) = ((min.max(1)) as f64, max as f64);
                ((lo.ln() + t * (hi.ln() - lo.ln())).exp().round() as i64).clamp(min, max)
            }),
        ]
        .prop_map(|v| v.to_string())
        .boxed(),
        Kind::IntVector { n, min, max } => proptest::collection::vec(min..=max, n)
            .prop_map(|v| v.iter().map(|c| c.to_string()).collect::<Vec<_>>().join(","))
            .boxed(),
        Kind::Vector { n, min, max } => proptest::collection::vec(min..=max, n)
            .prop_map(|v| v.iter().map(|c| c.to_string()).collect::<Vec<_>>().join(","))
            .boxed(),
        Kind::Enum(names) => proptest::sample::select(names.to_vec()).boxed(),
        Kind::Bool => proptest::bool::ANY.prop_map(|b| b.to_string()).boxed(),
    }
}

/// Accepted draws per kernel (`VISTA_FUZZ_CASES` for a longer run).
fn fuzz_cases() -> u32 {
    std::env::var("VISTA_FUZZ_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(64)
}

/// Large enough for each kernel's structure to show (octaves, a horizon,
/// cloud edges).
const FUZZ_SIZE: (u32, u32) = (32, 32);

/// Draws whose work estimate (inner-loop evaluations for the whole image)
/// exceeds this are rejected and counted, so one run stays within seconds.
const FUZZ_WORK: f64 = 5.0e7;

fn random_in_range_params_give_finite_output_within_documented_bounds(ctx: &vista_render::Renderer) {
    let start = std::time::Instant::now();
    let mut total = 0;
    for kernel in vista_kernels::registry() {
        let specs = kernel.params();
        let strategy: Vec<BoxedStrategy<String>> = specs.iter().map(value_strategy).collect();
        let config = Config {
            cases: fuzz_cases(),
            rng_seed: RngSeed::Fixed(0x5eed_0000 + kernel.name().len() as u64),
            failure_persistence: None,
            ..Config::default()
        };
        let mut runner = TestRunner::new(Config { max_global_rejects: 100_000, ..config });
        let (tried, invalid, heavy) = (Cell::new(0u32), Cell::new(0u32), Cell::new(0u32));
        let (w, h) = FUZZ_SIZE;
        let result = runner.run(&strategy, |values| {
            let overrides: Vec<(String, String)> =
                specs.iter().zip(&values).map(|(s, v)| (s.name.to_string(), v.clone())).collect();
            // Cross-parameter rules (e.g. a camera looking straight up) reject a draw.
            let p = kernel.resolve(None, &overrides);
            invalid.set(invalid.get() + p.is_err() as u32);
            prop_assume!(p.is_ok());
            let p = p.unwrap();
            let work = kernel.work_per_pixel(&p) * (w * h) as f64;
            heavy.set(heavy.get() + (work > FUZZ_WORK) as u32);
            prop_assume!(work <= FUZZ_WORK);
            tried.set(tried.get() + 1);
            let r = vista_render::render(ctx, kernel, &p, w, h)
                .map_err(|e| TestCaseError::fail(format!("{}: {e}", kernel.name())))?;
            if let Some((x, y)) = r.raw.first_nonfinite() {
                return Err(TestCaseError::fail(format!(
                    "{}: NaN/Inf at ({x}, {y}) with {}",
                    kernel.name(),
                    p.canonical()
                )));
            }
            if let Some((x, y, v)) = vista_golden::first_out_of_range(kernel, &p, &r.raw) {
                let (lo, hi) = kernel.output_bounds(&p);
                return Err(TestCaseError::fail(format!(
                    "{}: pixel ({x}, {y}) = {v} outside [{lo}, {hi}] with {}",
                    kernel.name(),
                    p.canonical()
                )));
            }
            Ok(())
        });
        if let Err(e) = result {
            panic!("{}: {e}", kernel.name());
        }
        let tried = tried.get();
        eprintln!(
            "fuzz {}: {tried} accepted renders at {w}x{h}, all finite and in range; rejected: {} by \
             cross-parameter checks, {} over the work budget",
            kernel.name(),
            invalid.get(),
            heavy.get()
        );
        assert!(tried >= fuzz_cases(), "{}: only {tried} draws accepted", kernel.name());
        total += tried;
    }
    eprintln!("fuzz: {total} renders in {:.1} s", start.elapsed().as_secs_f64());
}

/// VISTA_VALIDATION=1: with the Khronos layer on, a clean kernel renders,
/// and a validation message arriving during a dispatch fails it, naming the
/// layer and the message (injected here through the logger wgpu-hal uses).
fn a_validation_message_fails_the_dispatch(_shared: &vista_render::Renderer) {
    if !std::path::Path::new(vista_gpu::VALIDATION_LAYER_JSON).exists() {
        panic!("the Khronos validation layer is missing: run `bash ci/install-validation.sh`");
    }
    let config = vista_gpu::GpuConfig { validate: true, ..vista_gpu::GpuConfig::default() };
    let ctx = vista_gpu::Context::new(&config).unwrap();
    assert!(ctx.validating());
    let gpu = vista_render::Renderer::new(&ctx, &common::project(), Default::default()).unwrap();
    let k = vista_kernels::find("fbm").unwrap();
    let p = k.resolve(None, &[]).unwrap();
    vista_render::render(&gpu, k, &p, 32, 32).expect("a clean kernel passes under the validation layer");
    log::error!(target: vista_gpu::validation::TARGET, "VALIDATION [VUID-injected (0x1)] injected by the test");
    let e = vista_render::render(&gpu, k, &p, 32, 32).unwrap_err().to_string();
    assert!(e.contains("Khronos validation layer") && e.contains("VUID-injected"), "{e}");
    vista_render::render(&gpu, k, &p, 32, 32).expect("messages are per dispatch");
}

/// A parent whose GPU work runs in workers describes the device by the
/// facts a worker sends (the parent loads no Vulkan driver).
/// Through the wire's JSON, that context answers what vista asks of the
/// device as the device's own context does, and refuses to run a graph.
fn a_described_device_answers_as_the_device_does(shared: &vista_render::Renderer) {
    let ctx = shared.ctx;
    let facts = ctx.facts().expect("the tests' device is a wgpu one");
    let sent: vista_gpu::DeviceFacts = serde_json::from_str(&serde_json::to_string(&facts).unwrap()).unwrap();
    assert_eq!(sent, facts, "the facts cross the pipe whole");
    let described = vista_gpu::Context::described(ctx.config(), sent, std::time::Duration::ZERO);
    assert_eq!(described.facts().as_ref(), Some(&facts));
    assert_eq!(described.adapter_description(), ctx.adapter_description());
    assert_eq!(
        (described.backend(), described.is_software(), described.max_dimension()),
        (ctx.backend(), ctx.is_software(), ctx.max_dimension())
    );
    for name in ["maxComputeWorkgroupSizeX", "maxBindGroups", "maxTextureDimension2D", "maxStorageBufferBindingSize"] {
        assert!(ctx.limit(name).is_some(), "{name}");
        assert_eq!(described.limit(name), ctx.limit(name), "{name}");
    }
    let too_many = vista_gpu::Needs { workgroup_size: [4096, 1, 1], workgroups: [1, 1, 1], ..Default::default() };
    assert_eq!(
        described.require_needs("k", &too_many).unwrap_err().to_string(),
        ctx.require_needs("k", &too_many).unwrap_err().to_string()
    );
    let gpu = vista_render::Renderer::new(&described, &common::project(), Default::default()).unwrap();
    let k = vista_kernels::find("fbm").unwrap();
    let e = vista_render::render(&gpu, k, &k.resolve(None, &[]).unwrap(), 8, 8).unwrap_err().to_string();
    assert!(e.contains("only describes a worker's device"), "{e}");
}

fn main() {
    common::gpu_tests![
        a_described_device_answers_as_the_device_does,
        a_validation_message_fails_the_dispatch,
        injected_nan_fails_the_case_naming_count_and_first_pixel,
        render_path_reports_nan_from_the_gpu_bit_exactly,
        an_unwritten_pixel_reads_zero_after_a_run_that_wrote_it,
        a_render_taller_than_a_readback_band_comes_back_whole,
        random_in_range_params_give_finite_output_within_documented_bounds,
    ];
}
