//! Runs small kernels in headless Chromium. Needs Chromium
//! (`bash ci/install-browser.sh`); with VISTA_ALLOW_NO_GPU=1 and no
//! Chromium, every test is reported ignored (never ok) and a loud line says so.

use std::time::Duration;

use serde_json::{Value, json};
use vista_browser::{Browser, BrowserError, base64};

const GRADIENT: &str = r#"
struct Params { width: u32, height: u32, scale: f32, pad: f32 }
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(2) var<storage, read> table: array<u32>;
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.width || id.y >= params.height) { return; }
    let t = f32(table[(id.x + id.y) % 4u]);
    textureStore(out, vec2<i32>(id.xy), vec4<f32>(f32(id.x) * params.scale, f32(id.y), t, 1.0));
}
"#;

fn config() -> vista_browser::BrowserConfig {
    vista_browser::BrowserConfig::from_lookup(&|k| std::env::var_os(k))
}

fn browser() -> Browser {
    Browser::launch(Duration::from_secs(60), &config()).unwrap_or_else(|e| panic!("{e}"))
}

fn main() {
    let args = libtest_mimic::Arguments::from_args();
    let missing = vista_browser::find_chromium(&config()).err();
    // The one parser of VISTA_ALLOW_NO_GPU (1|0|true|false), as every GPU suite reads it.
    let allow = vista_project::truthy("VISTA_ALLOW_NO_GPU", std::env::var("VISTA_ALLOW_NO_GPU").ok().as_deref())
        .unwrap_or_else(|e| panic!("{e}"));
    let skip = missing.filter(|_| allow);
    // Each test's name is its function's name, written once.
    macro_rules! tests {
        ($($f:ident),* $(,)?) => {
            [$((stringify!($f), $f as fn())),*]
        };
    }
    let tests = tests![
        a_kernel_runs_and_reads_back_every_texel,
        tint_errors_name_the_case_and_the_next_run_works,
        a_hung_kernel_trips_the_watchdog_and_a_crashed_page_is_named,
    ];
    if let Some(e) = &skip {
        eprintln!(
            "\n!!! VISTA_ALLOW_NO_GPU=1 and no Chromium: {e}\n!!! SKIPPED {} browser tests (reported ignored)\n",
            tests.len()
        );
    }
    let trials = tests
        .into_iter()
        .map(|(name, f)| {
            libtest_mimic::Trial::test(name, move || {
                f();
                Ok(())
            })
            .with_ignored_flag(skip.is_some())
        })
        .collect();
    libtest_mimic::run(&args, trials).exit()
}

/// The error of a run that should have failed (without printing the
/// output of one that did not).
fn failure(r: Result<vista_browser::Output, BrowserError>, what: &str) -> BrowserError {
    match r {
        Ok(out) => panic!("{what}: {} texels came back", rgba(&out).len()),
        Err(e) => e,
    }
}

/// A one-pass graph over vista's usual bindings (uniforms at 0, an
/// rgba32float output at 1, the table at 2), 8 x 8 workgroups covering
/// `w` x `h`: the JSON `runner.js`'s `vistaRun` takes.
fn job(key: &str, wgsl: &str, u: &[u8], table: &[u32], w: u32, h: u32) -> Value {
    let table: Vec<u8> = table.iter().flat_map(|v| v.to_le_bytes()).collect();
    json!({
        "resources": [{
            "kind": "texture", "format": "rgba32float", "dimension": "2d", "width": w, "height": h, "layers": 1,
            "texel_bytes": 16, "storable": true, "contents": null, "fill": base64(&[0; 16]),
        }],
        "passes": [{
            "key": key, "label": "pass 1", "wgsl": wgsl, "entry": "main",
            "workgroups": [w.div_ceil(8), h.div_ceil(8), 1], "repeat": 1, "span": 1, "swap": [],
            "slots": [
                { "group": 0, "binding": 0, "layout": { "buffer": { "type": "uniform" } }, "owned": base64(u) },
                { "group": 0, "binding": 1, "layout": { "storageTexture": {
                    "access": "write-only", "format": "rgba32float", "viewDimension": "2d" } }, "resource": 0 },
                { "group": 0, "binding": 2, "layout": { "buffer": { "type": "read-only-storage" } }, "owned": base64(&table) },
            ],
        }],
        "outputs": [{ "resource": 0, "level": 0, "z": 0, "width": w, "height": h, "layers": 1 }],
    })
}

/// The output's rgba32float texels.
fn rgba(out: &vista_browser::Output) -> Vec<[f32; 4]> {
    out.outputs[0]
        .chunks_exact(16)
        .map(|t| std::array::from_fn(|c| f32::from_le_bytes(t[c * 4..c * 4 + 4].try_into().unwrap())))
        .collect()
}

fn uniforms(w: u32, h: u32, scale: f32) -> Vec<u8> {
    [w.to_le_bytes(), h.to_le_bytes(), scale.to_le_bytes(), 0f32.to_le_bytes()].concat()
}

fn a_kernel_runs_and_reads_back_every_texel() {
    let b = browser();
    assert!(b.info().architecture.contains("swiftshader"), "{:?}", b.info());
    let (w, h) = (37u32, 11u32);
    let table = [10u32, 20, 30, 40];
    let u = uniforms(w, h, 0.5);
    let out = b.run("gradient", &job("g1", GRADIENT, &u, &table, w, h)).unwrap();
    assert_eq!(rgba(&out).len(), (w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let px = rgba(&out)[(y * w + x) as usize];
            assert_eq!(px, [x as f32 * 0.5, y as f32, table[((x + y) % 4) as usize] as f32, 1.0], "({x}, {y})");
        }
    }
    // The same browser serves a second run with other uniforms.
    let u = uniforms(w, h, 2.0);
    let out = b.run("gradient", &job("g1", GRADIENT, &u, &table, w, h)).unwrap();
    assert_eq!(rgba(&out)[(w - 1) as usize][0], (w - 1) as f32 * 2.0);
}

fn tint_errors_name_the_case_and_the_next_run_works() {
    let b = browser();
    let bad = GRADIENT.replace("f32(id.y)", "id.y");
    let u = uniforms(8, 8, 1.0);
    let table = [0u32; 4];
    let e = failure(b.run("case-bad", &job("bad", &bad, &u, &table, 8, 8)), "Tint accepted a type error").to_string();
    assert!(e.starts_with("case-bad: in the browser: Tint rejected the WGSL of bad: line"), "{e}");
    let good = job("good", GRADIENT, &u, &table, 8, 8);
    assert_eq!(b.run("case-good", &good).map(|o| rgba(&o)).unwrap().len(), 64);
}

fn a_hung_kernel_trips_the_watchdog_and_a_crashed_page_is_named() {
    // A long watchdog for the launch and the runs that must succeed, a short
    // one for the hung kernel: SwiftShader spins on every core until it trips.
    let mut b = browser();
    // Never ends: scale is 1, so the loop's exit is never taken.
    let forever = GRADIENT.replace(
        "let t = ",
        "var i = 0.0;\n    loop {\n        i = i + params.scale;\n        textureStore(out, vec2<i32>(id.xy), vec4<f32>(i));\n        if (i < 0.0) { break; }\n    }\n    let t = ",
    );
    let u = uniforms(64, 64, 1.0);
    let table = [0u32; 4];
    b.set_timeout(Duration::from_secs(1));
    let start = std::time::Instant::now();
    let e = failure(b.run("case-hang", &job("hang", &forever, &u, &table, 64, 64)), "the hung kernel returned");
    let took = start.elapsed();
    b.set_timeout(Duration::from_secs(60));
    assert!(matches!(e, BrowserError::Timeout { .. } | BrowserError::Page { .. }), "{e}");
    assert!(e.to_string().starts_with("case-hang: "), "{e}");
    assert!(took < Duration::from_secs(30), "{took:?}");
    let good = job("good", GRADIENT, &u, &table, 64, 64);
    assert_eq!(b.run("after-hang", &good).map(|o| rgba(&o)).unwrap().len(), 64 * 64);

    b.crash_page_for_test();
    let e = failure(b.run("case-crash", &good), "the crashed page returned");
    assert!(matches!(e, BrowserError::Died { .. }), "{e}");
    assert!(e.to_string().starts_with("case-crash: "), "{e}");
    assert_eq!(b.run("after-hang", &good).map(|o| rgba(&o)).unwrap().len(), 64 * 64, "a fresh browser after the crash");
}
